"""What real heads carry besides their skin, in the template's frame (metres, +Y up, +Z out of
the face):

- hair cards: strips of quads hovering a few millimetres off the scalp, from behind the crown
  down over the forehead, in two layers; separate sheets no shape moves;
- eyebrow fins: strips standing off the skin along the brows, fused to it (each fin's foot is
  skin vertices), their tips moving with the skin they stand on;
- a bust: the neck continued into shoulders and a chest, one surface with the skin, no limbs.

Each is built on the avatar's skin as it is (ICT's or remeshed), so a decimated head gets cards
and fins at its own resolution."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.face_names import ARKIT_BLENDSHAPES
from softdeca_train.landmarks.topology import vertex_normals

CARD_COLUMNS = (-0.065, 0.065)  # m, the span of the cards' centres across the head
CARD_WIDTH = 0.012  # m
CARD_SEGMENTS = 12  # quads along a card
CARD_LAYERS = (0.003, 0.007)  # m off the scalp
CARD_ANGLES = (115.0, 35.0)  # degrees above forward, seen from the eyes' centre: crown to brow
CARD_ABOVE_BROWS = 0.012  # m: the cards end this far above the brows
FIN_HEIGHT = 0.002  # m the eyebrow fins stand off the skin
FIN_SHARE = 0.4  # skin vertices the brow shapes move this share of their largest carry fins
BROW_SHAPES = ("browDownLeft", "browDownRight", "browInnerUp")
EYE_SHAPES = ("eyeBlinkLeft", "eyeBlinkRight")


@dataclass(frozen=True)
class Sheet:
    vertices: np.ndarray  # (n, 3)
    triangles: np.ndarray  # (m, 3) into these vertices
    foot: np.ndarray  # (n,) the skin vertex each vertex hovers over


def _moved(deltas: np.ndarray, names: tuple[str, ...], share: float) -> np.ndarray:
    """(n,) bool: the vertices one of the shapes moves by `share` of its largest."""
    out = np.zeros(deltas.shape[1], bool)
    for name in names:
        size = np.linalg.norm(deltas[ARKIT_BLENDSHAPES.index(name)], axis=1)
        if size.max() > 0:
            out |= size > share * size.max()
    return out


def _strip(k: int) -> np.ndarray:
    """Triangles of the quads between two rows of k vertices (0..k-1 and k..2k-1)."""
    a = np.arange(k - 1)
    return np.concatenate([np.stack([a, a + 1, a + k], 1), np.stack([a + 1, a + k + 1, a + k], 1)])


def hair_cards(
    skin: np.ndarray, triangles: np.ndarray, deltas: np.ndarray, count: int, seed: int
) -> Sheet:
    """`count` cards in each layer over the scalp and the forehead of the skin (its vertices,
    triangles and shapes' deltas), each row's points the skin's support points in its
    direction, lifted along the normal there."""
    normals = vertex_normals(skin, triangles)
    brows = skin[_moved(deltas, BROW_SHAPES, 0.3)]
    eyes = skin[_moved(deltas, EYE_SHAPES, 0.3)]
    centre = np.array([0.0, eyes[:, 1].mean(), eyes[:, 2].mean() - 0.06])
    lowest = brows[:, 1].max() + CARD_ABOVE_BROWS
    rng = np.random.default_rng([seed, 3])
    angles = np.radians(np.linspace(*CARD_ANGLES, CARD_SEGMENTS + 1))
    directions = np.stack([np.zeros_like(angles), np.sin(angles), np.cos(angles)], 1)
    vertices, tris, feet = [], [], []
    for lift in CARD_LAYERS:
        for x in np.linspace(*CARD_COLUMNS, count) + rng.uniform(-0.004, 0.004, count):
            rows, supports = [], []
            for side in (-0.5, 0.5):
                near = np.flatnonzero(np.abs(skin[:, 0] - (x + side * CARD_WIDTH)) < 0.006)
                support = near[np.argmax((skin[near] - centre) @ directions.T, axis=0)]
                rows.append(skin[support] + (lift + rng.uniform(0, 0.001)) * normals[support])
                supports.append(support)
            keep = (rows[0][:, 1] > lowest) & (rows[1][:, 1] > lowest)
            if keep.sum() < 2:
                continue
            tris.append(_strip(int(keep.sum())) + sum(len(v) for v in vertices))
            vertices.append(np.concatenate([rows[0][keep], rows[1][keep]]))
            feet.append(np.concatenate([supports[0][keep], supports[1][keep]]))
    if not vertices:
        raise ValueError("hair cards: the skin has no scalp above its brows")
    return Sheet(
        np.concatenate(vertices), np.concatenate(tris).astype(np.int64), np.concatenate(feet)
    )


@dataclass(frozen=True)
class Fins:
    foot: np.ndarray  # (n,) skin vertex each fin tip stands on
    tips: np.ndarray  # (n, 3) the tips' positions
    triangles: np.ndarray  # (m, 3): an index < len(skin) a skin vertex, len(skin) + k tip k


def eyebrow_fins(skin: np.ndarray, triangles: np.ndarray, deltas: np.ndarray) -> Fins:
    """A fin on every skin edge between two vertices the brow shapes move clearly: the edge, and
    its two ends lifted FIN_HEIGHT along their normals (a tip shared by every fin at a vertex)."""
    band = _moved(deltas, BROW_SHAPES, FIN_SHARE)
    t = np.asarray(triangles, np.int64)
    edges = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    edges = edges[band[edges].all(axis=1)]
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    if len(edges) == 0:
        raise ValueError("eyebrow fins: no brow shape moves the skin")
    foot = np.unique(edges)
    tip = np.full(len(skin), -1, np.int64)
    tip[foot] = len(skin) + np.arange(len(foot))
    a, b = edges[:, 0], edges[:, 1]
    fins = np.concatenate([np.stack([a, b, tip[b]], 1), np.stack([a, tip[b], tip[a]], 1)])
    tips = skin[foot] + FIN_HEIGHT * vertex_normals(skin, t)[foot]
    return Fins(foot, tips, fins)
