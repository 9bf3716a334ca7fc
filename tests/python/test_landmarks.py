"""Landmarks: ARKit reference reader, the rule-based definition, registration to the template,
barycentric points on S, the CLI step."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from bounds import below
from PIL import Image
from softdeca_train.cli import main
from softdeca_train.landmarks import (
    ArkitFace,
    RegistrationConfig,
    canonical_shape_name,
    generate_definition,
    load_definition,
    register_arkit_to_template,
    template_landmarks,
    umeyama,
)
from softdeca_train.landmarks.definition import DEFINITION_PATH, LandmarkDefinition
from softdeca_train.landmarks.registration import CONSTRAINED_68, INTERIOR_68
from softdeca_train.landmarks.report import ResidualBounds, build_report, check_bounds
from softdeca_train.landmarks.topology import chain_through, edge_graph, subsample_chain
from softdeca_train.template import ARKIT_BLENDSHAPES, Template
from softdeca_train.template.model import N_SKIN

REGIONS = {
    "eye_right",
    "eye_left",
    "brow_right",
    "brow_left",
    "nose_bridge",
    "nose_base",
    "nose_ala_right",
    "nose_ala_left",
    "lip_outer",
    "lip_inner",
    "jaw",
}


def _ict_expression(tmpl: Template, name: str) -> np.ndarray:
    """The template's head under one ICT expression at weight 1."""
    return tmpl.neutral + tmpl.expression_deltas[tmpl.expression_names.index(name)]


@pytest.fixture(scope="module")
def arkit() -> ArkitFace:
    return ArkitFace.load()


@pytest.fixture(scope="module")
def tmpl() -> Template:
    return Template.load()


@pytest.fixture(scope="module")
def definition() -> LandmarkDefinition:
    return load_definition()


@pytest.fixture(scope="module")
def registration(tmpl, arkit, definition):
    return register_arkit_to_template(tmpl, arkit, definition, progress=False)


# ---- ARKit reference face -------------------------------------------------------------------
def test_reader_shapes_in_canonical_order(arkit):
    assert arkit.neutral.shape == (1220, 3) and arkit.triangles.shape == (2304, 3)
    assert arkit.shapes.shape == (52, 1220, 3)
    # The public set has 51 shapes plus Neutral.obj: tongueOut is missing and stays neutral.
    missing = [
        n for n, p in zip(ARKIT_BLENDSHAPES, arkit.present, strict=True) if not p
    ]
    assert missing == ["tongueOut"]
    assert np.abs(arkit.deltas[ARKIT_BLENDSHAPES.index("tongueOut")]).max() == 0
    # The median over all shapes is the rest pose and reproduces the bundled Neutral.obj.
    assert arkit.neutral_file_deviation < 1e-9
    # Metres: the face mask is about 14.5 cm wide.
    assert 0.12 < np.ptp(arkit.neutral[:, 0]) < 0.18
    w = np.zeros(52)
    w[ARKIT_BLENDSHAPES.index("jawOpen")] = 1.0
    np.testing.assert_allclose(
        arkit.blend(w), arkit.shapes[ARKIT_BLENDSHAPES.index("jawOpen")]
    )


def test_shape_names_map_robustly():
    for stem in (
        "eyeBlink_L",
        "EyeBlinkLeft",
        "eye_blink_left",
        "eyeBlinkLeft",
        "EYEBLINK-l",
    ):
        assert canonical_shape_name(stem) == "eyeBlinkLeft"
    assert (
        canonical_shape_name("mouthRollLower") == "mouthRollLower"
    )  # ends in r, no side
    assert canonical_shape_name("cheekSquint_R") == "cheekSquintRight"
    assert canonical_shape_name("Neutral") == "neutral"
    assert canonical_shape_name("browInnerUp") == "browInnerUp"
    assert canonical_shape_name("cheekRaiser_L") is None


def test_left_shapes_move_the_positive_x_side(arkit):
    """ARKit's own naming agrees with the frame: ...Left moves the subject's left, +x."""
    for name in ("eyeBlinkLeft", "browDownLeft", "mouthSmileLeft"):
        d = np.linalg.norm(arkit.deltas[ARKIT_BLENDSHAPES.index(name)], axis=1)
        assert (arkit.neutral[:, 0] * d).sum() / d.sum() > 0.01, name


def test_boundary_loops(arkit):
    loops = arkit.loops
    assert (len(loops.eye_right), len(loops.eye_left), len(loops.lip_inner)) == (
        24,
        24,
        36,
    )
    assert len(loops.outer) > 36
    lm = arkit.landmarks68
    assert (
        np.isin(lm[36:42], loops.eye_right).all()
        and np.isin(lm[42:48], loops.eye_left).all()
    )
    assert (
        arkit.neutral[loops.eye_left, 0].min()
        > 0
        > arkit.neutral[loops.eye_right, 0].max()
    )
    # Rings start at the 68-scheme's first point and run over the upper lid / lip first.
    assert loops.eye_right[0] == lm[36] and loops.eye_left[0] == lm[42]
    assert (
        list(loops.eye_right).index(lm[37]) < 12
        and list(loops.eye_left).index(lm[43]) < 12
    )
    upper = loops.lip_inner[1:17]
    lower = loops.lip_inner[19:35]
    w = np.zeros(52)
    w[ARKIT_BLENDSHAPES.index("jawOpen")] = 1.0
    dy = arkit.blend(w)[:, 1] - arkit.neutral[:, 1]
    assert dy[lower].mean() < dy[upper].mean() - 0.005  # the jaw opens the lower half


# ---- definition -----------------------------------------------------------------------------
def test_definition_is_valid(arkit, definition):
    n = len(definition)
    assert 140 <= n <= 160
    assert set(definition.regions) == REGIONS
    assert len(np.unique(definition.vertices)) == n
    assert definition.vertices.min() >= 0 and definition.vertices.max() < len(
        arkit.neutral
    )
    covered = {k for c in definition.contours for k in c.landmarks}
    assert covered == set(range(n))
    # The eye and inner-lip landmarks are ring vertices; all 68-point landmarks of the brows,
    # nose, eyes and outer lips are among them.
    for region, ring in (
        ("eye_left", arkit.loops.eye_left),
        ("lip_inner", arkit.loops.lip_inner),
    ):
        assert np.isin(definition.vertices[definition.region_mask(region)], ring).all()
    assert set(range(17, 60)) <= set(definition.ibug68.tolist())


def test_committed_definition_matches_its_rules(arkit, definition):
    assert generate_definition(arkit).to_json() == definition.to_json()
    assert json.loads(DEFINITION_PATH.read_text())["landmarks"][0]["arkit_vertex"] >= 0


def test_left_right_from_geometry(arkit, definition, tmpl):
    x = arkit.neutral[definition.vertices, 0]
    sides = np.array([definition.side(k) for k in range(len(definition))])
    assert (sides != 0).sum() > 50
    assert (np.sign(x[sides != 0]) == sides[sides != 0]).all()
    # The left eye landmarks are the ones ARKit's eyeBlinkLeft closes, on ARKit's face and
    # (through the registration) on the template under the mapped ICT shape.
    left, right = (
        definition.region_mask("eye_left"),
        definition.region_mask("eye_right"),
    )
    w = np.zeros(52)
    w[ARKIT_BLENDSHAPES.index("eyeBlinkLeft")] = 1.0
    moved = np.linalg.norm(arkit.blend(w) - arkit.neutral, axis=1)[definition.vertices]
    assert moved[left].mean() > 5 * moved[right].mean()
    lms = template_landmarks(tmpl, arkit, definition)
    blink = _ict_expression(tmpl, "eyeBlink" + tmpl.left_suffix)
    moved_t = np.linalg.norm(lms.evaluate(blink) - lms.evaluate(tmpl.neutral), axis=1)
    assert moved_t[left].mean() > 5 * moved_t[right].mean()


def test_subsample_keeps_anchors_and_spacing(arkit):
    graph = edge_graph(arkit.neutral, arkit.triangles)
    lm = arkit.landmarks68
    chain = chain_through(graph, [int(v) for v in lm[48:60]], closed=True)
    picked = subsample_chain(
        arkit.neutral, chain, [int(v) for v in lm[48:60]], 24, closed=True
    )
    assert len(picked) == 24 and np.isin(lm[48:60], picked).all()
    order = [list(chain).index(v) for v in picked]
    assert order == sorted(order)
    with pytest.raises(ValueError, match="anchors"):
        subsample_chain(
            arkit.neutral, chain, [int(v) for v in lm[48:60]], 5, closed=True
        )


# ---- registration ---------------------------------------------------------------------------
def test_umeyama_recovers_a_similarity():
    rng = np.random.default_rng(0)
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    r = q * np.sign(np.linalg.det(q))
    src = rng.standard_normal((20, 3))
    dst = 1.7 * src @ r.T + np.array([0.1, -0.2, 0.3])
    sim = umeyama(src, dst)
    assert abs(sim.scale - 1.7) < 1e-9
    np.testing.assert_allclose(sim.rotation, r, atol=1e-9)
    np.testing.assert_allclose(sim.apply(src), dst, atol=1e-9)
    with pytest.raises(ValueError):
        umeyama(src[:2], dst[:2])


def test_registration_residuals_within_bounds(registration):
    """Bounds (ResidualBounds): interior 68-pair residual after the similarity mean < 4 mm and
    max < 10 mm; constrained pairs after the non-rigid step mean < 0.5 mm, max < 1.5 mm; the
    same pairs, each left out of the non-rigid step, mean < 3 mm and better than the
    similarity alone; every landmark within 0.5 mm of S."""
    rep = build_report(registration)
    assert check_bounds(rep) == []
    nr = rep["nonrigid"]
    assert (
        nr["residual_constrained_held_out"]["mean"]
        < nr["residual_constrained_similarity_only"]["mean"]
    )
    assert nr["mesh"]["inverted_triangles"] == 0
    assert (
        1.0 < rep["similarity"]["scale"] < 1.2
    )  # both faces are adult-sized, in metres


def test_bounds_fail_on_a_wrong_pairing(tmpl, arkit, definition, registration):
    # Tighter bounds than the data supports are reported...
    tight = ResidualBounds(similarity_interior_mean_mm=1.0, held_out_mean_mm=0.5)
    assert len(check_bounds(build_report(registration), tight)) == 2
    # ...and so is a registration from scrambled pairs.
    lm = arkit.landmarks68.copy()
    inner = np.array(INTERIOR_68)
    lm[inner] = lm[np.random.default_rng(1).permutation(inner)]
    broken = dataclasses.replace(arkit, landmarks68=lm)
    r = register_arkit_to_template(
        tmpl, broken, definition, held_out=False, progress=False
    )
    problems = check_bounds(build_report(r))
    assert any("similarity interior mean" in p for p in problems)


def test_registration_rejects_bad_pairs(tmpl, arkit, definition):
    with pytest.raises(ValueError, match="68-point"):
        register_arkit_to_template(
            tmpl,
            arkit,
            definition,
            RegistrationConfig(nonrigid_pairs=(70,)),
            held_out=False,
            progress=False,
        )


# ---- barycentric points on S ----------------------------------------------------------------
def test_barycentric_points_on_s(tmpl, arkit, definition, registration):
    lms = template_landmarks(tmpl, arkit, definition)
    assert len(lms) == len(definition) and lms.names == definition.names
    assert (lms.bary >= 0).all() and (lms.bary <= 1).all()
    np.testing.assert_allclose(lms.bary.sum(axis=1), 1.0, atol=1e-12)
    st = tmpl.skin_triangles
    assert (lms.triangle >= 0).all() and (lms.triangle < len(st)).all()
    np.testing.assert_array_equal(st[lms.triangle], lms.corners)
    assert lms.corners.max() < N_SKIN
    # The cached points are those of a fresh registration: the same on one CPU, a few um apart
    # where the cache was made on other kernels (the registration's iterative fit).
    below(
        np.abs(
            lms.evaluate(tmpl.neutral) - registration.landmarks.evaluate(tmpl.neutral)
        ).max(),
        1e-5,
        "the registration's fit on another kernel family: 4.1e-6 m (AVX2 against AVX-512)",
        what="cached vs fresh m",
    )
    pts = registration.registration.registered[definition.vertices]
    below(
        np.linalg.norm(lms.evaluate(tmpl.neutral) - pts, axis=1).max(),
        5e-4,
        "the registered surface's points, projected back onto the template's triangles",
        what="m",
    )


def test_landmarks_follow_identity_and_expression(tmpl, arkit, definition):
    lms = template_landmarks(tmpl, arkit, definition)
    base = lms.evaluate(tmpl.neutral)
    other = tmpl.identity_neutral(tmpl.sample_identity(seed=3))
    moved = lms.evaluate(other)
    expected = np.einsum("lj,ljc->lc", lms.bary, other[lms.corners])
    np.testing.assert_allclose(moved, expected)
    assert (
        np.linalg.norm(moved - base, axis=1).mean() > 1e-3
    )  # another head: mm-scale shifts
    opened = lms.evaluate(_ict_expression(tmpl, "jawOpen"))
    dy = (opened - base)[:, 1]
    chin = definition.region_mask("jaw") & (np.abs(base[:, 0]) < 0.02)
    assert dy[chin].mean() < -0.01  # the chin drops by centimetres
    assert np.abs(dy[definition.region_mask("brow_left")]).max() < 0.002
    batch = lms.evaluate(np.stack([tmpl.neutral, other]))
    assert batch.shape == (2, len(lms), 3)
    np.testing.assert_allclose(batch[1], moved)
    with pytest.raises(ValueError, match="template topology"):
        lms.evaluate(arkit.neutral)


# ---- CLI ------------------------------------------------------------------------------------
def test_cli_step_writes_render_and_report(tmp_path, capsys):
    assert main(["landmarks", "--out", str(tmp_path)]) == 0
    png = tmp_path / "registration.png"
    with Image.open(png) as im:
        img = np.asarray(im.convert("RGB"))
    assert img.shape[0] > 1000 and img.shape[1] > 1500
    assert (np.abs(img.astype(int) - 255).sum(axis=2) > 30).mean() > 0.2  # not blank
    rep = json.loads((tmp_path / "landmarks_report.json").read_text())
    assert rep["landmarks"]["count"] == len(load_definition())
    assert rep["nonrigid"]["pairs"] == list(CONSTRAINED_68)
    assert "residual" in (tmp_path / "landmarks_report.md").read_text()
    assert "landmarks to S" in capsys.readouterr().out
