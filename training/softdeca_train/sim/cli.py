"""`python -m softdeca_train simulate`: φ† on a Live
Link Face take for one identity and parameter set -> point caches, OBJ sequence, render and
a summary of linear blendshapes against physics."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softdeca_train.commands import Command, add_ict_argument
from softdeca_train.sim.stress_cli import add_stress_args, run_stress_cli

if TYPE_CHECKING:
    import softdeca_native as native

    from softdeca_train.template import Template

DEFAULT_LEVEL = 4
REFERENCE_MAX_ITERATIONS = 20000  # a reference solve runs to its tolerance, not to the cap


def add_simulate_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("take", help="Live Link Face CSV take (columns by name; face-lost rows skipped)")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument(
        "--ict",
        default=None,
        help="ICT-FaceKit checkout, FaceXModel folder or archive (default: $SOFTDECA_ICT)",
    )
    who = p.add_mutually_exclusive_group()
    who.add_argument("--seed", type=int, default=None, help="ICT identity seed (default: template)")
    who.add_argument(
        "--coefficients", default=None, help="identity coefficients: .npy or text, one per mode"
    )
    p.add_argument(
        "--parameters",
        default=None,
        help="JSON object name -> value (others: defaults of plugin/data/parameters.json)",
    )
    p.add_argument("--level", type=int, default=DEFAULT_LEVEL, help="LHM wrap resolution (4)")
    p.add_argument("--start", type=int, default=0, help="first tracked frame (0)")
    p.add_argument("--frames", type=int, default=10, help="frames to simulate (10; about 1 s each)")
    p.add_argument("--stride", type=int, default=1, help="take every Nth tracked frame (1)")
    p.add_argument("--dynamic", action="store_true", help="second-order dynamics (eq. 9)")
    p.add_argument("--no-collisions", action="store_true", help="skip lip/teeth collisions")
    p.add_argument("--threads", type=int, default=1, help="simulator threads (1)")
    p.add_argument(
        "--tolerance", type=float, default=1e-5, help="solver tolerance (1e-5, docs/physics.md)"
    )
    p.add_argument("--max-iterations", type=int, default=800, help="solver iteration cap (800)")
    p.add_argument(
        "--reference-tolerance",
        type=float,
        default=None,
        help="also solve every frame to this tolerance (e.g. 1e-10, cap 20000 iterations) and "
        "report how far the result lies from it on S (simulate.json `reference`)",
    )
    p.add_argument("--obj-every", type=int, default=0, help="also write every Nth frame as OBJ")
    p.add_argument("--render-frames", type=int, default=3, help="rows of simulate.png (3; 0: none)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _identity(args: argparse.Namespace, template: Template) -> tuple[np.ndarray | None, str]:
    n = template.identity_modes.shape[0]
    if args.seed is not None:
        return template.sample_identity(args.seed), f"seed {args.seed}"
    if args.coefficients is None:
        return None, "template"
    path = Path(args.coefficients)
    if not path.is_file():
        raise FileNotFoundError(f"coefficients not found: {path}")
    h = np.load(path) if path.suffix == ".npy" else np.loadtxt(path)
    h = np.asarray(h, np.float64).ravel()
    if h.shape != (n,) or not np.isfinite(h).all():
        raise ValueError(f"{path}: need {n} finite identity coefficients, got {h.size}")
    return h, str(path)


def _parameters(path: str | None) -> dict[str, float]:
    if path is None:
        return {}
    p = Path(path)
    if not p.exists():  # not is_file(): a shell's <(...) is a pipe
        raise FileNotFoundError(f"parameter file not found: {p}")
    values = json.loads(p.read_text())
    if not isinstance(values, dict) or not all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in values.values()
    ):
        raise ValueError(f"{p}: expected a JSON object of parameter name -> number")
    return {str(k): float(v) for k, v in values.items()}


def _set_parameters(sim: native.Simulator, values: dict[str, float]) -> None:
    from softdeca_train.parameters import load_parameters

    load_parameters().check_values(values)
    for name, value in values.items():
        sim.set_parameter(name, value)


def run_simulate(args: argparse.Namespace) -> int:
    from softdeca_train.lhm import LhmConfig
    from softdeca_train.sim.figure import render_comparison
    from softdeca_train.sim.head import build_head_simulation
    from softdeca_train.sim.output import write_sequences
    from softdeca_train.sim.run import (
        SimulatedTake,
        reference_distances,
        reference_line,
        simulate_frames,
        summarise,
        summary_lines,
    )
    from softdeca_train.sim.take import read_take
    from softdeca_train.template import Template
    from softdeca_train.template.regions import region_labels

    t0 = time.perf_counter()
    if args.threads < 1 or args.level < 1 or args.obj_every < 0 or args.render_frames < 0:
        raise ValueError(
            "need --threads >= 1, --level >= 1, --obj-every >= 0, --render-frames >= 0"
        )
    tolerances = [t for t in (args.tolerance, args.reference_tolerance) if t is not None]
    if not all(0 < t < 1 for t in tolerances) or args.max_iterations < 1:
        raise ValueError("need 0 < --tolerance, --reference-tolerance < 1, --max-iterations >= 1")
    take = read_take(Path(args.take), args.start, args.frames, args.stride)
    values = _parameters(args.parameters)
    template = Template.load(args.ict)
    h, who = _identity(args, template)
    print(
        f"take {take.path.name}: {take.tracked} tracked frames, {take.face_lost_rows} face-lost "
        f"rows skipped; simulating {len(take.frames)} ({who}, LHM level {args.level}, "
        f"{'dynamic' if args.dynamic else 'static'}, collisions "
        f"{'off' if args.no_collisions else 'on'})",
        flush=True,
    )
    hs = build_head_simulation(template, h, LhmConfig(level=args.level))
    settings = {"collision_rounds": 0} if args.no_collisions else {}

    def run(tolerance: float, max_iterations: int) -> SimulatedTake:
        sim = hs.simulator(
            threads=args.threads, tolerance=tolerance, max_iterations=max_iterations, **settings
        )
        _set_parameters(sim, values)
        return simulate_frames(hs, sim, take.weights, args.dynamic, progress=not args.quiet)

    result = run(args.tolerance, args.max_iterations)
    reference = None
    if args.reference_tolerance is not None:
        exact = run(args.reference_tolerance, REFERENCE_MAX_ITERATIONS)
        reference = reference_distances(
            result, exact, args.reference_tolerance, region_labels(template)
        )

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    caches = write_sequences(
        out,
        hs.head,
        template.triangles,
        {"linear": result.linear, "physics": result.physics},
        args.obj_every,
    )
    summary = summarise(result.records)
    rendered = None
    if args.render_frames:
        rendered = render_comparison(
            out / "simulate.png",
            hs.head,
            template.triangles,
            result.linear,
            result.physics,
            [f"frame {int(f)}" for f in take.frames],
            args.render_frames,
            notes=[f"take {take.path.name}, {who}, LHM level {args.level}"],
        )
    report = {
        "take": str(take.path),
        "tracked_frames": take.tracked,
        "face_lost_rows_skipped": take.face_lost_rows,
        "malformed_rows_skipped": take.malformed_rows,
        "frames": take.frames.tolist(),
        "identity": who,
        "lhm_level": args.level,
        "tets": {"soft": len(hs.mesh.soft_tets), "muscle": len(hs.mesh.muscle_tets)},
        "simulated_vertices": hs.mesh.vertex_count,
        "parameters": values,
        "dynamic": args.dynamic,
        "collisions": not args.no_collisions,
        "threads": args.threads,
        "tolerance": args.tolerance,
        "max_iterations": args.max_iterations,
        "reference": reference,
        "simulation_seconds": result.seconds,
        "wall_seconds": time.perf_counter() - t0,
        "summary": summary,
        "per_frame": [r.as_dict() for r in result.records],
        "point_caches": caches,
        "render": None if rendered is None else str(rendered),
    }
    (out / "simulate.json").write_text(json.dumps(report, indent=2) + "\n")
    print("\n".join(summary_lines(summary, result.seconds)))
    if reference is not None:
        print(reference_line(reference, args.tolerance))
    for frame, r in zip(take.frames, result.records, strict=True):
        if r.failures:
            c = r.check
            print(
                f"  frame {int(frame)} fails: {', '.join(r.failures)} (max distance to linear "
                f"{c.max_displacement_mm:.1f} mm, penetrating lip points linear "
                f"{c.penetrating_linear} / physics {c.penetrating_physics}, mouth opening "
                f"{c.opening_linear_mm:.1f} -> {c.opening_physics_mm:.1f} mm, inverted tets "
                f"{c.inverted_elements})"
            )
    print(
        f"wrote {out}/neutral.obj, linear.pc2, physics.pc2, simulate.json"
        + (", simulate.png" if rendered else "")
    )
    return 0


def _bench_physics_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("--out", default="build/bench", help="folder for physics_lhm.json")
    p.add_argument("--take", default=None, help="Live Link Face CSV (default: alex_rom_3)")
    p.add_argument("--levels", type=int, nargs="+", default=[3, 4], help="LHM levels (3 4)")
    p.add_argument("--stride", type=int, default=400, help="every Nth frame (400)")


def _bench_physics_run(args: argparse.Namespace) -> int:
    from softdeca_train.bench import report_area
    from softdeca_train.sim.bench import DEFAULT_TAKE, bench_physics_lhm

    take = Path(args.take) if args.take else DEFAULT_TAKE
    figures = bench_physics_lhm(args.ict, take, tuple(args.levels), args.stride)
    report_area(Path(args.out), "physics_lhm", figures)
    return 0


COMMANDS = [
    Command(
        "simulate",
        "Simulate a Live Link Face take with the physics model for one identity: neutral.obj + "
        "linear.pc2/physics.pc2 point caches, simulate.png (linear | physics | distance), "
        "simulate.json (iterations, time, volume change, lip penetrations, distance).",
        add_simulate_args,
        run_simulate,
    ),
    Command(
        "stress",
        "The physics stress suite: extreme expressions, identities, materials, gravity, levels, "
        "static and dynamic, real takes, judged by the sanity bounds -> stress.json, stress.md, "
        "stress_worst.png (and physics_stress.json with --bench-out).",
        add_stress_args,
        run_stress_cli,
    ),
    Command(
        "bench-physics",
        "Benchmark the physics model on the real layered head model and real frames "
        "-> build/bench/physics_lhm.json.",
        _bench_physics_args,
        _bench_physics_run,
    ),
]
