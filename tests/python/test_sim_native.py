"""The physics simulator phi† through the Python binding (softdeca_native): the parameter list
read by path agrees with the compiled-in one, and a synthetic layered head simulates."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import softdeca_native as sn
from bounds import above, below

PARAMETERS = Path(__file__).resolve().parents[2] / "plugin" / "data" / "parameters.json"


def test_parameter_file_is_the_compiled_table() -> None:
    on_disk = json.loads(PARAMETERS.read_text())
    compiled = sn.parameter_table()
    assert [p["name"] for p in on_disk["parameters"]] == [p["name"] for p in compiled]
    for f, c in zip(on_disk["parameters"], compiled):
        assert (f["default"], f["lo"], f["hi"], f["scale"], f["domain"]) == (
            c["default"],
            c["lo"],
            c["hi"],
            c["scale"],
            c["domain"],
        )
    assert json.loads(sn.parameters_json()) == on_disk


@pytest.fixture(scope="module")
def head() -> sn.SimulationMesh:
    return sn.synthetic_layered_head(subdivisions=2, skin_subdivisions=3)


def test_static_batch_and_sequence(head: sn.SimulationMesh) -> None:
    sim = sn.Simulator(head, threads=2)
    rest = head.embed_skin(head.rest)
    vertices, _skin, stats = sim.solve_static(rest)
    assert stats["converged"]
    below(
        np.abs(vertices - head.rest).max(),
        1e-12,
        "rest is the fixed point: residual 0",
        what="m",
    )
    push = rest + 0.004 * np.clip(rest[:, 2:3] / 0.1, 0, None) * rest / np.linalg.norm(
        rest, axis=1, keepdims=True
    )
    frames = np.stack([rest, push, push])
    skins, verts, stats = sim.solve_static_batch(frames)
    assert skins.shape == (3, head.skin_count, 3) and verts.shape == (
        3,
        head.vertex_count,
        3,
    )
    assert all(s["converged"] for s in stats)
    below(
        np.abs(skins[1] - skins[2]).max(),
        1e-5,
        "one target twice: the second starts from the first, both within tolerance 1e-5",
        what="m",
    )
    front = int(np.argmax(rest[:, 2]))
    # follows the push (4 mm there): 3.0 mm of it at the defaults, the tissue taking the rest
    above(
        skins[1][front, 2] - rest[front, 2], 0.002, "3.0 mm of the 4 mm push", what="m"
    )
    sim.set_parameter("dyn_gamma", 0.5)
    sim.set_parameter("dyn_beta", 0.6)
    seq, _, _ = sim.solve_sequence(np.stack([rest] + [push] * 12))
    moved = seq[:, front, 2] - rest[front, 2]
    # overshoot, then back toward the static pose
    above(
        moved.max() / moved[-1],
        1.05,
        "eq. 9 with gamma 0.5, beta 0.6 overshoots",
        what="peak/end",
    )


def test_dynamic_target_is_what_the_next_step_solves_toward(
    head: sn.SimulationMesh,
) -> None:
    """The reference a dynamic frame is judged against: gamma S + 2 alpha T1 - beta T2."""
    sim = sn.Simulator(head, threads=1)
    sim.set_parameter("dyn_gamma", 0.3)
    sim.set_parameter("dyn_beta", 0.2)
    rest = head.embed_skin(head.rest)
    push = rest + np.array([0.0, 0.0, 0.003])
    np.testing.assert_array_equal(sim.dynamic_target(push), push)  # first frame: static
    _, t1, _ = sim.step_dynamic(rest)
    _, t2, _ = sim.step_dynamic(push)
    expected = 0.3 * push + (1 - 0.3 + 0.2) * t2 - 0.2 * t1
    np.testing.assert_allclose(sim.dynamic_target(push), expected, atol=1e-12)
    with pytest.raises(ValueError):
        sim.dynamic_target(push[:5])


def test_hand_built_mesh_and_errors(head: sn.SimulationMesh) -> None:
    mesh = sn.SimulationMesh(
        rest=head.rest,
        soft_tets=head.soft_tets,
        muscle_tets=head.muscle_tets,
        connecting_tets=head.connecting_tets,
        skull_triangles=head.skull_triangles,
        cranium_vertices=head.cranium_vertices,
        jaw_vertices=head.jaw_vertices,
        skin_vertices=head.skin_vertices,
        skin_weights=head.skin_weights,
        skin_triangles=head.skin_triangles,
    )
    sim = sn.Simulator(mesh)
    rest = mesh.embed_skin(mesh.rest)
    with pytest.raises(ValueError, match=r"outside its range \[0.001, 100\]"):
        sim.set_parameter("w_target", 1e3)
    with pytest.raises(ValueError, match="skin_point has"):
        sim.set_parameter_field("w_target", np.ones(3))
    bad = rest.copy()
    bad[4, 0] = np.nan
    with pytest.raises(ValueError, match=r"skin_targets\[4\]\[0\] is not finite"):
        sim.solve_static(bad)
    with pytest.raises(ValueError, match="rows, expected"):
        sim.solve_static(rest[:10])
    tets = head.soft_tets.copy()
    tets[0, [2, 3]] = tets[0, [3, 2]]
    with pytest.raises(ValueError, match=r"soft_tets\[0\] is inverted"):
        sn.SimulationMesh(
            rest=head.rest,
            soft_tets=tets,
            muscle_tets=head.muscle_tets,
            connecting_tets=head.connecting_tets,
            skull_triangles=head.skull_triangles,
            cranium_vertices=head.cranium_vertices,
            jaw_vertices=head.jaw_vertices,
            skin_vertices=head.skin_vertices,
            skin_weights=head.skin_weights,
            skin_triangles=head.skin_triangles,
        )


def test_batch_takes_per_frame_jaw_transforms(head: sn.SimulationMesh) -> None:
    """solve_static_batch(jaw=(F, 4, 4)) gives what solve_static gives frame by frame (both
    converged tightly: they start from different guesses)."""
    sim = sn.Simulator(head, threads=2, tolerance=1e-9, max_iterations=5000)
    rest = head.embed_skin(head.rest)
    jaws = np.stack([np.eye(4)] * 3)
    for k, angle in enumerate((0.0, 0.05, 0.1)):
        c, s = np.cos(angle), np.sin(angle)
        jaws[k, 1:3, 1:3] = [[c, -s], [s, c]]
    skins, verts, _ = sim.solve_static_batch(np.stack([rest] * 3), jaw=jaws)
    jaw = np.asarray(head.jaw_vertices)
    for k in range(3):
        _, s, _ = sim.solve_static(rest, jaw=jaws[k])
        below(
            np.abs(skins[k] - s).max(),
            1e-6,
            "both solved to tolerance 1e-9 of the diagonal from different guesses",
            what="m",
        )
        below(
            np.abs(verts[k][jaw] - (head.rest[jaw] @ jaws[k, :3, :3].T)).max(),
            1e-12,
            "pinned vertices are set, not solved: rounding only",
            what="m",
        )
    # the jaw really turned
    above(
        np.abs(verts[2][jaw] - head.rest[jaw]).max(), 1e-3, "0.1 rad at 5 cm", what="m"
    )
    with pytest.raises(ValueError, match="jaw must have as many frames"):
        sim.solve_static_batch(np.stack([rest] * 3), jaw=jaws[:2])
