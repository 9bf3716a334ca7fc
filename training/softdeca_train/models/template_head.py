"""The template head a bundle carries for fitting users' own avatars (docs/bundle.md,
"Template head"): the template's neutral head, its 52 ARKit shapes over the skin S and its
identity modes over S (each scaled by its standard deviation: an identity is the neutral plus
h . modes with h about N(0, 1)).

A fit registers this skin to an avatar's face: the shapes are the descriptors that any ARKit rig
shares with the template (a vertex's response to the 52 shapes) and give an avatar the shapes
its rig lacks. The neutral is float32 (metres); the shapes are float16 deltas (about 10 um of
rounding on centimetre-sized motion), and so are the modes. With the modes a fit first finds
the identity of the template's space closest to the avatar: the head it starts the
registration from and reads the identity code off."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from softdeca_train.template.components import N_SKIN

TEMPLATE_HEAD_FILE = "template_head.bin"
N_SHAPES = 52


@dataclass(frozen=True)
class TemplateHead:
    neutral: np.ndarray  # (head_vertices, 3) metres
    shapes: np.ndarray  # (52, skin_vertices, 3) deltas from the neutral
    identity_modes: np.ndarray  # (K, skin_vertices, 3), K >= 0

    def __post_init__(self) -> None:
        if self.neutral.ndim != 2 or self.neutral.shape[1] != 3:
            raise ValueError("the template head's neutral must be (head_vertices, 3)")
        s = self.shapes
        if (
            s.ndim != 3
            or s.shape[0] != N_SHAPES
            or s.shape[2] != 3
            or s.shape[1] > len(self.neutral)
        ):
            raise ValueError("the template head's shapes must be (52, skin_vertices, 3)")
        m = self.identity_modes
        if m.ndim != 3 or m.shape[1:] != s.shape[1:]:
            raise ValueError("the template head's identity modes must be (K, skin_vertices, 3)")
        if not (np.isfinite(self.neutral).all() and np.isfinite(s).all() and np.isfinite(m).all()):
            raise ValueError("the template head holds a non-finite value")


def template_head_of(
    neutral: np.ndarray,
    head_deltas: np.ndarray,
    skin_vertices: int,
    identity_modes: np.ndarray | None = None,
) -> TemplateHead:
    """From a head's neutral, its 52 ARKit shapes over the whole head (52, Vh, 3) and its
    identity modes over the whole head (K, Vh, 3; None: none)."""
    modes = np.zeros((0, skin_vertices, 3)) if identity_modes is None else identity_modes
    return TemplateHead(
        np.asarray(neutral, np.float32),
        np.asarray(head_deltas[:, :skin_vertices], np.float32),
        np.asarray(modes[:, :skin_vertices], np.float32),
    )


def template_head_file(head: TemplateHead) -> tuple[bytes, dict[str, Any]]:
    """The bytes of template_head.bin and the manifest's `template_head` entry (no sha256)."""
    data = (
        np.ascontiguousarray(head.neutral, "<f4").tobytes()
        + np.ascontiguousarray(head.shapes, "<f2").tobytes()
        + np.ascontiguousarray(head.identity_modes, "<f2").tobytes()
    )
    entry = {
        "file": TEMPLATE_HEAD_FILE,
        "neutral": {"dtype": "float32", "shape": list(head.neutral.shape)},
        "shapes": {"dtype": "float16", "shape": list(head.shapes.shape)},
        "identity_modes": {"dtype": "float16", "shape": list(head.identity_modes.shape)},
    }
    return data, entry


def read_template_head(entry: dict[str, Any], data: bytes) -> TemplateHead:
    vh = int(entry["neutral"]["shape"][0])
    vs = int(entry["shapes"]["shape"][1])
    k = int(entry["identity_modes"]["shape"][0])
    size = vh * 3 * 4 + N_SHAPES * vs * 3 * 2 + k * vs * 3 * 2
    if len(data) != size:
        raise ValueError(f"{TEMPLATE_HEAD_FILE}: {len(data)} bytes, its manifest says {size}")
    neutral = np.frombuffer(data, "<f4", vh * 3).reshape(vh, 3)
    shapes = np.frombuffer(data, "<f2", N_SHAPES * vs * 3, offset=vh * 12).reshape(N_SHAPES, vs, 3)
    modes = np.frombuffer(data, "<f2", offset=vh * 12 + N_SHAPES * vs * 6).reshape(k, vs, 3)
    return TemplateHead(
        neutral.astype(np.float32), shapes.astype(np.float32), modes.astype(np.float32)
    )


def template_head_from(template: Any) -> TemplateHead:
    """The ICT template's head (template.model.Template): its neutral and ARKit shapes."""
    eye = np.eye(N_SHAPES)
    deltas = np.stack([template.blend(eye[i]) - template.neutral for i in range(N_SHAPES)])
    return template_head_of(template.neutral, deltas, N_SKIN, template.identity_modes)
