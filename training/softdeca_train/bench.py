"""Benchmarks of the training-side pipeline, written as build/bench/<area>.json.

Each figure: {"value", "unit", "target" (or null), "better": "lower"|"higher", "how"}.
Timings are medians over repeated runs on this machine."""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path


def figure(
    value: float, unit: str, how: str, target: float | None = None, better: str = "lower"
) -> dict[str, object]:
    return {"value": round(value, 3), "unit": unit, "target": target, "better": better, "how": how}


def write_area(out_dir: Path, area: str, figures: dict) -> Path:
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{area}.json"
    path.write_text(json.dumps(figures, indent=2) + "\n")
    return path


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()}"


def report_area(out_dir: Path, area: str, figures: dict) -> Path:
    """Write <area>.json and print its figures with the machine."""
    path = write_area(out_dir, area, figures)
    print(f"machine: {machine()}")
    for name, f in figures.items():
        print(f"  {name:44s} {f['value']:>10.3f} {f['unit']:4s} (target {f['target']})")
    print(f"wrote {path}")
    return path
