"""Material parameter specs as the model bundle carries them, and each avatar's parameter
state: a global value, a per-face map or a per-vertex map per parameter, turned into the
per-element inputs of the hypernetworks by the localisation rules of docs/bundle.md. The rules
are the native library's (plugin/src/prepare/parameters.h), called through softdeca_native
where a map reaches the other kind of element."""

from __future__ import annotations

import copy
import json
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from softdeca_train.models.synthetic import TEST_PARAMETERS
from softdeca_train.paths import REPO_ROOT

# The one list of parameters (the physics'). The exporter reads it when present.
PARAMETERS_JSON = REPO_ROOT / "plugin" / "data" / "parameters.json"

Scale = Literal["linear", "log"]


@dataclass(frozen=True)
class ParameterSpec:
    """One material parameter: its range, default and whether it may vary over the face."""

    name: str
    default: float
    min: float
    max: float
    scale: Scale = "linear"
    unit: str = ""
    domain: str = "global"  # the physics' element kind ("global", "soft_tet", "skin_point", ...)
    symbol: str = ""
    description: str = ""

    def __post_init__(self) -> None:
        if not (np.isfinite([self.min, self.max, self.default]).all() and self.min < self.max):
            raise ValueError(f"parameter {self.name}: need finite min < max")
        if not self.min <= self.default <= self.max:
            raise ValueError(f"parameter {self.name}: default outside [min, max]")
        if self.scale not in ("linear", "log"):
            raise ValueError(f"parameter {self.name}: scale must be linear or log")
        if self.scale == "log" and self.min <= 0:
            raise ValueError(f"parameter {self.name}: log scale needs min > 0")

    @property
    def localisable(self) -> bool:
        """Per-region values are allowed for everything the physics defines per element."""
        return self.domain != "global"

    def manifest(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "symbol": self.symbol,
            "unit": self.unit,
            "default": self.default,
            "min": self.min,
            "max": self.max,
            "scale": self.scale,
            "domain": self.domain,
            "localisable": self.localisable,
            "description": self.description,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ParameterSpec:
        """Accepts the physics' parameters.json entries (lo/hi) and manifest entries (min/max)."""
        lo = d["min"] if "min" in d else d["lo"]
        hi = d["max"] if "max" in d else d["hi"]
        return cls(
            name=str(d["name"]),
            default=float(d["default"]),
            min=float(lo),
            max=float(hi),
            scale=d.get("scale", "linear"),
            unit=str(d.get("unit", "")),
            domain=str(d.get("domain", "global")),
            symbol=str(d.get("symbol", "")),
            description=str(d.get("description", "")),
        )


def load_parameter_specs(
    source: str | os.PathLike[str] | Sequence[ParameterSpec | dict[str, Any]] | None = None,
    controls_only: bool = False,
) -> tuple[ParameterSpec, ...]:
    """Parameter specs from a parameters.json file, a list of specs or dicts, or (None) the
    repository's plugin/data/parameters.json. `controls_only`: leave out the entries marked as
    no control (`"control": null`: they act on nothing in the head model)."""
    if source is None:
        if not PARAMETERS_JSON.is_file():
            raise FileNotFoundError(
                f"{PARAMETERS_JSON} does not exist; pass a parameter list or a file in its format"
            )
        source = PARAMETERS_JSON
    if isinstance(source, (str, os.PathLike)):
        doc = json.loads(Path(source).read_text())
        entries = doc["parameters"] if isinstance(doc, dict) else doc
        if controls_only:
            entries = [e for e in entries if not ("control" in e and e["control"] is None)]
        specs = tuple(ParameterSpec.from_dict(e) for e in entries)
    else:
        specs = tuple(
            s if isinstance(s, ParameterSpec) else ParameterSpec.from_dict(s) for s in source
        )
    names = [s.name for s in specs]
    if len(set(names)) != len(names) or not specs:
        raise ValueError("parameter names must be unique and at least one is needed")
    return specs


def specs_or_test_list(source: str | None) -> tuple[ParameterSpec, ...]:
    """For tools that must run before the physics' list exists: `source`, else the controls
    of plugin/data/parameters.json, else (with a note on stderr) the 5-parameter test list."""
    if source is None and not PARAMETERS_JSON.is_file():
        print(
            f"note: {PARAMETERS_JSON} is missing: using the 5-parameter test list", file=sys.stderr
        )
        return load_parameter_specs(TEST_PARAMETERS)
    return load_parameter_specs(source, controls_only=True)


@dataclass
class _Value:
    kind: Literal["global", "faces", "vertices"]
    data: np.ndarray | float


class ParameterState:
    """Per avatar: every parameter is a global value, a map over the skin triangles, or a map
    over the skin vertices. `face_matrix` / `vertex_matrix` give the hypernetworks' inputs:
    a face map reaches vertices as the area-weighted mean of the incident faces (neutral
    areas); a vertex map reaches faces as the mean of the three corners (the library's rules,
    softdeca_native.localise_to_vertices / localise_to_faces)."""

    def __init__(
        self, specs: Sequence[ParameterSpec], triangles: np.ndarray, face_areas: np.ndarray
    ) -> None:
        self.specs = tuple(specs)
        self.triangles = np.asarray(triangles, dtype=np.int64)
        self.n_vertices = int(self.triangles.max()) + 1 if len(self.triangles) else 0
        self.face_areas = np.asarray(face_areas, dtype=np.float64)
        self._values = [_Value("global", s.default) for s in self.specs]

    def index(self, name: str) -> int:
        for i, s in enumerate(self.specs):
            if s.name == name:
                return i
        raise KeyError(f"unknown parameter {name!r}")

    def _check(self, i: int, values: np.ndarray) -> None:
        s = self.specs[i]
        if not np.isfinite(values).all():
            raise ValueError(f"{s.name}: values must be finite")
        if (values < s.min).any() or (values > s.max).any():
            raise ValueError(f"{s.name}: values outside [{s.min}, {s.max}]")

    def set_global(self, name: str, value: float) -> None:
        i = self.index(name)
        self._check(i, np.array([value]))
        self._values[i] = _Value("global", float(value))

    def set_faces(self, name: str, values: np.ndarray) -> None:
        i = self.index(name)
        v = np.asarray(values, dtype=np.float64)
        if v.shape != (len(self.triangles),):
            raise ValueError(f"{name}: expected {len(self.triangles)} face values")
        if not self.specs[i].localisable:
            raise ValueError(f"{name} is global and cannot vary over the face")
        self._check(i, v)
        self._values[i] = _Value("faces", v.copy())

    def set_vertices(self, name: str, values: np.ndarray) -> None:
        i = self.index(name)
        v = np.asarray(values, dtype=np.float64)
        if v.shape != (self.n_vertices,):
            raise ValueError(f"{name}: expected {self.n_vertices} vertex values")
        if not self.specs[i].localisable:
            raise ValueError(f"{name} is global and cannot vary over the face")
        self._check(i, v)
        self._values[i] = _Value("vertices", v.copy())

    def _column(self, value: _Value, on: Literal["faces", "vertices"]) -> np.ndarray:
        n = len(self.triangles) if on == "faces" else self.n_vertices
        if value.kind == "global":
            return np.full(n, float(value.data))
        data = np.asarray(value.data)
        if value.kind == on:
            return data
        # A map on the other kind of element: the library's rules. Reading a bundle and
        # training with global values need no compiled softdeca_native.
        import softdeca_native as native

        if on == "faces":
            return native.localise_to_faces(data, self.triangles)
        return native.localise_to_vertices(data, self.triangles, self.face_areas, self.n_vertices)

    def with_defaults(self, names: Sequence[str] | None = None) -> ParameterState:
        """A copy with the named parameters (default: all) back at their global defaults."""
        out = copy.copy(self)
        out._values = [
            _Value("global", s.default) if names is None or s.name in names else v
            for v, s in zip(self._values, self.specs, strict=True)
        ]
        return out

    def at_defaults(self) -> bool:
        """Every parameter a global value at its default."""
        return all(
            v.kind == "global" and float(v.data) == s.default  # type: ignore[arg-type]
            for v, s in zip(self._values, self.specs, strict=True)
        )

    def face_matrix(self, names: Sequence[str] | None = None) -> np.ndarray:
        """(F, P) raw values, columns in `names` order (default: all specs)."""
        idx = [self.index(n) for n in names] if names is not None else range(len(self.specs))
        return np.stack([self._column(self._values[i], "faces") for i in idx], axis=1)

    def vertex_matrix(self, names: Sequence[str] | None = None) -> np.ndarray:
        idx = [self.index(n) for n in names] if names is not None else range(len(self.specs))
        return np.stack([self._column(self._values[i], "vertices") for i in idx], axis=1)
