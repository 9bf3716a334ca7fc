"""SoftDECA's residual stage (models/residual.py): its modes reproduce a low-rank residual, the
split at the first layer (prepare half, frame half) is the members' own forward pass, region
means read a regional pattern back, and the fit learns a residual nonlinear in the weights."""

from __future__ import annotations

import numpy as np
import torch
from bounds import above, below
from softdeca_train.models import load_parameter_specs
from softdeca_train.models.blocks import region_means
from softdeca_train.models.residual import ResidualFit, ResidualSizes, ResidualStage
from softdeca_train.models.synthetic import TEST_PARAMETERS

SPECS = load_parameter_specs(TEST_PARAMETERS)
V = 40
LABELS = np.arange(V) % 4  # four regions


def stage(modes: int = 3, members: int = 2, dropout: float = 0.3) -> ResidualStage:
    torch.manual_seed(0)
    sizes = ResidualSizes(modes=modes, hidden=32, members=members, dropout=dropout)
    return ResidualStage(LABELS, SPECS, sizes)


def defaults(n: int = V) -> torch.Tensor:
    return torch.tensor([[s.default_value for s in SPECS]], dtype=torch.float32).repeat(
        n, 1
    )


def test_region_means_average_each_region_and_skip_empty_ones():
    m = region_means(np.array([0, 0, 2, 2, 2]), 4)
    assert m.shape == (4, 5)
    np.testing.assert_allclose(m.sum(1), [1, 0, 1, 0])
    field = np.array([1.0, 3.0, 5.0, 5.0, 8.0])
    np.testing.assert_allclose(m @ field, [2.0, 0.0, 6.0, 0.0])


def test_parameter_features_read_a_regional_pattern_back():
    s = stage()
    p = defaults()
    col = [x.name for x in SPECS].index("target_volume")
    p[LABELS == 2, col] = 1.4
    features = s.parameter_features(p)
    region_values = features[0, 3:].reshape(4, len(SPECS))
    norm = s.normalise(p)
    assert torch.allclose(region_values[2, col], norm[LABELS == 2, col][0])
    assert torch.allclose(region_values[0, col], norm[LABELS == 0, col][0])
    assert region_values[2, col] > region_values[0, col]


def test_modes_reproduce_a_residual_of_low_rank():
    s = stage(modes=3)
    rng = np.random.default_rng(1)
    basis = torch.from_numpy(rng.normal(size=(3, V, 3))).float() * 1e-3
    mean = torch.from_numpy(rng.normal(size=(V, 3))).float() * 1e-3
    c = torch.from_numpy(rng.normal(size=(50, 3))).float()
    residual = mean + torch.einsum("nk,kvc->nvc", c, basis)
    coef = s.set_modes(residual)
    with torch.no_grad():
        rebuilt = torch.einsum("nk,vkc->nvc", coef, s.table[:, :3]) + s.table[:, 3]
    assert float((rebuilt - residual).abs().max()) < 1e-7


def test_the_split_at_the_first_layer_is_the_members_forward_pass():
    s = stage(members=3).eval()
    with torch.no_grad():
        s.input_mean.normal_()
        s.input_std.uniform_(0.5, 2.0)
    w = torch.rand(4, 52)
    p = defaults()
    x = (s.inputs(w, p) - s.input_mean) / s.input_std
    full = torch.stack([m(x) for m in s.members]).mean(0)
    split = s.coefficients(w, s.condition(p))
    assert torch.allclose(split[:, :-1], full, atol=1e-5)
    assert torch.all(split[:, -1] == 1)  # the mean mode's constant slot


def test_the_fit_learns_a_residual_nonlinear_in_the_weights():
    s = stage(modes=2, members=2, dropout=0.0)
    rng = np.random.default_rng(2)
    n = 400
    w = torch.from_numpy(rng.uniform(0, 1, (n, 52))).float()
    basis = torch.from_numpy(rng.normal(size=(2, V, 3))).float() * 1e-3
    c = torch.stack([torch.sin(3 * w[:, 0]) * w[:, 1], (w[:, 2] - 0.5) ** 2], 1)
    c = c - c.mean(0)  # all in the coefficients: the mean mode alone explains nothing
    residual = torch.einsum("nk,kvc->nvc", c, basis)
    features = s.parameter_features(defaults()).expand(n, -1)
    out = s.fit(w, features, residual, ResidualFit(steps=800, batch=64), progress=False)
    # the mean alone (the stage with its coefficients at zero) leaves most of it
    mean_only = float((residual - residual.mean(0)).norm(dim=-1).mean()) * 1e3
    above(
        mean_only / out["residual_mm"],
        0.5,
        "c has zero mean: the mean mode holds none of it (1.0 up to rounding)",
        what="ratio",
    )
    below(
        out["after_mm"] / out["residual_mm"],
        0.4,
        "800 Adam steps from a fixed seed on a smooth target",
        what="after/residual",
    )
    s.eval()
    with torch.no_grad():
        got = s(w[:50], defaults())
    assert (
        float((got - residual[:50]).norm(dim=-1).mean()) * 1e3
        < 0.4 * out["residual_mm"]
    )


def test_inputs_the_train_frames_never_move_are_read_as_nothing():
    """A parameter constant over the train frames gets no weight: moving it at run time (a
    value the data never had) leaves the coefficients as they are."""
    s = stage(modes=2, members=2)
    rng = np.random.default_rng(3)
    n = 64
    w = torch.from_numpy(rng.uniform(0, 1, (n, 52))).float()
    residual = torch.einsum(
        "n,vc->nvc",
        w[:, 0] - 0.5,
        torch.from_numpy(rng.normal(size=(V, 3))).float() * 1e-3,
    )
    features = s.parameter_features(defaults()).expand(n, -1)
    s.fit(w, features, residual, ResidualFit(steps=20, batch=16), progress=False)
    s.eval()
    p = defaults()
    p[:, [x.name for x in SPECS].index("target_volume")] = 1.4
    with torch.no_grad():
        moved = s.coefficients(w[:3], s.condition(p))
        still = s.coefficients(w[:3], s.condition(defaults()))
    assert torch.equal(moved, still)


def test_contrast_modes_span_a_response_the_residual_modes_miss():
    """A response to p far smaller than what differs between frames is no leading mode of the
    residual; the contrasts' own modes hold it."""
    s = stage(modes=3)
    rng = np.random.default_rng(4)
    big = torch.from_numpy(rng.normal(size=(3, V, 3))).float() * 1e-3
    response = torch.from_numpy(rng.normal(size=(V, 3))).float() * 1e-5
    n = 60
    c = torch.from_numpy(rng.normal(size=(n, 3))).float()
    dp = torch.from_numpy(rng.uniform(-1, 1, n)).float()
    residual = torch.einsum("nk,kvc->nvc", c, big) + dp[:, None, None] * response
    base = torch.einsum("nk,kvc->nvc", c, big)  # the same frames at p's base value
    contrasts = residual - base

    def unexplained(table: torch.Tensor) -> float:
        m = table[:, :-1].permute(0, 2, 1).reshape(-1, table.shape[1] - 1)  # (3V, K)
        r = response.reshape(-1)
        fit = m @ torch.linalg.lstsq(m.double(), r.double()[:, None]).solution.float()
        return float((fit[:, 0] - r).norm() / r.norm())

    s.set_modes(residual)
    above(
        unexplained(s.table),
        0.5,
        "the response lies outside the residual's modes",
        what="",
    )
    s.set_modes(residual, contrasts, extra=1)
    below(
        unexplained(s.table), 1e-3, "an SVD of the contrasts holds it: float32 rounding"
    )


def test_pairs_teach_a_response_that_differences_between_heads_hide():
    """Frames whose residual is mostly a per-head offset the inputs cannot predict and a
    little the response to one parameter: paired frames (same head and weights, the
    parameter changed) give the response far better than the frames alone."""
    rng = np.random.default_rng(5)
    col = [x.name for x in SPECS].index("target_volume")
    spec = SPECS[col]
    groups, n = 48, 96
    w = torch.from_numpy(np.repeat(rng.uniform(0, 1, (groups, 52)), 2, axis=0)).float()
    head = torch.from_numpy(np.repeat(rng.normal(size=(groups, 2)), 2, axis=0)).float()
    big = torch.from_numpy(rng.normal(size=(2, V, 3))).float() * 1e-3
    response = torch.from_numpy(rng.normal(size=(V, 3))).float() * 1e-4
    values = torch.from_numpy(rng.uniform(spec.minimum, spec.maximum, n)).float()
    t = (values - spec.minimum) / (spec.maximum - spec.minimum)
    residual = torch.einsum("nk,kvc->nvc", head, big) + t[:, None, None] * response
    p = defaults(1).repeat(n, 1)
    p[:, col] = values
    pairs = torch.arange(n).reshape(groups, 2)

    def learned(with_pairs: bool) -> float:
        s = stage(modes=3, members=1, dropout=0.0)
        features = torch.cat(
            [s.parameter_features(p[i : i + 1].expand(V, -1)) for i in range(n)]
        )
        cfg = ResidualFit(steps=600, batch=32, contrast_modes=1, contrast_weight=10.0)
        s.fit(w, features, residual, cfg, False, pairs if with_pairs else None)
        s.eval()
        lo, hi = defaults(), defaults()
        lo[:, col], hi[:, col] = spec.minimum, spec.maximum
        with torch.no_grad():
            got = s(w[:8], hi) - s(w[:8], lo)
        return float((got - response).norm() / (response.norm() * 8**0.5))

    paired, alone = learned(True), learned(False)
    # the heads' offsets swamp the response, which the pairs bring out
    above(alone, 2.0, "offsets 10x the response, no pairs", what="alone")
    below(
        paired,
        0.95,
        "600 Adam steps with the pairs' contrast: 0.79 measured",
        what="paired",
    )
    below(paired / alone, 0.25, "the pairs' contrast against none", what="paired/alone")
