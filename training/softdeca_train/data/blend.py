"""S_t of an identity for ARKit weights, restricted to the skin S, in float64. The generator
computes the simulator's targets with it and the loader rebuilds S_t (and T = S_t + offset)
with it, so the only difference between stored and simulated T is the float16 rounding."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN


@dataclass(frozen=True)
class SkinBlend:
    arkit_to_ict: np.ndarray  # (53, 52)
    deltas: np.ndarray  # (53, N_SKIN * 3) float64

    @classmethod
    def of(cls, template: Template) -> SkinBlend:
        d = template.expression_deltas[:, :N_SKIN].astype(np.float64)
        return cls(template.arkit_to_ict, d.reshape(len(d), -1))

    def targets(self, neutral_skin: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """(N_SKIN, 3) neutral skin, (F, 52) weights -> (F, N_SKIN, 3) float64."""
        w = np.atleast_2d(np.asarray(weights, dtype=np.float32)).astype(np.float64)
        ict = w @ self.arkit_to_ict.T
        return neutral_skin[None] + (ict @ self.deltas).reshape(len(w), N_SKIN, 3)
