"""Sampling ranges of the material parameters for a dataset: the physics' own ranges
(plugin/data/parameters.json, the paper's Appendix A) narrowed where they leave plausible
faces. Measured on softdeca-l3-v2 (Appendix A ranges): the log of the weakest constraint
weights drives the log of an instance's 99th-percentile offset |T - S| with correlation -0.8
(w_target for static/dynamic, w_regularisation for sparse); below 1 kPa (w_target) and
0.1 kPa (w_regularisation) gravity and skull scaling pull the skin centimetres to decimetres
off S (p99 56 mm, max 0.8 m), a sagging mask rather than a face. A network is only trained on,
and its bundle only accepts, the sampled ranges (the manifest records them)."""

from __future__ import annotations

from dataclasses import replace

from softdeca_train.parameters import ParameterSet

PROFILES: dict[str, dict[str, tuple[float, float]]] = {
    "appendix-a": {},
    "plausible": {"w_target": (1.0, 100.0), "w_regularisation": (0.1, 10.0)},
}
DEFAULT_PROFILE = "plausible"
# Datasets written before profiles existed sampled the physics' own ranges.
LEGACY_PROFILE = "appendix-a"


def sampling_parameters(params: ParameterSet, profile: str) -> ParameterSet:
    """`params` with the profile's ranges (defaults clamped into them)."""
    if profile not in PROFILES:
        raise ValueError(f"unknown range profile {profile!r}; known: {sorted(PROFILES)}")
    narrowed = PROFILES[profile]
    unknown = set(narrowed) - set(params.names)
    if unknown:
        raise ValueError(f"range profile {profile!r} names unknown parameters {sorted(unknown)}")
    specs = []
    for s in params.specs:
        if s.name in narrowed:
            lo, hi = narrowed[s.name]
            if not s.lo <= lo < hi <= s.hi:
                raise ValueError(f"{profile}: {s.name} range [{lo}, {hi}] outside [{s.lo}, {s.hi}]")
            s = replace(s, lo=lo, hi=hi, default=min(max(s.default, lo), hi))
        specs.append(s)
    return ParameterSet(tuple(specs))
