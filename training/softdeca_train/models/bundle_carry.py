"""One model's networks carried from one bundle into another, as they are (their ONNX files,
not a retraining): a bundle retrained for SoftDECA keeps the SparseSoftDECA of the bundle
before it, or the other way round. Only between bundles that read the same inputs the same
way (the template, its landmarks, the parameters, the identity encoder); every carried file
is checked against its source manifest's sha256, and the destination's manifest records what
was carried, from where, with the errors its source measured."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

from softdeca_train.models.bundle import (
    MANIFEST,
    lowest_format_version,
    read_manifest,
    replaced_description,
)

# what a bundle's networks read besides their own inputs: equal in both bundles, or the
# carried networks would run on another head, landmark set, parameter list or identity code
SHARED_KEYS = (
    "format",
    "units",
    "frame",
    "template",
    "latent_size",
    "identity_size",
    "blendshapes",
    "parameters",
    "landmarks",
    "template_head",
)
# the manifest keys a model's networks bring with them: the residual stage's sizes (its
# networks' shapes use them) and SoftDECA's rest gate (what z's last entry is, which f_w, always
# carried, decides: absent where the source has none)
OWN_KEYS = {"sparse": (), "softdeca": ("residual_stage", "rest_gate")}
# the models that can be carried: a model's networks are the manifest's networks named
# "<model>.*", and its errors the `errors` keys named "<model>", "<model>_*" or "<model>-*"
MODELS = tuple(OWN_KEYS)


def _differences(source: dict[str, Any], dest: dict[str, Any]) -> list[str]:
    """What the two manifests disagree on among what the carried networks read."""
    out = [k for k in SHARED_KEYS if source.get(k) != dest.get(k)]
    enc_s = (source.get("networks") or {}).get("identity_encoder", {}).get("sha256")
    enc_d = (dest.get("networks") or {}).get("identity_encoder", {}).get("sha256")
    if enc_s != enc_d:
        out.append("the identity encoder")
    return out


def _contract(spec: dict[str, Any]) -> dict[str, Any]:
    """A network's entry without what is the file's own (its name, hash, stored precision)."""
    return {k: v for k, v in spec.items() if k not in ("file", "sha256", "float16_initialisers")}


def carry_model(source: str | Path, folder: str | Path, model: str, command: str) -> list[str]:
    """Copy `model`'s networks (every network named "<model>.*") from bundle folder `source`
    into bundle folder `folder` in place; returns the networks carried. Raises ValueError, with
    what differs, when the bundles do not share what the networks read, a network's contract
    (inputs, outputs) differs, the destination has networks of the model the source lacks, or
    a source file does not match its manifest; nothing is written then."""
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; one of {', '.join(MODELS)}")
    source, folder = Path(source), Path(folder)
    src, dst = read_manifest(source), read_manifest(folder)
    if not folder.is_dir():
        raise ValueError(f"{folder}: carrying networks needs a bundle folder, not an archive")
    differs = _differences(src, dst)
    if differs:
        raise ValueError(f"{source} and {folder} differ in {', '.join(differs)}: not carried")
    present = [n for n in src["networks"] if n.startswith(f"{model}.")]
    if not present:
        raise ValueError(f"{source} has no {model} networks")
    left = [n for n in dst["networks"] if n.startswith(f"{model}.") and n not in present]
    if left:  # the destination would run networks of two origins as one model
        raise ValueError(f"{folder} has {', '.join(left)}, which {source} lacks: not carried")
    files: dict[str, bytes] = {}
    for name in present:
        spec = src["networks"][name]
        if name in dst["networks"] and _contract(dst["networks"][name]) != _contract(spec):
            raise ValueError(f"{name}: its inputs or outputs differ between the bundles")
        data = (source / spec["file"]).read_bytes()
        if hashlib.sha256(data).hexdigest() != spec["sha256"]:
            raise ValueError(f"{source / spec['file']}: sha256 does not match its manifest")
        files[name] = data
    for name, data in files.items():
        spec = dict(src["networks"][name])
        _write_atomic(folder / spec["file"], data)
        dst["networks"][name] = spec
    for key in OWN_KEYS[model]:
        if key in src:
            dst[key] = src[key]
        elif key == "rest_gate":
            dst.pop(key, None)
    dst["format_version"] = max(lowest_format_version(dst), dst["format_version"])
    record = {
        "command": command,
        "carried_from": str(source),
        "model": model,
        "dataset": {"name": ", ".join(sorted(set(_origins(src, present).values())))},
        "origins": _origins(src, present),
        "source_description": src.get("description", ""),
    }
    errors = {
        k: v
        for k, v in (src.get("errors") or {}).items()
        if k == model or k.startswith((f"{model}_", f"{model}-"))
    }
    training = dst.get("training") or {}
    training["replaced"] = [*training.get("replaced", []), {"networks": present, **record}]
    dst["training"] = training
    dst["errors"] = {**(dst.get("errors") or {}), **errors}
    dst["description"] = replaced_description(dst.get("description", ""), present, record)
    _write_atomic(folder / MANIFEST, (json.dumps(dst, indent=1) + "\n").encode())
    return present


def _origins(manifest: dict[str, Any], names: list[str]) -> dict[str, str]:
    """The dataset each network was last trained on, by the manifest's training record."""
    training = manifest.get("training") or {}
    out = {n: (training.get("dataset") or {}).get("name", "unknown") for n in names}
    for r in training.get("replaced", []):
        for n in set(r["networks"]) & set(names):
            out[n] = (r.get("dataset") or {}).get("name", "unknown")
    return out


def _write_atomic(path: Path, data: bytes) -> None:
    """Each file whole or not at all: a stopped carry leaves old files, never half of one."""
    tmp = path.with_name(path.name + ".partial")
    tmp.write_bytes(data)
    os.replace(tmp, path)
