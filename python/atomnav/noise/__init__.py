"""Sensor noise analysis (Niu et al. 2025).

- :mod:`.allan` — overlapping/modified Allan and Hadamard variance (Rust), EDF
  confidence intervals, the five-term IEEE-952 fit, bias / bias stability / SS / LS,
  improvement ratio.
- :mod:`.filters` — ARIMA(p,d,q) state-space form and the fixed, Eq. 17-adaptive and
  Sage–Husa Kalman filters (Rust), batch and streaming.
- :mod:`.arma` — differencing, ADF/KPSS, ACF/PACF, AIC/BIC order grid, exact-ML
  ARMA fit and residual diagnostics (statsmodels).
- :mod:`.baselines` — Butterworth low-pass and wavelet-threshold denoising.
- :mod:`.synth` — seeded synthetic data, model A and model B.
- :mod:`.report` — the paper's Tables 2–4 beside atomnav's values, Allan and PSD plots.

Notation: ω_k is the raw rate (°/h in the paper; the paper's x(n), y(n) in
Eqs. 9, 11–12), d_k = ω_k − ω_{k−1} the differenced series (the paper's y(n) in Eqs.
10–11, and the "y" of the differenced reading of Eq. 17), a_k the ARMA innovation.
"""

from . import allan, filters, arma, baselines, synth, report

__all__ = ["allan", "filters", "arma", "baselines", "synth", "report"]
