"""Epic's Live Link Face app: its UDP packet (version 6, big-endian) and its CSV takes; the
Python twin of plugin/src/stream/livelinkface_*.cpp and recording/livelinkface_csv.cpp."""

from __future__ import annotations

import math
import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from softdeca_train.face_names import ARKIT_BLENDSHAPES, LIVELINKFACE_VALUES
from softdeca_train.streaming.frame import BLENDSHAPE_COUNT, Frame, Pose, Tracking
from softdeca_train.streaming.protocol import DecodeError, DropReason
from softdeca_train.streaming.rotations import (
    quaternion_from_yaw_pitch_roll,
    yaw_pitch_roll_from_quaternion,
)

PORT = 11111
PACKET_VERSION = 6
MAX_NAME_BYTES = 255
MAX_PACKET_BYTES = 2048
TIMECODE_RATE = 60.0  # the app's default timecode clock

# The app's 61 values in its packet order (Unreal's EARFaceBlendShape).
VALUE_NAMES: tuple[str, ...] = LIVELINKFACE_VALUES
VALUE_COUNT = len(VALUE_NAMES)
HEAD_YAW, LEFT_EYE_YAW, RIGHT_EYE_YAW = 52, 55, 58
# Canonical index of each of the first 52 values.
CANONICAL = np.array([ARKIT_BLENDSHAPES.index(n[0].lower() + n[1:]) for n in VALUE_NAMES[:52]])
# The CSV's column order: the packet order with JawLeft/JawRight and MouthLeft/MouthRight swapped.
CSV_ORDER = list(range(VALUE_COUNT))
CSV_ORDER[15], CSV_ORDER[16] = 16, 15
CSV_ORDER[21], CSV_ORDER[22] = 22, 21


def values_to_frame(values: np.ndarray, frame: Frame) -> None:
    """Weights (clamped to [0, 1]) and head and eye rotations from the 61 values."""
    v = np.asarray(values, dtype=np.float32)
    frame.weights = np.zeros(BLENDSHAPE_COUNT, dtype=np.float32)
    frame.weights[CANONICAL] = np.clip(v[:52], 0.0, 1.0)

    def pose(at: int) -> Pose:
        return Pose(rotation=quaternion_from_yaw_pitch_roll(*(float(x) for x in v[at : at + 3])))

    frame.head, frame.left_eye, frame.right_eye = (
        pose(HEAD_YAW),
        pose(LEFT_EYE_YAW),
        pose(RIGHT_EYE_YAW),
    )


def frame_to_values(frame: Frame) -> np.ndarray:
    v = np.zeros(VALUE_COUNT, dtype=np.float32)
    v[:52] = frame.weights[CANONICAL]
    for at, pose in (
        (HEAD_YAW, frame.head),
        (LEFT_EYE_YAW, frame.left_eye),
        (RIGHT_EYE_YAW, frame.right_eye),
    ):
        if pose is not None:
            v[at : at + 3] = yaw_pitch_roll_from_quaternion(pose.rotation)
    return v


def session_id_of(device_id: str, subject: str) -> int:
    return zlib.crc32(f"{device_id}\n{subject}".encode())


@dataclass
class PacketInfo:
    device_id: str = "softdeca-virtual-device"
    subject: str = "take"
    frame_number: int = 0
    subframe: float = 0.0
    fps_numerator: int = 60
    fps_denominator: int = 1


def encode_packet(frame: Frame, info: PacketInfo) -> bytes:
    """A packet whose frame time is the frame's capture time at info's rate."""
    dev, sub = info.device_id.encode(), info.subject.encode()
    if len(dev) > MAX_NAME_BYTES or len(sub) > MAX_NAME_BYTES:
        raise ValueError("device id and subject have at most 255 bytes each")
    frames = frame.capture_time * info.fps_numerator / info.fps_denominator
    whole = math.floor(frames)
    out = (
        struct.pack(">Bi", PACKET_VERSION, len(dev))
        + dev
        + struct.pack(">i", len(sub))
        + sub
        + struct.pack(">ifii", whole, frames - whole, info.fps_numerator, info.fps_denominator)
    )
    if frame.tracking == Tracking.LOST:
        return out + b"\x00"
    values = frame_to_values(frame)
    if not np.isfinite(values).all():
        raise ValueError("frame values must be finite")
    return out + struct.pack(">B", VALUE_COUNT) + values.astype(">f4").tobytes()


def decode_packet(data: bytes) -> tuple[Frame, PacketInfo]:
    if len(data) > MAX_PACKET_BYTES:
        raise DecodeError(DropReason.OVERSIZED, "Live Link Face packet over 2048 bytes")
    if not data:
        raise DecodeError(DropReason.UNDERSIZED, "empty datagram")
    if data[0] != PACKET_VERSION:
        raise DecodeError(DropReason.INCOMPATIBLE_VERSION, "Live Link Face packet version is not 6")
    pos = 1
    names = []
    for _ in range(2):
        if len(data) - pos < 4:
            raise DecodeError(DropReason.BAD_LENGTH, "name length missing")
        (n,) = struct.unpack_from(">i", data, pos)
        if not 0 <= n <= MAX_NAME_BYTES or len(data) - pos - 4 < n:
            raise DecodeError(DropReason.BAD_LENGTH, "name length disagrees with the packet")
        names.append(data[pos + 4 : pos + 4 + n].decode("utf-8", errors="replace"))
        pos += 4 + n
    if len(data) - pos < 17:
        raise DecodeError(DropReason.UNDERSIZED, "packet cut before its values")
    frame_number, subframe, num, den, count = struct.unpack_from(">ifiiB", data, pos)
    pos += 17
    if num <= 0 or den <= 0 or not math.isfinite(subframe):
        raise DecodeError(DropReason.BAD_VALUE, "frame rate or subframe invalid")
    if count != 0 and count < VALUE_COUNT:
        raise DecodeError(DropReason.BAD_LENGTH, "packet with 1 to 60 values")
    if len(data) - pos < 4 * count:
        raise DecodeError(DropReason.BAD_LENGTH, "packet shorter than its value count")
    values = np.frombuffer(data, dtype=">f4", count=count, offset=pos).astype(np.float32)
    if not np.isfinite(values).all():
        raise DecodeError(DropReason.BAD_VALUE, "value not finite")
    info = PacketInfo(names[0], names[1], frame_number, subframe, num, den)
    frame = Frame(
        capture_time=(frame_number + subframe) * den / num,
        session_id=session_id_of(names[0], names[1]),
    )
    if count == 0:
        frame.tracking = Tracking.LOST
    else:
        values_to_frame(values[:VALUE_COUNT], frame)
    return frame, info


# ---- CSV takes --------------------------------------------------------------------------------


def parse_timecode(text: str, rate: float = TIMECODE_RATE) -> float:
    """ "HH:MM:SS:FF.mmm" -> seconds since midnight (FF frames and mmm thousandths of one)."""
    h, m, s, rest = text.split(":")
    frame, _, sub = rest.partition(".")
    if (
        not (
            h.isdigit()
            and m.isdigit()
            and s.isdigit()
            and frame.isdigit()
            and (sub == "" or sub.isdigit())
        )
        or len(sub) > 3
    ):
        raise ValueError(f"not a timecode: {text!r}")
    if int(h) >= 24 or int(m) >= 60 or int(s) >= 60 or int(frame) >= math.ceil(rate):
        raise ValueError(f"timecode field out of range: {text!r}")
    subframe = int(sub) / 10 ** len(sub) if sub else 0.0
    return int(h) * 3600 + int(m) * 60 + int(s) + (int(frame) + subframe) / rate


def format_timecode(seconds: float, rate: int) -> str:
    thousandths = math.floor(seconds * rate * 1000.0 + 0.5)  # C's llround for seconds >= 0
    frames, milli = divmod(thousandths, 1000)
    whole, frame = divmod(frames, rate)
    return (
        f"{whole // 3600 % 24:02d}:{whole // 60 % 60:02d}:{whole % 60:02d}:{frame:02d}.{milli:03d}"
    )


@dataclass
class CsvTake:
    frames: list[Frame] = field(default_factory=list)
    rows: int = 0
    face_lost_rows: int = 0  # the app had lost the face: timecode and a zero count only
    malformed_rows: int = 0


def parse_csv(text: str, rate: float = TIMECODE_RATE) -> CsvTake:
    """Columns by name (either spelling of BlendShapeCount); face-lost rows skipped and counted."""
    lines = [ln for ln in text.lstrip("\ufeff").splitlines() if ln]
    if not lines:
        raise ValueError("empty Live Link Face CSV")
    header = lines[0].split(",")
    col = {name: i for i, name in enumerate(header)}
    if "Timecode" not in col or any(n not in col for n in VALUE_NAMES[:52]):
        raise ValueError("Live Link Face CSV without Timecode or a blendshape column")
    count_col = col.get("BlendShapeCount", col.get("BlendshapeCount"))
    present = [n in col for n in VALUE_NAMES]
    take = CsvTake()
    for line in lines[1:]:
        take.rows += 1
        fields = line.split(",")
        if len(fields) != len(header):
            zero = count_col is not None and count_col < len(fields) and fields[count_col] == "0"
            if zero:
                take.face_lost_rows += 1
            else:
                take.malformed_rows += 1
            continue
        try:
            t = parse_timecode(fields[col["Timecode"]], rate)
            values = np.array(
                [
                    float(fields[col[n]]) if ok else 0.0
                    for n, ok in zip(VALUE_NAMES, present, strict=True)
                ],
                dtype=np.float32,
            )
        except ValueError:
            take.malformed_rows += 1
            continue
        if not np.isfinite(values).all():
            take.malformed_rows += 1
            continue
        f = Frame(capture_time=t)
        values_to_frame(values, f)
        if not all(present[HEAD_YAW : HEAD_YAW + 3]):
            f.head = None
        if not all(present[LEFT_EYE_YAW:]):
            f.left_eye = f.right_eye = None
        take.frames.append(f)
    return take


def read_csv(path: str | Path, rate: float = TIMECODE_RATE) -> CsvTake:
    return parse_csv(Path(path).read_text(encoding="utf-8"), rate)


def shortest_float32(v: float) -> str:
    """The shortest text that reads back as the same 32-bit float, as C++'s std::to_chars
    writes it: fixed or scientific, whichever is shorter (fixed on a tie); -0 as 0."""
    x = np.float32(float(v) + 0.0)
    # A whole number is written with all its digits in fixed form (161682407424, not
    # 161682400000); its length is the same either way.
    fixed = (
        str(int(x))
        if float(x).is_integer()
        else np.format_float_positional(x, unique=True, trim="-")
    )
    scientific = np.format_float_scientific(x, unique=True, trim="-", exp_digits=2)
    return scientific if len(scientific) < len(fixed) else fixed


def format_csv(frames: list[Frame], rate: int = int(TIMECODE_RATE)) -> str:
    out = ["Timecode,BlendShapeCount," + ",".join(VALUE_NAMES[i] for i in CSV_ORDER)]
    for f in frames:
        if f.tracking != Tracking.TRACKED:
            continue
        v = frame_to_values(f)
        out.append(
            format_timecode(f.capture_time, rate)
            + ",61,"
            + ",".join(shortest_float32(v[i]) for i in CSV_ORDER)
        )
    return "\n".join(out) + "\n"
