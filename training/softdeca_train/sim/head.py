"""A head's simulation: layered head model + teeth as bone vertices + lip, lid and teeth
collision sets → the native SimulationMesh and Simulator; ARKit frames → skin targets and jaw
motion."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import softdeca_native as native

from softdeca_train.contact_rules import ContactRules
from softdeca_train.lhm import LayeredHeadModel, LhmConfig, fit_lhm
from softdeca_train.lhm.carried import tissue_mesh
from softdeca_train.lhm.fit import embed_skin_by_side, jaw_motion
from softdeca_train.lhm.model import JAW
from softdeca_train.sim.lids import LidSets, lid_candidates, lid_sets_of
from softdeca_train.sim.lips import LipSets, lip_sets_of
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN


def _homogeneous(r: np.ndarray, t: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, t
    return m


@dataclass
class HeadSimulation:
    """Everything needed to run φ† on one identity."""

    template: Template
    identity: np.ndarray | None
    head: np.ndarray  # neutral, whole head (V, 3)
    lhm: LayeredHeadModel
    mesh: native.SimulationMesh
    teeth_upper: np.ndarray  # simulated vertex ids of the upper teeth (ICT order)
    teeth_lower: np.ndarray
    lips: LipSets
    lids: LidSets
    tet_source: str = "prisms"  # where its tets came from (_Tissue.source)

    def simulator(self, **settings: object) -> native.Simulator:
        return native.Simulator(self.mesh, **settings)

    def blend(self, weights: np.ndarray) -> np.ndarray:
        """Linear blendshapes S_t of this identity for (F, 52) ARKit weights: (F, V, 3)."""
        w = np.atleast_2d(np.asarray(weights, dtype=np.float64))
        ict = w @ self.template.arkit_to_ict.T  # (F, 53)
        deltas = self.template.expression_deltas.reshape(len(self.template.expression_names), -1)
        return self.head[None] + (ict.astype(np.float32) @ deltas).reshape(len(w), -1, 3)

    def jaw_transforms(self, blended: np.ndarray) -> np.ndarray:
        """(F, 4, 4) rigid jaw motion of each blended frame, from the lower teeth (Kabsch)."""
        return np.stack([_homogeneous(*jaw_motion(self.template, self.head, b)) for b in blended])

    def whole_head(self, skin: np.ndarray, blended: np.ndarray, jaw: np.ndarray) -> np.ndarray:
        """The whole head for a simulated skin: S from the simulation, components riding the
        jaw moved rigidly with it, the others (cranium-fixed teeth, eyes, lashes) as blended."""
        out = blended.copy()
        out[:N_SKIN] = skin
        on_jaw = N_SKIN + np.flatnonzero(self.lhm.attachments["bone_of_vertex"] == JAW)
        out[on_jaw] = self.head[on_jaw] @ jaw[:3, :3].T + jaw[:3, 3]
        return out


# A skull wrap vertex of a jaw direction rides the jaw only where it lies on the mandible:
# no deeper below the skin wrap than the tissue-depth prior plus this tolerance (metres).
JAW_DEPTH_TOLERANCE = 0.02


def jaw_skull_vertices(lhm: LayeredHeadModel) -> np.ndarray:
    """Per wrap vertex: whether the skull wrap vertex is pinned to the jaw. The radial wraps
    pass behind the oral cavity, so along most jaw directions (skin riding the jaw) the skull
    wrap lies 6-10 cm under the skin, level with the palate, not on the mandible; moved
    rigidly with the jaw it pushes outward along the rays through the muscle layer, which the
    skin above holds, and inverts the muscle tets. Those vertices stay with the cranium."""
    depth = np.linalg.norm(lhm.skin_wrap - lhm.skull_wrap, axis=1)
    on_bone = depth <= lhm.tissue_depth + JAW_DEPTH_TOLERANCE
    return (lhm.skull_labels == JAW) & on_bone


@dataclass(frozen=True)
class _Tissue:
    """The simulated tissue of a head: vertices, tets, bones, S's embedding in the soft tets."""

    vertices: np.ndarray
    soft_tets: np.ndarray
    muscle_tets: np.ndarray
    skull_triangles: np.ndarray  # over vertices; empty when every skull vertex is pinned
    cranium: np.ndarray
    jaw: np.ndarray
    skin_tet: np.ndarray
    skin_bary: np.ndarray
    source: str  # "prisms", or the conforming mesh's TetMesh.source


def _tissue(
    template: Template, identity: np.ndarray | None, head: np.ndarray, lhm: LayeredHeadModel
) -> _Tissue:
    """The LHM's own prism tets, or a conforming mesh: the template's fill carried to the head
    or the head's own fill (LhmConfig.tet_mesh)."""
    cfg = lhm.config
    if cfg.tet_mesh == "prisms":
        on_jaw = jaw_skull_vertices(lhm)
        skull_ids = (lhm.n_layers - 1) * lhm.n_wrap + np.arange(lhm.n_wrap)
        return _Tissue(
            lhm.vertices,
            lhm.soft_tets,
            lhm.muscle_tets,
            (lhm.wrap_triangles + (lhm.n_layers - 1) * lhm.n_wrap).astype(np.int32),
            skull_ids[~on_jaw],
            skull_ids[on_jaw],
            lhm.skin_tet,
            lhm.skin_bary,
            "prisms",
        )
    if cfg.tet_mesh not in ("carried", "conforming"):
        raise ValueError(f"unknown tet_mesh {cfg.tet_mesh!r}: 'carried', 'conforming' or 'prisms'")
    tm, wraps = tissue_mesh(template, identity, lhm)
    bone_jaw = jaw_skull_vertices(wraps)[tm.bone_wrap_vertex]
    skin_tet, skin_bary = embed_skin_by_side(
        tm.vertices,
        tm.soft_tets,
        head[:N_SKIN].astype(np.float64),
        tm.soft_side,
        lhm.attachments["skin_lip_bone"],
        tm.soft_lid_side,
        lhm.attachments["skin_lid_side"],
    )
    return _Tissue(
        tm.vertices,
        tm.soft_tets,
        tm.muscle_tets,
        np.zeros((0, 3), np.int32),
        tm.bone_vertices[~bone_jaw],
        tm.bone_vertices[bone_jaw],
        np.asarray(skin_tet, np.int32),
        skin_bary,
        tm.source,
    )


def build_head_simulation(
    template: Template,
    identity: np.ndarray | None = None,
    config: LhmConfig | None = None,
    landmarks: tuple[np.ndarray, np.ndarray] | None = None,
) -> HeadSimulation:
    """The simulation of identity h. `landmarks`: (triangle rows of S, barycentric (L, 3)) for
    the sparse variant (SurfaceLandmarks.triangle / .bary)."""
    head = template.identity_neutral(identity)
    lhm = fit_lhm(template, identity, config)
    tissue = _tissue(template, identity, head, lhm)
    n_lhm = len(tissue.vertices)
    up = template.components["teeth_upper"]
    lo = template.components["teeth_lower"]
    teeth_upper = n_lhm + np.arange(up.stop - up.start)
    teeth_lower = teeth_upper[-1] + 1 + np.arange(lo.stop - lo.start)
    rest = np.vstack([tissue.vertices, head[up.slice], head[lo.slice]])
    cranium = np.concatenate([tissue.cranium, teeth_upper])
    jaw = np.concatenate([tissue.jaw, teeth_lower])
    skin_vertices, skin_weights = native.skin_embedding_from_tets(
        tissue.soft_tets, tissue.skin_tet.tolist(), tissue.skin_bary
    )
    rules = ContactRules(template.landmarks68, lid_candidates(template))
    skin = head[:N_SKIN]
    lips, lids = lip_sets_of(skin, template.skin_triangles, rules), lid_sets_of(skin, rules)
    upper_teeth = template.component_triangles("teeth_upper") - up.start + teeth_upper[0]
    lower_teeth = template.component_triangles("teeth_lower") - lo.start + teeth_lower[0]
    collisions = native.contact_sets(
        skin, template.skin_triangles, upper_teeth, lower_teeth, **vars(rules)
    )
    lm_points = lm_weights = None
    if landmarks is not None:
        tri, bary = landmarks
        lm_points = template.skin_triangles[tri].astype(np.int32)
        lm_weights = np.asarray(bary, dtype=np.float64)
    mesh = native.SimulationMesh(
        rest=rest,
        soft_tets=tissue.soft_tets,
        muscle_tets=tissue.muscle_tets,
        connecting_tets=np.zeros((0, 4), np.int32),
        skull_triangles=tissue.skull_triangles,
        cranium_vertices=cranium.astype(np.int32).tolist(),
        jaw_vertices=jaw.astype(np.int32).tolist(),
        skin_vertices=skin_vertices,
        skin_weights=skin_weights,
        skin_triangles=template.skin_triangles,
        landmark_points=lm_points,
        landmark_weights=lm_weights,
        collisions=collisions,
    )
    return HeadSimulation(
        template, identity, head, lhm, mesh, teeth_upper, teeth_lower, lips, lids, tissue.source
    )
