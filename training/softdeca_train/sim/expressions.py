"""The stress suite's expression library: each ARKit shape alone at 1.0 and extreme
combinations where the lips, the jaw and the teeth meet (ARKit weights, canonical order)."""

from __future__ import annotations

import numpy as np

from softdeca_train.template.arkit import ARKIT_BLENDSHAPES


def _both(name: str, w: float) -> dict[str, float]:
    return {f"{name}Left": w, f"{name}Right": w}


# A real take's strong snarl on which the contact step once moved lip points 349 mm.
SNARL: dict[str, float] = {
    **_both("noseSneer", 0.8),
    **_both("mouthUpperUp", 0.7),
    **_both("mouthSmile", 0.55),
    **_both("mouthLowerDown", 0.5),
    **_both("browDown", 0.8),
    "jawOpen": 0.4,
}

COMBINATIONS: dict[str, dict[str, float]] = {
    "snarl": SNARL,
    "snarl_full": {
        **_both("noseSneer", 1),
        **_both("mouthUpperUp", 1),
        **_both("mouthSmile", 0.8),
        **_both("mouthLowerDown", 1),
        **_both("browDown", 1),
        "jawOpen": 0.6,
    },
    "scream": {
        "jawOpen": 1,
        **_both("mouthStretch", 1),
        "browInnerUp": 0.8,
        **_both("eyeWide", 0.6),
    },
    "pucker_jaw_open": {"mouthPucker": 1, "jawOpen": 0.4},
    "funnel_jaw_open": {"mouthFunnel": 1, "jawOpen": 0.5},
    "roll_lips": {"mouthRollLower": 1, "mouthRollUpper": 1},
    "roll_lips_jaw_open": {"mouthRollLower": 0.8, "mouthRollUpper": 0.8, "jawOpen": 0.3},
    "jaw_left_open": {"jawLeft": 1, "jawOpen": 0.5},
    "jaw_right_open": {"jawRight": 1, "jawOpen": 0.5},
    "jaw_forward_open": {"jawForward": 1, "jawOpen": 0.5},
    "cheek_puff": {"cheekPuff": 1, **_both("mouthPress", 0.5)},
    "tongue_out": {"tongueOut": 1, "jawOpen": 0.5},
    "smile_jaw_open": {**_both("mouthSmile", 1), "jawOpen": 0.6},
    "bared_teeth": {**_both("mouthUpperUp", 1), **_both("mouthLowerDown", 1)},
    "sneer_left": {"noseSneerLeft": 1, "mouthUpperUpLeft": 1, "mouthSmileLeft": 0.5},
    "sneer_right": {"noseSneerRight": 1, "mouthUpperUpRight": 1, "mouthSmileRight": 0.5},
    "disgust_asymmetric": {
        "noseSneerLeft": 1,
        "mouthUpperUpLeft": 0.8,
        "mouthFrownRight": 0.6,
        "browDownLeft": 1,
        "jawOpen": 0.2,
    },
    "mouth_close_jaw_open": {"jawOpen": 0.6, "mouthClose": 0.6},
    "press_shrug": {**_both("mouthPress", 1), "mouthShrugLower": 1, "mouthShrugUpper": 1},
    "frown_stretch": {**_both("mouthFrown", 1), **_both("mouthStretch", 1)},
    "mouth_left_open": {"mouthLeft": 1, "jawOpen": 0.3},
    "mouth_right_open": {"mouthRight": 1, "jawOpen": 0.3},
    "smile_dimple_squint": {
        **_both("mouthSmile", 1),
        **_both("mouthDimple", 1),
        **_both("cheekSquint", 1),
    },
    "surprise": {
        "jawOpen": 0.7,
        "browInnerUp": 1,
        **_both("browOuterUp", 1),
        **_both("eyeWide", 1),
        "mouthFunnel": 0.3,
    },
    "all_mouth_half": {
        **{n: 0.5 for n in ARKIT_BLENDSHAPES if n.startswith("mouth")},
        "jawOpen": 0.5,
    },
}


def weights_of(shapes: dict[str, float]) -> np.ndarray:
    """(52,) ARKit weights from name -> weight."""
    w = np.zeros(len(ARKIT_BLENDSHAPES), np.float32)
    for name, value in shapes.items():
        w[ARKIT_BLENDSHAPES.index(name)] = value
    return w


def single_shapes() -> dict[str, np.ndarray]:
    return {f"{n}=1": weights_of({n: 1.0}) for n in ARKIT_BLENDSHAPES}


def combinations() -> dict[str, np.ndarray]:
    return {name: weights_of(shapes) for name, shapes in COMBINATIONS.items()}


def all_expressions() -> dict[str, np.ndarray]:
    return single_shapes() | combinations()
