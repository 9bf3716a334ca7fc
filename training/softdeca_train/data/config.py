"""What a dataset is made of (GenerateConfig: it fixes the data, so it is the manifest's header
and a resume must match it) and how a run executes it (RunSettings: free to change between a
run and its resume, e.g. more workers or a Ray cluster)."""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

from softdeca_train import paths
from softdeca_train.data.ranges import DEFAULT_PROFILE, LEGACY_PROFILE, is_profile

KINDS = ("static", "dynamic", "sparse")
TRAIN, TEST = 0, 1
PAPER_STATIC_SHARE = 0.75  # paper 4.2.1: 75 % static instances, 25 % dynamic (by frames)


@dataclass(frozen=True)
class GenerateConfig:
    """A dataset's definition. Counts: static and sparse instances are frames; dynamic
    instances are sequences of `sequence_length` frames."""

    static: int = 300
    dynamic: int = 20
    sparse: int = 300
    seed: int = 0
    test_share: float = 0.1  # share of identities (shards) per kind held out for testing
    # Layered head model resolution (icosphere level of the wraps). The paper's tet mesh has
    # ~50k vertices; level 3 (6.3k simulated vertices) is a reduced scale that fits this
    # 2-core machine, level 4 or 5 is for a cluster. S keeps its full resolution (14,062
    # points) at every level: it is embedded in the tets.
    level: int = 3
    # Frames that share (identity, p) share one factorisation: solved in a row on one simulator.
    # 1 (the default): every static and sparse instance has its own p, so a batch of training
    # frames spans as many parameter sets as frames (datasets up to softdeca-l3-i2 used 2-8).
    frames_per_params: int = 1  # static and sparse frames per (identity, p) group
    params_per_identity: int = 8  # (identity, p) groups per shard; one identity per shard
    sequences_per_identity: int = 2  # dynamic: sequences (each its own p) per shard
    sequence_length: int = 16  # paper 4.2.1
    # Dynamic sequences start with a velocity: `lead_in` preceding frames of the take are
    # simulated with fixed dynamics (lead_in_gamma, lead_in_beta) before the sampled ones
    # take over (paper 4.2.1 draws it from a 2048-frame pre-simulated sequence instead).
    lead_in: int = 8
    lead_in_gamma: float = 0.5
    lead_in_beta: float = 0.5
    real_share: float = 0.5  # static/sparse frames from real takes; the rest from coverage
    # Real frames played at a reduced amplitude (weights times U(REDUCED_LO, REDUCED_HI)):
    # people talking calmer than the recorded ones, the input a live stream mostly carries.
    real_reduced_share: float = 0.0
    # Takes held out entirely for the test split, by name (file stem): one take of the
    # person most takes come from, and every take of a person no other take shows.
    test_takes: tuple[str, ...] = ("facial", "dao")
    landmark_noise_mm: float = 1.0  # sigma of the coordinate-wise Gaussian noise (eq. 24)
    identity_scale: float = 1.0  # identity coefficients h ~ N(0, scale^2) (plausible only)
    # Lip/teeth collision sets (paper 3.3.2) and the lips placed on S (docs/physics.md).
    collisions: bool = True
    tolerance: float = 1e-4  # solver convergence (relative to the head's bounding box)
    # A soft tissue far stiffer in volume than in shear converges slowly: 13 of 512 frames
    # were past 200 iterations, 11 of them converged by 560 (docs/physics.md, The conforming
    # tet mesh). A frame past the cap is kept with its `converged` flag and `estimated_error`
    # and counted `not_converged` in the report.
    max_iterations: int = 800
    # Parameter sampling ranges (data/ranges.py): "interactive" samples a decade around the
    # defaults (what the shipped bundle covers), "plausible" narrows only the weakest
    # constraint weights of Appendix A, "appendix-a" samples the physics' own ranges.
    ranges: str = DEFAULT_PROFILE
    # Share of static and sparse groups with a regional pattern: localisable parameters set
    # per region of S (data/plan.py regional_pattern), what region controls do at run time.
    region_share: float = 0.5
    # Contrasts: the static and sparse groups of a shard share their frames, and every group
    # after the first differs from the first's p in one factor only (one parameter, or its
    # value in one region), so the data holds the physics' response to that factor with the
    # identity, the expression and every other parameter fixed (data/plan.py contrast).
    contrasts: bool = False

    def __post_init__(self) -> None:
        problems = []
        for name in ("static", "dynamic", "sparse", "lead_in"):
            if getattr(self, name) < 0:
                problems.append(f"{name} must be >= 0")
        for name in (
            "frames_per_params",
            "params_per_identity",
            "sequences_per_identity",
            "sequence_length",
            "max_iterations",
        ):
            if getattr(self, name) < 1:
                problems.append(f"{name} must be >= 1")
        if self.static + self.dynamic + self.sparse == 0:
            problems.append("nothing to generate: static, dynamic and sparse are all 0")
        if not 0.0 <= self.test_share < 1.0:
            problems.append("test_share must be in [0, 1)")
        if not 0.0 <= self.real_share <= 1.0:
            problems.append("real_share must be in [0, 1]")
        if not 0.0 <= self.real_reduced_share <= 1.0:
            problems.append("real_reduced_share must be in [0, 1]")
        if not 0.0 <= self.region_share <= 1.0:
            problems.append("region_share must be in [0, 1]")
        if not 1 <= self.level <= 6:
            problems.append("level must be in 1..6")
        if self.landmark_noise_mm < 0 or self.identity_scale <= 0 or self.tolerance <= 0:
            problems.append("landmark_noise_mm >= 0, identity_scale > 0, tolerance > 0")
        if not (0.0 < self.lead_in_gamma <= 1.0 and 0.0 <= self.lead_in_beta < 1.0):
            problems.append("lead-in dynamics need gamma in (0, 1], beta in [0, 1)")
        if self.dynamic and self.lead_in < 2:
            problems.append("dynamic sequences need lead_in >= 2 (the two previous frames)")
        if not self.test_takes:
            problems.append("at least one test take")
        if not is_profile(self.ranges):
            problems.append(f"unknown range profile {self.ranges!r}")
        if problems:
            raise ValueError("bad generate configuration: " + "; ".join(problems))

    @classmethod
    def from_total(cls, instances: int, sparse: int, **kw: object) -> GenerateConfig:
        """The paper's mix: 75 % of `instances` frames static, 25 % in dynamic sequences."""
        length = int(kw.get("sequence_length", cls.sequence_length))  # type: ignore[arg-type]
        static = round(PAPER_STATIC_SHARE * instances)
        dynamic = round((instances - static) / length)
        return cls(static=static, dynamic=dynamic, sparse=sparse, **kw)  # type: ignore[arg-type]

    def count(self, kind: str) -> int:
        return {"static": self.static, "dynamic": self.dynamic, "sparse": self.sparse}[kind]

    def per_group(self, kind: str) -> int:
        """Instances per (identity, p) group."""
        return 1 if kind == "dynamic" else self.frames_per_params

    def groups_per_shard(self, kind: str) -> int:
        return self.sequences_per_identity if kind == "dynamic" else self.params_per_identity

    def as_dict(self) -> dict:
        return {**asdict(self), "test_takes": list(self.test_takes)}  # as JSON holds it

    @classmethod
    def from_dict(cls, d: dict) -> GenerateConfig:
        names = {f.name for f in fields(cls)}
        # written before range profiles and regional patterns existed
        d = {
            "ranges": LEGACY_PROFILE,
            "region_share": 0.0,
            "contrasts": False,
            "real_reduced_share": 0.0,
            **d,
        }
        if "test_take" in d:  # written when one take was held out
            d["test_takes"] = [d.pop("test_take")]
        if "test_takes" in d:
            d["test_takes"] = tuple(d["test_takes"])
        return cls(**{k: v for k, v in d.items() if k in names})


@dataclass(frozen=True)
class RunSettings:
    """How one run executes the plan; not part of the data's identity."""

    out: Path
    workers: int = field(default_factory=lambda: os.cpu_count() or 1)  # 0: in this process
    threads: int = 1  # simulator threads per worker (measured: 1 per process is faster)
    ray_address: str | None = None  # "local" starts a local Ray instance
    ict: str | None = None
    takes: Path = field(default_factory=paths.default_recordings_path)
    progress: bool = True
    # Kinds whose missing shards run before the others (the order only: the dataset is the
    # same), so that one kind is ready for training while the rest is still being made.
    first: tuple[str, ...] = ()
