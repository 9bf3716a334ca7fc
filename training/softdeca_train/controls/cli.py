"""Command line of the controls gallery."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument, add_tet_mesh_argument


def _add(p: argparse.ArgumentParser) -> None:
    from softdeca_train.controls.definitions import REGION_PARAMETERS
    from softdeca_train.controls.gallery import GalleryConfig
    from softdeca_train.paths import REPO_ROOT

    p.add_argument(
        "--out",
        type=Path,
        default=REPO_ROOT / "docs" / "controls",
        help="gallery folder (README.md, controls.json, PNGs; default docs/controls)",
    )
    p.add_argument(
        "--bundle",
        type=Path,
        default=REPO_ROOT / "models" / "softdeca-default",
        help="model bundle folder (default models/softdeca-default)",
    )
    p.add_argument("--no-model", action="store_true", help="physics only: no bundle")
    p.add_argument("--level", type=int, default=3, help="LHM level of the physics (default 3)")
    p.add_argument("--identities", type=int, default=2, help="unseen identities, 1-3 (default 2)")
    p.add_argument("--expressions", type=int, default=3, help="expressions, 1-3 (default 3)")
    p.add_argument("--only", default="", help="comma-separated control names (default: all)")
    p.add_argument(
        "--region-parameters",
        default=",".join(REGION_PARAMETERS),
        help="parameters the region controls set per region "
        f"(default {','.join(REGION_PARAMETERS)})",
    )
    p.add_argument(
        "--ranges",
        choices=("control", "physics"),
        default="control",
        help="move each control over its control range (default) or over the "
        "physics' whole range (also lists the parameters that are no controls)",
    )
    p.add_argument("--no-pictures", action="store_true", help="figures only, no PNGs")
    p.add_argument(
        "--split-rest",
        action="store_true",
        help="also solve every control at rest and split its change into that part and what "
        "the expression adds (rest_error, expression_share, expression_error per control)",
    )
    add_physics_cache_argument(p)
    add_tet_mesh_argument(p)
    p.add_argument(
        "--tolerance",
        type=float,
        default=GalleryConfig.tolerance,
        help=f"the physics solver's tolerance (default {GalleryConfig.tolerance:g}: ten times "
        "tighter than the data)",
    )
    p.add_argument(
        "--max-iterations",
        type=int,
        default=GalleryConfig.max_iterations,
        help=f"solver iterations at most ({GalleryConfig.max_iterations})",
    )
    p.add_argument(
        "--takes",
        type=Path,
        default=None,
        help="Live Link Face takes folder (default: the data folder's)",
    )
    add_ict_argument(p)


def _run(args: argparse.Namespace) -> int:
    from softdeca_train.controls.gallery import GalleryConfig, run_gallery, write_gallery
    from softdeca_train.paths import default_takes_path

    cfg = GalleryConfig(
        out=args.out,
        bundle=None if args.no_model else args.bundle,
        level=args.level,
        identities=args.identities,
        expressions=args.expressions,
        only=tuple(n for n in args.only.split(",") if n),
        region_parameters=tuple(n for n in args.region_parameters.split(",") if n),
        ranges=args.ranges,
        pictures=not args.no_pictures,
        split_rest=args.split_rest,
        tolerance=args.tolerance,
        max_iterations=args.max_iterations,
        tet_mesh=args.tet_mesh,
        takes=args.takes or default_takes_path(),
        ict=args.ict,
        physics_cache=physics_cache_of(args),
    )
    result = run_gallery(cfg)
    path = write_gallery(cfg, result)
    for e in result["controls"]:
        err = e["response_error"]
        leak = e["leakage"]
        print(
            f"{e['name']:28s} physics max {e['physics_max_mm']:8.3f} mm  "
            f"response error {'–' if err is None else f'{err:.2f}':>5s}  "
            f"leakage {'–' if leak is None else f'{leak:.2f}'}" + _split_text(e)
        )
    print(f"wrote {path} ({result['seconds']:.0f} s)")
    return 0


def _split_text(e: dict) -> str:
    """The rest split's figures of a gallery entry (--split-rest), or nothing."""
    if "expression_share" not in e:
        return ""
    rest, added = e["rest_error"], e["expression_error"]
    return (
        f"  at rest {'–' if rest is None else f'{rest:.3f}'}"
        f"  expression's share {e['expression_share']:.2f}"
        f", its error {'–' if added is None else f'{added:.2f}'}"
    )


def add_physics_cache_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--no-physics-cache",
        action="store_true",
        help="solve the physics again instead of reusing solves of the same physics sources "
        "($SOFTDECA_CACHE/controls-physics; never used with uncommitted physics changes)",
    )


def physics_cache_of(args: argparse.Namespace) -> Path | None:
    from softdeca_train.controls.physics_cache import default_folder

    return None if args.no_physics_cache else default_folder()


def add_report_arguments(p: argparse.ArgumentParser, standalone: bool = True) -> None:
    """Options of the report's `controls` and `real_takes` (also on `evaluate`)."""
    from softdeca_train.paths import data_dir

    if standalone:
        p.add_argument(
            "--report",
            type=Path,
            default=Path("docs/evaluation/evaluation.json"),
            help="evaluation report to add them to (keeps its `errors`)",
        )
        p.add_argument(
            "--bundle",
            type=Path,
            default=Path("models/softdeca-default"),
            help="model bundle (default models/softdeca-default)",
        )
    p.add_argument(
        "--controls-json",
        type=Path,
        default=None,
        help="take `controls` from a gallery's controls.json instead of measuring "
        "them (static, level 3, 2 identities x 3 expressions, no pictures)",
    )
    p.add_argument(
        "--recordings",
        type=Path,
        default=data_dir() / "recordings",
        help="every *.csv below it is a take for `real_takes` (default: the data "
        "folder's recordings)",
    )
    p.add_argument("--real-every", type=int, default=10, help="every n-th frame (default 10)")
    p.add_argument("--real-identities", type=int, default=3, help="identities, 1-3 (default 3)")
    p.add_argument(
        "--real-reduced",
        type=float,
        default=0.3,
        help="also judge every unseen take with its weights scaled by this, a calm face of the "
        "same motion (default 0.3; 0: as recorded only)",
    )
    p.add_argument("--no-real-takes", action="store_true", help="leave `real_takes` as it is")
    add_physics_cache_argument(p)


def report_parts(args: argparse.Namespace, bundle: Path) -> tuple[list[dict], dict | None]:
    """The report's `controls` (measured, or read from --controls-json) and `real_takes`."""

    from softdeca_train.controls.gallery import GalleryConfig, report_entries, run_gallery
    from softdeca_train.controls.report import RealTakes, real_takes

    if args.controls_json is not None:
        gallery = json.loads(Path(args.controls_json).read_text())
    else:
        gallery = run_gallery(
            GalleryConfig(bundle=bundle, pictures=False, physics_cache=physics_cache_of(args))
        )
    real = None
    if not args.no_real_takes:
        cfg = RealTakes(
            args.recordings,
            args.real_identities,
            args.real_every,
            reduced_amplitude=args.real_reduced or None,
            physics_cache=physics_cache_of(args),
        )
        real = real_takes(cfg, bundle)
    return report_entries(gallery), real


def _run_report(args: argparse.Namespace) -> int:
    from softdeca_train.controls.real_takes import one_line
    from softdeca_train.controls.report import merge_into_report, update_readme, validate_report

    controls, real = report_parts(args, args.bundle)
    doc = merge_into_report(args.report, controls, real)
    update_readme(Path(args.report).parent / "README.md", doc)
    if "real_takes" in doc:
        validate_report(doc)
        print(one_line(doc["real_takes"]))
    print(f"wrote {args.report}")
    return 0


COMMANDS = (
    Command(
        "controls",
        "controls gallery: every material control on the physics and a model bundle",
        _add,
        _run,
    ),
    Command(
        "controls-report",
        "add the controls' figures and the real takes' distances to an evaluation report",
        add_report_arguments,
        _run_report,
    ),
)
