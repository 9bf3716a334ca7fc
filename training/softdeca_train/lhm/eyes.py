"""The eyelids in the layered head model: a slit through every wrap along each eye's fissure,
cut like the mouth's (lhm/mouth.py), and each lid's points of S on its own side of it.

The wraps pass over the eye openings (S's eye sockets lie inside them), so without the slits
the volume in front of and around each eyeball is one piece of soft tissue holding both lids:
a full blink closed the template's lid gap from 8.3 to 6.5 mm at level 3 (the linear blend:
0.4 mm), and only to 3.3 mm with every tissue weight near zero and w_target 100, because
points of both lids shared tets."""

from __future__ import annotations

import numpy as np

from softdeca_train.contact_rules import CONTACT_RULES
from softdeca_train.lhm.mouth import closest_on_polyline

# ICT 68-landmark ids per eye: one corner, the upper lid's two, the other corner, and the
# lower lid's two (below the upper lid's, in the same order).
EYES = {
    "right": (36, (37, 38), 39, (41, 40)),
    "left": (42, (43, 44), 45, (47, 46)),
}
# S points within this share of the eye's width from the fissure's middle take a lid side.
EYE_ZONE_SHARE = CONTACT_RULES.eye_zone_share


def fissure_line(skin: np.ndarray, lm68: np.ndarray, eye: str) -> np.ndarray:
    """(4, 3) polyline from corner to corner through the midpoints of the lids' landmarks."""
    a, upper, b, lower = EYES[eye]
    lm = skin[lm68]
    mids = [0.5 * (lm[u] + lm[w]) for u, w in zip(upper, lower, strict=True)]
    return np.vstack([lm[a], *mids, lm[b]])


def _up_across(line: np.ndarray) -> np.ndarray:
    """The unit vector across the fissure toward the upper lid: +Y without its component along
    the corner-to-corner direction."""
    e = line[-1] - line[0]
    e /= np.linalg.norm(e)
    up = np.array([0.0, 1.0, 0.0]) - e[1] * e
    return up / np.linalg.norm(up)


def lid_side_of_points(skin: np.ndarray, lm68: np.ndarray) -> np.ndarray:
    """Per S point: +1 on an upper lid's side of its eye's fissure, -1 on the lower lid's, 0
    away from the eyes (farther than EYE_ZONE_SHARE of the eye's width from the fissure's
    middle). The lids are apart at rest (the template's: 8.3 mm), so the side of the fissure
    line decides; the socket behind the lids splits at the same line."""
    side = np.zeros(len(skin), np.int8)
    for eye in EYES:
        line = fissure_line(skin, lm68, eye)
        middle = 0.5 * (line[1] + line[2])
        width = float(np.linalg.norm(line[-1] - line[0]))
        zone = np.flatnonzero(np.linalg.norm(skin - middle, axis=1) < EYE_ZONE_SHARE * width)
        height = np.einsum(
            "nd,d->n", skin[zone] - closest_on_polyline(skin[zone], line), _up_across(line)
        )
        side[zone] = np.where(height >= 0, 1, -1)
    return side
