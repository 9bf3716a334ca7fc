"""The plan: every shard of a dataset, fixed by the configuration alone, before anything is
simulated. A shard is one identity with a few (identity, p) groups of frames; its instance
ids, identity seed, parameter vectors and expression frames (with their sources) are all in
its spec, so any worker on any machine produces the same shard, and a resumed run regenerates
exactly the missing ones.

Splits: each kind's shards (identities) are split by a seeded choice of `test_share` of
them. Parameter vectors are drawn per group and numbered (param_id), identities are numbered
(identity_id, including the sparse donors), so train and test share no identity and no
parameter set; test frames come from the held-out take and the test coverage stream only."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from softdeca_train.data.config import KINDS, TEST, TRAIN, GenerateConfig
from softdeca_train.data.expressions import Draws, ExpressionSource
from softdeca_train.data.ranges import fixed_outside_profile
from softdeca_train.parameters import ParameterSet
from softdeca_train.sim.dynamics import MAX_PEAK_GAIN, peak_gain
from softdeca_train.template.regions import CONTROL_REGIONS, REGIONAL_DOMAINS, REGIONS

KIND_CODE = {k: i for i, k in enumerate(KINDS)}
# Parameters that do not act in a kind keep their defaults there (paper 4.2.1: static
# instances sample everything but the dynamics): the networks then see no noise inputs.
FIXED = {
    "static": ("dyn_gamma", "dyn_beta", "w_regularisation", "w_landmark"),
    "dynamic": ("w_regularisation", "w_landmark"),
    "sparse": ("dyn_gamma", "dyn_beta", "w_target"),
}


def derived_seed(*key: int) -> int:
    """A 32-bit seed for one item (e.g. identity k of dataset seed s): independent streams."""
    return int(np.random.SeedSequence(list(key)).generate_state(1)[0])


@dataclass(frozen=True)
class GroupSpec:
    """Frames that share (identity, p): simulated in a row over one factorisation."""

    param_id: int
    p: np.ndarray  # (n_params,) float64
    frames: Draws  # static/sparse: the instances' frames; dynamic: lead-in + sequence
    donor_id: int = -1  # sparse: identity whose expression landmarks are personalised
    donor_seed: int = -1
    noise_seed: int = -1
    # static/sparse: the value of every parameter per region of S (len(REGIONS), n_params)
    # where the group has a regional pattern; None: p everywhere
    p_regions: np.ndarray | None = None


@dataclass(frozen=True)
class ShardSpec:
    kind: str
    index: int
    split: int
    identity_id: int
    identity_seed: int
    first_instance: int
    groups: tuple[GroupSpec, ...]

    @property
    def instances(self) -> int:
        per = 1 if self.kind == "dynamic" else None
        return sum(per or len(g.frames.weights) for g in self.groups)

    @property
    def instance_ids(self) -> np.ndarray:
        return self.first_instance + np.arange(self.instances, dtype=np.int64)


def sample_parameters(
    params: ParameterSet, kind: str, rng: np.random.Generator, fixed: tuple[str, ...] = ()
) -> np.ndarray:
    """One parameter vector; the kind's FIXED entries and `fixed` at their defaults. The
    dynamics pair (gamma, beta) is drawn again until eq. 9 amplifies no motion by more than
    MAX_PEAK_GAIN (sim/dynamics.py: past it the tissue resonates)."""
    p = params.sample(rng)
    g, b = params.names.index("dyn_gamma"), params.names.index("dyn_beta")
    dynamics_fixed = {"dyn_gamma", "dyn_beta"} <= {*FIXED[kind], *fixed}
    while not dynamics_fixed and peak_gain(p[g], p[b]) > MAX_PEAK_GAIN:
        p[[g, b]] = params.sample(rng)[[g, b]]
    defaults = params.defaults()
    for name in (*FIXED[kind], *fixed):
        k = params.names.index(name)
        p[k] = defaults[k]
    return p


def regional_pattern(
    params: ParameterSet,
    p: np.ndarray,
    fixed: tuple[str, ...],
    rng: np.random.Generator,
    share: float,
) -> np.ndarray | None:
    """With probability `share`, a regional pattern over p: each localisable parameter (one
    the physics defines per element of a place on S, REGIONAL_DOMAINS) that is not fixed
    gets, with probability 1/2, its own value in every region of the face a control can set
    (drawn from its range like p), the others keep p's value everywhere. None: p everywhere."""
    if rng.random() >= share:
        return None
    pattern = np.repeat(p[None], len(REGIONS), axis=0)
    rows = [REGIONS.index(r) for r in CONTROL_REGIONS]
    for k, s in enumerate(params.specs):
        if s.domain not in REGIONAL_DOMAINS or s.name in fixed or rng.random() < 0.5:
            continue
        pattern[rows, k] = s.sample(rng, len(rows))
    return pattern


def contrast(
    params: ParameterSet,
    p: np.ndarray,
    pattern: np.ndarray | None,
    fixed: tuple[str, ...],
    rng: np.random.Generator,
    region_share: float,
) -> tuple[np.ndarray, np.ndarray | None]:
    """(p, pattern) with one factor drawn again: one parameter that is not fixed, everywhere,
    or (with probability `region_share`, for a localisable one) its value in one region of
    the face a control can set. Everything else stays as it was."""
    free = [k for k, s in enumerate(params.specs) if s.name not in fixed]
    if not free:
        raise ValueError("contrasts need a parameter that is not fixed")
    k = free[int(rng.integers(len(free)))]
    spec = params.specs[k]
    value = float(spec.sample(rng))
    p = p.copy()
    if spec.domain in REGIONAL_DOMAINS and rng.random() < region_share:
        pattern = np.repeat(p[None], len(REGIONS), axis=0) if pattern is None else pattern.copy()
        pattern[REGIONS.index(CONTROL_REGIONS[int(rng.integers(len(CONTROL_REGIONS)))]), k] = value
        return p, pattern
    p[k] = value
    if pattern is not None:
        pattern = pattern.copy()
        pattern[:, k] = value
    return p, pattern


def _test_shards(n_shards: int, share: float, rng: np.random.Generator) -> set[int]:
    if share <= 0 or n_shards < 2:
        return set()
    n_test = min(n_shards - 1, max(1, round(share * n_shards)))
    return {int(i) for i in rng.choice(n_shards, n_test, replace=False)}


def make_plan(
    cfg: GenerateConfig, params: ParameterSet, sources: dict[int, ExpressionSource]
) -> list[ShardSpec]:
    shards: list[ShardSpec] = []
    next_instance = next_identity = next_param = 0
    for kind in KINDS:
        n, per_group = cfg.count(kind), cfg.per_group(kind)
        per_shard = per_group * cfg.groups_per_shard(kind)
        n_shards = math.ceil(n / per_shard)
        code = KIND_CODE[kind]
        test = _test_shards(n_shards, cfg.test_share, np.random.default_rng([cfg.seed, 20, code]))
        rng_p = np.random.default_rng([cfg.seed, 21, code])
        rng_r = np.random.default_rng([cfg.seed, 22, code])  # regional patterns
        rng_c = np.random.default_rng([cfg.seed, 23, code])  # contrasts
        contrasts = cfg.contrasts and kind != "dynamic"
        fixed = fixed_outside_profile(params, cfg.ranges)
        for s in range(n_shards):
            split = TEST if s in test else TRAIN
            left = min(per_shard, n - s * per_shard)
            identity_id = next_identity
            next_identity += 1
            groups = []
            while left > 0:
                k = min(per_group, left) if kind != "dynamic" else 1
                left -= k
                held = (*FIXED[kind], *fixed)
                src = sources[split]
                if contrasts and groups:  # the shard's first group with one factor changed
                    first = groups[0]
                    p, p_regions = contrast(
                        params, first.p, first.p_regions, held, rng_c, cfg.region_share
                    )
                    f = first.frames
                    frames = Draws(f.weights[:k], f.source_take[:k], f.source_index[:k])
                else:
                    p = sample_parameters(params, kind, rng_p, fixed)
                    p_regions = None
                    if kind != "dynamic" and cfg.region_share > 0:
                        p_regions = regional_pattern(params, p, held, rng_r, cfg.region_share)
                    if kind == "dynamic":
                        frames = src.window(cfg.lead_in + cfg.sequence_length)
                    else:
                        frames = src.frames(k, cfg.real_share, cfg.real_reduced_share)
                donor_id = donor_seed = noise_seed = -1
                if kind == "sparse":
                    donor_id = next_identity
                    next_identity += 1
                    donor_seed = derived_seed(cfg.seed, 1, donor_id)
                    noise_seed = derived_seed(cfg.seed, 3, next_param)
                groups.append(
                    GroupSpec(next_param, p, frames, donor_id, donor_seed, noise_seed, p_regions)
                )
                next_param += 1
            spec = ShardSpec(
                kind=kind,
                index=s,
                split=split,
                identity_id=identity_id,
                identity_seed=derived_seed(cfg.seed, 1, identity_id),
                first_instance=next_instance,
                groups=tuple(groups),
            )
            next_instance += spec.instances
            shards.append(spec)
    return shards
