"""Eq. 9 as a filter: its peak gain and the dynamics pairs data generation draws."""

from __future__ import annotations

import math

import numpy as np
import pytest
from softdeca_train.data.plan import sample_parameters
from softdeca_train.parameters import load_parameters
from softdeca_train.sim.dynamics import MAX_PEAK_GAIN, peak_gain


def test_peak_gain_of_known_pairs() -> None:
    assert peak_gain(1.0, 0.0) == pytest.approx(1.0)  # static: the target itself
    assert peak_gain(0.5, 0.5) == pytest.approx(math.sqrt(2.0), rel=1e-4)  # the lead-in
    assert peak_gain(0.2, 0.3) == pytest.approx(
        1.0
    )  # overdamped: lags, never overshoots
    assert peak_gain(0.89, 0.85) > 5.0  # lightly damped: resonates


def test_sampled_dynamics_pairs_stay_below_the_peak_gain() -> None:
    params = load_parameters()
    g, b = params.names.index("dyn_gamma"), params.names.index("dyn_beta")
    rng = np.random.default_rng(3)
    pairs = [sample_parameters(params, "dynamic", rng)[[g, b]] for _ in range(200)]
    gains = [peak_gain(*pair) for pair in pairs]
    assert max(gains) <= MAX_PEAK_GAIN
    # ... and still cover the range: slow (low gamma) and springy (high beta) pairs.
    assert min(p[0] for p in pairs) < 0.2
    assert max(p[1] for p in pairs) > 0.6
