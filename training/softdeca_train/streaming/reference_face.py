"""ARKit's reference face for streams: real blendshape weights drive realistic landmark streams
through it (geometry = neutral + sum_i w_i (shape_i - neutral)). The one reader of that data,
softdeca_train.landmarks.arkit_reference.ArkitFace, extended with blending of chosen vertices
and the landmark profiles a stream can name."""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from softdeca_train.landmarks.arkit_reference import ArkitFace
from softdeca_train.landmarks.definition import load_definition
from softdeca_train.streaming.protocol import Profile

# "softdeca149": SparseSoftDECA's contour landmarks (plugin/data/landmarks.json);
# "arkit68": the standard 68-point scheme's vertices; "none": no landmarks.
PROFILES = ("softdeca149", "arkit68", "none")


@dataclass(frozen=True)
class ReferenceFace(ArkitFace):
    @classmethod
    def load(cls, path: str | os.PathLike[str] | None = None) -> ReferenceFace:
        face = super().load(path)
        assert isinstance(face, ReferenceFace)
        return face

    def blend(self, weights: np.ndarray, vertices: np.ndarray | None = None) -> np.ndarray:
        """neutral + sum_i w_i delta_i, for all vertices or the given ones."""
        w = np.asarray(weights, dtype=np.float64)
        if vertices is None:
            return self.neutral + np.tensordot(w, self.deltas, axes=1)
        idx = np.asarray(vertices)
        return self.neutral[idx] + np.tensordot(w, self.deltas[:, idx], axes=1)

    def profile(self, name: str) -> Profile | None:
        """A landmark profile by name (see PROFILES)."""
        if name == "softdeca149":
            return Profile("softdeca149", tuple(int(i) for i in load_definition().vertices))
        if name == "arkit68":
            return Profile("arkit68", tuple(int(i) for i in self.landmarks68))
        if name == "none":
            return None
        raise ValueError(f"unknown landmark profile {name!r} (known: {', '.join(PROFILES)})")
