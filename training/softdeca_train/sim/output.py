"""`simulate`'s files, in `softdeca replay`'s format (docs/runtime.md): neutral.obj (template
topology, whole head), one PC2 point cache per sequence (linear.pc2, physics.pc2) for
Blender's Mesh Cache modifier, and optionally an OBJ sequence (obj/<name>_<frame>.obj) for
Unity, which imports OBJ but not point caches."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from softdeca_train.runtime.files import write_obj


def write_pc2(path: Path, frames: list[np.ndarray], sample_rate: float = 1.0) -> Path:
    """PC2: "POINTCACHE2\\0", version 1, point count, start frame 0, sample rate, frame
    count, then float32 xyz per point per frame (as plugin/cli/mesh_io.h writes it)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = np.stack([np.asarray(f, np.float32) for f in frames])
    header = struct.pack(
        "<12siiffi", b"POINTCACHE2\0", 1, data.shape[1], 0.0, sample_rate, len(data)
    )
    path.write_bytes(header + data.astype("<f4").tobytes())
    return path


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
