"""The mouth in the layered head model: a slit through every wrap along the mouth line (the
same cut separates the eyelids, lhm/eyes.py).

The wraps are radial graphs over one triangulation of directions, so a slit is a path of wrap
edges whose inner vertices are doubled: the triangles above the path keep the original
vertices, those below take the copies. The prisms (and so the tets) above and below then share
no vertex along the mouth line, in every layer from the skin wrap to the skull wrap, and the
slit closes at the mouth corners (the path's end vertices are not doubled). At rest the two
copies coincide (the lips touch); under load they part.

The path follows the mouth line of S (the inner lip contour's mid-line between the inner mouth
corners, ICT landmarks 60 and 64) as seen from the head centre: a shortest path on the
direction graph weighted by the distance from that line, whose vertices are then moved onto
it (directions only, so every wrap stays a radial graph; moves that would fold a triangle of
the direction sphere are shortened)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from softdeca_train.contact_rules import CONTACT_LANDMARKS

# ICT 68-landmark ids of the inner lip contour (the contact rules'): corner, the upper lip's
# three, corner, the lower lip's three back toward the first corner.
INNER_RIGHT_CORNER, INNER_LEFT_CORNER = CONTACT_LANDMARKS.inner_mouth_corners
INNER_UPPER = CONTACT_LANDMARKS.inner_lip[1:4]
INNER_LOWER = CONTACT_LANDMARKS.inner_lip[:4:-1]  # below INNER_UPPER's, in that order


def mouth_line(skin: np.ndarray, lm68: np.ndarray) -> np.ndarray:
    """(5, 3) polyline from the right to the left inner mouth corner through the midpoints of
    the upper and lower inner lip contour."""
    lm = skin[lm68]
    mids = [0.5 * (lm[u] + lm[w]) for u, w in zip(INNER_UPPER, INNER_LOWER, strict=True)]
    return np.vstack([lm[INNER_RIGHT_CORNER], *mids, lm[INNER_LEFT_CORNER]])


# ICT 68-landmark ids on each lip, away from the corners (48, 54, 60, 64): outer and inner
# contour.
UPPER_LIP_LANDMARKS = (49, 50, 51, 52, 53, *INNER_UPPER)
LOWER_LIP_LANDMARKS = (55, 56, 57, 58, 59, *INNER_LOWER[::-1])


def upper_lip_points(
    verts: np.ndarray, tris: np.ndarray, lm68: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """Per point of `points` (vertex ids of the surface (verts, tris)): whether it is nearer,
    along the surface, to the upper lip's landmarks than to the lower lip's. Along the surface
    the lips meet only at the corners and through the mouth socket, so this holds where the
    lips are pressed into each other and a split by height fails (on ICT identity seed 1 the
    lower lip's inner middle lies above the upper lip's)."""
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    w = np.linalg.norm(verts[e[:, 0]] - verts[e[:, 1]], axis=1)
    n = len(verts)
    graph = coo_matrix((np.r_[w, w], (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])), (n, n))
    g = graph.tocsr()
    to_upper = dijkstra(g, indices=lm68[list(UPPER_LIP_LANDMARKS)], min_only=True)
    to_lower = dijkstra(g, indices=lm68[list(LOWER_LIP_LANDMARKS)], min_only=True)
    return to_upper[points] < to_lower[points]


def closest_on_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Closest point of the polyline `line` to each of `points` (all 3D)."""
    a, b = line[:-1], line[1:]
    ab = b - a
    t = np.einsum("pkd,kd->pk", points[:, None] - a[None], ab) / np.einsum("kd,kd->k", ab, ab)
    c = a[None] + np.clip(t, 0, 1)[..., None] * ab[None]
    d = np.linalg.norm(c - points[:, None], axis=2)
    return c[np.arange(len(points)), np.argmin(d, axis=1)]


@dataclass(frozen=True)
class Slit:
    """The slit of a wrap triangulation with `n` directions."""

    directions: np.ndarray  # (n + k, 3): the moved directions, then the k copies'
    triangles: np.ndarray  # (F, 3) the cut triangulation
    path: np.ndarray  # wrap vertices along the line, end to end (original ids)
    copy_of: np.ndarray  # (k,) original vertex of each copy (the path's inner vertices)
    side: np.ndarray  # (F,) +1: the upper side of the slit (upper lip, lid), -1: the lower's

    @property
    def n_original(self) -> int:
        return len(self.directions) - len(self.copy_of)

    def extend(self, per_vertex: np.ndarray) -> np.ndarray:
        """A per-original-vertex array with the copies' values appended."""
        return np.concatenate([per_vertex, per_vertex[self.copy_of]])


def _edges(tris: np.ndarray) -> np.ndarray:
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0)


def _path_along(dirs: np.ndarray, tris: np.ndarray, line_dirs: np.ndarray) -> np.ndarray:
    """Shortest edge path between the directions nearest the line's ends, each edge costing
    its arc times (1 + its distance from the line in units of the mean edge arc, squared)."""
    e = _edges(tris)
    arc = np.arccos(np.clip(np.einsum("ij,ij->i", dirs[e[:, 0]], dirs[e[:, 1]]), -1, 1))
    mid = dirs[e].mean(axis=1)
    mid /= np.linalg.norm(mid, axis=1, keepdims=True)
    off = np.linalg.norm(closest_on_polyline(mid, line_dirs) - mid, axis=1) / arc.mean()
    w = arc * (1.0 + 25.0 * off**2)
    n = len(dirs)
    graph = coo_matrix((np.r_[w, w], (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])), (n, n))
    start = int(np.argmax(dirs @ line_dirs[0]))
    stop = int(np.argmax(dirs @ line_dirs[-1]))
    _, pred = dijkstra(graph.tocsr(), indices=start, return_predecessors=True)
    path = [stop]
    while path[-1] != start:
        if pred[path[-1]] < 0:
            raise ValueError("the slit's ends are not connected on the wrap triangulation")
        path.append(int(pred[path[-1]]))
    return np.array(path[::-1])


def _orientation(dirs: np.ndarray, tris: np.ndarray) -> np.ndarray:
    d = dirs[tris]
    return np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2]))


def _snap(
    dirs: np.ndarray, tris: np.ndarray, path: np.ndarray, line_dirs: np.ndarray
) -> np.ndarray:
    """Move the path's directions onto the line (ends onto its ends), shortening any move that
    would fold a direction triangle (orientation kept at least half of what it was)."""
    target = closest_on_polyline(dirs[path], line_dirs)
    target[0], target[-1] = line_dirs[0], line_dirs[-1]
    target /= np.linalg.norm(target, axis=1, keepdims=True)
    before = _orientation(dirs, tris)
    out = dirs.copy()
    for share in (1.0, 0.75, 0.5, 0.25, 0.0):
        trial = out.copy()
        moved = (1 - share) * dirs[path] + share * target
        trial[path] = moved / np.linalg.norm(moved, axis=1, keepdims=True)
        if np.all(_orientation(trial, tris) > 0.5 * before):
            return trial
    return out


def _sides(tris: np.ndarray, path: np.ndarray, dirs: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Per triangle touching the path's inner vertices: +1 / -1 for the two components the
    path's edges separate them into (+1: the one lying farther along `up`), 0 elsewhere."""
    inner = np.zeros(len(dirs), bool)
    inner[path[1:-1]] = True
    band = np.flatnonzero(inner[tris].any(axis=1))
    cut = {(min(a, b), max(a, b)) for a, b in itertools.pairwise(path.tolist())}
    by_edge: dict[tuple[int, int], list[int]] = {}
    for f in band:
        a, b, c = (int(x) for x in tris[f])
        for edge in ((a, b), (b, c), (c, a)):
            key = (min(edge), max(edge))
            if key not in cut:
                by_edge.setdefault(key, []).append(int(f))
    label = dict.fromkeys(band.tolist(), -1)
    comps = 0
    for f0 in band.tolist():
        if label[f0] >= 0:
            continue
        stack, label[f0] = [f0], comps
        while stack:
            f = stack.pop()
            a, b, c = (int(x) for x in tris[f])
            for edge in ((a, b), (b, c), (c, a)):
                for g in by_edge.get((min(edge), max(edge)), []):
                    if label[g] < 0:
                        label[g] = comps
                        stack.append(g)
        comps += 1
    if comps != 2:
        raise ValueError(f"the slit's path splits its neighbourhood into {comps} parts, not 2")
    comp = np.array([label[f] for f in band.tolist()])
    height = dirs[tris[band]].mean(axis=1) @ up
    upper = 0 if height[comp == 0].mean() > height[comp == 1].mean() else 1
    side = np.zeros(len(tris), np.int8)
    side[band] = np.where(comp == upper, 1, -1)
    return side


def slit_along(dirs: np.ndarray, tris: np.ndarray, center: np.ndarray, line: np.ndarray) -> Slit:
    """Cut the wrap triangulation (directions `dirs` from `center`) along `line` (3D points
    on S, corner to corner: the mouth line, an eye's fissure)."""
    line_dirs = line - center
    line_dirs /= np.linalg.norm(line_dirs, axis=1, keepdims=True)
    path = _path_along(dirs, tris, line_dirs)
    if len(path) < 3:
        # The line is shorter than two wrap edges (coarse wrap levels): nothing to cut.
        no_copies = np.zeros(0, np.int64)
        return Slit(dirs.copy(), tris.copy(), path, no_copies, np.zeros(len(tris), np.int8))
    moved = _snap(dirs, tris, path, line_dirs)
    up = np.cross(line_dirs[-1] - line_dirs[0], line_dirs[len(line_dirs) // 2])
    up /= np.linalg.norm(up)
    if up[1] < 0:
        up = -up
    side = _sides(tris, path, moved, up)
    copy_of = path[1:-1]
    new_id = np.full(len(dirs), -1)
    new_id[copy_of] = len(dirs) + np.arange(len(copy_of))
    cut = tris.copy()
    lower = side < 0
    swap = lower[:, None] & (new_id[tris] >= 0)
    cut[swap] = new_id[tris[swap]]
    return Slit(np.vstack([moved, moved[copy_of]]), cut.astype(np.int32), path, copy_of, side)
