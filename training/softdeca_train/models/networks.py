"""The networks of a model bundle (paper eq. 17-21, 25) as torch modules, and builders of
random-weight instances. Shapes are the bundle contract (docs/bundle.md):

  f_w      weights [B, 52]                            -> z [B, latent]
  f_l      landmark_offsets [B, 3K]                   -> z [B, latent]
  f_ph     parameters [F, P], identity [1, H]         -> L [F, latent, 9]   (per skin triangle)
  f_ph_v   parameters [V, P], identity [1, H]         -> L [V, latent, 3]   (per skin vertex)
  f_dyn    parameters [V, P], identity [1, H]         -> alpha, beta, gamma [V]
  identity_encoder  neutral [1, V, 3]                 -> identity [1, H]

Parameters enter as raw values; each network normalises them itself (log or linear to [-1, 1])
so the runtime never needs to know how. The positional encodings pi(i) are trainable tables
inside f_ph, f_ph_v and f_dyn."""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from softdeca_train.models.blocks import (
    NetworkSizes,
    Normalise,
    gravity_columns,
    gravity_load,
    region_means,
    rest_gate,
)
from softdeca_train.models.residual import ResidualSizes, ResidualStage
from softdeca_train.models.smoothing import FieldSmoothing
from softdeca_train.models.topology import TemplateDefinition
from softdeca_train.parameters import ParameterSpec

# The stable, equilibrium-preserving dynamics set (eq. 21 with gamma + 2 alpha - beta = 1):
# beta in [0, BETA_MAX], gamma in [GAMMA_MIN, GAMMA_MAX] keep both roots of
# r^2 - 2 alpha r + beta inside the unit circle, and a constant input stays constant.
BETA_MAX = 0.99
GAMMA_MIN, GAMMA_MAX = 0.01, 1.99


FULL_SIZES = NetworkSizes()
TEST_SIZES = NetworkSizes(
    latent=32,
    identity=8,
    f_w_hidden=(32,),
    f_l_hidden=(32,),
    hyper_hidden=(24,),
    dynamics_hidden=(8,),
    positional=8,
    encoder_points=64,
    encoder_hidden=(16,),
    residual_modes=7,
    residual_hidden=16,
    residual_members=2,
    residual_steps=100,
)


def mlp(sizes: Sequence[int], out_scale: float = 1.0) -> nn.Sequential:
    layers: list[nn.Module] = []
    for i in range(len(sizes) - 1):
        layers.append(nn.Linear(sizes[i], sizes[i + 1]))
        if i < len(sizes) - 2:
            layers.append(nn.ELU())
    last = layers[-1]
    assert isinstance(last, nn.Linear)
    with torch.no_grad():
        last.weight.mul_(out_scale)
        last.bias.mul_(out_scale)
    return nn.Sequential(*layers)


class WeightEncoder(nn.Module):
    """f_w: blendshape weights -> latent code z (per frame). Options: `linear_skip` adds a
    linear map of w to the MLP's output (the part of the correction linear in w starts there
    in closed form); `constant_slot` makes the last entry of z a constant 1, so the
    hypernetwork's entry for it is a correction that does not depend on w (p's own).

    With sizes.rest_gate set, z is exact at rest by construction: the MLP gives net(w) -
    net(0) (the zero frame a constant of the network, so the export computes the same) and the
    constant slot is the rest gate (models/blocks.py rest_gate), so z(0) = 0 and every
    correction built on z vanishes at rest."""

    def __init__(
        self,
        n_weights: int,
        sizes: NetworkSizes,
        linear_skip: bool = False,
        constant_slot: bool = False,
    ) -> None:
        super().__init__()
        self.constant_slot = constant_slot
        self.rest_tau = sizes.rest_gate
        free = sizes.latent - 1 if constant_slot else sizes.latent
        self.net = mlp([n_weights, *sizes.f_w_hidden, free])
        self.skip = nn.Linear(n_weights, free, bias=False) if linear_skip else None
        # not in the state: checkpoints and bundles written before it load as they are
        self.register_buffer("rest", torch.zeros(1, n_weights), persistent=False)
        # net(0) as a constant (freeze_rest_codes, at export): the exported graph then holds
        # it, and the frame does not run the MLP a second time
        self.rest_code: torch.Tensor | None = None

    def forward(self, weights: torch.Tensor) -> torch.Tensor:
        z = self.net(weights)
        if self.rest_tau is not None:
            z = z - (self.net(self.rest) if self.rest_code is None else self.rest_code)
        if self.skip is not None:
            z = z + self.skip(weights)
        if self.constant_slot:
            z = torch.cat([z, rest_gate(weights, self.rest_tau)], dim=1)
        return z


def freeze_rest_codes(module: nn.Module) -> nn.Module:
    """A copy of `module` whose weight encoders hold net(0) as a constant (WeightEncoder), as
    the export writes them; the copy is for export and checks only: training on it would leave
    the constant stale."""
    out = copy.deepcopy(module)
    for m in out.modules():
        if isinstance(m, WeightEncoder) and m.rest_tau is not None:
            with torch.no_grad():
                m.rest_code = m.net(m.rest).detach().clone()
    return out


class LandmarkEncoder(nn.Module):
    """f_L: landmark offsets from the avatar's neutral landmarks (metres) -> z (per frame): a
    linear map (what a ridge regression reads off the landmarks, set in closed form) plus an
    MLP for what is not linear in them."""

    def __init__(self, n_landmarks: int, sizes: NetworkSizes, offset_scale: float = 100.0) -> None:
        super().__init__()
        self.offset_scale = offset_scale  # metres -> centimetres: inputs of order one
        self.net = mlp([3 * n_landmarks, *sizes.f_l_hidden, sizes.latent])
        self.skip = nn.Linear(3 * n_landmarks, sizes.latent)
        nn.init.zeros_(self.skip.weight)
        nn.init.zeros_(self.skip.bias)

    def forward(self, landmark_offsets: torch.Tensor) -> torch.Tensor:
        x = landmark_offsets * self.offset_scale
        return self.skip(x) + self.net(x)


class ElementMLP(nn.Module):
    """An MLP evaluated for every element (face or vertex) on [p_i, h, pi(i)]. The first layer
    is split so that the identity's share is computed once, not once per element."""

    def __init__(
        self,
        n_elements: int,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        hidden: Sequence[int],
        n_out: int,
        out_scale: float,
    ) -> None:
        super().__init__()
        self.normalise = Normalise(specs)
        self.positional = nn.Parameter(torch.randn(n_elements, sizes.positional))
        h0 = hidden[0]
        self.from_parameters = nn.Linear(len(specs), h0, bias=False)
        self.from_positional = nn.Linear(sizes.positional, h0, bias=False)
        self.from_identity = nn.Linear(sizes.identity, h0)
        self.rest = nn.Sequential(nn.ELU(), mlp([*hidden, n_out], out_scale))

    def forward(self, parameters: torch.Tensor, identity: torch.Tensor) -> torch.Tensor:
        x = (
            self.from_parameters(self.normalise(parameters))
            + self.from_positional(self.positional)
            + self.from_identity(identity)
        )
        return self.rest(x)


# The parameters whose response depends on the expression: a tissue's strain and volume
# weights matter where the expression strains that tissue (measured: their physics response
# differs by 0.76-0.90 of its norm between expressions, a region's volume by 0.06-0.50). The
# vertex stage gives them terms per leading expression code (LocalLinear.slot_table); for
# the other parameters such terms fit noise (docs/training.md).
EXPRESSION_PARAMETERS = ("w_soft_volume", "w_soft_strain", "w_muscle_strain", "w_skin_strain")
EXPRESSION_SLOTS = 4  # leading codes of z (the largest modes of the start's w part)


class LocalLinear(nn.Module):
    """Per element, an affine map of the element's own parameters: [1, p_i, g_i] (p_i
    normalised, g_i its gravity load) times a table (n, 1 + P + 3 [+ S L] [+ R L], k). A
    region's control then changes the output in and around that region only. With `smoothing`
    (vertex elements), the L localisable parameters averaged around the element at S scales
    are inputs too: a material change moves the skin near it, not only above it
    (models/smoothing.py). With `regions` (a region label per element), each of the R regions'
    mean of the localisable parameters is an input of every element: a region's change then
    moves each vertex by a field of its own (the physics' response to a region's volume
    reaches past what averaging sees). With `slots`, the EXPRESSION_PARAMETERS among the specs
    also map into the first `slots` latent entries (`slot_table` (n, slots, E, k)): multiplied
    by those codes of z, their change depends on the expression (the paper's z(w) L(p) with p
    inside L), at no cost per frame. With `inputs` (parameter names), only those are inputs
    of the tables: a parameter the fit never sees vary has no coefficient to learn, and a
    collinear one would move the output when a user turns it. An element labelled -1 in
    `regions` is in no region's mean."""

    def __init__(
        self,
        n_elements: int,
        specs: Sequence[ParameterSpec],
        k: int,
        smoothing: FieldSmoothing | None = None,
        slots: int = 0,
        regions: np.ndarray | None = None,
        inputs: Sequence[str] | None = None,
    ) -> None:
        super().__init__()
        self.normalise = Normalise(specs)
        self.gravity = gravity_columns(specs)
        self.smoothing = smoothing
        unknown = set(inputs or ()) - {s.name for s in specs}
        if unknown:
            raise ValueError(f"inputs: no parameters {sorted(unknown)}")
        self.own = [i for i, s in enumerate(specs) if inputs is None or s.name in inputs]
        localisable = [i for i in self.own if specs[i].localisable]
        self.smoothed = localisable if smoothing else []
        n_smoothed = len(self.smoothed) * (len(smoothing.scales) if smoothing else 0)
        self.regional = localisable if regions is not None else []
        n_regions = int(np.max(regions)) + 1 if regions is not None else 0
        if regions is not None:
            if len(regions) != n_elements:
                raise ValueError("regions: one label per element")
            self.register_buffer("region_mean", torch.from_numpy(region_means(regions, n_regions)))
        n_regional = n_regions * len(self.regional)
        width = 1 + len(self.own) + 3 + n_smoothed + n_regional
        self.table = nn.Parameter(torch.zeros(n_elements, width, k))
        self.expression = [i for i in self.own if specs[i].name in EXPRESSION_PARAMETERS]
        self.slots = slots if self.expression else 0
        self.slot_table = (
            nn.Parameter(torch.zeros(n_elements, self.slots, len(self.expression), k))
            if self.slots
            else None
        )

    def features(self, parameters: torch.Tensor) -> torch.Tensor:
        """(n, P) raw -> (n, 1 + P' + 3 [+ S L] [+ R L]) (P' the parameters that are
        inputs, L the localisable ones among them)."""
        ones = torch.ones_like(parameters[:, :1])
        load = gravity_load(parameters, self.gravity)
        own = self.normalise(parameters)
        parts = [ones, own[:, self.own], load]
        if self.smoothing is not None and self.smoothed:
            parts.append(self.smoothing(own[:, self.smoothed]))
        if self.regional:
            means = self.region_mean.to(own.dtype) @ own[:, self.regional]  # (R, L)
            parts.append(means.reshape(1, -1).expand(len(own), -1))
        return torch.cat(parts, dim=1)

    def slot_features(self, parameters: torch.Tensor) -> torch.Tensor:
        """(n, P) raw -> (n, E): the normalised EXPRESSION_PARAMETERS of each element."""
        return self.normalise(parameters)[:, self.expression]

    def forward(self, parameters: torch.Tensor) -> torch.Tensor:
        """The constant slot's share (n, k)."""
        return torch.einsum("nd,ndk->nk", self.features(parameters), self.table)

    def slot_offsets(self, parameters: torch.Tensor) -> torch.Tensor:
        """The first `slots` latent entries' share (n, slots, k)."""
        assert self.slot_table is not None
        return torch.einsum("ne,nsek->nsk", self.slot_features(parameters), self.slot_table)


class HyperNetwork(nn.Module):
    """f_ph (k = 9: a 3x3 deformation-gradient block per face and latent) or f_ph_v (k = 3: a
    vertex offset per latent). Output [n, latent, k]. `unit` is a fixed factor on the output
    (part of the exported graph): vertex offsets are learned in centimetres (unit 0.01) so
    that the weights, not the optimiser's step size, carry the metre scale. With `base`, a
    trainable per-element table L0 is added: L = L0 + MLP(p_i, h, pi(i)), the mean tensor
    held directly (initialised from data by the training) and the hypernetwork its change
    with parameters and identity."""

    def __init__(
        self,
        n_elements: int,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        k: int,
        out_scale: float,
        unit: float = 1.0,
        base: bool = False,
        local_linear: bool = False,
        smoothing: FieldSmoothing | None = None,
        slots: int = 0,
        regions: np.ndarray | None = None,
        inputs: Sequence[str] | None = None,
    ) -> None:
        super().__init__()
        self.latent, self.k, self.unit = sizes.latent, k, unit
        self.base = nn.Parameter(torch.zeros(n_elements, sizes.latent, k)) if base else None
        self.body = ElementMLP(
            n_elements, specs, sizes, sizes.hyper_hidden, sizes.latent * k, out_scale / unit
        )
        # With a constant last entry of z (WeightEncoder.constant_slot): that entry's tensor
        # gains an affine map of each element's own parameters (and of those around it);
        # with `slots`, the first entries gain one of the expression-dependent parameters;
        # with `regions`, every region's mean parameters are inputs of each element.
        self.local = (
            LocalLinear(n_elements, specs, k, smoothing, slots, regions, inputs)
            if local_linear
            else None
        )

    def forward(self, parameters: torch.Tensor, identity: torch.Tensor) -> torch.Tensor:
        out = self.body(parameters, identity).reshape(-1, self.latent, self.k)
        if self.base is not None:
            out = out + self.base
        if self.local is not None:
            last = out[:, -1:] + self.local(parameters)[:, None]
            out = torch.cat([out[:, :-1], last], dim=1)
            if self.local.slots:
                s = self.local.slots
                out = torch.cat([out[:, :s] + self.local.slot_offsets(parameters), out[:, s:]], 1)
        return out * self.unit if self.unit != 1.0 else out


class DynamicsNetwork(nn.Module):
    """f_dyn: per-vertex alpha, beta, gamma of eq. 21 inside the stable set. f_gamma and f_beta
    are separate MLPs; alpha = (1 - gamma + beta) / 2 is not free: it keeps constants fixed."""

    def __init__(
        self,
        n_vertices: int,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        gamma0: float = 0.7,
        beta0: float = 0.3,
    ) -> None:
        super().__init__()
        hidden = sizes.dynamics_hidden
        self.f_gamma = ElementMLP(n_vertices, specs, sizes, hidden, 1, 0.1)
        self.f_beta = ElementMLP(n_vertices, specs, sizes, hidden, 1, 0.1)
        with torch.no_grad():  # start near (gamma0, beta0): visibly dynamic, clearly stable
            g = (gamma0 - GAMMA_MIN) / (GAMMA_MAX - GAMMA_MIN)
            self._last(self.f_gamma).bias.fill_(float(np.log(g / (1 - g))))
            b = beta0 / BETA_MAX
            self._last(self.f_beta).bias.fill_(float(np.log(b / (1 - b))))

    @staticmethod
    def _last(m: ElementMLP) -> nn.Linear:
        last = m.rest[-1][-1]
        assert isinstance(last, nn.Linear)
        return last

    def forward(
        self, parameters: torch.Tensor, identity: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        gamma = GAMMA_MIN + (GAMMA_MAX - GAMMA_MIN) * torch.sigmoid(
            self.f_gamma(parameters, identity)[:, 0]
        )
        beta = BETA_MAX * torch.sigmoid(self.f_beta(parameters, identity)[:, 0])
        alpha = 0.5 * (1.0 - gamma + beta)
        return alpha, beta, gamma


class IdentityEncoder(nn.Module):
    """Neutral skin vertices -> identity code h. Reads a fixed subset of vertices, centred."""

    def __init__(self, n_skin: int, sizes: NetworkSizes, seed: int = 0) -> None:
        super().__init__()
        rng = np.random.default_rng(seed)
        n = min(sizes.encoder_points, n_skin)
        self.register_buffer("points", torch.from_numpy(np.sort(rng.choice(n_skin, n, False))))
        self.net = mlp([3 * n, *sizes.encoder_hidden, sizes.identity])
        self.scale = 10.0  # metres -> decimetres

    def forward(self, neutral: torch.Tensor) -> torch.Tensor:
        x = neutral[:, self.points, :]
        x = (x - x.mean(dim=1, keepdim=True)) * self.scale
        return self.net(x.reshape(x.shape[0], -1))


@dataclass
class SoftDecaNetworks:
    f_w: WeightEncoder
    f_ph: HyperNetwork
    f_dyn: DynamicsNetwork
    # the optional vertex stage: X = DT(S_t, I + z . L) + z . L_v (bundle format version 2)
    f_ph_v: HyperNetwork | None = None
    # the optional residual stage: + sum_k c_k(w, p) M_k (models/residual.py; version 3)
    f_r: ResidualStage | None = None


@dataclass
class SparseNetworks:
    f_l: LandmarkEncoder
    f_ph_v: HyperNetwork
    f_dyn: DynamicsNetwork


@dataclass
class BundleNetworks:
    """Everything a bundle holds besides the manifest; either model may be absent."""

    sizes: NetworkSizes
    specs: tuple[ParameterSpec, ...]
    identity_encoder: IdentityEncoder
    softdeca: SoftDecaNetworks | None
    sparse: SparseNetworks | None
    rest_changes: bool = False  # SoftDECA trained on S_t + Pd (the bundle's `rest_changes`)

    @property
    def rest_gate(self) -> float | None:
        """tau of SoftDECA's rest gate where z's last entry is the gate (WeightEncoder's
        constant slot with sizes.rest_gate > 0): the bundle's `rest_gate`, which the physics at
        prepare weighs the networks' rest response with (models/reference.py). None where that
        entry is a constant 1 (tau None), 0 (tau 0) or no slot at all: there the rest physics
        needs nothing of the gate."""
        f_w = self.softdeca.f_w if self.softdeca is not None else None
        if f_w is None or not f_w.constant_slot or not f_w.rest_tau:
            return None
        return float(f_w.rest_tau)

    def modules(self) -> list[nn.Module]:
        out: list[nn.Module] = [self.identity_encoder]
        for m in (self.softdeca, self.sparse):
            if m is not None:
                out += [n for n in vars(m).values() if n is not None]
        return out

    def eval(self) -> BundleNetworks:
        for m in self.modules():
            m.eval()
        return self


def build_random(
    definition: TemplateDefinition,
    specs: Sequence[ParameterSpec],
    sizes: NetworkSizes = FULL_SIZES,
    seed: int = 0,
    softdeca: bool = True,
    sparse: bool = True,
    dg_scale: float = 0.02,
    offset_scale: float = 1e-3,
    vertex_stage: bool = False,
    residual_stage: bool = False,
    constant_slot: bool = False,
) -> BundleNetworks:
    """Random-weight networks (untrained). `dg_scale` sets the size of the deformation-gradient
    corrections (G - I) and `offset_scale` that of the vertex offsets (metres), so that an
    untrained bundle stays close to its input instead of producing noise. `vertex_stage` adds
    SoftDECA's vertex stage (with its per-vertex affine tables, random too; with the smoothed
    parameters among its inputs where the definition has the skin at rest, the region means
    where it has regions); `residual_stage`
    adds the residual stage (models/residual.py) over the definition's regions (one region
    where it has none), its modes random of size `offset_scale`. `constant_slot` makes z's
    last entry f_w's constant slot, as the trained bundles have it (WeightEncoder)."""
    torch.manual_seed(seed)
    specs = tuple(specs)
    nf, nv = definition.n_faces, definition.skin_vertices
    rest = definition.skin_rest
    smoothing = FieldSmoothing(rest) if vertex_stage and rest is not None else None
    sd = sp = None
    if softdeca:
        sd = SoftDecaNetworks(
            f_w=WeightEncoder(len(definition.blendshapes), sizes, constant_slot=constant_slot),
            f_ph=HyperNetwork(nf, specs, sizes, 9, dg_scale),
            f_dyn=DynamicsNetwork(nv, specs, sizes),
            f_ph_v=HyperNetwork(
                nv,
                specs,
                sizes,
                3,
                offset_scale,
                local_linear=True,
                smoothing=smoothing,
                slots=EXPRESSION_SLOTS,
                regions=definition.skin_regions,
            )
            if vertex_stage
            else None,
        )
    if sparse:
        sp = SparseNetworks(
            f_l=LandmarkEncoder(len(definition.landmarks), sizes),
            f_ph_v=HyperNetwork(nv, specs, sizes, 3, offset_scale),
            f_dyn=DynamicsNetwork(nv, specs, sizes, gamma0=0.6, beta0=0.25),
        )
    if sd is not None and residual_stage:
        regions = definition.skin_regions
        labels = np.zeros(nv, np.int64) if regions is None else regions
        sd.f_r = ResidualStage(labels, specs, ResidualSizes.of(sizes))
        with torch.no_grad():
            sd.f_r.table.normal_(0.0, 0.2 * offset_scale)
    if sd is not None and sd.f_ph_v is not None and sd.f_ph_v.local is not None:
        with torch.no_grad():  # the affine tables start at zero in training; random here
            sd.f_ph_v.local.table.normal_(0.0, offset_scale)
            if sd.f_ph_v.local.slot_table is not None:
                sd.f_ph_v.local.slot_table.normal_(0.0, offset_scale)
    enc = IdentityEncoder(nv, sizes, seed)
    return BundleNetworks(sizes, specs, enc, sd, sp).eval()
