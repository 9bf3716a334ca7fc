"""Test avatars written as glTF the way the largest sources of Unity avatars write them, to test
the import and the fit on what users bring (tests/python/test_avatar_gltf_families.py):

- `write_ready_player_me`: one mesh per part (head, eyes, teeth, ...), each with the 52 ARKit
  morph targets named in the mesh's `extras.targetNames`; a target that moves nothing is an
  accessor with no buffer view (zeros, as glTF 2.0 defines it), the others sparse accessors
  holding only the vertices they move.
- `write_vroid`: one face mesh of several primitives (a material each) over one vertex buffer,
  124 morph targets: VRoid's own `Fcl_*` expressions (mixes of the ARKit shapes) before the
  52 ARKit ones; then through gltfpack as glTF-Transform and gltfpack users ship it:
  `EXT_meshopt_compression` with a fallback buffer and `KHR_mesh_quantization`.

Positions are the avatar's own, in metres with +Y up as glTF defines them, so a fit of the
file and the avatar's truth (avatars/mesh.py) share one frame."""

from __future__ import annotations

import json
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np

from softdeca_train.avatars.mesh import PARTS, AvatarMesh
from softdeca_train.face_names import ARKIT_BLENDSHAPES

READY_PLAYER_ME_NAMES = {
    "skin": "Wolf3D_Head",
    "eyes": "Wolf3D_Eyes",
    "teeth": "Wolf3D_Teeth",
    "inner": "Wolf3D_Inner",
    "body": "Wolf3D_Body",
    "hair": "Wolf3D_Hair",
}
# VRoid's own expressions before the ARKit ones: name -> (ARKit shape, weight) mixes.
VROID_PRIMITIVES = 7
VROID_TARGETS = 124
FLOAT, UINT16, UINT32 = 5126, 5123, 5125


class GlbWriter:
    """A glTF 2.0 document and its binary chunk, built accessor by accessor."""

    def __init__(self) -> None:
        self.doc: dict = {
            "asset": {"version": "2.0", "generator": "softdeca_train test avatars"},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "buffers": [{"byteLength": 0}],
            "bufferViews": [],
            "accessors": [],
        }
        self.bin = bytearray()

    def _view(self, data: bytes) -> int:
        offset = len(self.bin)
        self.bin += data + b"\0" * (-len(data) % 4)
        self.doc["buffers"][0]["byteLength"] = len(self.bin)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(data)})
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, accessor: dict) -> int:
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def vec3(self, values: np.ndarray, bounds: bool = False) -> int:
        v = np.ascontiguousarray(values, "<f4")
        a = {"bufferView": self._view(v.tobytes()), "componentType": FLOAT, "count": len(v)}
        a["type"] = "VEC3"
        if bounds:  # POSITION needs its bounds (glTF 2.0)
            a["min"], a["max"] = v.min(axis=0).tolist(), v.max(axis=0).tolist()
        return self._accessor(a)

    def zeros(self, count: int) -> int:
        """A VEC3 accessor with no buffer view: `count` zeros."""
        return self._accessor({"componentType": FLOAT, "count": count, "type": "VEC3"})

    def sparse(self, values: np.ndarray) -> int:
        """Zeros but for the rows of `values` that are not: a sparse accessor over no view."""
        rows = np.flatnonzero(np.abs(values).max(axis=1) > 0)
        if not len(rows):
            return self.zeros(len(values))
        wide = len(values) > 0xFFFF
        moved = np.ascontiguousarray(values[rows], "<f4").tobytes()
        index = np.ascontiguousarray(rows, "<u4" if wide else "<u2")
        sparse = {
            "count": len(rows),
            "indices": {
                "bufferView": self._view(index.tobytes()),
                "componentType": UINT32 if wide else UINT16,
            },
            "values": {"bufferView": self._view(moved)},
        }
        return self._accessor(
            {"componentType": FLOAT, "count": len(values), "type": "VEC3", "sparse": sparse}
        )

    def indices(self, triangles: np.ndarray) -> int:
        t = np.ascontiguousarray(triangles, "<u4").ravel()
        return self._accessor(
            {"bufferView": self._view(t.tobytes()), "componentType": UINT32, "count": len(t)}
            | {"type": "SCALAR"}
        )

    def material(self, name: str) -> int:
        self.doc["materials"].append({"name": name})
        return len(self.doc["materials"]) - 1

    def mesh_node(self, mesh: dict) -> None:
        self.doc["meshes"].append(mesh)
        self.doc["nodes"].append({"name": mesh["name"], "mesh": len(self.doc["meshes"]) - 1})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, path: Path) -> Path:
        text = json.dumps(self.doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        binary = bytes(self.bin)
        total = 12 + 8 + len(text) + 8 + len(binary)
        path.write_bytes(
            b"glTF"
            + struct.pack("<II", 2, total)
            + struct.pack("<I", len(text))
            + b"JSON"
            + text
            + struct.pack("<I", len(binary))
            + b"BIN\0"
            + binary
        )
        return path


def _check_metres_y_up(avatar: AvatarMesh) -> None:
    t = avatar.truth
    if t.metres_per_unit != 1.0 or t.mirror or not np.allclose(t.rotation, np.eye(3)):
        raise ValueError("a glTF avatar is in metres with +Y up: make it with unit 'm', up 'y'")


def _part_of_triangles(avatar: AvatarMesh) -> np.ndarray:
    """Each triangle's part: the lowest of its corners' (a bust joins the skin at the neck)."""
    return avatar.truth.part[avatar.triangles].min(axis=1)


def write_ready_player_me(avatar: AvatarMesh, path: Path) -> Path:
    """One mesh per part, 52 ARKit targets each: zeros with no view, else sparse."""
    _check_metres_y_up(avatar)
    g = GlbWriter()
    tri_part = _part_of_triangles(avatar)
    for p, part in enumerate(PARTS):
        triangles = avatar.triangles[tri_part == p]
        if not len(triangles):
            continue
        used = np.unique(triangles)
        local = np.full(len(avatar.neutral), -1, np.int64)
        local[used] = np.arange(len(used))
        targets = [
            {"POSITION": g.sparse(avatar.deltas[k][used])} for k in range(len(ARKIT_BLENDSHAPES))
        ]
        primitive = {
            "attributes": {"POSITION": g.vec3(avatar.neutral[used], bounds=True)},
            "indices": g.indices(local[triangles]),
            "material": g.material(f"{READY_PLAYER_ME_NAMES[part]}_material"),
            "targets": targets,
        }
        g.mesh_node(
            {
                "name": READY_PLAYER_ME_NAMES[part],
                "primitives": [primitive],
                "extras": {"targetNames": list(ARKIT_BLENDSHAPES)},
            }
        )
    return g.write(path)


def vroid_expressions(deltas: np.ndarray) -> tuple[list[str], list[np.ndarray]]:
    """VRoid's own `Fcl_*` targets, mixes of the ARKit shapes (its mouth vowels, eye and brow
    expressions, whole-face ones), enough to make VROID_TARGETS with the 52."""
    k = {n: i for i, n in enumerate(ARKIT_BLENDSHAPES)}
    groups = {
        "ALL": ("jawOpen", "mouthSmileLeft", "mouthSmileRight", "browInnerUp", "eyeSquintLeft"),
        "BRW": ("browDownLeft", "browDownRight", "browInnerUp", "browOuterUpLeft"),
        "EYE": ("eyeBlinkLeft", "eyeBlinkRight", "eyeWideLeft", "eyeSquintRight"),
        "MTH": ("jawOpen", "mouthFunnel", "mouthPucker", "mouthClose", "mouthStretchLeft"),
        "HA": ("mouthRollLower", "mouthShrugUpper", "cheekPuff"),
    }
    names, targets = [], []
    n_own = VROID_TARGETS - len(ARKIT_BLENDSHAPES)
    for i in range(n_own):
        group = list(groups)[i % len(groups)]
        shapes = groups[group]
        a, b = shapes[i % len(shapes)], shapes[(i // len(groups) + 1) % len(shapes)]
        share = 0.3 + 0.6 * ((i * 7) % 10) / 10
        names.append(f"Fcl_{group}_{i:02d}")
        targets.append(share * deltas[k[a]] + (1 - share) * deltas[k[b]])
    return names, targets


def write_vroid(avatar: AvatarMesh, path: Path, gltfpack: str = "gltfpack") -> Path:
    """The face as VRoid exports it, then compressed by gltfpack (meshopt with a fallback
    buffer, quantised positions and targets); named nodes, meshes and materials kept."""
    _check_metres_y_up(avatar)
    program = shutil.which(gltfpack)
    if program is None:
        raise FileNotFoundError("gltfpack is not installed (.ci/setup installs it)")
    g = GlbWriter()
    position = g.vec3(avatar.neutral, bounds=True)
    own_names, own = vroid_expressions(avatar.deltas)
    targets = [{"POSITION": g.vec3(d)} for d in own + list(avatar.deltas)]
    # the triangles in VROID_PRIMITIVES groups, by part and then in runs, a material each
    order = np.argsort(_part_of_triangles(avatar), kind="stable")
    primitives = []
    for i, chunk in enumerate(np.array_split(order, VROID_PRIMITIVES)):
        primitives.append(
            {
                "attributes": {"POSITION": position},
                "indices": g.indices(avatar.triangles[chunk]),
                "material": g.material(f"N00_000_00_Face_{i:02d} (Instance)"),
                "targets": targets,
            }
        )
    g.mesh_node(
        {
            "name": "Face",
            "primitives": primitives,
            "extras": {"targetNames": own_names + list(ARKIT_BLENDSHAPES)},
        }
    )
    plain = g.write(path.with_name(path.stem + "-uncompressed.glb"))
    subprocess.run(
        [program, "-i", str(plain), "-o", str(path), "-cf", "-kn", "-km", "-ke"],
        check=True,
        capture_output=True,
    )
    plain.unlink()
    return path
