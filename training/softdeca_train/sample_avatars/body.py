"""A synthetic whole body under a head, as whole-body avatars carry one: a torso lofted from the
skin's neck boundary (one surface with the head, its triangles wound like the skin's), closed at
the hips, and two arms and two legs as closed cylinders overlapping it. No shape moves it; its
vertices make the face a small part of the mesh. Metres, +Y up, in the head's frame."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdeca_train.landmarks.topology import boundary_loops

NECK_DEPTH = 0.03  # m below the neck boundary where the torso's section is a circle
# The torso's section below the neck boundary: (depth m, half width m, half depth m), linear
# between; shoulders, chest, waist, hips. The hips are closed with a fan.
TORSO_PROFILE = ((0.09, 0.20, 0.12), (0.35, 0.17, 0.11), (0.55, 0.15, 0.10), (0.72, 0.17, 0.11))
# A bust's: the shoulders and the chest, closed under the chest.
BUST_PROFILE = ((0.09, 0.20, 0.12), (0.22, 0.18, 0.11))
RING_SPACING = 0.01  # m between the torso's rings
# Limbs: (start, end) as (x m, depth m below the neck boundary) and the radius in m; the
# left one, mirrored for the right.
ARM = ((0.20, 0.11), (0.34, 0.68), 0.045)
LEG = ((0.09, 0.68), (0.11, 1.55), 0.065)
LIMB_SEGMENTS = 40  # vertices around a limb


@dataclass(frozen=True)
class Body:
    """The body's own vertices, and its triangles over the skin's vertices and its own: an
    index i < skin count is skin vertex i, an index skin count + k is body vertex k."""

    vertices: np.ndarray  # (n, 3) float64
    triangles: np.ndarray  # (m, 3) int64


def neck_loop(skin: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The skin's lowest boundary loop (the cut at the neck), wound like its triangles."""
    loops = boundary_loops(triangles)
    if not loops:
        raise ValueError("the skin has no boundary to join a body to")
    return min(loops, key=lambda loop: float(skin[loop, 1].mean()))


def _torso(
    skin: np.ndarray, loop: np.ndarray, profile_rows: tuple = TORSO_PROFILE
) -> tuple[np.ndarray, np.ndarray]:
    """Rings from the neck loop down the profile (TORSO_PROFILE: to the hips), then a fan:
    vertices and triangles in the combined index space (the loop's skin indices, the torso's
    from len(skin))."""
    ring0 = skin[loop]
    centre = ring0.mean(axis=0)
    y0 = centre[1]
    offset = ring0[:, [0, 2]] - centre[[0, 2]]
    theta = np.arctan2(offset[:, 1], offset[:, 0])
    neck_radius = float(np.linalg.norm(offset, axis=1).mean())
    depths = np.arange(RING_SPACING, profile_rows[-1][0] + 1e-9, RING_SPACING)
    profile = np.array(((NECK_DEPTH, neck_radius, neck_radius), *profile_rows))
    half_x = np.interp(depths, profile[:, 0], profile[:, 1])
    half_z = np.interp(depths, profile[:, 0], profile[:, 2])
    rings = []
    for d, rx, rz in zip(depths, half_x, half_z, strict=True):
        section = np.stack(
            [
                centre[0] + rx * np.cos(theta),
                np.full_like(theta, y0 - d),
                centre[2] + rz * np.sin(theta),
            ],
            axis=1,
        )
        s = min(d / NECK_DEPTH, 1.0)  # from the loop's own shape to the section
        rings.append((1 - s) * ring0 + s * section if s < 1 else section)
    vertices = np.concatenate([*rings, [[centre[0], y0 - depths[-1], centre[2]]]])
    n, m = len(loop), len(skin)
    index = np.concatenate([loop, m + np.arange(len(depths) * n)]).reshape(-1, n)
    a, b = index[:-1], index[1:]
    a1, b1 = np.roll(a, -1, axis=1), np.roll(b, -1, axis=1)
    # the skin runs a_i -> a_i+1 along the loop, so the torso runs it back
    quads = np.concatenate(
        [np.stack([a1, a, b], -1).reshape(-1, 3), np.stack([a1, b, b1], -1).reshape(-1, 3)]
    )
    last, tip = index[-1], m + len(vertices) - 1
    fan = np.stack([np.roll(last, -1), last, np.full(n, tip)], axis=1)
    return vertices, np.concatenate([quads, fan])


def tube(
    start: np.ndarray, end: np.ndarray, radius: float, rings: int
) -> tuple[np.ndarray, np.ndarray]:
    """A closed cylinder from start to end (rings of LIMB_SEGMENTS vertices and a centre at
    each end), its triangles wound outwards."""
    axis = end - start
    u = np.cross(axis, (0.0, 0.0, 1.0))
    u /= np.linalg.norm(u)
    w = np.cross(axis / np.linalg.norm(axis), u)
    phi = 2 * np.pi * np.arange(LIMB_SEGMENTS) / LIMB_SEGMENTS
    circle = radius * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * w)
    t = np.linspace(0.0, 1.0, rings)
    sides = ((start + t[:, None] * axis)[:, None] + circle).reshape(-1, 3)
    vertices = np.concatenate([sides, [start, end]])
    k = LIMB_SEGMENTS
    index = np.arange(rings * k).reshape(rings, k)
    a, b = index[:-1], index[1:]
    a1, b1 = np.roll(a, -1, axis=1), np.roll(b, -1, axis=1)
    triangles = [np.stack([a, a1, b], -1).reshape(-1, 3), np.stack([a1, b1, b], -1).reshape(-1, 3)]
    first, last = index[0], index[-1]
    triangles.append(np.stack([np.full(k, rings * k), np.roll(first, -1), first], axis=1))
    triangles.append(np.stack([np.full(k, rings * k + 1), last, np.roll(last, -1)], axis=1))
    tris = np.concatenate(triangles)
    corners = vertices[tris]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum()
    return vertices, tris if volume > 0 else tris[:, ::-1].copy()


def synthetic_body(skin: np.ndarray, skin_triangles: np.ndarray, n_vertices: int) -> Body:
    """A body of about n_vertices vertices under the skin (vertices, triangles): the torso
    joined to its neck boundary, the limbs taking the rest."""
    loop = neck_loop(skin, skin_triangles)
    torso, torso_tris = _torso(skin, loop)
    y0, z0 = float(skin[loop, 1].mean()), float(skin[loop, 2].mean())
    parts, tris = [torso], [torso_tris]
    count = len(skin) + len(torso)
    rings = max(2, (n_vertices - len(torso)) // 4 // LIMB_SEGMENTS)
    for (x0, d0), (x1, d1), radius in (ARM, LEG):
        for side in (1.0, -1.0):
            start = np.array([side * x0, y0 - d0, z0])
            v, t = tube(start, np.array([side * x1, y0 - d1, z0]), radius, rings)
            parts.append(v)
            tris.append(t + count)
            count += len(v)
    return Body(np.concatenate(parts), np.concatenate(tris).astype(np.int64))


def synthetic_bust(skin: np.ndarray, skin_triangles: np.ndarray) -> Body:
    """Shoulders and a chest under the skin (vertices, triangles), joined to its neck boundary,
    as busts and head-and-shoulders avatars end."""
    loop = neck_loop(skin, skin_triangles)
    vertices, triangles = _torso(skin, loop, BUST_PROFILE)
    return Body(vertices, triangles.astype(np.int64))
