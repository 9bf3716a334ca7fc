"""The material parameters p: ParameterSpec, the one description of a parameter (the C ABI's
softdeca_parameter_info, the native ParameterSpec and Unity's ParameterInfo carry the same
fields under the same names), and the physics' list of them, read from its single definition
plugin/data/parameters.json (the same file the C++ simulator embeds at build time, and the
bundle manifest copies).

Each entry of the definition holds both of its ranges: `lo`/`hi`, where the physics accepts a
value, and `control`, the range a user moves it in (what datasets sample by default and a
bundle trained on them accepts), or null for a parameter that acts on nothing in the head
model: the models do not take those (docs/controls.md). The files keep their keys (the
definition's `lo`/`hi`, the manifest's `min`/`max`); in memory both are `minimum`/`maximum`."""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from softdeca_train.paths import REPO_ROOT

DEFINITION = REPO_ROOT / "plugin" / "data" / "parameters.json"


@dataclass(frozen=True)
class ParameterSpec:
    """One material parameter: its closed range [minimum, maximum], default, scale, the element
    kind per-element values are given for, and (the physics' list only) its control range."""

    name: str
    default_value: float
    minimum: float
    maximum: float
    log_scale: bool = False  # sampled (and normalised) uniformly in log space
    unit: str = ""
    domain: str = "global"  # "global" or the physics' element kind ("soft_tet", "skin_point", ...)
    symbol: str = ""  # the paper's symbol
    description: str = ""
    control: tuple[float, float] | None = None  # the control range; None: not a control

    def __post_init__(self) -> None:
        lo, hi = self.minimum, self.maximum
        if not (np.isfinite([lo, hi, self.default_value]).all() and lo < hi):
            raise ValueError(f"parameter {self.name}: need finite minimum < maximum")
        if not lo <= self.default_value <= hi:
            raise ValueError(f"parameter {self.name}: default outside [{lo}, {hi}]")
        if self.log_scale and lo <= 0:
            raise ValueError(f"parameter {self.name}: log scale needs minimum > 0")

    @property
    def scale(self) -> str:
        """`log_scale` as the files spell it: "log" or "linear"."""
        return "log" if self.log_scale else "linear"

    @property
    def localisable(self) -> bool:
        """Per-region values are allowed for everything the physics defines per element."""
        return self.domain != "global"

    def narrowed(self, minimum: float, maximum: float) -> ParameterSpec:
        """This parameter over [minimum, maximum], its default clamped into that range."""
        default = min(max(self.default_value, minimum), maximum)
        return replace(self, minimum=minimum, maximum=maximum, default_value=default)

    def sample(self, rng: np.random.Generator, size: int | None = None) -> np.ndarray | float:
        """Uniform (or log-uniform) in [minimum, maximum]; exp(log(maximum)) may round past
        maximum, so the value is clipped into the range exactly."""
        lo, hi = self.minimum, self.maximum
        if self.log_scale:
            v = np.exp(rng.uniform(np.log(lo), np.log(hi), size))
        else:
            v = rng.uniform(lo, hi, size)
        clipped = np.clip(v, lo, hi)
        return clipped if size is not None else float(clipped)

    def normalise(self, value: np.ndarray | float) -> np.ndarray | float:
        """Map [minimum, maximum] to [0, 1] on the parameter's own scale (network inputs use
        this)."""
        if self.log_scale:
            lo, hi = np.log(self.minimum), np.log(self.maximum)
            return (np.log(value) - lo) / (hi - lo)
        return (np.asarray(value) - self.minimum) / (self.maximum - self.minimum)

    def manifest(self) -> dict[str, Any]:
        """The bundle manifest's entry (docs/bundle.md)."""
        return {
            "name": self.name,
            "symbol": self.symbol,
            "unit": self.unit,
            "default": self.default_value,
            "min": self.minimum,
            "max": self.maximum,
            "scale": self.scale,
            "domain": self.domain,
            "localisable": self.localisable,
            "description": self.description,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ParameterSpec:
        """An entry of parameters.json (`lo`/`hi`, `control`) or of a manifest (`min`/`max`)."""
        scale = d.get("scale", "linear")
        if scale not in ("linear", "log"):
            raise ValueError(f"parameter {d['name']}: scale must be linear or log, not {scale!r}")
        spec = cls(
            name=str(d["name"]),
            default_value=float(d["default"]),
            minimum=float(d["min"] if "min" in d else d["lo"]),
            maximum=float(d["max"] if "max" in d else d["hi"]),
            log_scale=scale == "log",
            unit=str(d.get("unit", "")),
            domain=str(d.get("domain", "global")),
            symbol=str(d.get("symbol", "")),
            description=str(d.get("description", "")),
        )
        c = d.get("control")
        if c is None:
            return spec
        lo, hi = float(c["lo"]), float(c["hi"])
        if not spec.minimum <= lo < hi <= spec.maximum:
            raise ValueError(f"{spec.name}: control range [{lo}, {hi}] outside the physics' range")
        return replace(spec, control=(lo, hi))


@dataclass(frozen=True)
class ParameterSet:
    specs: tuple[ParameterSpec, ...]

    @property
    def names(self) -> list[str]:
        return [s.name for s in self.specs]

    def defaults(self) -> np.ndarray:
        return np.array([s.default_value for s in self.specs])

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        """One parameter vector, each entry uniform or log-uniform in its range (Appendix A)."""
        return np.array([s.sample(rng) for s in self.specs])

    def controls(self) -> ParameterSet:
        """The controls only (what the models take), each over its control range with its
        default clamped into it."""
        out = []
        for s in self.specs:
            if s.control is not None:
                out.append(s.narrowed(*s.control))
        return ParameterSet(tuple(out))

    def validate(self, p: np.ndarray) -> None:
        p = np.asarray(p, dtype=np.float64)
        if p.shape[-1] != len(self.specs):
            raise ValueError(f"expected {len(self.specs)} parameters, got {p.shape[-1]}")
        if not np.isfinite(p).all():
            raise ValueError("parameter vector has NaN or infinity")
        for k, s in enumerate(self.specs):
            v = p[..., k]
            if np.any(v < s.minimum - 1e-9) or np.any(v > s.maximum + 1e-9):
                raise ValueError(
                    f"{s.name} out of range [{s.minimum}, {s.maximum}]: {np.ravel(v)[:3]}"
                )

    def check_values(self, values: dict[str, float]) -> None:
        """Named values (a command line's or a file's): each a known parameter within the
        range the physics accepts."""
        specs = {s.name: s for s in self.specs}
        for name, value in values.items():
            if name not in specs:
                raise ValueError(f"unknown parameter {name!r}; known: {', '.join(specs)}")
            s = specs[name]
            if not (s.minimum <= value <= s.maximum):
                raise ValueError(
                    f"parameter {name} = {value} outside its range [{s.minimum}, {s.maximum}]"
                )

    def normalise(self, p: np.ndarray) -> np.ndarray:
        return np.stack([s.normalise(p[..., k]) for k, s in enumerate(self.specs)], axis=-1)


@cache
def load_parameters(path: Path = DEFINITION) -> ParameterSet:
    if not path.is_file():
        raise FileNotFoundError(f"parameter definition not found: {path}")
    doc = json.loads(path.read_text())
    if doc.get("format") != "softdeca-parameters":
        raise ValueError(f"{path} is not a softdeca-parameters file")
    return ParameterSet(tuple(ParameterSpec.from_dict(p) for p in doc["parameters"]))
