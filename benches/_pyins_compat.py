"""One IMU record in the conventions of atomnav and of pyins (PyPI ``python-ins``), for the
side-by-side strapdown benchmark.

Both libraries take raw increments (∫ω dt, ∫f dt over (t_{k-1}, t_k], body FRD), the
WGS-84 ellipsoid and Earth rate, and gravity along the local vertical only. They differ
in normal gravity: pyins uses Somigliana with the linear height term, γ₀(1 − 2h/a);
atomnav the second-order height correction of NIMA TR8350.2 (2000), ch. 4,
γ₀(1 − 2(1 + f + m − 2f sin²φ)h/a + 3h²/a²). At 200 m and 55.75° N they differ by
1.3e-6 m/s², which the unstable vertical channel (time constant √(a/2γ) ≈ 570 s) turns
into 1.2e2 m of height after an hour. So an ideal IMU is ideal for one gravity model
only: :func:`regravitate` re-derives its velocity increments for the other model.
pyins' layout besides: degrees for latitude, longitude and Euler angles, and one
duplicated "before" sample ahead of increment data (``pyins.strapdown.compute_increments_from_imu``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyins.earth
from pyins.util import ACCEL_COLS, GYRO_COLS, LLA_COLS, RPH_COLS, TRAJECTORY_COLS, VEL_COLS

import atomnav as an

INCREMENT_COLUMNS = an.trajectory.IMU_COLUMNS["increments"]


def gravity_atomnav(lat_rad, h_m):
    """atomnav's normal gravity (m/s², down)."""
    return an.earth.gravity(lat_rad, h_m)


def gravity_pyins(lat_rad, h_m):
    """pyins' normal gravity (m/s², down)."""
    return pyins.earth.gravity(np.rad2deg(lat_rad), h_m)


def regravitate(dv, time_s, lla, q_nb, gravity_from, gravity_to):
    """Velocity increments (N−1, 3) of an ideal IMU under ``gravity_from`` turned into those
    under ``gravity_to`` along the same motion sampled at (N,) ``time_s``: f_to = f_from +
    C_bn (0, 0, γ_from − γ_to), integrated over each interval by the trapezoid rule (its
    error, ~Δγ·Δt·(ωΔt)², is below 1e-15 m/s here)."""
    dg = gravity_from(lla[:, 0], lla[:, 2]) - gravity_to(lla[:, 0], lla[:, 2])
    u = an.rotation.dcm_from_quat(q_nb)[:, 2, :] * dg[:, None]  # C_bn · (0, 0, Δγ)
    return dv + 0.5 * np.diff(time_s)[:, None] * (u[:-1] + u[1:])


def pyins_imu(imu: pd.DataFrame, t0: float) -> pd.DataFrame:
    """atomnav increments (stamped at the end of their interval, first interval starting at
    ``t0``) as a pyins increment IMU table, with the duplicated "before" row."""
    vals = imu[INCREMENT_COLUMNS[1:]].to_numpy()
    return pd.DataFrame(np.vstack([vals[:1], vals]), index=np.r_[t0, imu["time_s"].to_numpy()],
                        columns=GYRO_COLS + ACCEL_COLS)


def atomnav_imu(imu: pd.DataFrame) -> pd.DataFrame:
    """pyins increment IMU table (first row the duplicated "before" sample) as atomnav increments."""
    return pd.DataFrame(np.column_stack([imu.index[1:], imu[GYRO_COLS + ACCEL_COLS].to_numpy()[1:]]),
                        columns=INCREMENT_COLUMNS)


def pyins_pva(lla, vel_ned, euler) -> pd.Series:
    """pyins initial state from lat, lon (rad), h (m), NED velocity (m/s), roll, pitch, yaw (rad)."""
    return pd.Series([*np.rad2deg(lla[:2]), lla[2], *vel_ned, *np.rad2deg(euler)], index=TRAJECTORY_COLS)


def pyins_state(traj: pd.DataFrame):
    """lla (rad, rad, m), NED velocity (m/s) and q_nb rows of a pyins trajectory table."""
    lla = traj[LLA_COLS].to_numpy(float).copy()
    lla[:, :2] = np.deg2rad(lla[:, :2])
    return lla, traj[VEL_COLS].to_numpy(float), an.rotation.quat_from_euler(np.deg2rad(traj[RPH_COLS].to_numpy(float)))


def final_errors(lla, vel_ned, q_nb, true_lla, true_vel, true_q):
    """Position (m), velocity (m/s) and attitude (rad) error norms of one state against the truth."""
    return (float(np.linalg.norm(an.earth.lla_to_ned(lla, true_lla))),
            float(np.linalg.norm(np.asarray(vel_ned) - true_vel)),
            float(an.rotation.attitude_error_angle(q_nb, true_q)[0]))
