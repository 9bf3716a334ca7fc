"""Avatar folders and point caches of `softdeca replay` (plugin/cli/runtime_session.h):

<dir>/neutral.obj                   the avatar's neutral head in template topology
<dir>/blendshapes/<name>.obj        its 52 ARKit shapes as full meshes (missing: no motion)
<dir>/user_face/neutral.obj         optional ARKit face mesh (1,220 vertices) and its shapes:
<dir>/user_face/blendshapes/*.obj   blended with a take it stands in for a phone's tracking
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from softdeca_train.template.arkit import ARKIT_BLENDSHAPES


def write_obj(path: Path, vertices: np.ndarray, triangles: np.ndarray | None = None) -> Path:
    """Vertices (and 0-based triangles) as OBJ text; fast enough for 52 shapes of 26,719."""
    path.parent.mkdir(parents=True, exist_ok=True)
    v = np.asarray(vertices, dtype=np.float64)
    lines = ["v %.6f %.6f %.6f" % tuple(p) for p in v]  # noqa: UP031 - bulk formatting
    if triangles is not None:
        lines += ["f %d %d %d" % tuple(t) for t in np.asarray(triangles) + 1]  # noqa: UP031
    path.write_text("\n".join(lines) + "\n")
    return path


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    verts, tris = [], []
    for line in Path(path).read_text().splitlines():
        if line.startswith("v "):
            verts.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            idx = [int(t.split("/")[0]) - 1 for t in line.split()[1:]]
            tris += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
    return np.array(verts), np.array(tris, dtype=np.int64).reshape(-1, 3)


def write_rig(
    folder: Path,
    neutral: np.ndarray,
    deltas: np.ndarray,
    triangles: np.ndarray | None,
    progress: bool = False,
) -> None:
    """neutral.obj and blendshapes/<name>.obj (shapes that move nothing are left out)."""
    from tqdm import tqdm

    write_obj(folder / "neutral.obj", neutral, triangles)
    shapes = zip(ARKIT_BLENDSHAPES, deltas, strict=True)
    for name, d in tqdm(shapes, total=len(deltas), desc=folder.name, disable=not progress):
        if np.any(d != 0):
            write_obj(folder / "blendshapes" / f"{name}.obj", neutral + d)


def write_identity_avatar(seed: int, out: Path, ict: str | None = None) -> Path:
    """The avatar of the ICT identity `seed` (template blendshapes, mapped to ARKit's 52),
    with ARKit's reference face as the user_face rig."""
    from softdeca_train.landmarks import ArkitFace
    from softdeca_train.template import Template

    t = Template.load(ict)
    neutral = t.identity_neutral(t.sample_identity(seed))
    deltas = (t.arkit_to_ict.T @ t.expression_deltas.reshape(len(t.expression_names), -1)).reshape(
        52, -1, 3
    )
    write_rig(out, neutral, deltas, t.triangles, progress=True)
    face = ArkitFace.load()
    write_rig(out / "user_face", face.neutral, face.deltas, face.triangles, progress=True)
    return out


def read_pc2(path: Path) -> np.ndarray:
    """A PC2 point cache as (frames, points, 3) float32."""
    data = Path(path).read_bytes()
    sig, _version, points, _start, _rate, frames = struct.unpack("<12siiffi", data[:32])
    if sig != b"POINTCACHE2\0":
        raise ValueError(f"{path}: not a PC2 point cache")
    return np.frombuffer(data, dtype="<f4", offset=32, count=frames * points * 3).reshape(
        frames, points, 3
    )
