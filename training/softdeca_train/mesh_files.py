"""Mesh files every stage writes or reads: OBJ (vertices and triangles) and PC2 point caches
(Blender's Mesh Cache format, as plugin/cli/mesh_io.h writes it)."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np


def write_obj(path: Path, vertices: np.ndarray, triangles: np.ndarray | None = None) -> Path:
    """Vertices (and 0-based triangles) as OBJ text; fast enough for 52 shapes of 26,719."""
    path.parent.mkdir(parents=True, exist_ok=True)
    v = np.asarray(vertices, dtype=np.float64)
    lines = ["v %.6f %.6f %.6f" % tuple(p) for p in v]  # noqa: UP031 - bulk formatting
    if triangles is not None:
        lines += ["f %d %d %d" % tuple(t) for t in np.asarray(triangles) + 1]  # noqa: UP031
    path.write_text("\n".join(lines) + "\n")
    return path


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    verts, tris = [], []
    for line in Path(path).read_text().splitlines():
        if line.startswith("v "):
            verts.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            idx = [int(t.split("/")[0]) - 1 for t in line.split()[1:]]
            tris += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
    return np.array(verts), np.array(tris, dtype=np.int64).reshape(-1, 3)


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


def read_pc2(path: Path) -> np.ndarray:
    """A PC2 point cache as (frames, points, 3) float32."""
    data = Path(path).read_bytes()
    sig, _version, points, _start, _rate, frames = struct.unpack("<12siiffi", data[:32])
    if sig != b"POINTCACHE2\0":
        raise ValueError(f"{path}: not a PC2 point cache")
    return np.frombuffer(data, dtype="<f4", offset=32, count=frames * points * 3).reshape(
        frames, points, 3
    )
