"""A test avatar in memory (AvatarMesh) and its ground truth (AvatarTruth, `truth.npz`).

The truth says, for every avatar vertex, the point of the source mesh it sits on (ICT's head,
`Template.triangles`, or ARKit's reference face, `ArkitFace.triangles`): a triangle and its
barycentric coordinates, so a quantity computed on the template path can be compared with the
avatar's at the same surface points. It also holds the similarity from the template's frame
(metres, +Y up, +Z out of the face, +X the subject's left) to the avatar's, which shapes the
avatar has and under which names, and which vertices are skin, eyes, teeth, ICT's other inner
parts or body."""

from __future__ import annotations

import json
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

# Vertex parts, the values of AvatarTruth.part. "inner": ICT's gums and tongue, lacrimal fluid,
# eye blend and occlusion meshes and eyelashes (in the whole-head layout; the gums and tongue
# alone with eyes_teeth_tongue); "hair": hair cards and the eyebrow fins' tips.
PARTS = ("skin", "eyes", "teeth", "inner", "body", "hair")
SOURCES = ("ict", "arkit")
TRUTH_FORMAT = 1


@dataclass(frozen=True)
class AvatarTruth:
    """avatar point = linear @ template point + translation, linear = rotation @ mirror /
    metres_per_unit (mirror: diag(-1, 1, 1) when set, else the identity)."""

    source: str  # "ict": rows of Template.triangles; "arkit": rows of ArkitFace.triangles
    triangle: np.ndarray  # (N,) int64, the source triangle each vertex sits on; -1: body, hair
    bary: np.ndarray  # (N, 3) float64, its barycentric coordinates there (0 for the body)
    corners: np.ndarray  # (N, 3) int64, that triangle's source vertices; -1: body
    source_vertex: np.ndarray  # (N,) int64, the source vertex it is, -1 where none
    part: np.ndarray  # (N,) int8, index into PARTS
    order: np.ndarray  # (N,) int64: vertex i was vertex order[i] before the shuffle
    metres_per_unit: float
    rotation: np.ndarray  # (3, 3) proper rotation
    mirror: bool  # x negated (a left-handed export) before the rotation
    translation: np.ndarray  # (3,) in avatar units
    identity: str  # the identity label, or "ARKit reference face"
    identity_coefficients: np.ndarray  # (100,) ICT identity coefficients, (0,) for none
    present: np.ndarray  # (52,) bool, canonical ARKit order
    names: tuple[str, ...]  # 52 rig names, "" where the shape is absent
    config: str  # the AvatarConfig as JSON

    @property
    def linear(self) -> np.ndarray:
        m = np.diag([-1.0 if self.mirror else 1.0, 1.0, 1.0])
        return self.rotation @ m / self.metres_per_unit

    def to_avatar(self, points: np.ndarray, direction: bool = False) -> np.ndarray:
        """Template-frame metres (..., 3) in the avatar's unit and axes; `direction`: no
        translation (shape deltas, normals)."""
        out = np.asarray(points, dtype=np.float64) @ self.linear.T
        return out if direction else out + self.translation

    def to_template(self, points: np.ndarray, direction: bool = False) -> np.ndarray:
        """The inverse of to_avatar."""
        p = np.asarray(points, dtype=np.float64)
        p = p if direction else p - self.translation
        return p @ np.linalg.inv(self.linear).T

    def evaluate(self, values: np.ndarray) -> np.ndarray:
        """A per-vertex quantity of the source mesh (V, ...) at the avatar's vertices: (N, ...),
        NaN on the body (no source point)."""
        v = np.asarray(values, dtype=np.float64)
        out = np.einsum("kj,kj...->k...", self.bary, v[np.maximum(self.corners, 0)])
        out[self.triangle < 0] = np.nan
        return out

    def part_mask(self, *names: str) -> np.ndarray:
        return np.isin(self.part, [PARTS.index(n) for n in names])

    def save(self, path: Path) -> Path:
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        data["names"] = np.array(self.names)
        np.savez_compressed(path, format=TRUTH_FORMAT, parts=np.array(PARTS), **data)
        return path

    @classmethod
    def load(cls, path: Path) -> AvatarTruth:
        with np.load(path) as z:
            if int(z["format"]) != TRUTH_FORMAT:
                raise ValueError(f"{path}: truth format {int(z['format'])}, not {TRUTH_FORMAT}")
            data = {f.name: z[f.name] for f in fields(cls)}
        for key in ("source", "identity", "config"):
            data[key] = str(data[key])
        data["metres_per_unit"] = float(data["metres_per_unit"])
        data["mirror"] = bool(data["mirror"])
        data["names"] = tuple(str(n) for n in data["names"])
        return cls(**data)

    def config_dict(self) -> dict:
        return json.loads(self.config)


@dataclass(frozen=True)
class AvatarMesh:
    """A test avatar: its neutral mesh, its shapes as deltas in ARKit's canonical order (zeros
    for an absent shape), its objects and its truth. Units and axes are the avatar's."""

    neutral: np.ndarray  # (N, 3) float64
    triangles: np.ndarray  # (F, 3) int32
    deltas: np.ndarray  # (52, N, 3) float64
    groups: tuple[tuple[str, int], ...]  # objects (name, triangle count), in triangle order
    truth: AvatarTruth

    @property
    def names(self) -> tuple[str, ...]:
        return self.truth.names

    @property
    def present(self) -> np.ndarray:
        return self.truth.present

    def shapes(self) -> dict[str, np.ndarray]:
        """The present shapes as whole meshes, by their rig names (what a rig's file holds)."""
        return {self.names[i]: self.neutral + self.deltas[i] for i in np.flatnonzero(self.present)}
