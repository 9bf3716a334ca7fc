"""The sanity bounds of a simulated frame, defined once: `simulate`, the stress suite, the
benchmarks, data generation and the tests all judge frames here (docs/physics.md, "Sanity
bounds"). A frame is compared with the linear blend S_t it was simulated from:

- exploded: a skin point farther than `exploded_mm` from the linear blend, beyond what a
  contact correction explains (the linear blend's deepest lip penetration, which a contact
  may undo);
- penetration: more penetrating lip points (inside the other lip or the teeth) than the
  linear blend has;
- mouth opening: where the linear blend's lips are more than `open_mm` apart (inner middle of
  the upper lip to that of the lower lip, ICT landmarks 62 and 66; negative where the upper
  lip's middle is below the lower lip's: crossed lips, an interpenetration that the
  penetration bound judges, not an open mouth), physics / linear opening outside `open_ratio`,
  beyond what a contact correction explains (as for `exploded`: a lip the linear blend pushes
  into the teeth must come out of them, and the opening changes by up to that depth);
- inverted elements: any soft or muscle tet with volume <= 0 at the end of the solve;
- volume: the soft tissue's volume change farther from the requested one (`target_volume`)
  than the linear blend's (refit, measures.py) by more than `volume_slack_percent`
  (percentage points: both are ~0 near rest at the default target_volume 1). The slack is
  the tissue's own compliance under the loads a frame may carry: on the neutral face, with
  nothing but gravity 2 g against the capture's (a 3 g difference), the physics' soft tissue
  loses 0.6 points at the default volume weights. Where target_volume varies by region, the
  regions' errors are taken together: the root mean square over regions, each weighted by its
  share of the tissue's rest volume, of the change's distance from the region's request, for
  the physics against the linear blend. The tissue is continuous, so a region whose
  neighbours are asked otherwise can be carried along by them and end farther from its own
  request than the linear blend (whose refit changes a region's volume by itself, the
  expression's doing, not the request's); what the physics owes is to bring the regions as a
  whole closer to what was asked. With one region this is the rule above;
- not converged: the volumetric solve stopped at its iteration cap.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import asdict, dataclass

import numpy as np
import softdeca_native as native

from softdeca_train.contact_rules import CONTACT_LANDMARKS
from softdeca_train.sim.head import HeadSimulation
from softdeca_train.sim.measures import PENETRATION_TOLERANCE, SoftVolume

# ICT 68-landmark ids of the inner lip middles
UPPER_LIP_MIDDLE, LOWER_LIP_MIDDLE = CONTACT_LANDMARKS.inner_lip_middles


@dataclass(frozen=True)
class SanityBounds:
    exploded_mm: float = 15.0
    open_mm: float = 3.0
    open_ratio: tuple[float, float] = (0.9, 1.1)
    volume_slack_percent: float = 1.0


BOUNDS = SanityBounds()
REASONS = (
    "exploded",
    "penetration",
    "mouth_open_ratio",
    "inverted_elements",
    "volume",
    "not_converged",
)


@dataclass(frozen=True)
class VolumeField:
    """A target_volume that varies by region: per soft tet its value and its region's id."""

    values: np.ndarray
    groups: np.ndarray


@dataclass
class FrameCheck:
    """One frame's figures against its linear blend and the reasons it fails (if any)."""

    converged: bool
    iterations: int
    max_displacement_mm: float  # largest |S_physics - S_linear| over S
    explained_mm: float  # deepest lip penetration of the linear blend
    max_target_distance_mm: float  # the solver's own: largest |S - target| (blended target)
    penetrating_linear: int
    penetrating_physics: int
    opening_linear_mm: float
    opening_physics_mm: float
    inverted_elements: int
    volume_linear_percent: float
    volume_physics_percent: float
    # The soft tissue's requested change, 100 (target_volume - 1): the physics grows or
    # shrinks the tissue toward it, so both changes are measured from it.
    volume_requested_percent: float = 0.0
    # Where target_volume varies by region: per region (physics, linear, requested) change
    # (%) and its share of the tissue's rest volume, judged in place of the totals.
    volume_regions: tuple[tuple[float, float, float, float], ...] = ()

    @property
    def open_ratio(self) -> float:
        """physics / linear mouth opening; NaN where the linear blend's mouth is closed."""
        if self.opening_linear_mm <= BOUNDS.open_mm:
            return math.nan
        return self.opening_physics_mm / self.opening_linear_mm

    @property
    def judged_open_ratio(self) -> float:
        """The ratio the mouth-opening bound judges: the physics' opening with the part a contact
        correction explains taken off (at most the linear blend's deepest lip penetration, as
        in `failures`). A lip the linear blend sinks into the teeth must come out of them,
        which changes the opening by up to that depth; only the change beyond it counts."""
        if math.isnan(self.open_ratio):
            return math.nan
        excess = self.opening_physics_mm - self.opening_linear_mm
        beyond = math.copysign(max(abs(excess) - self.explained_mm, 0.0), excess)
        return (self.opening_linear_mm + beyond) / self.opening_linear_mm

    @property
    def volume_errors(self) -> tuple[float, float]:
        """(physics, linear blend) distance of the soft tissue's volume change from the
        request, in percentage points: over a regional request the rest-volume-weighted root
        mean square of the regions' distances."""
        regions = np.array(
            self.volume_regions
            or (
                (
                    self.volume_physics_percent,
                    self.volume_linear_percent,
                    self.volume_requested_percent,
                    1.0,
                ),
            ),
            np.float64,
        ).reshape(-1, 4)
        phys, lin, req, share = regions.T
        share = share / share.sum()
        rms = lambda d: float(np.sqrt((share * d**2).sum()))  # noqa: E731
        return rms(phys - req), rms(lin - req)

    def failures(self, bounds: SanityBounds = BOUNDS) -> list[str]:
        out = []
        if self.max_displacement_mm > bounds.exploded_mm + self.explained_mm:
            out.append("exploded")
        if self.penetrating_physics > self.penetrating_linear:
            out.append("penetration")
        if not math.isnan(self.open_ratio):
            lo, hi = bounds.open_ratio
            if not lo <= self.judged_open_ratio <= hi:
                out.append("mouth_open_ratio")
        if self.inverted_elements > 0:
            out.append("inverted_elements")
        physics, linear = self.volume_errors
        if physics > linear + bounds.volume_slack_percent:
            out.append("volume")
        if not self.converged:
            out.append("not_converged")
        return out

    def as_dict(self) -> dict[str, object]:
        return asdict(self) | {
            "open_ratio": self.open_ratio,
            "judged_open_ratio": self.judged_open_ratio,
            "failures": self.failures(),
        }


def _penetrations(hs: HeadSimulation, skin: np.ndarray, vertices: np.ndarray) -> dict[int, float]:
    """Deepest penetration (m) per penetrating lip point."""
    out: dict[int, float] = {}
    skin, vertices = np.asarray(skin, np.float64), np.asarray(vertices, np.float64)
    for _, point, depth in native.find_penetrations(hs.mesh, skin, vertices, PENETRATION_TOLERANCE):
        out[point] = max(out.get(point, 0.0), depth)
    return out


def lip_openings_mm(landmarks68: np.ndarray, heads: np.ndarray) -> np.ndarray:
    """(..., V, 3) skins or heads in template order -> (...) inner upper-lip middle to inner
    lower-lip middle (mm); negative where the upper lip's middle lies below the lower lip's
    (+Y is up in the head's frame): crossed lips, not an open mouth."""
    heads = np.asarray(heads)
    d = heads[..., landmarks68[UPPER_LIP_MIDDLE], :] - heads[..., landmarks68[LOWER_LIP_MIDDLE], :]
    return 1e3 * np.linalg.norm(d, axis=-1) * np.where(d[..., 1] >= 0.0, 1.0, -1.0)


def lip_opening_mm(hs: HeadSimulation, skin: np.ndarray) -> float:
    """One frame's lip opening (lip_openings_mm)."""
    return float(lip_openings_mm(hs.template.landmarks68, skin))


def check_frame(
    hs: HeadSimulation,
    volume: SoftVolume,
    target: np.ndarray,
    skin: np.ndarray,
    vertices: np.ndarray,
    stats: dict[str, object],
    target_volume: float | VolumeField = 1.0,
) -> FrameCheck:
    """`target`: the linear blend's S (S_t); skin / vertices / stats: the solver's result;
    `target_volume`: the soft tissue's parameter of that name for the frame, or its field
    where it varies by region (the regions judged together, FrameCheck.volume_errors; its
    rest-volume-weighted mean is the total's request)."""
    linear_pen = _penetrations(hs, target, vertices)
    physics_pen = _penetrations(hs, skin, vertices)
    linear_vertices = volume.linear_vertices(target, vertices)
    regions: tuple[tuple[float, float, float, float], ...] = ()
    if not isinstance(target_volume, VolumeField):
        requested = float(target_volume)
    else:
        g = target_volume.groups
        by = zip(
            volume.change_percent_by_group(vertices, g),
            volume.change_percent_by_group(linear_vertices, g),
            volume.requested_percent_by_group(target_volume.values, g),
            volume.rest_share_by_group(g),
            strict=True,
        )
        regions = tuple(
            (float(a), float(b), float(c), float(d)) for a, b, c, d in by if not math.isnan(c)
        )
        requested = volume.mean_over_tets(target_volume.values)
    return FrameCheck(
        converged=bool(stats["converged"]),
        iterations=int(stats["iterations"]),  # type: ignore[call-overload]
        max_displacement_mm=1e3 * float(np.linalg.norm(skin - target, axis=1).max()),
        explained_mm=1e3 * max(linear_pen.values(), default=0.0),
        max_target_distance_mm=1e3 * float(stats["max_target_distance"]),  # type: ignore[arg-type]
        penetrating_linear=len(linear_pen),
        penetrating_physics=len(physics_pen),
        opening_linear_mm=lip_opening_mm(hs, target),
        opening_physics_mm=lip_opening_mm(hs, skin),
        inverted_elements=int(stats["inverted_elements"]),  # type: ignore[call-overload]
        volume_linear_percent=volume.change_percent(linear_vertices),
        volume_physics_percent=volume.change_percent(vertices),
        volume_requested_percent=100.0 * (requested - 1.0),
        volume_regions=regions,
    )


def failure_counts(checks: list[FrameCheck]) -> dict[str, int]:
    """Frames failing each reason (a frame may count under several) and in all."""
    c: Counter[str] = Counter()
    for ch in checks:
        f = ch.failures()
        c.update(f)
        c["failed_frames"] += bool(f)
    return {r: c[r] for r in (*REASONS, "failed_frames")}


def bench_figures(checks: list[FrameCheck]) -> dict[str, float | int]:
    """The stress figures of `make bench` over a set of frames: the opening ratio as the bound
    judges it (judged_open_ratio) and, beside it, the plain physics / linear ratio."""
    open_ = [c for c in checks if not math.isnan(c.open_ratio)]
    ratios, raw = [c.judged_open_ratio for c in open_], [c.open_ratio for c in open_]
    return {
        "stress_frames": len(checks),
        "stress_exploded_frames": sum("exploded" in c.failures() for c in checks),
        "stress_penetration_worse_frames": sum("penetration" in c.failures() for c in checks),
        "mouth_open_frames": len(ratios),
        "mouth_open_ratio_min": min(ratios, default=math.nan),
        "mouth_open_ratio_max": max(ratios, default=math.nan),
        "mouth_open_raw_ratio_min": min(raw, default=math.nan),
        "mouth_open_raw_ratio_max": max(raw, default=math.nan),
        "stress_failed_frames": sum(bool(c.failures()) for c in checks),
        "max_displacement_mm": max((c.max_displacement_mm for c in checks), default=0.0),
    }
