"""SoftDECA trained on the rest physics (train/rest_changes.py, the bundle's `rest_changes`):
a dataset's rest changes Pd are what the bundle's physics at prepare computes, resumable, and
put on S_t by the loader; a bundle trained on them gets Pd whole at prepare and keeps the
networks' response to p (nothing taken off), natively as in its reference."""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import softdeca_native
import torch
from bounds import above, below
from gated_bundle import edited_copy, gated_bundle, reference_and_native
from softdeca_train.host.fit_check import DEFAULT_BUNDLE
from softdeca_train.host.native import NativeError, NativeModel
from softdeca_train.models import (
    read_manifest,
)
from softdeca_train.models.bundle import (
    read_rest_physics,
    read_rest_physics_bytes,
    replace_softdeca,
)
from softdeca_train.models.dt import face_geometry
from softdeca_train.models.parameters import ParameterState
from softdeca_train.models.rest_physics import RestSolver
from softdeca_train.train.batches import (
    EVERY_FRAME,
    REST_CHANGES,
    Dataset,
    rest_changes_path,
)
from softdeca_train.train.rest_changes import (
    GroupSolver,
    RestChangesConfig,
    make_rest_changes,
    write_shard,
)
from softdeca_train.train.run import Run, RunConfig

SHIPPED = Path(DEFAULT_BUNDLE)  # its physics at prepare: the template's
# float16 storage of Pd (tenths of a mm): 2^-11 relative, with margin
REASON_STORED = "float16 storage of the rest change: 2^-11 of ~0.3 mm"
REASON_SAME = "the reference adds the same arrays it was given: float64 rounding"
REASON_ORACLE = "two solves to the physics' tolerance 1e-4 of ~0.3 mm, float32 neutral"
REASON_NATIVE = "one solver, same tolerance and start; float32 networks against float64"


@pytest.fixture(scope="module")
def rested(small, tmp_path_factory):
    """The small dataset (a copy) with its rest changes made by the shipped bundle's physics."""
    folder, _ = small
    copy = tmp_path_factory.mktemp("rested") / "data"
    shutil.copytree(folder, copy)
    written = list(make_rest_changes(RestChangesConfig(copy, SHIPPED, 1, False)))
    return copy, written


def test_every_static_and_dynamic_shard_gets_its_rest_changes(rested) -> None:
    folder, written = rested
    data = Dataset(folder)
    kinds = [f for k in ("static", "dynamic") for f in data.shards(k, "all")]
    assert sorted(written) == sorted(kinds)
    assert not any(f in written for f in data.shards("sparse", "all"))
    # a rerun writes nothing; one file gone is made again, as it was
    assert list(make_rest_changes(RestChangesConfig(folder, SHIPPED, 1, False))) == []
    path = rest_changes_path(folder, kinds[0])
    before = np.load(path)["rest_change"]
    path.unlink()
    assert list(make_rest_changes(RestChangesConfig(folder, SHIPPED, 1, False))) == [
        kinds[0]
    ]
    assert np.array_equal(np.load(path)["rest_change"], before)


def test_the_loader_puts_the_rest_change_on_s_t(rested) -> None:
    folder, _ = rested
    groups = GroupSolver(SHIPPED, Dataset(folder).template)
    names = [s.name for s in groups.specs]
    plain = Dataset(folder, groups.template, names)
    on_rest = Dataset(folder, groups.template, names, rest_changes=True)
    shard = plain.shards("static", "train")[0]
    pairs = zip(
        plain.shard_batches("static", shard, limit=EVERY_FRAME),
        on_rest.shard_batches("static", shard, limit=EVERY_FRAME),
    )
    for (idx, a), (_, b) in pairs:
        pd = groups.rest_change(a)  # the group's Pd, solved again here
        above(np.abs(pd).max(), 1e-5, "p moves the head at rest", what="m")
        assert np.array_equal(a.T.numpy(), b.T.numpy())  # the physics is the physics
        moved = (b.S - a.S).double().numpy()
        for f in range(a.frames):  # every frame of a group gets its Pd
            below(np.abs(moved[f] - pd).max() / np.abs(pd).max(), 2e-3, REASON_STORED)
    # without the files the loader says what to run
    shutil.move(folder / REST_CHANGES, folder / "moved")
    try:
        with pytest.raises(FileNotFoundError, match="rest-changes --dataset"):
            next(on_rest.batches("static", "train"))
        next(on_rest.batches("sparse", "train"))  # no rest change: SparseSoftDECA's
    finally:
        shutil.move(folder / "moved", folder / REST_CHANGES)


def test_the_rest_changes_are_the_runtimes_physics_at_prepare(rested) -> None:
    """Pd comes from the runtime's solve (softdeca_native.RestPhysics) and agrees with the
    Python oracle of it, regional patterns included."""
    folder, _ = rested
    groups = GroupSolver(SHIPPED, Dataset(folder).template)
    data = Dataset(folder, groups.template, [s.name for s in groups.specs])
    rest = read_rest_physics(SHIPPED, read_manifest(SHIPPED))
    tris = groups.template.skin_triangles
    for kind in ("static", "dynamic"):
        shard = data.shards(kind, "all")[0]
        for _, b in data.shard_batches(kind, shard, limit=EVERY_FRAME):
            neutral = groups.template.identity_neutral(b.h[0].double().numpy())
            oracle = RestSolver(rest, neutral, tris)
            area = face_geometry(neutral[: b.S.shape[1]], tris)[0]
            params = ParameterState(groups.specs, tris, area)
            rest0 = oracle.solve(params)
            for k, spec in enumerate(groups.specs):
                params.set_global(spec.name, float(b.p[0, k]))
                if b.p_vertices is not None and spec.localisable:
                    params.set_vertices(spec.name, b.p_vertices[:, k].double().numpy())
            want = oracle.solve(params) - rest0
            got = groups.rest_change(b)
            above(np.abs(want).max(), 1e-5, "p moves the head at rest", what="m")
            below(np.abs(got - want).max() / np.abs(want).max(), 0.02, REASON_ORACLE)
            break
    assert isinstance(groups.solver, softdeca_native.RestPhysics)


@pytest.mark.parametrize(
    "edit, message",
    [
        (None, "no_such_parameter is not one of the physics' parameters"),
        ({"max": 1e9}, "range is wider than the physics accepts"),
    ],
)
def test_the_physics_at_prepare_refuses_a_parameter_it_cannot_take(
    template, edit, message
) -> None:
    manifest = read_manifest(SHIPPED)
    rest = read_rest_physics_bytes(SHIPPED, manifest)
    first = manifest["parameters"][0]
    if (
        edit is None
    ):  # one more parameter, no network's column: only the physics can object
        manifest["parameters"].append({**first, "name": "no_such_parameter"})
    else:
        first.update(edit)
    neutral = np.ascontiguousarray(template.neutral, np.float32)
    tris = np.ascontiguousarray(template.skin_triangles, np.int32)
    with pytest.raises(ValueError, match=message):
        softdeca_native.RestPhysics(json.dumps(manifest), rest, neutral, tris)


class RefusingOne:
    """A group solver whose physics refuses the first identity it is given, as the physics at
    prepare refuses a head whose carried tissue fill inverts a tet."""

    def __init__(self, groups: GroupSolver) -> None:
        self.groups, self.refused = groups, None

    def rest_change(self, b):
        if self.refused in (None, b.identity_id):
            self.refused = b.identity_id
            raise ValueError("soft_tets[1] is inverted")
        return self.groups.rest_change(b)


def test_a_head_the_physics_refuses_is_left_out_and_counted(rested, tmp_path) -> None:
    folder, _ = rested
    copy = tmp_path / "data"
    shutil.copytree(folder, copy)
    groups = GroupSolver(SHIPPED, Dataset(copy).template)
    names = [s.name for s in groups.specs]
    data = Dataset(copy, groups.template, names, rest_changes=True)
    shard = data.shards("static", "train")[0]
    before = data.left_out("static", "train")
    write_shard(data, RefusingOne(groups), "static", shard)
    with np.load(rest_changes_path(copy, shard)) as z:
        refused = ~z["solved"]
        assert refused.any() and all("inverted" in r for r in z["refusal"][refused])
    after = data.left_out("static", "train")
    assert after["no_rest_physics"] == before["no_rest_physics"] + int(refused.sum())
    assert after["kept"] == before["kept"] - int(refused.sum())
    kept = sum(b.frames for b in data.batches("static", "train"))
    assert kept == after["kept"]
    everything = sum(
        b.frames for b in data.batches("static", "train", None, 8, EVERY_FRAME)
    )
    assert everything < sum(
        b.frames for b in Dataset(copy).batches("static", "train", None, 8, EVERY_FRAME)
    )


def test_a_run_on_the_rest_changes_evaluates_its_bundle_on_the_blend(
    rested, tmp_path
) -> None:
    """The run trains on S_t + Pd; its bundle reads S_t (the runtime adds Pd at prepare), so
    the report's bundle pass takes its frames from blend_data."""
    folder, _ = rested
    run = Run(tmp_path / "run", RunConfig(str(folder), "test", rest_changes=True))
    a = next(run.data.batches("static", "test", None, 8, EVERY_FRAME))
    b = next(run.blend_data.batches("static", "test", None, 8, EVERY_FRAME))
    assert a.param_id == b.param_id and torch.equal(a.T, b.T)
    above(float((a.S - b.S).abs().max()), 1e-5, "Pd on the run's frames", what="m")
    plain = Run(tmp_path / "plain", RunConfig(str(folder), "test"))
    assert plain.blend_data is plain.data


@pytest.fixture(scope="module")
def trained_on_rest(tmp_path_factory):
    """A gated bundle trained on the rest physics (format version 7)."""
    return gated_bundle(
        tmp_path_factory.mktemp("rest-changes") / "bundle", rest_changes=True
    )


def _avatars(setup, gravity: float, rest_physics: bool = True):
    ref, nat = reference_and_native(setup, "float", rest_physics)
    for set_parameter in (ref.params.set_global, nat.set_parameter):
        set_parameter("gravity_strength", gravity)
    ref.prepare()
    nat.prepare()
    return ref, nat


def test_a_bundle_trained_on_the_rest_physics_adds_it_whole(trained_on_rest) -> None:
    """frame(w, p) = networks(w, p) + Pd: at rest the linear blend and Pd, on an expression the
    networks' own response to p kept (the gated rule would take M1(p) - M1(p0) off)."""
    head, _, _, folder, rest = trained_on_rest
    manifest = read_manifest(folder)
    assert manifest["rest_changes"] is True and manifest["format_version"] == 7
    vs = head.definition.skin_vertices
    ref0, nat0 = _avatars(trained_on_rest, 1.0)
    ref, nat = _avatars(trained_on_rest, 1.7)
    plain, plain0 = _avatars(trained_on_rest, 1.7, False)[0], ref0
    solver = RestSolver(rest, head.neutral, head.definition.skin_triangles)
    physics = solver.solve(ref.params) - solver.solve(ref0.params)
    above(
        np.abs(physics).max(), 1e-5, "1.7 g moves the synthetic head at rest", what="m"
    )
    zero, strong = np.zeros(52), np.full(52, 0.6)
    got = ref.evaluate_weights(zero)[0][:vs] - head.neutral[:vs]
    below(np.abs(got - physics).max() * 1e3, 1e-6, REASON_SAME, what="mm")
    networks = (
        plain.evaluate_weights(strong)[0][:vs] - plain0.evaluate_weights(strong)[0][:vs]
    )
    above(np.abs(networks).max(), 1e-5, "the networks respond to p", what="m")
    got = ref.evaluate_weights(strong)[0][:vs] - ref0.evaluate_weights(strong)[0][:vs]
    below(np.abs(got - (networks + physics)).max() * 1e3, 1e-6, REASON_SAME, what="mm")
    for w in (zero, strong):
        x, want = nat.evaluate_weights(w)[0], ref.evaluate_weights(w)[0]
        below(np.abs(x - want).max() * 1e3, 3e-4, REASON_NATIVE, what="mm")
    moved = nat.evaluate_weights(zero)[0][:vs] - nat0.evaluate_weights(zero)[0][:vs]
    below(np.abs(moved - physics).max() * 1e3, 3e-4, REASON_NATIVE, what="mm")


def _no_rest_physics(m: dict) -> None:
    del m["rest_physics"]


@pytest.mark.parametrize(
    "edit, message",
    [
        (
            {"format_version": 6},
            r"rest_changes \(SoftDECA trained on the rest physics\) needs bundle format version 7",
        ),
        ({"rest_changes": 1}, "rest_changes must be"),
        (_no_rest_physics, "rest_changes .* needs the physics at prepare"),
    ],
)
def test_rest_changes_are_checked_at_load(
    trained_on_rest, tmp_path, edit, message
) -> None:
    """A runtime that ignored `rest_changes` would take the networks' response to p off: it
    needs format version 7, a boolean and the physics at prepare it speaks of."""

    copy = edited_copy(trained_on_rest[3], tmp_path / "bundle", edit)
    with pytest.raises(NativeError, match=message):
        NativeModel(copy)


def test_a_softdeca_trained_on_the_rest_physics_replaces_a_bundles_own(
    trained_on_rest, tmp_path
) -> None:
    """bundle-softdeca (models/bundle.replace_softdeca): a gated bundle's SoftDECA frame
    networks give way to one trained on the rest physics; its dynamics network and
    SparseSoftDECA stay, the manifest says rest_changes (format version 7), and the runtime
    runs the new networks as the reference does. A model the bundle cannot take leaves the
    bundle as it was."""
    head, nets, _, _, rest = trained_on_rest
    _, plain_nets, _, plain, _ = gated_bundle(tmp_path / "plain", seed=10)
    before = read_manifest(plain)
    assert before["format_version"] == 6 and "rest_changes" not in before
    folder = edited_copy(plain, tmp_path / "bundle", {})
    record = {"model": "softdeca", "command": "test"}
    replace_softdeca(folder, nets, record, {"softdeca_static": {"mean_mm": 0.1}})
    after = read_manifest(folder)
    assert after["rest_changes"] is True and after["format_version"] == 7
    assert after["rest_gate"] == before["rest_gate"]
    for name, spec in after["networks"].items():
        moved = spec["sha256"] != before["networks"][name]["sha256"]
        frame = name.startswith("softdeca.") and name != "softdeca.f_dyn"
        assert moved == frame, name
    assert after["training"]["replaced"][-1]["model"] == "softdeca"
    assert after["errors"]["softdeca_static"] == {"mean_mm": 0.1}
    # what the bundle now holds: the plain bundle's identity encoder, dynamics and sparse
    # networks with the new SoftDECA frame networks
    held = replace(
        plain_nets,
        softdeca=replace(nets.softdeca, f_dyn=plain_nets.softdeca.f_dyn),
        rest_changes=True,
    )
    setup = (head, held, NativeModel(folder), folder, rest)
    ref, nat = reference_and_native(setup, "float")
    ref.prepare()
    nat.prepare()
    for w in (np.zeros(52), np.full(52, 0.6)):
        x, want = nat.evaluate_weights(w)[0], ref.evaluate_weights(w)[0]
        below(np.abs(x - want).max() * 1e3, 3e-4, REASON_NATIVE, what="mm")
    # refused before anything is written: no physics at prepare for the rest changes, or a
    # SoftDECA without the bundle's residual stage
    bare = edited_copy(plain, tmp_path / "bare", _no_rest_physics)
    kept = read_manifest(bare)
    with pytest.raises(ValueError, match="needs its physics at prepare"):
        replace_softdeca(bare, nets, record)
    assert read_manifest(bare) == kept
    no_residual = replace(
        nets, softdeca=replace(nets.softdeca, f_r=None), rest_changes=False
    )
    with pytest.raises(ValueError, match="the bundle's SoftDECA has"):
        replace_softdeca(folder, no_residual, record)
    assert read_manifest(folder) == after
