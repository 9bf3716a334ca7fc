"""Expression frames: the real takes (whole takes held out for the test split) and the
coverage sampler fitted to the training takes only. Every frame drawn carries its source:
(take index, frame index) for a real frame, (-1, draw index) for a coverage draw."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdeca_train.data.config import TEST, TRAIN
from softdeca_train.data.coverage import CoverageSampler
from softdeca_train.streaming.takes import TAKE_SUFFIXES, read_take, take_paths

COVERAGE = -1  # source_take of a coverage draw
MAX_GAP_S = 0.1  # a dynamic window may not span a face-lost gap longer than this
# A reduced real frame keeps its shape at this share of its amplitude: calm talking is the
# same mouth shapes at a fraction of an expressive take's weights.
REDUCED_LO, REDUCED_HI = 0.15, 0.85


@dataclass(frozen=True)
class Take:
    name: str
    sha256: str
    weights: np.ndarray  # (n, 52) float32, canonical ARKit order
    times: np.ndarray  # (n,) capture time in seconds
    face_lost_rows: int


def load_takes(folder: Path) -> list[Take]:
    """Every take below a folder (Live Link Face CSV or LLV recording, streaming/takes.py),
    sorted by path (the take index is the position), named by file stem: stems must differ."""
    folder = Path(folder)
    paths = take_paths(folder)
    if not paths:
        raise FileNotFoundError(f"no takes ({', '.join(TAKE_SUFFIXES)}) below {folder}")
    stems = [p.stem for p in paths]
    if len(set(stems)) != len(stems):
        twice = sorted({s for s in stems if stems.count(s) > 1})
        raise ValueError(f"takes below {folder} share a name: {', '.join(twice)}")
    takes = []
    for p in paths:
        csv = read_take(p)
        if not csv.frames:
            raise ValueError(f"{p}: no tracked frames")
        takes.append(
            Take(
                name=p.stem,
                sha256=hashlib.sha256(p.read_bytes()).hexdigest(),
                weights=np.stack([f.weights for f in csv.frames]).astype(np.float32),
                times=np.array([f.capture_time for f in csv.frames]),
                face_lost_rows=csv.face_lost_rows,
            )
        )
    return takes


@dataclass(frozen=True)
class Draws:
    weights: np.ndarray  # (n, 52) float32
    source_take: np.ndarray  # (n,) int16, COVERAGE for coverage draws
    source_index: np.ndarray  # (n,) int32: frame index in the take, or coverage draw index


class ExpressionSource:
    """Deterministic frame streams for one split. Real frames are dealt from seeded
    permutations of the split's pool (each frame once before any repeats); coverage draws are
    numbered in the order they are made, so a draw index names one draw of this split."""

    def __init__(
        self,
        takes: list[Take],
        take_ids: list[int],
        sampler: CoverageSampler,
        seed: tuple[int, ...],
        exclude: np.ndarray | None = None,
    ) -> None:
        self.takes = takes
        self.sampler = sampler
        pairs = [(t, i) for t in take_ids for i in range(len(takes[t].weights))]
        if exclude is not None and len(exclude):
            # Test frames may not repeat a training frame exactly (e.g. an all-zero frame).
            seen = {row.tobytes() for row in exclude}
            pairs = [(t, i) for t, i in pairs if takes[t].weights[i].tobytes() not in seen]
        if not pairs:
            raise ValueError("a split has no real expression frames")
        self.pool = np.array(pairs, dtype=np.int64)
        self.take_ids = take_ids
        self._rng_real = np.random.default_rng([*seed, 0])
        self._rng_cov = np.random.default_rng([*seed, 1])
        self._rng_mix = np.random.default_rng([*seed, 2])
        self._rng_win = np.random.default_rng([*seed, 3])
        self._rng_amp = np.random.default_rng([*seed, 4])
        self._order = np.zeros(0, np.int64)
        self._next_coverage = 0

    def _real(self, n: int) -> np.ndarray:
        while len(self._order) < n:
            self._order = np.concatenate([self._order, self._rng_real.permutation(len(self.pool))])
        picked, self._order = self._order[:n], self._order[n:]
        return self.pool[picked]

    def frames(self, n: int, real_share: float, reduced_share: float = 0.0) -> Draws:
        """n independent frames, each real with probability real_share, else coverage; a
        real frame is scaled to a reduced amplitude with probability reduced_share (its own
        stream: a share of 0 leaves every other draw as it was)."""
        real = self._rng_mix.random(n) < real_share
        w = np.zeros((n, 52), np.float32)
        take = np.full(n, COVERAGE, np.int16)
        index = np.zeros(n, np.int32)
        k = int(real.sum())
        if k:
            pairs = self._real(k)
            w[real] = [self.takes[t].weights[i] for t, i in pairs]
            take[real], index[real] = pairs[:, 0], pairs[:, 1]
            if reduced_share > 0:
                rows = np.flatnonzero(real)
                calm = self._rng_amp.random(k) < reduced_share
                scale = self._rng_amp.uniform(REDUCED_LO, REDUCED_HI, k).astype(np.float32)
                w[rows[calm]] *= scale[calm, None]
        if n - k:
            w[~real] = self.sampler.sample(self._rng_cov, n - k)
            index[~real] = self._next_coverage + np.arange(n - k)
            self._next_coverage += n - k
        return Draws(w, take, index)

    def window(self, length: int) -> Draws:
        """`length` consecutive real frames of one take (no face-lost gap inside)."""
        starts = []
        for t in self.take_ids:
            times = self.takes[t].times
            if len(times) < length:
                continue
            gap = np.diff(times) > MAX_GAP_S
            bad = np.concatenate([[0], np.cumsum(gap)])  # gaps before frame i
            s = np.arange(len(times) - length + 1)
            ok = bad[s + length - 1] == bad[s]
            starts += [(t, int(i)) for i in s[ok]]
        if not starts:
            raise ValueError(f"no take of the split has {length} consecutive frames")
        t, s = starts[int(self._rng_win.integers(len(starts)))]
        idx = np.arange(s, s + length, dtype=np.int32)
        return Draws(self.takes[t].weights[idx], np.full(length, t, np.int16), idx)


def expression_sources(
    takes: list[Take], test_takes: tuple[str, ...], seed: int, test_share: float
) -> tuple[dict[int, ExpressionSource], CoverageSampler]:
    """Train and test sources: the test split owns the `test_takes` alone; the coverage
    sampler is fitted to the other takes only."""
    names = [t.name for t in takes]
    missing = [t for t in test_takes if t not in names]
    if missing:
        raise ValueError(f"test takes {missing} are not among the takes {names}")
    held = [names.index(t) for t in test_takes]
    train_ids = [i for i in range(len(takes)) if i not in held]
    if not train_ids:
        raise ValueError("need at least one take besides the held-out test takes")
    train_frames = np.concatenate([takes[i].weights for i in train_ids])
    sampler = CoverageSampler.fit(train_frames)
    sources = {
        TRAIN: ExpressionSource(takes, train_ids, sampler, (seed, 10, TRAIN)),
    }
    if test_share > 0:
        sources[TEST] = ExpressionSource(
            takes, held, sampler, (seed, 10, TEST), exclude=train_frames
        )
    return sources, sampler
