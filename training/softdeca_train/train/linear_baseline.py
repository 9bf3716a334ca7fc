"""Closed-form linear baselines on a dataset's static offsets T - S_t: ridge regressions of the
offsets on sets of input features, fitted on the train split (the frames training keeps) and
measured on every test frame, as the evaluation measures the networks.

They say how much of the physics' correction the model inputs explain *linearly*: the
blendshape weights w, the material parameters p (normalised to the dataset's sampling
ranges), the gravity load vector (the part of p that acts as a force, linear in the load where
p's strength and angles are not) and the identity code h. A trained network that does worse
than one of them has not learned what its inputs carry.

The fit streams the shards: it accumulates A^T A and A^T Y per feature set (A: features, Y:
the offsets, 14,062 x 3 per frame), so memory holds one shard and the (features x 42,186)
products, never the dataset."""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.data.shards import iter_shards
from softdeca_train.models.blocks import GRAVITY_COLUMNS
from softdeca_train.parameters import ParameterSet, load_parameters
from softdeca_train.train.batches import EVERY_FRAME, training_mask

# Feature groups by letter: a feature set is a string of them ("wpg": w, p and gravity).
GROUPS = {
    "w": "blendshape weights (52)",
    "p": "material parameters, normalised to the dataset's ranges",
    "g": "gravity load vector s d - d0 (3; in g)",
    "h": "identity code h",
    "x": "products of w and the normalised p (52 x P): a response to p that the expression changes",
}
DEFAULT_SETS = ("w", "p", "wp", "wpg", "wpgh")
_CAPTURE = np.array([0.0, -1.0, 0.0])  # the neutral's own load: 1 g along -Y


@dataclass(frozen=True)
class LinearBaselineConfig:
    feature_sets: tuple[str, ...] = DEFAULT_SETS
    # Ridge strength relative to the mean diagonal of A^T A (features are of unit scale).
    ridge: float = 1e-3
    # Training keeps frames whose solver error is within this multiple of the tolerance and
    # that pass the sanity bounds (as the networks' training does).
    error_limit: float = 3.0


@dataclass(frozen=True)
class ParameterScaling:
    """p -> [0, 1] over the dataset's sampling ranges (ParameterSet.normalise: log-scaled
    parameters in log), and the gravity load p's strength and angles make."""

    params: ParameterSet
    gravity: tuple[int, int, int]  # columns of strength, tilt, azimuth

    @classmethod
    def of(cls, manifest: dict) -> ParameterScaling:
        """The ranges the manifest recorded as sampled (the definition may have changed)."""
        sampled = {q["name"]: q for q in manifest["dataset"]["parameters"]}
        params = ParameterSet(
            tuple(
                s.narrowed(sampled[s.name]["lo"], sampled[s.name]["hi"])
                for s in load_parameters().specs
            )
        )
        names = params.names
        g = tuple(names.index(n) for n in GRAVITY_COLUMNS)
        return cls(params, g)  # type: ignore[arg-type]

    def normalise(self, p: np.ndarray) -> np.ndarray:
        return self.params.normalise(np.asarray(p, float))

    def gravity_load(self, p: np.ndarray) -> np.ndarray:
        """s d - d0 (in g): zero at the capture's load, 1 g along -Y (plugin/src/sim/model.cpp,
        gravity_forces)."""
        s, t, a = (np.asarray(p, float)[..., i] for i in self.gravity)
        t, a = np.radians(t), np.radians(a)
        d = np.stack([np.sin(t) * np.cos(a), -np.cos(t), np.sin(t) * np.sin(a)], -1)
        return s[..., None] * d - _CAPTURE


def features(
    feature_set: str, w: np.ndarray, p: np.ndarray, h: np.ndarray, scaling: ParameterScaling
) -> np.ndarray:
    """The rows of A for n frames: a constant column, then the groups of `feature_set`."""
    unknown = set(feature_set) - set(GROUPS)
    if unknown or not feature_set:
        raise ValueError(f"feature set {feature_set!r}: use letters of {''.join(GROUPS)}")
    cols = [np.ones((len(w), 1))]
    for g in feature_set:
        cols.append(
            {
                "w": lambda: np.asarray(w, float),
                "p": lambda: scaling.normalise(p),
                "g": lambda: scaling.gravity_load(p),
                "h": lambda: np.asarray(h, float),
                "x": lambda: (
                    np.asarray(w, float)[:, :, None] * scaling.normalise(p)[:, None, :]
                ).reshape(len(w), -1),
            }[g]()
        )
    return np.concatenate(cols, axis=1)


def fit_ridge(gram: np.ndarray, cross: np.ndarray, ridge: float) -> np.ndarray:
    """argmin |A X - Y|^2 + lambda |X|^2 from A^T A and A^T Y; lambda relative to the mean
    diagonal of A^T A (the constant column is regularised too: it is one of few columns)."""
    scale = float(np.trace(gram)) / len(gram)
    return np.linalg.solve(gram + ridge * scale * np.eye(len(gram)), cross)


def mean_vertex_error_mm(predicted: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Per frame: mean distance (mm) between predicted and true offsets, (n, V * 3) each."""
    d = (predicted - offsets).reshape(len(offsets), -1, 3)
    return 1e3 * np.linalg.norm(d, axis=2).mean(axis=1)


def _frames(
    folder: Path, split: str, limit: float
) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """(w, p, h, offsets flattened) of the kept static frames of each shard of a split."""
    for a in iter_shards(folder, "static", split):
        solved, sane = training_mask(a, limit)
        keep = solved & sane
        if keep.any():
            n = int(keep.sum())
            yield (
                a["weights"][keep].reshape(n, -1),
                a["p"][keep].reshape(n, -1),
                a["h"][keep].reshape(n, -1),
                a["offsets"][keep].reshape(n, -1).astype(np.float64),
            )


@dataclass
class BaselineRow:
    feature_set: str
    columns: int
    train_mm: float
    test_mm: float


def run_linear_baselines(
    folder: str | Path, cfg: LinearBaselineConfig, progress: bool = True
) -> dict:
    """Fit every feature set on the train split and measure it on every test frame."""
    folder = Path(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    scaling = ParameterScaling.of(manifest)
    limit = cfg.error_limit * float(manifest["header"]["config"]["tolerance"])
    sets = tuple(dict.fromkeys(cfg.feature_sets))
    for s in sets:
        features(s, np.zeros((1, 52)), scaling.params.defaults()[None], np.zeros((1, 1)), scaling)
    n_train_shards = sum(
        1 for s in manifest["shards"] if s["kind"] == "static" and s.get("split", 0) == 0
    )
    gram: dict[str, np.ndarray] = {}
    cross: dict[str, np.ndarray] = {}
    n_train = 0
    for w, p, h, y in tqdm(
        _frames(folder, "train", limit),
        total=n_train_shards,
        desc="fit (train shards)",
        unit="shard",
        disable=not progress,
    ):
        n_train += len(y)
        for s in sets:
            a = features(s, w, p, h, scaling)
            gram[s] = gram.get(s, 0) + a.T @ a
            cross[s] = cross.get(s, 0) + a.T @ y
    if n_train == 0:
        raise ValueError(f"{folder}: no static train frame to fit")
    coef = {s: fit_ridge(gram[s], cross[s], cfg.ridge) for s in sets}
    train_err = {s: 0.0 for s in sets}
    test_err = {s: 0.0 for s in (*sets, "none")}
    n_test = 0
    # Second passes: the training error and every test frame (failed ones included).
    for w, p, h, y in tqdm(
        _frames(folder, "train", limit), desc="train error", unit="shard", disable=not progress
    ):
        for s in sets:
            train_err[s] += float(
                mean_vertex_error_mm(features(s, w, p, h, scaling) @ coef[s], y).sum()
            )
    for w, p, h, y in tqdm(
        _frames(folder, "test", EVERY_FRAME), desc="test error", unit="shard", disable=not progress
    ):
        n_test += len(y)
        test_err["none"] += float(mean_vertex_error_mm(np.zeros_like(y), y).sum())
        for s in sets:
            test_err[s] += float(
                mean_vertex_error_mm(features(s, w, p, h, scaling) @ coef[s], y).sum()
            )
    if n_test == 0:
        raise ValueError(f"{folder}: no static test frame to measure")
    rows = [
        BaselineRow(s, len(gram[s]), train_err[s] / n_train, test_err[s] / n_test) for s in sets
    ]
    return {
        "dataset": str(folder),
        "train_frames": n_train,
        "test_frames": n_test,
        "no_correction_test_mm": test_err["none"] / n_test,
        "config": asdict(cfg),
        "groups": GROUPS,
        "rows": [asdict(r) for r in rows],
    }


def format_table(result: dict) -> str:
    none = result["no_correction_test_mm"]
    lines = [
        f"{result['dataset']}: {result['train_frames']} train frames (kept), "
        f"{result['test_frames']} test frames (every one)",
        "| features | columns | train mm | test mm | test / no correction |",
        "| --- | ---: | ---: | ---: | ---: |",
        f"| none (S_t) | 0 | – | {none:.3f} | 1.00 |",
    ]
    for r in result["rows"]:
        ratio = r["test_mm"] / none if none > 0 else math.nan
        lines.append(
            f"| {r['feature_set']} | {r['columns']} | {r['train_mm']:.3f} | "
            f"{r['test_mm']:.3f} | {ratio:.2f} |"
        )
    return "\n".join(lines)


def parse_sets(text: Sequence[str]) -> tuple[str, ...]:
    return tuple(s.strip() for s in text if s.strip())
