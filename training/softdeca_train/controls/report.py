"""The evaluation report's material-control parts (docs/evaluation/evaluation.json): `controls`
(the gallery's figures per control) and `real_takes` (SoftDECA and the linear blendshapes
against the physics on every n-th frame of every recorded take, for unseen identities), their
schema, and merging them into a report that keeps its `errors`."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.controls.cases import IDENTITY_SEEDS, ModelCase, PhysicsCase
from softdeca_train.controls.definitions import Setting
from softdeca_train.controls.physics_cache import (
    PhysicsCache,
    default_folder,
    open_cache,
    solve_cached,
)
from softdeca_train.controls.real_takes import (
    FrameDistances,
    readme_lines,
    recorded_takes,
    reduced,
    summarise,
    trained_on,
    trained_take_names,
    validate_real_takes,
)
from softdeca_train.models.bundle import OnnxNetworks
from softdeca_train.parameters import load_parameters
from softdeca_train.template import Template

CONTROL_KEYS = ("name", "region", "physics_max_mm", "response_error", "leakage")


def _number_or_none(x: object) -> bool:
    return x is None or (isinstance(x, (int, float)) and math.isfinite(x))


def validate_report(doc: dict) -> None:
    """ValueError naming the first problem, unless `doc` has `errors` (a table keyed by model),
    `controls` (a list of {name, region, physics_max_mm, response_error, leakage}) and
    `real_takes` (controls/real_takes.py)."""
    if not isinstance(doc.get("errors"), dict) or not doc["errors"]:
        raise ValueError("report: `errors` must be a non-empty table")
    controls = doc.get("controls")
    if not isinstance(controls, list) or not controls:
        raise ValueError("report: `controls` must be a non-empty list")
    for c in controls:
        if not isinstance(c, dict) or set(c) != set(CONTROL_KEYS):
            raise ValueError(f"report: a control needs exactly {CONTROL_KEYS}: {c}")
        if not isinstance(c["name"], str) or not (
            c["region"] is None or isinstance(c["region"], str)
        ):
            raise ValueError(f"report: control name/region must be strings: {c}")
        if not (isinstance(c["physics_max_mm"], (int, float)) and c["physics_max_mm"] >= 0):
            raise ValueError(f"report: physics_max_mm must be a number >= 0: {c}")
        if not (_number_or_none(c["response_error"]) and _number_or_none(c["leakage"])):
            raise ValueError(f"report: response_error and leakage are numbers or null: {c}")
        if c["region"] is None and c["leakage"] is not None:
            raise ValueError(f"report: a global control has no leakage: {c}")
    validate_real_takes(doc.get("real_takes"))


@dataclass(frozen=True)
class RealTakes:
    recordings: Path  # every *.csv below it is a take
    identities: int = 3
    every: int = 10
    # every unseen take is also judged with its weights scaled by this (a calm face of the
    # same motion; controls/real_takes.py); None: as recorded only
    reduced_amplitude: float | None = 0.3
    level: int = 3
    chunk: int = 32  # frames solved per batch (memory)
    # solves reused across runs (controls/physics_cache.py); None: always solve
    physics_cache: Path | None = field(default_factory=default_folder)


class _Judge:
    """The physics and a bundle on one identity's frames: their mean distances (mm) over S."""

    def __init__(self, nets: OnnxNetworks, first: PhysicsCase, cache: PhysicsCache) -> None:
        physics = load_parameters()
        self.defaults = {s.name: s.default_value for s in physics.specs}
        self.defaults.update({s.name: s.default_value for s in physics.controls().specs})
        self.domains = {s.name: s.domain for s in physics.specs}
        self.first, self.model, self.cache = first, ModelCase(nets, first), cache

    def distances(self, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(SoftDECA, linear blend) per frame of `weights`."""
        case = self.first.with_weights(weights)
        self.model.use(case)
        t = solve_cached(self.cache, case, Setting(), self.defaults, self.domains)
        x = self.model.solve(Setting())
        return (
            1e3 * np.linalg.norm(x - t, axis=-1).mean(axis=1),
            1e3 * np.linalg.norm(case.targets - t, axis=-1).mean(axis=1),
        )


def real_takes(cfg: RealTakes, bundle: Path, progress: bool = True) -> dict:
    """SoftDECA (the bundle, default parameters) and the linear blendshapes against the physics
    (default parameters) on every n-th frame of every take, per take (controls/real_takes.py);
    the takes the bundle trained on apart from those it never saw, and the neutral face."""
    if not 1 <= cfg.identities <= len(IDENTITY_SEEDS) or cfg.every < 1:
        raise ValueError(f"identities must be in 1..{len(IDENTITY_SEEDS)}, every >= 1")
    takes = recorded_takes(cfg.recordings, cfg.every)
    trained = trained_take_names(json.loads((Path(bundle) / "manifest.json").read_text()))
    if cfg.reduced_amplitude is not None:
        takes += [
            reduced(t, cfg.reduced_amplitude) for t in list(takes) if not trained_on(t, trained)
        ]
    template = Template.load()
    nets = OnnxNetworks(bundle)
    cache = open_cache(cfg.physics_cache)
    rows: dict[str, list] = {"take": [], "softdeca": [], "linear": []}
    rest = []
    total = cfg.identities * sum(len(t.weights) for t in takes)
    with tqdm(total=total, desc="real takes", unit="frame", disable=not progress) as bar:
        for seed in IDENTITY_SEEDS[: cfg.identities]:
            head = template.sample_identity(seed)
            first = PhysicsCase(template, head, takes[0].weights[:1], cfg.level)
            judge = _Judge(nets, first, cache)
            rest.append(judge.distances(np.zeros((1, 52), np.float32)))
            for index, take in enumerate(takes):
                for start in range(0, len(take.weights), cfg.chunk):
                    softdeca, linear = judge.distances(take.weights[start : start + cfg.chunk])
                    rows["take"] += [index] * len(softdeca)
                    rows["softdeca"] += list(softdeca)
                    rows["linear"] += list(linear)
                    bar.update(len(softdeca))
    distances = FrameDistances(
        np.array(rows["take"]), np.array(rows["softdeca"]), np.array(rows["linear"])
    )
    seen = [trained_on(t, trained) for t in takes]
    at_rest = (float(np.mean([r[0] for r in rest])), float(np.mean([r[1] for r in rest])))
    return summarise(takes, seen, distances, cfg.every, cfg.identities, at_rest)


def kept_real_takes(path: Path) -> dict | None:
    """The `real_takes` a report already has (None: no report, or none in it): what a rerun
    that does not measure them keeps."""
    path = Path(path)
    return json.loads(path.read_text()).get("real_takes") if path.is_file() else None


def merge_into_report(path: Path, controls: list[dict] | None, real: dict | None) -> dict:
    """Add (or replace) `controls` and `real_takes` in an existing report, keeping the rest."""
    doc = json.loads(Path(path).read_text())
    if controls is not None:
        doc["controls"] = controls
    if real is not None:
        doc["real_takes"] = real
    Path(path).write_text(json.dumps(doc, indent=1) + "\n")
    return doc


SECTION = "## Material controls and real takes"


def _fmt(x: float | None) -> str:
    return "–" if x is None else f"{x:.3f}"


def readme_section(doc: dict) -> str:
    """The report README's section on `controls` and `real_takes` (docs/controls.md)."""
    lines = [SECTION, ""]
    controls = doc.get("controls") or []
    if controls:
        errs = [c["response_error"] for c in controls if c["response_error"] is not None]
        leaks = [c["leakage"] for c in controls if c["leakage"] is not None]
        short = [c["name"] for c in controls if c["physics_max_mm"] < 1.0]
        lines += [
            f"{len(controls)} controls (docs/controls.md, docs/controls/): median response "
            f"error {_fmt(float(np.median(errs)) if errs else None)}, median leakage "
            f"{_fmt(float(np.median(leaks)) if leaks else None)}; moving the physics by less "
            f"than 1 mm over their range: {', '.join(short) or 'none'}.",
            "",
            "| control | region | physics max (mm) | response error | leakage |",
            "| --- | --- | ---: | ---: | ---: |",
        ]
        lines += [
            f"| {c['name']} | {c['region'] or 'global'} | {_fmt(c['physics_max_mm'])} "
            f"| {_fmt(c['response_error'])} | {_fmt(c['leakage'])} |"
            for c in controls
        ]
        lines.append("")
    real = doc.get("real_takes")
    if real:
        lines += readme_lines(real)
    return "\n".join(lines) + "\n"


def update_readme(readme: Path, doc: dict) -> None:
    """Replace (or append) the README's controls section."""
    text = Path(readme).read_text() if Path(readme).is_file() else ""
    if SECTION in text:
        text = text[: text.index(SECTION)]
    Path(readme).write_text(text.rstrip("\n") + "\n\n" + readme_section(doc))
