"""End to end on loopback (127.0.0.1 only): the virtual device streams real takes to the native
`softdeca receive`, which records them; the recorded frames equal the take's within the wire
format's quantisation, and the receiver's statistics match what the device put on the wire,
under loss, duplication and reordering. Then `softdeca play` replays the recording, printed and
streamed again. Waits are bounded; nothing asserts a duration."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from softdeca_train.streaming import protocol, recording
from softdeca_train.streaming.frame import Frame
from softdeca_train.streaming.impairments import Impairments
from softdeca_train.streaming.reference_face import ReferenceFace
from softdeca_train.streaming.virtual_device import SendLog, VirtualDeviceConfig, run
from streaming_cli import CLI, TAKES

WEIGHT_STEP = 0.5 / 65535 + 1e-7  # half a quantisation step, plus float32 rounding
LANDMARK_STEP = 0.5 * protocol.LANDMARK_STEP + 1e-8


class Receiving:
    """`softdeca receive` on 127.0.0.1, any free port, until 2 s pass without a datagram."""

    def __init__(self, tmp: Path, name: str, *args: str) -> None:
        self.out, self.stats_path = tmp / f"{name}.sdrec", tmp / f"{name}.json"
        self.proc = subprocess.Popen(
            [
                CLI,
                "receive",
                "--bind",
                "127.0.0.1",
                "--port",
                "0",
                "--idle",
                "2",
                "--duration",
                "120",
                "--quiet",
                "--out",
                str(self.out),
                "--stats-json",
                str(self.stats_path),
                *args,
            ],
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        match = re.search(r"port (\d+)", line)
        assert match, line
        self.port = int(match[1])

    def finish(self) -> tuple[dict[str, float], recording.Recording]:
        out, _ = self.proc.communicate(timeout=150)
        assert self.proc.returncode == 0, out
        return json.loads(self.stats_path.read_text()), recording.read_recording(
            self.out
        )


def expected_sequence_stats(log: SendLog) -> dict[str, int]:
    """What a receiver must count, from the datagrams in the order they went out."""
    seen: set[int] = set()
    newest = -1
    duplicates = reordered = 0
    for seq, _ in log.datagrams:
        assert seq is not None
        if seq in seen:
            duplicates += 1
            continue
        seen.add(seq)
        reordered += seq < newest
        newest = max(newest, seq)
    return {
        "duplicates": duplicates,
        "reordered": reordered,
        "lost": newest + 1 - len(seen),
        "expected": newest + 1,
    }


def by_time(frames: list[Frame]) -> dict[float, Frame]:
    return {f.capture_time: f for f in frames}


def test_virtual_device_to_recording_under_loss_reordering_and_duplication(
    tmp_path: Path,
) -> None:
    rx = Receiving(tmp_path, "impaired", "--format", "softdeca", "--delay", "1.0")
    imp = Impairments(loss=0.05, duplicate=0.05, reorder=0.05, jitter_ms=12.0, seed=7)
    log = run(
        VirtualDeviceConfig(
            take=TAKES / "alex_rom_3.csv",
            port=rx.port,
            start=600,
            count=240,
            speed=4.0,
            impairments=imp,
            session_id=1234,
        )
    )
    stats, rec = rx.finish()
    want = expected_sequence_stats(log)
    assert log.dropped and log.duplicated and log.held  # the impairments did happen
    assert want["lost"] == len(log.dropped)
    for key, value in want.items():
        assert stats[key] == value, key
    sent = [f for i, f in enumerate(log.frames) if i not in set(log.dropped)]
    assert stats["late"] == 0 and stats["malformed"] == 0
    assert stats["delivered"] == stats["recorded"] == len(sent) == len(rec.frames)

    # Every recorded frame is the take's frame, within the quantisation, in capture order.
    face = ReferenceFace.load()
    profile = face.profile(
        "softdeca149"
    )  # the virtual device's default: SparseSoftDECA's
    assert profile is not None and len(profile.indices) == 149
    assert [p.indices for p in rec.profiles] == [profile.indices]
    assert rec.neutral is not None
    np.testing.assert_array_equal(rec.neutral, face.neutral.astype(np.float32))
    assert [f.capture_time for f in rec.frames] == [f.capture_time for f in sent]
    for got, want_frame in zip(rec.frames, sent, strict=True):
        assert got.session_id == 1234 and got.profile_id == profile.id
        np.testing.assert_allclose(
            got.weights, want_frame.weights, rtol=0, atol=WEIGHT_STEP
        )
        np.testing.assert_allclose(
            got.landmarks, want_frame.landmarks, rtol=0, atol=LANDMARK_STEP
        )
        assert got.left_eye is not None and want_frame.left_eye is not None
        np.testing.assert_allclose(
            got.left_eye.rotation, want_frame.left_eye.rotation, atol=2e-7
        )


def test_live_link_face_packets_from_a_take_with_lost_faces(tmp_path: Path) -> None:
    rx = Receiving(tmp_path, "llf", "--format", "livelinkface", "--delay", "1.0")
    log = run(
        VirtualDeviceConfig(
            take=TAKES / "apfel.csv",
            port=rx.port,
            format="livelinkface",
            start=0,
            count=150,
            speed=4.0,
            impairments=Impairments(duplicate=0.1, seed=3),
        )
    )
    stats, rec = rx.finish()
    assert log.duplicated > 0
    assert (
        stats["duplicates"] == log.duplicated
    )  # by frame time: the format has no numbers
    assert stats["lost"] == 0 and stats["malformed"] == 0
    assert len(rec.frames) == len(log.frames) == 150
    sent = by_time(log.frames)
    for got in rec.frames:
        want = min(sent, key=lambda t: abs(t - got.capture_time))
        assert got.capture_time == pytest.approx(want, abs=1e-6)
        np.testing.assert_array_equal(
            got.weights, sent[want].weights
        )  # float32 on the wire


def test_cli_replays_a_recording_printed_and_streamed(tmp_path: Path) -> None:
    rx = Receiving(tmp_path, "first", "--delay", "0.2")
    run(
        VirtualDeviceConfig(
            take=TAKES / "facial.csv", port=rx.port, count=60, speed=8.0
        )
    )
    _, first = rx.finish()
    assert len(first.frames) == 60

    lines = subprocess.run(
        [CLI, "play", str(rx.out), "--speed", "20"],
        check=True,
        capture_output=True,
        text=True,
        timeout=60,
    ).stdout.splitlines()
    printed = [json.loads(line) for line in lines]
    assert len(printed) == 60
    for p, f in zip(printed, first.frames, strict=True):
        assert p["capture_time"] == f.capture_time
        np.testing.assert_allclose(p["weights"], f.weights, atol=1e-8)
        assert len(p["landmarks"]) == 3 * 149  # the softdeca149 profile

    again = Receiving(tmp_path, "second", "--delay", "0.2")
    subprocess.run(
        [
            CLI,
            "play",
            str(rx.out),
            "--speed",
            "8",
            "--send",
            f"127.0.0.1:{again.port}",
            "--quiet",
        ],
        check=True,
        timeout=60,
    )
    stats, second = again.finish()
    assert stats["lost"] == 0 and len(second.frames) == 60
    assert [p.indices for p in second.profiles] == [p.indices for p in first.profiles]
    for a, b in zip(second.frames, first.frames, strict=True):
        assert a.capture_time == b.capture_time
        # Already quantised once: a second trip over the wire changes nothing.
        np.testing.assert_array_equal(a.weights, b.weights)
        np.testing.assert_array_equal(a.landmarks, b.landmarks)


def test_python_virtual_device_command(tmp_path: Path) -> None:
    rx = Receiving(tmp_path, "cli", "--delay", "0.2")
    log_path = tmp_path / "log.json"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "softdeca_train",
            "virtual-device",
            str(TAKES / "S07-001.csv"),
            "--port",
            str(rx.port),
            "--count",
            "40",
            "--speed",
            "8",
            "--loss",
            "0.1",
            "--seed",
            "2",
            "--log-json",
            str(log_path),
        ],
        check=True,
        capture_output=True,
        timeout=60,
    )
    stats, rec = rx.finish()
    log = json.loads(log_path.read_text())
    assert len(rec.frames) == log["frames"] - len(log["dropped"]) and stats[
        "lost"
    ] == len(log["dropped"])
    for step in ("virtual-device", "stream-golden"):
        out = subprocess.run(
            [sys.executable, "-m", "softdeca_train", step, "--help"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        assert out.startswith("usage:")


def test_cli_help_and_info(tmp_path: Path) -> None:
    top = subprocess.run(
        [CLI, "--help"], check=True, capture_output=True, text=True
    ).stdout
    for command in ("receive", "play", "convert", "info", "bench-streaming"):
        assert command in top
        sub = subprocess.run(
            [CLI, command, "--help"], check=True, capture_output=True, text=True
        )
        assert sub.stdout.startswith(f"usage: softdeca {command}")
    bad = subprocess.run(
        [CLI, "receive", "--no-such-option"],
        check=False,
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and "unknown option" in bad.stderr
    rec = tmp_path / "s88.sdrec"
    subprocess.run(
        [CLI, "convert", str(TAKES / "S88-001.csv"), str(rec)],
        check=True,
        capture_output=True,
    )
    info = json.loads(
        subprocess.run(
            [CLI, "info", str(rec), "--json"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    )
    assert (info["frames"], info["subject"], info["damaged_regions"]) == (
        1662,
        "S88-001",
        0,
    )
    cut = tmp_path / "cut.sdrec"
    cut.write_bytes(rec.read_bytes()[:-100])
    info = json.loads(
        subprocess.run(
            [CLI, "info", str(cut), "--json"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    )
    assert info["frames"] == 1661 and info["truncated_bytes"] > 0
