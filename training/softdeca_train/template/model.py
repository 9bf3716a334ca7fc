"""The head template built from ICT-FaceKit: components, the skin surface S, expressions,
identity modes, and identity sampling."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from softdeca_train.template.arkit import ARKIT_BLENDSHAPES, arkit_to_ict_matrix
from softdeca_train.template.components import COMPONENTS, N_SKIN, Component
from softdeca_train.template.ict_source import load_ict
from softdeca_train.template.plausibility import implausibilities

# Identity coefficients: ICT's modes are principal components already scaled by their standard
# deviation (the largest displacement at weight 1 falls from 13 mm for mode 0 to 0.3 mm for
# mode 99, like a PCA spectrum), so h ~ N(0, I) samples the population; truncated at 3 sigma.
IDENTITY_TRUNCATION = 3.0


def _triangulate(polygons: np.ndarray, verts: np.ndarray) -> np.ndarray:
    """Quads split along the shorter diagonal of the neutral; winding kept."""
    tri = polygons[polygons[:, 3] < 0, :3]
    quads = polygons[polygons[:, 3] >= 0]
    d02 = np.linalg.norm(verts[quads[:, 0]] - verts[quads[:, 2]], axis=1)
    d13 = np.linalg.norm(verts[quads[:, 1]] - verts[quads[:, 3]], axis=1)
    a = quads[d02 <= d13]
    b = quads[d02 > d13]
    return np.concatenate(
        [tri, a[:, [0, 1, 2]], a[:, [0, 2, 3]], b[:, [0, 1, 3]], b[:, [1, 2, 3]]]
    ).astype(np.int32)


@dataclass
class Template:
    """ICT-FaceKit as the product's template. Units metres; +Y up, +Z out of the face; +X is
    the subject's own left (checked from the geometry in `left_suffix`)."""

    neutral: np.ndarray  # (V, 3) float64
    polygons: np.ndarray  # (F, 4) int32, -1 pads triangles
    expression_names: list[str]
    expression_deltas: np.ndarray  # (53, V, 3) float32
    identity_modes: np.ndarray  # (100, V, 3) float32
    landmarks68: np.ndarray  # ICT's Multi-PIE 68 vertex indices
    components: dict[str, Component] = field(
        default_factory=lambda: {c.name: c for c in COMPONENTS}
    )

    @classmethod
    def load(cls, ict_path: str | None = None) -> Template:
        raw = load_ict(ict_path)
        return cls(
            neutral=raw["neutral"],
            polygons=raw["polygons"],
            expression_names=[str(n) for n in raw["expression_names"]],
            expression_deltas=raw["expression_deltas"],
            identity_modes=raw["identity_modes"],
            landmarks68=raw["landmarks68"],
        )

    # ---- topology --------------------------------------------------------------------------
    @cached_property
    def triangles(self) -> np.ndarray:
        """All triangles of the head (every component)."""
        return _triangulate(self.polygons, self.neutral)

    @cached_property
    def skin_triangles(self) -> np.ndarray:
        """Triangles of S (all three vertices in the skin range)."""
        t = self.triangles
        return t[(t < N_SKIN).all(axis=1)]

    def component_triangles(self, name: str) -> np.ndarray:
        c = self.components[name]
        t = self.triangles
        return t[((t >= c.start) & (t < c.stop)).all(axis=1)]

    @property
    def n_vertices(self) -> int:
        return self.neutral.shape[0]

    # ---- expressions -------------------------------------------------------------------------
    @cached_property
    def left_suffix(self) -> str:
        """ICT suffix of shapes that move the subject's own left (+x), from the geometry:
        the displacement-weighted centroid of eyeBlink_L."""
        i = self.expression_names.index("eyeBlink_L")
        mag = np.linalg.norm(self.expression_deltas[i], axis=1)
        x = float((self.neutral[:, 0] * mag).sum() / mag.sum())
        return "_L" if x > 0 else "_R"

    @cached_property
    def arkit_to_ict(self) -> np.ndarray:
        """(53, 52): ICT weights = arkit_to_ict @ ARKit weights (canonical ARKit order)."""
        return arkit_to_ict_matrix(self.expression_names, self.left_suffix)

    def blend(self, arkit_weights: np.ndarray, identity: np.ndarray | None = None) -> np.ndarray:
        """Linear blendshapes: the whole head for 52 ARKit weights (and identity coefficients)."""
        w = np.asarray(arkit_weights, dtype=np.float64)
        if w.shape != (len(ARKIT_BLENDSHAPES),):
            raise ValueError(f"expected {len(ARKIT_BLENDSHAPES)} ARKit weights, got {w.shape}")
        ict_w = self.arkit_to_ict @ w
        out = self.identity_neutral(identity)
        out += np.tensordot(ict_w, self.expression_deltas, axes=1)
        return out

    # ---- identities --------------------------------------------------------------------------
    def identity_neutral(self, coefficients: np.ndarray | None) -> np.ndarray:
        """The neutral head of identity coefficients h (None: the template itself)."""
        out = self.neutral.copy()
        if coefficients is not None:
            h = np.asarray(coefficients, dtype=np.float64)
            if h.shape != (self.identity_modes.shape[0],):
                raise ValueError(f"expected {self.identity_modes.shape[0]} identity coefficients")
            modes = self.identity_modes.reshape(len(h), -1)  # float32 GEMV: no float64 copy
            out += (h.astype(np.float32) @ modes).reshape(out.shape)
        return out

    def sample_identity(self, seed: int, scale: float = 1.0, max_draws: int = 200) -> np.ndarray:
        """Identity coefficients of a plausible head, reproducible from `seed`.

        Distribution: h ~ N(0, scale² I) truncated at |h_k| <= 3 scale, conditioned on the head
        being plausible (S free of self-intersection away from the lip contact, face sizes in
        the human range; see plausibility.py). Draws are rejected and redrawn from the same
        seeded stream: at scale 1 about a third of raw draws fold at the inner eye corners or
        the columella (14 of 40 seeds, measured with the tests' check)."""
        rng = np.random.default_rng(seed)
        for _ in range(max_draws):
            h = (
                np.clip(
                    rng.standard_normal(self.identity_modes.shape[0]),
                    -IDENTITY_TRUNCATION,
                    IDENTITY_TRUNCATION,
                )
                * scale
            )
            if not implausibilities(
                self.identity_neutral(h), self.skin_triangles, self.landmarks68
            ):
                return h
        raise RuntimeError(f"no plausible identity in {max_draws} draws at scale {scale}")
