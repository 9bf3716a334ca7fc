"""Mesh files every stage writes or reads: OBJ (vertices and triangles) and PC2 point caches
(Blender's Mesh Cache format, as plugin/cli/mesh_io.h writes it)."""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path

import numpy as np


def write_obj(
    path: Path,
    vertices: np.ndarray,
    triangles: np.ndarray | None = None,
    groups: Sequence[tuple[str, int]] | None = None,
) -> Path:
    """Vertices (and 0-based triangles) as OBJ text; fast enough for 52 shapes of 26,719.
    `groups`: the triangles' objects in their order, (name, triangle count) each, written as
    `o name` lines before their faces."""
    path.parent.mkdir(parents=True, exist_ok=True)
    v = np.asarray(vertices, dtype=np.float64)
    lines = ["v %.6f %.6f %.6f" % tuple(p) for p in v]  # noqa: UP031 - bulk formatting
    if triangles is not None:
        faces = ["f %d %d %d" % tuple(t) for t in np.asarray(triangles) + 1]  # noqa: UP031
        start = 0
        for name, count in groups or [("", len(faces))]:
            lines += [f"o {name}"] if name else []
            lines += faces[start : start + count]
            start += count
        if start != len(faces):
            raise ValueError(f"{path}: the groups hold {start} of {len(faces)} triangles")
    path.write_text("\n".join(lines) + "\n")
    return path


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    verts, tris, _ = read_obj_groups(path)
    return verts, tris


def read_obj_groups(path: Path) -> tuple[np.ndarray, np.ndarray, list[tuple[str, int]]]:
    """Vertices, triangles (polygons fanned) and the objects (`o`) or groups (`g`) the
    triangles fall in, (name, triangle count) in order; faces before any name fall in ""."""
    verts, tris, groups = [], [], [("", 0)]
    for line in Path(path).read_text().splitlines():
        if line.startswith("v "):
            verts.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            idx = [int(t.split("/")[0]) - 1 for t in line.split()[1:]]
            tris += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
            groups[-1] = (groups[-1][0], groups[-1][1] + len(idx) - 2)
        elif line.startswith(("o ", "g ")):
            groups.append((line[2:].strip(), 0))
    named = [g for g in groups if g[1] > 0]
    return np.array(verts), np.array(tris, dtype=np.int64).reshape(-1, 3), named


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
