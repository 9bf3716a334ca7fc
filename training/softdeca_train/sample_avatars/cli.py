"""The avatars stage's command: `avatar`, a test avatar folder in the conventions users' avatars
come in, with its ground truth (docs/avatars.md, "Test avatars")."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from softdeca_train.commands import Command, add_ict_argument
from softdeca_train.sample_avatars.config import (
    DEFAULT_BODY_VERTICES,
    DEFAULT_IDENTITY,
    HELD_OUT_IDENTITIES,
    LOW_POLY_VERTICES,
    NAME_STYLES,
    REMESH_STYLES,
    UNITS,
    AvatarConfig,
    low_poly,
)

# What real heads carry and how they are exported: on/off options of `avatar`.
LOOK_FLAGS = (
    (
        "--eyes-teeth-tongue",
        "the eyeballs, the teeth and the tongue with the skin (decimated with it by --remesh; "
        "one object with --one-object)",
    ),
    (
        "--hair-follows",
        "the hair cards move with the skin under them (shapes transferred to every mesh)",
    ),
    ("--eyebrows", "eyebrow fins fused to the skin along the brows"),
    ("--shoulders", "a bust: the neck continued into shoulders and a chest (no shape moves it)"),
    ("--one-object", "every part in one object, as one mesh"),
    (
        "--low-poly",
        f"a game-ready head as artists export one: --remesh {LOW_POLY_VERTICES} --remesh-style "
        "adaptive (unless given) --eyes-teeth-tongue --hair-cards 12 --eyebrows --shoulders "
        "--one-object --unit cm --up z --names prefix --shuffle",
    ),
)


def _avatar_args(p: argparse.ArgumentParser) -> None:
    add_ict_argument(p)
    p.add_argument("--out", required=True, help="avatar folder (neutral.obj, blendshapes/, ...)")
    who = p.add_mutually_exclusive_group()
    who.add_argument(
        "--identity",
        default=None,
        help="the ICT head: template, 'seed N' or h+2.5σ / h-2.5σ (default: "
        f"'{DEFAULT_IDENTITY}'; {', '.join(HELD_OUT_IDENTITIES)} are identities no dataset "
        "holds)",
    )
    who.add_argument("--seed", type=int, default=None, help="the same as --identity 'seed N'")
    p.add_argument(
        "--remesh",
        type=int,
        default=None,
        metavar="N",
        help="the skin remeshed to about N vertices (another topology; 5,000-10,000 is typical)",
    )
    p.add_argument(
        "--remesh-style",
        choices=REMESH_STYLES,
        default="isotropic",
        help="isotropic: even edges everywhere; adaptive: dense where the surface curves "
        "(isotropic)",
    )
    p.add_argument("--shuffle", action="store_true", help="the vertices in a random order")
    p.add_argument("--unit", choices=tuple(UNITS), default="m", help="the avatar's unit (m)")
    p.add_argument(
        "--up",
        choices=("y", "z"),
        default="y",
        help="up axis (y); z: +Y becomes +Z, the face looks along -Y",
    )
    p.add_argument(
        "--mirror", action="store_true", help="a left-handed export: x negated, indices kept"
    )
    p.add_argument(
        "--body",
        action="store_true",
        help=f"a synthetic whole body (about {DEFAULT_BODY_VERTICES:,} vertices, no shape moves "
        "it) joined under the neck",
    )
    p.add_argument(
        "--separate-eyes-teeth",
        action="store_true",
        help="the skin, the eyeballs and the teeth as separate objects (o lines)",
    )
    for flag, text in LOOK_FLAGS:
        p.add_argument(flag, action="store_true", help=text)
    p.add_argument(
        "--hair-cards",
        type=int,
        default=0,
        metavar="K",
        help="K hair cards a layer (two layers, a few mm off the scalp) over the scalp and the "
        "forehead, moved by no shape (0)",
    )
    p.add_argument(
        "--split-width",
        type=float,
        default=None,
        metavar="M",
        help="the side shapes split from their symmetric sum by a linear ramp M metres wide "
        "across the face, as rigging tools split them (each side's shape moves the other side "
        "a little); default: the source's own",
    )
    p.add_argument(
        "--keep-shapes", type=int, default=None, metavar="K", help="only K shapes, at random"
    )
    p.add_argument(
        "--drop", default="", help="shapes left out: canonical ARKit names, comma-separated"
    )
    p.add_argument(
        "--names",
        choices=NAME_STYLES,
        default="arkit",
        help="the shapes' names: eyeBlinkLeft, blendShape1.eyeBlinkLeft, AK_09_EyeBlinkLeft, "
        "eyeBlink_L, eye_blink_l, EyeBlinkLeft, CC_Base_Body.Eye_Blink_L or "
        "facs_bs_EyeBlinkLeft (arkit)",
    )
    p.add_argument(
        "--arkit-face",
        action="store_true",
        help="ARKit's reference face (1,220 vertices, 51 shapes) instead of an ICT head",
    )
    p.add_argument(
        "--variant-seed", type=int, default=0, help="seed of the vertex order and kept shapes (0)"
    )
    p.add_argument(
        "--user-face",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="also write ARKit's reference face in user_face/: the tracked face `softdeca "
        "replay` stands in for a phone's (default: on)",
    )


def config_from_args(args: argparse.Namespace) -> AvatarConfig:
    identity = args.identity or DEFAULT_IDENTITY
    if args.seed is not None:
        identity = f"seed {args.seed}"
    config = AvatarConfig(
        identity=identity,
        remesh=args.remesh,
        remesh_style=args.remesh_style,
        shuffle=args.shuffle,
        unit=args.unit,
        up=args.up,
        mirror=args.mirror,
        body=args.body,
        separate_eyes_teeth=args.separate_eyes_teeth,
        eyes_teeth_tongue=args.eyes_teeth_tongue,
        hair_cards=args.hair_cards,
        hair_follows=args.hair_follows,
        eyebrows=args.eyebrows,
        split_width=args.split_width,
        shoulders=args.shoulders,
        one_object=args.one_object,
        keep_shapes=args.keep_shapes,
        drop=tuple(n.strip() for n in args.drop.split(",") if n.strip()),
        names=args.names,
        arkit_face=args.arkit_face,
        variant_seed=args.variant_seed,
    )
    return low_poly(config) if args.low_poly else config


def _avatar_run(args: argparse.Namespace) -> int:
    from softdeca_train.landmarks import ArkitFace
    from softdeca_train.sample_avatars.build import make_avatar
    from softdeca_train.sample_avatars.files import write_avatar
    from softdeca_train.template import Template

    start = time.perf_counter()
    config = config_from_args(args)
    face = ArkitFace.load() if config.arkit_face or args.user_face else None
    template = None if config.arkit_face else Template.load(args.ict)
    mesh = make_avatar(config, template, face, progress=True)
    user_face = make_avatar(AvatarConfig(arkit_face=True), face=face) if args.user_face else None
    out = write_avatar(mesh, Path(args.out), user_face, progress=True)
    objects = ", ".join(f"{name} {count}" for name, count in mesh.groups)
    print(
        f"wrote {out}: {mesh.truth.identity}, {len(mesh.neutral)} vertices, "
        f"{len(mesh.triangles)} triangles ({objects}), {int(mesh.present.sum())} shapes named "
        f"{config.names}, {config.unit}, {config.up.upper()} up"
        f"{', mirrored' if config.mirror else ''}{', shuffled' if config.shuffle else ''} "
        f"({time.perf_counter() - start:.1f} s)"
    )
    return 0


COMMANDS = [
    Command(
        "avatar",
        "Write a test avatar folder (neutral.obj, blendshapes/<name>.obj, truth.npz): an ICT "
        "head or ARKit's face in another topology, unit, axes, naming, with a body, ...",
        _avatar_args,
        _avatar_run,
    ),
]
