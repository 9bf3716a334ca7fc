"""The physics stress suite: extreme expressions, extreme identities, material parameters at
the ends of their ranges, strong gravity, two resolutions, static and dynamic, plus real takes,
every frame judged by the sanity bounds of sanity.py. `make stress` runs it in full
(`python -m softdeca_train stress`); the tests run a reduced plan."""

from __future__ import annotations

import heapq
import json
import math
import multiprocessing
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from softdeca_train.lhm import LhmConfig
from softdeca_train.parameters import load_parameters
from softdeca_train.sim.expressions import all_expressions, combinations
from softdeca_train.sim.figure import render_rows
from softdeca_train.sim.head import HeadSimulation, build_head_simulation
from softdeca_train.sim.measures import SoftVolume
from softdeca_train.sim.sanity import FrameCheck, bench_figures, check_frame, failure_counts
from softdeca_train.sim.take import read_take
from softdeca_train.template import Template
from softdeca_train.template.identities import identity_coefficients
from softdeca_train.template.model import N_SKIN

# The material controls put at the ends of their control ranges together (the ranges a user
# moves them in and data generation samples, plugin/data/parameters.json): "soft" is every
# tissue weight at the bottom with the targets' weight at the top (the targets' strongest
# pull on the weakest tissue), "stiff" the other way round; "thin" and "full" the soft
# tissue's requested volume and strain limit at their bottom and top.
MATERIAL_WEIGHTS = (
    "w_soft_volume",
    "w_soft_strain",
    "w_muscle_volume",
    "w_muscle_strain",
    "w_skin_strain",
)
TISSUE_SHAPE = ("target_volume", "max_strain")
# Gravity 2 g: (tilt, azimuth) in degrees from -Y (down) - forward (+Z, face down), sideways, up.
GRAVITY_DIRECTIONS = {
    "down": (0.0, 0.0),
    "forward": (90.0, 90.0),
    "side": (90.0, 0.0),
    "up": (180.0, 0.0),
}
# The dynamic run: each combination held for HOLD frames, judged on the last (the others are
# transients of eq. 9 towards it); γ 0.7, β 0.3 settle to within 5 % in 5 frames.
DYNAMIC_PARAMETERS = {"dyn_gamma": 0.7, "dyn_beta": 0.3}
HOLD = 6


@dataclass(frozen=True)
class StressCase:
    group: str
    identity: str  # "template", "seed N", "h+2.5σ", "h-2.5σ"
    level: int
    frames: list[tuple[str, np.ndarray]]  # (label, (52,) ARKit weights)
    parameters: dict[str, float] = field(default_factory=dict)
    dynamic: bool = False
    judge_every: int = 1  # judge frames judge_every-1, 2*judge_every-1, ...
    tet_mesh: str = "carried"  # LhmConfig.tet_mesh of its head


@dataclass(frozen=True)
class StressPlan:
    identities: tuple[str, ...] = ("template", "seed 1", "seed 2", "h+2.5σ", "h-2.5σ")
    level: int = 3
    fine_level: int | None = 4  # every expression once more at this level (template); None: off
    tet_mesh: str = "carried"  # LhmConfig.tet_mesh of every head
    materials: bool = True
    gravity: bool = True
    dynamic: bool = True
    takes: tuple[Path, ...] = ()
    take_stride: int = 10
    take_identities: int = 3
    combinations_only: bool = False  # the combinations without the single shapes
    # extra material cases, e.g. ({"w_soft_volume": 3.0},): the combinations on the first
    # identity with those values (what a wider control range would ask of the physics)
    extra_materials: tuple[dict[str, float], ...] = ()


def material_ends() -> dict[str, dict[str, float]]:
    ranges = {s.name: s.control for s in load_parameters().specs if s.control is not None}
    # a weight that is no control stays at its default, as in the data
    weights = [n for n in MATERIAL_WEIGHTS if n in ranges]
    lo = {n: ranges[n][0] for n in (*weights, "w_target", *TISSUE_SHAPE)}
    hi = {n: ranges[n][1] for n in (*weights, "w_target", *TISSUE_SHAPE)}
    return {
        "soft": {**{n: lo[n] for n in weights}, "w_target": hi["w_target"]},
        "stiff": {**{n: hi[n] for n in weights}, "w_target": lo["w_target"]},
        "thin": {n: lo[n] for n in TISSUE_SHAPE},
        "full": {n: hi[n] for n in TISSUE_SHAPE},
    }


def parse_material(text: str) -> dict[str, float]:
    """'NAME=VALUE[,NAME=VALUE...]' -> values, each a parameter of plugin/data/parameters.json
    within the range the physics accepts."""
    out: dict[str, float] = {}
    for item in filter(None, (t.strip() for t in text.split(","))):
        name, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"material {item!r}: expected NAME=VALUE")
        try:
            out[name] = float(value)
        except ValueError:
            raise ValueError(f"material {item!r}: {value!r} is not a number") from None
    if not out:
        raise ValueError(f"material {text!r}: no NAME=VALUE")
    load_parameters().check_values(out)
    return out


def build_cases(plan: StressPlan) -> list[StressCase]:
    combos = list(combinations().items())
    exprs = combos if plan.combinations_only else list(all_expressions().items())
    cases = [StressCase("expressions", who, plan.level, exprs) for who in plan.identities]
    first = plan.identities[0]
    if plan.fine_level is not None:
        cases.append(StressCase(f"level {plan.fine_level}", first, plan.fine_level, exprs))
    if plan.materials:
        for name, values in material_ends().items():
            cases.append(StressCase(f"materials {name}", first, plan.level, combos, values))
    for values in plan.extra_materials:
        label = ",".join(f"{k}={v:g}" for k, v in values.items())
        cases.append(StressCase(f"materials {label}", first, plan.level, combos, values))
    if plan.gravity:
        for name, (tilt, azimuth) in GRAVITY_DIRECTIONS.items():
            g = {"gravity_strength": 2.0, "gravity_tilt": tilt, "gravity_azimuth": azimuth}
            cases.append(StressCase(f"gravity 2 g {name}", first, plan.level, combos, g))
    if plan.dynamic:
        held = [(label, w) for label, w in combos for _ in range(HOLD)]
        cases.append(StressCase("dynamic", first, plan.level, held, DYNAMIC_PARAMETERS, True, HOLD))
    for take in plan.takes:
        t = read_take(take, stride=plan.take_stride)
        frames = [(f"frame {int(i)}", w) for i, w in zip(t.frames, t.weights, strict=True)]
        for who in plan.identities[: plan.take_identities]:
            cases.append(StressCase(f"take {take.stem}", who, plan.level, frames))
    # One head simulation at a time: group the cases by (identity, level).
    cases = [replace(c, tet_mesh=plan.tet_mesh) for c in cases]
    return sorted(cases, key=lambda c: (c.identity, c.level))


@dataclass
class StressFrame:
    group: str
    identity: str
    level: int
    label: str
    check: FrameCheck

    def as_dict(self) -> dict[str, Any]:
        return {
            "group": self.group,
            "identity": self.identity,
            "level": self.level,
            "frame": self.label,
        } | self.check.as_dict()


@dataclass
class WorstFrame:
    """A frame kept for the contact sheet: its whole heads."""

    title: str
    neutral: np.ndarray
    linear: np.ndarray
    physics: np.ndarray
    score: float = 0.0  # _severity: the contact sheet shows the highest first


@dataclass
class StressResult:
    frames: list[StressFrame] = field(default_factory=list)
    worst: list[WorstFrame] = field(default_factory=list)
    seconds: float = 0.0


def _severity(c: FrameCheck) -> float:
    """Order of the contact sheet: failing frames first, then by displacement beyond the bound."""
    return (1e6 if c.failures() else 0.0) + c.max_displacement_mm - c.explained_mm


def _frames(sim: Any, hs: HeadSimulation, case: StressCase) -> Iterator[tuple[int, Any]]:
    """Per frame (linear blend, jaw, the S a frame is judged against, the solve's result):
    a dynamic frame is judged against its step's blended target (eq. 9)."""
    if case.dynamic:
        sim.reset_dynamics()
    for i, (_, w) in enumerate(case.frames):
        blended = hs.blend(w[None])[0]
        jaw = hs.jaw_transforms(blended[None])[0]
        target = blended[:N_SKIN].astype(np.float64)
        solve = sim.step_dynamic if case.dynamic else sim.solve_static
        judged = sim.dynamic_target(target) if case.dynamic else target
        vertices, skin, st = solve(target, jaw=jaw)
        yield i, (blended, jaw, judged, vertices, skin, st)


def run_stress(
    template: Template,
    cases: list[StressCase],
    keep_worst: int = 6,
    progress: bool = True,
    **settings: Any,
) -> StressResult:
    """Every case's frames through φ† and the sanity bounds; `settings` go to the Simulator."""
    t0 = time.perf_counter()
    out = StressResult()
    heap: list[tuple[float, int, WorstFrame]] = []
    hs: HeadSimulation | None = None
    key: tuple[str, int] | None = None
    volume: SoftVolume | None = None
    total = sum(len(c.frames) for c in cases)
    bar = tqdm(total=total, desc="stress", unit="frame", disable=not progress)
    for case in cases:
        if key != (case.identity, case.level):
            key = (case.identity, case.level)
            h = identity_coefficients(template, case.identity)
            hs = build_head_simulation(
                template, h, LhmConfig(level=case.level, tet_mesh=case.tet_mesh)
            )
            volume = SoftVolume(hs)
        assert hs is not None and volume is not None
        sim = hs.simulator(threads=1, **settings)
        for name, value in case.parameters.items():
            sim.set_parameter(name, value)
        bar.set_postfix_str(f"{case.group}, {case.identity}, level {case.level}")
        for i, (blended, jaw, target, vertices, skin, st) in _frames(sim, hs, case):
            bar.update(1)
            if (i + 1) % case.judge_every:
                continue
            check = check_frame(
                hs, volume, target, skin, vertices, st, sim.get_parameter("target_volume")
            )
            label = case.frames[i][0]
            out.frames.append(StressFrame(case.group, case.identity, case.level, label, check))
            score = _severity(check)
            if keep_worst and (len(heap) < keep_worst or score > heap[0][0]):
                title = (
                    f"{label} - {case.group}, {case.identity}, level {case.level}: "
                    f"{', '.join(check.failures()) or 'passes'}, max "
                    f"{check.max_displacement_mm:.1f} mm"
                )
                physics = hs.whole_head(skin, blended, jaw).astype(np.float32)
                worst = WorstFrame(title, hs.head, blended.astype(np.float32), physics, score)
                item = (score, len(out.frames), worst)
                if len(heap) < keep_worst:
                    heapq.heappush(heap, item)
                else:
                    heapq.heapreplace(heap, item)
    bar.close()
    out.worst = [w for _, _, w in sorted(heap, key=lambda t: -t[0])]
    out.seconds = time.perf_counter() - t0
    return out


def _case_groups(cases: list[StressCase]) -> list[list[StressCase]]:
    """The cases of one head simulation (identity, level) together, in the given order."""
    groups: dict[tuple[str, int], list[StressCase]] = {}
    for c in cases:
        groups.setdefault((c.identity, c.level), []).append(c)
    return list(groups.values())


def _run_group(
    ict: str | None, cases: list[StressCase], keep_worst: int, settings: dict[str, Any]
) -> StressResult:
    return run_stress(Template.load(ict), cases, keep_worst, False, **settings)


def run_stress_parallel(
    ict: str | None,
    cases: list[StressCase],
    keep_worst: int = 6,
    workers: int = 2,
    progress: bool = True,
    **settings: Any,
) -> StressResult:
    """run_stress over `workers` processes, one head simulation (identity, level) per task,
    the largest first; the frames come back in the order run_stress gives them."""
    t0 = time.perf_counter()
    groups = _case_groups(cases)
    size = [sum(len(c.frames) for c in g) for g in groups]
    results: list[StressResult | None] = [None] * len(groups)
    bar = tqdm(total=sum(size), desc="stress", unit="frame", disable=not progress)
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(workers, mp_context=ctx) as pool:
        order = sorted(range(len(groups)), key=lambda k: -size[k])
        jobs = {pool.submit(_run_group, ict, groups[k], keep_worst, settings): k for k in order}
        for job in as_completed(jobs):
            k = jobs[job]
            results[k] = job.result()
            bar.update(size[k])
    bar.close()
    out = StressResult()
    done = [r for r in results if r is not None]
    out.frames = [f for r in done for f in r.frames]
    out.worst = sorted((w for r in done for w in r.worst), key=lambda w: -w.score)[:keep_worst]
    out.seconds = time.perf_counter() - t0
    return out


def group_summary(frames: list[StressFrame]) -> dict[str, dict[str, Any]]:
    groups: dict[str, list[FrameCheck]] = {}
    for f in frames:
        groups.setdefault(f.group, []).append(f.check)
    groups["all"] = [f.check for f in frames]
    return {g: bench_figures(c) | {"failures": failure_counts(c)} for g, c in groups.items()}


def _fmt(v: float) -> str:
    return "–" if isinstance(v, float) and math.isnan(v) else f"{v:.3f}"


def markdown_report(result: StressResult, summary: dict[str, dict[str, Any]], command: str) -> str:
    lines = [
        "# Physics stress suite",
        "",
        f"`{command}` ({len(result.frames)} judged frames, {result.seconds:.0f} s).",
        'Bounds: docs/physics.md, "Sanity bounds". The open ratio is the one the bound judges '
        "(the part of the change a contact explains taken off); the plain ratio is physics / "
        "linear.",
        "",
        "| group | frames | failed | exploded | penetration worse | open ratio min / max | "
        "plain ratio min / max | inverted | volume | not converged | "
        "max distance to linear (mm) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for g, s in summary.items():
        f = s["failures"]
        lines.append(
            f"| {g} | {s['stress_frames']} | {f['failed_frames']} | {f['exploded']} | "
            f"{f['penetration']} | {_fmt(s['mouth_open_ratio_min'])} / "
            f"{_fmt(s['mouth_open_ratio_max'])} | {_fmt(s['mouth_open_raw_ratio_min'])} / "
            f"{_fmt(s['mouth_open_raw_ratio_max'])} | {f['inverted_elements']} | {f['volume']} | "
            f"{f['not_converged']} | {s['max_displacement_mm']:.1f} |"
        )
    failing = sorted(
        (f for f in result.frames if f.check.failures()),
        key=lambda f: -_severity(f.check),
    )
    lines += ["", f"## Failing frames ({len(failing)}; the 40 worst)", ""]
    for f in failing[:40]:
        c = f.check
        lines.append(
            f"- {f.group}, {f.identity}, level {f.level}, {f.label}: "
            f"{', '.join(c.failures())} (max {c.max_displacement_mm:.1f} mm, explained "
            f"{c.explained_mm:.1f}; penetrating {c.penetrating_linear} -> "
            f"{c.penetrating_physics}; opening {c.opening_linear_mm:.1f} -> "
            f"{c.opening_physics_mm:.1f} mm; inverted {c.inverted_elements}; volume "
            f"{c.volume_linear_percent:.2f} -> {c.volume_physics_percent:.2f} %)"
        )
    return "\n".join(lines) + "\n"


def write_report(
    out: Path, result: StressResult, template: Template, command: str
) -> dict[str, dict[str, Any]]:
    """stress.json, stress.md and the contact sheet stress_worst.png in `out`."""
    out.mkdir(parents=True, exist_ok=True)
    summary = group_summary(result.frames)
    doc = {
        "command": command,
        "seconds": result.seconds,
        "summary": summary,
        "frames": [f.as_dict() for f in result.frames],
    }
    (out / "stress.json").write_text(json.dumps(doc, indent=1) + "\n")
    (out / "stress.md").write_text(markdown_report(result, summary, command))
    if result.worst:
        render_rows(
            out / "stress_worst.png",
            template.triangles,
            [(w.neutral, w.linear, w.physics, w.title) for w in result.worst],
            notes=["the stress suite's worst frames (failing first, then by distance)"],
        )
    return summary
