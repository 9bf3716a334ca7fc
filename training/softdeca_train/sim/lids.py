"""The eyelids' points of S (lhm/eyes.py has the slits between the lids). They form a
collision set with no surface: like every collision set's points they are placed on their
targets after the volumetric solve (docs/physics.md, Collisions), and there is nothing for
them to stay out of. The lids are thin flaps moved by their own muscles, far thinner than the
tets under them: with the eye slits the volumetric solve alone left a full blink's lids 4.0 mm
(level 3) and 3.1 mm (level 4) apart where the linear blend closes them to 0.4 mm.

No lid-against-lid contacts: on real blinks the lids press over a large area (alex_rom_3
frame 800, `eyeBlink` 0.94 with `eyeSquint` 0.64: 198 lid points 10-40 µm inside the other
lid), and the contact rounds took 30 rounds and 4 s there, against 1.3 s for the whole frame
without them, still leaving 13 points 40 µm inside. Where the linear blend drives the upper lid
past the lower one (`eyeBlink` with `eyeLookDown`) it passes in front of it, as in the linear
blend.

Each lid's points lie on the face or its eye socket within the rules' `lid_reach` of the eye's
fissure line; points within `lid_corner_radius` of the eye corners belong to neither lid (the
lids are one surface there; they follow the volumetric solve)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import softdeca_native as native

from softdeca_train.contact_rules import ContactRules
from softdeca_train.template import Template


@dataclass(frozen=True)
class LidSets:
    upper: np.ndarray  # skin vertex indices of the upper lids (both eyes)
    lower: np.ndarray


def lid_candidates(template: Template) -> np.ndarray:
    """The S points that may belong to a lid: the face and the eye sockets."""
    return np.concatenate([
        np.arange(template.components[c].slice.start, template.components[c].slice.stop)
        for c in ("face", "eye_socket_left", "eye_socket_right")
    ])  # fmt: skip


def lid_sets_of(skin: np.ndarray, rules: ContactRules) -> LidSets:
    """The lid sets of a head's skin `skin` (rules.lid_candidates: lid_candidates), found by
    the native library (prepare/contact_sets.h) as at prepare."""
    return LidSets(*native.lid_sets(skin, **vars(rules)))
