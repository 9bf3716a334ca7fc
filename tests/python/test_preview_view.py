"""A replay of a user's avatar is shown as a person would look at it: each part's own
coordinates (any unit, any up axis) mapped to metres in the subject's frame by the replay's
`avatar_mesh.view`, the face framed around the eyes whatever else the mesh holds."""

from __future__ import annotations

import numpy as np
from softdeca_train.host.preview import face_focus, to_view


def _summary(to_view_rows: list[list[float]], count: int) -> dict:
    return {
        "avatar_mesh": {
            "view": {
                "metres_per_unit": 0.01,
                "parts": [
                    {
                        "first_vertex": 0,
                        "vertex_count": count,
                        "to_view": [x for row in to_view_rows for x in row],
                    }
                ],
            }
        }
    }


def test_a_centimetre_z_up_part_is_shown_in_metres_y_up() -> None:
    # cm, Z up, the face looking along -Y, the eyes at (0, 0, 170) cm: to_view as the
    # replay writes it (x stays the subject's left, z -> up, -y -> out of the face).
    rows = [[0.01, 0, 0, 0], [0, 0, 0.01, -1.70], [0, -0.01, 0, 0]]
    points = np.array([[0, 0, 170], [0, -10, 170], [3, 0, 175]], dtype=np.float32)
    shown = to_view(_summary(rows, 3), points)
    np.testing.assert_allclose(
        shown, [[0, 0, 0], [0, 0, 0.1], [0.03, 0.05, 0]], atol=1e-6
    )
    frames = to_view(_summary(rows, 3), np.stack([points, points + [0, 0, 1]]))
    np.testing.assert_allclose(frames[1] - frames[0], [[0, 0.01, 0]] * 3, atol=1e-6)


def test_the_templates_heads_are_shown_as_they_are() -> None:
    points = np.random.default_rng(0).normal(size=(5, 3)).astype(np.float32)
    assert to_view({"avatar_mesh": None}, points) is points


def test_the_face_is_framed_around_the_eyes_not_at_a_bodys_toes() -> None:
    rng = np.random.default_rng(1)
    head = rng.uniform(-0.08, 0.08, size=(400, 3))  # around the eyes, metres
    toes = np.array(
        [[0.1, -1.6, 0.25], [-0.1, -1.6, 0.25]]
    )  # further forward than the nose
    mesh = np.concatenate([head, toes])
    focus = face_focus(mesh, centred=True)
    assert focus.hi[2] < 0.1 and focus.lo[1] > -0.2
    assert face_focus(mesh).hi[2] > 0.2  # without the view, the most forward point wins
