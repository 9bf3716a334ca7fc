"""Benchmark of φ† on the real layered head model (the template identity) and real frames of
alex_rom_3: time per static frame with and without the lip/teeth collision step, per dynamic
frame, iterations, local / global share, batched frames per second over both cores. The
synthetic-head figures come from plugin/bench/bench_physics (physics.json); these go to
build/bench/physics_lhm.json."""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.bench import figure
from softdeca_train.lhm import LhmConfig
from softdeca_train.paths import default_takes_path
from softdeca_train.sim.head import HeadSimulation, build_head_simulation
from softdeca_train.sim.take import read_take
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN

DEFAULT_TAKE = default_takes_path() / "alex_rom_3.csv"


def _inputs(hs: HeadSimulation, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    blended = hs.blend(weights)
    return blended[:, :N_SKIN].astype(np.float64), hs.jaw_transforms(blended)


def _static(hs: HeadSimulation, targets: np.ndarray, jaws: np.ndarray, **settings: int) -> dict:
    sim = hs.simulator(threads=1, **settings)
    sim.solve_static(targets[0], jaw=jaws[0])  # factorise outside the timing
    wall, cpu, its, local, glob, rounds = [], [], [], [], [], []
    for t, j in zip(targets, jaws, strict=True):
        c0 = time.process_time()
        _, _, st = sim.solve_static(t, jaw=j)
        cpu.append(time.process_time() - c0)
        wall.append(st["total_seconds"])
        its.append(st["iterations"])
        local.append(st["local_seconds"] / st["total_seconds"])
        glob.append(st["global_seconds"] / st["total_seconds"])
        rounds.append(st["collision_rounds"])
    m = statistics.median
    return {
        "wall": m(wall),
        "cpu": m(cpu),
        "mean_wall": float(np.mean(wall)),
        "iterations": m(its),
        "local": m(local),
        "global": m(glob),
        "with_contacts": int(np.count_nonzero(rounds)),
    }


def _dynamic(hs: HeadSimulation, targets: np.ndarray, jaws: np.ndarray) -> tuple[float, float]:
    sim = hs.simulator(threads=1)
    sim.set_parameter("dyn_gamma", 0.5)
    sim.set_parameter("dyn_beta", 0.5)
    sim.reset_dynamics()
    sim.step_dynamic(targets[0], jaw=jaws[0])  # the static start
    wall, its = [], []
    for t, j in zip(targets[1:], jaws[1:], strict=True):
        _, _, st = sim.step_dynamic(t, jaw=j)
        wall.append(st["total_seconds"])
        its.append(st["iterations"])
    return statistics.median(wall), statistics.median(its)


def _batched(hs: HeadSimulation, targets: np.ndarray, jaws: np.ndarray, threads: int) -> float:
    sim = hs.simulator(threads=threads)
    sim.solve_static(targets[0], jaw=jaws[0])
    t0 = time.perf_counter()
    sim.solve_static_batch(targets, jaw=jaws)
    return len(targets) / (time.perf_counter() - t0)


def bench_physics_lhm(
    ict: str | None, take: Path, levels: tuple[int, ...] = (3, 4), stride: int = 400
) -> dict:
    template = Template.load(ict)
    static_w = read_take(take, stride=stride).weights
    dynamic_w = read_take(take, start=1000, frames=8).weights
    cores = os.cpu_count() or 1
    out: dict[str, dict] = {}
    for level in tqdm(levels, desc="physics bench", unit="level"):
        hs = build_head_simulation(template, None, LhmConfig(level=level))
        tets = len(hs.mesh.soft_tets) + len(hs.mesh.muscle_tets)
        base = (
            f"python -m softdeca_train bench-physics: template LHM level {level} ({tets} tets: "
            f"{len(hs.mesh.soft_tets)} soft + {len(hs.mesh.muscle_tets)} muscle, "
            f"{hs.mesh.vertex_count} simulated vertices, S {hs.mesh.skin_count} points), "
            f"default parameters"
        )
        targets, jaws = _inputs(hs, static_w)
        on = _static(hs, targets, jaws)
        off = _static(hs, targets, jaws, collision_rounds=0)
        dt, dit = _dynamic(hs, *_inputs(hs, dynamic_w))
        fps = _batched(hs, targets, jaws, cores)
        frames = f"{len(targets)} frames of {take.name} (every {stride}th), 1 thread, median"
        k = f".lhm_level{level}"
        out |= {
            f"physics.static_frame_s{k}": figure(
                on["wall"],
                "s",
                f"{base}; {frames}, from rest, with collisions "
                f"({on['with_contacts']} frames needed contact rounds; "
                f"mean {on['mean_wall']:.3f} s)",
                target=1.0,
            ),
            f"physics.static_frame_cpu_s{k}": figure(on["cpu"], "CPU s", f"{base}; {frames}"),
            f"physics.static_frame_no_collisions_s{k}": figure(
                off["wall"], "s", f"{base}; {frames}, volumetric solve only"
            ),
            f"physics.static_iterations{k}": figure(on["iterations"], "iterations", base),
            f"physics.local_step_share{k}": figure(
                off["local"], "fraction of frame time", f"{base}; volumetric solve only"
            ),
            f"physics.global_step_share{k}": figure(
                off["global"], "fraction of frame time", f"{base}; volumetric solve only"
            ),
            f"physics.dynamic_frame_s{k}": figure(
                dt,
                "s",
                f"{base}; 7 consecutive dynamic frames from frame 1001 of {take.name} "
                f"(gamma 0.5, beta 0.5; {dit:.0f} iterations median), 1 thread",
            ),
            f"physics.batched_frames_per_s{k}": figure(
                fps,
                "frames/s",
                f"{base}; solve_static_batch of the {len(targets)} static frames "
                f"on {cores} threads",
                better="higher",
            ),
            f"physics.tets{k}": figure(tets, "tets", base, better="higher"),
        }
    return out
