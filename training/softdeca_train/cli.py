"""Command line of the training pipeline: one sub-command per step, each with --help."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence

# Steps register themselves here: name -> (help, add_arguments, run).
Step = tuple[str, Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], int]]


def _steps() -> dict[str, Step]:
    from softdeca_train import steps

    return steps.STEPS


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m softdeca_train",
        description="SoftDECA training pipeline: template, layered head model, data, networks.",
    )
    sub = parser.add_subparsers(dest="step", metavar="<step>", required=True)
    steps = _steps()
    for name, (help_text, add_args, _) in steps.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        add_args(p)
    args = parser.parse_args(argv)
    try:
        return steps[args.step][2](args)
    except (FileNotFoundError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
