"""Recorded Live Link Face takes in the forms they are shared in: the app's CSV export and LLV's
recordings (`.gesichter`, the UDP packets as the LLV recorder keeps them). Both read into the
same CsvTake, face-lost frames counted, and both bounded in memory whatever the file holds."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

from softdeca_train.streaming.frame import Tracking
from softdeca_train.streaming.livelinkface import (
    MAX_PACKET_BYTES,
    CsvTake,
    decode_packet,
    read_csv,
)
from softdeca_train.streaming.protocol import DecodeError

TAKE_SUFFIXES = (".csv", ".gesichter")
LLV_VERSION = 6  # the container's version byte (LLV writes its packets' version)
# The decompressed container may hold at most this much: about 3.5 hours of 320-byte packets
# at 60 fps, so a hostile file cannot make the reader allocate more.
MAX_LLV_BYTES = 256 << 20
MAX_LLV_FILE_BYTES = 64 << 20


def _gunzip_bounded(raw: bytes, limit: int) -> bytes:
    d = zlib.decompressobj(wbits=16 + zlib.MAX_WBITS)
    out = d.decompress(raw, limit + 1)
    if len(out) > limit or d.unconsumed_tail:
        raise ValueError(f"LLV recording larger than {limit >> 20} MiB decompressed")
    if not d.eof:
        raise ValueError("LLV recording cut short (gzip stream incomplete)")
    return out


def parse_gesichter(raw: bytes) -> CsvTake:
    """An LLV recording: gzip of a version byte, a big-endian u32 frame count, then per frame
    a big-endian u32 size and one Live Link Face packet. Packets that fail to decode count as
    malformed; those of a lost face as face-lost, as rows of a CSV take do."""
    data = _gunzip_bounded(raw, MAX_LLV_BYTES)
    if len(data) < 5 or data[0] != LLV_VERSION:
        raise ValueError("not an LLV recording (version byte 6 and a frame count expected)")
    (count,) = struct.unpack_from(">I", data, 1)
    take = CsvTake()
    pos = 5
    while pos < len(data):
        if take.rows == count:
            raise ValueError(f"LLV recording holds more than its {count} frames")
        if len(data) - pos < 4:
            raise ValueError("LLV recording cut inside a packet size")
        (size,) = struct.unpack_from(">I", data, pos)
        if size > MAX_PACKET_BYTES or len(data) - pos - 4 < size:
            raise ValueError(f"LLV packet {take.rows}: size {size} disagrees with the file")
        take.rows += 1
        try:
            frame, _ = decode_packet(data[pos + 4 : pos + 4 + size])
        except DecodeError:
            take.malformed_rows += 1
        else:
            if frame.tracking == Tracking.TRACKED:
                take.frames.append(frame)
            else:
                take.face_lost_rows += 1
        pos += 4 + size
    if take.rows != count:
        raise ValueError(f"LLV recording holds {take.rows} of its {count} frames")
    return take


def read_take(path: str | Path) -> CsvTake:
    """A take by its suffix: Live Link Face CSV or LLV recording."""
    path = Path(path)
    if path.suffix == ".gesichter":
        if path.stat().st_size > MAX_LLV_FILE_BYTES:
            raise ValueError(f"{path}: larger than {MAX_LLV_FILE_BYTES >> 20} MiB")
        return parse_gesichter(path.read_bytes())
    if path.suffix == ".csv":
        return read_csv(path)
    raise ValueError(f"{path}: not a take ({', '.join(TAKE_SUFFIXES)})")


def take_paths(folder: Path) -> list[Path]:
    """Every take below `folder`, sorted by path. Where a folder holds an LLV recording and the
    same take converted to CSV, the original is read and the copy left out."""
    paths = sorted(p for s in TAKE_SUFFIXES for p in Path(folder).rglob(f"*{s}"))
    originals = {p.with_suffix("") for p in paths if p.suffix == ".gesichter"}
    return [p for p in paths if p.suffix != ".csv" or p.with_suffix("") not in originals]
