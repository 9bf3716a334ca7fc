"""Command lines of the training: `train-bundle` (every bundle network, then the bundle),
`bundle-sparse` (a retrained SparseSoftDECA into a bundle), `bundle-softdeca` (a retrained
SoftDECA into a bundle), `bundle-carry` (one model's
networks as they are from another bundle), `train-model` (one model of the
registry, e.g. a baseline), `evaluate` (the report), `linear-baseline` (closed-form linear
fits of the data)."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from softdeca_train.commands import Command
from softdeca_train.paths import REPO_ROOT
from softdeca_train.train.registry import MODELS

DEFAULT_RUN = "out/train/default"
DEFAULT_BUNDLE = "models/softdeca-default"


def _run_args(p: argparse.ArgumentParser, dataset_required: bool = True) -> None:
    p.add_argument("--run", default=DEFAULT_RUN, help=f"training run folder ({DEFAULT_RUN})")
    p.add_argument(
        "--dataset",
        required=False,
        help="generated dataset folder (needed when the run folder is new)",
    )
    p.add_argument(
        "--contrasts",
        default=None,
        help="a dataset generated with --contrasts: SoftDECA's residual stage also fits its "
        "frames and their pairs (with --dataset, when the run folder is new)",
    )
    p.add_argument(
        "--more-static",
        action="append",
        default=[],
        metavar="DATASET",
        help="a dataset generated like --dataset (another seed) whose static train frames "
        "join SoftDECA's closed-form start and residual stage; repeatable (with --dataset, "
        "when the run folder is new)",
    )
    p.add_argument("--sizes", choices=["full", "test"], default="full", help="network sizes")
    p.add_argument(
        "--rest-gate",
        default="0",
        help="SoftDECA at rest: 0, exact (its correction g(w) - g(0)); TAU > 0, exact with the "
        "part independent of w gated by |w|^2 / (|w|^2 + TAU^2); 'none', the form of the "
        "bundles trained before (a constant part) (0; with --dataset, when the run is new)",
    )
    p.add_argument(
        "--residual-members",
        type=int,
        default=None,
        help="members of SoftDECA's residual stage (default: the sizes' own, 5 at full size; "
        "each costs the frame its weights; with --dataset, when the run is new)",
    )
    p.add_argument(
        "--rest-changes",
        action="store_true",
        help="SoftDECA learns the correction on top of the rest physics, which the runtime adds "
        "whole at prepare (the dataset's rest changes: python -m softdeca_train rest-changes; "
        "with --dataset, when the run is new)",
    )
    p.add_argument("--seed", type=int, default=0, help="training seed (0)")
    p.add_argument("--threads", type=int, default=0, help="torch threads (0: all cores)")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")


def _open_run(args: argparse.Namespace):  # -> Run
    import torch

    from softdeca_train.train.run import Run, RunConfig

    if args.threads:
        torch.set_num_threads(args.threads)
    if args.dataset:
        contrasts = str(Path(args.contrasts)) if args.contrasts else None
        more = tuple(str(Path(d)) for d in args.more_static)
        gate = None if args.rest_gate.lower() == "none" else float(args.rest_gate)
        if gate is not None and gate < 0:
            raise SystemExit("--rest-gate is 'none' or a number >= 0")
        config = RunConfig(
            str(Path(args.dataset)),
            args.sizes,
            args.seed,
            contrasts=contrasts,
            more_static=more,
            rest_gate=gate,
            residual_members=args.residual_members,
            rest_changes=args.rest_changes,
        )
        return Run(args.run, config)
    if args.contrasts or args.more_static or args.residual_members is not None or args.rest_changes:
        raise SystemExit(
            "--contrasts, --more-static, --residual-members and --rest-changes are part of a "
            "new run: give --dataset"
        )
    return Run(args.run)


def add_bundle_args(p: argparse.ArgumentParser) -> None:
    _run_args(p)
    p.add_argument("--bundle", default=DEFAULT_BUNDLE, help=f"bundle folder ({DEFAULT_BUNDLE})")
    p.add_argument(
        "--scale",
        type=float,
        default=1.0,
        help="multiply every stage's minutes (1.0: about 2 h on 2 cores; 0.25: a quick run)",
    )
    p.add_argument(
        "--identity-steps",
        type=int,
        default=0,
        help="identity encoder fine-tuning steps after its exact least-squares start (0)",
    )
    p.add_argument(
        "--softdeca-steps",
        type=int,
        default=None,
        help="SoftDECA's step budget instead of its minutes (0: its closed-form start alone)",
    )


def run_bundle(args: argparse.Namespace) -> int:
    from softdeca_train.train.bundle_stages import BundleBudget, default_command, train_bundle

    run = _open_run(args)
    budget = BundleBudget(
        identity_steps=args.identity_steps, softdeca_steps=args.softdeca_steps
    ).scaled(args.scale)
    out = train_bundle(run, Path(args.bundle), budget, default_command(), not args.no_progress)
    print(f"bundle written to {out}")
    return 0


def add_replace_sparse_args(p: argparse.ArgumentParser) -> None:
    _run_args(p)
    p.add_argument(
        "--bundle", default=DEFAULT_BUNDLE, help=f"bundle to change in place ({DEFAULT_BUNDLE})"
    )
    sparse = sorted(k for k in MODELS if k.startswith("sparse") and "dynamics" not in k)
    p.add_argument(
        "--model", choices=sparse, default="sparse", help="the run's trained model (sparse)"
    )
    p.add_argument(
        "--report",
        default=None,
        help="also re-measure this evaluation report's SparseSoftDECA rows on the run "
        "(e.g. docs/evaluation)",
    )


def run_replace_sparse(args: argparse.Namespace) -> int:
    from softdeca_train.train.bundle_stages import default_command, replace_sparse

    run = _open_run(args)
    deviations = replace_sparse(
        run, Path(args.bundle), args.model, default_command(), not args.no_progress
    )
    checks = ", ".join(f"{k} {v:.1e}" for k, v in deviations.items())
    print(f"{args.bundle}: SparseSoftDECA replaced by {args.model} (export check: {checks})")
    if args.report:
        from softdeca_train.train.report import refresh_sparse

        path = refresh_sparse(
            run, Path(args.bundle), Path(args.report), args.model, not args.no_progress
        )
        print(f"{path}: SparseSoftDECA's rows re-measured")
    return 0


def add_replace_softdeca_args(p: argparse.ArgumentParser) -> None:
    _run_args(p)
    p.add_argument(
        "--bundle", default=DEFAULT_BUNDLE, help=f"bundle to change in place ({DEFAULT_BUNDLE})"
    )


def run_replace_softdeca(args: argparse.Namespace) -> int:
    from softdeca_train.train.bundle_stages import default_command, replace_softdeca_model

    run = _open_run(args)
    deviations = replace_softdeca_model(
        run, Path(args.bundle), default_command(), not args.no_progress
    )
    checks = ", ".join(f"{k} {v:.1e}" for k, v in deviations.items())
    print(f"{args.bundle}: SoftDECA's frame networks replaced (export check: {checks})")
    return 0


def add_carry_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.models.bundle_carry import MODELS as CARRIED

    p.add_argument("--from", dest="source", required=True, help="bundle folder to copy from")
    p.add_argument(
        "--bundle", default=DEFAULT_BUNDLE, help=f"bundle to change in place ({DEFAULT_BUNDLE})"
    )
    p.add_argument(
        "--model", choices=sorted(CARRIED), default="sparse", help="whose networks (sparse)"
    )


def run_carry(args: argparse.Namespace) -> int:
    from softdeca_train.models.bundle_carry import carry_model
    from softdeca_train.train.bundle_stages import default_command

    names = carry_model(args.source, args.bundle, args.model, default_command())
    print(f"{args.bundle}: {', '.join(names)} carried from {args.source}")
    return 0


def add_model_args(p: argparse.ArgumentParser) -> None:
    _run_args(p)
    p.add_argument("model", choices=sorted(MODELS), help="which model to train")
    p.add_argument("--minutes", type=float, default=None, help="time budget")
    p.add_argument("--steps", type=int, default=1_000_000, help="step budget")
    p.add_argument("--lr", type=float, default=1e-3, help="initial learning rate (1e-3)")
    p.add_argument("--lr-end", type=float, default=5e-5, help="final learning rate (5e-5)")
    p.add_argument("--frames", type=int, default=8, help="frames per batch (8)")
    p.add_argument(
        "--groups", type=int, default=1, help="batches ((identity, p) groups) per step (1)"
    )
    p.add_argument(
        "--hyper-lr",
        type=float,
        default=None,
        help="learning-rate factor of the per-element hypernetworks (default: the model's)",
    )
    p.add_argument(
        "--test-error",
        action="store_true",
        help="print the mean error on the dataset's test split after training (mm)",
    )


def run_model(args: argparse.Namespace) -> int:
    from softdeca_train.train.loop import LoopConfig

    if args.minutes is None and args.steps >= 1_000_000:
        raise ValueError("give a budget: --minutes and/or --steps")
    run = _open_run(args)
    cfg = LoopConfig(
        steps=args.steps,
        minutes=args.minutes,
        lr=args.lr,
        lr_end=args.lr_end,
        frames=args.frames,
        seed=args.seed,
        hyper_lr=args.hyper_lr,
        groups=args.groups,
    )
    summary = run.train(args.model, cfg, not args.no_progress)
    print(f"{args.model}: {summary}")
    if args.test_error:
        from softdeca_train.train.evaluate import measure, no_correction

        model = run.load(args.model)
        mm = measure(run, args.model, model).summary()["mean_mm"]
        base = measure(run, "no-correction", no_correction(model.kind)).summary()["mean_mm"]
        print(
            f"{args.model}: test error {mm:.3f} mm, {mm / base:.0%} of no correction "
            f"({base:.3f} mm; every test frame)"
        )
    return 0


def add_evaluate_args(p: argparse.ArgumentParser) -> None:
    _run_args(p)
    p.add_argument("--bundle", default=DEFAULT_BUNDLE, help=f"bundle to check ({DEFAULT_BUNDLE})")
    p.add_argument("--out", default="docs/evaluation", help="report folder (docs/evaluation)")
    p.add_argument("--bench", default="build/bench", help="folder for models.json (build/bench)")
    from softdeca_train.controls.cli import add_report_arguments

    add_report_arguments(p, standalone=False)


def run_evaluate(args: argparse.Namespace) -> int:
    from softdeca_train.controls.cli import report_parts
    from softdeca_train.controls.report import (
        kept_real_takes,
        merge_into_report,
        update_readme,
        validate_report,
    )
    from softdeca_train.train.report import write_report

    run = _open_run(args)
    report = Path(args.out) / "evaluation.json"
    # --no-real-takes keeps the figures the report had (write_report starts it afresh)
    kept = kept_real_takes(report)
    path = write_report(run, Path(args.bundle), Path(args.out), Path(args.bench))
    controls, real = report_parts(args, Path(args.bundle))
    real = real if real is not None else kept
    doc = merge_into_report(report, controls, real)
    update_readme(path, doc)
    if real is not None:
        validate_report(doc)
    print(f"report written to {path}")
    return 0


def add_linear_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.train.linear_baseline import DEFAULT_SETS, GROUPS

    p.add_argument("--dataset", required=True, help="generated dataset folder")
    p.add_argument(
        "--features",
        nargs="+",
        default=list(DEFAULT_SETS),
        help="feature sets, each a string of group letters ("
        + "; ".join(f"{k}: {v}" for k, v in GROUPS.items())
        + f"); default {' '.join(DEFAULT_SETS)}",
    )
    p.add_argument(
        "--ridge", type=float, default=1e-3, help="ridge strength relative to A^T A (1e-3)"
    )
    p.add_argument(
        "--local",
        action="store_true",
        help="also the per-element fits (per vertex, also with the parameters averaged around "
        "each vertex; per face through deformation transfer) and DT's floor, on each "
        "element's own (regional) parameters; needs the template data",
    )
    p.add_argument("--out", help="also write the figures as JSON here")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")


def run_linear(args: argparse.Namespace) -> int:
    from softdeca_train.train.linear_baseline import (
        LinearBaselineConfig,
        format_table,
        parse_sets,
        run_linear_baselines,
    )

    cfg = LinearBaselineConfig(feature_sets=parse_sets(args.features), ridge=args.ridge)
    result = run_linear_baselines(args.dataset, cfg, progress=not args.no_progress)
    print(format_table(result))
    if args.local:
        from softdeca_train.train.local_fit import (
            LocalFitConfig,
            format_local_table,
            run_local_fits,
        )

        local = run_local_fits(
            args.dataset, LocalFitConfig(ridge=args.ridge), progress=not args.no_progress
        )
        print(format_local_table(local))
        result["local"] = local
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(result, indent=1) + "\n")
        print(f"wrote {args.out}")
    return 0


def add_rest_changes_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dataset", required=True, help="dataset folder (with manifest.json)")
    p.add_argument(
        "--bundle",
        default=str(REPO_ROOT / "models" / "softdeca-default"),
        help="bundle whose physics at prepare is used (default: models/softdeca-default)",
    )
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="processes (all cores)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def run_rest_changes(args: argparse.Namespace) -> int:
    from softdeca_train.train.rest_changes import RestChangesConfig, make_rest_changes

    config = RestChangesConfig(
        Path(args.dataset), Path(args.bundle), args.workers, not args.no_progress
    )
    written = sum(1 for _ in make_rest_changes(config))
    print(f"rest changes: {written} shard files written in {Path(args.dataset) / 'rest-changes'}")
    return 0


COMMANDS = [
    Command(
        "train-bundle",
        "Train every network of a model bundle (identity encoder, SoftDECA, SparseSoftDECA, "
        "their dynamics) on a generated dataset, resumably, and export the bundle.",
        add_bundle_args,
        run_bundle,
    ),
    Command(
        "bundle-sparse",
        "Replace a bundle's SparseSoftDECA (landmark encoder and per-vertex hypernetwork) by "
        "a run's trained one, with its test errors and training record in the manifest.",
        add_replace_sparse_args,
        run_replace_sparse,
    ),
    Command(
        "bundle-softdeca",
        "Replace a bundle's SoftDECA frame networks (weight encoder, hypernetworks, vertex and "
        "residual stages) by a run's trained `softdeca`, with its rest gate, rest changes, test "
        "error and training record in the manifest; its dynamics network stays.",
        add_replace_softdeca_args,
        run_replace_softdeca,
    ),
    Command(
        "bundle-carry",
        "Copy one model's networks (e.g. SparseSoftDECA) as they are from another bundle that "
        "reads the same template, landmarks, parameters and identity code, with their test "
        "errors and origin in the manifest.",
        add_carry_args,
        run_carry,
    ),
    Command(
        "train-model",
        "Train one model of the registry in a run folder (e.g. a Table 1 baseline).",
        add_model_args,
        run_model,
    ),
    Command(
        "evaluate",
        "Evaluate a training run and its bundle on the test split: report (markdown, plots, "
        "error heat maps) and build/bench/models.json.",
        add_evaluate_args,
        run_evaluate,
    ),
    Command(
        "linear-baseline",
        "Closed-form ridge regressions of a dataset's static offsets T - S on the model inputs "
        "(w, p, gravity load, h), fitted on the train split, measured on every test frame: "
        "what the inputs explain linearly; with --local also per-element fits and the floor "
        "of deformation transfer.",
        add_linear_args,
        run_linear,
    ),
    Command(
        "rest-changes",
        "The rest physics' change of every static and dynamic group of a dataset (what the "
        "runtime adds at prepare), for train-bundle --rest-changes; resumable.",
        add_rest_changes_args,
        run_rest_changes,
    ),
]
