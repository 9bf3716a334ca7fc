"""`python -m softdeca_train stress` (`make stress`): the physics stress suite -> a report
(stress.json, stress.md), a contact sheet of the worst frames, and with --bench-out the
benchmark figures (physics_stress.json)."""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from softdeca_train.commands import add_tet_mesh_argument
from softdeca_train.paths import data_dir


def add_stress_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="build/stress", help="report folder (build/stress)")
    p.add_argument("--bench-out", default=None, help="also write physics_stress.json here")
    p.add_argument("--level", type=int, default=3, help="LHM level of most cases (3)")
    p.add_argument(
        "--fine-level", type=int, default=4, help="every expression once more here (4; 0: off)"
    )
    p.add_argument(
        "--identities",
        nargs="+",
        default=["template", "seed 1", "seed 2", "h+2.5σ", "h-2.5σ"],
        help="identities: template, 'seed N', h+2.5σ, h-2.5σ (the leading modes at ±2.5 σ)",
    )
    p.add_argument(
        "--recordings",
        default=str(data_dir() / "recordings"),
        help="folder searched for Live Link Face takes (*.csv; default: the data folder's "
        "recordings); '' for none",
    )
    p.add_argument("--take-stride", type=int, default=10, help="every Nth take frame (10)")
    p.add_argument("--take-identities", type=int, default=3, help="identities on takes (3)")
    p.add_argument(
        "--combinations-only", action="store_true", help="leave out the 52 single shapes"
    )
    p.add_argument("--no-materials", action="store_true", help="skip the material cases")
    p.add_argument(
        "--material",
        action="append",
        default=[],
        metavar="NAME=VALUE[,...]",
        help="an extra case: the combinations on the first identity with these parameter "
        "values (repeatable; e.g. to judge a wider control range's end)",
    )
    p.add_argument("--no-gravity", action="store_true", help="skip the 2 g cases")
    p.add_argument("--no-dynamic", action="store_true", help="skip the dynamic run")
    p.add_argument("--no-collisions", action="store_true", help="collision rounds 0")
    add_tet_mesh_argument(p)
    p.add_argument("--keep-worst", type=int, default=6, help="rows of the contact sheet (6)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="processes, one head simulation (identity, level) each at a time (1)",
    )
    p.add_argument(
        "--ict",
        default=None,
        help="ICT-FaceKit checkout, FaceXModel folder or archive (default: $SOFTDECA_ICT)",
    )


def run_stress_cli(args: argparse.Namespace) -> int:
    from softdeca_train.bench import figure, report_area
    from softdeca_train.sim.run import failure_line
    from softdeca_train.sim.stress import (
        StressPlan,
        build_cases,
        parse_material,
        run_stress,
        run_stress_parallel,
        write_report,
    )
    from softdeca_train.streaming.takes import take_paths
    from softdeca_train.template import Template

    if args.level < 1 or args.fine_level < 0 or args.take_stride < 1 or args.workers < 1:
        raise ValueError("need --level >= 1, --fine-level >= 0, --take-stride >= 1, --workers >= 1")
    takes: tuple[Path, ...] = ()
    if args.recordings:
        folder = Path(args.recordings)
        if not folder.is_dir():
            raise FileNotFoundError(f"recordings folder not found: {folder}")
        takes = tuple(take_paths(folder))
    plan = StressPlan(
        identities=tuple(args.identities),
        level=args.level,
        fine_level=args.fine_level or None,
        materials=not args.no_materials,
        gravity=not args.no_gravity,
        dynamic=not args.no_dynamic,
        takes=takes,
        take_stride=args.take_stride,
        take_identities=args.take_identities,
        combinations_only=args.combinations_only,
        extra_materials=tuple(parse_material(m) for m in args.material),
        tet_mesh=args.tet_mesh,
    )
    template = Template.load(args.ict)
    cases = build_cases(plan)
    print(
        f"stress suite: {len(cases)} cases, {sum(len(c.frames) for c in cases)} frames "
        f"({len(takes)} takes, every {args.take_stride}th frame)",
        flush=True,
    )
    settings = {"collision_rounds": 0} if args.no_collisions else {}
    if args.workers > 1:
        result = run_stress_parallel(
            args.ict, cases, args.keep_worst, args.workers, not args.quiet, **settings
        )
    else:
        result = run_stress(template, cases, args.keep_worst, not args.quiet, **settings)
    command = "python -m softdeca_train stress " + shlex.join(sys.argv[2:])
    summary = write_report(Path(args.out), result, template, command)
    s = summary["all"]
    print(
        f"{s['stress_frames']} frames; {failure_line(s['failures'])}; mouth open ratio "
        f"{s['mouth_open_ratio_min']:.3f}-{s['mouth_open_ratio_max']:.3f}"
    )
    print(f"wrote {args.out}/stress.json, stress.md, stress_worst.png")
    if args.bench_out:
        how = f"{command}: {s['stress_frames']} frames judged by the sanity bounds"
        figures = {
            "physics.stress_exploded_frames": figure(s["stress_exploded_frames"], "frames", how, 0),
            "physics.stress_penetration_worse_frames": figure(
                s["stress_penetration_worse_frames"], "frames", how, 0
            ),
            "physics.mouth_open_ratio_min": figure(
                s["mouth_open_ratio_min"], "ratio", how, 0.9, "higher"
            ),
            "physics.mouth_open_ratio_max": figure(s["mouth_open_ratio_max"], "ratio", how, 1.1),
            "physics.mouth_open_raw_ratio_min": figure(
                s["mouth_open_raw_ratio_min"], "ratio", how + " (plain physics / linear)"
            ),
            "physics.mouth_open_raw_ratio_max": figure(
                s["mouth_open_raw_ratio_max"], "ratio", how + " (plain physics / linear)"
            ),
            "physics.stress_failed_frames": figure(s["stress_failed_frames"], "frames", how, 0),
        }
        report_area(Path(args.bench_out), "physics_stress", figures)
    return 0
