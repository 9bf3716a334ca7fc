"""`make bench`'s runtime figures: a full-size untrained bundle on the template topology (with
SoftDECA's vertex and residual stages, as the trained bundles have them), the avatar of
identity seed 1, and `softdeca bench-runtime` on the frames of a real take, with the shipped
bundle (models/softdeca-default) timed as users run it on the same avatars ->
build/bench/runtime.json (docs/ARCHITECTURE.md, Conventions)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from softdeca_train.models import FULL_SIZES, BundleInfo, build_random, export_bundle
from softdeca_train.models.parameters import specs_or_test_list
from softdeca_train.models.rest_head import rest_head_for_bundle
from softdeca_train.models.template_head import template_head_from
from softdeca_train.models.topology import from_template
from softdeca_train.paths import REPO_ROOT, default_takes_path
from softdeca_train.sample_avatars import AvatarConfig, make_avatar, write_avatar
from softdeca_train.template import Template

DEFAULT_TAKE = default_takes_path() / "S07-001.csv"
SHIPPED_BUNDLE = REPO_ROOT / "models" / "softdeca-default"
CLI = REPO_ROOT / "build" / "release" / "plugin" / "cli" / "softdeca"


def bench_runtime(
    out: Path,
    ict: str | None = None,
    take: Path = DEFAULT_TAKE,
    frames: int = 600,
    parameters: str | None = None,
) -> Path:
    work = out / "runtime-inputs"
    specs = specs_or_test_list(parameters)
    definition = from_template(Template.load(ict))
    nets = build_random(
        definition, specs, FULL_SIZES, seed=0, vertex_stage=True, residual_stage=True
    )
    info = BundleInfo(True, "UNTRAINED full-size random networks for the runtime benchmark")

    template = Template.load(ict)
    rest = rest_head_for_bundle(template, specs)  # the physics at prepare, as trained bundles
    bundle = export_bundle(
        work / "bundle",
        definition,
        nets,
        info,
        check=False,
        rest_head=rest,
        template_head=template_head_from(template),
    )
    avatar = work / "avatar-seed1"
    if not (avatar / "neutral.obj").is_file():
        face = make_avatar(AvatarConfig(arkit_face=True))  # the tracked face's stand-in
        write_avatar(make_avatar(AvatarConfig(identity="seed 1"), template), avatar, face)
    # a user's avatar: a held-out identity remeshed, inside a whole body (about 20,000 vertices)
    own = work / "avatar-body"
    if not (own / "neutral.obj").is_file():
        body = AvatarConfig(identity="seed 404", remesh=6000, body=True, body_vertices=14_000)
        write_avatar(make_avatar(body, template), own, None)
    path = out / "runtime.json"
    how = (
        f"make bench (softdeca bench-runtime, {len(specs)} parameters, "
        f"{FULL_SIZES.latent} latents, hyper hidden {FULL_SIZES.hyper_hidden}, "
        "SoftDECA with its vertex and residual stages, the physics at prepare)"
    )
    cmd = [
        str(CLI), "bench-runtime", "--bundle", str(bundle), "--avatar", str(avatar),
        "--take", str(take), "--frames", str(frames), "--out", str(path), "--how", how,
        "--own-avatar", str(own),
    ]  # fmt: skip
    if (SHIPPED_BUNDLE / "manifest.json").is_file():  # the path users run, timed too
        cmd += ["--shipped-bundle", str(SHIPPED_BUNDLE)]
    print("running", " ".join(cmd), file=sys.stderr)
    subprocess.run(cmd, check=True, env=os.environ.copy())
    figures = json.loads(path.read_text())
    for name, f in figures.items():
        target = "" if f["target"] is None else f"(target {f['target']})"
        print(f"  {name:44s} {f['value']:>10.4g} {f['unit']:7s} {target}")
    return path
