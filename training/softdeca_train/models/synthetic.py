"""A small synthetic head in the bundle's terms, for fast tests of the bundle, the reference and
the native runtime: an ellipsoidal skin S (an icosphere), a jaw and an eyeball as non-skin
components, 52 smooth blendshapes, landmarks, and an "ARKit-like" user face that drives them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.models.rest_head import RestHead
from softdeca_train.models.topology import CRANIUM, JAW, LandmarkSet, TemplateDefinition

JAW_OPEN = 24  # canonical ARKit index of jawOpen


@dataclass(frozen=True)
class SyntheticHead:
    definition: TemplateDefinition
    neutral: np.ndarray  # (Vh, 3)
    head_triangles: np.ndarray  # (T, 3)
    blendshapes: np.ndarray  # (52, Vh, 3) deltas
    user_neutral: np.ndarray  # (A, 3): the "ARKit face mesh" of a user, neutral
    user_deltas: np.ndarray  # (52, A, 3)

    def user_face(self, weights: np.ndarray) -> np.ndarray:
        return self.user_neutral + np.tensordot(weights, self.user_deltas, 1)


def icosphere(level: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit icosphere (V, 3) and outward triangles (F, 3). Kept here (not lhm.sphere) so the
    runtime tests' data needs no native module: they also run from the sanitizer build."""
    t = (1.0 + 5.0**0.5) / 2.0
    v = np.array(
        [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)], dtype=np.float64,
    )  # fmt: skip
    f = np.array(
        [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)], dtype=np.int64,
    )  # fmt: skip
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    for _ in range(level):
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        mid = v[uniq].sum(axis=1)
        m = inv.reshape(3, -1).T + len(v)
        v = np.vstack([v, mid / np.linalg.norm(mid, axis=1, keepdims=True)])
        a, b, c = f[:, 0], f[:, 1], f[:, 2]
        f = np.concatenate([
            np.stack([a, m[:, 0], m[:, 2]], 1), np.stack([b, m[:, 1], m[:, 0]], 1),
            np.stack([c, m[:, 2], m[:, 1]], 1), np.stack([m[:, 0], m[:, 1], m[:, 2]], 1),
        ])  # fmt: skip
    return v, f.astype(np.int32)


def _bumps(points: np.ndarray, rng: np.random.Generator, n: int, amp: float) -> np.ndarray:
    centres = points[rng.choice(len(points), n)]
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    d2 = ((points[None] - centres[:, None]) ** 2).sum(-1)
    return amp * np.exp(-d2 / 0.03**2)[..., None] * dirs[:, None, :]


def _rotation_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def synthetic_head(level: int = 2, seed: int = 0, n_landmarks: int = 20) -> SyntheticHead:
    rng = np.random.default_rng(seed)
    dirs, tris = icosphere(level)
    radii = np.array([0.08, 0.11, 0.09])
    skin = dirs * radii
    jaw_dirs, jaw_tris = icosphere(0)
    jaw = jaw_dirs * 0.02 + np.array([0.0, -0.06, 0.04])
    eye_dirs, eye_tris = icosphere(0)
    eye = eye_dirs * 0.012 + np.array([0.03, 0.03, 0.06])
    vs = len(skin)
    neutral = np.vstack([skin, jaw, eye])
    head_triangles = np.vstack([tris, jaw_tris + vs, eye_tris + vs + len(jaw)]).astype(np.int32)
    bones = np.concatenate([np.full(len(jaw), JAW), np.full(len(eye), CRANIUM)]).astype(np.uint8)
    anchors = np.nonzero((skin[:, 1] < -0.05) & (skin[:, 2] > 0.02))[0]

    deltas = np.zeros((52, len(neutral), 3))
    deltas[:, :vs] = _bumps(skin, rng, 52, 0.006)
    # jawOpen: the jaw and the chin rotate about a pivot behind the mouth.
    pivot = np.array([0.0, -0.02, -0.02])
    r = _rotation_x(0.25)
    chin = np.nonzero(skin[:, 1] < -0.04)[0]
    moved = np.concatenate([chin, np.arange(vs, vs + len(jaw))])
    deltas[JAW_OPEN, moved] = (neutral[moved] - pivot) @ r.T + pivot - neutral[moved]

    front = np.nonzero(dirs[tris].mean(axis=1)[:, 2] > 0.3)[0]
    lm_tri = rng.choice(front, n_landmarks, replace=False)
    bary = rng.dirichlet(np.ones(3), n_landmarks)
    n_arkit = 3 * n_landmarks
    arkit_vertex = rng.choice(n_arkit, n_landmarks, replace=False)
    user_neutral = rng.normal(size=(n_arkit, 3)) * 0.03 * np.array([1.0, 1.2, 0.3])
    user_neutral[arkit_vertex] = np.einsum("kj,kjc->kc", bary, skin[tris[lm_tri]]) * 1.1 + np.array(
        [0.0, 0.01, 0.0]
    )
    user_deltas = _bumps(user_neutral, rng, 52, 0.004)
    definition = TemplateDefinition(
        name=f"synthetic-ico{level}",
        head_vertices=len(neutral),
        skin_triangles=tris.astype(np.int32),
        skin_vertices=vs,
        landmarks=LandmarkSet(
            names=tuple(f"lm{k:02d}" for k in range(n_landmarks)),
            regions=("synthetic",) * n_landmarks,
            arkit_vertex=arkit_vertex.astype(np.int64),
            triangle=lm_tri.astype(np.int64),
            bary=bary,
            arkit_vertex_count=n_arkit,
        ),
        non_skin_bones=bones,
        jaw_anchors=anchors.astype(np.int64),
        skin_rest=skin,
        # four regions by quadrant of the rest skin (x and y signs): enough to exercise the
        # residual stage's region means
        skin_regions=((skin[:, 0] > 0).astype(np.int64) + 2 * (skin[:, 1] > 0)),
    )
    return SyntheticHead(definition, neutral, head_triangles, deltas, user_neutral, user_deltas)


# A short parameter list in parameters.json's format, for tests that must not depend on the
# physics' full list: one global, one per-face and one per-vertex parameter, linear and log.
TEST_PARAMETERS: tuple[dict[str, object], ...] = (
    {"name": "dyn_gamma", "default": 1.0, "lo": 0.05, "hi": 1.0, "domain": "skin_point"},
    {"name": "dyn_beta", "default": 0.0, "lo": 0.0, "hi": 0.95, "domain": "skin_point"},
    {"name": "w_skin_strain", "default": 1.0, "lo": 0.001, "hi": 100.0, "scale": "log",
     "unit": "kPa", "domain": "skin_triangle"},
    {"name": "target_volume", "default": 1.0, "lo": 0.5, "hi": 1.5, "domain": "soft_tet"},
    {"name": "gravity_strength", "default": 1.0, "lo": 1.0, "hi": 2.0, "unit": "g",
     "domain": "global"},
)  # fmt: skip


def _prism_tets(tris: np.ndarray, outer: int, inner: int) -> np.ndarray:
    """Three tets per skin triangle between two shells (vertex offsets `outer`, `inner`), each
    quad split from its larger-index outer corner to its smaller-index inner corner, so
    neighbouring prisms agree; oriented to positive volume by the caller."""
    a, b, c = np.sort(tris, axis=1).T
    return np.concatenate([
        np.stack([a + outer, b + outer, c + outer, a + inner], 1),
        np.stack([b + outer, c + outer, a + inner, b + inner], 1),
        np.stack([c + outer, a + inner, b + inner, c + inner], 1),
    ]).astype(np.int32)  # fmt: skip


def synthetic_rest_head(head: SyntheticHead, shells: tuple[float, ...] = (1.0, 0.9, 0.8)):
    """A rest head for the synthetic skin (rest_physics.RestHead): shells of S scaled about its
    centre, soft tissue between the first two, muscle between the last two, the innermost the
    pinned cranium; S is the outer shell itself."""
    d = head.definition
    vs = d.skin_vertices
    skin = head.neutral[:vs]
    centre = skin.mean(axis=0)
    vertices = np.vstack([centre + (skin - centre) * r for r in shells])
    tets = [_prism_tets(d.skin_triangles, k * vs, (k + 1) * vs) for k in range(2)]
    for t in tets:
        p = vertices[t]
        vol = np.einsum(
            "ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]
        )
        t[vol < 0, :2] = t[vol < 0, 1::-1]
    # S is the outer shell: each skin vertex embedded as the first corner of a soft tet of it
    tet_of = np.zeros(vs, np.int64)
    for t, corners in enumerate(tets[0]):
        tet_of[corners[corners < vs]] = t
    corners = tets[0][tet_of]
    first = np.argsort(corners != np.arange(vs)[:, None], axis=1, kind="stable")
    skin_vertex = np.take_along_axis(corners, first, axis=1)
    return RestHead(
        vertices=vertices,
        soft_tets=tets[0],
        muscle_tets=tets[1],
        skin_vertex=skin_vertex.astype(np.int32),
        skin_weight=np.tile(np.array([1.0, 0.0, 0.0, 0.0]), (vs, 1)),
        carry_weight=np.ones(vs),
        carry_smoothness=30.0,
        teeth_upper=np.zeros(0, np.int32),
        teeth_lower=np.zeros(0, np.int32),
        cranium=np.arange(2 * vs, 3 * vs, dtype=np.int32),
        jaw=np.zeros(0, np.int32),
        upper_teeth_triangles=np.zeros((0, 3), np.int32),
        lower_teeth_triangles=np.zeros((0, 3), np.int32),
        contacts=None,
    )
