"""Sensitivity function and convolution predictor with finite rectangular pulses (Tennstedt
et al. 2023 Eqs. 13–14). Times are relative to
the centre of the π pulse; dark time T_d (s), π/2-pulse duration τ (s), pulse-centre
separation T = T_d + 1.5τ."""

from __future__ import annotations

import numpy as np

from .. import _core, plausibility
from .._validate import as_floats, finite_scalar, vector


def sensitivity(t, t_dark: float, tau: float):
    """Phase response g(t) (dimensionless) and acceleration response f(t) (s) at times t (s)."""
    return _core.cai_sensitivity(vector(np.atleast_1d(as_floats(t, "t")), None, "t"), plausibility.pulse_separation(finite_scalar(t_dark, "t_dark"), "t_dark"),
                               finite_scalar(tau, "tau"))


def response_area(t_dark: float, tau: float) -> float:
    """∫ f dt = (T_d + 2τ)(T_d + 4τ/π) (s²)."""
    return _core.cai_response_area(plausibility.pulse_separation(finite_scalar(t_dark, "t_dark"), "t_dark"), finite_scalar(tau, "tau"))


def convolution_phase(t, acceleration, centres, *, t_dark: float, tau: float, k: float) -> np.ndarray:
    """Convolution phase φ = k ∫ f(t − t_c) a(t) dt (rad) of shots centred at ``centres`` (s)
    (Tennstedt et al. 2023 Eq. 14). ``acceleration`` (m/s²) of the atoms relative to the sensor along k,
    sampled at any rate at times t (s), linear between samples (the atom strapdown
    equivalent is a = −k̂·f_s)."""
    return _core.cai_convolution_phase(plausibility.pulse_separation(finite_scalar(t_dark, "t_dark"), "t_dark"), finite_scalar(tau, "tau"), finite_scalar(k, "k"),
                                       vector(t, None, "t"), np.ascontiguousarray(as_floats(acceleration, "acceleration")),
                                       vector(np.atleast_1d(as_floats(centres, "centres")), None, "centres"))


def ideal_transfer(T: float, omega) -> np.ndarray:
    """∫ (T − |t|) cos(ωt) dt = 4 sin²(ωT/2)/ω² (s²) for angular frequencies ω (rad/s)."""
    return _core.cai_ideal_transfer(plausibility.pulse_separation(finite_scalar(T, "T"), "T"), vector(np.atleast_1d(as_floats(omega, "omega")), None, "omega"))
