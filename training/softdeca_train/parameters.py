"""The material parameter vector p, read from its single definition plugin/data/parameters.json
(the same file the C++ simulator embeds at build time, and the bundle manifest copies).

Each entry holds both of its ranges: `lo`/`hi`, where the physics accepts a value, and
`control`, the range a user moves it in (what datasets sample by default and a bundle trained
on them accepts), or null for a parameter that acts on nothing in the head model: the models
do not take those (docs/controls.md)."""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

import numpy as np

from softdeca_train.paths import REPO_ROOT

DEFINITION = REPO_ROOT / "plugin" / "data" / "parameters.json"


@dataclass(frozen=True)
class ParameterSpec:
    name: str
    default: float
    lo: float
    hi: float
    scale: str  # "linear" or "log": how to sample uniformly between lo and hi
    unit: str
    domain: str  # "global" or the element kind per-element values are given for
    control: tuple[float, float] | None = None  # the control range; None: not a control

    def sample(self, rng: np.random.Generator, size: int | None = None) -> np.ndarray | float:
        """Uniform (or log-uniform) in [lo, hi]; exp(log(hi)) may round past hi, so the value
        is clipped into the range exactly."""
        if self.scale == "log":
            v = np.exp(rng.uniform(np.log(self.lo), np.log(self.hi), size))
        else:
            v = rng.uniform(self.lo, self.hi, size)
        clipped = np.clip(v, self.lo, self.hi)
        return clipped if size is not None else float(clipped)

    def normalise(self, value: np.ndarray | float) -> np.ndarray | float:
        """Map [lo, hi] to [0, 1] on the parameter's own scale (network inputs use this)."""
        if self.scale == "log":
            return (np.log(value) - np.log(self.lo)) / (np.log(self.hi) - np.log(self.lo))
        return (np.asarray(value) - self.lo) / (self.hi - self.lo)


@dataclass(frozen=True)
class ParameterSet:
    specs: tuple[ParameterSpec, ...]

    @property
    def names(self) -> list[str]:
        return [s.name for s in self.specs]

    def defaults(self) -> np.ndarray:
        return np.array([s.default for s in self.specs])

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        """One parameter vector, each entry uniform or log-uniform in its range (Appendix A)."""
        return np.array([s.sample(rng) for s in self.specs])

    def controls(self) -> ParameterSet:
        """The controls only (what the models take), each over its control range with its
        default clamped into it."""
        out = []
        for s in self.specs:
            if s.control is not None:
                lo, hi = s.control
                out.append(replace(s, lo=lo, hi=hi, default=min(max(s.default, lo), hi)))
        return ParameterSet(tuple(out))

    def validate(self, p: np.ndarray) -> None:
        p = np.asarray(p, dtype=np.float64)
        if p.shape[-1] != len(self.specs):
            raise ValueError(f"expected {len(self.specs)} parameters, got {p.shape[-1]}")
        if not np.isfinite(p).all():
            raise ValueError("parameter vector has NaN or infinity")
        for k, s in enumerate(self.specs):
            v = p[..., k]
            if np.any(v < s.lo - 1e-9) or np.any(v > s.hi + 1e-9):
                raise ValueError(f"{s.name} out of range [{s.lo}, {s.hi}]: {np.ravel(v)[:3]}")

    def check_values(self, values: dict[str, float]) -> None:
        """Named values (a command line's or a file's): each a known parameter within the
        range the physics accepts."""
        specs = {s.name: s for s in self.specs}
        for name, value in values.items():
            if name not in specs:
                raise ValueError(f"unknown parameter {name!r}; known: {', '.join(specs)}")
            s = specs[name]
            if not (s.lo <= value <= s.hi):
                raise ValueError(f"parameter {name} = {value} outside its range [{s.lo}, {s.hi}]")

    def normalise(self, p: np.ndarray) -> np.ndarray:
        return np.stack([s.normalise(p[..., k]) for k, s in enumerate(self.specs)], axis=-1)


@cache
def load_parameters(path: Path = DEFINITION) -> ParameterSet:
    if not path.is_file():
        raise FileNotFoundError(f"parameter definition not found: {path}")
    doc = json.loads(path.read_text())
    if doc.get("format") != "softdeca-parameters":
        raise ValueError(f"{path} is not a softdeca-parameters file")
    specs = tuple(
        ParameterSpec(
            p["name"],
            float(p["default"]),
            float(p["lo"]),
            float(p["hi"]),
            p["scale"],
            p.get("unit", ""),
            p.get("domain", "global"),
            _control(p),
        )
        for p in doc["parameters"]
    )
    return ParameterSet(specs)


def _control(entry: dict) -> tuple[float, float] | None:
    c = entry.get("control")
    if c is None:
        return None
    lo, hi = float(c["lo"]), float(c["hi"])
    if not float(entry["lo"]) <= lo < hi <= float(entry["hi"]):
        raise ValueError(f"{entry['name']}: control range [{lo}, {hi}] outside the physics' range")
    return lo, hi
