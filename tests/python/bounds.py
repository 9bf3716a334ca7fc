"""Numerical bounds of the tests, each with the reason it has the value it has.

A bound on a result of an iterative solve, a training run or a floating-point sum is checked with
`below` or `above` instead of a bare assert: the check is the same, and the measured value, the
bound and the margin between them (relative to the value) are recorded. The test session prints
the bounds whose margin is under 25 % and writes every one to $SOFTDECA_BOUNDS_REPORT (JSON), so
that a run on another CPU's kernels (tests/cpu/run-as.sh, `make test-kernels`) shows how close
each bound came. A bound within 10 % of its value holds only by luck on another machine; its
reason must then say why it has to be tight (`tight=True`).
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass

# Under this margin a bound is listed in the session's summary; under TIGHT it is flagged.
LISTED = 0.25
TIGHT = 0.10


@dataclass(frozen=True)
class Bound:
    test: str
    what: str
    value: float
    limit: float
    upper: bool  # value must stay below the limit (else above it)
    reason: str
    tight: bool

    @property
    def margin(self) -> float:
        """How far the limit lies from the value, relative to the value: 0.25 is 25 %."""
        gap = self.limit - self.value if self.upper else self.value - self.limit
        scale = abs(self.value)
        return math.inf if scale == 0 and gap > 0 else gap / scale if scale else 0.0


RECORDED: list[Bound] = []


def _record(
    value: float, limit: float, upper: bool, reason: str, what: str, tight: bool
) -> None:
    value = float(value)
    test = os.environ.get("PYTEST_CURRENT_TEST", "?").split(" ")[0]
    b = Bound(test, what, value, float(limit), upper, reason, tight)
    RECORDED.append(b)
    sign = "<" if upper else ">"
    ok = value < limit if upper else value > limit
    assert ok, f"{what or 'value'} = {value:.6g}, must be {sign} {limit:.6g} ({reason})"


def below(
    value: float, limit: float, reason: str, *, what: str = "", tight: bool = False
) -> None:
    """Asserts value < limit; `reason` says which tolerance or measurement the limit comes from."""
    _record(value, limit, True, reason, what, tight)


def above(
    value: float, limit: float, reason: str, *, what: str = "", tight: bool = False
) -> None:
    """Asserts value > limit; `reason` as for `below`."""
    _record(value, limit, False, reason, what, tight)


def report() -> list[dict]:
    return [{**asdict(b), "margin": b.margin} for b in RECORDED]


def summary_lines() -> list[str]:
    """The bounds of this session whose margin is under LISTED, closest first."""
    close = sorted((b for b in RECORDED if b.margin < LISTED), key=lambda b: b.margin)
    lines = [
        f"{len(RECORDED)} numerical bounds checked; {len(close)} with a margin under {LISTED:.0%}"
    ]
    for b in close:
        flag = "tight by design" if b.tight else "TIGHT" if b.margin < TIGHT else ""
        sign = "<" if b.upper else ">"
        lines.append(
            f"  {b.margin:7.1%}  {b.value:.4g} {sign} {b.limit:.4g}  {b.test} {b.what}  {flag}".rstrip()
        )
    return lines
