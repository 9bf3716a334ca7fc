"""The physics column of a replay's contact sheet: φ† itself (static, default parameters,
collisions on) on the shown frames of the take, for the identity the avatar was made from, so
that the picture shows what the networks were trained to reproduce next to what they produce.

The shown frames include the take's widest-open mouth (of the linear blendshapes), where the
physics has to keep the lips apart as the linear blend has them, and the lip opening (inner
middles of the upper and lower lip) of every column is measured there.

A replay's parameter changes (`--set`, `--localised`: 'name=value[@x,y,z,r];...') reach the
physics as they reach the runtime: a ball covers the skin faces whose centroid on the avatar's
neutral lies in it, the face map reaches the skin vertices as the area-weighted mean of their
faces, and a tet takes the value of the skin vertex nearest its centroid
(models/rest_physics.py), so the physics of a localised change is the truth its SoftDECA column
is measured against."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softdeca_train.lhm import LhmConfig
from softdeca_train.models.dt import face_geometry
from softdeca_train.models.parameters import ParameterState
from softdeca_train.models.rest_physics import element_values
from softdeca_train.parameters import ParameterSpec
from softdeca_train.sim import sanity
from softdeca_train.sim.head import build_head_simulation
from softdeca_train.sim.run import simulate_frames
from softdeca_train.sim.take import read_take
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import mesh_tet_skin_vertices

if TYPE_CHECKING:
    from softdeca_train.sim.head import HeadSimulation

# Linear blends of the replay and of the simulation must agree to this (m): the avatar was
# made from the identity the physics simulates, else the columns compare different faces.
SAME_FACE_TOLERANCE = 1e-4


@dataclass(frozen=True)
class Change:
    """One replay parameter change: `value` a number or the bundle's 'min', 'max', 'default';
    `ball` (x, y, z, r) in metres on the avatar, or None for the whole head."""

    name: str
    value: str
    ball: tuple[float, float, float, float] | None = None


def parse_changes(text: str) -> list[Change]:
    """The replay CLI's 'name=value[@x,y,z,r];...' (plugin/cli/cmd_replay.cpp)."""
    out = []
    for item in filter(None, (t.strip() for t in text.split(";"))):
        name, eq, rest = item.partition("=")
        value, at, where = rest.partition("@")
        if not eq or not name or not value:
            raise ValueError(f"expected name=value[@x,y,z,r], got {item!r}")
        if value not in ("min", "max", "default"):
            float(value)  # a number, else ValueError names it
        ball = None
        if at:
            numbers = [float(x) for x in where.split(",")]
            if len(numbers) != 4 or numbers[3] <= 0:
                raise ValueError(f"a region needs x,y,z,r with r > 0, got {item!r}")
            ball = (numbers[0], numbers[1], numbers[2], numbers[3])
        out.append(Change(name, value, ball))
    return out


def _resolved(spec: ParameterSpec, value: str) -> float:
    bounds = {"min": spec.minimum, "max": spec.maximum, "default": spec.default_value}
    return float(bounds[value]) if value in bounds else float(value)


def parameter_fields(
    hs: HeadSimulation, specs: Sequence[ParameterSpec], changes: Sequence[Change]
) -> dict[str, float | np.ndarray]:
    """Every parameter's value for `hs`'s simulator after `changes` (applied in order on top of
    the defaults): a number, or one value per element of the parameter's domain."""
    skin = np.asarray(hs.head[:N_SKIN], np.float64)
    faces = np.asarray(hs.mesh.skin_triangles, np.int64)
    params = ParameterState(specs, faces, face_geometry(skin, faces)[0])
    centroids = skin[faces].mean(axis=1)
    for c in changes:
        spec = specs[params.index(c.name)]
        value = _resolved(spec, c.value)
        if c.ball is None:
            params.set_global(c.name, value)
            continue
        current = params.face_matrix([c.name])[:, 0]
        inside = np.linalg.norm(centroids - np.asarray(c.ball[:3]), axis=1) <= c.ball[3]
        params.set_faces(c.name, np.where(inside, value, current))
    tet_vertex = mesh_tet_skin_vertices(hs.mesh, skin)
    out: dict[str, float | np.ndarray] = {}
    for spec in specs:
        values = element_values(tet_vertex, params, spec.name, spec.domain)
        out[spec.name] = float(params.face_matrix([spec.name])[0, 0]) if values is None else values
    return out


@dataclass(frozen=True)
class PhysicsColumn:
    heads: np.ndarray  # (len(frames), V, 3) whole heads from φ†
    failures: list[list[str]]  # the sanity bounds' reasons per frame (empty: passes)
    seconds: float


def lip_openings_mm(heads: np.ndarray, template: Template) -> np.ndarray:
    """(F, V, 3) heads in template order -> (F,) signed inner-lip-middle distances in mm."""
    return sanity.lip_openings_mm(template.landmarks68, heads)


def widest_open_frame(linear: np.ndarray, template: Template) -> int:
    return int(np.argmax(lip_openings_mm(linear, template)))


def simulate_column(
    take: Path,
    first_frame: int,
    frames: list[int],
    linear: np.ndarray,
    template: Template,
    seed: int,
    settings: Sequence[Sequence[Change]] = ((),),
    specs: Sequence[ParameterSpec] = (),
    level: int = 3,
) -> list[PhysicsColumn]:
    """φ† on frames `frames` (indices into the replay, whose frame 0 is the take's tracked
    frame `first_frame`) for ICT identity `seed`, one column per entry of `settings` (the
    changes on top of the defaults of `specs`, the bundle's parameters); `linear` is the
    replay's linear cache, the check that the avatar is that identity."""

    t0 = time.perf_counter()
    weights = np.stack([read_take(take, first_frame + f, 1).weights[0] for f in frames])
    hs = build_head_simulation(template, template.sample_identity(seed), LhmConfig(level=level))
    ours = hs.blend(weights)
    if ours.shape != linear[frames].shape:
        raise ValueError(
            f"the replay's heads have {linear.shape[1]} vertices, the simulated identity "
            f"{ours.shape[1]}: not the same head model"
        )
    off = float(np.abs(ours - linear[frames]).max())
    if off > SAME_FACE_TOLERANCE:
        raise ValueError(
            f"the replay's linear blendshapes differ from identity seed {seed}'s by "
            f"{1e3 * off:.2f} mm: the avatar was not made from that identity"
        )
    columns = []
    for changes in settings:
        sim = hs.simulator(threads=1)  # the physics' own defaults, unless changed
        fields = parameter_fields(hs, specs, changes) if changes else {}
        for name, value in fields.items():
            if isinstance(value, float):
                sim.set_parameter(name, value)
            else:
                sim.set_parameter_field(name, value)
        result = simulate_frames(hs, sim, weights, progress=False)
        columns.append(
            PhysicsColumn(
                heads=np.stack(result.physics),
                failures=[r.failures for r in result.records],
                seconds=time.perf_counter() - t0,
            )
        )
        t0 = time.perf_counter()
    return columns
