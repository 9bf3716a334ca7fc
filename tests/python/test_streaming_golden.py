"""The golden packets and recording: the Python decoders read the expected values, the encoders
reproduce the bytes, and the generator still writes exactly the committed files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from softdeca_train.streaming import ifacialmocap, livelinkface, protocol, recording
from softdeca_train.streaming.frame import Frame, Pose
from softdeca_train.streaming.golden import generate
from streaming_expected import GOLDEN, read_expected

PACKETS = sorted(p.stem for p in GOLDEN.glob("*.bin"))


def floats(values: list[str] | str) -> np.ndarray:
    assert isinstance(values, list)
    return np.array([float(v) for v in values], dtype=np.float64)


def check_pose(expected: dict, key: str, pose: Pose | None) -> None:
    if key not in expected:
        assert pose is None, key
        return
    assert pose is not None, key
    want = floats(expected[key]).astype(np.float32)
    np.testing.assert_array_equal(
        np.concatenate([pose.position, pose.rotation]), want, err_msg=key
    )


def check_frame(e: dict, f: Frame) -> None:
    if "capture_time" in e:
        assert f.capture_time == float(e["capture_time"][0])
    if "send_time" in e:
        assert f.send_time == float(e["send_time"][0])
    assert int(f.tracking) == int(e["tracking"][0])
    if "weights" in e:
        np.testing.assert_array_equal(
            f.weights, floats(e["weights"]).astype(np.float32)
        )
    for key, pose in (
        ("head", f.head),
        ("left_eye", f.left_eye),
        ("right_eye", f.right_eye),
    ):
        check_pose(e, key, pose)
    if "landmarks" in e:
        lm = floats(e["landmarks"])
        assert len(f.landmarks) == int(lm[0])
        np.testing.assert_array_equal(f.landmarks.ravel(), lm[1:].astype(np.float32))
        if int(lm[0]):
            assert f.profile_id == int(e["profile_id"][0])


def test_every_golden_packet_has_its_expected_values() -> None:
    assert len(PACKETS) >= 12
    for name in PACKETS:
        assert (GOLDEN / f"{name}.txt").is_file(), name


@pytest.mark.parametrize("name", PACKETS)
def test_python_decoders_read_the_golden_packets(name: str) -> None:
    data = (GOLDEN / f"{name}.bin").read_bytes()
    e = read_expected(GOLDEN / f"{name}.txt")[""]
    fmt, kind = e["format"], e["kind"]
    if kind == "drop":
        with pytest.raises(protocol.DecodeError) as err:
            protocol.decode(data)
        assert err.value.reason.value == e["drop_reason"]
        return
    reencoded: bytes | None = None
    if fmt == "softdeca":
        env, msg = protocol.decode(data)
        assert env.session_id == int(e["session_id"][0])
        assert env.sequence == int(e["sequence"][0])
        if kind == "frame":
            assert isinstance(msg, Frame)
            assert env.minor == int(e["minor"][0])
            check_frame(e, msg)
            reencoded = protocol.encode_frame(msg)
        elif kind == "profile":
            assert isinstance(msg, protocol.Profile)
            assert msg.id == int(e["profile_id"][0]) and msg.name == e["profile_name"]
            assert msg.indices == tuple(int(i) for i in e["indices"])
            reencoded = protocol.encode_profile(env.session_id, env.sequence, msg)
        elif kind == "neutral_chunk":
            assert isinstance(msg, protocol.NeutralChunk)
            assert msg.neutral_id == int(e["neutral_id"][0])
            assert msg.total_vertices == int(e["total_vertices"][0])
            assert msg.first_vertex == int(e["first_vertex"][0])
            xyz = floats(e["xyz"])
            np.testing.assert_array_equal(msg.xyz.ravel(), xyz[1:].astype(np.float32))
            reencoded = protocol.encode_neutral_chunk(env.session_id, env.sequence, msg)
        else:
            assert isinstance(msg, protocol.Request)
            assert int(msg.what) == int(e["request_what"][0]) and msg.id == int(
                e["request_id"][0]
            )
            reencoded = protocol.encode_request(env.session_id, env.sequence, msg)
    elif fmt == "livelinkface":
        f, info = livelinkface.decode_packet(data)
        assert f.session_id == int(e["session_id"][0])
        assert info.frame_number == int(e["frame_number"][0])
        assert np.float32(info.subframe) == np.float32(float(e["subframe"][0]))
        check_frame(e, f)
        if "values" in e:
            np.testing.assert_array_equal(
                livelinkface.frame_to_values(f)[:52],
                floats(e["values"])[:52].astype(np.float32),
            )
        reencoded = livelinkface.encode_packet(f, info)
    else:
        f, present = ifacialmocap.decode_packet(data)
        check_frame(e, f)
        np.testing.assert_array_equal(present, [v == "1" for v in e["present"]])
    if e["reencode"] == ["1"]:
        assert reencoded == data


def test_python_reader_reads_the_golden_recording() -> None:
    rec = recording.read_recording(GOLDEN / "small.sdrec")
    sections = read_expected(GOLDEN / "small.txt")
    h = sections["header"]
    for key in ("device", "subject", "source", "clock", "units"):
        assert getattr(rec.header, key) == h[key]
    assert rec.header.start_unix_time == float(h["start_unix_time"][0])
    assert rec.header.timecode_rate == float(h["timecode_rate"][0])
    assert len(rec.frames) == int(h["frames"][0]) and len(rec.profiles) == int(
        h["profiles"][0]
    )
    neutral = floats(h["neutral"])
    assert rec.neutral is not None
    np.testing.assert_array_equal(rec.neutral.ravel(), neutral[1:].astype(np.float32))
    for i, p in enumerate(rec.profiles):
        s = sections[f"profile {i}"]
        assert p.id == int(s["profile_id"][0]) and p.name == s["profile_name"]
        assert p.indices == tuple(int(v) for v in s["indices"])
    for i, f in enumerate(rec.frames):
        s = sections[f"frame {i}"]
        assert (f.session_id, f.sequence) == (
            int(s["session_id"][0]),
            int(s["sequence"][0]),
        )
        assert f.receive_time == float(s["receive_time"][0])
        check_frame(s, f)
    assert rec.recovery == recording.Recovery(records=5)


def test_generator_reproduces_the_committed_files(tmp_path: Path) -> None:
    written = generate(tmp_path)
    committed = sorted(
        p.name for p in GOLDEN.iterdir() if p.suffix in (".bin", ".txt", ".sdrec")
    )
    assert sorted(p.name for p in written) == committed
    for p in written:
        assert p.read_bytes() == (GOLDEN / p.name).read_bytes(), p.name
