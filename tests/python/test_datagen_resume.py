"""Kill-and-resume and the Ray path of the generator, on a tiny configuration (LHM level 1,
one or two frames per shard): a run killed with SIGKILL after its first shard landed and
then resumed must equal an uninterrupted run shard by shard, bit for bit, and so must a run
on a local Ray instance."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from softdeca_train.data.config import KINDS, GenerateConfig, RunSettings
from softdeca_train.data.generate import generate, made_first, summarise
from softdeca_train.data.shards import verify

TINY = GenerateConfig(
    static=6,
    dynamic=2,
    sparse=2,
    level=1,
    frames_per_params=1,
    params_per_identity=2,
    sequences_per_identity=1,
    sequence_length=2,
    lead_in=2,
    test_share=0.3,
    seed=11,
)
ARGS = [
    "--static", "6", "--dynamic", "2", "--sparse", "2", "--level", "1",
    "--frames-per-params", "1", "--params-per-identity", "2", "--sequences-per-identity", "1",
    "--sequence-length", "2", "--lead-in", "2", "--test-share", "0.3", "--seed", "11",
]  # fmt: skip


def _shards(folder: Path) -> dict[str, dict[str, np.ndarray]]:
    m = json.loads((folder / "manifest.json").read_text())
    out = {}
    for s in m["shards"]:
        with np.load(folder / s["file"]) as z:
            out[s["file"]] = {k: z[k] for k in z.files}
    return out


def _same(a: Path, b: Path) -> None:
    sa, sb = _shards(a), _shards(b)
    assert sorted(sa) == sorted(sb)
    for name in sa:
        assert sorted(sa[name]) == sorted(sb[name]), name
        for k in sa[name]:
            assert np.array_equal(sa[name][k], sb[name][k]), f"{name}: {k} differs"


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("uninterrupted")
    summary = generate(TINY, RunSettings(out=out, workers=2, progress=False))
    assert summary["complete"]
    return out


def _cmd(out: Path, workers: int) -> list[str]:
    return [sys.executable, "-m", "softdeca_train", "generate", "--out", str(out),
            "--workers", str(workers), "--no-progress", *ARGS]  # fmt: skip


def test_killed_generator_resumes_without_loss_corruption_or_duplicates(
    reference, tmp_path
) -> None:
    out = tmp_path / "killed"
    proc = subprocess.Popen(
        _cmd(out, 1),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    manifest = out / "manifest.json"
    try:
        deadline = time.time() + 300
        while time.time() < deadline:
            if manifest.is_file() and json.loads(manifest.read_text() or "{}").get(
                "shards"
            ):
                break
            assert proc.poll() is None, "the generator ended before its first shard"
            time.sleep(0.05)
        else:
            pytest.fail("no shard landed in time")
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the generator and its worker, mid-shard
        proc.wait()
    m = json.loads(manifest.read_text())
    total = sum(TINY.count(k) for k in KINDS)
    done = sum(s["instances"] for s in m["shards"])
    assert 0 < done < total, "the kill should land mid-run"
    assert verify(out) == []  # what is listed is intact
    partial = summarise(m)  # what a report of the killed dataset shows
    assert not partial["complete"]
    assert sum(partial["kinds"][k]["instances"] for k in KINDS) == done
    r = subprocess.run(
        _cmd(out, 2), check=False, capture_output=True, text=True, timeout=600
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert verify(out) == []
    m = json.loads(manifest.read_text())
    ids = np.concatenate([d["instance_id"] for d in _shards(out).values()])
    assert len(ids) == len(set(ids.tolist())) == total
    assert len(m["runs"]) == 2
    full = summarise(m)
    assert full["complete"]
    for k in KINDS:
        planned = m["dataset"]["kinds"][k]["instances"]
        assert (full["kinds"][k]["train"], full["kinds"][k]["test"]) == (
            planned["train"],
            planned["test"],
        ), k
    _same(out, reference)


def test_ray_local_cluster_makes_the_same_shards(reference, tmp_path) -> None:
    pytest.importorskip("ray")
    out = tmp_path / "ray"
    summary = generate(
        TINY, RunSettings(out=out, workers=2, ray_address="local", progress=False)
    )
    assert summary["complete"]
    assert (
        json.loads((out / "manifest.json").read_text())["runs"][-1]["executor"]
        == "ray:local"
    )
    _same(out, reference)


def test_kinds_made_first_change_the_order_not_the_data(reference, tmp_path) -> None:
    out = tmp_path / "sparse-first"
    summary = generate(
        TINY,
        RunSettings(out=out, workers=1, progress=False, first=("sparse", "dynamic")),
    )
    assert summary["complete"]
    _same(out, reference)
    plan = [SimpleNamespace(kind=k, index=i) for i in range(2) for k in KINDS]
    order = [(s.kind, s.index) for s in made_first(plan, ("sparse", "dynamic"))]
    assert order == [("sparse", 0), ("sparse", 1), ("dynamic", 0), ("dynamic", 1),
                     ("static", 0), ("static", 1)]  # fmt: skip
