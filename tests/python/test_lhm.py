"""The layered head model: validity over sampled identities, and the checks' power to fail."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import softdeca_native as native
from bounds import below
from softdeca_train.lhm import LhmConfig, check_lhm, fit_lhm
from softdeca_train.lhm.model import CRANIUM, JAW, LayeredHeadModel
from softdeca_train.lhm.sphere import icosphere, zoom
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN

# Plausible totals for the soft-tissue layer (litres): more than the face's own soft tissue,
# less than a whole head. The layer also fills the oral cavity and the gaps behind the ears.
SOFT_VOLUME_L = (0.8, 5.0)


def skin_of(template: Template, h: np.ndarray | None) -> np.ndarray:
    return template.identity_neutral(h)[:N_SKIN]


@pytest.fixture(scope="module")
def template_model(template: Template) -> LayeredHeadModel:
    return fit_lhm(template)


@pytest.mark.parametrize("seed", range(20))
def test_sampled_identity_gives_a_valid_model(template: Template, seed: int) -> None:
    h = template.sample_identity(seed)
    model = fit_lhm(template, h)
    report = check_lhm(model, skin_of(template, h), template.skin_triangles)
    assert report.failures() == []
    assert report.min_volume_mm3 > 0 and report.min_quality > 0
    assert -1e-9 <= report.bary_min and report.bary_max <= 1 + 1e-9
    assert report.outside_max_mm == 0.0
    assert SOFT_VOLUME_L[0] < report.soft_volume_l < SOFT_VOLUME_L[1]
    assert 0.1 < report.muscle_volume_l < report.soft_volume_l
    # the skin wrap hugs S
    below(
        report.skin_wrap_to_s_mean_mm,
        5.0,
        "a wrap 1-2 mm under S; 5 mm: off the face",
        what="mm",
    )


def test_embedding_reproduces_skin_exactly(
    template: Template, template_model: LayeredHeadModel
) -> None:
    assert (
        np.abs(template_model.embedded_skin() - skin_of(template, None)).max() < 1e-12
    )


def test_wraps_are_nested_along_every_direction(
    template_model: LayeredHeadModel,
) -> None:
    r = [
        np.linalg.norm(template_model.layer(k) - template_model.center, axis=1)
        for k in range(template_model.n_layers)
    ]
    gap = template_model.config.min_layer_gap
    for outer, inner in itertools.pairwise(r):
        assert (outer - inner).min() >= gap * (1 - 1e-9)


def test_jaw_and_cranium_labels(
    template: Template, template_model: LayeredHeadModel
) -> None:
    labels = template_model.skull_labels
    assert 0.02 < (labels == JAW).mean() < 0.2
    # Jaw directions end below the mouth and in front of the ears; the vault is cranium.
    jaw_skin = template_model.skin_wrap[labels == JAW]
    mouth_y = template.neutral[template.landmarks68[62], 1]
    assert np.median(jaw_skin[:, 1]) < mouth_y
    assert np.median(jaw_skin[:, 2]) > template_model.center[2]
    top = np.argmax(template_model.skull_wrap[:, 1])
    assert labels[top] == CRANIUM
    bones = template_model.attachments["bone_of_vertex"]
    lower = template.components["teeth_lower"]
    upper = template.components["teeth_upper"]
    assert (bones[lower.start - N_SKIN : lower.stop - N_SKIN] == JAW).all()
    assert (bones[upper.start - N_SKIN : upper.stop - N_SKIN] == CRANIUM).all()


def test_eyes_are_attached(template_model: LayeredHeadModel) -> None:
    centers = template_model.attachments["eye_centers"]
    radii = template_model.attachments["eye_radii"]
    assert centers[0, 0] > 0 > centers[1, 0]  # left eye at +x
    assert np.allclose(radii, 0.012, atol=0.003)  # human eyeball radius ~ 12 mm


def test_resolution_is_a_parameter(template: Template) -> None:
    coarse = fit_lhm(template, None, LhmConfig(level=3, soft_layers=2))
    # The icosphere's directions plus the slits' copies of their inner vertices (mouth, eyes).
    copies = len(coarse.slit_copy_of) + len(coarse.eye_copy_of)
    assert coarse.n_wrap == 10 * 4**3 + 2 + copies and len(coarse.eye_copy_of) >= 2
    assert coarse.n_layers == 4
    assert len(coarse.soft_tets) == 2 * 3 * 20 * 4**3
    assert (
        check_lhm(coarse, skin_of(template, None), template.skin_triangles).failures()
        == []
    )


def test_checks_catch_an_inverted_tet(
    template: Template, template_model: LayeredHeadModel
) -> None:
    broken = LayeredHeadModel(**template_model.__dict__)
    broken.soft_tets = template_model.soft_tets.copy()
    broken.soft_tets[0, [1, 2]] = broken.soft_tets[0, [2, 1]]
    report = check_lhm(broken, skin_of(template, None), template.skin_triangles)
    assert any("inverted" in f for f in report.failures())


def test_checks_catch_a_wrap_cutting_the_skin(
    template: Template, template_model: LayeredHeadModel
) -> None:
    broken = LayeredHeadModel(**template_model.__dict__)
    broken.vertices = template_model.vertices.copy()
    # Pull the skin wrap 5 mm toward the centre: it now cuts S.
    n = template_model.n_wrap
    d = broken.vertices[:n] - template_model.center
    broken.vertices[:n] -= 0.005 * d / np.linalg.norm(d, axis=1, keepdims=True)
    failures = check_lhm(
        broken, skin_of(template, None), template.skin_triangles
    ).failures()
    assert any("skin_wrap x S" in f for f in failures)
    assert any("leaves the skin wrap" in f for f in failures)


def test_save_and_load_round_trip(tmp_path, template_model: LayeredHeadModel) -> None:
    path = tmp_path / "lhm.npz"
    template_model.save(path)
    back = LayeredHeadModel.load(path)
    assert back.config == template_model.config
    assert np.array_equal(back.soft_tets, template_model.soft_tets)
    assert np.array_equal(
        back.attachments["bone_of_vertex"], template_model.attachments["bone_of_vertex"]
    )


def test_icosphere_and_zoom_keep_a_closed_outward_sphere() -> None:
    for level in range(4):
        d, f = icosphere(level)
        assert len(d) == 10 * 4**level + 2 and len(f) == 20 * 4**level
        z = zoom(d, np.array([0.0, -1.0, 0.2]), 1.8)
        assert np.allclose(np.linalg.norm(z, axis=1), 1.0)
        vol = native.tet_signed_volumes(
            np.vstack([np.zeros((1, 3)), z]),
            np.hstack([np.zeros((len(f), 1), np.int32), f + 1]),
        )
        assert vol.min() > 0  # outward, no fold: every cone positive
        if level >= 3:  # fine enough to approach the ball's volume
            assert vol.sum() == pytest.approx(4 / 3 * np.pi, rel=0.05)
