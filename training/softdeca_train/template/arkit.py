"""ARKit's 52 blendshapes in canonical order, and their map onto ICT-FaceKit's 53 shapes."""

from __future__ import annotations

import numpy as np

from softdeca_train.face_names import ARKIT_BLENDSHAPES

# The canonical order of every interface of the product (plugin/data/face_names.json).
__all__ = ["ARKIT_BLENDSHAPES", "arkit_to_ict_matrix"]


def arkit_to_ict_matrix(ict_names: list[str], left_suffix: str) -> np.ndarray:
    """(53, 52) matrix M with ict_weights = M @ arkit_weights.

    `left_suffix` is the ICT suffix ("_L" or "_R") whose shapes move the subject's own left,
    determined from the geometry by the template (never assumed). browInnerUp and cheekPuff drive
    both ICT halves; tongueOut has no ICT shape and maps to nothing.
    """
    right_suffix = "_R" if left_suffix == "_L" else "_L"
    index = {n: i for i, n in enumerate(ict_names)}
    m = np.zeros((len(ict_names), len(ARKIT_BLENDSHAPES)))
    for j, name in enumerate(ARKIT_BLENDSHAPES):
        if name == "tongueOut":
            continue
        if name in index:  # e.g. jawLeft, mouthRight: whole-face shapes, not _L/_R halves
            targets = [name]
        elif name in ("browInnerUp", "cheekPuff"):
            targets = [name + left_suffix, name + right_suffix]
        elif name.endswith("Left"):
            targets = [name[:-4] + left_suffix]
        elif name.endswith("Right"):
            targets = [name[:-5] + right_suffix]
        else:
            targets = [name]
        for t in targets:
            if t not in index:
                raise KeyError(f"ICT-FaceKit has no shape {t} for ARKit {name}")
            m[index[t], j] = 1.0
    return m
