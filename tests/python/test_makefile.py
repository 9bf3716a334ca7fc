"""The Makefile: every target defined once and listed by `make help` with what it does."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
# a rule line, not a variable (`X :=`) nor a target-specific variable (`target: X := value`)
RULE = re.compile(
    r"^([a-zA-Z][a-zA-Z0-9_-]*):(?!=)(?!\s*[A-Za-z_][A-Za-z0-9_]*\s*[:+?]?=)"
)


def rule_targets() -> list[str]:
    return [
        m.group(1)
        for line in (REPO / "Makefile").read_text().splitlines()
        if (m := RULE.match(line))
    ]


def test_every_target_is_defined_once_and_described_by_help() -> None:
    targets = rule_targets()
    assert len(targets) > 10
    assert sorted(targets) == sorted(set(targets)), (
        "a target has more than one rule line"
    )
    out = subprocess.run(
        ["make", "--no-print-directory", "-C", str(REPO), "help"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "overriding recipe" not in out.stderr
    described = {
        line.split()[0] for line in out.stdout.splitlines() if line.startswith("  ")
    }
    assert "more targets:" not in out.stdout, "a target lacks its ## description"
    assert set(targets) <= described
