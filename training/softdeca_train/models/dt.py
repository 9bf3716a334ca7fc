"""Deformation transfer DT(S_t, G) of eq. 17 as a linear least-squares problem whose matrix
depends only on the avatar's neutral skin, so it is factorised once per avatar.

For skin triangle f = (i, j, k) with neutral corners n_i, n_j, n_k:
  N_f = [n_j - n_i, n_k - n_i]  (3x2),  a_f = |(n_j - n_i) x (n_k - n_i)| / 2,
  W_f = (N_f^T N_f)^-1          (2x2, the neutral's metric),  m_v = sum of a_f / 3 over f at v.
For any vertex positions Y, E_f(Y) = [y_j - y_i, y_k - y_i]. Given the blended skin S_t and one
deformation gradient G_f per face (G_f = I + sum_k z_k L[f, k] reshaped row-major to 3x3),

  X = argmin_X  sum_f a_f || (E_f(X) - G_f E_f(S_t)) N_f^+ ||_F^2  +  mu sum_v m_v |x_v - s_v|^2

with N_f^+ = W_f N_f^T (so the first term compares per-face gradients measured on the neutral:
the cotangent Poisson formulation) and mu = lambda / mean(m): the small mass-weighted pull
toward S_t fixes the translation. The normal equations are K X = b with

  K = sum_f a_f D_f W_f D_f^T + mu M      (the cotangent Laplacian plus mu diag(m)),

constant per avatar. Written as a correction of S_t, X = S_t + K^-1 r with

  r = sum_f D_f a_f W_f ((G_f - I) E_f(S_t))^T,

so three right-hand sides per frame and no dependence of K on the frame. The native runtime
(plugin/src/runtime/deformation_transfer.*) evaluates exactly this."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import torch

DEFAULT_REGULARISATION = 1e-3  # lambda: the pull toward S_t relative to the Laplacian
MIN_FACE_AREA = 1e-12  # m^2; a skin triangle with less area on the neutral is rejected


@dataclass
class DtSystem:
    """Everything of DT that depends only on the avatar's neutral skin."""

    triangles: np.ndarray  # (F, 3) int64
    area: np.ndarray  # (F,)
    coeff: np.ndarray  # (F, 3): a_f W_f as (w00, w01, w11)
    mass: np.ndarray  # (V,)
    mu: float
    matrix: sp.csc_matrix  # K
    factor: spla.SuperLU

    @property
    def n_vertices(self) -> int:
        return len(self.mass)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """K^-1 rhs for rhs (V, c), float64."""
        return self.factor.solve(np.ascontiguousarray(rhs, dtype=np.float64))


def face_geometry(
    neutral: np.ndarray, triangles: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per face: area a_f, the metric coefficients a_f W_f (w00, w01, w11); per vertex: m_v."""
    v = np.asarray(neutral, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    e1 = v[t[:, 1]] - v[t[:, 0]]
    e2 = v[t[:, 2]] - v[t[:, 0]]
    area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    if (area < MIN_FACE_AREA).any():
        f = int(np.argmin(area))
        raise ValueError(f"skin triangle {f} is degenerate on the neutral (area {area[f]:.3g})")
    g00, g01, g11 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    det = g00 * g11 - g01 * g01
    coeff = np.stack([g11, -g01, g00], axis=1) / det[:, None] * area[:, None]
    mass = np.zeros(len(v))
    np.add.at(mass, t.ravel(), np.repeat(area / 3.0, 3))
    return area, coeff, mass


def dt_system(
    neutral_skin: np.ndarray, triangles: np.ndarray, regularisation: float = DEFAULT_REGULARISATION
) -> DtSystem:
    """Assemble and factorise K for an avatar's neutral skin (V, 3)."""
    t = np.asarray(triangles, dtype=np.int64)
    area, c, mass = face_geometry(neutral_skin, t)
    n = len(neutral_skin)
    if mass.min() <= 0:
        raise ValueError("every skin vertex must belong to a skin triangle")
    mu = regularisation / float(mass.mean())
    i, j, k = t[:, 0], t[:, 1], t[:, 2]
    c00, c01, c11 = c[:, 0], c[:, 1], c[:, 2]
    rows = np.concatenate([j, k, j, k, i, j, i, k, i])
    cols = np.concatenate([j, k, k, j, j, i, k, i, i])
    vals = np.concatenate(
        [c00, c11, c01, c01, -c00 - c01, -c00 - c01, -c01 - c11, -c01 - c11, c00 + 2 * c01 + c11]
    )
    lap = sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsc()
    matrix = (lap + sp.diags(mu * mass)).tocsc()
    factor = spla.splu(matrix, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
    return DtSystem(t, area, c, mass, mu, matrix, factor)


def residual_rhs(system: DtSystem, skin: torch.Tensor, dg_minus_i: torch.Tensor) -> torch.Tensor:
    """r for a batch: skin (B, V, 3), dg_minus_i (B, F, 3, 3) -> (B, V, 3). Differentiable."""
    t = torch.as_tensor(system.triangles, device=skin.device)
    c = torch.as_tensor(system.coeff, dtype=skin.dtype, device=skin.device)
    s0, s1, s2 = skin[:, t[:, 0]], skin[:, t[:, 1]], skin[:, t[:, 2]]
    e = torch.stack([s1 - s0, s2 - s0], dim=-1)  # (B, F, 3, 2)
    p = dg_minus_i.to(skin.dtype) @ e  # (G - I) E: (B, F, 3, 2)
    col0 = p[..., 0] * c[:, 0, None] + p[..., 1] * c[:, 1, None]  # (P a W)[:, 0]
    col1 = p[..., 0] * c[:, 1, None] + p[..., 1] * c[:, 2, None]
    r = torch.zeros_like(skin)
    r = r.index_add(1, t[:, 1], col0)
    r = r.index_add(1, t[:, 2], col1)
    return r.index_add(1, t[:, 0], -(col0 + col1))


class _SolveK(torch.autograd.Function):
    """X = K^-1 r with the prefactored K; K is symmetric, so the gradient is K^-1 too."""

    @staticmethod
    def forward(ctx, r: torch.Tensor, system: DtSystem) -> torch.Tensor:  # type: ignore[override]
        ctx.system = system
        return _solve_batch(system, r)

    @staticmethod
    def backward(ctx, grad: torch.Tensor) -> tuple[torch.Tensor, None]:  # type: ignore[override]
        return _solve_batch(ctx.system, grad), None


def _solve_batch(system: DtSystem, r: torch.Tensor) -> torch.Tensor:
    b, v, _ = r.shape
    rhs = r.detach().to("cpu", torch.float64).permute(1, 0, 2).reshape(v, 3 * b).numpy()
    x = torch.from_numpy(system.solve(rhs)).reshape(v, b, 3).permute(1, 0, 2)
    return x.to(r.device, r.dtype)


def deformation_transfer(
    system: DtSystem, skin: torch.Tensor, dg_minus_i: torch.Tensor
) -> torch.Tensor:
    """DT(S_t, G) for a batch: skin (B, V, 3) and G - I (B, F, 3, 3) -> X (B, V, 3).
    DT(S_t, I) = S_t: with G - I zero everywhere (a model at its closed-form start) and no
    gradient to carry there is no right-hand side to build and nothing to solve, as in the
    native runtime."""
    if not torch.is_grad_enabled() and not bool(dg_minus_i.any()):
        return skin
    return skin + _SolveK.apply(residual_rhs(system, skin, dg_minus_i), system)
