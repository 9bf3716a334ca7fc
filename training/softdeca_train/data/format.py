"""The arrays of a shard, per kind: one row per instance. Written into the manifest and, as
`meta` (JSON), into every shard, so a shard explains itself without the code."""

from __future__ import annotations

import json

from softdeca_train.template.model import N_SKIN

COMMON = {
    "instance_id": ("int64", "(n,)", "unique over the dataset, fixed by the plan"),
    "split": ("int8", "(n,)", "0 train, 1 test"),
    "identity_id": ("int32", "(n,)", "simulated identity (one per shard)"),
    "h": ("float32", "(n, 100)", "ICT identity coefficients of the simulated head"),
    "param_id": ("int32", "(n,)", "parameter set; frames of one (identity, p) group share it"),
    "p": ("float64", "(n, 25)", "material parameters, plugin/data/parameters.json order"),
}
FRAME = {
    "weights": ("float32", "(n, 52)", "ARKit weights w_t, canonical order"),
    "source_take": ("int16", "(n,)", "take index (manifest takes) or -1: coverage sampler"),
    "source_index": ("int32", "(n,)", "frame index in the take, or coverage draw index"),
    "offsets": (
        "float16",
        f"(n, {N_SKIN}, 3)",
        "T - S_t in metres; S_t = SkinBlend(identity_neutral(h), w) (data/blend.py)",
    ),
    "iterations": ("int16", "(n,)", "solver iterations"),
    "converged": ("bool", "(n,)", "solver reached the tolerance"),
    "estimated_error": (
        "float32",
        "(n,)",
        "solver's estimated RMS distance to the fixed point / bounding-box diagonal",
    ),
    "failures": (
        "uint8",
        "(n,)",
        "sanity bounds failed, bit i: sim/sanity.py REASONS[i] (exploded, penetration, "
        "mouth_open_ratio, inverted_elements, volume, not_converged); 0: passes",
    ),
}
REGIONAL = {
    "p_regions": (
        "float64",
        "(n, 10, 25)",
        "parameters per region of S (template/regions.py REGIONS order): a regional pattern, or p "
        "in every region",
    ),
}
SPARSE = {
    "landmarks": (
        "float32",
        "(n, 149, 3)",
        "L = sigma(L'_t): personalised donor landmarks + noise",
    ),
    "landmarks_clean": ("float32", "(n, 149, 3)", "the same before the noise"),
    "donor_id": ("int32", "(n,)", "identity whose expression landmarks were personalised"),
    "donor_h": ("float32", "(n, 100)", "its identity coefficients"),
}


def _axis(shape: str, size: str) -> str:
    """`shape` with an axis of `size` after the rows: (n, 52) -> (n, size, 52)."""
    return shape.replace("(n,", f"(n, {size},").replace(f"(n, {size},)", f"(n, {size})")


def _sequence(d: dict) -> dict:
    return {k: (t, _axis(s, "L"), a) for k, (t, s, a) in d.items()}


def _lead_in(key: str, about: str) -> tuple[str, str, str]:
    """FRAME's array `key` for the two lead-in frames before a sequence."""
    t, s, _ = FRAME[key]
    return t, _axis(s, "2"), about


DYNAMIC = {
    **_sequence(FRAME),
    "prev_weights": _lead_in("weights", "w of the two lead-in frames before the sequence"),
    "prev_offsets": _lead_in(
        "offsets", "T - S of those frames: T_{-2}, T_{-1} (the sequence's starting velocity)"
    ),
    "prev_source_index": _lead_in("source_index", "their frame indices in the same take"),
}

ARRAYS = {
    "static": {**COMMON, **FRAME, **REGIONAL},
    "dynamic": {**COMMON, **DYNAMIC},
    "sparse": {**COMMON, **FRAME, **REGIONAL, **SPARSE},
}


def describe(kind: str) -> dict[str, dict[str, str]]:
    return {k: {"dtype": t, "shape": s, "about": a} for k, (t, s, a) in ARRAYS[kind].items()}


def shard_meta(kind: str, split: int, header_digest: str) -> str:
    return json.dumps(
        {
            "format": "softdeca-dataset-shard",
            "kind": kind,
            "split": split,
            "units": "metres",
            "dataset": header_digest,
            "arrays": describe(kind),
        }
    )
