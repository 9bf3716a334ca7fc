"""The physics at prepare's head (models/rest_head.py, rest_physics.py): its file, its carry to
an avatar, the contact rules against the data's sets, the rest-inert parameters."""

from __future__ import annotations

import numpy as np
import pytest
from softdeca_train.contact_rules import ContactRules
from softdeca_train.models.rest_head import (
    contact_sets,
    embedding_weights,
    inert_parameters,
    read_rest_head,
    rest_head_file,
)
from softdeca_train.models.synthetic import (
    TEST_PARAMETERS,
    synthetic_head,
    synthetic_rest_head,
)


@pytest.fixture(scope="module")
def head():
    return synthetic_head()


@pytest.fixture(scope="module")
def rest(head):
    return synthetic_rest_head(head)


def test_the_file_round_trips_and_refuses_another_length(head, rest):
    data, entry = rest_head_file(rest)
    back = read_rest_head(entry, data, head.definition.skin_vertices)
    for name in (
        "vertices",
        "soft_tets",
        "muscle_tets",
        "skin_vertex",
        "skin_weight",
        "cranium",
    ):
        assert np.array_equal(getattr(back, name), getattr(rest, name)), name
    assert back.contacts is None and back.tolerance == rest.tolerance
    with pytest.raises(ValueError, match="shorter than its manifest"):
        read_rest_head(entry, data[:-8], head.definition.skin_vertices)
    with pytest.raises(ValueError, match="more than its manifest"):
        read_rest_head(entry, data + b"\0" * 8, head.definition.skin_vertices)


def test_the_carry_keeps_the_template_and_moves_a_shifted_head_rigidly(head, rest):
    vs = head.definition.skin_vertices
    skin = head.neutral[:vs]
    assert np.allclose(rest.carried_vertices(skin), rest.vertices, atol=1e-12)
    # A constant displacement has no Dirichlet energy: the fill follows it exactly.
    shift = np.array([0.01, -0.02, 0.005])
    assert np.allclose(
        rest.carried_vertices(skin + shift), rest.vertices + shift, atol=1e-9
    )
    # A stretched skin stretches the fill too, and the skin is re-embedded exactly.
    stretched = skin * np.array([1.05, 1.0, 0.97])
    fill = rest.carried_vertices(stretched)
    w = embedding_weights(fill, rest.skin_vertex, rest.skin_weight, stretched)
    assert np.allclose(
        np.einsum("nk,nkd->nd", w, fill[rest.skin_vertex]), stretched, atol=1e-12
    )
    assert np.allclose(w.sum(axis=1), 1.0)


def test_rest_inert_parameters_are_those_that_move_nothing_unloaded(head, rest):
    from softdeca_train.models.parameters import load_parameter_specs

    specs = load_parameter_specs(TEST_PARAMETERS)
    inert = inert_parameters(rest, head.neutral, head.definition.skin_triangles, specs)
    # the skin's strain weight and the dynamics move nothing of the unloaded head at rest; the
    # target volume does; gravity is global and never counts
    assert "w_skin_strain" in inert and "dyn_gamma" in inert and "dyn_beta" in inert
    assert "target_volume" not in inert and "gravity_strength" not in inert


def test_the_contact_rules_find_the_datas_sets(template):
    """Prepare's five sets are the data's lip and lid sets (both from the native rules,
    prepare/contact_sets.h), each against its surface."""
    from softdeca_train.sim.lids import lid_candidates, lid_sets_of
    from softdeca_train.sim.lips import lip_sets_of
    from softdeca_train.template.model import N_SKIN

    rules = ContactRules(template.landmarks68, lid_candidates(template))
    none = np.zeros((0, 3), np.int32)
    for seed in (None, 7):
        skin = template.identity_neutral(
            None if seed is None else template.sample_identity(seed)
        )[:N_SKIN]
        ours = contact_sets(rules, skin, template.skin_triangles, none, none)
        lips = lip_sets_of(skin, template.skin_triangles, rules)
        lids = lid_sets_of(skin, rules)
        expected = [
            ("upper_lip_over_lower_lip", lips.upper, lips.lower_triangles),
            ("lower_lip_over_upper_lip", lips.lower, lips.upper_triangles),
            ("lips_over_upper_teeth", lips.zone, none),
            ("lips_over_lower_teeth", lips.zone, none),
            ("eyelids", np.concatenate([lids.upper, lids.lower]), none),
        ]
        assert [c.name for c in ours] == [name for name, _, _ in expected]
        for c, (name, points, surface) in zip(ours, expected, strict=True):
            assert np.array_equal(c.points, points), name
            assert np.array_equal(c.surface, surface), name
        assert len(ours[0].points) > 100 and len(ours[4].points) > 100
