"""Avatar folders, as `python -m softdeca_train avatar` writes them:

<dir>/neutral.obj                  the neutral mesh; `o name` before each object's faces when
                                   it has several (skin, eyeball_left, ..., body)
<dir>/blendshapes/<rig name>.obj   each present shape as a whole mesh: the neutral's vertices
                                   in the same order, at their positions in the shape
<dir>/truth.npz                    the ground truth (mesh.py, AvatarTruth)
<dir>/user_face/...                optionally ARKit's reference face as a rig of its own: what
                                   `softdeca replay` blends with a take to stand in for a
                                   phone's tracking (plugin/cli/runtime_session.h)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from softdeca_train.mesh_files import read_obj, read_obj_groups, write_obj
from softdeca_train.sample_avatars.mesh import AvatarMesh, AvatarTruth

TRUTH_FILE = "truth.npz"


def write_avatar(
    mesh: AvatarMesh,
    folder: Path,
    user_face: AvatarMesh | None = None,
    truth: bool = True,
    progress: bool = False,
) -> Path:
    """The avatar folder of `mesh` (and of `user_face` in user_face/, without its truth)."""
    folder = Path(folder)
    groups = mesh.groups if len(mesh.groups) > 1 else None
    write_obj(folder / "neutral.obj", mesh.neutral, mesh.triangles, groups)
    shapes = mesh.shapes()
    for name, vertices in tqdm(shapes.items(), desc=folder.name, disable=not progress):
        write_obj(folder / "blendshapes" / f"{name}.obj", vertices)
    if truth:
        mesh.truth.save(folder / TRUTH_FILE)
    if user_face is not None:
        write_avatar(user_face, folder / "user_face", truth=False, progress=progress)
    return folder


@dataclass(frozen=True)
class AvatarFiles:
    """An avatar folder read back: what a user's rig gives a loader."""

    neutral: np.ndarray  # (N, 3)
    triangles: np.ndarray  # (F, 3) int64
    groups: list[tuple[str, int]]  # objects (name, triangle count), in triangle order
    shapes: dict[str, np.ndarray]  # file stem (the rig's name) -> (N, 3) positions
    truth: AvatarTruth | None


def read_avatar(folder: Path) -> AvatarFiles:
    folder = Path(folder)
    neutral, triangles, groups = read_obj_groups(folder / "neutral.obj")
    shapes = {}
    for path in sorted((folder / "blendshapes").glob("*.obj")):
        vertices, _ = read_obj(path)
        if vertices.shape != neutral.shape:
            raise ValueError(f"{path}: {len(vertices)} vertices, the neutral has {len(neutral)}")
        shapes[path.stem] = vertices
    truth_path = folder / TRUTH_FILE
    truth = AvatarTruth.load(truth_path) if truth_path.is_file() else None
    return AvatarFiles(neutral, triangles, groups, shapes, truth)
