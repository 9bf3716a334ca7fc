"""ARKit's reference face (Apple's face-mesh topology, 1,220 vertices, 2,304 triangles, metres,
face-anchor frame) with its reference blendshapes, read once from the zip of OBJs into a compact
cache. Neutral = per-vertex median over every shape in the archive; the shapes are put into the
canonical ARKit order; the boundary loops (outer rim, two eye rings, inner-lip ring) come from
the topology, and the 68 landmark vertex indices from ARKit_landmarks68.txt."""

from __future__ import annotations

import hashlib
import os
import re
import zipfile
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from softdeca_train.landmarks.topology import boundary_loops, edge_graph, graph_nearest
from softdeca_train.paths import cache_dir, default_arkit_reference_path
from softdeca_train.template.arkit import ARKIT_BLENDSHAPES

CACHE_FORMAT = 1
ARCHIVE = "ARKit_reference_blendshapes.zip"
LANDMARKS_FILE = "ARKit_landmarks68.txt"
N_VERTICES = 1220
N_TRIANGLES = 2304
EYE_RING = 24
LIP_RING = 36
# Standard 68-point order (Multi-PIE / iBUG): the eyes and the inner lips, subject's right first.
EYE_RIGHT_68 = tuple(range(36, 42))
EYE_LEFT_68 = tuple(range(42, 48))
LIP_INNER_68 = tuple(range(60, 68))
NEUTRAL_NAMES = ("neutral", "basis", "base", "rest")


def _key(text: str) -> str:
    return re.sub(r"[^a-z0-9]", "", text.lower())


def canonical_shape_name(stem: str) -> str | None:
    """The canonical ARKit name of a file stem ("eyeBlink_L", "EyeBlinkLeft", "eye_blink_left"
    all give "eyeBlinkLeft"; the library's rule for rigs' names, softdeca_blendshape_find_index),
    "neutral" for a rest shape, None if it is not an ARKit shape."""
    if _key(stem) in NEUTRAL_NAMES:
        return "neutral"
    # the compiled library, imported where it is needed: this package's readers load without it
    from softdeca_native import rig_blendshape_index

    index = rig_blendshape_index(stem)
    return ARKIT_BLENDSHAPES[index] if index >= 0 else None


def _parse_obj(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    verts, faces = [], []
    for line in data.splitlines():
        if line.startswith(b"v "):
            verts.append(line.split()[1:4])
        elif line.startswith(b"f "):
            faces.append([int(tok.split(b"/")[0]) - 1 for tok in line.split()[1:]])
    if any(len(f) != 3 for f in faces):
        raise ValueError("ARKit reference OBJ with non-triangle faces")
    return np.asarray(verts, dtype=np.float64), np.asarray(faces, dtype=np.int32)


def _find(path: Path) -> tuple[Path, Path]:
    path = path.expanduser().resolve()
    folder = path.parent if path.is_file() else path
    archive = path if path.is_file() else folder / ARCHIVE
    landmarks = folder / LANDMARKS_FILE
    for f in (archive, landmarks):
        if not f.is_file():
            raise FileNotFoundError(
                f"no {f.name} at {folder}: expected the ARKit reference folder with {ARCHIVE} "
                f"and {LANDMARKS_FILE} (set SOFTDECA_ARKIT_REFERENCE)"
            )
    return archive, landmarks


def _cache_key(archive: Path, landmarks: Path) -> str:
    parts = [str(CACHE_FORMAT)]
    for f in (archive, landmarks):
        st = f.stat()
        parts += [str(f), str(st.st_size), str(int(st.st_mtime))]
    return hashlib.sha256("|".join(parts).encode()).hexdigest()[:16]


def _read_landmarks(path: Path) -> np.ndarray:
    idx = np.asarray([int(tok) for tok in path.read_text().split()], dtype=np.int64)
    if idx.shape != (68,):
        raise ValueError(f"{path} holds {len(idx)} indices, expected 68")
    if idx.min() < 0 or idx.max() >= N_VERTICES:
        raise ValueError(f"{path}: landmark index outside [0, {N_VERTICES})")
    return idx


def _build_cache(archive: Path, landmarks: Path, target: Path) -> None:
    meshes: dict[str, np.ndarray] = {}
    triangles = None
    unknown = []
    with zipfile.ZipFile(archive) as z:
        for info in z.infolist():
            if info.is_dir() or not info.filename.lower().endswith(".obj"):
                continue
            stem = Path(info.filename).stem
            name = canonical_shape_name(stem)
            if name is None:
                unknown.append(stem)
                continue
            if name in meshes:
                raise ValueError(f"{archive}: two files map to ARKit shape {name}")
            v, f = _parse_obj(z.read(info))
            if v.shape != (N_VERTICES, 3) or f.shape != (N_TRIANGLES, 3):
                raise ValueError(
                    f"{info.filename}: {len(v)} vertices / {len(f)} triangles, "
                    f"expected ARKit's {N_VERTICES} / {N_TRIANGLES}"
                )
            if triangles is None:
                triangles = f
            elif not np.array_equal(triangles, f):
                raise ValueError(f"{info.filename}: triangles differ from the other shapes")
            meshes[name] = v
    if unknown:
        raise ValueError(f"{archive}: files that are no ARKit blendshape: {', '.join(unknown)}")
    if triangles is None or len(meshes) < 3:
        raise ValueError(f"{archive}: fewer than three ARKit shapes")
    # Each shape moves only part of the face, so the median over all of them is the rest pose
    # (and reproduces a bundled Neutral.obj exactly, which the loader reports).
    neutral = np.median(np.stack(list(meshes.values())), axis=0)
    present = np.array([n in meshes for n in ARKIT_BLENDSHAPES])
    shapes = np.stack([meshes.get(n, neutral) for n in ARKIT_BLENDSHAPES])
    file_dev = np.abs(meshes["neutral"] - neutral).max() if "neutral" in meshes else np.nan
    tmp = target.with_suffix(".tmp.npz")
    np.savez(
        tmp,
        format=np.int32(CACHE_FORMAT),
        neutral=neutral,
        triangles=triangles,
        shapes=shapes,
        present=present,
        landmarks68=_read_landmarks(landmarks),
        neutral_file_deviation=np.float64(file_dev),
        source=np.array(str(archive)),
    )
    os.replace(tmp, target)


@dataclass(frozen=True)
class FaceLoops:
    """Boundary loops of ARKit's face mesh, ordered. Eye rings and the inner-lip ring start at
    the 68-point scheme's first point of that feature (subject's right corner) and run like it
    (over the upper lid / upper lip first)."""

    outer: np.ndarray
    eye_right: np.ndarray
    eye_left: np.ndarray
    lip_inner: np.ndarray


@dataclass(frozen=True)
class ArkitFace:
    """ARKit's reference face. `shapes` are full meshes at weight 1 in canonical ARKit order;
    a shape the archive lacks (the public set has no tongueOut) equals the neutral and is
    marked False in `present`."""

    neutral: np.ndarray  # (1220, 3)
    triangles: np.ndarray  # (2304, 3) int32
    shapes: np.ndarray  # (52, 1220, 3)
    present: np.ndarray  # (52,) bool
    landmarks68: np.ndarray  # (68,) vertex indices, standard 68-point order
    neutral_file_deviation: float  # max |median - Neutral.obj| in metres, NaN without the file

    @classmethod
    def load(cls, path: str | os.PathLike[str] | None = None) -> ArkitFace:
        archive, landmarks = _find(Path(path) if path else default_arkit_reference_path())
        target = cache_dir() / "arkit" / f"arkit-{_cache_key(archive, landmarks)}.npz"
        if not target.is_file():
            target.parent.mkdir(parents=True, exist_ok=True)
            _build_cache(archive, landmarks, target)
        with np.load(target) as z:
            return cls(
                neutral=z["neutral"],
                triangles=z["triangles"],
                shapes=z["shapes"],
                present=z["present"],
                landmarks68=z["landmarks68"],
                neutral_file_deviation=float(z["neutral_file_deviation"]),
            )

    @property
    def deltas(self) -> np.ndarray:
        return self.shapes - self.neutral

    def blend(self, weights: np.ndarray) -> np.ndarray:
        """ARKit face geometry for 52 weights: neutral + sum_i w_i (shape_i - neutral)."""
        w = np.asarray(weights, dtype=np.float64)
        if w.shape != (len(ARKIT_BLENDSHAPES),):
            raise ValueError(f"expected {len(ARKIT_BLENDSHAPES)} ARKit weights, got {w.shape}")
        return self.neutral + np.tensordot(w, self.deltas, axes=1)

    @cached_property
    def loops(self) -> FaceLoops:
        loops = boundary_loops(self.triangles)
        if len(loops) != 4:
            raise ValueError(
                f"ARKit face mesh has {len(loops)} boundary loops, expected 4 "
                f"(outer rim, two eyes, mouth)"
            )
        lm = self.landmarks68

        def holding(ids: tuple[int, ...]) -> np.ndarray:
            hits = [lp for lp in loops[1:] if np.isin(lm[list(ids)], lp).all()]
            if len(hits) != 1:
                raise ValueError(f"no single boundary loop holds 68-landmarks {ids}")
            return hits[0]

        eye_r, eye_l = holding(EYE_RIGHT_68), holding(EYE_LEFT_68)
        lip = next(lp for lp in loops[1:] if lp is not eye_r and lp is not eye_l)
        # The inner-lip landmarks lie a few mm outside the ring, on the lip contact line, and
        # the closed ring's upper and lower halves nearly coincide: find the ring's right
        # corner (68-point 60) and upper side (61) by distance along the surface.
        graph = edge_graph(self.neutral, self.triangles)
        corner = graph_nearest(graph, int(lm[60]), lip)
        upper = graph_nearest(graph, int(lm[61]), lip)
        return FaceLoops(
            outer=loops[0],
            eye_right=_start(eye_r, int(lm[36]), int(lm[37])),
            eye_left=_start(eye_l, int(lm[42]), int(lm[43])),
            lip_inner=_start(lip, corner, upper),
        )


def _start(loop: np.ndarray, start: int, toward: int) -> np.ndarray:
    """Rotate a loop to begin at `start` and run so that `toward` comes in its first half."""
    loop = np.roll(loop, -int(np.nonzero(loop == start)[0][0]))
    forward = int(np.nonzero(loop == toward)[0][0]) < len(loop) / 2
    return loop if forward else np.r_[loop[:1], loop[1:][::-1]]

    def _start(self, loop: np.ndarray, start: int, toward: int | None) -> np.ndarray:
        """Rotate a loop to begin at `start` and run so that `toward` (or, if None, the
        upper side, +y) comes first."""
        loop = np.roll(loop, -int(np.nonzero(loop == start)[0][0]))
        if toward is not None:
            forward = int(np.nonzero(loop == toward)[0][0]) < len(loop) / 2
        else:
            half = len(loop) // 2
            y = self.neutral[loop, 1]
            forward = y[1:half].mean() > y[half + 1 :].mean()
        return loop if forward else np.r_[loop[:1], loop[1:][::-1]]
