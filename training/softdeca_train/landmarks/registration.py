"""Registration of ARKit's reference neutral onto the template's skin surface S.

1. Similarity (scale, rotation, translation; Umeyama 1991) from paired 68-point landmarks.
2. Non-rigid ICP (after Amberg et al. 2007, with a linear displacement model): minimise
       sum_i c_i |x_i - q_i|^2  +  w_lm sum_k |x_a(k) - p_k|^2  +  alpha^2 |L (X - X_sim)|^2
   over the ARKit vertices X, where q_i is the closest point of x_i on S's face region (kept
   only if the normals agree and it is near), p_k the template's landmark vertices, and L the
   ARKit mesh's uniform graph Laplacian, so the smoothness term penalises uneven displacement
   of neighbours. alpha falls over a schedule: first near-rigid, then freer.

Which of the 68 pairs are trusted (measured on the data; the landmarks report shows it):
- Jaw (0-16): ARKit's jaw vertices lie on the outer rim of ARKit's face mask, which reaches back
  to the ears and under the chin, while ICT's lie on the frontal face contour: different anatomy,
  17-32 mm apart after an interior-only similarity (a similarity over all 68 pairs leaves the
  interior pairs 6.9 mm apart on average, against 3.4 mm without the jaw). They enter
  neither step; the closest-point term places the jaw line.
- Inner lips (60-67): used by the similarity, not by the non-rigid step. With closed lips the
  upper and lower inner-lip points are under 1 mm apart and pulling them onto ICT's folds the
  lips into each other (with them: 2 inverted triangles at the mouth corners and 56 intersecting
  triangle pairs; without: none inverted and 15 pairs, fewer than ARKit's own neutral has, 22).
  Their residual after the non-rigid step is then an unconstrained check.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from tqdm import tqdm

from softdeca_train.geometry import Similarity, umeyama
from softdeca_train.landmarks.topology import face_normals, unique_edges, vertex_normals

JAW_68 = tuple(range(0, 17))
INTERIOR_68 = tuple(range(17, 68))  # brows, nose, eyes, lips
INNER_LIPS_68 = tuple(range(60, 68))
CONSTRAINED_68 = tuple(range(17, 60))  # brows, nose, eyes, outer lips


@dataclass(frozen=True)
class RegistrationConfig:
    similarity_pairs: tuple[int, ...] = INTERIOR_68
    nonrigid_pairs: tuple[int, ...] = CONSTRAINED_68
    # Smoothness weight alpha per stage (relative to a unit per-vertex data weight).
    stiffness: tuple[float, ...] = (8.0, 4.0, 2.0, 1.0, 0.5)
    iterations_per_stage: int = 3
    landmark_weight: float = 4.0  # per landmark pair, relative to one closest-point vertex
    max_normal_angle_deg: float = 60.0
    max_distance: float = 0.012  # m; farther closest points are rejected as wrong matches
    target_region: str = "face"  # ICT component the closest points may lie on


@dataclass
class Registration:
    config: RegistrationConfig
    similarity: Similarity
    aligned: np.ndarray  # (1220, 3) ARKit neutral after the similarity
    registered: np.ndarray  # (1220, 3) after the non-rigid step
    residual_similarity: np.ndarray  # (68,) m, |landmark pair| after the similarity
    residual_nonrigid: np.ndarray  # (68,) m, after the non-rigid step
    surface_distance: np.ndarray  # (1220,) m, registered vertex to S's target region
    matched: np.ndarray  # (1220,) bool, vertex had an accepted closest point at the end
    history: list[dict[str, float]] = field(default_factory=list)


@dataclass(frozen=True)
class TargetSurface:
    """A part of S: triangles (rows of the template's skin triangles) for closest points."""

    vertices: np.ndarray
    triangles: np.ndarray  # (T, 3) vertex indices
    skin_rows: np.ndarray  # (T,) row of each triangle in Template.skin_triangles

    def closest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(distance, triangle row into self.triangles, closest point) per point."""
        d2, tri, cp = igl.point_mesh_squared_distance(
            np.ascontiguousarray(points, dtype=np.float64),
            self.vertices,
            self.triangles.astype(np.int64),
        )
        return np.sqrt(d2), tri, cp


def _uniform_laplacian(n: int, triangles: np.ndarray) -> sp.csr_matrix:
    """I - D^-1 A: unitless, so the smoothness weight means the same at any scale."""
    e = unique_edges(triangles)
    ones = np.ones(2 * len(e))
    a = sp.coo_matrix((ones, (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])), (n, n)).tocsr()
    deg = np.asarray(a.sum(axis=1)).ravel()
    return (sp.identity(n) - sp.diags(1.0 / deg) @ a).tocsr()


def register(
    source_vertices: np.ndarray,
    source_triangles: np.ndarray,
    source_landmarks68: np.ndarray,
    target: TargetSurface,
    target_landmarks68: np.ndarray,
    config: RegistrationConfig | None = None,
    progress: bool = True,
    desc: str = "non-rigid ICP",
) -> Registration:
    """Register a source mesh (ARKit's neutral) onto the target surface (S's face region).
    `target_landmarks68` are positions (68, 3) on the target paired with the source's 68
    landmark vertex indices."""
    cfg = config or RegistrationConfig()
    src = np.asarray(source_vertices, dtype=np.float64)
    lm_src = np.asarray(source_landmarks68, dtype=np.int64)
    lm_dst = np.asarray(target_landmarks68, dtype=np.float64)
    if lm_src.shape != (68,) or lm_dst.shape != (68, 3):
        raise ValueError("register needs 68 source landmark indices and (68, 3) target positions")
    for name, pairs in (("similarity", cfg.similarity_pairs), ("nonrigid", cfg.nonrigid_pairs)):
        if any(not 0 <= k < 68 for k in pairs):
            raise ValueError(f"{name}_pairs must be 68-point indices")
    if len(cfg.similarity_pairs) < 3:
        raise ValueError("the similarity needs at least 3 landmark pairs")

    sim_pairs = list(cfg.similarity_pairs)
    sim = umeyama(src[lm_src[sim_pairs]], lm_dst[sim_pairs])
    aligned = sim.apply(src)
    res_sim = np.linalg.norm(aligned[lm_src] - lm_dst, axis=1)

    n = len(src)
    lap = _uniform_laplacian(n, source_triangles)
    ltl = (lap.T @ lap).tocsc()
    rhs_smooth = ltl @ aligned  # smoothness pulls towards the similarity's displacement field
    pairs = list(cfg.nonrigid_pairs)
    sel = sp.coo_matrix(
        (np.ones(len(pairs)), (np.arange(len(pairs)), lm_src[pairs])), (len(pairs), n)
    ).tocsr()
    lm_normal = cfg.landmark_weight * (sel.T @ sel)
    lm_rhs = cfg.landmark_weight * (sel.T @ lm_dst[pairs])
    tri_normals = face_normals(target.vertices, target.triangles)
    cos_max = np.cos(np.radians(cfg.max_normal_angle_deg))

    x = aligned.copy()
    history = []
    stages = [(a, it) for a in cfg.stiffness for it in range(cfg.iterations_per_stage)]
    matched = np.zeros(n, dtype=bool)
    for alpha, _ in tqdm(stages, desc=desc, unit="iter", disable=not progress, leave=False):
        dist, tri, cp = target.closest(x)
        normals = vertex_normals(x, source_triangles)
        compatible = (normals * tri_normals[tri]).sum(axis=1) >= cos_max
        matched = compatible & (dist <= cfg.max_distance)
        w = matched.astype(np.float64)
        a = (alpha**2) * ltl + sp.diags(w) + lm_normal
        b = (alpha**2) * rhs_smooth + w[:, None] * cp + lm_rhs
        x = spla.splu(a.tocsc()).solve(b)
        history.append(
            {
                "alpha": alpha,
                "matched": float(matched.mean()),
                "mean_distance_mm": float(dist[matched].mean() * 1e3),
            }
        )

    dist, _, _ = target.closest(x)
    return Registration(
        config=cfg,
        similarity=sim,
        aligned=aligned,
        registered=x,
        residual_similarity=res_sim,
        residual_nonrigid=np.linalg.norm(x[lm_src] - lm_dst, axis=1),
        surface_distance=dist,
        matched=matched,
        history=history,
    )
