"""The closed-form linear baselines: the features, the ridge fit, and a planted dataset whose
offsets are linear in w and p, which the `wp` fit must recover and the `w` fit must not."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from bounds import above, below
from softdeca_train.data.config import GenerateConfig
from softdeca_train.data.ranges import sampling_parameters
from softdeca_train.parameters import load_parameters
from softdeca_train.train.linear_baseline import (
    LinearBaselineConfig,
    ParameterScaling,
    features,
    fit_ridge,
    format_table,
    run_linear_baselines,
)

VERTICES = (
    20  # a small stand-in for S: the fit does not care how many vertices there are
)


def _header() -> dict:
    return {
        "config": GenerateConfig().as_dict()
    }  # the default range profile, `controls`


def _ranges() -> list[dict]:
    """What a manifest records: the ranges its profile sampled."""
    params = sampling_parameters(load_parameters(), GenerateConfig().ranges)
    return [
        {"name": s.name, "lo": s.minimum, "hi": s.maximum, "scale": s.scale}
        for s in params.specs
    ]


def _scaling() -> ParameterScaling:
    return ParameterScaling.of({"dataset": {"parameters": _ranges()}})


def test_parameters_normalise_to_the_dataset_ranges() -> None:
    sc = _scaling()
    specs = sc.params.specs
    # the dataset's ranges are the control ranges where a parameter is a control
    controls = {s.name: s.control for s in load_parameters().specs if s.control}
    assert all(
        (s.minimum, s.maximum) == controls[s.name] for s in specs if s.name in controls
    )
    lo = np.array([s.minimum for s in specs])
    hi = np.array([s.maximum for s in specs])
    assert np.allclose(sc.normalise(lo), 0.0) and np.allclose(sc.normalise(hi), 1.0)
    k = next(i for i, s in enumerate(specs) if s.log_scale)
    mid = lo.copy()
    mid[k] = np.sqrt(lo[k] * hi[k])  # the geometric middle of a log-scaled range
    assert sc.normalise(mid)[k] == pytest.approx(0.5)


def test_gravity_load_is_zero_at_the_capture_load() -> None:
    sc = _scaling()
    names = load_parameters().names
    p = np.array([s.default_value for s in load_parameters().specs])
    assert np.allclose(
        sc.gravity_load(p), 0.0
    )  # 1 g straight down: what the neutral carries
    p[names.index("gravity_strength")] = 2.0
    assert np.allclose(sc.gravity_load(p), [0.0, -1.0, 0.0])
    p[names.index("gravity_strength")] = 1.0
    p[names.index("gravity_tilt")] = 180.0  # upside down
    assert np.allclose(sc.gravity_load(p), [0.0, 2.0, 0.0])


def test_unknown_feature_letters_are_refused() -> None:
    sc = _scaling()
    with pytest.raises(ValueError, match="feature set"):
        features(
            "wz", np.zeros((1, 52)), sc.params.defaults()[None], np.zeros((1, 3)), sc
        )


def test_products_pair_every_weight_with_every_normalised_parameter() -> None:
    sc = _scaling()
    rng = np.random.default_rng(3)
    w = rng.uniform(size=(4, 52))
    p = np.repeat(sc.params.defaults()[None], 4, axis=0)
    a = features("x", w, p, np.zeros((4, 3)), sc)
    n_p = len(sc.params.specs)
    assert a.shape == (4, 1 + 52 * n_p)
    q = sc.normalise(p)
    assert a[2, 1 + 7 * n_p + 5] == pytest.approx(w[2, 7] * q[2, 5])


def test_ridge_recovers_a_planted_linear_map() -> None:
    rng = np.random.default_rng(0)
    a = np.concatenate([np.ones((200, 1)), rng.normal(size=(200, 5))], axis=1)
    x = rng.normal(size=(6, 12))
    y = a @ x + 1e-6 * rng.normal(size=(200, 12))
    est = fit_ridge(a.T @ a, a.T @ y, 1e-9)
    below(np.abs(est - x).max(), 1e-5, "noise 1e-6 over 200 rows, float64 solve")
    # a strong ridge shrinks the coefficients toward zero
    below(
        np.abs(fit_ridge(a.T @ a, a.T @ y, 100.0)).max() / np.abs(x).max(),
        0.1,
        "ridge 100 against a Gram matrix of ~200",
    )


def _planted_dataset(folder: Path, rng: np.random.Generator) -> None:
    """Static shards whose offsets are A_w w + A_p p_hat: linear in w and in p normalised."""
    sc = _scaling()
    specs = sc.params.specs
    a_w = 1e-3 * rng.normal(size=(52, VERTICES * 3))
    a_p = 1e-3 * rng.normal(size=(len(specs), VERTICES * 3))
    lo = np.array([s.minimum for s in specs])
    hi = np.array([s.maximum for s in specs])
    shards = []
    for index, split in enumerate((0, 0, 0, 0, 1)):
        n = 40
        w = rng.uniform(0, 1, size=(n, 52)).astype(np.float32)
        p = lo + (hi - lo) * rng.uniform(size=(n, len(specs)))
        log = np.array([s.log_scale for s in specs])
        p[:, log] = np.exp(
            np.log(lo[log])
            + (np.log(hi[log]) - np.log(lo[log])) * rng.uniform(size=(n, log.sum()))
        )
        off = w @ a_w + sc.normalise(p) @ a_p
        name = f"shard-static-{index:05d}.npz"
        np.savez(
            folder / name,
            instance_id=np.arange(n) + 100 * index,
            split=np.full(n, split, np.int8),
            failures=np.zeros(n, np.uint8),
            estimated_error=np.zeros(n, np.float32),
            weights=w,
            p=p,
            h=rng.normal(size=(n, 4)).astype(np.float32),
            offsets=off.reshape(n, VERTICES, 3).astype(np.float16),
        )
        shards.append({"file": name, "kind": "static", "split": split})
    manifest = {
        "header": _header(),
        "dataset": {"parameters": _ranges()},
        "shards": shards,
    }
    (folder / "manifest.json").write_text(json.dumps(manifest))


def test_a_planted_dataset_is_explained_by_w_and_p_together(tmp_path: Path) -> None:
    _planted_dataset(tmp_path, np.random.default_rng(1))
    cfg = LinearBaselineConfig(feature_sets=("w", "p", "wp"), ridge=1e-9)
    result = run_linear_baselines(tmp_path, cfg, progress=False)
    rows = {r["feature_set"]: r for r in result["rows"]}
    none = result["no_correction_test_mm"]
    assert result["train_frames"] == 160 and result["test_frames"] == 40
    # float16 offsets limit the fit: about 1e-3 of the offsets' size
    below(rows["wp"]["test_mm"] / none, 0.01, "float16 offsets: ~1e-3 of their size")
    above(rows["w"]["test_mm"] / none, 0.2, "p's part is missing", what="w")
    above(rows["p"]["test_mm"] / none, 0.2, "w's part is missing", what="p")
    assert rows["wp"]["columns"] == 1 + 52 + len(load_parameters().names)
    assert "| wp |" in format_table(result)


def test_a_dataset_without_test_frames_is_an_error(tmp_path: Path) -> None:
    _planted_dataset(tmp_path, np.random.default_rng(2))
    m = json.loads((tmp_path / "manifest.json").read_text())
    m["shards"] = [s for s in m["shards"] if s["split"] == 0]
    (tmp_path / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(ValueError, match="no static test frame"):
        run_linear_baselines(
            tmp_path, LinearBaselineConfig(feature_sets=("w",)), progress=False
        )
