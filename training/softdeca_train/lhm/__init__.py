"""The layered head model (paper 3.1): wraps, tet layers and S's embedding per identity.

The names below load on first use (PEP 562), so that importing a submodule that does not need
the native module (the stage's commands in lhm/cli.py, for `--help` of every step) works
without it."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from softdeca_train.lhm.checks import LhmReport, check_lhm
    from softdeca_train.lhm.fit import fit_lhm
    from softdeca_train.lhm.model import LayeredHeadModel, LhmConfig

_MODULE = {
    "LayeredHeadModel": "model",
    "LhmConfig": "model",
    "LhmReport": "checks",
    "check_lhm": "checks",
    "fit_lhm": "fit",
}
__all__ = ["LayeredHeadModel", "LhmConfig", "LhmReport", "check_lhm", "fit_lhm"]


def __getattr__(name: str) -> Any:
    if name in _MODULE:
        return getattr(importlib.import_module(f"softdeca_train.lhm.{_MODULE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
