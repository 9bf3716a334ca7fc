"""Generation throughput on this machine (build/bench/datagen.json): each kind generated alone
into a temporary folder with all workers, timed end to end (planning, identity sampling, LHM
fitting, simulation, writing), and the paper's 500k-instance dataset projected from it."""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from tqdm import tqdm

from softdeca_train.bench import figure
from softdeca_train.data.config import GenerateConfig, RunSettings
from softdeca_train.data.generate import generate

PAPER_INSTANCES = 500_000  # paper 4.2.1: 500k instances, 75 % static, 25 % dynamic frames
PAPER_HOURS = 5 * 24.0  # "spanned five days" (64-core Threadripper Pro 3995WX)
PAPER_BYTES = 1e12  # "one terabyte"


def _config(kind: str, shards: int, level: int) -> GenerateConfig:
    """`shards` shards of one kind: 2 x 8 frames (static, sparse) or 1 sequence (dynamic)."""
    d = GenerateConfig()
    per = 1 if kind == "dynamic" else d.frames_per_params * d.params_per_identity
    counts = {"static": 0, "dynamic": 0, "sparse": 0}
    counts[kind] = shards * per
    return GenerateConfig(
        **counts, level=level, test_share=0.0, sequences_per_identity=1, seed=1234
    )


def bench_datagen(ict: str | None, level: int, workers: int, shards: int) -> dict:
    cores = os.cpu_count() or 1
    rates, sizes, secs = {}, {}, {}
    judged = failed = 0
    for kind in tqdm(("static", "dynamic", "sparse"), desc="datagen bench", unit="kind"):
        cfg = _config(kind, shards, level)
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            summary = generate(
                cfg, RunSettings(out=Path(tmp) / kind, workers=workers, ict=ict, progress=False)
            )
            wall = time.perf_counter() - t0
        judged += summary["frames_judged"]
        failed += summary["failures"].get("failed_frames", 0)
        k = summary["kinds"][kind]
        rates[kind] = k["instances"] * 3600 / wall
        sizes[kind] = k["bytes_per_instance"]
        secs[kind] = k["worker_seconds_per_instance"]
    d = GenerateConfig()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    how = (
        f"make bench (python -m softdeca_train bench-datagen): {shards} shards of each kind "
        f"generated alone, {workers} worker processes x 1 simulator thread, LHM level {level}, "
        f"tolerance {d.tolerance:g}, {cores} cores (1-minute load average {load:.1f} at the "
        "end, these workers included); wall clock incl. identity sampling, LHM fit, simulation "
        "and writing"
    )
    static_frames = 0.75 * PAPER_INSTANCES
    sequences = 0.25 * PAPER_INSTANCES / d.sequence_length
    hours = static_frames / rates["static"] + sequences / rates["dynamic"]
    proj = (
        f"projection: {static_frames:.0f} static frames and {sequences:.0f} sequences of "
        f"{d.sequence_length} (+{d.lead_in} lead-in) at the measured rates"
    )
    return {
        "datagen.failed_fraction": figure(
            failed / judged if judged else float("nan"),
            "share",
            how + f"; frames failing the sanity bounds (docs/physics.md) of {judged} judged",
            target=0.001,
        ),
        "datagen.instances_per_hour": figure(
            rates["static"], "1/h", how + "; static frames", better="higher"
        ),
        "datagen.instances_per_hour_dynamic": figure(
            rates["dynamic"],
            "1/h",
            how + f"; sequences of {d.sequence_length} frames after {d.lead_in} lead-in frames",
            better="higher",
        ),
        "datagen.frames_per_hour_dynamic": figure(
            rates["dynamic"] * d.sequence_length, "1/h", how, better="higher"
        ),
        "datagen.instances_per_hour_sparse": figure(
            rates["sparse"], "1/h", how + "; sparse frames", better="higher"
        ),
        "datagen.worker_seconds_per_static_instance": figure(
            secs["static"], "s", how + "; per worker process"
        ),
        "datagen.bytes_per_instance": figure(
            sizes["static"], "B", "static instance: float16 T - S (14,062 x 3) + w, p, h, ids"
        ),
        "datagen.bytes_per_instance_dynamic": figure(
            sizes["dynamic"], "B", "one sequence of 16 frames + 2 previous frames"
        ),
        "datagen.bytes_per_instance_sparse": figure(
            sizes["sparse"], "B", "sparse instance: static + 2 x 149 landmarks + donor"
        ),
        "datagen.paper_500k_hours_here": figure(
            hours, "h", f"{proj}, on this machine ({cores} cores)", target=PAPER_HOURS
        ),
        "datagen.paper_500k_hours_16_cores": figure(
            hours * cores / 16,
            "h",
            f"{proj}, scaled linearly to 16 cores (shards are independent processes; "
            "assumes no other load)",
            target=PAPER_HOURS,
        ),
        "datagen.paper_500k_gigabytes": figure(
            (static_frames * sizes["static"] + sequences * sizes["dynamic"]) / 1e9,
            "GB",
            "storage of the paper's mix at the measured bytes per instance",
            target=PAPER_BYTES / 1e9,
        ),
    }
