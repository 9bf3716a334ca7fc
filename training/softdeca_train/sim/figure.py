"""`simulate`'s side-by-side render: for a few frames, linear blendshapes | physics | the
distance between them as a heat map on the physics result (one colour scale for all rows)."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np

from softdeca_train.render import Focus, MeshLayer, RenderSettings, TileSettings, render, tile

# Heat ramp: light grey (no difference) -> yellow -> red (the scale's top).
_RAMP = np.array([[0.85, 0.85, 0.85], [1.0, 0.85, 0.1], [0.8, 0.0, 0.0]])


def heat_colors(distance: np.ndarray, top: float) -> np.ndarray:
    """(V,) distances -> (V, 3) RGB on the ramp, `top` and above at its red end."""
    t = np.clip(np.asarray(distance, np.float64) / max(top, 1e-12), 0.0, 1.0) * (len(_RAMP) - 1)
    k = np.minimum(t.astype(int), len(_RAMP) - 2)
    f = (t - k)[:, None]
    return _RAMP[k] * (1 - f) + _RAMP[k + 1] * f


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
    dist = {f: np.linalg.norm(physics[f] - linear[f], axis=1) for f in chosen}
    top = max(float(np.percentile(d, 99.5)) for d in dist.values())
    focus = Focus.of([MeshLayer(neutral, triangles)])
    settings = RenderSettings(size=(size, size))
    images, names = [], []
    for f in chosen:
        for title, layer in (
            ("linear blendshapes", MeshLayer(linear[f], triangles)),
            ("physics", MeshLayer(physics[f], triangles)),
            (
                "|physics - linear|",
                MeshLayer(physics[f], triangles, vertex_colors=heat_colors(dist[f], top)),
            ),
        ):
            images.append(render([layer], "three_quarter", settings=settings, focus=focus))
            names.append(f"{title} - {labels[f]}")
    footer = [
        f"heat map: grey 0 mm, yellow {top * 500:.2f} mm, red >= {top * 1e3:.2f} mm",
        *(notes or []),
    ]
    tile(images, names, path, TileSettings(columns=3, font_size=14, extra_labels=footer))
    return Path(path)
