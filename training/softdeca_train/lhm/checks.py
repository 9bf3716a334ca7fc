"""Validity checks of a layered head model: the properties the simulation relies on."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import igl
import numpy as np
import softdeca_native as native

from softdeca_train.lhm.model import LayeredHeadModel
from softdeca_train.lhm.quality import QualityReport, mouth_columns, quality_report


@dataclass(frozen=True)
class LhmReport:
    n_wrap_vertices: int
    n_soft_tets: int
    n_muscle_tets: int
    min_volume_mm3: float  # smallest signed tet volume (must be > 0)
    min_quality: float  # 6*sqrt(2)*V / l_rms^3: 1 for a regular tet, 0 degenerate
    median_quality: float
    intersections: dict[str, int]  # pair of surfaces -> intersecting triangle pairs
    winding_skin_min: float  # S vertices w.r.t. the skin wrap: ~1 (inside)
    winding_muscle_max: float  # S vertices w.r.t. the muscle wrap: ~0 (outside)
    bary_min: float  # S's embedding coordinates (must lie in [0, 1] but next to the slit)
    bary_max: float
    # S points embedded in their own lip's side of the mouth slit outside their tet (lhm/fit.py
    # embed_skin_by_side), and the farthest of them from it.
    side_embedded_points: int
    side_embedded_outside_max_mm: float
    tets_spanning_both_lips: int  # tets with vertices of both lips' columns (must be 0)
    tets_spanning_both_lids: int  # the same for an eye's two lids (must be 0)
    quality: dict[str, dict[str, float]]  # lhm/quality.py: overall and in the mouth region
    outside_max_mm: float  # distance of S vertices outside their tet (0 when embedded)
    soft_volume_l: float
    muscle_volume_l: float
    skin_wrap_to_s_mean_mm: float  # how close the skin wrap hugs S (where S is below it)
    skin_wrap_to_s_p95_mm: float

    def as_dict(self) -> dict[str, object]:
        return asdict(self)

    def failures(self, bary_tol: float = 1e-6) -> list[str]:
        """Violated invariants, as readable sentences (empty: the model is valid)."""
        out = []
        if self.min_volume_mm3 <= 0:
            out.append(f"inverted or degenerate tet (min volume {self.min_volume_mm3:.3g} mm³)")
        out += [f"{k}: {v} intersecting triangle pairs" for k, v in self.intersections.items() if v]
        if self.winding_skin_min < 0.5:
            out.append(f"S leaves the skin wrap (winding {self.winding_skin_min:.3f})")
        if self.winding_muscle_max > 0.5:
            out.append(f"S enters the muscle wrap (winding {self.winding_muscle_max:.3f})")
        if self.bary_min < -bary_tol or self.bary_max > 1 + bary_tol:
            out.append(f"S embedding outside [0, 1]: [{self.bary_min:.3g}, {self.bary_max:.3g}]")
        if self.side_embedded_outside_max_mm > SIDE_EMBEDDING_MAX_MM:
            out.append(
                f"S points {self.side_embedded_outside_max_mm:.3g} mm outside their lip's tets"
            )
        if self.tets_spanning_both_lips:
            out.append(f"{self.tets_spanning_both_lips} tets span both lips")
        if self.tets_spanning_both_lids:
            out.append(f"{self.tets_spanning_both_lids} tets span both lids of an eye")
        return out


# S points next to the mouth slit lie at most this far outside the tet of their own lip's side
# that holds them (measured: 4.6 mm on the template at wrap level 3, 2.0 mm at level 4).
SIDE_EMBEDDING_MAX_MM = 8.0


def closed_wrap_triangles(model: LayeredHeadModel) -> np.ndarray:
    """The wrap triangles with the slits' copies mapped back to their originals: the closed
    surface the wraps form at rest (the copies coincide with them there)."""
    return model.copy_of()[model.wrap_triangles].astype(np.int32)


def tets_spanning_both_lips(
    model: LayeredHeadModel, tets: np.ndarray, vertex_side: np.ndarray | None = None
) -> int:
    """Tets with vertices on both sides of a slit (`vertex_side`: the wraps' lip_side, or
    eye_side for the lids)."""
    side = model.lip_side if vertex_side is None else vertex_side
    side = np.tile(side, model.n_layers)[tets]
    return int(((side > 0).any(axis=1) & (side < 0).any(axis=1)).sum())


def slit_middle(model: LayeredHeadModel) -> np.ndarray:
    """Middle of the slit's inner part on the skin wrap: the mouth region's centre."""
    middle = model.mouth_copies if len(model.slit_copy_of) else model.slit_path
    return model.skin_wrap[middle].mean(axis=0)


def mouth_quality(model: LayeredHeadModel) -> QualityReport:
    """Element quality of the model, overall and in the mouth region around the slit."""
    center = slit_middle(model)
    mouth = mouth_columns(model.skin_wrap, center, model.n_layers)
    return quality_report(model.vertices, model.soft_tets, model.muscle_tets, mouth)


def tet_quality(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    p = points[tets]
    vol = (
        np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])) / 6
    )
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    l2 = sum(((p[:, a] - p[:, b]) ** 2).sum(1) for a, b in pairs) / 6.0
    return 6.0 * np.sqrt(2.0) * vol / np.maximum(l2, 1e-30) ** 1.5


def check_lhm(model: LayeredHeadModel, skin: np.ndarray, skin_tris: np.ndarray) -> LhmReport:
    """All invariants of `model` for the skin surface S = (skin, skin_tris)."""
    v = model.vertices
    tris = closed_wrap_triangles(model)
    wraps = {
        "skin_wrap": model.skin_wrap,
        "muscle_wrap": model.muscle_wrap,
        "skull_wrap": model.skull_wrap,
    }
    all_tets = np.vstack([model.soft_tets, model.muscle_tets])
    vol = native.tet_signed_volumes(v, all_tets)
    q = tet_quality(v, all_tets)
    inter: dict[str, int] = {}
    for name, w in wraps.items():
        inter[f"{name} x itself"] = len(native.self_intersections(w, tris, 100))
        inter[f"{name} x S"] = len(native.mesh_intersections(w, tris, skin, skin_tris, 100))
    inter["skin_wrap x muscle_wrap"] = len(
        native.mesh_intersections(wraps["skin_wrap"], tris, wraps["muscle_wrap"], tris, 100)
    )
    inter["muscle_wrap x skull_wrap"] = len(
        native.mesh_intersections(wraps["muscle_wrap"], tris, wraps["skull_wrap"], tris, 100)
    )
    w_skin = igl.fast_winding_number(wraps["skin_wrap"], tris, skin)
    w_muscle = igl.fast_winding_number(wraps["muscle_wrap"], tris, skin)
    _, _, outside = native.embed_points(v, model.soft_tets, skin)
    b = model.skin_bary
    side = (b.min(axis=1) < -1e-9) | (b.max(axis=1) > 1 + 1e-9)
    own_outside = [0.0]
    one_tet = np.array([[0, 1, 2, 3]], np.int32)
    for i in np.flatnonzero(side):
        corners = v[model.soft_tets[model.skin_tet[i]]]
        own_outside.append(float(native.embed_points(corners, one_tet, skin[i : i + 1])[2][0]))
    bary = b[~side]
    d2, _, _ = igl.point_mesh_squared_distance(wraps["skin_wrap"], skin, skin_tris)
    d = np.sqrt(d2)
    # Wrap vertices over the neck opening have no S beneath them: leave them out.
    covered = d < 0.02
    return LhmReport(
        n_wrap_vertices=model.n_wrap,
        n_soft_tets=len(model.soft_tets),
        n_muscle_tets=len(model.muscle_tets),
        min_volume_mm3=float(vol.min() * 1e9),
        min_quality=float(q.min()),
        median_quality=float(np.median(q)),
        intersections=inter,
        winding_skin_min=float(w_skin.min()),
        winding_muscle_max=float(w_muscle.max()),
        bary_min=float(bary.min()),
        bary_max=float(bary.max()),
        side_embedded_points=int(side.sum()),
        side_embedded_outside_max_mm=max(own_outside) * 1e3,
        tets_spanning_both_lips=tets_spanning_both_lips(model, all_tets),
        tets_spanning_both_lids=tets_spanning_both_lips(model, all_tets, model.eye_side),
        quality=mouth_quality(model).as_dict(),
        outside_max_mm=float(outside.max() * 1e3),
        soft_volume_l=float(native.tet_signed_volumes(v, model.soft_tets).sum() * 1e3),
        muscle_volume_l=float(native.tet_signed_volumes(v, model.muscle_tets).sum() * 1e3),
        skin_wrap_to_s_mean_mm=float(d[covered].mean() * 1e3),
        skin_wrap_to_s_p95_mm=float(np.percentile(d[covered], 95) * 1e3),
    )
