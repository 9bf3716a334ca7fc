"""Fitting the layered head model to one identity (paper 3.1.2, adapted; see ARCHITECTURE.md).

All wraps are radial graphs over one icosphere seen from a head centre defined by fixed ICT
landmark vertices, so wrap vertex i corresponds across identities and layers:
  1. skin wrap: tightest radii that keep every point of S `skin_margin` inside;
  2. inner bound: largest radii that keep every point of S `inner_margin` outside (S includes
     the mouth and eye sockets, so the deeper layers pass behind them);
  3. skull wrap: skin wrap minus the forensic tissue-depth prior (along the ray), never above
     the inner bound;
  4. muscle wrap: the template's absolute skin-to-muscle depth plus 10 % of the relative change
     (paper), clamped between the layers;
  5. prisms between corresponding triangles, three positive tets each; S embedded in the
     outer (soft-tissue) layer with barycentric coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import softdeca_native as native

from softdeca_train.geometry import umeyama
from softdeca_train.lhm import radial
from softdeca_train.lhm.eyes import EYES, fissure_line, lid_side_of_points
from softdeca_train.lhm.model import CRANIUM, JAW, LayeredHeadModel, LhmConfig
from softdeca_train.lhm.mouth import Slit, mouth_line, slit_along, upper_lip_points
from softdeca_train.lhm.sphere import icosphere, vertex_neighbours, zoom
from softdeca_train.lhm.tissue_depth import depth_anchors, interpolate_depth
from softdeca_train.template.model import N_SKIN, Template
from softdeca_train.template.plausibility import lip_contact_zone


@dataclass(frozen=True)
class _Radii:
    skin: np.ndarray
    inner: np.ndarray  # S-enclosure bound for everything below the skin wrap
    skull_prior: np.ndarray
    depth: np.ndarray  # prior depth along the surface normal
    owner: np.ndarray  # per wrap vertex: S vertex that set the skin radius (-1: none)


def head_center(
    skin: np.ndarray, lm68: np.ndarray, offset: tuple[float, float, float]
) -> np.ndarray:
    """Midpoint of the two upper jaw-line landmarks (by the ears), plus a fixed offset."""
    return 0.5 * (skin[lm68[0]] + skin[lm68[16]]) + np.asarray(offset)


@dataclass(frozen=True)
class SampleLayout:
    """Where S is sampled to fit the wraps: vertices plus points inside triangles, as
    (triangle, barycentric) pairs. Fixed per template so it applies to every identity."""

    triangle: np.ndarray  # (n,) index into S's triangles
    bary: np.ndarray  # (n, 3)

    def points(self, verts: np.ndarray, tris: np.ndarray) -> np.ndarray:
        return np.einsum("nk,nkd->nd", self.bary, verts[tris[self.triangle]])


def surface_sample_layout(verts: np.ndarray, tris: np.ndarray, spacing: float) -> SampleLayout:
    """Barycentric grids inside every triangle (corners excluded: vertices are samples
    already), fine enough that no point of a triangle is farther than about `spacing` from a
    sample: large triangles (mouth socket, neck) cannot slip through the wraps between samples."""
    p = verts[tris]
    longest = np.max(np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2), axis=1)
    n_sub = np.clip(np.ceil(longest / spacing).astype(int), 1, 32)
    tri_ids = [np.arange(len(tris))]
    barys = [np.full((len(tris), 3), 1.0 / 3.0)]
    for n in np.unique(n_sub[n_sub > 1]):
        sel = np.flatnonzero(n_sub == n)
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        b = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], 1) / n
        b = b[(b < 1).all(axis=1)]
        tri_ids.append(np.repeat(sel, len(b)))
        barys.append(np.tile(b, (len(sel), 1)))
    return SampleLayout(np.concatenate(tri_ids), np.vstack(barys))


def _wrap_normals(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    fn = np.cross(points[tris[:, 1]] - points[tris[:, 0]], points[tris[:, 2]] - points[tris[:, 0]])
    vn = np.zeros_like(points)
    for k in range(3):
        np.add.at(vn, tris[:, k], fn)
    return vn / np.linalg.norm(vn, axis=1, keepdims=True)


def _radii(
    skin: np.ndarray,
    skin_tris: np.ndarray,
    lm68: np.ndarray,
    center: np.ndarray,
    cfg: LhmConfig,
    layout: SampleLayout,
    dirs: np.ndarray,
) -> _Radii:
    """Radii of the wraps' rules along the directions `dirs` (the uncut triangulation)."""
    _, tris, nbrs = wrap_directions(cfg.level, cfg.zoom_toward, cfg.zoom_factor)
    inner_pts = layout.points(skin, skin_tris)
    pts = np.vstack([skin, inner_pts])
    src = np.concatenate([np.arange(len(skin)), np.full(len(inner_pts), -1)])
    smp = radial.cast_samples(pts, center, dirs, tris)
    # Each sample votes for the cone corner it is closest to (largest cone coefficient).
    nearest = tris[smp.triangle, np.argmax(smp.coeff, axis=1)]
    n = len(dirs)
    hi = np.full(n, -np.inf)
    lo = np.full(n, np.inf)
    np.maximum.at(hi, nearest, smp.rho)
    np.minimum.at(lo, nearest, smp.rho)
    known = np.isfinite(hi)
    owner = np.full(n, -1)
    order = np.argsort(smp.rho)  # later (larger) writes win: the outermost S vertex
    order = order[src[order] >= 0]
    owner[nearest[order]] = src[order]
    r_skin = radial.push_outside(
        radial.harmonic_fill(np.where(known, hi, 0), known, nbrs), smp, tris, cfg.skin_margin
    )
    r_skin = radial.repair_crossings(r_skin, center, dirs, tris, skin, skin_tris, outward=True)
    r_inner = radial.pull_inside(
        radial.harmonic_fill(np.where(known, lo, 0), known, nbrs), smp, tris, cfg.inner_margin
    )
    r_inner = radial.repair_crossings(r_inner, center, dirs, tris, skin, skin_tris, outward=False)
    depth = interpolate_depth(depth_anchors(skin, lm68), center, dirs, cfg.depth_sigma_deg)
    cos = np.einsum("ij,ij->i", _wrap_normals(center + r_skin[:, None] * dirs, tris), dirs)
    ray_depth = depth / np.clip(cos, 0.35, 1.0)
    return _Radii(r_skin, r_inner, r_skin - ray_depth, depth, owner)


@cache
def wrap_directions(
    level: int, toward: tuple[float, float, float], factor: float
) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """Directions, triangles and one-rings of the wraps' shared triangulation."""
    dirs, tris = icosphere(level)
    return zoom(dirs, np.asarray(toward), factor), tris, vertex_neighbours(tris, len(dirs))


@dataclass(frozen=True)
class _Cuts:
    """The wraps' slits: each eye's fissure cut first, then the mouth's on their result, so
    the wrap vertices are the originals, the eyes' copies, then the mouth's (the last
    len(mouth.copy_of), as LayeredHeadModel documents). Cuts keep the triangles' order."""

    eyes: list[Slit]
    mouth: Slit

    @property
    def directions(self) -> np.ndarray:
        return self.mouth.directions

    @property
    def triangles(self) -> np.ndarray:
        return self.mouth.triangles

    @property
    def eye_copy_of(self) -> np.ndarray:
        return np.concatenate([e.copy_of for e in self.eyes]).astype(np.int64)

    @property
    def n_original(self) -> int:
        return len(self.directions) - len(self.mouth.copy_of) - len(self.eye_copy_of)

    @property
    def eye_triangle_side(self) -> np.ndarray:
        """Per wrap triangle: +1 / -1 on an upper / lower lid's side of its eye's slit."""
        return np.sum([e.side for e in self.eyes], axis=0).astype(np.int8)

    def extend(self, per_vertex: np.ndarray) -> np.ndarray:
        """A per-original-vertex array with the copies' values appended."""
        copies = np.concatenate([self.eye_copy_of, self.mouth.copy_of])
        return np.concatenate([per_vertex, per_vertex[copies]])


def _slit(skin: np.ndarray, lm68: np.ndarray, center: np.ndarray, cfg: LhmConfig) -> _Cuts:
    dirs, tris, _ = wrap_directions(cfg.level, cfg.zoom_toward, cfg.zoom_factor)
    eyes = []
    for eye in EYES:
        cut = slit_along(dirs, tris, center, fissure_line(skin, lm68, eye))
        eyes.append(cut)
        dirs, tris = cut.directions, cut.triangles
    return _Cuts(eyes, slit_along(dirs, tris, center, mouth_line(skin, lm68)))


def _template_radii(template: Template, cfg: LhmConfig) -> tuple[_Radii, SampleLayout]:
    """The template's own radii (for the muscle rule) and S's sample layout, once per template
    and configuration."""
    memo = template.__dict__.setdefault("_lhm_template_radii", {})
    if cfg not in memo:
        skin = template.neutral[:N_SKIN]
        layout = surface_sample_layout(skin, template.skin_triangles, cfg.sample_spacing)
        center = head_center(skin, template.landmarks68, cfg.center_offset)
        slit = _slit(skin, template.landmarks68, center, cfg)
        radii = _radii(
            skin, template.skin_triangles, template.landmarks68, center, cfg, layout,
            slit.directions[: slit.n_original],
        )  # fmt: skip
        memo[cfg] = (radii, layout)
    return memo[cfg]


def prism_tets(
    outer: np.ndarray, inner: np.ndarray, tris: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """Three tets per prism between corresponding triangles of two layers (vertex index arrays
    `outer`, `inner` per wrap vertex). The split is conforming: every quad side takes the
    diagonal from the lower-indexed wrap vertex's outer to the higher one's inner vertex, a
    rule both prisms sharing that side agree on. Orientation is fixed to positive volume."""
    s = np.sort(tris, axis=1)
    a, b, c = s[:, 0], s[:, 1], s[:, 2]
    tets = np.concatenate([
        np.stack([outer[a], outer[b], outer[c], inner[c]], 1),
        np.stack([outer[a], outer[b], inner[c], inner[b]], 1),
        np.stack([outer[a], inner[b], inner[c], inner[a]], 1),
    ])  # fmt: skip
    p = points[tets]
    vol = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
    flip = vol < 0
    tets[flip, 1], tets[flip, 2] = tets[flip, 2].copy(), tets[flip, 1].copy()
    return tets.astype(np.int32)


def jaw_motion(
    template: Template, head: np.ndarray, expression: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The jaw's rigid motion between two poses of a head, read from ICT's lower teeth."""
    sl = template.components["teeth_lower"].slice
    fit = umeyama(head[sl], expression[sl], with_scale=False)
    return fit.rotation, fit.translation


def bone_labels(template: Template, head: np.ndarray) -> np.ndarray:
    """Per ICT vertex: JAW where jawOpen moves it like the lower teeth do, else CRANIUM."""
    i = template.expression_names.index("jawOpen")
    opened = head + template.expression_deltas[i]
    r, t = jaw_motion(template, head, opened)
    predicted = head @ r.T + t - head
    actual = opened - head
    pn = np.linalg.norm(predicted, axis=1)
    an = np.linalg.norm(actual, axis=1)
    cos = np.einsum("ij,ij->i", predicted, actual) / np.maximum(pn * an, 1e-12)
    jaw = (pn > 3e-3) & (an > 0.5 * pn) & (cos > 0.8)
    return np.where(jaw, JAW, CRANIUM).astype(np.int8)


def _sphere_fit(points: np.ndarray) -> tuple[np.ndarray, float]:
    a = np.hstack([2 * points, np.ones((len(points), 1))])
    sol = np.linalg.lstsq(a, (points**2).sum(1), rcond=None)[0]
    center = sol[:3]
    return center, float(np.sqrt(sol[3] + center @ center))


def _vertex_side(tris: np.ndarray, tri_side: np.ndarray, n: int, ends: np.ndarray) -> np.ndarray:
    """Per wrap vertex (copies included): +1 in the upper side's columns next to a slit, -1 in
    the lower's, 0 elsewhere and at the slits' ends (`ends`), where they close."""
    side = np.zeros(n, np.int8)
    for s in (1, -1):
        side[np.unique(tris[tri_side == s])] = s
    side[ends] = 0
    return side


def lip_of_points(template: Template, head: np.ndarray, bones: np.ndarray) -> np.ndarray:
    """Per S vertex, the bone its lip side hangs on: in the lip contact zone, CRANIUM where the
    upper lip's landmarks are nearer along S than the lower lip's, else JAW; elsewhere the
    bone ICT's jawOpen moves it with (the mouth socket's roof with the cranium, its floor with
    the jaw)."""
    side = bones[:N_SKIN].copy()
    zone = np.flatnonzero(lip_contact_zone(head, template.landmarks68))
    above = upper_lip_points(head[:N_SKIN], template.skin_triangles, template.landmarks68, zone)
    side[zone] = np.where(above, CRANIUM, JAW)
    return side


def embed_skin_by_side(
    vertices: np.ndarray,
    soft: np.ndarray,
    skin: np.ndarray,
    tet_side: np.ndarray,
    bone: np.ndarray,
    tet_lid_side: np.ndarray,
    lid_side: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """S's embedding in the soft tets, each lip and each lid in its own side of its slit: a
    point of the lower lip's side (`bone` JAW, `lip_of_points`) is not embedded in a tet of
    the upper lip's side of the mouth slit (`tet_side` +1, per soft tet), one of the upper
    lip's not in the lower lip's (-1); likewise a point of an upper or lower lid (`lid_side`
    +1 / -1, lhm/eyes.py) is not embedded in a tet of the other lid's side (`tet_lid_side`).
    Next to a slit the radial wall between the sides leans through the lips (the rays come
    from above and behind), so such points are embedded in the nearest tet of their own side,
    with barycentric coordinates outside [0, 1] (exact at rest, affine under deformation)."""
    tet, bary, _ = native.embed_points(vertices, soft, skin)
    tet = np.asarray(tet, np.int64)
    lip_of_point = np.where(bone == JAW, -1, 1)

    def clash(t_lip: np.ndarray, t_lid: np.ndarray, p_lip: np.ndarray, p_lid: np.ndarray):
        return ((t_lip != 0) & (t_lip != p_lip)) | ((t_lid != 0) & (p_lid != 0) & (t_lid != p_lid))

    wrong = clash(tet_side[tet], tet_lid_side[tet], lip_of_point, lid_side)
    centroid = vertices[soft].mean(axis=1)
    for p_lip in (1, -1):
        for p_lid in (1, 0, -1):
            pick = np.flatnonzero(wrong & (lip_of_point == p_lip) & (lid_side == p_lid))
            if len(pick) == 0:
                continue
            # Candidates near the points only (the nearest-tet search is costly for outside
            # points).
            lo, hi = skin[pick].min(axis=0) - 0.02, skin[pick].max(axis=0) + 0.02
            near = ((centroid > lo) & (centroid < hi)).all(axis=1)
            allowed = np.flatnonzero(~clash(tet_side, tet_lid_side, p_lip, p_lid) & near)
            t2, b2, _ = native.embed_points(vertices, soft[allowed], skin[pick])
            tet[pick] = allowed[np.asarray(t2)]
            bary[pick] = b2
    return tet, bary


def fit_lhm(
    template: Template, identity: np.ndarray | None = None, config: LhmConfig | None = None
) -> LayeredHeadModel:
    """The layered head model of identity coefficients `identity` (None: the template)."""
    cfg = config or LhmConfig()
    if cfg.soft_layers < 1 or cfg.muscle_layers < 1:
        raise ValueError("soft_layers and muscle_layers must be at least 1")
    head = template.identity_neutral(identity)
    skin = head[:N_SKIN]
    _, _, nbrs = wrap_directions(cfg.level, cfg.zoom_toward, cfg.zoom_factor)
    center = head_center(skin, template.landmarks68, cfg.center_offset)
    slit = _slit(skin, template.landmarks68, center, cfg)
    dirs = slit.directions[: slit.n_original]
    tpl, layout = _template_radii(template, cfg)
    rad = _radii(skin, template.skin_triangles, template.landmarks68, center, cfg, layout, dirs)

    # Muscle wrap: template's absolute depth plus a share of the relative change (paper 3.1.2).
    total_t = np.maximum(tpl.skin - tpl.skull_prior, 1e-6)
    depth_t = cfg.muscle_fraction * total_t
    total = rad.skin - rad.skull_prior
    depth = (
        1 - cfg.muscle_relative_share
    ) * depth_t + cfg.muscle_relative_share * depth_t * total / total_t
    gap = cfg.min_layer_gap
    # Smooth the wish, then clamp: min() keeps every bound (nesting, S outside the muscle wrap).
    wish = radial.smooth(rad.skin - depth, nbrs, cfg.inner_smoothing)
    r_muscle = np.minimum(np.minimum(wish, rad.inner), rad.skin - gap)
    if cfg.max_wrap_slope > 0:
        r_muscle = radial.limit_slope(r_muscle, dirs, nbrs, cfg.max_wrap_slope)
    # Where S's cavities (mouth, eye sockets) push the muscle wrap below its wish, the skull
    # prior no longer applies (it would lie above the muscle wrap): keep the muscle layer at
    # least min_muscle_thickness thick there instead of min_layer_gap.
    pushed = wish > r_muscle + gap
    muscle_gap = np.where(pushed, max(gap, cfg.min_muscle_thickness), gap)
    r_skull = radial.smooth(
        np.minimum(rad.skull_prior, r_muscle - muscle_gap), nbrs, cfg.inner_smoothing
    )
    r_skull = np.maximum(np.minimum(r_skull, r_muscle - muscle_gap), cfg.min_skull_radius)
    if cfg.max_wrap_slope > 0:
        r_skull = radial.limit_slope(r_skull, dirs, nbrs, cfg.max_wrap_slope)
    r_skull = np.minimum(r_skull, r_muscle - gap)
    if np.any(r_skull > r_muscle - gap + 1e-12):
        raise ValueError("the head is too thin for the layers: lower min_skull_radius or gaps")

    # Layers from outside in, with optional intermediate tet layers; the mouth slit's copies
    # take their original's radius (the lips touch at rest).
    radii = [rad.skin + (r_muscle - rad.skin) * k / cfg.soft_layers for k in range(cfg.soft_layers)]
    radii += [
        r_muscle + (r_skull - r_muscle) * k / cfg.muscle_layers for k in range(cfg.muscle_layers)
    ]
    radii = [slit.extend(r) for r in [*radii, r_skull]]
    all_dirs, tris = slit.directions, slit.triangles
    n = len(all_dirs)
    vertices = np.vstack([center + r[:, None] * all_dirs for r in radii])
    ids = [np.arange(k * n, (k + 1) * n) for k in range(len(radii))]
    tets = [prism_tets(ids[k], ids[k + 1], tris, vertices) for k in range(len(radii) - 1)]
    soft = np.vstack(tets[: cfg.soft_layers])
    muscle = np.vstack(tets[cfg.soft_layers :])

    bones = bone_labels(template, head)
    lip_bone = lip_of_points(template, head, bones)
    lid_side = lid_side_of_points(skin, template.landmarks68)
    layers = len(soft) // len(tris)
    tet, bary = embed_skin_by_side(
        vertices, soft, skin,
        np.tile(slit.mouth.side, layers), lip_bone,
        np.tile(slit.eye_triangle_side, layers), lid_side,
    )  # fmt: skip
    skull_labels = np.where(
        (rad.owner >= 0) & (bones[np.maximum(rad.owner, 0)] == JAW), JAW, CRANIUM
    )
    # Clean isolated labels: majority of the one-ring, twice.
    counts = np.array([len(nb) for nb in nbrs])
    owner_of = np.repeat(np.arange(len(nbrs)), counts)
    flat = np.concatenate(nbrs)
    for _ in range(2):
        share = np.bincount(owner_of, weights=skull_labels[flat], minlength=len(nbrs)) / counts
        skull_labels = np.where(share > 0.5, JAW, np.where(share < 0.5, CRANIUM, skull_labels))
    lip_side = _vertex_side(tris, slit.mouth.side, n, slit.mouth.path[[0, -1]])
    eye_ends = np.concatenate([e.path[[0, -1]] for e in slit.eyes])
    eye_side = _vertex_side(tris, slit.eye_triangle_side, n, eye_ends)
    skull_labels = slit.extend(skull_labels)
    skull_labels[lip_side > 0] = CRANIUM  # the upper lip hangs on the maxilla
    skull_labels[lip_side < 0] = JAW  # the lower lip on the mandible
    eyes = [
        _sphere_fit(head[template.components[c].slice]) for c in ("eyeball_left", "eyeball_right")
    ]
    return LayeredHeadModel(
        config=cfg,
        center=center,
        directions=all_dirs,
        wrap_triangles=tris,
        vertices=vertices,
        soft_tets=soft,
        muscle_tets=muscle,
        skull_labels=skull_labels.astype(np.int8),
        skin_tet=np.asarray(tet, np.int32),
        skin_bary=bary,
        tissue_depth=slit.extend(rad.depth),
        lip_side=lip_side,
        slit_copy_of=slit.mouth.copy_of.astype(np.int32),
        slit_path=slit.mouth.path.astype(np.int32),
        eye_side=eye_side,
        eye_copy_of=slit.eye_copy_of.astype(np.int32),
        attachments={
            # Bone each non-skin ICT vertex rides with (teeth, gums, tongue, eyes, ...).
            "bone_of_vertex": bones[N_SKIN:],
            # Per S vertex, the bone its lip side hangs on (lip_of_points): how any tet mesh
            # of this model embeds S by side.
            "skin_lip_bone": lip_bone,
            # Per S vertex, its lid's side of the eye slits (+1 upper, -1 lower, 0 neither).
            "skin_lid_side": lid_side,
            "eye_centers": np.array([e[0] for e in eyes]),
            "eye_radii": np.array([e[1] for e in eyes]),
        },
    )
