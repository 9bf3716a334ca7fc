"""The physics column of a replay's contact sheet: φ† itself (static, default parameters,
collisions on) on the shown frames of the take, for the identity the avatar was made from, so
that the picture shows what the networks were trained to reproduce next to what they produce.

The shown frames include the take's widest-open mouth (of the linear blendshapes), where the
physics has to keep the lips apart as the linear blend has them, and the lip opening (inner
middles of the upper and lower lip) of every column is measured there."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdeca_train.sim import sanity
from softdeca_train.template import Template

# Linear blends of the replay and of the simulation must agree to this (m): the avatar was
# made from the identity the physics simulates, else the columns compare different faces.
SAME_FACE_TOLERANCE = 1e-4


@dataclass(frozen=True)
class PhysicsColumn:
    heads: np.ndarray  # (len(frames), V, 3) whole heads from φ†
    failures: list[list[str]]  # the sanity bounds' reasons per frame (empty: passes)
    seconds: float


def lip_openings_mm(heads: np.ndarray, template: Template) -> np.ndarray:
    """(F, V, 3) heads in template order -> (F,) signed inner-lip-middle distances in mm."""
    return sanity.lip_openings_mm(template.landmarks68, heads)


def widest_open_frame(linear: np.ndarray, template: Template) -> int:
    return int(np.argmax(lip_openings_mm(linear, template)))


def simulate_column(
    take: Path,
    first_frame: int,
    frames: list[int],
    linear: np.ndarray,
    template: Template,
    seed: int,
    level: int = 3,
) -> PhysicsColumn:
    """φ† on frames `frames` (indices into the replay, whose frame 0 is the take's tracked
    frame `first_frame`) for ICT identity `seed`; `linear` is the replay's linear cache, the
    check that the avatar is that identity."""
    import time

    from softdeca_train.lhm import LhmConfig
    from softdeca_train.sim.head import build_head_simulation
    from softdeca_train.sim.run import simulate_frames
    from softdeca_train.sim.take import read_take

    t0 = time.perf_counter()
    weights = np.stack([read_take(take, first_frame + f, 1).weights[0] for f in frames])
    hs = build_head_simulation(template, template.sample_identity(seed), LhmConfig(level=level))
    ours = hs.blend(weights)
    if ours.shape != linear[frames].shape:
        raise ValueError(
            f"the replay's heads have {linear.shape[1]} vertices, the simulated identity "
            f"{ours.shape[1]}: not the same head model"
        )
    off = float(np.abs(ours - linear[frames]).max())
    if off > SAME_FACE_TOLERANCE:
        raise ValueError(
            f"the replay's linear blendshapes differ from identity seed {seed}'s by "
            f"{1e3 * off:.2f} mm: the avatar was not made from that identity"
        )
    result = simulate_frames(hs, hs.simulator(threads=1), weights, progress=False)
    return PhysicsColumn(
        heads=np.stack(result.physics),
        failures=[r.failures for r in result.records],
        seconds=time.perf_counter() - t0,
    )
