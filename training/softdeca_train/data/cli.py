"""Arguments and entry points of the data steps (generate, report-data, bench-datagen).
Imports stay light here so that --help is instant."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument
from softdeca_train.data.config import GenerateConfig, RunSettings, default_takes_path
from softdeca_train.data.ranges import PROFILES

D = GenerateConfig()


def add_generate_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, help="dataset folder (created; resumed if present)")
    add_ict_argument(p)
    p.add_argument(
        "--takes",
        default=None,
        help="folder of Live Link Face CSV takes "
        f"(default: $SOFTDECA_TAKES or {default_takes_path()})",
    )
    g = p.add_argument_group("what to generate (fixes the dataset; a resume must match)")
    g.add_argument("--static", type=int, default=D.static, help=f"static instances ({D.static})")
    g.add_argument(
        "--dynamic", type=int, default=D.dynamic, help=f"dynamic sequences ({D.dynamic})"
    )
    g.add_argument("--sparse", type=int, default=D.sparse, help=f"sparse instances ({D.sparse})")
    g.add_argument(
        "--instances",
        type=int,
        default=None,
        help="instead of --static/--dynamic: this many frames, 75 %% static and 25 %% in "
        "dynamic sequences (the paper's mix)",
    )
    g.add_argument("--seed", type=int, default=D.seed, help=f"dataset seed ({D.seed})")
    g.add_argument(
        "--test-share", type=float, default=D.test_share, help=f"test identities ({D.test_share})"
    )
    g.add_argument(
        "--level",
        type=int,
        default=D.level,
        help=f"LHM wrap resolution ({D.level}: a reduced scale for this machine; 4-5 on a cluster)",
    )
    g.add_argument(
        "--frames-per-params",
        type=int,
        default=D.frames_per_params,
        help=f"static/sparse frames per (identity, p) group ({D.frames_per_params})",
    )
    g.add_argument(
        "--params-per-identity",
        type=int,
        default=D.params_per_identity,
        help=f"static/sparse groups per identity ({D.params_per_identity})",
    )
    g.add_argument(
        "--sequences-per-identity",
        type=int,
        default=D.sequences_per_identity,
        help=f"dynamic sequences per identity ({D.sequences_per_identity})",
    )
    g.add_argument(
        "--sequence-length",
        type=int,
        default=D.sequence_length,
        help=f"frames per dynamic sequence ({D.sequence_length})",
    )
    g.add_argument(
        "--lead-in",
        type=int,
        default=D.lead_in,
        help=f"frames simulated with fixed dynamics before a sequence ({D.lead_in})",
    )
    g.add_argument(
        "--real-share",
        type=float,
        default=D.real_share,
        help=f"share of static/sparse frames from real takes ({D.real_share})",
    )
    g.add_argument(
        "--test-take", default=D.test_take, help=f"take held out for testing ({D.test_take})"
    )
    g.add_argument(
        "--noise-mm",
        type=float,
        default=D.landmark_noise_mm,
        help=f"landmark noise sigma, mm ({D.landmark_noise_mm})",
    )
    g.add_argument(
        "--no-collisions",
        dest="collisions",
        action="store_false",
        help="skip the lip/teeth collision sets and the lips on S (on by default)",
    )
    g.add_argument(
        "--tolerance", type=float, default=D.tolerance, help=f"solver tolerance ({D.tolerance})"
    )
    g.add_argument(
        "--max-iterations",
        type=int,
        default=D.max_iterations,
        help=f"solver iterations per frame at most; slower frames are flagged ({D.max_iterations})",
    )
    g.add_argument(
        "--ranges",
        choices=sorted(PROFILES),
        default=D.ranges,
        help=f"parameter sampling ranges (data/ranges.py; {D.ranges})",
    )
    r = p.add_argument_group("how to run (free to change on resume)")
    r.add_argument(
        "--workers",
        type=int,
        default=os.cpu_count() or 1,
        help="worker processes (default: all cores); 0 runs in this process",
    )
    r.add_argument("--threads", type=int, default=1, help="simulator threads per worker (1)")
    r.add_argument(
        "--ray-address",
        default=None,
        help="run the shards on Ray: a cluster address, or 'local' for a local instance",
    )
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument("--report", action="store_true", help="write the report when done")


def config_from_args(args: argparse.Namespace) -> GenerateConfig:
    kw = {
        "seed": args.seed,
        "test_share": args.test_share,
        "level": args.level,
        "frames_per_params": args.frames_per_params,
        "params_per_identity": args.params_per_identity,
        "sequences_per_identity": args.sequences_per_identity,
        "sequence_length": args.sequence_length,
        "lead_in": args.lead_in,
        "real_share": args.real_share,
        "test_take": args.test_take,
        "landmark_noise_mm": args.noise_mm,
        "collisions": args.collisions,
        "tolerance": args.tolerance,
        "max_iterations": args.max_iterations,
        "ranges": args.ranges,
    }
    if args.instances is not None:
        return GenerateConfig.from_total(args.instances, args.sparse, **kw)
    return GenerateConfig(static=args.static, dynamic=args.dynamic, sparse=args.sparse, **kw)


def run_generate(args: argparse.Namespace) -> int:
    from softdeca_train.data.generate import generate

    cfg = config_from_args(args)
    run = RunSettings(
        out=Path(args.out),
        workers=args.workers,
        threads=args.threads,
        ray_address=args.ray_address,
        ict=args.ict,
        takes=Path(args.takes) if args.takes else default_takes_path(),
        progress=not args.no_progress,
    )
    try:
        summary = generate(cfg, run)
    except KeyboardInterrupt:
        print(f"interrupted: finished shards are kept; run the same command to resume {run.out}")
        return 130
    print(json.dumps(summary, indent=1))
    if args.report:
        from softdeca_train.data.report import write_report

        print(f"report: {write_report(Path(args.out), Path(args.out) / 'report', args.ict)}")
    return 0 if summary["complete"] else 1


def add_report_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("dataset", help="dataset folder (with manifest.json)")
    p.add_argument("--out", default=None, help="report folder (default: <dataset>/report)")
    add_ict_argument(p)


def run_report(args: argparse.Namespace) -> int:
    from softdeca_train.data.report import write_report

    out = Path(args.out) if args.out else Path(args.dataset) / "report"
    print(f"wrote {write_report(Path(args.dataset), out, args.ict)}")
    return 0


def add_bench_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="build/bench", help="folder for datagen.json (build/bench)")
    add_ict_argument(p)
    p.add_argument("--level", type=int, default=D.level, help=f"LHM level ({D.level})")
    p.add_argument(
        "--workers", type=int, default=os.cpu_count() or 1, help="worker processes (all cores)"
    )
    p.add_argument("--shards", type=int, default=2, help="shards per kind to time (2)")


def run_bench(args: argparse.Namespace) -> int:
    from softdeca_train.bench import machine, write_area
    from softdeca_train.data.bench import bench_datagen

    figures = bench_datagen(args.ict, args.level, args.workers, args.shards)
    path = write_area(Path(args.out), "datagen", figures)
    print(f"machine: {machine()}")
    for name, f in figures.items():
        print(f"  {name:40s} {f['value']:>12.1f} {f['unit']}")
    print(f"wrote {path}")
    return 0


COMMANDS = [
    Command(
        "generate",
        "Generate (or resume) the training dataset: static, dynamic and sparse instances "
        "simulated by the physics, in parallel (processes or Ray), as shards + manifest.",
        add_generate_args,
        run_generate,
    ),
    Command(
        "report-data",
        "Report on a generated dataset: markdown + plots (parameter, weight and identity "
        "distributions; |T - S| per region).",
        add_report_args,
        run_report,
    ),
    Command(
        "bench-datagen",
        "Benchmark data generation on this machine into build/bench/datagen.json.",
        add_bench_args,
        run_bench,
    ),
]
