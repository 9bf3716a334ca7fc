"""Recorded takes in the forms they are shared in (streaming/takes.py): LLV's `.gesichter`
recordings built here from known frames, the real one in the data folder, and hostile
containers, which are refused with a clear error and bounded in memory."""

from __future__ import annotations

import gzip
import struct

import numpy as np
import pytest
from softdeca_train.paths import default_recordings_path
from softdeca_train.streaming import takes
from softdeca_train.streaming.frame import Frame, Tracking
from softdeca_train.streaming.livelinkface import PacketInfo, encode_packet, format_csv


def _frames(n: int) -> list[Frame]:
    frames = []
    for i in range(n):
        f = Frame(capture_time=i / 60.0)
        f.weights[:] = np.linspace(0, 1, 52, dtype=np.float32) * (i + 1) / n
        frames.append(f)
    frames[1].tracking = Tracking.LOST
    return frames


def _container(
    packets: list[bytes], count: int | None = None, version: int = 6
) -> bytes:
    body = struct.pack(">BI", version, len(packets) if count is None else count)
    body += b"".join(struct.pack(">I", len(p)) + p for p in packets)
    return gzip.compress(body)


def test_an_llv_recording_reads_as_its_frames() -> None:
    frames = _frames(5)
    info = PacketInfo(frame_number=0)
    take = takes.parse_gesichter(_container([encode_packet(f, info) for f in frames]))
    assert (take.rows, take.face_lost_rows, take.malformed_rows) == (5, 1, 0)
    tracked = [f for f in frames if f.tracking == Tracking.TRACKED]
    assert np.allclose([f.weights for f in take.frames], [f.weights for f in tracked])
    assert np.allclose(
        [f.capture_time for f in take.frames], [f.capture_time for f in tracked]
    )


def test_a_recording_and_its_csv_beside_it_count_once(tmp_path) -> None:
    frames = _frames(3)
    (tmp_path / "a.gesichter").write_bytes(
        _container([encode_packet(f, PacketInfo()) for f in frames])
    )
    (tmp_path / "a.csv").write_text(format_csv(frames))
    (tmp_path / "b.csv").write_text(format_csv(frames))
    assert [p.name for p in takes.take_paths(tmp_path)] == ["a.gesichter", "b.csv"]
    assert len(takes.read_take(tmp_path / "a.gesichter").frames) == 2
    with pytest.raises(ValueError, match="not a take"):
        takes.read_take(tmp_path / "a.txt")


def test_hostile_containers_are_refused() -> None:
    good = encode_packet(_frames(2)[0], PacketInfo())
    cases = {
        "version byte 6": _container([good], version=5),
        "more than its 1 frames": _container([good, good], count=1),
        "holds 1 of its 3 frames": _container([good], count=3),
        "disagrees with the file": gzip.compress(
            struct.pack(">BII", 6, 1, 4000) + good
        ),
        "cut inside a packet size": gzip.compress(struct.pack(">BI", 6, 2) + b"\0\0"),
        "gzip stream incomplete": _container([good])[:-12],
    }
    for message, raw in cases.items():
        with pytest.raises(ValueError, match=message):
            takes.parse_gesichter(raw)
    malformed = takes.parse_gesichter(_container([good, b"\x06garbage"]))
    assert (malformed.rows, malformed.malformed_rows, len(malformed.frames)) == (
        2,
        1,
        1,
    )


def test_a_decompression_bomb_stops_at_the_bound(monkeypatch) -> None:
    monkeypatch.setattr(takes, "MAX_LLV_BYTES", 1 << 16)
    bomb = gzip.compress(struct.pack(">BI", 6, 1) + bytes(1 << 20))
    with pytest.raises(ValueError, match="decompressed"):
        takes.parse_gesichter(bomb)


def test_the_llv_take_of_the_data_folder() -> None:
    path = default_recordings_path() / "livelinkface-llv" / "dao.gesichter"
    if not path.is_file():
        pytest.skip("the data folder has no LLV recording (make setup fetches it)")
    take = takes.read_take(path)
    assert (take.rows, len(take.frames), take.malformed_rows) == (180, 180, 0)
    w = np.stack([f.weights for f in take.frames])
    assert 0.9 < w.max() <= 1.0 and w.min() >= 0.0
    gaps = np.diff([f.capture_time for f in take.frames])
    assert gaps.min() > 0 and gaps.max() < 0.14  # 6 packets were dropped in the capture
