"""The cases a control is measured on: unseen identities x expressions, each run through the
physics (φ†, the data's settings) and through a model bundle (its ONNX networks, as a host runs
them). Both take a Setting (controls/definitions.py) and return the skin S for every
expression of the case, so the gallery compares like with like."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from softdeca_train.controls.definitions import Setting
from softdeca_train.data.expressions import load_takes
from softdeca_train.models.reference import ReferenceAvatar
from softdeca_train.models.topology import from_template
from softdeca_train.template import Template
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import REGIONS, element_regions, region_labels

# Identity seeds of the gallery: datasets derive theirs from a SeedSequence of (dataset seed,
# 1, identity id), a 32-bit hash, so these small seeds name identities no dataset holds.
IDENTITY_SEEDS = (101, 202, 303)


def expressions(takes_folder: Path, take: str = "facial", count: int = 3) -> np.ndarray:
    """(count, 52) ARKit frames of a held-out take: the frame that opens the jaw most, the
    broadest smile and the strongest pucker (in that order, the first `count`)."""
    takes = {t.name: t for t in load_takes(takes_folder)}
    if take not in takes:
        raise ValueError(f"no take {take!r} in {takes_folder}")
    w = takes[take].weights.astype(np.float64)
    k = {n: ARKIT_BLENDSHAPES.index(n) for n in ARKIT_BLENDSHAPES}
    scores = (
        w[:, k["jawOpen"]],
        w[:, k["mouthSmileLeft"]] + w[:, k["mouthSmileRight"]],
        w[:, k["mouthPucker"]] + w[:, k["mouthFunnel"]],
    )
    if not 1 <= count <= len(scores):
        raise ValueError(f"expressions: count must be in 1..{len(scores)}")
    return np.stack([w[int(np.argmax(s))] for s in scores[:count]]).astype(np.float32)


@dataclass
class PhysicsCase:
    """One identity under the physics, with the expressions it is solved for."""

    template: Template
    identity: np.ndarray
    weights: np.ndarray  # (E, 52)
    level: int = 3
    tolerance: float = 1e-4
    max_iterations: int = 800
    tet_mesh: str = "carried"  # LhmConfig.tet_mesh

    @cached_property
    def head(self):  # -> HeadSimulation
        # the physics needs the compiled softdeca_native; the rest of the gallery does not
        from softdeca_train.lhm import LhmConfig
        from softdeca_train.sim import build_head_simulation

        cfg = LhmConfig(level=self.level, tet_mesh=self.tet_mesh)
        return build_head_simulation(self.template, self.identity, cfg)

    @cached_property
    def sim(self):  # -> native.Simulator
        import softdeca_native as native  # compiled with the plugin: see `head`

        return native.Simulator(
            self.head.mesh, tolerance=self.tolerance, max_iterations=self.max_iterations
        )

    @cached_property
    def blended(self) -> np.ndarray:
        return self.head.blend(self.weights)

    @cached_property
    def targets(self) -> np.ndarray:
        """S_t: the linear blendshapes (E, N_SKIN, 3)."""
        return self.blended[:, :N_SKIN].astype(np.float64)

    @cached_property
    def labels(self) -> np.ndarray:
        return region_labels(self.template)

    def with_weights(self, weights: np.ndarray) -> PhysicsCase:
        """The same identity (head and simulator shared) with other expressions."""
        other = replace(self, weights=weights)
        other.__dict__.update(head=self.head, sim=self.sim, labels=self.labels)
        return other

    def element_regions(self, domain: str) -> np.ndarray:
        return element_regions(self.labels, self.head.mesh, self.head.head[:N_SKIN], domain)

    def solve(self, setting: Setting, defaults: dict[str, float], domains: dict[str, str]):
        """(E, N_SKIN, 3) simulated skin for every expression under `setting`."""
        sim = self.sim
        for name, value in {**defaults, **setting.globals}.items():
            sim.set_parameter(name, float(value))
        if setting.local is not None:
            name, region, value = setting.local
            where = self.element_regions(domains[name]) == REGIONS.index(region)
            field = np.full(len(where), float({**defaults, **setting.globals}[name]))
            field[where] = value
            sim.set_parameter_field(name, field)
        jaw = self.head.jaw_transforms(self.blended)
        skin, _, _ = sim.solve_static_batch(self.targets, jaw=jaw)
        return np.asarray(skin, np.float64)


class ModelCase:
    """The same identity and expressions through a bundle's networks (ReferenceAvatar: the
    runtime's rules in Python). Values outside the bundle's ranges are clamped into them (the
    runtime refuses them); `clamped` records which parameters were."""

    def __init__(self, networks, case: PhysicsCase) -> None:  # networks: OnnxNetworks
        t = case.template
        self.case = case
        self.nets = networks
        self.avatar = ReferenceAvatar(
            networks, from_template(t), t.identity_neutral(case.identity), t.triangles
        )
        self.specs = {s.name: s for s in networks.specs}
        self.clamped: set[str] = set()

    def _value(self, name: str, value: float) -> float:
        s = self.specs[name]
        v = min(max(value, s.minimum), s.maximum)
        if v != value:
            self.clamped.add(name)
        return v

    def use(self, case: PhysicsCase) -> None:
        """Other expressions of the same identity (PhysicsCase.with_weights)."""
        if case.identity is not self.case.identity:
            raise ValueError("a model case keeps its identity")
        self.case = case

    def solve(self, setting: Setting) -> np.ndarray:
        params = self.avatar.params
        for s in self.nets.specs:
            params.set_global(s.name, s.default_value)
        for name, value in setting.globals.items():
            if name in self.specs:
                params.set_global(name, self._value(name, value))
        if setting.local is not None and setting.local[0] in self.specs:
            # A region is a set of skin vertices (region_labels), as the physics and the
            # training data read it: the model gets it as a vertex map.
            name, region, value = setting.local
            field = params.vertex_matrix([name])[:, 0].copy()
            field[self.case.labels == REGIONS.index(region)] = self._value(name, value)
            params.set_vertices(name, field)
        self.avatar.prepare()
        return np.stack(
            [
                self.avatar.softdeca_static(w, s)
                for w, s in zip(self.case.weights, self.case.targets, strict=True)
            ]
        )
