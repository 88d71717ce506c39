"""Reference trajectories: the papers' named motions, and a :class:`Trajectory` type
users build from their own data.

A generated trajectory carries its continuous motion model, so its ideal IMU output is
exact (:meth:`Trajectory.ideal_imu`). Angles in rad, positions (lat rad, lon rad, h m),
velocities NED m/s, attitude ``q_nb`` scalar first.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from . import _core, plausibility
from ._validate import (FIRST_SAMPLE, finite_scalar, increasing, input_error, instance, integer, locate, path as checked_path,
                        positive, renamed, rows, table, timestamp, vector)
from .rotation import euler_from_quat

#: Column names of a trajectory table (units in the names).
COLUMNS = ["time_s", "lat_rad", "lon_rad", "h_m", "vn_mps", "ve_mps", "vd_mps", "qw", "qx", "qy", "qz", "roll_rad", "pitch_rad", "yaw_rad"]
#: IMU table columns for each output kind.
IMU_COLUMNS = {
    "rates": ["time_s", "gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s", "accel_x_mps2", "accel_y_mps2", "accel_z_mps2"],
    "increments": ["time_s", "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps"],
}


def imu_kind(kind, imu, name: str = "imu") -> str:
    """The IMU output kind of a call, by the one rule of every function taking ``kind``.

    Parameters
    ----------
    kind : str or None
        ``"rates"`` or ``"increments"`` (checked by the core), returned when given.
    imu : DataFrame or array_like
        The IMU table; with ``kind=None``, the kind is the one whose gyro or accel
        columns of :data:`IMU_COLUMNS` this DataFrame has.
    name : str
        The argument holding ``imu``, named in errors.

    Returns
    -------
    str
        ``"rates"`` or ``"increments"``.

    Raises
    ------
    InputError
        Naming ``name`` (listing both column sets): a table with columns of both kinds or
        of neither. Naming ``kind``: a plain array, which has no column names, with
        ``kind=None``.
    """
    if kind is not None:
        return kind
    if not isinstance(imu, pd.DataFrame):
        raise input_error("kind", 'a plain array needs kind="rates" or "increments" (kind=None reads it from a table\'s column names)')
    found = [k for k, columns in IMU_COLUMNS.items() if any(c in imu.columns for c in columns[1:])]
    if len(found) != 1:
        raise input_error(name, f"has {'columns of both IMU kinds' if found else 'no IMU columns'}, so kind=None cannot tell its kind: "
                                f"give kind=, or the columns of one kind, rates {IMU_COLUMNS['rates']} or increments "
                                f"{IMU_COLUMNS['increments']}")
    return found[0]


#: Default site: Moscow, 55.75°N 37.6°E, 200 m.
MOSCOW = (np.deg2rad(55.75), np.deg2rad(37.6), 200.0)
#: Most samples of a generated trajectory (a table of 14 float columns: 11 GB).
MAX_SAMPLES = 100_000_000


def nav_table(time, lla, vel_ned, q_nb) -> pd.DataFrame:
    """A trajectory / navigation-solution table from arrays (Euler angles added).

    Parameters
    ----------
    time : array_like (N,)
        Time (s).
    lla : array_like (N, 3)
        Latitude (rad), longitude (rad), height (m).
    vel_ned : array_like (N, 3)
        NED velocity (m/s).
    q_nb : array_like (N, 4)
        Attitude, scalar first.

    Returns
    -------
    DataFrame
        The columns of :data:`COLUMNS`.

    Raises
    ------
    InputError
        A latitude beyond ±π/2.

    Warns
    -----
    UnitWarning
        A longitude beyond 2π (degrees).
    """
    p = rows(lla, 3, "lla")
    _check_positions(p, "lla")
    return _frame(vector(time, None, "time"), p, rows(vel_ned, 3, "vel_ned"), rows(q_nb, 4, "q_nb"), "q_nb")


def _check_positions(lla: np.ndarray, name: str, columns: bool = False) -> None:
    """The core's latitude check of positions ``lla`` (N, 3) (an :class:`atomnav.InputError`
    naming argument ``name`` and the first bad row, and the column ``lat_rad`` when the
    positions are the ``columns`` of a table) and the longitude unit warning."""
    try:
        _core.check_latitudes_rows(np.ascontiguousarray(lla, dtype=float), name)
    except _core.InputError as e:
        if not columns:
            raise
        raise input_error(name, f"column 'lat_rad': {str(e)[len(name) + 2:]}", e.index) from None
    plausibility.lla(lla, name)


def _frame(time: np.ndarray, lla: np.ndarray, vel_ned: np.ndarray, q: np.ndarray, q_name: str) -> pd.DataFrame:
    """The table of :data:`COLUMNS` from checked arrays; the quaternions ``q`` are checked by
    the Euler conversion (errors naming ``q_name``)."""
    with renamed(q=q_name):
        e = euler_from_quat(q) if len(q) else np.zeros((0, 3))
    return pd.DataFrame(np.column_stack([time, lla, vel_ned, q, e]), columns=COLUMNS)


class Trajectory:
    """A sampled trajectory (truth or user data) as a DataFrame with unit-named columns
    (:data:`COLUMNS`), optionally backed by an exact motion model.

    Build from data with :meth:`from_dataframe` / :meth:`from_csv`, or with the
    generators of this module (:func:`sinusoidal`, :func:`hexapod`, ...).

    Parameters
    ----------
    df : DataFrame
        Read by column name (:data:`COLUMNS`; extra columns are kept but not read). A
        table of float64 columns is kept as given (no copy); otherwise the columns of
        :data:`COLUMNS` are converted in a copy: nullable dtypes with ``pd.NA`` read as NaN,
        and ``time_s`` as in :meth:`from_dataframe` (a timedelta64 as its seconds, a
        datetime64 as seconds since ``epoch``, by default since the first sample, which
        then becomes :attr:`epoch`).
    motion : atomnav._core.Motion, optional
        The exact motion model the samples come from (the generators pass it).
    ellipsoid : str
        Earth model of the positions, default ``"WGS84"``.
    epoch : datetime, optional
        The datetime of ``time_s`` 0 for a datetime64 ``time_s``.

    Raises
    ------
    InputError
        Without a ``motion`` (whose samples come from its checked origin): positions not
        finite or a latitude beyond ±π/2, naming ``df`` and the row.

    Warns
    -----
    UnitWarning
        A longitude beyond 2π (degrees).
    """

    def __init__(self, df: pd.DataFrame, motion: _core.Motion | None = None, ellipsoid: str = "WGS84", epoch=None):
        where = locate(instance(df, pd.DataFrame, "df"), COLUMNS, "df")
        if motion is not None:
            instance(motion, _core.Motion, "motion")
        epoch = _epoch(df, epoch)
        if not all(df.dtypes.iloc[k] == np.float64 for k in where):
            values = table(df, COLUMNS, "df", epoch=FIRST_SAMPLE if epoch is None else epoch, finite=False)
            df = df.copy()
            for j, name in enumerate(COLUMNS):
                df[name] = values[:, j]
        if motion is None:  # a motion's samples come from its checked origin
            _check_positions(df[["lat_rad", "lon_rad", "h_m"]].to_numpy(dtype=float), "df", columns=True)
        self.df = df
        self.motion = motion
        self.ellipsoid = instance(ellipsoid, str, "ellipsoid")
        #: The datetime of ``time_s`` 0 for a trajectory read from datetimes (or given one), else None.
        self.epoch = None if epoch is None else timestamp(epoch)

    # ---- construction -------------------------------------------------------------
    @classmethod
    def from_motion(cls, motion: _core.Motion, rate_hz: float, ellipsoid: str = "WGS84") -> "Trajectory":
        """Sample a motion model over its whole duration.

        Parameters
        ----------
        motion : atomnav._core.Motion
            The motion model.
        rate_hz : float
            Sample rate (Hz); at most :data:`MAX_SAMPLES` samples.
        ellipsoid : str
            Earth model, default ``"WGS84"``.

        Returns
        -------
        Trajectory
            Backed by ``motion``.
        """
        instance(motion, _core.Motion, "motion")
        rate_hz = positive(rate_hz, "rate_hz")
        n = np.floor(motion.duration * rate_hz + 1e-9) + 1
        if not n <= MAX_SAMPLES:
            raise input_error("rate_hz", f"{motion.duration} s at {rate_hz} Hz is more than {MAX_SAMPLES} samples")
        n = int(n)
        t = np.arange(n) / rate_hz
        tr = motion.truth(t, ellipsoid)
        return cls(_frame(tr["time"], tr["lla"], tr["vel_ned"], tr["q_nb"], "q_nb"), motion, ellipsoid)

    @classmethod
    def from_dataframe(cls, df: pd.DataFrame, ellipsoid: str = "WGS84", *, epoch=None) -> "Trajectory":
        """A trajectory from a table, read by column name (extra columns ignored).

        Validated: finite values, strictly increasing time, latitude within ±π/2.

        Parameters
        ----------
        df : DataFrame
            ``time_s, lat_rad, lon_rad, h_m, vn_mps, ve_mps, vd_mps`` and either ``qw, qx,
            qy, qz`` or ``roll_rad, pitch_rad, yaw_rad`` (the quaternion when both are
            there). ``time_s`` holds seconds, a timedelta64 (read as seconds) or a
            datetime64: then seconds since ``epoch``.
        ellipsoid : str
            Earth model of the positions, default ``"WGS84"``.
        epoch : datetime, optional
            Time 0 of a datetime64 ``time_s``; by default the first sample. The trajectory
            keeps that datetime as :attr:`epoch`, which :meth:`initial_state` passes on and
            :meth:`errors` reads datetime solutions against.

        Returns
        -------
        Trajectory
            Without a motion model.

        Raises
        ------
        InputError
            Naming ``df``: some but not all of the quaternion columns (naming the missing
            ones: a misspelled column, never a switch to the Euler angles), or a value
            that fails validation.
        """
        need = ["time_s", "lat_rad", "lon_rad", "h_m", "vn_mps", "ve_mps", "vd_mps"]
        quaternion, euler = ["qw", "qx", "qy", "qz"], ["roll_rad", "pitch_rad", "yaw_rad"]
        columns = instance(df, pd.DataFrame, "df").columns
        given = [c for c in quaternion if c in columns]
        if given and len(given) < len(quaternion):  # a misspelled or lost quaternion column, not a request for Euler angles
            raise input_error("df", f"has quaternion column(s) {given} but not {[c for c in quaternion if c not in given]}: give all "
                                    "of qw, qx, qy, qz, or none of them and roll_rad, pitch_rad, yaw_rad")
        attitude = quaternion if given else euler
        if not given and not all(c in columns for c in euler):
            raise input_error("df", f"needs attitude columns qw, qx, qy, qz or roll_rad, pitch_rad, yaw_rad (and {need})")
        epoch = _epoch(df, epoch)
        a = table(df, need + attitude, "df", epoch=FIRST_SAMPLE if epoch is None else epoch)
        t, lla, vel = a[:, 0], a[:, 1:4], a[:, 4:7]
        q = a[:, 7:] if len(attitude) == 4 else _core.quat_from_euler_rows(plausibility.angles(np.ascontiguousarray(a[:, 7:]), "df", "roll_rad, pitch_rad, yaw_rad"))
        increasing(t, "df", "time_s")
        return cls(_frame(t, lla, vel, np.ascontiguousarray(q), "df"), None, ellipsoid, epoch)

    @classmethod
    def from_csv(cls, path, ellipsoid: str = "WGS84", **read_csv_kwargs) -> "Trajectory":
        """Read a CSV with the columns of :meth:`from_dataframe`, time in seconds.

        For datetimes read the file with ``pandas.read_csv(..., parse_dates=["time_s"])``
        and use :meth:`from_dataframe`.

        Parameters
        ----------
        path : str or path-like
            The CSV file.
        ellipsoid : str
            Earth model of the positions, default ``"WGS84"``.
        **read_csv_kwargs
            Passed to :func:`pandas.read_csv`.

        Returns
        -------
        Trajectory
            Without a motion model.

        Raises
        ------
        InputError
            Naming ``path``: not a readable CSV table.
        """
        try:
            df = pd.read_csv(checked_path(path), **read_csv_kwargs)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
            raise input_error("path", f"not a readable CSV table: {e}") from None
        return cls.from_dataframe(df, ellipsoid)

    def to_csv(self, path) -> Path:
        """Write the table as CSV (the columns :meth:`from_csv` reads).

        Parameters
        ----------
        path : str or path-like
            The file to write.

        Returns
        -------
        pathlib.Path
            The path written.
        """
        path = checked_path(path)
        self.df.to_csv(path, index=False)
        return path

    # ---- access -------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.df)

    def __repr__(self) -> str:
        name = self.motion.name if self.motion is not None else "user data"
        t = self.df["time_s"]
        span = f", {t.iloc[0]:.3f}..{t.iloc[-1]:.3f} s" if len(t) else ""
        return f"Trajectory({name}, {len(self)} samples{span})"

    @property
    def time(self) -> np.ndarray:
        return self.df["time_s"].to_numpy()

    @property
    def lla(self) -> np.ndarray:
        return self.df[["lat_rad", "lon_rad", "h_m"]].to_numpy()

    @property
    def vel_ned(self) -> np.ndarray:
        return self.df[["vn_mps", "ve_mps", "vd_mps"]].to_numpy()

    @property
    def q_nb(self) -> np.ndarray:
        return self.df[["qw", "qx", "qy", "qz"]].to_numpy()

    def initial_state(self) -> dict:
        """The first sample as keyword arguments for :func:`atomnav.strapdown.integrate`.

        Returns
        -------
        dict
            ``t0`` (s), ``lla`` (rad, rad, m), ``vel_ned`` (m/s), ``q_nb``, and ``epoch``
            when the trajectory has one, so that datetime64 IMU times count from the same
            datetime as this trajectory's seconds.

        Raises
        ------
        InputError
            Naming ``df``: the trajectory has no samples.
        """
        if not len(self):
            raise input_error("df", "the trajectory has no samples, so no initial state")
        state = {"t0": float(self.time[0]), "lla": self.lla[0], "vel_ned": self.vel_ned[0], "q_nb": self.q_nb[0]}
        return state if self.epoch is None else {**state, "epoch": self.epoch}

    # ---- IMU ------------------------------------------------------------------------
    def ideal_imu(self, kind: str = "increments") -> pd.DataFrame:
        """Error-free IMU output at the trajectory's sample times, body axes FRD.

        Includes Earth rate, transport rate and normal gravity. Needs a generated
        trajectory.

        Parameters
        ----------
        kind : str
            ``"rates"``: specific force (m/s²), angular rate (rad/s) and angular
            acceleration (rad/s²) at each sample (N rows). ``"increments"`` (default): Δθ
            (rad) and Δv (m/s) over each interval (t_{k−1}, t_k], N − 1 rows stamped with
            t_k.

        Returns
        -------
        DataFrame
            The columns of ``IMU_COLUMNS[kind]``, and for rates ``angacc_{x,y,z}_rad_s2``.

        Raises
        ------
        InputError
            Naming ``kind``: a trajectory built from data, which has no motion model.
        """
        if self.motion is None:
            raise input_error("kind", "no ideal IMU output: this trajectory was built from data and has no motion model; use a generator")
        out = self.motion.ideal_imu(self.time, kind, self.ellipsoid)
        t = self.time if kind == "rates" else self.time[1:]
        df = pd.DataFrame(np.column_stack([t, out["gyro"], out["accel"]]), columns=IMU_COLUMNS[kind])
        if kind == "rates":
            for i, a in enumerate("xyz"):
                df[f"angacc_{a}_rad_s2"] = out["angular_acceleration"][:, i]
        return df

    # ---- comparison -----------------------------------------------------------------
    def errors(self, nav: pd.DataFrame) -> pd.DataFrame:
        """Errors (estimate − truth) of a navigation solution, one row per solution row.

        Every solution time stamp must be one of the trajectory's (an increments-driven
        solution, which starts one step after the initial state, is fine).

        Parameters
        ----------
        nav : DataFrame
            The solution, read by column name (``time_s``, ``lat_rad``, ``lon_rad``,
            ``h_m``, ``vn_mps``, ``ve_mps``, ``vd_mps``, ``qw``..``qz``); a datetime64
            ``time_s`` counts from this trajectory's :attr:`epoch` (a ``TypeError`` when it
            has none).

        Returns
        -------
        DataFrame
            ``time_s``; NED position error ``dpos_{n,e,d}_m`` (m); NED velocity error
            ``dvel_{n,e,d}_mps`` (m/s); attitude error ``psi_{n,e,d}_rad`` (rad, nav frame,
            C_nb(est) = (I − [ψ×]) C_nb(true)).

        Raises
        ------
        InputError
            Naming ``nav`` and the row: a time stamp that is not one of the trajectory's.
        """
        a = table(nav, ["time_s", "lat_rad", "lon_rad", "h_m", "vn_mps", "ve_mps", "vd_mps", "qw", "qx", "qy", "qz"], "nav",
                  epoch=self.epoch, epoch_name="epoch (Trajectory.from_dataframe's)")
        tn = a[:, 0]
        plausibility.lla(a[:, 1:4], "nav")
        idx = np.clip(np.searchsorted(self.time, tn), 0, len(self.time) - 1)
        off = np.nonzero(np.abs(self.time[idx] - tn) > 1e-9)[0]
        if off.size:
            raise input_error("nav", f"time stamp {tn[off[0]]} at index {off[0]} is not a time stamp of the trajectory", off[0])
        truth = self.df.iloc[idx]
        arrays = [np.ascontiguousarray(x) for x in (a[:, 1:4], a[:, 4:7], a[:, 7:11], truth[["lat_rad", "lon_rad", "h_m"]].to_numpy(),
                                                    truth[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(), truth[["qw", "qx", "qy", "qz"]].to_numpy())]
        err = _core.nav_errors(*arrays, ellipsoid=self.ellipsoid)
        return pd.DataFrame(np.column_stack([tn, err]), columns=["time_s", *_core.NAV_ERROR_COLUMNS])

    def plot(self, ax=None):
        """Ground track (east vs north, m, relative to the start) coloured by time.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on; a new 5 × 5 in figure by default.

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        import matplotlib.pyplot as plt
        from .earth import lla_to_ned

        from matplotlib.axes import Axes

        if ax is None:
            _, ax = plt.subplots(figsize=(5, 5))
        instance(ax, Axes, "ax")
        ned = lla_to_ned(self.lla, self.lla[0], self.ellipsoid)
        sc = ax.scatter(ned[:, 1], ned[:, 0], c=self.time, s=2)
        ax.set_xlabel("east (m)")
        ax.set_ylabel("north (m)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.figure.colorbar(sc, ax=ax, label="time (s)")
        return ax


def _epoch(df: pd.DataFrame, epoch):
    """The datetime a datetime64 ``time_s`` of ``df`` counts from: ``epoch`` if given (a
    datetime, else a ``TypeError``), else the column's first sample; None for a time in
    seconds (or timedelta64) with no ``epoch``."""
    if epoch is not None:
        if timestamp(epoch) is None:
            raise TypeError(f"epoch: expected a datetime (pandas.Timestamp, datetime or numpy.datetime64), got {type(epoch).__name__}")
        return epoch
    if "time_s" not in df.columns:
        return None  # the table read reports the missing column with the others
    column = df.iloc[:, locate(df, ["time_s"], "df")[0]]
    if pd.api.types.is_datetime64_any_dtype(column.dtype) and column.notna().any():
        return column.dropna().iloc[0]  # the first sample, the reference of the conversion
    return None


# ---- generators -----------------------------------------------------------------------

def _origin(origin):
    return plausibility.lla(vector(origin, 3, "origin"), "origin")


def stationary(duration: float, rate_hz: float = 100.0, origin=MOSCOW, euler=(0.0, 0.0, 0.0), ellipsoid: str = "WGS84") -> Trajectory:
    """At rest at ``origin`` with constant attitude.

    Parameters
    ----------
    duration : float
        Length (s).
    rate_hz : float
        Sample rate (Hz), default 100 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    euler : array_like (3,)
        Constant (roll, pitch, yaw) (rad).
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    return Trajectory.from_motion(_core.Motion.stationary(_origin(origin), finite_scalar(duration, "duration"), plausibility.angles(vector(euler, 3, "euler"), "euler")), rate_hz, ellipsoid)


def sinusoidal(duration: float, rate_hz: float = 100.0, *, origin=MOSCOW, amp_ned=(20.0, 15.0, 2.0), period_ned=(60.0, 45.0, 30.0),
               amp_euler=(0.1, 0.08, 0.3), period_euler=(20.0, 25.0, 40.0), heading: float = 0.5, ellipsoid: str = "WGS84") -> Trajectory:
    """Sinusoidal motion in position and attitude about ``origin``.

    Parameters
    ----------
    duration : float
        Length (s).
    rate_hz : float
        Sample rate (Hz), default 100 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    amp_ned, period_ned : array_like (3,)
        NED displacement amplitudes (m) and periods (s).
    amp_euler, period_euler : array_like (3,)
        Roll/pitch/yaw oscillation amplitudes (rad) and periods (s).
    heading : float
        Mean yaw the yaw oscillates about (rad).
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    m = _core.Motion.sinusoidal(_origin(origin), finite_scalar(duration, "duration"), vector(amp_ned, 3, "amp_ned"), vector(period_ned, 3, "period_ned"),
                                plausibility.angles(vector(amp_euler, 3, "amp_euler"), "amp_euler", "Euler amplitudes"), vector(period_euler, 3, "period_euler"),
                                plausibility.angles(finite_scalar(heading, "heading"), "heading", "heading"))
    return Trajectory.from_motion(m, rate_hz, ellipsoid)


def hexapod(rate_hz: float = 1000.0, origin=MOSCOW, max_tilt: float = 0.0654, pitch_delay: float = 5.0, heading: float = 0.0, ellipsoid: str = "WGS84") -> Trajectory:
    """Hexapod of Tennstedt et al. 2021, §5.3: 170 s of roll/pitch tilt steps.

    10 s static, then roll performs [+a, −a, +a/2, −a/2] three times (each: 1 s
    raised-cosine ramp, 5 s hold, 1 s ramp back, 5 s at 0), pitch the same delayed; see
    docs/departures.md#hexapod-scenario.

    Parameters
    ----------
    rate_hz : float
        Sample rate (Hz), default 1000 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    max_tilt : float
        Tilt amplitude a (rad): 0.0654 rad = 3.75° by default; below 0.5 rad in magnitude.
    pitch_delay : float
        Delay of the pitch sequence after the roll one (s).
    heading : float
        Constant yaw (rad).
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    return Trajectory.from_motion(_core.Motion.hexapod(_origin(origin), plausibility.angles(finite_scalar(max_tilt, "max_tilt"), "max_tilt", "tilt"),
                                                      finite_scalar(pitch_delay, "pitch_delay"),
                                                      plausibility.angles(finite_scalar(heading, "heading"), "heading", "heading")), rate_hz, ellipsoid)


def drive_with_yaw(rate_hz: float = 200.0, origin=MOSCOW, speed: float = 1.0, yaw_rate_amp: float = 0.05, period: float = 50.0,
                   duration: float = 50.0, heading: float = 0.0, ellipsoid: str = "WGS84") -> Trajectory:
    """Tennstedt et al. 2023, Fig. 7: straight drive with a sinusoidal yaw rate.

    The yaw rate is ``yaw_rate_amp``·sin(2πt/``period``); the velocity follows the heading
    (no side slip).

    Parameters
    ----------
    rate_hz : float
        Sample rate (Hz), default 200 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    speed : float
        Speed (m/s).
    yaw_rate_amp : float
        Yaw-rate amplitude (rad/s).
    period : float
        Yaw-rate period (s).
    duration : float
        Length (s).
    heading : float
        Initial heading (rad).
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    m = _core.Motion.drive_with_yaw(_origin(origin), finite_scalar(speed, "speed"), finite_scalar(yaw_rate_amp, "yaw_rate_amp"),
                                    finite_scalar(period, "period"), finite_scalar(duration, "duration"),
                                    plausibility.angles(finite_scalar(heading, "heading"), "heading", "heading"))
    return Trajectory.from_motion(m, rate_hz, ellipsoid)


def slalom(rate_hz: float = 200.0, origin=MOSCOW, speed: float = 5.0, amp: float = 2.0, period: float = 10.0, duration: float = 60.0,
           ellipsoid: str = "WGS84") -> Trajectory:
    """Smooth slalom (Tennstedt et al. 2023): north = speed·t, east = amp·sin(2πt/period),
    level, heading along the path.

    Parameters
    ----------
    rate_hz : float
        Sample rate (Hz), default 200 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    speed : float
        Northward speed (m/s).
    amp : float
        East amplitude (m).
    period : float
        Slalom period (s).
    duration : float
        Length (s).
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    return Trajectory.from_motion(_core.Motion.slalom(_origin(origin), finite_scalar(speed, "speed"), finite_scalar(amp, "amp"),
                                                     finite_scalar(period, "period"), finite_scalar(duration, "duration")), rate_hz, ellipsoid)


def car(rate_hz: float = 200.0, origin=MOSCOW, heading: float = 0.0, vibration: bool = True, ellipsoid: str = "WGS84") -> Trajectory:
    """Car-like 40 s profile after Tennstedt et al. 2023, Fig. 9: static, accelerating,
    sliding and coordinated turns, a shock at 26 s, vibration at 4.3/9.7/15.1 Hz.

    Parameters
    ----------
    rate_hz : float
        Sample rate (Hz), default 200 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    heading : float
        Initial heading (rad).
    vibration : bool
        Add the vibration.
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    return Trajectory.from_motion(_core.Motion.car(_origin(origin), plausibility.angles(finite_scalar(heading, "heading"), "heading", "heading"), bool(instance(vibration, (bool, np.bool_), "vibration"))), rate_hz, ellipsoid)


def stop_and_go(rate_hz: float = 200.0, origin=MOSCOW, *, heading: float = 0.0, speed: float = 5.0, ramp: float = 3.0,
                cruise: float = 5.0, stop: float = 10.0, cycles: int = 3, squat: float = 0.005,
                vibration: float = 0.02, ellipsoid: str = "WGS84") -> Trajectory:
    """Level stop-and-go drive along a constant course: at rest ``stop`` s, then ``cycles``
    times: speed up to ``speed`` over a raised-cosine ramp of ``ramp`` s, cruise ``cruise``
    s, slow to rest over ``ramp`` s, stand ``stop`` s.

    The body pitches with the longitudinal acceleration a (squat and dive on the
    suspension): a raised-cosine pulse over each ramp peaking at ``squat``·a_max (a_max =
    π·``speed``/(2·``ramp``)), nose up while speeding up. While moving it also rolls in a
    12 Hz oscillation of angular-rate amplitude ``vibration`` times speed/``speed`` (road
    vibration; without it a smooth cruise looks like rest to any IMU).

    Parameters
    ----------
    rate_hz : float
        Sample rate (Hz), default 200 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    heading : float
        Course and heading (rad).
    speed : float
        Cruise speed (m/s, > 0).
    ramp : float
        Length of each speed-up and slow-down (s, > 0).
    cruise : float
        Time at ``speed`` in each cycle (s, ≥ 0).
    stop : float
        Time at rest before the first and after every cycle (s, > 0).
    cycles : int
        Number of go-and-stop cycles (1 to 10 000).
    squat : float
        Pitch per longitudinal acceleration (rad per m/s², ≥ 0).
    vibration : float
        Roll-rate amplitude of the road vibration at ``speed`` (rad/s, ≥ 0).
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`);
        ``stop + cycles·(2·ramp + cruise + stop)`` s long.

    Raises
    ------
    InputError
        Naming the argument out of its range.
    """
    m = _core.Motion.stop_and_go(_origin(origin), heading=plausibility.angles(finite_scalar(heading, "heading"), "heading", "heading"),
                                 speed=finite_scalar(speed, "speed"), ramp=finite_scalar(ramp, "ramp"),
                                 cruise=finite_scalar(cruise, "cruise"), stop=finite_scalar(stop, "stop"),
                                 cycles=integer(cycles, "cycles", 1, 10_000), squat=finite_scalar(squat, "squat"),
                                 vibration=finite_scalar(vibration, "vibration"))
    return Trajectory.from_motion(m, rate_hz, ellipsoid)


def rotary_stand(states, move_starts, move_duration: float, duration: float, rate_hz: float = 200.0, origin=MOSCOW, ellipsoid: str = "WGS84") -> Trajectory:
    """Two-axis stand, C_nb = R_y(tilt) R_z(turntable), holding each state and moving to the
    next with the quintic profile 10x³ − 15x⁴ + 6x⁵.

    Parameters
    ----------
    states : array_like (K, 2)
        (tilt, turntable) angles (rad) held in turn.
    move_starts : array_like (K − 1,)
        Start time of the move to each next state (s).
    move_duration : float
        Length of each move (s).
    duration : float
        Length (s).
    rate_hz : float
        Sample rate (Hz), default 200 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default :data:`MOSCOW`.
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    m = _core.Motion.rotary_stand(_origin(origin), rows(states, 2, "states"), vector(move_starts, None, "move_starts"),
                                  finite_scalar(move_duration, "move_duration"), finite_scalar(duration, "duration"))
    return Trajectory.from_motion(m, rate_hz, ellipsoid)


def vasilyuk2024_stand(rate_hz: float = 200.0, origin=(np.deg2rad(55.6), np.deg2rad(38.2), 200.0), ellipsoid: str = "WGS84") -> Trajectory:
    """Calibration stand schedule after Vasilyuk et al. 2024: 13 states, 12 quintic moves,
    73 camera epochs 21.0007 s apart.

    Parameters
    ----------
    rate_hz : float
        Sample rate (Hz), default 200 Hz.
    origin : array_like (3,)
        Site: latitude (rad), longitude (rad), height (m); default 55.6°N, 38.2°E, 200 m.
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]`` (default ``"WGS84"``).

    Returns
    -------
    Trajectory
        Sampled at ``rate_hz``, with its motion model (exact :meth:`Trajectory.ideal_imu`).
    """
    return Trajectory.from_motion(_core.Motion.vasilyuk2024_stand(_origin(origin)), rate_hz, ellipsoid)
