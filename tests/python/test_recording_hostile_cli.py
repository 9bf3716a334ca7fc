"""Hostile recordings and takes through the `softdeca` CLI (docs/security.md, "Recordings"):
FIFOs and folders where a file should be are refused at once, out-of-range values follow one
rule that `info` counts and `play` applies, and exported CSV numbers read back exactly."""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
from softdeca_train.streaming import recording
from softdeca_train.streaming.frame import Frame, Pose
from streaming_cli import CLI

# A generous bound: the point is "does not hang", not how fast (that is bench-reliability's).
RETURNS_WITHIN_S = 10


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [CLI, *args],
        capture_output=True,
        text=True,
        timeout=RETURNS_WITHIN_S,
        check=False,
    )


def good_recording(path: Path) -> Path:
    frames = [Frame(capture_time=10 + k / 60) for k in range(3)]
    recording.write_recording(path, recording.Header(subject="good"), frames)
    return path


@pytest.mark.parametrize(
    "command",
    [
        ["info", "{fifo}.sdrec"],
        ["play", "{fifo}.sdrec", "--quiet"],
        ["convert", "{fifo}.sdrec", "{dir}/out.csv"],
        ["convert", "{fifo}.csv", "{dir}/out.sdrec"],
        ["convert", "{good}", "{fifo}.csv"],
        [
            "receive",
            "--port",
            "0",
            "--out",
            "{fifo}.sdrec",
            "--duration",
            "1",
            "--quiet",
        ],
        ["receive", "--port", "0", "--duration", "0.2", "--stats-json", "{fifo}.csv"],
    ],
)
def test_a_fifo_is_refused_at_once(tmp_path: Path, command: list[str]) -> None:
    for ext in (".sdrec", ".csv"):
        os.mkfifo(tmp_path / f"take{ext}")
    good = good_recording(tmp_path / "good.sdrec")
    args = [a.format(fifo=tmp_path / "take", dir=tmp_path, good=good) for a in command]
    result = run(*args)  # raises TimeoutExpired if it blocks on the FIFO
    assert result.returncode == 1, result.stderr
    assert "is a FIFO, not a regular file" in result.stderr


def test_a_folder_is_named_as_one(tmp_path: Path) -> None:
    (tmp_path / "folder.sdrec").mkdir()
    result = run("info", str(tmp_path / "folder.sdrec"))
    assert result.returncode == 1
    assert "folder.sdrec is a folder, not a regular file" in result.stderr


def test_out_of_range_values_are_counted_by_info_and_never_played(
    tmp_path: Path,
) -> None:
    weights = np.full(52, 0.5, dtype=np.float32)
    wild = weights.copy()
    wild[:2] = (1e30, -1e30)
    nan = weights.copy()
    nan[3] = np.nan
    zero_rotation = Pose(rotation=np.zeros(4, dtype=np.float32))
    frames = [
        Frame(capture_time=1.0, weights=weights),
        Frame(capture_time=1.1, weights=wild),
        Frame(capture_time=1.2, weights=nan),
        Frame(capture_time=1.3, weights=weights, head=zero_rotation),
    ]
    path = tmp_path / "wild.sdrec"
    recording.write_recording(path, recording.Header(), frames)
    info = json.loads(run("info", str(path), "--json").stdout)
    assert (info["frames"], info["invalid_frames"], info["clamped_frames"]) == (2, 2, 1)
    # The Python reader follows the same rule.
    python = recording.read_recording(path)
    assert (
        len(python.frames),
        python.recovery.invalid_frames,
        python.recovery.clamped_frames,
        python.recovery.damaged_regions,
    ) == (2, 2, 1, 0)
    assert python.frames[1].weights[:2].tolist() == [1.0, 0.0]
    played = run("play", str(path), "--speed", "1000")
    assert played.returncode == 0, played.stderr
    lines = [json.loads(line) for line in played.stdout.splitlines()]
    assert len(lines) == info["frames"]
    for line in lines:
        assert all(0 <= w <= 1 for w in line["weights"])


def test_exported_csv_numbers_read_back_exactly(tmp_path: Path) -> None:
    rng = np.random.default_rng(5)
    # Weights within [0, 1] down to the smallest subnormal (values above 1 are clamped).
    values = np.concatenate(
        [
            np.array([1e-45, 1.1754944e-38, 1e-10, 0.1, 1 / 3, 0.99999994, 1.0]),
            rng.random(52 * 4 - 7),
        ]
    ).astype(np.float32)
    frames = [
        Frame(capture_time=3600 + k / 60, weights=values[52 * k : 52 * (k + 1)])
        for k in range(4)
    ]
    path = tmp_path / "numbers.sdrec"
    recording.write_recording(path, recording.Header(timecode_rate=60), frames)
    csv = tmp_path / "numbers.csv"
    result = run("convert", str(path), str(csv))
    assert result.returncode == 0, result.stderr
    back = tmp_path / "back.sdrec"
    assert run("convert", str(csv), str(back)).returncode == 0
    again = recording.read_recording(back)
    assert len(again.frames) == 4
    for a, b in zip(frames, again.frames, strict=True):
        np.testing.assert_array_equal(a.weights, b.weights)
    assert not any(math.isnan(float(w)) for f in again.frames for w in f.weights)
