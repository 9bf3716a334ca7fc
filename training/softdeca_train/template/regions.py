"""Regions of S for reading errors by place: ICT's components (face, head and neck, mouth
socket, eye sockets) and, inside the face, areas around ICT's 68 Multi-PIE landmarks on the
template's neutral (lips, eyes, nose, brows, cheeks, chin). Each skin vertex belongs to exactly
one region; the first matching rule wins, in the order of REGIONS."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN

REGIONS = (
    "lips",  # within 10 mm of the 20 lip contour landmarks (48-67)
    "eyes",  # within 12 mm of the eye contour landmarks (36-47): lids and corners
    "nose",  # within 12 mm of the nose landmarks (27-35)
    "brows",  # within 12 mm of the brow landmarks (17-26)
    "cheeks",  # within 25 mm of the midpoints between jaw line (2, 14) and nose wings (31, 35)
    "chin_jaw",  # within 20 mm of the lower jaw-line landmarks (5-11)
    "face_other",  # the rest of ICT's face component (forehead, temples, ...)
    "head_neck",
    "mouth_socket",
    "eye_sockets",
)
# The regions on the outer skin (the mouth and eye sockets are inside the head): the ones a
# region control acts on and a regional pattern of the data varies.
CONTROL_REGIONS = tuple(r for r in REGIONS if r not in ("mouth_socket", "eye_sockets"))


# Parameter domains whose elements have a region (element_regions); a landmark's weight
# (w_landmark) belongs to a tracked point, not to a place on S, and takes no regional value.
REGIONAL_DOMAINS = ("soft_tet", "muscle_tet", "skin_triangle", "skin_point")


def _near(points: np.ndarray, centres: np.ndarray, radius: float) -> np.ndarray:
    d = np.linalg.norm(points[:, None, :] - centres[None, :, :], axis=2)
    return d.min(axis=1) < radius


def region_labels(template: Template) -> np.ndarray:
    """(N_SKIN,) index into REGIONS for every vertex of S."""
    v = template.neutral[:N_SKIN]
    lm = template.neutral[template.landmarks68]
    comp = template.components
    labels = np.full(N_SKIN, -1, np.int16)
    face = np.zeros(N_SKIN, bool)
    face[comp["face"].slice] = True
    cheek_centres = np.stack([(lm[2] + lm[31]) / 2, (lm[14] + lm[35]) / 2])
    rules = {
        "lips": _near(v, lm[48:68], 0.010),
        "eyes": _near(v, lm[36:48], 0.012),
        "nose": _near(v, lm[27:36], 0.012),
        "brows": _near(v, lm[17:27], 0.012),
        "cheeks": _near(v, cheek_centres, 0.025),
        "chin_jaw": _near(v, lm[5:12], 0.020),
        "face_other": np.ones(N_SKIN, bool),
    }
    for name, mask in rules.items():
        labels[(labels < 0) & face & mask] = REGIONS.index(name)
    labels[comp["head_neck"].slice] = REGIONS.index("head_neck")
    labels[comp["mouth_socket"].slice] = REGIONS.index("mouth_socket")
    labels[comp["eye_socket_left"].start : comp["eye_socket_right"].stop] = REGIONS.index(
        "eye_sockets"
    )
    assert (labels >= 0).all()
    return labels


def nearest_skin_vertices(
    vertices: np.ndarray, tets: np.ndarray, neutral_skin: np.ndarray
) -> np.ndarray:
    """Per tet, the vertex of S nearest its centroid at rest: the vertex whose region and
    per-vertex parameter values the tet takes (the data, the gallery and the runtime alike)."""
    centroids = np.asarray(vertices)[np.asarray(tets)].mean(axis=1)
    return cKDTree(neutral_skin).query(centroids)[1]


def mesh_tet_skin_vertices(mesh: object, neutral_skin: np.ndarray) -> dict[str, np.ndarray]:
    """`nearest_skin_vertices` of both tet domains of a softdeca_native.SimulationMesh."""
    rest = np.asarray(mesh.rest)  # type: ignore[attr-defined]
    return {
        "soft_tet": nearest_skin_vertices(rest, mesh.soft_tets, neutral_skin),  # type: ignore[attr-defined]
        "muscle_tet": nearest_skin_vertices(rest, mesh.muscle_tets, neutral_skin),  # type: ignore[attr-defined]
    }


def element_regions(
    labels: np.ndarray, mesh: object, neutral_skin: np.ndarray, domain: str
) -> np.ndarray:
    """Region index of every element of a parameter domain of a simulation mesh
    (softdeca_native.SimulationMesh): tets by the vertex of S nearest their centroid at rest,
    skin triangles by their first corner, skin points by their own label. `labels`: (N_SKIN,)
    from `region_labels`; `neutral_skin`: the identity's S at rest (N_SKIN, 3)."""
    if domain in ("soft_tet", "muscle_tet"):
        tets = mesh.soft_tets if domain == "soft_tet" else mesh.muscle_tets  # type: ignore[attr-defined]
        return labels[nearest_skin_vertices(np.asarray(mesh.rest), tets, neutral_skin)]  # type: ignore[attr-defined]
    if domain == "skin_triangle":
        return labels[np.asarray(mesh.skin_triangles)[:, 0]]  # type: ignore[attr-defined]
    if domain == "skin_point":
        return labels
    raise ValueError(f"no per-region values for domain {domain!r}")
