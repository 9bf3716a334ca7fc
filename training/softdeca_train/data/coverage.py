"""Expression weights for coverage: a sampler fitted to real ARKit takes.

Real takes are the best source of realistic co-activation but leave parts of the 52-D cube
empty. The sampler keeps the co-activation (a Gaussian over logit-weights fitted to the real
frames, so correlated shapes move together) and adds coverage (each draw, with probability
`sweep_share`, sweeps one or two random weights uniformly over [0, 1]).

One rule of the rig holds in every draw: `mouthClose` never exceeds `jawOpen`. The shape
closes the lips against an open jaw; past the jaw's opening it drives the lips through each
other (two generated frames had the upper lip's middle 10.4 and 5.1 mm below the lower's).
Real takes keep it: of 15,333 recorded frames 3 exceed it, by at most 0.058."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

EPS = 1e-3
MOUTH_CLOSE, JAW_OPEN = ARKIT_BLENDSHAPES.index("mouthClose"), ARKIT_BLENDSHAPES.index("jawOpen")


def _logit(w: np.ndarray) -> np.ndarray:
    w = np.clip(w, EPS, 1 - EPS)
    return np.log(w) - np.log1p(-w)


@dataclass(frozen=True)
class CoverageSampler:
    mean: np.ndarray  # (52,) logit space
    chol: np.ndarray  # (52, 52) Cholesky factor of the (regularised) covariance
    spread: float = 1.25  # widen the fitted Gaussian a little: cover beyond the recorded person
    sweep_share: float = 0.5

    @classmethod
    def fit(
        cls, frames: np.ndarray, spread: float = 1.25, sweep_share: float = 0.5
    ) -> CoverageSampler:
        x = _logit(np.asarray(frames, dtype=np.float64))
        cov = np.cov(x, rowvar=False) + 1e-3 * np.eye(x.shape[1])
        return cls(x.mean(axis=0), np.linalg.cholesky(cov), spread, sweep_share)

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        z = rng.standard_normal((n, len(self.mean)))
        w = 1.0 / (1.0 + np.exp(-(self.mean + self.spread * z @ self.chol.T)))
        sweep = rng.random(n) < self.sweep_share
        for i in np.flatnonzero(sweep):
            k = rng.choice(len(self.mean), size=rng.integers(1, 3), replace=False)
            w[i, k] = rng.random(len(k))
        w[w < 0.01] = 0.0  # real takes are sparse: keep near-zero weights at zero
        w[:, MOUTH_CLOSE] = np.minimum(w[:, MOUTH_CLOSE], w[:, JAW_OPEN])
        return w.astype(np.float32)
