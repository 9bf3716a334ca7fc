"""Command line of the controls gallery."""

from __future__ import annotations

import argparse
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument


def _add(p: argparse.ArgumentParser) -> None:
    from softdeca_train.controls.definitions import REGION_PARAMETERS
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
        takes=args.takes or default_takes_path(),
        ict=args.ict,
    )
    result = run_gallery(cfg)
    path = write_gallery(cfg, result)
    for e in result["controls"]:
        err = e["response_error"]
        leak = e["leakage"]
        print(
            f"{e['name']:28s} physics max {e['physics_max_mm']:8.3f} mm  "
            f"response error {'–' if err is None else f'{err:.2f}':>5s}  "
            f"leakage {'–' if leak is None else f'{leak:.2f}'}"
        )
    print(f"wrote {path} ({result['seconds']:.0f} s)")
    return 0


COMMANDS = (
    Command(
        "controls",
        "controls gallery: every material control on the physics and a model bundle",
        _add,
        _run,
    ),
)
