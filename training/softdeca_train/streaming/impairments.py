"""Deterministic network impairments for the virtual device: loss, duplication, reordering and
jitter of frame datagrams, drawn from a seeded generator so that a test knows exactly what the
receiver should count."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Impairments:
    loss: float = 0.0  # probability that a frame datagram is not sent
    duplicate: float = 0.0  # probability that it is sent twice
    reorder: float = 0.0  # probability that it is held back until after the next datagram
    jitter_ms: float = 0.0  # extra delay per datagram, uniform in [0, jitter_ms]
    seed: int = 0
    # The first and last frames go through untouched: a receiver cannot see loss at the very
    # ends of a stream, so tests could not hold it to an exact count there.
    protect: int = 3

    def __post_init__(self) -> None:
        for name in ("loss", "duplicate", "reorder"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"{name} must be a probability in [0, 1]")
        if self.jitter_ms < 0:
            raise ValueError("jitter_ms must be >= 0")

    @property
    def active(self) -> bool:
        return self.loss > 0 or self.duplicate > 0 or self.reorder > 0 or self.jitter_ms > 0


@dataclass(frozen=True)
class Fate:
    """What happens to one frame datagram."""

    dropped: bool = False
    copies: int = 1
    held: bool = False  # sent after the next datagram
    delay: float = 0.0  # seconds of jitter


class FateDrawer:
    def __init__(self, impairments: Impairments, frame_count: int) -> None:
        self.imp = impairments
        self.count = frame_count
        self.rng = np.random.default_rng(impairments.seed)

    def fate(self, index: int) -> Fate:
        # Draw for every frame, protected or not, so fates do not shift with `protect`.
        u = self.rng.random(4)
        if index < self.imp.protect or index >= self.count - self.imp.protect:
            return Fate()
        if u[0] < self.imp.loss:
            return Fate(dropped=True)
        return Fate(
            copies=2 if u[1] < self.imp.duplicate else 1,
            held=bool(u[2] < self.imp.reorder),
            delay=float(u[3]) * self.imp.jitter_ms / 1000.0,
        )
