"""Where an avatar's face is, which way it faces and its unit, read off its own ARKit shapes
(plugin/src/fit/avatar_frame.h): on the ICT template, and on it moved into the conventions
avatars come in: centimetres, Z-up, a whole body around the head, shuffled vertices, a mirrored
export, only some of the shapes."""

from __future__ import annotations

import numpy as np
import pytest
import softdeca_native as native
from softdeca_train.face_names import ARKIT_BLENDSHAPES
from softdeca_train.template import Template


@pytest.fixture(scope="module")
def head(template: Template) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The template's skin S (what a bundle's template head holds), its 52 ARKit shapes as
    deltas, and its triangles."""
    eye = np.eye(52)
    deltas = np.stack([template.blend(eye[i]) - template.neutral for i in range(52)])
    skin = template.skin_triangles
    n = int(skin.max()) + 1
    return (
        template.neutral[:n].astype(np.float32),
        deltas[:, :n].astype(np.float32),
        skin.astype(np.int32),
    )


def frame(neutral, deltas, present=None, triangles=None) -> dict:
    present = np.ones(52, bool) if present is None else present
    return native.avatar_frame(
        np.ascontiguousarray(neutral, np.float32),
        np.ascontiguousarray(deltas, np.float32),
        present,
        None if triangles is None else np.ascontiguousarray(triangles, np.int32),
    )


def angle_deg(a, b) -> float:
    a, b = np.asarray(a), np.asarray(b)
    return float(
        np.degrees(
            np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))
        )
    )


def test_the_template_faces_plus_z_in_metres(head) -> None:
    neutral, deltas, triangles = head
    f = frame(neutral, deltas, triangles=triangles)
    # the template's own convention: +X the subject's left, +Y up, +Z out of the face
    assert angle_deg(f["left"], (1, 0, 0)) < 1.0
    assert angle_deg(f["up"], (0, 1, 0)) < 5.0
    assert angle_deg(f["forward"], (0, 0, 1)) < 5.0
    assert f["up_axis"] == "+Y" and not f["mirrored"]
    assert f["metres_per_unit"] == 1.0
    assert (
        abs(f["metres_per_unit_measured"] - 1.0) < 1e-3
    )  # the pairs' table is the template's
    moving = int(
        (np.abs(deltas).reshape(52, -1).max(axis=1) > 0).sum()
    )  # ICT: no tongueOut
    assert f["shapes_used"] == moving and 1000 < f["face_vertices"] < len(neutral)
    assert (
        abs(f["eyes"][0]) < 1e-3 and f["eyes"][2] > 0.05
    )  # between the eyes, in front


# Every pair of the library's table (fit/avatar_frame.cpp, kSidePairs).
SIDE_PAIRS = [
    "browDown", "browOuterUp", "cheekSquint", "eyeBlink", "eyeLookDown", "eyeLookIn",
    "eyeLookOut", "eyeLookUp", "eyeSquint", "eyeWide", "mouthDimple", "mouthFrown",
    "mouthLowerDown", "mouthPress", "mouthSmile", "mouthStretch", "mouthUpperUp", "noseSneer",
]  # fmt: skip


@pytest.mark.parametrize("stem", SIDE_PAIRS)
def test_each_side_pair_alone_gives_the_unit(head, stem: str) -> None:
    """One Left/Right pair, one eye and one mouth shape: the table's distance for that pair is
    the template's (so any subset of shapes measures the unit)."""
    neutral, deltas, triangles = head
    present = np.zeros(52, bool)
    for name in (stem + "Left", stem + "Right", "eyeBlinkLeft", "jawOpen"):
        present[ARKIT_BLENDSHAPES.index(name)] = True
    f = frame(neutral, deltas, present, triangles)
    assert abs(f["metres_per_unit_measured"] - 1.0) < 0.01, f
    assert angle_deg(f["left"], (1, 0, 0)) < 2.0


def rot_x(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


@pytest.mark.parametrize("unit", [0.001, 0.01, 0.0254, 0.1, 1.0])
def test_units_and_z_up(head, unit: float) -> None:
    neutral, deltas, triangles = head
    r = rot_x(90)  # +Y up becomes +Z up, +Z forward becomes -Y
    f = frame(neutral @ r.T / unit, deltas @ r.T / unit, triangles=triangles)
    assert f["metres_per_unit"] == unit
    assert f["up_axis"] == "+Z"
    assert angle_deg(f["forward"], (0, -1, 0)) < 5.0
    assert angle_deg(f["left"], (1, 0, 0)) < 1.0


def test_a_whole_body_and_shuffled_vertices(head) -> None:
    neutral, deltas, _ = head
    rng = np.random.default_rng(0)
    # a "body": 20k still vertices below and around the head, as a whole-body mesh carries
    body = rng.uniform((-0.3, -1.6, -0.2), (0.3, -0.1, 0.2), (20000, 3)).astype(
        np.float32
    )
    whole = np.concatenate([body, neutral])
    whole_deltas = np.concatenate(
        [np.zeros((52, len(body), 3), np.float32), deltas], axis=1
    )
    order = rng.permutation(len(whole))
    f = frame(whole[order], whole_deltas[:, order])
    g = frame(neutral, deltas)
    assert f["face_vertices"] == g["face_vertices"]
    assert set(order[f["face"]] - len(body)) == set(
        g["face"]
    )  # the same vertices, found again
    for key in ("left", "up", "forward", "eyes"):
        np.testing.assert_allclose(f[key], g[key], atol=1e-6)
    assert f["metres_per_unit"] == 1.0


def test_a_mirrored_export_is_recognised(head) -> None:
    neutral, deltas, triangles = head
    m = np.array([-1.0, 1.0, 1.0], np.float32)  # x negated: a left-handed export
    f = frame(neutral * m, deltas * m, triangles=triangles)
    assert f["mirrored"]
    assert angle_deg(f["left"], (-1, 0, 0)) < 1.0
    assert angle_deg(f["forward"], (0, 0, 1)) < 5.0  # still out of the face


def test_forty_of_fifty_two_shapes(head) -> None:
    neutral, deltas, triangles = head
    present = np.ones(52, bool)
    present[np.random.default_rng(3).choice(52, 12, replace=False)] = False
    f = frame(neutral, deltas, present, triangles)
    moving = (np.abs(deltas).reshape(52, -1).max(axis=1) > 0) & present
    assert f["shapes_used"] == moving.sum() and f["metres_per_unit"] == 1.0
    assert angle_deg(f["up"], (0, 1, 0)) < 5.0


def test_bad_avatars_get_a_message_a_user_can_act_on(head) -> None:
    neutral, deltas, _ = head
    with pytest.raises(
        ValueError, match="none of the avatar's ARKit blendshapes moves a vertex"
    ):
        frame(neutral, np.zeros_like(deltas))
    only_jaw = np.zeros(52, bool)
    only_jaw[ARKIT_BLENDSHAPES.index("jawOpen")] = True
    with pytest.raises(ValueError, match="Left/Right pair"):
        frame(neutral, deltas, only_jaw)
    bad = neutral.copy()
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite value at vertex 7"):
        frame(bad, deltas)
    with pytest.raises(ValueError, match="vertex index outside"):
        frame(neutral, deltas, triangles=np.array([[0, 1, len(neutral)]]))


def test_arkits_reference_face() -> None:
    """ARKit's own face mesh (1,220 vertices, its own topology, metres, +Y up, +Z out of the
    face), with the 51 shapes of the public set."""
    from softdeca_train.landmarks.arkit_reference import ArkitFace

    face = ArkitFace.load()
    f = frame(face.neutral, face.deltas, face.present, face.triangles)
    assert f["metres_per_unit"] == 1.0 and f["up_axis"] == "+Y" and not f["mirrored"]
    assert angle_deg(f["left"], (1, 0, 0)) < 2.0
    assert angle_deg(f["forward"], (0, 0, 1)) < 10.0
    assert 0.05 < f["eye_distance"] < 0.08
