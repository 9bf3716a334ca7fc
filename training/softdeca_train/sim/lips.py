"""Lip and teeth collision sets on the template (paper 3.3.2): which skin points must stay on
which side of which surface. Found from the geometry, for any head in template topology.

At the mouth corners (commissures) the upper and lower lip are one continuous surface: split
there by the mouth line, points of one side lie "behind" the other side's curling triangles
without any interpenetration. Counted as collisions they made the contact rounds fight each
other on real takes (alex_rom_3: 5 of 41 sampled frames never resolved), so the lip-against-lip
sets leave out points within `corner_radius` of the inner mouth corners; against the teeth every
point of the zone counts."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.lhm.mouth import upper_lip_points
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.plausibility import lip_contact_zone


@dataclass(frozen=True)
class LipSets:
    zone: np.ndarray  # skin vertex indices of the lip contact zone (both lips, corners too)
    upper: np.ndarray  # of the upper lip, away from the mouth corners
    lower: np.ndarray
    upper_triangles: np.ndarray  # skin triangles with all corners in `upper`
    lower_triangles: np.ndarray


def lip_sets(
    template: Template, head: np.ndarray, radius: float = 0.012, corner_radius: float = 0.008
) -> LipSets:
    """Split the lip contact zone into upper and lower lip: each point goes to the lip whose
    landmarks are nearer along S (lhm/mouth.py `upper_lip_points`; a split by height fails
    where the lips are pressed into each other); points within `corner_radius` of the inner
    mouth corners (ICT landmarks 60 and 64) belong to neither."""
    zone = np.flatnonzero(lip_contact_zone(head, template.landmarks68, radius))
    lm = head[template.landmarks68]
    above = upper_lip_points(head[:N_SKIN], template.skin_triangles, template.landmarks68, zone)
    corner = np.linalg.norm(head[zone, None] - lm[None, [60, 64]], axis=2).min(axis=1)
    away = corner > corner_radius
    upper = zone[away & above]
    lower = zone[away & ~above]
    tris = template.skin_triangles

    def inside(ids: np.ndarray) -> np.ndarray:
        mask = np.zeros(N_SKIN, bool)
        mask[ids] = True
        return tris[mask[tris].all(axis=1)]

    return LipSets(zone, upper, lower, inside(upper), inside(lower))
