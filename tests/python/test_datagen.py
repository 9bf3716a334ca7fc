"""Training data generation: a small dataset of every kind end to end, its format,
splits, loader and report; planning, personalisation and configuration errors.

Scale: the small dataset is LHM level 2 (162 vertices per wrap), 16 static + 16 sparse
frames and 2 dynamic sequences of 4 frames (2 lead-in), on 2 worker processes; the
acceptance-size run (a few hundred instances per kind) is measured separately (see
docs/benchmarks.md, datagen)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from conftest import SMALL
from softdeca_train.data.blend import SkinBlend
from softdeca_train.data.config import KINDS, TEST, TRAIN, GenerateConfig, RunSettings
from softdeca_train.data.expressions import (
    COVERAGE,
    REDUCED_HI,
    REDUCED_LO,
    expression_sources,
    load_takes,
)
from softdeca_train.data.format import ARRAYS
from softdeca_train.data.generate import generate
from softdeca_train.data.loader import ShardDataset
from softdeca_train.data.personalise import add_noise, personalise
from softdeca_train.data.plan import FIXED, make_plan
from softdeca_train.data.ranges import fixed_outside_profile
from softdeca_train.data.shards import iter_shards, verify
from softdeca_train.landmarks import template_landmarks
from softdeca_train.parameters import load_parameters
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import REGIONS, region_labels


def _all(folder, kind: str) -> dict[str, np.ndarray]:
    parts = list(iter_shards(folder, kind))
    return {
        k: np.concatenate([p[k] for p in parts]) for k in parts[0] if parts[0][k].ndim
    }


def test_small_dataset_is_complete_and_self_describing(small) -> None:
    out, summary = small
    assert summary["complete"] and verify(out) == []
    m = json.loads((out / "manifest.json").read_text())
    assert m["header"]["config"] == SMALL.as_dict()
    assert m["runs"][-1]["code_version"]
    for kind in KINDS:
        a = _all(out, kind)
        assert (
            len(a["instance_id"])
            == SMALL.count(kind)
            == summary["kinds"][kind]["instances"]
        )
        for name, (dtype, shape, _) in ARRAYS[kind].items():
            assert a[name].dtype == np.dtype(dtype), name
            dims = shape.strip("()").replace(" ", "").split(",")
            assert a[name].ndim == len([d for d in dims if d]), name
        assert a["offsets"].shape[-2:] == (N_SKIN, 3)
        # Extreme parameter draws may stop at max_iterations: flagged, not hidden.
        assert a["converged"].dtype == bool
        assert np.all(a["estimated_error"][a["converged"]] <= SMALL.tolerance)
        # Kind-specific parameters and the ones that are no controls stay at their defaults.
        params = load_parameters()
        for name in (*FIXED[kind], *fixed_outside_profile(params, SMALL.ranges)):
            k = params.names.index(name)
            assert np.all(a["p"][:, k] == params.defaults()[k])
        params.validate(a["p"])
        if (
            kind != "dynamic"
        ):  # regional patterns: per region, p elsewhere and where none
            pr = a["p_regions"]
            assert pr.shape == (len(a["p"]), len(REGIONS), len(params.names))
            params.validate(pr)
            patterned = np.any(pr != a["p"][:, None, :], axis=(1, 2))
            rows_same = np.all(pr == a["p"][:, None, :], axis=(1, 2))
            assert np.all(patterned | rows_same)
    dyn = _all(out, "dynamic")
    assert dyn["offsets"].shape[1] == SMALL.sequence_length
    # The lead-in leaves the sequence moving: T_{-1} != T_{-2}.
    assert np.abs(dyn["prev_offsets"][:, 1].astype(np.float32)).max() > 0
    with np.load(out / m["shards"][0]["file"]) as z:
        meta = json.loads(str(z["meta"]))
    assert meta["kind"] == m["shards"][0]["kind"] and "offsets" in meta["arrays"]


def test_every_frame_is_judged_by_the_sanity_bounds(small) -> None:
    """Failures are stored per frame (bit mask) and counted per reason: nothing is hidden."""
    from softdeca_train.sim.sanity import REASONS

    out, summary = small
    frames = 0
    masks = []
    for kind in KINDS:
        a = _all(out, kind)
        frames += a["failures"].size
        masks.append(a["failures"].ravel())
    mask = np.concatenate(masks)
    assert summary["frames_judged"] == frames > 0
    assert set(summary["failures"]) == {*REASONS, "failed_frames"}
    assert summary["failures"]["failed_frames"] == int((mask > 0).sum())
    for i, reason in enumerate(REASONS):
        assert summary["failures"][reason] == int((mask & (1 << i) > 0).sum()), reason
    assert summary["failed_fraction"] == round(int((mask > 0).sum()) / frames, 6)


def test_quantisation_error_is_measured_and_small(small) -> None:
    _, summary = small
    # float16 keeps 11 significant bits: half a unit in the last place of the largest offset.
    bound = summary["max_offset_mm"] * 2.0**-11
    assert 0 < summary["max_quantisation_error_mm"] <= bound + 1e-9
    # Typical offsets are millimetres: the typical rounding error is far below a micrometre.
    assert 0 < summary["rms_quantisation_error_mm"] < 0.01


def test_train_and_test_share_no_identity_parameters_or_expressions(small) -> None:
    out, _ = small
    m = json.loads((out / "manifest.json").read_text())
    sp = m["dataset"]["splits"]
    assert not set(sp["train"]["identities"]) & set(sp["test"]["identities"])
    assert set(sp["test"]["takes"]) == set(SMALL.test_takes)
    assert not set(SMALL.test_takes) & set(sp["train"]["takes"])
    # every source's takes are used: more than one person trains
    assert len(sp["train"]["takes"]) >= 6
    names = [t["name"] for t in m["header"]["takes"]]
    test_take = [names.index(t) for t in SMALL.test_takes]
    rows = {TRAIN: [], TEST: []}
    for kind in KINDS:
        rows_kind = {}
        for a in iter_shards(out, kind):
            for s in (TRAIN, TEST):
                sel = a["split"] == s
                if sel.any():
                    rows_kind.setdefault(s, []).append(
                        {k: v[sel] for k, v in a.items() if v.ndim}
                    )
        for s in (TRAIN, TEST):
            assert s in rows_kind, f"{kind}: no {s} instances"
            rows[s] += rows_kind[s]
    cat = {
        s: {
            k: np.concatenate([r[k] if k == "p" else r[k].ravel() for r in rows[s]])
            for k in ("identity_id", "param_id", "p", "source_take", "source_index")
        }
        for s in (TRAIN, TEST)
    }
    donors = {
        s: set(
            np.concatenate([r["donor_id"] for r in rows[s] if "donor_id" in r]).tolist()
        )
        for s in (TRAIN, TEST)
    }
    ids = {s: set(cat[s]["identity_id"].tolist()) | donors[s] for s in (TRAIN, TEST)}
    assert not ids[TRAIN] & ids[TEST]
    assert not set(cat[TRAIN]["param_id"].tolist()) & set(
        cat[TEST]["param_id"].tolist()
    )
    p_rows = {s: {r.tobytes() for r in cat[s]["p"]} for s in (TRAIN, TEST)}
    assert not p_rows[TRAIN] & p_rows[TEST]
    # Real frames: the test split uses the held-out take only, train never does.
    real_test = cat[TEST]["source_take"][cat[TEST]["source_take"] != COVERAGE]
    assert np.all(np.isin(real_test, test_take))
    assert not np.any(np.isin(cat[TRAIN]["source_take"], test_take))
    # No weight vector (real or coverage) appears in both splits.
    w = {
        s: {r.tobytes() for part in rows[s] for r in part["weights"].reshape(-1, 52)}
        for s in (TRAIN, TEST)
    }
    assert not w[TRAIN] & w[TEST]


def test_plan_is_deterministic_and_ids_unique(template) -> None:
    takes = load_takes(RunSettings(out=".").takes)
    params = load_parameters()
    plans = []
    for _ in range(2):
        sources, _ = expression_sources(
            takes, SMALL.test_takes, SMALL.seed, SMALL.test_share
        )
        plans.append(make_plan(SMALL, params, sources))
    a, b = plans
    assert [s.identity_seed for s in a] == [s.identity_seed for s in b]
    for sa, sb in zip(a, b, strict=True):
        for ga, gb in zip(sa.groups, sb.groups, strict=True):
            assert np.array_equal(ga.p, gb.p)
            assert np.array_equal(ga.frames.weights, gb.frames.weights)
    ids = np.concatenate([s.instance_ids for s in a])
    assert np.array_equal(ids, np.arange(len(ids)))
    other = GenerateConfig(**{**SMALL.as_dict(), "seed": SMALL.seed + 1})
    sources, _ = expression_sources(
        takes, other.test_takes, other.seed, other.test_share
    )
    c = make_plan(other, params, sources)
    assert not np.array_equal(a[0].groups[0].p, c[0].groups[0].p)


def test_reduced_real_frames_keep_their_shape_at_a_lower_amplitude() -> None:
    takes = load_takes(RunSettings(out=".").takes)
    draws = {}
    for share in (0.0, 1.0):
        sources, _ = expression_sources(takes, SMALL.test_takes, SMALL.seed, 0.0)
        draws[share] = sources[TRAIN].frames(200, 1.0, share)
    plain, calm = draws[0.0], draws[1.0]
    assert np.array_equal(plain.source_take, calm.source_take)
    assert np.array_equal(plain.source_index, calm.source_index)
    for row, (t, i) in enumerate(
        zip(plain.source_take, plain.source_index, strict=True)
    ):
        assert np.array_equal(takes[t].weights[i], plain.weights[row])
    big = plain.weights.max(axis=1) > 0.05
    ratio = calm.weights[big].max(axis=1) / plain.weights[big].max(axis=1)
    assert np.all((ratio >= REDUCED_LO - 1e-6) & (ratio <= REDUCED_HI + 1e-6))
    # every weight of a frame is scaled alike: the expression's shape is kept
    scaled = plain.weights[big] * ratio[:, None]
    assert np.allclose(calm.weights[big], scaled, atol=1e-6)


def test_loader_streams_each_instance_once_and_rebuilds_targets(
    small, template
) -> None:
    out, _ = small
    ds = ShardDataset(out, "static", split="train", seed=3)
    loader = torch.utils.data.DataLoader(ds, batch_size=3, num_workers=2)
    seen = torch.cat([b["instance_id"] for b in loader]).tolist()
    a = _all(out, "static")
    want = (a["split"] == TRAIN) & (a["estimated_error"] <= 3 * SMALL.tolerance)
    assert sorted(seen) == sorted(a["instance_id"][want].tolist())
    every = ShardDataset(out, "static", split="all", max_error=None)
    assert len(list(every)) == len(every) == SMALL.static
    item = next(
        iter(ShardDataset(out, "static", split="all", shuffle=False, max_error=None))
    )
    i = int(np.flatnonzero(a["instance_id"] == int(item["instance_id"]))[0])
    blend = SkinBlend.of(template)
    s = blend.targets(
        template.identity_neutral(a["h"][i].astype(np.float64))[:N_SKIN],
        a["weights"][i][None],
    )[0]
    assert torch.allclose(item["S"], torch.from_numpy(s).float())
    assert torch.allclose(item["T"] - item["S"], item["offsets"], atol=1e-6)
    assert 0 <= item["p_norm"].min() and item["p_norm"].max() <= 1
    seq = next(iter(ShardDataset(out, "dynamic", split="all", max_error=None)))
    assert seq["T"].shape == (SMALL.sequence_length, N_SKIN, 3)
    assert seq["prev_T"].shape == (2, N_SKIN, 3)
    sparse = next(
        iter(ShardDataset(out, "sparse", split="all", targets=False, max_error=None))
    )
    assert sparse["landmarks"].shape == (149, 3) and "S" not in sparse


def test_sparse_landmarks_follow_the_augmentation(small, template) -> None:
    out, _ = small
    a = _all(out, "sparse")
    noise = a["landmarks"] - a["landmarks_clean"]
    sigma = SMALL.landmark_noise_mm * 1e-3
    assert abs(noise.std() - sigma) < 0.1 * sigma and abs(noise.mean()) < 0.1 * sigma
    assert np.all(a["donor_id"] != a["identity_id"])


def test_personalisation_is_exact_for_the_same_head_and_follows_a_similarity(
    template,
) -> None:
    lms = template_landmarks(template)
    blend = SkinBlend.of(template)
    neutral = template.identity_neutral(template.sample_identity(3))[:N_SKIN]
    w = np.random.default_rng(0).random((3, 52)).astype(np.float32) * 0.5
    frames = lms.evaluate(blend.targets(neutral, w))
    l0 = lms.evaluate(neutral)
    assert np.allclose(personalise(l0, frames, l0), frames, atol=1e-12)
    # A donor that is the same face rotated, scaled and moved gives the same landmarks.
    c, s = np.cos(0.3), np.sin(0.3)
    r = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    donor0, donor = 1.2 * l0 @ r.T + 0.1, 1.2 * frames @ r.T + 0.1
    assert np.allclose(personalise(donor0, donor, l0), frames, atol=1e-9)
    noisy = add_noise(frames, 1e-3, seed=5)
    assert np.allclose(noisy, add_noise(frames, 1e-3, seed=5))
    assert 0.8e-3 < (noisy - frames).std() < 1.2e-3


def test_regions_cover_s_once(template) -> None:
    labels = region_labels(template)
    assert labels.shape == (N_SKIN,)
    counts = np.bincount(labels, minlength=len(REGIONS))
    assert counts.sum() == N_SKIN and (counts > 50).all()


def test_report_counts_tet_sources_by_kind_with_the_span_of_their_figures() -> None:
    from softdeca_train.data.report import _tet_sources

    sources = {
        "carried": 781,
        "fill: the carried mesh has S up to 1.00 mm outside": 1,
        "fill: the carried mesh has S up to 2.61 mm outside": 2,
        "fill: the carried mesh has 1 inverted tets": 2,
        "fill: the carried mesh has 2 inverted tets": 1,
        "fill: the carried mesh has smallest dihedral angle 5.0 deg": 1,
    }
    assert _tet_sources(sources) == (
        "carried: 781; fill: the carried mesh has S up to 1-2.61 mm outside: 3; "
        "fill: the carried mesh has 1-2 inverted tets: 3; "
        "fill: the carried mesh has smallest dihedral angle 5 deg: 1"
    )


def test_report_writes_markdown_and_plots(small, tmp_path) -> None:
    from softdeca_train.data.report import write_report

    out, _ = small
    md = write_report(out, tmp_path)
    text = md.read_text()
    for name in ("parameters.png", "weights.png", "identities.png", "displacement.png"):
        assert (tmp_path / name).stat().st_size > 10_000
        assert name in text
    tables = json.loads((tmp_path / "displacement.json").read_text())["all"]
    assert set(tables) == set(KINDS)
    for rows in tables.values():
        assert [r["region"] for r in rows] == [*REGIONS, "all of S"]
        for r in rows:
            assert 0 < r["mean"] and r["p50"] <= r["p90"] <= r["p99"] <= r["max"] + 0.01


def test_bad_configurations_and_folders_are_refused(tmp_path) -> None:
    with pytest.raises(ValueError, match="test_share"):
        GenerateConfig(test_share=1.5)
    with pytest.raises(ValueError, match="nothing to generate"):
        GenerateConfig(static=0, dynamic=0, sparse=0)
    with pytest.raises(ValueError, match="lead_in"):
        GenerateConfig(lead_in=1)
    (tmp_path / "junk").mkdir()
    (tmp_path / "junk" / "x.txt").write_text("x")
    tiny = GenerateConfig(static=1, dynamic=0, sparse=0, level=1)
    with pytest.raises(ValueError, match="no dataset manifest"):
        generate(tiny, RunSettings(out=tmp_path / "junk", workers=0, progress=False))
    bad_take = GenerateConfig(static=1, dynamic=0, sparse=0, test_takes=("nope",))
    with pytest.raises(ValueError, match=r"test takes \['nope'\]"):
        generate(bad_take, RunSettings(out=tmp_path / "a", workers=0, progress=False))


def test_resuming_with_another_configuration_is_refused(small) -> None:
    out, _ = small
    other = GenerateConfig(**{**SMALL.as_dict(), "landmark_noise_mm": 2.0})
    with pytest.raises(ValueError, match="another configuration"):
        generate(other, RunSettings(out=out, workers=0, progress=False))
    # The same configuration resumes to a no-op: nothing left to do, nothing duplicated.
    summary = generate(SMALL, RunSettings(out=out, workers=0, progress=False))
    assert summary["kinds"]["static"]["instances"] == SMALL.static


def test_parameters_are_sampled_in_the_range_profile(small) -> None:
    from softdeca_train.data.ranges import (
        DEFAULT_PROFILE,
        FROM_DEFINITION,
        PROFILES,
        profile_ranges,
        sampling_parameters,
    )

    out, _ = small
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["dataset"]["range_profile"] == DEFAULT_PROFILE == "controls"
    params = sampling_parameters(load_parameters(), DEFAULT_PROFILE)
    for kind in KINDS:
        p = _all(out, kind)["p"]
        params.validate(p)  # inside the narrowed ranges, not only the physics' own
    lo, hi = profile_ranges(load_parameters(), DEFAULT_PROFILE)["w_target"]
    k = params.names.index("w_target")
    assert params.specs[k].minimum == lo and params.specs[k].maximum == hi
    # datasets written before range profiles sampled the physics' ranges
    legacy = {k: v for k, v in SMALL.as_dict().items() if k != "ranges"}
    assert GenerateConfig.from_dict(legacy).ranges == "appendix-a"
    with pytest.raises(ValueError, match="unknown range profile"):
        sampling_parameters(load_parameters(), "nonsense")
    # every profile lies inside the physics' ranges and keeps the physics' defaults sampled
    physics = {s.name: s for s in load_parameters().specs}
    for profile in (*PROFILES, *FROM_DEFINITION):
        for s in sampling_parameters(load_parameters(), profile).specs:
            lo, hi = physics[s.name].minimum, physics[s.name].maximum
            assert lo <= s.minimum <= s.default_value <= s.maximum <= hi
            assert s.default_value == physics[s.name].default_value, (profile, s.name)


def test_a_sample_at_the_top_of_a_log_range_stays_inside_it() -> None:
    from dataclasses import replace

    class Top:  # a generator that always draws the top of the interval it is given
        def uniform(self, lo, hi, size=None):
            return hi if size is None else np.full(size, hi)

    # exp(log(100)) is 100 + 4e-14 in float64: without the clip a value leaves its range
    assert np.exp(np.log(100.0)) > 100.0
    spec = replace(
        load_parameters().specs[0], minimum=0.001, maximum=100.0, log_scale=True
    )
    assert spec.sample(Top()) == 100.0  # type: ignore[arg-type]
    assert (spec.sample(Top(), 3) == 100.0).all()  # type: ignore[arg-type]


def test_offset_structure_splits_shared_and_expression_parts(small) -> None:
    from softdeca_train.data.offset_structure import offset_structure
    from softdeca_train.data.report import dataset_parameters

    out, _ = small
    manifest = json.loads((out / "manifest.json").read_text())
    params = dataset_parameters(manifest)
    o = offset_structure(out, "static", params, max_error=np.inf)
    assert o is not None
    # every static frame kept: 16 frames in groups of frames_per_params
    assert o.train_groups + o.test_groups == SMALL.static // SMALL.frames_per_params
    assert o.frames_per_group == SMALL.frames_per_params
    assert 0 < o.expression_part_mm < o.no_correction_mm
    assert 0 < o.shared_share < 1
    if o.test_groups and o.train_groups:
        assert o.test_linear_in_p_mm is not None and np.isfinite(o.test_linear_in_p_mm)
    # nothing passes a filter nothing meets
    assert offset_structure(out, "static", params, max_error=-1.0) is None


def test_evaluation_reads_every_test_frame_and_training_counts_what_it_leaves_out(
    small, template, tmp_path
) -> None:
    import shutil

    from softdeca_train.train.batches import EVERY_FRAME, Dataset

    out, _ = small
    copy = tmp_path / "ds"
    shutil.copytree(out, copy)
    ds = Dataset(copy, template)
    # Mark one test frame as a solve far above the tolerance.
    shard = copy / ds.shards("static", "test")[0]
    with np.load(shard) as z:
        a = {k: z[k] for k in z.files}
    a["estimated_error"] = np.array(a["estimated_error"], copy=True)
    a["estimated_error"][0] = 1.0
    # and another as failing a sanity bound (bit 0: exploded)
    a["failures"] = np.array(a["failures"], copy=True)
    a["failures"][:] = 0
    a["failures"][1] = 1
    np.savez(shard, **a)
    n_test = int((_all(copy, "static")["split"] == TEST).sum())

    def frames(max_error: float | None) -> int:
        return sum(
            len(b.weights) for b in ds.batches("static", "test", None, 8, max_error)
        )

    assert frames(EVERY_FRAME) == n_test
    assert frames(None) == n_test - 2
    assert ds.left_out("static", "test") == {
        "kept": n_test - 2,
        "left_out": 1,
        "failed_bounds": 1,
        "max_error": 3 * SMALL.tolerance,
    }
