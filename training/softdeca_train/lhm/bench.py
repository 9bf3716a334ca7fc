"""Benchmark of the layered head model: fitting time per head at each wrap resolution,
written as build/bench/lhm.json."""

from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable

from tqdm import tqdm

from softdeca_train.bench import figure
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
