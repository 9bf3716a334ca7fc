"""The canonical frame (plugin/src/stream/frame.h): metres, ARKit's face-anchor frame, 52
weights in canonical ARKit order (softdeca_train.template.arkit.ARKIT_BLENDSHAPES)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

BLENDSHAPE_COUNT = len(ARKIT_BLENDSHAPES)
MAX_LANDMARKS = 150
ARKIT_VERTEX_COUNT = 1220


class Tracking(IntEnum):
    LOST = 0
    TRACKED = 1
    LIMITED = 2


def _identity() -> np.ndarray:
    return np.array([0.0, 0.0, 0.0, 1.0], dtype=np.float32)


@dataclass
class Pose:
    """Position in metres and rotation as a unit quaternion (x, y, z, w), float32."""

    position: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.float32))
    rotation: np.ndarray = field(default_factory=_identity)


@dataclass
class Frame:
    capture_time: float = 0.0  # seconds, sender's clock
    send_time: float = 0.0
    receive_time: float = 0.0
    session_id: int = 0
    sequence: int = 0
    has_sequence: bool = False
    tracking: Tracking = Tracking.TRACKED
    weights: np.ndarray = field(
        default_factory=lambda: np.zeros(BLENDSHAPE_COUNT, dtype=np.float32)
    )
    head: Pose | None = None  # face anchor pose, ARKit world frame
    left_eye: Pose | None = None  # eye poses relative to the face anchor; both or neither
    right_eye: Pose | None = None
    profile_id: int = 0
    landmarks: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.float32))
