"""The runtime stage's commands: the untrained bundle and its additions, replay previews, the
native tests' inputs and the runtime benchmark."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument


def _runtime_bundle_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
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
    from softdeca_train.models import (
        FULL_SIZES,
        TEST_SIZES,
        BundleInfo,
        build_random,
        export_bundle,
        pack_bundle,
    )
    from softdeca_train.models.parameters import specs_or_test_list
    from softdeca_train.models.template_head import template_head_from, template_head_of

    specs = specs_or_test_list(args.parameters)
    if args.synthetic:
        from softdeca_train.models.synthetic import synthetic_head

        head = synthetic_head()
        definition, sizes = head.definition, TEST_SIZES
        template_head = template_head_of(head.neutral, head.blendshapes, definition.skin_vertices)
    else:
        from softdeca_train.models.topology import from_template
        from softdeca_train.template import Template

        template = Template.load(args.ict)
        definition, sizes = from_template(template), FULL_SIZES
        template_head = template_head_from(template)
    nets = build_random(definition, specs, sizes, seed=args.seed)
    info = BundleInfo(
        untrained=True,
        description="UNTRAINED: random-weight networks of the contract's shapes, for tests, "
        "benchmarks and replays that must not depend on a trained bundle",
    )
    out = export_bundle(Path(args.out), definition, nets, info, template_head=template_head)
    if args.tar:
        Path(str(out) + ".tar").write_bytes(pack_bundle(out))
    print(f"wrote untrained bundle {out} ({definition.name}, {len(specs)} parameters)")
    return 0


def _rest_physics_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("bundle", help="bundle folder (SoftDECA, the template's topology)")
    p.add_argument("--level", type=int, default=3, help="LHM level of the tissue fill (3)")


def _rest_physics_run(args: argparse.Namespace) -> int:
    from softdeca_train.lhm import LhmConfig
    from softdeca_train.models.bundle import add_rest_physics, read_manifest
    from softdeca_train.models.rest_head import rest_head_for_bundle
    from softdeca_train.parameters import ParameterSpec
    from softdeca_train.template import Template

    folder = Path(args.bundle)
    specs = tuple(ParameterSpec.from_dict(p) for p in read_manifest(folder)["parameters"])
    print("building the template's tissue fill and measuring the rest-inert parameters ...")
    cfg = LhmConfig(level=args.level, tet_mesh="carried")
    head = rest_head_for_bundle(Template.load(args.ict), specs, cfg)
    add_rest_physics(folder, head)
    size = (folder / "rest_head.bin").stat().st_size
    entry = json.loads((folder / "manifest.json").read_text())["rest_physics"]
    print(
        f"{folder}: rest_head.bin ({size / 2**20:.1f} MiB, {entry['fill_vertices']} fill "
        f"vertices, {entry['soft_tets'] + entry['muscle_tets']} tets); rest-inert: "
        f"{', '.join(head.inert) or 'none'}"
    )
    return 0


def _template_head_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("bundle", help="bundle folder in the ICT template's topology")


def _template_head_run(args: argparse.Namespace) -> int:
    from softdeca_train.models.bundle import add_template_head
    from softdeca_train.models.template_head import TEMPLATE_HEAD_FILE, template_head_from
    from softdeca_train.template import Template

    folder = Path(args.bundle)
    add_template_head(folder, template_head_from(Template.load(args.ict)))
    size = (folder / TEMPLATE_HEAD_FILE).stat().st_size
    print(f"{folder}: {TEMPLATE_HEAD_FILE} ({size / 2**20:.1f} MiB), format version 5")
    return 0


def _replay_preview_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--replay", required=True, help="output folder of `softdeca replay`")
    p.add_argument("--frames", type=int, default=4, help="rows of the contact sheet (4)")
    p.add_argument(
        "--physics-seed",
        type=int,
        default=None,
        help="add the physics on the shown frames for the ICT identity of this seed (the "
        "avatar's), with the take's widest-open mouth among them (about a minute)",
    )
    p.add_argument(
        "--ict", default=None, help="ICT-FaceKit (default: $SOFTDECA_ICT or the data folder's)"
    )


def _replay_preview_run(args: argparse.Namespace) -> int:
    from softdeca_train.host.preview import render_preview

    out = render_preview(args.replay, args.frames, physics_seed=args.physics_seed, ict=args.ict)
    print(f"wrote {out}")
    return 0


def _runtime_test_data_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, help="folder for the native runtime tests' inputs")


def _runtime_test_data_run(args: argparse.Namespace) -> int:
    from softdeca_train.host.testdata import write_test_data

    print(f"wrote {write_test_data(Path(args.out))}")
    return 0


def _hostile_avatars_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, help="folder for the corpus (must not exist)")
    p.add_argument("--fan-mib", type=int, default=30, help="size of the OBJ face fan (30)")
    p.add_argument(
        "--bomb-mib",
        type=int,
        default=1024,
        help="what the FBX zlib bomb inflates to (1024; 0: none)",
    )


def _hostile_avatars_run(args: argparse.Namespace) -> int:
    from softdeca_train.host.hostile_avatars import write_corpus

    attacks = write_corpus(Path(args.out), args.fan_mib, args.bomb_mib)
    print(f"wrote {len(attacks)} hostile avatars and {Path(args.out) / 'corpus.json'}")
    return 0


def _runtime_bench_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("--out", default="build/bench", help="folder for runtime.json (build/bench)")
    p.add_argument("--frames", type=int, default=600, help="frames per figure (600)")
    p.add_argument("--take", default=None, help="Live Link Face CSV (default: S07-001)")
    p.add_argument("--parameters", default=None, help="parameter specs (parameters.json format)")


def _runtime_bench_run(args: argparse.Namespace) -> int:
    from softdeca_train.host.bench import DEFAULT_TAKE, bench_runtime

    take = Path(args.take) if args.take else DEFAULT_TAKE
    print(f"wrote {bench_runtime(Path(args.out), args.ict, take, args.frames, args.parameters)}")
    return 0


def _fit_check_args(p: argparse.ArgumentParser) -> None:
    from softdeca_train.sample_avatars.config import HELD_OUT_IDENTITIES as held_out

    p.add_argument("--out", default="build/fit-check/fit_check.json", help="the report (JSON)")
    p.add_argument(
        "--identity",
        action="append",
        default=None,
        help=f"an identity to check (repeatable; default: {', '.join(held_out)})",
    )
    p.add_argument("--remesh", type=int, default=8000, help="the avatar's skin vertices (8000)")
    p.add_argument("--stride", type=int, default=10, help="every N-th frame of each take (10)")
    p.add_argument("--max-frames", type=int, default=None, help="at most this many per take")
    p.add_argument("--take", action="append", default=None, help="a take's name (repeatable)")
    p.add_argument("--bundle", default=None, help="model bundle (default: the committed one)")


def _fit_check_run(args: argparse.Namespace) -> int:
    from softdeca_train.host.fit_check import FitCheckConfig, run_fit_check, write_report
    from softdeca_train.sample_avatars.config import HELD_OUT_IDENTITIES as held_out

    config = FitCheckConfig(
        identities=tuple(args.identity or held_out),
        remesh=args.remesh,
        stride=args.stride,
        max_frames=args.max_frames,
        takes=tuple(args.take or ()),
        **({"bundle": args.bundle} if args.bundle else {}),
    )
    report = run_fit_check(config)
    out = write_report(report, Path(args.out))
    worst = max(t["softdeca_ratio"] for i in report["identities"] for t in i["takes"])
    residual = max(i["fit"]["face_residual_mm_mean"] for i in report["identities"])
    codes = ", ".join(f"{i['code_error_rms']:.2f}" for i in report["identities"])
    print(
        f"wrote {out}: face residual at most {residual:.3f} mm; SoftDECA's correction off by "
        f"at most {100 * worst:.1f} % of its mean over the face (per take); identity code "
        f"error (RMS per coefficient) {codes}; {report['seconds']:.0f} s"
    )
    return 0


COMMANDS = [
    Command(
        "runtime-bundle",
        "Export an UNTRAINED model bundle (random networks of the contract's shapes).",
        _runtime_bundle_args,
        _runtime_bundle_run,
    ),
    Command(
        "bundle-rest-physics",
        "Add the physics at prepare to a bundle: the template's tissue fill (rest_head.bin) "
        "and its rest-inert parameters (format version 4).",
        _rest_physics_args,
        _rest_physics_run,
    ),
    Command(
        "bundle-template-head",
        "Add the template head that fitting users' avatars needs to a bundle "
        "(template_head.bin, format version 5).",
        _template_head_args,
        _template_head_run,
    ),
    Command(
        "replay-preview",
        "Render the contact sheet of a `softdeca replay` output folder.",
        _replay_preview_args,
        _replay_preview_run,
    ),
    Command(
        "runtime-test-data",
        "Write the native runtime tests' inputs (synthetic bundle, avatar, take).",
        _runtime_test_data_args,
        _runtime_test_data_run,
    ),
    Command(
        "hostile-avatars",
        "Write hostile avatar files (path escapes, FIFOs, links, nesting, bombs, wild values) "
        "and corpus.json, for softdeca bench-reliability --import-corpus.",
        _hostile_avatars_args,
        _hostile_avatars_run,
    ),
    Command(
        "runtime-bench",
        "Benchmark the native runtime per frame -> build/bench/runtime.json.",
        _runtime_bench_args,
        _runtime_bench_run,
    ),
    Command(
        "avatar-fit-check",
        "Fit held-out ICT identities remeshed to another topology and compare what they get "
        "with the template path on every take, per take (docs/avatars.md).",
        _fit_check_args,
        _fit_check_run,
    ),
]
