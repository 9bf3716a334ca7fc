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
    rows = [(neutral, linear[f], physics[f], labels[f]) for f in chosen]
    return render_rows(path, triangles, rows, size, notes)


def render_rows(
    path: Path,
    triangles: np.ndarray,
    rows: list[tuple[np.ndarray, np.ndarray, np.ndarray, str]],
    size: int = 360,
    notes: list[str] | None = None,
) -> Path:
    """One row per (neutral, linear, physics, label): linear | physics | distance heat map,
    framed on the first row's neutral."""
    dist_mm = [1e3 * np.linalg.norm(p - lin, axis=1) for _, lin, p, _ in rows]
    top = max(float(np.percentile(d, 99.5)) for d in dist_mm)
    focus = Focus.of([MeshLayer(rows[0][0], triangles)])
    settings = RenderSettings(size=(size, size))
    images, names = [], []
    for (_, lin, phys, label), dist in zip(rows, dist_mm, strict=True):
        for title, layer in (
            ("linear blendshapes", MeshLayer(lin, triangles)),
            ("physics", MeshLayer(phys, triangles)),
            (
                "|physics - linear|",
                MeshLayer(
                    phys,
                    triangles,
                    scalars=dist,
                    cmap=HEAT_MAP,
                    clim=(0.0, top),
                    scalar_bar="mm",
                ),
            ),
        ):
            images.append(render([layer], "three_quarter", settings=settings, focus=focus))
            names.append(f"{title} - {label}")
    footer = [
        f"heat map: |physics - linear| per vertex, 0 to {top:.2f} mm (99.5th percentile of "
        "the rows; above it at the top colour)",
        *(notes or []),
    ]
    tile(images, names, path, TileSettings(columns=3, font_size=14, extra_labels=footer))
    return Path(path)
