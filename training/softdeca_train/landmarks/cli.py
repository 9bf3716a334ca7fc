"""The `landmarks` step: definition check, registration, report, render."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument


def run(ict: str | None, arkit_path: str | None, out: str, rewrite: bool) -> int:
    from softdeca_train.landmarks.arkit_reference import ArkitFace
    from softdeca_train.landmarks.definition import (
        DEFINITION_PATH,
        generate_definition,
        load_definition,
        write_definition,
    )
    from softdeca_train.landmarks.figure import render_registration_of
    from softdeca_train.landmarks.pipeline import register_arkit_to_template
    from softdeca_train.landmarks.report import build_report, check_bounds, write_report
    from softdeca_train.template import Template

    template = Template.load(ict)
    arkit = ArkitFace.load(arkit_path)
    generated = generate_definition(arkit)
    if rewrite:
        print(f"wrote {write_definition(generated)}")
    definition = load_definition()
    if generated.to_json() != definition.to_json():
        print(
            f"warning: {DEFINITION_PATH} differs from what its rules give on this ARKit face; "
            "rerun with --write-definition if the rules changed",
            file=sys.stderr,
        )
    r = register_arkit_to_template(template, arkit, definition)
    report = build_report(r)
    json_path, md_path = write_report(report, out)
    png = render_registration_of(r, out, report)
    s, nr = report["similarity"], report["nonrigid"]
    print(
        f"{len(definition)} landmarks; 68-pair residual (interior 17-67): similarity "
        f"{s['residual_interior_51']['mean']:.2f} mm mean / {s['residual_interior_51']['max']:.2f}"
        f" max; non-rigid constrained {nr['residual_constrained']['mean']:.2f} / "
        f"{nr['residual_constrained']['max']:.2f}, left out "
        f"{nr['residual_constrained_held_out']['mean']:.2f} mm mean; landmarks to S max "
        f"{report['landmarks']['to_S']['max']:.3f} mm ({r.seconds:.1f} s)"
    )
    for p in (png, json_path, md_path):
        print(f"  {Path(p)}")
    violations = check_bounds(report)
    for v in violations:
        print(f"error: registration outside its bounds: {v}", file=sys.stderr)
    return 1 if violations else 0


def add_landmarks_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument(
        "--arkit",
        default=None,
        help="folder with ARKit_reference_blendshapes.zip and ARKit_landmarks68.txt "
        "(default: $SOFTDECA_ARKIT_REFERENCE or arkit-reference in the data folder)",
    )
    p.add_argument(
        "--out",
        default="out/landmarks",
        help="folder for registration.png and landmarks_report.{json,md}",
    )
    p.add_argument(
        "--write-definition",
        action="store_true",
        help="regenerate the committed landmark definition (plugin/data/landmarks.json) from "
        "its rules before registering",
    )


def run_landmarks(args: argparse.Namespace) -> int:
    return run(args.ict, args.arkit, args.out, args.write_definition)


COMMANDS = [
    Command(
        "landmarks",
        "Register ARKit's reference face to the template, embed the ~150 landmarks "
        "on S, and write a render and a residual report.",
        add_landmarks_args,
        run_landmarks,
    ),
]
