"""Pictures of the layered head model: cut-away views of its nested layers, and of several
sampled identities. Used by the demo."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from softdeca_train.lhm.fit import fit_lhm
from softdeca_train.lhm.model import JAW, LayeredHeadModel
from softdeca_train.render import (
    ClipPlane,
    Focus,
    MeshLayer,
    RenderSettings,
    TileSettings,
    render,
    tile,
)
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN
from softdeca_train.template.plausibility import face_measures

SKIN, WRAP, MUSCLE, SKULL, JAW_COLOR, TEETH = (
    (0.87, 0.70, 0.58),
    (0.55, 0.75, 0.95),
    (0.80, 0.22, 0.20),
    (0.93, 0.91, 0.82),
    (0.95, 0.75, 0.35),
    (0.98, 0.98, 0.95),
)


def _skull_layers(model: LayeredHeadModel, clip: ClipPlane | None) -> list[MeshLayer]:
    """The skull wrap split into cranium and jaw triangles (a triangle is jaw if all of its
    vertices are)."""
    jaw = (model.skull_labels[model.wrap_triangles] == JAW).all(axis=1)
    return [
        MeshLayer(model.skull_wrap, model.wrap_triangles[~jaw], SKULL, clip=clip),
        MeshLayer(model.skull_wrap, model.wrap_triangles[jaw], JAW_COLOR, clip=clip),
    ]


def layer_stack(
    template: Template,
    head: np.ndarray,
    model: LayeredHeadModel,
    clip: ClipPlane | None,
    wrap_opacity: float = 0.35,
) -> list[MeshLayer]:
    """S, teeth and eyes, and the three wraps, outside in."""
    rigid = [
        template.component_triangles(c)
        for c in ("teeth_upper", "teeth_lower", "eyeball_left", "eyeball_right")
    ]
    return [
        MeshLayer(head, template.skin_triangles, SKIN, clip=clip),
        MeshLayer(head, np.vstack(rigid), TEETH, clip=clip),
        MeshLayer(
            model.skin_wrap,
            model.wrap_triangles,
            WRAP,
            opacity=wrap_opacity,
            clip=clip,
            show_edges=True,
            edge_color=(0.3, 0.45, 0.7),
        ),
        MeshLayer(model.muscle_wrap, model.wrap_triangles, MUSCLE, clip=clip),
        *_skull_layers(model, clip),
    ]


def render_layers(
    template: Template, model: LayeredHeadModel, path: str | Path, head: np.ndarray | None = None
) -> Path:
    """Three views of one head's nested layers: a sagittal cut (side), a transverse cut at the
    eyes (top) and the skull and muscle seen through the translucent skin wrap."""
    head = template.neutral if head is None else head
    c = model.center
    sagittal = ClipPlane((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))  # removes the subject's left half
    eye_y = float(head[template.landmarks68[[36, 45]], 1].mean())
    transverse = ClipPlane((0.0, eye_y, 0.0), (0.0, 1.0, 0.0))
    settings = RenderSettings(size=(640, 700))
    layers_s = layer_stack(template, head, model, sagittal)
    focus = Focus.of([MeshLayer(head[:N_SKIN], template.skin_triangles)])
    images = [
        render(layers_s, "side", settings=settings, focus=focus),
        render(
            layer_stack(template, head, model, transverse), "top", settings=settings, focus=focus
        ),
        render(
            [
                MeshLayer(model.skin_wrap, model.wrap_triangles, WRAP, opacity=0.25),
                MeshLayer(model.muscle_wrap, model.wrap_triangles, MUSCLE, opacity=0.35),
                *_skull_layers(model, None),
            ],
            "three_quarter",
            settings=settings,
            focus=focus,
        ),
    ]
    n_tets = len(model.soft_tets) + len(model.muscle_tets)
    labels = [
        "sagittal cut (seen from the left)",
        "cut at eye height (from above)",
        "skull (cranium/jaw) and muscle wrap",
    ]

    footer = [
        f"skin: S (tan), skin wrap (blue), muscle wrap (red), skull wrap (ivory, jaw "
        f"orange); {model.n_wrap} vertices per wrap, {n_tets} tets; centre "
        f"{np.round(c * 100, 1).tolist()} cm"
    ]
    tile(images, labels, path, TileSettings(extra_labels=footer))
    return Path(path)


def render_identities(template: Template, seeds: list[int], path: str | Path) -> Path:
    """Sampled identities side by side: the face, and its layers in a sagittal cut."""
    images, labels = [], []
    settings = RenderSettings(size=(480, 560))
    sagittal = ClipPlane((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    for seed in seeds:
        h = template.sample_identity(seed)
        head = template.identity_neutral(h)
        model = fit_lhm(template, h)
        focus = Focus.of([MeshLayer(head[:N_SKIN], template.skin_triangles)])
        whole = [MeshLayer(head, template.triangles, SKIN)]
        images.append(render(whole, "three_quarter", settings=settings, focus=focus))
        images.append(
            render(
                layer_stack(template, head, model, sagittal), "side", settings=settings, focus=focus
            )
        )
        m = face_measures(head, template.landmarks68)
        text = f"seed {seed}: eyes {m['biocular']:.0f} mm, face {m['nasion_menton']:.0f} mm"
        labels += [text, f"seed {seed}: layers"]

    tile(images, labels, path, TileSettings(columns=2 * min(len(seeds), 3)))
    return Path(path)
