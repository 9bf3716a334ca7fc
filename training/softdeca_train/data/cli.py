"""Arguments and entry points of the data steps (generate, report-data, bench-datagen).
Imports stay light here so that --help is instant."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument
from softdeca_train.data.config import KINDS, GenerateConfig, RunSettings
from softdeca_train.data.ranges import FROM_DEFINITION, PROFILES
from softdeca_train.paths import default_recordings_path

D = GenerateConfig()


# The dataset's options that set one GenerateConfig field each: (option, field, help with `{}`
# where the default goes). Type and default come from GenerateConfig's defaults.
_COUNTS = (
    ("--static", "static", "static instances ({})"),
    ("--dynamic", "dynamic", "dynamic sequences ({})"),
    ("--sparse", "sparse", "sparse instances ({})"),
)
_SAMPLING = (
    ("--seed", "seed", "dataset seed ({})"),
    ("--test-share", "test_share", "test identities ({})"),
    (
        "--level",
        "level",
        "LHM wrap resolution ({}: a reduced scale for this machine; 4-5 on a cluster)",
    ),
    (
        "--frames-per-params",
        "frames_per_params",
        "static/sparse frames per (identity, p) group ({})",
    ),
    ("--params-per-identity", "params_per_identity", "static/sparse groups per identity ({})"),
    ("--sequences-per-identity", "sequences_per_identity", "dynamic sequences per identity ({})"),
    ("--sequence-length", "sequence_length", "frames per dynamic sequence ({})"),
    ("--lead-in", "lead_in", "frames simulated with fixed dynamics before a sequence ({})"),
    ("--real-share", "real_share", "share of static/sparse frames from real takes ({})"),
    (
        "--real-reduced-share",
        "real_reduced_share",
        "share of those real frames played at a reduced amplitude, calmer talking ({})",
    ),
    (
        "--region-share",
        "region_share",
        "share of static/sparse groups with per-region parameter values ({})",
    ),
    ("--noise-mm", "landmark_noise_mm", "landmark noise sigma, mm ({})"),
)
_SOLVER = (
    ("--tolerance", "tolerance", "solver tolerance ({})"),
    (
        "--max-iterations",
        "max_iterations",
        "solver iterations per frame at most; slower frames are flagged ({})",
    ),
)


def _dest(option: str) -> str:
    return option.removeprefix("--").replace("-", "_")


def _add_config_options(
    g: argparse._ArgumentGroup, options: tuple[tuple[str, str, str], ...]
) -> None:
    for option, field, help_text in options:
        default = getattr(D, field)
        g.add_argument(option, type=type(default), default=default, help=help_text.format(default))


def add_generate_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, help="dataset folder (created; resumed if present)")
    add_ict_argument(p)
    p.add_argument(
        "--takes",
        default=None,
        help="folder of takes, searched recursively (Live Link Face CSV, LLV recordings) "
        f"(default: $SOFTDECA_RECORDINGS or {default_recordings_path()})",
    )
    g = p.add_argument_group("what to generate (fixes the dataset; a resume must match)")
    _add_config_options(g, _COUNTS)
    g.add_argument(
        "--instances",
        type=int,
        default=None,
        help="instead of --static/--dynamic: this many frames, 75 %% static and 25 %% in "
        "dynamic sequences (the paper's mix)",
    )
    _add_config_options(g, _SAMPLING)
    g.add_argument(
        "--test-take",
        dest="test_takes",
        action="append",
        default=None,
        help="a take held out entirely for testing, by file stem; repeat for more "
        f"(default: {' '.join(D.test_takes)})",
    )
    g.add_argument(
        "--contrasts",
        action="store_true",
        help="a shard's static/sparse groups share their frames and differ from its first "
        "group's p in one parameter (or one region's value) each",
    )
    g.add_argument(
        "--no-collisions",
        dest="collisions",
        action="store_false",
        help="skip the lip/teeth collision sets and the lips on S (on by default)",
    )
    _add_config_options(g, _SOLVER)
    g.add_argument(
        "--ranges",
        choices=sorted([*PROFILES, *FROM_DEFINITION]),
        default=D.ranges,
        help=f"parameter sampling ranges (data/ranges.py; default {D.ranges}: the control "
        "ranges of plugin/data/parameters.json)",
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
    r.add_argument(
        "--first",
        action="append",
        choices=KINDS,
        default=[],
        help="make this kind's missing shards before the others' (repeatable; the data is "
        "the same, only the order changes)",
    )
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument("--report", action="store_true", help="write the report when done")


def config_from_args(args: argparse.Namespace) -> GenerateConfig:
    kw = {field: getattr(args, _dest(option)) for option, field, _ in (*_SAMPLING, *_SOLVER)}
    kw |= {"collisions": args.collisions, "ranges": args.ranges, "contrasts": args.contrasts}
    kw["test_takes"] = tuple(args.test_takes) if args.test_takes else D.test_takes
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
        takes=Path(args.takes) if args.takes else default_recordings_path(),
        progress=not args.no_progress,
        first=tuple(args.first),
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
