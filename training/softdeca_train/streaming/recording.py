"""Recording files (.sdrec, docs/recording.md): the Python twin of plugin/src/recording/
(recording_reader.cpp, recording_writer.cpp, record_codec.cpp), including its recovery of files
cut off mid-write or damaged in the middle."""

from __future__ import annotations

import math
import struct
import zlib
from dataclasses import dataclass, field
from enum import IntEnum
from pathlib import Path

import numpy as np

from softdeca_train.streaming.frame import MAX_LANDMARKS, Frame, Pose, Tracking
from softdeca_train.streaming.protocol import (
    MAX_NEUTRAL_VERTICES,
    DecodeError,
    DropReason,
    Profile,
    _Reader,
    decode_profile_body,
    encode_profile_body,
)
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

FILE_MAGIC = b"\x89SDREC\r\n"
VERSION_MAJOR = 1
VERSION_MINOR = 0
RECORD_MAGIC = b"SDRC"
RECORD_HEADER_BYTES = 12
MAX_RECORD_BYTES = 1 << 16
MAX_HEADER_BYTES = 1 << 20
_HAS_HEAD, _HAS_EYES, _HAS_SEQUENCE = 1, 2, 4
_FRAME_FIXED = struct.Struct("<BBBBIIIdddHH")  # type, tracking, flags, reserved, ...


class RecordType(IntEnum):
    FRAME = 1
    PROFILE = 2
    NEUTRAL = 3


class HeaderTag(IntEnum):
    DEVICE = 1
    SUBJECT = 2
    SOURCE = 3
    START_UNIX_TIME = 4
    TIMECODE_RATE = 5
    CLOCK = 6
    UNITS = 7
    COORDINATE_FRAME = 8
    BLENDSHAPE_NAMES = 9
    PROFILE = 10
    NEUTRAL = 11


@dataclass
class Header:
    device: str = ""
    subject: str = ""
    source: str = ""
    start_unix_time: float = 0.0
    timecode_rate: float = 0.0
    clock: str = "sender seconds"
    units: str = "m"
    coordinate_frame: str = "ARKit face anchor: right-handed, +Y up, +Z out of the face"
    profile: Profile | None = None
    neutral: np.ndarray | None = None  # (n, 3) float32


@dataclass
class Recovery:
    records: int = 0
    damaged_regions: int = 0
    skipped_bytes: int = 0
    truncated_bytes: int = 0
    unknown_records: int = 0
    # Frames the frame rule left out (values not finite, impossible poses or landmarks) or
    # kept with weights clamped to [0, 1], as the native reader (recording/frame_rule.h).
    invalid_frames: int = 0
    clamped_frames: int = 0


@dataclass
class Recording:
    header: Header
    frames: list[Frame] = field(default_factory=list)
    profiles: list[Profile] = field(default_factory=list)
    neutral: np.ndarray | None = None
    recovery: Recovery = field(default_factory=Recovery)


# ---- encoding ---------------------------------------------------------------------------------


def _field(tag: HeaderTag, body: bytes) -> bytes:
    return struct.pack("<HI", int(tag), len(body)) + body


def _neutral_body(xyz: np.ndarray) -> bytes:
    xyz = np.asarray(xyz, dtype="<f4").reshape(-1, 3)
    if not 1 <= len(xyz) <= MAX_NEUTRAL_VERTICES:
        raise ValueError("a neutral mesh has 1 to 4096 vertices")
    return struct.pack("<I", len(xyz)) + xyz.tobytes()


def encode_header(h: Header) -> bytes:
    fields = b"".join(
        [
            _field(HeaderTag.DEVICE, h.device.encode()),
            _field(HeaderTag.SUBJECT, h.subject.encode()),
            _field(HeaderTag.SOURCE, h.source.encode()),
            _field(HeaderTag.START_UNIX_TIME, struct.pack("<d", h.start_unix_time)),
            _field(HeaderTag.TIMECODE_RATE, struct.pack("<d", h.timecode_rate)),
            _field(HeaderTag.CLOCK, h.clock.encode()),
            _field(HeaderTag.UNITS, h.units.encode()),
            _field(HeaderTag.COORDINATE_FRAME, h.coordinate_frame.encode()),
            _field(HeaderTag.BLENDSHAPE_NAMES, ",".join(ARKIT_BLENDSHAPES).encode()),
        ]
    )
    if h.profile is not None:
        fields += _field(HeaderTag.PROFILE, encode_profile_body(h.profile))
    if h.neutral is not None:
        fields += _field(HeaderTag.NEUTRAL, _neutral_body(h.neutral))
    body = struct.pack("<HHI", VERSION_MAJOR, VERSION_MINOR, len(fields)) + fields
    return FILE_MAGIC + body + struct.pack("<I", zlib.crc32(body))


def _pose_bytes(p: Pose) -> bytes:
    return np.concatenate([p.position, p.rotation]).astype("<f4").tobytes()


def encode_frame_record(f: Frame) -> bytes:
    lm = np.asarray(f.landmarks, dtype="<f4").reshape(-1, 3)
    if len(lm) > MAX_LANDMARKS:
        raise ValueError("too many landmarks")
    eyes = f.left_eye is not None and f.right_eye is not None
    flags = (
        (_HAS_HEAD if f.head is not None else 0)
        | (_HAS_EYES if eyes else 0)
        | (_HAS_SEQUENCE if f.has_sequence else 0)
    )
    out = _FRAME_FIXED.pack(
        RecordType.FRAME,
        int(f.tracking),
        flags,
        0,
        f.session_id,
        f.sequence,
        f.profile_id,
        f.capture_time,
        f.send_time,
        f.receive_time,
        len(f.weights),
        len(lm),
    )
    out += np.asarray(f.weights, dtype="<f4").tobytes()
    if f.head is not None:
        out += _pose_bytes(f.head)
    if eyes:
        assert f.left_eye is not None and f.right_eye is not None
        out += _pose_bytes(f.left_eye) + _pose_bytes(f.right_eye)
    return out + lm.tobytes()


def encode_record(payload: bytes) -> bytes:
    length = struct.pack("<I", len(payload))
    return (
        RECORD_MAGIC + length + struct.pack("<I", zlib.crc32(payload, zlib.crc32(length))) + payload
    )


def write_recording(path: str | Path, header: Header, frames: list[Frame]) -> None:
    with open(path, "wb") as out:
        out.write(encode_header(header))
        for f in frames:
            out.write(encode_record(encode_frame_record(f)))


# ---- decoding ---------------------------------------------------------------------------------


def _read_pose(values: np.ndarray) -> Pose | None:
    if not np.isfinite(values[:3]).all() or np.abs(values[:3]).max() > 1e3:
        return None
    n = float(np.linalg.norm(values[3:7].astype(np.float64)))
    if not (math.isfinite(n) and 0.9 <= n <= 1.1):
        return None
    rotation = (values[3:7].astype(np.float64) / n).astype(np.float32)  # as the native reader
    return Pose(values[:3].astype(np.float32), rotation)


# The header's text fields: tag -> Header attribute.
_TEXT_FIELDS = {
    HeaderTag.DEVICE: "device",
    HeaderTag.SUBJECT: "subject",
    HeaderTag.SOURCE: "source",
    HeaderTag.CLOCK: "clock",
    HeaderTag.UNITS: "units",
    HeaderTag.COORDINATE_FRAME: "coordinate_frame",
}


def _decode_header_fields(data: bytes, h: Header) -> list[int]:
    order: list[int] | None = None
    pos = 0
    while pos < len(data):
        if len(data) - pos < 6:
            raise ValueError("truncated header field")
        tag, length = struct.unpack_from("<HI", data, pos)
        pos += 6
        if length > len(data) - pos:
            raise ValueError("header field runs past the header")
        body = data[pos : pos + length]
        pos += length
        text = body.decode("utf-8", errors="replace")
        if tag in _TEXT_FIELDS:
            setattr(h, _TEXT_FIELDS[tag], text)
        elif tag in (HeaderTag.START_UNIX_TIME, HeaderTag.TIMECODE_RATE):
            if len(body) < 8:
                raise ValueError("short number field")
            (v,) = struct.unpack_from("<d", body)
            if not math.isfinite(v) or (tag == HeaderTag.TIMECODE_RATE and v < 0):
                raise ValueError("bad number field")
            if tag == HeaderTag.START_UNIX_TIME:
                h.start_unix_time = v
            else:
                h.timecode_rate = v
        elif tag == HeaderTag.BLENDSHAPE_NAMES:
            order = [
                ARKIT_BLENDSHAPES.index(n) if n in ARKIT_BLENDSHAPES else -1
                for n in text.split(",")
            ]
        elif tag == HeaderTag.PROFILE:
            try:
                h.profile = decode_profile_body(_Reader(body, DropReason.BAD_LENGTH, "profile"))
            except DecodeError as e:
                raise ValueError(str(e)) from e
        elif tag == HeaderTag.NEUTRAL:
            h.neutral = _decode_neutral_body(body)
            if h.neutral is None:
                raise ValueError("bad neutral field")
    if order is None:
        raise ValueError("header without blendshape names")
    return order


def _decode_neutral_body(body: bytes) -> np.ndarray | None:
    if len(body) < 4:
        return None
    (n,) = struct.unpack_from("<I", body)
    if not 0 < n <= MAX_NEUTRAL_VERTICES or len(body) - 4 < 12 * n:
        return None
    xyz = np.frombuffer(body, dtype="<f4", count=3 * n, offset=4).reshape(n, 3).astype(np.float32)
    return xyz if np.isfinite(xyz).all() else None


# What became of a frame record: its layout broken (damage), its values refused by the frame
# rule, or kept (with weights clamped, or as written).
BROKEN, INVALID, CLAMPED, KEPT = "broken", "invalid", "clamped", "kept"


def _decode_frame_record(body: bytes, order: list[int]) -> tuple[str, Frame | None]:
    if len(body) < _FRAME_FIXED.size:
        return BROKEN, None
    (_, tracking, flags, _, session, seq, profile_id, capture, send, receive, nw, nl) = (
        _FRAME_FIXED.unpack_from(body)
    )
    if tracking > Tracking.LIMITED or nw != len(order) or nl > MAX_LANDMARKS:
        return BROKEN, None
    head, eyes = bool(flags & _HAS_HEAD), bool(flags & _HAS_EYES)
    need = _FRAME_FIXED.size + 4 * (nw + 7 * head + 14 * eyes + 3 * nl)
    if len(body) < need:
        return BROKEN, None
    v = np.frombuffer(
        body, dtype="<f4", count=(need - _FRAME_FIXED.size) // 4, offset=_FRAME_FIXED.size
    ).astype(np.float32)
    weights = np.zeros(len(ARKIT_BLENDSHAPES), dtype=np.float32)
    for i, k in enumerate(order):
        if k >= 0:
            weights[k] = v[i]
    f = Frame(
        capture_time=capture,
        send_time=send,
        receive_time=receive,
        session_id=session,
        sequence=seq,
        has_sequence=bool(flags & _HAS_SEQUENCE),
        tracking=Tracking(tracking),
        weights=weights,
        profile_id=profile_id,
    )
    # The frame rule: every value finite, poses the stream decoder accepts, landmarks within
    # 1 km; then weights clamped to [0, 1].
    if not all(map(math.isfinite, (capture, send, receive))) or not np.isfinite(weights).all():
        return INVALID, None
    at = nw
    if head:
        f.head = _read_pose(v[at : at + 7])
        if f.head is None:
            return INVALID, None
        at += 7
    if eyes:
        f.left_eye, f.right_eye = _read_pose(v[at : at + 7]), _read_pose(v[at + 7 : at + 14])
        if f.left_eye is None or f.right_eye is None:
            return INVALID, None
        at += 14
    lm = v[at : at + 3 * nl]
    if not np.isfinite(lm).all() or (nl and np.abs(lm).max() > 1e3):
        return INVALID, None
    f.landmarks = lm.reshape(nl, 3)
    clamped = bool(((weights < 0) | (weights > 1)).any())
    f.weights = np.clip(weights, 0, 1).astype(np.float32)
    return (CLAMPED if clamped else KEPT), f


def _good_record(data: bytes, at: int) -> int:
    """Length of the good record at `at` (magic, length and checksum right), else 0."""
    if len(data) - at < RECORD_HEADER_BYTES or data[at : at + 4] != RECORD_MAGIC:
        return 0
    (length,) = struct.unpack_from("<I", data, at + 4)
    if not 0 < length <= MAX_RECORD_BYTES or len(data) - at - RECORD_HEADER_BYTES < length:
        return 0
    (crc,) = struct.unpack_from("<I", data, at + 8)
    payload = data[at + RECORD_HEADER_BYTES : at + RECORD_HEADER_BYTES + length]
    return (
        RECORD_HEADER_BYTES + length
        if zlib.crc32(payload, zlib.crc32(data[at + 4 : at + 8])) == crc
        else 0
    )


def parse_recording(data: bytes) -> Recording:
    """Raises ValueError when the header is missing, damaged or of another major version."""
    fixed = len(FILE_MAGIC) + 8
    if len(data) < fixed + 4 or data[: len(FILE_MAGIC)] != FILE_MAGIC:
        raise ValueError("not a recording: no SDREC magic")
    major, minor, length = struct.unpack_from("<HHI", data, len(FILE_MAGIC))
    if major != VERSION_MAJOR:
        raise ValueError(f"recording format {major}.{minor} is not 1.x")
    if length > MAX_HEADER_BYTES or len(data) < fixed + length + 4:
        raise ValueError("not a recording: header cut short")
    body = data[len(FILE_MAGIC) : fixed + length]
    (crc,) = struct.unpack_from("<I", data, fixed + length)
    if zlib.crc32(body) != crc:
        raise ValueError("not a recording: header checksum mismatch")
    rec = Recording(Header())
    order = _decode_header_fields(data[fixed : fixed + length], rec.header)
    if rec.header.profile is not None:
        rec.profiles.append(rec.header.profile)
    rec.neutral = rec.header.neutral
    at = fixed + length + 4
    while at < len(data):
        n = _good_record(data, at)
        if n:
            _apply(data[at + RECORD_HEADER_BYTES : at + n], order, rec)
            rec.recovery.records += 1
            at += n
            continue
        nxt = data.find(RECORD_MAGIC[:1], at + 1)
        while nxt >= 0 and nxt + RECORD_HEADER_BYTES <= len(data) and not _good_record(data, nxt):
            nxt = data.find(RECORD_MAGIC[:1], nxt + 1)
        if nxt < 0 or nxt + RECORD_HEADER_BYTES > len(data):
            rec.recovery.truncated_bytes = len(data) - at
            break
        rec.recovery.damaged_regions += 1
        rec.recovery.skipped_bytes += nxt - at
        at = nxt
    return rec


def _apply(payload: bytes, order: list[int], rec: Recording) -> None:
    kind = payload[0]
    ok = True
    if kind == RecordType.FRAME:
        verdict, f = _decode_frame_record(payload, order)
        ok = verdict != BROKEN
        rec.recovery.invalid_frames += verdict == INVALID
        rec.recovery.clamped_frames += verdict == CLAMPED
        if f is not None:
            rec.frames.append(f)
    elif kind == RecordType.PROFILE:
        try:
            rec.profiles.append(
                decode_profile_body(_Reader(payload[1:], DropReason.BAD_LENGTH, "profile"))
            )
        except DecodeError:
            ok = False
    elif kind == RecordType.NEUTRAL:
        xyz = _decode_neutral_body(payload[1:])
        ok = xyz is not None
        if xyz is not None:
            rec.neutral = xyz
    else:
        rec.recovery.unknown_records += 1
    if not ok:
        rec.recovery.damaged_regions += 1


def read_recording(path: str | Path) -> Recording:
    return parse_recording(Path(path).read_bytes())
