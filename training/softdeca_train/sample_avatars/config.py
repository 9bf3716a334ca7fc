"""What a test avatar is: one field per choice of `python -m softdeca_train avatar`.

Identities: the template, or ICT identities no dataset holds. Datasets derive their identity
seeds from a SeedSequence of (dataset seed, 1, identity id), 32-bit hashes (data/plan.py,
`derived_seed`), so a small seed names a head training never saw; the controls gallery takes
101, 202 and 303, the test avatars take 404, 505 and 606 (HELD_OUT_IDENTITIES)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

from softdeca_train.face_names import ARKIT_BLENDSHAPES

# Metres per unit of each unit an avatar comes in.
UNITS: dict[str, float] = {"mm": 0.001, "cm": 0.01, "inch": 0.0254, "dm": 0.1, "m": 1.0}
UP_AXES = ("y", "z")
# The naming habits of rigs (names.py): eyeBlinkLeft, blendShape1.eyeBlinkLeft,
# AK_09_EyeBlinkLeft, eyeBlink_L, eye_blink_l, EyeBlinkLeft, CC_Base_Body.Eye_Blink_L,
# facs_bs_EyeBlinkLeft.
REMESH_STYLES = ("isotropic", "adaptive")  # remesh.py
NAME_STYLES = ("arkit", "namespace", "prefix", "suffix_LR", "snake", "pascal", "cc", "daz")
HELD_OUT_IDENTITIES = ("seed 404", "seed 505", "seed 606")
DEFAULT_IDENTITY = HELD_OUT_IDENTITIES[0]
DEFAULT_BODY_VERTICES = 20_000
LOW_POLY_VERTICES = 1500  # skin vertices of low_poly: about 3,900 with the rest


@dataclass(frozen=True)
class AvatarConfig:
    """A test avatar. The defaults give the ICT head of a held-out identity in the template's
    own topology and conventions (metres, +Y up, right-handed, ARKit's names): the avatar
    `softdeca replay` takes. Every other field moves it into a convention users' avatars come
    in; the fields combine."""

    # "template", "seed N" or "h+2.5σ"/"h-2.5σ" (template/identities.py); ignored by arkit_face
    identity: str = DEFAULT_IDENTITY
    # the skin remeshed to about this many vertices (another topology); None keeps ICT's
    remesh: int | None = None
    remesh_style: str = "isotropic"  # or "adaptive" (remesh.py)
    shuffle: bool = False  # the vertices in a random order
    unit: str = "m"  # a key of UNITS
    up: str = "y"  # "z": the template's +Y becomes +Z (and its +Z, out of the face, -Y)
    mirror: bool = False  # a left-handed export: x negated, the triangles' indices kept
    body: bool = False  # a synthetic whole body joined under the neck, moved by no shape
    body_vertices: int = DEFAULT_BODY_VERTICES  # the body's own vertices, about
    # the skin, the eyeballs and the teeth as separate objects (ICT's other inner parts left out)
    separate_eyes_teeth: bool = False
    # the eyeballs, the teeth and the tongue in the skin's object (decimated with it: remesh)
    eyes_teeth_tongue: bool = False
    hair_cards: int = 0  # this many hair cards a layer over the scalp and forehead (extras.py)
    # the cards move with the skin under them (shapes transferred to every mesh of a head)
    hair_follows: bool = False
    eyebrows: bool = False  # eyebrow fins fused to the skin along the brows (extras.py)
    shoulders: bool = False  # a bust (neck, shoulders, chest) joined under the neck
    one_object: bool = False  # every part in one object (the mesh's o line), as one mesh
    # the side shapes split from their symmetric sum by a linear ramp this many metres wide
    # across the face (build.resplit); None: as the source has them
    split_width: float | None = None
    keep_shapes: int | None = None  # only this many of the shapes, chosen at random
    drop: tuple[str, ...] = ()  # canonical ARKit names of shapes left out
    names: str = "arkit"  # a NAME_STYLES entry
    arkit_face: bool = False  # ARKit's reference face (1,220 vertices) instead of an ICT head
    variant_seed: int = 0  # the random choices: vertex order, the kept shapes

    def __post_init__(self) -> None:
        problems = []
        if self.unit not in UNITS:
            problems.append(f"unit must be one of {', '.join(UNITS)}")
        if self.up not in UP_AXES:
            problems.append(f"up must be one of {', '.join(UP_AXES)}")
        if self.names not in NAME_STYLES:
            problems.append(f"names must be one of {', '.join(NAME_STYLES)}")
        if self.remesh is not None and not 500 <= self.remesh <= 200_000:
            problems.append("remesh must be between 500 and 200,000 vertices")
        if self.remesh_style not in REMESH_STYLES:
            problems.append(f"remesh_style must be one of {', '.join(REMESH_STYLES)}")
        if self.keep_shapes is not None and not 1 <= self.keep_shapes <= 52:
            problems.append("keep_shapes must be between 1 and 52")
        if self.body and self.body_vertices < 2_000:
            problems.append("body_vertices must be at least 2,000")
        unknown = [n for n in self.drop if n not in ARKIT_BLENDSHAPES]
        if unknown:
            problems.append(f"drop: not ARKit blendshape names: {', '.join(unknown)}")
        if self.arkit_face and (
            self.body or self.separate_eyes_teeth or self.eyes_teeth_tongue or self.shoulders
        ):
            problems.append(
                "arkit_face takes no body, shoulders, eyes, teeth or tongue (ARKit's reference "
                "face has no neck, eyes or teeth)"
            )
        if self.body and self.shoulders:
            problems.append("body and shoulders exclude each other (a body has shoulders)")
        if self.separate_eyes_teeth and self.eyes_teeth_tongue:
            problems.append("separate_eyes_teeth and eyes_teeth_tongue exclude each other")
        if not 0 <= self.hair_cards <= 200:
            problems.append("hair_cards must be between 0 and 200")
        if self.split_width is not None and not 0.01 <= self.split_width <= 1.0:
            problems.append("split_width must be between 0.01 and 1 metre")
        if problems:
            raise ValueError("avatar: " + "; ".join(problems))

    @property
    def metres_per_unit(self) -> float:
        return UNITS[self.unit]

    def to_dict(self) -> dict:
        return {**asdict(self), "drop": list(self.drop)}


def low_poly(config: AvatarConfig) -> AvatarConfig:
    """`config` as a game-ready head as artists export one (--low-poly): decimated, eyes, teeth
    and tongue, hair cards and eyebrow fins in one mesh with a bust, centimetres, Z-up, AK_NN_
    names, shuffled; a remesh already asked for is kept (ARKit's face: no eyes, teeth, tongue
    or bust)."""
    return replace(
        config,
        remesh=config.remesh or LOW_POLY_VERTICES,
        remesh_style="adaptive" if not config.remesh else config.remesh_style,
        eyes_teeth_tongue=not config.arkit_face,  # ARKit's face has none
        hair_cards=config.hair_cards or 12,
        eyebrows=True,
        shoulders=not (config.body or config.arkit_face),
        one_object=True,
        unit="cm",
        up="z",
        names="prefix",
        shuffle=True,
    )


# Low-poly game heads as artists export them (about 1,200 to 5,500 vertices): decimated skin with
# eyes, teeth and tongue, hair cards and eyebrow fins in one mesh with a bust, centimetres,
# Z-up, AK_NN_ names (config.low_poly); rigs whose side shapes are split by a ramp across the
# face (each side's shape moves the other side too), whose hair cards carry the shapes, under
# Character Creator's and Daz's names: each a test (tests/python/test_fit_avatars.py).
LOW_POLY_VARIANTS: dict[str, AvatarConfig] = {
    "low-poly game head": low_poly(AvatarConfig()),
    "low-poly, sides split by a ramp across the face": low_poly(AvatarConfig(split_width=0.16)),
    "low-poly seed 505, hair carrying the shapes, CC names": replace(
        low_poly(AvatarConfig(identity="seed 505", remesh=2000, hair_follows=True)),
        names="cc",
    ),
    "ARKit's face decimated, split by a ramp, Daz names": replace(
        low_poly(AvatarConfig(arkit_face=True, remesh=800, split_width=0.3)),
        names="daz",
    ),
}
