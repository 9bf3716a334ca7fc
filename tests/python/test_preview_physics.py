"""The demo sheet's physics column: the widest-open mouth is found, the column is simulated for
the avatar's identity and refused for another face."""

from __future__ import annotations

import numpy as np
import pytest
from softdeca_train.runtime.preview import _with_physics
from softdeca_train.runtime.preview_physics import (
    lip_openings_mm,
    simulate_column,
    widest_open_frame,
)
from softdeca_train.sim.head import build_head_simulation
from softdeca_train.sim.take import read_take
from softdeca_train.template import Template
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES
from streaming_cli import TAKES

TAKE = TAKES / "alex_rom_3.csv"


def _jaw_open(template: Template, amounts: list[float]) -> np.ndarray:
    from softdeca_train.lhm import LhmConfig

    hs = build_head_simulation(template, None, LhmConfig(level=3))
    w = np.zeros((len(amounts), 52))
    w[:, ARKIT_BLENDSHAPES.index("jawOpen")] = amounts
    return hs.blend(w)


def test_the_widest_open_mouth_is_found(template: Template) -> None:
    heads = _jaw_open(template, [0.0, 0.8, 0.3])
    openings = lip_openings_mm(heads, template)
    assert openings[0] < 3.0 < openings[2] < openings[1]
    assert widest_open_frame(heads, template) == 1


def test_the_physics_column_follows_the_linear_one() -> None:
    linear = np.arange(4 * 5 * 3, dtype=np.float32).reshape(4, 5, 3)
    caches = {"linear": linear, "softdeca": linear + 1}
    out = _with_physics(caches, [1, 3], np.full((2, 5, 3), 7.0, np.float32))
    assert list(out) == ["linear", "physics", "softdeca"]
    assert (out["physics"][[1, 3]] == 7.0).all() and (out["physics"][[0, 2]] == 0).all()


def test_the_column_is_refused_for_another_face(template: Template) -> None:
    """The replay's linear heads of identity seed 1 against a simulation of seed 2."""
    from softdeca_train.lhm import LhmConfig

    w = read_take(TAKE, 100, 1).weights
    hs = build_head_simulation(
        template, template.sample_identity(1), LhmConfig(level=3)
    )
    linear = hs.blend(w)
    with pytest.raises(ValueError, match="not made from that identity"):
        simulate_column(TAKE, 100, [0], linear, template, seed=2)
