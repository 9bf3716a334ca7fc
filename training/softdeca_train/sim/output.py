"""`simulate`'s files, in `softdeca replay`'s format (docs/runtime.md): neutral.obj (template
topology, whole head), one PC2 point cache per sequence (linear.pc2, physics.pc2) for
Blender's Mesh Cache modifier, and optionally an OBJ sequence (obj/<name>_<frame>.obj) for
Unity, which imports OBJ but not point caches."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from softdeca_train.mesh_files import write_obj, write_pc2


def write_sequences(
    out: Path,
    neutral: np.ndarray,
    triangles: np.ndarray,
    sequences: dict[str, list[np.ndarray]],
    obj_every: int = 0,
) -> dict[str, str]:
    """neutral.obj, <name>.pc2 per sequence, and every obj_every-th frame as OBJ; returns the
    point caches written, by name."""
    write_obj(out / "neutral.obj", neutral, triangles)
    caches = {}
    for name, frames in sequences.items():
        caches[name] = str(write_pc2(out / f"{name}.pc2", frames))
        if obj_every > 0:
            for f in range(0, len(frames), obj_every):
                write_obj(out / "obj" / f"{name}_{f:05d}.obj", frames[f], triangles)
    return caches
