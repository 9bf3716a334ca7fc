"""A conforming tet mesh of the layered head model's tissue (fTetWild, through pytetwild).

The LHM's prisms follow its radial wraps: over the mouth and the chin they are long needles
(aspect ratio up to 137, dihedral angles down to 0.5 degrees) that invert under the skin's
shear. This module keeps the LHM's geometry (skin wrap outside, skull wrap inside, the mouth
slit between the lips) and fills it with well-shaped tets instead:

1. the boundary of the LHM's tets, with the slit opened into a slot `slit_gap` wide (the lower
   lip's copies moved down, the upper lip's originals up, by half of it each; the slot closes
   at the mouth corners, where the slit's ends are not doubled), is a closed surface;
2. fTetWild fills it (`tet_edge_length` and `tet_envelope` relative to the bounding box
   diagonal);
3. tets inside the muscle wrap are muscle tets, the others soft tets; each soft tet next to the
   slot takes the lip side of the prism holding its centroid;
4. the mesh's vertices on the skull wrap are the bone's (pinned), each with the skull wrap
   vertex nearest to it (its bone label).

fTetWild's fill takes 14-21 s at wrap level 3 (a head build about 35 s, 90 s at level 4). It
seeds itself from std::random_device (the same input gave 5,000 to 5,600 vertices from run to
run), so it runs in a process of its own with those seeds fixed (lhm/tetfill.py): a head's mesh
depends on its input surface and the settings only, on every machine. Meshes are cached on
disk under the cache folder (`tetmesh/`), keyed by both."""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass
from pathlib import Path

import igl
import numpy as np
import softdeca_native as native
from scipy.spatial import cKDTree

from softdeca_train.lhm.checks import closed_wrap_triangles, slit_middle
from softdeca_train.lhm.model import LayeredHeadModel
from softdeca_train.lhm.quality import MOUTH_REGION_RADIUS, QualityReport, quality_report
from softdeca_train.lhm.tetfill import run_fill
from softdeca_train.paths import cache_dir


@dataclass(frozen=True)
class TetMesh:
    vertices: np.ndarray  # (n, 3)
    soft_tets: np.ndarray  # (T_s, 4), positive volume
    muscle_tets: np.ndarray  # (T_m, 4), positive volume
    soft_side: np.ndarray  # (T_s,) +1 upper lip's side of the slit, -1 lower lip's, 0 elsewhere
    soft_lid_side: np.ndarray  # (T_s,) the same for the eye slits: +1 upper lid's, -1 lower
    bone_vertices: np.ndarray  # vertices on the skull wrap (pinned to a bone)
    bone_wrap_vertex: np.ndarray  # the skull wrap vertex nearest to each of them
    # "fill" (fTetWild's fill of this head), "carried" (the template's, lhm/carried.py) or
    # "fill: <why the template's was not carried>"
    source: str = "fill"


def boundary_faces(tets: np.ndarray) -> np.ndarray:
    """Faces of a tet mesh that belong to one tet only, oriented outward (for positive tets)."""
    f = np.concatenate(
        [tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]]
    )
    key = np.sort(f, axis=1)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    return f[first[counts == 1]]


def slotted_vertices(model: LayeredHeadModel, gap: float) -> np.ndarray:
    """The LHM's vertices with the slits opened: in every layer each slit's inner vertices
    (upper lip, upper lid) move up and their copies (lower lip, lower lid) down by gap / 2."""
    v = model.vertices.copy()
    originals = np.concatenate([model.eye_copy_of, model.slit_copy_of])
    copies = np.concatenate([model.eye_copies, model.mouth_copies])
    for layer in range(model.n_layers):
        base = layer * model.n_wrap
        v[base + originals, 1] += 0.5 * gap
        v[base + copies, 1] -= 0.5 * gap
    return v


def _triangle_side(model: LayeredHeadModel, vertex_side: np.ndarray) -> np.ndarray:
    s = vertex_side[model.wrap_triangles]
    return np.where((s > 0).any(axis=1), 1, np.where((s < 0).any(axis=1), -1, 0)).astype(np.int8)


def _winding_inside(surface: np.ndarray, tris: np.ndarray, points: np.ndarray) -> np.ndarray:
    w = igl.fast_winding_number(surface.astype(np.float64), tris.astype(np.int64), points)
    return np.asarray(w) > 0.5


# Part of the cache key: meshes made before the fill's seeds were fixed are not reused.
FILL_VERSION = "fixed-seed-1"


def _cache_key(surface: np.ndarray, faces: np.ndarray, settings: tuple[float, ...]) -> str:
    h = hashlib.sha1()
    h.update(np.ascontiguousarray(surface, np.float64).tobytes())
    h.update(np.ascontiguousarray(faces, np.int64).tobytes())
    h.update(repr(settings).encode())
    h.update(FILL_VERSION.encode())
    return h.hexdigest()[:20]


def fill(
    surface: np.ndarray, faces: np.ndarray, edge_length: float, envelope: float
) -> tuple[np.ndarray, np.ndarray]:
    """fTetWild's tets inside a closed surface (positively oriented), cached on disk."""
    key = _cache_key(surface, faces, (edge_length, envelope))
    path: Path = cache_dir() / "tetmesh" / f"{key}.npz"
    if path.exists():
        with np.load(path) as z:
            return z["vertices"], z["tets"]
    v, t = run_fill(surface.astype(np.float64), faces.astype(np.int32), edge_length, envelope)
    vol = native.tet_signed_volumes(v, t)
    t[vol < 0] = t[vol < 0][:, [0, 2, 1, 3]]
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f"{key}.{os.getpid()}.tmp.npz")  # parallel workers may race here
    np.savez_compressed(tmp, vertices=v, tets=t)
    tmp.replace(path)
    return v, t


def conforming_mesh(
    model: LayeredHeadModel, edge_length: float, envelope: float, slit_gap: float
) -> TetMesh:
    """The conforming tet mesh of `model`'s tissue (see the module's documentation)."""
    lhm_tets = np.vstack([model.soft_tets, model.muscle_tets])
    slotted = slotted_vertices(model, slit_gap)
    faces = boundary_faces(lhm_tets)
    used = np.unique(faces)
    remap = np.full(len(slotted), -1)
    remap[used] = np.arange(len(used))
    v, tets = fill(slotted[used], remap[faces], edge_length, envelope)
    vol = native.tet_signed_volumes(v, tets)
    if np.any(vol <= 0):
        raise RuntimeError(f"fTetWild returned {int((vol <= 0).sum())} degenerate tets")

    closed = closed_wrap_triangles(model)
    centroids = v[tets].mean(axis=1)
    muscle = _winding_inside(model.muscle_wrap, closed, centroids)
    soft = tets[~muscle]
    # Lip side: the side of the LHM prism (slotted) that holds the soft tet's centroid.
    prism, _, _ = native.embed_points(slotted, model.soft_tets, centroids[~muscle])
    triangle = np.asarray(prism) % len(model.wrap_triangles)
    side = _triangle_side(model, model.lip_side)[triangle]
    lid_side = _triangle_side(model, model.eye_side)[triangle]

    skull = slotted[(model.n_layers - 1) * model.n_wrap :]
    d2, _, _ = igl.point_mesh_squared_distance(v, skull, model.wrap_triangles.astype(np.int64))
    on_boundary = np.zeros(len(v), bool)
    on_boundary[boundary_faces(tets).ravel()] = True
    diag = float(np.linalg.norm(slotted[used].max(axis=0) - slotted[used].min(axis=0)))
    bone = np.flatnonzero(on_boundary & (np.sqrt(d2) <= 2.0 * envelope * diag))
    _, nearest = cKDTree(skull).query(v[bone])
    return TetMesh(
        vertices=v,
        soft_tets=soft.astype(np.int32),
        muscle_tets=tets[muscle].astype(np.int32),
        soft_side=side.astype(np.int8),
        soft_lid_side=lid_side.astype(np.int8),
        bone_vertices=bone.astype(np.int32),
        bone_wrap_vertex=np.asarray(nearest, np.int32),
    )


def conforming_quality(model: LayeredHeadModel, tm: TetMesh) -> QualityReport:
    """Element quality of `model`'s conforming tet mesh (its fill, this module's, or the
    template's carried, lhm/carried.py), overall and in the mouth region (vertices within the
    region's radius of the slit's middle)."""
    center = slit_middle(model)
    # the mouth's columns: directions from the head centre within the region's radius of the
    # slit's middle on the skin wrap (as for the prisms, from the skin to the skull)
    axis = center - model.center
    r = np.linalg.norm(axis)
    d = tm.vertices - model.center
    cos = d @ axis / np.maximum(np.linalg.norm(d, axis=1) * r, 1e-12)
    mouth = cos > np.cos(np.arctan(MOUTH_REGION_RADIUS / r))
    return quality_report(tm.vertices, tm.soft_tets, tm.muscle_tets, mouth)
