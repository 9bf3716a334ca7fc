"""A surface in another topology: about N vertices, each on the original surface.

Two styles (REMESH_STYLES):
- isotropic: midpoint subdivision (every new vertex on the surface), then collapsing the
  shortest edge first (libigl's decimate, the new vertex at the edge's midpoint): the edge
  lengths even out whatever the original's density (ICT's face is dense, the back of its head
  coarse); features thinner than an edge (the ears' rims, the nostrils) are cut across.
- adaptive: collapsing the edge of least quadric error first (libigl's qslim, Garland and
  Heckbert): dense where the surface curves, coarse where it is flat, as artists' meshes are.
Each vertex is then put on its closest point of the original surface, one that faces its way:
where two sheets lie close (the lips, the eyelids), the nearest point may belong to the other
sheet, whose normal points the other way. The vertex's triangle and barycentric coordinates
there carry every per-vertex quantity of the original (positions, shapes) to the new mesh."""

from __future__ import annotations

from dataclasses import dataclass

import igl
import numpy as np

from softdeca_train.landmarks.topology import face_normals, vertex_normals
from softdeca_train.sample_avatars.config import REMESH_STYLES


@dataclass(frozen=True)
class SurfacePoints:
    """Points on a triangle mesh: point k is sum_j bary[k, j] * x[triangles[triangle[k], j]]."""

    triangle: np.ndarray  # (n,) int64, rows of the mesh's triangles
    bary: np.ndarray  # (n, 3) float64, non-negative, summing to 1

    def evaluate(self, values: np.ndarray, triangles: np.ndarray) -> np.ndarray:
        """A per-vertex quantity (V, ...) of the mesh at the points: (n, ...)."""
        corners = np.asarray(values)[np.asarray(triangles)[self.triangle]]  # (n, 3, ...)
        return np.einsum("kj,kj...->k...", self.bary, corners)


@dataclass(frozen=True)
class Remeshed:
    triangles: np.ndarray  # (F, 3) int32 of the new surface
    points: SurfacePoints  # its vertices on the original surface
    resnapped: int  # vertices whose nearest point faced the other way and were moved


def _compact(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Without vertices no triangle uses, in their order."""
    used = np.unique(triangles)
    index = np.full(len(vertices), -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    return vertices[used], index[triangles]


def snap(
    points: np.ndarray, normals: np.ndarray, vertices: np.ndarray, triangles: np.ndarray
) -> tuple[SurfacePoints, int]:
    """The closest point of the surface (vertices, triangles) to each point among the
    triangles that face the point's normal's way, as SurfacePoints, and how many points the
    plain closest point put on a triangle facing the other way."""
    tris = np.asarray(triangles, dtype=np.int64)
    _, tri, closest = igl.point_mesh_squared_distance(points, vertices, tris)
    fn = face_normals(vertices, tris)
    wrong = np.flatnonzero(np.einsum("ij,ij->i", normals, fn[tri]) < 0)
    for i in wrong:
        facing = np.flatnonzero(fn @ normals[i] > 0)
        _, t, c = igl.point_mesh_squared_distance(points[i : i + 1], vertices, tris[facing])
        tri[i], closest[i] = facing[t[0]], c[0]
    corners = vertices[tris[tri]]
    bary = igl.barycentric_coordinates(closest, corners[:, 0], corners[:, 1], corners[:, 2])
    bary = np.clip(bary, 0.0, 1.0)
    bary /= bary.sum(axis=1, keepdims=True)
    return SurfacePoints(tri.astype(np.int64), bary), len(wrong)


def remesh(
    vertices: np.ndarray, triangles: np.ndarray, target: int, style: str = "isotropic"
) -> Remeshed:
    """The surface (vertices, triangles) remeshed to about `target` vertices (within a few
    per cent) in a REMESH_STYLES style; it may have boundaries (ICT's skin ends at the neck)."""
    if style not in REMESH_STYLES:
        raise ValueError(f"remesh style must be one of {', '.join(REMESH_STYLES)}")
    v, t = _compact(np.asarray(vertices, dtype=np.float64), np.asarray(triangles, np.int64))
    faces = round(target * len(t) / len(v))  # the original's ratio of triangles to vertices
    if style == "isotropic":
        up_v, up_t = igl.upsample(v, t)
        new_v, new_t, _, _ = igl.decimate(up_v, up_t.astype(np.int32), faces, False)
    else:
        new_v, new_t, _, _ = igl.qslim(v, t.astype(np.int32), faces, False)
    new_v, new_t = _compact(new_v, np.asarray(new_t, dtype=np.int64))
    points, resnapped = snap(new_v, vertex_normals(new_v, new_t), v, t)
    # the triangles of the compacted original are the original's rows, in their order
    return Remeshed(new_t.astype(np.int32), points, resnapped)
