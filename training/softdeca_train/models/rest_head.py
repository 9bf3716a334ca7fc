"""The head a bundle carries for the physics at prepare (rest_physics.py): the template's
simulation mesh and the rules that fit it to any avatar in the template's topology.

Carried to an avatar's neutral like data generation carries the fill to an identity
(lhm/carried.py), but from the avatar's own skin S, by the library's carry
(plugin/src/prepare/rest_physics.h):

    V = V0 + K^-1 B^T W (S - B V0),   K = B^T W B + lambda * stiffness(V0)

B the skin's embedding in the fill, W 1 for skin points the template's fill holds (not the
mouth and eye sockets), stiffness the fill's Dirichlet energy. S is then embedded in the same
tets with its own barycentric coordinates, the teeth are the avatar's own, and the lip and lid
sets are found on the avatar's neutral by the data's rules (prepare/contact_sets.h). The
file format is docs/bundle.md's "Rest physics"."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from softdeca_train.contact_rules import CONTACT_RULES, ContactRules
from softdeca_train.lhm import LhmConfig

REST_HEAD_FILE = "rest_head.bin"


def contact_sets(
    rules: ContactRules,
    skin: np.ndarray,
    skin_triangles: np.ndarray,
    upper_teeth: np.ndarray,
    lower_teeth: np.ndarray,
) -> list[Any]:
    """The collision sets (native.CollisionSet) the rules find on a head's skin, as data
    generation finds them (sim/head.py)."""
    # the physics needs the compiled softdeca_native; reading a bundle does not
    import softdeca_native as native

    if rules.eye_zone_share != CONTACT_RULES.eye_zone_share:
        raise ValueError("the bundle's eye_zone_share differs from the physics'")
    return native.contact_sets(skin, skin_triangles, upper_teeth, lower_teeth, **vars(rules))


@dataclass
class RestHead:
    """The template's simulation mesh and what carrying it to an avatar needs."""

    vertices: np.ndarray  # (n, 3) the tissue fill's vertices (template), metres
    soft_tets: np.ndarray  # (T_s, 4) int32 over the fill's vertices
    muscle_tets: np.ndarray  # (T_m, 4)
    skin_vertex: np.ndarray  # (N_SKIN, 4) int32: the fill's tet embedding each skin point
    skin_weight: np.ndarray  # (N_SKIN, 4) its barycentric coordinates on the template
    carry_weight: np.ndarray  # (N_SKIN,) 1 where the fill holds the skin point, else 0
    carry_smoothness: float
    teeth_upper: np.ndarray  # head vertex indices, appended to the simulated vertices in order
    teeth_lower: np.ndarray
    cranium: np.ndarray  # simulated vertex indices (fill, then upper and lower teeth)
    jaw: np.ndarray
    upper_teeth_triangles: np.ndarray  # (T, 3) over teeth_upper's order
    lower_teeth_triangles: np.ndarray
    contacts: ContactRules | None  # None: no collision sets (synthetic heads)
    # Parameters that leave the unloaded head at rest as it is (measured at export,
    # inert_parameters): the model's own response to them is kept.
    inert: tuple[str, ...] = ()
    tolerance: float = 1e-5  # ten times the data's 1e-4, whose noise is a fifth of a small
    max_iterations: int = 2000  # control's response (docs/training.md)

    @property
    def skin_count(self) -> int:
        return len(self.skin_vertex)

    def carried_vertices(self, neutral_skin: np.ndarray) -> np.ndarray:
        """The fill's vertices carried to an avatar's neutral skin (N_SKIN, 3), by the library's
        carry (prepare/rest_physics.h, carry_fill)."""
        # the carried fill needs the compiled softdeca_native; reading a bundle does not
        import softdeca_native as native

        s = np.asarray(neutral_skin, np.float64)
        if s.shape != (self.skin_count, 3):
            raise ValueError(f"neutral skin must be ({self.skin_count}, 3), got {s.shape}")
        return native.carry_fill(
            self.vertices, self.soft_tets, self.muscle_tets, self.skin_vertex, self.skin_weight,
            self.carry_weight, self.carry_smoothness, s,
        )  # fmt: skip

    def simulation_mesh(
        self, neutral_head: np.ndarray, skin_triangles: np.ndarray
    ) -> tuple[Any, np.ndarray]:
        """The avatar's simulation mesh (native.SimulationMesh) and its fill's vertices."""
        import softdeca_native as native  # compiled with the plugin: see carried_vertices

        head = np.asarray(neutral_head, np.float64)
        skin = head[: self.skin_count]
        fill = self.carried_vertices(skin)
        rest = np.vstack([fill, head[self.teeth_upper], head[self.teeth_lower]])
        collisions = []
        if self.contacts is not None:
            n, nu = len(fill), len(self.teeth_upper)
            collisions = contact_sets(
                self.contacts, skin, skin_triangles, self.upper_teeth_triangles + n,
                self.lower_teeth_triangles + n + nu,
            )  # fmt: skip
        mesh = native.SimulationMesh(
            rest=rest,
            soft_tets=self.soft_tets,
            muscle_tets=self.muscle_tets,
            connecting_tets=np.zeros((0, 4), np.int32),
            skull_triangles=np.zeros((0, 3), np.int32),
            cranium_vertices=self.cranium.tolist(),
            jaw_vertices=self.jaw.tolist(),
            skin_vertices=self.skin_vertex,
            skin_weights=embedding_weights(fill, self.skin_vertex, self.skin_weight, skin),
            skin_triangles=np.asarray(skin_triangles, np.int32),
            collisions=collisions,
        )
        return mesh, fill


def embedding_weights(
    vertices: np.ndarray, corners: np.ndarray, weights: np.ndarray, points: np.ndarray
) -> np.ndarray:
    """Barycentric coordinates of `points` in the tets `corners` (N, 4) of `vertices` (negative
    where a point lies outside its tet): the carry follows S only approximately, and the
    template's coordinates would leave S off its targets at rest. Rows whose tet is degenerate
    keep `weights`."""
    x = vertices[corners]  # (N, 4, 3)
    edges = (x[:, 1:] - x[:, :1]).transpose(0, 2, 1)  # columns x_k - x_0
    ok = np.abs(np.linalg.det(edges)) > 1e-18
    out = np.array(weights, np.float64, copy=True)
    b = np.linalg.solve(edges[ok], (points[ok] - x[ok, 0])[..., None])[..., 0]
    out[ok] = np.concatenate([1.0 - b.sum(axis=1, keepdims=True), b], axis=1)
    return out


def rest_head_for_bundle(template: Any, specs: Any, config: Any = None) -> RestHead:
    """The template's rest head with the bundle's rest-inert parameters (of `specs`) measured
    on the template's neutral."""
    head = rest_head_from_template(template, config)
    neutral = np.asarray(template.neutral, np.float64)
    return replace(head, inert=inert_parameters(head, neutral, template.skin_triangles, specs))


def rest_head_from_template(template: Any, config: Any = None) -> RestHead:
    """The template's rest head as data generation builds it (the carried fill at identity
    zero, LHM level 3 unless `config` says otherwise)."""
    # the physics needs the compiled softdeca_native; reading a bundle does not
    from softdeca_train.lhm.carried import carry_basis
    from softdeca_train.sim import build_head_simulation
    from softdeca_train.sim.lids import lid_candidates

    cfg = config or LhmConfig(level=3, tet_mesh="carried")
    head_sim = build_head_simulation(template, None, cfg)
    if head_sim.tet_source != "carried":
        raise ValueError(f"the template's tets are not the carried fill ({head_sim.tet_source})")
    basis = carry_basis(template, cfg)
    mesh = head_sim.mesh
    n_fill = len(basis.mesh.vertices)
    up = template.components["teeth_upper"]
    lo = template.components["teeth_lower"]
    i32 = np.int32
    return RestHead(
        vertices=np.asarray(mesh.rest)[:n_fill].copy(),
        soft_tets=np.asarray(mesh.soft_tets, i32),
        muscle_tets=np.asarray(mesh.muscle_tets, i32),
        skin_vertex=np.asarray(mesh.skin_vertices, i32),
        skin_weight=np.asarray(mesh.skin_weights, np.float64),
        carry_weight=basis.skin_inside.astype(np.float64),
        carry_smoothness=float(cfg.carry_smoothness),
        teeth_upper=np.arange(up.start, up.stop, dtype=i32),
        teeth_lower=np.arange(lo.start, lo.stop, dtype=i32),
        cranium=np.asarray(mesh.cranium_vertices, i32),
        jaw=np.asarray(mesh.jaw_vertices, i32),
        upper_teeth_triangles=(template.component_triangles("teeth_upper") - up.start).astype(i32),
        lower_teeth_triangles=(template.component_triangles("teeth_lower") - lo.start).astype(i32),
        contacts=ContactRules(
            np.asarray(template.landmarks68, i32),
            lid_candidates(template).astype(i32),
        ),
    )


# ---- the file -------------------------------------------------------------------------------
_CONTACT_KEYS = ("lip_radius", "lip_corner_radius", "lid_reach", "lid_corner_radius",
                 "eye_zone_share")  # fmt: skip


def _arrays(head: RestHead) -> list[tuple[str, np.ndarray]]:
    """The file's arrays in order, each with its stored little-endian dtype."""
    c = head.contacts
    none = np.zeros(0, np.int32)
    return [
        ("<f8", head.vertices), ("<i4", head.soft_tets), ("<i4", head.muscle_tets),
        ("<i4", head.skin_vertex), ("<f8", head.skin_weight), ("<f8", head.carry_weight),
        ("<i4", head.teeth_upper), ("<i4", head.teeth_lower),
        ("<i4", head.cranium), ("<i4", head.jaw),
        ("<i4", head.upper_teeth_triangles), ("<i4", head.lower_teeth_triangles),
        ("<i4", none if c is None else c.landmarks68),
        ("<i4", none if c is None else c.lid_candidates),
    ]  # fmt: skip


def rest_head_file(head: RestHead) -> tuple[bytes, dict[str, Any]]:
    """The bytes of rest_head.bin and the manifest's `rest_physics` entry (without sha256)."""
    arrays = _arrays(head)
    data = b"".join(np.ascontiguousarray(a, dtype=d).tobytes() for d, a in arrays)
    entry: dict[str, Any] = {
        "file": REST_HEAD_FILE,
        "fill_vertices": len(head.vertices),
        "soft_tets": len(head.soft_tets),
        "muscle_tets": len(head.muscle_tets),
        "teeth_upper": len(head.teeth_upper),
        "teeth_lower": len(head.teeth_lower),
        "cranium": len(head.cranium),
        "jaw": len(head.jaw),
        "upper_teeth_triangles": len(head.upper_teeth_triangles),
        "lower_teeth_triangles": len(head.lower_teeth_triangles),
        "contacts": None
        if head.contacts is None
        else {
            "lid_candidates": len(head.contacts.lid_candidates),
            **{k: float(getattr(head.contacts, k)) for k in _CONTACT_KEYS},
        },
        "inert_parameters": list(head.inert),
        "carry_smoothness": head.carry_smoothness,
        "tolerance": head.tolerance,
        "max_iterations": head.max_iterations,
    }
    return data, entry


def read_rest_head(entry: dict[str, Any], data: bytes, skin_vertices: int) -> RestHead:
    """A bundle's rest head from its manifest entry and file bytes."""
    e, ns = entry, skin_vertices
    c = e["contacts"]
    shapes: list[tuple[str, tuple[int, ...]]] = [
        ("<f8", (e["fill_vertices"], 3)), ("<i4", (e["soft_tets"], 4)),
        ("<i4", (e["muscle_tets"], 4)), ("<i4", (ns, 4)), ("<f8", (ns, 4)), ("<f8", (ns,)),
        ("<i4", (e["teeth_upper"],)), ("<i4", (e["teeth_lower"],)),
        ("<i4", (e["cranium"],)), ("<i4", (e["jaw"],)),
        ("<i4", (e["upper_teeth_triangles"], 3)), ("<i4", (e["lower_teeth_triangles"], 3)),
        ("<i4", (0 if c is None else 68,)), ("<i4", (0 if c is None else c["lid_candidates"],)),
    ]  # fmt: skip
    arrays, at = [], 0
    for dtype, shape in shapes:
        count = int(np.prod(shape))
        size = count * np.dtype(dtype).itemsize
        if at + size > len(data):
            raise ValueError(f"{REST_HEAD_FILE}: {len(data)} bytes, shorter than its manifest says")
        arrays.append(np.frombuffer(data, dtype, count, at).reshape(shape).copy())
        at += size
    if at != len(data):
        raise ValueError(f"{REST_HEAD_FILE}: {len(data) - at} bytes more than its manifest says")
    contacts = (
        None
        if c is None
        else ContactRules(arrays[12], arrays[13], **{k: float(c[k]) for k in _CONTACT_KEYS})
    )
    return RestHead(
        vertices=arrays[0], soft_tets=arrays[1], muscle_tets=arrays[2], skin_vertex=arrays[3],
        skin_weight=arrays[4], carry_weight=arrays[5],
        carry_smoothness=float(e["carry_smoothness"]),
        teeth_upper=arrays[6], teeth_lower=arrays[7], cranium=arrays[8], jaw=arrays[9],
        upper_teeth_triangles=arrays[10], lower_teeth_triangles=arrays[11], contacts=contacts,
        inert=tuple(e["inert_parameters"]),
        tolerance=float(e["tolerance"]), max_iterations=int(e["max_iterations"]),
    )  # fmt: skip


def inert_parameters(
    head: RestHead, neutral_head: np.ndarray, skin_triangles: np.ndarray, specs: Any
) -> tuple[str, ...]:
    """The parameters (of `specs`, ParameterSpec) that leave the unloaded head at rest where it
    is under the physics (under 0.1 µm at either end of their range, solved on `neutral_head`
    with the others at their defaults). Global parameters never count: gravity's direction
    moves nothing at rest only while its tilt is zero."""
    import softdeca_native as native  # compiled with the plugin: see carried_vertices

    mesh, _ = head.simulation_mesh(neutral_head, skin_triangles)
    sim = native.Simulator(mesh, tolerance=head.tolerance, max_iterations=head.max_iterations)
    skin = np.asarray(neutral_head, np.float64)[None, : head.skin_count]

    def rest() -> np.ndarray:
        return np.asarray(sim.solve_static_batch(skin, jaw=np.eye(4)[None])[0][0])

    base = rest()
    inert = []
    for s in specs:
        if s.domain == "global":
            continue
        moved = 0.0
        for value in (s.minimum, s.maximum):
            sim.set_parameter(s.name, float(value))
            moved = max(moved, float(np.abs(rest() - base).max()))
        sim.set_parameter(s.name, float(s.default_value))
        if moved < 1e-7:
            inert.append(s.name)
    return tuple(inert)
