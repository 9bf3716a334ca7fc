"""Pieces the bundle's networks share (models/networks.py, models/residual.py): the layer
widths, the parameters' normalisation, the gravity load of a parameter vector and averages
over the regions of S."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from softdeca_train.parameters import ParameterSpec


@dataclass(frozen=True)
class NetworkSizes:
    """Layer widths. `latent` is the 32 of the paper; the rest are ours (Appendix D is lost)."""

    latent: int = 32
    identity: int = 100
    f_w_hidden: tuple[int, ...] = (128, 128)
    f_l_hidden: tuple[int, ...] = (256, 256)
    hyper_hidden: tuple[int, ...] = (128, 128)
    dynamics_hidden: tuple[int, ...] = (32,)
    positional: int = 32
    encoder_points: int = 1024
    encoder_hidden: tuple[int, ...] = (256,)
    # SoftDECA's residual stage (models/residual.py): modes besides the mean, the members'
    # width and count, and the steps each member trains
    residual_modes: int = 31
    residual_hidden: int = 256
    residual_members: int = 5
    residual_steps: int = 3000
    # SoftDECA at rest (rest_gate): None, the correction is g(w) with a constant part (bundles
    # trained before); a number tau, exact at rest by construction: every network of w gives
    # g(w) - g(0), and the part that does not depend on w is scaled by |w|^2 / (|w|^2 + tau^2),
    # 0 at rest (tau = 0: left out).
    rest_gate: float | None = None
    # SoftDECA's vertex stage reads each region's mean of the localisable parameters (LocalLinear
    # `regions`). Trained on the rest physics (`rest_changes`) it does not: the physics at
    # prepare gives a region's far-reaching rest response exactly, and what is left for these
    # inputs is fitted noise (measured on the same frames: the region controls' response errors
    # 0.16-0.61 with them, 0.10-0.51 without; docs/training.md).
    region_means: bool = True


def rest_gate(weights: torch.Tensor, tau: float | None) -> torch.Tensor:
    """(B, 1): the share of SoftDECA's w-independent correction a frame gets (NetworkSizes.
    rest_gate): 1 without a gate; |w|^2 / (|w|^2 + tau^2), exactly 0 at rest, with one."""
    if tau is None:
        return torch.ones_like(weights[:, :1])
    if tau == 0:
        return torch.zeros_like(weights[:, :1])
    s = (weights * weights).sum(dim=1, keepdim=True)
    return s / (s + tau * tau)


class Normalise(nn.Module):
    """Raw parameter values -> [-1, 1] (log scale where the spec says so)."""

    def __init__(self, specs: Sequence[ParameterSpec]) -> None:
        super().__init__()
        log = torch.tensor([s.log_scale for s in specs])
        lo = torch.tensor([np.log(s.minimum) if s.log_scale else s.minimum for s in specs])
        hi = torch.tensor([np.log(s.maximum) if s.log_scale else s.maximum for s in specs])
        self.register_buffer("log", log)
        self.register_buffer("lo", lo.float())
        self.register_buffer("span", (hi - lo).float())

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        x = torch.where(self.log, torch.log(torch.clamp(x, min=1e-30)), x)
        return 2.0 * (x - self.lo) / self.span - 1.0


# The gravity load of a parameter vector: s d - d0 in g, d the direction of the strength s,
# tilt and azimuth (degrees), d0 the capture's own load (1 g along -Y); the simulator's
# gravity_forces and linear_baseline.ParameterScaling.gravity_load use the same.
GRAVITY_COLUMNS = ("gravity_strength", "gravity_tilt", "gravity_azimuth")


def gravity_columns(specs: Sequence[ParameterSpec]) -> list[int] | None:
    """The indices of GRAVITY_COLUMNS among `specs`, or None where gravity is no input."""
    names = [s.name for s in specs]
    return (
        [names.index(c) for c in GRAVITY_COLUMNS]
        if all(c in names for c in GRAVITY_COLUMNS)
        else None
    )


def gravity_load(parameters: torch.Tensor, columns: list[int] | None) -> torch.Tensor:
    """(n, P) raw parameters -> (n, 3) gravity load in g (zero without gravity columns)."""
    if columns is None:
        return torch.zeros_like(parameters[:, :3])
    s, tilt, azimuth = (parameters[:, i] for i in columns)
    # degrees by a constant factor: ONNX opset 17 has no deg2rad
    t, a = tilt * (np.pi / 180.0), azimuth * (np.pi / 180.0)
    d = torch.stack([torch.sin(t) * torch.cos(a), -torch.cos(t), torch.sin(t) * torch.sin(a)], 1)
    return s[:, None] * d + torch.tensor([0.0, 1.0, 0.0], dtype=d.dtype)


def region_means(labels: np.ndarray, n_regions: int) -> np.ndarray:
    """(R, V) rows averaging a per-vertex field over each region's vertices (a region without
    vertices gets a zero row; a vertex labelled -1 is in none)."""
    labels = np.asarray(labels, np.int64)
    m = np.zeros((n_regions, len(labels)), np.float32)
    for r in range(n_regions):
        idx = np.nonzero(labels == r)[0]
        if len(idx):
            m[r, idx] = 1.0 / len(idx)
    return m
