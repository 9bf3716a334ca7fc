"""Command line of the training pipeline: one sub-command per step, each with --help.

The commands live with their pipeline stage, each stage's `cli` module listing them in
`COMMANDS` (see softdeca_train.commands); STAGES gives the order `--help` shows them in."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from softdeca_train.commands import Command

STAGES = (
    "softdeca_train.template.cli",
    "softdeca_train.lhm.cli",
    "softdeca_train.landmarks.cli",
    "softdeca_train.sim.cli",
    "softdeca_train.data.cli",
    "softdeca_train.train.cli",
    "softdeca_train.controls.cli",
    "softdeca_train.host.cli",
    "softdeca_train.sample_avatars.cli",
    "softdeca_train.streaming.cli",
)


def commands() -> dict[str, Command]:
    out: dict[str, Command] = {}
    for stage in STAGES:
        for c in importlib.import_module(stage).COMMANDS:
            if c.name in out:
                raise RuntimeError(f"command {c.name} is registered twice ({stage})")
            out[c.name] = c
    return out


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m softdeca_train",
        description="SoftDECA training pipeline: template, layered head model, data, networks.",
    )
    sub = parser.add_subparsers(dest="step", metavar="<step>", required=True)
    table = commands()
    for c in table.values():
        c.add_arguments(sub.add_parser(c.name, help=c.help, description=c.help))
    args = parser.parse_args(argv)
    try:
        return table[args.step].run(args)
    except (FileNotFoundError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
