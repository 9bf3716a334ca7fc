"""The inputs of the native runtime tests (tests/native/test_runtime_*.cpp), written once per
test run by a ctest fixture: a small synthetic bundle (also packed as .tar, a variant with
only SoftDECA and one at SoftDECA's closed-form start), the avatar as raw arrays and as a
replay folder, and a short Live Link Face CSV take with face-lost rows."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from softdeca_train.host.files import write_rig
from softdeca_train.mesh_files import write_obj
from softdeca_train.models import (
    TEST_SIZES,
    BundleInfo,
    build_random,
    export_bundle,
    load_parameter_specs,
    pack_bundle,
)
from softdeca_train.models.synthetic import TEST_PARAMETERS, synthetic_head, synthetic_rest_head
from softdeca_train.models.template_head import template_head_of
from softdeca_train.streaming.livelinkface import CSV_ORDER, VALUE_NAMES
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

# Live Link Face CSV columns: its own order (eyes, jaw, mouth, brows, cheeks, nose, tongue).
_LLF_ORDER = [VALUE_NAMES[i] for i in CSV_ORDER[:52]]


def write_take(path: Path, weights: np.ndarray, face_lost: tuple[int, ...] = ()) -> Path:
    """A CSV in Live Link Face's layout; rows listed in `face_lost` hold only two fields."""
    names = [n[0].lower() + n[1:] for n in _LLF_ORDER]
    order = [ARKIT_BLENDSHAPES.index(n) for n in names]
    head = ["Timecode", "BlendshapeCount", *_LLF_ORDER, "HeadYaw", "HeadPitch", "HeadRoll"]
    rows = [",".join(head)]
    for i, w in enumerate(weights):
        tc = f"10:00:{i // 30:02d}:{(2 * i) % 60:02d}.000"
        if i in face_lost:
            rows.append(f"{tc},0")  # what the app writes when it lost the face
            continue
        rows.append(",".join([tc, "61", *(f"{w[j]:.6f}" for j in order), "0", "0", "0"]))
    path.write_text("\n".join(rows) + "\n")
    return path


def write_test_data(out: Path) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    head = synthetic_head()
    specs = load_parameter_specs(TEST_PARAMETERS)
    nets = build_random(head.definition, specs, TEST_SIZES, seed=1)
    info = BundleInfo(untrained=True, description="native test bundle: synthetic head, random")
    # with the physics at prepare (format version 4) on a shell head under the synthetic skin,
    # and the template head fits read
    rest = synthetic_rest_head(head)
    fits = template_head_of(head.neutral, head.blendshapes, head.definition.skin_vertices)
    export_bundle(out / "bundle", head.definition, nets, info, rest_head=rest, template_head=fits)
    (out / "bundle.tar").write_bytes(pack_bundle(out / "bundle"))
    only = build_random(head.definition, specs, TEST_SIZES, seed=2, sparse=False)
    export_bundle(out / "bundle_softdeca_only", head.definition, only, info)
    # SoftDECA at its closed-form start (f_ph zero: DT at identity) with its vertex and residual
    # stages, as the committed bundle: the frames written in place and the fitted avatars'
    # carried frames run on it
    closed = build_random(
        head.definition,
        specs,
        TEST_SIZES,
        seed=3,
        dg_scale=0.0,
        vertex_stage=True,
        residual_stage=True,
    )
    export_bundle(
        out / "bundle_closed_form",
        head.definition,
        closed,
        info,
        rest_head=rest,
        template_head=fits,
    )
    for name, a in {
        "neutral.f32": head.neutral,
        "blendshapes.f32": head.blendshapes,
        "user_neutral.f32": head.user_neutral,
        "user_deltas.f32": head.user_deltas,
    }.items():
        (out / name).write_bytes(np.ascontiguousarray(a, dtype="<f4").tobytes())
    (out / "triangles.i32").write_bytes(np.ascontiguousarray(head.head_triangles, "<i4").tobytes())
    write_rig(out / "avatar", head.neutral, head.blendshapes, head.head_triangles)
    write_rig(out / "avatar" / "user_face", head.user_neutral, head.user_deltas, None)
    rng = np.random.default_rng(3)
    weights = np.clip(np.sin(np.arange(40)[:, None] * 0.2 + rng.uniform(0, 6, 52)), 0, 1)
    write_take(out / "take.csv", weights, face_lost=(5, 6, 17))
    write_obj(out / "avatar_neutral_copy.obj", head.neutral, head.head_triangles)
    return out
