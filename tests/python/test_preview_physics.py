"""The demo sheet's physics columns: the widest-open mouth is found, the column is simulated for
the avatar's identity and refused for another face, and a replay's parameter changes reach the
physics' elements as they reach the runtime."""

from __future__ import annotations

import numpy as np
import pytest
from softdeca_train.host.preview import _with_physics, localised_response
from softdeca_train.host.preview_physics import (
    Change,
    lip_openings_mm,
    parameter_fields,
    parse_changes,
    simulate_column,
    widest_open_frame,
)
from softdeca_train.models.parameters import load_parameter_specs
from softdeca_train.sim.head import build_head_simulation
from softdeca_train.sim.take import read_take
from softdeca_train.template import Template
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES
from softdeca_train.template.model import N_SKIN
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
    caches = {
        "linear": linear,
        "softdeca": linear + 1,
        "softdeca_localised": linear + 2,
    }
    columns = {"physics": np.full((2, 5, 3), 7.0, np.float32)}
    out = _with_physics(caches, [1, 3], columns)
    assert list(out) == ["linear", "physics", "softdeca", "softdeca_localised"]
    assert (out["physics"][[1, 3]] == 7.0).all() and (out["physics"][[0, 2]] == 0).all()
    columns["physics_localised"] = np.full((2, 5, 3), 8.0, np.float32)
    out = _with_physics(caches, [1, 3], columns)
    assert list(out) == [
        "linear",
        "physics",
        "softdeca",
        "physics_localised",
        "softdeca_localised",
    ]
    assert (out["physics_localised"][[1, 3]] == 8.0).all()


def test_replay_changes_are_read_as_the_replay_tool_writes_them() -> None:
    got = parse_changes("gravity_strength=2; target_volume=max@0.05,-0.015,0.085,0.03;")
    assert got == [
        Change("gravity_strength", "2"),
        Change("target_volume", "max", (0.05, -0.015, 0.085, 0.03)),
    ]
    assert parse_changes("") == []
    for bad in ("gravity_strength", "=2", "w=soft", "w=1@1,2,3", "w=1@0,0,0,0"):
        with pytest.raises(ValueError):
            parse_changes(bad)


def test_the_localised_response_is_measured_against_the_physics() -> None:
    rng = np.random.default_rng(0)
    base = rng.normal(size=(3, 20, 3)).astype(np.float32)
    d = np.zeros_like(base)
    d[:, 4] = [0.001, 0.0, 0.0]  # the change moves one vertex 1 mm
    caches = {"physics": base, "physics_localised": base + d, "softdeca": base + 1}
    caches["softdeca_localised"] = caches["softdeca"] + d
    same = localised_response(caches, [0, 2])
    assert same["response_error"] == pytest.approx(
        [0.0, 0.0], abs=1e-3
    )  # float32 caches
    assert same["physics_max_mm"] == pytest.approx([1.0, 1.0], abs=1e-3)
    assert same["softdeca_max_mm"] == pytest.approx([1.0, 1.0], abs=1e-3)
    caches["softdeca_localised"] = caches["softdeca"]  # the model ignores the change
    assert localised_response(caches, [1])["response_error"] == [1.0]


def test_a_ball_change_reaches_the_tets_under_it(template: Template) -> None:
    from softdeca_train.lhm import LhmConfig

    hs = build_head_simulation(template, None, LhmConfig(level=3))
    specs = load_parameter_specs(controls_only=True)
    spec = next(s for s in specs if s.name == "target_volume")
    skin = hs.head[:N_SKIN].astype(np.float64)
    centre = skin[np.argmax(skin[:, 0] + skin[:, 2])]  # a point on the left of the face
    ball = (*map(float, centre), 0.03)
    fields = parameter_fields(
        hs,
        specs,
        [Change("gravity_strength", "2"), Change("target_volume", "max", ball)],
    )
    assert fields["gravity_strength"] == 2.0
    field = fields["target_volume"]
    assert isinstance(field, np.ndarray) and field.shape == (len(hs.mesh.soft_tets),)
    # inside: the top of the range; at the ball's rim a vertex's faces are partly in (its
    # area-weighted mean); elsewhere the default
    assert (field > spec.default_value - 1e-9).all() and (
        field < spec.maximum + 1e-9
    ).all()
    changed = field > spec.default_value + 1e-9
    assert np.isclose(field, spec.maximum).any() and changed.mean() < 0.1
    rest = np.asarray(hs.mesh.rest)
    centroids = rest[np.asarray(hs.mesh.soft_tets)].mean(axis=1)
    # every changed tet lies under the ball (its nearest skin vertex is in or near it)
    assert np.linalg.norm(centroids[changed] - centre, axis=1).max() < 0.03 + 0.03
    far = (*map(float, centre + 1.0), 0.03)  # a ball away from the head changes nothing
    assert (
        parameter_fields(hs, specs, [Change("target_volume", "max", far)])[
            "target_volume"
        ]
        == spec.default_value
    )


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
