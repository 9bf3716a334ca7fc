"""`simulate`'s side-by-side render: for a few frames, linear blendshapes | physics | the
distance between them as a heat map on the physics result (one colour scale for all rows,
render.py's per-vertex scalars)."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np

from softdeca_train.render import Focus, MeshLayer, RenderSettings, TileSettings, render, tile

HEAT_MAP = "YlOrRd"  # pale yellow (no difference) to dark red (the scale's top)


def pick_frames(linear: list[np.ndarray], physics: list[np.ndarray], count: int) -> list[int]:
    """The frames where physics and linear differ most, one per segment of the sequence."""
    d = np.array(
        [np.linalg.norm(p - lin, axis=1).mean() for lin, p in zip(linear, physics, strict=True)]
    )
    bounds = np.linspace(0, len(d), min(count, len(d)) + 1).astype(int)
    return [int(a + np.argmax(d[a:b])) for a, b in pairwise(bounds) if b > a]


def render_comparison(
    path: Path,
    neutral: np.ndarray,
    triangles: np.ndarray,
    linear: list[np.ndarray],
    physics: list[np.ndarray],
    labels: list[str],
    frames: int = 3,
    size: int = 360,
    notes: list[str] | None = None,
) -> Path:
    chosen = pick_frames(linear, physics, frames)
    dist_mm = {f: 1e3 * np.linalg.norm(physics[f] - linear[f], axis=1) for f in chosen}
    top = max(float(np.percentile(d, 99.5)) for d in dist_mm.values())
    focus = Focus.of([MeshLayer(neutral, triangles)])
    settings = RenderSettings(size=(size, size))
    images, names = [], []
    for f in chosen:
        for title, layer in (
            ("linear blendshapes", MeshLayer(linear[f], triangles)),
            ("physics", MeshLayer(physics[f], triangles)),
            (
                "|physics - linear|",
                MeshLayer(
                    physics[f],
                    triangles,
                    scalars=dist_mm[f],
                    cmap=HEAT_MAP,
                    clim=(0.0, top),
                    scalar_bar="mm",
                ),
            ),
        ):
            images.append(render([layer], "three_quarter", settings=settings, focus=focus))
            names.append(f"{title} - {labels[f]}")
    footer = [
        f"heat map: |physics - linear| per vertex, 0 to {top:.2f} mm (99.5th percentile of "
        "the rows; above it at the top colour)",
        *(notes or []),
    ]
    tile(images, names, path, TileSettings(columns=3, font_size=14, extra_labels=footer))
    return Path(path)
