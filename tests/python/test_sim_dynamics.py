"""Eq. 9 as a filter: its peak gain, the linear reference dynamic frames are judged against,
and the dynamics pairs data generation draws."""

from __future__ import annotations

import math

import numpy as np
import pytest
from softdeca_train.data.plan import sample_parameters
from softdeca_train.parameters import load_parameters
from softdeca_train.sim.dynamics import MAX_PEAK_GAIN, LinearDynamics, peak_gain


def test_peak_gain_of_known_pairs() -> None:
    assert peak_gain(1.0, 0.0) == pytest.approx(1.0)  # static: the target itself
    assert peak_gain(0.5, 0.5) == pytest.approx(math.sqrt(2.0), rel=1e-4)  # the lead-in
    assert peak_gain(0.2, 0.3) == pytest.approx(
        1.0
    )  # overdamped: lags, never overshoots
    assert peak_gain(0.89, 0.85) > 5.0  # lightly damped: resonates


def test_linear_dynamics_starts_at_rest_and_keeps_a_constant_target() -> None:
    rng = np.random.default_rng(0)
    s = rng.normal(size=(7, 3))
    d = LinearDynamics()
    np.testing.assert_array_equal(d.step(s, 0.3, 0.6), s)
    for _ in range(20):
        np.testing.assert_allclose(d.step(s, 0.3, 0.6), s, atol=1e-12)


def test_linear_dynamics_lags_a_step_and_settles_on_it() -> None:
    d = LinearDynamics()
    d.step(np.zeros((1, 3)), 0.2, 0.1)
    path = [float(d.step(np.ones((1, 3)), 0.2, 0.1)[0, 0]) for _ in range(60)]
    assert path[0] == pytest.approx(0.2)  # gamma of the way in the first frame
    assert max(path) <= 1.0 + 1e-9  # gain 1: no overshoot
    assert path[-1] == pytest.approx(1.0, abs=1e-6)


def test_the_step_response_of_a_resonant_pair_overshoots() -> None:
    d = LinearDynamics()
    d.step(np.zeros((1, 3)), 0.89, 0.85)
    path = [float(d.step(np.ones((1, 3)), 0.89, 0.85)[0, 0]) for _ in range(30)]
    assert max(path) > 1.5


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
