"""The reference forward pass of SoftDECA and SparseSoftDECA for one avatar: the exact math the
native runtime implements (docs/bundle.md), in float64 around float32 networks. Training uses
the same pieces (dt.py, parameters.py); parity tests compare the runtime against this.

Per frame, SoftDECA: S_t = neutral + sum_i w_i B_i (whole head), z = f_w(w),
G_f = I + sum_k z_k L[f, k], X = DT(S_t, G) on the skin, plus sum_k z_k L_v[v, k] where the
bundle has SoftDECA's vertex stage and sum_k c_k M[v, k] where it has the residual stage
(c = f_r_w(w, f_r_ph(p)), M its modes). SparseSoftDECA: offsets of the
retargeted landmarks from the avatar's neutral landmarks, z = f_l(offsets),
X = neutral_skin + sum_k z_k L_v[v, k]. SoftDECA's frames then get the physics at prepare
(Preparation.rest_offset; with a rest gate, less the gate z_last times rest_gated). Then, if
enabled, dynamics per skin vertex
X_t = gamma Y_t + 2 alpha X_{t-1} - beta X_{t-2}, the non-skin vertices, and normals.

Oracle: a deliberate second implementation of the runtime's frame (plugin/src/runtime/), the
reference the parity tests hold the library to (tests/python/test_runtime_parity.py) and the
evaluation runs bundles with."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
import torch

from softdeca_train.geometry import Similarity, umeyama
from softdeca_train.models.dt import DtSystem, deformation_transfer, dt_system
from softdeca_train.models.networks import BundleNetworks
from softdeca_train.models.parameters import ParameterState
from softdeca_train.models.rest_head import RestHead
from softdeca_train.models.rest_physics import RestSolver
from softdeca_train.models.topology import JAW, TemplateDefinition
from softdeca_train.parameters import ParameterSpec

Model = Literal["softdeca", "sparse"]


class Networks(Protocol):
    """What the reference needs from a bundle's networks (torch modules or ONNX sessions)."""

    specs: tuple[ParameterSpec, ...]
    rest_head: RestHead | None  # the bundle's physics at prepare, if it has one
    rest_gate: float | None  # tau where z's last entry is SoftDECA's rest gate (BundleNetworks)
    rest_changes: bool  # SoftDECA trained on the rest physics (BundleNetworks)

    def has(self, model: Model) -> bool: ...
    def identity(self, neutral_skin: np.ndarray) -> np.ndarray: ...
    def f_w(self, weights: np.ndarray) -> np.ndarray: ...
    def f_l(self, offsets: np.ndarray) -> np.ndarray: ...
    def f_ph(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray: ...
    def f_ph_v(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray: ...
    def vertex_stage(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray | None: ...
    def residual(self, parameters: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None: ...
    def residual_coefficients(self, weights: np.ndarray, condition: np.ndarray) -> np.ndarray: ...
    def f_dyn(
        self, model: Model, parameters: np.ndarray, identity: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


class TorchNetworks:
    """Networks from torch modules (float32, no gradient)."""

    def __init__(self, nets: BundleNetworks, rest_head: RestHead | None = None) -> None:
        self.nets = nets
        self.specs = nets.specs
        self.rest_head = rest_head
        self.rest_gate = nets.rest_gate
        self.rest_changes = nets.rest_changes

    def has(self, model: Model) -> bool:
        return (self.nets.softdeca if model == "softdeca" else self.nets.sparse) is not None

    @staticmethod
    def _t(a: np.ndarray) -> torch.Tensor:
        return torch.as_tensor(np.asarray(a, dtype=np.float32))

    @torch.no_grad()
    def identity(self, neutral_skin: np.ndarray) -> np.ndarray:
        return self.nets.identity_encoder(self._t(neutral_skin)[None]).numpy()[0]

    @torch.no_grad()
    def f_w(self, weights: np.ndarray) -> np.ndarray:
        assert self.nets.softdeca is not None
        return self.nets.softdeca.f_w(self._t(weights)).numpy()

    @torch.no_grad()
    def f_l(self, offsets: np.ndarray) -> np.ndarray:
        assert self.nets.sparse is not None
        return self.nets.sparse.f_l(self._t(offsets)).numpy()

    @torch.no_grad()
    def f_ph(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray:
        assert self.nets.softdeca is not None
        return self.nets.softdeca.f_ph(self._t(parameters), self._t(identity)[None]).numpy()

    @torch.no_grad()
    def f_ph_v(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray:
        assert self.nets.sparse is not None
        return self.nets.sparse.f_ph_v(self._t(parameters), self._t(identity)[None]).numpy()

    @torch.no_grad()
    def vertex_stage(self, parameters: np.ndarray, identity: np.ndarray) -> np.ndarray | None:
        assert self.nets.softdeca is not None
        if self.nets.softdeca.f_ph_v is None:
            return None
        h = self._t(identity)[None]
        return self.nets.softdeca.f_ph_v(self._t(parameters), h).numpy()

    @torch.no_grad()
    def residual(self, parameters: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        assert self.nets.softdeca is not None
        stage = self.nets.softdeca.f_r
        if stage is None:
            return None
        p = self._t(parameters)
        return stage.condition(p).numpy(), stage.table.numpy().copy()

    @torch.no_grad()
    def residual_coefficients(self, weights: np.ndarray, condition: np.ndarray) -> np.ndarray:
        assert self.nets.softdeca is not None and self.nets.softdeca.f_r is not None
        return self.nets.softdeca.f_r.coefficients(self._t(weights), self._t(condition)).numpy()

    @torch.no_grad()
    def f_dyn(
        self, model: Model, parameters: np.ndarray, identity: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        m = self.nets.softdeca if model == "softdeca" else self.nets.sparse
        assert m is not None
        a, b, g = m.f_dyn(self._t(parameters), self._t(identity)[None])
        return a.numpy(), b.numpy(), g.numpy()


def vertex_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals, unit length; zero where no triangle has area."""
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    fn = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    n = np.zeros_like(v)
    for c in range(3):
        np.add.at(n, t[:, c], fn)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0, n / np.where(length > 0, length, 1.0), 0.0)


@dataclass
class Preparation:
    identity: np.ndarray
    face_l: np.ndarray | None  # (F, latent, 9)
    vertex_l: np.ndarray | None  # (Vs, latent, 3)
    softdeca_vertex_l: np.ndarray | None  # SoftDECA's vertex stage (Vs, latent, 3), or None
    # SoftDECA's residual stage: its condition (1, C) and modes (Vs, K, 3), or None
    residual: tuple[np.ndarray, np.ndarray] | None
    dynamics: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]  # model -> alpha, beta, gamma
    # SoftDECA's rest physics (Vs, 3) added to every frame (rest_physics.py), or None: c(p),
    # or with a rest gate Pd = P_rest(p) - P_rest(p0)
    rest_offset: np.ndarray | None = None
    # with a rest gate, Md = M1(p) - M1(p_inert) (Vs, 3), taken off every frame times its gate
    rest_gated: np.ndarray | None = None


class ReferenceAvatar:
    """One avatar, mirroring softdeca_avatar of the C ABI."""

    def __init__(
        self,
        nets: Networks,
        definition: TemplateDefinition,
        neutral: np.ndarray,
        head_triangles: np.ndarray,
        blendshapes: np.ndarray | None = None,
        regularisation: float = 1e-3,
        identity: np.ndarray | None = None,
        rest_physics: bool = True,
    ) -> None:
        self.nets = nets
        self.d = definition
        self.neutral = np.asarray(neutral, dtype=np.float64)
        if self.neutral.shape != (definition.head_vertices, 3):
            raise ValueError("neutral must be (head_vertices, 3)")
        self.head_triangles = np.asarray(head_triangles, dtype=np.int64)
        self.blendshapes = None if blendshapes is None else np.asarray(blendshapes, np.float64)
        vs = definition.skin_vertices
        self.dt: DtSystem = dt_system(self.neutral[:vs], definition.skin_triangles, regularisation)
        self.params = ParameterState(nets.specs, definition.skin_triangles, self.dt.area)
        self.identity = (
            np.asarray(identity, np.float64)
            if identity is not None
            else nets.identity(self.neutral[:vs]).astype(np.float64)
        )
        self.neutral_landmarks = definition.landmarks.evaluate(
            self.neutral[:vs], definition.skin_triangles
        )
        self.calibration: Similarity | None = None
        self.dynamics = False
        self._state: tuple[Model, np.ndarray, np.ndarray] | None = None
        self.prep: Preparation | None = None
        # Physics at prepare: the avatar's head at rest, where the bundle has it (the runtime
        # always uses it then; `rest_physics=False` measures the networks alone).
        self.rest_head = nets.rest_head if rest_physics else None
        self._rest_solver: RestSolver | None = None
        # P_rest(p0) and M_rest(p0) (with a rest gate, M1(p0))
        self._rest_defaults: tuple[np.ndarray, np.ndarray] | None = None

    # ---- per avatar ------------------------------------------------------------------------
    def _networks(self, params: ParameterState) -> Preparation:
        names = [s.name for s in self.nets.specs]
        pf, pv = params.face_matrix(names), params.vertex_matrix(names)
        h = self.identity
        face_l = vertex_l = stage = residual = None
        dyn = {}
        if self.nets.has("softdeca"):
            face_l = self.nets.f_ph(pf, h).astype(np.float64)
            stage = self.nets.vertex_stage(pv, h)
            stage = None if stage is None else stage.astype(np.float64)
            residual = self.nets.residual(pv)
            dyn["softdeca"] = tuple(
                x.astype(np.float64) for x in self.nets.f_dyn("softdeca", pv, h)
            )
        if self.nets.has("sparse"):
            vertex_l = self.nets.f_ph_v(pv, h).astype(np.float64)
            dyn["sparse"] = tuple(x.astype(np.float64) for x in self.nets.f_dyn("sparse", pv, h))
        return Preparation(h.copy(), face_l, vertex_l, stage, residual, dyn)  # type: ignore[arg-type]

    def prepare(self) -> Preparation:
        prep = self._networks(self.params)
        head = self.rest_head
        if head is not None and self.nets.has("softdeca") and not self.params.at_defaults():
            if self._rest_solver is None:
                self._rest_solver = RestSolver(head, self.neutral, self.d.skin_triangles)
            if self._rest_defaults is None:
                defaults = self.params.with_defaults()
                self._rest_defaults = (
                    self._rest_solver.solve(defaults),
                    self._softdeca_rest(self._networks(defaults)),
                )
            physics0, model0 = self._rest_defaults
            # The networks' own rest response to p, less their response to p's rest-inert
            # parameters alone (kept: the physics says nothing about those at rest).
            others = [s.name for s in self.nets.specs if s.name not in head.inert]
            inert_only = self.params.with_defaults(others)
            model_inert = (
                model0
                if inert_only.at_defaults()
                else self._softdeca_rest(self._networks(inert_only))
            )
            model = self._softdeca_rest(prep)
            physics = self._rest_solver.solve(self.params)
            if self.nets.rest_changes:
                # trained on S_t + Pd: the networks' response to p is what an expression adds
                # on top of the rest physics, kept whole
                prep.rest_offset = physics - physics0
            elif self.nets.rest_gate is None:
                prep.rest_offset = (physics - physics0) - (model - model_inert)
            else:
                # Gated: at rest the networks add nothing, so the physics' Pd is the frame's;
                # on an expression the gate g(w) opens the networks' own response to p,
                # which Md, taken off times g(w), brings back to p_inert's.
                prep.rest_offset = physics - physics0
                prep.rest_gated = model - model_inert
        self.prep = prep
        return prep

    def _softdeca_rest(self, prep: Preparation) -> np.ndarray:
        """SoftDECA's static frame at rest as the physics at prepare compares it: zero weights
        on the neutral (M_rest); with a rest gate, the gate open (M1: the networks'
        w-independent response as it acts on an expression)."""
        vs = self.d.skin_vertices
        gate = None if self.nets.rest_gate is None else 1.0
        return self._softdeca_static(prep, np.zeros(52), self.neutral[:vs], gate)

    def calibrate(self, user_neutral: np.ndarray) -> None:
        """The user's neutral landmarks (K, 3): similarity user -> avatar neutral landmarks."""
        self.calibration = umeyama(self._select(user_neutral), self.neutral_landmarks)
        self._user_neutral = self._select(user_neutral)

    def _select(self, points: np.ndarray) -> np.ndarray:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        lm = self.d.landmarks
        if len(p) == lm.arkit_vertex_count and len(p) != len(lm):
            return p[lm.arkit_vertex]
        if len(p) != len(lm):
            raise ValueError(f"expected {len(lm)} landmarks or {lm.arkit_vertex_count} vertices")
        return p

    # ---- per frame -------------------------------------------------------------------------
    def blend(self, weights: np.ndarray) -> np.ndarray:
        if self.blendshapes is None:
            raise ValueError("the avatar has no blendshapes")
        return self.neutral + np.tensordot(np.asarray(weights, np.float64), self.blendshapes, 1)

    def _need(self) -> Preparation:
        if self.prep is None:
            raise RuntimeError("prepare() first")
        return self.prep

    def softdeca_static(self, weights: np.ndarray, skin: np.ndarray) -> np.ndarray:
        prep = self._need()
        out = self._softdeca_static(prep, weights, skin)
        if prep.rest_offset is not None:
            out = out + prep.rest_offset
        if prep.rest_gated is not None:
            gate = float(self.nets.f_w(np.asarray(weights, np.float32)[None])[0, -1])
            out = out - gate * prep.rest_gated
        return out

    def _softdeca_static(
        self,
        prep: Preparation,
        weights: np.ndarray,
        skin: np.ndarray,
        gate: float | None = None,
    ) -> np.ndarray:
        """The networks' static frame (without the rest physics); `gate` replaces the rest
        gate's value (z's last entry and the residual stage's mean mode coefficient)."""
        assert prep.face_l is not None
        z = self.nets.f_w(np.asarray(weights, np.float32)[None])[0].astype(np.float64)
        if gate is not None:
            z[-1] = gate
        g = np.einsum("k,fkc->fc", z, prep.face_l).reshape(-1, 3, 3)
        x = deformation_transfer(self.dt, torch.from_numpy(skin[None]), torch.from_numpy(g[None]))
        out = x[0].numpy()
        if prep.softdeca_vertex_l is not None:
            out = out + np.einsum("k,vkc->vc", z, prep.softdeca_vertex_l)
        if prep.residual is not None:
            condition, modes = prep.residual
            w = np.asarray(weights, np.float32)[None]
            c = self.nets.residual_coefficients(w, condition)[0].astype(np.float64)
            if gate is not None:
                c[-1] = gate
            out = out + np.einsum("k,vkc->vc", c, modes.astype(np.float64))
        return out

    def landmark_offsets(self, points: np.ndarray) -> np.ndarray:
        u = self._select(points)
        if self.calibration is None:
            return u - self.neutral_landmarks
        s, r = self.calibration.scale, self.calibration.rotation
        return s * (u - self._user_neutral) @ r.T

    def sparse_static(self, points: np.ndarray) -> np.ndarray:
        prep = self._need()
        assert prep.vertex_l is not None
        off = self.landmark_offsets(points).reshape(1, -1)
        z = self.nets.f_l(off.astype(np.float32))[0].astype(np.float64)
        vs = self.d.skin_vertices
        return self.neutral[:vs] + np.einsum("k,vkc->vc", z, prep.vertex_l)

    def _dynamics(self, model: Model, y: np.ndarray) -> np.ndarray:
        if not self.dynamics:
            self._state = None
            return y
        alpha, beta, gamma = self._need().dynamics[model]
        if self._state is None or self._state[0] != model:
            self._state = (model, y, y)
        _, x1, x2 = self._state
        x = gamma[:, None] * y + 2 * alpha[:, None] * x1 - beta[:, None] * x2
        self._state = (model, x, x1)
        return x

    def reset_dynamics(self) -> None:
        self._state = None

    def _finish(
        self, skin: np.ndarray, non_skin: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray]:
        vs = self.d.skin_vertices
        head = self.neutral.copy()
        head[:vs] = skin
        if non_skin is not None:
            head[vs:] = non_skin
        else:  # cranium stays, jaw follows the rigid motion of its skin anchors
            jaw = np.nonzero(self.d.non_skin_bones == JAW)[0] + vs
            if len(jaw):
                a = self.d.jaw_anchors
                fit = umeyama(self.neutral[a], skin[a], with_scale=False)
                r, t = fit.rotation, fit.translation
                head[jaw] = self.neutral[jaw] @ r.T + t
        return head, vertex_normals(head, self.head_triangles)

    def evaluate_weights(self, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s = self.blend(weights)
        vs = self.d.skin_vertices
        x = self._dynamics("softdeca", self.softdeca_static(weights, s[:vs]))
        return self._finish(x, s[vs:])

    def evaluate_surface(
        self, weights: np.ndarray, surface: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        s = np.asarray(surface, dtype=np.float64)
        vs = self.d.skin_vertices
        x = self._dynamics("softdeca", self.softdeca_static(weights, s[:vs]))
        return self._finish(x, s[vs:] if len(s) == self.d.head_vertices else None)

    def evaluate_landmarks(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = self._dynamics("sparse", self.sparse_static(points))
        return self._finish(x, None)

    def evaluate_linear(self, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        head = self.blend(weights)
        return head, vertex_normals(head, self.head_triangles)
