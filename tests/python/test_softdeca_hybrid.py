"""SoftDECA with a vertex stage (train/trainable.py SoftDecaHybrid): the constant slot of z, the
per-vertex local map of the parameters, and the closed-form start at the per-vertex ridge
fit, checked against an independent fit on the small generated dataset."""

from __future__ import annotations

import json
import shutil
from dataclasses import replace

import numpy as np
import pytest
import torch
from bounds import below
from softdeca_train.data.plan import FIXED
from softdeca_train.models.networks import TEST_SIZES, LocalLinear, WeightEncoder
from softdeca_train.train.evaluate import time_per_frame
from softdeca_train.train.linear_baseline import ParameterScaling
from softdeca_train.train.run import Run, RunConfig
from softdeca_train.train.trainable import CM, SoftDecaHybrid


def test_the_constant_slot_is_one_and_the_skip_is_linear() -> None:
    enc = WeightEncoder(52, TEST_SIZES, linear_skip=True, constant_slot=True)
    w = torch.rand(4, 52)
    z = enc(w)
    assert z.shape == (4, TEST_SIZES.latent)
    assert torch.equal(z[:, -1], torch.ones(4))
    with torch.no_grad():
        enc.net[-1].weight.zero_()
        enc.net[-1].bias.zero_()
    assert torch.allclose(enc(2 * w)[:, :-1], 2 * enc(w)[:, :-1])


@pytest.mark.parametrize("tau", [0.0, 0.1])
def test_with_a_rest_gate_the_codes_are_zero_at_rest(tau: float) -> None:
    """Exact at rest by construction: z(0) = 0 in every slot (to float32 rounding: the two
    evaluations of the network differ in their batch), the network's own output at zero taken
    out inside the model, not a constant subtracted afterwards; the constant slot is the gate,
    |w|^2 / (|w|^2 + tau^2) (0 for tau 0), rising with the expression."""
    sizes = replace(TEST_SIZES, rest_gate=tau)
    enc = WeightEncoder(52, sizes, linear_skip=True, constant_slot=True)
    with torch.no_grad():
        for layer in enc.net:
            if isinstance(layer, torch.nn.Linear):
                layer.bias.normal_()  # a network whose output at zero is far from zero
    w = torch.rand(5, 52) * torch.tensor([[0.0], [0.01], [0.1], [0.5], [1.0]])
    z = enc(w).detach()
    assert enc.net(enc.rest).abs().max() > 0.1  # what is taken out
    below(z[0].abs().max().item(), 1e-6, "float32 rounding of the network at rest")
    assert (z[1:, :-1].abs().amax(dim=1) > 1e-4).all()
    gate = z[:, -1]
    if tau == 0:
        assert torch.equal(gate, torch.zeros_like(gate))
    else:
        assert (torch.diff(gate) > 0).all() and (gate < 1).all()
        s = (w * w).sum(dim=1)
        assert torch.allclose(gate, s / (s + tau * tau))


def test_with_a_rest_gate_the_residual_stage_is_zero_at_rest() -> None:
    from softdeca_train.models.parameters import load_parameter_specs
    from softdeca_train.models.residual import ResidualSizes, ResidualStage
    from softdeca_train.models.synthetic import TEST_PARAMETERS

    specs = load_parameter_specs(TEST_PARAMETERS)
    labels = np.array([0, 0, 1, 1, 2, 2])
    for tau, at_rest_is_zero in ((None, False), (0.0, True), (0.2, True)):
        stage = ResidualStage(labels, specs, ResidualSizes(3, 8, 2, 0.0, rest_gate=tau))
        with torch.no_grad():
            stage.table.normal_()
        stage.eval()
        p = torch.tensor([[s.default_value for s in specs]] * len(labels))
        with torch.no_grad():
            rest = stage(torch.zeros(1, 52), p).abs().max().item()
            moving = stage(torch.rand(1, 52), p).abs().max().item()
        assert (rest < 1e-5 * moving) == at_rest_is_zero, (tau, rest, moving)


def _linear_ops(
    module: torch.nn.Module, inputs: list[tuple[str, list]], out: list
) -> int:
    """How many matrix products the exported graph of `module` runs per call, and a check
    that it computes what the module does."""
    import onnx
    import onnxruntime as ort
    from softdeca_train.models.bundle import _export_onnx

    spec = {
        "inputs": [{"name": n, "shape": s} for n, s in inputs],
        "outputs": [{"name": n, "shape": s} for n, s in out],
    }
    example = tuple(
        torch.rand(*[1 if isinstance(d, str) else d for d in s]) for _, s in inputs
    )
    data = _export_onnx(module.eval(), spec, example)
    session = ort.InferenceSession(data, providers=["CPUExecutionProvider"])
    feed = {n: x.numpy() for (n, _), x in zip(inputs, example, strict=True)}
    with torch.no_grad():
        want = module(*example).numpy()
    np.testing.assert_allclose(session.run(None, feed)[0], want, rtol=1e-4, atol=1e-6)
    graph = onnx.load_from_string(data).graph
    return sum(n.op_type in ("Gemm", "MatMul") for n in graph.node)


def test_the_exported_frame_networks_hold_their_rest_terms_as_constants() -> None:
    """With a rest gate, z(w) = net(w) - net(0) and the residual stage's c(w) - c(0): the
    exported per-frame graphs run each network once, net(0) a constant of f_w's graph and
    c(0) part of the condition made at prepare (models/residual.py condition_size)."""
    from softdeca_train.models.parameters import load_parameter_specs
    from softdeca_train.models.residual import (
        ResidualCoefficients,
        ResidualSizes,
        ResidualStage,
    )
    from softdeca_train.models.synthetic import TEST_PARAMETERS

    sizes = replace(TEST_SIZES, rest_gate=0.1)
    enc = WeightEncoder(52, sizes, linear_skip=True, constant_slot=True)
    layers = sum(isinstance(m, torch.nn.Linear) for m in enc.modules())
    z = [("z", ["batch", sizes.latent])]
    assert _linear_ops(enc, [("weights", ["batch", 52])], z) == layers

    specs = load_parameter_specs(TEST_PARAMETERS)
    labels = np.array([0, 0, 1, 1, 2, 2])
    stage = ResidualStage(labels, specs, ResidualSizes(3, 8, 2, 0.0, rest_gate=0.1))
    with torch.no_grad():
        for prm in stage.parameters():
            prm.normal_()
    p = torch.tensor([[s.default_value for s in specs]] * len(labels))
    condition = stage.condition(p)
    # modes 3, hidden 8, members 2: the members' shares, then the 3 coefficients at rest
    assert condition.shape == (1, stage.condition_size) == (1, 2 * 8 + 3)
    assert torch.equal(
        stage.coefficients(torch.zeros(1, 52), condition), torch.zeros(1, 4)
    )
    inputs = [("weights", ["batch", 52]), ("condition", [1, stage.condition_size])]
    # per member: its first layer's share of w, then its two hidden layers
    per_frame = _linear_ops(
        ResidualCoefficients(stage), inputs, [("coefficients", ["batch", 4])]
    )
    assert per_frame == 3 * stage.sizes.members


def test_local_features_carry_the_gravity_load_of_the_baselines(small) -> None:
    folder, _ = small
    run = Run(folder / "run-local", RunConfig(str(folder), "test", seed=3))
    local = LocalLinear(3, run.specs, 3)
    names = [s.name for s in run.specs]
    p = np.tile(np.array([s.default_value for s in run.specs], np.float32), (3, 1))
    p[1, names.index("gravity_strength")] = 2.0
    p[2, names.index("gravity_tilt")] = 30.0
    x = local.features(torch.from_numpy(p)).numpy()
    assert x.shape == (3, 1 + len(names) + 3) and (x[:, 0] == 1).all()
    scaling = ParameterScaling.of(run.data.manifest)
    cols = [scaling.params.names.index(n) for n in names]
    full = np.tile(scaling.params.defaults(), (3, 1))
    full[:, cols] = p
    assert np.allclose(x[:, -3:], scaling.gravity_load(full), atol=1e-6)


def test_region_means_are_inputs_of_every_vertex() -> None:
    from softdeca_train.models.parameters import load_parameter_specs
    from softdeca_train.models.synthetic import TEST_PARAMETERS

    specs = load_parameter_specs(TEST_PARAMETERS)
    loc = [i for i, s in enumerate(specs) if s.localisable]
    labels = np.array([0, 0, 1, 1, 2, 2])
    plain = LocalLinear(6, specs, 3)
    local = LocalLinear(6, specs, 3, regions=labels)
    assert local.table.shape[1] - plain.table.shape[1] == 3 * len(loc)
    p = torch.tensor([[s.default_value for s in specs]] * 6)
    f = local.features(p)
    # every vertex sees each region's mean; at a constant field that is the own value
    own = f[:, 1 : 1 + len(specs)][:, loc]
    np.testing.assert_allclose(f[:, -3 * len(loc) :].numpy(), own.repeat(1, 3).numpy())
    q = p.clone()
    s0 = specs[loc[0]]
    q[4:, loc[0]] = (
        s0.minimum if s0.default_value != s0.minimum else s0.maximum
    )  # region 2 only
    g = local.features(q)
    assert torch.equal(g[:, 1 : 1 + len(specs)][:4], f[:, 1 : 1 + len(specs)][:4])
    assert (g[:4, -3 * len(loc) :] != f[:4, -3 * len(loc) :]).any(dim=1).all()
    with pytest.raises(ValueError, match="one label per element"):
        LocalLinear(5, specs, 3, regions=labels)
    # only the named parameters are inputs; a region labelled -1 is in no mean
    taken = [specs[i].name for i in loc[:2]]
    some = LocalLinear(
        6, specs, 3, regions=np.array([0, 0, 1, 1, -1, -1]), inputs=taken
    )
    assert some.table.shape[1] == 1 + 2 + 3 + 2 * 2
    q = p.clone()
    q[4:, loc[0]] = (
        s0.minimum if s0.default_value != s0.minimum else s0.maximum
    )  # the unnumbered region only
    h = some.features(q) - some.features(p)
    assert torch.equal(h[:4], torch.zeros_like(h[:4])) and (h[4:, 1] != 0).all()
    with pytest.raises(ValueError, match="no parameters"):
        LocalLinear(6, specs, 3, inputs=("no_such_parameter",))


def test_a_run_on_the_rest_physics_has_no_region_means(small, tmp_path) -> None:
    """The physics at prepare carries a region's rest response in such a run: the vertex stage
    keeps its own and averaged parameters but reads no region's mean."""
    folder, _ = small
    for rest_changes in (False, True):
        cfg = RunConfig(str(folder), "test", seed=3, rest_changes=rest_changes)
        run = Run(tmp_path / f"run-{rest_changes}", cfg)
        assert run.definition.skin_regions is not None
        local = SoftDecaHybrid(run.definition, run.specs, run.sizes).f_ph_v.local
        assert local is not None and local.smoothing is not None
        assert bool(local.regional) is not rest_changes


def test_only_the_tissues_weights_reach_the_expression_slots(small) -> None:
    from softdeca_train.models.networks import EXPRESSION_PARAMETERS, HyperNetwork

    folder, _ = small
    run = Run(folder / "run-slots", RunConfig(str(folder), "test", seed=3))
    names = [s.name for s in run.specs]
    hyper = HyperNetwork(3, run.specs, run.sizes, 3, 1e-3, local_linear=True, slots=2)
    local = hyper.local
    assert local is not None and local.slot_table is not None
    assert [names[i] for i in local.expression] == [
        n for n in names if n in EXPRESSION_PARAMETERS
    ]
    with torch.no_grad():
        local.slot_table.normal_()
        hyper.body.rest[-1][-1].weight.zero_()  # the MLP's share off, as at the start
        hyper.body.rest[-1][-1].bias.zero_()
    p = torch.tensor([[s.default_value for s in run.specs]] * 3)
    h = torch.zeros(1, run.sizes.identity)
    base = hyper(p, h)
    for name in ("gravity_strength", "target_volume", "w_soft_strain"):
        q = p.clone()
        s = run.specs[names.index(name)]
        q[:, names.index(name)] = s.maximum
        change = (hyper(q, h) - base).abs().amax(dim=(0, 2))  # per latent slot
        # the expression slots move with the tissues' weights only; the other slots of z
        # (beyond the constant one and those two) never move with a local parameter change
        assert (change[:2] > 0).all() == (name in EXPRESSION_PARAMETERS), name
        assert torch.equal(change[2:-1], torch.zeros_like(change[2:-1]))


def _assert_is_the_ridge_fit(model: SoftDecaHybrid, run: Run, ridge: float) -> list:
    """The start's per-vertex solution against an independent float64 fit on a few vertices;
    returns the train batches."""
    batches = list(run.data.batches("static", "train"))
    picked = np.arange(0, model.n_vertices, 997)  # an independent fit on a few vertices
    xs, ys = [], []
    local = model.f_ph_v.local
    # the tissues' weights are among the specs: the start has its expression terms
    assert local is not None and local.slots > 0
    width = (
        model.f_ph_v.latent
        - 1
        + local.table.shape[1]
        + local.slots * len(local.expression)
    )
    for b in batches:
        # the start's final fit: on z's codes (fixed by the first fit), the local features and
        # the leading codes times the expression-dependent parameters
        x = model.code_features(b.weights, b.vertex_parameters(model.n_vertices))
        assert x.shape[-1] == width
        xs.append(x[picked].numpy())
        ys.append(((b.T - b.S).transpose(0, 1)[picked] / CM).double().numpy())
    x, y = (
        np.concatenate(xs, axis=1),
        np.concatenate(ys, axis=1),
    )  # (n, frames, d), (n, frames, 3)
    with torch.no_grad():
        for b in batches[:2]:
            got = (model.predict(b) - b.S)[:, picked].numpy()
            xb = model.code_features(b.weights, b.vertex_parameters(model.n_vertices))
            for j, vtx in enumerate(picked):
                gram = x[j].T @ x[j]
                lam = ridge * np.trace(gram) / len(gram)
                coef = np.linalg.solve(gram + lam * np.eye(len(gram)), x[j].T @ y[j])
                want = CM * (xb[vtx].numpy() @ coef)  # (B, 3) metres
                below(
                    np.abs(got[:, j] - want).max(),
                    2e-6,
                    "the model's float32 ridge solution against numpy's float64 solve",
                    what=f"vertex {vtx} m",
                )
    return batches


def test_a_frame_timing_leaves_later_fits_right(small, monkeypatch) -> None:
    """The report times each model's frame at one thread. Lowering torch's thread count and
    raising it again in one process left later closed-form fits in it wrong (by 0.2 mm), so the
    timing never changes this process's count: after it the start is still the ridge fit."""
    folder, _ = small
    run = Run(folder / "run-hybrid-timed", RunConfig(str(folder), "test", seed=3))
    model = SoftDecaHybrid(run.definition, run.specs, replace(run.sizes, latent=53))
    changed: list[int] = []
    real = torch.set_num_threads
    monkeypatch.setattr(
        torch, "set_num_threads", lambda n: (changed.append(n), real(n))
    )
    threads = torch.get_num_threads()
    batch = next(iter(run.data.batches("static", "test")))
    assert time_per_frame(model, batch, repeats=2) > 0
    assert changed == [] and torch.get_num_threads() == threads
    ridge = 1e-3
    model.init_from_dataset(run.data, progress=False, ridge=ridge)
    _assert_is_the_ridge_fit(model, run, ridge)


def test_the_start_is_the_per_vertex_ridge_fit(small) -> None:
    folder, _ = small
    run = Run(folder / "run-hybrid", RunConfig(str(folder), "test", seed=3))
    # latent 53: the w part keeps its full rank 52, so the start is the fit itself
    model = SoftDecaHybrid(run.definition, run.specs, replace(run.sizes, latent=53))
    ridge = 1e-3
    model.init_from_dataset(run.data, progress=False, ridge=ridge)
    batches = _assert_is_the_ridge_fit(model, run, ridge)
    # and it is a correction: closer to T than S_t on the train frames
    with torch.no_grad():
        b = batches[0]
        assert (model.predict(b) - b.T).norm(dim=-1).mean() < (b.S - b.T).norm(
            dim=-1
        ).mean()
    # a parameter static frames hold at its default (the dynamics, the tracking weights) is no
    # input of the vertex stage: turning it leaves a static frame where it was
    names = [s.name for s in run.specs]
    held = [n for n in FIXED["static"] if n in names]
    assert held
    with torch.no_grad():
        before = model.predict(b)
        for name in held:
            spec = run.specs[names.index(name)]
            q = b.p.clone()
            q[:, names.index(name)] = (
                spec.maximum if spec.default_value != spec.maximum else spec.minimum
            )
            moved = replace(b, p=q, p_faces=None, p_vertices=None)
            if b.p_vertices is not None:
                moved = replace(
                    moved, p_vertices=_with(b.p_vertices, names.index(name), q)
                )
                moved = replace(moved, p_faces=_with(b.p_faces, names.index(name), q))
            assert torch.equal(model.predict(moved), before), name


def _with(
    field: torch.Tensor | None, column: int, p: torch.Tensor
) -> torch.Tensor | None:
    """A per-element parameter field with one column set to p's value."""
    if field is None:
        return None
    out = field.clone()
    out[:, column] = p[0, column]
    return out


def test_a_run_with_contrasts_fits_the_residual_stage_on_their_pairs(
    small, tmp_path
) -> None:
    from softdeca_train.data.config import GenerateConfig, RunSettings
    from softdeca_train.data.generate import generate

    folder, _ = small
    contrasts = tmp_path / "contrasts"
    cfg = GenerateConfig(
        static=8, dynamic=0, sparse=0, level=2, frames_per_params=1, params_per_identity=4,
        test_share=0.0, seed=9, contrasts=True,
    )  # fmt: skip
    generate(cfg, RunSettings(out=contrasts, workers=1, progress=False))
    run = Run(
        tmp_path / "run",
        RunConfig(str(folder), "test", seed=3, contrasts=str(contrasts)),
    )
    assert run.contrasts is not None
    # a dataset without contrasts is refused as one
    plain = Run(
        tmp_path / "plain",
        RunConfig(str(folder), "test", seed=3, contrasts=str(folder)),
    )
    with pytest.raises(ValueError, match="--contrasts"):
        _ = plain.contrasts
    model = SoftDecaHybrid(run.definition, run.specs, run.sizes)
    assert model.f_r is not None
    seen = {}
    fit = model.f_r.fit

    def spy(weights, features, residual, cfg, progress=True, pairs=None):
        seen.update(frames=len(weights), pairs=pairs)
        return fit(weights, features, residual, cfg, progress, pairs)

    model.f_r.fit = spy  # type: ignore[method-assign]
    kept = run.data.left_out("static", "train")["kept"]
    model.fit_residual(run.data, kept, False, run.contrasts)
    # 2 shards of one frame at 4 parameter sets: each shard's 3 later sets against its first
    assert seen["frames"] == kept + 8 and seen["pairs"].shape == (6, 2)


class _Alternate:
    """Every other static train batch of a dataset (the even or the odd ones), as a dataset."""

    def __init__(self, data, odd: bool) -> None:
        self.data, self.odd = data, odd

    def batches(self, kind: str, split: str, rng=None):
        for i, b in enumerate(self.data.batches(kind, split)):
            if i % 2 == self.odd:
                yield b

    def left_out(self, kind: str, split: str) -> dict:
        return {"kept": sum(b.frames for b in self.batches(kind, split))}


def _drawn_again(folder, out, **config):
    """A copy of a dataset whose manifest says it was generated with `config` changed."""
    shutil.copytree(folder, out, ignore=shutil.ignore_patterns("run-*"))
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["header"]["config"].update(config)
    (out / "manifest.json").write_text(json.dumps(manifest))
    return out


def test_more_static_data_joins_the_closed_form_start(small, tmp_path) -> None:
    folder, _ = small
    drawn = json.loads((folder / "manifest.json").read_text())["header"]["config"]
    seed, level = drawn["seed"], drawn["level"] + 1
    other = _drawn_again(folder, tmp_path / "other", seed=seed + 1)
    run = Run(
        tmp_path / "run-more",
        RunConfig(str(folder), "test", seed=3, more_static=[other]),
    )
    # run.json keeps the list; reopened, the run has the same configuration and datasets
    again = Run(tmp_path / "run-more")
    assert again.config.more_static == (str(other),)
    assert [d.folder for d in again.more_static] == [other]
    # the evaluation report counts the frames it leaves out and names it
    from softdeca_train.train.report import _more_static_clause, left_out_counts

    counts = left_out_counts(again)
    assert counts[f"static/train of {other.name}"] == again.more_static[0].left_out(
        "static", "train"
    )
    assert counts[f"static/train of {other.name}"]["kept"] > 0
    assert f"`{other.name}`" in _more_static_clause(again)
    assert (
        _more_static_clause(Run(tmp_path / "plain", RunConfig(str(folder), "test")))
        == ""
    )
    with pytest.raises(ValueError, match="more static data"):
        Run(tmp_path / "run-more", RunConfig(str(folder), "test", seed=3))
    # drawn otherwise, or from the same identities: refused
    finer = _drawn_again(folder, tmp_path / "level", seed=seed + 2, level=level)
    for data, problem in ((finer, f"level {level}"), (folder, f"seed {seed} again")):
        bad = Run(
            tmp_path / f"run-{problem}",
            RunConfig(str(folder), "test", more_static=[data]),
        )
        with pytest.raises(ValueError, match=problem):
            _ = bad.more_static
    sizes = replace(run.sizes, latent=53)

    def start(data, more=()) -> torch.Tensor:
        model = SoftDecaHybrid(run.definition, run.specs, sizes)
        model.f_r = (
            None  # the closed-form vertex stage only (the residual stage is stochastic)
        )
        model.init_from_dataset(data, progress=False, more=more)
        local = model.f_ph_v.local
        assert local is not None
        return local.table.detach().clone()

    whole = start(run.data)
    even, odd = _Alternate(run.data, False), _Alternate(run.data, True)
    # half the frames as the dataset and the other half as more data: the fit on all of them
    # (on half of them alone it would differ: the ridge fit is not that of its half)
    assert torch.allclose(start(even, [odd]), whole, rtol=1e-4, atol=1e-6)
