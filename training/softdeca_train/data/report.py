"""The dataset report: report.md + PNGs, computed by streaming the shards once.

- parameters: histogram of every entry of p on its own scale (normalised to [0, 1]) against
  the target (uniform on that scale, paper Appendix A); fixed entries are marked;
- weights: histogram of every ARKit weight against the target mix (real_share of the train
  takes' frames, the rest from the fitted coverage sampler);
- identities: the coefficients h against N(0, 1), and the spread of the neutral heads;
- |T - S| (mm) per region and kind: mean and percentiles. This is the yardstick the
  networks' errors are read against: an error near it means the network learnt nothing.

Kept whole: every figure comes from the one streaming pass over the shards."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from softdeca_train import paths
from softdeca_train.data.blend import SkinBlend
from softdeca_train.data.config import KINDS, GenerateConfig
from softdeca_train.data.expressions import expression_sources, load_takes
from softdeca_train.data.generate import summarise
from softdeca_train.data.offset_structure import RIDGE, offset_structure
from softdeca_train.data.ranges import sampling_parameters
from softdeca_train.data.shards import iter_shards
from softdeca_train.landmarks import SurfaceLandmarks, template_landmarks
from softdeca_train.parameters import ParameterSet, load_parameters
from softdeca_train.template import ARKIT_BLENDSHAPES, Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.regions import REGIONS, region_labels

BIN_MM = 0.01
MAX_MM = 200.0
PERCENTILES = (50, 90, 99)


class Displacements:
    """Streaming mean and histogram percentiles of |T - S| per region (mm)."""

    def __init__(self, labels: np.ndarray) -> None:
        self.labels = labels
        self.nbins = int(MAX_MM / BIN_MM) + 1  # the last bin holds everything beyond
        self.hist = np.zeros((len(REGIONS) + 1, self.nbins), np.int64)  # + "all of S"
        self.sum = np.zeros(len(REGIONS) + 1)
        self.max = np.zeros(len(REGIONS) + 1)
        self.frames = 0

    def add(self, offsets: np.ndarray) -> None:
        if offsets.size == 0:
            return
        d = np.linalg.norm(offsets.astype(np.float32).reshape(-1, N_SKIN, 3), axis=2) * 1e3
        self.frames += len(d)
        bins = np.minimum((d / BIN_MM).astype(np.int64), self.nbins - 1)
        for r in range(len(REGIONS) + 1):
            sel = slice(None) if r == len(REGIONS) else self.labels == r
            b, v = bins[:, sel].ravel(), d[:, sel]
            self.hist[r] += np.bincount(b, minlength=self.nbins)
            self.sum[r] += float(v.sum())
            self.max[r] = max(self.max[r], float(v.max()))

    def table(self) -> list[dict]:
        rows = []
        for r, name in enumerate((*REGIONS, "all of S")):
            n = self.hist[r].sum()
            if n == 0:
                continue
            cdf = np.cumsum(self.hist[r]) / n
            row = {
                "region": name,
                "vertices": int((self.labels == r).sum()) if r < len(REGIONS) else N_SKIN,
                "mean": self.sum[r] / n,
            }
            for q in PERCENTILES:
                row[f"p{q}"] = (np.searchsorted(cdf, q / 100) + 1) * BIN_MM
            row["max"] = self.max[r]
            rows.append(row)
        return rows


def _target_weights(manifest: dict, takes_dir: Path | None, n: int = 20000) -> np.ndarray | None:
    """Samples of the intended weight distribution of the train split's static frames."""
    cfg = GenerateConfig.from_dict(manifest["header"]["config"])
    try:
        takes = load_takes(takes_dir) if takes_dir else None
    except FileNotFoundError:
        takes = None
    if takes is None:
        return None
    sources, sampler = expression_sources(takes, cfg.test_takes, cfg.seed + 1, 0.0)
    src = sources[0]
    real = src.pool[np.random.default_rng(0).integers(len(src.pool), size=n)]
    w_real = np.stack([takes[t].weights[i] for t, i in real])
    w_cov = sampler.sample(np.random.default_rng(1), n)
    pick = np.random.default_rng(2).random(n) < cfg.real_share
    return np.where(pick[:, None], w_real, w_cov)


def dataset_parameters(manifest: dict) -> ParameterSet:
    """The parameters with the ranges this dataset sampled (its range profile)."""
    cfg = GenerateConfig.from_dict(manifest["header"]["config"])
    return sampling_parameters(load_parameters(), cfg.ranges)


def _plot_parameters(p_norm: dict[str, np.ndarray], manifest: dict, path: Path) -> None:
    params = dataset_parameters(manifest)
    fixed = {k: set(v["fixed_parameters"]) for k, v in manifest["dataset"]["kinds"].items()}
    fig, axes = plt.subplots(5, 5, figsize=(17, 14))
    for k, (ax, spec) in enumerate(zip(axes.ravel(), params.specs, strict=True)):
        for kind, values in p_norm.items():
            if len(values) and spec.name not in fixed[kind]:
                ax.hist(
                    values[:, k], bins=20, range=(0, 1), density=True, histtype="step", label=kind
                )
        ax.axhline(1.0, color="k", ls="--", lw=1, label="target (uniform)")
        fixed_in = [kind for kind in p_norm if spec.name in fixed[kind]]
        note = f"\nfixed in {', '.join(fixed_in)}" if fixed_in else ""
        title = f"{spec.name} [{spec.minimum:g}, {spec.maximum:g}] {spec.scale}{note}"
        ax.set_title(title, fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 2].legend(fontsize=7)
    fig.suptitle("parameters p, normalised on their sampling scale (density)")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _plot_weights(w: np.ndarray, target: np.ndarray | None, path: Path) -> None:
    fig, axes = plt.subplots(6, 9, figsize=(22, 14))
    for k, ax in enumerate(axes.ravel()):
        if k >= 52:
            ax.axis("off")
            continue
        ax.hist(w[:, k], bins=20, range=(0, 1), density=True, histtype="step", label="dataset")
        if target is not None:
            ax.hist(
                target[:, k],
                bins=20,
                range=(0, 1),
                density=True,
                histtype="step",
                ls="--",
                color="k",
                label="target",
            )
        ax.set_yscale("log")
        ax.set_title(ARKIT_BLENDSHAPES[k], fontsize=8)
        ax.tick_params(labelsize=6)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(
        "ARKit weights of all frames (density, log): dataset vs target mix of real "
        "train takes and coverage sampler"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)


def _plot_identities(h: np.ndarray, split: np.ndarray, spread_mm: np.ndarray, path: Path) -> None:
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.5))
    x = np.linspace(-3.5, 3.5, 200)
    axes[0].hist(h.ravel(), bins=40, density=True, histtype="step", label="h (all modes)")
    axes[0].plot(x, np.exp(-(x**2) / 2) / np.sqrt(2 * np.pi), "k--", label="N(0, 1)")
    axes[0].set_title("identity coefficients")
    axes[0].legend()
    for s, name in ((0, "train"), (1, "test")):
        axes[1].scatter(h[split == s, 0], h[split == s, 1], s=10, label=name)
    axes[1].set_xlabel("h[0]")
    axes[1].set_ylabel("h[1]")
    axes[1].set_title("first two identity modes")
    axes[1].legend()
    axes[2].hist(spread_mm, bins=20)
    axes[2].set_title("RMS distance of each neutral S to the template (mm)")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _plot_displacements(tables: dict[str, list[dict]], path: Path) -> None:
    fig, ax = plt.subplots(figsize=(14, 5))
    names = [r["region"] for r in next(iter(tables.values()))]
    width = 0.8 / max(1, len(tables))
    for j, (kind, rows) in enumerate(tables.items()):
        x = np.arange(len(rows)) + j * width
        ax.bar(x, [r["mean"] for r in rows], width, label=f"{kind} mean")
        ax.scatter(x, [r["p99"] for r in rows], marker="_", s=200, color="k")
    ax.set_xticks(np.arange(len(names)) + 0.4 - width / 2, names, rotation=30)
    ax.set_ylabel("|T - S| (mm); dash: 99th percentile")
    ax.set_yscale("log")
    ax.legend()
    ax.set_title("how much the physics moves S, per region")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _fmt_table(rows: list[dict]) -> list[str]:
    out = [
        "| region | vertices | mean | p50 | p90 | p99 | max |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        out.append(
            f"| {r['region']} | {r['vertices']} | {r['mean']:.3f} | {r['p50']:.2f} | "
            f"{r['p90']:.2f} | {r['p99']:.2f} | {r['max']:.2f} |"
        )
    return out


def _landmark_distances(
    template: Template, lms: SurfaceLandmarks, blend: SkinBlend, a: dict[str, np.ndarray]
) -> np.ndarray:
    """(4, n * 149) distances (m) of one sparse shard: expression motion, personalisation
    error, with noise, and noise against the simulated T."""
    neutral = template.identity_neutral(a["h"][0].astype(np.float64))[:N_SKIN]
    s = blend.targets(neutral, a["weights"])
    l_s, l_0 = lms.evaluate(s), lms.evaluate(neutral)
    l_t = lms.evaluate(s + a["offsets"].astype(np.float64))
    d = [
        l_s - l_0[None],
        a["landmarks_clean"] - l_s,
        a["landmarks"] - l_s,
        a["landmarks"] - l_t,
    ]
    return np.stack([np.linalg.norm(x, axis=-1).ravel() for x in d])


def _offset_structure_lines(
    folder: Path, kinds: list[str], params: ParameterSet, max_error: float
) -> list[str]:
    rows = []
    for kind in kinds:
        if kind == "dynamic":
            continue
        o = offset_structure(folder, kind, params, max_error)
        if o is None:
            continue
        linear = "–" if o.test_linear_in_p_mm is None else f"{o.test_linear_in_p_mm:.3f}"
        rows.append(
            f"| {kind} | {o.train_groups} / {o.test_groups} | {o.frames_per_group:.1f} | "
            f"{o.no_correction_mm:.3f} | "
            f"{o.expression_part_mm:.3f} | {100 * o.shared_share:.0f} % | "
            f"{o.test_no_correction_mm:.3f} | {linear} |"
        )
    if not rows:
        return []
    return [
        "## How much of |T - S| depends on the expression",
        "",
        "The frames of one (identity, p) group share an offset that does not depend on the "
        "expression (their mean T - S_t); a network has to predict it from p and h alone, on "
        "parameter sets it never saw. Expression part: |T - S_t - the group's mean|. Linear in "
        f"p: ridge (lambda {RIDGE} x groups) from the normalised p to the shared offset, fitted "
        "on the train groups, applied to the test groups' frames (data/offset_structure.py). "
        "Mean per-vertex distances in mm, frames within 3x the tolerance. With few frames "
        "per group the group's mean also absorbs part of the expression's effect, so the "
        "shared share reads high there.",
        "",
        "| kind | groups train / test | frames per group | \\|T - S\\| | expression part | "
        "shared share | test: no correction | test: linear in p |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
        *rows,
        "",
    ]


def _sanity_line(summary: dict) -> str:
    """Frames failing the physics sanity bounds (docs/physics.md), per reason."""
    judged, failures = summary.get("frames_judged"), summary.get("failures")
    if not judged or failures is None:
        return "Sanity bounds: not judged (generated before the bounds were checked)."
    reasons = ", ".join(f"{k} {v}" for k, v in failures.items() if v and k != "failed_frames")
    tets = _tet_sources(summary.get("tet_sources") or {})
    return (
        f"Sanity bounds: {failures.get('failed_frames', 0)} of {judged} judged frames fail "
        f"(failed fraction {summary.get('failed_fraction')}; {reasons or 'no reason'}); "
        "per frame in the shards' `failures` bit mask."
        + (f" Shards by the source of their head's tets: {tets}." if tets else "")
    )


_NUMBER = re.compile(r"-?\d+(?:\.\d+)?")


def _tet_sources(sources: dict[str, int]) -> str:
    """The manifest's shard counts per tet source, one entry per kind of source: a reason that
    differs between heads only in its figure ("S up to 1.48 mm outside") is counted once, with
    the span of its figures."""
    groups: dict[str, tuple[int, list[float]]] = {}
    for reason, count in sources.items():
        key = _NUMBER.sub("#", reason)
        n, figures = groups.get(key, (0, []))
        groups[key] = (n + count, figures + [float(x) for x in _NUMBER.findall(reason)])
    out = []
    for key, (n, figures) in groups.items():
        if figures and key.count("#") == 1:
            lo, hi = min(figures), max(figures)
            span = f"{lo:g}" if lo == hi else f"{lo:g}-{hi:g}"
            key = key.replace("#", span)
        out.append(f"{key}: {n}")
    return "; ".join(out)


@dataclass
class _Stats:
    """Everything the report reads from the shards, gathered in one pass."""

    disp: dict[str, Displacements]
    kept: dict[str, Displacements]  # the frames the loader yields by default
    p_norm: dict[str, list[np.ndarray]] = field(default_factory=dict)
    conv: dict[str, list[np.ndarray]] = field(default_factory=dict)
    its: dict[str, list[np.ndarray]] = field(default_factory=dict)
    errs: dict[str, list[np.ndarray]] = field(default_factory=dict)
    drivers: dict[str, list[tuple[np.ndarray, np.ndarray, np.ndarray]]] = field(
        default_factory=dict
    )
    weights: list[np.ndarray] = field(default_factory=list)
    h_rows: list[np.ndarray] = field(default_factory=list)
    h_split: list[int] = field(default_factory=list)
    h_seen: set[int] = field(default_factory=set)
    landmark_stats: list[np.ndarray] = field(default_factory=list)

    @property
    def kinds(self) -> list[str]:
        return [k for k in KINDS if self.disp[k].frames]

    def add_identities(self, a: dict) -> None:
        ids = [(a["identity_id"], a["h"])]
        if "donor_id" in a:
            ids.append((a["donor_id"], a["donor_h"]))
        for id_col, h_col in ids:
            for i, hid in enumerate(id_col):
                if int(hid) not in self.h_seen:
                    self.h_seen.add(int(hid))
                    self.h_rows.append(h_col[i])
                    self.h_split.append(int(a["split"][i]))


def _collect(folder: Path, template: Template, params: ParameterSet, tol: float) -> _Stats:
    """Stream every shard once into the report's statistics."""
    labels = region_labels(template)
    lms, blend = template_landmarks(template), SkinBlend.of(template)
    st = _Stats(
        disp={k: Displacements(labels) for k in KINDS},
        kept={k: Displacements(labels) for k in KINDS},
    )
    for kind in KINDS:
        st.drivers[kind] = []
        st.p_norm[kind], st.conv[kind], st.its[kind], st.errs[kind] = [], [], [], []
        for a in iter_shards(folder, kind):
            st.disp[kind].add(a["offsets"])
            n = len(a["p"])
            ok = (a["estimated_error"].reshape(n, -1) <= 3 * tol).all(axis=1)
            st.kept[kind].add(a["offsets"][ok])
            worst = np.abs(a["offsets"].reshape(n, -1)).max(axis=1).astype(np.float64)
            err = a["estimated_error"].reshape(n, -1).max(axis=1).astype(np.float64)
            st.drivers[kind].append((np.asarray(params.normalise(a["p"])), err, worst))
            if kind == "sparse":
                st.landmark_stats.append(_landmark_distances(template, lms, blend, a))
            st.p_norm[kind].append(np.asarray(params.normalise(a["p"])))
            st.weights.append(a["weights"].reshape(-1, 52))
            st.conv[kind].append(a["converged"].ravel())
            st.its[kind].append(a["iterations"].ravel())
            st.errs[kind].append(a["estimated_error"].ravel())
            st.add_identities(a)
    return st


def _identity_spread(template: Template, h: np.ndarray) -> np.ndarray:
    """RMS distance (mm) of each identity's neutral skin to the template's."""
    ref = template.neutral[:N_SKIN]
    return np.array(
        [
            np.sqrt(
                ((template.identity_neutral(x.astype(np.float64))[:N_SKIN] - ref) ** 2)
                .sum(axis=1)
                .mean()
            )
            * 1e3
            for x in h
        ]
    )


def _of(made: int, planned: int) -> str:
    return f"{made}" if made == planned else f"{made} of {planned}"


def _overview_lines(folder: Path, manifest: dict, st: _Stats) -> list[str]:
    """Title, configuration, contents table, splits, storage and solver summary."""
    cfg = manifest["header"]["config"]
    summary = summarise(manifest)  # from the shards: right also while a dataset is being made
    ds = manifest["dataset"]
    lines = [
        f"# Dataset report: {folder.name}",
        "",
        f"Generated by `python -m softdeca_train generate` ({manifest['runs'][-1]['code_version']}"
        f" at the last run); LHM level {cfg['level']}, collisions "
        f"{'on' if cfg['collisions'] else 'off'}, solver tolerance {cfg['tolerance']:g}.",
        "",
        _sanity_line(summary),
        "",
        "## Contents",
        "",
        "Made of planned (the plan's count where they differ: a dataset still being made).",
        "",
        "| kind | shards | train | test | frames per instance | bytes per instance |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for k in KINDS:
        kd, sk = ds["kinds"][k], summary["kinds"][k]
        made = [
            _of(sk["shards"], kd["shards"]),
            _of(sk["train"], kd["instances"]["train"]),
            _of(sk["test"], kd["instances"]["test"]),
        ]
        lines.append(
            f"| {k} | {' | '.join(made)} | {kd['frames_per_instance']} "
            f"| {sk['bytes_per_instance']} |"
        )
    sp = ds["splits"]
    lines += [
        "",
        f"Identities: {len(sp['train']['identities'])} train, {len(sp['test']['identities'])} "
        f"test (sparse donors included); parameter sets: {sp['train']['parameter_sets']} train, "
        f"{sp['test']['parameter_sets']} test; takes: train {', '.join(sp['train']['takes'])}; "
        f"test {', '.join(sp['test']['takes'])}; coverage draws: "
        f"{sp['train']['coverage_draws']} train, {sp['test']['coverage_draws']} test.",
        "",
        f"Storage: {summary.get('bytes', 0) / 1e6:.1f} MB; offsets T - S_t as float16: "
        f"rounding error RMS {summary.get('rms_quantisation_error_mm')} mm, largest "
        f"{summary.get('max_quantisation_error_mm')} mm (float16 keeps 11 significant bits: "
        f"the largest error sits on the largest offset, {summary.get('max_offset_mm')} mm).",
        "",
        f"Solver (tolerance {cfg['tolerance']:g}, at most {cfg['max_iterations']} iterations; "
        "estimated error = estimated RMS distance to the fixed point / bounding-box diagonal; "
        "the loader skips frames above 3x the tolerance by default): "
        + "; ".join(
            f"{k} {100 * np.concatenate(st.conv[k]).mean():.1f} % converged, "
            f"{100 * (np.concatenate(st.errs[k]) <= 3 * cfg['tolerance']).mean():.1f} % within "
            f"3x, median {np.median(np.concatenate(st.its[k])):.0f} iterations, estimated error "
            f"median {np.median(np.concatenate(st.errs[k])):.1e} / p99 "
            f"{np.percentile(np.concatenate(st.errs[k]), 99):.1e}"
            for k in st.kinds
        )
        + ".",
        "",
    ]
    return lines


def _displacement_lines(st: _Stats, tables: dict, tables_all: dict) -> list[str]:
    """|T - S| per region: the kept frames, then all frames."""
    lines = [
        "## How much the physics moves S: |T - S| in mm",
        "",
        "Per vertex and frame (dynamic: all sequence frames). Regions: template/regions.py. "
        "This is the yardstick for the networks' errors.",
        "",
    ]
    for k in tables:
        lines += [
            f"### {k}: {st.kept[k].frames} of {st.disp[k].frames} frames (estimated error "
            "<= 3x tol)",
            "",
            *_fmt_table(tables[k]),
            "",
        ]
    lines += ["All frames, including those the solver left above 3x the tolerance:", ""]
    for k in st.kinds:
        lines += [f"### {k}, all {st.disp[k].frames} frames", "", *_fmt_table(tables_all[k]), ""]
    return lines


def _driver_lines(st: _Stats, params: ParameterSet) -> list[str]:
    """The parameters most correlated with large offsets and with solver error."""
    lines = [
        "## What drives |T - S| and slow convergence",
        "",
        "Correlation (over instances) of each normalised parameter with log(largest |T - S| "
        "of the instance) and with log(solver's estimated error); the three strongest each way:",
        "",
        "| kind | largest offset grows with | shrinks with | error grows with | shrinks with |",
        "| --- | --- | --- | --- | --- |",
    ]
    for k in st.kinds:
        pn_k = np.concatenate([d[0] for d in st.drivers[k]])
        cols = []
        for y in (
            np.concatenate([d[2] for d in st.drivers[k]]),
            np.concatenate([d[1] for d in st.drivers[k]]),
        ):
            ly = np.log(np.maximum(y, 1e-12))
            c = [
                (float(np.corrcoef(pn_k[:, j], ly)[0, 1]), params.names[j])
                for j in range(pn_k.shape[1])
                if pn_k[:, j].std() > 0 and ly.std() > 0
            ]
            c.sort()
            cols.append(", ".join(f"{n} {v:+.2f}" for v, n in reversed(c[-3:])))
            cols.append(", ".join(f"{n} {v:+.2f}" for v, n in c[:3]))
        lines.append(f"| {k} | " + " | ".join(cols) + " |")
    lines.append("")
    return lines


def _landmark_lines(st: _Stats) -> list[str]:
    """Distances between the sparse kind's landmark sets."""
    if not st.landmark_stats:
        return []
    ls = np.concatenate(st.landmark_stats, axis=1) * 1e3
    names = (  # pipes escaped: these sit in a markdown table
        "expression motion of the landmarks on S (\\|L(S_t) - L(S_0)\\|)",
        "personalised donor landmarks vs the head's own (\\|L_clean - L(S_t)\\|)",
        "noisy landmarks vs the head's own (\\|L - L(S_t)\\|)",
        "noisy landmarks vs the simulated result (\\|L - L(T)\\|)",
    )
    return [
        "### Sparse landmarks (mm, per landmark and frame)",
        "",
        "| distance | mean | p50 | p95 | max |",
        "| --- | ---: | ---: | ---: | ---: |",
        *(
            f"| {name} | {row.mean():.2f} | {np.median(row):.2f} | "
            f"{np.percentile(row, 95):.2f} | {row.max():.2f} |"
            for name, row in zip(names, ls, strict=True)
        ),
        "",
    ]


def _distribution_lines(n_identities: int, spread: np.ndarray) -> list[str]:
    return [
        "![displacement](displacement.png)",
        "",
        "## Distributions",
        "",
        "Parameters on their sampling scale against the uniform target (Appendix A):",
        "",
        "![parameters](parameters.png)",
        "",
        "ARKit weights of all frames against the target mix (real train takes and coverage):",
        "",
        "![weights](weights.png)",
        "",
        f"Identities ({n_identities}): coefficients against N(0, 1) (the sampler keeps only "
        "plausible heads, so the tails are thinner), first two modes by split, and the spread "
        f"of the neutral heads (RMS distance to the template: median {np.median(spread):.1f} mm).",
        "",
        "![identities](identities.png)",
        "",
    ]


def write_report(
    folder: Path, out: Path, ict: str | None = None, takes_dir: Path | None = None
) -> Path:
    folder, out = Path(folder), Path(out)
    manifest = json.loads((folder / "manifest.json").read_text())
    template = Template.load(ict)
    params = dataset_parameters(manifest)
    out.mkdir(parents=True, exist_ok=True)
    tol = manifest["header"]["config"]["tolerance"]
    st = _collect(folder, template, params, tol)
    kinds = st.kinds
    tables = {k: st.kept[k].table() for k in kinds if st.kept[k].frames}
    tables_all = {k: st.disp[k].table() for k in kinds}
    h = np.stack(st.h_rows)
    spread = _identity_spread(template, h)
    takes_dir = takes_dir or paths.default_recordings_path()
    pn = {k: np.concatenate(st.p_norm[k]) for k in kinds}
    _plot_parameters(pn, manifest, out / "parameters.png")
    w = np.concatenate(st.weights)
    _plot_weights(w, _target_weights(manifest, takes_dir), out / "weights.png")
    _plot_identities(h, np.array(st.h_split), spread, out / "identities.png")
    _plot_displacements(tables, out / "displacement.png")

    lines = _overview_lines(folder, manifest, st)
    lines += _displacement_lines(st, tables, tables_all)
    lines += _driver_lines(st, params)
    lines += _offset_structure_lines(folder, kinds, params, 3 * tol)
    lines += _landmark_lines(st)
    lines += _distribution_lines(len(h), spread)
    (out / "report.md").write_text("\n".join(lines))
    (out / "displacement.json").write_text(
        json.dumps({"kept": tables, "all": tables_all}, indent=1) + "\n"
    )
    return out / "report.md"
