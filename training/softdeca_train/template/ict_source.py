"""Read ICT-FaceKit (an upstream checkout, its FaceXModel folder, or the .tar.xz archive) once,
and keep a compact float32 cache so that later loads take milliseconds instead of parsing
~390 MB of OBJ text."""

from __future__ import annotations

import hashlib
import json
import os
import tarfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.paths import cache_dir, default_ict_path

CACHE_FORMAT = 1
CM_TO_M = 0.01
N_IDENTITY_MODES = 100
NEUTRAL = "generic_neutral_mesh.obj"
INDICES = "vertex_indices.json"


def _find_source(path: Path) -> Path:
    """The archive or the folder holding the OBJs, from any of the accepted layouts."""
    path = path.expanduser().resolve()
    if path.is_file() and path.name.endswith((".tar.xz", ".tar.gz", ".tar")):
        return path
    if path.is_dir():
        for cand in (path, path / "FaceXModel"):
            if (cand / NEUTRAL).is_file():
                return cand
        archives = sorted(path.glob("*.tar.xz"))
        if archives:
            return archives[0]
    raise FileNotFoundError(
        f"no ICT-FaceKit found at {path}: expected an ICT-FaceKit checkout, its FaceXModel/ "
        f"folder, or ICT-FaceKit-FaceXModel.tar.xz (set --ict or SOFTDECA_ICT)"
    )


def _iter_files(source: Path) -> Iterator[tuple[str, bytes]]:
    """(file name, bytes) for every file of FaceXModel, from a folder or an archive."""
    if source.is_dir():
        for f in sorted(source.iterdir()):
            if f.is_file():
                yield f.name, f.read_bytes()
        return
    with tarfile.open(source) as tar:
        for member in tar:
            if member.isfile() and "/FaceXModel/" in "/" + member.name:
                fh = tar.extractfile(member)
                if fh is not None:
                    yield Path(member.name).name, fh.read()


def _parse_vertices(data: bytes) -> np.ndarray:
    lines = [ln for ln in data.split(b"\n") if ln.startswith(b"v ")]
    flat = np.array(b" ".join(ln[2:] for ln in lines).split(), dtype=np.float64)
    return flat.reshape(len(lines), -1)[:, :3]


def _parse_polygons(data: bytes) -> np.ndarray:
    """Faces as an (F, 4) array of 0-based vertex indices, -1 in the 4th column for triangles."""
    polys = []
    for ln in data.split(b"\n"):
        if ln.startswith(b"f "):
            idx = [int(tok.split(b"/")[0]) - 1 for tok in ln.split()[1:]]
            if len(idx) not in (3, 4):
                raise ValueError(f"unsupported {len(idx)}-gon in ICT-FaceKit neutral mesh")
            polys.append(idx + [-1] * (4 - len(idx)))
    return np.asarray(polys, dtype=np.int32)


def _source_key(source: Path) -> str:
    st = source.stat()
    if source.is_dir():
        st = (source / NEUTRAL).stat()
    text = f"{CACHE_FORMAT}|{source}|{st.st_size}|{int(st.st_mtime)}"
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _build_cache(source: Path, target: Path) -> None:
    neutral = polygons = indices = None
    shapes: dict[str, np.ndarray] = {}
    total = sum(1 for f in source.iterdir() if f.is_file()) if source.is_dir() else None
    for name, data in tqdm(
        _iter_files(source), desc="reading ICT-FaceKit", unit="file", total=total, leave=False
    ):
        if name == NEUTRAL:
            neutral = _parse_vertices(data)
            polygons = _parse_polygons(data)
        elif name == INDICES:
            indices = json.loads(data)
        elif name.endswith(".obj"):
            shapes[name[:-4]] = _parse_vertices(data)
    if neutral is None or polygons is None or indices is None:
        raise FileNotFoundError(f"{source} lacks {NEUTRAL} or {INDICES}")
    expressions = list(indices["expressions"])
    missing = [e for e in expressions if e not in shapes]
    missing += [
        f"identity{k:03d}" for k in range(N_IDENTITY_MODES) if f"identity{k:03d}" not in shapes
    ]
    if missing:
        raise FileNotFoundError(f"{source} lacks shapes: {', '.join(missing[:5])} ...")
    # ICT modes and expressions are full meshes: store differences to the neutral, in metres.
    expr = np.stack([shapes[e] - neutral for e in expressions]) * CM_TO_M
    ident = np.stack([shapes[f"identity{k:03d}"] - neutral for k in range(N_IDENTITY_MODES)])
    # One temporary per process: worker processes that start together may all build it.
    tmp = target.with_suffix(f".{os.getpid()}.tmp.npz")
    np.savez(
        tmp,
        format=np.int32(CACHE_FORMAT),
        neutral=(neutral * CM_TO_M).astype(np.float64),
        polygons=polygons,
        expression_names=np.array(expressions),
        expression_deltas=expr.astype(np.float32),
        identity_modes=(ident * CM_TO_M).astype(np.float32),
        landmarks68=np.asarray(indices["idx_to_landmark_verts"], dtype=np.int32),
        source=np.array(str(source)),
    )
    os.replace(tmp, target)  # atomic: a killed run never leaves a half-written cache


def load_ict(path: str | os.PathLike[str] | None = None) -> dict[str, np.ndarray]:
    """The raw ICT-FaceKit arrays (metres), from the cache, building it on first use."""
    source = _find_source(Path(path) if path is not None else default_ict_path())
    target = cache_dir() / "ict" / f"ict-{_source_key(source)}.npz"
    if not target.is_file():
        target.parent.mkdir(parents=True, exist_ok=True)
        _build_cache(source, target)
    with np.load(target) as z:
        return {k: z[k] for k in z.files}
