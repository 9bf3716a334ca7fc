"""The identity encoder (neutral skin in the template's topology -> identity coefficients h),
trained on freshly drawn identities: the template's neutral is linear in h, so every step
draws a new batch and the encoder never sees the same head twice. Truncated N(0, I) draws
cover the plausible identities the data generator samples (template/model.py)."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import torch
from tqdm import tqdm

from softdeca_train.models.networks import IdentityEncoder, NetworkSizes
from softdeca_train.template import Template
from softdeca_train.template.model import IDENTITY_TRUNCATION, N_SKIN


@dataclass(frozen=True)
class IdentityConfig:
    steps: int = 1500
    batch: int = 64
    lr: float = 1e-3
    seed: int = 0


class IdentityDraws:
    """Batches of (neutral skin, h) for random identities."""

    def __init__(self, template: Template) -> None:
        self.mean = torch.from_numpy(template.neutral[:N_SKIN].astype(np.float32))
        modes = template.identity_modes[:, :N_SKIN].astype(np.float32)
        self.modes = torch.from_numpy(modes.reshape(len(modes), -1))

    def __call__(self, rng: np.random.Generator, n: int) -> tuple[torch.Tensor, torch.Tensor]:
        h = np.clip(rng.standard_normal((n, len(self.modes))), -IDENTITY_TRUNCATION, None)
        h = torch.from_numpy(np.clip(h, None, IDENTITY_TRUNCATION).astype(np.float32))
        return self.mean + (h @ self.modes).reshape(n, N_SKIN, 3), h


def train_identity_encoder(
    template: Template, sizes: NetworkSizes, cfg: IdentityConfig, progress: bool = True
) -> tuple[IdentityEncoder, dict]:
    """Train the encoder; returns it with its held-out errors (coefficients RMS, and the
    neutral rebuilt from the estimate against the true one, mm)."""
    if sizes.identity != template.identity_modes.shape[0]:
        raise ValueError(
            f"identity size {sizes.identity} != the template's {template.identity_modes.shape[0]}"
        )
    torch.manual_seed(cfg.seed)
    draws = IdentityDraws(template)
    enc = IdentityEncoder(N_SKIN, sizes, cfg.seed)
    opt = torch.optim.Adam(enc.parameters(), lr=cfg.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, cfg.steps, cfg.lr * 0.05)
    rng = np.random.default_rng([cfg.seed, 7])
    t0 = time.monotonic()
    for _ in tqdm(range(cfg.steps), desc="identity encoder", disable=not progress):
        neutral, h = draws(rng, cfg.batch)
        loss = ((enc(neutral) - h) ** 2).mean()
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        sched.step()
    enc.eval()
    with torch.no_grad():
        neutral, h = draws(np.random.default_rng([cfg.seed, 8]), 256)
        est = enc(neutral)
        rebuilt = draws.mean + (est @ draws.modes).reshape(len(est), N_SKIN, 3)
        # the encoder sees centred points: compare shapes up to translation
        diff = (rebuilt - rebuilt.mean(1, keepdim=True)) - (neutral - neutral.mean(1, keepdim=True))
        errors = {
            "coefficients_rms": float(((est - h) ** 2).mean().sqrt()),
            "coefficients_std": 1.0,
            "neutral_mm": float(diff.norm(dim=-1).mean()) * 1e3,
            "test_identities": 256,
            "minutes": round((time.monotonic() - t0) / 60, 2),
        }
    return enc, errors
