"""The eyelids in the layered head model: a slit through every wrap along each eye's fissure,
cut like the mouth's (lhm/mouth.py), and each lid's points of S on its own side of it.

The wraps pass over the eye openings (S's eye sockets lie inside them), so without the slits
the volume in front of and around each eyeball is one piece of soft tissue holding both lids:
a full blink closed the template's lid gap from 8.3 to 6.5 mm at level 3 (the linear blend:
0.4 mm), and only to 3.3 mm with every tissue weight near zero and w_target 100, because
points of both lids shared tets."""

from __future__ import annotations

import numpy as np
import softdeca_native as native

from softdeca_train.contact_rules import CONTACT_RULES

# The eyes in the order the native rules give their fissures (prepare/contact_sets.h).
EYES = ("right", "left")


def fissure_line(skin: np.ndarray, lm68: np.ndarray, eye: str) -> np.ndarray:
    """(4, 3) polyline from corner to corner through the midpoints of the lids' landmarks."""
    return native.eye_fissures(skin, lm68)[EYES.index(eye)]


def lid_side_of_points(skin: np.ndarray, lm68: np.ndarray) -> np.ndarray:
    """Per S point: +1 on an upper lid's side of its eye's fissure, -1 on the lower lid's, 0
    away from the eyes (farther than the contact rules' eye_zone_share of the eye's width from
    the fissure's middle). The lids are apart at rest (the template's: 8.3 mm), so the side of
    the fissure line decides; the socket behind the lids splits at the same line."""
    return native.lid_sides(skin, lm68, CONTACT_RULES.eye_zone_share)
