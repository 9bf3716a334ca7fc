"""The mouth in the layered head model: the slit between the lips, the lips' sides, the bones
their deep layers hang on, and the element quality around the mouth (docs/physics.md, "The
mouth model")."""

from __future__ import annotations

import numpy as np
import pytest
from bounds import above, below
from softdeca_train.lhm import LhmConfig, fit_lhm
from softdeca_train.lhm.checks import check_lhm, mouth_quality
from softdeca_train.lhm.model import CRANIUM, JAW, LayeredHeadModel
from softdeca_train.lhm.quality import aspect_ratios, dihedral_angles, quality_figures
from softdeca_train.sim.expressions import weights_of
from softdeca_train.sim.head import HeadSimulation, build_head_simulation
from softdeca_train.sim.sanity import lip_opening_mm
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN

LEVEL = 3  # the stress suite's level


@pytest.fixture(scope="module", params=[None, 1], ids=["template", "seed1"])
def head(request: pytest.FixtureRequest, template: Template) -> HeadSimulation:
    h = None if request.param is None else template.sample_identity(request.param)
    # the LHM's own prisms: these tests index the simulation by wrap vertex
    return build_head_simulation(template, h, LhmConfig(level=LEVEL, tet_mesh="prisms"))


def _columns(model: LayeredHeadModel, tets: np.ndarray) -> np.ndarray:
    return tets % model.n_wrap


def _tet_side(m: LayeredHeadModel) -> np.ndarray:
    """Per soft tet: +1 / -1 in the slit's upper / lower band of triangles (those at its inner
    vertices: originals above, copies below), 0 elsewhere."""
    k = len(m.slit_copy_of)
    tri_side = np.zeros(len(m.wrap_triangles), np.int8)
    tri_side[np.isin(m.wrap_triangles, m.slit_copy_of).any(axis=1)] = 1
    tri_side[(m.wrap_triangles >= m.n_wrap - k).any(axis=1)] = -1
    return np.tile(tri_side, len(m.soft_tets) // len(tri_side))


def _at_slit_ends(m: LayeredHeadModel) -> np.ndarray:
    """Wrap vertices sharing a triangle with both an original and a copy of the slit (its
    two end vertices, where the slit closes)."""
    k = len(m.slit_copy_of)
    up = np.isin(m.wrap_triangles, m.slit_copy_of).any(axis=1)
    lo = (m.wrap_triangles >= m.n_wrap - k).any(axis=1)
    near_up = np.zeros(m.n_wrap, bool)
    near_lo = np.zeros(m.n_wrap, bool)
    near_up[m.wrap_triangles[up]] = True
    near_lo[m.wrap_triangles[lo]] = True
    return near_up & near_lo


def test_the_slit_copies_coincide_at_rest_and_close_at_the_corners(
    head: HeadSimulation,
) -> None:
    m = head.lhm
    k = len(m.slit_copy_of)
    assert k >= 2
    for layer in range(m.n_layers):
        w = m.layer(layer)
        assert np.abs(w[-k:] - w[m.slit_copy_of]).max() < 1e-12
    # The lower lip's triangles use the copies, the upper lip's the originals: no triangle
    # holds both, and the copies are the only wrap vertices with no twin at the corners.
    tris = m.wrap_triangles
    copies = tris >= m.n_wrap - k
    originals = np.isin(tris, m.slit_copy_of)
    assert not (copies.any(axis=1) & originals.any(axis=1)).any()
    assert (m.lip_side[m.n_wrap - k :] < 0).all() and (
        m.lip_side[m.slit_copy_of] > 0
    ).all()


def test_no_tet_spans_both_lips(head: HeadSimulation, template: Template) -> None:
    m = head.lhm
    for tets in (m.soft_tets, m.muscle_tets):
        side = m.lip_side[_columns(m, tets)]
        assert not ((side > 0).any(axis=1) & (side < 0).any(axis=1)).any()
    # No tet holds points of both lips (split along S, as the embedding does; the lip sets
    # leave out the mouth corners) but at the mouth corners, where the slit closes.
    from softdeca_train.lhm.fit import bone_labels, lip_of_points

    lip = lip_of_points(template, head.head, bone_labels(template, head.head))
    away = np.concatenate([head.lips.upper, head.lips.lower])
    upper = m.skin_tet[away[lip[away] == CRANIUM]]
    lower = m.skin_tet[away[lip[away] == JAW]]
    both = np.intersect1d(upper, lower)
    corner_cols = np.flatnonzero((m.lip_side == 0) & _at_slit_ends(m))
    assert np.isin(_columns(m, m.soft_tets[both]), corner_cols).any(axis=1).all()
    # Each lip lies on its own side of the slit.
    side = _tet_side(m)
    assert (side[upper] >= 0).all() and (side[lower] <= 0).all()


def test_each_point_is_embedded_on_its_own_lips_side(
    head: HeadSimulation, template: Template
) -> None:
    """The lip contact zone split by the mouth line; elsewhere the bone jawOpen moves a
    point with."""
    from softdeca_train.lhm.fit import bone_labels, lip_of_points

    m = head.lhm
    bone = lip_of_points(template, head.head, bone_labels(template, head.head))
    side_of_tet = _tet_side(m)[m.skin_tet]
    assert not ((side_of_tet > 0) & (bone == JAW)).any()
    assert not ((side_of_tet < 0) & (bone == CRANIUM)).any()
    # Those next to the slit are embedded outside their tet but reproduce S exactly at rest.
    assert np.abs(m.embedded_skin() - head.head[:N_SKIN]).max() < 1e-12


def test_the_upper_lips_deep_layer_is_on_the_cranium(head: HeadSimulation) -> None:
    m = head.lhm
    skull = (m.n_layers - 1) * m.n_wrap + np.flatnonzero(m.lip_side > 0)
    cranium = np.asarray(head.mesh.cranium_vertices)
    assert np.isin(skull, cranium).all()
    assert (m.skull_labels[m.lip_side > 0] == CRANIUM).all()
    assert (m.skull_labels[m.lip_side < 0] == JAW).all()


def test_element_quality_is_bounded_around_the_mouth(
    head: HeadSimulation, template: Template
) -> None:
    """Measured at level 3 (template / seed 1): muscle tets' smallest dihedral angle 7.2 / 8.1
    degrees and largest aspect ratio 8.8 / 9.0 (the radial wraps without the slope limit: 3.1
    / 2.2 degrees, 57.6 / 71.5); in the mouth region soft tets 3.0 / 3.2 degrees and 20.4 /
    19.8 (before: 41.7 / 27.2), muscle tets 7.2 / 9.0 degrees and 8.7 / 9.0 (before: 24.3 /
    18.6)."""
    q = mouth_quality(head.lhm)
    # the wraps' slope limit; without it 3.1 deg and 57.6
    for name, part, lo, hi in (
        ("muscle", q.muscle, 6.0, 11.0),
        ("mouth soft", q.mouth_soft, 2.5, 25.0),
        ("mouth muscle", q.mouth_muscle, 6.0, 11.0),
    ):
        above(
            part.min_dihedral_deg,
            lo,
            "the slope limit's floor, measured above",
            what=name,
        )
        below(
            part.max_aspect_ratio,
            hi,
            "the slope limit's cap, measured under",
            what=name,
        )
    report = check_lhm(head.lhm, head.head[:N_SKIN], template.skin_triangles)
    assert report.failures() == []
    assert report.tets_spanning_both_lips == 0
    assert report.quality["mouth_muscle"] == q.as_dict()["mouth_muscle"]


def test_quality_figures_of_a_regular_tet_and_a_needle() -> None:
    regular = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    tet = np.array([[0, 1, 2, 3]])
    assert np.allclose(dihedral_angles(regular, tet), np.degrees(np.arccos(1 / 3)))
    assert np.allclose(aspect_ratios(regular, tet), np.sqrt(1.5))
    needle = regular * [0.05, 0.05, 1.0]
    f = quality_figures(needle, tet)
    assert f.max_aspect_ratio > 10 and f.min_dihedral_deg < 10
    with pytest.raises(ValueError, match="no tets"):
        quality_figures(regular, np.zeros((0, 4), int))


def test_an_open_mouth_stays_open_in_the_volumetric_solve(head: HeadSimulation) -> None:
    """Without the lips placed on S (lips_follow_targets off, no contacts) the volumetric
    solve alone keeps the opening: before the slit it closed jawOpen 0.5 on the template at
    level 3 from 19.7 mm to 1.4 mm."""
    sim = head.simulator(threads=1, lips_follow_targets=False, collision_rounds=0)
    blended = head.blend(weights_of({"jawOpen": 0.5})[None])[0]
    jaw = head.jaw_transforms(blended[None])[0]
    _, skin, _ = sim.solve_static(blended[:N_SKIN].astype(np.float64), jaw=jaw)
    linear = lip_opening_mm(head, blended[:N_SKIN])
    above(linear, 10.0, "jawOpen 0.5 opens the blend 19.7 mm", what="mm")
    ratio = lip_opening_mm(head, skin) / linear
    # measured 0.99 to 1.01; without the slit 0.07
    above(ratio, 0.8, "the slit keeps the opening (without it 0.07)", what="ratio")
    below(ratio, 1.25, "the slit keeps the opening (without it 0.07)", what="ratio")


def test_the_default_resolution_has_a_slit_too(template: Template) -> None:
    """Level 4 on the template: 7 doubled vertices; muscle tets' largest aspect ratio 15.4
    (149.6 without the slope limit), 11.8 in the mouth region (32.4)."""
    m = fit_lhm(template)
    assert len(m.slit_copy_of) > 2
    q = mouth_quality(m)
    below(
        q.muscle.max_aspect_ratio,
        20.0,
        "15.4 measured (149.6 without the limit)",
        what="muscle",
    )
    below(
        q.mouth_muscle.max_aspect_ratio,
        15.0,
        "11.8 measured (32.4)",
        what="mouth muscle",
    )
    assert (
        check_lhm(m, template.neutral[:N_SKIN], template.skin_triangles).failures()
        == []
    )


def test_a_mouth_narrower_than_two_wrap_edges_gets_no_slit() -> None:
    from softdeca_train.lhm.mouth import slit_along
    from softdeca_train.lhm.sphere import icosphere

    dirs, tris = icosphere(2)
    narrow = np.array([[-0.01, 0.0, 1.0], [0.0, 0.0, 1.0], [0.01, 0.0, 1.0]])
    slit = slit_along(dirs, tris, np.zeros(3), narrow)
    assert len(slit.copy_of) == 0 and np.array_equal(slit.triangles, tris)
    wide = np.array([[-0.5, 0.0, 1.0], [0.0, 0.0, 1.0], [0.5, 0.0, 1.0]])
    cut = slit_along(dirs, tris, np.zeros(3), wide)
    assert len(cut.copy_of) >= 1 and (cut.side != 0).any()
