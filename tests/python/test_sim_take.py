"""`python -m softdeca_train simulate` on a real take, its bad-input errors, and lip collisions
on real frames."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from bounds import above, below
from softdeca_train.lhm import LhmConfig
from softdeca_train.mesh_files import read_obj, read_pc2
from softdeca_train.sim import HeadSimulation, build_head_simulation
from softdeca_train.sim.measures import penetrating_points
from softdeca_train.sim.take import read_take
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from streaming_cli import TAKES

TAKE = TAKES / "alex_rom_3.csv"
LEVEL = 2  # LHM resolution of these tests: fast, same code paths as the default 4


def _simulate(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, OMP_NUM_THREADS="1")
    return subprocess.run(
        [sys.executable, "-m", "softdeca_train", "simulate", *args],
        check=False,
        capture_output=True,
        text=True,
        env=env,
        cwd=cwd,
        timeout=600,
    )


def _take_with_face_lost_row(path: Path, rows: int) -> Path:
    """The first `rows` rows of alex_rom_3 plus a face-lost row in the middle."""
    lines = TAKE.read_text(encoding="utf-8").splitlines()
    timecode = lines[1].split(",")[0]
    path.write_text(
        "\n".join(
            [*lines[: 1 + rows // 2], f"{timecode},0", *lines[1 + rows // 2 : 1 + rows]]
        )
        + "\n"
    )
    return path


@pytest.fixture(scope="module")
def simulated(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """`softdeca_train simulate` on 2 frames of a take with a face-lost row: (output folder, stdout)."""
    tmp_path = tmp_path_factory.mktemp("simulate")
    take = _take_with_face_lost_row(tmp_path / "take.csv", 40)
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"w_soft_volume": 20.0}))
    out = tmp_path / "sim"
    r = _simulate(
        str(take), "--out", str(out), "--level", str(LEVEL), "--start", "10", "--frames", "2",
        "--stride", "15", "--parameters", str(params), "--obj-every", "1", "--render-frames", "2",
        "--seed", "3", "--reference-tolerance", "1e-9", "--quiet", cwd=tmp_path,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    return out, r.stdout


def test_simulate_writes_caches_render_and_summary(simulated: tuple[Path, str]) -> None:
    out, stdout = simulated
    summary = json.loads((out / "simulate.json").read_text())
    assert summary["face_lost_rows_skipped"] == 1
    assert summary["tracked_frames"] == 40
    assert summary["frames"] == [10, 25]
    assert summary["parameters"] == {"w_soft_volume": 20.0}
    assert summary["summary"]["frames"] == 2
    neutral, _ = read_obj(out / "neutral.obj")
    for name in ("linear", "physics"):
        cache = read_pc2(out / f"{name}.pc2")
        assert cache.shape == (2, len(neutral), 3)
        assert np.isfinite(cache).all()
        assert (out / "obj" / f"{name}_00001.obj").is_file()
    # The physics differs from the linear blend.
    d = np.linalg.norm(
        read_pc2(out / "physics.pc2") - read_pc2(out / "linear.pc2"), axis=2
    )
    above(d.max(), 1e-4, "contacts and tissue move the skin by millimetres", what="m")
    assert summary["summary"]["distance_mm_mean"] > 0
    assert (out / "simulate.png").stat().st_size > 10_000
    assert "penetrating lip vertices" in stdout


def test_simulate_measures_its_distance_to_a_tight_reference(
    simulated: tuple[Path, str],
) -> None:
    out, stdout = simulated
    summary = json.loads((out / "simulate.json").read_text())
    ref = summary["reference"]
    assert summary["tolerance"] == 1e-5 and ref["tolerance"] == 1e-9
    assert ref["converged"] == 2 and len(ref["per_frame"]) == 2
    # At 1e-5 of the diagonal the mean distance to the tight solve is a few µm, not zero.
    above(ref["mean_mm"], 0, "a solve stopped at 1e-5 is not the tight one", what="mm")
    below(
        ref["mean_mm"],
        0.02,
        "tolerance 1e-5 of the 0.3 m diagonal: a few um RMS; 0.02 mm allows the estimate's "
        "3.4-fold slack and more",
        what="mm",
    )
    assert ref["max_mm"] >= max(f["mean_mm"] for f in ref["per_frame"])
    assert "distance on S to the solve at tolerance 1e-09" in stdout


@pytest.mark.skipif(shutil.which("blender") is None, reason="Blender is not installed")
def test_simulate_output_imports_into_blender(simulated: tuple[Path, str]) -> None:
    """The documented Blender steps (training/blender/check_import.py) show the caches."""
    script = (
        Path(__file__).resolve().parents[2] / "training" / "blender" / "check_import.py"
    )
    for cache in ("physics.pc2", "linear.pc2"):
        r = subprocess.run(
            ["blender", "-b", "--factory-startup", "--python-exit-code", "1",
             "--python", str(script), "--",
             str(simulated[0]), cache],
            capture_output=True, text=True, timeout=300, check=False,
        )  # fmt: skip
        assert r.returncode == 0, r.stdout + r.stderr
        assert "largest difference" in r.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--parameters", "{p}"], "unknown parameter"),
        (["--parameters", "{q}"], "outside its range"),
        (["--coefficients", "{c}"], "identity coefficients"),
        (["--start", "999999"], "past the take"),
        (["--stride", "0"], "--stride >= 1"),
        (["--reference-tolerance", "0"], "--reference-tolerance < 1"),
    ],
)
def test_simulate_refuses_bad_input(
    tmp_path: Path, args: list[str], message: str
) -> None:
    (tmp_path / "p.json").write_text(json.dumps({"no_such_parameter": 1.0}))
    (tmp_path / "q.json").write_text(json.dumps({"w_soft_volume": -5.0}))
    np.savetxt(tmp_path / "c.txt", np.zeros(3))
    files = {
        k: str(tmp_path / f)
        for k, f in (("p", "p.json"), ("q", "q.json"), ("c", "c.txt"))
    }
    r = _simulate(
        str(TAKE), "--out", str(tmp_path / "o"), "--level", str(LEVEL), "--frames", "1",
        *[a.format(**files) for a in args], cwd=tmp_path,
    )  # fmt: skip
    assert r.returncode == 2
    assert message in r.stderr
    assert not (tmp_path / "o" / "simulate.json").exists()


def test_simulate_refuses_a_missing_take(tmp_path: Path) -> None:
    r = _simulate(
        str(tmp_path / "none.csv"), "--out", str(tmp_path / "o"), cwd=tmp_path
    )
    assert r.returncode == 2
    assert "take not found" in r.stderr


@pytest.fixture(scope="module")
def lip_head(template: Template) -> HeadSimulation:
    return build_head_simulation(template, None, LhmConfig(level=3))


def _linear_penetrations(hs: HeadSimulation, weights: np.ndarray) -> int:
    """Penetrating lip vertices of the linear blend, teeth placed rigidly (no solve)."""
    blended = hs.blend(weights[None])[0]
    jaw = hs.jaw_transforms(blended[None])[0]
    vertices = np.asarray(hs.mesh.rest, np.float64).copy()
    on_jaw = np.asarray(hs.mesh.jaw_vertices)
    vertices[on_jaw] = vertices[on_jaw] @ jaw[:3, :3].T + jaw[:3, 3]
    return penetrating_points(hs, blended[:N_SKIN], vertices)


def _resolved(hs: HeadSimulation, weights: np.ndarray) -> tuple[int, dict]:
    blended = hs.blend(weights[None])[0]
    jaw = hs.jaw_transforms(blended[None])[0]
    sim = hs.simulator(threads=1)
    vertices, skin, stats = sim.solve_static(
        blended[:N_SKIN].astype(np.float64), jaw=jaw
    )
    return penetrating_points(hs, skin, vertices), stats


def test_collisions_resolve_lips_that_linear_blendshapes_interpenetrate(
    lip_head: HeadSimulation,
) -> None:
    """alex_rom_3, every 200th frame: on each frame whose linear blend has penetrating lip
    vertices (a cheap check, no solve) φ† leaves none (LHM level 3), its volumetric solve
    converging with an energy that never increases."""
    take = read_take(TAKE, stride=200)
    counts = np.array([_linear_penetrations(lip_head, w) for w in take.weights])
    assert (counts > 0).sum() >= 5  # the take really makes linear lips interpenetrate
    assert counts.max() > 50
    for k in np.flatnonzero(counts):
        after, stats = _resolved(lip_head, take.weights[k])
        print(f"frame {take.frames[k]}: linear {counts[k]}, after {after}")
        assert stats["converged"]
        energy = np.array(stats["energy_history"])
        assert len(energy) > 5
        # the solver's safeguard rejects any step that raises the energy it computes
        below(
            np.diff(energy).max() / energy[0],
            1e-12,
            "energy safeguard: a step that raises the energy is rejected",
            what="rise/energy",
        )
        assert after == 0
        assert stats["penetrating_after"] == 0
        # contacts close: no gap between the sides
        below(
            stats["max_contact_gap"],
            1e-5,
            "rounds continue until every contact's sides are within 10 um",
            what="m",
        )


def test_collisions_need_the_contact_step_on_some_frames(
    lip_head: HeadSimulation,
) -> None:
    """Frame 1800 of alex_rom_3: penetrating after the volumetric solve, none after the
    contact rounds."""
    w = read_take(TAKE, start=1800, frames=1).weights[0]
    before = _linear_penetrations(lip_head, w)
    after, stats = _resolved(lip_head, w)
    assert before > 0
    assert stats["penetrating_before"] > 0
    assert stats["collision_rounds"] > 0
    assert after == 0


def test_simulate_dynamic_starts_static_then_lags(tmp_path: Path) -> None:
    """--dynamic: the first frame is the static solution, later ones differ (eq. 9 with γ 0.5)."""
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"dyn_gamma": 0.5, "dyn_beta": 0.5}))
    caches = {}
    for mode in ("static", "dynamic"):
        out = tmp_path / mode
        extra = ["--dynamic"] if mode == "dynamic" else []
        r = _simulate(
            str(TAKE), "--out", str(out), "--level", str(LEVEL), "--start", "1000",
            "--frames", "4", "--parameters", str(params), "--render-frames", "0", "--quiet",
            *extra, cwd=tmp_path,
        )  # fmt: skip
        assert r.returncode == 0, r.stderr
        assert json.loads((out / "simulate.json").read_text())["dynamic"] == (
            mode == "dynamic"
        )
        caches[mode] = read_pc2(out / "physics.pc2")
    d = np.abs(caches["dynamic"] - caches["static"]).max(axis=(1, 2))
    below(
        d[0],
        1e-6,
        "the first dynamic frame is the static solve, same tolerance",
        what="m",
    )
    above(d[1:].min(), 1e-5, "eq. 9 with gamma 0.5 lags by millimetres", what="m")


def test_steps_parse_without_the_native_module(tmp_path: Path) -> None:
    """Every step's arguments load without softdeca_native (ctest runs steps that way)."""
    training = Path(__file__).resolve().parents[2] / "training"
    env = dict(os.environ, PYTHONPATH=str(training))
    for step in ("simulate", "bench-physics", "runtime-test-data"):
        r = subprocess.run(
            [sys.executable, "-m", "softdeca_train", step, "--help"],
            capture_output=True, text=True, env=env, cwd=tmp_path, check=False,
        )  # fmt: skip
        assert r.returncode == 0, r.stderr


def test_reference_distances_name_the_largest_and_its_region() -> None:
    from softdeca_train.sim.run import SimulatedTake, reference_distances
    from softdeca_train.template.regions import REGIONS

    rng = np.random.default_rng(0)
    heads = [rng.normal(size=(N_SKIN + 5, 3)).astype(np.float32) for _ in range(2)]
    labels = np.zeros(N_SKIN, np.int64)
    labels[7] = REGIONS.index("lips")
    a, b = (
        SimulatedTake(physics=heads),
        SimulatedTake(physics=[h.copy() for h in heads]),
    )
    same = reference_distances(a, b, 1e-9, labels)
    assert same["mean_mm"] == 0 and same["max_mm"] == 0
    b.physics[1][7, 0] += 0.002  # 2 mm on one vertex of S
    b.physics[1][N_SKIN + 1] += 1.0  # not S: not measured
    moved = reference_distances(a, b, 1e-9, labels)
    assert moved["per_frame"][0]["max_mm"] == 0
    f = moved["per_frame"][1]
    assert f["max_mm"] == pytest.approx(2.0, rel=1e-3) and f["max_region"] == "lips"
    assert f["max_vertex"] == 7 and moved["tolerance"] == 1e-9
    assert f["over_0_1_mm"] == 1 and f["mean_mm"] == pytest.approx(
        2.0 / N_SKIN, rel=1e-3
    )
