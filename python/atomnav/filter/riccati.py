"""Steady-state Kalman filter analysis (Rust core).

Filter-form discrete algebraic Riccati equation (spec cai-ekf E24/E25, seed 000 Eq. 31)::

    P⁻ = Φ P⁻ Φᵀ + Q − Φ P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻ Φᵀ
    P⁺ = P⁻ − P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻,     K∞ = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹

solved by structure-preserving doubling with state scaling. Units: P in the squared
units of the state, Q per filter step, R in the squared units of the measurement.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core


def _mat(x, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim == 0:
        a = a.reshape(1, 1)
    if a.ndim != 2:
        raise ValueError(f"{name}: expected a 2-D array, got shape {a.shape}")
    return np.ascontiguousarray(a)


@dataclass(frozen=True)
class SteadyState:
    """Steady state of a Kalman filter: a-priori and a-posteriori covariance and gain."""

    p_prior: np.ndarray
    p_post: np.ndarray
    gain: np.ndarray
    iterations: int


def dare(phi, q, h, r) -> SteadyState:
    """Solve the filter-form DARE.

    phi (n, n) transition, q (n, n) process noise per step (PSD), h (m, n) observation,
    r (m, m) measurement noise (PD). Scalars are accepted as 1×1. Raises ValueError on
    bad shapes, asymmetric or indefinite q/r, and when no stabilising solution exists
    ((phi, h) not detectable or (phi, q) not stabilisable).
    """
    p_prior, p_post, gain, it = _core.dare(_mat(phi, "phi"), _mat(q, "q"), _mat(h, "h"), _mat(r, "r"))
    return SteadyState(p_prior, p_post, gain, it)


def closed_loop_matrix(phi, h, gain) -> np.ndarray:
    """Φ̃ = (I − K∞H)Φ (spec cai-ekf E22, seed 000 Eq. 28)."""
    phi, h, gain = _mat(phi, "phi"), _mat(h, "h"), _mat(gain, "gain")
    return (np.eye(phi.shape[0]) - gain @ h) @ phi


def riccati_scalar(q: float, r: float, h: float) -> tuple[float, float]:
    """Scalar steady state for Φ = 1 (spec cai-ekf E26/E27, seed 000 Eqs. 32–35).

    q process noise per step, r measurement variance, h observation gain.
    Returns (P⁻, P⁺); Table 1 of seed 000 lists P⁺.
    """
    return _core.riccati_scalar(float(q), float(r), float(h))


def kalman_recursion(phi, q, h, r, p0, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Iterate the Kalman covariance recursion from P⁻₀ = p0 for ``steps`` steps.

    Returns (P⁻, P⁺) stacks of shape (steps, n, n).
    """
    if int(steps) < 1:
        raise ValueError(f"steps: must be >= 1, got {steps}")
    return _core.kalman_recursion(_mat(phi, "phi"), _mat(q, "q"), _mat(h, "h"), _mat(r, "r"), _mat(p0, "p0"), int(steps))
