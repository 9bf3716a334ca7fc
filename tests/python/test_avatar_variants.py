"""Test avatars (softdeca_train.sample_avatars, `python -m softdeca_train avatar`): the template
moved into the conventions users' avatars come in, and the truth that takes each back to the
template: the remesh stays on the surface, carried shapes are the template's at the same
surface points, unit, axes and mirror invert exactly, rig names read back under the library's
rule, the files read back, a whole body leaves the face a small part; and the library's avatar
frame reads each variant's unit and axes."""

from __future__ import annotations

import argparse

import igl
import numpy as np
import pytest
import scipy.sparse as sp
import softdeca_native as native
from bounds import below
from scipy.spatial import cKDTree
from softdeca_train.cli import STAGES
from softdeca_train.data.plan import derived_seed
from softdeca_train.face_names import ARKIT_BLENDSHAPES
from softdeca_train.landmarks import ArkitFace
from softdeca_train.sample_avatars import (
    HELD_OUT_IDENTITIES,
    NAME_STYLES,
    UNITS,
    AvatarConfig,
    AvatarMesh,
    make_avatar,
    read_avatar,
    rig_name,
    write_avatar,
)
from softdeca_train.sample_avatars.cli import COMMANDS, config_from_args
from softdeca_train.sample_avatars.config import low_poly
from softdeca_train.sample_avatars.mesh import PARTS
from softdeca_train.sample_avatars.remesh import remesh
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN


@pytest.fixture(scope="module")
def face() -> ArkitFace:
    return ArkitFace.load()


@pytest.fixture(scope="module")
def remeshed(template: Template) -> AvatarMesh:
    """A held-out head's skin remeshed to about 6,000 vertices, its eyes and teeth apart,
    shuffled, in inches, Z-up, mirrored, its shapes named eyeBlink_L."""
    config = AvatarConfig(
        remesh=6000,
        separate_eyes_teeth=True,
        shuffle=True,
        unit="inch",
        up="z",
        mirror=True,
        names="suffix_LR",
    )
    return make_avatar(config, template)


@pytest.fixture(scope="module")
def bodied(template: Template) -> AvatarMesh:
    config = AvatarConfig(
        remesh=5000, remesh_style="adaptive", body=True, unit="cm", up="z", shuffle=True
    )
    return make_avatar(config, template)


def identity(truth) -> np.ndarray | None:
    h = truth.identity_coefficients
    return None if h.size == 0 else h


def frame(mesh: AvatarMesh) -> dict:
    """The library's avatar frame of an avatar as a loader has it: its shapes found by their
    rig names under the library's rule."""
    n = len(mesh.neutral)
    deltas = np.zeros((52, n, 3), np.float32)
    present = np.zeros(52, bool)
    for name, shape in mesh.shapes().items():
        i = native.rig_blendshape_index(name)
        assert i >= 0, name
        deltas[i], present[i] = shape - mesh.neutral, True
    return native.avatar_frame(
        np.ascontiguousarray(mesh.neutral, np.float32),
        deltas,
        present,
        np.ascontiguousarray(mesh.triangles, np.int32),
    )


def angle_deg(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    c = a @ b / np.linalg.norm(a) / np.linalg.norm(b)
    return float(np.degrees(np.arccos(np.clip(c, -1, 1))))


def check_frame(mesh: AvatarMesh, forward_deg: float = 5.0, unit: bool = True) -> dict:
    """The frame reads the unit (unless `unit` is False), up axis and handedness the truth
    states, and the subject's left and forward where the template's +X and +Z went."""
    f, truth = frame(mesh), mesh.truth
    if unit:
        assert f["metres_per_unit"] == truth.metres_per_unit
    up = truth.to_avatar((0, 1, 0), direction=True)
    assert f["up_axis"] == ("+Z" if abs(up[2]) > abs(up[1]) else "+Y")
    assert f["mirrored"] == truth.mirror
    assert angle_deg(f["left"], truth.to_avatar((1, 0, 0), direction=True)) < 2.0
    assert (
        angle_deg(f["forward"], truth.to_avatar((0, 0, 1), direction=True))
        < forward_deg
    )
    return f


def test_the_default_is_a_held_out_head_in_the_template_topology(template) -> None:
    """No options: what `softdeca replay` takes (ICT's whole head, metres, ARKit's names)."""
    a = make_avatar(AvatarConfig(), template)
    h = template.sample_identity(404)
    np.testing.assert_array_equal(a.neutral, template.identity_neutral(h))
    np.testing.assert_array_equal(a.triangles, template.triangles)
    eye = np.eye(52)
    for i in range(52):
        np.testing.assert_allclose(
            a.neutral + a.deltas[i], template.blend(eye[i], h), rtol=0, atol=1e-12
        )
    assert a.groups == (("head", len(template.triangles)),)
    assert a.present.sum() == 51 and not a.present[ARKIT_BLENDSHAPES.index("tongueOut")]
    assert a.names == tuple(
        n if p else "" for n, p in zip(ARKIT_BLENDSHAPES, a.present)
    )
    np.testing.assert_array_equal(a.truth.source_vertex, np.arange(template.n_vertices))


def test_held_out_identities_are_no_datasets() -> None:
    """Datasets take their identities' seeds from derived_seed(dataset seed, 1, identity id):
    none of the first 3,000 identities of dataset seeds 0-15 is a test avatar's (or the
    controls gallery's)."""
    used = {derived_seed(s, 1, i) for s in range(16) for i in range(3000)}
    held = {int(label.split()[1]) for label in HELD_OUT_IDENTITIES}
    assert not held & used and not held & {101, 202, 303}


def hausdorff(v, f, w, g) -> tuple[float, float, float]:
    """(Hausdorff distance, mean distance of the original's vertices to the new surface, mean
    edge length of the new): the new surface sampled at its vertices, triangle centres and
    edge midpoints, the original at its vertices."""
    to_new = np.sqrt(igl.point_mesh_squared_distance(v[np.unique(f)], w, g)[0])
    corners = w[g]
    midpoints = ((corners + np.roll(corners, 1, 1)) / 2).reshape(-1, 3)
    samples = np.concatenate([corners.mean(axis=1), midpoints])
    to_old = np.sqrt(igl.point_mesh_squared_distance(samples, v, f)[0])
    edge = np.linalg.norm(corners - np.roll(corners, 1, 1), axis=2).mean()
    return max(to_new.max(), to_old.max()), to_new.mean(), edge


@pytest.mark.parametrize("style", ["isotropic", "adaptive"])
@pytest.mark.parametrize("target", [5000, 10000])
def test_the_remesh_stays_on_the_surface(template, style: str, target: int) -> None:
    v = template.identity_neutral(template.sample_identity(404))
    f = template.skin_triangles.astype(np.int64)
    r = remesh(v, f, target, style)
    w, g = r.points.evaluate(v, f), r.triangles.astype(np.int64)
    below(
        abs(len(w) / target - 1),
        0.02,
        "the face count asked for is the original's triangles-per-vertex times N: "
        "measured +0.3 % (adaptive) and +0.4-0.8 % (isotropic)",
        what="relative vertex count error",
    )
    assert r.resnapped < 0.002 * len(
        w
    )  # a few vertices at the lips and lids (measured 0-8)
    h, mean, edge = hausdorff(v, f, w, g)
    if style == "isotropic":
        below(
            h / edge,
            1.5,
            "every vertex lies on the surface, so the two part inside triangles, across "
            "features thinner than an edge (ears' rims, nostrils): measured 0.65 and 1.00 "
            "mean edges (3.2 and 7.0 mm) at 10k and 5k on this head",
            what="Hausdorff / mean edge",
        )
        below(
            mean / edge,
            0.1,
            "a chord of length L over skin of curvature radius R parts by L²/8R: measured "
            "0.05-0.06 mean edges",
            what="mean distance / mean edge",
        )
    else:
        below(
            h,
            0.001,
            "the least quadric error goes first, so features keep their vertices: "
            "measured 0.2-0.65 mm over seeds 404 and 505 at 5k-10k",
            what="Hausdorff m",
        )
        below(mean, 0.0002, "measured 0.017-0.099 mm", what="mean distance m")


def test_carried_shapes_are_the_templates_at_the_same_points(
    template, remeshed
) -> None:
    """Back in the template's frame, every vertex of every shape is the template's blend at
    the vertex's truth point: the remesh, the unit, the axes, the mirror and the shuffle
    all invert with the truth."""
    truth, h = remeshed.truth, identity(remeshed.truth)
    eye = np.eye(52)
    np.testing.assert_allclose(
        truth.to_template(remeshed.neutral),
        truth.evaluate(template.identity_neutral(h)),
        rtol=0,
        atol=1e-12,
    )
    for i in np.flatnonzero(truth.present):
        shape = truth.to_template(remeshed.neutral + remeshed.deltas[i])
        expected = truth.evaluate(template.blend(eye[i], h))
        np.testing.assert_allclose(shape, expected, rtol=0, atol=1e-12)
    assert truth.present.sum() == 51
    skin = truth.part_mask("skin")
    assert (truth.corners[skin] < N_SKIN).all() and (
        truth.source_vertex[skin] < 0
    ).all()
    assert (
        truth.source_vertex[~skin] >= N_SKIN
    ).all()  # eyes and teeth as ICT has them


def test_the_linear_map_is_what_the_options_say(remeshed) -> None:
    t = remeshed.truth
    expected = (
        np.array([[-1, 0, 0], [0, 0, -1], [0, 1, 0]]) / 0.0254
    )  # mirror, Z-up, inch
    np.testing.assert_allclose(t.linear, expected, rtol=1e-15)
    np.testing.assert_array_equal(t.translation, 0)
    n = len(remeshed.neutral)
    assert sorted(t.order) == list(range(n)) and (t.order != np.arange(n)).any()


@pytest.mark.parametrize("mirror", [False, True])
@pytest.mark.parametrize("up", ["y", "z"])
@pytest.mark.parametrize("unit", list(UNITS))
def test_units_axes_and_mirror_of_arkits_face(
    face, unit: str, up: str, mirror: bool
) -> None:
    """ARKit's face in every unit and axis, mirrored or not, shuffled: the truth takes it back
    exactly and the avatar frame reads what the truth states."""
    config = AvatarConfig(
        arkit_face=True, unit=unit, up=up, mirror=mirror, shuffle=True
    )
    a = make_avatar(config, face=face)
    t = a.truth
    assert t.source == "arkit" and len(a.neutral) == 1220 and a.present.sum() == 51
    np.testing.assert_allclose(
        t.to_template(a.neutral), face.neutral[t.order], rtol=0, atol=1e-12
    )
    assert np.sign(np.linalg.det(t.linear)) == (-1 if mirror else 1)
    check_frame(a, forward_deg=10.0)  # ARKit's face looks 7.5° off its +Z (avatars.md)


def test_the_frame_reads_the_remeshed_heads_axes(remeshed) -> None:
    f = check_frame(remeshed, unit=False)  # the unit: below
    assert f["up_axis"] == "+Z" and f["mirrored"]


def test_the_frame_reads_an_adaptive_remeshs_unit(template) -> None:
    config = AvatarConfig(
        remesh=8000, remesh_style="adaptive", unit="cm", up="z", mirror=True
    )
    f = check_frame(make_avatar(config, template))
    assert f["metres_per_unit"] == 0.01


@pytest.mark.parametrize("identity", ["template", "seed 505"])
def test_the_frame_reads_an_isotropic_remeshs_unit(template, identity: str) -> None:
    """Evenly meshed, unlike ICT's dense eyes and lips: each shape's centre is weighted by the
    vertices' share of the surface, so the Left/Right distances and the unit still hold."""
    a = make_avatar(AvatarConfig(identity=identity, remesh=5000), template)
    assert frame(a)["metres_per_unit"] == 1.0


@pytest.mark.parametrize("style", NAME_STYLES)
def test_every_name_style_reads_back_under_the_librarys_rule(style: str) -> None:
    names = [rig_name(n, style) for n in ARKIT_BLENDSHAPES]
    assert len(set(names)) == 52
    assert [native.rig_blendshape_index(n) for n in names] == list(range(52))


def test_name_styles_look_as_rigs_spell_them() -> None:
    spelled = {s: rig_name("eyeBlinkLeft", s) for s in NAME_STYLES}
    assert spelled == {
        "arkit": "eyeBlinkLeft",
        "namespace": "blendShape1.eyeBlinkLeft",
        "prefix": "AK_09_EyeBlinkLeft",
        "suffix_LR": "eyeBlink_L",
        "snake": "eye_blink_l",
        "pascal": "EyeBlinkLeft",
        "cc": "CC_Base_Body.Eye_Blink_L",
        "daz": "facs_bs_EyeBlinkLeft",
    }
    assert rig_name("jawLeft", "suffix_LR") == "jawLeft"  # a direction, not a side
    assert rig_name("mouthSmileRight", "snake") == "mouth_smile_r"


def test_separate_eyes_and_teeth_are_objects_of_their_own(remeshed) -> None:
    names = [name for name, _ in remeshed.groups]
    assert names == [
        "skin",
        "teeth_upper",
        "teeth_lower",
        "eyeball_left",
        "eyeball_right",
    ]
    parts = {"skin": "skin", "teeth_upper": "teeth", "teeth_lower": "teeth"}
    start, owner = 0, np.full(len(remeshed.neutral), -1)
    for k, (name, count) in enumerate(remeshed.groups):
        corners = np.unique(remeshed.triangles[start : start + count])
        start += count
        assert (owner[corners] == -1).all(), f"{name} shares vertices"
        owner[corners] = k
        assert remeshed.truth.part_mask(parts.get(name, "eyes"))[corners].all(), name
    assert (owner >= 0).all()


def test_a_low_poly_game_head(template) -> None:
    """Decimated skin, eyes, teeth and tongue, hair cards, eyebrow fins and a bust in one
    object: the cards hover off the skin as sheets of their own that no shape moves, the fins
    stand on skin vertices and move with them, and the frame still reads centimetres and Z-up."""
    a = make_avatar(low_poly(AvatarConfig()), template)
    t = a.truth
    assert a.groups == (("head", len(a.triangles)),) and 3_000 < len(a.neutral) < 5_000
    assert {"skin", "eyes", "teeth", "inner", "body", "hair"} <= {
        PARTS[p] for p in t.part
    }
    adjacency = sp.csc_matrix(igl.adjacency_matrix(a.triangles.astype(np.int64)))
    _, labels, _ = igl.connected_components(adjacency)
    skin = t.part_mask("skin")
    head = labels[skin][0]
    fins = t.part_mask("hair") & (labels == head)
    cards = t.part_mask("hair") & (labels != head)
    assert fins.sum() > 20 and cards.sum() > 100
    assert not a.deltas[:, cards].any() and a.deltas[:, fins].any()
    assert not np.isin(labels[cards], labels[skin]).any()  # sheets of their own
    gap = cKDTree(a.neutral[skin]).query(a.neutral[cards])[0]  # cm
    assert 0.1 < np.median(gap) < 1.5
    assert (labels[t.part_mask("body")] == head).all()  # the bust continues the neck
    f = check_frame(a)
    assert f["up_axis"] == "+Z" and f["metres_per_unit"] == 0.01


def test_a_ramp_split_moves_both_sides_and_keeps_the_sum(template) -> None:
    plain = make_avatar(AvatarConfig(), template)
    ramp = make_avatar(AvatarConfig(split_width=0.16), template)
    left, right = (
        ARKIT_BLENDSHAPES.index(n) for n in ("eyeBlinkLeft", "eyeBlinkRight")
    )
    np.testing.assert_allclose(
        ramp.deltas[left] + ramp.deltas[right], plain.deltas[left] + plain.deltas[right]
    )
    on_right = plain.neutral[:, 0] < -0.03  # the subject's right, metres
    assert (
        np.abs(ramp.deltas[left][on_right]).max()
        > 0.1 * np.abs(plain.deltas[right]).max()
    )
    # the unit is read off the pairs' sides; the ramp moves the eye and brow shapes' centres of
    # motion a little, and with them the up axis read (forward 5.1° off measured)
    f = check_frame(ramp, forward_deg=8.0)
    assert f["metres_per_unit"] == 1.0


def test_a_whole_body_leaves_the_face_a_small_part(bodied) -> None:
    """About 20,000 body vertices joined to the neck, still, feet at 0 on the up axis (+Z)."""
    t, n = bodied.truth, len(bodied.neutral)
    body = t.part_mask("body")
    assert abs(body.sum() / 20_000 - 1) < 0.05 and n > 24_000
    assert not bodied.deltas[:, body].any()
    assert bodied.neutral[:, 2].min() == pytest.approx(0.0, abs=1e-9)
    assert bodied.neutral[~body, 2].mean() > bodied.neutral[body, 2].max() - 20  # cm
    # the head and the torso are one surface, wound one way; the limbs four closed ones
    adjacency = sp.csc_matrix(igl.adjacency_matrix(bodied.triangles.astype(np.int64)))
    count, labels, _ = igl.connected_components(adjacency)
    assert count == 5 and len(np.unique(labels[~body])) == 1
    assert (labels[body] == labels[~body][0]).any()
    half = np.concatenate([bodied.triangles[:, [i, (i + 1) % 3]] for i in range(3)])
    assert len(np.unique(half, axis=0)) == len(half)  # no directed edge twice
    f = check_frame(bodied)
    assert f["up_axis"] == "+Z" and f["metres_per_unit"] == 0.01
    assert f["face_vertices"] < 0.2 * n  # measured 17 %


def test_the_files_read_back(tmp_path, template) -> None:
    config = AvatarConfig(
        remesh=3000,
        separate_eyes_teeth=True,
        body=True,
        body_vertices=4000,
        keep_shapes=6,
        names="namespace",
        unit="mm",
        shuffle=True,
    )
    a = make_avatar(config, template)
    back = read_avatar(write_avatar(a, tmp_path / "avatar"))
    np.testing.assert_allclose(back.neutral, a.neutral, rtol=0, atol=5e-7)  # %.6f mm
    np.testing.assert_array_equal(back.triangles, a.triangles)
    assert back.groups == list(a.groups)
    assert sorted(back.shapes) == sorted(n for n in a.names if n)
    for name, vertices in back.shapes.items():
        assert name.startswith("blendShape1.")
        i = native.rig_blendshape_index(name)
        np.testing.assert_allclose(vertices, a.neutral + a.deltas[i], rtol=0, atol=5e-7)
    assert back.truth is not None
    for key, value in vars(a.truth).items():
        np.testing.assert_array_equal(getattr(back.truth, key), value, err_msg=key)


def test_keep_and_drop_shapes(face) -> None:
    def make(**kw) -> AvatarMesh:
        return make_avatar(AvatarConfig(arkit_face=True, **kw), face=face)

    a = make(keep_shapes=40, drop=("jawOpen",), variant_seed=3)
    assert a.present.sum() == 40 and not a.present[ARKIT_BLENDSHAPES.index("jawOpen")]
    assert not a.deltas[~a.present].any()
    assert [n == "" for n in a.names] == list(~a.present)
    same = make(keep_shapes=40, drop=("jawOpen",), variant_seed=3)
    np.testing.assert_array_equal(same.present, a.present)
    assert (make(keep_shapes=40, variant_seed=4).present != a.present).any()
    with pytest.raises(ValueError, match="only 51 shapes"):
        make(keep_shapes=52)
    with pytest.raises(ValueError, match="not ARKit blendshape names: jawOpn"):
        AvatarConfig(drop=("jawOpn",))
    with pytest.raises(ValueError, match="unit must be one of"):
        AvatarConfig(unit="ft")


def test_the_command_line(tmp_path) -> None:
    command = COMMANDS[0]
    assert command.name == "avatar" and "softdeca_train.sample_avatars.cli" in STAGES
    p = argparse.ArgumentParser()
    command.add_arguments(p)
    out = tmp_path / "face"
    argv = ["--arkit-face", "--names", "prefix", "--unit", "cm", "--keep-shapes", "30"]
    assert command.run(p.parse_args(["--out", str(out), *argv, "--no-user-face"])) == 0
    back = read_avatar(out)
    assert len(back.shapes) == 30 and all(n.startswith("AK_") for n in back.shapes)
    assert back.truth is not None and back.truth.metres_per_unit == 0.01
    assert not (out / "user_face").exists()
    args = p.parse_args(
        ["--out", "x", "--seed", "7", "--drop", "jawOpen, eyeBlinkLeft"]
    )
    config = config_from_args(args)
    assert config.identity == "seed 7" and config.drop == ("jawOpen", "eyeBlinkLeft")
    assert config_from_args(p.parse_args(["--out", "x"])).identity == "seed 404"
