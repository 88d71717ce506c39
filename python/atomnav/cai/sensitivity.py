"""Sensitivity function and convolution predictor with finite rectangular pulses (Tennstedt
et al. 2023 Eqs. 13–14). Times are relative to
the centre of the π pulse; dark time T_d (s), π/2-pulse duration τ (s), pulse-centre
separation T = T_d + 1.5τ."""

from __future__ import annotations

import numpy as np

from .. import _core, plausibility
from .._validate import as_floats, finite_scalar, vector


def sensitivity(t, t_dark: float, tau: float):
    """Phase response g(t) and acceleration response f(t) of finite rectangular pulses.

    Tennstedt et al. 2023, Eq. 13; times relative to the centre of the π pulse.

    Parameters
    ----------
    t : float or array_like, shape (N,)
        Times (s) relative to the centre of the π pulse.
    t_dark : float
        Dark time T_d between the pulses (s).
    tau : float
        π/2-pulse duration τ (s).

    Returns
    -------
    g : numpy.ndarray, shape (N,)
        Phase response g(t) (dimensionless).
    f : numpy.ndarray, shape (N,)
        Acceleration response f(t) (s).
    """
    return _core.cai_sensitivity(vector(np.atleast_1d(as_floats(t, "t")), None, "t"), plausibility.pulse_separation(finite_scalar(t_dark, "t_dark"), "t_dark"),
                               finite_scalar(tau, "tau"))


def response_area(t_dark: float, tau: float) -> float:
    """Area of the acceleration response, ∫ f dt = (T_d + 2τ)(T_d + 4τ/π).

    Parameters
    ----------
    t_dark : float
        Dark time T_d between the pulses (s).
    tau : float
        π/2-pulse duration τ (s).

    Returns
    -------
    float
        ∫ f dt (s²).
    """
    return _core.cai_response_area(plausibility.pulse_separation(finite_scalar(t_dark, "t_dark"), "t_dark"), finite_scalar(tau, "tau"))


def convolution_phase(t, acceleration, centres, *, t_dark: float, tau: float, k: float) -> np.ndarray:
    """Convolution phase φ = k ∫ f(t − t_c) a(t) dt of shots centred at ``centres``.

    Tennstedt et al. 2023, Eq. 14. The acceleration is sampled at any rate and taken
    linear between samples (the atom strapdown equivalent is a = −k̂·f_s).

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times (s) of ``acceleration``.
    acceleration : array_like, shape (N,)
        Acceleration of the atoms relative to the sensor along k (m/s²) at times ``t``.
    centres : float or array_like, shape (S,)
        Centre times t_c of the shots (s), the centres of their π pulses.
    t_dark : float
        Dark time T_d between the pulses (s).
    tau : float
        π/2-pulse duration τ (s).
    k : float
        Effective wave number (rad/m).

    Returns
    -------
    numpy.ndarray, shape (S,)
        Phase φ of each shot (rad).
    """
    return _core.cai_convolution_phase(plausibility.pulse_separation(finite_scalar(t_dark, "t_dark"), "t_dark"), finite_scalar(tau, "tau"), finite_scalar(k, "k"),
                                       vector(t, None, "t"), np.ascontiguousarray(as_floats(acceleration, "acceleration")),
                                       vector(np.atleast_1d(as_floats(centres, "centres")), None, "centres"))


def ideal_transfer(T: float, omega) -> np.ndarray:
    """Ideal transfer ∫ (T − |t|) cos(ωt) dt = 4 sin²(ωT/2)/ω² of instantaneous pulses.

    Parameters
    ----------
    T : float
        Pulse separation (s).
    omega : float or array_like, shape (M,)
        Angular frequencies ω (rad/s).

    Returns
    -------
    numpy.ndarray, shape (M,)
        Transfer at each ω (s²).
    """
    return _core.cai_ideal_transfer(plausibility.pulse_separation(finite_scalar(T, "T"), "T"), vector(np.atleast_1d(as_floats(omega, "omega")), None, "omega"))
