"""Benchmarks of the training-side pipeline, written as build/bench/<area>.json.

Each figure: {"value", "unit", "target" (or null), "better": "lower"|"higher", "how"}.
Timings are medians over repeated runs on this machine."""

from __future__ import annotations

import json
import os
import platform
import statistics
import time
from collections.abc import Callable
from pathlib import Path

from tqdm import tqdm

from softdeca_train.lhm import LhmConfig, fit_lhm
from softdeca_train.template import Template

PAPER_LHM_MS = 500.0  # paper 3.1.2: ~500 ms per head on a Threadripper Pro 3995WX


def _median_ms(run: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


def figure(
    value: float, unit: str, how: str, target: float | None = None, better: str = "lower"
) -> dict[str, object]:
    return {"value": round(value, 3), "unit": unit, "target": target, "better": better, "how": how}


def bench_lhm(ict: str | None, levels: tuple[int, ...] = (3, 4, 5), heads: int = 8) -> dict:
    """LHM fitting time per head at each wrap resolution (sampled identities, template warm)."""
    t0 = time.perf_counter()
    template = Template.load(ict)
    load_ms = (time.perf_counter() - t0) * 1e3
    ids = [template.sample_identity(seed) for seed in range(heads)]
    out = {
        "lhm.template_load_ms": figure(
            load_ms,
            "ms",
            "Template.load() from the warm ICT cache (first call in the process)",
            target=1000.0,
        )
    }
    default = LhmConfig().level
    for level in tqdm(levels, desc="lhm bench", unit="level"):
        cfg = LhmConfig(level=level)
        first = fit_lhm(template, None, cfg)  # builds the template's per-config caches
        per_head = [_median_ms(lambda h=h, c=cfg: fit_lhm(template, h, c), 1) for h in ids]
        how = (
            f"make bench: fit_lhm over {heads} sampled identities, median; level {level}: "
            f"{first.n_wrap} vertices per wrap, {len(first.soft_tets)} soft + "
            f"{len(first.muscle_tets)} muscle tets; {os.cpu_count()} cores"
        )
        name = "lhm.fit_ms_per_head" if level == default else f"lhm.fit_ms_per_head_level{level}"
        out[name] = figure(
            statistics.median(per_head),
            "ms",
            how,
            target=PAPER_LHM_MS if level == default else None,
        )
    return out


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
