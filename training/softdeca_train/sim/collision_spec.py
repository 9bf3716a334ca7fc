"""A head's collision sets as plain arrays (native.CollisionSet's fields): the lips against
each other and the teeth, the eyelids placed on their targets (paper 3.3.2; sim/lips.py,
sim/lids.py say which points)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from softdeca_train.sim.lids import LidSets
    from softdeca_train.sim.lips import LipSets


@dataclass(frozen=True)
class CollisionSpec:
    """One collision set of a head (native.CollisionSet's fields)."""

    name: str
    points: np.ndarray  # skin point indices
    surface: np.ndarray  # (T, 3) int32 over skin points, or simulated vertices (teeth)
    surface_on_skin: bool


def collision_sets(
    lips: LipSets, lids: LidSets, upper_teeth: np.ndarray, lower_teeth: np.ndarray
) -> list[CollisionSpec]:
    """The sets of a head; `*_teeth`: the teeth's triangles over simulated vertices."""
    i32 = np.int32
    zone = lips.zone.astype(i32)
    return [
        CollisionSpec("upper_lip_over_lower_lip", lips.upper.astype(i32),
                      lips.lower_triangles.astype(i32), True),
        CollisionSpec("lower_lip_over_upper_lip", lips.lower.astype(i32),
                      lips.upper_triangles.astype(i32), True),
        CollisionSpec("lips_over_upper_teeth", zone, np.asarray(upper_teeth, i32), False),
        CollisionSpec("lips_over_lower_teeth", zone, np.asarray(lower_teeth, i32), False),
        # The eyelids: placed on their targets like the lips, with no surface to stay out of
        # (sim/lids.py says why no lid contacts).
        CollisionSpec("eyelids", np.concatenate([lids.upper, lids.lower]).astype(i32),
                      np.zeros((0, 3), i32), True),
    ]  # fmt: skip
