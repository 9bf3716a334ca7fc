"""Sampling ranges of the material parameters for a dataset: the physics' own ranges
(plugin/data/parameters.json, the paper's Appendix A) narrowed where they leave plausible
faces. Measured on softdeca-l3-v2 (Appendix A ranges): the log of the weakest constraint
weights drives the log of an instance's 99th-percentile offset |T - S| with correlation -0.8
(w_target for static/dynamic, w_regularisation for sparse); below 1 kPa (w_target) and
0.1 kPa (w_regularisation) gravity and skull scaling pull the skin centimetres to decimetres
off S (p99 56 mm, max 0.8 m), a sagging mask rather than a face. A network is only trained on,
and its bundle only accepts, the sampled ranges (the manifest records them).

`interactive` samples what a user moves live around the defaults: every constraint weight
within a decade of its default, target volume and the strain limit within 10 %, skull and jaw
scale within 2 %, gravity up to 1.2 g and 30 degrees off vertical. Measured on softdeca-l3-v3
(`plausible`): 69 % of |T - S| of its static frames is an offset shared by the frames of an
(identity, p) group, independent of the expression (data/offset_structure.py), and with
weights spread over five decades and skulls scaled by up to 50 % nothing learned it from 120
parameter sets (ridge linear in p made the test error worse; SoftDECA stayed within 1 % of no
correction, docs/training.md).

`controls` (the default) samples every control over its control range, the one list in
plugin/data/parameters.json (`control`: the range a user moves it in; docs/controls.md says
how far each moves the physics and why a range ends where it does: within it every sampled
frame passes the physics' sanity bounds, docs/physics.md) and keeps the parameters that are
no controls (they act on nothing in the head model) at their defaults."""

from __future__ import annotations

from softdeca_train.parameters import ParameterSet, load_parameters


def _decade(default: float) -> tuple[float, float]:
    return default / 10, default * 10


_TEN_PERCENT = (0.9, 1.1)
# The pinned bones scale about their pivots: 5 % moves skull vertices 4-5 mm, farther than
# the muscle layer is thick over most of the head, so the bone crosses the muscle wrap at rest
# (docs/physics.md, Known limits).
_BONE_SCALE = (0.98, 1.02)
PROFILES: dict[str, dict[str, tuple[float, float]]] = {
    "appendix-a": {},
    "plausible": {"w_target": (1.0, 100.0), "w_regularisation": (0.1, 10.0)},
    "interactive": {
        "w_soft_volume": (3.0, 100.0),  # a decade below the default, up to the physics' top
        "w_soft_strain": _decade(1.0),
        "w_muscle_volume": (3.0, 100.0),
        "w_muscle_strain": _decade(1.0),
        "w_skin_strain": _decade(1.0),
        "w_skull_strain": (10.0, 100.0),  # the default is the physics' maximum
        "w_skull_bending": (10.0, 100.0),
        "w_connect_volume": _decade(10.0),
        "w_connect_strain": _decade(10.0),
        "w_target": _decade(1.0),
        "w_regularisation": (0.1, 1.0),  # below 0.1 the skin hangs off S (plausible)
        "w_landmark": _decade(0.3),
        "target_volume": _TEN_PERCENT,
        "max_strain": _TEN_PERCENT,
        "gravity_strength": (1.0, 1.2),
        "gravity_tilt": (0.0, 30.0),
        "cranium_scale_x": _BONE_SCALE,
        "cranium_scale_y": _BONE_SCALE,
        "cranium_scale_z": _BONE_SCALE,
        "jaw_scale_x": _BONE_SCALE,
        "jaw_scale_y": _BONE_SCALE,
        "jaw_scale_z": _BONE_SCALE,
    },
}
# Profiles read from parameters.json: sampling ranges are the parameters' control ranges.
FROM_DEFINITION = ("controls",)
DEFAULT_PROFILE = "controls"
# Datasets written before profiles existed sampled the physics' own ranges.
LEGACY_PROFILE = "appendix-a"


def profile_ranges(params: ParameterSet, profile: str) -> dict[str, tuple[float, float]]:
    """The ranges a profile narrows, by parameter name."""
    if profile in FROM_DEFINITION:
        return {s.name: s.control for s in params.specs if s.control is not None}
    if profile not in PROFILES:
        known = sorted([*PROFILES, *FROM_DEFINITION])
        raise ValueError(f"unknown range profile {profile!r}; known: {known}")
    return PROFILES[profile]


def fixed_outside_profile(params: ParameterSet, profile: str) -> tuple[str, ...]:
    """Parameters a profile keeps at their defaults: the ones that are no controls."""
    if profile in FROM_DEFINITION:
        return tuple(s.name for s in params.specs if s.control is None)
    return ()


def is_profile(profile: str) -> bool:
    return profile in PROFILES or profile in FROM_DEFINITION


def control_names() -> tuple[str, ...]:
    """The parameters the models take (every control of parameters.json)."""
    return tuple(load_parameters().controls().names)


def sampling_parameters(params: ParameterSet, profile: str) -> ParameterSet:
    """`params` with the profile's ranges (defaults clamped into them)."""
    narrowed = profile_ranges(params, profile)
    unknown = set(narrowed) - set(params.names)
    if unknown:
        raise ValueError(f"range profile {profile!r} names unknown parameters {sorted(unknown)}")
    specs = []
    for s in params.specs:
        if s.name in narrowed:
            lo, hi = narrowed[s.name]
            if not s.minimum <= lo < hi <= s.maximum:
                raise ValueError(
                    f"{profile}: {s.name} range [{lo}, {hi}] outside [{s.minimum}, {s.maximum}]"
                )
            s = s.narrowed(lo, hi)
        specs.append(s)
    return ParameterSet(tuple(specs))
