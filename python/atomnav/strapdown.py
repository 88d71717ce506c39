"""Strapdown INS in the local-level NED frame (Rust core).

Batch: :func:`integrate` over a whole IMU table. Streaming: :class:`Strapdown`, fed
chunk by chunk, for records that do not fit in memory. Attitude with coning
correction, velocity with rotation/sculling, Coriolis, Earth and transport rate,
normal gravity; second order in the step (see ``rust/strapdown.rs``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from . import _core
from ._validate import choice, rows, vector
from .trajectory import COLUMNS, IMU_COLUMNS

#: Rows per call into Rust: the progress bar's granularity for long runs.
CHUNK = 500_000


def _table(columns: np.ndarray) -> pd.DataFrame:
    """DataFrame of a (14, N) column table from the core, without copying it."""
    return pd.DataFrame(columns.T, columns=COLUMNS, copy=False)


def _imu_arrays(imu, kind: str):
    """(time, gyro, accel) views of an IMU table of the given kind. Only shapes are checked
    here: the core checks values (NaN/inf, time order) once, with indices in the record."""
    cols = IMU_COLUMNS[kind]
    if isinstance(imu, pd.DataFrame):
        missing = [c for c in cols if c not in imu.columns]
        if missing:
            raise ValueError(f"imu: missing column(s) {missing} for kind={kind!r} (expected {cols})")
        a = imu[cols].to_numpy(float)
    else:
        a = np.asarray(imu, dtype=float)
        if a.ndim != 2 or a.shape[1] != 7:
            raise ValueError(f"imu: expected shape (N, 7), got {a.shape}")
    return a[:, 0], a[:, 1:4], a[:, 4:7]


class Strapdown:
    """Streaming strapdown INS. ``kind`` is ``"rates"`` or ``"increments"``; ``vertical``
    is ``"free"`` or ``"damped"`` (baro loop on a reference altitude, damping ratio
    ``zeta``, natural frequency ``omega`` rad/s; spec gnss-ins-tight Eq. 26).

    With rates, the first sample must be at ``t0`` (it primes the integrator). With
    increments, each row covers (t_{k−1}, t_k] and is stamped t_k > t0."""

    def __init__(self, t0, lla, vel_ned, q_nb, kind: str = "increments", ellipsoid: str = "WGS84", vertical: str = "free",
                 zeta: float = 0.707, omega: float = 0.01):
        self.kind = choice(kind, IMU_COLUMNS, "kind")
        choice(vertical, ("free", "damped"), "vertical")
        self._core = _core.Strapdown(float(t0), vector(lla, 3, "lla"), vector(vel_ned, 3, "vel_ned"), vector(q_nb, 4, "q_nb"),
                                     kind, ellipsoid, vertical, float(zeta), float(omega))

    def run(self, imu, h_ref=None) -> pd.DataFrame:
        """Integrate one chunk (IMU table with the columns of
        :data:`atomnav.trajectory.IMU_COLUMNS`); returns the solution at each row."""
        t, g, a = _imu_arrays(imu, self.kind)
        h = None if h_ref is None else vector(h_ref, len(t), "h_ref")
        return _table(self._core.run(t, g, a, h))

    def state(self) -> pd.DataFrame:
        return _table(self._core.state())


def integrate(imu, t0, lla, vel_ned, q_nb, kind: str = "increments", ellipsoid: str = "WGS84", vertical: str = "free",
              h_ref=None, zeta: float = 0.707, omega: float = 0.01, progress: bool | None = None) -> pd.DataFrame:
    """Integrate a whole IMU record from the initial state (t0 s; lla rad, rad, m; NED
    velocity m/s; q_nb). Returns a DataFrame (time_s, lat_rad, lon_rad, h_m, vn_mps,
    ve_mps, vd_mps, qw..qz, roll_rad, pitch_rad, yaw_rad) with one row per IMU row.

    ``h_ref`` (m, one per IMU row) is the reference altitude of a damped vertical
    channel. A progress bar shows for records over 10⁶ rows (``progress`` forces it on or
    off). If the solution diverges, :class:`atomnav.NumericalError` is raised with every
    row computed before the failure attached as ``err.partial`` (a DataFrame)."""
    choice(kind, IMU_COLUMNS, "kind")
    t, g, a = _imu_arrays(imu, kind)
    h = None if h_ref is None else vector(h_ref, len(t), "h_ref")
    sd = Strapdown(t0, lla, vel_ned, q_nb, kind, ellipsoid, vertical, zeta, omega)
    show = len(t) > 1_000_000 if progress is None else progress
    # one table for the whole record, filled chunk by chunk in place (no concatenation)
    table = np.empty((len(COLUMNS), len(t)))
    from tqdm.auto import tqdm

    with tqdm(total=len(t), disable=not show, unit="sample", desc="strapdown") as bar:
        for s in range(0, len(t), CHUNK):
            sl = slice(s, s + CHUNK)
            try:
                sd._core.run_into(t[sl], g[sl], a[sl], table, None if h is None else h[sl], s)
            except _core.NumericalError as err:
                err.partial = _table(table[:, :s + err.rows])
                raise
            bar.update(len(t[sl]))
    return _table(table)


def integrate_attitude(q0, dtheta, dtheta_prev=None) -> np.ndarray:
    """Body attitude from gyro increments (rad) with the multi-interval coning correction
    (see ``rust/strapdown.rs``), no navigation-frame rotation: q (N, 4) after each
    increment.

    ``dtheta_prev`` holds the increments of up to two intervals before the first one,
    oldest first, if known (a running INS has them); without them the first step has no
    coning term, a one-time error of about |Δθ₀ × Δθ₁|/12 rad."""
    prev = None if dtheta_prev is None else rows(dtheta_prev, 3, "dtheta_prev")
    return _core.integrate_attitude_increments(rows(q0, 4, "q0"), rows(dtheta, 3, "dtheta"), prev)
