"""Landmarks as barycentric points on the template's skin surface S, evaluated on any mesh in
template topology (any identity, any expression)."""

from __future__ import annotations

from dataclasses import dataclass

import igl
import numpy as np

from softdeca_train.landmarks.registration import TargetSurface


@dataclass(frozen=True)
class SurfaceLandmarks:
    """Landmark k lies in triangle `triangle[k]` (a row of Template.skin_triangles) with
    vertices `corners[k]` (template vertex indices) at barycentric coordinates `bary[k]`:
    position = sum_j bary[k, j] * vertices[corners[k, j]]."""

    names: tuple[str, ...]
    regions: tuple[str, ...]
    triangle: np.ndarray  # (L,) int64
    corners: np.ndarray  # (L, 3) int64
    bary: np.ndarray  # (L, 3) float64, each row in [0, 1], sums to 1

    def __len__(self) -> int:
        return len(self.triangle)

    def evaluate(self, vertices: np.ndarray) -> np.ndarray:
        """Landmark positions on a mesh in template topology: (V, 3) -> (L, 3), or a batch
        (B, V, 3) -> (B, L, 3)."""
        v = np.asarray(vertices)
        if v.ndim not in (2, 3) or v.shape[-1] != 3:
            raise ValueError(f"expected (V, 3) or (B, V, 3) vertices, got {v.shape}")
        if v.shape[-2] <= int(self.corners.max()):
            raise ValueError(
                f"mesh has {v.shape[-2]} vertices; landmarks need template "
                f"topology (index {int(self.corners.max())})"
            )
        return np.einsum("lj,...ljc->...lc", self.bary, v[..., self.corners, :])


def embed(
    points: np.ndarray, target: TargetSurface, names: tuple[str, ...], regions: tuple[str, ...]
) -> tuple[SurfaceLandmarks, np.ndarray]:
    """Project points onto the target part of S; returns the barycentric landmarks and each
    point's distance to S (m)."""
    dist, tri, cp = target.closest(points)
    corners = target.triangles[tri].astype(np.int64)
    v = target.vertices
    bary = igl.barycentric_coordinates(cp, v[corners[:, 0]], v[corners[:, 1]], v[corners[:, 2]])
    # The closest point lies in its triangle: clear round-off outside [0, 1] and renormalise.
    bary = np.clip(bary, 0.0, 1.0)
    bary /= bary.sum(axis=1, keepdims=True)
    lms = SurfaceLandmarks(
        names=names, regions=regions, triangle=target.skin_rows[tri], corners=corners, bary=bary
    )
    return lms, dist
