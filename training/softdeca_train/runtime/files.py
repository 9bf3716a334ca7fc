"""Avatar folders of `softdeca replay` (plugin/cli/runtime_session.h):

<dir>/neutral.obj                   the avatar's neutral head in template topology
<dir>/blendshapes/<name>.obj        its 52 ARKit shapes as full meshes (missing: no motion)
<dir>/user_face/neutral.obj         optional ARKit face mesh (1,220 vertices) and its shapes:
<dir>/user_face/blendshapes/*.obj   blended with a take it stands in for a phone's tracking
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.landmarks import ArkitFace
from softdeca_train.mesh_files import write_obj
from softdeca_train.template import Template
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES


def write_rig(
    folder: Path,
    neutral: np.ndarray,
    deltas: np.ndarray,
    triangles: np.ndarray | None,
    progress: bool = False,
) -> None:
    """neutral.obj and blendshapes/<name>.obj (shapes that move nothing are left out)."""
    write_obj(folder / "neutral.obj", neutral, triangles)
    shapes = zip(ARKIT_BLENDSHAPES, deltas, strict=True)
    for name, d in tqdm(shapes, total=len(deltas), desc=folder.name, disable=not progress):
        if np.any(d != 0):
            write_obj(folder / "blendshapes" / f"{name}.obj", neutral + d)


def write_identity_avatar(seed: int, out: Path, ict: str | None = None) -> Path:
    """The avatar of the ICT identity `seed` (template blendshapes, mapped to ARKit's 52),
    with ARKit's reference face as the user_face rig."""
    t = Template.load(ict)
    neutral = t.identity_neutral(t.sample_identity(seed))
    deltas = (t.arkit_to_ict.T @ t.expression_deltas.reshape(len(t.expression_names), -1)).reshape(
        52, -1, 3
    )
    write_rig(out, neutral, deltas, t.triangles, progress=True)
    face = ArkitFace.load()
    write_rig(out / "user_face", face.neutral, face.deltas, face.triangles, progress=True)
    return out
