"""SoftDECA's residual stage: what the per-vertex stages leave of the physics, as a few modes
of the whole skin shared by every head, with coefficients from an MLP of the frame's weights,
the gravity load and each region's mean parameter values.

Why this form: the start's residual on unseen heads lies mostly in modes shared between heads
(projected on 64 modes of the train residual it drops to a quarter), but its coefficients
depend nonlinearly on the weights and on the material; ridge maps of them gained nothing, an
MLP did, and the regions' values of p (not only the global p) made the difference
(docs/training.md, "The residual stage").

Split for the runtime (docs/bundle.md): `condition` is computed once per preparation from the
per-vertex parameters (the region means and the parameters' share of the first layer), and
`coefficients` per frame from the weights and that condition; the modes are a constant table,
the frame adds sum_k c_k modes[:, k] to the skin. The last mode is the residual's mean, with a
coefficient fixed at 1."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from softdeca_train.models.blocks import (
    NetworkSizes,
    Normalise,
    gravity_columns,
    gravity_load,
    region_means,
    rest_gate,
)
from softdeca_train.parameters import ParameterSpec

N_WEIGHTS = 52


@dataclass(frozen=True)
class ResidualSizes:
    """The stage's shape. Measured on softdeca-l3-c5's static split (docs/training.md): 32 and
    64 modes did as well; dropout 0.3 generalised best to unseen heads; averaging several
    independently trained members gained a little more."""

    modes: int = 31  # plus the mean: 32 slots, the latent size of the other stages
    hidden: int = 256
    members: int = 5
    dropout: float = 0.3
    # NetworkSizes.rest_gate: None, coefficients c(w) and the mean mode at 1; a number, the
    # coefficients c(w) - c(0) and the mean mode at the rest gate, so the stage is 0 at rest
    rest_gate: float | None = None

    @staticmethod
    def of(sizes: NetworkSizes) -> ResidualSizes:
        return ResidualSizes(
            sizes.residual_modes,
            sizes.residual_hidden,
            sizes.residual_members,
            rest_gate=sizes.rest_gate,
        )


DEFAULT_SIZES = ResidualSizes()


@dataclass(frozen=True)
class ResidualFit:
    """How the members are trained on the modes' coefficients (AdamW, cosine decay)."""

    steps: int = 3000
    batch: int = 128
    lr: float = 1e-3
    weight_decay: float = 1e-2
    seed: int = 0
    # With contrasts (frames of one identity and expression that differ in one factor of p):
    # modes of their differences join the table, and the members also learn the differences
    # of the coefficients, weighted against the plain fit by this factor.
    contrast_modes: int = 16
    contrast_weight: float = 1.0


DEFAULT_FIT = ResidualFit()


class ResidualStage(nn.Module):
    """offsets (B, V, 3) = sum_k c_k(w, g, p_regions) table[:, k], c_last = 1."""

    def __init__(
        self,
        labels: np.ndarray,
        specs: Sequence[ParameterSpec],
        sizes: ResidualSizes = DEFAULT_SIZES,
    ) -> None:
        super().__init__()
        self.sizes = sizes
        labels = np.asarray(labels)
        n_regions = int(labels.max()) + 1
        self.normalise = Normalise(specs)
        self.gravity = gravity_columns(specs)
        self.register_buffer("regions", torch.from_numpy(region_means(labels, n_regions)))
        n_p = 3 + n_regions * len(specs)
        self.n_inputs = N_WEIGHTS + n_p
        # the inputs' standardisation, from the train frames (ResidualStage.fit)
        self.register_buffer("input_mean", torch.zeros(self.n_inputs))
        self.register_buffer("input_std", torch.ones(self.n_inputs))
        h = sizes.hidden
        self.members = nn.ModuleList(
            nn.Sequential(
                nn.Linear(self.n_inputs, h),
                nn.SiLU(),
                nn.Dropout(sizes.dropout),
                nn.Linear(h, h),
                nn.SiLU(),
                nn.Dropout(sizes.dropout),
                nn.Linear(h, sizes.modes),
            )
            for _ in range(sizes.members)
        )
        # (V, modes + 1, 3) metres; zero until fitted, so the stage starts as a no-op. A buffer:
        # the modes come from the data in closed form; gradient steps train the members only
        # (Adam would move every entry by about its learning rate, metres, per step).
        self.register_buffer("table", torch.zeros(len(labels), sizes.modes + 1, 3))

    # ---- the inputs ----------------------------------------------------------------------
    def parameter_features(self, parameters: torch.Tensor) -> torch.Tensor:
        """(V, P) raw per-vertex parameters -> (1, 3 + R P): the gravity load and each
        region's mean normalised values."""
        load = gravity_load(parameters.mean(0, keepdim=True), self.gravity)
        own = self.regions.to(parameters.dtype) @ self.normalise(parameters)  # (R, P)
        return torch.cat([load, own.reshape(1, -1)], dim=1)

    def inputs(self, weights: torch.Tensor, parameters: torch.Tensor) -> torch.Tensor:
        """(B, 52 + 3 + R P) unstandardised inputs of the members."""
        pf = self.parameter_features(parameters)
        return torch.cat([weights, pf.expand(len(weights), -1)], dim=1)

    # ---- the two runtime halves -----------------------------------------------------------
    @property
    def condition_size(self) -> int:
        """C: every member's first-layer share, then (with a rest gate) the coefficients at
        rest, so that the per-frame half subtracts them instead of running the members twice."""
        gated = self.sizes.rest_gate is not None
        return self.sizes.members * self.sizes.hidden + (self.sizes.modes if gated else 0)

    def condition(self, parameters: torch.Tensor) -> torch.Tensor:
        """(1, C): the parameters' share of every member's first layer, then with a rest gate
        the members' mean at w = 0 (condition_size)."""
        n = N_WEIGHTS
        x = (self.parameter_features(parameters) - self.input_mean[n:]) / self.input_std[n:]
        parts = []
        for m in self.members:
            first = m[0]
            assert isinstance(first, nn.Linear)
            parts.append(x @ first.weight[:, n:].T + first.bias)
        shares = torch.cat(parts, dim=1)
        if self.sizes.rest_gate is None:
            return shares
        at_rest = self.members_mean(torch.zeros(1, n, dtype=shares.dtype), shares)
        return torch.cat([shares, at_rest], dim=1)

    def members_mean(self, weights: torch.Tensor, condition: torch.Tensor) -> torch.Tensor:
        """(B, modes): the members' mean output for these weights and that condition."""
        n, h = N_WEIGHTS, self.sizes.hidden
        xw = (weights - self.input_mean[:n]) / self.input_std[:n]
        out = 0
        for i, m in enumerate(self.members):
            first = m[0]
            assert isinstance(first, nn.Linear)
            a = xw @ first.weight[:, :n].T + condition[:, i * h : (i + 1) * h]
            out = out + m[1:](a)
        return out / len(self.members)

    def coefficients(self, weights: torch.Tensor, condition: torch.Tensor) -> torch.Tensor:
        """(B, modes + 1): the members' mean, then the mean mode's coefficient (1; with a rest
        gate, c(w) - c(0) and the gate: 0 at rest)."""
        tau = self.sizes.rest_gate
        c = self.members_mean(weights, condition)
        if tau is not None:
            c = c - condition[:, self.sizes.members * self.sizes.hidden :]
        return torch.cat([c, rest_gate(weights, tau)], dim=1)

    def forward(self, weights: torch.Tensor, parameters: torch.Tensor) -> torch.Tensor:
        c = self.coefficients(weights, self.condition(parameters))
        return torch.einsum("bk,vkc->bvc", c, self.table)

    # ---- fitting ---------------------------------------------------------------------------
    @torch.no_grad()
    def set_modes(
        self,
        residual: torch.Tensor,
        contrasts: torch.Tensor | None = None,
        extra: int = 0,
        gates: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """Take the mean and leading modes of `residual` (N, V, 3) metres as the table and
        return the modes' coefficients per frame (N, modes), in units of each mode's spread
        (the table holds the modes scaled by it). With `contrasts` (M, V, 3), differences
        between frames that differ in one factor of p, the last `extra` modes are theirs
        (orthogonal to the others): the response to p is small next to what differs between
        heads and expressions, and the residual's leading modes alone miss part of it.
        `gates` (N, 1): each frame's coefficient of the mean mode (the rest gate; 1 without):
        the mean is then their least-squares mean, and what is left of it is fitted by modes."""
        n, k = len(residual), self.sizes.modes
        # Column block by column block in double: a whole double copy of the residual (and of
        # its centred form) is gigabytes for thousands of frames of the skin.
        r = residual.reshape(n, -1)
        g = torch.ones(n, dtype=torch.float64) if gates is None else gates.double().reshape(n)
        weight = float((g * g).sum())
        mean = torch.zeros(r.shape[1], dtype=torch.float64)
        if weight > 0:
            for cols in _column_blocks(r.shape[1]):
                mean[cols] = g @ r[:, cols].double() / weight

        def centred(cols: slice) -> torch.Tensor:
            return r[:, cols].double() - g[:, None] * mean[cols]

        extra = 0 if contrasts is None else min(extra, k)
        basis = _leading_rows(centred, n, r.shape[1], k - extra)  # (k1, 3V) orthonormal
        scale = _rms(_project(centred, n, basis))
        if extra:
            assert contrasts is not None
            d = contrasts.reshape(len(contrasts), -1)
            on = _project(lambda cols: d[:, cols].double(), len(d), basis)

            def rest(cols: slice) -> torch.Tensor:
                return d[:, cols].double() - on @ basis[:, cols]

            more = _leading_rows(rest, len(d), d.shape[1], extra)
            basis = torch.cat([basis, more])
            scale = torch.cat([scale, _rms(_project(lambda c: d[:, c].double(), len(d), more))])
        keep = scale > scale.max() * 1e-9 if len(scale) else scale > 0
        scale = torch.where(keep, scale, torch.ones_like(scale))
        coef = torch.zeros(n, k, dtype=torch.float64)
        coef[:, : len(basis)] = _project(centred, n, basis) / scale * keep
        table = torch.zeros_like(self.table, dtype=torch.float64)
        v = self.table.shape[0]
        table[:, : len(basis)] = (
            (basis * (scale * keep)[:, None]).reshape(len(basis), v, 3).permute(1, 0, 2)
        )
        table[:, -1] = mean.reshape(v, 3)
        self.table.copy_(table.float())
        return coef.float()

    def fit(
        self,
        weights: torch.Tensor,
        parameter_features: torch.Tensor,
        residual: torch.Tensor,
        cfg: ResidualFit = DEFAULT_FIT,
        progress: bool = True,
        pairs: torch.Tensor | None = None,
    ) -> dict[str, float]:
        """Fit the table to `residual` (N, V, 3) and train every member on the modes'
        coefficients from the frames' weights (N, 52) and parameter features (N, 3 + R P).
        `pairs` (M, 2): frames of one identity and expression whose p differs in one factor;
        the members then also learn their coefficients' differences (ResidualFit).
        Returns the fit's train errors (mm, mean per-vertex distance)."""
        x = torch.cat([weights, parameter_features], dim=1).float()
        with torch.no_grad():
            self.input_mean.copy_(x.mean(0))
            # an input the train frames (nearly) never move is no input: dividing by its
            # spread would turn rounding, or a value the data never had, into huge activations
            std = x.std(0)
            constant = std < 1e-3
            self.input_std.copy_(torch.where(constant, torch.ones_like(std), std))
        xn = (x - self.input_mean) / self.input_std
        tau = self.sizes.rest_gate
        gates = rest_gate(weights.float(), tau)
        # With a rest gate, a member's coefficients are m(x) - m(x at rest): the same frame's
        # inputs with every weight 0, under the same dropout mask.
        x0 = x.clone()
        x0[:, :N_WEIGHTS] = 0.0
        xn0 = (x0 - self.input_mean) / self.input_std

        def out(m: nn.Module, rows: torch.Tensor) -> torch.Tensor:
            if tau is None:
                return m(xn[rows])
            seed = int(torch.randint(0, 2**31 - 1, (1,)))
            torch.manual_seed(seed)
            y = m(xn[rows])
            torch.manual_seed(seed)
            return y - m(xn0[rows])

        contrasts = None
        if pairs is not None and len(pairs):
            contrasts = residual[pairs[:, 0]] - residual[pairs[:, 1]]
        target = self.set_modes(residual, contrasts, cfg.contrast_modes, gates)
        if contrasts is not None:
            assert pairs is not None
            change = target[pairs[:, 0]] - target[pairs[:, 1]]
            change_scale = change.pow(2).mean().clamp_min(1e-12)
        gen = torch.Generator().manual_seed(cfg.seed)
        bar = tqdm(total=cfg.steps * len(self.members), desc="residual stage", disable=not progress)
        for i, m in enumerate(self.members):
            torch.manual_seed(cfg.seed * 1000 + i)
            for layer in m:
                if isinstance(layer, nn.Linear):
                    layer.reset_parameters()
            opt = torch.optim.AdamW(m.parameters(), cfg.lr, weight_decay=cfg.weight_decay)
            sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, cfg.steps)
            m.train()
            with torch.enable_grad():  # also when called under no_grad (a model's start)
                for _ in range(cfg.steps):
                    idx = torch.randint(0, len(xn), (min(cfg.batch, len(xn)),), generator=gen)
                    loss = ((out(m, idx) - target[idx]) ** 2).mean()
                    if contrasts is not None:
                        assert pairs is not None
                        j = torch.randint(
                            0, len(pairs), (min(cfg.batch, len(pairs)),), generator=gen
                        )
                        # one dropout mask for both frames of a pair: their difference is
                        # the response, not two masks' noise
                        seed = int(torch.randint(0, 2**31 - 1, (1,), generator=gen))
                        torch.manual_seed(seed)
                        ya = out(m, pairs[j, 0])
                        torch.manual_seed(seed)
                        yb = out(m, pairs[j, 1])
                        miss = ((ya - yb - change[j]) ** 2).mean() / change_scale
                        loss = loss + cfg.contrast_weight * miss
                    opt.zero_grad()
                    loss.backward()
                    opt.step()
                    sched.step()
                    bar.update()
            m.eval()
            first = m[0]
            assert isinstance(first, nn.Linear)
            with torch.no_grad():  # what never varied in training is read as nothing at all
                first.weight[:, constant] = 0.0
        bar.close()
        with torch.no_grad():
            every = torch.arange(len(xn))
            c = torch.stack([out(m, every) for m in self.members]).mean(0)
            c = torch.cat([c, gates], dim=1)
            before = after = 0.0
            for i in range(0, len(residual), 256):  # a frame batch at a time: N meshes each
                part = residual[i : i + 256]
                fitted = torch.einsum("bk,vkc->bvc", c[i : i + 256], self.table)
                before += float(part.norm(dim=-1).mean(dim=1).sum())
                after += float((part - fitted).norm(dim=-1).mean(dim=1).sum())
        n = max(len(residual), 1)
        return {"residual_mm": before / n * 1e3, "after_mm": after / n * 1e3}


def _column_blocks(d: int, size: int = 4096) -> list[slice]:
    return [slice(i, min(i + size, d)) for i in range(0, d, size)]


def _leading_rows(block: Callable[[slice], torch.Tensor], n: int, d: int, k: int) -> torch.Tensor:
    """(k', d) orthonormal rows spanning the k leading directions of the rows of a matrix
    X (n, d) given by its column blocks (`block(cols)`, double), from the n x n Gram matrix
    (n is thousands, d tens of thousands); k' <= k where X has fewer independent rows."""
    if k <= 0 or n == 0:
        return torch.zeros(0, d, dtype=torch.float64)
    gram = torch.zeros(n, n, dtype=torch.float64)
    for cols in _column_blocks(d):
        x = block(cols)
        gram += x @ x.T
    ev, u = torch.linalg.eigh(gram)
    order = torch.argsort(ev, descending=True)[:k]
    s = ev[order].clamp_min(0).sqrt()
    order = order[s > s[0] * 1e-9]
    ut = u[:, order].T / s[: len(order), None]
    out = torch.empty(len(order), d, dtype=torch.float64)
    for cols in _column_blocks(d):
        out[:, cols] = ut @ block(cols)
    return out


def _project(block: Callable[[slice], torch.Tensor], n: int, basis: torch.Tensor) -> torch.Tensor:
    """X @ basis.T (n, k) for X (n, d) given by its column blocks."""
    out = torch.zeros(n, len(basis), dtype=torch.float64)
    for cols in _column_blocks(basis.shape[1]):
        out += block(cols) @ basis[:, cols].T
    return out


def _rms(x: torch.Tensor) -> torch.Tensor:
    """Per column: the root mean square over the rows."""
    return x.pow(2).mean(0).sqrt()


class ResidualCondition(nn.Module):
    """The exported prepare half: parameters (V, P) -> condition (1, C), modes (V, K, 3)."""

    def __init__(self, stage: ResidualStage) -> None:
        super().__init__()
        self.stage = stage
        self.train(stage.training)  # a fresh module trains; export restores this mode

    def forward(self, parameters: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.stage.condition(parameters), self.stage.table * 1.0


class ResidualCoefficients(nn.Module):
    """The exported per-frame half: weights (B, 52), condition (1, C) -> coefficients (B, K)."""

    def __init__(self, stage: ResidualStage) -> None:
        super().__init__()
        self.stage = stage
        self.train(stage.training)

    def forward(self, weights: torch.Tensor, condition: torch.Tensor) -> torch.Tensor:
        return self.stage.coefficients(weights, condition)
