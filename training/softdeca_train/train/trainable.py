"""The trainable models, each as `loss(batch)` and `predict(batch)` over a Batch: SoftDECA
(deformation gradients through the differentiable deformation transfer, eq. 16-19), its
vertex-position variant, SparseSoftDECA (eq. 25), the dynamics stage (eq. 21) over a frozen
static model, and the Table 1 baselines. Errors are per-vertex Euclidean distances on S.

Kept whole: the registry's models share the Batch handling, the features and the
losses defined here; each model is a class of its own."""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Sequence
from dataclasses import replace

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from softdeca_train.data.personalise import personalise
from softdeca_train.data.plan import FIXED
from softdeca_train.landmarks.arkit_reference import ArkitFace
from softdeca_train.models.blocks import rest_gate
from softdeca_train.models.dt import deformation_transfer
from softdeca_train.models.networks import (
    EXPRESSION_SLOTS,
    DynamicsNetwork,
    ElementMLP,
    HyperNetwork,
    LandmarkEncoder,
    NetworkSizes,
    Normalise,
    WeightEncoder,
    mlp,
)
from softdeca_train.models.residual import ResidualFit, ResidualSizes, ResidualStage
from softdeca_train.models.smoothing import FieldSmoothing
from softdeca_train.models.topology import TemplateDefinition
from softdeca_train.parameters import ParameterSpec
from softdeca_train.template.regions import CONTROL_REGIONS, REGIONS
from softdeca_train.train.batches import Batch, Dataset
from softdeca_train.train.gradients import GRADIENT_CLAMP, frame_gradients
from softdeca_train.train.local_fit import LocalRidge

EPS = 1e-12
CM = 0.01  # vertex offsets are learned in centimetres (HyperNetwork.unit)
# f_ph's learning-rate factor: on softdeca-l3-i2, 400-step runs reached 0.570 / 0.524 / 0.479 /
# 0.459 mm on the static test split at 0.3 / 0.1 / 0.03 / 0.01 and 0.451 mm frozen (no
# correction 0.595 mm; docs/training.md): with one (identity, p) group per step, larger
# hypernetwork steps fit the group at hand and forget the others.
HYPER_LR_SOFTDECA = 0.01


def vertex_error(x: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
    """Per-vertex Euclidean distance (..., V)."""
    return torch.sqrt(((x - t) ** 2).sum(-1) + EPS)


class Trainable(nn.Module):
    """A model trained on one kind of batch. Subclasses implement `predict` (B, V, 3)."""

    kind = "static"

    def init_from_data(self, batches: Sequence[Batch]) -> None:
        """Data-driven initialisation from a sample of batches (default: none)."""

    def init_from_dataset(
        self,
        data: Dataset,
        rng: np.random.Generator,
        progress: bool = True,
        contrasts: Dataset | None = None,
        more: Sequence[Dataset] = (),
    ) -> None:
        """Initialisation before the first step: by default `init_from_data` on 48 shuffled
        train batches; a model with a closed-form start over all the data overrides it.
        `contrasts`: a contrasts dataset (data/plan.py contrast), for the models that use
        one (SoftDECA's residual stage); `more`: datasets drawn like `data` whose static
        train frames join a closed-form start (SoftDECA's); the others ignore both."""
        if type(self).init_from_data is not Trainable.init_from_data:
            self.init_from_data(list(itertools.islice(data.batches(self.kind, "train", rng), 48)))

    # The per-element hypernetworks (attribute names) and their learning-rate factor. Adam
    # moves every weight by about the learning rate per step whatever its gradient, so a
    # hypernetwork whose output is a small correction may need smaller steps than the
    # per-frame encoder; LoopConfig.hyper_lr overrides the factor for one run.
    hypernetworks: tuple[str, ...] = ()
    hyper_lr: float = 1.0

    def lr_scales(self, hyper_lr: float | None = None) -> dict[str, float]:
        """Learning-rate factors by parameter-name prefix."""
        f = self.hyper_lr if hyper_lr is None else hyper_lr
        return {f"{name}.": f for name in self.hypernetworks}

    def predict(self, batch: Batch) -> torch.Tensor:
        raise NotImplementedError

    def loss(self, batch: Batch) -> tuple[torch.Tensor, dict[str, float]]:
        err = vertex_error(self.predict(batch), batch.T)
        mm = float(err.detach().mean()) * 1e3
        # the batch's "no correction" error: groups differ tenfold in how far the physics
        # moves S, so progress reads better as the ratio of the two
        base = float(vertex_error(batch.S, batch.T).mean()) * 1e3
        return err.mean(), {"error_mm": mm, "no_correction_mm": base}


@torch.no_grad()
def init_basis(
    hyper: HyperNetwork,
    encoder: nn.Sequential,
    inputs: torch.Tensor,
    targets: torch.Tensor,
    unit: float,
    ridge_scale: float = 0.1,
    readout: bool = True,
) -> torch.Tensor:
    """Start a model "output = z(inputs) . L" at the data's principal components: L's base
    table = the leading modes of `targets` (n, elements * k, in `unit`s), and the encoder's
    last layer = the ridge least-squares readout of the mode coefficients from its (random)
    features (`readout`; else zero). Training then refines both instead of discovering the
    modes from noise. Returns the frames' mode coefficients (n, k)."""
    assert hyper.base is not None
    n, k = len(targets), hyper.latent
    m = targets.reshape(n, -1).double() / unit
    u, s, vt = torch.linalg.svd(m, full_matrices=False)
    k_data = min(k, len(s))
    base = torch.zeros_like(hyper.base)
    modes = (vt[:k_data] * (s[:k_data, None] / np.sqrt(n))).reshape(k_data, -1, hyper.k)
    base[:, :k_data] = modes.permute(1, 0, 2).float()
    hyper.base.copy_(base)
    last = encoder[-1]
    assert isinstance(last, nn.Linear)
    target = torch.zeros(n, k, dtype=torch.float64)
    target[:, :k_data] = u[:, :k_data] * np.sqrt(n)
    if not readout:  # z = 0: the model starts exactly at its input (no correction)
        last.weight.zero_()
        last.bias.zero_()
        return target
    feats = encoder[:-1](inputs).double()
    a = torch.cat([feats, torch.ones(n, 1, dtype=torch.float64)], 1)
    # a strong ridge (relative to the features' scale): the readout must generalise from a
    # few hundred frames, and the coefficients also vary with p and h, which it cannot see
    ridge = ridge_scale * float((a * a).sum(0).mean()) * torch.eye(a.shape[1], dtype=torch.float64)
    w = torch.linalg.solve(a.T @ a + ridge, a.T @ target)  # (hidden + 1, k)
    last.weight.copy_(w[:-1].T.float())
    last.bias.copy_(w[-1].float())
    return target


def expand(p: torch.Tensor, n: int) -> torch.Tensor:
    """One global parameter vector (1, P) as a per-element map (n, P)."""
    return p.expand(n, p.shape[-1])


class NoCorrection(Trainable):
    """The trivial baseline: the linear blend S_t itself."""

    def predict(self, batch: Batch) -> torch.Tensor:
        return batch.S


class SoftDeca(Trainable):
    """f(S_t, w, p, h) = DT(S_t, I + z(w) . L(p, h)) (eq. 17-19; the residual form of
    docs/bundle.md)."""

    hypernetworks = ("f_ph",)
    hyper_lr = HYPER_LR_SOFTDECA

    def __init__(self, d: TemplateDefinition, specs: Sequence[ParameterSpec], sizes: NetworkSizes):
        super().__init__()
        self.f_w = WeightEncoder(len(d.blendshapes), sizes)
        self.f_ph = HyperNetwork(d.n_faces, specs, sizes, 9, 1e-4, base=True)
        self.n_faces = d.n_faces
        self.register_buffer(
            "triangles", torch.as_tensor(d.skin_triangles, dtype=torch.long), persistent=False
        )

    def init_from_data(self, batches: Sequence[Batch]) -> None:
        """L0 = the leading modes of the deformation gradients that map S_t to T per face (the
        classic deformation-transfer frames [e1, e2, n]), f_w's readout = their coefficients."""
        g = torch.cat([frame_gradients(b.S, b.T, self.triangles) for b in batches])
        eye = torch.eye(3).reshape(1, 1, 3, 3)
        w = torch.cat([b.weights for b in batches])
        # a few sliver faces reach |G - I| of 30 and would own the leading modes; clamped at
        # 0.3 (the 90th percentile) DT still lands 0.17 mm from T where S_t is 0.69 mm off
        # (measured on a softdeca-l3-v3 batch)
        dg = (g - eye).clamp(-GRADIENT_CLAMP, GRADIENT_CLAMP)
        init_basis(self.f_ph, self.f_w.net, w, dg.reshape(len(g), -1), 1.0, readout=False)

    def deformation_gradients(self, batch: Batch) -> torch.Tensor:
        hyper = self.f_ph(batch.face_parameters(self.n_faces), batch.h)  # (F, latent, 9)
        z = self.f_w(batch.weights)  # (B, latent)
        return torch.einsum("bk,fkn->bfn", z, hyper).reshape(len(z), self.n_faces, 3, 3)

    def predict(self, batch: Batch) -> torch.Tensor:
        return deformation_transfer(batch.dt, batch.S, self.deformation_gradients(batch))


def static_inputs(specs: Sequence[ParameterSpec]) -> tuple[str, ...]:
    """The parameters static frames vary (data/plan.py FIXED holds the others at their
    defaults): the only ones a closed-form fit on them can learn a response to."""
    return tuple(s.name for s in specs if s.name not in FIXED["static"])


def varied_region_labels(labels: np.ndarray) -> np.ndarray:
    """Region labels (template/regions.py REGIONS) renumbered over the regions a regional pattern
    sets (controls/definitions.py CONTROL_REGIONS); -1 for the others, which keep the group's
    p and so add no input of their own."""
    number = np.full(len(REGIONS), -1, np.int64)
    for k, name in enumerate(CONTROL_REGIONS):
        number[REGIONS.index(name)] = k
    return number[np.asarray(labels, np.int64)]


class SoftDecaHybrid(Trainable):
    """SoftDECA with a vertex stage and a residual stage:
    X = DT(S_t, I + z(w) . L(p, h)) + z(w) . L_v(p, h) + c(w, p) . M.

    DT alone cannot reach the physics: fed the physics' own face gradients it stays 0.187 mm
    from T where S_t is 0.398 mm off (`linear-baseline --local`, docs/training.md), because its
    pull toward S_t holds back the smooth, low-frequency part of the correction (the sag).
    The vertex stage carries that part. z has a linear path in w and a constant last entry
    whose L_v tensor is an affine map of each vertex's own parameters, of the localisable
    ones averaged around it (models/smoothing.py) and of each region's mean of them, so the
    model starts at the per-vertex ridge fit (`init_from_dataset`, closed form) and a
    region's control acts in and around its region. The tissues' strain and volume weights
    also enter the L_v tensors of z's leading codes (LocalLinear.slot_table): their response
    changes with the expression. What the fit leaves is largely shared between heads but
    nonlinear in w and p: the residual stage (models/residual.py), fitted to it right after,
    carries that part."""

    hypernetworks = ("f_ph", "f_ph_v")
    hyper_lr = HYPER_LR_SOFTDECA

    def __init__(
        self,
        d: TemplateDefinition,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
    ):
        super().__init__()
        self.residual_fit = ResidualFit(steps=sizes.residual_steps)
        self.f_w = WeightEncoder(len(d.blendshapes), sizes, linear_skip=True, constant_slot=True)
        self.f_ph = HyperNetwork(d.n_faces, specs, sizes, 9, 1e-4, base=True)
        smoothing = None if d.skin_rest is None else FieldSmoothing(d.skin_rest)
        self.f_ph_v = HyperNetwork(
            d.skin_vertices,
            specs,
            sizes,
            3,
            1e-5,
            unit=CM,
            base=True,
            local_linear=True,
            smoothing=smoothing,
            slots=EXPRESSION_SLOTS,
            regions=None
            if d.skin_regions is None or not sizes.region_means
            else varied_region_labels(d.skin_regions),
            inputs=static_inputs(specs),
        )
        self.n_faces, self.n_vertices = d.n_faces, d.skin_vertices
        self.n_weights = len(d.blendshapes)
        regions = d.skin_regions
        self.f_r = (
            None if regions is None else ResidualStage(regions, specs, ResidualSizes.of(sizes))
        )

    def gated(self, weights: torch.Tensor, own: torch.Tensor) -> torch.Tensor:
        """(V, B, F): each vertex's local features `own` (V, F) as the constant slot weighs
        them in each frame: times the rest gate (1 without one; models/blocks.py)."""
        gate = rest_gate(weights.double(), self.f_w.rest_tau)[:, 0]  # (B,)
        return own[:, None] * gate[None, :, None]

    def vertex_features(self, weights: torch.Tensor, p_vertices: torch.Tensor) -> torch.Tensor:
        """(V, B, 52 + 1 + P + 3): [w, local features of each vertex] (the vertex stage's
        linear inputs, in the networks' own normalisation; the local features weighed by the
        rest gate, so a start exact at rest is fitted as such)."""
        assert self.f_ph_v.local is not None
        own = self.f_ph_v.local.features(p_vertices).double()  # (V, 1 + P + 3)
        b, v = len(weights), len(own)
        return torch.cat([weights.double()[None].expand(v, b, -1), self.gated(weights, own)], dim=2)

    @torch.no_grad()
    def code_features(self, weights: torch.Tensor, p_vertices: torch.Tensor) -> torch.Tensor:
        """(V, B, r + F + slots E): [z's first r codes, the F local features of each
        vertex, the leading `slots` codes times the vertex's expression-dependent parameters]
        (the vertex stage's inputs once f_w's linear path is set; r = latent - 1)."""
        local = self.f_ph_v.local
        assert local is not None
        z = self.f_w(weights).double()[:, :-1]  # (B, r), the constant slot left out
        own = local.features(p_vertices).double()  # (V, F)
        v, b = len(own), len(z)
        parts = [z[None].expand(v, b, -1), self.gated(weights, own)]
        if local.slots:
            e = local.slot_features(p_vertices).double()  # (V, E)
            prod = torch.einsum("bs,ve->vbse", z[:, : local.slots], e)
            parts.append(prod.reshape(v, b, -1))
        return torch.cat(parts, dim=2)

    @torch.no_grad()
    def init_from_dataset(
        self,
        data: Dataset,
        rng: np.random.Generator | None = None,
        progress: bool = True,
        contrasts: Dataset | None = None,
        more: Sequence[Dataset] = (),
        ridge: float = 1e-3,
    ) -> None:
        """Start at the per-vertex ridge fit of T - S_t on [w, LocalLinear's features] (1,
        p_v, g_v and the averaged parameters) over the kept static train frames of `data`
        and of `more`: its w part (rank latent - 1, reduced-rank regression) in f_w's linear
        path and L_v's base, its constant and parameter parts in L_v's local map; every MLP's
        output and the DT stage start at zero."""
        fit: LocalRidge | None = None
        moment = torch.zeros(self.n_weights, self.n_weights, dtype=torch.float64)
        sources = [data, *more]
        kept = sum(d.left_out("static", "train")["kept"] for d in sources)
        bar = tqdm(total=kept, desc="vertex stage fit", unit="frame", disable=not progress)
        for b in static_train(sources):
            x = self.vertex_features(b.weights, b.vertex_parameters(self.n_vertices))
            fit = fit or LocalRidge(self.n_vertices, x.shape[-1], 3)
            fit.add(x, (b.T - b.S).transpose(0, 1) / CM)
            moment += b.weights.double().T @ b.weights.double()
            bar.update(b.frames)
        bar.close()
        if fit is None:
            raise ValueError("no static train frame to start the vertex stage from")
        coef = fit.solve(ridge)  # (V, 52 + 1 + P + 3, 3), centimetres
        nw, v = self.n_weights, self.n_vertices
        a = coef[:, :nw].permute(0, 2, 1).reshape(v * 3, nw)  # w part, (V * 3, 52)
        # Rank r in the norm of the data's weights (reduced-rank regression): with C = R R^T
        # their second moment, the truncation of A R loses least of E |A w|^2; a plain SVD of A
        # keeps modes of shapes that are rarely used (start 0.211 mm against the full fit's
        # 0.200 on softdeca-l3-c3's test split at latent 32).
        # The moment is regularised relative to its own scale: weights the data (nearly) never
        # moves would otherwise get R^-1 in the thousands, and with them codes z in the
        # thousands for inputs that do move them (f_w's ONNX export then differed from torch by
        # 2.4e-4: float32 rounding at that scale).
        moment = moment / fit.frames
        ridge_w = 1e-2 * float(torch.trace(moment)) / nw + 1e-12
        chol = torch.linalg.cholesky(moment + ridge_w * torch.eye(nw, dtype=torch.float64))
        u, sv, vt = torch.linalg.svd(a @ chol, full_matrices=False)
        vt = torch.linalg.solve_triangular(chol.T, vt.T, upper=True).T  # rows: (V^T R^-1)
        r = min(self.f_ph_v.latent - 1, len(sv))
        hyper, enc = self.f_ph_v, self.f_w
        assert hyper.base is not None and hyper.local is not None and enc.skip is not None
        base = torch.zeros_like(hyper.base)
        base[:, :r] = (u[:, :r] * sv[:r]).reshape(v, 3, r).permute(0, 2, 1).float()
        hyper.base.copy_(base)
        hyper.local.table.copy_(coef[:, nw:].float())
        enc.skip.weight.zero_()
        enc.skip.weight[:r] = vt[:r].float()
        # The MLPs' output layers at zero (f_w's, both hypernetworks' bodies; the DT stage's
        # base table is zero too): the model starts exactly at the fit and they train from it.
        for last in (enc.net[-1], self.f_ph.body.rest[-1][-1], hyper.body.rest[-1][-1]):
            assert isinstance(last, nn.Linear)
            last.weight.zero_()
            last.bias.zero_()
        del fit, coef  # gigabytes of normal equations: the stages after need their own
        if hyper.local.slots:
            self._fit_on_codes(sources, kept, progress, ridge)
        if self.f_r is not None:
            self.fit_residual(data, kept, progress, contrasts, more)

    @torch.no_grad()
    def _fit_on_codes(
        self, sources: Sequence[Dataset], frames: int, progress: bool, ridge: float
    ) -> None:
        """With z's codes fixed by the first fit, the vertex stage again as a per-vertex ridge
        fit on `code_features`: its code part in L_v's base, the local features' in the
        constant slot's table, the products in the slot table. One more pass over the data."""
        hyper = self.f_ph_v
        assert hyper.base is not None and hyper.local is not None
        assert hyper.local.slot_table is not None
        fit: LocalRidge | None = None
        bar = tqdm(
            total=frames, desc="vertex stage on the codes", unit="frame", disable=not progress
        )
        for b in static_train(sources):
            x = self.code_features(b.weights, b.vertex_parameters(self.n_vertices))
            fit = fit or LocalRidge(self.n_vertices, x.shape[-1], 3)
            fit.add(x, (b.T - b.S).transpose(0, 1) / CM)
            bar.update(b.frames)
        bar.close()
        assert fit is not None
        coef = fit.solve(ridge)  # (V, r + F + slots E, 3), centimetres
        r, f = hyper.latent - 1, hyper.local.table.shape[1]
        hyper.base[:, :r] = coef[:, :r].float()
        hyper.base[:, r:] = 0.0
        hyper.local.table.copy_(coef[:, r : r + f].float())
        hyper.local.slot_table.copy_(coef[:, r + f :].reshape(hyper.local.slot_table.shape).float())

    def fit_residual(
        self,
        data: Dataset,
        frames: int,
        progress: bool = True,
        contrasts: Dataset | None = None,
        more: Sequence[Dataset] = (),
    ) -> dict[str, float]:
        """The residual stage from what the model (without it) leaves on the kept static train
        frames (`frames` of them in `data` and `more`): its modes and the members that give
        their coefficients (models/residual.py). `contrasts`: a dataset generated with
        contrasts (data/plan.py contrast), whose static train frames join the fit with their
        pairs."""
        assert self.f_r is not None
        with torch.no_grad():
            self.f_r.table.zero_()  # the model without the stage
        weights, features = [], []
        keys: list[tuple[int, int, bytes]] = []  # (identity, param_id, weights) of each frame
        sources = [data, *more] + ([] if contrasts is None else [contrasts])
        if contrasts is not None:
            frames += contrasts.left_out("static", "train")["kept"]
        # filled in place: a list of frames joined at the end would hold the skin's residual
        # of every frame twice (gigabytes)
        residual = torch.empty(frames, self.n_vertices, 3)
        done = 0
        bar = tqdm(total=frames, desc="residual of the start", unit="frame", disable=not progress)
        for source in sources:
            for b in source.batches("static", "train"):
                if done + b.frames > frames:
                    raise ValueError(f"more static train frames than the {frames} counted")
                with torch.no_grad():
                    residual[done : done + b.frames] = b.T - self.predict(b)
                    pv = b.vertex_parameters(self.n_vertices)
                    features.append(self.f_r.parameter_features(pv).expand(b.frames, -1))
                done += b.frames
                weights.append(b.weights.float())
                if source is contrasts:
                    keys += [(b.identity_id, b.param_id, w.numpy().tobytes()) for w in b.weights]
                else:
                    keys += [(-1, -1, b"")] * b.frames
                bar.update(b.frames)
        bar.close()
        if done != frames:
            raise ValueError(f"{done} static train frames, {frames} counted")
        return self.f_r.fit(
            torch.cat(weights),
            torch.cat(features),
            residual,
            self.residual_fit,
            progress,
            contrast_pairs(keys) if contrasts is not None else None,
        )

    def predict(self, batch: Batch) -> torch.Tensor:
        z = self.f_w(batch.weights)  # (B, latent), last entry 1
        hyper = self.f_ph(batch.face_parameters(self.n_faces), batch.h)  # (F, latent, 9)
        g = torch.einsum("bk,fkn->bfn", z, hyper).reshape(len(z), self.n_faces, 3, 3)
        vertex = self.f_ph_v(batch.vertex_parameters(self.n_vertices), batch.h)  # (V, latent, 3)
        x = deformation_transfer(batch.dt, batch.S, g) + torch.einsum("bk,vkn->bvn", z, vertex)
        if self.f_r is None:
            return x
        return x + self.f_r(batch.weights, batch.vertex_parameters(self.n_vertices))


def static_train(sources: Sequence[Dataset]) -> Iterator[Batch]:
    """The kept static train batches of every dataset in turn."""
    for data in sources:
        yield from data.batches("static", "train")


def contrast_pairs(keys: Sequence[tuple[int, int, bytes]]) -> torch.Tensor:
    """(M, 2) frame pairs of a contrasts dataset from each frame's (identity, param_id,
    weights): every frame paired with the frame of the same identity and expression whose
    p came first (the shard's base p; the others differ from it in one factor). Frames with
    identity -1 take part in no pair."""
    base: dict[tuple[int, bytes], tuple[int, int]] = {}
    for i, (identity, param, w) in enumerate(keys):
        if identity >= 0 and ((identity, w) not in base or param < base[(identity, w)][0]):
            base[(identity, w)] = (param, i)
    pairs = [
        (i, base[(identity, w)][1])
        for i, (identity, param, w) in enumerate(keys)
        if identity >= 0 and base[(identity, w)][1] != i
    ]
    return torch.tensor(pairs, dtype=torch.long).reshape(-1, 2)


class SoftDecaVertex(Trainable):
    """The vertex-position variant (Table 1): X = S_t + z(w) . L_v(p, h), no DT."""

    hypernetworks = ("f_ph_v",)

    def __init__(self, d: TemplateDefinition, specs: Sequence[ParameterSpec], sizes: NetworkSizes):
        super().__init__()
        self.f_w = WeightEncoder(len(d.blendshapes), sizes)
        self.f_ph_v = HyperNetwork(d.skin_vertices, specs, sizes, 3, 1e-5, unit=CM, base=True)
        self.n_vertices = d.skin_vertices

    def init_from_data(self, batches: Sequence[Batch]) -> None:
        w = torch.cat([b.weights for b in batches])
        off = torch.cat([b.T - b.S for b in batches])
        init_basis(self.f_ph_v, self.f_w.net, w, off.reshape(len(off), -1), CM)

    def predict(self, batch: Batch) -> torch.Tensor:
        hyper = self.f_ph_v(batch.vertex_parameters(self.n_vertices), batch.h)  # (V, latent, 3)
        return batch.S + torch.einsum("bk,vkn->bvn", self.f_w(batch.weights), hyper)


class SparseSoftDeca(Trainable):
    """f(L, p, h) = neutral + z(L - L_0) . L_v(p, h) (eq. 25); L_0: the identity's neutral
    landmarks, evaluated on its neutral skin through the landmark definition."""

    kind = "sparse"
    hypernetworks = ("f_ph_v",)

    def __init__(
        self,
        d: TemplateDefinition,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        noisy: bool = True,
        code_noise: float = 0.0,
    ):
        super().__init__()
        self.noisy = noisy  # train on sigma(L) with noise (eq. 24) or on the clean landmarks
        # Training only: N(0, code_noise^2) added to each identity coefficient (h is N(0, I)),
        # so that the basis does not hang on a code read off an imperfect head (a fitted
        # avatar's registered template reads h with an error of that size).
        self.code_noise = code_noise
        self.f_l = LandmarkEncoder(len(d.landmarks), sizes)
        self.f_ph_v = HyperNetwork(d.skin_vertices, specs, sizes, 3, 1e-5, unit=CM, base=True)
        self.n_vertices = d.skin_vertices
        tri = torch.as_tensor(d.skin_triangles[d.landmarks.triangle], dtype=torch.long)
        self.register_buffer("lm_corners", tri, persistent=False)  # (K, 3)
        self.register_buffer(
            "lm_bary", torch.as_tensor(d.landmarks.bary, dtype=torch.float32), persistent=False
        )
        self.arkit_vertex = np.asarray(d.landmarks.arkit_vertex, dtype=np.int64)
        self.arkit_vertex_count = d.landmarks.arkit_vertex_count

    def neutral_landmarks(self, neutral: torch.Tensor) -> torch.Tensor:
        return (neutral[self.lm_corners] * self.lm_bary[..., None]).sum(1)  # (K, 3)

    def landmarks_on(self, skin: torch.Tensor) -> torch.Tensor:
        return (skin[:, self.lm_corners] * self.lm_bary[..., None]).sum(2)  # (B, K, 3)

    def inputs(self, batch: Batch) -> torch.Tensor:
        """The tracked landmarks: the batch's (noisy or clean) sigma(L), or for batches
        without landmarks (dynamic sequences) the identity's own on S_t."""
        lm = batch.landmarks if self.noisy else batch.landmarks_clean
        return self.landmarks_on(batch.S) if lm is None else lm

    def arkit_landmarks(self, batch: Batch, face: ArkitFace) -> torch.Tensor:
        """ARKit's reference face making the batch's expressions (its own shapes at the frames'
        weights), personalised to the batch's head as the runtime calibrates a phone's face:
        what a phone sends, where the data's donors are other ICT heads. (B, K, 3)."""
        if len(face.neutral) != self.arkit_vertex_count:
            raise ValueError(
                f"the landmarks are vertices of a {self.arkit_vertex_count}-vertex face, "
                f"not of ARKit's reference face ({len(face.neutral)} vertices)"
            )
        k = self.arkit_vertex
        frames = face.neutral[k] + np.tensordot(
            batch.weights.double().numpy(), face.deltas[:, k], 1
        )
        own = self.neutral_landmarks(batch.neutral).double().numpy()
        return torch.as_tensor(personalise(face.neutral[k], frames, own), dtype=torch.float32)

    def offsets(self, batch: Batch) -> torch.Tensor:
        """The encoder's input: tracked landmarks minus the neutral ones, (B, 3K)."""
        off = self.inputs(batch) - self.neutral_landmarks(batch.neutral)
        return off.reshape(len(off), -1)

    @torch.no_grad()
    def init_from_dataset(
        self, data: Dataset, *_: object, progress: bool = True, **__: object
    ) -> None:
        """The closed-form start over every kept sparse train frame (the order of frames, other
        datasets and contrasts do not matter to it): L_v's base = the leading
        principal components of the deformations, f_L's linear path = the ridge regression of
        their coefficients on the clean landmark offsets (each frame's from the data's donor
        and, when the landmarks are ARKit's face's, from that face), with the ridge that training on
        landmarks noisy by the dataset's sigma amounts to (n sigma^2; Bishop 1995); the MLPs'
        output layers at zero. It is nearer the physics than the random-feature start after
        40 minutes of steps, and steps from it make it worse (docs/training.md)."""
        clean, phone, y = [], [], []
        kept = data.left_out("sparse", "train")["kept"]
        bar = tqdm(total=kept, desc="sparse closed form", unit="frame", disable=not progress)
        face: ArkitFace | None = ArkitFace.load()
        if len(face.neutral) != self.arkit_vertex_count:
            face = None  # landmarks on another face (a synthetic definition)
        for b in data.batches("sparse", "train"):
            own = self.neutral_landmarks(b.neutral)
            lm = b.landmarks_clean if b.landmarks_clean is not None else self.landmarks_on(b.S)
            clean.append((lm - own).reshape(b.frames, -1).double())
            if face is not None:  # what phones send: ARKit's face making the same expression
                phone.append((self.arkit_landmarks(b, face) - own).reshape(b.frames, -1).double())
            y.append((b.T - b.neutral).reshape(b.frames, -1))
            bar.update(b.frames)
        bar.close()
        if not y:
            raise ValueError(f"the dataset {data.folder} has no usable sparse training frames")
        scale = self.f_l.offset_scale
        # the basis and each frame's coefficients once; the regression reads them from each donor
        per_frame = init_basis(
            self.f_ph_v, self.f_l.net, torch.cat(clean) * scale, torch.cat(y), CM, readout=False
        )
        del y
        donors = [torch.cat(clean)] + ([torch.cat(phone)] if phone else [])
        inputs = torch.cat(donors) * scale
        coefficients = per_frame.repeat(len(donors), 1)
        sigma = (
            float(data.manifest["header"]["config"].get("landmark_noise_mm", 0.0))
            if self.noisy
            else 0.0
        )
        sigma_units = sigma * 1e-3 * self.f_l.offset_scale
        n = len(inputs)
        a = torch.cat([inputs, torch.ones(n, 1, dtype=torch.float64)], 1)
        gram = a.T @ a
        # n sigma^2 on the offsets (the bias free); a floor relative to the inputs' scale keeps
        # the clean-landmark ablation well posed
        ridge = (n * sigma_units**2 + 1e-6 * float(gram.diagonal().mean())) * torch.eye(
            len(gram), dtype=torch.float64
        )
        ridge[-1, -1] = 0
        w = torch.linalg.solve(gram + ridge, a.T @ coefficients)
        self.f_l.skip.weight.copy_(w[:-1].T.float())
        self.f_l.skip.bias.copy_(w[-1].float())
        last = self.f_ph_v.body.rest[-1][-1]
        assert isinstance(last, nn.Linear)
        last.weight.zero_()
        last.bias.zero_()

    def predict(self, batch: Batch) -> torch.Tensor:
        offsets = self.offsets(batch)
        z = self.f_l(offsets)
        h = batch.h
        if self.training and self.code_noise > 0:
            h = h + self.code_noise * torch.randn_like(h)
        hyper = self.f_ph_v(batch.vertex_parameters(self.n_vertices), h)
        return batch.neutral + torch.einsum("bk,vkn->bvn", z, hyper)


class OverStatic(Trainable):
    """A dynamics stage over a frozen static model whose outputs per sequence are computed
    once (no gradient) and cached: training then costs only the stage's own networks."""

    kind = "dynamic"

    def __init__(self, static: Trainable) -> None:
        super().__init__()
        self.static = static
        for q in self.static.parameters():
            q.requires_grad_(False)
        self._y: dict[tuple[int, int], torch.Tensor] = {}

    def static_frames(self, batch: Batch) -> torch.Tensor:
        """The static model on the two frames before the sequence and on the sequence:
        (2 + L, V, 3). The stage starts from its own static output, never from the simulated
        states: started there, a stage that barely follows its input (gamma near 0) would
        score well on 16-frame windows by holding the true state, and lag in use."""
        key = (batch.param_id, batch.identity_id)
        if key not in self._y:
            assert batch.prev_S is not None and batch.prev_weights is not None
            frames = replace(
                batch,
                weights=torch.cat([batch.prev_weights, batch.weights]),
                S=torch.cat([batch.prev_S, batch.S]),
                T=torch.cat([batch.prev_T, batch.T]) if batch.prev_T is not None else batch.T,
                landmarks=None,
                landmarks_clean=None,
            )
            with torch.no_grad():
                self._y[key] = self.static.predict(frames)
            if len(self._y) > 256:
                self._y.pop(next(iter(self._y)))
        return self._y[key]


class Dynamics(OverStatic):
    """Per-vertex alpha, beta, gamma (eq. 21) learned over a frozen static model: for a
    sequence, Y_t = static(t), X_t = gamma Y_t + 2 alpha X_{t-1} - beta X_{t-2}, started from
    the simulated frames before the sequence (its initial velocity)."""

    def __init__(
        self,
        static: Trainable,
        n_vertices: int,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        gamma0: float = 0.7,
        beta0: float = 0.3,
    ):
        super().__init__(static)
        self.f_dyn = DynamicsNetwork(n_vertices, specs, sizes, gamma0, beta0)
        self.n_vertices = n_vertices

    def predict(self, batch: Batch) -> torch.Tensor:
        y_all = self.static_frames(batch)
        alpha, beta, gamma = self.f_dyn(batch.vertex_parameters(self.n_vertices), batch.h)
        a, b, g = alpha[:, None], beta[:, None], gamma[:, None]
        x2, x1, y = y_all[0], y_all[1], y_all[2:]
        out = []
        for t in range(len(y)):
            x = g * y[t] + 2 * a * x1 - b * x2
            out.append(x)
            x2, x1 = x1, x
        return torch.stack(out)


# --- Table 1 baselines ---------------------------------------------------------------------


class GlobalMlp(Trainable):
    """SoftSMPL-style: one MLP from (w, p, h) to offsets of every skin vertex, X = S_t + MLP."""

    def __init__(
        self,
        d: TemplateDefinition,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        hidden: Sequence[int],
    ):
        super().__init__()
        self.normalise = Normalise(specs)
        self.n_vertices = d.skin_vertices
        n_in = len(d.blendshapes) + len(specs) + sizes.identity
        self.net = mlp([n_in, *hidden, 3 * d.skin_vertices], 1e-3 / CM)

    def predict(self, batch: Batch) -> torch.Tensor:
        n = batch.frames
        x = torch.cat(
            [batch.weights, self.normalise(batch.p).expand(n, -1), batch.h.expand(n, -1)], 1
        )
        return batch.S + CM * self.net(x).reshape(n, self.n_vertices, 3)


class FaceMlp(Trainable):
    """Face-wise MLP: per face, an MLP of (w, p, h, pi(f)) gives G_f - I, then DT."""

    def __init__(self, d: TemplateDefinition, specs: Sequence[ParameterSpec], sizes: NetworkSizes):
        super().__init__()
        self.n_faces = d.n_faces
        self.body = ElementMLP(d.n_faces, specs, sizes, sizes.hyper_hidden, 9, 0.02)
        self.from_weights = nn.Linear(len(d.blendshapes), sizes.hyper_hidden[0], bias=False)

    def predict(self, batch: Batch) -> torch.Tensor:
        p = batch.face_parameters(self.n_faces)
        base = (
            self.body.from_parameters(self.body.normalise(p))
            + self.body.from_positional(self.body.positional)
            + self.body.from_identity(batch.h)
        )  # (F, hidden): shared by the frames
        x = base[None] + self.from_weights(batch.weights)[:, None]  # (B, F, hidden)
        dg = self.body.rest(x).reshape(batch.frames, self.n_faces, 3, 3)
        return deformation_transfer(batch.dt, batch.S, dg)


class LatentDynamics(OverStatic):
    """SNP-style latent dynamics (Table 1): a recurrent state over a learned global latent of
    the frame drives one set of offset modes; unlike eq. 21 nothing is per vertex, so the
    dynamics cannot be localised. X_t = Y_t + U s_t, s_t = GRU(s_{t-1}, [e(Y_t), p, h])."""

    def __init__(
        self,
        static: Trainable,
        d: TemplateDefinition,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        modes: int = 32,
        state: int = 64,
    ):
        super().__init__(static)
        self.normalise = Normalise(specs)
        self.n_vertices = d.skin_vertices
        self.sub = torch.arange(0, d.skin_vertices, max(1, d.skin_vertices // 256))
        n_in = 3 * len(self.sub) + len(specs) + sizes.identity
        self.cell = nn.GRUCell(n_in, state)
        self.modes = nn.Linear(state, 3 * d.skin_vertices)  # centimetres
        with torch.no_grad():
            self.modes.weight.mul_(0.1)
            self.modes.bias.zero_()

    def predict(self, batch: Batch) -> torch.Tensor:
        y_all = self.static_frames(batch)
        y = y_all[2:]
        cond = torch.cat([self.normalise(batch.p), batch.h], 1)[0]
        s = torch.zeros(1, self.cell.hidden_size)
        # warm up on the two frames before the sequence, as the per-vertex model starts there
        seq = y_all  # warm up on the static output of the two frames before the sequence
        out = []
        for t in range(len(seq)):
            e = (seq[t, self.sub] - batch.neutral[self.sub]).reshape(-1) * 100.0
            s = self.cell(torch.cat([e, cond])[None], s)
            if t >= 2:
                out.append(y[t - 2] + CM * self.modes(s).reshape(self.n_vertices, 3))
        return torch.stack(out)
