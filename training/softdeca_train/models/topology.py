"""What a bundle says about the template's topology, in the project's own terms: sizes, the
canonical triangulation of S (indices), landmarks (ARKit vertex indices and barycentric points
on S), and how the non-skin vertices follow the skin. No geometry: the avatar brings its mesh."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.landmarks import template_landmarks
from softdeca_train.landmarks.definition import load_definition
from softdeca_train.lhm.model import JAW as LHM_JAW
from softdeca_train.template import Template
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import region_labels

CRANIUM, JAW = 0, 1  # non-skin bone labels (the layered head model's convention)


@dataclass(frozen=True)
class LandmarkSet:
    """Landmark k: ARKit face-mesh vertex `arkit_vertex[k]`, and on the avatar the point
    sum_j bary[k, j] * skin_vertex[skin_triangles[triangle[k], j]]."""

    names: tuple[str, ...]
    regions: tuple[str, ...]
    arkit_vertex: np.ndarray  # (K,) int
    triangle: np.ndarray  # (K,) int, rows of the skin triangulation
    bary: np.ndarray  # (K, 3) float
    arkit_vertex_count: int

    def __len__(self) -> int:
        return len(self.triangle)

    def evaluate(self, skin: np.ndarray, skin_triangles: np.ndarray) -> np.ndarray:
        """Landmark positions (K, 3) on skin vertices (Vs, 3)."""
        corners = skin_triangles[self.triangle]
        return np.einsum("kj,kjc->kc", self.bary, np.asarray(skin)[corners])


@dataclass(frozen=True)
class TemplateDefinition:
    """Sizes and index data of the template topology that a bundle is trained on."""

    name: str
    head_vertices: int
    skin_triangles: np.ndarray  # (F, 3) int32, indices < skin_vertices
    skin_vertices: int
    landmarks: LandmarkSet
    non_skin_bones: np.ndarray  # (head_vertices - skin_vertices,) uint8: CRANIUM or JAW
    jaw_anchors: np.ndarray  # skin vertex indices whose rigid motion the JAW vertices follow
    blendshapes: tuple[str, ...] = ARKIT_BLENDSHAPES
    # (skin_vertices, 3) S at rest, metres: where the vertex stage's smoothing tables come
    # from (models/smoothing.py); None (a bundle read back) builds no smoothing
    skin_rest: np.ndarray | None = None
    # (skin_vertices,) region index of every skin vertex (template/regions.py): where the residual
    # stage reads each region's parameters; None (a bundle read back) builds no residual stage
    skin_regions: np.ndarray | None = None

    def __post_init__(self) -> None:
        t = self.skin_triangles
        if t.ndim != 2 or t.shape[1] != 3 or t.min() < 0 or t.max() >= self.skin_vertices:
            raise ValueError("skin triangles must be (F, 3) indices below skin_vertices")
        if len(np.unique(t)) != self.skin_vertices:
            raise ValueError("every skin vertex must belong to a skin triangle")
        if self.non_skin_bones.shape != (self.head_vertices - self.skin_vertices,):
            raise ValueError("non_skin_bones needs one label per non-skin vertex")
        if not np.isin(self.non_skin_bones, (CRANIUM, JAW)).all():
            raise ValueError("non_skin_bones holds CRANIUM (0) or JAW (1)")
        a = self.jaw_anchors
        if len(a) and (a.min() < 0 or a.max() >= self.skin_vertices):
            raise ValueError("jaw anchors must be skin vertex indices")
        if (self.non_skin_bones == JAW).any() and len(a) < 3:
            raise ValueError("JAW vertices need at least 3 jaw anchors")
        lm = self.landmarks
        if lm.triangle.max() >= len(t) or lm.arkit_vertex.max() >= lm.arkit_vertex_count:
            raise ValueError("landmark indices out of range")
        r = self.skin_rest
        if r is not None and (r.shape != (self.skin_vertices, 3) or not np.isfinite(r).all()):
            raise ValueError("skin_rest must be finite (skin_vertices, 3) positions")
        g = self.skin_regions
        if g is not None and (g.shape != (self.skin_vertices,) or g.min() < 0):
            raise ValueError("skin_regions must be one non-negative region index per skin vertex")
        if self.blendshapes != ARKIT_BLENDSHAPES:
            raise ValueError("bundles use the canonical ARKit blendshape order")

    @property
    def n_faces(self) -> int:
        return len(self.skin_triangles)


def from_template(template: object | None = None) -> TemplateDefinition:
    """The definition of the ICT-based template: S, the 149 landmarks registered to S, and the
    bone labels of the layered head model (JAW where jawOpen moves a vertex like the teeth)."""
    # the head model's fit needs the compiled softdeca_native; a bundle's definition does not
    from softdeca_train.lhm.fit import bone_labels

    t = template if isinstance(template, Template) else Template.load()
    definition = load_definition()
    lms = template_landmarks(t)
    bones = bone_labels(t, t.neutral)
    return TemplateDefinition(
        name="ict-facekit-s",
        head_vertices=t.n_vertices,
        skin_triangles=np.ascontiguousarray(t.skin_triangles, dtype=np.int32),
        skin_vertices=N_SKIN,
        landmarks=LandmarkSet(
            names=lms.names,
            regions=lms.regions,
            arkit_vertex=np.asarray(definition.vertices, dtype=np.int64),
            triangle=np.asarray(lms.triangle, dtype=np.int64),
            bary=np.asarray(lms.bary, dtype=np.float64),
            arkit_vertex_count=1220,
        ),
        non_skin_bones=np.where(bones[N_SKIN:] == LHM_JAW, JAW, CRANIUM).astype(np.uint8),
        jaw_anchors=np.nonzero(bones[:N_SKIN] == LHM_JAW)[0].astype(np.int64),
        skin_rest=np.asarray(t.neutral[:N_SKIN], dtype=np.float64),
        skin_regions=region_labels(t).astype(np.int64),
    )
