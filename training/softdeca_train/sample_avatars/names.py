"""Blendshape names as rigs spell them. Every style reads back to its ARKit shape under the
library's rule for rigs' names (softdeca_blendshape_find_index, docs/avatars.md)."""

from __future__ import annotations

import re

from softdeca_train.face_names import ARKIT_BLENDSHAPES

# Shapes whose Left/Right is a direction (the jaw or the mouth moves to the subject's left), not
# a side of the face: rigs keep their names whole where they shorten the sides' to _L and _R.
DIRECTIONS = ("jawLeft", "jawRight", "mouthLeft", "mouthRight")
_WORD = re.compile(r"[A-Z]?[a-z]+|[A-Z]+(?![a-z])|\d+")


def _side(name: str) -> tuple[str, str]:
    """(stem, "Left" / "Right" / "") of a side shape's name; directions keep their whole name."""
    if name not in DIRECTIONS:
        for side in ("Left", "Right"):
            if name.endswith(side):
                return name[: -len(side)], side
    return name, ""


def rig_name(canonical: str, style: str) -> str:
    """The name a rig of `style` (config.NAME_STYLES) gives the ARKit shape `canonical`:

    arkit      eyeBlinkLeft               namespace  blendShape1.eyeBlinkLeft
    prefix     AK_09_EyeBlinkLeft         suffix_LR  eyeBlink_L (jawLeft stays jawLeft)
    snake      eye_blink_l, jaw_left      pascal     EyeBlinkLeft
    cc         CC_Base_Body.Eye_Blink_L   daz        facs_bs_EyeBlinkLeft
    """
    index = ARKIT_BLENDSHAPES.index(canonical)
    pascal = canonical[0].upper() + canonical[1:]
    stem, side = _side(canonical)
    if style == "arkit":
        return canonical
    if style == "namespace":
        return f"blendShape1.{canonical}"
    if style == "prefix":
        return f"AK_{index + 1:02d}_{pascal}"
    if style == "suffix_LR":
        return f"{stem}_{side[0]}" if side else canonical
    if style == "snake":
        words = [w.lower() for w in _WORD.findall(stem)]
        return "_".join(words + ([side[0].lower()] if side else []))
    if style == "pascal":
        return pascal
    if style == "cc":  # Character Creator's mesh before the name, its words capitalised
        words = [w.capitalize() for w in _WORD.findall(stem)]
        return "CC_Base_Body." + "_".join(words + ([side[0]] if side else []))
    if style == "daz":
        return f"facs_bs_{pascal}"
    raise ValueError(f"unknown name style {style!r}")
