"""What `simulate` reports per frame, linear blendshapes against physics, on the same head:

- soft-tissue volume change (%): the soft tets' volume against the rest. Physics: the
  simulated vertices. Linear: the same tets with the layers above the muscle wrap refitted
  (least squares) so that S's embedding lands on the linear blend S_t, over the muscle wrap
  physics placed; both therefore differ only in where the skin is.
- penetrating lip vertices: skin points of the lip collision sets behind the other lip or a
  tooth (native find_penetrations, 10 µm tolerance), counted once per point.
- distance: mean |S_physics - S_t| over S (mm)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import softdeca_native as native

from softdeca_train.sim.head import HeadSimulation

PENETRATION_TOLERANCE = 1e-5  # m, as the simulator's default


class SoftVolume:
    """Soft-tissue volume of a head simulation's tets, and the linear skin refit."""

    def __init__(self, hs: HeadSimulation) -> None:
        self.tets = hs.mesh.soft_tets
        rest = hs.mesh.rest
        self._rest_volumes = np.asarray(native.tet_signed_volumes(rest, self.tets))
        self.rest_volume = float(self._rest_volumes.sum())
        # The refit moves the vertices of the soft tissue alone (not shared with the muscle
        # tets, not on a bone): the skin wrap's, for the LHM's prisms.
        free = np.zeros(len(rest), bool)
        free[np.unique(self.tets)] = True
        free[np.unique(hs.mesh.muscle_tets)] = False
        free[hs.mesh.cranium_vertices] = False
        free[hs.mesh.jaw_vertices] = False
        self.free_ids = np.flatnonzero(free)
        self.fixed_ids = np.flatnonzero(~free)
        rows = np.repeat(np.arange(len(hs.mesh.skin_vertices)), 4)
        cols = hs.mesh.skin_vertices.ravel()
        embed = sp.csr_matrix(
            (hs.mesh.skin_weights.ravel(), (rows, cols)), shape=(len(rows) // 4, len(rest))
        )
        self.free = embed[:, self.free_ids].tocsc()
        self.fixed = embed[:, self.fixed_ids].tocsr()
        normal = (self.free.T @ self.free).tocsc()
        self.ridge = 1e-6 * float(normal.diagonal().mean())
        self.solve = spla.factorized(
            (normal + self.ridge * sp.identity(len(self.free_ids))).tocsc()
        )

    def mean_over_tets(self, field: np.ndarray) -> float:
        """The rest-volume-weighted mean of a per-soft-tet field (e.g. a regional
        target_volume: the soft tissue's requested volume, relative to rest)."""
        rest = self._rest_volumes
        return float((rest * np.asarray(field, np.float64)).sum() / rest.sum())

    def change_percent(self, vertices: np.ndarray) -> float:
        v = float(native.tet_signed_volumes(np.asarray(vertices, np.float64), self.tets).sum())
        return 100.0 * (v / self.rest_volume - 1.0)

    def change_percent_by_group(self, vertices: np.ndarray, groups: np.ndarray) -> np.ndarray:
        """Per group of soft tets (`groups`: a non-negative id per tet) its volume change (%);
        NaN for ids that hold no tet."""
        v = np.asarray(native.tet_signed_volumes(np.asarray(vertices, np.float64), self.tets))
        rest = self._by_group(self._rest_volumes, groups)
        return 100.0 * (self._by_group(v, groups) / rest - 1.0)

    def requested_percent_by_group(self, field: np.ndarray, groups: np.ndarray) -> np.ndarray:
        """Per group the requested change (%) of a per-tet target_volume field (rest-weighted)."""
        rest = self._rest_volumes
        return 100.0 * (self._by_group(rest * field, groups) / self._by_group(rest, groups) - 1.0)

    def rest_share_by_group(self, groups: np.ndarray) -> np.ndarray:
        """Per group its share of the soft tissue's rest volume; NaN for ids without tets."""
        return self._by_group(self._rest_volumes, groups) / self.rest_volume

    @staticmethod
    def _by_group(values: np.ndarray, groups: np.ndarray) -> np.ndarray:
        sums = np.bincount(groups, weights=values)
        held = np.bincount(groups) > 0
        return np.where(held, sums, np.nan)

    def linear_vertices(self, skin_target: np.ndarray, simulated: np.ndarray) -> np.ndarray:
        """`simulated` with the soft tissue's own vertices refitted to the skin target."""
        x = np.asarray(simulated, np.float64).copy()
        rhs = np.asarray(skin_target, np.float64) - self.fixed @ x[self.fixed_ids]
        b = self.free.T @ rhs + self.ridge * x[self.free_ids]
        x[self.free_ids] = np.column_stack([self.solve(b[:, k]) for k in range(3)])
        return x


def penetrating_points(hs: HeadSimulation, skin: np.ndarray, vertices: np.ndarray) -> int:
    found = native.find_penetrations(
        hs.mesh,
        np.asarray(skin, np.float64),
        np.asarray(vertices, np.float64),
        PENETRATION_TOLERANCE,
    )
    return len({point for _, point, _ in found})


def mean_distance_mm(a: np.ndarray, b: np.ndarray) -> float:
    return 1e3 * float(np.linalg.norm(np.asarray(a) - np.asarray(b), axis=-1).mean())
