"""`evaluate`: the evaluation report of a training run and its bundle (markdown + PNG plots +
per-vertex error heat maps), the Table 1 and Table 2 analogues of the paper, and the figures
of build/bench/models.json. The bundle's own rows run the exported ONNX networks end to end
as a host would: identity estimated by the bundle's encoder, ONNX hypernetworks, DT.

Kept whole: every section is written from the one set of measured errors."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import torch
from tqdm import tqdm

from softdeca_train.bench import write_area
from softdeca_train.data.config import GenerateConfig
from softdeca_train.models.bundle import OnnxNetworks, read_manifest
from softdeca_train.models.reference import ReferenceAvatar
from softdeca_train.render import MeshLayer, RenderSettings, render, tile
from softdeca_train.template.model import N_SKIN
from softdeca_train.train.batches import EVERY_FRAME
from softdeca_train.train.evaluate import (
    SPARSE_INPUTS,
    ErrorSum,
    GroupOffsetOracle,
    _AsDynamic,
    _test_takes,
    measure,
    no_correction,
    time_per_frame,
)
from softdeca_train.train.localisation import localisation_figure
from softdeca_train.train.registry import MODELS
from softdeca_train.train.run import Run
from softdeca_train.train.trainable import (
    NoCorrection,
    SparseSoftDeca,
    Trainable,
    vertex_error,
)

TABLE1 = (
    ("no correction (S_t)", "no-correction"),
    ("SoftDECA", "softdeca"),
    ("SoftDECA, DT only (the paper's design)", "softdeca-dt"),
    ("SoftDECA, vertex positions", "softdeca-vertex"),
    ("MLP, equal time (SoftSMPL-style)", "mlp-equal-time"),
    ("MLP, large (SoftSMPL-style)", "mlp-large"),
    ("face-wise MLP", "face-mlp"),
)
DYNAMIC = (
    ("no correction (S_t)", "no-correction"),
    ("SoftDECA without dynamics", "softdeca"),
    ("SoftDECA + per-vertex dynamics (eq. 21)", "softdeca-dynamics"),
    ("SNP-style latent dynamics", "snp-dynamics"),
)


def _trained(run: Run) -> dict[str, Trainable]:
    out: dict[str, Trainable] = {}
    for name in MODELS:
        if run.finished(name):  # an interrupted training is not evaluated
            out[name] = run.load(name)
    return out


def _bundle_errors(
    run: Run, bundle: Path, progress: bool, models: tuple[str, ...] = ("softdeca", "sparse")
) -> dict[str, dict]:
    """SoftDECA static and SparseSoftDECA (other head, noisy) through the bundle's ONNX
    networks with the identity its encoder estimates from each test head's neutral, and each
    group's parameters: p, and per skin vertex its regional pattern where it has one."""
    nets = OnnxNetworks(bundle)
    d = run.definition
    t = run.template
    tris = t.triangles
    acc = {m: ErrorSum() for m in models}
    take = _test_takes(run)
    avatars: dict[tuple[int, int], ReferenceAvatar] = {}
    kinds = {"softdeca": "static", "sparse": "sparse"}
    for kind, model in ((kinds[m], m) for m in models):
        batches = list(run.blend_data.batches(kind, "test", None, 8, EVERY_FRAME))
        for b in tqdm(batches, desc=f"bundle {model}", disable=not progress):
            key = (b.identity_id, b.param_id)
            if key not in avatars:
                h = b.h[0].double().numpy()
                neutral = t.identity_neutral(h)
                # the physics at prepare acts on SoftDECA only: the sparse frames skip it
                av = ReferenceAvatar(
                    nets,
                    d,
                    neutral,
                    tris if tris is not None else d.skin_triangles,
                    rest_physics=model == "softdeca",
                )
                for k, s in enumerate(nets.specs):
                    av.params.set_global(s.name, float(b.p[0, k]))
                    if b.p_vertices is not None and s.localisable:
                        # the group's regional pattern, as the physics and training had it
                        av.params.set_vertices(s.name, b.p_vertices[:, k].double().numpy())
                av.prepare()
                avatars = {key: av}  # one at a time: memory
            av = avatars[key]
            outs = []
            for f in range(b.frames):
                if model == "softdeca":
                    x = av.softdeca_static(b.weights[f].numpy(), b.S[f].double().numpy())
                else:
                    assert b.landmarks is not None
                    x = av.sparse_static(b.landmarks[f].double().numpy())
                outs.append(x)
            x = torch.from_numpy(np.stack(outs)).float()
            acc[model].add(vertex_error(x, b.T), b.source_take, take)
    return {k: v.summary() for k, v in acc.items()}


def _curves(run: Run, names: list[str], path: Path) -> None:
    fig, ax = plt.subplots(figsize=(9, 5))
    for name in names:
        log = run.folder / f"{name}.log.jsonl"
        if not log.is_file():
            continue
        rows = [json.loads(line) for line in log.read_text().splitlines() if line.strip()]
        if not rows:  # a closed-form model kept at its start (0 steps) has no curve
            continue
        s = np.array([r["s"] for r in rows]) / 60
        e = np.array([r["error_mm"] for r in rows])
        k = max(1, len(e) // 100)
        smooth = np.convolve(e, np.ones(k) / k, mode="valid")
        ax.plot(s[k - 1 :], smooth, label=name)
    ax.set_xlabel("training minutes (this machine)")
    ax.set_ylabel("training error, mm (moving mean)")
    ax.set_yscale("log")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _heatmaps(run: Run, maps: dict[str, np.ndarray], path: Path, vmax: float) -> None:
    t = run.template
    neutral = t.neutral[:N_SKIN]
    images, labels = [], []
    for label, values in maps.items():
        for view in ("front", "three_quarter"):
            layer = MeshLayer(
                neutral,
                t.skin_triangles,
                scalars=values,
                clim=(0.0, vmax),
                scalar_bar="mm" if view == "three_quarter" else None,
            )
            images.append(render([layer], view, settings=RenderSettings(size=(420, 420))))
            labels.append(f"{label} ({view.replace('_', ' ')})")
    tile(images, labels, path)


def _training(run: Run, name: str) -> str:
    """Steps and minutes a model of the run trained for (its summary), or "–"."""
    path = run.folder / f"{name}.summary.json"
    if not path.is_file():
        return "–"
    s = json.loads(path.read_text())
    if s["steps"] == 0:
        return "closed-form start, no steps"
    return f"{s['steps']:,} steps, {s['minutes']:.0f} min"


def _measured(r: dict | None, key: str = "mean_mm") -> bool:
    return r is not None and r.get(key) is not None


def _row(r: dict | None, key: str = "mean_mm") -> str:
    return f"{r[key]:.3f}" if r is not None and _measured(r, key) else "–"


def write_report(
    run: Run, bundle: Path, out: Path, bench: Path | None = None, progress: bool = True
) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    models = _trained(run)
    if "softdeca" not in models:
        raise ValueError(f"{run.folder} has no trained softdeca model")
    errors: dict[str, dict] = {}
    maps: dict[str, np.ndarray] = {}
    static_models = {"no-correction": NoCorrection(), **models}
    for name, m in tqdm(static_models.items(), desc="test errors", disable=not progress):
        if isinstance(m, SparseSoftDeca):
            for which in SPARSE_INPUTS:
                errors[f"{name}/{which}"] = measure(run, name, m, which).summary()
        elif m.kind == "static":
            acc = measure(run, name, m)
            errors[name] = acc.summary()
            vertex_mm = acc.vertex_mm()
            if vertex_mm is not None:
                maps[name] = vertex_mm
            if name == "softdeca":
                errors["softdeca/dynamic"] = measure(run, name, _AsDynamic(m)).summary()
        else:
            errors[name] = measure(run, name, m).summary()

    errors["no-correction/dynamic"] = measure(run, "nc", no_correction("dynamic")).summary()
    oracle = measure(run, "oracle", GroupOffsetOracle())
    errors["group-offset-oracle"] = oracle.summary()
    if oracle.vertex_mm() is not None:
        maps["group-offset-oracle"] = oracle.vertex_mm()
    # the generalisation gap: the same models on the frames they trained on
    gap = [n for n in ("no-correction", "softdeca", "mlp-equal-time") if n in static_models]
    for name in tqdm(gap, desc="train-split errors", disable=not progress):
        errors[f"{name}/train"] = measure(run, name, static_models[name], split="train").summary()
    batch = next(run.data.batches("static", "test", None, 8))
    times = {}
    for name, m in tqdm(static_models.items(), desc="timings", disable=not progress):
        if m.kind in ("static", "sparse"):
            b = batch if m.kind == "static" else next(run.data.batches("sparse", "test", None, 8))
            times[name] = time_per_frame(m, b)
    bundle_rows = _bundle_errors(run, bundle, progress) if bundle.is_dir() else {}
    _curves(run, list(models), out / "training_curves.png")
    vmax = float(np.percentile(maps["no-correction"], 98))
    shown = {
        k: maps[k]
        for k in ("no-correction", "softdeca", "mlp-equal-time", "group-offset-oracle")
        if k in maps
    }
    _heatmaps(
        run, {f"{k}: mean error": v for k, v in shown.items()}, out / "error_heatmaps.png", vmax
    )

    local = localisation_figure(run, models["softdeca"], out / "localisation.png")
    left_out = left_out_counts(run)
    result = {
        "errors": errors,
        "ms_per_frame": times,
        "bundle": bundle_rows,
        "localisation": local,
        "left_out_by_solver_error": left_out,
    }
    (out / "evaluation.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "README.md").write_text(_markdown(run, bundle, result))
    if bench is not None:
        _write_bench(bench, result, run, bool(_carried(bundle)))
    return out / "README.md"


def left_out_counts(run: Run) -> dict[str, dict[str, int]]:
    """Frames training leaves out because the volumetric solver's estimated error is above 3x
    the dataset's tolerance or the frame fails a sanity bound, per kind, and of each dataset
    whose static train frames SoftDECA's start also reads; the evaluation reads every test
    frame."""
    out = {
        f"{kind}/train": run.data.left_out(kind, "train")
        for kind in ("static", "sparse", "dynamic")
    }
    for extra in run.more_static:
        out[f"static/train of {extra.folder.name}"] = extra.left_out("static", "train")
    return out


def _left_out_line(left: dict[str, dict[str, int]]) -> str:
    """Frames training leaves out for the volumetric solver's error or a failed sanity bound
    (evaluation: none)."""
    if not left:
        return "Frames left out for the solver's estimated error: not counted."

    def total(v: dict[str, int]) -> int:
        return v["kept"] + v["left_out"] + v.get("failed_bounds", 0) + v.get("no_rest_physics", 0)

    parts = [f"{k} {v['left_out']} of {total(v)}" for k, v in left.items()]
    failed = [f"{k} {v.get('failed_bounds', 0)}" for k, v in left.items()]
    unrested = [f"{k} {v['no_rest_physics']}" for k, v in left.items() if "no_rest_physics" in v]
    return (
        "The evaluation reads every test frame. Frames left out of training because the "
        "volumetric solver's estimated error exceeds 3x the dataset's tolerance: "
        f"{', '.join(parts)}; because they fail a sanity bound (docs/physics.md): "
        f"{', '.join(failed)}"
        + (
            "; because the physics at prepare refuses their head (also out of the evaluation "
            f"on S_t + Pd): {', '.join(unrested)}"
            if unrested
            else ""
        )
        + "."
    )


def _held_out_takes(cfg: dict) -> str:
    names = GenerateConfig.from_dict(cfg).test_takes
    return ", ".join(f"`{n}`" for n in names)


def _more_static_clause(run: Run) -> str:
    """Where SoftDECA's start also read static frames of other datasets (--more-static)."""
    names = [f"`{Path(d).name}`" for d in run.config.more_static]
    if not names:
        return ""
    return f", SoftDECA's start also on the static train frames of {', '.join(names)}"


def _markdown(run: Run, bundle: Path, r: dict) -> str:
    e, ms = r["errors"], r["ms_per_frame"]
    m = run.data.manifest
    cfg = m["header"]["config"]
    lines = [
        "# Evaluation: SoftDECA and SparseSoftDECA against the physics",
        "",
        f"Run `{run.folder}` on dataset `{Path(run.config.dataset).name}` (LHM level "
        f"{cfg['level']}, {cfg['static']} static frames, {cfg['dynamic']} dynamic sequences, "
        f"{cfg['sparse']} sparse frames; range profile `{cfg.get('ranges', 'appendix-a')}`)"
        f"{_more_static_clause(run)}; "
        f"bundle `{bundle}`. Errors: mean per-vertex Euclidean distance to the simulated skin "
        "T over all skin vertices of S, in mm, on the test split (identities, parameter sets "
        "and expression frames unseen in training: the held-out takes "
        f"{_held_out_takes(cfg)} and "
        "test coverage draws). Times: median per-frame work, torch, 1 thread, batch 1, "
        "per-avatar parts prepared; the native runtime's figures are in docs/benchmarks.md.",
        "",
        "Reproduce: `python -m softdeca_train evaluate --run "
        f"{run.folder} --bundle {bundle}` (see docs/training.md for the training commands).",
        "",
        _left_out_line(r.get("left_out_by_solver_error", {})),
        "",
        "## Table 1 analogue: static frames",
        "",
        "| model | mean (mm) | held-out take (mm) | coverage (mm) | ms/frame | training |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    nc_label = _no_correction_label(run)
    for label, key in TABLE1:
        if key in e:
            t = f"{ms[key]:.2f}" if key in ms else "–"
            label = nc_label if key == "no-correction" else label
            lines.append(
                f"| {label} | {_row(e[key])} | {_row(e[key], 'real_take_mm')} | "
                f"{_row(e[key], 'coverage_mm')} | {t} | {_training(run, key)} |"
            )
    if r["bundle"]:
        b = r["bundle"]["softdeca"]
        lines.append(
            f"| SoftDECA, the bundle end to end (ONNX, encoder's h) | {_row(b)} | "
            f"{_row(b, 'real_take_mm')} | {_row(b, 'coverage_mm')} | – |"
        )
    missing = [label for label, key in TABLE1 if key not in e]
    if missing:
        lines += [
            "",
            "Not trained in this run (no finished checkpoint): " + "; ".join(missing) + ".",
        ]
    lines += _where_the_error_is(e, nc_label)
    lines += [
        "",
        "## Dynamic sequences",
        "",
        "| model | mean (mm) | held-out take (mm) | coverage (mm) | training |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    dynamic = {"no-correction": "no-correction/dynamic", "softdeca": "softdeca/dynamic"}
    rows = [(label, key, dynamic.get(key, key)) for label, key in DYNAMIC]
    rows = [(label, key, k) for label, key, k in rows if _measured(e.get(k))]
    for label, key, k in rows:
        label = nc_label if key == "no-correction" else label
        lines.append(
            f"| {label} | {_row(e[k])} | {_row(e[k], 'real_take_mm')} | "
            f"{_row(e[k], 'coverage_mm')} | {_training(run, key)} |"
        )
    if not rows:
        lines[-2:] = [NOTHING_MEASURED.format(kind="dynamic test sequence", model="dynamics")]
    lines += sparse_section(
        run, e, r["bundle"].get("sparse") if r["bundle"] else None, _carried(bundle)
    )
    loc = r["localisation"]
    lines += [
        "",
        "## Localisation (eq. 20)",
        "",
        f"{loc['change']} ({loc['faces_changed']} faces) on a test identity and frame, the "
        "rest of p as sampled for it; the displacement the change causes, physics (the same "
        "value on the soft-tissue tets in the ball) next to SoftDECA (per-face and per-vertex "
        f"parameter maps into its hypernetworks). Mean displacement inside the ball: physics "
        f"{loc['physics_mean_in_region_mm']:.3f} mm, SoftDECA "
        f"{loc['softdeca_mean_in_region_mm']:.3f} mm; largest: physics "
        f"{loc['physics_max_mm']:.2f} mm, SoftDECA {loc['softdeca_max_mm']:.2f} mm.",
        "",
        "![localisation](localisation.png)",
        "",
        "## Pictures",
        "",
        "![training curves](training_curves.png)",
        "",
        "Per-vertex mean test error on the template's neutral (same colour scale):",
        "",
        "![error heat maps](error_heatmaps.png)",
        "",
    ]
    return "\n".join(lines)


SPARSE_ROWS = (
    ("sparse", "with noise augmentation"),
    ("sparse-code-noise", "the same on a perturbed identity code"),
    ("sparse-no-noise", "without"),
)
SPARSE_HEADING = "## Table 2 analogue: SparseSoftDECA"


def _carried(bundle: Path) -> dict[str, str]:
    """The bundle's SparseSoftDECA networks that another bundle made (bundle-carry), with
    the dataset each was trained on; empty when the bundle's own training made them."""
    if not (bundle / "manifest.json").is_file():
        return {}
    out: dict[str, str] = {}
    for r in (read_manifest(bundle).get("training") or {}).get("replaced", []):
        for name in r["networks"]:
            if name.startswith("sparse."):
                if "carried_from" in r:
                    out[name] = r.get("origins", {}).get(name, "another bundle")
                else:
                    out.pop(name, None)
    return out


def sparse_section(
    run: Run, e: dict, bundle_sparse: dict | None, carried: dict[str, str] | None = None
) -> list[str]:
    """The report's Table 2: SparseSoftDECA's models of the run on its test split; with
    `carried` (_carried), a note that the bundle's networks are not the run's."""
    cfg = run.data.manifest["header"]["config"]
    lines = [
        "",
        SPARSE_HEADING,
        "",
        f"Run `{run.folder}` on dataset `{Path(run.config.dataset).name}` ({cfg['sparse']} "
        "sparse frames, its test split). Inputs: the simulated head's own landmarks on S_t "
        "(same head); another head's expression personalised to this head (other head); the "
        f"same with the augmentation's coordinate noise (sigma {cfg['landmark_noise_mm']} mm); "
        "ARKit's reference face making the expression with its own shapes, personalised to "
        "this head as the runtime calibrates a phone's face (ARKit face).",
        "",
        "| trained | same head | other head | other head + noise | ARKit face | training |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    measured = False
    for name, label in SPARSE_ROWS:
        if _measured(e.get(f"{name}/same_head")):
            cells = " | ".join(_row(e[f"{name}/{w}"]) for w in SPARSE_INPUTS)
            lines.append(f"| {label} | {cells} | {_training(run, name)} |")
            measured = True
    if _measured(bundle_sparse):
        lines.append(
            f"| the bundle end to end (ONNX, encoder's h) | – | – | {_row(bundle_sparse)} | – | – |"
        )
        measured = True
    if not measured:
        lines[-2:] = [NOTHING_MEASURED.format(kind="sparse test frame", model="SparseSoftDECA")]
    if carried:
        origins = ", ".join(f"`{k}` ({v})" for k, v in sorted(carried.items()))
        measures = " The bundle row measures them on this run's test split." if measured else ""
        lines += [
            "",
            "The bundle's SparseSoftDECA is not this run's: its networks were carried as they "
            f"are from another bundle (`bundle-carry`; trained on: {origins}; the manifest's "
            f"training.replaced).{measures}",
        ]
    return lines


def refresh_sparse(
    run: Run, bundle: Path, out: Path, name: str = "sparse", progress: bool = True
) -> Path:
    """Re-measure a report's SparseSoftDECA rows (evaluation.json and README.md's Table 2)
    on `run`, after its SparseSoftDECA `name` went into the bundle (bundle-sparse); the rest
    of the report stays as its own run measured it."""
    doc = json.loads((out / "evaluation.json").read_text())
    errors = {k: v for k, v in doc["errors"].items() if not k.startswith("sparse/")}
    for row, _ in SPARSE_ROWS:
        if run.finished(row):
            model = run.load(row)
            for which in SPARSE_INPUTS:
                errors[f"{row}/{which}"] = measure(run, row, model, which).summary()
    doc["errors"] = errors
    doc["bundle"] = {**doc.get("bundle", {}), **_bundle_errors(run, bundle, progress, ("sparse",))}
    batch = next(run.data.batches("sparse", "test", None, 8))
    doc["ms_per_frame"]["sparse"] = time_per_frame(run.load(name), batch)
    doc["sparse_run"] = {
        "run": str(run.folder),
        "model": name,
        "dataset": Path(run.config.dataset).name,
    }
    (out / "evaluation.json").write_text(json.dumps(doc, indent=1) + "\n")
    readme = out / "README.md"
    text = readme.read_text()
    start = text.index(SPARSE_HEADING)
    end = text.find("\n## ", start + len(SPARSE_HEADING))
    section = "\n".join(sparse_section(run, errors, doc["bundle"]["sparse"])[1:]) + "\n"
    readme.write_text(text[:start] + section + (text[end:] if end >= 0 else ""))
    return readme


def _no_correction_label(run: Run) -> str:
    """What "no correction" is: S_t, or for a run on the rest physics S_t + Pd."""
    if run.config.rest_changes:
        return "no correction (S_t + Pd: the linear blend with the physics at rest)"
    return "no correction (S_t)"


NOTHING_MEASURED = (
    "This run's dataset has no {kind} yet, so nothing is measured here; the bundle's "
    "{model} networks keep the test errors their training recorded (the manifest's "
    "`errors` and `training`)."
)


def _where_the_error_is(e: dict, nc_label: str) -> list[str]:
    """How much of the error depends on the expression at all, and the generalisation gap."""
    nc, orc = e.get("no-correction"), e.get("group-offset-oracle")
    if nc is None:
        return []
    if orc is None or orc.get("mean_mm") is None:
        reference = (
            "Every (identity, p) group of the test split has one frame, so the part of the "
            "correction shared by a group's frames (S_t plus their mean T - S_t) is not "
            "measured here."
        )
    else:
        share = 1 - orc["mean_mm"] / nc["mean_mm"]
        reference = (
            "Reference (uses the physics, not a model): S_t plus the mean of T - S_t over "
            "the frames of the same (identity, p) group, the part of the correction that "
            f"does not depend on the expression, known exactly: {_row(orc)} mm. So "
            f"{100 * share:.0f} % of the no-correction error is an offset shared by the "
            "frames of a group, which depends on p and h alone; a model has to learn it "
            "from the training parameter sets (data/offset_structure.py measures the same "
            "split on a whole dataset)."
        )
    lines = [
        "",
        "### Where the error is",
        "",
        reference,
        "",
        "| model | training frames (mm) | test frames (mm) |",
        "| --- | ---: | ---: |",
    ]
    for label, key in (
        (nc_label, "no-correction"),
        ("SoftDECA", "softdeca"),
        ("MLP, equal time", "mlp-equal-time"),
    ):
        if f"{key}/train" in e:
            lines.append(f"| {label} | {_row(e[f'{key}/train'])} | {_row(e.get(key))} |")
    return lines


def _write_bench(folder: Path, r: dict, run: Run, sparse_carried: bool = False) -> None:
    """build/bench/models.json: the shipped networks' figures. A bundle whose SparseSoftDECA
    came from another bundle ships those networks, not the run's: its sparse figure is then
    the bundle's own on this test split, and the run's figures of its own are left out."""
    e, ms = r["errors"], r["ms_per_frame"]
    how = f"python -m softdeca_train evaluate --run {run.folder} (test split, mean per-vertex mm)"
    figs = {}

    def fig(name: str, value: float | None, unit: str, target: float | None) -> None:
        if value is not None:
            figs[name] = {
                "value": value,
                "unit": unit,
                "target": target,
                "better": "lower",
                "how": how,
            }

    get = lambda k, f="mean_mm": e[k].get(f) if k in e else None  # noqa: E731
    fig("softdeca_static_mm", get("softdeca"), "mm", 0.5)
    fig("softdeca_dynamic_mm", get("softdeca-dynamics"), "mm", 1.0)
    fig("no_correction_static_mm", get("no-correction"), "mm", None)
    fig("mlp_equal_time_static_mm", get("mlp-equal-time"), "mm", None)
    if sparse_carried:
        carried = (r["bundle"] or {}).get("sparse") or {}
        fig("sparse_other_head_noise_mm", carried.get("mean_mm"), "mm", 1.5)
    else:
        fig("sparse_other_head_noise_mm", get("sparse/other_head_noise"), "mm", 1.5)
        fig("sparse_arkit_face_mm", get("sparse/arkit_face"), "mm", None)
    fig("softdeca_torch_ms_per_frame", ms.get("softdeca"), "ms", None)
    write_area(folder, "models", figs)
