"""Smoothed copies of a per-vertex field on the template's skin, at a few spatial scales.

A material change in one region moves the skin around it too (swollen cheeks push on the
nose and lips), so a vertex's offset depends on the parameters near it, not only on its own.
The vertex stage therefore also sees each localisable parameter averaged over a neighbourhood
of the vertex (Gaussian, σ per scale). The averaging is fixed geometry of the template at rest,
so it lives inside the exported graph as gathers over two small index tables per scale: the
field is sampled at points spread evenly over the skin, averaged around centres, and the
centres are blended back onto every vertex. A constant field stays constant (both steps are
normalised averages)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import torch
from scipy.spatial import cKDTree
from torch import nn

# σ of the default scales in metres: about a region's half width, and a neighbour's reach.
DEFAULT_SCALES = (0.015, 0.04)
SAMPLE_SPACING = 0.006  # metres between the points the field is sampled at
CENTRE_SPACING = 1.0  # centres every σ
SUPPORT = 2.5  # a centre averages the samples within SUPPORT x σ
CENTRES_PER_VERTEX = 8


def farthest_points(points: np.ndarray, spacing: float, start: int = 0) -> np.ndarray:
    """Indices of points spread evenly: greedily the farthest from those taken, until every
    point is within `spacing` of one (deterministic: starts at `start`)."""
    taken = [start]
    dist = np.linalg.norm(points - points[start], axis=1)
    while dist.max() > spacing:
        i = int(dist.argmax())
        taken.append(i)
        dist = np.minimum(dist, np.linalg.norm(points - points[i], axis=1))
    return np.asarray(taken, np.int64)


@dataclass(frozen=True)
class ScaleTables:
    """One scale's gathers: centre m = Σ_j centre_weights[m, j] f[centre_samples[m, j]], then
    vertex v = Σ_k vertex_weights[v, k] centre[vertex_centres[v, k]] (rows sum to 1; padding
    has weight 0)."""

    centre_samples: np.ndarray  # (M, N) int64, vertex indices
    centre_weights: np.ndarray  # (M, N) float32
    vertex_centres: np.ndarray  # (V, K) int64
    vertex_weights: np.ndarray  # (V, K) float32


def _gaussian(d: np.ndarray, sigma: float) -> np.ndarray:
    return np.exp(-0.5 * (d / sigma) ** 2)


def scale_tables(rest: np.ndarray, sigma: float, samples: np.ndarray) -> ScaleTables:
    """The gathers of one scale over skin positions `rest` (V, 3) and sample vertices."""
    if sigma <= 0:
        raise ValueError("a smoothing scale must be positive")
    rest = np.asarray(rest, np.float64)
    pts = rest[samples]
    centres = samples[farthest_points(pts, CENTRE_SPACING * sigma)]
    near = cKDTree(pts).query_ball_point(rest[centres], SUPPORT * sigma)
    n = max(len(j) for j in near)
    c_idx = np.zeros((len(centres), n), np.int64)
    c_w = np.zeros((len(centres), n), np.float64)
    for m, j in enumerate(near):
        j = np.asarray(j, np.int64)
        c_idx[m, : len(j)] = samples[j]
        c_w[m, : len(j)] = _gaussian(np.linalg.norm(pts[j] - rest[centres[m]], axis=1), sigma)
    c_w /= c_w.sum(axis=1, keepdims=True)
    k = min(CENTRES_PER_VERTEX, len(centres))
    d, v_idx = cKDTree(rest[centres]).query(rest, k=k)
    d, v_idx = d.reshape(len(rest), k), v_idx.reshape(len(rest), k)
    v_w = _gaussian(d, sigma)
    v_w /= v_w.sum(axis=1, keepdims=True)
    return ScaleTables(
        c_idx, c_w.astype(np.float32), v_idx.astype(np.int64), v_w.astype(np.float32)
    )


class FieldSmoothing(nn.Module):
    """(V, C) field -> (V, C x scales): the field averaged at each scale (tables as buffers,
    so they are saved with the model and exported as constants of the graph)."""

    def __init__(self, rest: np.ndarray, scales: Sequence[float] = DEFAULT_SCALES) -> None:
        super().__init__()
        rest = np.asarray(rest, np.float64)
        if rest.ndim != 2 or rest.shape[1] != 3 or not np.isfinite(rest).all():
            raise ValueError("smoothing needs finite rest positions (V, 3)")
        samples = farthest_points(rest, SAMPLE_SPACING)
        self.scales = tuple(float(s) for s in scales)
        for i, sigma in enumerate(self.scales):
            t = scale_tables(rest, sigma, samples)
            self.register_buffer(f"centre_samples_{i}", torch.from_numpy(t.centre_samples))
            self.register_buffer(f"centre_weights_{i}", torch.from_numpy(t.centre_weights))
            self.register_buffer(f"vertex_centres_{i}", torch.from_numpy(t.vertex_centres))
            self.register_buffer(f"vertex_weights_{i}", torch.from_numpy(t.vertex_weights))

    def forward(self, field: torch.Tensor) -> torch.Tensor:
        out = []
        for i in range(len(self.scales)):
            idx, w = getattr(self, f"centre_samples_{i}"), getattr(self, f"centre_weights_{i}")
            centre = (field[idx] * w[..., None].to(field.dtype)).sum(dim=1)  # (M, C)
            idx, w = getattr(self, f"vertex_centres_{i}"), getattr(self, f"vertex_weights_{i}")
            out.append((centre[idx] * w[..., None].to(field.dtype)).sum(dim=1))  # (V, C)
        return torch.cat(out, dim=1)
