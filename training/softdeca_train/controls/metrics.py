"""What one control does, as numbers: the change between the two ends of its range on the
physics and on a model, and the figures of the gallery and the evaluation report. Pure numpy,
so the figures are tested on tiny cases without a simulator."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Response:
    """The figures of one control over its cases (identities x expressions)."""

    physics_max_mm: float  # largest |change| of the physics at any vertex of the region
    physics_mean_mm: float  # mean |change| of the physics over the region's vertices
    model_max_mm: float
    response_error: float | None  # |dM - dP| / |dP| over all cases; None when dP is zero
    leakage: float | None  # model: mean |dM| outside the region / inside; None for global
    physics_leakage: float | None  # the same for the physics (how local the control is)


def _norms(delta: np.ndarray) -> np.ndarray:
    """(..., V, 3) metres -> (..., V) millimetres."""
    return 1e3 * np.linalg.norm(np.asarray(delta, np.float64), axis=-1)


def response_error(delta_model: np.ndarray, delta_physics: np.ndarray) -> float | None:
    """‖ΔM − ΔP‖ / ‖ΔP‖ (Frobenius over every case and vertex); None when the physics does
    not move (the ratio is undefined, and the control is dead there)."""
    dp = np.asarray(delta_physics, np.float64)
    ref = float(np.linalg.norm(dp))
    if ref == 0.0:
        return None
    return float(np.linalg.norm(np.asarray(delta_model, np.float64) - dp)) / ref


def leakage(delta: np.ndarray, inside: np.ndarray | None) -> float | None:
    """Mean |change| outside the region over mean |change| inside it; None for a global
    control (no region) or when nothing moves inside."""
    if inside is None:
        return None
    inside = np.asarray(inside, bool)
    if inside.all() or not inside.any():
        raise ValueError("a region must hold some vertices but not all")
    d = _norms(delta).reshape(-1, inside.size)
    inner = float(d[:, inside].mean())
    if inner == 0.0:
        return None
    return float(d[:, ~inside].mean()) / inner


def identity_spread(deltas: list[np.ndarray]) -> float | None:
    """How much the physics' response differs between identities: the mean over ordered pairs
    (a, b) of ‖ΔP_a − ΔP_b‖ / ‖ΔP_b‖, one identity's change (cases, V, 3) standing in for
    another's on the same expressions. A model that gives every identity the same change
    cannot do much better than about 1/√2 of it (the spread around the mean response). None
    with fewer than two identities or where an identity's physics does not move."""
    if len(deltas) < 2:
        return None
    errors = []
    for b, own in enumerate(deltas):
        for a, other in enumerate(deltas):
            if a != b:
                if np.shape(other) != np.shape(own):
                    raise ValueError("identities must be measured on the same cases")
                e = response_error(other, own)
                if e is None:
                    return None
                errors.append(e)
    return float(np.mean(errors))


def control_response(
    delta_physics: np.ndarray, delta_model: np.ndarray, inside: np.ndarray | None
) -> Response:
    """Figures of one control from its changes (cases, V, 3) in metres; `inside`: (V,) mask of
    its region, None for a global control (then every vertex counts as its region)."""
    dp, dm = _norms(delta_physics), _norms(delta_model)
    region = np.ones(dp.shape[-1], bool) if inside is None else np.asarray(inside, bool)
    return Response(
        physics_max_mm=float(dp[..., region].max()),
        physics_mean_mm=float(dp[..., region].mean()),
        model_max_mm=float(dm[..., region].max()),
        response_error=response_error(delta_model, delta_physics),
        leakage=leakage(delta_model, inside),
        physics_leakage=leakage(delta_physics, inside),
    )


@dataclass(frozen=True)
class RestSplit:
    """A control's change split at rest: the part the physics makes with no expression (which
    a bundle's physics at prepare gives) and what each expression adds to it."""

    rest_error: float | None  # ‖ΔM₀ − ΔP₀‖ / ‖ΔP₀‖ at rest; None where the physics rests
    expression_share: float  # ‖ΔP − ΔP₀‖ / ‖ΔP‖: how much of the change the expression makes
    # ‖(ΔM − ΔM₀) − (ΔP − ΔP₀)‖ / ‖ΔP − ΔP₀‖: above 1, the model's expression part is worse
    # than none; None where the expression adds nothing
    expression_error: float | None


def rest_split(
    delta_physics: np.ndarray,
    rest_physics: np.ndarray,
    delta_model: np.ndarray,
    rest_model: np.ndarray,
) -> RestSplit:
    """From the changes (cases, V, 3) in metres at the expressions and at rest (each identity's
    change at rest repeated over its expressions)."""
    dp, dp0 = np.asarray(delta_physics, np.float64), np.asarray(rest_physics, np.float64)
    dm, dm0 = np.asarray(delta_model, np.float64), np.asarray(rest_model, np.float64)
    ref = float(np.linalg.norm(dp))
    if ref == 0.0:
        raise ValueError("the physics does not move: nothing to split")
    added_p, added_m = dp - dp0, dm - dm0
    return RestSplit(
        rest_error=response_error(dm0, dp0),
        expression_share=float(np.linalg.norm(added_p)) / ref,
        expression_error=response_error(added_m, added_p),
    )
