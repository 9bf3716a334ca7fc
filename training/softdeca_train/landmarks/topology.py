"""Triangle-mesh topology helpers: boundary loops, the edge graph, shortest paths along edges,
arc-length subsampling of vertex chains, vertex normals."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra


def boundary_loops(triangles: np.ndarray) -> list[np.ndarray]:
    """Every boundary loop as an ordered vertex array, oriented like the triangles' winding
    (each boundary edge (a, b) taken in the direction of its one triangle). Longest first."""
    t = np.asarray(triangles, dtype=np.int64)
    half = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    keys = set(map(tuple, half.tolist()))
    boundary = [(a, b) for a, b in half.tolist() if (b, a) not in keys]
    nxt: dict[int, int] = {}
    for a, b in boundary:
        if a in nxt:
            raise ValueError(f"non-manifold boundary at vertex {a}")
        nxt[a] = b
    loops, seen = [], set()
    for a, _ in boundary:
        if a in seen:
            continue
        loop = [a]
        seen.add(a)
        v = nxt[a]
        while v != a:
            if v in seen or v not in nxt:
                raise ValueError(f"boundary does not close into loops near vertex {v}")
            loop.append(v)
            seen.add(v)
            v = nxt[v]
        loops.append(np.asarray(loop, dtype=np.int64))
    return sorted(loops, key=len, reverse=True)


def unique_edges(triangles: np.ndarray) -> np.ndarray:
    """(E, 2) undirected edges, each once, smaller index first."""
    t = np.asarray(triangles, dtype=np.int64)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0)


def edge_graph(vertices: np.ndarray, triangles: np.ndarray) -> sp.csr_matrix:
    """Symmetric sparse adjacency with Euclidean edge lengths as weights."""
    e = unique_edges(triangles)
    w = np.linalg.norm(vertices[e[:, 0]] - vertices[e[:, 1]], axis=1)
    n = len(vertices)
    g = sp.coo_matrix((np.r_[w, w], (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])), (n, n))
    return g.tocsr()


def shortest_path(graph: sp.csr_matrix, a: int, b: int) -> np.ndarray:
    """Vertices of the shortest edge path from a to b, both included."""
    _, pred = dijkstra(graph, indices=a, return_predecessors=True)
    if a != b and pred[b] < 0:
        raise ValueError(f"vertices {a} and {b} are not connected")
    path = [b]
    while path[-1] != a:
        path.append(int(pred[path[-1]]))
    return np.asarray(path[::-1], dtype=np.int64)


def graph_nearest(graph: sp.csr_matrix, source: int, candidates: np.ndarray) -> int:
    """The candidate nearest to `source` along mesh edges. Unlike Euclidean distance this
    never jumps across a hole: on closed lips the upper and lower lip's ring vertices nearly
    coincide, but only one of them is near along the surface."""
    dist = dijkstra(graph, indices=source)
    cand = np.asarray(candidates)
    return int(cand[np.argmin(dist[cand])])


def chain_through(graph: sp.csr_matrix, anchors: Sequence[int], closed: bool) -> np.ndarray:
    """Concatenated shortest paths anchor to anchor (and back to the first if closed);
    each anchor appears once, in order."""
    stops = [*anchors, anchors[0]] if closed else list(anchors)
    chain: list[int] = [int(stops[0])]
    for a, b in itertools.pairwise(stops):
        chain.extend(shortest_path(graph, int(a), int(b))[1:].tolist())
    if closed:
        chain.pop()
    out = np.asarray(chain, dtype=np.int64)
    if len(np.unique(out)) != len(out):
        raise ValueError(f"the path through anchors {list(anchors)} crosses itself")
    return out


def loop_arc(loop: np.ndarray, start: int, end: int, through: int) -> np.ndarray:
    """The part of a closed loop from `start` to `end` (both included) that contains `through`."""
    loop = np.asarray(loop)
    pos = {int(v): i for i, v in enumerate(loop)}
    for v in (start, end, through):
        if v not in pos:
            raise ValueError(f"vertex {v} is not on the loop")
    rolled = np.roll(loop, -pos[start])
    k = int(np.nonzero(rolled == end)[0][0])
    forward = rolled[: k + 1]
    if through in forward:
        return forward
    backward = np.r_[rolled[:1], rolled[k:][::-1]]
    return backward


def subsample_chain(
    vertices: np.ndarray, chain: np.ndarray, keep: Sequence[int], n: int, closed: bool
) -> np.ndarray:
    """n vertices of a chain, in chain order: every vertex in `keep` (the anchors; an open
    chain's ends too) plus, between consecutive kept vertices, the chain vertices nearest to
    evenly spaced arc-length positions. Segments get points in proportion to their length
    (largest remainder), so the spacing is even along the whole contour."""
    chain = np.asarray(chain, dtype=np.int64)
    missing = [k for k in keep if k not in chain]
    if missing:
        raise ValueError(f"anchors {missing} are not on the chain")
    if closed:
        if not len(keep):
            raise ValueError("a closed chain needs at least one anchor to start from")
        chain = np.roll(chain, -int(np.nonzero(chain == keep[0])[0][0]))
        work = np.r_[chain, chain[:1]]  # walk back to the start
    else:
        work = chain
    m = len(work)
    body = work[:-1] if closed else work  # each chain vertex once
    kept = sorted({0, m - 1, *(int(np.nonzero(body == k)[0][0]) for k in keep)})
    n_unique = len(kept) - 1 if closed else len(kept)
    n_chain = m - 1 if closed else m
    if not n_unique <= n <= n_chain:
        raise ValueError(
            f"cannot pick {n} points from a chain of {n_chain} vertices with {n_unique} anchors"
        )
    p = vertices[work]
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    lengths = np.diff(s[kept])
    extra = n - n_unique
    quota = extra * lengths / max(lengths.sum(), 1e-300)
    alloc = np.floor(quota).astype(int)
    for i in np.argsort(-(quota - alloc), kind="stable")[: extra - int(alloc.sum())]:
        alloc[i] += 1
    # A segment cannot take more points than it has interior vertices: move the surplus on.
    room = np.diff(kept) - 1
    while (alloc > room).any():
        alloc[int(np.argmax(alloc - room))] -= 1
        alloc[int(np.argmax(room - alloc))] += 1
    chosen = set(kept)
    for (a, b), k in zip(itertools.pairwise(kept), alloc, strict=True):
        free = list(range(a + 1, b))
        for tgt in s[a] + (s[b] - s[a]) * np.arange(1, k + 1) / (k + 1):
            j = min(free, key=lambda i, t=tgt: abs(s[i] - t))
            free.remove(j)
            chosen.add(j)
    idx = sorted(chosen)
    if closed:
        idx = idx[:-1]  # the walk's last vertex is its first
    return work[idx]


def vertex_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals."""
    t = np.asarray(triangles, dtype=np.int64)
    fn = np.cross(vertices[t[:, 1]] - vertices[t[:, 0]], vertices[t[:, 2]] - vertices[t[:, 0]])
    vn = np.zeros_like(vertices, dtype=np.float64)
    for k in range(3):
        np.add.at(vn, t[:, k], fn)
    return vn / np.maximum(np.linalg.norm(vn, axis=1, keepdims=True), 1e-300)


def face_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    t = np.asarray(triangles, dtype=np.int64)
    fn = np.cross(vertices[t[:, 1]] - vertices[t[:, 0]], vertices[t[:, 2]] - vertices[t[:, 0]])
    return fn / np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-300)
