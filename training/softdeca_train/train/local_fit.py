"""Per-element closed-form fits of a dataset's static frames, and the floor of deformation
transfer (DT) as an output stage.

linear-baseline's fits share one coefficient per feature across the head. Here every skin
element has its own, on its own parameters (a regional pattern's values where the frame has
one, so a region's control acts in its region only):

  vertex-local    T - S_t = A_v [w, 1, p_v, g_v]                  per skin vertex
  vertex-averaged T - S_t = A_v [w, 1, p_v, g_v, p~_v]            per skin vertex, p~_v the
                  localisable parameters averaged around the vertex at the vertex stage's
                  scales (models/smoothing.py): the inputs of SoftDECA's vertex stage
  vertex-identity the same, + [p_v, g_v] x the first IDENTITY_TERMS identity coefficients:
                  whether a linear identity interaction carries over to unseen identities
  gradient-local  G_f - I = A_f [w, 1, p_f, g_f], X = DT(S_t, G)   per skin triangle
  DT floor        X = DT(S_t, G*) with the physics' own per-face gradients G* (clamped as
                  SoftDECA's initialisation clamps them): the best any model whose output is
                  DT(S_t, G) can do on these frames

(p normalised to the dataset's sampling ranges, g the gravity load; linear_baseline.py.) Fitted
on the train split's kept frames, measured on every test frame."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from softdeca_train.models.dt import deformation_transfer
from softdeca_train.models.smoothing import FieldSmoothing
from softdeca_train.train.batches import EVERY_FRAME, Batch, Dataset
from softdeca_train.train.gradients import GRADIENT_CLAMP, frame_gradients
from softdeca_train.train.linear_baseline import ParameterScaling


def _own(p: np.ndarray, scaling: ParameterScaling) -> np.ndarray:
    """(n, P + 3): each element's normalised parameters and gravity load."""
    return np.concatenate([scaling.normalise(p), scaling.gravity_load(p)], axis=1)


def local_features(weights: np.ndarray, p: np.ndarray, scaling: ParameterScaling) -> torch.Tensor:
    """(n, B, 52 + 1 + P + 3) float64: for each of n elements and B frames, [w, 1, p_e, g_e]
    with the element's own parameters p (n, P)."""
    b, n = len(weights), len(p)
    own = _own(p, scaling)
    w1 = np.concatenate([np.asarray(weights, float), np.ones((b, 1))], axis=1)
    x = np.concatenate(
        [
            np.broadcast_to(w1[None], (n, b, w1.shape[1])),
            np.broadcast_to(own[:, None], (n, b, own.shape[1])),
        ],
        axis=2,
    )
    return torch.from_numpy(np.ascontiguousarray(x))


def averaged_features(
    x: torch.Tensor, p: np.ndarray, scaling: ParameterScaling, smoothing: FieldSmoothing
) -> torch.Tensor:
    """x (n, B, d) of local_features for n vertices, with the vertices' localisable normalised
    parameters averaged around each vertex appended: (n, B, d + L x scales)."""
    local = [i for i, s in enumerate(scaling.params.specs) if s.domain != "global"]
    field = torch.from_numpy(scaling.normalise(p)[:, local])
    around = smoothing(field)  # (n, L x scales)
    return torch.cat([x, around[:, None].expand(-1, x.shape[1], -1)], dim=2)


IDENTITY_TERMS = 3  # identity coefficients the interaction uses (the largest modes first)


def identity_features(
    x: torch.Tensor, p: np.ndarray, h: np.ndarray, scaling: ParameterScaling
) -> torch.Tensor:
    """x (n, B, d) with [p_v, g_v] x h[:IDENTITY_TERMS] of each element appended (one
    identity per batch, h (1, H) or (H,))."""
    own = _own(p, scaling)
    k = np.asarray(h, float).reshape(-1)[:IDENTITY_TERMS]
    inter = torch.from_numpy((own[:, :, None] * k[None, None]).reshape(len(own), -1))
    return torch.cat([x, inter[:, None].expand(-1, x.shape[1], -1)], dim=2)


class LocalRidge:
    """Accumulates per-element normal equations (n elements, d features, k outputs) frame batch
    by frame batch, then solves each element's ridge regression."""

    def __init__(self, n: int, d: int, k: int) -> None:
        self.gram = torch.zeros(n, d, d, dtype=torch.float64)
        self.cross = torch.zeros(n, d, k, dtype=torch.float64)
        self.frames = 0

    def add(self, x: torch.Tensor, y: torch.Tensor) -> None:
        """x (n, B, d), y (n, B, k)."""
        xt = x.transpose(1, 2)
        self.gram.baddbmm_(xt, x)
        self.cross.baddbmm_(xt, y.to(torch.float64))
        self.frames += x.shape[1]

    def solve(self, ridge: float, chunk: int = 1024, features: int | None = None) -> torch.Tensor:
        """(n, d, k); `ridge` relative to each element's mean diagonal of its A^T A. With
        `features`, the fit on the first that many feature columns only: nested feature sets
        share one accumulation, their systems being its leading blocks. Solved `chunk`
        elements at a time: a copy of every element's system at once would double the memory
        the normal equations already take (gigabytes for the skin's vertices)."""
        d = self.gram.shape[-1] if features is None else features
        eye = np.eye(d)
        out = torch.empty(len(self.cross), d, self.cross.shape[-1], dtype=torch.float64)
        for i in range(0, len(self.gram), chunk):
            g = self.gram[i : i + chunk, :d, :d].numpy()
            scale = np.maximum(np.diagonal(g, axis1=1, axis2=2).mean(axis=1), 1e-30)
            # numpy's LAPACK, not torch's batched LU: once a process has set torch's thread
            # count, that LU returned wrong solutions (0.2 mm off, or invalid pivots) in a
            # process that had also made a dataset (tests/python/test_softdeca_hybrid.py)
            out[i : i + chunk] = torch.from_numpy(
                np.linalg.solve(
                    g + ridge * scale[:, None, None] * eye, self.cross[i : i + chunk, :d].numpy()
                )
            )
        return out


def predict(x: torch.Tensor, coef: torch.Tensor) -> torch.Tensor:
    """(B, n, k) from x (n, B, d) and coef (n, d, k)."""
    return torch.bmm(x, coef).transpose(0, 1)


def _mean_mm(x: torch.Tensor, t: torch.Tensor) -> list[float]:
    return (1e3 * (x.double() - t.double()).norm(dim=-1).mean(dim=1)).tolist()


@dataclass(frozen=True)
class LocalFitConfig:
    ridge: float = 1e-3
    error_limit: float = 3.0  # kept training frames: solver error within this x tolerance


def _residual_gradients(batch: Batch, triangles: torch.Tensor) -> torch.Tensor:
    """G* - I per frame and face, clamped: (B, F, 3, 3)."""
    eye = torch.eye(3)
    return (frame_gradients(batch.S, batch.T, triangles) - eye).clamp(
        -GRADIENT_CLAMP, GRADIENT_CLAMP
    )


def run_local_fits(folder: str | Path, cfg: LocalFitConfig, progress: bool = True) -> dict:
    """Fit the per-element models on the train split; measure them, the DT floor and no
    correction on every static test frame."""
    ds = Dataset(folder)
    scaling = ParameterScaling.of(ds.manifest)
    tri_np = ds.template.skin_triangles
    tri = torch.as_tensor(tri_np, dtype=torch.long)
    n_f, n_v = len(tri_np), int(tri_np.max()) + 1
    limit = cfg.error_limit * ds.tolerance
    kept = ds.left_out("static", "train", limit)["kept"]
    test_total = ds.left_out("static", "test", EVERY_FRAME)["kept"]
    if kept == 0:
        raise ValueError(f"{folder}: no static train frame to fit")
    if test_total == 0:
        raise ValueError(f"{folder}: no static test frame to measure")
    smoothing = FieldSmoothing(ds.template.neutral[:n_v])

    def vertex_features(b: Batch) -> tuple[torch.Tensor, int, int]:
        """[own | averaged | identity] columns of every vertex, and where the first two end:
        the three per-vertex models fit nested prefixes of these columns."""
        pv = b.vertex_parameters(n_v).numpy()
        xv = local_features(b.weights.numpy(), pv, scaling)
        xa = averaged_features(xv, pv, scaling, smoothing)
        return identity_features(xa, pv, b.h.numpy(), scaling), xv.shape[-1], xa.shape[-1]

    vert = grad = None
    d_own = d_aver = 0
    bar = tqdm(total=kept, desc="local fits (train)", unit="frame", disable=not progress)
    for b in ds.batches("static", "train", max_error=limit):
        xi, d_own, d_aver = vertex_features(b)
        xf = local_features(b.weights.numpy(), b.face_parameters(n_f).numpy(), scaling)
        if vert is None or grad is None:
            vert, grad = LocalRidge(n_v, xi.shape[-1], 3), LocalRidge(n_f, xf.shape[-1], 9)
        vert.add(xi, (b.T - b.S).transpose(0, 1))
        grad.add(xf, _residual_gradients(b, tri).reshape(b.frames, n_f, 9).transpose(0, 1))
        bar.update(b.frames)
    bar.close()
    assert vert is not None and grad is not None
    train_frames = vert.frames
    coef_v = vert.solve(cfg.ridge, features=d_own)
    coef_a = vert.solve(cfg.ridge, features=d_aver)
    coef_i = vert.solve(cfg.ridge)
    del vert  # the normal equations are the largest arrays here
    coef_f = grad.solve(cfg.ridge)
    del grad
    err: dict[str, list[float]] = {
        "none": [],
        "vertex_local": [],
        "vertex_averaged": [],
        "vertex_identity": [],
        "gradient_local": [],
        "dt_floor": [],
    }
    bar = tqdm(total=test_total, desc="local fits (test)", unit="frame", disable=not progress)
    for b in ds.batches("static", "test", max_error=EVERY_FRAME):
        xi, _, _ = vertex_features(b)
        xf = local_features(b.weights.numpy(), b.face_parameters(n_f).numpy(), scaling)
        err["none"] += _mean_mm(b.S, b.T)
        err["vertex_local"] += _mean_mm(b.S + predict(xi[..., :d_own], coef_v).float(), b.T)
        err["vertex_averaged"] += _mean_mm(b.S + predict(xi[..., :d_aver], coef_a).float(), b.T)
        err["vertex_identity"] += _mean_mm(b.S + predict(xi, coef_i).float(), b.T)
        g = predict(xf, coef_f).float().reshape(b.frames, n_f, 3, 3)
        err["gradient_local"] += _mean_mm(deformation_transfer(b.dt, b.S, g), b.T)
        err["dt_floor"] += _mean_mm(
            deformation_transfer(b.dt, b.S, _residual_gradients(b, tri)), b.T
        )
        bar.update(b.frames)
    bar.close()
    return {
        "dataset": str(folder),
        "train_frames": train_frames,
        "test_frames": len(err["none"]),
        "config": {
            "ridge": cfg.ridge,
            "error_limit": cfg.error_limit,
            "gradient_clamp": GRADIENT_CLAMP,
            "smoothing_scales_m": list(smoothing.scales),
            "identity_terms": IDENTITY_TERMS,
        },
        "test_mm": {k: float(np.mean(v)) for k, v in err.items()},
    }


LOCAL_ROWS = {
    "vertex_local": "per vertex: T - S = A_v [w, 1, p_v, g_v]",
    "vertex_averaged": "per vertex, + localisable p averaged around it: A_v [w, 1, p_v, g_v, p~_v]",
    "vertex_identity": f"the same, + [p_v, g_v] x the first {IDENTITY_TERMS} identity coefficients",
    "gradient_local": "per face: G - I = A_f [w, 1, p_f, g_f], through DT",
    "dt_floor": "DT of the physics' own face gradients (clamped)",
}


def format_local_table(result: dict) -> str:
    mm = result["test_mm"]
    none = mm["none"]
    lines = [
        f"{result['dataset']}: {result['train_frames']} train frames (kept), "
        f"{result['test_frames']} test frames (every one); per-element fits",
        "| model | test mm | test / no correction |",
        "| --- | ---: | ---: |",
        f"| none (S_t) | {none:.3f} | 1.00 |",
    ]
    for key, label in LOCAL_ROWS.items():
        lines.append(f"| {label} | {mm[key]:.3f} | {mm[key] / none:.2f} |")
    return "\n".join(lines)
