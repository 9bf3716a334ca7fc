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
file and the avatar's truth (sample_avatars/mesh.py) share one frame."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np

from softdeca_train.face_names import ARKIT_BLENDSHAPES
from softdeca_train.gltf_writer import GltfWriter
from softdeca_train.sample_avatars.mesh import PARTS, AvatarMesh

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
    g = GltfWriter()
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
        g.add_mesh(
            {
                "name": READY_PLAYER_ME_NAMES[part],
                "primitives": [primitive],
                "extras": {"targetNames": list(ARKIT_BLENDSHAPES)},
            }
        )
    return g.write_glb(path)


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
    g = GltfWriter()
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
    g.add_mesh(
        {
            "name": "Face",
            "primitives": primitives,
            "extras": {"targetNames": own_names + list(ARKIT_BLENDSHAPES)},
        }
    )
    plain = g.write_glb(path.with_name(path.stem + "-uncompressed.glb"))
    subprocess.run(
        [program, "-i", str(plain), "-o", str(path), "-cf", "-kn", "-km", "-ke"],
        check=True,
        capture_output=True,
    )
    plain.unlink()
    return path
