"""The second-order dynamics of eq. 9 seen as a filter on the target sequence: how much it can
amplify motion, so which (gamma, beta) pairs are plausible tissue.

Eq. 9 blends the target gamma S_t + 2 alpha T_{t-1} - beta T_{t-2} with 2 alpha = 1 - gamma +
beta, so a constant S is kept (gain 1 at rest). Its frequency response is
H(w) = gamma / (1 - 2 alpha e^{-iw} + beta e^{-2iw}); a peak well above 1 is a lightly damped
resonance: motion near that frequency (a few frames per period, as in speech) comes out
amplified, so the face wobbles by several times the expression's own motion (measured: a
sequence at gamma 0.89, beta 0.85, peak gain 7, moved skin 61 mm from the linear blend)."""

from __future__ import annotations

import numpy as np

# Largest peak gain of a plausible pair: overshoot like a damped oscillator with damping ratio
# >= 0.35. The lead-in's fixed pair (0.5, 0.5) has 1.41.
MAX_PEAK_GAIN = 1.5
_FREQUENCIES = np.linspace(0.0, np.pi, 1025)


def peak_gain(gamma: float, beta: float) -> float:
    """max over frequencies of |H(w)| for eq. 9's (gamma, beta)."""
    z = np.exp(-1j * _FREQUENCIES)
    h = gamma / np.abs(1.0 - (1.0 - gamma + beta) * z + beta * z * z)
    return float(h.max())
