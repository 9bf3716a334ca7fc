"""The template stage's command: `template` (load ICT-FaceKit, summarise it)."""

from __future__ import annotations

import argparse

from softdeca_train.commands import Command, add_ict_argument


def run_template(args: argparse.Namespace) -> int:
    from softdeca_train.template import Template

    t = Template.load(args.ict)
    print(
        f"template: {t.n_vertices} vertices, {len(t.triangles)} triangles, "
        f"S: {len(t.skin_triangles)} triangles; {len(t.expression_names)} expressions, "
        f"{t.identity_modes.shape[0]} identity modes; ICT '{t.left_suffix}' = subject's left"
    )
    return 0


COMMANDS = [
    Command(
        "template",
        "Load ICT-FaceKit into the cache and summarise the template.",
        add_ict_argument,
        run_template,
    ),
]
