"""Is a head in template topology plausible? Used by identity sampling and the tests."""

from __future__ import annotations

import numpy as np

from softdeca_train.contact_rules import CONTACT_RULES
from softdeca_train.template.components import N_SKIN

# Adult anthropometric ranges in mm, about mean +- 3 SD of Farkas (1994, "Anthropometry of the
# Head and Face") and later tables: biocular width ex-ex, mouth width ch-ch, nasion-menton.
HUMAN_RANGES_MM: dict[str, tuple[float, float]] = {
    "biocular": (75.0, 110.0),
    "mouth": (35.0, 65.0),
    "nasion_menton": (90.0, 140.0),
}


def face_measures(head: np.ndarray, lm68: np.ndarray) -> dict[str, float]:
    """Anthropometric distances (mm) from ICT's 68 landmark vertices."""
    p = head[lm68] * 1e3
    return {
        "biocular": float(np.linalg.norm(p[36] - p[45])),
        "mouth": float(np.linalg.norm(p[48] - p[54])),
        "nasion_menton": float(np.linalg.norm(p[27] - p[8])),
    }


def lip_contact_zone(
    head: np.ndarray, lm68: np.ndarray, radius: float = CONTACT_RULES.lip_radius
) -> np.ndarray:
    """S vertices within `radius` of the inner lip contour. ICT's own neutral has its lips
    pressed into each other there; the simulation's collision step resolves that contact."""
    # The compiled module holds the contact rules (prepare/contact_sets.h); the template loads
    # without it (streaming and landmark tools read the template on machines that never build
    # the plugin).
    import softdeca_native as native

    return native.lip_contact_zone(head[:N_SKIN], lm68, radius).astype(bool)


def skin_self_intersections(
    head: np.ndarray, skin_tris: np.ndarray, lm68: np.ndarray, limit: int = 100000
) -> list[tuple[int, int]]:
    """Intersecting triangle pairs of S, ignoring those where both lie in the lip contact."""
    import softdeca_native as native  # compiled with the plugin: see lip_contact_zone

    lips = lip_contact_zone(head, lm68)
    pairs = native.self_intersections(head[:N_SKIN], skin_tris, limit)
    return [(a, b) for a, b in pairs if not (lips[skin_tris[a]].all() and lips[skin_tris[b]].all())]


def implausibilities(head: np.ndarray, skin_tris: np.ndarray, lm68: np.ndarray) -> list[str]:
    """Why a head is implausible (empty list: plausible)."""
    out = []
    n = len(skin_self_intersections(head, skin_tris, lm68))
    if n:
        out.append(f"S intersects itself away from the lips ({n} triangle pairs)")
    for name, value in face_measures(head, lm68).items():
        lo, hi = HUMAN_RANGES_MM[name]
        if not lo < value < hi:
            out.append(f"{name} = {value:.1f} mm outside the human range [{lo}, {hi}] mm")
    return out
