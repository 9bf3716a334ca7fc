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

from softdeca_train.mesh_files import write_obj
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
