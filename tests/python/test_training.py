"""Training at the smallest scale: the small dataset of conftest (LHM level 2, 16
static, 2 dynamic, 16 sparse frames) and the tiny "test" network sizes. Each model trains a
few dozen steps and must lower its error on the frames it trained on; the bundle pipeline runs
end to end and its ONNX files agree with torch; the committed bundle loads in onnxruntime."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch
from bounds import below
from softdeca_train.data.ranges import DEFAULT_PROFILE, profile_ranges
from softdeca_train.models.bundle import OnnxNetworks, read_manifest
from softdeca_train.models.networks import BETA_MAX
from softdeca_train.parameters import load_parameters
from softdeca_train.paths import REPO_ROOT
from softdeca_train.train.batches import index_ranges
from softdeca_train.train.bundle_stages import BundleBudget, stage_config, train_bundle
from softdeca_train.train.loop import LoopConfig, train
from softdeca_train.train.run import Run, RunConfig
from softdeca_train.train.trainable import vertex_error

COMMITTED = REPO_ROOT / "models" / "softdeca-default"


def _check_export_deviation(manifest: dict) -> None:
    """ONNX (onnxruntime) against torch at export: 1e-4 on the hypernetworks' outputs (DG
    entries, metres), 1e-3 on the encoders' codes (identity h, the landmark code: unit
    variance, and their first layers sum hundreds of inputs, so float32 summation order shows;
    measured up to 1.3e-4)."""
    dev = dict(manifest["export_check_max_abs"])
    below(
        max(dev.pop(k) for k in ("identity_encoder", "sparse.f_l")),
        1e-3,
        "float32 sums of hundreds of unit-variance inputs, in two runtimes' orders",
        what="codes",
    )
    below(
        max(dev.values()), 1e-4, "float32 DG entries (metres) in two runtimes", what="m"
    )


@pytest.fixture(scope="module")
def run(small, tmp_path_factory) -> Run:
    folder, _ = small
    torch.set_num_threads(2)
    return Run(tmp_path_factory.mktemp("run"), RunConfig(str(folder), "test", seed=3))


def _train_error(run: Run, model: torch.nn.Module) -> float:
    with torch.no_grad():
        errs = [
            float(vertex_error(model.predict(b), b.T).mean())
            for b in run.data.batches(model.kind, "train", None, 8)
        ]
    return float(np.mean(errs))


@pytest.mark.parametrize(
    "name", ["softdeca", "softdeca-dt", "sparse", "mlp-equal-time", "face-mlp"]
)
def test_static_models_learn(run: Run, name: str) -> None:
    # The initial weights from a fixed seed: otherwise they depend on what the tests before
    # drew (the MLP learned 77 % in 40 steps from one start and 9 % from another).
    torch.manual_seed(0)
    before = _train_error(run, run.build(name))
    run.train(name, LoopConfig(steps=40, lr=3e-3, lr_end=1e-3, seed=1), progress=False)
    after = _train_error(run, run.load(name))
    below(
        after / before,
        0.9,
        "40 steps from a fixed seed learn 20-80 % on every kernel family",
        what=f"{name} after/before",
    )


def _mean_mm(offsets: torch.Tensor) -> float:
    """Mean vertex distance (mm) of (frames, V * 3) offsets in metres."""
    return float(offsets.reshape(len(offsets), -1, 3).norm(dim=2).mean()) * 1000


def test_sparsesoftdeca_starts_at_its_closed_form(run: Run) -> None:
    """Before any step, SparseSoftDECA on clean landmarks is the deformations' principal
    components read off the landmarks by ridge regression, each frame from the data's donor and
    from ARKit's reference face: with fewer such rows than landmark coordinates the regression
    interpolates, so on those frames it is as close to the physics as the components themselves
    from either donor, where the untrained model is far."""
    from dataclasses import replace

    from softdeca_train.landmarks.arkit_reference import ArkitFace
    from softdeca_train.train.registry import MODELS

    torch.manual_seed(0)
    model = MODELS["sparse-no-noise"].make(run.definition, run.specs, run.sizes)
    batches = list(run.data.batches("sparse", "train", None, 8))
    y = torch.cat([(b.T - b.neutral).reshape(b.frames, -1) for b in batches]).double()
    assert 2 * len(y) < 3 * len(run.definition.landmarks.triangle)
    _, _, vt = torch.linalg.svd(y, full_matrices=False)
    modes = vt[: run.sizes.latent]
    floor = _mean_mm(y - (y @ modes.T) @ modes)
    face = ArkitFace.load()
    phone = [
        replace(b, landmarks_clean=model.arkit_landmarks(b, face)) for b in batches
    ]

    def error(frames: list) -> float:
        with torch.no_grad():
            out = torch.cat([model.predict(b) - b.neutral for b in frames])
            return _mean_mm(out.reshape(y.shape) - y)

    before = error(batches)
    model.init_from_dataset(run.data, progress=False)
    for frames, donor in ((batches, "the data's donor"), (phone, "ARKit's face")):
        below(
            error(frames),
            1.05 * floor + 1e-3,
            "the regression interpolates the modes' coefficients (ridge 1e-6 of the inputs' "
            "scale)",
            what=f"mm, {donor}",
        )
    below(
        error(batches), 0.5 * before, "the untrained model is nowhere near", what="mm"
    )
    # at rest ARKit's face lands on the head's own neutral landmarks
    rest = replace(batches[0], weights=torch.zeros_like(batches[0].weights))
    own = model.neutral_landmarks(rest.neutral)
    assert torch.allclose(
        model.arkit_landmarks(rest, face), own.expand(rest.frames, -1, -1), atol=1e-6
    )


def test_a_runs_summary_says_how_many_train_frames_it_could_read(run: Run) -> None:
    """The stage summary (and so a bundle's training record) counts the train frames the
    dataset listed when the run started and when it ended."""
    summary = run.train("sparse-no-noise", LoopConfig(steps=2, seed=1), progress=False)
    kept = run.data.left_out("sparse", "train")["kept"]
    assert summary["train_frames_listed"] == {
        "kind": "sparse",
        "at_start": kept,
        "at_end": kept,
    }
    assert kept > 0


def test_dynamics_learn_and_stay_stable(run: Run) -> None:
    if not run.finished("softdeca"):
        run.train("softdeca", LoopConfig(steps=20, seed=1), progress=False)
    before = _train_error(run, run.build("softdeca-dynamics"))
    run.train(
        "softdeca-dynamics", LoopConfig(steps=30, lr=1e-2, seed=1), progress=False
    )
    model = run.load("softdeca-dynamics")
    after = _train_error(run, model)
    assert after < before
    b = next(run.data.batches("dynamic", "train", None))
    alpha, beta, gamma = model.f_dyn(b.p.expand(b.neutral.shape[0], -1), b.h)
    assert torch.allclose(gamma + 2 * alpha - beta, torch.ones_like(gamma), atol=1e-6)
    assert float(beta.detach().min()) >= 0 and float(beta.detach().max()) <= BETA_MAX


def test_hypernetwork_learning_rate_factor_reaches_the_optimiser(
    run: Run, tmp_path
) -> None:
    """LoopConfig.hyper_lr overrides the model's factor for its hypernetworks only: at 0,
    f_ph stays as initialised while f_w trains."""
    model = run.build("softdeca-dt")
    before = {k: v.clone() for k, v in model.state_dict().items()}
    train(
        model,
        run.data,
        LoopConfig(steps=3, seed=1, hyper_lr=0.0),
        tmp_path,
        "sd",
        False,
    )
    after = model.state_dict()
    moved = {k for k in before if not torch.equal(before[k], after[k])}
    assert moved and all(k.startswith("f_w.") for k in moved), sorted(moved)
    assert model.lr_scales() == {"f_ph.": model.hyper_lr}


def test_a_checkpoint_of_another_architecture_is_refused_clearly(run: Run) -> None:
    if not run.finished("softdeca-dt"):
        run.train("softdeca-dt", LoopConfig(steps=2, seed=1), progress=False)
    other = Run(run.folder.parent / "other-arch", run.config)
    shutil.copy(run.checkpoint("softdeca-dt"), other.checkpoint("softdeca"))
    with pytest.raises(ValueError, match="another version"):
        other.load("softdeca")


def test_a_step_can_average_several_groups(run: Run, tmp_path) -> None:
    model = run.build("softdeca-vertex")
    cfg = LoopConfig(steps=3, seed=1, groups=2)
    summary = train(model, run.data, cfg, tmp_path, "v", False)
    assert summary["steps"] == 3
    assert len((tmp_path / "v.log.jsonl").read_text().splitlines()) == 3
    with pytest.raises(ValueError, match="at least 1"):
        train(
            model, run.data, LoopConfig(steps=1, groups=0), tmp_path / "x", "v", False
        )


def test_no_correction_is_the_linear_blend_on_every_test_frame_of_its_kind(
    run: Run,
) -> None:
    from softdeca_train.train.batches import EVERY_FRAME
    from softdeca_train.train.evaluate import measure, no_correction

    for kind in ("static", "dynamic"):
        errors = [
            vertex_error(b.S, b.T).reshape(-1, b.T.shape[-2])
            for b in run.data.batches(kind, "test", None, 8, EVERY_FRAME)
        ]
        frames = torch.cat(errors)
        got = measure(run, "nc", no_correction(kind)).summary()
        assert got["frames"] == len(frames) > 0
        assert got["mean_mm"] == pytest.approx(
            1e3 * float(frames.double().mean()), rel=1e-9
        )


def test_training_resumes_from_its_checkpoint(run: Run) -> None:
    cfg = LoopConfig(steps=6, seed=2)
    run.train("softdeca-vertex", cfg, progress=False)
    log = run.folder / "softdeca-vertex.log.jsonl"
    assert len(log.read_text().splitlines()) == 6
    # a longer budget continues at step 6 (the checkpoint carries the configuration, so the
    # same configuration is required: a different one is refused with a clear message)
    with pytest.raises(ValueError, match="another configuration"):
        run.train("softdeca-vertex", LoopConfig(steps=9, seed=2), progress=False)
    state = torch.load(run.checkpoint("softdeca-vertex"), weights_only=False)
    assert state["step"] == 6 and state["done"]


def test_softdeca_step_budget_overrides_only_its_own_stage() -> None:
    budget = BundleBudget(softdeca_steps=0).scaled(0.5)
    own = stage_config("softdeca", budget, 0)
    assert own.steps == 0 and own.minutes is None  # its closed-form start alone
    other = stage_config("sparse", budget, 0)
    assert other.minutes == 15.0 and other.steps > 1000
    assert stage_config("softdeca", BundleBudget(), 0).minutes == 60.0


def test_bundle_pipeline_exports_a_bundle_onnxruntime_agrees_with(
    run: Run, tmp_path
) -> None:
    bundle = train_bundle(
        run,
        tmp_path / "bundle",
        BundleBudget(identity_steps=30, steps=4),
        "test",
        False,
    )
    m = read_manifest(bundle)
    assert not m["untrained"]
    _check_export_deviation(m)
    errors = m["errors"]
    for key in ("no_correction_static", "softdeca_static"):
        assert np.isfinite(errors[key]["mean_mm"]) and errors[key]["frames"] > 0
    # the small dataset's sparse test frames may all fail the solver filter: then it says so
    sparse = errors["sparse_other_head_noise"]
    assert sparse["frames"] == 0 or np.isfinite(sparse["mean_mm"])
    # the networks accept only the ranges the data sampled (the default profile: the control
    # ranges of plugin/data/parameters.json), and take no parameter that is no control
    ranges = profile_ranges(load_parameters(), DEFAULT_PROFILE)
    for name in ("w_target", "cranium_scale_x"):
        spec = next(p for p in m["parameters"] if p["name"] == name)
        assert (spec["min"], spec["max"]) == ranges[name]
    names = {p["name"] for p in m["parameters"]}
    assert names == set(load_parameters().controls().names)
    nets = OnnxNetworks(bundle)
    assert nets.has("softdeca") and nets.has("sparse")
    _check_take_frames(run, m["training"]["dataset"]["train_take_frames"])


def _check_take_frames(run: Run, record: dict) -> None:
    """The training record names every take frame the kept train instances came from."""
    names = [t["name"] for t in run.data.manifest["header"]["takes"]]
    want: dict[str, set[int]] = {}
    for kind in run.data.manifest["dataset"]["kinds"]:
        for b in run.data.batches(kind, "train"):
            for t, i in zip(b.source_take, b.source_index, strict=True):
                if t >= 0:
                    want.setdefault(names[int(t)], set()).add(int(i))
    assert want, "the small dataset draws frames from the takes"
    got = {}
    for name, entry in record.items():
        frames: set[int] = set()
        for r in entry["frames"].split(","):
            lo, _, hi = r.partition("-")
            frames.update(range(int(lo), int(hi or lo) + 1))
        got[name] = frames
    assert got == want
    assert index_ranges([0, 1, 2, 4, 7, 8]) == "0-2,4,7-8" and index_ranges([]) == ""


def test_bundle_at_softdecas_start_is_exported_and_evaluated(small, tmp_path) -> None:
    """SoftDECA kept at its closed-form start (0 steps, as the committed bundle): the bundle
    exports, and the evaluation report, whose training curves have no rows for it, says so."""
    from softdeca_train.train.report import write_report

    folder, _ = small
    # one member in the residual stage (--residual-members): the run keeps it, the bundle
    # runs it (its condition is each member's first-layer share, then c(0))
    fresh = Run(
        tmp_path / "run", RunConfig(str(folder), "test", seed=4, residual_members=1)
    )
    assert Run(tmp_path / "run").sizes.residual_members == 1
    with pytest.raises(ValueError, match="residual members"):
        Run(
            tmp_path / "run", RunConfig(str(folder), "test", seed=4, residual_members=2)
        )
    bundle = train_bundle(
        fresh,
        tmp_path / "bundle",
        BundleBudget(steps=2, softdeca_steps=0),
        "test",
        False,
    )
    assert (
        json.loads((fresh.folder / "softdeca.summary.json").read_text())["steps"] == 0
    )
    _check_export_deviation(read_manifest(bundle))
    sizes = fresh.sizes
    assert read_manifest(bundle)["residual_stage"]["condition"] == (
        sizes.residual_hidden + sizes.residual_modes
    )
    # a new run is exact at rest (rest gate 0): the exported networks give no correction at
    # w = 0, whatever their weights, in the bundle as the runtime runs it
    assert fresh.config.rest_gate == 0.0
    nets = OnnxNetworks(bundle)
    zero = np.zeros((1, 52), np.float32)
    # float32 rounding of the network at rest
    assert np.abs(nets.f_w(zero)).max() < 1e-6
    assert np.abs(nets.f_w(np.full((1, 52), 0.3, np.float32))[:, :-1]).max() > 1e-4
    readme = write_report(fresh, bundle, tmp_path / "report", progress=False)
    doc = json.loads((tmp_path / "report" / "evaluation.json").read_text())
    assert np.isfinite(doc["errors"]["softdeca"]["mean_mm"])
    assert "closed-form start, no steps" in readme.read_text()
    assert (tmp_path / "report" / "training_curves.png").is_file()


@pytest.mark.skipif(not COMMITTED.is_dir(), reason="no committed bundle yet")
def test_committed_bundle_is_trained_loads_and_says_what_made_it() -> None:
    m = read_manifest(COMMITTED)
    assert not m["untrained"]
    assert m["training"]["command"].startswith("python -m softdeca_train train-bundle")
    _check_export_deviation(m)
    nets = OnnxNetworks(COMMITTED)
    z = nets.f_w(np.zeros((1, 52), np.float32))
    assert z.shape == (1, m["latent_size"]) and np.isfinite(z).all()
    readme = json.loads((COMMITTED / "manifest.json").read_text())["training"][
        "dataset"
    ]
    assert Path(
        REPO_ROOT / "docs" / "datasets" / readme["name"] / "manifest.json"
    ).is_file()


def test_identity_encoder_recovers_identities_exactly(template) -> None:
    from softdeca_train.models.networks import FULL_SIZES
    from softdeca_train.train.identity import IdentityConfig, train_identity_encoder

    _, errors = train_identity_encoder(
        template, FULL_SIZES, IdentityConfig(steps=0), False
    )
    # h has unit variance; the closed form recovers it to float32 rounding
    below(
        errors["coefficients_rms"],
        1e-3,
        "closed-form least squares in float32",
        what="rms",
    )
    below(errors["neutral_mm"], 1e-3, "closed-form least squares in float32", what="mm")


def test_contrast_pairs_join_each_frame_to_its_base() -> None:
    from softdeca_train.train.trainable import contrast_pairs

    a, b = b"a", b"b"
    keys = [
        (-1, -1, b""),
        (7, 3, a),
        (7, 1, a),
        (7, 2, a),
        (7, 1, b),
        (8, 5, a),
        (8, 4, a),
    ]
    pairs = {tuple(x) for x in contrast_pairs(keys).tolist()}
    # identity 7, weights a: base param 1 (frame 2); weights b alone; identity 8: base frame 6
    assert pairs == {(1, 2), (3, 2), (5, 6)}
    assert contrast_pairs([(-1, -1, b"")]).shape == (0, 2)


def test_a_retrained_sparsesoftdeca_replaces_the_bundles_own(
    run: Run, tmp_path
) -> None:
    """bundle-sparse: the run's SparseSoftDECA (here the code-noise variant) replaces the
    bundle's landmark encoder and per-vertex hypernetwork, what onnxruntime runs agrees with
    torch, SoftDECA's files are untouched, and the manifest says what trained the new ones."""
    from softdeca_train.models.bundle import replace_networks
    from softdeca_train.models.networks import LandmarkEncoder
    from softdeca_train.train.bundle_stages import replace_sparse

    bundle = train_bundle(
        run, tmp_path / "bundle", BundleBudget(steps=4), "test", False
    )
    before = read_manifest(bundle)
    run.train("sparse-code-noise", LoopConfig(steps=6, lr=3e-4, seed=1), progress=False)
    replace_sparse(run, bundle, "sparse-code-noise", "replace", progress=False)
    after = read_manifest(bundle)
    _check_export_deviation(after)
    for name, spec in after["networks"].items():
        changed = spec["sha256"] != before["networks"][name]["sha256"]
        assert changed == (name in ("sparse.f_l", "sparse.f_ph_v")), name
    record = after["training"]["replaced"][-1]
    assert record["model"] == "sparse-code-noise" and record["command"] == "replace"
    assert after["errors"]["sparse_other_head"] == record["errors"]["sparse_other_head"]
    assert after["errors"]["softdeca_static"] == before["errors"]["softdeca_static"]
    assert after["description"].startswith(before["description"])
    assert after["description"].endswith(
        "replaced since: sparse.f_l, sparse.f_ph_v (sparse-code-noise on "
        f"{record['dataset']['name']}), see training.replaced"
    )
    model = run.load("sparse-code-noise")
    nets = OnnxNetworks(bundle)
    x = np.random.default_rng(0).standard_normal(
        (3, 3 * len(model.lm_bary)), np.float32
    )
    with torch.no_grad():
        want = model.f_l(torch.from_numpy(x)).numpy()
    assert np.abs(nets.f_l(x) - want).max() < 1e-3
    # the contract stays the manifest's: a network of another shape, or one the bundle does
    # not have, is refused and leaves the bundle as it was
    wrong = LandmarkEncoder(len(model.lm_bary) + 1, run.sizes)
    for modules in ({"sparse.f_l": wrong}, {"softdeca.f_nothing": model.f_l}):
        with pytest.raises(ValueError):
            replace_networks(bundle, modules, {})
    assert read_manifest(bundle) == after
    # the report's SparseSoftDECA rows are measured again on this run; the rest stays
    from softdeca_train.train.report import SPARSE_HEADING, refresh_sparse

    report = tmp_path / "report"
    report.mkdir()
    kept = {"mean_mm": 0.1, "frames": 3}
    doc = {"errors": {"softdeca": kept, "sparse/same_head": kept}, "ms_per_frame": {}}
    (report / "evaluation.json").write_text(
        json.dumps({**doc, "bundle": {"softdeca": kept}})
    )
    (report / "README.md").write_text(
        f"# R\n\n{SPARSE_HEADING}\n\nold\n\n## Next\n\nkept\n"
    )
    refresh_sparse(run, bundle, report, "sparse-code-noise", progress=False)
    doc = json.loads((report / "evaluation.json").read_text())
    assert doc["errors"]["softdeca"] == kept and doc["bundle"]["softdeca"] == kept
    assert (
        doc["errors"]["sparse-code-noise/other_head"]
        == record["errors"]["sparse_other_head"]
    )
    assert doc["errors"]["sparse/same_head"] != kept and "sparse" in doc["bundle"]
    text = (report / "README.md").read_text()
    assert "old" not in text and text.endswith("## Next\n\nkept\n")
    assert "the same on a perturbed identity code" in text


def test_code_noise_perturbs_training_only(run: Run) -> None:
    from softdeca_train.train.registry import MODELS

    model = MODELS["sparse-code-noise"].make(run.definition, run.specs, run.sizes)
    batch = next(iter(run.data.batches("sparse", "train", None, 4)))
    model.train()
    assert not torch.equal(model.predict(batch), model.predict(batch))
    model.eval()
    assert torch.equal(model.predict(batch), model.predict(batch))


def test_the_report_names_what_it_did_not_measure() -> None:
    from types import SimpleNamespace as NS

    from softdeca_train.train import report as r

    cfg = {"header": {"config": {"sparse": 8, "landmark_noise_mm": 1.0}}}
    run = NS(
        folder="r", config=NS(dataset="d", rest_changes=True), data=NS(manifest=cfg)
    )
    assert "S_t + Pd" in r._no_correction_label(run)
    e = {"sparse/same_head": {"mean_mm": None, "frames": 0}}
    text = "\n".join(r.sparse_section(run, e, {"mean_mm": None}, {"sparse.f_l": "c"}))
    assert (
        r.NOTHING_MEASURED.format(kind="sparse test frame", model="SparseSoftDECA")
        in text
    )
    assert "| the bundle end" not in text and "measures them" not in text
