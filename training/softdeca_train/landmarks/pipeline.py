"""ARKit reference face -> template: register, embed the landmark definition on S, measure it,
and cache the barycentric landmarks so later stages load them in milliseconds."""

from __future__ import annotations

import hashlib
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from softdeca_train.landmarks.arkit_reference import ArkitFace
from softdeca_train.landmarks.definition import LandmarkDefinition, load_definition
from softdeca_train.landmarks.registration import (
    Registration,
    RegistrationConfig,
    TargetSurface,
    register,
)
from softdeca_train.landmarks.surface import SurfaceLandmarks, embed
from softdeca_train.paths import cache_dir
from softdeca_train.template import Template

CACHE_FORMAT = 1


def face_target(template: Template, region: str = "face") -> TargetSurface:
    """S's triangles whose three vertices all lie in one template component (default the
    face: ARKit's mask covers only it, and the sockets behind eyes and mouth are no match)."""
    if region not in template.components:
        raise ValueError(f"unknown template component {region!r}")
    c = template.components[region]
    st = template.skin_triangles
    rows = np.nonzero(((st >= c.start) & (st < c.stop)).all(axis=1))[0]
    if not len(rows):
        raise ValueError(f"component {region!r} has no skin triangles")
    return TargetSurface(template.neutral, st[rows].astype(np.int64), rows)


@dataclass
class LandmarkRegistration:
    """Everything the report and the render need."""

    arkit: ArkitFace
    template: Template
    definition: LandmarkDefinition
    registration: Registration
    landmarks: SurfaceLandmarks
    landmark_distance: np.ndarray  # (L,) m, registered ARKit landmark vertex to S
    held_out: np.ndarray  # (68,) m, pair residual when the pair was left out; NaN if unused
    seconds: float


def register_arkit_to_template(
    template: Template | None = None,
    arkit: ArkitFace | None = None,
    definition: LandmarkDefinition | None = None,
    config: RegistrationConfig | None = None,
    held_out: bool = True,
    progress: bool = True,
) -> LandmarkRegistration:
    """Register ARKit's neutral to S and embed the landmarks. With `held_out`, also run the
    non-rigid step twice more, each time without half of its landmark pairs (alternating), to
    measure each constrained pair's residual when it was not a constraint."""
    t0 = time.perf_counter()
    template = template or Template.load()
    arkit = arkit or ArkitFace.load()
    definition = definition or load_definition()
    config = config or RegistrationConfig()
    target = face_target(template, config.target_region)
    dst68 = template.neutral[template.landmarks68]

    def run(cfg: RegistrationConfig, desc: str) -> Registration:
        return register(
            arkit.neutral,
            arkit.triangles,
            arkit.landmarks68,
            target,
            dst68,
            cfg,
            progress=progress,
            desc=desc,
        )

    reg = run(config, "non-rigid ICP")
    ho = np.full(68, np.nan)
    pairs = list(config.nonrigid_pairs)
    if held_out and len(pairs) >= 2:
        for half, (keep, leave) in enumerate(
            ((pairs[0::2], pairs[1::2]), (pairs[1::2], pairs[0::2]))
        ):
            cfg = RegistrationConfig(**{**asdict(config), "nonrigid_pairs": tuple(keep)})
            ho[leave] = run(cfg, f"held-out check {half + 1}/2").residual_nonrigid[leave]
    points = reg.registered[definition.vertices]
    lms, dist = embed(points, target, definition.names, definition.regions)
    return LandmarkRegistration(
        arkit, template, definition, reg, lms, dist, ho, time.perf_counter() - t0
    )


def _key(
    template: Template, arkit: ArkitFace, definition: LandmarkDefinition, config: RegistrationConfig
) -> str:
    h = hashlib.sha256(str(CACHE_FORMAT).encode())
    # The code that computes the points is part of the key: editing it invalidates the cache.
    for module in ("registration.py", "surface.py", "pipeline.py"):
        h.update((Path(__file__).parent / module).read_bytes())
    for a in (
        template.neutral,
        template.skin_triangles,
        arkit.neutral,
        arkit.triangles,
        arkit.landmarks68,
        template.landmarks68,
        definition.vertices,
    ):
        h.update(np.ascontiguousarray(a).tobytes())
    h.update(repr((definition.names, definition.regions, config)).encode())
    return h.hexdigest()[:16]


def template_landmarks(
    template: Template | None = None,
    arkit: ArkitFace | None = None,
    definition: LandmarkDefinition | None = None,
    config: RegistrationConfig | None = None,
) -> SurfaceLandmarks:
    """The landmark definition as barycentric points on the template's S (cached; computed
    by `register_arkit_to_template` on first use, about a second)."""
    template = template or Template.load()
    arkit = arkit or ArkitFace.load()
    definition = definition or load_definition()
    config = config or RegistrationConfig()
    path = cache_dir() / "landmarks" / f"surface-{_key(template, arkit, definition, config)}.npz"
    if path.is_file():
        with np.load(path) as z:
            return SurfaceLandmarks(
                names=definition.names,
                regions=definition.regions,
                triangle=z["triangle"],
                corners=z["corners"],
                bary=z["bary"],
            )
    lms = register_arkit_to_template(
        template, arkit, definition, config, held_out=False, progress=False
    ).landmarks
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    np.savez(tmp, triangle=lms.triangle, corners=lms.corners, bary=lms.bary)
    os.replace(tmp, path)
    return lms
