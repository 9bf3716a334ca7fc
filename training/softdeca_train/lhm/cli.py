"""The layered head model stage's commands: `lhm` (fit, check, save and render one
identity's model), `demo` (the template's layers, sampled identities, landmarks), `carry-check`
(which heads the template's tet mesh is carried to, and how well) and `bench` (LHM fitting per
resolution)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument, add_tet_mesh_argument


def _bench_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("--out", default="build/bench", help="folder for <area>.json (build/bench)")
    p.add_argument("--heads", type=int, default=8, help="identities per LHM resolution (8)")


def _bench_run(args: argparse.Namespace) -> int:
    from softdeca_train.bench import report_area
    from softdeca_train.lhm.bench import bench_lhm

    report_area(Path(args.out), "lhm", bench_lhm(args.ict, heads=args.heads))
    return 0


def _lhm_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("--seed", type=int, default=None, help="identity seed (default: the template)")
    p.add_argument("--level", type=int, default=4, help="wrap resolution: icosphere level (4)")
    p.add_argument("--soft-layers", type=int, default=1, help="tet layers skin..muscle (1)")
    p.add_argument("--muscle-layers", type=int, default=1, help="tet layers muscle..skull (1)")
    add_tet_mesh_argument(p)
    p.add_argument("--out", default="out/lhm", help="output folder (out/lhm)")


def _lhm_run(args: argparse.Namespace) -> int:
    from softdeca_train.lhm import LhmConfig, check_lhm, fit_lhm
    from softdeca_train.lhm.figures import render_layers
    from softdeca_train.template import Template
    from softdeca_train.template.model import N_SKIN

    t = Template.load(args.ict)
    h = None if args.seed is None else t.sample_identity(args.seed)
    cfg = LhmConfig(
        level=args.level,
        soft_layers=args.soft_layers,
        muscle_layers=args.muscle_layers,
        tet_mesh=args.tet_mesh,
    )
    model = fit_lhm(t, h, cfg)
    checked = check_lhm(model, t.identity_neutral(h)[:N_SKIN], t.skin_triangles)
    report = checked.as_dict()
    if cfg.tet_mesh in ("carried", "conforming"):
        from softdeca_train.lhm.carried import tissue_mesh
        from softdeca_train.lhm.conforming import conforming_quality

        mesh, _ = tissue_mesh(t, h, model)
        report["tet_source"] = mesh.source
        report["conforming_quality"] = conforming_quality(model, mesh).as_dict()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    name = "template" if args.seed is None else f"seed{args.seed}"
    model.save(out / f"lhm_{name}.npz")
    (out / f"lhm_{name}_report.json").write_text(json.dumps(report, indent=2) + "\n")
    render_layers(t, model, out / f"lhm_{name}.png", head=t.identity_neutral(h))
    print(json.dumps(report, indent=2))
    problems = checked.failures()
    print("valid" if not problems else "INVALID: " + "; ".join(problems))
    print(f"wrote {out}/lhm_{name}.npz, .png and _report.json")
    return 0 if not problems else 1


def _carry_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("--level", type=int, default=3, help="wrap resolution: icosphere level (3)")
    p.add_argument("--seeds", type=int, default=40, help="sampled identities, seeds 1000.. (40)")
    p.add_argument("--out", default="out/carry-check.json", help="report (out/carry-check.json)")


def _carry_run(args: argparse.Namespace) -> int:
    import numpy as np
    from tqdm import tqdm

    from softdeca_train.lhm import LhmConfig
    from softdeca_train.lhm.carried import carry_basis, carry_quality
    from softdeca_train.template import Template
    from softdeca_train.template.identities import identity_coefficients
    from softdeca_train.template.model import N_SKIN

    t = Template.load(args.ict)
    cfg = LhmConfig(level=args.level, tet_mesh="carried")
    basis = carry_basis(t, cfg)
    labels = ["template", "h+2.5σ", "h-2.5σ"] + [f"seed {1000 + k}" for k in range(args.seeds)]
    rows = []
    for label in tqdm(labels, desc="carry-check", unit="head"):
        h = identity_coefficients(t, label)
        skin = t.identity_neutral(h)[:N_SKIN].astype(np.float64)
        q = carry_quality(basis.vertices(h), basis.mesh, skin, basis.skin_inside)
        why = q.shortfall(cfg)
        rows.append({
            "identity": label,
            "carried": not why,
            "why_not": why or None,
            "inverted": q.inverted,
            "min_dihedral_deg": round(q.min_dihedral_deg, 2),
            "max_aspect": round(q.max_aspect, 2),
            "skin_outside_mm": round(1e3 * q.skin_outside, 3),
        })  # fmt: skip
        print(f"{label:10s} {'carried' if not why else 'fill: ' + why}")
    carried = [r for r in rows if r["carried"]]
    summary = {
        "level": args.level,
        "heads": len(rows),
        "carried": len(carried),
        "carried_min_dihedral_deg": min((r["min_dihedral_deg"] for r in carried), default=None),
        "carried_max_aspect": max((r["max_aspect"] for r in carried), default=None),
        "template_fill": {"vertices": len(basis.mesh.vertices), "tets": int(
            len(basis.mesh.soft_tets) + len(basis.mesh.muscle_tets))},
    }  # fmt: skip
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"summary": summary, "heads": rows}, indent=2) + "\n")
    print(json.dumps(summary))
    print(f"wrote {out}")
    return 0


def _demo_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("--out", default="out/demo", help="output folder (out/demo)")
    p.add_argument(
        "--seeds", type=int, nargs="+", default=[1, 2, 3], help="identity seeds to show (1 2 3)"
    )


def _demo_run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from softdeca_train.landmarks.figure import render_registration
    from softdeca_train.lhm import check_lhm, fit_lhm
    from softdeca_train.lhm.figures import render_identities, render_layers
    from softdeca_train.template import Template
    from softdeca_train.template.model import N_SKIN

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    with tqdm(total=4, desc="demo", unit="figure") as bar:
        t = Template.load(args.ict)
        model = fit_lhm(t)
        written.append(render_layers(t, model, out / "template_layers.png"))
        bar.update()
        written.append(render_identities(t, list(args.seeds), out / "identities.png"))
        bar.update()
        written.append(render_registration(out))
        bar.update()
        reports = {"template": check_lhm(model, t.neutral[:N_SKIN], t.skin_triangles).as_dict()}
        for seed in args.seeds:
            h = t.sample_identity(seed)
            reports[f"seed {seed}"] = check_lhm(
                fit_lhm(t, h), t.identity_neutral(h)[:N_SKIN], t.skin_triangles
            ).as_dict()
        report_path = out / "lhm_reports.json"
        report_path.write_text(json.dumps(reports, indent=2) + "\n")
        written.append(report_path)
        bar.update()
    print("demo outputs:")
    for p in written:
        print(f"  {p.resolve()}")
    return 0


COMMANDS = [
    Command(
        "lhm",
        "Fit the layered head model of one identity, check it, save it and render it.",
        _lhm_args,
        _lhm_run,
    ),
    Command(
        "carry-check",
        "Which heads the template's tet mesh is carried to (docs/physics.md), and how well.",
        _carry_args,
        _carry_run,
    ),
    Command(
        "demo",
        "The demo: renders of the template's layers, sampled identities, landmarks.",
        _demo_args,
        _demo_run,
    ),
    Command(
        "bench",
        "Benchmark the pipeline (LHM fitting per resolution) into build/bench/<area>.json.",
        _bench_args,
        _bench_run,
    ),
]
