"""The numbers and landmarks of the lip and lid contact rules, read from their one definition
plugin/data/contact_rules.json (the same file the C++ library embeds at build time for the
rules' one implementation, plugin/src/prepare/contact_sets.cpp)."""

from __future__ import annotations

import json
from dataclasses import dataclass, fields

import numpy as np

from softdeca_train.paths import REPO_ROOT

DEFINITION = REPO_ROOT / "plugin" / "data" / "contact_rules.json"


@dataclass(frozen=True)
class ContactDistances:
    """Lengths in metres; eye_zone_share is a share of an eye's width."""

    lip_radius: float
    lip_corner_radius: float
    lid_reach: float
    lid_corner_radius: float
    eye_zone_share: float


def _load() -> ContactDistances:
    data = json.loads(DEFINITION.read_text())
    if data.get("format") != "softdeca-contact-rules":
        raise ValueError(f"{DEFINITION}: not a softdeca-contact-rules file")
    rules = data["rules"]
    names = [f.name for f in fields(ContactDistances)]
    if sorted(rules) != sorted(names):
        raise ValueError(f"{DEFINITION}: rules must be exactly {', '.join(names)}")
    return ContactDistances(**{n: float(rules[n]["value"]) for n in names})


CONTACT_RULES = _load()


@dataclass(frozen=True)
class ContactLandmarks:
    """Ids of the 68 Multi-PIE landmarks the rules use (the file's "landmarks")."""

    inner_lip: tuple[int, ...]  # right corner, upper lip's three, left corner, lower lip's three
    inner_mouth_corners: tuple[int, ...]  # right, left
    inner_lip_middles: tuple[int, ...]  # upper, lower
    right_eye: tuple[int, ...]  # corner, upper lid's two, corner, lower lid's two
    left_eye: tuple[int, ...]


def _load_landmarks() -> ContactLandmarks:
    entries = json.loads(DEFINITION.read_text())["landmarks"]
    names = [f.name for f in fields(ContactLandmarks)]
    if sorted(entries) != sorted(names):
        raise ValueError(f"{DEFINITION}: landmarks must be exactly {', '.join(names)}")
    return ContactLandmarks(**{n: tuple(int(i) for i in entries[n]["value"]) for n in names})


CONTACT_LANDMARKS = _load_landmarks()


@dataclass(frozen=True)
class ContactRules:
    """How the lip and lid sets are found on a head (sim/lips.py, sim/lids.py): its landmarks
    and lid candidates, and the distances (this file's unless a bundle carries its own)."""

    landmarks68: np.ndarray  # (68,) skin vertex indices of the 68 Multi-PIE landmarks
    lid_candidates: np.ndarray  # skin vertices that may belong to a lid
    lip_radius: float = CONTACT_RULES.lip_radius
    lip_corner_radius: float = CONTACT_RULES.lip_corner_radius
    lid_reach: float = CONTACT_RULES.lid_reach
    lid_corner_radius: float = CONTACT_RULES.lid_corner_radius
    eye_zone_share: float = CONTACT_RULES.eye_zone_share
