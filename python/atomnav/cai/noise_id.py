"""Fringe noise identification (Tennstedt et al. 2021, §3).

Readout p_i = p0 + A cos(φ + ψ_i) with noise on offset (σ_p0), phase (σ_φ, rad) and
amplitude (σ_A); ψ_i is the known phase of shot i (from a vibration sensor). The residual
variance is a + b sin²φ_i with a = σ_p0² + σ_A², b = A²σ_φ² − σ_A²: only (a, b) are
identifiable, so (σ_p0, σ_φ, σ_A) are estimated with at least one of them fixed; asking
for all three raises an :class:`atomnav.InputError` that says so.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _core, plausibility
from .._validate import as_floats, choice, finite_scalar, flag, generator, input_error, integer, nonnegative, table, vector

_NAMES = ("p0", "phi", "A")


def simulate_fringe(n: int, *, p0: float = 0.5, phi: float = 1.0, amplitude: float = 0.15, sigma_p0: float = 0.025,
                    sigma_phi: float = 0.23, sigma_A: float = 0.02, seed=None):
    """n readouts of the nonlinear fringe model with noise on offset, phase and amplitude.

    p = (p0 + n_p0) + (A + n_A) cos(φ + ψ + n_φ) (Tennstedt et al. 2021, Eq. 17), with ψ
    uniform on [0, 2π) (fringe scanned by vibration).

    Parameters
    ----------
    n : int
        Number of readouts.
    p0 : float
        Population offset p0.
    phi : float
        Fringe phase φ (rad).
    amplitude : float
        Fringe amplitude A (population units).
    sigma_p0 : float
        Standard deviation of the offset noise n_p0 (population units).
    sigma_phi : float
        Standard deviation of the phase noise n_φ (rad).
    sigma_A : float
        Standard deviation of the amplitude noise n_A (population units).
    seed : int, numpy.random.Generator or None
        Seed (an int ≥ 0) or generator of the draws; None draws fresh entropy.

    Returns
    -------
    p : numpy.ndarray, shape (n,)
        Readouts (population).
    psi : numpy.ndarray, shape (n,)
        Known phase ψ of each shot (rad).
    """
    n = integer(n, "n", 0, 100_000_000)
    p0, phi, amplitude = (finite_scalar(v, name) for name, v in (("p0", p0), ("phi", phi), ("amplitude", amplitude)))
    sigma_p0, sigma_phi, sigma_A = (nonnegative(v, name) for name, v in (
        ("sigma_p0", sigma_p0), ("sigma_phi", sigma_phi), ("sigma_A", sigma_A)))
    rng = generator(seed, "seed")
    psi = rng.uniform(0.0, 2 * np.pi, n)
    p = (p0 + rng.normal(0, sigma_p0, n)) + (amplitude + rng.normal(0, sigma_A, n)) * np.cos(phi + psi + rng.normal(0, sigma_phi, n))
    return p, psi


def fringe_track(p, psi, *, zeta0=(0.5, 0.0, 0.1), sigma0=(0.1, 1.0, 0.1), q=(1e-9, 1e-7, 1e-9),
                 r: float = 1e-3) -> pd.DataFrame:
    """Fringe-tracking EKF on ζ = [p0, φ, A] (Tennstedt et al. 2021, Sec. 3.2).

    The readout model is p_i = p0 + A cos(φ + ψ_i); the state is a random walk. Departures
    from the paper are described in ``docs/departures.md#fringe-tracking``.

    Parameters
    ----------
    p : array_like, shape (N,)
        Readouts (population, 0–1).
    psi : array_like, shape (N,)
        Known phase ψ_i of each shot (rad), e.g. from a vibration sensor.
    zeta0 : array_like, shape (3,)
        Initial state [p0, φ (rad), A].
    sigma0 : array_like, shape (3,)
        Initial σ of [p0, φ (rad), A], uncorrelated.
    q : array_like, shape (3,)
        Random-walk variance per shot of [p0, φ (rad²), A].
    r : float
        Readout variance (population², > 0).

    Returns
    -------
    pandas.DataFrame
        One row per readout, the state after its update: ``p0``, ``phi_rad`` (wrapped to
        (−π, π]) and ``A`` (kept > 0).
    """
    z = _core.cai_fringe_track(plausibility.population(vector(p, None, "p"), "p"), vector(psi, None, "psi"), vector(zeta0, 3, "zeta0"),
                               vector(sigma0, 3, "sigma0"), vector(q, 3, "q"), finite_scalar(r, "r"))
    return pd.DataFrame({"p0": z[:, 0], "phi_rad": z[:, 1], "A": z[:, 2]})


def residuals(p, psi, track: pd.DataFrame):
    """Residuals x_i = p_i − (p̂0 + Â cos φ_i) of a fringe track, with its phases and amplitudes.

    Parameters
    ----------
    p : array_like, shape (N,)
        Readouts (population).
    psi : array_like, shape (N,)
        Known phase ψ_i of each shot (rad).
    track : pandas.DataFrame
        The N-row result of :func:`fringe_track` (columns ``p0``, ``phi_rad``, ``A``,
        read by name).

    Returns
    -------
    x : numpy.ndarray, shape (N,)
        Residuals x_i (population).
    phase : numpy.ndarray, shape (N,)
        Fringe phases φ_i = φ̂ + ψ_i (rad).
    amplitude : numpy.ndarray, shape (N,)
        Tracked amplitudes Â (population units).
    """
    p0, phi, amp = table(track, ["p0", "phi_rad", "A"], "track").T  # a frame of fringe_track, read by name
    n = len(p0)
    phase = phi + vector(psi, n, "psi")
    return vector(p, n, "p") - (p0 + amp * np.cos(phase)), phase, amp


def identify_noise(x, phi, amplitude, *, free=("p0", "phi"), theta0=(0.02, 0.2, 0.02), method: str = "newton",
                   batch: int | None = None, sliding: bool = False, max_iter: int = 100,
                   tol: float = 1e-6) -> pd.DataFrame:
    """Maximum-likelihood (σ_p0, σ_φ, σ_A) from fringe residuals (Tennstedt et al. 2021, Eqs. 18–26).

    Only a = σ_p0² + σ_A² and b = Ā²σ_φ² − σ_A² are identifiable, so at most two of the
    three components are estimated; departures from the paper are described in
    ``docs/departures.md#identifiable-readout-noise``.

    Parameters
    ----------
    x : array_like, shape (N,)
        Residuals (population), e.g. from :func:`residuals`.
    phi : array_like, shape (N,)
        Fringe phases φ_i (rad).
    amplitude : array_like, shape (N,)
        Fringe amplitudes (population units).
    free : list or tuple of {"p0", "phi", "A"}
        The estimated components (at most two); the others stay at ``theta0``.
    theta0 : array_like, shape (3,)
        Starting (and fixed) values of (σ_p0, σ_φ (rad), σ_A).
    method : {"newton", "gradient"}
        Newton iteration, or gradient ascent (Tennstedt et al. 2021, Eqs. 22–25).
    batch : int, optional
        Samples per estimate, in [3, N] (default: all; Tennstedt et al. 2021 use 200).
    sliding : bool
        False: consecutive batches; True: a window of ``batch`` samples ending at every
        sample, each estimate warm-started from the previous one.
    max_iter : int
        Maximum iterations per estimate.
    tol : float
        Convergence tolerance.

    Returns
    -------
    pandas.DataFrame
        One row per estimate: ``sigma_p0``, ``sigma_phi_rad``, ``sigma_A``, the
        identifiable ``a`` = σ_p0² + σ_A², ``b`` = Ā²σ_φ² − σ_A², ``R_mid`` = a + b
        (readout variance at mid-fringe), ``iterations``, ``converged``,
        ``log_likelihood`` and ``hessian_eig_ratio`` (smallest / largest eigenvalue
        magnitude of the Hessian of ln L in the three variances, ≈ 0: the unidentifiable
        direction); the standard errors ``se_sigma_p0``, ``se_sigma_phi_rad``,
        ``se_sigma_A``, ``se_a``, ``se_b`` from the observed information of the free
        variances (0 for a component held fixed, +inf where the information is singular,
        e.g. an estimate at zero). Over Monte-Carlo batches of 200 readouts their scatter
        matches these standard errors within 10 % (``tests/consistency``).

    Raises
    ------
    atomnav.InputError
        Naming ``free`` when all three components are asked for.
    """
    if isinstance(free, str) or not isinstance(free, (list, tuple)) or not all(isinstance(f, str) for f in free):
        raise TypeError(f"free: expected a list of names from {_NAMES}, got {type(free).__name__}")
    for f in free:
        choice(f, _NAMES, "free")
    x = vector(x, None, "x")
    mask = [n in free for n in _NAMES]
    n = len(x)
    res = _core.cai_ml_identify(x, vector(phi, n, "phi"), vector(amplitude, n, "amplitude"), method=method, free=mask,
                                theta0=vector(theta0, 3, "theta0"), max_iter=max_iter, tol=finite_scalar(tol, "tol"), batch=n if batch is None else batch,
                                sliding=flag(sliding, "sliding"))
    th = res["theta"]
    return pd.DataFrame({
        "sigma_p0": th[:, 0], "sigma_phi_rad": th[:, 1], "sigma_A": th[:, 2],
        "a": res["a"], "b": res["b"], "R_mid": res["a"] + res["b"],
        "iterations": res["iterations"], "converged": res["converged"],
        "log_likelihood": res["log_likelihood"], "hessian_eig_ratio": np.abs(res["hessian_eigenvalues"][:, 0] / res["hessian_eigenvalues"][:, 2]),
        "se_sigma_p0": res["se_theta"][:, 0], "se_sigma_phi_rad": res["se_theta"][:, 1], "se_sigma_A": res["se_theta"][:, 2],
        "se_a": res["se_a"], "se_b": res["se_b"],
    })


def readout_variance(a: float, b: float, phi) -> np.ndarray:
    """Readout variance σ_p²(φ) = a + b sin²φ, the measurement variance R (Tennstedt et al. 2021, Eq. 26).

    Parameters
    ----------
    a, b : float or array_like
        Identifiable noise parameters a = σ_p0² + σ_A² and b = A²σ_φ² − σ_A²
        (population²), as :func:`identify_noise` returns them.
    phi : float or array_like
        Fringe phase φ (rad), broadcast against ``a`` and ``b``.

    Returns
    -------
    float or numpy.ndarray
        σ_p² (population²), the broadcast shape of the inputs.
    """
    a, b, phi = as_floats(a, "a"), as_floats(b, "b"), as_floats(phi, "phi")
    try:
        return a + b * np.sin(phi) ** 2
    except ValueError:
        raise input_error("phi", f"shape {phi.shape} does not broadcast with a {a.shape} and b {b.shape}") from None
