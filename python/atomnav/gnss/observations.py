"""Simulated code and pseudorange-rate observations as a table
with one row per satellite and epoch: ``time_s, sat, channel, code_m, rate_mps``.
GLONASS code is delivered with c·ΔT_leap removed (as in Demidov 2009)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _core, plausibility
from .._validate import as_floats, finite, finite_scalar, input_error, instance, integer, locate, renamed, rows, table, vector
from .ephemeris import Ephemerides
from .options import GnssOptions, split_options

C_LIGHT = 299792458.0
OBS_COLUMNS = ["time_s", "sat", "channel", "code_m", "rate_mps"]


def simulate(eph: Ephemerides, time, lla, vel_ned, options: GnssOptions | None = None, *, tau_gps: float = 0.0,
             clock_bias: float = 0.0, clock_drift: float = 0.0, mask_deg: float = 10.0, only: list[str] | None = None,
             outages=(), sat_outages=(), seed: int = 0, **option_fields) -> pd.DataFrame:
    """Simulated code and pseudorange-rate observations of a moving receiver.

    Noise and atmosphere come from the options: code σ, rate σ, Klobuchar ionosphere and
    Saastamoinen troposphere. GLONASS code is delivered with c·ΔT_leap removed (as in
    Demidov 2009).

    Parameters
    ----------
    eph : Ephemerides
        Broadcast ephemerides of the satellites.
    time : array_like, shape (N,)
        GPS times of the epochs, s.
    lla : array_like, shape (N, 3)
        Receiver latitude (rad), longitude (rad), height (m) per epoch.
    vel_ned : array_like, shape (N, 3)
        Receiver NED velocity per epoch, m/s.
    options : GnssOptions, optional
        Noise and atmosphere options (default ``GnssOptions()``).
    tau_gps : float, default 0.0
        True GPS−GLONASS system-time offset τ_GPS on the GLONASS code, s.
    clock_bias : float, default 0.0
        Receiver clock offset at the first epoch, s: δt_r(t) = clock_bias +
        clock_drift·(t − time[0]), so the bias is the offset at the start of the record
        whatever its time of week.
    clock_drift : float, default 0.0
        Receiver clock drift, s/s (δt_r grows by clock_drift·Δt s over Δt s).
    mask_deg : float, default 10.0
        Elevation mask, degrees.
    only : list of str, optional
        A fixed satellite subset (names such as "G01"); None: every satellite above the
        mask.
    outages : sequence of (float, float), default ()
        Intervals (start, end), s, without any satellite.
    sat_outages : sequence of (str, float, float), default ()
        Outages (sat, start, end), s, of single satellites.
    seed : int, default 0
        Noise seed, in [0, 2**64).
    **option_fields
        Fields of :class:`GnssOptions` given as keywords (e.g. ``sigma_code=1.0,
        iono=False``), replacing those of ``options``.

    Returns
    -------
    pandas.DataFrame
        One row per satellite and epoch: :data:`OBS_COLUMNS` ``time_s`` (GPS s), ``sat``,
        ``channel`` (FDMA channel k, 0 for GPS), ``code_m`` (m), ``rate_mps`` (m/s), and
        the true ``elevation_rad`` (rad).

    Raises
    ------
    atomnav.InputError
        Naming ``lla`` for a latitude beyond ±π/2.
    TypeError
        For a keyword that is not a field of :class:`GnssOptions`.

    Warns
    -----
    atomnav.UnitWarning
        For a longitude beyond 2π (degrees given for radians).
    """
    instance(eph, Ephemerides, "eph")
    opts, rest = split_options(options, option_fields)
    if rest:
        raise TypeError(f"simulate() got an unexpected keyword argument {sorted(rest)[0]!r}")
    t = vector(time, None, "time")
    out = as_floats(outages, "outages")
    out = rows(out.reshape(-1, 2) if out.size % 2 == 0 else out, 2, "outages")
    if isinstance(sat_outages, (str, bytes)) or not all(isinstance(o, (tuple, list)) and len(o) == 3 for o in sat_outages):
        raise TypeError("sat_outages: expected a list of (sat, start, end) tuples")
    sat_out = [(str(s), finite_scalar(a, "sat_outages"), finite_scalar(b, "sat_outages")) for s, a, b in sat_outages]
    with renamed(t="time"):  # the core names the epochs t
        d = _core.gnss_simulate(eph._core, t, plausibility.lla(rows(lla, 3, "lla"), "lla"), rows(vel_ned, 3, "vel_ned"), opts.native,
                                tau_gps=finite_scalar(tau_gps, "tau_gps"), clock_bias=finite_scalar(clock_bias, "clock_bias"),
                                clock_drift=finite_scalar(clock_drift, "clock_drift"),
                                mask=float(np.radians(finite_scalar(mask_deg, "mask_deg"))), only=only, outages=out,
                                sat_outages=sat_out, seed=integer(seed, "seed", 0, 2**64 - 1))
    return pd.DataFrame({c: d[c] for c in OBS_COLUMNS + ["elevation_rad"]})


def doppler_to_rate(doppler_hz, sat, channel) -> np.ndarray:
    """Pseudorange rate = −λ·D of Doppler measurements, with the per-channel GLONASS
    wavelength (FDMA carrier).

    Parameters
    ----------
    doppler_hz : float or array_like, shape (N,)
        Doppler shifts D, Hz; NaN where not tracked (the rate is then NaN).
    sat : str or sequence of str, shape (N,)
        Satellite names ("G01", "R05", ...); the first letter selects the system.
    channel : int or array_like, shape (N,)
        FDMA channels k of GLONASS satellites (−7..6; ignored for GPS). Carrier
        f = 1602 + 0.5625 k MHz for GLONASS, 1575.42 MHz for GPS L1.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Pseudorange rates, m/s.

    Raises
    ------
    atomnav.InputError
        Naming ``sat`` or ``channel`` for a count other than one per Doppler, or
        ``channel`` for an unknown GLONASS channel.
    """
    d = np.atleast_1d(as_floats(doppler_hz, "doppler_hz")).reshape(-1)
    infinite = np.flatnonzero(np.isinf(d))
    if infinite.size:  # NaN is a Doppler not tracked: its rate is NaN (missing) too
        raise input_error("doppler_hz", f"infinite value at index {infinite[0]}", infinite[0])
    sats = np.atleast_1d(np.asarray(sat, dtype=object)).reshape(-1)
    if not all(isinstance(s, str) and s for s in sats):
        raise TypeError("sat: expected satellite names such as 'G01' or 'R05'")
    sys = np.array([s[0] for s in sats])
    k = np.atleast_1d(as_floats(channel, "channel")).reshape(-1)
    finite(k, "channel")
    for name, a in (("sat", sys), ("channel", k)):
        if len(a) != len(d):
            raise input_error(name, f"expected {len(d)} values (one per Doppler), got {len(a)}")
    if np.any((sys == "R") & ((k < -7) | (k > 6))):
        i = int(np.nonzero((sys == "R") & ((k < -7) | (k > 6)))[0][0])
        raise input_error("channel", f"unknown GLONASS frequency channel {k[i]:g} at index {i} (valid: -7..6)", i)
    f = np.where(sys == "R", (1602.0 + 0.5625 * k) * 1e6, 1575.42e6)
    return -C_LIGHT / f * d


def _gps_week_start(obs: pd.DataFrame):
    """The epoch of a datetime64 ``time_s``: 00:00 of the Sunday starting the GPS week of
    the first observation, the datetimes being GPS time (as in RINEX); None for seconds.
    A tz-aware column is civil time, off GPS time by the leap seconds: an InputError."""
    t = obs.iloc[:, locate(obs, ["time_s"], "obs")[0]]
    if not pd.api.types.is_datetime64_any_dtype(t.dtype) or t.dropna().empty:
        return None
    if t.dt.tz is not None:
        raise input_error("obs", "column 'time_s' is tz-aware (civil time, which differs from GPS time by the leap seconds): "
                                 "give GPS time as naive datetimes or as GPS seconds of week")
    return _gps_week_of(t.dropna().iloc[0])


def _gps_week_of(t) -> pd.Timestamp:
    """00:00 of the Sunday that starts the GPS week of the GPS time ``t`` (a checked
    datetime of the caller)."""
    t = pd.Timestamp(t)
    return t.normalize() - pd.Timedelta(days=(t.day_of_week + 1) % 7)


def obs_arrays(obs: pd.DataFrame) -> tuple:
    """The observation table as the arrays the core takes, read by column name (extra
    columns ignored).

    Parameters
    ----------
    obs : pandas.DataFrame
        Observation table with :data:`OBS_COLUMNS`. ``time_s`` is GPS seconds of week, or
        naive GPS-time datetime64 (converted to seconds since the start of its GPS week).

    Returns
    -------
    tuple
        ``(time, sat, channel, code, rate)``: times (N,) GPS s, satellite names (list of
        str), FDMA channels (N,) int64, code (N,) m and pseudorange rate (N,) m/s.

    Raises
    ------
    atomnav.InputError
        Naming ``obs`` for a missing column, non-integer channels, or a tz-aware
        ``time_s`` (civil time differs from GPS time by the leap seconds).
    """
    instance(obs, pd.DataFrame, "obs")
    numeric = ["time_s", "channel", "code_m", "rate_mps"]
    # a NaN code or rate is an observable the receiver did not track: the solvers leave it out
    time, channel, code, rate = (np.ascontiguousarray(c) for c in table(obs, numeric, "obs", epoch=_gps_week_start(obs),
                                                                      epoch_name="GPS week start",
                                                                      finite=("time_s", "channel")).T)
    if np.any(channel != np.round(channel)) or np.any(np.abs(channel) > 2**31):
        raise input_error("obs", "column 'channel': expected integer FDMA channels")
    sats = obs.iloc[:, locate(obs, ["sat"], "obs")[0]]
    return (time, [str(s) for s in sats], channel.astype(np.int64), code, rate)
