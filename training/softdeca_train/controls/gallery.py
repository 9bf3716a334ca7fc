"""`controls`: the controls gallery. Every control moved from one end of its range to the other
on unseen identities and expressions, through the physics and through a model bundle; per
control its figures (controls/metrics.py), heat maps of the change, and a markdown page."""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.controls.cases import IDENTITY_SEEDS, ModelCase, PhysicsCase, expressions
from softdeca_train.controls.definitions import (
    REGION_PARAMETERS,
    Control,
    Setting,
    global_controls,
    region_controls,
)
from softdeca_train.controls.metrics import control_response, identity_spread, rest_split
from softdeca_train.controls.physics_cache import (
    PhysicsCache,
    default_folder,
    open_cache,
    solve_cached,
)
from softdeca_train.controls.pictures import draw_gallery, markdown
from softdeca_train.models.bundle import OnnxNetworks
from softdeca_train.parameters import ParameterSet, load_parameters
from softdeca_train.paths import REPO_ROOT, data_dir, default_takes_path
from softdeca_train.template import Template
from softdeca_train.template.regions import REGIONS, region_labels

RANGES = ("control", "physics")


@dataclass(frozen=True)
class GalleryConfig:
    out: Path = REPO_ROOT / "docs" / "controls"
    bundle: Path | None = REPO_ROOT / "models" / "softdeca-default"  # None: physics only
    level: int = 3
    identities: int = 2
    expressions: int = 3
    only: tuple[str, ...] = ()  # control names; empty: every control
    region_parameters: tuple[str, ...] = REGION_PARAMETERS
    ranges: str = "control"  # control: the control ranges; physics: the physics' own
    pictures: bool = True
    # The physics is the reference of every figure: solved ten times tighter than the training
    # data (1e-4), so that its own convergence error stays small against the changes of the
    # smaller controls; more iterations allowed to get there.
    tolerance: float = 1e-5
    max_iterations: int = 4000
    tet_mesh: str = "carried"  # the physics' tets (LhmConfig.tet_mesh)
    takes: Path = field(default_factory=default_takes_path)
    ict: str | None = None
    # solved physics reused across runs (controls/physics_cache.py); None: always solve
    physics_cache: Path | None = field(default_factory=default_folder)
    # each control also at rest (every weight 0), its change split into that part and what the
    # expression adds (metrics.rest_split): where a model's error comes from
    split_rest: bool = False

    def __post_init__(self) -> None:
        if self.ranges not in RANGES:
            raise ValueError(f"ranges must be one of {RANGES}")
        if not 1 <= self.identities <= len(IDENTITY_SEEDS):
            raise ValueError(f"identities must be in 1..{len(IDENTITY_SEEDS)}")
        if not (0 < self.tolerance < 1 and self.max_iterations >= 1):
            raise ValueError("tolerance must be in (0, 1) and max_iterations at least 1")


def controls_of(cfg: GalleryConfig) -> tuple[list[Control], dict[str, float]]:
    """The controls to measure and the default value of every physics parameter."""
    physics = load_parameters()
    params: ParameterSet = physics.controls() if cfg.ranges == "control" else physics
    defaults = {s.name: s.default_value for s in physics.specs}
    defaults.update({s.name: s.default_value for s in params.specs})
    out = global_controls(params) + region_controls(params, cfg.region_parameters)
    if cfg.only:
        unknown = set(cfg.only) - {c.name for c in out}
        if unknown:
            raise ValueError(f"unknown controls {sorted(unknown)}; known: {[c.name for c in out]}")
        out = [c for c in out if c.name in cfg.only]
    return out, defaults


@dataclass
class Collected:
    physics: dict[str, list[np.ndarray]] = field(default_factory=dict)  # name -> per case dP
    model: dict[str, list[np.ndarray]] = field(default_factory=dict)
    shown: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)  # first case
    clamped: set[str] = field(default_factory=set)
    rest: Collected | None = None  # the same at rest (GalleryConfig.split_rest)


Solve = Callable[[Setting], np.ndarray]  # a Setting -> skin (E, V, 3) for every expression


def measure_controls(
    controls: list[Control], physics: Solve, model: Solve | None, acc: Collected
) -> None:
    """Both ends of every control through the physics and the model (when given); the changes
    go into `acc`, and the first case's shapes are kept for the pictures."""
    for c in controls:
        first = c.name not in acc.shown
        lo, hi = (physics(s) for s in c.ends)
        acc.physics.setdefault(c.name, []).append(hi - lo)
        if first:
            acc.shown[c.name] = {"physics": hi, "lo": lo}
        if model is not None:
            m_lo, m_hi = (model(s) for s in c.ends)
            acc.model.setdefault(c.name, []).append(m_hi - m_lo)
            if first:
                acc.shown[c.name].update({"model": m_hi, "model_lo": m_lo})


def _measure_case(
    cfg: GalleryConfig,
    case: PhysicsCase,
    controls: list[Control],
    defaults: dict[str, float],
    acc: Collected,
    bar: tqdm,
) -> None:
    domains = {s.name: s.domain for s in load_parameters().specs}
    cache = open_cache(cfg.physics_cache)
    model = None
    if cfg.bundle is not None:
        model = ModelCase(OnnxNetworks(cfg.bundle), case)

    def physics(s: Setting) -> np.ndarray:
        return solve_cached(cache, case, s, defaults, domains)

    # The rest split: the same controls again on the case at rest, into their own accumulator.
    rest: tuple[Solve, Solve | None, Collected] | None = None
    if cfg.split_rest:
        acc.rest = acc.rest or Collected()
        rest = (*_at_rest(case, model, cache, defaults, domains), acc.rest)
    for c in controls:
        measure_controls([c], physics, None if model is None else model.solve, acc)
        if rest is not None:
            measure_controls([c], *rest)
        bar.update(1)
    if model is not None:
        acc.clamped |= model.clamped


def _at_rest(
    case: PhysicsCase,
    model: ModelCase | None,
    cache: PhysicsCache,
    defaults: dict[str, float],
    domains: dict[str, str],
) -> tuple[Solve, Solve | None]:
    """The physics and the model of `case`'s identity at rest (GalleryConfig.split_rest), each
    shape repeated over the case's expressions, so that its change lines up with theirs."""
    rest = case.with_weights(np.zeros((1, case.weights.shape[1]), np.float32))
    n = len(case.weights)

    def physics(s: Setting) -> np.ndarray:
        return np.repeat(solve_cached(cache, rest, s, defaults, domains), n, axis=0)

    if model is None:
        return physics, None
    at_rest = ModelCase(model.nets, rest)
    return physics, lambda s: np.repeat(at_rest.solve(s), n, axis=0)


def control_entry(c: Control, acc: Collected, labels: np.ndarray) -> dict:
    """The gallery's figures of one control over every case measured."""
    dp = np.concatenate(acc.physics[c.name])
    dm = np.concatenate(acc.model[c.name]) if c.name in acc.model else np.zeros_like(dp)
    inside = None if c.region is None else labels == REGIONS.index(c.region)
    r = control_response(dp, dm, inside)
    split = {}
    if acc.rest is not None and c.name in acc.rest.model:
        rp, rm = (np.concatenate(x[c.name]) for x in (acc.rest.physics, acc.rest.model))
        split = asdict(rest_split(dp, rp, dm, rm))
    return {
        "name": c.name,
        "parameter": c.parameter,
        "region": c.region,
        "lo": c.lo,
        "hi": c.hi,
        "unit": c.unit,
        "fixed": dict(c.fixed),
        **asdict(r),
        "identity_spread": identity_spread(acc.physics[c.name]),
        "model_clamped": c.parameter in acc.clamped,
        **split,
    }


def run_gallery(cfg: GalleryConfig, progress: bool = True) -> dict:
    """Measure every control (and draw its pictures); returns the gallery's JSON."""
    t0 = time.perf_counter()
    controls, defaults = controls_of(cfg)
    template = Template.load(cfg.ict)
    weights = expressions(cfg.takes, count=cfg.expressions)
    acc = Collected()
    total = cfg.identities * len(controls)
    cases = [
        PhysicsCase(
            template,
            template.sample_identity(seed),
            weights,
            cfg.level,
            cfg.tolerance,
            cfg.max_iterations,
            cfg.tet_mesh,
        )
        for seed in IDENTITY_SEEDS[: cfg.identities]
    ]
    with tqdm(total=total, desc="controls", unit="control", disable=not progress) as bar:
        for case in cases:
            _measure_case(cfg, case, controls, defaults, acc, bar)
    labels = region_labels(template)
    entries = [control_entry(c, acc, labels) for c in controls]
    result = {
        # where this machine keeps its cache is no property of the gallery
        "config": {k: _shown_path(v) for k, v in asdict(cfg).items() if k != "physics_cache"},
        "identity_seeds": list(IDENTITY_SEEDS[: cfg.identities]),
        "expressions": weights.tolist(),
        "controls": entries,
        "seconds": round(time.perf_counter() - t0, 1),
    }
    if cfg.pictures:
        draw_gallery(
            cfg.out, controls, acc.shown, cases[0], entries, progress, complete=not cfg.only
        )
    return result


def _shown_path(value: object) -> object:
    """Paths as the report shows them: relative to the repository or the data folder (the
    gallery is committed: no machine's absolute paths)."""
    if not isinstance(value, Path):
        return value
    p = value.resolve()
    for root, label in ((data_dir().resolve(), "<data>"), (REPO_ROOT.resolve(), "")):
        if p.is_relative_to(root):
            rel = str(p.relative_to(root))
            return f"{label}/{rel}" if label else rel
    return str(value)


def report_entries(result: dict) -> list[dict]:
    """The evaluation report's `controls` list: {name, region, physics_max_mm,
    response_error, leakage} per control."""
    keys = ("name", "region", "physics_max_mm", "response_error", "leakage")
    return [{k: e[k] for k in keys} for e in result["controls"]]


def write_gallery(cfg: GalleryConfig, result: dict) -> Path:
    cfg.out.mkdir(parents=True, exist_ok=True)
    (cfg.out / "controls.json").write_text(json.dumps(result, indent=1) + "\n")
    path = cfg.out / "README.md"
    path.write_text(markdown(cfg, result))
    return path
