"""The memory budget holds in resident memory (docs/security.md, "Memory budget"):
`softdeca bench-reliability --bundle` loads copies of the test bundle grown by one
constant-foldable fragment each; those just under the budget load without computing it (ONNX
Runtime's constant folding is off), those over it are refused; neither costs memory."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

from streaming_cli import CLI

BUDGET_MIB = 32
FAMILIES = {"constant_of_shape", "expand", "mul", "gather", "concat", "matmul", "shape"}


def test_bundles_cost_at_most_their_budget(tmp_path: Path) -> None:
    data = tmp_path / "data"
    subprocess.run(
        [sys.executable, "-m", "softdeca_train", "runtime-test-data", "--out", str(data)],
        check=True, capture_output=True,
    )  # fmt: skip
    out = tmp_path / "reliability.json"
    r = subprocess.run(
        [CLI, "bench-reliability", "--out", str(out), "--scratch", str(tmp_path),
         "--flood-seconds", "0.2", "--slow-seconds", "0.2", "--resync-mib", "1", "--ports", "2",
         "--bundle", str(data / "bundle"), "--bundle-budget-mib", str(BUDGET_MIB)],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    line = r"^  (\w+) +(just under|just over|large) +(loaded|refused), .*\(([0-9.]+) of"
    runs = re.findall(line, r.stderr, re.MULTILINE)
    assert {family for family, *_ in runs} == FAMILIES, r.stderr
    for family, size, outcome, ratio in runs:
        expected = "loaded" if size == "just under" else "refused"
        assert outcome == expected, (family, size, r.stderr)
        assert float(ratio) < 0.1, (family, size, ratio)
    figures = json.loads(out.read_text())
    assert figures["reliability.bundle_peak_rss_over_budget"]["value"] < 0.1
    assert figures["reliability.runtime_start_rss_mib"]["value"] > 0
