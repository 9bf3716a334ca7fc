"""Tet element quality of a layered head model: minimum dihedral angle and aspect ratio, over
the whole head and in the mouth region (where the lips, the mouth corners and the tissue under
the nose are). These are the figures that predict inverted elements under shear: a needle or a
sliver inverts under a small sideways move of one vertex."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

# The mouth region: the wrap columns (a direction through every layer) whose skin wrap vertex
# lies within this distance of the mouth's centre: from the nose's base to the chin.
MOUTH_REGION_RADIUS = 0.045


def dihedral_angles(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """(T, 6) interior dihedral angles in degrees at the six edges of each tet."""
    p = points[tets]
    faces = [(1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)]  # face opposite vertex k, outward
    n = []
    for a, b, c in faces:
        fn = np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a])
        n.append(fn / np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-300))
    out = []
    for i, j in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)):
        cos = -np.einsum("ij,ij->i", n[i], n[j])
        out.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return np.stack(out, axis=1)


def aspect_ratios(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """(T,) longest edge / smallest height (the distance of a vertex from its opposite face's
    plane): sqrt(3/2) ~ 1.22 for a regular tet, unbounded for needles and slivers."""
    p = points[tets]
    vol6 = np.abs(
        np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
    )
    area2 = [
        np.linalg.norm(np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a]), axis=1)
        for a, b, c in ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))
    ]
    height = vol6 / np.maximum(np.max(area2, axis=0), 1e-300)
    edges = [np.linalg.norm(p[:, a] - p[:, b], axis=1) for a in range(4) for b in range(a + 1, 4)]
    return np.max(edges, axis=0) / np.maximum(height, 1e-300)


@dataclass(frozen=True)
class QualityFigures:
    """Quality of one set of tets."""

    tets: int
    min_dihedral_deg: float
    p01_dihedral_deg: float  # 1st percentile of the tets' smallest dihedral angle
    max_aspect_ratio: float
    p99_aspect_ratio: float
    median_aspect_ratio: float


def quality_figures(points: np.ndarray, tets: np.ndarray) -> QualityFigures:
    if len(tets) == 0:
        raise ValueError("no tets to measure")
    dmin = dihedral_angles(points, tets).min(axis=1)
    ar = aspect_ratios(points, tets)
    return QualityFigures(
        tets=len(tets),
        min_dihedral_deg=float(dmin.min()),
        p01_dihedral_deg=float(np.percentile(dmin, 1)),
        max_aspect_ratio=float(ar.max()),
        p99_aspect_ratio=float(np.percentile(ar, 99)),
        median_aspect_ratio=float(np.median(ar)),
    )


@dataclass(frozen=True)
class QualityReport:
    soft: QualityFigures
    muscle: QualityFigures
    mouth_soft: QualityFigures
    mouth_muscle: QualityFigures

    def as_dict(self) -> dict[str, dict[str, float]]:
        return asdict(self)


def mouth_columns(skin_wrap: np.ndarray, mouth_center: np.ndarray, n_layers: int) -> np.ndarray:
    """Per-vertex mask of a layered model's mouth region (layers stacked, `n_wrap` each)."""
    near = np.linalg.norm(skin_wrap - mouth_center, axis=1) < MOUTH_REGION_RADIUS
    return np.tile(near, n_layers)


def quality_report(
    points: np.ndarray, soft_tets: np.ndarray, muscle_tets: np.ndarray, mouth: np.ndarray
) -> QualityReport:
    """Quality of the soft and muscle tets, overall and in the mouth region: the tets with a
    vertex in `mouth` (per-vertex mask)."""
    return QualityReport(
        soft=quality_figures(points, soft_tets),
        muscle=quality_figures(points, muscle_tets),
        mouth_soft=quality_figures(points, soft_tets[mouth[soft_tets].any(axis=1)]),
        mouth_muscle=quality_figures(points, muscle_tets[mouth[muscle_tets].any(axis=1)]),
    )
