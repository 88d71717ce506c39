"""Steady-state Kalman filter analysis (Rust core).

Filter-form discrete algebraic Riccati equation (Tennstedt, Weddig & Schön 2021, Eq. 31)::

    P⁻ = Φ P⁻ Φᵀ + Q − Φ P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻ Φᵀ
    P⁺ = P⁻ − P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻,     K∞ = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹

solved by structure-preserving doubling with state scaling (Chu, Fan & Lin 2005), on
register kernels for small states and on faer's blocked algebra for large ones. Units: P
in the squared units of the state, Q per filter step, R in the squared units of the
measurement.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass

import numpy as np

from .. import _core
from .._validate import as_floats, finite, finite_result, finite_scalar, input_error


def _mat(x, name: str) -> np.ndarray:
    """``x`` as a C-contiguous 2-D float64 array (a scalar is 1×1)."""
    a = as_floats(x, name)
    if a.ndim == 0:
        a = a.reshape(1, 1)
    if a.ndim != 2:
        raise input_error(name, f"expected a 2-D array, got shape {a.shape}")
    return np.ascontiguousarray(a)


@dataclass(frozen=True)
class SteadyState:
    """Steady state of a Kalman filter: a-priori and a-posteriori covariance and gain.

    Returned by :func:`dare`.

    Attributes
    ----------
    p_prior : numpy.ndarray (n, n)
        A-priori covariance P⁻, squared state units.
    p_post : numpy.ndarray (n, n)
        A-posteriori covariance P⁺, squared state units.
    gain : numpy.ndarray (n, m)
        Steady-state gain K∞, state units per measurement unit.
    iterations : int
        Number of doubling iterations.
    """

    p_prior: np.ndarray
    p_post: np.ndarray
    gain: np.ndarray
    iterations: int


def dare(phi, q, h, r) -> SteadyState:
    """Solve the filter-form DARE (Tennstedt et al. 2021, Eq. 31).

    Scalars are accepted as 1×1.

    Parameters
    ----------
    phi : (n, n) array_like
        Transition matrix over one filter step.
    q : (n, n) array_like
        Process noise covariance per step (symmetric PSD), squared state units.
    h : (m, n) array_like
        Observation matrix.
    r : (m, m) array_like
        Measurement noise covariance (symmetric PD), squared measurement units.

    Returns
    -------
    SteadyState
        A-priori and a-posteriori covariance (squared state units), gain K∞ and the number
        of doubling iterations.

    Raises
    ------
    atomnav.InputError
        Bad shapes, non-finite values, asymmetric or indefinite q/r, and when no
        stabilising solution exists ((phi, h) not detectable or (phi, q) not stabilisable).
    """
    p_prior, p_post, gain, it = _core.dare(_mat(phi, "phi"), _mat(q, "q"), _mat(h, "h"), _mat(r, "r"))
    return SteadyState(p_prior, p_post, gain, it)


def closed_loop_matrix(phi, h, gain) -> np.ndarray:
    """Closed-loop transition Φ̃ = (I − K∞H)Φ (Tennstedt et al. 2021, Eq. 28).

    Parameters
    ----------
    phi : (n, n) array_like
        Transition matrix.
    h : (m, n) array_like
        Observation matrix.
    gain : (n, m) array_like
        Steady-state gain K∞ (e.g. ``dare(...).gain``).

    Returns
    -------
    (n, n) ndarray
    """
    phi, h, gain = _mat(phi, "phi"), _mat(h, "h"), _mat(gain, "gain")
    for a, name in ((phi, "phi"), (h, "h"), (gain, "gain")):
        finite(a, name)
    n, m = phi.shape[0], h.shape[0]
    if phi.shape != (n, n):
        raise input_error("phi", f"expected a square matrix, got shape {phi.shape}")
    if h.shape != (m, n):
        raise input_error("h", f"expected shape ({m}, {n}) to match phi {phi.shape}, got {h.shape}")
    if gain.shape != (n, m):
        raise input_error("gain", f"expected shape ({n}, {m}) to match phi and h, got {gain.shape}")
    with np.errstate(all="ignore"):
        out = (np.eye(n) - gain @ h) @ phi
    return finite_result(out, "phi", "(I − KH)Φ (phi, h or gain too large)")


def riccati_scalar(q: float, r: float, h: float) -> tuple[float, float]:
    """Scalar steady state for Φ = 1 (Tennstedt et al. 2021, Eqs. 32–35).

    Parameters
    ----------
    q : float
        Process noise variance per step (≥ 0), squared state units.
    r : float
        Measurement variance (> 0), squared measurement units.
    h : float
        Observation gain (≠ 0), measurement units per state unit.

    Returns
    -------
    (float, float)
        (P⁻, P⁺) in squared state units; Table 1 of Tennstedt et al. (2021) lists P⁺.

    Raises
    ------
    atomnav.InputError
        A non-finite or out-of-range argument, or an ``h`` so small that the steady state
        exceeds the floating-point range.
    """
    return _core.riccati_scalar(finite_scalar(q, "q"), finite_scalar(r, "r"), finite_scalar(h, "h"))


def kalman_recursion(phi, q, h, r, p0, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Iterate the Kalman covariance recursion (Tennstedt et al. 2021, Eq. 31) from
    P⁻₀ = p0 for ``steps`` steps.

    Parameters
    ----------
    phi, q, h, r : array_like
        The system as for :func:`dare`.
    p0 : (n, n) array_like
        Initial a-priori covariance (symmetric PSD), squared state units.
    steps : int
        Number of steps, at least 1 (the core's upper limit is in the error message).

    Returns
    -------
    (ndarray, ndarray)
        (P⁻, P⁺) stacks of shape (steps, n, n).

    Raises
    ------
    atomnav.InputError
        Bad matrices or a ``steps`` out of range; ``MemoryError`` naming the size when the
        stacks do not fit in memory.
    """
    try:
        steps = operator.index(steps)
    except TypeError:
        raise TypeError(f"steps: expected an int, got {type(steps).__name__}") from None
    return _core.kalman_recursion(_mat(phi, "phi"), _mat(q, "q"), _mat(h, "h"), _mat(r, "r"), _mat(p0, "p0"), steps)
