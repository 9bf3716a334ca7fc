"""How much of the physics' correction T - S_t depends on the expression at all. The frames of
one (identity, p) group share an offset that does not: its mean over the group's frames. What
is left after subtracting it is the expression-dependent part; the shared part is what a
network has to predict from p and h alone, across parameter sets it never saw. A ridge model
linear in the normalised p, fitted on the train groups' shared offsets and scored on the test
groups, says how far the simplest such prediction gets."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdeca_train.data.config import TEST
from softdeca_train.data.shards import iter_shards
from softdeca_train.parameters import ParameterSet

RIDGE = 0.1  # relative to the number of groups; fixed, not tuned on the test groups


@dataclass(frozen=True)
class OffsetStructure:
    """Mean per-vertex distances in mm over the frames the loader keeps."""

    train_groups: int
    test_groups: int
    frames_per_group: float  # with few frames, the group mean absorbs some of the expression
    no_correction_mm: float  # |T - S_t|, all groups
    expression_part_mm: float  # |T - S_t - group mean|, all groups
    test_no_correction_mm: float
    test_linear_in_p_mm: float | None  # the test groups' frames corrected by the ridge model

    @property
    def shared_share(self) -> float:
        """Share of the no-correction error that the group's shared offset removes."""
        return 1.0 - self.expression_part_mm / self.no_correction_mm


def _mean_distance(x: np.ndarray) -> float:
    return float(np.linalg.norm(x, axis=-1).mean()) * 1e3


def offset_structure(
    folder: str | Path, kind: str, params: ParameterSet, max_error: float
) -> OffsetStructure | None:
    """For the static or sparse frames of a dataset whose estimated error is at most
    `max_error`; None when it has no such frames."""
    means: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {0: [], TEST: []}
    test_frames: list[np.ndarray] = []
    total = expr = count = 0.0
    frames = 0
    for a in iter_shards(Path(folder), kind):
        ok = a["estimated_error"].reshape(len(a["p"]), -1).max(axis=1) <= max_error
        for g in np.unique(a["param_id"]):
            idx = np.flatnonzero((a["param_id"] == g) & ok)
            if len(idx) == 0:
                continue
            off = a["offsets"][idx].astype(np.float32)  # (n, V, 3)
            mean = off.mean(axis=0)
            total += np.linalg.norm(off, axis=-1).sum()
            expr += np.linalg.norm(off - mean, axis=-1).sum()
            count += off.shape[0] * off.shape[1]
            frames += off.shape[0]
            split = int(a["split"][idx[0]])
            p = np.asarray(params.normalise(a["p"][idx[0]][None]))[0]
            means[TEST if split == TEST else 0].append((p, mean.reshape(-1)))
            if split == TEST:
                test_frames.append(off)
    if count == 0:
        return None
    linear = None
    if means[0] and means[TEST]:
        linear = _ridge_test_error(means[0], means[TEST], test_frames)
    return OffsetStructure(
        train_groups=len(means[0]),
        test_groups=len(means[TEST]),
        frames_per_group=frames / (len(means[0]) + len(means[TEST])),
        no_correction_mm=float(1e3 * total / count),
        expression_part_mm=float(1e3 * expr / count),
        test_no_correction_mm=float(np.mean([_mean_distance(f) for f in test_frames]))
        if test_frames
        else float("nan"),
        test_linear_in_p_mm=linear,
    )


def _ridge_test_error(
    train: list[tuple[np.ndarray, np.ndarray]],
    test: list[tuple[np.ndarray, np.ndarray]],
    test_frames: list[np.ndarray],
) -> float:
    x = np.array([p for p, _ in train], dtype=np.float64)
    keep = x.std(axis=0) > 1e-9  # parameters the data holds fixed carry nothing
    a = np.c_[x[:, keep], np.ones(len(x))]
    y = np.array([m for _, m in train], dtype=np.float64)
    reg = RIDGE * len(a) * np.eye(a.shape[1])
    reg[-1, -1] = 0.0  # the intercept (the mean shared offset) is not shrunk
    w = np.linalg.solve(a.T @ a + reg, a.T @ y)
    xt = np.array([p for p, _ in test], dtype=np.float64)
    pred = np.c_[xt[:, keep], np.ones(len(xt))] @ w
    return float(
        np.mean(
            [
                _mean_distance(f - q.reshape(1, -1, 3))
                for f, q in zip(test_frames, pred, strict=True)
            ]
        )
    )
