"""Identities named by a label, as the stress suite and the tet-mesh checks name them: the
template, a sampled identity, or an extreme head at ±2.5 σ in the leading modes."""

from __future__ import annotations

import numpy as np

from softdeca_train.template.model import Template

EXTREME_SIGMA = 2.5
EXTREME_MODES = 10  # the identity modes set to ±EXTREME_SIGMA (the leading ones)


def identity_coefficients(template: Template, label: str) -> np.ndarray | None:
    """h for "template" (None), "seed N" (sampled) or "h+2.5σ" / "h-2.5σ"."""
    if label == "template":
        return None
    if label.startswith("seed "):
        return template.sample_identity(int(label.split()[1]))
    if label in ("h+2.5σ", "h-2.5σ"):
        h = np.zeros(template.identity_modes.shape[0])
        h[:EXTREME_MODES] = EXTREME_SIGMA * (1 if label[1] == "+" else -1)
        return h
    raise ValueError(f"unknown identity {label!r}: template, 'seed N', h+2.5σ or h-2.5σ")
