"""The contact sheet of a replay: chosen frames (rows) of every model the replay wrote (columns:
linear blendshapes, SoftDECA, SparseSoftDECA, SoftDECA with the localised change), and, when
asked, the physics φ† itself on those frames (preview_physics.py), with the localised change
too when the replay has one, rendered with render.py, framed on the face.

A correction of a few millimetres is invisible in a shaded render, so the models' columns are
coloured by how far each vertex lies from the linear blendshapes of the same frame, and the
localised columns by how far they lie from the same model without the change (what the
localised change does): white 0 to dark red at the column's scale (its 99.5th percentile over
the shown frames; the physics' and SoftDECA's localised columns share one), written in the
column's labels.
"""

from __future__ import annotations

import json
from itertools import pairwise
from pathlib import Path

import numpy as np

from softdeca_train.controls.metrics import response_error
from softdeca_train.mesh_files import read_obj, read_pc2
from softdeca_train.models.bundle import read_manifest
from softdeca_train.parameters import ParameterSpec
from softdeca_train.render import Focus, MeshLayer, RenderSettings, TileSettings, render, tile
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN

LABELS = {
    "linear": "linear blendshapes",
    "physics": "physics (static)",
    "physics_localised": "physics, localised change",
    "softdeca": "SoftDECA",
    "softdeca_localised": "SoftDECA, localised change",
    "sparse": "SparseSoftDECA (landmarks)",
}
COLORMAP = "Reds"  # 0: near white, the column's scale: dark red


def pick_frames(caches: dict[str, np.ndarray], neutral: np.ndarray, count: int) -> list[int]:
    """Frames spread over the take, each the most expressive (largest linear displacement) of
    its segment."""
    lin = caches.get("linear", next(iter(caches.values())))
    motion = np.linalg.norm(lin - neutral[None].astype(np.float32), axis=2).max(axis=1)
    bounds = np.linspace(0, len(lin), count + 1).astype(int)
    return [int(a + np.argmax(motion[a:b])) for a, b in pairwise(bounds) if b > a]


def face_focus(neutral: np.ndarray, centred: bool = False) -> Focus:
    """The box of the face: the extent (width, chin to forehead) of the vertices within 5 cm
    of the most forward point (the nose tip), 10 cm deep so that the cheeks are in frame.
    `centred`: the origin lies between the eyes (to_view), and only what lies within 15 cm of
    it is the head (a body's hands or toes may reach further forward than the nose)."""
    if centred:
        neutral = neutral[np.linalg.norm(neutral, axis=1) < 0.15]
    z = neutral[:, 2]
    front = neutral[z > z.max() - 0.05]
    lo, hi = front.min(axis=0), front.max(axis=0)
    lo[2] = z.max() - 0.10
    return Focus(tuple(float(x) for x in lo), tuple(float(x) for x in hi))


def to_view(summary: dict, points: np.ndarray) -> np.ndarray:
    """A user's avatar (`softdeca replay` of a fit writes each part in its own coordinates, units
    and axes) in metres in the subject's frame (+X left, +Y up, +Z out of the face, the origin
    between the eyes), by the replay's `avatar_mesh.view`; the template's heads are in it already.
    `points`: (..., N, 3)."""
    view = (summary.get("avatar_mesh") or {}).get("view")
    if not view:
        return points
    out = np.empty(points.shape, dtype=np.float32)
    for part in view["parts"]:
        a, n = int(part["first_vertex"]), int(part["vertex_count"])
        m = np.asarray(part["to_view"], dtype=np.float64).reshape(3, 4)
        p = points[..., a : a + n, :].astype(np.float64)
        out[..., a : a + n, :] = p @ m[:, :3].T + m[:, 3]
    return out


def _with_physics(
    caches: dict[str, np.ndarray], chosen: list[int], columns: dict[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """The physics column after the linear one, the localised physics before the localised
    SoftDECA; only the chosen frames are filled."""
    out: dict[str, np.ndarray] = {}
    for name, cache in caches.items():
        if name == "softdeca_localised" and "physics_localised" in columns:
            out["physics_localised"] = np.zeros_like(cache)
            out["physics_localised"][chosen] = columns["physics_localised"]
        out[name] = cache
        if name == "linear":
            out["physics"] = np.zeros_like(cache)
            out["physics"][chosen] = columns["physics"]
    return out


def render_preview(
    replay: Path,
    frames: int = 4,
    size: int = 360,
    physics_seed: int | None = None,
    ict: str | None = None,
) -> Path:
    """`physics_seed`: simulate the shown frames for the ICT identity the avatar was made
    from, and show the take's widest-open mouth among them (preview.json: lip openings)."""
    replay = Path(replay)
    summary = json.loads((replay / "replay.json").read_text())
    neutral, triangles = read_obj(replay / "neutral.obj")
    neutral = to_view(summary, neutral)
    caches = {
        name: to_view(summary, read_pc2(Path(path)))
        for name, path in summary["point_caches"].items()
    }
    chosen = pick_frames(caches, neutral, frames)
    first = int(summary.get("first_frame", 0))
    physics_notes: list[str] = []
    if physics_seed is not None:
        caches, chosen, physics_notes = _add_physics(
            replay, summary, caches, chosen, first, physics_seed, ict
        )
    focus = face_focus(neutral, centred=bool((summary.get("avatar_mesh") or {}).get("view")))
    settings = RenderSettings(size=(size, size), margin=1.15)

    def distance_mm(a: str, b: str, f: int) -> np.ndarray:
        return np.linalg.norm(caches[a][f] - caches[b][f], axis=1) * 1e3

    # Colour scales per column: the 99.5th percentile over the shown frames.
    ref = {
        "physics": "linear",
        "softdeca": "linear",
        "sparse": "linear",
        "physics_localised": "physics",
        "softdeca_localised": "softdeca",
    }
    ref = {k: v for k, v in ref.items() if k in caches and v in caches}
    scale = {
        k: float(np.percentile(np.concatenate([distance_mm(k, v, f) for f in chosen]), 99.5))
        for k, v in ref.items()
    }
    # The localised change's physics and model share one scale: equal colours, equal motion.
    together = [k for k in ("physics_localised", "softdeca_localised") if k in scale]
    for k in together:
        scale[k] = max(scale[j] for j in together)

    images, labels = [], []
    for f in chosen:
        for name, cache in caches.items():
            layer, note = MeshLayer(cache[f], triangles), ""
            if name in ref:
                layer.scalars = distance_mm(name, ref[name], f)
                layer.cmap, layer.clim = COLORMAP, (0.0, max(scale[name], 1e-9))
                note = f"\nred: {scale[name]:.3g} mm from {LABELS[ref[name]]}"
            images.append(
                render(
                    [layer],
                    "three_quarter",
                    settings=settings,
                    focus=focus,
                )
            )
            labels.append(f"{LABELS.get(name, name)}, frame {first + f}{note}")
    untrained = summary.get("untrained", False)
    timing = summary["timings"]
    localised = summary.get("localised") or ""
    notes = [
        "UNTRAINED: random-weight networks, not a model of physics" if untrained else "",
        f"take {Path(summary['take']).name}: frames {first} to {first + summary['frames'] - 1}, "
        f"{summary['face_lost_rows_skipped']} face-lost rows skipped; "
        f"landmarks from {summary['landmarks_from']}; dynamics "
        + ("on" if summary.get("dynamics") else "off"),
        "colour: distance per vertex to the model named in the label, white 0 to dark red at "
        "the column's scale (99.5th percentile of the shown frames; the two localised columns "
        "share theirs)"
        if ref
        else "",
        f"localised change: {localised} ({summary.get('localised_faces', 0)} skin faces)"
        if localised
        else "",
        "median ms/frame: "
        + ", ".join(f"{LABELS.get(k, k)} {v['median_ms']:.2f}" for k, v in timing.items()),
        *physics_notes,
    ]
    out = replay / "preview.png"
    tile(
        images,
        labels,
        out,
        TileSettings(
            columns=len(caches),
            font_size=14,
            label_height=42,
            extra_labels=[n for n in notes if n],
        ),
    )
    return out


def _add_physics(
    replay: Path,
    summary: dict,
    caches: dict[str, np.ndarray],
    chosen: list[int],
    first: int,
    seed: int,
    ict: str | None,
) -> tuple[dict[str, np.ndarray], list[int], list[str]]:
    """The physics column, the widest-open mouth among the rows (it replaces the row of its
    segment), preview.json with every column's lip opening, and the sheet's notes."""
    # the physics needs the compiled softdeca_native; the sheet without it does not
    from softdeca_train.host.preview_physics import (
        lip_openings_mm,
        parse_changes,
        simulate_column,
        widest_open_frame,
    )

    template = Template.load(ict)
    lin = caches["linear"]
    wide = widest_open_frame(lin, template)
    segment = int(np.searchsorted(np.linspace(0, len(lin), len(chosen) + 1), wide, "right")) - 1
    chosen = sorted({*chosen[:segment], wide, *chosen[segment + 1 :]})
    base = parse_changes(summary.get("set") or "")
    settings = {"physics": base}
    if summary.get("localised") and "softdeca_localised" in caches:
        settings["physics_localised"] = base + parse_changes(summary["localised"])
    specs = tuple(
        ParameterSpec.from_dict(p) for p in read_manifest(summary["bundle"])["parameters"]
    )
    simulated = dict(
        zip(
            settings,
            simulate_column(
                Path(summary["take"]),
                first,
                chosen,
                lin,
                template,
                seed,
                list(settings.values()),
                specs,
            ),
            strict=True,
        )
    )
    caches = _with_physics(caches, chosen, {k: c.heads for k, c in simulated.items()})
    openings = {
        name: [round(float(x), 3) for x in lip_openings_mm(c[chosen], template)]
        for name, c in caches.items()
    }
    report: dict[str, object] = {
        "frames": [first + f for f in chosen],
        "widest_open_frame": first + wide,
        "identity_seed": seed,
        "lip_opening_mm": openings,
        "physics_failures": {k: c.failures for k, c in simulated.items()},
        "physics_seconds": {k: round(c.seconds, 1) for k, c in simulated.items()},
    }
    row = chosen.index(wide)
    failing = sum(bool(f) for c in simulated.values() for f in c.failures)
    described = summary.get("set") or "default parameters"
    notes = [
        f"physics: the simulation, static, LHM level 3, {described}, collisions on, "
        f"ICT identity seed {seed}; {failing} of {len(chosen) * len(simulated)} simulated "
        "frames fail a sanity bound",
        f"lip opening at frame {first + wide} (the take's widest-open mouth): "
        + ", ".join(f"{LABELS.get(k, k)} {v[row]:.1f} mm" for k, v in openings.items()),
    ]
    if "physics_localised" in simulated:
        response = localised_response(caches, chosen)
        report["localised"] = {"change": summary["localised"], **response}
        notes.append(
            "localised change on the shown frames: the physics moves the skin by up to "
            f"{max(response['physics_max_mm']):.2f} mm, SoftDECA by up to "
            f"{max(response['softdeca_max_mm']):.2f} mm; response error "
            f"|dSoftDECA - dphysics| / |dphysics| {_median(response['response_error'])} "
            "(median of the frames; SoftDECA as replayed, the physics static)"
        )
    (replay / "preview.json").write_text(json.dumps(report, indent=1))
    return caches, chosen, notes


def _median(values: list[float | None]) -> str:
    known = [v for v in values if v is not None]
    return f"{np.median(known):.2f}" if known else "undefined (the physics does not move)"


def localised_response(caches: dict[str, np.ndarray], chosen: list[int]) -> dict[str, list]:
    """Per shown frame, over the skin: how far the localised change moves the physics and
    SoftDECA (largest vertex distance, mm) and the response error |dm - dp| / |dp| as the
    controls gallery measures a control (None where the physics does not move)."""
    out: dict[str, list] = {"physics_max_mm": [], "softdeca_max_mm": [], "response_error": []}
    for f in chosen:
        dp = (caches["physics_localised"][f] - caches["physics"][f])[:N_SKIN].astype(np.float64)
        dm = (caches["softdeca_localised"][f] - caches["softdeca"][f])[:N_SKIN].astype(np.float64)
        out["physics_max_mm"].append(round(1e3 * float(np.linalg.norm(dp, axis=1).max()), 4))
        out["softdeca_max_mm"].append(round(1e3 * float(np.linalg.norm(dm, axis=1).max()), 4))
        error = response_error(dm, dp)
        out["response_error"].append(None if error is None else round(error, 4))
    return out
