"""The report's `real_takes`: SoftDECA and the linear blendshapes against the physics on every
n-th frame of every recorded take, for identities no model trained on, reported per take.

A figure on frames the model trained on says little about a user's own takes, so the takes
any training frame of the bundle came from (its manifest's training record) are summarised
apart from those it never saw, and the report leads with the unseen ones. Mild frames (the
linear blend within MILD_MM of the physics: speech, small co-activations) are summarised apart
from strong ones, since a pooled mean is mostly the many mild frames. Calm frames (the linear
blend within CALM_MM: a face near rest, as in most live talking) are summarised too: there the
linear blend is nearly the physics already, and SoftDECA must not be further from it. Recorded
takes are mostly expressive, so every unseen take is also judged at a reduced amplitude (each
frame's weights scaled alike): the same motion as a calm face makes it, where calm frames are
many."""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdeca_train.streaming.takes import TAKE_SUFFIXES, read_take, take_paths

MILD_MM = 0.1  # a frame is mild when the linear blend is this close to the physics (mean, mm)
CALM_MM = 0.05  # and calm when it is this close
GROUP_KEYS = ("frames", "softdeca_mm", "linear_mm", "ratio")
TAKE_KEYS = ("take", "trained_on", "amplitude", *GROUP_KEYS, "mild", "strong", "calm")
KEYS = (
    "every",
    "identities",
    "mild_mm",
    "calm_mm",
    "reduced_amplitude",
    "takes",
    "unseen",
    "unseen_reduced",
    "seen",
    "rest",
)
# Reports made before the calm figure and the reduced takes existed lack these; they are read
# all the same.
LATER_TAKE_KEYS = ("calm", "amplitude")
LATER_KEYS = ("calm_mm", "reduced_amplitude", "unseen_reduced")
REST_KEYS = ("softdeca_mm", "linear_mm")


@dataclass(frozen=True)
class RecordedTake:
    name: str  # "<source folder>/<take>" relative to the recordings folder
    sha256: str
    weights: np.ndarray  # (n, 52) every n-th tracked frame, canonical ARKit order
    amplitude: float = 1.0  # the recorded weights scaled by this (1: as recorded)

    def label(self) -> str:
        return take_label(self.name, self.amplitude)


def take_label(name: str, amplitude: float) -> str:
    """How the report names a take: its name, and its amplitude where it is reduced."""
    return name if amplitude == 1.0 else f"{name} x{amplitude:g}"


def reduced(take: RecordedTake, amplitude: float) -> RecordedTake:
    """`take` at a reduced amplitude: every weight of every frame scaled by `amplitude` (the
    expression's shape kept, as the data's reduced draws, data/expressions.py)."""
    if not 0.0 < amplitude < 1.0:
        raise ValueError(f"a reduced amplitude is in (0, 1), got {amplitude}")
    return RecordedTake(take.name, take.sha256, take.weights * np.float32(amplitude), amplitude)


def recorded_takes(recordings: Path, every: int) -> list[RecordedTake]:
    """Every `every`-th tracked frame of every take below `recordings` (Live Link Face CSV or
    LLV recording: streaming/takes.py), sorted by name."""
    root = Path(recordings)
    paths = take_paths(root)
    if not paths:
        raise FileNotFoundError(f"no takes ({', '.join(TAKE_SUFFIXES)}) below {recordings}")
    takes = []
    for p in paths:
        frames = read_take(p).frames
        if not frames:
            raise ValueError(f"{p}: no tracked frames")
        w = np.stack([f.weights for f in frames]).astype(np.float32)[::every]
        name = p.relative_to(root).with_suffix("").as_posix()
        takes.append(RecordedTake(name, hashlib.sha256(p.read_bytes()).hexdigest(), w))
    return takes


def _split_takes(dataset: dict) -> list[str]:
    return list(((dataset.get("splits") or {}).get("train") or {}).get("takes") or [])


def trained_take_names(manifest: dict) -> set[str]:
    """The names of the takes any training frame of a bundle came from: the train split of
    its dataset and of every dataset added to it (an untrained bundle: none)."""
    training = manifest.get("training") or {}
    datasets = [training.get("dataset") or {}]
    datasets += list(training.get("more_static") or [])
    datasets += [training["contrasts"]] if training.get("contrasts") else []
    return {name for d in datasets for name in _split_takes(d)}


def trained_on(take: RecordedTake, trained: set[str]) -> bool:
    """Whether a training frame may have come from `take`. The training record names takes
    by file stem only, so any take of that stem counts as seen: a collision can only make
    the unseen figure leave a take out, never flatter it."""
    return take.name.rsplit("/", 1)[-1] in trained


@dataclass(frozen=True)
class FrameDistances:
    """Per evaluated frame (one identity, one take frame): the take's index and the mean
    distance over the skin (mm) of SoftDECA and of the linear blend to the physics."""

    take: np.ndarray  # (n,) int
    softdeca_mm: np.ndarray  # (n,)
    linear_mm: np.ndarray  # (n,)


def _group(softdeca: np.ndarray, linear: np.ndarray) -> dict | None:
    if len(softdeca) == 0:
        return None
    s, lin = float(softdeca.mean()), float(linear.mean())
    return {
        "frames": len(softdeca),
        "softdeca_mm": s,
        "linear_mm": lin,
        "ratio": s / lin if lin > 0 else None,
    }


def _with_mild_and_strong(softdeca: np.ndarray, linear: np.ndarray) -> dict | None:
    whole = _group(softdeca, linear)
    if whole is None:
        return None
    mild, calm = linear <= MILD_MM, linear <= CALM_MM
    return {
        **whole,
        "mild": _group(softdeca[mild], linear[mild]),
        "strong": _group(softdeca[~mild], linear[~mild]),
        "calm": _group(softdeca[calm], linear[calm]),
    }


def _pooled(d: FrameDistances, takes: list[int], per_take: list[dict]) -> dict | None:
    rows = np.isin(d.take, takes)
    pooled = _with_mild_and_strong(d.softdeca_mm[rows], d.linear_mm[rows])
    if pooled is None:
        return None
    ratios = [per_take[t]["ratio"] for t in takes if per_take[t]["ratio"] is not None]
    pooled["mean_take_ratio"] = float(np.mean(ratios)) if ratios else None
    pooled["worst_take_ratio"] = max(ratios) if ratios else None
    return pooled


def summarise(
    takes: list[RecordedTake],
    seen: list[bool],
    d: FrameDistances,
    every: int,
    identities: int,
    rest: tuple[float, float] | None = None,
) -> dict:
    """The `real_takes` section: per take, pooled over the unseen takes and over the seen ones
    (those a training frame came from) as recorded, and over the unseen takes at a reduced
    amplitude (`unseen_reduced`); ratio: SoftDECA's distance to the physics over the linear
    blend's, pooled over frames. `rest`: the mean distances (SoftDECA, linear) of the neutral
    face (every weight 0), where a calm take's frames lie."""
    per_take = []
    for i, take in enumerate(takes):
        rows = d.take == i
        group = _with_mild_and_strong(d.softdeca_mm[rows], d.linear_mm[rows])
        if group is None:
            raise ValueError(f"take {take.label()}: no frame evaluated")
        per_take.append(
            {"take": take.name, "trained_on": seen[i], "amplitude": take.amplitude, **group}
        )
    amplitudes = sorted({t.amplitude for t in takes if t.amplitude != 1.0})
    if len(amplitudes) > 1:
        raise ValueError(f"one reduced amplitude per report, got {amplitudes}")
    whole = [i for i, t in enumerate(takes) if t.amplitude == 1.0]
    calm = [i for i, t in enumerate(takes) if t.amplitude != 1.0 and not seen[i]]
    return {
        "every": every,
        "identities": identities,
        "mild_mm": MILD_MM,
        "calm_mm": CALM_MM,
        "reduced_amplitude": amplitudes[0] if amplitudes else None,
        "takes": per_take,
        "unseen": _pooled(d, [i for i in whole if not seen[i]], per_take),
        "unseen_reduced": _pooled(d, calm, per_take),
        "seen": _pooled(d, [i for i in whole if seen[i]], per_take),
        "rest": None if rest is None else dict(zip(REST_KEYS, rest, strict=True)),
    }


def _check_group(where: str, g: object, optional: bool = False) -> None:
    if g is None and optional:
        return
    if not isinstance(g, dict) or not set(GROUP_KEYS) <= set(g):
        raise ValueError(f"report: real_takes {where} needs {GROUP_KEYS}")
    if not (isinstance(g["frames"], int) and g["frames"] > 0):
        raise ValueError(f"report: real_takes {where}.frames must be a positive count")
    for k in ("softdeca_mm", "linear_mm"):
        if not (isinstance(g[k], (int, float)) and math.isfinite(g[k]) and g[k] >= 0):
            raise ValueError(f"report: real_takes {where}.{k} must be a distance in mm")


def validate_real_takes(real: object) -> None:
    """ValueError naming the first problem of a `real_takes` section."""
    if not isinstance(real, dict) or not set(KEYS) - set(LATER_KEYS) <= set(real) <= set(KEYS):
        raise ValueError(f"report: `real_takes` needs exactly {KEYS}")
    if not (isinstance(real["identities"], int) and real["identities"] > 0):
        raise ValueError("report: real_takes.identities must be a positive count")
    if not isinstance(real["takes"], list) or not real["takes"]:
        raise ValueError("report: real_takes.takes must be a non-empty list")
    for t in real["takes"]:
        if not isinstance(t, dict) or not set(TAKE_KEYS) - set(LATER_TAKE_KEYS) <= set(t) <= set(
            TAKE_KEYS
        ):
            raise ValueError(f"report: a real take needs exactly {TAKE_KEYS}")
        _check_group(t["take"], t)
        for part in ("mild", "strong", "calm"):
            _check_group(f"{t['take']}.{part}", t.get(part), optional=True)
    if real["unseen"] is None and real["seen"] is None:
        raise ValueError("report: real_takes has neither unseen nor seen takes")
    for part in ("unseen", "seen", "unseen_reduced"):
        _check_group(part, real.get(part), optional=True)
    rest = real["rest"]
    if rest is not None and not (
        isinstance(rest, dict)
        and set(rest) == set(REST_KEYS)
        and all(isinstance(v, (int, float)) and math.isfinite(v) and v >= 0 for v in rest.values())
    ):
        raise ValueError(f"report: real_takes.rest needs the distances {REST_KEYS} in mm")


def worse_when_calm(real: dict) -> list[str]:
    """The takes on whose calm frames SoftDECA is further from the physics than the linear
    blend (calm ratio above 1): what a user streaming calm talking would see."""
    return [
        _take_label(t)
        for t in real["takes"]
        if (t.get("calm") or {}).get("ratio") is not None and t["calm"]["ratio"] > 1.0
    ]


def _take_label(t: dict) -> str:
    return take_label(t["take"], t.get("amplitude", 1.0))


def _cell(g: dict | None, key: str) -> str:
    if g is None or g.get(key) is None:
        return "–"
    return f"{g[key]:.2f}" if key == "ratio" else f"{g[key]:.3f}"


def readme_lines(real: dict) -> list[str]:
    """The report README's real-takes table: unseen takes first, each pooled figure labelled."""
    lines = [
        f"Real takes (every {real['every']}th frame, {real['identities']} identities no model "
        "trained on, default parameters): mean distance to the physics over the skin (mm) and "
        "SoftDECA's share of the linear blend's (ratio; below 1 is closer to the physics). "
        f"Mild frames: the linear blend within {real['mild_mm']} mm of the physics"
        + (f"; calm frames: within {real['calm_mm']} mm." if "calm_mm" in real else ".")
        + (
            f" Takes marked x{real['reduced_amplitude']:g} are an unseen take with every weight "
            "scaled by that: the same motion made calmly."
            if real.get("reduced_amplitude")
            else ""
        ),
        "",
        *(
            [
                "**On calm frames SoftDECA is further from the physics than the linear blend "
                f"in {len(worse)} take(s): {', '.join(worse)}.**",
                "",
            ]
            if (worse := worse_when_calm(real))
            else []
        ),
        *(
            [
                f"At rest (every weight 0) SoftDECA is {real['rest']['softdeca_mm']:.3f} mm from "
                f"the physics and the linear blend {real['rest']['linear_mm']:.3f} mm.",
                "",
            ]
            if real["rest"]
            else []
        ),
        "| take | trained on | frames | SoftDECA | linear | ratio | calm ratio | mild ratio "
        "| strong ratio |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    rows = sorted(
        real["takes"], key=lambda t: (t["trained_on"], t["take"], -t.get("amplitude", 1.0))
    )
    reduced_label = f"unseen takes x{real.get('reduced_amplitude') or 0:g}, pooled"
    for label, g in [(_take_label(t), t) for t in rows] + [
        ("**unseen takes, pooled**", real["unseen"]),
        (f"**{reduced_label}**", real.get("unseen_reduced")),
        ("in-distribution takes, pooled", real["seen"]),
    ]:
        if g is None:
            continue
        seen = {True: "yes", False: "no"}.get(g.get("trained_on"), "")
        lines.append(
            f"| {label} | {seen} | {g['frames']} | {_cell(g, 'softdeca_mm')} "
            f"| {_cell(g, 'linear_mm')} | {_cell(g, 'ratio')} | {_cell(g.get('calm'), 'ratio')} "
            f"| {_cell(g['mild'], 'ratio')} | {_cell(g['strong'], 'ratio')} |"
        )
    return lines


def one_line(real: dict) -> str:
    """The figure a command prints: the unseen takes' pooled distances, else the seen ones'."""
    part, label = (real["unseen"], "unseen") if real["unseen"] else (real["seen"], "seen")
    return (
        f"real takes ({label}, {part['frames']} frames): SoftDECA {part['softdeca_mm']:.3f} mm, "
        f"linear {part['linear_mm']:.3f} mm, ratio {_cell(part, 'ratio')}"
    )
