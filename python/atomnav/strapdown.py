"""Strapdown INS in the local-level NED frame (Rust core).

Batch: :func:`integrate` over a whole IMU table. Streaming: :class:`Strapdown`, fed
chunk by chunk, for records that do not fit in memory. Attitude with coning
correction, velocity with rotation/sculling, Coriolis, Earth and transport rate,
normal gravity; second order in the step (Savage, Strapdown Analytics §7.2; see
``rust/strapdown/mod.rs``).

Options by name are checked by the core; their accepted names are
``atomnav._core.OPTIONS["ImuKind"]`` (``kind``), ``["Ellipsoid"]`` (``ellipsoid``) and
``["Vertical"]`` (``vertical``).
"""

from __future__ import annotations

from collections.abc import Mapping
from contextlib import contextmanager

import numpy as np
import pandas as pd

from . import _core, plausibility
from ._stateful import Stateful, serialized
from ._validate import as_floats, flag, input_error, renamed, rows, scalar, seconds, table, timestamp, vector
from .trajectory import COLUMNS, IMU_COLUMNS, imu_kind

#: Rows per call into Rust: the progress bar's granularity for long runs.
CHUNK = 500_000


def _table(columns: np.ndarray, first_row: int = 0) -> pd.DataFrame:
    """DataFrame of a (14, N) column table from the core, without copying it; the index
    is the row number in the whole record, from ``first_row``."""
    index = pd.RangeIndex(first_row, first_row + columns.shape[1])
    return pd.DataFrame(columns.T, columns=COLUMNS, index=index, copy=False)


def _imu_arrays(imu, kind: str, epoch=None):
    """(time, gyro, accel) views of an IMU table of the given kind, in one Fortran-ordered
    array so the core reads each in place. A DataFrame is read by column name once per
    call (a datetime ``time_s`` as seconds since ``epoch``, None: refused); an array must
    have the columns of ``IMU_COLUMNS[kind]`` in that order. Only shapes and types are
    checked here: the core checks values (NaN/inf, time order) once, with indices in the
    record, and :func:`_imu_errors` names the column."""
    if isinstance(imu, pd.DataFrame):
        a = table(imu, IMU_COLUMNS[kind], "imu", order="F", epoch=epoch, epoch_name="epoch (or t0 as a datetime)", finite=False)
    else:
        a = as_floats(imu, "imu")
        if a.ndim != 2 or a.shape[1] != 7:
            raise input_error("imu", f"expected shape (N, 7) with the columns {IMU_COLUMNS[kind]} in this order, got {a.shape}")
        a = np.asfortranarray(a)
        evidence = plausibility.swapped_blocks(a[:, 0], a[:, 1:4], a[:, 4:7], kind)
        if evidence is not None:
            raise input_error("imu", f"a plain array is read as {IMU_COLUMNS[kind]} in this order, but its columns 1-3 look like "
                                     f"the accelerometer and 4-6 like the gyro ({evidence}): reorder them, or pass a DataFrame "
                                     "whose columns are read by name")
    return a[:, 0], a[:, 1:4], a[:, 4:7]


@contextmanager
def _imu_errors(kind: str, gyro: np.ndarray, accel: np.ndarray, first_row: int):
    """The core's errors about the IMU arrays (``time``, ``gyro``, ``accel``, rows of the
    record from ``first_row``) name the caller's argument ``imu`` and, in the message, the
    offending column."""
    try:
        yield
    except _core.InputError as e:
        field = getattr(e, "parameter", None)
        if field not in ("time", "gyro", "accel"):
            raise
        cols = IMU_COLUMNS[kind]
        names, block = {"time": (cols[:1], None), "gyro": (cols[1:4], gyro), "accel": (cols[4:7], accel)}[field]
        row = None if e.index is None else e.index - first_row
        if block is not None and row is not None and 0 <= row < len(block) and not np.isfinite(block[row]).all():
            names = [names[int(np.flatnonzero(~np.isfinite(block[row]))[0])]]
        msg = str(e)
        reason = msg[len(field) + 2:] if msg.startswith(f"{field}: ") else msg
        raise input_error("imu", f"column {names[0]!r}: {reason}" if len(names) == 1 else f"columns {names}: {reason}", e.index) from None


def _epoch(t0, epoch):
    """The datetime of time 0: ``epoch``, else ``t0`` if it is a datetime, else None."""
    if epoch is None:
        return timestamp(t0)
    if timestamp(epoch) is None:
        raise TypeError(f"epoch: expected a datetime (pandas.Timestamp, datetime or numpy.datetime64), got {type(epoch).__name__}")
    return timestamp(epoch)


def _h_ref(h_ref, n: int):
    """The reference altitudes as a float array of ``n`` values (the core checks them)."""
    if h_ref is None:
        return None
    h = as_floats(h_ref, "h_ref")
    if h.shape != (n,):
        raise input_error("h_ref", f"expected shape ({n},), got {h.shape}")
    return h


def _diverged(err, table: np.ndarray, done: int, first_row: int, time: np.ndarray):
    """Complete a divergence error: ``partial``, the DataFrame of the ``done`` rows of
    ``table`` computed before it (rows ``first_row``… of the record), and the record row
    ``row`` and time ``time_s`` (s) of the sample at which the solution diverged."""
    err.partial = _table(table[:, :done], first_row)
    err.row = first_row + done
    err.time_s = float(time[done])
    return err


class Strapdown(Stateful):
    """Streaming strapdown INS from an initial state (time, position, velocity, attitude).

    Times are in seconds. A timedelta64 ``time_s`` column of the IMU tables is read as
    seconds. A datetime64 one needs an epoch, the datetime of time 0: ``epoch``, or else
    ``t0`` given as a datetime (then time 0 is ``t0``); every time in and out (``t0``, the
    solution's ``time_s``) is then in seconds since it, and without one a datetime64
    column is a ``TypeError``. Datetimes and the epoch must be both tz-aware or both naive.

    The initial state is checked: finite values, latitude within ±90°, height within
    [−10 km, 1000 km] (``atomnav.earth.HEIGHT_RANGE``), and ``q_nb`` a rotation, of unit
    norm within 1e-6 (``atomnav.rotation.ROTATION_TOLERANCE``): ``[1, .1, .1, .1]`` is an
    :class:`InputError` naming ``q_nb``, not a quaternion to rescale silently.

    Parameters
    ----------
    t0 : float or datetime
        Time of the initial state (s), or a datetime (then time 0, see above).
    lla : array_like (3,)
        Initial position: latitude (rad), longitude (rad), height (m).
    vel_ned : array_like (3,)
        Initial NED velocity (m/s).
    q_nb : array_like (4,)
        Initial attitude, body to NED, scalar first, unit norm.
    kind : str, optional
        ``"rates"`` (rad/s, m/s²) or ``"increments"`` (rad, m/s). With rates, the first
        sample must be at ``t0`` (it primes the integrator). With increments, each row
        covers (t_{k−1}, t_k] and is stamped t_k > t0. None (default): the kind of the
        column names of the first table :meth:`run` reads
        (:func:`atomnav.trajectory.imu_kind`), fixed from then on; :attr:`kind` is None
        until then. A plain array needs ``kind`` given here.
    ellipsoid : str
        Earth model, one of ``_core.OPTIONS["Ellipsoid"]``.
    vertical : str
        ``"free"`` or ``"damped"``: a second-order baro loop on a reference altitude, gains
        2ζω and ω² + 2γ/R₀.
    zeta, omega : float, optional
        Damping ratio and natural frequency (rad/s) of the baro loop; the core's defaults
        (0.707, 0.01 rad/s) when not given.
    epoch : datetime, optional
        ``pandas.Timestamp``, ``datetime`` or ``numpy.datetime64``: time 0 of the seconds
        (see above); :meth:`atomnav.trajectory.Trajectory.initial_state` gives it for a
        trajectory read from datetimes.

    Rows are numbered in the whole record: the DataFrames of successive :meth:`run` calls
    continue each other's index, as do error indices.

    One object may be shared by threads (their calls run one after another) and pickled
    or deep-copied mid-record: the copy continues bit for bit like the original.
    """

    def __init__(self, t0, lla, vel_ned, q_nb, *, kind: str | None = None, ellipsoid: str = "WGS84",
                 vertical: str = "free", zeta: float | None = None, omega: float | None = None, epoch=None):
        #: The datetime of time 0 (``epoch``, or ``t0`` given as a datetime), else None.
        self.epoch = _epoch(t0, epoch)
        t0 = scalar(t0, "t0") if timestamp(t0) is None else seconds(pd.Series([t0]), "t0", "t0", self.epoch, "epoch")[0]
        # the state and options, to build the core anew for the kind of the first table when none is given
        self._start = (t0, vector(lla, 3, "lla"), vector(vel_ned, 3, "vel_ned"), vector(q_nb, 4, "q_nb"))
        self._options = dict(ellipsoid=ellipsoid, vertical=vertical, zeta=None if zeta is None else scalar(zeta, "zeta"),
                             omega=None if omega is None else scalar(omega, "omega"))
        self._core = _core.Strapdown(*self._start, kind="increments" if kind is None else kind, **self._options)
        self._fixed = kind is not None
        plausibility.lla(lla, "lla")
        self._rows = 0

    @property
    @serialized
    def kind(self) -> str | None:
        """The IMU kind, ``"rates"`` or ``"increments"`` (None until the first table when
        not given)."""
        return self._core.kind if self._fixed else None

    @serialized
    def run(self, imu, h_ref=None) -> pd.DataFrame:
        """Integrate the next chunk of the record.

        Parameters
        ----------
        imu : DataFrame or array (N, 7)
            IMU table with the columns of :data:`atomnav.trajectory.IMU_COLUMNS` for this
            object's kind (time s, gyro, accel). A DataFrame is read by column name (any
            order, extra columns ignored; ``time_s`` may be datetime64 when ``t0`` is a
            datetime, or timedelta64). A plain array is accepted only with exactly these
            seven columns in exactly this order: time, gyro x/y/z, accel x/y/z (one whose
            columns 1-3 have the mean magnitude of gravity and 4-6 that of a rate, the
            order time, accel, gyro, is an :class:`InputError`:
            :func:`atomnav.plausibility.swapped_blocks`).
        h_ref : array (N,), optional
            Reference altitude (m) per row, required with ``vertical="damped"``.

        Returns
        -------
        DataFrame
            The solution after each row, indexed by the row's number in the whole record.

        Raises
        ------
        InputError
            ``parameter == "imu"`` for a bad row (its record row in ``.index``, the column
            in the message); the state is left unchanged.
        TypeError
            For a column that does not hold numbers (strings included).
        NumericalError
            If the solution diverges: ``.partial`` holds the rows computed before it (as
            this method would return them), ``.row`` and ``.time_s`` (s) name the sample
            at which it diverged. Restart with :meth:`reset`.
        """
        core = self._core
        if not self._fixed:  # the first table fixes the kind
            kind = imu_kind(None, imu, "imu")
            core = core if kind == core.kind else _core.Strapdown(*self._start, kind=kind, **self._options)
        t, g, a = _imu_arrays(imu, core.kind, self.epoch)
        plausibility.imu(t, g, a, core.kind)
        first = self._rows
        try:
            with _imu_errors(core.kind, g, a, first):
                table = core.run(t, g, a, _h_ref(h_ref, len(t)), first)
        except _core.NumericalError as err:
            self._core, self._fixed, self._rows = core, True, first + err.rows + 1
            raise _diverged(err, err.table, err.rows, first, t) from None
        self._core, self._fixed, self._rows = core, True, first + len(t)
        return _table(table, first)

    @serialized
    def state(self) -> pd.DataFrame:
        """The current state.

        Returns
        -------
        DataFrame
            One row with the columns of :meth:`run`.
        """
        return _table(self._core.state())

    @serialized
    def reset(self, state) -> None:
        """Restart from ``state`` as a new :class:`Strapdown` with this one's options would
        (coning/sculling history cleared, rate priming anew, rows numbered from 0).

        Parameters
        ----------
        state : DataFrame or dict
            A one-row DataFrame with the columns of :meth:`state` (e.g. a row of a
            :meth:`run` result), or a dict with ``t0`` (s), ``lla`` (rad, rad, m),
            ``vel_ned`` (m/s) and ``q_nb``, checked as by the constructor.

        Raises
        ------
        InputError
            ``parameter == "state"``: a missing field or a state the constructor rejects.
            The object is then unchanged.
        """
        if isinstance(state, pd.DataFrame):
            missing = [c for c in COLUMNS[:11] if c not in state.columns]
            if missing or len(state) != 1:
                raise input_error("state", f"expected one row with columns {COLUMNS[:11]}, got {len(state)} row(s), missing {missing}")
            row = state.iloc[0]
            fields = (row["time_s"], row[COLUMNS[1:4]], row[COLUMNS[4:7]], row[COLUMNS[7:11]])
        elif isinstance(state, Mapping):
            missing = [k for k in ("t0", "lla", "vel_ned", "q_nb") if k not in state]
            if missing:
                raise input_error("state", f"missing {missing}")
            fields = (state["t0"], state["lla"], state["vel_ned"], state["q_nb"])
        else:
            raise TypeError(f"state: expected a one-row DataFrame or a dict, got {type(state).__name__}")
        t0, lla, vel, q = fields
        start = (scalar(t0, "state"), vector(lla, 3, "state"), vector(vel, 3, "state"), vector(q, 4, "state"))
        with renamed(t0="state", lla="state", vel_ned="state", q_nb="state"):
            self._core.reset(*start)
        self._start = start
        plausibility.lla(lla, "state")
        self._rows = 0


def integrate(imu, t0, lla, vel_ned, q_nb, *, kind: str | None = None, ellipsoid: str = "WGS84",
              vertical: str = "free", h_ref=None, zeta: float | None = None, omega: float | None = None,
              progress: bool | None = None, epoch=None) -> pd.DataFrame:
    """Integrate a whole IMU record from the initial state.

    Parameters
    ----------
    imu : DataFrame or array (N, 7)
        IMU table, read by column name (see :meth:`Strapdown.run`); a plain array only in
        the column order of ``atomnav.trajectory.IMU_COLUMNS[kind]``: time, gyro x/y/z,
        accel x/y/z.
    t0, lla, vel_ned, q_nb
        Initial state: time (s, or a datetime, see :class:`Strapdown`); lat (rad), lon
        (rad), h (m); NED velocity (m/s); q_nb.
    kind : str, optional
        ``"rates"`` or ``"increments"``; None (default): the kind of the table's column
        names (:func:`atomnav.trajectory.imu_kind`); required for a plain array.
    ellipsoid, vertical, zeta, omega, epoch
        As for :class:`Strapdown` (``epoch``: time 0 of a datetime64 ``time_s``).
    h_ref : array (N,), optional
        Reference altitude (m) per IMU row for a damped vertical channel.
    progress : bool, optional
        Show a progress bar; by default for records over 10⁶ rows.

    Returns
    -------
    DataFrame
        time_s, lat_rad, lon_rad, h_m, vn_mps, ve_mps, vd_mps, qw..qz, roll_rad,
        pitch_rad, yaw_rad, one row per IMU row.

    Raises
    ------
    NumericalError
        If the solution diverges: ``.partial`` holds every row computed before it,
        ``.row`` and ``.time_s`` (s) name the sample at which it diverged.
    """
    sd = Strapdown(t0, lla, vel_ned, q_nb, kind=imu_kind(kind, imu, "imu"), ellipsoid=ellipsoid, vertical=vertical, zeta=zeta, omega=omega, epoch=epoch)
    t, g, a = _imu_arrays(imu, sd.kind, sd.epoch)
    plausibility.imu(t, g, a, sd.kind)
    h = _h_ref(h_ref, len(t))
    show = len(t) > 1_000_000 if progress is None else flag(progress, "progress")
    # one table for the whole record, filled chunk by chunk in place (no concatenation)
    table = np.empty((len(COLUMNS), len(t)))
    from tqdm.auto import tqdm

    with tqdm(total=len(t), disable=not show, unit="sample", desc="strapdown") as bar:
        for s in range(0, len(t), CHUNK):
            sl = slice(s, s + CHUNK)
            try:
                with _imu_errors(sd.kind, g, a, 0):
                    sd._core.run_into(t[sl], g[sl], a[sl], table, None if h is None else h[sl], s)
            except _core.NumericalError as err:
                raise _diverged(err, table, s + err.rows, 0, t) from None
            bar.update(len(t[sl]))
    return _table(table)


def integrate_attitude(q0, dtheta, dtheta_prev=None) -> np.ndarray:
    """Body attitude from gyro increments with the multi-interval coning correction
    (see ``rust/strapdown/mod.rs``), no navigation-frame rotation.

    Parameters
    ----------
    q0 : array_like (4,)
        Initial attitude, scalar first (normalised before use).
    dtheta : array_like (N, 3)
        Gyro angle increments (rad), one row per interval.
    dtheta_prev : array_like (K, 3), optional
        The increments of up to two intervals before the first one (rad), oldest first, if
        known (a running INS has them; only the last two rows are used). Without them the
        first step has no coning term, a one-time error of about |Δθ₀ × Δθ₁|/12 rad.

    Returns
    -------
    ndarray (N, 4)
        The attitude q after each increment, scalar first.
    """
    prev = None if dtheta_prev is None else rows(dtheta_prev, 3, "dtheta_prev")
    return _core.integrate_attitude_increments(rows(q0, 4, "q0"), rows(dtheta, 3, "dtheta"), prev)
