"""Golden packets and a golden recording (tests/golden/streaming): bytes produced by the Python
encoders from synthetic values, next to the values a decoder must read back, in a plain text
format that every decoder (C++, Python, later C# and Swift) parses in a few lines:

    # comment
    [section name]          (recordings: [header], [profile 0], [frame 0], ...)
    key value value ...

Floats are written with enough digits to round-trip; quantised fields hold the value after
quantisation (the decoder's exact output). `reencode 1` marks bytes the encoders reproduce."""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from softdeca_train.streaming import livelinkface, protocol, recording
from softdeca_train.streaming.frame import Frame, Pose, Tracking
from softdeca_train.streaming.rotations import (
    quaternion_from_unity_euler_degrees as unity_quaternion,
)
from softdeca_train.streaming.rotations import quaternion_from_yaw_pitch_roll
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

FORMAT_VERSION = 1


@dataclass
class Expected:
    lines: list[str] = field(default_factory=list)

    def put(self, key: str, *values: object) -> None:
        self.lines.append(" ".join([key, *(_fmt(v) for v in values)]))

    def section(self, name: str) -> None:
        self.lines.append(f"[{name}]")

    def text(self, comment: str) -> str:
        return f"# {comment}\n" + "\n".join(self.lines) + "\n"


def _fmt(v: object) -> str:
    if isinstance(v, np.floating):
        return repr(float(v))
    if isinstance(v, float):
        return repr(v)
    return str(v)


def _weights(seed: int) -> np.ndarray:
    i = np.arange(52)
    return (((i * 37 + seed * 11) % 101) / 100.0).astype(np.float32)


def _pose(position: tuple[float, float, float], ypr: tuple[float, float, float]) -> Pose:
    return Pose(np.array(position, dtype=np.float32), quaternion_from_yaw_pitch_roll(*ypr))


def _landmarks(n: int, phase: float) -> np.ndarray:
    k = np.arange(3 * n, dtype=np.float64)
    return (0.09 * np.sin(0.7 * k + phase)).astype(np.float32).reshape(n, 3)


SYNTHETIC_PROFILE = protocol.Profile("golden-every-18th", tuple(range(0, 1220, 18))[:68])


def _put_pose(e: Expected, key: str, p: Pose | None) -> None:
    if p is not None:
        e.put(key, *p.position, *p.rotation)


def _put_frame(e: Expected, f: Frame, *, quantised: bool) -> None:
    """Decoded values: quantised (the wire) or exact (recordings)."""
    e.put("capture_time", f.capture_time)
    e.put("send_time", f.send_time)
    e.put("tracking", int(f.tracking))
    if quantised:
        q = protocol.quantize_weights(f.weights)
        e.put("weights", *(np.float32(v / 65535.0) for v in q))
    else:
        e.put("weights", *np.asarray(f.weights, dtype=np.float32))
    _put_pose(e, "head", f.head)
    _put_pose(e, "left_eye", f.left_eye)
    _put_pose(e, "right_eye", f.right_eye)
    lm = np.asarray(f.landmarks, dtype=np.float32).reshape(-1, 3)
    e.put("profile_id", f.profile_id if len(lm) else 0)
    if quantised and len(lm):
        q = protocol.quantize_landmarks(lm).astype(np.float64) * protocol.LANDMARK_STEP
        e.put("landmarks", len(lm), *q.astype(np.float32).ravel())
    else:
        e.put("landmarks", len(lm), *lm.ravel())


def _frame_full() -> Frame:
    return Frame(
        capture_time=12345.678901234,
        send_time=12345.6812,
        session_id=0x5EED0001,
        sequence=41,
        has_sequence=True,
        weights=_weights(1),
        head=_pose((0.012, -0.034, -0.456), (0.1, -0.2, 0.05)),
        left_eye=_pose((0.031, 0.025, 0.02), (0.15, -0.05, 0.0)),
        right_eye=_pose((-0.031, 0.025, 0.02), (0.12, -0.05, 0.0)),
        profile_id=SYNTHETIC_PROFILE.id,
        landmarks=_landmarks(68, 0.3),
    )


def _softdeca_expected(kind: str, **fields: object) -> Expected:
    """The first lines of a SoftDECA packet's expected values: format, kind, then `fields`."""
    e = Expected()
    e.put("format", "softdeca")
    e.put("kind", kind)
    for key, value in fields.items():
        e.put(key, value)
    return e


def _reencoded_frame(
    out: dict[str, tuple[bytes, Expected, str]], name: str, f: Frame, description: str
) -> None:
    """A frame of the current version: decoding it gives `f` back, and so does re-encoding."""
    e = _softdeca_expected("frame", minor=0, session_id=f.session_id, sequence=f.sequence)
    _put_frame(e, f, quantised=True)
    e.put("reencode", 1)
    out[name] = (protocol.encode_frame(f), e, description)


def _softdeca_frames(out: dict[str, tuple[bytes, Expected, str]]) -> None:
    _reencoded_frame(
        out, "softdeca_frame_full", _frame_full(), "a full frame: weights, head, eyes, 68 landmarks"
    )

    lost = Frame(
        capture_time=7.25,
        send_time=7.5,
        session_id=3,
        sequence=0xFFFFFFFF,
        has_sequence=True,
        tracking=Tracking.LOST,
    )
    _reencoded_frame(
        out, "softdeca_frame_minimal", lost, "the smallest frame: weights only, face lost"
    )

    # A newer minor version: a longer weights block and an unknown block, both skipped over.
    newer = bytearray(
        protocol.encode_frame(
            Frame(capture_time=1.0, send_time=1.0, session_id=9, sequence=5, weights=_weights(2))
        )
    )
    newer[5] = 1  # minor
    weights_at = protocol.HEADER_BYTES + 20
    struct.pack_into("<H", newer, weights_at + 2, 104 + 4)
    newer[weights_at + 4 + 104 : weights_at + 4 + 104] = b"\x01\x02\x03\x04"
    newer += struct.pack("<HH", 99, 6) + b"future"
    newer[protocol.HEADER_BYTES + 18] += 1  # the block count includes the unknown block
    e = _softdeca_expected("frame", minor=1, session_id=9, sequence=5)
    _put_frame(e, Frame(capture_time=1.0, send_time=1.0, weights=_weights(2)), quantised=True)
    e.put("reencode", 0)
    out["softdeca_frame_minor1"] = (
        bytes(newer),
        e,
        "version 1.1: a longer weights block and block type 99 are skipped",
    )


def _softdeca_messages(out: dict[str, tuple[bytes, Expected, str]]) -> None:
    e = _softdeca_expected("profile", session_id=17, sequence=2)
    e.put("profile_id", SYNTHETIC_PROFILE.id)
    e.put("profile_name", SYNTHETIC_PROFILE.name)
    e.put("indices", *SYNTHETIC_PROFILE.indices)
    e.put("reencode", 1)
    out["softdeca_profile"] = (
        protocol.encode_profile(17, 2, SYNTHETIC_PROFILE),
        e,
        "a landmark profile",
    )

    neutral = _landmarks(1220, 1.1)
    chunk = protocol.split_neutral(neutral)[3]
    e = _softdeca_expected("neutral_chunk", session_id=17, sequence=6)
    e.put("neutral_id", chunk.neutral_id)
    e.put("total_vertices", chunk.total_vertices)
    e.put("first_vertex", chunk.first_vertex)
    e.put("xyz", len(chunk.xyz), *chunk.xyz.ravel())
    e.put("reencode", 1)
    out["softdeca_neutral_chunk"] = (
        protocol.encode_neutral_chunk(17, 6, chunk),
        e,
        "chunk 3 of a 1,220-vertex neutral mesh",
    )

    e = _softdeca_expected("request", session_id=17, sequence=0)
    e.put("request_what", int(protocol.RequestKind.PROFILE))
    e.put("request_id", SYNTHETIC_PROFILE.id)
    e.put("reencode", 1)
    req = protocol.encode_request(
        17, 0, protocol.Request(protocol.RequestKind.PROFILE, SYNTHETIC_PROFILE.id)
    )
    out["softdeca_request"] = (req, e, "a receiver asking for a profile")


def _softdeca_drops(out: dict[str, tuple[bytes, Expected, str]]) -> None:
    future = bytearray(
        protocol.encode_request(1, 1, protocol.Request(protocol.RequestKind.NEUTRAL))
    )
    future[5], future[6] = 1, 9
    out["softdeca_unknown_type"] = (
        bytes(future),
        _softdeca_expected("drop", drop_reason="unknown_type"),
        "version 1.1 message type 9: ignored, not malformed",
    )

    major = bytearray(protocol.encode_frame(_frame_full()))
    major[4] = 2
    out["softdeca_major2"] = (
        bytes(major),
        _softdeca_expected("drop", drop_reason="incompatible_version"),
        "version 2.0: a 1.x receiver refuses it",
    )


def _softdeca(out: dict[str, tuple[bytes, Expected, str]]) -> None:
    _softdeca_frames(out)
    _softdeca_messages(out)
    _softdeca_drops(out)


def _livelinkface(out: dict[str, tuple[bytes, Expected, str]]) -> None:
    f = Frame(
        capture_time=(16 * 3600 + 48 * 60 + 39) + 43.245 / 60.0,
        weights=_weights(3),
        head=_pose((0, 0, 0), (0.2, -0.1, 0.03)),
        left_eye=_pose((0, 0, 0), (-0.3, 0.01, 0.0)),
        right_eye=_pose((0, 0, 0), (-0.27, 0.012, 0.0)),
    )
    info = livelinkface.PacketInfo("5E0A2B3C-golden", "golden", 0, 0.0, 60, 1)
    data = livelinkface.encode_packet(f, info)
    frames = f.capture_time * 60
    whole = math.floor(frames)
    sub = float(np.float32(frames - whole))
    values = livelinkface.frame_to_values(f)
    decoded = Frame(capture_time=(whole + sub) * 1 / 60)
    livelinkface.values_to_frame(values, decoded)
    e = Expected()
    e.put("format", "livelinkface")
    e.put("kind", "frame")
    e.put("session_id", livelinkface.session_id_of(info.device_id, info.subject))
    e.put("device_id", info.device_id)
    e.put("subject", info.subject)
    e.put("frame_number", whole)
    e.put("subframe", sub)
    e.put("fps", 60, 1)
    e.put("values", *values)
    _put_frame(e, decoded, quantised=False)
    e.put("reencode", 0)  # angles pass through quaternions: equal to ~1e-7 rad, not in bits
    out["livelinkface_v6"] = (data, e, "Live Link Face UDP version 6, big-endian, 61 values")

    lost = livelinkface.encode_packet(Frame(capture_time=100.5, tracking=Tracking.LOST), info)
    e = Expected()
    e.put("format", "livelinkface")
    e.put("kind", "frame")
    e.put("session_id", livelinkface.session_id_of(info.device_id, info.subject))
    e.put("frame_number", 6030)
    e.put("subframe", 0.0)
    e.put("capture_time", 100.5)
    e.put("tracking", 0)
    e.put("reencode", 1)
    out["livelinkface_face_lost"] = (
        lost,
        e,
        "Live Link Face packet with no values: the face is lost",
    )


def _ifacialmocap(out: dict[str, tuple[bytes, Expected, str]]) -> None:
    template = (
        "mouthSmile_R{s}25|eyeBlink_L{s}100|jawOpen{s}40|browInnerUp{s}7|mouthLeft{s}3|"
        "trackingStatus{s}1|34903,-1.666|=head#-21.5,6.0,-6.6,-0.03,-0.1,-0.65|"
        "rightEye#6.0,2.4,0.25|leftEye#6.0,-1.6,-0.17|"
    )
    named = {
        "mouthSmileRight": 0.25,
        "eyeBlinkLeft": 1.0,
        "jawOpen": 0.4,
        "browInnerUp": 0.07,
        "mouthLeft": 0.03,
    }
    w = np.zeros(52, dtype=np.float32)
    present = np.zeros(52, dtype=int)
    for n, v in named.items():
        w[ARKIT_BLENDSHAPES.index(n)] = np.float32(v)
        present[ARKIT_BLENDSHAPES.index(n)] = 1
    for name, sep in (("ifacialmocap_v1", "-"), ("ifacialmocap_v2", "&")):
        e = Expected()
        e.put("format", "ifacialmocap")
        e.put("kind", "frame")
        e.put("tracking", 1)
        e.put("weights", *w)
        e.put("present", *present)
        e.put(
            "head",
            np.float32(-0.03),
            np.float32(-0.1),
            np.float32(0.65),
            *unity_quaternion(-21.5, 6.0, -6.6),
        )
        e.put("left_eye", 0.0, 0.0, 0.0, *unity_quaternion(6.0, -1.6, -0.17))
        e.put("right_eye", 0.0, 0.0, 0.0, *unity_quaternion(6.0, 2.4, 0.25))
        e.put("reencode", 0)
        comment = (
            f"iFacialMocap text, '{sep}' between name and value, shapes missing, an unnamed field"
        )
        out[name] = (template.format(s=sep).encode(), e, comment)


def _recording() -> tuple[bytes, Expected]:
    header = recording.Header(
        device="golden device",
        subject="golden take",
        source="golden",
        start_unix_time=1700000000.25,
        timecode_rate=60.0,
        clock="sender seconds",
        profile=SYNTHETIC_PROFILE,
        neutral=_landmarks(4, 0.5),
    )
    frames = []
    for k in range(4):
        f = Frame(
            capture_time=50.0 + k / 30.0,
            send_time=50.01 + k / 30.0,
            receive_time=900.0 + k / 30.0,
            session_id=77,
            sequence=10 + k,
            has_sequence=True,
            weights=_weights(k + 4),
            head=_pose((0.0, 0.01 * k, -0.4), (0.05 * k, 0.0, 0.0)),
            profile_id=SYNTHETIC_PROFILE.id,
            landmarks=_landmarks(68, k),
        )
        if k == 2:
            f.tracking, f.head, f.profile_id, f.landmarks = Tracking.LOST, None, 0, np.zeros((0, 3))
        frames.append(f)
    data = recording.encode_header(header)
    for f in frames[:2]:
        data += recording.encode_record(recording.encode_frame_record(f))
    data += recording.encode_record(
        bytes([recording.RecordType.PROFILE])
        + protocol.encode_profile_body(protocol.Profile("second", (1, 2, 3)))
    )
    for f in frames[2:]:
        data += recording.encode_record(recording.encode_frame_record(f))
    e = Expected()
    e.section("header")
    for key in ("device", "subject", "source", "clock", "units"):
        e.put(key, getattr(header, key))
    e.put("start_unix_time", header.start_unix_time)
    e.put("timecode_rate", header.timecode_rate)
    e.put("frames", len(frames))
    e.put("profiles", 2)
    e.put("neutral", 4, *np.asarray(header.neutral, dtype=np.float32).ravel())
    for i, p in enumerate((SYNTHETIC_PROFILE, protocol.Profile("second", (1, 2, 3)))):
        e.section(f"profile {i}")
        e.put("profile_id", p.id)
        e.put("profile_name", p.name)
        e.put("indices", *p.indices)
    for i, f in enumerate(frames):
        e.section(f"frame {i}")
        e.put("session_id", f.session_id)
        e.put("sequence", f.sequence)
        e.put("receive_time", f.receive_time)
        _put_frame(e, f, quantised=False)
    return data, e


def generate(folder: Path) -> list[Path]:
    """Writes every golden file into folder; returns their paths."""
    folder.mkdir(parents=True, exist_ok=True)
    packets: dict[str, tuple[bytes, Expected, str]] = {}
    _softdeca(packets)
    _livelinkface(packets)
    _ifacialmocap(packets)
    written = []
    for name, (data, expected, comment) in sorted(packets.items()):
        for path, content in (
            (folder / f"{name}.bin", data),
            (folder / f"{name}.txt", expected.text(comment).encode()),
        ):
            path.write_bytes(content)
            written.append(path)
    data, expected = _recording()
    for path, content in (
        (folder / "small.sdrec", data),
        (
            folder / "small.txt",
            expected.text(
                "a small recording: header with profile and neutral, "
                "4 frames (one face-lost), a second profile"
            ).encode(),
        ),
    ):
        path.write_bytes(content)
        written.append(path)
    return written
