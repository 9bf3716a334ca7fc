"""Our UDP wire format, version 1.0 (docs/protocol.md): the Python twin of
plugin/src/stream/wire_encode.cpp and wire_decode.cpp. Both must produce the same bytes; the
golden packets in tests/golden/streaming hold them to it."""

from __future__ import annotations

import math
import struct
import zlib
from dataclasses import dataclass
from enum import Enum, IntEnum

import numpy as np

from softdeca_train.streaming.frame import (
    ARKIT_VERTEX_COUNT,
    BLENDSHAPE_COUNT,
    MAX_LANDMARKS,
    Frame,
    Pose,
    Tracking,
)

MAGIC = b"SDCA"
VERSION_MAJOR = 1
VERSION_MINOR = 0
HEADER_BYTES = 16
DATAGRAM_LIMIT = 1200  # every datagram is shorter
LANDMARK_STEP = 1e-5  # metres per landmark unit
NEUTRAL_CHUNK_VERTICES = 80
MAX_NEUTRAL_VERTICES = 4096
MAX_PROFILE_NAME = 64
DEFAULT_PORT = 50110

_HEADER = struct.Struct("<4sBBBBII")
_FRAME_FIXED = struct.Struct("<ddBBH")
_BLOCK = struct.Struct("<HH")


class MessageType(IntEnum):
    FRAME = 1
    PROFILE = 2
    NEUTRAL_CHUNK = 3
    REQUEST = 4


class BlockType(IntEnum):
    WEIGHTS = 1
    HEAD_POSE = 2
    EYE_POSES = 3
    LANDMARKS = 4


class RequestKind(IntEnum):
    PROFILE = 1
    NEUTRAL = 2


class DropReason(str, Enum):
    UNDERSIZED = "undersized"
    OVERSIZED = "oversized"
    BAD_MAGIC = "bad_magic"
    INCOMPATIBLE_VERSION = "incompatible_version"
    BAD_LENGTH = "bad_length"
    BAD_VALUE = "bad_value"
    UNKNOWN_TYPE = "unknown_type"


class DecodeError(ValueError):
    def __init__(self, reason: DropReason, detail: str) -> None:
        super().__init__(f"{reason.value}: {detail}")
        self.reason = reason


def profile_id_of(indices: tuple[int, ...] | list[int]) -> int:
    return zlib.crc32(struct.pack(f"<{len(indices)}H", *indices))


def neutral_id_of(xyz: np.ndarray) -> int:
    return zlib.crc32(np.ascontiguousarray(xyz, dtype="<f4").tobytes())


@dataclass(frozen=True)
class Profile:
    """The ARKit face-mesh vertices whose positions frames carry, in order."""

    name: str
    indices: tuple[int, ...]

    @property
    def id(self) -> int:
        return profile_id_of(self.indices)


@dataclass
class NeutralChunk:
    neutral_id: int
    total_vertices: int
    first_vertex: int
    xyz: np.ndarray  # (n, 3) float32


@dataclass(frozen=True)
class Request:
    what: RequestKind
    id: int = 0


@dataclass(frozen=True)
class Envelope:
    minor: int
    type: MessageType
    session_id: int
    sequence: int


Message = Frame | Profile | NeutralChunk | Request


def _header(kind: MessageType, session_id: int, sequence: int) -> bytes:
    return _HEADER.pack(MAGIC, VERSION_MAJOR, VERSION_MINOR, int(kind), 0, session_id, sequence)


def _pose_bytes(p: Pose) -> bytes:
    return np.concatenate([p.position, p.rotation]).astype("<f4").tobytes()


def _block(kind: BlockType, body: bytes) -> bytes:
    return _BLOCK.pack(int(kind), len(body)) + body


def _round_half_away(x: np.ndarray) -> np.ndarray:
    """C's lround: halves away from zero."""
    return np.sign(x) * np.floor(np.abs(x) + 0.5)


def quantize_weights(weights: np.ndarray) -> np.ndarray:
    w = np.clip(np.asarray(weights, dtype=np.float32).astype(np.float64), 0.0, 1.0)
    return _round_half_away(w * 65535.0).astype(np.uint16)


def quantize_landmarks(xyz: np.ndarray) -> np.ndarray:
    q = _round_half_away(np.asarray(xyz, dtype=np.float32).astype(np.float64) / LANDMARK_STEP)
    if q.size and (q.min() < -32768 or q.max() > 32767):
        raise ValueError("landmark coordinates outside [-0.32768, 0.32767] m")
    return q.astype(np.int16)


def encode_frame(frame: Frame) -> bytes:
    """One frame datagram; the frame's session_id and sequence go into the header."""
    landmarks = np.asarray(frame.landmarks, dtype=np.float32).reshape(-1, 3)
    if len(landmarks) > MAX_LANDMARKS:
        raise ValueError(f"a frame carries at most {MAX_LANDMARKS} landmarks")
    values = [frame.capture_time, frame.send_time, *frame.weights, *landmarks.ravel()]
    if not all(math.isfinite(v) for v in values):
        raise ValueError("frame values must be finite")
    out = bytearray(_header(MessageType.FRAME, frame.session_id, frame.sequence))
    blocks = [_block(BlockType.WEIGHTS, quantize_weights(frame.weights).astype("<u2").tobytes())]
    if frame.head is not None:
        blocks.append(_block(BlockType.HEAD_POSE, _pose_bytes(frame.head)))
    if frame.left_eye is not None and frame.right_eye is not None:
        eyes = _pose_bytes(frame.left_eye) + _pose_bytes(frame.right_eye)
        blocks.append(_block(BlockType.EYE_POSES, eyes))
    if len(landmarks):
        body = struct.pack("<IHH", frame.profile_id, len(landmarks), 0)
        q = quantize_landmarks(landmarks).astype("<i2").tobytes()
        blocks.append(_block(BlockType.LANDMARKS, body + q))
    # The block count lets a receiver see a datagram cut at a block boundary.
    out += _FRAME_FIXED.pack(
        frame.capture_time, frame.send_time, int(frame.tracking), 0, len(blocks)
    )
    out += b"".join(blocks)
    if len(out) >= DATAGRAM_LIMIT:
        raise ValueError(f"datagram of {len(out)} bytes exceeds the limit")
    return bytes(out)


def encode_profile_body(profile: Profile) -> bytes:
    name = profile.name.encode()
    if len(profile.indices) > MAX_LANDMARKS or len(name) > MAX_PROFILE_NAME:
        raise ValueError("a profile has at most 150 vertices and a 64-byte name")
    if any(not 0 <= i < ARKIT_VERTEX_COUNT for i in profile.indices):
        raise ValueError("profile vertices must be below 1220")
    if len(set(profile.indices)) != len(profile.indices):
        raise ValueError("a profile names each vertex once")
    return (
        struct.pack("<IHBB", profile.id, len(profile.indices), len(name), 0)
        + name
        + struct.pack(f"<{len(profile.indices)}H", *profile.indices)
    )


def encode_profile(session_id: int, sequence: int, profile: Profile) -> bytes:
    return _header(MessageType.PROFILE, session_id, sequence) + encode_profile_body(profile)


def split_neutral(xyz: np.ndarray) -> list[NeutralChunk]:
    xyz = np.asarray(xyz, dtype=np.float32).reshape(-1, 3)
    if not 1 <= len(xyz) <= MAX_NEUTRAL_VERTICES or not np.isfinite(xyz).all():
        raise ValueError("a neutral mesh has 1 to 4096 finite vertices")
    nid = neutral_id_of(xyz)
    return [
        NeutralChunk(nid, len(xyz), first, xyz[first : first + NEUTRAL_CHUNK_VERTICES])
        for first in range(0, len(xyz), NEUTRAL_CHUNK_VERTICES)
    ]


def encode_neutral_chunk(session_id: int, sequence: int, chunk: NeutralChunk) -> bytes:
    xyz = np.asarray(chunk.xyz, dtype="<f4").reshape(-1, 3)
    return (
        _header(MessageType.NEUTRAL_CHUNK, session_id, sequence)
        + struct.pack(
            "<IHHHH", chunk.neutral_id, chunk.total_vertices, chunk.first_vertex, len(xyz), 0
        )
        + xyz.tobytes()
    )


def encode_request(session_id: int, sequence: int, request: Request) -> bytes:
    return _header(MessageType.REQUEST, session_id, sequence) + struct.pack(
        "<BBHI", int(request.what), 0, 0, request.id
    )


# ---- decoding ---------------------------------------------------------------------------------


class _Reader:
    """Bounds-checked reads; running out raises DecodeError(reason)."""

    def __init__(self, data: bytes, reason: DropReason, detail: str) -> None:
        self.data, self.pos, self.reason, self.detail = data, 0, reason, detail

    def remaining(self) -> int:
        return len(self.data) - self.pos

    def take(self, n: int) -> bytes:
        if n > self.remaining():
            raise DecodeError(self.reason, self.detail)
        out = self.data[self.pos : self.pos + n]
        self.pos += n
        return out

    def unpack(self, fmt: str) -> tuple:
        return struct.unpack(fmt, self.take(struct.calcsize(fmt)))


def _pose(values: np.ndarray) -> Pose:
    p = Pose(values[:3].astype(np.float32), values[3:7].astype(np.float32))
    if not np.isfinite(values).all() or np.abs(p.position).max() > 1e3:
        raise DecodeError(DropReason.BAD_VALUE, "pose not finite")
    n = float(np.linalg.norm(p.rotation.astype(np.float64)))
    if not 0.9 <= n <= 1.1:
        raise DecodeError(DropReason.BAD_VALUE, "pose rotation is no unit quaternion")
    p.rotation = (p.rotation.astype(np.float64) / n).astype(np.float32)
    return p


def _decode_frame(r: _Reader, env: Envelope) -> Frame:
    if r.remaining() < _FRAME_FIXED.size:
        raise DecodeError(DropReason.UNDERSIZED, "frame shorter than 36 bytes")
    capture, send, tracking, _flags, block_count = r.unpack("<ddBBH")
    if not (math.isfinite(capture) and math.isfinite(send)):
        raise DecodeError(DropReason.BAD_VALUE, "frame time not finite")
    if tracking > Tracking.LIMITED:
        raise DecodeError(DropReason.BAD_VALUE, "unknown tracking state")
    f = Frame(
        capture_time=capture,
        send_time=send,
        session_id=env.session_id,
        sequence=env.sequence,
        has_sequence=True,
        tracking=Tracking(tracking),
    )
    seen: set[int] = set()
    r.reason, r.detail = DropReason.BAD_LENGTH, "truncated block"
    blocks = 0
    while r.remaining() > 0:
        blocks += 1
        kind, length = r.unpack("<HH")
        body = _Reader(r.take(length), DropReason.BAD_LENGTH, "block too short")
        if kind in seen and kind in BlockType.__members__.values():
            raise DecodeError(DropReason.BAD_VALUE, "duplicate block")
        seen.add(kind)
        if kind == BlockType.WEIGHTS:
            q = np.frombuffer(body.take(2 * BLENDSHAPE_COUNT), dtype="<u2")
            f.weights = (q / 65535.0).astype(np.float32)
        elif kind == BlockType.HEAD_POSE:
            f.head = _pose(np.frombuffer(body.take(28), dtype="<f4"))
        elif kind == BlockType.EYE_POSES:
            v = np.frombuffer(body.take(56), dtype="<f4")
            f.left_eye, f.right_eye = _pose(v[:7]), _pose(v[7:])
        elif kind == BlockType.LANDMARKS:
            f.profile_id, count, _ = body.unpack("<IHH")
            if count > MAX_LANDMARKS:
                raise DecodeError(DropReason.BAD_VALUE, "more landmarks than 150")
            q = np.frombuffer(body.take(6 * count), dtype="<i2").reshape(count, 3)
            f.landmarks = (q * LANDMARK_STEP).astype(np.float32)
    if blocks != block_count:
        raise DecodeError(DropReason.BAD_LENGTH, "block count disagrees with the blocks")
    if BlockType.WEIGHTS not in seen:
        raise DecodeError(DropReason.BAD_LENGTH, "frame without a weights block")
    return f


def decode_profile_body(r: _Reader) -> Profile:
    pid, count, name_length, _ = r.unpack("<IHBB")
    if count > MAX_LANDMARKS:
        raise DecodeError(DropReason.BAD_VALUE, "profile with more than 150 vertices")
    if name_length > MAX_PROFILE_NAME:
        raise DecodeError(DropReason.BAD_VALUE, "profile name over 64 bytes")
    r.reason, r.detail = DropReason.BAD_LENGTH, "profile shorter than its counts"
    name = r.take(name_length).decode("utf-8", errors="replace")
    indices = struct.unpack(f"<{count}H", r.take(2 * count))
    if any(i >= ARKIT_VERTEX_COUNT for i in indices) or len(set(indices)) != len(indices):
        raise DecodeError(DropReason.BAD_VALUE, "profile vertex out of range or repeated")
    if profile_id_of(indices) != pid:
        raise DecodeError(DropReason.BAD_VALUE, "profile id does not match its indices")
    return Profile(name, tuple(indices))


def _decode_neutral(r: _Reader) -> NeutralChunk:
    nid, total, first, count, _ = r.unpack("<IHHHH")
    if not (
        0 < total <= MAX_NEUTRAL_VERTICES
        and 0 < count <= NEUTRAL_CHUNK_VERTICES
        and first + count <= total
    ):
        raise DecodeError(DropReason.BAD_VALUE, "neutral chunk counts out of range")
    r.reason, r.detail = DropReason.BAD_LENGTH, "neutral chunk shorter than its count"
    xyz = np.frombuffer(r.take(12 * count), dtype="<f4").reshape(count, 3).astype(np.float32)
    if not np.isfinite(xyz).all():
        raise DecodeError(DropReason.BAD_VALUE, "neutral vertex not finite")
    return NeutralChunk(nid, total, first, xyz)


def decode(data: bytes) -> tuple[Envelope, Message]:
    """Parses one datagram; raises DecodeError with the receiver's drop reason."""
    if len(data) >= DATAGRAM_LIMIT:
        raise DecodeError(DropReason.OVERSIZED, "datagram of 1,200 bytes or more")
    if len(data) < HEADER_BYTES:
        raise DecodeError(DropReason.UNDERSIZED, "datagram shorter than the 16-byte header")
    magic, major, minor, kind, _flags, session, sequence = _HEADER.unpack_from(data)
    if magic != MAGIC:
        raise DecodeError(DropReason.BAD_MAGIC, "no SDCA magic")
    if major != VERSION_MAJOR:
        raise DecodeError(DropReason.INCOMPATIBLE_VERSION, "protocol major version is not 1")
    if kind not in MessageType.__members__.values():
        raise DecodeError(DropReason.UNKNOWN_TYPE, "message type of a newer minor version")
    env = Envelope(minor, MessageType(kind), session, sequence)
    r = _Reader(data[HEADER_BYTES:], DropReason.UNDERSIZED, "message shorter than its fields")
    if env.type == MessageType.FRAME:
        return env, _decode_frame(r, env)
    if env.type == MessageType.PROFILE:
        return env, decode_profile_body(r)
    if env.type == MessageType.NEUTRAL_CHUNK:
        return env, _decode_neutral(r)
    what, _, _, rid = r.unpack("<BBHI")
    if what not in RequestKind.__members__.values():
        raise DecodeError(DropReason.UNKNOWN_TYPE, "request for something this version lacks")
    return env, Request(RequestKind(what), rid)
