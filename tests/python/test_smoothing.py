"""The vertex stage's smoothed parameter fields (models/smoothing.py)."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from softdeca_train.models.networks import TEST_SIZES, HyperNetwork
from softdeca_train.models.parameters import load_parameter_specs
from softdeca_train.models.smoothing import FieldSmoothing, farthest_points
from softdeca_train.models.synthetic import TEST_PARAMETERS, synthetic_head


@pytest.fixture(scope="module")
def rest() -> np.ndarray:
    head = synthetic_head(level=3)
    assert head.definition.skin_rest is not None
    return head.definition.skin_rest


def test_farthest_points_cover_every_point_within_the_spacing(rest: np.ndarray) -> None:
    idx = farthest_points(rest, 0.02)
    d = np.linalg.norm(rest[:, None] - rest[idx][None], axis=2).min(axis=1)
    assert d.max() <= 0.02
    assert len(np.unique(idx)) == len(idx) < len(rest)


def test_a_constant_field_stays_constant(rest: np.ndarray) -> None:
    s = FieldSmoothing(rest, scales=(0.02, 0.05))
    field = torch.full((len(rest), 2), 0.7, dtype=torch.float64)
    field[:, 1] = -1.5
    out = s(field)
    assert out.shape == (len(rest), 4)
    np.testing.assert_allclose(out[:, [0, 2]].numpy(), 0.7, rtol=1e-6)
    np.testing.assert_allclose(out[:, [1, 3]].numpy(), -1.5, rtol=1e-6)


def test_a_local_change_reaches_its_neighbourhood_only(rest: np.ndarray) -> None:
    sigma = 0.015
    s = FieldSmoothing(rest, scales=(sigma,))
    d = np.linalg.norm(rest - rest[0], axis=1)
    field = torch.zeros(len(rest), 1, dtype=torch.float64)
    field[d < 0.02, 0] = 1.0
    out = s(field)[:, 0].numpy()
    assert out[0] > 0.3  # inside the changed patch
    assert (out >= 0).all() and (out <= 1 + 1e-9).all()
    assert np.all(out[d > 0.02 + 6 * sigma] == 0.0)  # beyond the tables' reach: nothing
    near, far = out[(d > 0.02) & (d < 0.03)].mean(), out[(d > 0.04) & (d < 0.06)].mean()
    assert near > far  # it decays with distance


def test_smoothed_inputs_widen_the_vertex_stage_table(rest: np.ndarray) -> None:
    specs = load_parameter_specs(TEST_PARAMETERS)
    localisable = sum(s.localisable for s in specs)
    assert 0 < localisable < len(specs)
    plain = HyperNetwork(len(rest), specs, TEST_SIZES, 3, 1e-3, local_linear=True)
    s = FieldSmoothing(rest)
    wide = HyperNetwork(
        len(rest), specs, TEST_SIZES, 3, 1e-3, local_linear=True, smoothing=s
    )
    assert plain.local is not None and wide.local is not None
    extra = wide.local.table.shape[1] - plain.local.table.shape[1]
    assert extra == localisable * len(s.scales)
    p = torch.tensor(
        [[sp.default_value for sp in specs]] * len(rest), dtype=torch.float32
    )
    f = wide.local.features(p)
    # at a constant field the smoothed columns equal the vertex's own normalised values
    own = f[:, 1 : 1 + len(specs)][
        :, [i for i, sp in enumerate(specs) if sp.localisable]
    ]
    np.testing.assert_allclose(
        f[:, -extra:].numpy(), own.repeat(1, len(s.scales)).numpy(), atol=1e-6
    )


def test_rest_positions_are_checked() -> None:
    with pytest.raises(ValueError, match="rest positions"):
        FieldSmoothing(np.zeros((4, 2)))
    bad = np.zeros((4, 3))
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match="rest positions"):
        FieldSmoothing(bad)
