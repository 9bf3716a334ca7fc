"""Dataset storage and expression coverage: atomic shards, resumable manifest, streaming."""

from __future__ import annotations

import json

import numpy as np
import pytest
from softdeca_train.data.coverage import (
    BLINKS,
    DEFAULT_SHARES,
    JAW_OPEN,
    KINDS,
    MOUTH_CLOSE,
    SIDES,
    CoverageSampler,
    cumulative_shares,
)
from softdeca_train.data.shards import (
    Manifest,
    iter_shards,
    shard_name,
    verify,
    write_shard,
)


def _arrays(n: int, start: int, split: int = 0) -> dict[str, np.ndarray]:
    return {
        "instance_id": np.arange(start, start + n),
        "split": np.full(n, split, np.int8),
        "x": np.random.default_rng(start).standard_normal((n, 4)).astype(np.float32),
    }


def test_shards_round_trip_and_stream(tmp_path) -> None:
    m = Manifest.open(tmp_path, {"seed": 1})
    m.add(write_shard(tmp_path, "static", 0, _arrays(5, 0)))
    m.add(write_shard(tmp_path, "static", 1, _arrays(5, 5, split=1)))
    assert m.done("static") == {0, 1} and m.done("dynamic") == set()
    ids = np.concatenate([a["instance_id"] for a in iter_shards(tmp_path, "static")])
    assert ids.tolist() == list(range(10))
    test = np.concatenate(
        [a["instance_id"] for a in iter_shards(tmp_path, "static", "test")]
    )
    assert test.tolist() == list(range(5, 10))
    assert verify(tmp_path) == []


def test_resume_needs_the_same_configuration(tmp_path) -> None:
    Manifest.open(tmp_path, {"seed": 1, "n": 3})
    assert Manifest.open(tmp_path, {"seed": 1, "n": 3}).done("static") == set()
    with pytest.raises(ValueError, match="another configuration"):
        Manifest.open(tmp_path, {"seed": 2, "n": 3})


def test_corrupt_or_truncated_shards_are_not_counted(tmp_path) -> None:
    m = Manifest.open(tmp_path, {"seed": 1})
    m.add(write_shard(tmp_path, "static", 0, _arrays(5, 0)))
    m.add(write_shard(tmp_path, "static", 1, _arrays(5, 5)))
    path = tmp_path / shard_name("static", 1)
    path.write_bytes(path.read_bytes()[:-10])  # cut off: a crash or a full disk
    assert Manifest.open(tmp_path, {"seed": 1}).done("static") == {0}
    assert any("checksum" in p for p in verify(tmp_path))
    # A leftover temporary from a killed writer is ignored.
    (tmp_path / (shard_name("static", 2) + ".tmp123")).write_bytes(b"partial")
    assert Manifest.open(tmp_path, {"seed": 1}).done("static") == {0}
    assert (
        json.loads((tmp_path / "manifest.json").read_text())["format"]
        == "softdeca-dataset"
    )


def test_coverage_sampler_keeps_co_activation_and_covers_the_range() -> None:
    rng = np.random.default_rng(0)
    # Synthetic "takes": weights 0 and 1 move together, the rest are small.
    base = rng.random(2000)
    frames = np.clip(rng.random((2000, 52)) * 0.1, 0, 1)
    frames[:, 0] = base
    frames[:, 1] = np.clip(base + 0.05 * rng.standard_normal(2000), 0, 1)
    sampler = CoverageSampler.fit(frames)
    w = sampler.sample(np.random.default_rng(1), 4000)
    assert w.shape == (4000, 52) and w.min() >= 0 and w.max() <= 1
    assert np.corrcoef(w[:, 0], w[:, 1])[0, 1] > 0.5  # co-activation kept
    # Coverage: every weight reaches the upper part of its range somewhere, but mouthClose
    # never passes jawOpen (it would push the lips through each other; these synthetic takes
    # barely open the jaw, so it stays low here).
    others = np.delete(np.arange(52), MOUTH_CLOSE)
    assert (w[:, others].max(axis=0) > 0.8).all()
    assert (w[:, MOUTH_CLOSE] <= w[:, JAW_OPEN]).all()
    assert (
        w[:, MOUTH_CLOSE][w[:, MOUTH_CLOSE] > 0]
        == w[:, JAW_OPEN][w[:, MOUTH_CLOSE] > 0]
    ).any()
    assert not np.array_equal(w, sampler.sample(np.random.default_rng(2), 4000))


def test_coverage_draws_real_faces_kinds_in_their_shares() -> None:
    rng = np.random.default_rng(0)
    frames = np.clip(rng.random((2000, 52)) * 0.1, 0, 1)  # a calm "person"
    sampler = CoverageSampler.fit(frames)
    n = 6000
    kinds = sampler.kinds(np.random.default_rng(3), n)
    shares = np.bincount(kinds, minlength=len(KINDS)) / n
    assert np.allclose(shares, DEFAULT_SHARES, atol=0.02)
    w = sampler.sample(np.random.default_rng(4), n)
    blink = w[:, BLINKS]
    # blinks: both lids closing together, far more often than the calm person does
    together = (blink > 0.6).all(axis=1) & (np.abs(blink[:, 0] - blink[:, 1]) < 0.1)
    assert 0.08 < together.mean() < 0.2
    # asymmetric draws: one side's shapes clearly weaker than the other's
    left, right = w[:, SIDES["Left"]].sum(1), w[:, SIDES["Right"]].sum(1)
    assert (np.minimum(left, right) < 0.5 * np.maximum(left, right)).mean() > 0.1
    # calm frames: a face near rest
    assert (w.max(axis=1) < 0.4).mean() > 0.1
    # strong frames: a stress combination's largest weights at 60 % or more
    assert (w.max(axis=1) >= 0.6).mean() > 0.15 + 0.1
    with pytest.raises(ValueError, match="summing to 1"):
        cumulative_shares((0.9, *DEFAULT_SHARES[1:]))
