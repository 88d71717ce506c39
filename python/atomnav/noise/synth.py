"""Seeded synthetic data: model A (ARIMA(2,1,1) with the paper's
coefficients) and model B (white + flicker + rate random walk + trend calibrated to the
paper's raw metrics). Rates in °/h, τ₀ = 52 s, mean shifted to exactly 0.6851 °/h.
Both draw from ``numpy.random.default_rng(seed)`` in the documented order, so the
same seed gives the same series on every machine."""

from __future__ import annotations

import numpy as np
from .. import units
from .._validate import as_floats, finite_result, finite_scalar, generator, instance, integer, nonnegative, positive, vector
from .filters import PAPER_AR, PAPER_MA, PAPER_SIGMA2

#: Niu et al. 2025: sample interval (s), record length, Table 2 raw mean (°/h).
TAU0 = 52.0
N_SAMPLES = 900
MEAN = 0.6851


def _n(n: int) -> int:
    return integer(n, "n", 1)


def flicker(rng: np.random.Generator, n: int, sigma: float) -> np.ndarray:
    """Kasdin–Walter flicker (α = 1): (h ∗ e)[:n], h₀ = 1, h_j = h_{j−1}(j − ½)/j,
    e ~ N(0, sigma²). Its Allan plateau is ≈ (2 ln 2/π)·sigma².

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the white draws e.
    n : int
        Number of samples (≥ 1).
    sigma : float
        Standard deviation of e, in the unit of the output (≥ 0).

    Returns
    -------
    numpy.ndarray (n,)
        Flicker series, in the unit of ``sigma``.

    References
    ----------
    N. J. Kasdin and T. Walter, "Discrete simulation of power law noise", Proc. IEEE
    Frequency Control Symposium (1992).
    """
    from scipy.signal import fftconvolve

    instance(rng, np.random.Generator, "rng")
    n, sigma = _n(n), nonnegative(sigma, "sigma")
    j = np.arange(1, n)
    h = np.concatenate([[1.0], np.cumprod((j - 0.5) / j)])
    e = rng.normal(0.0, sigma, n)
    return fftconvolve(h, e)[:n]


def model_a(seed: int = 20250226, n: int = N_SAMPLES, ar=PAPER_AR, ma=PAPER_MA, sigma2: float = PAPER_SIGMA2, burn_in: int = 500, mean: float = MEAN) -> np.ndarray:
    """Model A (°/h): d_n = φ₁d_{n−1} + φ₂d_{n−2} + a_n + β₁a_{n−1}, a ~ N(0, σ²), zero
    pre-sample values, first ``burn_in`` dropped, ω = cumsum(d) shifted to ``mean``.

    Parameters
    ----------
    seed : int, default 20250226
        Seed of ``numpy.random.default_rng``.
    n : int, default N_SAMPLES (900)
        Number of samples (≥ 1).
    ar : array_like (p,), default PAPER_AR
        AR coefficients φ of the differenced series.
    ma : array_like (q,), default PAPER_MA
        MA coefficients β.
    sigma2 : float, default PAPER_SIGMA2
        Innovation variance σ², (°/h)² (≥ 0).
    burn_in : int, default 500
        Leading samples drawn and dropped.
    mean : float, default MEAN (0.6851)
        Mean of the returned series, °/h.

    Returns
    -------
    numpy.ndarray (n,)
        Rate series, °/h.

    Raises
    ------
    atomnav.InputError
        Naming ``ar`` when the simulated rate is not finite (an explosive AR polynomial,
        or ``ma`` or ``sigma2`` too large).
    """
    from scipy.signal import lfilter

    n = _n(n)
    burn_in = integer(burn_in, "burn_in", 0, 10**8)
    ar, ma = (vector(np.atleast_1d(as_floats(v, k)), None, k) for k, v in (("ar", ar), ("ma", ma)))
    sigma2, mean = nonnegative(sigma2, "sigma2"), finite_scalar(mean, "mean")
    rng = generator(seed, "seed")
    a = rng.normal(0.0, np.sqrt(sigma2), n + burn_in)
    with np.errstate(all="ignore"):
        d = lfilter(np.r_[1.0, ma], np.r_[1.0, -ar], a)[burn_in:]
        w = np.cumsum(d)
        w = w - w.mean() + mean
    return finite_result(w, "ar", "the simulated rate (an explosive AR polynomial, or ma or sigma2 too large)")


def model_b(seed: int = 105, n: int = N_SAMPLES, tau0: float = TAU0, arw: float = 0.015, flicker_b: float = 0.01, rrw: float = 0.01, ramp: float = 0.0042, mean: float = MEAN) -> np.ndarray:
    """Model B (°/h) = white (ARW ``arw`` °/√h) + flicker (``flicker_b`` °/h) + rate
    random walk (``rrw`` °/h/√h) + trend (``ramp`` °/h per h), drawn in that order, then
    shifted to ``mean``. Per-sample σ of the white part: arw/√(τ₀/h).

    Parameters
    ----------
    seed : int, default 105
        Seed of ``numpy.random.default_rng``.
    n : int, default N_SAMPLES (900)
        Number of samples (≥ 1).
    tau0 : float, default TAU0 (52.0)
        Sampling interval, s.
    arw : float, default 0.015
        Angle random walk, °/√h (≥ 0).
    flicker_b : float, default 0.01
        Per-sample σ of the flicker draws, °/h (≥ 0; see :func:`flicker`).
    rrw : float, default 0.01
        Rate random walk, °/h/√h (≥ 0).
    ramp : float, default 0.0042
        Trend, °/h per h.
    mean : float, default MEAN (0.6851)
        Mean of the returned series, °/h.

    Returns
    -------
    numpy.ndarray (n,)
        Rate series, °/h.
    """
    n = _n(n)
    tau0 = positive(tau0, "tau0")
    arw, flicker_b, rrw = (nonnegative(v, k) for k, v in (("arw", arw), ("flicker_b", flicker_b), ("rrw", rrw)))
    ramp, mean = finite_scalar(ramp, "ramp"), finite_scalar(mean, "mean")
    rng = generator(seed, "seed")
    hours = tau0 / units.HOUR
    with np.errstate(all="ignore"):
        white = rng.normal(0.0, finite_result(arw / np.sqrt(hours), "arw", "the white-noise σ per sample"), n)
        fl = flicker(rng, n, flicker_b)
        rw = np.cumsum(rng.normal(0.0, finite_result(rrw * np.sqrt(hours), "rrw", "the random-walk σ per sample"), n))
        trend = ramp * hours * np.arange(n)
        w = white + fl + rw + trend
        w = w - w.mean() + mean
    return finite_result(w, "tau0", "the simulated rate (τ₀, a noise level or the ramp too large)")
