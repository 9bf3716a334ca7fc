"""Every trainable model by name: what it is, which batches it trains on, which trained static
model it builds on (dynamics stages and the latent-dynamics baseline), and how to make it.
A training run (a folder) holds one checkpoint per name."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from softdeca_train.data.ranges import fixed_outside_profile, sampling_parameters
from softdeca_train.models.networks import NetworkSizes
from softdeca_train.models.topology import TemplateDefinition
from softdeca_train.parameters import ParameterSpec, load_parameters
from softdeca_train.train import trainable as m

Build = Callable[
    [TemplateDefinition, Sequence[ParameterSpec], NetworkSizes, m.Trainable | None], m.Trainable
]


@dataclass(frozen=True)
class Entry:
    name: str
    description: str
    build: Build
    base: str | None = None  # the static model a dynamics stage runs over

    def make(
        self,
        d: TemplateDefinition,
        specs: Sequence[ParameterSpec],
        sizes: NetworkSizes,
        base: m.Trainable | None = None,
    ) -> m.Trainable:
        if (self.base is None) != (base is None):
            raise ValueError(
                f"{self.name} needs the trained {self.base} model" if self.base else ""
            )
        return self.build(d, specs, sizes, base)


# Widths of the SoftSMPL-style MLPs. Its cost is the output layer (hidden x 3 x skin vertices):
# measured in torch, 96 hidden units took 0.6 ms per frame, so 400 match SoftDECA's 2.5 ms per
# frame in the native runtime (docs/benchmarks.md): "equal time". "large" is two layers of 768.
MLP_EQUAL = (400,)
MLP_LARGE = (768, 768)


def _sparse(name: str, description: str, **options: float | bool) -> Entry:
    """A SparseSoftDECA variant: the model with these training options."""
    return Entry(name, description, lambda d, s, z, b: m.SparseSoftDeca(d, s, z, **options))  # type: ignore[arg-type]


# The identity code's error on fitted avatars, per coefficient (h is N(0, I)): RMS 0.54, 0.56,
# 0.81 and 0.64 for seeds 111, 222, 333 and 444 remeshed to 8,000 vertices and fitted
# (`avatar-fit-check --identity "seed 111" ... --take S07-001 --max-frames 2`), none of them
# an identity the fit check judges by.
CODE_NOISE = 0.65

MODELS: dict[str, Entry] = {
    e.name: e
    for e in (
        Entry(
            "softdeca",
            "SoftDECA: deformation gradients + DT, plus a vertex stage started at the "
            "per-vertex ridge fit (the bundle's model)",
            lambda d, s, z, b: m.SoftDecaHybrid(d, s, z),
        ),
        Entry(
            "softdeca-dt",
            "SoftDECA as the paper has it: deformation gradients + DT only",
            lambda d, s, z, b: m.SoftDeca(d, s, z),
        ),
        Entry(
            "softdeca-dynamics",
            "SoftDECA's per-vertex dynamics (eq. 21)",
            lambda d, s, z, b: m.Dynamics(b, d.skin_vertices, s, z),  # type: ignore[arg-type]
            base="softdeca",
        ),
        _sparse("sparse", "SparseSoftDECA, trained with noise augmentation (eq. 24)"),
        _sparse(
            "sparse-code-noise",
            "SparseSoftDECA trained with noise augmentation and a perturbed identity code "
            "(measured: no better on fitted avatars)",
            code_noise=CODE_NOISE,
        ),
        Entry(
            "sparse-dynamics",
            "SparseSoftDECA's per-vertex dynamics",
            lambda d, s, z, b: m.Dynamics(b, d.skin_vertices, s, z, 0.6, 0.25),  # type: ignore[arg-type]
            base="sparse",
        ),
        _sparse(
            "sparse-no-noise",
            "SparseSoftDECA trained on clean personalised landmarks (Table 2 ablation)",
            noisy=False,
        ),
        Entry(
            "softdeca-vertex",
            "vertex-position variant of SoftDECA (Table 1)",
            lambda d, s, z, b: m.SoftDecaVertex(d, s, z),
        ),
        Entry(
            "mlp-equal-time",
            f"SoftSMPL-style MLP {MLP_EQUAL} (Table 1, equal time)",
            lambda d, s, z, b: m.GlobalMlp(d, s, z, MLP_EQUAL),
        ),
        Entry(
            "mlp-large",
            f"SoftSMPL-style MLP {MLP_LARGE} (Table 1, large)",
            lambda d, s, z, b: m.GlobalMlp(d, s, z, MLP_LARGE),
        ),
        Entry("face-mlp", "face-wise MLP + DT (Table 1)", lambda d, s, z, b: m.FaceMlp(d, s, z)),
        Entry(
            "snp-dynamics",
            "SNP-style latent dynamics over SoftDECA (Table 1, dynamic)",
            lambda d, s, z, b: m.LatentDynamics(b, d, s, z),  # type: ignore[arg-type]
            base="softdeca",
        ),
    )
}

BUNDLE_STAGES = ("softdeca", "softdeca-dynamics", "sparse", "sparse-dynamics")


def dataset_specs(range_profile: str) -> tuple[ParameterSpec, ...]:
    """The bundle's parameter specs: the physics' list with the ranges the data sampled (a
    network is only valid there, so the runtime refuses values outside them). Parameters the
    profile keeps at their defaults because they are no controls are not model inputs."""
    physics = load_parameters()
    fixed = set(fixed_outside_profile(physics, range_profile))
    sampled = sampling_parameters(physics, range_profile).specs
    return tuple(s for s in sampled if s.name not in fixed)
