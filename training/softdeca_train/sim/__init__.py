"""φ† on real heads: the layered head model turned into the native simulator's mesh, and
frames (ARKit weights, takes) turned into its inputs.

The names below load on first use (PEP 562), so that importing a submodule that does not need
the native module (the `simulate` step's arguments, for `--help` of every step) works without
it."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from softdeca_train.sim.head import HeadSimulation, build_head_simulation

__all__ = ["HeadSimulation", "build_head_simulation"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from softdeca_train.sim import head  # needs the native module: loaded on first use

        return getattr(head, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
