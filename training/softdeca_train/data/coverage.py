"""Expression weights for coverage: a sampler fitted to real ARKit takes.

Real takes are the best source of realistic co-activation but leave parts of the 52-D cube
empty, and a model trained on one person's takes meets other people's faces. The sampler
keeps the co-activation (a Gaussian over logit-weights fitted to the real frames, so
correlated shapes move together) and draws, by kind (KINDS, DEFAULT_SHARES), what real faces
do beyond the recorded person:
- `calm`: a draw of the fitted Gaussian scaled down to 0-40 %: a face near rest, as in calm
  speech; without it no frame near the neutral is trained on, and a model's response there
  is a guess that a calm take's every frame pays for;
- `mild`: the fitted Gaussian itself: small co-activations, most of speech;
- `wide`: the Gaussian widened (`spread`): expressions a little beyond the recorded person;
- `blink`: a mild draw with both lids closing together, as people blink mid-expression;
- `asymmetric`: a mild draw with one side's shapes scaled down, as real faces rarely match;
- `strong`: one of the stress suite's extreme combinations (sim/expressions.py) at 60-100 %
  over a mild draw: the frames where the physics departs most from the blend;
- `sweep`: a wide draw with one or two weights swept uniformly over [0, 1] (coverage).

One rule of the rig holds in every draw: `mouthClose` never exceeds `jawOpen`. The shape
closes the lips against an open jaw; past the jaw's opening it drives the lips through each
other (two generated frames had the upper lip's middle 10.4 and 5.1 mm below the lower's).
Real takes keep it: of 15,333 recorded frames 3 exceed it, by at most 0.058."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.sim.expressions import combinations
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

EPS = 1e-3
MOUTH_CLOSE, JAW_OPEN = ARKIT_BLENDSHAPES.index("mouthClose"), ARKIT_BLENDSHAPES.index("jawOpen")


def _logit(w: np.ndarray) -> np.ndarray:
    w = np.clip(w, EPS, 1 - EPS)
    return np.log(w) - np.log1p(-w)


SIDES = {
    side: np.array([i for i, n in enumerate(ARKIT_BLENDSHAPES) if n.endswith(side)])
    for side in ("Left", "Right")
}
BLINKS = np.array([ARKIT_BLENDSHAPES.index(f"eyeBlink{side}") for side in ("Left", "Right")])
STRONG = np.stack(list(combinations().values()))


KINDS = ("calm", "mild", "wide", "blink", "asymmetric", "strong", "sweep")
DEFAULT_SHARES = (0.15, 0.2, 0.1, 0.1, 0.1, 0.15, 0.2)  # of the draws, per kind of KINDS


def cumulative_shares(shares: tuple[float, ...]) -> np.ndarray:
    """The shares of the draw kinds (KINDS order), checked, summed up."""
    s = np.asarray(shares, dtype=np.float64)
    if s.shape != (len(KINDS),) or np.any(s < 0) or not np.isclose(s.sum(), 1.0):
        raise ValueError(f"draw shares: one per kind {KINDS}, each >= 0, summing to 1: {shares}")
    return np.cumsum(s)


@dataclass(frozen=True)
class CoverageSampler:
    mean: np.ndarray  # (52,) logit space
    chol: np.ndarray  # (52, 52) Cholesky factor of the (regularised) covariance
    spread: float = 1.25  # the `wide` kind: cover beyond the recorded person
    shares: tuple[float, ...] = DEFAULT_SHARES

    @classmethod
    def fit(
        cls, frames: np.ndarray, spread: float = 1.25, shares: tuple[float, ...] = DEFAULT_SHARES
    ) -> CoverageSampler:
        x = _logit(np.asarray(frames, dtype=np.float64))
        cov = np.cov(x, rowvar=False) + 1e-3 * np.eye(x.shape[1])
        return cls(x.mean(axis=0), np.linalg.cholesky(cov), spread, shares)

    def _gaussian(self, rng: np.random.Generator, n: int, spread: np.ndarray) -> np.ndarray:
        z = rng.standard_normal((n, len(self.mean)))
        return 1.0 / (1.0 + np.exp(-(self.mean + spread[:, None] * (z @ self.chol.T))))

    def kinds(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """(n,) indices into KINDS: which kind each of n draws is."""
        return np.searchsorted(cumulative_shares(self.shares), rng.random(n), side="right").clip(
            0, len(KINDS) - 1
        )

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        kind = self.kinds(rng, n)
        named = {k: np.flatnonzero(kind == i) for i, k in enumerate(KINDS)}
        wide = np.isin(kind, [KINDS.index("wide"), KINDS.index("sweep")])
        w = self._gaussian(rng, n, np.where(wide, self.spread, 1.0))
        c = named["calm"]
        w[c] *= rng.uniform(0.0, 0.4, (len(c), 1))
        for i in named["sweep"]:
            k = rng.choice(len(self.mean), size=rng.integers(1, 3), replace=False)
            w[i, k] = rng.random(len(k))
        b = named["blink"]
        w[b[:, None], BLINKS] = rng.uniform(0.6, 1.0, (len(b), 1)) + rng.uniform(
            -0.05, 0.05, (len(b), 2)
        )
        a = named["asymmetric"]
        weaker = np.where(rng.random(len(a)) < 0.5, 0, 1)
        scale = rng.uniform(0.0, 0.7, len(a))
        for i, side, f in zip(a, weaker, scale, strict=True):
            w[i, SIDES[("Left", "Right")[side]]] *= f
        s = named["strong"]
        combo = STRONG[rng.integers(len(STRONG), size=len(s))]
        w[s] = np.maximum(w[s], combo * rng.uniform(0.6, 1.0, (len(s), 1)))
        w = np.clip(w, 0.0, 1.0)
        w[w < 0.01] = 0.0  # real takes are sparse: keep near-zero weights at zero
        w[:, MOUTH_CLOSE] = np.minimum(w[:, MOUTH_CLOSE], w[:, JAW_OPEN])
        return w.astype(np.float32)
