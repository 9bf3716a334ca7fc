"""Per-element closed-form fits (train/local_fit.py): the features, the per-element ridge on
planted maps, and the whole analysis on the small generated dataset."""

from __future__ import annotations

import json
import math

import numpy as np
import torch
from bounds import below
from softdeca_train.data.config import GenerateConfig
from softdeca_train.data.ranges import sampling_parameters
from softdeca_train.models.smoothing import FieldSmoothing
from softdeca_train.parameters import load_parameters
from softdeca_train.train.linear_baseline import ParameterScaling
from softdeca_train.train.local_fit import (
    LocalFitConfig,
    LocalRidge,
    averaged_features,
    format_local_table,
    local_features,
    predict,
    run_local_fits,
)


def _scaling() -> ParameterScaling:
    params = sampling_parameters(load_parameters(), GenerateConfig().ranges)
    ranges = [{"name": s.name, "lo": s.minimum, "hi": s.maximum} for s in params.specs]
    return ParameterScaling.of({"dataset": {"parameters": ranges}})


def test_features_use_each_elements_own_parameters() -> None:
    sc = _scaling()
    p = np.repeat(sc.params.defaults()[None], 3, axis=0)
    strength = sc.params.names.index("gravity_strength")
    p[1, strength] = 2.0  # one element in a region with twice the gravity
    w = np.random.default_rng(0).uniform(size=(2, 52))
    x = local_features(w, p, sc).numpy()
    n_p = len(sc.params.names)
    assert x.shape == (3, 2, 52 + 1 + n_p + 3)
    assert np.array_equal(x[:, :, :52], np.broadcast_to(w, (3, 2, 52)))
    assert (x[:, :, 52] == 1).all()
    assert np.array_equal(x[0], x[2]) and not np.array_equal(x[0], x[1])
    # the element's gravity load: 1 g more along -Y where the strength doubles
    assert np.allclose(x[1, 0, -3:] - x[0, 0, -3:], [0.0, -1.0, 0.0])


def test_averaged_features_carry_a_local_change_to_the_neighbours_only() -> None:
    sc = _scaling()
    # a row of skin points 5 mm apart along x
    rest = np.stack([np.arange(40) * 0.005, np.zeros(40), np.zeros(40)], axis=1)
    smoothing = FieldSmoothing(rest)
    p = np.repeat(sc.params.defaults()[None], len(rest), axis=0)
    w = np.zeros((1, 52))
    base = averaged_features(local_features(w, p, sc), p, sc, smoothing).numpy()
    n_own = 52 + 1 + len(sc.params.names) + 3
    local = [i for i, s in enumerate(sc.params.specs) if s.domain != "global"]
    assert base.shape == (40, 1, n_own + len(local) * len(smoothing.scales))
    # a constant field averages to itself
    assert np.allclose(base[:, 0, n_own:], base[0, 0, n_own:])
    column = sc.params.names.index("target_volume")
    p[:3, column] = sc.params.specs[column].maximum  # a change at one end of the row
    changed = averaged_features(local_features(w, p, sc), p, sc, smoothing).numpy()
    delta = np.abs(changed - base)[:, 0, n_own:].sum(axis=1)
    assert delta[5] > 0 and delta[5] > delta[20] and delta[-1] < 1e-2 * delta[0]
    # the vertex's own features change only where its own parameter does
    assert np.array_equal(changed[3:, 0, :n_own], base[3:, 0, :n_own])


def test_each_element_recovers_its_own_planted_map() -> None:
    rng = np.random.default_rng(1)
    n, d, k = 5, 7, 3
    truth = torch.from_numpy(rng.normal(size=(n, d, k)))
    fit = LocalRidge(n, d, k)
    for _ in range(4):  # batches of frames, as the dataset streams them
        x = torch.from_numpy(rng.normal(size=(n, 6, d)))
        fit.add(x, predict(x, truth).transpose(0, 1))
    assert fit.frames == 24
    assert torch.allclose(fit.solve(1e-12), truth, atol=1e-8)
    # solved a few elements at a time (memory), the same answer
    assert torch.allclose(fit.solve(1e-3, chunk=2), fit.solve(1e-3), atol=1e-12)
    # a strong ridge shrinks every element's map
    below(
        fit.solve(1e3).abs().max() / truth.abs().max(), 0.1, "ridge 1e3 over 24 frames"
    )


def test_a_leading_feature_block_solves_as_its_own_fit() -> None:
    rng = np.random.default_rng(2)
    n, d, k, lead = 4, 9, 3, 5
    full, own = LocalRidge(n, d, k), LocalRidge(n, lead, k)
    for _ in range(3):
        x = torch.from_numpy(rng.normal(size=(n, 8, d)))
        y = torch.from_numpy(rng.normal(size=(n, 8, k)))
        full.add(x, y)
        own.add(x[..., :lead], y)
    sub = full.solve(1e-3, chunk=3, features=lead)
    assert sub.shape == (n, lead, k)
    assert torch.allclose(sub, own.solve(1e-3), atol=1e-10)


def test_the_small_dataset_gets_every_figure(small) -> None:
    folder, _ = small
    manifest = json.loads((folder / "manifest.json").read_text())
    test_frames = sum(
        s["instances"]
        for s in manifest["shards"]
        if s["kind"] == "static" and s.get("split") == 1
    )
    result = run_local_fits(folder, LocalFitConfig(), progress=False)
    mm = result["test_mm"]
    assert test_frames > 0 and result["test_frames"] == test_frames  # every one
    assert result["train_frames"] > 0
    assert all(math.isfinite(v) for v in mm.values())
    # DT of the physics' own gradients lands closer to T than the linear blend does
    assert mm["dt_floor"] < mm["none"]
    assert {"vertex_local", "vertex_averaged", "gradient_local"} <= set(mm)
    assert "| DT of the physics' own face gradients (clamped) |" in format_local_table(
        result
    )
