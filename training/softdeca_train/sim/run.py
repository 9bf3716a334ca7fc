"""φ† over a window of a take: per frame the linear blend S_t, the jaw from the lower teeth,
then the static solve or one dynamic step; both whole heads kept, with the solver's figures
and the measures of measures.py."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import softdeca_native as native
from tqdm import tqdm

from softdeca_train.sim.head import HeadSimulation
from softdeca_train.sim.measures import SoftVolume, mean_distance_mm
from softdeca_train.sim.sanity import FrameCheck, check_frame, failure_counts
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import REGIONS

STAT_KEYS = ("iterations", "converged", "estimated_error", "collision_rounds", "total_seconds")


@dataclass
class FrameRecord:
    iterations: int
    converged: bool
    collision_rounds: int
    seconds: float
    volume_linear_percent: float
    volume_physics_percent: float
    penetrating_linear: int
    penetrating_physics: int
    distance_mm: float
    check: FrameCheck

    @property
    def failures(self) -> list[str]:
        return self.check.failures()

    def as_dict(self) -> dict[str, object]:
        out: dict[str, object] = {k: v for k, v in self.__dict__.items() if k != "check"}
        return out | {"sanity": self.check.as_dict(), "failures": self.failures}


@dataclass
class SimulatedTake:
    linear: list[np.ndarray] = field(default_factory=list)  # whole heads (V, 3) float32
    physics: list[np.ndarray] = field(default_factory=list)
    records: list[FrameRecord] = field(default_factory=list)
    seconds: float = 0.0


def simulate_frames(
    hs: HeadSimulation,
    sim: native.Simulator,
    weights: np.ndarray,
    dynamic: bool = False,
    progress: bool = True,
) -> SimulatedTake:
    """Static (each frame warm-started from rest) or dynamic (eq. 9 from the first frame)."""
    volume = SoftVolume(hs)
    out = SimulatedTake()
    start = time.perf_counter()
    if dynamic:
        sim.reset_dynamics()
    for w in tqdm(weights, desc="simulate", unit="frame", disable=not progress):
        blended = hs.blend(w[None])[0]
        jaw = hs.jaw_transforms(blended[None])[0]
        target = blended[:N_SKIN].astype(np.float64)
        # a dynamic frame is judged against its step's blended target (eq. 9)
        judged = sim.dynamic_target(target) if dynamic else target
        solve = sim.step_dynamic if dynamic else sim.solve_static
        vertices, skin, st = solve(target, jaw=jaw)
        out.linear.append(blended.astype(np.float32))
        out.physics.append(hs.whole_head(skin, blended, jaw).astype(np.float32))
        check = check_frame(
            hs, volume, judged, skin, vertices, st, sim.get_parameter("target_volume")
        )
        out.records.append(
            FrameRecord(
                iterations=int(st["iterations"]),
                converged=bool(st["converged"]),
                collision_rounds=int(st["collision_rounds"]),
                seconds=float(st["total_seconds"]),
                volume_linear_percent=check.volume_linear_percent,
                volume_physics_percent=check.volume_physics_percent,
                penetrating_linear=check.penetrating_linear,
                penetrating_physics=check.penetrating_physics,
                distance_mm=mean_distance_mm(skin, target),
                check=check,
            )
        )
    out.seconds = time.perf_counter() - start
    return out


def reference_distances(
    result: SimulatedTake, reference: SimulatedTake, tolerance: float, labels: np.ndarray
) -> dict[str, Any]:
    """How far `result`'s skin S lies from a `reference` run of the same frames (solved to
    `tolerance`): per frame the mean and largest vertex distance (mm), the vertex of S with the
    largest and its region (template/regions.py, `labels` per vertex of S)."""
    frames = []
    for a, b in zip(result.physics, reference.physics, strict=True):
        d = 1e3 * np.linalg.norm(a[:N_SKIN].astype(np.float64) - b[:N_SKIN], axis=1)
        worst = int(np.argmax(d))
        frames.append(
            {
                "mean_mm": float(d.mean()),
                "max_mm": float(d[worst]),
                "max_vertex": worst,
                "max_region": REGIONS[int(labels[worst])],
                "over_0_1_mm": int((d > 0.1).sum()),
            }
        )
    return {
        "tolerance": tolerance,
        "mean_mm": float(np.mean([f["mean_mm"] for f in frames])),
        "max_mm": max(f["max_mm"] for f in frames),
        "converged": sum(r.converged for r in reference.records),
        "iterations_mean": float(np.mean([r.iterations for r in reference.records]))
        if reference.records
        else None,
        "per_frame": frames,
    }


def reference_line(ref: dict[str, Any], tolerance: float) -> str:
    """The terminal line of `reference_distances`' figures."""
    regions = sorted({f["max_region"] for f in ref["per_frame"]})
    return (
        f"distance on S to the solve at tolerance {ref['tolerance']:g} (from {tolerance:g}): "
        f"mean {ref['mean_mm']:.5f} mm, max {ref['max_mm']:.3f} mm (largest in "
        f"{', '.join(regions)}); reference {ref['converged']} of {len(ref['per_frame'])} "
        f"converged, {ref['iterations_mean'] or 0:.0f} iterations mean"
    )


def summarise(records: list[FrameRecord]) -> dict[str, Any]:
    """Means and worst values over the frames (volume: of the absolute change)."""
    if not records:
        return {}

    def col(name: str) -> np.ndarray:
        return np.array([getattr(r, name) for r in records], dtype=np.float64)

    out: dict[str, Any] = {
        "frames": len(records),
        "converged": int(col("converged").sum()),
        "iterations_mean": float(col("iterations").mean()),
        "iterations_max": int(col("iterations").max()),
        "solve_seconds_mean": float(col("seconds").mean()),
        "distance_mm_mean": float(col("distance_mm").mean()),
        "max_displacement_mm": max(r.check.max_displacement_mm for r in records),
        "failures": failure_counts([r.check for r in records]),
    }
    for kind in ("linear", "physics"):
        v = np.abs(col(f"volume_{kind}_percent"))
        p = col(f"penetrating_{kind}")
        out |= {
            f"volume_{kind}_abs_percent_mean": float(v.mean()),
            f"volume_{kind}_abs_percent_worst": float(v.max()),
            f"penetrating_{kind}_mean": float(p.mean()),
            f"penetrating_{kind}_max": int(p.max()),
            f"frames_penetrating_{kind}": int((p > 0).sum()),
        }
    return out


def summary_lines(s: dict[str, Any], seconds: float) -> list[str]:
    """The terminal summary of `summarise`'s figures."""
    return [
        f"{s['frames']} frames ({s['converged']} converged), {s['iterations_mean']:.1f} "
        f"iterations mean ({s['iterations_max']} max), {seconds / s['frames']:.2f} s/frame",
        "soft-tissue volume change |%| mean / worst: "
        f"linear {s['volume_linear_abs_percent_mean']:.3f} / "
        f"{s['volume_linear_abs_percent_worst']:.3f}, "
        f"physics {s['volume_physics_abs_percent_mean']:.3f} / "
        f"{s['volume_physics_abs_percent_worst']:.3f}",
        "penetrating lip vertices per frame mean / max: "
        f"linear {s['penetrating_linear_mean']:.1f} / {s['penetrating_linear_max']}, "
        f"physics {s['penetrating_physics_mean']:.1f} / {s['penetrating_physics_max']}",
        f"mean distance physics - linear: {s['distance_mm_mean']:.3f} mm "
        f"(max {s['max_displacement_mm']:.1f} mm)",
        failure_line(s["failures"]),  # type: ignore[arg-type]
    ]


def failure_line(counts: dict[str, int]) -> str:
    """'N frames fail the sanity bounds (reason: n, ...)' or that none does."""
    if not counts["failed_frames"]:
        return "sanity bounds: every frame passes"
    reasons = ", ".join(f"{k} {v}" for k, v in counts.items() if v and k != "failed_frames")
    return f"sanity bounds: {counts['failed_frames']} frames fail ({reasons})"
