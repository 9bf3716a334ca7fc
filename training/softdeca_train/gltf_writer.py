"""glTF 2.0 files built accessor by accessor, for the import's tests: the test avatars written
as exporters write them (sample_avatars/gltf_families.py) and the hostile corpus
(host/hostile_avatars.py), whose files are this writer's output edited to attack a reader.
The first buffer is the binary chunk of a .glb, or a file beside a .gltf."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np

FLOAT, UINT16, UINT32 = 5126, 5123, 5125


class GltfWriter:
    """A glTF 2.0 document and its first buffer."""

    def __init__(self) -> None:
        self.doc: dict = {
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [],
            "meshes": [],
            "buffers": [{"byteLength": 0}],
            "bufferViews": [],
            "accessors": [],
        }
        self.bin = bytearray()

    def view(self, data: bytes) -> int:
        """A buffer view of `data`, appended to the first buffer (4-byte aligned)."""
        offset = len(self.bin)
        self.bin += data + b"\0" * (-len(data) % 4)
        self.doc["buffers"][0]["byteLength"] = len(self.bin)
        return self.buffer_view(0, offset, len(data))

    def buffer_view(self, buffer: int, offset: int, length: int) -> int:
        view = {"buffer": buffer, "byteOffset": offset, "byteLength": length}
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def add_accessor(self, accessor: dict) -> int:
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def accessor(self, view: int, count: int, kind: str, component: int = FLOAT) -> int:
        return self.add_accessor(
            {"bufferView": view, "componentType": component, "count": count, "type": kind}
        )

    def vec3(self, values: np.ndarray, bounds: bool = False) -> int:
        """Float VEC3s; `bounds`: with min and max, which a POSITION must have."""
        v = np.ascontiguousarray(values, "<f4")
        index = self.accessor(self.view(v.tobytes()), len(v), "VEC3")
        if bounds:
            self.doc["accessors"][index] |= {
                "min": v.min(axis=0).tolist(),
                "max": v.max(axis=0).tolist(),
            }
        return index

    def zeros(self, count: int) -> int:
        """A VEC3 accessor with no buffer view: `count` zeros (glTF 2.0)."""
        return self.add_accessor({"componentType": FLOAT, "count": count, "type": "VEC3"})

    def sparse(self, values: np.ndarray) -> int:
        """Zeros but for the rows of `values` that are not: a sparse accessor over no view."""
        rows = np.flatnonzero(np.abs(values).max(axis=1) > 0)
        if not len(rows):
            return self.zeros(len(values))
        wide = len(values) > 0xFFFF
        index = np.ascontiguousarray(rows, "<u4" if wide else "<u2")
        moved = np.ascontiguousarray(values[rows], "<f4")
        sparse = {
            "count": len(rows),
            "indices": {
                "bufferView": self.view(index.tobytes()),
                "componentType": UINT32 if wide else UINT16,
            },
            "values": {"bufferView": self.view(moved.tobytes())},
        }
        return self.add_accessor(
            {"componentType": FLOAT, "count": len(values), "type": "VEC3", "sparse": sparse}
        )

    def indices(self, triangles: np.ndarray) -> int:
        t = np.ascontiguousarray(triangles, "<u4").ravel()
        return self.accessor(self.view(t.tobytes()), len(t), "SCALAR", UINT32)

    def material(self, name: str) -> int:
        self.doc.setdefault("materials", []).append({"name": name})
        return len(self.doc["materials"]) - 1

    def add_mesh(self, mesh: dict) -> int:
        """The mesh, used by a new node of the scene named as it is; returns its index."""
        self.doc["meshes"].append(mesh)
        self.doc["nodes"].append({"name": mesh["name"], "mesh": len(self.doc["meshes"]) - 1})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        return len(self.doc["meshes"]) - 1

    def glb(self) -> bytes:
        text = json.dumps(self.doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        binary = bytes(self.bin)
        total = 12 + 8 + len(text) + (8 + len(binary) if binary else 0)
        out = b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(text)) + b"JSON" + text
        if binary:
            out += struct.pack("<I", len(binary)) + b"BIN\0" + binary
        return out

    def gltf(self, uri: str) -> bytes:
        """The JSON text with the first buffer at `uri` (the caller writes self.bin there)."""
        self.doc["buffers"][0]["uri"] = uri
        return json.dumps(self.doc, separators=(",", ":")).encode()

    def write_glb(self, path: Path) -> Path:
        path.write_bytes(self.glb())
        return path
