"""Seeded synthetic data of the spec (§5): model A (ARIMA(2,1,1) with the paper's
coefficients) and model B (white + flicker + rate random walk + trend calibrated to the
paper's raw metrics). Rates in °/h, τ₀ = 52 s, mean shifted to exactly 0.6851 °/h.
Both draw from ``numpy.random.default_rng(seed)`` in the documented order, so the
spec's reference numbers reproduce."""

from __future__ import annotations

import numpy as np
from .. import units
from .._validate import instance, integer, scalar
from .filters import PAPER_AR, PAPER_MA, PAPER_SIGMA2

#: Niu et al. 2025: sample interval (s), record length, Table 2 raw mean (°/h).
TAU0 = 52.0
N_SAMPLES = 900
MEAN = 0.6851


def _n(n: int) -> int:
    return integer(n, "n", 1)


def flicker(rng: np.random.Generator, n: int, sigma: float) -> np.ndarray:
    """Kasdin–Walter flicker (α = 1): (h ∗ e)[:n], h₀ = 1, h_j = h_{j−1}(j − ½)/j,
    e ~ N(0, sigma²). Its Allan plateau is ≈ (2 ln 2/π)·sigma²."""
    from scipy.signal import fftconvolve

    instance(rng, np.random.Generator, "rng")
    j = np.arange(1, n)
    h = np.concatenate([[1.0], np.cumprod((j - 0.5) / j)])
    e = rng.normal(0.0, sigma, n)
    return fftconvolve(h, e)[:n]


def model_a(seed: int = 20250226, n: int = N_SAMPLES, ar=PAPER_AR, ma=PAPER_MA, sigma2: float = PAPER_SIGMA2, burn_in: int = 500, mean: float = MEAN) -> np.ndarray:
    """Model A (°/h): d_n = φ₁d_{n−1} + φ₂d_{n−2} + a_n + β₁a_{n−1}, a ~ N(0, σ²), zero
    pre-sample values, first ``burn_in`` dropped, ω = cumsum(d) shifted to ``mean``."""
    from scipy.signal import lfilter

    n = _n(n)
    rng = np.random.default_rng(seed)
    a = rng.normal(0.0, np.sqrt(sigma2), n + burn_in)
    d = lfilter(np.r_[1.0, ma], np.r_[1.0, -np.asarray(ar, dtype=float)], a)[burn_in:]
    w = np.cumsum(d)
    return w - w.mean() + scalar(mean, "mean")


def model_b(seed: int = 105, n: int = N_SAMPLES, tau0: float = TAU0, arw: float = 0.015, flicker_b: float = 0.01, rrw: float = 0.01, ramp: float = 0.0042, mean: float = MEAN) -> np.ndarray:
    """Model B (°/h) = white (ARW ``arw`` °/√h) + flicker (``flicker_b`` °/h) + rate
    random walk (``rrw`` °/h/√h) + trend (``ramp`` °/h per h), drawn in that order, then
    shifted to ``mean``. Per-sample σ of the white part: arw/√(τ₀/h)."""
    n = _n(n)
    tau0, arw, flicker_b, rrw, ramp, mean = (scalar(v, k) for k, v in (
        ("tau0", tau0), ("arw", arw), ("flicker_b", flicker_b), ("rrw", rrw), ("ramp", ramp), ("mean", mean)))
    rng = np.random.default_rng(seed)
    hours = tau0 / units.HOUR
    white = rng.normal(0.0, arw / np.sqrt(hours), n)
    fl = flicker(rng, n, flicker_b)
    rw = np.cumsum(rng.normal(0.0, rrw * np.sqrt(hours), n))
    trend = ramp * hours * np.arange(n)
    w = white + fl + rw + trend
    return w - w.mean() + scalar(mean, "mean")
