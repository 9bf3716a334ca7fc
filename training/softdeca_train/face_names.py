"""ARKit's blendshape names and the Live Link Face values, read from their one definition
plugin/data/face_names.json (the same file the C++ library embeds at build time)."""

from __future__ import annotations

import json

from softdeca_train.paths import REPO_ROOT

DEFINITION = REPO_ROOT / "plugin" / "data" / "face_names.json"


def _load() -> tuple[tuple[str, ...], tuple[str, ...]]:
    data = json.loads(DEFINITION.read_text())
    if data.get("format") != "softdeca-face-names":
        raise ValueError(f"{DEFINITION}: not a softdeca-face-names file")
    arkit = tuple(data["arkit_blendshapes"])
    llf = tuple(data["livelinkface_values"])
    if len(arkit) != 52 or len(set(arkit)) != 52:
        raise ValueError(f"{DEFINITION}: arkit_blendshapes must be 52 distinct names")
    if len(llf) != 61 or {n[0].lower() + n[1:] for n in llf[:52]} != set(arkit):
        raise ValueError(f"{DEFINITION}: livelinkface_values: the 52 ARKit names, then 9 angles")
    return arkit, llf


# ARKIT_BLENDSHAPES: the canonical order of every interface (alphabetical, as ARKit's
# ARFaceAnchor.BlendShapeLocation). LIVELINKFACE_VALUES: the app's 61 values in its packet order.
ARKIT_BLENDSHAPES, LIVELINKFACE_VALUES = _load()
