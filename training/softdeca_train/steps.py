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


STEPS = {
    "template": (
        "Load ICT-FaceKit into the cache and summarise the template.",
        _template_args,
        _template_run,
    ),
}
