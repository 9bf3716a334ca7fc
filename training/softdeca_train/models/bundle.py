"""The model bundle: writing it (ONNX export + manifest), packing it into one tar for hosts
that ship it as an asset, and reading it back (manifest, topology, networks through
onnxruntime). The format is specified in docs/bundle.md; the native runtime reads the same.

Kept whole: the bundle's writer and its reader (the export, the ONNX check,
OnnxNetworks) side by side, so the contract cannot drift between them."""

from __future__ import annotations

import copy
import hashlib
import io
import json
import tarfile
import warnings
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from softdeca_train.models.dt import DEFAULT_REGULARISATION
from softdeca_train.models.networks import (
    BETA_MAX,
    GAMMA_MAX,
    GAMMA_MIN,
    BundleNetworks,
    freeze_rest_codes,
)
from softdeca_train.models.reference import Model
from softdeca_train.models.residual import ResidualCoefficients, ResidualCondition
from softdeca_train.models.rest_head import (
    RestHead,
    read_rest_head,
    rest_head_file,
)
from softdeca_train.models.template_head import (
    TemplateHead,
    read_template_head,
    template_head_file,
)
from softdeca_train.models.topology import LandmarkSet, TemplateDefinition
from softdeca_train.parameters import ParameterSpec

FORMAT = "softdeca-bundle"
# Version 2 adds SoftDECA's optional vertex stage (softdeca.f_ph_v), version 3 its optional
# residual stage (softdeca.f_r_ph, softdeca.f_r_w), version 4 the physics at prepare
# (rest_physics, rest_head.bin), version 5 the template head for fitting users' avatars
# (template_head, template_head.bin), version 6 SoftDECA's rest gate (rest_gate: a runtime
# that ignored it would count p's effect at rest twice), version 7 SoftDECA trained on the rest
# physics (rest_changes: a runtime that ignored it would take the networks' response to p
# off); a bundle is written with the lowest version that holds it, so runtimes that read only
# older versions still run what they can.
FORMAT_VERSION = 7
FORMAT_VERSIONS = (1, 2, 3, 4, 5, 6, 7)
OPSET = 17
MANIFEST = "manifest.json"
SKIN_TRIANGLES_FILE = "skin_triangles.i32"
NON_SKIN_BONES_FILE = "non_skin_bones.u8"
# The per-element tables (one row per face or vertex: HyperNetwork.base, the positional
# encodings, LocalLinear.table and .slot_table) are stored as float16 and cast back to float32
# inside the graph. They are most of a bundle (SoftDECA's base table alone is 28,068 x 32 x
# 9), and the runtime stores the per-avatar tensors in half or int8 by default anyway
# (docs/bundle.md).
# Encoders and MLP weights stay float32.
HALF_TABLES = ("base", "positional", "table", "slot_table")


def _is_half_table(name: str) -> bool:
    return name.rsplit(".", 1)[-1] in HALF_TABLES


@dataclass(frozen=True)
class BundleInfo:
    """What a bundle says about where it came from. `training` and `errors` are filled by
    training (train-bundle); random bundles leave them None and set `untrained`."""

    untrained: bool
    description: str
    training: dict[str, Any] | None = None
    errors: dict[str, Any] | None = None
    dt_regularisation: float = DEFAULT_REGULARISATION
    dynamics_frame_rate_hz: float = 30.0


def _tensor(name: str, shape: list[int | str]) -> dict[str, Any]:
    return {"name": name, "dtype": "float32", "shape": shape}


def _network_specs(d: TemplateDefinition, nets: BundleNetworks) -> dict[str, dict[str, Any]]:
    f, v, k = d.n_faces, d.skin_vertices, len(d.landmarks)
    lat, h = nets.sizes.latent, nets.sizes.identity
    p = len(nets.specs)
    cols = [s.name for s in nets.specs]
    per_vertex = [_tensor("parameters", [v, p]), _tensor("identity", [1, h])]
    dyn_out = [_tensor("alpha", [v]), _tensor("beta", [v]), _tensor("gamma", [v])]
    # Both models' dynamics networks have the same signature (a copy each: "file" is added below).
    dynamics = {"inputs": per_vertex, "outputs": dyn_out, "parameter_columns": cols}
    specs: dict[str, dict[str, Any]] = {
        "identity_encoder": {
            "inputs": [_tensor("neutral", [1, v, 3])],
            "outputs": [_tensor("identity", [1, h])],
        }
    }
    if nets.softdeca is not None:
        specs["softdeca.f_w"] = {
            "inputs": [_tensor("weights", ["batch", len(d.blendshapes)])],
            "outputs": [_tensor("z", ["batch", lat])],
        }
        specs["softdeca.f_ph"] = {
            "inputs": [_tensor("parameters", [f, p]), _tensor("identity", [1, h])],
            "outputs": [_tensor("L", [f, lat, 9])],
            "parameter_columns": cols,
        }
        specs["softdeca.f_dyn"] = dict(dynamics)
        if nets.softdeca.f_ph_v is not None:
            specs["softdeca.f_ph_v"] = {
                "inputs": per_vertex,
                "outputs": [_tensor("L", [v, lat, 3])],
                "parameter_columns": cols,
            }
        if (stage := nets.softdeca.f_r) is not None:
            c, modes = stage.condition_size, stage.sizes.modes + 1
            specs["softdeca.f_r_ph"] = {
                "inputs": [_tensor("parameters", [v, p])],
                "outputs": [_tensor("condition", [1, c]), _tensor("modes", [v, modes, 3])],
                "parameter_columns": cols,
            }
            specs["softdeca.f_r_w"] = {
                "inputs": [
                    _tensor("weights", ["batch", len(d.blendshapes)]),
                    _tensor("condition", [1, c]),
                ],
                "outputs": [_tensor("coefficients", ["batch", modes])],
            }
    if nets.sparse is not None:
        specs["sparse.f_l"] = {
            "inputs": [_tensor("landmark_offsets", ["batch", 3 * k])],
            "outputs": [_tensor("z", ["batch", lat])],
        }
        specs["sparse.f_ph_v"] = {
            "inputs": per_vertex,
            "outputs": [_tensor("L", [v, lat, 3])],
            "parameter_columns": cols,
        }
        specs["sparse.f_dyn"] = dict(dynamics)
    for name, spec in specs.items():
        spec["file"] = name.replace(".", "_") + ".onnx"
    return specs


def _modules(nets: BundleNetworks) -> dict[str, nn.Module]:
    out: dict[str, nn.Module] = {"identity_encoder": nets.identity_encoder}
    if nets.softdeca is not None:
        out |= {
            f"softdeca.{k}": m
            for k, m in vars(nets.softdeca).items()
            if m is not None and k != "f_r"
        }
        if (stage := nets.softdeca.f_r) is not None:
            out["softdeca.f_r_ph"] = ResidualCondition(stage)
            out["softdeca.f_r_w"] = ResidualCoefficients(stage)
    if nets.sparse is not None:
        out |= {f"sparse.{k}": m for k, m in vars(nets.sparse).items()}
    return out


# The export check's inputs in the networks' domain, in metres: a head's points span about 20 cm
# and its landmarks move up to about 2 cm either way. Random points in a metre's cube would judge
# the encoders' float32 sums far outside it (codes in the thousands, float32 steps of 1e-3).
HEAD_SPAN_M = 0.2
LANDMARK_OFFSET_SPAN_M = 0.04


def _example(spec: dict[str, Any]) -> tuple[torch.Tensor, ...]:
    out = []
    for t in spec["inputs"]:
        shape = [1 if isinstance(s, str) else s for s in t["shape"]]
        x = torch.rand(*shape)
        if t["name"] == "parameters":
            x = x * 0  # replaced by in-range values in export_bundle
        elif t["name"] == "neutral":
            x = x * HEAD_SPAN_M
        elif t["name"] == "landmark_offsets":
            x = (x - 0.5) * LANDMARK_OFFSET_SPAN_M
        out.append(x)
    return tuple(out)


def _export_onnx(
    module: nn.Module, spec: dict[str, Any], example: tuple[torch.Tensor, ...]
) -> bytes:
    module = freeze_rest_codes(module)  # the rest terms as constants, not per-frame work
    buf = io.BytesIO()
    names_in = [t["name"] for t in spec["inputs"]]
    names_out = [t["name"] for t in spec["outputs"]]
    dynamic = {
        t["name"]: {i: s for i, s in enumerate(t["shape"]) if isinstance(s, str)}
        for t in spec["inputs"] + spec["outputs"]
    }
    dynamic = {k: v for k, v in dynamic.items() if v}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        torch.onnx.export(
            module,
            example,
            buf,
            input_names=names_in,
            output_names=names_out,
            dynamic_axes=dynamic or None,
            opset_version=OPSET,
            dynamo=False,
        )
    return _name_constant_outputs(buf.getvalue(), names_out)


def _name_constant_outputs(data: bytes, names: list[str]) -> bytes:
    """An output the exporter folded into a constant (the residual stage's mode table) keeps
    the constant's generated name; give it its contract name through an Identity, and the
    constant a table name, so that _store_half stores it in float16 like the other tables."""
    # onnx only where a bundle is exported
    import onnx
    from onnx import helper

    model = onnx.load_from_string(data)
    graph = model.graph
    inits = {i.name: i for i in graph.initializer}
    renamed = False
    for out, name in zip(graph.output, names, strict=True):
        if out.name == name or out.name not in inits:
            continue
        table = f"{name}.{HALF_TABLES[-1]}"
        inits[out.name].name = table
        graph.node.append(helper.make_node("Identity", [table], [name]))
        out.name = name
        renamed = True
    return model.SerializeToString() if renamed else data


def _store_half(data: bytes) -> tuple[bytes, list[str]]:
    """Store the per-element tables (HALF_TABLES) as float16, each read through a Cast node
    (torch's exporter folds such a Cast away, so it is done here)."""
    import onnx  # only where a bundle is exported
    from onnx import TensorProto, helper, numpy_helper

    model = onnx.load_from_string(data)
    graph = model.graph
    casts, names = [], []
    for init in graph.initializer:
        if init.data_type != TensorProto.FLOAT or not _is_half_table(init.name):
            continue
        name = init.name
        half = numpy_helper.from_array(
            numpy_helper.to_array(init).astype(np.float16), name + "_f16"
        )
        init.CopyFrom(half)
        casts.append(helper.make_node("Cast", [half.name], [name], to=TensorProto.FLOAT))
        names.append(name)
    if not names:
        return data, names
    nodes = casts + list(graph.node)
    del graph.node[:]
    graph.node.extend(nodes)
    onnx.checker.check_model(model)
    return model.SerializeToString(), names


def _round_tables(module: nn.Module) -> None:
    """Round the per-element tables of `module` to float16 in place, as _store_half stores them."""
    with torch.no_grad():
        for name, t in [*module.named_parameters(), *module.named_buffers()]:
            if t.dtype == torch.float32 and _is_half_table(name):
                t.copy_(t.half().float())


def as_stored(nets: BundleNetworks) -> BundleNetworks:
    """A copy of `nets` as an exported bundle holds them (per-element tables in float16): the
    torch reference a runtime running the bundle should reproduce."""
    out = copy.deepcopy(nets)
    for m in out.modules():
        _round_tables(m)
    return out


def _default_parameters(specs: tuple[ParameterSpec, ...], n: int) -> torch.Tensor:
    return torch.tensor([[s.default_value for s in specs]], dtype=torch.float32).repeat(n, 1)


def export_bundle(
    folder: str | Path,
    definition: TemplateDefinition,
    nets: BundleNetworks,
    info: BundleInfo,
    check: bool = True,
    rest_head: RestHead | None = None,
    template_head: TemplateHead | None = None,
) -> Path:
    """Write a bundle folder: manifest.json, the skin triangulation, the non-skin bone labels
    and one ONNX file per network, and with `rest_head` the physics at prepare
    (rest_physics.py), with `template_head` what fitting users' avatars needs
    (template_head.py). With `check`, every ONNX file is run in onnxruntime against its torch
    module and the largest deviation is recorded in the manifest."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    specs = _network_specs(definition, nets)
    modules = _modules(nets)
    # the check compares with the networks as stored (the same float16 rounding): it is of the
    # export; what the rounding costs shows in the bundle's end-to-end errors
    references = _modules(as_stored(nets)) if check else {}
    deviations: dict[str, float] = {}
    for name, spec in specs.items():
        example = list(_example(spec))
        for i, t in enumerate(spec["inputs"]):
            if t["name"] == "parameters":
                example[i] = _default_parameters(nets.specs, t["shape"][0])
        data, half = _store_half(_export_onnx(modules[name], spec, tuple(example)))
        (folder / spec["file"]).write_bytes(data)
        spec["sha256"] = hashlib.sha256(data).hexdigest()
        spec["float16_initialisers"] = half
        if check:
            deviations[name] = _check_onnx(data, references[name], spec, tuple(example))
    tri = np.ascontiguousarray(definition.skin_triangles, dtype="<i4")
    bones = np.ascontiguousarray(definition.non_skin_bones, dtype=np.uint8)
    (folder / SKIN_TRIANGLES_FILE).write_bytes(tri.tobytes())
    (folder / NON_SKIN_BONES_FILE).write_bytes(bones.tobytes())
    lm = definition.landmarks
    gate = _rest_gate(nets)
    if nets.rest_changes and rest_head is None:
        raise ValueError("a SoftDECA trained on the rest physics needs its physics at prepare")
    manifest: dict[str, Any] = {
        "format": FORMAT,
        "format_version": 1,  # below, once the manifest says what the bundle holds
        "untrained": info.untrained,
        "description": info.description,
        "units": "metre",
        "frame": "right-handed, +Y up, +Z out of the face, +X the subject's own left "
        "(ARKit face anchor)",
        "template": {
            "name": definition.name,
            "head_vertices": definition.head_vertices,
            "skin_vertices": definition.skin_vertices,
            "skin_triangles": definition.n_faces,
        },
        "latent_size": nets.sizes.latent,
        "identity_size": nets.sizes.identity,
        "blendshapes": list(definition.blendshapes),
        "parameters": [s.manifest() for s in nets.specs],
        "landmarks": {
            "count": len(lm),
            "arkit_vertex_count": lm.arkit_vertex_count,
            "points": [
                {
                    "name": lm.names[k],
                    "region": lm.regions[k],
                    "arkit_vertex": int(lm.arkit_vertex[k]),
                    "triangle": int(lm.triangle[k]),
                    "bary": [float(b) for b in lm.bary[k]],
                }
                for k in range(len(lm))
            ],
        },
        "files": {
            "skin_triangles": {
                "path": SKIN_TRIANGLES_FILE,
                "dtype": "int32",
                "shape": [definition.n_faces, 3],
                "sha256": hashlib.sha256(tri.tobytes()).hexdigest(),
            },
            "non_skin_bones": {
                "path": NON_SKIN_BONES_FILE,
                "dtype": "uint8",
                "shape": [definition.head_vertices - definition.skin_vertices],
                "sha256": hashlib.sha256(bones.tobytes()).hexdigest(),
            },
        },
        "non_skin": {
            "labels": {"0": "cranium (stays at the neutral)", "1": "jaw (follows jaw_anchors)"},
            "jaw_anchors": [int(a) for a in definition.jaw_anchors],
        },
        "deformation_transfer": {
            "formulation": "cotangent-poisson-1",
            "regularisation": info.dt_regularisation,
        },
        "dynamics": {
            "frame_rate_hz": info.dynamics_frame_rate_hz,
            "constraint": "gamma + 2 alpha - beta = 1",
            "beta_max": BETA_MAX,
            "gamma_range": [GAMMA_MIN, GAMMA_MAX],
        },
        "networks": specs,
        **_residual_sizes(nets),
        **({} if gate is None else {"rest_gate": gate}),
        **({"rest_changes": True} if nets.rest_changes else {}),
        "export_check_max_abs": deviations or None,
        "training": info.training,
        "errors": info.errors,
    }
    manifest["format_version"] = lowest_format_version(manifest)
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")
    if rest_head is not None:
        add_rest_physics(folder, rest_head)
    if template_head is not None:
        add_template_head(folder, template_head)
    return folder


def lowest_format_version(manifest: dict[str, Any]) -> int:
    """The lowest format version that holds what `manifest` says the bundle has (FORMAT)."""
    networks = manifest.get("networks") or {}
    for version, held in (
        (7, "rest_changes" in manifest),
        (6, "rest_gate" in manifest),
        (5, "template_head" in manifest),
        (4, "rest_physics" in manifest),
        (3, "softdeca.f_r_ph" in networks),
        (2, "softdeca.f_ph_v" in networks),
    ):
        if held:
            return version
    return 1


def replace_networks(
    folder: str | Path,
    modules: dict[str, nn.Module],
    record: dict[str, Any],
    errors: dict[str, Any] | None = None,
) -> dict[str, float]:
    """Replace networks of an existing bundle (e.g. SparseSoftDECA's, retrained on more data)
    by `modules`, keyed as the manifest's `networks`; each is exported against the contract
    the manifest already states (inputs, outputs, parameter columns), stored and checked as
    export_bundle does. `record` (what trained them) is appended to the manifest's
    training.replaced and `errors` (their test errors) replace the manifest's entries of the
    same keys; the deviations of the export check are returned."""
    folder = Path(folder)
    manifest = read_manifest(folder)
    unknown = sorted(set(modules) - set(manifest["networks"]))
    if unknown:
        raise ValueError(f"{folder}: the bundle has no network {', '.join(unknown)}")
    defaults = torch.tensor([[p["default"] for p in manifest["parameters"]]], dtype=torch.float32)
    deviations: dict[str, float] = {}
    for name, module in modules.items():
        spec = manifest["networks"][name]
        example = list(_example(spec))
        for i, t in enumerate(spec["inputs"]):
            if t["name"] == "parameters":
                example[i] = defaults.repeat(t["shape"][0], 1)
        stored = copy.deepcopy(module).eval()
        _round_tables(stored)
        try:
            with torch.no_grad():
                got = stored(*example)
        except RuntimeError as e:  # inputs of other sizes than the contract's
            raise ValueError(f"{name}: does not take the bundle's inputs ({e})") from e
        for t, y in zip(spec["outputs"], got if isinstance(got, tuple) else (got,), strict=True):
            fixed = [(a, b) for a, b in zip(t["shape"], y.shape, strict=True) if isinstance(a, int)]
            if len(y.shape) != len(t["shape"]) or any(a != b for a, b in fixed):
                raise ValueError(f"{name}: output {t['name']} {list(y.shape)}, not {t['shape']}")
        data, half = _store_half(_export_onnx(module.eval(), spec, tuple(example)))
        deviations[name] = _check_onnx(data, stored, spec, tuple(example))
        (folder / spec["file"]).write_bytes(data)
        spec["sha256"] = hashlib.sha256(data).hexdigest()
        spec["float16_initialisers"] = half
    manifest["export_check_max_abs"] = {
        **(manifest.get("export_check_max_abs") or {}),
        **deviations,
    }
    training = manifest.get("training") or {}
    training["replaced"] = [*training.get("replaced", []), {"networks": sorted(modules), **record}]
    manifest["training"] = training
    manifest["errors"] = {**(manifest.get("errors") or {}), **(errors or {})}
    manifest["description"] = replaced_description(manifest.get("description", ""), modules, record)
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")
    return deviations


def replace_softdeca(
    folder: str | Path,
    nets: BundleNetworks,
    record: dict[str, Any],
    errors: dict[str, Any] | None = None,
) -> dict[str, float]:
    """Replace a bundle's SoftDECA frame networks (f_w, f_ph and the vertex and residual
    stages) by `nets.softdeca`'s, as replace_networks does; SoftDECA's dynamics network stays
    the bundle's (f_dyn reads p and h, not the static model). The manifest's `rest_gate`,
    `rest_changes` and `residual_stage` become those of `nets`, and its format version the
    lowest that holds them. Everything is checked before the first file is written."""
    folder = Path(folder)
    manifest = read_manifest(folder)
    gate = _rest_gate(nets)
    if nets.rest_changes and "rest_physics" not in manifest:
        raise ValueError(
            f"{folder}: a SoftDECA trained on the rest physics needs its physics at prepare"
        )
    frame = {k for k in manifest["networks"] if k.startswith("softdeca.") and k != "softdeca.f_dyn"}
    modules = {k: m for k, m in _modules(nets).items() if k in frame}
    if set(modules) != frame:
        raise ValueError(
            f"{folder}: the bundle's SoftDECA has {sorted(frame)}, the model {sorted(modules)}"
        )
    deviations = replace_networks(folder, modules, record, errors)
    manifest = read_manifest(folder)
    for key in ("rest_gate", "rest_changes", "residual_stage"):
        manifest.pop(key, None)
    manifest |= {
        **({} if gate is None else {"rest_gate": gate}),
        **({"rest_changes": True} if nets.rest_changes else {}),
        **_residual_sizes(nets),
    }
    manifest["format_version"] = lowest_format_version(manifest)
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")
    return deviations


REPLACED = "; replaced since: "


def replaced_description(description: str, modules: Iterable[str], record: dict) -> str:
    """The bundle's description with its latest replacement named (the full history is in
    training.replaced): a description that says what trained the bundle stays true."""
    dataset = (record.get("dataset") or {}).get("name", "another dataset")
    what = f"{', '.join(sorted(modules))} ({record.get('model', 'a model')} on {dataset})"
    return f"{description.split(REPLACED)[0]}{REPLACED}{what}, see training.replaced"


def _add_file(
    folder: Path,
    manifest: dict[str, Any],
    key: str,
    data: bytes,
    entry: dict[str, Any],
) -> None:
    """Write one of a bundle's optional files and its manifest entry `key` (entry, with the
    file's sha256), and raise the format version to the one that entry needs (a bundle that
    already holds a later version's entry keeps that version)."""
    (folder / entry["file"]).write_bytes(data)
    manifest[key] = {**entry, "sha256": hashlib.sha256(data).hexdigest()}
    manifest["format_version"] = max(lowest_format_version(manifest), manifest["format_version"])
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")


def _read_file(
    folder: str | Path, manifest: dict[str, Any], key: str
) -> tuple[dict[str, Any], bytes] | None:
    """The manifest entry `key` and its file's bytes (checked against the entry's sha256), or
    None when the bundle has no such entry."""
    entry = manifest.get(key)
    if entry is None:
        return None
    data = (Path(folder) / entry["file"]).read_bytes()
    if hashlib.sha256(data).hexdigest() != entry["sha256"]:
        raise ValueError(f"{entry['file']}: sha256 does not match the manifest")
    return entry, data


def add_template_head(folder: str | Path, head: TemplateHead) -> None:
    """Add (or replace) a bundle's template head: template_head.bin and the manifest's
    `template_head` entry; the format version becomes 5."""
    folder = Path(folder)
    manifest = read_manifest(folder)
    t = manifest["template"]
    if head.neutral.shape[0] != t["head_vertices"] or head.shapes.shape[1] != t["skin_vertices"]:
        raise ValueError("the template head does not match the bundle's template sizes")
    _add_file(folder, manifest, "template_head", *template_head_file(head))


def read_bundle_template_head(folder: str | Path, manifest: dict[str, Any]) -> TemplateHead | None:
    """A bundle's template head, or None when it has none."""
    found = _read_file(folder, manifest, "template_head")
    return None if found is None else read_template_head(*found)


def add_rest_physics(folder: str | Path, head: RestHead) -> None:
    """Add (or replace) a bundle's physics at prepare: rest_head.bin and the manifest's
    `rest_physics` entry; the format version becomes at least 4."""
    folder = Path(folder)
    manifest = read_manifest(folder)
    if manifest["template"]["skin_vertices"] != head.skin_count:
        raise ValueError("the rest head's skin does not match the bundle's template")
    if "softdeca.f_w" not in manifest["networks"]:
        raise ValueError("the physics at prepare corrects SoftDECA: the bundle has no SoftDECA")
    _add_file(folder, manifest, "rest_physics", *rest_head_file(head))


def read_rest_physics(folder: str | Path, manifest: dict[str, Any]) -> RestHead | None:
    """A bundle's rest head, or None when it has none."""
    found = _read_file(folder, manifest, "rest_physics")
    if found is None:
        return None
    return read_rest_head(*found, manifest["template"]["skin_vertices"])


def read_rest_physics_bytes(folder: str | Path, manifest: dict[str, Any]) -> bytes | None:
    """A bundle's rest head file as it is stored (checked against its sha256), or None."""
    found = _read_file(folder, manifest, "rest_physics")
    return None if found is None else found[1]


def _rest_gate(nets: BundleNetworks) -> float | None:
    """The manifest's `rest_gate` (BundleNetworks.rest_gate), or None when it has none. The
    runtime folds the physics at prepare's share of the gated correction into the vertex
    stage's column of z's last entry, so a gated SoftDECA needs that stage."""
    gate = nets.rest_gate
    if gate is not None and (nets.softdeca is None or nets.softdeca.f_ph_v is None):
        raise ValueError("a SoftDECA with a rest gate needs its vertex stage (softdeca.f_ph_v)")
    return gate


def _residual_sizes(nets: BundleNetworks) -> dict[str, Any]:
    """The manifest's `residual_stage` entry (the sizes its networks' shapes use), if any."""
    stage = nets.softdeca.f_r if nets.softdeca is not None else None
    if stage is None:
        return {}
    sizes = stage.sizes
    return {
        "residual_stage": {
            "modes": sizes.modes + 1,
            "condition": stage.condition_size,
            "regions": int(stage.regions.shape[0]),
        }
    }


def _check_onnx(
    data: bytes, module: nn.Module, spec: dict[str, Any], example: tuple[torch.Tensor, ...]
) -> float:
    import onnxruntime as ort  # only where a bundle is run

    so = ort.SessionOptions()
    so.log_severity_level = 3
    sess = ort.InferenceSession(data, so, providers=["CPUExecutionProvider"])
    feeds = {t["name"]: x.numpy() for t, x in zip(spec["inputs"], example, strict=True)}
    got = sess.run(None, feeds)
    with torch.no_grad():
        want = module(*example)
    want = want if isinstance(want, tuple) else (want,)
    return float(max(np.abs(g - w.numpy()).max() for g, w in zip(got, want, strict=True)))


def pack_bundle(folder: str | Path) -> bytes:
    """The bundle folder as one uncompressed ustar archive (what softdeca_model_load_memory
    and a Unity TextAsset take)."""
    folder = Path(folder)
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w", format=tarfile.USTAR_FORMAT) as tar:
        for p in sorted(folder.iterdir()):
            if p.is_file():
                tar.add(p, arcname=p.name, recursive=False)
    return buf.getvalue()


# ---- reading ---------------------------------------------------------------------------------


def read_manifest(folder: str | Path) -> dict[str, Any]:
    """The manifest of a bundle folder or of its packed archive (pack_bundle)."""
    path = Path(folder)
    if path.is_file():
        with tarfile.open(path) as tar:
            member = tar.extractfile(MANIFEST) if MANIFEST in tar.getnames() else None
            if member is None:
                raise ValueError(f"{path}: an archive without {MANIFEST}: not a bundle")
            m = json.loads(member.read())
    else:
        m = json.loads((path / MANIFEST).read_text())
    if m.get("format") != FORMAT or m.get("format_version") not in FORMAT_VERSIONS:
        raise ValueError(
            f"{folder}: not a {FORMAT} bundle of version "
            f"{' or '.join(map(str, FORMAT_VERSIONS))} "
            f"({m.get('format')!r} version {m.get('format_version')!r})"
        )
    return m


def read_definition(folder: str | Path) -> TemplateDefinition:
    """The topology part of a bundle."""
    folder = Path(folder)
    m = read_manifest(folder)
    t = m["template"]
    tri = np.frombuffer((folder / SKIN_TRIANGLES_FILE).read_bytes(), dtype="<i4").reshape(-1, 3)
    bones = np.frombuffer((folder / NON_SKIN_BONES_FILE).read_bytes(), dtype=np.uint8)
    pts = m["landmarks"]["points"]
    return TemplateDefinition(
        name=t["name"],
        head_vertices=t["head_vertices"],
        skin_triangles=tri.astype(np.int32),
        skin_vertices=t["skin_vertices"],
        landmarks=LandmarkSet(
            names=tuple(p["name"] for p in pts),
            regions=tuple(p["region"] for p in pts),
            arkit_vertex=np.array([p["arkit_vertex"] for p in pts], dtype=np.int64),
            triangle=np.array([p["triangle"] for p in pts], dtype=np.int64),
            bary=np.array([p["bary"] for p in pts], dtype=np.float64),
            arkit_vertex_count=m["landmarks"]["arkit_vertex_count"],
        ),
        non_skin_bones=bones.copy(),
        jaw_anchors=np.array(m["non_skin"]["jaw_anchors"], dtype=np.int64),
    )


class OnnxNetworks:
    """A bundle's networks run by onnxruntime (the reference for trained bundles)."""

    def __init__(self, folder: str | Path) -> None:
        import onnxruntime as ort  # only where a bundle is run

        folder = Path(folder)
        self.manifest = read_manifest(folder)
        self.specs = tuple(ParameterSpec.from_dict(p) for p in self.manifest["parameters"])
        self.rest_head = read_rest_physics(folder, self.manifest)
        self.rest_gate: float | None = self.manifest.get("rest_gate")
        self.rest_changes: bool = bool(self.manifest.get("rest_changes", False))
        so = ort.SessionOptions()
        so.log_severity_level = 3
        self.sessions = {
            name: ort.InferenceSession(
                str(folder / spec["file"]), so, providers=["CPUExecutionProvider"]
            )
            for name, spec in self.manifest["networks"].items()
        }

    def has(self, model: Model) -> bool:
        return f"{model}.f_dyn" in self.sessions

    def _run(self, name: str, **inputs: np.ndarray) -> list[np.ndarray]:
        feeds = {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in inputs.items()}
        return self.sessions[name].run(None, feeds)

    def _columns(self, name: str, parameters: np.ndarray) -> np.ndarray:
        cols = self.manifest["networks"][name]["parameter_columns"]
        index = [[s.name for s in self.specs].index(c) for c in cols]
        return parameters[:, index]

    def identity(self, neutral_skin: np.ndarray) -> np.ndarray:
        return self._run("identity_encoder", neutral=neutral_skin[None])[0][0]

    def f_w(self, weights: np.ndarray) -> np.ndarray:
        return self._run("softdeca.f_w", weights=weights)[0]

    def f_l(self, offsets: np.ndarray) -> np.ndarray:
        return self._run("sparse.f_l", landmark_offsets=offsets)[0]

    def f_ph(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray:
        p = self._columns("softdeca.f_ph", parameters)
        return self._run("softdeca.f_ph", parameters=p, identity=identity[None])[0]

    def f_ph_v(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray:
        p = self._columns("sparse.f_ph_v", parameters)
        return self._run("sparse.f_ph_v", parameters=p, identity=identity[None])[0]

    def vertex_stage(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray | None:
        if "softdeca.f_ph_v" not in self.sessions:
            return None
        p = self._columns("softdeca.f_ph_v", parameters)
        return self._run("softdeca.f_ph_v", parameters=p, identity=identity[None])[0]

    def residual(self, parameters: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        if "softdeca.f_r_ph" not in self.sessions:
            return None
        p = self._columns("softdeca.f_r_ph", parameters)
        condition, modes = self._run("softdeca.f_r_ph", parameters=p)
        return condition, modes

    def residual_coefficients(self, weights: np.ndarray, condition: np.ndarray) -> np.ndarray:
        return self._run("softdeca.f_r_w", weights=weights, condition=condition)[0]

    def f_dyn(
        self, model: Model, parameters: np.ndarray, identity: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        name = f"{model}.f_dyn"
        a, b, g = self._run(
            name, parameters=self._columns(name, parameters), identity=identity[None]
        )
        return a, b, g
