"""The pipeline's steps, registered for the CLI. Each imports its module lazily so that
`--help` is instant and a step only pays for what it uses."""

from __future__ import annotations

import argparse


def _ict_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--ict",
        default=None,
        help="ICT-FaceKit checkout, FaceXModel folder or .tar.xz archive "
        "(default: $SOFTDECA_ICT or ict-facekit in the data folder)",
    )


def _template_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)


def _template_run(args: argparse.Namespace) -> int:
    from softdeca_train.template import Template

    t = Template.load(args.ict)
    print(
        f"template: {t.n_vertices} vertices, {len(t.triangles)} triangles, "
        f"S: {len(t.skin_triangles)} triangles; {len(t.expression_names)} expressions, "
        f"{t.identity_modes.shape[0]} identity modes; ICT '{t.left_suffix}' = subject's left"
    )
    return 0


def _bench_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--out", default="build/bench", help="folder for <area>.json (build/bench)")
    p.add_argument("--heads", type=int, default=8, help="identities per LHM resolution (8)")


def _bench_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.bench import bench_lhm, report_area

    report_area(Path(args.out), "lhm", bench_lhm(args.ict, heads=args.heads))
    return 0


def _lhm_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--seed", type=int, default=None, help="identity seed (default: the template)")
    p.add_argument("--level", type=int, default=4, help="wrap resolution: icosphere level (4)")
    p.add_argument("--soft-layers", type=int, default=1, help="tet layers skin..muscle (1)")
    p.add_argument("--muscle-layers", type=int, default=1, help="tet layers muscle..skull (1)")
    p.add_argument("--out", default="out/lhm", help="output folder (out/lhm)")


def _lhm_run(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from softdeca_train.lhm import LhmConfig, check_lhm, fit_lhm
    from softdeca_train.lhm.figures import render_layers
    from softdeca_train.template import Template
    from softdeca_train.template.model import N_SKIN

    t = Template.load(args.ict)
    h = None if args.seed is None else t.sample_identity(args.seed)
    cfg = LhmConfig(
        level=args.level, soft_layers=args.soft_layers, muscle_layers=args.muscle_layers
    )
    model = fit_lhm(t, h, cfg)
    report = check_lhm(model, t.identity_neutral(h)[:N_SKIN], t.skin_triangles)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    name = "template" if args.seed is None else f"seed{args.seed}"
    model.save(out / f"lhm_{name}.npz")
    (out / f"lhm_{name}_report.json").write_text(json.dumps(report.as_dict(), indent=2) + "\n")
    render_layers(t, model, out / f"lhm_{name}.png", head=t.identity_neutral(h))
    print(json.dumps(report.as_dict(), indent=2))
    problems = report.failures()
    print("valid" if not problems else "INVALID: " + "; ".join(problems))
    print(f"wrote {out}/lhm_{name}.npz, .png and _report.json")
    return 0 if not problems else 1


def _demo_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--out", default="out/demo", help="output folder (out/demo)")
    p.add_argument(
        "--seeds", type=int, nargs="+", default=[1, 2, 3], help="identity seeds to show (1 2 3)"
    )


def _demo_run(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

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


def _landmarks_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument(
        "--arkit",
        default=None,
        help="folder with ARKit_reference_blendshapes.zip and ARKit_landmarks68.txt "
        "(default: $SOFTDECA_ARKIT_REFERENCE or arkit-reference in the data folder)",
    )
    p.add_argument(
        "--out",
        default="out/landmarks",
        help="folder for registration.png and landmarks_report.{json,md}",
    )
    p.add_argument(
        "--write-definition",
        action="store_true",
        help="regenerate the committed landmark definition (definition.json) from "
        "its rules before registering",
    )


def _landmarks_run(args: argparse.Namespace) -> int:
    from softdeca_train.landmarks.cli import run

    return run(args.ict, args.arkit, args.out, args.write_definition)


STEPS = {
    "template": (
        "Load ICT-FaceKit into the cache and summarise the template.",
        _template_args,
        _template_run,
    ),
    "lhm": (
        "Fit the layered head model of one identity, check it, save it and render it.",
        _lhm_args,
        _lhm_run,
    ),
    "demo": (
        "The demo: renders of the template's layers, sampled identities, landmarks.",
        _demo_args,
        _demo_run,
    ),
    "bench": (
        "Benchmark the pipeline (LHM fitting per resolution) into build/bench/<area>.json.",
        _bench_args,
        _bench_run,
    ),
    "landmarks": (
        "Register ARKit's reference face to the template, embed the ~150 landmarks "
        "on S, and write a render and a residual report.",
        _landmarks_args,
        _landmarks_run,
    ),
}


# ---- Streaming: the virtual device and the golden files -------------------------------------


def _virtual_device_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("take", help="a Live Link Face CSV take or a .sdrec recording")
    p.add_argument("--host", default="127.0.0.1", help="receiver's numeric address (127.0.0.1)")
    p.add_argument(
        "--port",
        type=int,
        default=None,
        help="receiver's UDP port (default: 50110 ours, 11111 Live Link Face)",
    )
    p.add_argument("--format", choices=("softdeca", "livelinkface"), default="softdeca")
    p.add_argument(
        "--landmarks",
        choices=("softdeca149", "arkit68", "none"),
        default="softdeca149",
        help="landmark profile streamed in our protocol (from ARKit's reference face)",
    )
    p.add_argument("--speed", type=float, default=1.0, help="1 = the take's own rate")
    p.add_argument("--start", type=int, default=0, help="first frame of the take")
    p.add_argument("--count", type=int, default=None, help="frames to send (default: all)")
    p.add_argument("--fps", type=float, default=60.0, help="timecode rate of a CSV take")
    p.add_argument("--loss", type=float, default=0.0, help="probability a frame is dropped")
    p.add_argument("--duplicate", type=float, default=0.0, help="probability it is sent twice")
    p.add_argument(
        "--reorder",
        type=float,
        default=0.0,
        help="probability it is held back until after the next frame",
    )
    p.add_argument("--jitter-ms", type=float, default=0.0, help="uniform extra delay per frame")
    p.add_argument("--seed", type=int, default=0, help="seed of the impairments")
    p.add_argument("--session", type=int, default=None, help="session id (default: random)")
    p.add_argument("--log-json", default=None, help="write what went on the wire as JSON")


def _virtual_device_run(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from softdeca_train.streaming.impairments import Impairments
    from softdeca_train.streaming.virtual_device import VirtualDeviceConfig, run

    log = run(
        VirtualDeviceConfig(
            take=Path(args.take),
            host=args.host,
            port=args.port,
            format=args.format,
            landmarks=args.landmarks,
            speed=args.speed,
            start=args.start,
            count=args.count,
            timecode_rate=args.fps,
            session_id=args.session,
            progress=True,
            impairments=Impairments(
                loss=args.loss,
                duplicate=args.duplicate,
                reorder=args.reorder,
                jitter_ms=args.jitter_ms,
                seed=args.seed,
            ),
        )
    )
    print(
        f"sent {len(log.frames) - len(log.dropped)} of {len(log.frames)} frames "
        f"({len(log.datagrams)} datagrams; {len(log.dropped)} dropped, {log.duplicated} "
        f"duplicated, {log.held} held back; {log.requests_answered} requests answered)"
    )
    if args.log_json:
        Path(args.log_json).write_text(
            json.dumps(
                {
                    "session_id": log.session_id,
                    "datagrams": log.datagrams,
                    "dropped": log.dropped,
                    "duplicated": log.duplicated,
                    "held": log.held,
                    "frames": len(log.frames),
                    "requests_answered": log.requests_answered,
                }
            )
        )
    return 0


def _golden_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="tests/golden/streaming", help="folder of the golden files")


def _golden_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.streaming.golden import generate

    for path in generate(Path(args.out)):
        print(path)
    return 0


STEPS["virtual-device"] = (
    "Stream a take over UDP like a phone (our protocol or Live Link Face), with optional "
    "loss, duplication, reordering and jitter.",
    _virtual_device_args,
    _virtual_device_run,
)
STEPS["stream-golden"] = (
    "Write the golden packets and recording of the streaming formats (tests/golden/streaming).",
    _golden_args,
    _golden_run,
)


# ---- runtime -----------------------------------------------------------------------------


def _runtime_bundle_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--out", default="build/bundles/random-untrained", help="bundle folder")
    p.add_argument(
        "--parameters",
        default=None,
        help="parameter specs in parameters.json's format (default plugin/data/parameters.json)",
    )
    p.add_argument("--seed", type=int, default=0, help="random weights seed (0)")
    p.add_argument(
        "--synthetic", action="store_true", help="a small synthetic head instead of the template"
    )
    p.add_argument("--tar", action="store_true", help="also write <out>.tar (one-file bundle)")


def _runtime_bundle_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.models import (
        FULL_SIZES,
        TEST_SIZES,
        BundleInfo,
        build_random,
        export_bundle,
        pack_bundle,
    )
    from softdeca_train.models.parameters import specs_or_test_list

    specs = specs_or_test_list(args.parameters)
    if args.synthetic:
        from softdeca_train.models.synthetic import synthetic_head

        definition, sizes = synthetic_head().definition, TEST_SIZES
    else:
        from softdeca_train.models.topology import from_template
        from softdeca_train.template import Template

        definition, sizes = from_template(Template.load(args.ict)), FULL_SIZES
    nets = build_random(definition, specs, sizes, seed=args.seed)
    info = BundleInfo(
        untrained=True,
        description="UNTRAINED: random-weight networks of the contract's shapes, for tests, "
        "benchmarks and replays that must not depend on a trained bundle",
    )
    out = export_bundle(Path(args.out), definition, nets, info)
    if args.tar:
        Path(str(out) + ".tar").write_bytes(pack_bundle(out))
    print(f"wrote untrained bundle {out} ({definition.name}, {len(specs)} parameters)")
    return 0


def _avatar_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--seed", type=int, required=True, help="identity seed")
    p.add_argument("--out", required=True, help="avatar folder for `softdeca replay`")


def _avatar_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.runtime.files import write_identity_avatar

    out = write_identity_avatar(args.seed, Path(args.out), args.ict)
    print(f"wrote avatar of identity seed {args.seed} to {out}")
    return 0


def _replay_preview_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--replay", required=True, help="output folder of `softdeca replay`")
    p.add_argument("--frames", type=int, default=4, help="rows of the contact sheet (4)")


def _replay_preview_run(args: argparse.Namespace) -> int:
    from softdeca_train.runtime.preview import render_preview

    print(f"wrote {render_preview(args.replay, args.frames)}")
    return 0


def _runtime_test_data_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, help="folder for the native runtime tests' inputs")


def _runtime_test_data_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.runtime.testdata import write_test_data

    print(f"wrote {write_test_data(Path(args.out))}")
    return 0


STEPS |= {
    "runtime-bundle": (
        "Export an UNTRAINED model bundle (random networks of the contract's shapes).",
        _runtime_bundle_args,
        _runtime_bundle_run,
    ),
    "avatar": (
        "Write an ICT identity's avatar folder (neutral, 52 shapes, ARKit user face) "
        "for `softdeca replay`.",
        _avatar_args,
        _avatar_run,
    ),
    "replay-preview": (
        "Render the contact sheet of a `softdeca replay` output folder.",
        _replay_preview_args,
        _replay_preview_run,
    ),
    "runtime-test-data": (
        "Write the native runtime tests' inputs (synthetic bundle, avatar, take).",
        _runtime_test_data_args,
        _runtime_test_data_run,
    ),
}


def _runtime_bench_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--out", default="build/bench", help="folder for runtime.json (build/bench)")
    p.add_argument("--frames", type=int, default=600, help="frames per figure (600)")
    p.add_argument("--take", default=None, help="Live Link Face CSV (default: S07-001)")
    p.add_argument("--parameters", default=None, help="parameter specs (parameters.json format)")


def _runtime_bench_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.runtime.bench import DEFAULT_TAKE, bench_runtime

    take = Path(args.take) if args.take else DEFAULT_TAKE
    print(f"wrote {bench_runtime(Path(args.out), args.ict, take, args.frames, args.parameters)}")
    return 0


STEPS["runtime-bench"] = (
    "Benchmark the native runtime per frame -> build/bench/runtime.json.",
    _runtime_bench_args,
    _runtime_bench_run,
)


# ---- Training data: generation, report, benchmark -------------------------------------------


def _generate_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.data.cli import add_generate_args

    add_generate_args(p)


def _generate_run(args: argparse.Namespace) -> int:
    from softdeca_train.data.cli import run_generate

    return run_generate(args)


def _report_data_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.data.cli import add_report_args

    add_report_args(p)


def _report_data_run(args: argparse.Namespace) -> int:
    from softdeca_train.data.cli import run_report

    return run_report(args)


def _bench_datagen_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.data.cli import add_bench_args

    add_bench_args(p)


def _bench_datagen_run(args: argparse.Namespace) -> int:
    from softdeca_train.data.cli import run_bench

    return run_bench(args)


STEPS["generate"] = (
    "Generate (or resume) the training dataset: static, dynamic and sparse instances "
    "simulated by the physics, in parallel (processes or Ray), as shards + manifest.",
    _generate_args,
    _generate_run,
)
STEPS["report-data"] = (
    "Report on a generated dataset: markdown + plots (parameter, weight and identity "
    "distributions; |T - S| per region).",
    _report_data_args,
    _report_data_run,
)
STEPS["bench-datagen"] = (
    "Benchmark data generation on this machine into build/bench/datagen.json.",
    _bench_datagen_args,
    _bench_datagen_run,
)


def _train_cli():  # the training's command lines, imported only when used (torch is slow)
    from softdeca_train.train import cli

    return cli


STEPS |= {
    "train-bundle": (
        "Train every network of a model bundle (identity encoder, SoftDECA, SparseSoftDECA, "
        "their dynamics) on a generated dataset, resumably, and export the bundle.",
        lambda p: _train_cli().add_bundle_args(p),
        lambda a: _train_cli().run_bundle(a),
    ),
    "train-model": (
        "Train one model of the registry in a run folder (e.g. a Table 1 baseline).",
        lambda p: _train_cli().add_model_args(p),
        lambda a: _train_cli().run_model(a),
    ),
    "evaluate": (
        "Evaluate a training run and its bundle on the test split: report (markdown, plots, "
        "error heat maps) and build/bench/models.json.",
        lambda p: _train_cli().add_evaluate_args(p),
        lambda a: _train_cli().run_evaluate(a),
    ),
}


# ---- Physics: a take through φ† ------------------------------------------------------------


def _simulate_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.sim.cli import add_simulate_args

    add_simulate_args(p)


def _simulate_run(args: argparse.Namespace) -> int:
    from softdeca_train.sim.cli import run_simulate

    return run_simulate(args)


STEPS["simulate"] = (
    "Simulate a Live Link Face take with the physics model for one identity: neutral.obj + "
    "linear.pc2/physics.pc2 point caches, simulate.png (linear | physics | distance), "
    "simulate.json (iterations, time, volume change, lip penetrations, distance).",
    _simulate_args,
    _simulate_run,
)


def _stress_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.sim.stress_cli import add_stress_args

    add_stress_args(p)


def _stress_run(args: argparse.Namespace) -> int:
    from softdeca_train.sim.stress_cli import run_stress_cli

    return run_stress_cli(args)


STEPS["stress"] = (
    "The physics stress suite: extreme expressions, identities, materials, gravity, levels, "
    "static and dynamic, real takes, judged by the sanity bounds -> stress.json, stress.md, "
    "stress_worst.png (and physics_stress.json with --bench-out).",
    _stress_args,
    _stress_run,
)


def _bench_physics_args(p: argparse.ArgumentParser) -> None:
    _ict_arg(p)
    p.add_argument("--out", default="build/bench", help="folder for physics_lhm.json")
    p.add_argument("--take", default=None, help="Live Link Face CSV (default: alex_rom_3)")
    p.add_argument("--levels", type=int, nargs="+", default=[3, 4], help="LHM levels (3 4)")
    p.add_argument("--stride", type=int, default=400, help="every Nth frame (400)")


def _bench_physics_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from softdeca_train.bench import report_area
    from softdeca_train.sim.bench import DEFAULT_TAKE, bench_physics_lhm

    take = Path(args.take) if args.take else DEFAULT_TAKE
    figures = bench_physics_lhm(args.ict, take, tuple(args.levels), args.stride)
    report_area(Path(args.out), "physics_lhm", figures)
    return 0


STEPS["bench-physics"] = (
    "Benchmark the physics model on the real layered head model and real frames "
    "-> build/bench/physics_lhm.json.",
    _bench_physics_args,
    _bench_physics_run,
)
