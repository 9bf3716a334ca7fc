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


def _landmarks_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument(
        "--arkit",
        default=None,
        help="folder with ARKit_reference_blendshapes.zip and ARKit_landmarks68.txt "
        "(default: $SOFTDECA_ARKIT_REFERENCE or ../shared/arkit-reference)",
    )
    p.add_argument(
        "--out",
        default="out/landmarks",
        help="folder for registration.png and landmarks_report.{json,md}",
    )
    p.add_argument(
        "--write-definition",
        action="store_true",
        help="regenerate the committed landmark definition (definition.json) from "
        "its rules before registering",
    )


def _landmarks_run(args: argparse.Namespace) -> int:
    from softdeca_train.landmarks.cli import run

    return run(args.ict, args.arkit, args.out, args.write_definition)


STEPS = {
    "template": (
        "Load ICT-FaceKit into the cache and summarise the template.",
        _template_args,
        _template_run,
    ),
    "landmarks": (
        "Register ARKit's reference face to the template, embed the ~150 landmarks "
        "on S, and write a render and a residual report.",
        _landmarks_args,
        _landmarks_run,
    ),
}
