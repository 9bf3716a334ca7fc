"""`python -m softdeca_train generate`: plan the dataset, simulate the missing shards in
parallel, write each atomically and list it in the manifest, and keep the manifest's
description (counts, splits, parameters, sizes, throughput, code version) up to date."""

from __future__ import annotations

import hashlib
import json
import signal
import subprocess
import threading
import time
from collections.abc import Iterator
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.data import executors
from softdeca_train.data.config import KINDS, TEST, GenerateConfig, RunSettings
from softdeca_train.data.expressions import Take, expression_sources, load_takes
from softdeca_train.data.format import describe, shard_meta
from softdeca_train.data.plan import FIXED, ShardSpec, make_plan
from softdeca_train.data.ranges import fixed_outside_profile, sampling_parameters
from softdeca_train.data.shards import Manifest, write_shard
from softdeca_train.parameters import DEFINITION, load_parameters
from softdeca_train.paths import REPO_ROOT
from softdeca_train.template.model import N_SKIN


def code_version() -> str:
    try:
        r = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--tags"],
            cwd=REPO_ROOT,
            capture_output=True,
            text=True,
            check=True,
        )
        return r.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def make_header(cfg: GenerateConfig, takes: list[Take]) -> dict:
    """Everything that fixes the data: a resume must match it exactly."""
    return {
        "config": cfg.as_dict(),
        "takes": [
            {"index": i, "name": t.name, "sha256": t.sha256, "frames": len(t.weights)}
            for i, t in enumerate(takes)
        ],
        "parameters_sha256": hashlib.sha256(DEFINITION.read_bytes()).hexdigest(),
        "n_skin": N_SKIN,
    }


def _digest(header: dict) -> str:
    return hashlib.sha256(json.dumps(header, sort_keys=True).encode()).hexdigest()[:16]


def describe_plan(cfg: GenerateConfig, plan: list[ShardSpec], takes: list[Take]) -> dict:
    """The dataset as planned: counts, splits (identities, parameter sets, expression
    sources) and the parameter definition, written before anything is simulated."""
    params = sampling_parameters(load_parameters(), cfg.ranges)
    per_kind: dict[str, dict] = {}
    splits: dict[str, dict] = {
        s: {"identities": [], "parameter_sets": 0, "takes": [], "coverage_draws": 0}
        for s in ("train", "test")
    }
    for kind in KINDS:
        shards = [s for s in plan if s.kind == kind]
        k = {"shards": len(shards), "instances": {"train": 0, "test": 0}, "frames_per_instance": 1}
        if kind == "dynamic":
            k["frames_per_instance"] = cfg.sequence_length
            k["lead_in_frames"] = cfg.lead_in
        for s in shards:
            name = "test" if s.split == TEST else "train"
            k["instances"][name] += s.instances
            splits[name]["identities"].append(s.identity_id)
            for g in s.groups:
                splits[name]["parameter_sets"] += 1
                if g.donor_id >= 0:
                    splits[name]["identities"].append(g.donor_id)
                splits[name]["coverage_draws"] += int((g.frames.source_take < 0).sum())
        k["arrays"] = describe(kind)
        k["fixed_parameters"] = [*FIXED[kind], *fixed_outside_profile(params, cfg.ranges)]
        if kind != "dynamic":
            k["regional_patterns"] = sum(g.p_regions is not None for s in shards for g in s.groups)
        per_kind[kind] = k
    splits["train"]["takes"] = [t.name for t in takes if t.name not in cfg.test_takes]
    splits["test"]["takes"] = list(cfg.test_takes)
    return {
        "kinds": per_kind,
        "splits": splits,
        "parameters": [
            {
                "name": s.name,
                "lo": s.minimum,
                "hi": s.maximum,
                "default": s.default_value,
                "scale": s.scale,
            }
            for s in params.specs
        ],
        "expressions": {
            "real_share": cfg.real_share,
            "real_reduced_share": cfg.real_reduced_share,
            "coverage": "CoverageSampler fitted to the train takes (data/coverage.py)",
            "source": "source_take = take index (header.takes) and source_index = frame, "
            "or source_take = -1 and source_index = coverage draw of that split",
        },
        "sparse_augmentation": {
            "personalisation": "L_0 + s R (L'_t - L'_0), (s, R) Umeyama from the donor's "
            "neutral landmarks to the simulated head's (data/personalise.py)",
            "noise_sigma_mm": cfg.landmark_noise_mm,
        },
        "lhm_level": cfg.level,
        "collisions": cfg.collisions,
        "range_profile": cfg.ranges,
    }


def _prepare(cfg: GenerateConfig, run: RunSettings) -> tuple[Manifest, list[ShardSpec], dict]:
    out = Path(run.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{out} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not (out / "manifest.json").is_file():
        raise ValueError(f"{out} is not empty and holds no dataset manifest: use a new folder")
    takes = load_takes(run.takes)
    sources, _ = expression_sources(takes, cfg.test_takes, cfg.seed, cfg.test_share)
    plan = make_plan(cfg, sampling_parameters(load_parameters(), cfg.ranges), sources)
    out.mkdir(parents=True, exist_ok=True)
    header = make_header(cfg, takes)
    m = Manifest.open(out, header)
    m.doc["dataset"] = describe_plan(cfg, plan, takes)
    m.doc.setdefault("runs", [])
    m.save()
    return m, plan, header


def _results(
    todo: list[ShardSpec], cfg: GenerateConfig, run: RunSettings
) -> Iterator[executors.Result]:
    if run.ray_address:
        return executors.run_ray(todo, cfg, run.ict, run.threads, run.ray_address, run.workers)
    if run.workers <= 0:
        return executors.run_inline(todo, cfg, run.ict, run.threads)
    return executors.run_processes(todo, cfg, run.ict, run.threads, run.workers)


def summarise(doc: dict) -> dict:
    """Totals from a manifest's listed (finished) shards: what a run ended with, and what a
    report of a dataset still being made (or killed mid-run) shows."""
    shards = doc["shards"]
    out: dict = {"complete": False, "kinds": {}}
    planned = doc["dataset"]["kinds"]
    for kind in KINDS:
        ss = [s for s in shards if s["kind"] == kind]
        n = sum(s["instances"] for s in ss)
        # a shard is one split's (data/plan.py)
        n_test = sum(s["instances"] for s in ss if s.get("split") == TEST)
        nbytes = sum(s["bytes"] for s in ss)
        secs = sum(s.get("seconds", 0.0) for s in ss)
        out["kinds"][kind] = {
            "shards": len(ss),
            "instances": n,
            "train": n - n_test,
            "test": n_test,
            "bytes": nbytes,
            "bytes_per_instance": round(nbytes / n) if n else None,
            "worker_seconds_per_instance": round(secs / n, 3) if n else None,
            "frames_solved": sum(s.get("frames_solved", 0) for s in ss),
        }
    out["complete"] = all(out["kinds"][k]["shards"] == planned[k]["shards"] for k in KINDS)
    errs = [s["max_quantisation_error_m"] for s in shards if "max_quantisation_error_m" in s]
    mags = [s["max_offset_m"] for s in shards if "max_offset_m" in s]
    out["max_quantisation_error_mm"] = round(max(errs) * 1e3, 6) if errs else None
    sq = sum(s.get("quantisation_sq_sum_m2", 0.0) for s in shards)
    nq = sum(s.get("quantisation_values", 0) for s in shards)
    out["rms_quantisation_error_mm"] = float(f"{np.sqrt(sq / nq) * 1e3:.3g}") if nq else None
    out["max_offset_mm"] = round(max(mags) * 1e3, 3) if mags else None
    out["bytes"] = sum(s["bytes"] for s in shards)
    # The sanity bounds (docs/physics.md): frames failing each, over the judged frames.
    judged = sum(s.get("frames_judged", 0) for s in shards)
    failures: dict[str, int] = {}
    for s in shards:
        for reason, count in s.get("failures", {}).items():
            failures[reason] = failures.get(reason, 0) + count
    out["frames_judged"] = judged
    out["failures"] = failures
    # Where the heads' tets came from (lhm/carried.py): "carried", or why a head got a fill.
    sources: dict[str, int] = {}
    for s in shards:
        key = s.get("tet_source", "unrecorded")
        sources[key] = sources.get(key, 0) + 1
    out["tet_sources"] = dict(sorted(sources.items()))
    out["failed_fraction"] = round(failures.get("failed_frames", 0) / judged, 6) if judged else None
    return out


def _terminate(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def _frames(spec: ShardSpec) -> int:
    return sum(len(g.frames.weights) for g in spec.groups)


def made_first(todo: list[ShardSpec], first: tuple[str, ...]) -> list[ShardSpec]:
    """The shards of the kinds in `first` (in that order) before the rest, each kind's
    shards in plan order."""
    return sorted(todo, key=lambda s: first.index(s.kind) if s.kind in first else len(first))


def generate(cfg: GenerateConfig, run: RunSettings) -> dict:
    """Generate (or resume) the dataset in run.out; returns the manifest's summary."""
    m, plan, header = _prepare(cfg, run)
    digest = _digest(header)
    done = {k: m.done(k) for k in KINDS}
    todo = [s for s in plan if s.index not in done[s.kind]]
    todo = made_first(todo, run.first)
    # Progress in solved frames: a dynamic instance costs lead-in + sequence frames.
    total = sum(_frames(s) for s in plan)
    started = time.time()
    record = {
        "code_version": code_version(),
        "started": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "executor": f"ray:{run.ray_address}" if run.ray_address else "processes",
        "workers": run.workers,
        "threads_per_worker": run.threads,
        "shards": 0,
        "instances": {k: 0 for k in KINDS},
        "wall_seconds": 0.0,
    }
    m.doc["runs"].append(record)
    # SIGTERM ends the run like Ctrl-C: the finally below still records its wall time.
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if main else None
    bar = tqdm(
        total=total,
        initial=total - sum(_frames(s) for s in todo),
        unit="frame",
        desc=f"generate {Path(run.out).name}",
        disable=not run.progress,
        smoothing=0.1,
    )
    try:
        for spec, arrays, info in _results(todo, cfg, run):
            arrays["meta"] = np.array(shard_meta(spec.kind, spec.split, digest))
            entry = write_shard(Path(run.out), spec.kind, spec.index, arrays)
            entry.update(info)
            record["shards"] += 1
            record["instances"][spec.kind] += spec.instances
            record["wall_seconds"] = round(time.time() - started, 2)
            m.add(entry)  # saves the manifest: the shard counts from here on
            bar.update(_frames(spec))
    finally:
        if main:
            signal.signal(signal.SIGTERM, previous)
        bar.close()
        record["wall_seconds"] = round(time.time() - started, 2)
        n = sum(record["instances"].values())
        record["instances_per_hour"] = round(n * 3600 / record["wall_seconds"]) if n else 0
        m.doc["summary"] = summarise(m.doc)
        m.save()
    return m.doc["summary"]
