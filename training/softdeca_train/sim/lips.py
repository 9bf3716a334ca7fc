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

from softdeca_train.contact_rules import ContactRules
from softdeca_train.template.plausibility import lip_contact_zone


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
    corners (ICT landmarks 60 and 64), per x; points within `lip_corner_radius` of those
    corners belong to neither."""
    lm68 = rules.landmarks68
    zone = np.flatnonzero(lip_contact_zone(skin, lm68, rules.lip_radius))
    lm = skin[lm68]
    left, right = lm[64], lm[60]
    t = np.clip((skin[zone, 0] - right[0]) / (left[0] - right[0]), 0.0, 1.0)
    mouth_y = right[1] + t * (left[1] - right[1])
    # The inner lip contour's midpoint between the upper (62) and lower (66) middles.
    mouth_y += 0.5 * (lm[62, 1] + lm[66, 1]) - 0.5 * (left[1] + right[1])
    corner = np.linalg.norm(skin[zone, None] - lm[None, [60, 64]], axis=2).min(axis=1)
    away = corner > rules.lip_corner_radius
    upper = zone[away & (skin[zone, 1] >= mouth_y)]
    lower = zone[away & (skin[zone, 1] < mouth_y)]
    tris = np.asarray(skin_triangles)

    def inside(ids: np.ndarray) -> np.ndarray:
        mask = np.zeros(len(skin), bool)
        mask[ids] = True
        return tris[mask[tris].all(axis=1)]

    return LipSets(zone, upper, lower, inside(upper), inside(lower))
