"""The Python side of the streaming formats: Live Link Face CSV takes (the real ones in the
data folder), timecodes, recordings and their recovery, hostile datagrams, ARKit's reference
face, and the impairment draws. Cross-checked against the native CLI where both read the same
file."""

from __future__ import annotations

import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from softdeca_train.streaming import livelinkface, protocol, recording
from softdeca_train.streaming.frame import Frame, Pose, Tracking
from softdeca_train.streaming.impairments import FateDrawer, Impairments
from softdeca_train.streaming.reference_face import ReferenceFace
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES
from streaming_cli import CLI, TAKES


@pytest.mark.parametrize(
    ("take", "rows", "lost"),
    [("S88-001.csv", 1939, 277), ("apfel.csv", 1926, 35), ("alex_rom_3.csv", 4030, 0)],
)
def test_real_takes_parse_with_face_lost_rows_counted(
    take: str, rows: int, lost: int
) -> None:
    t = livelinkface.read_csv(TAKES / take)
    assert (t.rows, t.face_lost_rows, t.malformed_rows, len(t.frames)) == (
        rows,
        lost,
        0,
        rows - lost,
    )
    times = np.array([f.capture_time for f in t.frames])
    assert (np.diff(times) > 0).all()
    # About 30 rows per second on the app's 60 fps timecode (two frames apart).
    assert np.median(np.diff(times)) == pytest.approx(2 / 60, abs=1e-4)


def test_columns_are_found_by_name_in_either_spelling() -> None:
    names = list(reversed(livelinkface.VALUE_NAMES))
    row = ",".join(f"{(60 - i) / 100 if 60 - i < 52 else 0.0}" for i in range(61))
    text = (
        "Timecode,BlendshapeCount,"
        + ",".join(names)
        + "\n01:02:03:04.500,61,"
        + row
        + "\n01:02:03:06.000,0\n"
    )
    t = livelinkface.parse_csv(text)
    assert (len(t.frames), t.face_lost_rows) == (1, 1)
    for i, name in enumerate(livelinkface.VALUE_NAMES[:52]):
        canonical = ARKIT_BLENDSHAPES.index(name[0].lower() + name[1:])
        assert t.frames[0].weights[canonical] == np.float32(i / 100)


def test_timecodes() -> None:
    s = livelinkface.parse_timecode("16:48:39:43.245")
    assert s == pytest.approx(16 * 3600 + 48 * 60 + 39 + 43.245 / 60, abs=1e-9)
    assert livelinkface.format_timecode(s, 60) == "16:48:39:43.245"
    assert livelinkface.format_timecode(59.9999999, 60) == "00:01:00:00.000"
    for bad in ("24:00:00:00.000", "00:00:00:60.000", "00:00:00:01.2345", "a:b:c:d"):
        with pytest.raises(ValueError):
            livelinkface.parse_timecode(bad)


def test_python_and_native_csv_readers_agree(tmp_path: Path) -> None:
    rec_path = tmp_path / "apfel.sdrec"
    out = subprocess.run(
        [CLI, "convert", str(TAKES / "apfel.csv"), str(rec_path)],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    assert "1926 rows, 1891 frames written, 35 face-lost rows skipped" in out
    native = recording.read_recording(rec_path)
    python = livelinkface.read_csv(TAKES / "apfel.csv")
    assert len(native.frames) == len(python.frames) == 1891
    for a, b in zip(native.frames, python.frames, strict=True):
        assert a.capture_time == b.capture_time
        np.testing.assert_array_equal(a.weights, b.weights)
        assert a.left_eye is not None and b.left_eye is not None
        # Readers renormalise rotations: equal to the last bit or two.
        np.testing.assert_allclose(a.left_eye.rotation, b.left_eye.rotation, atol=2e-7)
    # And the Python CSV writer gives the rows the native exporter gives.
    csv_path = tmp_path / "apfel.csv"
    subprocess.run(
        [CLI, "convert", str(rec_path), str(csv_path)], check=True, capture_output=True
    )
    assert csv_path.read_text() == livelinkface.format_csv(native.frames)


def _frames(n: int) -> list[Frame]:
    rng = np.random.default_rng(3)
    return [
        Frame(
            capture_time=5.0 + k / 60,
            session_id=1,
            sequence=k,
            has_sequence=True,
            weights=rng.random(52).astype(np.float32),
            head=Pose(rotation=np.array([0, 0, 0, 1], dtype=np.float32)),
            profile_id=9,
            landmarks=rng.normal(0, 0.05, (6, 3)).astype(np.float32),
        )
        for k in range(n)
    ]


def test_recording_round_trip_and_cut_files(tmp_path: Path) -> None:
    path = tmp_path / "r.sdrec"
    frames = _frames(6)
    recording.write_recording(path, recording.Header(device="py"), frames)
    data = path.read_bytes()
    rec = recording.parse_recording(data)
    assert rec.header.device == "py" and len(rec.frames) == 6
    for a, b in zip(rec.frames, frames, strict=True):
        np.testing.assert_array_equal(a.weights, b.weights)
        np.testing.assert_array_equal(a.landmarks, b.landmarks)
    record = len(recording.encode_record(recording.encode_frame_record(frames[0])))
    header_end = len(data) - 6 * record
    for cut in range(header_end, len(data) + 1):
        r = recording.parse_recording(data[:cut])
        assert len(r.frames) == (cut - header_end) // record
        assert r.recovery.truncated_bytes == (cut - header_end) % record
    with pytest.raises(ValueError):
        recording.parse_recording(data[: header_end - 1])


def test_recording_recovers_from_a_damaged_record(tmp_path: Path) -> None:
    frames = _frames(5)
    path = tmp_path / "r.sdrec"
    recording.write_recording(path, recording.Header(), frames)
    data = bytearray(path.read_bytes())
    record = len(recording.encode_record(recording.encode_frame_record(frames[0])))
    start = len(data) - 3 * record  # record 2
    data[start + 50] ^= 0x40
    rec = recording.parse_recording(bytes(data))
    assert [f.sequence for f in rec.frames] == [0, 1, 3, 4]
    assert (rec.recovery.damaged_regions, rec.recovery.skipped_bytes) == (1, record)
    data[20] ^= 1  # the header
    with pytest.raises(ValueError, match="checksum"):
        recording.parse_recording(bytes(data))


def test_python_decoder_drops_hostile_datagrams_with_their_reason() -> None:
    good = protocol.encode_frame(_frames(1)[0])
    cases = {
        good[:10]: protocol.DropReason.UNDERSIZED,
        good + bytes(1200): protocol.DropReason.OVERSIZED,
        b"XDCA" + good[4:]: protocol.DropReason.BAD_MAGIC,
        good[:4] + b"\x02" + good[5:]: protocol.DropReason.INCOMPATIBLE_VERSION,
        good[:38] + b"\xff\xff" + good[40:]: protocol.DropReason.BAD_LENGTH,
        good[:-1]: protocol.DropReason.BAD_LENGTH,
        good[:32] + b"\x09" + good[33:]: protocol.DropReason.BAD_VALUE,
        good[:6] + b"\x4d" + good[7:]: protocol.DropReason.UNKNOWN_TYPE,
    }
    for data, reason in cases.items():
        with pytest.raises(protocol.DecodeError) as err:
            protocol.decode(data)
        assert err.value.reason == reason
    for n in range(len(good)):  # every prefix is refused, none crashes
        with pytest.raises(protocol.DecodeError):
            protocol.decode(good[:n])


def test_live_link_face_packet_round_trip() -> None:
    f = _frames(1)[0]
    f.capture_time = 1000.25
    f.left_eye = f.right_eye = Pose()
    data = livelinkface.encode_packet(f, livelinkface.PacketInfo("dev", "sub"))
    g, info = livelinkface.decode_packet(data)
    assert (info.device_id, info.subject) == ("dev", "sub")
    assert g.capture_time == pytest.approx(1000.25, abs=1e-9)
    np.testing.assert_array_equal(g.weights, f.weights)
    lost = livelinkface.encode_packet(
        Frame(capture_time=1.0, tracking=Tracking.LOST), livelinkface.PacketInfo()
    )
    assert livelinkface.decode_packet(lost)[0].tracking == Tracking.LOST
    with pytest.raises(protocol.DecodeError):
        livelinkface.decode_packet(struct.pack(">Bi", 6, 500) + b"x")


def test_reference_face_neutral_and_blend() -> None:
    face = ReferenceFace.load()
    assert face.neutral.shape == (1220, 3) and face.deltas.shape == (52, 1220, 3)
    # The median over the shapes is exactly the archive's own Neutral.obj.
    assert face.neutral_file_deviation == 0.0
    assert not face.present[
        ARKIT_BLENDSHAPES.index("tongueOut")
    ]  # the public set lacks it
    assert face.present.sum() == 51
    jaw = np.zeros(52)
    jaw[ARKIT_BLENDSHAPES.index("jawOpen")] = 1.0
    opened = face.blend(jaw)
    assert np.abs(opened - face.neutral).max() > 0.01  # a jaw opens by centimetres
    np.testing.assert_allclose(face.blend(jaw, np.array([5, 9])), opened[[5, 9]])
    np.testing.assert_array_equal(face.blend(np.zeros(52)), face.neutral)
    profile = face.profile("arkit68")
    assert profile is not None and len(set(profile.indices)) == 68
    ours = face.profile("softdeca149")
    assert ours is not None and len(set(ours.indices)) == 149
    assert face.profile("none") is None
    with pytest.raises(ValueError, match="unknown landmark profile"):
        face.profile("dlib5")
    # Blended landmarks fit the wire format's range.
    assert np.abs(face.blend(np.ones(52))).max() < 0.32


def test_impairment_draws_are_deterministic_and_spare_the_ends() -> None:
    imp = Impairments(loss=0.3, duplicate=0.3, reorder=0.3, jitter_ms=5, seed=11)
    first, second = FateDrawer(imp, 100), FateDrawer(imp, 100)
    b = [first.fate(i) for i in range(100)]
    assert b == [second.fate(i) for i in range(100)]
    assert all(f == type(f)() for f in b[:3] + b[-3:])
    assert (
        any(f.dropped for f in b)
        and any(f.copies == 2 for f in b)
        and any(f.held for f in b)
    )
    with pytest.raises(ValueError):
        Impairments(loss=1.5)
