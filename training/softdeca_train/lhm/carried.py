"""The template's conforming tet mesh carried to another head: one discretisation of every
head, linear in its identity coefficients, instead of a fill of its own.

A head's conforming fill (lhm/conforming.py, fTetWild) is most of its build (about 20 of
26 s at level 3) and discretises each head its own way. Here the template's fill is made
once and deformed for each head by a displacement field that is linear in the identity
coefficients h: per identity mode k a field D_k on the fill's vertices, fitted once to that
mode's displacement of S,

    D_k = argmin  sum over S points i of |B_i D - m_k(i)|^2  +  lambda * E_dirichlet(D)

with B S's barycentric embedding in the fill (points in the mouth and eye sockets, outside
the fill, left out) and E_dirichlet the fill's volume-weighted gradient energy of D (its
stiffness matrix). The head's mesh is V + sum_k h_k D_k: S's displacement followed where S
is, spread smoothly inward, so the skull and the muscle wrap follow the face's shape. The
tets, their tissue and their lip and lid sides, and the bone vertices are the template's.

Where the LHM's own wraps would fit a head another way (they are radial graphs of S, which
jump between neck and shoulder from one head to the next), the carried mesh follows S
smoothly instead. A carried mesh is held to the floor a fill is held to
(`LhmConfig.carry_min_dihedral_deg`, `carry_max_aspect`, no inverted tet) and S has to lie
inside it (`carry_max_skin_outside`); a head it does not suit gets a fill of its own, and
`TetMesh.source` says which and why."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
import softdeca_native as native
from scipy.sparse.linalg import splu

from softdeca_train.lhm.conforming import TetMesh, conforming_mesh
from softdeca_train.lhm.fit import embed_skin_by_side, fit_lhm
from softdeca_train.lhm.model import LayeredHeadModel, LhmConfig
from softdeca_train.lhm.quality import aspect_ratios, dihedral_angles
from softdeca_train.template import Template
from softdeca_train.template.model import N_SKIN


def embedding_matrix(
    n_vertices: int, tets: np.ndarray, tet: np.ndarray, bary: np.ndarray, weight: np.ndarray
) -> sp.csr_matrix:
    """(points, n_vertices): row i interpolates point i from its tet's corners, times weight."""
    rows = np.repeat(np.arange(len(tet)), 4)
    vals = (bary * weight[:, None]).ravel()
    return sp.csr_matrix((vals, (rows, tets[tet].ravel())), shape=(len(tet), n_vertices))


@dataclass(frozen=True)
class CarryBasis:
    """The template's fill and the displacement field of each identity mode on it."""

    lhm: LayeredHeadModel  # the template's: the fill's bone_wrap_vertex index its wraps
    mesh: TetMesh
    fields: np.ndarray  # (K, n, 3) per identity mode
    skin_inside: np.ndarray  # (n_S,) S points the template's fill holds (not in a socket)

    def vertices(self, identity: np.ndarray | None) -> np.ndarray:
        """The fill's vertices carried to identity coefficients h (None: the template)."""
        if identity is None:
            return self.mesh.vertices
        h = np.asarray(identity, np.float64)
        if h.shape != (len(self.fields),):
            raise ValueError(f"expected {len(self.fields)} identity coefficients, got {h.shape}")
        return self.mesh.vertices + np.einsum("k,knd->nd", h, self.fields)


def carry_basis(template: Template, cfg: LhmConfig) -> CarryBasis:
    """The template's fill and its identity fields (a few seconds after the fill, which is
    cached on disk), once per template and configuration."""
    memo = template.__dict__.setdefault("_lhm_carry_basis", {})
    if cfg in memo:
        return memo[cfg]
    lhm = fit_lhm(template, None, cfg)
    mesh = conforming_mesh(lhm, cfg.tet_edge_length, cfg.tet_envelope, cfg.slit_gap)
    tets = np.vstack([mesh.soft_tets, mesh.muscle_tets])
    n = len(mesh.vertices)
    skin = template.neutral[:N_SKIN].astype(np.float64)
    _, _, outside = native.embed_points(mesh.vertices, tets, skin)
    inside = np.asarray(outside) <= 0.0
    # S by side, as the simulation embeds it (lips and lids in their own side's tets).
    tet, bary = embed_skin_by_side(
        mesh.vertices, mesh.soft_tets, skin, mesh.soft_side,
        lhm.attachments["skin_lip_bone"], mesh.soft_lid_side, lhm.attachments["skin_lid_side"],
    )  # fmt: skip
    b = embedding_matrix(n, mesh.soft_tets, np.asarray(tet), bary, inside.astype(np.float64))
    # the fill's Dirichlet stiffness: the library's (prepare/rest_physics.cpp), as the runtime's
    # carry of a fill assembles it
    stiffness = sp.csc_matrix(native.fill_stiffness(mesh.vertices, tets))
    system = (b.T @ b + cfg.carry_smoothness * stiffness).tocsc()
    modes = np.asarray(template.identity_modes[:, :N_SKIN], np.float64)  # (K, n_S, 3)
    k = len(modes)
    rhs = b.T @ modes.transpose(1, 0, 2).reshape(N_SKIN, 3 * k)
    fields = splu(system).solve(np.asarray(rhs)).reshape(n, k, 3).transpose(1, 0, 2)
    memo[cfg] = CarryBasis(lhm, mesh, np.ascontiguousarray(fields), inside)
    return memo[cfg]


@dataclass(frozen=True)
class CarryQuality:
    """A carried mesh's worst tets and how far S leaves it."""

    inverted: int
    min_dihedral_deg: float
    max_aspect: float
    skin_outside: float  # metres: the farthest S point (of those the template's fill holds)

    def shortfall(self, cfg: LhmConfig) -> str:
        """Why the mesh is below the floor ('' when it holds)."""
        if self.inverted:
            return f"{self.inverted} inverted tets"
        if self.min_dihedral_deg < cfg.carry_min_dihedral_deg:
            return f"smallest dihedral angle {self.min_dihedral_deg:.1f} deg"
        if self.max_aspect > cfg.carry_max_aspect:
            return f"largest aspect ratio {self.max_aspect:.1f}"
        if self.skin_outside > cfg.carry_max_skin_outside:
            return f"S up to {1e3 * self.skin_outside:.2f} mm outside"
        return ""


def carry_quality(
    vertices: np.ndarray, mesh: TetMesh, skin: np.ndarray, inside: np.ndarray
) -> CarryQuality:
    tets = np.vstack([mesh.soft_tets, mesh.muscle_tets])
    vol = np.asarray(native.tet_signed_volumes(vertices, tets))
    ok = vol > 0
    _, _, outside = native.embed_points(vertices, tets, skin[inside])
    return CarryQuality(
        inverted=int((~ok).sum()),
        min_dihedral_deg=float(dihedral_angles(vertices, tets[ok]).min(initial=180.0)),
        max_aspect=float(aspect_ratios(vertices, tets[ok]).max(initial=0.0)),
        skin_outside=float(np.max(outside, initial=0.0)),
    )


def tissue_mesh(
    template: Template, identity: np.ndarray | None, lhm: LayeredHeadModel
) -> tuple[TetMesh, LayeredHeadModel]:
    """The conforming tet mesh of the head `lhm` (of identity coefficients `identity`), with
    the LHM whose skull wrap its `bone_wrap_vertex` index: the template's carried
    (`tet_mesh = "carried"`) where it holds the floor, else the head's own fill."""
    cfg = lhm.config
    if cfg.tet_mesh not in ("carried", "conforming"):
        raise ValueError(f"tet_mesh {cfg.tet_mesh!r} has no conforming mesh")

    def own(source: str) -> tuple[TetMesh, LayeredHeadModel]:
        mesh = conforming_mesh(lhm, cfg.tet_edge_length, cfg.tet_envelope, cfg.slit_gap)
        return replace(mesh, source=source), lhm

    if cfg.tet_mesh == "conforming":
        return own("fill")
    basis = carry_basis(template, cfg)
    vertices = basis.vertices(identity)
    skin = template.identity_neutral(identity)[:N_SKIN].astype(np.float64)
    why = carry_quality(vertices, basis.mesh, skin, basis.skin_inside).shortfall(cfg)
    if why:
        return own(f"fill: the carried mesh has {why}")
    return replace(basis.mesh, vertices=vertices, source="carried"), basis.lhm
