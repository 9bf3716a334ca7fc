"""Lip and teeth collision sets on the template (paper 3.3.2): which skin points must stay on
which side of which surface. Found from the geometry, for any head in template topology.

At the mouth corners (commissures) the upper and lower lip are one continuous surface: split
there by the mouth line, points of one side lie "behind" the other side's curling triangles
without any interpenetration. Counted as collisions they made the contact rounds fight each
other on real takes (alex_rom_3: 5 of 41 sampled frames never resolved), so the lip-against-lip
sets leave out points within `lip_corner_radius` of the inner mouth corners; against the teeth
every point of the zone counts."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import softdeca_native as native

from softdeca_train.contact_rules import ContactRules


@dataclass(frozen=True)
class LipSets:
    zone: np.ndarray  # skin vertex indices of the lip contact zone (both lips, corners too)
    upper: np.ndarray  # of the upper lip, away from the mouth corners
    lower: np.ndarray
    upper_triangles: np.ndarray  # skin triangles with all corners in `upper`
    lower_triangles: np.ndarray


def lip_sets_of(skin: np.ndarray, skin_triangles: np.ndarray, rules: ContactRules) -> LipSets:
    """Split the lip contact zone (S points within the rules' `lip_radius` of the inner lip
    contour) into upper and lower lip by the mouth line: the segment between the inner mouth
    corners, per x, raised to the contour's middle; points within `lip_corner_radius` of those
    corners belong to neither. The rules run in the native library (prepare/contact_sets.h),
    the same code that finds an avatar's sets at prepare."""
    return LipSets(*native.lip_sets(skin, skin_triangles, **vars(rules)))
