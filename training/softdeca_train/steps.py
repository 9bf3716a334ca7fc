"""The pipeline's steps, registered for the CLI. Each imports its module lazily so that
`--help` is instant and a step only pays for what it uses."""

from __future__ import annotations

import argparse


def _ict_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--ict",
        default=None,
        help="ICT-FaceKit checkout, FaceXModel folder or .tar.xz archive "
        "(default: $SOFTDECA_ICT or ../shared/ict-facekit)",
    )


def _template_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)


def _template_run(args: argparse.Namespace) -> int:
    from softdeca_train.template import Template

    t = Template.load(args.ict)
    print(
        f"template: {t.n_vertices} vertices, {len(t.triangles)} triangles, "
        f"S: {len(t.skin_triangles)} triangles; {len(t.expression_names)} expressions, "
        f"{t.identity_modes.shape[0]} identity modes; ICT '{t.left_suffix}' = subject's left"
    )
    return 0


def _bench_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--out", default="build/bench", help="folder for <area>.json (build/bench)")
    p.add_argument("--heads", type=int, default=8, help="identities per LHM resolution (8)")


def _bench_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.bench import bench_lhm, machine, write_area

    figures = bench_lhm(args.ict, heads=args.heads)
    path = write_area(Path(args.out), "lhm", figures)
    print(f"machine: {machine()}")
    for name, f in figures.items():
        print(f"  {name:34s} {f['value']:>10.1f} {f['unit']:4s} (target {f['target']})")
    print(f"wrote {path}")
    return 0


STEPS = {
    "template": (
        "Load ICT-FaceKit into the cache and summarise the template.",
        _template_args,
        _template_run,
    ),
    "bench": (
        "Benchmark the pipeline (LHM fitting per resolution) into build/bench/<area>.json.",
        _bench_args,
        _bench_run,
    ),
}
