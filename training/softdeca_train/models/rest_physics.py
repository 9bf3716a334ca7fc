"""Physics at prepare: the avatar's own head simulated at rest, so a material change moves the
avatar the way its physics does where the networks cannot tell heads apart.

The networks carry what p does to an expression; what p does to a head at rest (gravity sag,
a wider cranium, a region's fuller volume) depends on the head more than they learn from the
identities they saw. So at prepare the runtime solves the avatar's head once at rest under p
(and once under the defaults, kept per avatar), and adds to every frame

    c(p) = [P_rest(p) - P_rest(p0)] - [M_rest(p) - M_rest(p_inert)]

P_rest the simulated skin at rest, M_rest the model's own output at rest (zero weights on the
neutral): the model's rest response is replaced by the physics'. p_inert is p with only the
parameters that leave the unloaded head at rest as it is (the bundle's `inert_parameters`: the
tissue weights, w_target, max_strain), the others at their defaults: the physics says nothing
about those at rest, so the networks' response to them alone stays; what they do together
with a load (softer tissue sagging more under heavier gravity) is the physics'. At the
defaults c = 0; a frame costs one add. A bundle with a rest gate (the manifest's rest_gate)
adds nothing of the networks at rest, so its frames get Pd = P_rest(p) - P_rest(p0) less the
frame's gate times M1(p) - M1(p_inert), M1 the model at rest with the gate open
(models/reference.py, docs/bundle.md "Rest physics").

The head is the bundle's (rest_head.py) carried to the avatar. Parameter maps reach the
physics' elements as the data's regions do (template/regions.py, element_regions): a tet takes the
values of the skin vertex nearest its centroid on the avatar, a skin triangle its face value,
a skin point its vertex value.

Oracle: the reference's physics at prepare, a deliberate second implementation of
plugin/src/prepare/rest_physics.cpp that tests/python/test_runtime_parity.py compares with."""

from __future__ import annotations

import numpy as np

from softdeca_train.models.parameters import ParameterState
from softdeca_train.models.rest_head import RestHead
from softdeca_train.template.regions import nearest_skin_vertices

# The physics' element kinds a parameter map is carried to (plugin/data/parameters.json).
MAPPED_DOMAINS = ("soft_tet", "muscle_tet", "skin_triangle", "skin_point")


def element_values(
    tet_vertex: dict[str, np.ndarray], params: ParameterState, name: str, domain: str
) -> np.ndarray | None:
    """The per-element field of parameter `name` for the physics (None: one global value).
    `tet_vertex`: per tet domain, the skin vertex whose value each tet takes."""
    faces = params.face_matrix([name])[:, 0]
    vertices = params.vertex_matrix([name])[:, 0]
    if domain not in MAPPED_DOMAINS or (
        np.all(faces == faces[0]) and np.all(vertices == vertices[0])
    ):
        return None
    if domain in tet_vertex:
        return vertices[tet_vertex[domain]].astype(np.float64)
    if domain == "skin_triangle":
        return faces.astype(np.float64)
    return vertices.astype(np.float64)


class RestSolver:
    """One avatar's head at rest under the physics."""

    def __init__(
        self, head: RestHead, neutral_head: np.ndarray, skin_triangles: np.ndarray
    ) -> None:
        # compiled with the plugin: reading and running a bundle does not need it
        import softdeca_native as native

        self.head = head
        self.neutral_skin = np.asarray(neutral_head, np.float64)[: head.skin_count]
        self.mesh, fill = head.simulation_mesh(neutral_head, skin_triangles)
        self.tet_vertex = {
            domain: nearest_skin_vertices(fill, tets, self.neutral_skin)
            for domain, tets in (("soft_tet", head.soft_tets), ("muscle_tet", head.muscle_tets))
        }
        self.sim = native.Simulator(
            self.mesh, tolerance=head.tolerance, max_iterations=head.max_iterations
        )

    def solve(self, params: ParameterState) -> np.ndarray:
        """(N_SKIN, 3) simulated skin at rest under the avatar's parameters."""
        for spec in params.specs:
            values = element_values(self.tet_vertex, params, spec.name, spec.domain)
            if values is None:
                self.sim.set_parameter(spec.name, float(params.face_matrix([spec.name])[0, 0]))
            else:
                self.sim.set_parameter_field(spec.name, values)
        skin, _, _ = self.sim.solve_static_batch(self.neutral_skin[None], jaw=np.eye(4)[None])
        return np.asarray(skin[0], np.float64)
