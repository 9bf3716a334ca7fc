"""The layered head model (paper 3.1) of one identity, and its configuration."""

from __future__ import annotations

import ast
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

# Skull-wrap vertex labels.
CRANIUM, JAW = 0, 1


@dataclass(frozen=True)
class LhmConfig:
    """Resolution and placement rules. Lengths in metres."""

    level: int = 4  # icosphere subdivisions of the wraps: V = 10 * 4**level + 2 per wrap
    soft_layers: int = 1  # tet layers between skin and muscle wrap
    muscle_layers: int = 1  # tet layers between muscle and skull wrap
    skin_margin: float = 1.0e-3  # S lies at least this far inside the skin wrap
    inner_margin: float = 1.0e-3  # S lies at least this far outside the muscle wrap
    sample_spacing: float = 3.0e-3  # S is sampled this densely to fit the wraps against it
    min_layer_gap: float = 2.0e-3  # minimum radial thickness of each tissue layer
    # Where S's cavities push the muscle wrap deep (behind the oral cavity and the eye
    # sockets), the skull wrap keeps at least this far below it (min_layer_gap stays the hard
    # bound): a thinner muscle layer there inverts under the skin's shear (2 mm: on every
    # frame moving the mouth; 10 mm: 3 more failing frames of the stress set than 16 mm).
    min_muscle_thickness: float = 16.0e-3
    # Largest radial change of the muscle and skull wraps per unit of arc between neighbouring
    # directions (0: unbounded); steeper steps lean the prisms over into needles and slivers.
    max_wrap_slope: float = 0.5
    # The simulation's tets: "carried" deforms the template's conforming fill to the head
    # (lhm/carried.py; a head it does not suit gets a fill of its own), "conforming" fills
    # every head's wraps with well-shaped tets of its own (lhm/conforming.py, fTetWild),
    # "prisms" uses the wraps' own prism tets.
    tet_mesh: str = "carried"
    # The carried mesh: weight of its displacement fields' smoothness against following S
    # (1/m), and the floor it is held to (the template's fill: 8.8 deg / 10.9 at level 3; S
    # lies skin_margin inside the skin wrap at rest).
    carry_smoothness: float = 30.0
    carry_min_dihedral_deg: float = 5.0
    carry_max_aspect: float = 15.0
    carry_max_skin_outside: float = 1.0e-3
    tet_edge_length: float = 0.03  # target tet edge, share of the head's bounding box diagonal
    tet_envelope: float = 5.0e-4  # largest boundary deviation, share of that diagonal
    # The mouth slit opened this wide (vertically, metres) for the conforming mesh: at 1.5 mm
    # fTetWild joined the two sides in 140 vertices up to 4.4 mm from the mouth corners' columns.
    slit_gap: float = 4.0e-3
    muscle_fraction: float = 0.5  # template muscle wrap depth, as a share of skin-to-skull
    muscle_relative_share: float = 0.1  # paper: 10 % of the relative change is followed
    min_skull_radius: float = 0.02  # the skull wrap keeps this far from the head centre
    depth_sigma_deg: float = 14.0  # smoothing of the tissue-depth prior over directions
    center_offset: tuple[float, float, float] = (0.0, 0.02, -0.03)  # from the ear midpoint
    zoom_toward: tuple[float, float, float] = (0.0, -1.0, 0.2)  # denser wrap toward the neck
    zoom_factor: float = 1.8
    inner_smoothing: int = 10  # umbrella iterations on the muscle and skull radii


@dataclass
class LayeredHeadModel:
    """Wraps (shared icosphere triangulation), tet meshes and S's embedding.

    `vertices` stacks the wrap layers from outside in: layer 0 is the skin wrap, layer
    `soft_layers` the muscle wrap, the last the skull wrap; each layer has `n_wrap` vertices.
    """

    config: LhmConfig
    center: np.ndarray  # (3,)
    directions: np.ndarray  # (n_wrap, 3)
    wrap_triangles: np.ndarray  # (F, 3), outward
    vertices: np.ndarray  # (n_layers * n_wrap, 3)
    soft_tets: np.ndarray  # (T_s, 4) skin wrap .. muscle wrap
    muscle_tets: np.ndarray  # (T_m, 4) muscle wrap .. skull wrap
    skull_labels: np.ndarray  # (n_wrap,) CRANIUM or JAW
    skin_tet: np.ndarray  # (n_S,) index into soft_tets
    skin_bary: np.ndarray  # (n_S, 4)
    tissue_depth: np.ndarray  # (n_wrap,) the prior's skin-to-skull depth (normal), metres
    # Mouth slit (lhm/mouth.py): per wrap vertex +1 / -1 in the upper / lower lip's columns
    # next to the slit (0 elsewhere); the last len(slit_copy_of) wrap vertices are the lower
    # lip's copies of the slit's inner vertices slit_copy_of (none below wrap level 3, where
    # the mouth is narrower than two wrap edges).
    lip_side: np.ndarray
    slit_copy_of: np.ndarray
    slit_path: np.ndarray  # wrap vertices along the mouth line, corner to corner
    # Eye slits (lhm/eyes.py), the same per eye: eye_side +1 / -1 in an upper / lower lid's
    # columns; the len(eye_copy_of) wrap vertices before the mouth's copies are the lower
    # lids' copies of eye_copy_of.
    eye_side: np.ndarray
    eye_copy_of: np.ndarray
    attachments: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n_wrap(self) -> int:
        return len(self.directions)

    @property
    def n_original(self) -> int:
        """Wrap vertices that are not a slit's copy."""
        return self.n_wrap - len(self.slit_copy_of) - len(self.eye_copy_of)

    @property
    def eye_copies(self) -> np.ndarray:
        """Wrap vertex ids of the eye slits' copies (twins of eye_copy_of)."""
        return self.n_original + np.arange(len(self.eye_copy_of))

    @property
    def mouth_copies(self) -> np.ndarray:
        """Wrap vertex ids of the mouth slit's copies (twins of slit_copy_of)."""
        return self.n_wrap - len(self.slit_copy_of) + np.arange(len(self.slit_copy_of))

    def copy_of(self) -> np.ndarray:
        """Per wrap vertex, its original (itself for originals)."""
        return np.concatenate([np.arange(self.n_original), self.eye_copy_of, self.slit_copy_of])

    @property
    def n_layers(self) -> int:
        return len(self.vertices) // self.n_wrap

    def layer(self, k: int) -> np.ndarray:
        return self.vertices[k * self.n_wrap : (k + 1) * self.n_wrap]

    @property
    def skin_wrap(self) -> np.ndarray:
        return self.layer(0)

    @property
    def muscle_wrap(self) -> np.ndarray:
        return self.layer(self.config.soft_layers)

    @property
    def skull_wrap(self) -> np.ndarray:
        return self.layer(self.n_layers - 1)

    def embedded_skin(self) -> np.ndarray:
        """S reconstructed from the tet vertices through its barycentric embedding."""
        corners = self.vertices[self.soft_tets[self.skin_tet]]  # (n_S, 4, 3)
        return np.einsum("nk,nkd->nd", self.skin_bary, corners)

    def save(self, path: str | Path) -> None:
        arrays = {k: v for k, v in self.__dict__.items() if isinstance(v, np.ndarray)}
        arrays |= {f"attach_{k}": v for k, v in self.attachments.items()}
        cfg = asdict(self.config)
        np.savez_compressed(
            path,
            config_keys=np.array(list(cfg)),
            config_values=np.array([repr(v) for v in cfg.values()]),
            **arrays,
        )

    @classmethod
    def load(cls, path: str | Path) -> LayeredHeadModel:
        with np.load(path) as z:
            cfg = {
                str(k): ast.literal_eval(str(v))
                for k, v in zip(z["config_keys"], z["config_values"], strict=True)
            }
            data = {k: z[k] for k in z.files if k not in ("config_keys", "config_values")}
        attach = {k[7:]: data.pop(k) for k in list(data) if k.startswith("attach_")}
        return cls(config=LhmConfig(**cfg), attachments=attach, **data)
