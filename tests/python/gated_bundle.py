"""A random bundle trained exact at rest, as the trained bundles are: z's last entry the rest
gate (f_w's constant slot, format version 6), with the vertex and residual stages and the
physics at prepare; shared by the tests of the rest gate and of the rest changes."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from softdeca_train.host.native import NativeAvatar, NativeModel
from softdeca_train.models import (
    TEST_SIZES,
    BundleInfo,
    ReferenceAvatar,
    TorchNetworks,
    as_stored,
    build_random,
    export_bundle,
    load_parameter_specs,
)
from softdeca_train.models.synthetic import (
    TEST_PARAMETERS,
    synthetic_head,
    synthetic_rest_head,
)


def gated_bundle(folder: Path, rest_changes: bool = False, seed: int = 9) -> tuple:
    """(head, nets, NativeModel, folder, rest head) of the bundle written to `folder`;
    `rest_changes`: its SoftDECA trained on the rest physics (format version 7); `seed`: its
    random weights'."""
    head = synthetic_head()
    specs = load_parameter_specs(TEST_PARAMETERS)
    nets = build_random(
        head.definition,
        specs,
        replace(TEST_SIZES, rest_gate=0.1),
        seed=seed,
        vertex_stage=True,
        residual_stage=True,
        constant_slot=True,
        # the constant slot's local map of p makes tables of this scale correct S_t by a few
        # mm (the parity tests' bundle: ~1 mm), which the storage bounds are relative to
        offset_scale=1e-4,
    )
    nets.rest_changes = rest_changes
    # the skin strain is rest-inert here: it moves nothing of the unloaded head at rest
    rest = replace(synthetic_rest_head(head), inert=("w_skin_strain",))
    export_bundle(
        folder, head.definition, nets, BundleInfo(True, "gated"), rest_head=rest
    )
    return head, nets, NativeModel(folder), folder, rest


def edited_copy(folder: Path, out: Path, edit: dict | Callable[[dict], None]) -> Path:
    """A copy of the bundle at `out` with its manifest edited: keys updated from a dict, or
    changed by a function."""
    shutil.copytree(folder, out)
    manifest = json.loads((out / "manifest.json").read_text())
    if callable(edit):
        edit(manifest)
    else:
        manifest.update(edit)
    (out / "manifest.json").write_text(json.dumps(manifest))
    return out


def reference_and_native(
    setup: tuple, precision: str, rest_physics: bool = True
) -> tuple:
    """The reference and the native avatar of a bundle (head, nets, NativeModel, folder,
    rest head) on its head, both models' tables at `precision`, not prepared yet;
    `rest_physics` False: the reference without the physics at prepare."""
    head, nets, model, _, rest = setup
    ref = ReferenceAvatar(
        TorchNetworks(as_stored(nets), rest_head=rest),
        head.definition,
        head.neutral,
        head.head_triangles,
        head.blendshapes,
        rest_physics=rest_physics,
    )
    nat = NativeAvatar(
        model,
        head.neutral,
        head.head_triangles,
        head.blendshapes,
        precision=precision,
        sparse_precision=precision,
    )
    return ref, nat
