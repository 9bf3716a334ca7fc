"""ARKit's reference face (../shared/arkit-reference): its face-mesh topology (1,220 vertices,
metres, face-anchor frame) with reference blendshapes, so that real blendshape weights drive
realistic landmark streams: geometry = neutral + sum_i w_i (shape_i - neutral). Read once from
the zip of OBJs into a small cache under .cache/streaming/.

The public archive holds 51 shapes and a Neutral.obj; it has no tongueOut, whose offset is
therefore zero. The neutral is the per-vertex median over the shapes (each moves only part of
the face); `neutral_file_deviation` says how far that lies from the bundled Neutral.obj."""

from __future__ import annotations

import hashlib
import os
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdeca_train.paths import cache_dir, default_arkit_reference_path
from softdeca_train.streaming.frame import ARKIT_VERTEX_COUNT
from softdeca_train.streaming.protocol import Profile
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

ARCHIVE = "ARKit_reference_blendshapes.zip"
LANDMARKS_FILE = "ARKit_landmarks68.txt"
CACHE_VERSION = 1
PROFILES = ("arkit68", "none")


def _obj_vertices(data: bytes) -> np.ndarray:
    v = np.array(
        [line.split()[1:4] for line in data.splitlines() if line.startswith(b"v ")],
        dtype=np.float64,
    )
    if v.shape != (ARKIT_VERTEX_COUNT, 3):
        raise ValueError(f"an ARKit reference OBJ has {len(v)} vertices, expected 1220")
    return v


def _build(archive: Path, landmarks: Path, target: Path) -> None:
    shapes: dict[str, np.ndarray] = {}
    neutral_file = None
    with zipfile.ZipFile(archive) as z:
        for name in z.namelist():
            stem = Path(name).stem
            if not name.endswith(".obj"):
                continue
            if stem.lower() == "neutral":
                neutral_file = _obj_vertices(z.read(name))
            elif stem in ARKIT_BLENDSHAPES:
                shapes[stem] = _obj_vertices(z.read(name))
            else:
                raise ValueError(f"{archive}: {name} is no ARKit blendshape")
    if len(shapes) < 3:
        raise ValueError(f"{archive}: fewer than three ARKit shapes")
    neutral = np.median(np.stack(list(shapes.values())), axis=0)
    deltas = np.stack(
        [shapes[n] - neutral if n in shapes else np.zeros_like(neutral) for n in ARKIT_BLENDSHAPES]
    )
    present = np.array([n in shapes for n in ARKIT_BLENDSHAPES])
    lm = np.array(landmarks.read_text().split(), dtype=np.int64)
    deviation = np.abs(neutral_file - neutral).max() if neutral_file is not None else np.nan
    tmp = target.with_name(target.stem + ".tmp.npz")
    np.savez(
        tmp,
        neutral=neutral,
        deltas=deltas,
        present=present,
        landmarks68=lm,
        neutral_file_deviation=np.float64(deviation),
    )
    os.replace(tmp, target)


@dataclass(frozen=True)
class ReferenceFace:
    neutral: np.ndarray  # (1220, 3) metres
    deltas: np.ndarray  # (52, 1220, 3): shape - neutral, canonical order; zero where absent
    present: np.ndarray  # (52,) bool: shapes the archive holds
    landmarks68: np.ndarray  # (68,) vertex indices, standard 68-point order
    neutral_file_deviation: float  # max |median - Neutral.obj| in metres; NaN without the file

    @classmethod
    def load(cls, folder: str | os.PathLike[str] | None = None) -> ReferenceFace:
        root = Path(folder) if folder else default_arkit_reference_path()
        archive, landmarks = root / ARCHIVE, root / LANDMARKS_FILE
        for f in (archive, landmarks):
            if not f.is_file():
                raise FileNotFoundError(f"{f} not found (set SOFTDECA_ARKIT_REFERENCE)")
        key = hashlib.sha256()
        for f in (archive, landmarks):
            key.update(f.read_bytes())
        target = (
            cache_dir()
            / "streaming"
            / f"arkit-reference-v{CACHE_VERSION}-{key.hexdigest()[:16]}.npz"
        )
        if not target.is_file():
            target.parent.mkdir(parents=True, exist_ok=True)
            _build(archive, landmarks, target)
        with np.load(target) as z:
            return cls(
                z["neutral"],
                z["deltas"],
                z["present"],
                z["landmarks68"],
                float(z["neutral_file_deviation"]),
            )

    def blend(self, weights: np.ndarray, vertices: np.ndarray | None = None) -> np.ndarray:
        """neutral + sum_i w_i delta_i, for all vertices or the given ones."""
        w = np.asarray(weights, dtype=np.float64)
        if vertices is None:
            return self.neutral + np.tensordot(w, self.deltas, axes=1)
        idx = np.asarray(vertices)
        return self.neutral[idx] + np.tensordot(w, self.deltas[:, idx], axes=1)

    def profile(self, name: str) -> Profile | None:
        """A landmark profile by name: "arkit68" (the 68-point scheme's vertices) or "none"."""
        if name == "arkit68":
            return Profile("arkit68", tuple(int(i) for i in self.landmarks68))
        if name == "none":
            return None
        raise ValueError(f"unknown landmark profile {name!r} (known: {', '.join(PROFILES)})")
