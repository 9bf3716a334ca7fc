"""How well a fit covers an avatar's face, measured independently of the fit's own report: the
avatar's moving face vertices (its skin the skin-only shapes move; eyes, teeth, tongue, hair
and anything no such shape moves left out) to the registered template skin
(`softdeca_avatar_fit_get_registered` on the bundle's skin triangles), the closest point on its
triangles. A template squeezed onto part of the face leaves most of the face far from it; one
lying on the avatar's surface leaves every face vertex within a millimetre or so.

`python -m softdeca_train.host.fit_coverage` fits each low-poly variant (sample_avatars/config.py,
LOW_POLY_VARIANTS) with the committed bundle and prints its coverage ($SOFTDECA_LIBRARY: another
build of the library).

Oracle: an independent measure of what plugin/src/fit/fit_quality.cpp measures, from the test
avatars' truth; tests/python/test_fit_avatars.py holds the two together."""

from __future__ import annotations

import time
from dataclasses import dataclass

import igl
import numpy as np

from softdeca_train.face_names import ARKIT_BLENDSHAPES
from softdeca_train.host.fit_check import DEFAULT_BUNDLE, avatar_arrays
from softdeca_train.host.native import NativeFit, NativeModel
from softdeca_train.landmarks.arkit_reference import ArkitFace
from softdeca_train.sample_avatars.build import make_avatar
from softdeca_train.sample_avatars.config import LOW_POLY_VARIANTS
from softdeca_train.sample_avatars.mesh import AvatarMesh
from softdeca_train.template import Template

# The shapes that move skin only on every rig (plugin/src/fit/avatar_fit.cpp, kSkinShapes).
SKIN_SHAPES = (
    "browDownLeft",
    "browDownRight",
    "browInnerUp",
    "browOuterUpLeft",
    "browOuterUpRight",
    "eyeBlinkLeft",
    "eyeBlinkRight",
    "cheekSquintLeft",
    "cheekSquintRight",
    "noseSneerLeft",
    "noseSneerRight",
    "mouthSmileLeft",
    "mouthSmileRight",
    "mouthDimpleLeft",
    "mouthDimpleRight",
    "mouthStretchLeft",
    "mouthStretchRight",
    "cheekPuff",
)
MOVING = 0.05  # a vertex moves when a skin-only shape moves it this share of its largest
WITHIN_MM = 3.0


@dataclass(frozen=True)
class Coverage:
    vertices: int  # the avatar's moving face vertices measured
    median_mm: float  # their median distance to the registered template skin
    within: float  # the share of them within WITHIN_MM
    extent_mm: tuple[float, float, float]  # the registered skin's bounding box (template axes)


def moving_face(avatar: AvatarMesh) -> np.ndarray:
    """(N,) bool: the avatar's skin vertices a skin-only shape moves by MOVING of its largest."""
    moving = np.zeros(len(avatar.neutral), bool)
    for name in SKIN_SHAPES:
        k = ARKIT_BLENDSHAPES.index(name)
        if not avatar.present[k]:
            continue
        size = np.linalg.norm(avatar.deltas[k], axis=1)
        moving |= size > MOVING * size.max()
    return moving & avatar.truth.part_mask("skin")


def face_coverage(model: NativeModel, fit: NativeFit, avatar: AvatarMesh) -> Coverage:
    triangles = model.skin_triangles().astype(np.int64)
    registered = fit.registered(int(triangles.max()) + 1).astype(np.float64)
    metres = avatar.truth.metres_per_unit
    face = moving_face(avatar)
    squared, _, _ = igl.point_mesh_squared_distance(avatar.neutral[face], registered, triangles)
    mm = 1000 * metres * np.sqrt(squared)
    used = registered[np.unique(triangles)]
    in_template = avatar.truth.to_template(used)
    extent = 1000 * (in_template.max(axis=0) - in_template.min(axis=0))
    return Coverage(
        int(face.sum()),
        float(np.median(mm)),
        float((mm <= WITHIN_MM).mean()),
        (float(extent[0]), float(extent[1]), float(extent[2])),
    )


def main() -> int:
    model, template, face = NativeModel(DEFAULT_BUNDLE), Template.load(), ArkitFace.load()
    for name, config in LOW_POLY_VARIANTS.items():
        avatar = make_avatar(config, template, face)
        start = time.perf_counter()
        fit = NativeFit.create(model, avatar_arrays(avatar))
        seconds = time.perf_counter() - start
        c, r = face_coverage(model, fit, avatar), fit.report()
        x, y, z = c.extent_mm
        print(
            f"{name}: {len(avatar.neutral)} vertices, unit {r['metres_per_unit']} (measured "
            f"{r['metres_per_unit_measured']:.4g}), median {c.median_mm:.2f} mm, within "
            f"{WITHIN_MM:g} mm {c.within:.3f} of {c.vertices}, the registered skin {x:.0f} x "
            f"{y:.0f} x {z:.0f} mm, {r['embedded_vertices']} embedded, fit {seconds:.1f} s",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
