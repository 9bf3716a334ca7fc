"""Icospheres: the shared triangulation of all wraps of the layered head model."""

from __future__ import annotations

from functools import cache

import numpy as np


@cache
def icosphere(level: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (V, 3) and outward counter-clockwise triangles (F, 3) of an icosahedron
    subdivided `level` times: V = 10 * 4**level + 2, F = 20 * 4**level."""
    if not 0 <= level <= 7:
        raise ValueError(f"icosphere level must be in 0..7, got {level}")
    t = (1.0 + 5.0**0.5) / 2.0
    verts = [
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
        (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1),
    ]  # fmt: skip
    faces = [
        (0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
        (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
        (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1),
    ]  # fmt: skip
    v = [np.array(p, dtype=np.float64) / np.linalg.norm(p) for p in verts]
    f = np.array(faces, dtype=np.int64)
    for _ in range(level):
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        base = len(v)
        mid = np.asarray(v)[uniq].sum(axis=1)
        v.extend(mid / np.linalg.norm(mid, axis=1, keepdims=True))
        m = inv.reshape(3, -1).T + base  # midpoints of edges (0,1), (1,2), (2,0)
        a, b, c = f[:, 0], f[:, 1], f[:, 2]
        f = np.concatenate([
            np.stack([a, m[:, 0], m[:, 2]], 1), np.stack([b, m[:, 1], m[:, 0]], 1),
            np.stack([c, m[:, 2], m[:, 1]], 1), np.stack([m[:, 0], m[:, 1], m[:, 2]], 1),
        ])  # fmt: skip
    dirs = np.asarray(v)
    return dirs, f.astype(np.int32)


def vertex_neighbours(triangles: np.ndarray, n: int) -> list[np.ndarray]:
    """One-ring neighbour lists of a closed triangle mesh."""
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    e = np.concatenate([e, e[:, ::-1]])
    e = np.unique(e, axis=0)
    split = np.searchsorted(e[:, 0], np.arange(n + 1))
    return [e[split[i] : split[i + 1], 1] for i in range(n)]


def zoom(dirs: np.ndarray, toward: np.ndarray, factor: float) -> np.ndarray:
    """Conformal re-spacing of directions: magnify the neighbourhood of `toward` by `factor`
    (stereographic projection from the opposite pole, scaling, projection back). Triangles keep
    their shape; the wrap gets more vertices where the head needs them (the neck)."""
    if factor == 1.0:
        return dirs
    t = toward / np.linalg.norm(toward)
    # Orthonormal frame (e1, e2, t); project from -t onto the plane through the origin.
    e1 = np.cross(t, [1.0, 0.0, 0.0] if abs(t[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(t, e1)
    x, y, z = dirs @ e1, dirs @ e2, dirs @ t
    denom = np.maximum(1.0 + z, 1e-12)
    px, py = x / denom / factor, y / denom / factor
    q = px**2 + py**2
    nz = (1.0 - q) / (1.0 + q)
    out = np.outer(2 * px / (1 + q), e1) + np.outer(2 * py / (1 + q), e2) + np.outer(nz, t)
    return out / np.linalg.norm(out, axis=1, keepdims=True)
