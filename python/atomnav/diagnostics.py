"""Free-inertial diagnostics of the strapdown INS: a stationary INS with injected
initial errors or sensor biases, and the Schuler-period test (a velocity error oscillates
with the Schuler period 2π√(R/g) ≈ 84 min; Titterton & Weston 2004, §12.3)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from . import earth, strapdown, trajectory
from ._validate import floats, input_error, positive, renamed, scalar, vector


#: Samples a stationary test may take: 3 days at 1 Hz, a few seconds of work.
STATIONARY_MAX_SAMPLES = 300_000


def stationary_errors(lat: float, hours: float, *, rate_hz: float = 10.0, h: float = 100.0, dv0=(0.0, 0.0, 0.0),
                      gyro_bias=(0.0, 0.0, 0.0), accel_bias=(0.0, 0.0, 0.0), vertical: str = "damped") -> pd.DataFrame:
    """Errors (:meth:`atomnav.trajectory.Trajectory.errors`) of a level, north-pointing INS at
    rest at latitude ``lat`` (rad) and height ``h`` (m) over ``hours``, started with NED
    velocity error ``dv0`` (m/s), with constant body-frame gyro (rad/s) and accelerometer
    (m/s²) biases. The vertical channel is held to the true height by default (baro loop).
    The vehicle is at rest, so a low ``rate_hz`` is exact; ``hours × 3600 × rate_hz`` may be
    at most :data:`STATIONARY_MAX_SAMPLES` (a 3-day test at 1 Hz).

    Parameters
    ----------
    lat : float
        Geodetic latitude, rad.
    hours : float
        Duration of the test, h (> 0).
    rate_hz : float, default 10.0
        IMU sample rate, Hz (> 0).
    h : float, default 100.0
        Height above the ellipsoid, m, inside ``earth.HEIGHT_RANGE``.
    dv0 : array_like (3,), default (0, 0, 0)
        Initial NED velocity error, m/s.
    gyro_bias : array_like (3,), default (0, 0, 0)
        Constant body-frame gyro bias, rad/s.
    accel_bias : array_like (3,), default (0, 0, 0)
        Constant body-frame accelerometer bias, m/s².
    vertical : str, default "damped"
        Vertical channel of :func:`atomnav.strapdown.integrate`; "damped" holds it to the
        true height (baro loop).

    Returns
    -------
    pandas.DataFrame
        The error table of :meth:`atomnav.trajectory.Trajectory.errors`, one row per
        epoch from the (perturbed) initial state.

    Raises
    ------
    atomnav.InputError
        Naming ``lat``, ``h`` (outside the height range), ``hours`` (too many samples),
        ``rate_hz``, ``dv0``, ``gyro_bias`` or ``accel_bias``.
    """
    lat, h = float(floats(scalar(lat, "lat"), "lat")), float(floats(scalar(h, "h"), "h"))
    lo, hi = earth.HEIGHT_RANGE
    if not lo <= h <= hi:  # checked here: inside, h reaches the INS as part of lla
        raise input_error("h", f"height {h} m is outside [{lo:g}, {hi:g}] m")
    hours, rate_hz = positive(hours, "hours"), positive(rate_hz, "rate_hz")
    if not hours * 3600.0 * rate_hz <= STATIONARY_MAX_SAMPLES:
        raise input_error("hours", f"{hours} h at {rate_hz} Hz is more than {STATIONARY_MAX_SAMPLES} samples; "
                                   "at rest a lower rate_hz is exact")
    gyro_bias, accel_bias = vector(gyro_bias, 3, "gyro_bias"), vector(accel_bias, 3, "accel_bias")
    dv0 = vector(dv0, 3, "dv0")
    with renamed(origin="lat", duration="hours"):
        traj = trajectory.stationary(hours * 3600.0, rate_hz, origin=(lat, 0.4, h))
    imu = traj.ideal_imu("increments")
    dt = 1.0 / rate_hz
    imu[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]] += gyro_bias * dt
    imu[["dv_x_mps", "dv_y_mps", "dv_z_mps"]] += accel_bias * dt
    init = traj.initial_state()
    init["vel_ned"] = init["vel_ned"] + dv0
    h_ref = traj.df["h_m"].to_numpy()[1:] if vertical == "damped" else None
    nav = strapdown.integrate(imu, **init, vertical=vertical, h_ref=h_ref)
    first = strapdown.Strapdown(**init).state()  # the perturbed initial state
    return traj.errors(pd.concat([first, nav], ignore_index=True))


def zero_crossing_periods(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Oscillation periods from the zero crossings of ``v(t)`` (linear interpolation):
    T = 2·Δt between successive crossings.

    Parameters
    ----------
    t : array_like (N,)
        Times, s.
    v : array_like (N,)
        Oscillating values (any unit), one per time.

    Returns
    -------
    numpy.ndarray (C − 1,)
        Periods, s, for C zero crossings.

    Raises
    ------
    atomnav.InputError
        Naming ``v`` when its length differs from that of ``t``.
    """
    t, v = vector(t, None, "t"), vector(v, None, "v")
    if v.size != t.size:
        raise input_error("v", f"{v.size} values for {t.size} times")
    s = np.sign(v)
    idx = np.nonzero(s[:-1] * s[1:] < 0)[0]
    tc = t[idx] - v[idx] * (t[idx + 1] - t[idx]) / (v[idx + 1] - v[idx])
    return 2.0 * np.diff(tc)


def schuler_test(lat: float = np.deg2rad(55.75), *, v0: float = 200.0, hours: float = 4.5, h: float = 100.0) -> dict:
    """The Schuler test: a stationary INS started with a ``v0`` m/s north velocity error.

    Parameters
    ----------
    lat : float, default 55.75° in rad
        Geodetic latitude, rad.
    v0 : float, default 200.0
        Initial north velocity error, m/s.
    hours : float, default 4.5
        Duration of the test, h.
    h : float, default 100.0
        Height above the ellipsoid, m.

    Returns
    -------
    dict
        The error table and the measured quantities: ``errors`` (DataFrame of
        :func:`stationary_errors`), ``periods_min`` the zero-crossing periods of v_N
        (min), ``schuler_period_min`` the Schuler period 2π√((√(MN)+h)/γ) (min), and the
        first-period peaks ``position_peak_m`` of the horizontal position error (m) and
        ``tilt_peak_rad`` of the tilt (rad).

    References
    ----------
    D. H. Titterton and J. L. Weston, *Strapdown Inertial Navigation Technology*, 2nd ed.
    (2004), §12.3.
    """
    # 1 Hz is exact at rest and keeps multi-day tests to seconds
    err = stationary_errors(lat, hours, rate_hz=1.0, dv0=(scalar(v0, "v0"), 0.0, 0.0), h=h)
    periods = zero_crossing_periods(err["time_s"].to_numpy(), err["dvel_n_mps"].to_numpy()) / 60.0
    ts = earth.schuler_period(lat, h)
    first = err["time_s"] < ts
    return {
        "errors": err,
        "periods_min": periods,
        "schuler_period_min": ts / 60.0,
        "position_peak_m": float(np.hypot(err["dpos_n_m"], err["dpos_e_m"])[first].max()),
        "tilt_peak_rad": float(np.hypot(err["psi_n_rad"], err["psi_e_rad"])[first].max()),
    }
