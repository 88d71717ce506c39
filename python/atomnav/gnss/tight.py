"""Tightly coupled GPS + GLONASS / INS on the generic aided-INS engine (Rust
``gnss/tight.rs``; spec gnss-ins-tight §2.12): between-satellite first differences of code
and pseudorange rate with c·τ_GPS as an extra state (default), or undifferenced rows with
receiver clock states; lever arm; open or closed loop and ΔT = MΔt from the engine."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _core
from .._validate import choice, vector
from ..filter.aided import AidedIns, ins_setup
from ..filter.engine import BiasModel
from .ephemeris import Ephemerides
from .observations import C_LIGHT, obs_arrays


def tight_ins(eph: Ephemerides, obs: pd.DataFrame, t0: float, lla0, vel0, q0, kind: str, p0_ins, accel_psd: float,
              gyro_psd: float, accel_bias: BiasModel = BiasModel(), gyro_bias: BiasModel = BiasModel(),
              formulation: str = "first_difference", lever_arm=(0.0, 0.0, 0.0), sigma_code: float = 3.0,
              sigma_code_glonass: float | None = None, sigma_rate: float = 0.05, use_rate: bool = True,
              iono: bool = True, tropo: bool = True, tau0: float = 0.0, sigma_tau0: float = 1e-6,
              tau_psd: float = (0.1e-9) ** 2 / 3600.0, clock0=(0.0, 0.0), sigma_clock0=(3e5, 300.0),
              clock_h0: float = 2e-19, clock_hm2: float = 2e-20, ba0=(0, 0, 0), bg0=(0, 0, 0), predict_every: int = 1,
              method: str = "van_loan", mode: str = "closed", sequential: bool = True, gate: float | None = 10.83,
              ellipsoid: str = "WGS84", **vertical) -> AidedIns:
    """A tightly coupled aided INS.

    ``obs``: observation table (``time_s, sat, channel, code_m, rate_mps``, GPS time; see
    :func:`atomnav.gnss.simulate` or :func:`atomnav.gnss.rinex.read`); the INS arguments
    (t0, lla0, vel0, q0, kind, biases, predict_every = M, method, mode "closed"/"open",
    sequential, gate) as :func:`atomnav.filter.aided.position_aided_ins`, with ``p0_ins``
    the 15 × 15 INS block. GNSS: ``formulation`` "first_difference" or "clock_states";
    ``lever_arm`` IMU → antenna in body axes (m); code σ (m), rate σ (m/s);
    Klobuchar/Saastamoinen corrections; τ_GPS initial value ``tau0`` ± ``sigma_tau0`` (s)
    and random-walk PSD ``tau_psd`` (s²/s; spec Eq. 42: (0.1 ns)²/h); clock states (m, m/s)
    with oscillator h₀ (s), h₋₂ (1/s); the nominal clock bias follows the drift between
    epochs. Extra states are carried in metres: ``c_tau_gps`` = c·τ_GPS and ``clock`` =
    (c·δt_r, c·δṫ_r). The default gate 10.83 is χ²₁ at 0.999 per decorrelated row (spec
    Eq. 40). A barometric altimeter damps the vertical channel through the ``vertical``
    keywords of :func:`atomnav.filter.aided.position_aided_ins` (``vertical="damped"``,
    then ``run(..., h_ref=...)``; spec decision 13)."""
    choice(formulation, ("first_difference", "clock_states"), "formulation")
    p_ins = np.asarray(p0_ins, float)
    if p_ins.shape != (15, 15):
        raise ValueError(f"p0_ins: expected (15, 15), got {p_ins.shape}")
    extra = [C_LIGHT * float(tau0)]
    var = [(C_LIGHT * float(sigma_tau0)) ** 2]
    if formulation == "clock_states":
        extra += [float(c) for c in vector(clock0, 2, "clock0")]
        var += [float(s) ** 2 for s in vector(sigma_clock0, 2, "sigma_clock0")]
    n = 15 + len(extra)
    p0 = np.zeros((n, n))
    p0[:15, :15] = p_ins
    p0[15:, 15:] = np.diag(var)
    ins = ins_setup(t0, lla0, vel0, q0, kind, p0, accel_psd, gyro_psd, accel_bias, gyro_bias, ba0, bg0,
                    predict_every, method, mode, sequential, gate, ellipsoid, **vertical)
    core = _core.gnss_tight_ins(
        eph._core, *obs_arrays(obs), formulation=formulation, lever_arm=vector(lever_arm, 3, "lever_arm"),
        sigma_code_gps=float(sigma_code), sigma_code_glo=float(sigma_code if sigma_code_glonass is None else sigma_code_glonass),
        sigma_rate=float(sigma_rate), use_rate=bool(use_rate), iono=bool(iono), tropo=bool(tropo),
        tau_psd=C_LIGHT ** 2 * float(tau_psd), clock_h0=float(clock_h0), clock_hm2=float(clock_hm2),
        ins=ins, extra0=np.array(extra))
    return AidedIns(core, kind)
