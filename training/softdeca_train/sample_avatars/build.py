"""make_avatar: a test avatar from its AvatarConfig, in memory.

The parts of an avatar from an ICT head:
- the whole-head layout (no remesh, no separate eyes and teeth): ICT's head as it is, every
  component in one object: the template topology the runtime evaluates (`softdeca replay`);
- remeshed: the skin S remeshed (remesh.py), its shapes carried by barycentric interpolation at
  each new vertex's point of the original surface;
- separate eyes and teeth: the skin (ICT's or remeshed), then the eyeballs and the upper and
  lower teeth in ICT's topology, each its own object and connected component;
- a body (body.py) joined to the skin's neck boundary, after everything else.
The shapes are ICT's 53 mapped to ARKit's 52 (Template.arkit_to_ict, as Template.blend); a
shape that moves nothing (ICT has no tongueOut) is absent. Then the unit, the axes, the
mirror and the vertex order change, in the order the truth states them."""

from __future__ import annotations

import json
from dataclasses import dataclass, replace

import numpy as np

from softdeca_train.face_names import ARKIT_BLENDSHAPES
from softdeca_train.landmarks import ArkitFace
from softdeca_train.sample_avatars.body import synthetic_body, synthetic_bust
from softdeca_train.sample_avatars.config import AvatarConfig
from softdeca_train.sample_avatars.extras import eyebrow_fins, hair_cards
from softdeca_train.sample_avatars.mesh import PARTS, AvatarMesh, AvatarTruth
from softdeca_train.sample_avatars.names import _side, rig_name
from softdeca_train.sample_avatars.remesh import SurfacePoints, remesh
from softdeca_train.template import Template
from softdeca_train.template.components import COMPONENTS, SKIN_COMPONENTS
from softdeca_train.template.identities import identity_coefficients

# ICT components written as their own objects with separate_eyes_teeth, and the part each is.
SEPARATE = {
    "eyeball_left": "eyes",
    "eyeball_right": "eyes",
    "teeth_upper": "teeth",
    "teeth_lower": "teeth",
}
# ICT components in the skin's object with eyes_teeth_tongue: the eyeballs, the teeth, the tongue.
IN_HEAD = (*SEPARATE, "gums_tongue")
Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # +Y to +Z, +Z to -Y


@dataclass(frozen=True)
class Source:
    """The mesh an avatar is made from, in the template's frame (metres)."""

    name: str  # "ict" or "arkit"
    vertices: np.ndarray  # (V, 3) the identity's neutral
    deltas: np.ndarray  # (52, V, 3) float64, canonical ARKit order
    triangles: np.ndarray  # (T, 3) int64
    part: np.ndarray  # (V,) int8, index into PARTS
    identity: str
    coefficients: np.ndarray  # (100,) or (0,)

    @property
    def moving(self) -> np.ndarray:
        return np.abs(self.deltas).reshape(52, -1).max(axis=1) > 0

    def rows_within(self, vertices: np.ndarray) -> np.ndarray:
        """The triangles whose three corners are all in `vertices`."""
        inside = np.zeros(len(self.vertices), bool)
        inside[vertices] = True
        return np.flatnonzero(inside[self.triangles].all(axis=1))


@dataclass(frozen=True)
class Piece:
    """One object of the avatar before the changes of convention (template frame)."""

    name: str
    vertices: np.ndarray  # (n, 3)
    deltas: np.ndarray  # (52, n, 3)
    triangles: np.ndarray  # (m, 3) into this piece's vertices
    points: SurfacePoints  # each vertex on the source (triangle -1: none)
    source_vertex: np.ndarray  # (n,)
    part: np.ndarray  # (n,) int8


def ict_source(template: Template, identity: str) -> Source:
    h = identity_coefficients(template, identity)
    n = len(template.expression_names)
    deltas = template.arkit_to_ict.T @ template.expression_deltas.reshape(n, -1)
    part = np.full(template.n_vertices, PARTS.index("inner"), np.int8)
    for c in template.components.values():
        if c.name in SKIN_COMPONENTS:
            part[c.slice] = PARTS.index("skin")
        elif c.name in SEPARATE:
            part[c.slice] = PARTS.index(SEPARATE[c.name])
    return Source(
        "ict",
        template.identity_neutral(h),
        deltas.reshape(52, -1, 3),
        template.triangles.astype(np.int64),
        part,
        identity,
        np.zeros(0) if h is None else np.asarray(h, dtype=np.float64),
    )


def arkit_source(face: ArkitFace) -> Source:
    deltas = np.where(face.present[:, None, None], face.deltas, 0.0)
    n = len(face.neutral)
    part = np.full(n, PARTS.index("skin"), np.int8)
    triangles = face.triangles.astype(np.int64)
    return Source(
        "arkit", face.neutral, deltas, triangles, part, "ARKit reference face", np.zeros(0)
    )


def subset_piece(source: Source, name: str, vertices: np.ndarray) -> Piece:
    """The source's vertices `vertices` (sorted) and the triangles among them, as they are."""
    rows = source.rows_within(vertices)
    local = np.full(len(source.vertices), -1, np.int64)
    local[vertices] = np.arange(len(vertices))
    # every vertex on one of its own triangles, at that corner
    triangle = np.full(len(source.vertices), -1, np.int64)
    corner = np.zeros(len(source.vertices), np.int64)
    for j in range(3):
        triangle[source.triangles[:, j]] = np.arange(len(source.triangles))
        corner[source.triangles[:, j]] = j
    points = SurfacePoints(triangle[vertices], np.eye(3)[corner[vertices]])
    return Piece(
        name,
        source.vertices[vertices],
        source.deltas[:, vertices],
        local[source.triangles[rows]],
        points,
        vertices.copy(),
        source.part[vertices],
    )


def remeshed_piece(
    source: Source, name: str, vertices: np.ndarray, target: int, style: str
) -> Piece:
    """The surface of the source's `vertices` remeshed to about `target` vertices."""
    rows = source.rows_within(vertices)
    r = remesh(source.vertices, source.triangles[rows], target, style)
    points = SurfacePoints(rows[r.points.triangle], r.points.bary)
    carried = points.evaluate(source.deltas.transpose(1, 0, 2), source.triangles)
    n = len(points.triangle)
    part = source.part[source.triangles[points.triangle, 0]]
    return Piece(
        name,
        points.evaluate(source.vertices, source.triangles),
        carried.transpose(1, 0, 2),
        r.triangles.astype(np.int64),
        points,
        np.full(n, -1, np.int64),
        part,
    )


def head_pieces(source: Source, config: AvatarConfig, progress: bool) -> list[Piece]:
    """The avatar's objects from the source, the skin first."""
    whole = source.name == "ict" and not (config.remesh or config.separate_eyes_teeth)
    if source.name == "arkit" or whole:  # one object: ARKit's face or ICT's whole head
        name, surface = ("head" if whole else "face"), np.arange(len(source.vertices))
    else:
        name, surface = "skin", np.flatnonzero(source.part == PARTS.index("skin"))
    if config.remesh:
        _say(progress, f"remeshing ({config.remesh_style}) to about {config.remesh} vertices")
        pieces = [remeshed_piece(source, name, surface, config.remesh, config.remesh_style)]
    else:
        pieces = [subset_piece(source, name, surface)]
    if config.separate_eyes_teeth:
        for c in COMPONENTS:
            if c.name in SEPARATE:
                pieces.append(subset_piece(source, c.name, np.arange(c.start, c.stop)))
    if config.eyes_teeth_tongue:
        # decimated in the skin's proportion, as a low-poly head's are
        ratio = (config.remesh or len(surface)) / len(surface)
        for c in COMPONENTS:
            if c.name not in IN_HEAD:
                continue
            inside = np.arange(c.start, c.stop)
            if config.remesh:
                target = max(60, round(ratio * len(inside)))
                pieces.append(remeshed_piece(source, c.name, inside, target, "adaptive"))
            else:
                pieces.append(subset_piece(source, c.name, inside))
    if config.eyebrows:
        pieces[0] = with_eyebrow_fins(pieces[0])
    if config.hair_cards:
        pieces.append(hair_piece(pieces[0], config))
    return pieces


def with_eyebrow_fins(skin: Piece) -> Piece:
    """The skin with fins along its brows (extras.py): their feet are its own vertices, their
    tips new vertices that move as the skin they stand on; the tips are hair."""
    rows = (skin.part[skin.triangles] == PARTS.index("skin")).all(axis=1)
    fins = eyebrow_fins(skin.vertices, skin.triangles[rows], skin.deltas)
    n = len(fins.foot)
    return Piece(
        skin.name,
        np.concatenate([skin.vertices, fins.tips]),
        np.concatenate([skin.deltas, skin.deltas[:, fins.foot]], axis=1),
        np.concatenate([skin.triangles, fins.triangles]),
        SurfacePoints(
            np.concatenate([skin.points.triangle, np.full(n, -1, np.int64)]),
            np.concatenate([skin.points.bary, np.zeros((n, 3))]),
        ),
        np.concatenate([skin.source_vertex, np.full(n, -1, np.int64)]),
        np.concatenate([skin.part, np.full(n, PARTS.index("hair"), np.int8)]),
    )


def hair_piece(skin: Piece, config: AvatarConfig) -> Piece:
    """Hair cards over the skin's scalp and forehead (extras.py), moved by no shape, or with
    hair_follows by the shapes of the skin they hover over."""
    rows = (skin.part[skin.triangles] == PARTS.index("skin")).all(axis=1)
    cards = hair_cards(
        skin.vertices, skin.triangles[rows], skin.deltas, config.hair_cards, config.variant_seed
    )
    piece = _unmoved("hair", cards.vertices, cards.triangles, "hair")
    if config.hair_follows:
        piece = replace(piece, deltas=skin.deltas[:, cards.foot])
    return piece


def _unmoved(name: str, vertices: np.ndarray, triangles: np.ndarray, part: str) -> Piece:
    """A piece on no source point that no shape moves."""
    n = len(vertices)
    return Piece(
        name,
        vertices,
        np.zeros((52, n, 3)),
        triangles,
        SurfacePoints(np.full(n, -1, np.int64), np.zeros((n, 3))),
        np.full(n, -1, np.int64),
        np.full(n, PARTS.index(part), np.int8),
    )


def _say(progress: bool, text: str) -> None:
    if progress:
        print(text, flush=True)


def body_piece(skin: Piece, n_vertices: int | None, offset: int) -> Piece:
    """The body (a bust when n_vertices is None) joined to the skin's neck boundary; the skin is
    the avatar's first object and the body starts at vertex `offset`, so its triangles' indices
    below 0 are the skin's."""
    rows = (skin.part[skin.triangles] == PARTS.index("skin")).all(axis=1)
    if n_vertices is None:
        body = synthetic_bust(skin.vertices, skin.triangles[rows])
    else:
        body = synthetic_body(skin.vertices, skin.triangles[rows], n_vertices)
    n_skin = len(skin.vertices)
    triangles = np.where(body.triangles < n_skin, body.triangles - offset, body.triangles - n_skin)
    return _unmoved("body", body.vertices, triangles, "body")


def assemble(pieces: list[Piece]) -> tuple[Piece, tuple[tuple[str, int], ...]]:
    """The pieces as one mesh, and its objects (name, triangle count) in triangle order."""
    offsets = np.cumsum([0] + [len(p.vertices) for p in pieces])[:-1]
    whole = Piece(
        "avatar",
        np.concatenate([p.vertices for p in pieces]),
        np.concatenate([p.deltas for p in pieces], axis=1),
        np.concatenate([p.triangles + o for p, o in zip(pieces, offsets, strict=True)]),
        SurfacePoints(
            np.concatenate([p.points.triangle for p in pieces]),
            np.concatenate([p.points.bary for p in pieces]),
        ),
        np.concatenate([p.source_vertex for p in pieces]),
        np.concatenate([p.part for p in pieces]),
    )
    return whole, tuple((p.name, len(p.triangles)) for p in pieces)


def resplit(whole: Piece, width: float) -> np.ndarray:
    """The side shapes split again from their symmetric sum by a linear ramp `width` metres
    wide across the face (x, the subject's left), as rigging tools split a symmetric shape
    into Left and Right: each side's shape then moves the other side a little too."""
    deltas = whole.deltas.copy()
    left = np.clip(0.5 + whole.vertices[:, 0] / width, 0.0, 1.0)[:, None]
    for k, name in enumerate(ARKIT_BLENDSHAPES):
        stem, side = _side(name)
        if side != "Left":
            continue
        r = ARKIT_BLENDSHAPES.index(stem + "Right")
        both = whole.deltas[k] + whole.deltas[r]
        deltas[k], deltas[r] = left * both, (1 - left) * both
    return deltas


def chosen_shapes(config: AvatarConfig, moving: np.ndarray) -> np.ndarray:
    """(52,) bool: the shapes the avatar has: those that move a vertex, without the dropped
    ones, and of those keep_shapes at random."""
    present = moving.copy()
    for name in config.drop:
        present[ARKIT_BLENDSHAPES.index(name)] = False
    if config.keep_shapes is not None:
        candidates = np.flatnonzero(present)
        if config.keep_shapes > len(candidates):
            raise ValueError(
                f"keep_shapes {config.keep_shapes}: the avatar has only {len(candidates)} shapes"
            )
        rng = np.random.default_rng([config.variant_seed, 1])
        present[:] = False
        present[rng.choice(candidates, config.keep_shapes, replace=False)] = True
    return present


def make_avatar(
    config: AvatarConfig | None = None,
    template: Template | None = None,
    face: ArkitFace | None = None,
    progress: bool = False,
) -> AvatarMesh:
    """The test avatar of `config` (default: AvatarConfig()). `template` and `face` spare
    loading ICT-FaceKit and ARKit's reference face again (from the cache otherwise)."""
    config = config or AvatarConfig()
    if config.arkit_face:
        source = arkit_source(face or ArkitFace.load())
    else:
        source = ict_source(template or Template.load(), config.identity)
    pieces = head_pieces(source, config, progress)
    if config.body or config.shoulders:
        offset = sum(len(p.vertices) for p in pieces)
        size = config.body_vertices if config.body else None
        pieces.append(body_piece(pieces[0], size, offset))
    whole, groups = assemble(pieces)
    if config.one_object:
        groups = (("head", len(whole.triangles)),)
    present = chosen_shapes(config, source.moving)
    deltas = whole.deltas if config.split_width is None else resplit(whole, config.split_width)
    deltas = np.where(present[:, None, None], deltas, 0.0)
    # the conventions: feet at 0 with a body, then mirror, axes and unit (AvatarTruth.linear)
    lift = np.array([0.0, -whole.vertices[:, 1].min() if config.body else 0.0, 0.0])
    rotation = Z_UP if config.up == "z" else np.eye(3)
    mirror = np.diag([-1.0 if config.mirror else 1.0, 1.0, 1.0])
    linear = rotation @ mirror / config.metres_per_unit
    n = len(whole.vertices)
    order = np.arange(n)
    if config.shuffle:
        order = np.random.default_rng([config.variant_seed, 2]).permutation(n)
    position = np.empty(n, np.int64)
    position[order] = np.arange(n)
    triangle = whole.points.triangle[order]
    corners = np.where(triangle[:, None] >= 0, source.triangles[np.maximum(triangle, 0)], -1)
    truth = AvatarTruth(
        source=source.name,
        triangle=triangle,
        bary=whole.points.bary[order],
        corners=corners,
        source_vertex=whole.source_vertex[order],
        part=whole.part[order],
        order=order,
        metres_per_unit=config.metres_per_unit,
        rotation=rotation.copy(),
        mirror=config.mirror,
        translation=linear @ lift,
        identity=source.identity,
        identity_coefficients=source.coefficients,
        present=present,
        names=tuple(
            rig_name(name, config.names) if present[i] else ""
            for i, name in enumerate(ARKIT_BLENDSHAPES)
        ),
        config=json.dumps(config.to_dict()),
    )
    return AvatarMesh(
        neutral=truth.to_avatar(whole.vertices[order]),
        triangles=position[whole.triangles].astype(np.int32),
        deltas=truth.to_avatar(deltas[:, order], direction=True),
        groups=groups,
        truth=truth,
    )
