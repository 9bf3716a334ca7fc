"""The parameter specs a model takes (softdeca_train.parameters.ParameterSpec, from a list or a
file), and each avatar's parameter state: a global value, a per-face map or a per-vertex map per
parameter, turned into the per-element inputs of the hypernetworks by the localisation rules of
docs/bundle.md. The rules are the native library's (plugin/src/prepare/parameters.h), called
through softdeca_native where a map reaches the other kind of element."""

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
from softdeca_train.parameters import DEFINITION, ParameterSpec


def load_parameter_specs(
    source: str | os.PathLike[str] | Sequence[ParameterSpec | dict[str, Any]] | None = None,
    controls_only: bool = False,
) -> tuple[ParameterSpec, ...]:
    """Parameter specs from a parameters.json file, a list of specs or dicts, or (None) the
    repository's plugin/data/parameters.json. `controls_only`: leave out the entries marked as
    no control (`"control": null`: they act on nothing in the head model)."""
    if source is None:
        if not DEFINITION.is_file():
            raise FileNotFoundError(
                f"{DEFINITION} does not exist; pass a parameter list or a file in its format"
            )
        source = DEFINITION
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
    if source is None and not DEFINITION.is_file():
        print(f"note: {DEFINITION} is missing: using the 5-parameter test list", file=sys.stderr)
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
        self._values = [_Value("global", s.default_value) for s in self.specs]

    def index(self, name: str) -> int:
        for i, s in enumerate(self.specs):
            if s.name == name:
                return i
        raise KeyError(f"unknown parameter {name!r}")

    def _check(self, i: int, values: np.ndarray) -> None:
        s = self.specs[i]
        if not np.isfinite(values).all():
            raise ValueError(f"{s.name}: values must be finite")
        if (values < s.minimum).any() or (values > s.maximum).any():
            raise ValueError(f"{s.name}: values outside [{s.minimum}, {s.maximum}]")

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
            _Value("global", s.default_value) if names is None or s.name in names else v
            for v, s in zip(self._values, self.specs, strict=True)
        ]
        return out

    def at_defaults(self) -> bool:
        """Every parameter a global value at its default."""
        return all(
            v.kind == "global" and float(v.data) == s.default_value  # type: ignore[arg-type]
            for v, s in zip(self._values, self.specs, strict=True)
        )

    def face_matrix(self, names: Sequence[str] | None = None) -> np.ndarray:
        """(F, P) raw values, columns in `names` order (default: all specs)."""
        idx = [self.index(n) for n in names] if names is not None else range(len(self.specs))
        return np.stack([self._column(self._values[i], "faces") for i in idx], axis=1)

    def vertex_matrix(self, names: Sequence[str] | None = None) -> np.ndarray:
        idx = [self.index(n) for n in names] if names is not None else range(len(self.specs))
        return np.stack([self._column(self._values[i], "vertices") for i in idx], axis=1)
