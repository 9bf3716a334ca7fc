"""The contact sheet of a replay: chosen frames (rows) of every model the replay wrote (columns:
linear blendshapes, SoftDECA, SparseSoftDECA, ...), rendered with render.py."""

from __future__ import annotations

import json
from itertools import pairwise
from pathlib import Path

import numpy as np

from softdeca_train.render import Focus, MeshLayer, RenderSettings, TileSettings, render, tile
from softdeca_train.runtime.files import read_obj, read_pc2

LABELS = {
    "linear": "linear blendshapes",
    "softdeca": "SoftDECA",
    "softdeca_localised": "SoftDECA, localised change",
    "sparse": "SparseSoftDECA (landmarks)",
}


def pick_frames(caches: dict[str, np.ndarray], neutral: np.ndarray, count: int) -> list[int]:
    """Frames spread over the take, each the most expressive (largest linear displacement) of
    its segment."""
    lin = caches.get("linear", next(iter(caches.values())))
    motion = np.linalg.norm(lin - neutral[None].astype(np.float32), axis=2).max(axis=1)
    bounds = np.linspace(0, len(lin), count + 1).astype(int)
    return [int(a + np.argmax(motion[a:b])) for a, b in pairwise(bounds) if b > a]


def render_preview(replay: Path, frames: int = 4, size: int = 360) -> Path:
    replay = Path(replay)
    summary = json.loads((replay / "replay.json").read_text())
    neutral, triangles = read_obj(replay / "neutral.obj")
    caches = {name: read_pc2(Path(path)) for name, path in summary["point_caches"].items()}
    chosen = pick_frames(caches, neutral, frames)
    focus = Focus.of([MeshLayer(neutral, triangles)])
    settings = RenderSettings(size=(size, size))
    images, labels = [], []
    for f in chosen:
        for name, cache in caches.items():
            images.append(
                render(
                    [MeshLayer(cache[f], triangles)],
                    "three_quarter",
                    settings=settings,
                    focus=focus,
                )
            )
            labels.append(f"{LABELS.get(name, name)} - frame {f}")
    untrained = summary.get("untrained", False)
    timing = summary["timings"]
    notes = [
        "UNTRAINED: random-weight networks, not a model of physics" if untrained else "",
        f"take {Path(summary['take']).name}: {summary['frames']} frames, "
        f"{summary['face_lost_rows_skipped']} face-lost rows skipped; "
        f"landmarks from {summary['landmarks_from']}",
        "median ms/frame: "
        + ", ".join(f"{LABELS.get(k, k)} {v['median_ms']:.2f}" for k, v in timing.items()),
    ]
    out = replay / "preview.png"
    tile(
        images,
        labels,
        out,
        TileSettings(columns=len(caches), font_size=14, extra_labels=[n for n in notes if n]),
    )
    return out
