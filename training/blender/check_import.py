"""Run inside Blender (not the project's Python): import a `softdeca_train simulate` / `softdeca
replay` output folder the way docs/physics.md describes and check that what Blender shows is
the point cache.

    blender -b --factory-startup --python-exit-code 1 \
        --python training/blender/check_import.py -- OUT_DIR [CACHE]

Imports OUT_DIR/neutral.obj (Forward -Z, Up Y), adds a Mesh Cache modifier (PC2, default
axes) reading OUT_DIR/CACHE (default physics.pc2), and for every cached frame compares the
evaluated mesh in world space with the cache's points turned from +Y up to Blender's +Z up.
Prints the largest difference and exits non-zero when it exceeds 1e-5 m."""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import bpy  # type: ignore[import-not-found]


def read_pc2(path: Path) -> list[list[tuple[float, float, float]]]:
    data = path.read_bytes()
    _sig, _version, points, _start, _rate, frames = struct.unpack("<12siiffi", data[:32])
    values = struct.unpack(f"<{frames * points * 3}f", data[32 : 32 + frames * points * 12])
    return [
        [tuple(values[(f * points + i) * 3 : (f * points + i) * 3 + 3]) for i in range(points)]
        for f in range(frames)
    ]


def import_obj(path: Path) -> bpy.types.Object:
    if hasattr(bpy.ops.wm, "obj_import"):  # Blender 3.2+
        bpy.ops.wm.obj_import(filepath=str(path), forward_axis="NEGATIVE_Z", up_axis="Y")
    else:
        bpy.ops.import_scene.obj(
            filepath=str(path), axis_forward="-Z", axis_up="Y", split_mode="OFF"
        )
    return bpy.context.selected_objects[0]


def main() -> int:
    args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    if not args:
        print(__doc__)
        return 2
    out = Path(args[0])
    cache = out / (args[1] if len(args) > 1 else "physics.pc2")
    frames = read_pc2(cache)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    obj = import_obj(out / "neutral.obj")
    if len(obj.data.vertices) != len(frames[0]):
        print(f"vertex count {len(obj.data.vertices)} != cache points {len(frames[0])}")
        return 1
    mod = obj.modifiers.new("cache", "MESH_CACHE")
    mod.cache_format = "PC2"
    mod.filepath = str(cache)
    # Default axes (Forward +Y, Up +Z): no conversion in the modifier. Blender 3.2+'s OBJ
    # importer keeps the file's coordinates in the mesh and puts the -Z/Y conversion into the
    # object's rotation, which then applies to the cached points too; converting in the
    # modifier as well would turn the head twice.
    worst = 0.0
    for f, points in enumerate(frames):
        bpy.context.scene.frame_set(f)
        mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
        world = obj.matrix_world
        for v, (x, y, z) in zip(mesh.vertices, points, strict=True):
            p = world @ v.co
            worst = max(worst, abs(p.x - x), abs(p.y + z), abs(p.z - y))
    print(
        f"{cache.name}: {len(frames)} frames x {len(frames[0])} points, largest difference "
        f"between Blender's evaluated mesh and the cache: {worst:.3g} m"
    )
    return 0 if worst < 1e-5 else 1


if __name__ == "__main__":
    sys.exit(main())
