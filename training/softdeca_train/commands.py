"""How a pipeline stage declares its command lines for `python -m softdeca_train`.

Every stage's `cli` module lists its commands in `COMMANDS`; the dispatcher (softdeca_train.cli)
builds one sub-command per entry. A command's `run` imports what it needs itself, so that
`--help` stays fast and a command only pays for the modules it uses."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Command:
    name: str
    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


def add_tet_mesh_argument(p: argparse.ArgumentParser) -> None:
    """The simulation's tets (LhmConfig.tet_mesh), for commands that build heads."""
    p.add_argument(
        "--tet-mesh",
        choices=("carried", "conforming", "prisms"),
        default="carried",
        help="the heads' tets: the template's fill carried to each head (default), each "
        "head's own fill, or the wraps' prisms (docs/physics.md)",
    )


def add_ict_argument(p: argparse.ArgumentParser) -> None:
    """The ICT-FaceKit location option every template-based command shares."""
    p.add_argument(
        "--ict",
        default=None,
        help="ICT-FaceKit checkout, FaceXModel folder or .tar.xz archive "
        "(default: $SOFTDECA_ICT or ict-facekit in the data folder)",
    )
