"""Radial surfaces over a shared icosphere triangulation, seen from a head centre c.

A wrap is a radius per icosphere direction: vertex i sits at c + r_i u_i. Such a "radial graph"
can never intersect itself, two of them with r_a < r_b at every vertex never intersect each
other (the radius of a flat triangle along any ray inside its cone is the weighted harmonic
mean 1 / sum_k(a_k / r_k), monotone in every corner radius), and the prism between two
corresponding triangles is convex, so all three tets of its split are positive. These are
exactly the guarantees the layered head model needs."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import softdeca_native as native
from scipy.spatial import cKDTree


@dataclass(frozen=True)
class RaySamples:
    """Points of a surface seen from c: which wrap triangle's cone holds each, with the cone
    coefficients a (u = sum_k a_k u_k) and the point's distance rho from c."""

    triangle: np.ndarray  # (n,) wrap triangle index
    coeff: np.ndarray  # (n, 3) a_k >= 0
    rho: np.ndarray  # (n,)


def cone_inverses(dirs: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Per wrap triangle, the inverse of [u_a u_b u_c]: cone coefficients a = inv @ u."""
    return np.linalg.inv(np.transpose(dirs[tris], (0, 2, 1)))


def cast_samples(
    points: np.ndarray,
    center: np.ndarray,
    dirs: np.ndarray,
    tris: np.ndarray,
    inverses: np.ndarray | None = None,
    candidates: int = 3,
) -> RaySamples:
    """Assign points to the cones of the wrap triangles (cone = centre + spherical triangle):
    nearest triangle centres first, then the first cone whose coefficients are all >= 0."""
    d = points - center
    rho = np.linalg.norm(d, axis=1)
    if np.any(rho < 1e-9):
        raise ValueError("a surface point coincides with the head centre")
    u = d / rho[:, None]
    inv = cone_inverses(dirs, tris) if inverses is None else inverses
    tri = np.full(len(u), -1)
    coeff = np.zeros((len(u), 3))
    todo = np.arange(len(u))
    tree = _centre_tree(dirs, tris)
    k = candidates
    while len(todo):
        _, cand = tree.query(u[todo], k=min(k, len(tris)))
        a = np.einsum("nkij,nj->nki", inv[cand], u[todo])  # (n, k, 3)
        ok = a.min(axis=2) >= -1e-12
        first = np.argmax(ok, axis=1)
        found = ok[np.arange(len(todo)), first]
        rows = todo[found]
        tri[rows] = cand[found, first[found]]
        coeff[rows] = a[found, first[found]]
        todo = todo[~found]
        if k >= len(tris):
            if len(todo):
                raise RuntimeError("direction outside every cone: the sphere is not closed")
            break
        k *= 4
    return RaySamples(triangle=tri, coeff=np.clip(coeff, 0.0, None), rho=rho)


_TREES: dict[tuple[int, int], tuple[np.ndarray, cKDTree]] = {}


def _centre_tree(dirs: np.ndarray, tris: np.ndarray) -> cKDTree:
    """KD-tree of triangle centre directions, memoised per (dirs, tris) buffer."""
    key = (id(dirs), id(tris))
    hit = _TREES.get(key)
    if hit is None or hit[0] is not dirs:
        c = dirs[tris].mean(axis=1)
        hit = (dirs, cKDTree(c / np.linalg.norm(c, axis=1, keepdims=True)))
        _TREES[key] = hit
    return hit[1]


def radius_along(samples: RaySamples, tris: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Radius at which each sample's ray meets the flat wrap triangle with corner radii r."""
    return 1.0 / (samples.coeff / r[tris[samples.triangle]]).sum(axis=1)


def push_outside(r: np.ndarray, samples: RaySamples, tris: np.ndarray, margin: float) -> np.ndarray:
    """Raise the corners of every triangle whose flat face passes below one of its samples, but
    only the corners lower than that sample, and only up to it: afterwards every corner of such a
    triangle is at least the sample's radius, so its harmonic-mean radius along the sample's ray
    is too. One pass suffices, and corners already high enough (e.g. a neighbouring shoulder)
    are never inflated."""
    target = samples.rho + margin
    bad = radius_along(samples, tris, r) < target
    raised = r.copy()
    np.maximum.at(raised, tris[samples.triangle[bad]].ravel(), np.repeat(target[bad], 3))
    return raised


def pull_inside(r: np.ndarray, samples: RaySamples, tris: np.ndarray, margin: float) -> np.ndarray:
    """Mirror of push_outside: lower offending corners to `margin` below the sample."""
    target = samples.rho - margin
    if np.any(target <= 0):
        raise ValueError("a surface point lies within `margin` of the head centre")
    bad = radius_along(samples, tris, r) > target
    lowered = r.copy()
    np.minimum.at(lowered, tris[samples.triangle[bad]].ravel(), np.repeat(target[bad], 3))
    return lowered


def harmonic_fill(
    values: np.ndarray, known: np.ndarray, neighbours: list[np.ndarray], iterations: int = 300
) -> np.ndarray:
    """Fill unknown vertex values by averaging neighbours (Jacobi on the graph Laplacian)."""
    v = values.copy()
    v[~known] = values[known].mean()
    counts = np.array([len(n) for n in neighbours])
    flat = np.concatenate(neighbours)
    owner = np.repeat(np.arange(len(neighbours)), counts)
    for _ in range(iterations):
        mean = np.bincount(owner, weights=v[flat], minlength=len(v)) / counts
        v[~known] = mean[~known]
    return v


def smooth(
    values: np.ndarray, neighbours: list[np.ndarray], iterations: int, weight: float = 0.5
) -> np.ndarray:
    """Umbrella smoothing of a per-vertex scalar on the sphere graph."""
    v = values.copy()
    counts = np.array([len(n) for n in neighbours])
    flat = np.concatenate(neighbours)
    owner = np.repeat(np.arange(len(neighbours)), counts)
    for _ in range(iterations):
        mean = np.bincount(owner, weights=v[flat], minlength=len(v)) / counts
        v = (1 - weight) * v + weight * mean
    return v


def repair_crossings(
    r: np.ndarray,
    center: np.ndarray,
    dirs: np.ndarray,
    tris: np.ndarray,
    surf: np.ndarray,
    surf_tris: np.ndarray,
    outward: bool,
    step: float = 0.02,
    max_rounds: int = 60,
) -> np.ndarray:
    """Exact clean-up after the sampled fit: while any wrap triangle crosses the surface (exact
    triangle-triangle test), scale that triangle's corners out (or in) by `step`. Needed where
    the surface is seen at a grazing angle from the centre (the nape), which sampling alone
    cannot guarantee."""
    r = r.copy()
    factor = 1.0 + step if outward else 1.0 - step
    tris32 = tris.astype(np.int32)
    for _ in range(max_rounds):
        pairs = native.mesh_intersections(
            center + r[:, None] * dirs, tris32, surf, surf_tris, 100000
        )
        if not pairs:
            return r
        hit = np.unique(tris[np.array([a for a, _ in pairs])].ravel())
        r[hit] *= factor
    raise RuntimeError("wrap still crosses the surface after repair; raise the wrap level")


def limit_slope(
    r: np.ndarray, dirs: np.ndarray, neighbours: list[np.ndarray], slope: float
) -> np.ndarray:
    """The largest radii <= r whose change between neighbouring directions is at most
    `slope` times the arc between them (|r_i - r_j| <= slope * r_j * angle_ij): a lower
    envelope, found by relaxing every edge until nothing changes (a shortest-path fixed
    point). Steep steps in a deep wrap (where S's cavities push it down next to a
    directions where they do not) make the prisms' side walls lean over and split into
    needles and slivers; only lowering keeps every "below" bound of the wrap."""
    counts = np.array([len(n) for n in neighbours])
    flat = np.concatenate(neighbours)
    owner = np.repeat(np.arange(len(neighbours)), counts)
    angle = np.arccos(np.clip(np.einsum("ij,ij->i", dirs[owner], dirs[flat]), -1.0, 1.0))
    out = r.copy()
    for _ in range(len(r)):
        bound = np.full(len(r), np.inf)
        np.minimum.at(bound, owner, out[flat] * (1.0 + slope * angle))
        new = np.minimum(out, bound)
        if np.array_equal(new, out):
            return out
        out = new
    return out
