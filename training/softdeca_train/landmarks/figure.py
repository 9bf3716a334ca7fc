"""The registration picture: ARKit's registered neutral and the template's S side by side and
overlaid, each with its landmarks, plus the residuals."""

from __future__ import annotations

import itertools
import os
from pathlib import Path
from typing import Any

import numpy as np

from softdeca_train import render as R
from softdeca_train.landmarks.definition import LandmarkDefinition
from softdeca_train.landmarks.pipeline import LandmarkRegistration, register_arkit_to_template
from softdeca_train.landmarks.report import build_report
from softdeca_train.landmarks.topology import face_normals, unique_edges, vertex_normals

REGION_COLORS: dict[str, str] = {
    "eye_right": "deepskyblue", "eye_left": "deepskyblue",
    "brow_right": "darkorange", "brow_left": "darkorange",
    "nose_bridge": "gold", "nose_base": "gold",
    "nose_ala_right": "yellowgreen", "nose_ala_left": "yellowgreen",
    "lip_outer": "crimson", "lip_inner": "magenta",
    "jaw": "mediumseagreen",
}  # fmt: skip
SKIN = "wheat"
ARKIT = "lightsteelblue"
PANEL = (700, 700)


def landmark_layers(
    points: np.ndarray,
    definition: LandmarkDefinition,
    radius: float = 0.0011,
    normals: np.ndarray | None = None,
    lift: float = 0.0004,
) -> list[R.Layer]:
    """One sphere layer per region colour plus the contours as polylines (lifted along
    `normals`, if given, so that lines on a surface are not hidden in it)."""
    layers: list[R.Layer] = []
    for color in dict.fromkeys(REGION_COLORS.get(g, "black") for g in definition.regions):
        mask = np.array([REGION_COLORS.get(g, "black") == color for g in definition.regions])
        layers.append(R.PointLayer(points[mask], color=color, radius=radius))
    segs = []
    for c in definition.contours:
        idx = list(c.landmarks) + ([c.landmarks[0]] if c.closed else [])
        segs += list(itertools.pairwise(idx))
    line_points = points if normals is None else points + lift * normals
    layers.append(R.LineLayer(line_points, np.asarray(segs), color="black", width=1.5))
    return layers


def _wireframe(vertices: np.ndarray, triangles: np.ndarray, lift: float) -> R.LineLayer:
    """Mesh edges lifted along the normals so they show on a surface they lie on."""
    v = vertices + lift * vertex_normals(vertices, triangles)
    e = unique_edges(triangles)
    return R.LineLayer(v, e, color="navy", width=0.8, opacity=0.8)


def _span(pairs: list[int]) -> str:
    contiguous = pairs == list(range(pairs[0], pairs[-1] + 1)) if pairs else False
    return f"{pairs[0]}-{pairs[-1]}" if contiguous else ",".join(map(str, pairs))


def render_registration_of(
    r: LandmarkRegistration, out_dir: str | os.PathLike[str], report: dict[str, Any] | None = None
) -> Path:
    """Write registration.png for a computed registration (and its report, if already built);
    returns its path."""
    out = Path(out_dir)
    t, a, d = r.template, r.arkit, r.definition
    reg = r.registration
    skin = R.MeshLayer(t.neutral, t.skin_triangles, color=SKIN)
    arkit = R.MeshLayer(
        reg.registered, a.triangles, color=ARKIT, show_edges=True, edge_color="slategray"
    )
    on_arkit = reg.registered[d.vertices]
    on_skin = r.landmarks.evaluate(t.neutral)
    skin_normals = face_normals(t.neutral, r.landmarks.corners)
    arkit_normals = vertex_normals(reg.registered, a.triangles)[d.vertices]
    ict68 = R.PointLayer(t.neutral[t.landmarks68], color="red", radius=0.0013)
    focus = R.Focus.of([arkit])
    settings = R.RenderSettings(size=PANEL)

    def panel(layers: list[R.Layer], view: str) -> np.ndarray:
        return R.render(layers, view, settings=settings, focus=focus)

    wire = _wireframe(reg.registered, a.triangles, lift=0.0004)
    overlay = [
        skin,
        wire,
        ict68,
        R.PointLayer(reg.registered[a.landmarks68], color="blue", radius=0.0013),
    ]
    before = [
        skin,
        R.MeshLayer(reg.aligned, a.triangles, color=ARKIT, opacity=0.55),
        ict68,
        R.PointLayer(reg.aligned[a.landmarks68], color="blue", radius=0.0013),
    ]
    images = [
        panel([arkit, *landmark_layers(on_arkit, d, normals=arkit_normals)], "front"),
        panel([skin, *landmark_layers(on_skin, d, normals=skin_normals)], "front"),
        panel(overlay, "front"),
        panel([skin, *landmark_layers(on_skin, d, normals=skin_normals)], "three_quarter"),
        panel(before, "side"),
        panel(overlay, "side"),
    ]
    labels = [
        f"ARKit neutral, registered: {len(d)} landmarks",
        "template S: the same landmarks (barycentric)",
        "overlay: S + ARKit edges; 68 pairs ICT red / ARKit blue",
        "template S, three-quarter",
        "after the similarity only (ARKit translucent)",
        "after the non-rigid step",
    ]
    rep = report or build_report(r)
    s, nr = rep["similarity"], rep["nonrigid"]
    sim_i, nr_c = s["residual_interior_51"], nr["residual_constrained"]
    held = nr["residual_constrained_held_out"].get("mean", float("nan"))
    footer = [
        f"68-pair residual (pairs {_span(s['pairs'])} in the similarity): similarity mean "
        f"{sim_i['mean']:.2f} / max {sim_i['max']:.2f} mm on interior pairs 17-67; after the "
        f"non-rigid step (pairs {_span(nr['pairs'])} constrained) mean {nr_c['mean']:.2f} / max "
        f"{nr_c['max']:.2f} mm, same pairs left out {held:.2f} mm mean.",
        "Jaw pairs 0-16 are different anatomy (ARKit's mask rim, ICT's frontal contour): "
        f"{nr['residual_jaw_17']['mean']:.1f} mm mean apart. Landmarks to S: mean "
        f"{rep['landmarks']['to_S']['mean']:.3f} / max {rep['landmarks']['to_S']['max']:.3f} mm.",
    ]
    path = out / "registration.png"
    R.tile(images, labels, path, R.TileSettings(columns=3, extra_labels=footer))
    return path


def render_registration(out_dir: str | os.PathLike[str]) -> Path:
    """Register ARKit's reference face to the template (default inputs) and write
    `out_dir/registration.png`; returns its path. The demo calls this."""
    return render_registration_of(register_arkit_to_template(progress=False), out_dir)
