"""The virtual device: streams a take (a Live Link Face CSV or a recording) over UDP at the
take's rate, in our protocol or Live Link Face's packet format, with optional loss, duplication,
reordering and jitter. In our protocol it sends the landmark profile (at start and every
second), the neutral mesh, and answers a receiver's requests for either; landmark positions
come from the take's weights through ARKit's reference face."""

from __future__ import annotations

import heapq
import random
import socket
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.streaming import livelinkface, protocol
from softdeca_train.streaming.frame import Frame
from softdeca_train.streaming.impairments import FateDrawer, Impairments
from softdeca_train.streaming.recording import read_recording
from softdeca_train.streaming.reference_face import ReferenceFace

FORMATS = ("softdeca", "livelinkface")


@dataclass
class VirtualDeviceConfig:
    take: Path
    host: str = "127.0.0.1"
    port: int | None = None  # None: the format's default port
    format: str = "softdeca"
    landmarks: str = "softdeca149"  # landmark profile (ours only): softdeca149, arkit68 or none
    speed: float = 1.0
    start: int = 0  # first frame of the take
    count: int | None = None  # frames to send; None: to the end
    impairments: Impairments = field(default_factory=Impairments)
    timecode_rate: float = livelinkface.TIMECODE_RATE  # of a CSV take
    session_id: int | None = None  # None: random
    profile_interval: float = 1.0  # seconds between profile repeats
    reference: Path | None = None  # ARKit reference folder; None: the default
    progress: bool = False


@dataclass
class SendLog:
    """What went on the wire, in order: the sequence number (ours) and kind of each datagram."""

    session_id: int
    datagrams: list[tuple[int | None, str]] = field(default_factory=list)
    # The take's frames as planned (with landmarks), whether sent or not.
    frames: list[Frame] = field(default_factory=list)
    dropped: list[int] = field(default_factory=list)  # planned frame indices not sent
    duplicated: int = 0
    held: int = 0
    requests_answered: int = 0


def load_take(path: Path, timecode_rate: float = livelinkface.TIMECODE_RATE) -> list[Frame]:
    if path.suffix == ".sdrec":
        return read_recording(path).frames
    return livelinkface.read_csv(path, timecode_rate).frames


class _Wire:
    """Datagrams due at given times, sent in time order (jitter may reorder them)."""

    def __init__(self, sock: socket.socket, to: tuple[str, int], log: SendLog) -> None:
        self.sock, self.to, self.log = sock, to, log
        self.heap: list[tuple[float, int, bytes, int | None, str]] = []
        self.order = 0

    def put(self, due: float, data: bytes, seq: int | None, kind: str) -> None:
        heapq.heappush(self.heap, (due, self.order, data, seq, kind))
        self.order += 1

    def flush(self, now: float) -> None:
        while self.heap and self.heap[0][0] <= now:
            _, _, data, seq, kind = heapq.heappop(self.heap)
            self.sock.sendto(data, self.to)
            self.log.datagrams.append((seq, kind))

    def next_due(self) -> float:
        return self.heap[0][0] if self.heap else float("inf")


class _Device:
    """The sending side: sequence numbers, control messages and request answers (ours)."""

    def __init__(
        self,
        wire: _Wire,
        session: int,
        profile: protocol.Profile | None,
        face: ReferenceFace | None,
    ) -> None:
        self.wire, self.session, self.profile, self.face = wire, session, profile, face
        self.seq = 0

    def next_sequence(self) -> int:
        self.seq += 1
        return self.seq - 1

    def send_profile(self, now: float) -> None:
        assert self.profile is not None
        s = self.next_sequence()
        self.wire.put(now, protocol.encode_profile(self.session, s, self.profile), s, "profile")

    def send_neutral(self, now: float) -> None:
        assert self.face is not None
        for chunk in protocol.split_neutral(self.face.neutral):
            s = self.next_sequence()
            self.wire.put(now, protocol.encode_neutral_chunk(self.session, s, chunk), s, "neutral")

    def answer_requests(self, now: float) -> int:
        """Answers the receiver's profile and neutral requests waiting on the socket."""
        answered = 0
        while True:
            try:
                data = self.wire.sock.recv(2048)
            except BlockingIOError:
                return answered
            try:
                env, msg = protocol.decode(data)
            except protocol.DecodeError:
                continue
            if not isinstance(msg, protocol.Request) or env.session_id != self.session:
                continue
            if (
                msg.what == protocol.RequestKind.PROFILE
                and self.profile
                and msg.id == self.profile.id
            ):
                self.send_profile(now)
                answered += 1
            elif msg.what == protocol.RequestKind.NEUTRAL and self.face is not None:
                self.send_neutral(now)
                answered += 1


def run(config: VirtualDeviceConfig) -> SendLog:
    """Streams the take; returns what went on the wire."""
    if config.format not in FORMATS:
        raise ValueError(f"format must be one of {FORMATS}")
    if not config.speed > 0:
        raise ValueError("speed must be > 0")
    ours = config.format == "softdeca"
    frames = load_take(config.take, config.timecode_rate)
    end = len(frames) if config.count is None else config.start + config.count
    frames = frames[config.start : end]
    if not frames:
        raise ValueError(f"{config.take}: no frames in the chosen range")
    face = ReferenceFace.load(config.reference) if ours and config.landmarks != "none" else None
    profile = face.profile(config.landmarks) if face is not None else None
    if face is not None and profile is not None:
        idx = np.array(profile.indices)
        for f in frames:
            f.profile_id = profile.id
            f.landmarks = face.blend(f.weights, idx).astype(np.float32)
    session = config.session_id if config.session_id is not None else random.getrandbits(32) | 1
    log = SendLog(session, frames=frames)
    port = config.port or (protocol.DEFAULT_PORT if ours else livelinkface.PORT)
    info = livelinkface.PacketInfo(subject=config.take.stem)
    drawer = FateDrawer(config.impairments, len(frames))
    family = socket.AF_INET6 if ":" in config.host else socket.AF_INET
    with socket.socket(family, socket.SOCK_DGRAM) as sock:
        sock.setblocking(False)
        wire = _Wire(sock, (config.host, port), log)
        device = _Device(wire, session, profile, face)
        t0 = time.monotonic()
        first = frames[0].capture_time
        if profile is not None:
            device.send_profile(t0)
            device.send_neutral(t0)
        last_profile = t0
        progress = _progress(config.progress, len(frames))
        for i, frame in enumerate(frames):
            due = t0 + (frame.capture_time - first) / config.speed
            now = time.monotonic()
            while now < due:  # sleep to the frame's time, sending what falls due meanwhile
                time.sleep(max(0.0, min(due, wire.next_due()) - now))
                now = time.monotonic()
                wire.flush(now)
            if profile is not None:
                log.requests_answered += device.answer_requests(now)
                if now - last_profile >= config.profile_interval:
                    device.send_profile(now)
                    last_profile = now
            fate = drawer.fate(i)
            number: int | None = None
            if ours:
                number = device.next_sequence()
                frame.session_id, frame.sequence, frame.send_time = (
                    session,
                    number,
                    time.monotonic(),
                )
                data = protocol.encode_frame(frame)
            else:
                data = livelinkface.encode_packet(frame, info)
            if fate.dropped:
                log.dropped.append(i)
            else:
                # A held datagram waits until just after the next frame's time.
                at = now
                if fate.held and i + 1 < len(frames):
                    at = t0 + (frames[i + 1].capture_time - first) / config.speed + 1e-4
                for _ in range(fate.copies):
                    wire.put(at + fate.delay, data, number, "frame")
                log.duplicated += fate.copies - 1
                log.held += fate.held
            wire.flush(time.monotonic())
            progress(i + 1)
        while wire.heap:
            time.sleep(max(0.0, wire.next_due() - time.monotonic()))
            wire.flush(time.monotonic())
    return log


def _progress(enabled: bool, total: int) -> Callable[[int], None]:
    if not enabled:
        return lambda n: None

    bar = tqdm(total=total, unit="frame", desc="virtual device")

    def update(n: int) -> None:
        bar.update(n - bar.n)
        if n == total:
            bar.close()

    return update
