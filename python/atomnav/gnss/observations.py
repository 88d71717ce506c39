"""Simulated code and pseudorange-rate observations (spec gnss-ins-tight §2.6) as a table
with one row per satellite and epoch: ``time_s, sat, channel, code_m, rate_mps``.
GLONASS code is delivered with c·ΔT_leap removed (Eq. 15)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _core
from .._validate import input_error, rows, vector
from .ephemeris import Ephemerides
from .options import GnssOptions, split_options

C_LIGHT = 299792458.0
OBS_COLUMNS = ["time_s", "sat", "channel", "code_m", "rate_mps"]


def simulate(eph: Ephemerides, time, lla, vel_ned, options: GnssOptions | None = None, *, tau_gps: float = 0.0,
             clock_bias: float = 0.0, clock_drift: float = 0.0, mask_deg: float = 10.0, only: list[str] | None = None,
             outages=(), sat_outages=(), seed: int = 0, **option_fields) -> pd.DataFrame:
    """Observations of a receiver at ``lla`` (N, 3) rad/rad/m with NED velocity ``vel_ned``
    (N, 3) m/s at GPS times ``time`` (N,) s.

    Noise and atmosphere from ``options`` (:class:`GnssOptions`; its fields may also be
    given as keywords, e.g. ``sigma_code=1.0, iono=False``): code σ, rate σ, Klobuchar
    and Saastamoinen. Truth: ``tau_gps`` (s) on GLONASS code, receiver clock
    δt_r = clock_bias + clock_drift·t (s). Visibility: elevation mask ``mask_deg``,
    ``only`` a fixed satellite subset, ``outages`` [(start, end)] s of all satellites,
    ``sat_outages`` [(sat, start, end)]. Seeded. The table also carries the true
    ``elevation_rad``."""
    opts, rest = split_options(options, option_fields)
    if rest:
        raise TypeError(f"simulate() got an unexpected keyword argument {sorted(rest)[0]!r}")
    t = vector(time, None, "time")
    out = np.asarray(outages, float).reshape(-1, 2)
    d = _core.gnss_simulate(eph._core, t, rows(lla, 3, "lla"), rows(vel_ned, 3, "vel_ned"), opts.native,
                            tau_gps=float(tau_gps), clock_bias=float(clock_bias), clock_drift=float(clock_drift),
                            mask=float(np.radians(mask_deg)), only=only, outages=np.ascontiguousarray(out),
                            sat_outages=[(str(s), float(a), float(b)) for s, a, b in sat_outages], seed=int(seed))
    return pd.DataFrame({c: d[c] for c in OBS_COLUMNS + ["elevation_rad"]})


def doppler_to_rate(doppler_hz, sat, channel) -> np.ndarray:
    """Pseudorange rate (m/s) = −λ·D with the per-channel GLONASS wavelength (spec Eq. 16)."""
    d = np.asarray(doppler_hz, float)
    sys = np.array([str(s)[0] for s in np.atleast_1d(sat)])
    k = np.asarray(channel, float)
    if np.any((sys == "R") & ((k < -7) | (k > 6))):
        i = int(np.nonzero((sys == "R") & ((k < -7) | (k > 6)))[0][0])
        raise input_error("channel", f"unknown GLONASS frequency channel {k[i]:g} at index {i} (valid: -7..6)", i)
    f = np.where(sys == "R", (1602.0 + 0.5625 * k) * 1e6, 1575.42e6)
    return -C_LIGHT / f * d


def obs_arrays(obs: pd.DataFrame) -> tuple:
    """The observation table as the arrays the core takes."""
    missing = [c for c in OBS_COLUMNS if c not in obs.columns]
    if missing:
        raise input_error("obs", f"missing columns {missing}")
    return (np.ascontiguousarray(obs["time_s"].to_numpy(float)), [str(s) for s in obs["sat"]],
            np.ascontiguousarray(obs["channel"].to_numpy(np.int64)), np.ascontiguousarray(obs["code_m"].to_numpy(float)),
            np.ascontiguousarray(obs["rate_mps"].to_numpy(float)))
