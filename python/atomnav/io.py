"""Reading a user's own logs: an IMU log or a reference trajectory, from CSV, Parquet or a
DataFrame, into atomnav's tables.

:func:`read_imu` gives an :class:`ImuLog`: the table of
:data:`atomnav.trajectory.IMU_COLUMNS` in SI units (for :func:`atomnav.strapdown.integrate`,
:func:`atomnav.imu.corrupt` and the aided INS) with a :class:`SamplingReport` of its time
stamps. :func:`read_trajectory` gives a :class:`atomnav.trajectory.Trajectory`.

Files are read by pandas: :func:`pandas.read_csv` for ``.csv``/``.txt``/``.tsv`` (and
their compressed forms, e.g. ``.csv.gz``), :func:`pandas.read_parquet` for ``.parquet``/``.pq``
(pyarrow). Extra keyword arguments go to
that reader (``sep=";"``, ``decimal=","``, ``skiprows=...``).

Nothing is guessed. ``columns`` maps each of atomnav's names to the file's column, and
``units`` states every unit; the factors are those of :mod:`atomnav.units`. Nothing is
silently reordered or dropped: a missing value (NaN), a time stamp that does not increase,
or a gap beyond a stated ``max_gap`` is an :class:`atomnav.InputError` with
``.parameter == "source"``, the file's column in the message and the row in ``.index``.
Rows are counted as 0-based data rows: row k of a CSV with one header line is on line
k + 2 of the file.
"""

from __future__ import annotations

import unicodedata
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from . import earth, plausibility, units as _units
from ._core import InputError
from ._validate import check_numbers, choice, input_error, instance, locate, path as checked_path, positive, seconds, timestamp
from .trajectory import IMU_COLUMNS, Trajectory

#: atomnav's names of an IMU log's fields, in the order of ``IMU_COLUMNS[kind]`` (``gyro``
#: is Δθ and ``accel`` Δv for ``kind="increments"``).
IMU_FIELDS = ("time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")

#: Accepted units of an IMU log per kind and quantity, with their factors to SI.
IMU_UNITS = {
    "rates": {
        "gyro": {"rad/s": 1.0, "deg/s": _units.DEG, "deg/h": _units.DEG_PER_HOUR},
        "accel": {"m/s²": 1.0, "m/s^2": 1.0, "mps2": 1.0, "g": _units.G0, "mg": _units.MILLI_G, "µg": _units.MICRO_G,
                  "ug": _units.MICRO_G},
    },
    "increments": {
        "gyro": {"rad": 1.0, "deg": _units.DEG},
        "accel": {"m/s": 1.0, "mps": 1.0},
    },
}

_ANGLE = {"rad": 1.0, "deg": _units.DEG}
#: atomnav's names of a trajectory's fields and their columns of
#: :data:`atomnav.trajectory.COLUMNS`: position and velocity, then the attitude as a
#: quaternion q_nb or as Euler angles.
TRAJECTORY_FIELDS = {"time": "time_s", "lat": "lat_rad", "lon": "lon_rad", "h": "h_m", "vn": "vn_mps", "ve": "ve_mps", "vd": "vd_mps"}
QUATERNION_FIELDS = {"qw": "qw", "qx": "qx", "qy": "qy", "qz": "qz"}
EULER_FIELDS = {"roll": "roll_rad", "pitch": "pitch_rad", "yaw": "yaw_rad"}
#: Accepted units of a trajectory per quantity (``vel``: vn, ve, vd; ``euler``: roll,
#: pitch, yaw), with their factors to SI. ``lat`` and ``lon`` are required (never
#: guessed), ``euler`` too when the attitude is in Euler angles.
TRAJECTORY_UNITS = {"lat": _ANGLE, "lon": _ANGLE, "h": {"m": 1.0}, "vel": {"m/s": 1.0, "mps": 1.0}, "euler": _ANGLE}
_QUANTITY = {"lat": "lat", "lon": "lon", "h": "h", "vn": "vel", "ve": "vel", "vd": "vel", "roll": "euler", "pitch": "euler", "yaw": "euler"}

#: Units of a time column of numbers (seconds and the decimal fractions numpy's timedelta
#: knows), or ``"datetime"`` for date-and-time text or datetime64 values.
TIME_UNITS = ("s", "ms", "us", "ns", "datetime")

#: ``on_gap`` choices: raise an :class:`atomnav.InputError`, or only list the gaps.
ON_GAP = ("raise", "report")

_CSV = (".csv", ".txt", ".tsv")
_PARQUET = (".parquet", ".pq")


@dataclass(frozen=True)
class SamplingReport:
    """The sampling of a log's time stamps, the ``report`` of an :class:`ImuLog`.

    Attributes
    ----------
    samples : int
        Rows of the log.
    start_s, end_s : float
        First and last time stamp (s).
    median_interval_s : float
        Median interval between stamps (s).
    rate_hz : float
        Its inverse (Hz).
    max_gap_s : float
        The longest interval not counted as a gap (s): the stated ``max_gap`` or 1.5 × the
        median interval.
    gaps : DataFrame
        One row per interval longer than ``max_gap_s``: ``row`` (the data row after the
        gap), ``start_s`` and ``end_s`` (the stamps either side, s), ``length_s`` (s) and
        ``missing_samples`` (the interval in median intervals, rounded, less one).
    """

    samples: int
    start_s: float
    end_s: float
    median_interval_s: float
    rate_hz: float
    max_gap_s: float
    gaps: pd.DataFrame

    def __str__(self) -> str:
        head = (f"{self.samples} samples, {self.start_s:.6g}..{self.end_s:.6g} s, median interval "
                f"{self.median_interval_s:.6g} s ({self.rate_hz:.6g} Hz)")
        if self.gaps.empty:
            return f"{head}; no gap longer than {self.max_gap_s:.6g} s"
        return f"{head}; {len(self.gaps)} gap(s) longer than {self.max_gap_s:.6g} s:\n{self.gaps.to_string(index=False)}"


@dataclass(frozen=True)
class ImuLog:
    """An IMU log read by :func:`read_imu`.

    Attributes
    ----------
    data : DataFrame
        The table of ``atomnav.trajectory.IMU_COLUMNS[kind]`` in SI units (time s; rates
        rad/s and m/s², or increments rad and m/s), one row per data row of the source in
        the same order (its index is that row).
    kind : str
        ``"rates"`` or ``"increments"``.
    report : SamplingReport
        The sampling of its time stamps.
    epoch : pandas.Timestamp or None
        The datetime of time 0 when the time column held datetimes (pass it on as
        ``epoch=`` where a call compares with other datetimes), else None.
    """

    data: pd.DataFrame
    kind: str
    report: SamplingReport
    epoch: pd.Timestamp | None = None

    @property
    def time(self) -> np.ndarray:
        """Time stamps (N,), s."""
        return self.data.iloc[:, 0].to_numpy()

    @property
    def gyro(self) -> np.ndarray:
        """Angular rates (rad/s) or increments Δθ (rad), (N, 3)."""
        return self.data.iloc[:, 1:4].to_numpy()

    @property
    def accel(self) -> np.ndarray:
        """Specific forces (m/s²) or increments Δv (m/s), (N, 3)."""
        return self.data.iloc[:, 4:7].to_numpy()


def read_imu(source, *, columns: Mapping, units: Mapping, kind: str, time_unit: str = "s", epoch=None,
             max_gap: float | None = None, on_gap: str = "raise", **read_options) -> ImuLog:
    """Read an IMU log into atomnav's IMU table (SI) with a report of its sampling.

    Parameters
    ----------
    source : str, path-like or DataFrame
        A CSV or Parquet file (told apart by its suffix, see the module docstring), or a
        DataFrame already read.
    columns : mapping
        atomnav's name → the source's column for each of :data:`IMU_FIELDS`: ``time``,
        ``gyro_x``, ``gyro_y``, ``gyro_z``, ``accel_x``, ``accel_y``, ``accel_z`` (for
        ``kind="increments"`` ``gyro_*`` are the Δθ and ``accel_*`` the Δv columns). Other
        columns of the source are ignored.
    units : mapping
        The unit of ``"gyro"`` and of ``"accel"``, one of :data:`IMU_UNITS` ``[kind]``:
        rates ``"rad/s"``, ``"deg/s"``, ``"deg/h"`` and ``"m/s²"`` (also ``"m/s^2"``,
        ``"mps2"``), ``"g"`` (standard gravity), ``"mg"``, ``"µg"`` (also ``"ug"``);
        increments ``"rad"``, ``"deg"`` and ``"m/s"``.
    kind : str
        ``"rates"`` or ``"increments"`` (each row the Δθ and Δv over the interval ending
        at its stamp); the source's own column names say nothing about it.
    time_unit : str
        Unit of the time column, one of :data:`TIME_UNITS`: numbers in ``"s"``, ``"ms"``,
        ``"us"`` or ``"ns"`` (divided by the count per second), or ``"datetime"``:
        date-and-time text or datetime64 values, read as seconds since ``epoch``. A
        timedelta64 column is read as its seconds whatever the unit.
    epoch : datetime, optional
        With ``time_unit="datetime"``: time 0 (``pandas.Timestamp``, ``datetime`` or
        ``numpy.datetime64``, tz-aware exactly when the column is); by default the first
        sample.
    max_gap : float, optional
        The longest interval between two stamps (s) the log may have. A longer one is an
        :class:`atomnav.InputError` unless ``on_gap="report"``. Without it, intervals over
        1.5 × the median interval are only listed in the report.
    on_gap : str
        ``"raise"`` (default) or ``"report"``: list gaps beyond ``max_gap`` instead.
    **read_options
        Passed to :func:`pandas.read_csv` or :func:`pandas.read_parquet`.

    Returns
    -------
    ImuLog
        ``.data`` the table of ``atomnav.trajectory.IMU_COLUMNS[kind]``, ``.report`` its
        :class:`SamplingReport`, ``.epoch`` time 0 of datetimes.

    Raises
    ------
    InputError
        ``parameter`` ``"columns"``, ``"units"``, ``"kind"``, ``"time_unit"``, ``"epoch"``,
        ``"max_gap"`` or ``"on_gap"`` for a bad argument (a missing or unknown field, a
        column not in the source, an unknown unit with the accepted ones listed), and
        ``"source"`` for bad data, with the column in the message and the 0-based data
        row in ``.index``: a missing value (NaN) or an infinite one, fewer than two rows,
        a time stamp not above the one before it (repeated or going back), an interval
        over ``max_gap`` (``.index`` the row after the gap).
    TypeError
        A column that does not hold numbers (text in a sensor column, numbers where
        ``time_unit="datetime"`` expects dates).
    """
    kind = choice(kind, IMU_COLUMNS, "kind")
    factors = {q: _factor(units, q, IMU_UNITS[kind][q], f"kind={kind!r}") for q in ("gyro", "accel")}
    _known(units, IMU_UNITS[kind], "units")
    wanted = _fields(columns, IMU_FIELDS)
    frame = _read(source, read_options)
    where = _where(frame, wanted)
    t, epoch = _time(frame.iloc[:, where["time"]], wanted["time"], time_unit, epoch)
    sensors = _numbers(frame, where, wanted, IMU_FIELDS[1:])
    _finite(np.column_stack([t, sensors]), [wanted[f] for f in IMU_FIELDS])
    report = _sampling(t, wanted["time"], max_gap, on_gap)
    gyro, accel = sensors[:, :3] * factors["gyro"], sensors[:, 3:] * factors["accel"]
    plausibility.imu(t, gyro, accel, kind, "source")
    data = pd.DataFrame(np.column_stack([t, gyro, accel]), columns=IMU_COLUMNS[kind])
    return ImuLog(data, kind, report, epoch)


def read_trajectory(source, *, columns: Mapping, units: Mapping, time_unit: str = "s", epoch=None, ellipsoid: str = "WGS84",
                    **read_options) -> Trajectory:
    """Read a reference trajectory (a truth or another system's solution).

    Parameters
    ----------
    source : str, path-like or DataFrame
        A CSV or Parquet file, or a DataFrame (as for :func:`read_imu`).
    columns : mapping
        atomnav's name → the source's column: ``time``, ``lat``, ``lon``, ``h``, ``vn``,
        ``ve``, ``vd`` (NED velocity), and the attitude either as the quaternion q_nb
        (``qw``, ``qx``, ``qy``, ``qz``, scalar first, Hamilton) or as Euler angles
        (``roll``, ``pitch``, ``yaw``; C_nb = Rz(yaw) Ry(pitch) Rx(roll)).
    units : mapping
        ``"lat"`` and ``"lon"``: ``"deg"`` or ``"rad"`` (required: never guessed);
        ``"euler"`` likewise, required with Euler angles; ``"h"``: ``"m"`` and ``"vel"``:
        ``"m/s"`` (the defaults). See :data:`TRAJECTORY_UNITS`.
    time_unit, epoch, **read_options
        As for :func:`read_imu`; the trajectory keeps ``epoch`` (the first sample by
        default) as :attr:`atomnav.trajectory.Trajectory.epoch` for datetimes.
    ellipsoid : str
        The ellipsoid of the positions, ``"WGS84"`` or ``"PZ90.11"``.

    Returns
    -------
    atomnav.trajectory.Trajectory
        In atomnav's units (rad, m, m/s), one row per data row of the source.

    Raises
    ------
    InputError
        As for :func:`read_imu` (without gaps), and with ``parameter == "source"`` and the
        row in ``.index``: a latitude beyond ±90°, a height outside
        ``atomnav.earth.HEIGHT_RANGE`` (m), a quaternion whose norm is not 1 within
        ``atomnav.rotation.ROTATION_TOLERANCE``.
    TypeError
        As for :func:`read_imu`.
    """
    if not isinstance(columns, Mapping):
        raise TypeError(f"columns: expected a mapping of atomnav's names to the source's columns, got {type(columns).__name__}")
    attitude = QUATERNION_FIELDS if any(f in columns for f in QUATERNION_FIELDS) else EULER_FIELDS
    fields = {**TRAJECTORY_FIELDS, **attitude}
    wanted = _fields(columns, tuple(fields), also=tuple(EULER_FIELDS if attitude is QUATERNION_FIELDS else QUATERNION_FIELDS))
    needed = ("lat", "lon") + (("euler",) if attitude is EULER_FIELDS else ())
    _known(units, TRAJECTORY_UNITS, "units")
    factors = {q: _factor(units, q, TRAJECTORY_UNITS[q], "a trajectory", q in needed)
               for q in ("lat", "lon", "h", "vel") + (("euler",) if attitude is EULER_FIELDS else ())}
    frame = _read(source, read_options)
    where = _where(frame, wanted)
    t, epoch = _time(frame.iloc[:, where["time"]], wanted["time"], time_unit, epoch)
    names = tuple(fields)[1:]
    values = _numbers(frame, where, wanted, names)
    _finite(np.column_stack([t, values]), [wanted[f] for f in fields])
    if len(t) > 1:
        _increasing(t, wanted["time"])
    for j, name in enumerate(names):
        if name in _QUANTITY:
            values[:, j] *= factors[_QUANTITY[name]]
    h = values[:, names.index("h")]
    low, high = earth.HEIGHT_RANGE
    outside = np.flatnonzero((h < low) | (h > high))
    if outside.size:
        k = outside[0]
        raise input_error("source", f"column {wanted['h']!r} (h): height {h[k]} m at {_row(k)} is outside "
                                    f"[{low:g}, {high:g}] m", k)
    table = pd.DataFrame(np.column_stack([t, values]), columns=list(fields.values()))
    try:
        return Trajectory.from_dataframe(table, ellipsoid, epoch=epoch)
    except InputError as e:  # the core's checks of the table (latitudes, quaternions): in the source's names
        if getattr(e, "parameter", None) != "df":
            raise
        reason = str(e)[len("df: "):]
        for f, name in fields.items():
            reason = reason.replace(repr(name), f"{wanted[f]!r} ({name})")
        if e.index is not None:
            reason = reason.replace(f"at index {e.index}", f"at {_row(e.index)}")
        raise input_error("source", reason, e.index) from None


# ---- arguments ----------------------------------------------------------------------------

def _row(k: int) -> str:
    """Row ``k`` as error messages name it."""
    return f"data row {k} (0-based, the header line not counted)"


def _fields(columns, fields: tuple, also: tuple = ()) -> dict:
    """``columns`` (atomnav's name → the source's column) checked against ``fields``, all
    required; ``also`` are names of the other attitude form, an error when mixed in."""
    if not isinstance(columns, Mapping):
        raise TypeError(f"columns: expected a mapping of atomnav's names to the source's columns, got {type(columns).__name__}")
    unknown = [k for k in columns if k not in fields]
    if unknown:
        mixed = [k for k in unknown if k in also]
        why = (f"{mixed} mix the quaternion (qw, qx, qy, qz) and Euler angles (roll, pitch, yaw): give one of them" if mixed
               else f"unknown name(s) {unknown}")
        raise input_error("columns", f"{why}; atomnav's names are {list(fields)}")
    missing = [f for f in fields if f not in columns]
    if missing:
        raise input_error("columns", f"no column given for {missing}; atomnav's names are {list(fields)}")
    seen = {}
    for f in fields:
        try:
            hash(columns[f])
        except TypeError:
            raise TypeError(f"columns: {f!r}: expected a column name, got {type(columns[f]).__name__}") from None
        if columns[f] in seen:
            raise input_error("columns", f"{seen[columns[f]]!r} and {f!r} both name the column {columns[f]!r}")
        seen[columns[f]] = f
    return {f: columns[f] for f in fields}


def _known(given, accepted: Mapping, name: str) -> None:
    """An :class:`InputError` naming ``name`` for a key of the mapping ``given`` that is no
    key of ``accepted``."""
    if not isinstance(given, Mapping):
        raise TypeError(f"{name}: expected a mapping of quantities to unit names, got {type(given).__name__}")
    unknown = [k for k in given if k not in accepted]
    if unknown:
        raise input_error(name, f"unknown quantity {unknown}; the quantities are {list(accepted)}")


def _unit_key(name: str) -> str:
    """A unit name in its compatibility form (the micro sign and Greek mu alike, ² as 2)."""
    return unicodedata.normalize("NFKC", name).strip()


def _factor(given, quantity: str, accepted: dict, what: str, required: bool = True) -> float:
    """The factor to SI of the unit ``given[quantity]`` among ``accepted`` (SI when absent
    and not ``required``); an unknown or missing unit is an :class:`InputError` naming
    ``units`` and the quantity, listing the accepted units."""
    if not isinstance(given, Mapping):
        raise TypeError(f"units: expected a mapping of quantities to unit names, got {type(given).__name__}")
    if quantity not in given:
        if required:
            raise input_error("units", f"no unit given for {quantity!r}; state one of {list(accepted)}")
        return 1.0
    unit = given[quantity]
    if not isinstance(unit, str):
        raise TypeError(f"units: {quantity!r}: expected a unit name (str), got {type(unit).__name__}")
    factor = {_unit_key(k): v for k, v in accepted.items()}.get(_unit_key(unit))
    if factor is None:
        raise input_error("units", f"{quantity!r}: unknown unit {unit!r} for {what}; accepted units are {list(accepted)}")
    return factor


# ---- the source -----------------------------------------------------------------------

def _read(source, read_options: dict) -> pd.DataFrame:
    """The source as a DataFrame: itself, or its file read by pandas."""
    if isinstance(source, pd.DataFrame):
        if read_options:
            raise input_error("source", f"is a DataFrame already: the file reader's options {sorted(read_options)} do not apply")
        return source
    p = checked_path(source, "source")
    suffixes = [s.lower() for s in p.suffixes]
    if any(s in _PARQUET for s in suffixes):
        reader, what = pd.read_parquet, "Parquet"
    elif any(s in _CSV for s in suffixes):
        reader, what = pd.read_csv, "CSV"
    else:
        raise input_error("source", f"cannot tell the format of {p.name!r} from its suffix: name it {' '.join(_CSV + _PARQUET)}, "
                                    "or read it with pandas and pass the DataFrame")
    if not p.is_file():
        raise FileNotFoundError(f"source: no such file {str(p)!r}")
    try:
        return instance(reader(p, **read_options), pd.DataFrame, "source")
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
        raise input_error("source", f"not a readable {what} table: {e}") from None
    except Exception as e:  # pyarrow's errors on a file that is not Parquet
        if type(e).__module__.startswith("pyarrow"):
            raise input_error("source", f"not a readable {what} table: {e}") from None
        raise


def _where(frame: pd.DataFrame, wanted: dict) -> dict:
    """The position in ``frame`` of each wanted column (atomnav's name → position)."""
    missing = {f: c for f, c in wanted.items() if c not in frame.columns}
    if missing:
        raise input_error("columns", f"{missing} not in the source; its columns are {list(frame.columns)}")
    return dict(zip(wanted, locate(frame, list(wanted.values()), "source")))


def _time(values: pd.Series, column, time_unit: str, epoch):
    """A time column as float seconds and the datetime of time 0 (None unless datetimes)."""
    choice(time_unit, TIME_UNITS, "time_unit")
    dtype = values.dtype
    if time_unit != "datetime":
        if epoch is not None:
            raise input_error("epoch", f"applies to time_unit='datetime' only, not {time_unit!r}")
        if pd.api.types.is_datetime64_any_dtype(dtype):
            raise input_error("time_unit", f"column {column!r} holds datetimes, not numbers in {time_unit!r}: give time_unit='datetime'")
        t = seconds(values, "source", column, None)
        if pd.api.types.is_timedelta64_dtype(dtype):
            return t, None
        return t / (np.timedelta64(1, "s") / np.timedelta64(1, time_unit)), None
    if epoch is not None and timestamp(epoch) is None:
        raise TypeError(f"epoch: expected a datetime (pandas.Timestamp, datetime or numpy.datetime64), got {type(epoch).__name__}")
    if not pd.api.types.is_datetime64_any_dtype(dtype):
        if pd.api.types.is_numeric_dtype(dtype) and not pd.api.types.is_bool_dtype(dtype):
            raise TypeError(f"source: column {column!r} holds numbers, not datetimes: give time_unit as one of {list(TIME_UNITS[:-1])}")
        try:
            parsed = pd.to_datetime(values, errors="coerce", format="ISO8601")
        except (ValueError, TypeError) as e:  # e.g. time zones that differ between rows
            raise input_error("source", f"column {column!r}: not one series of ISO 8601 dates and times ({e})") from None
        bad = np.flatnonzero(parsed.isna().to_numpy() & values.notna().to_numpy())
        if bad.size:
            k = bad[0]
            raise input_error("source", f"column {column!r}: {values.iloc[k]!r} at {_row(k)} is not an ISO 8601 date and time", k)
        values = parsed
    first = values.dropna()
    epoch = timestamp(epoch) if epoch is not None else (first.iloc[0] if len(first) else None)
    return seconds(values, "source", column, epoch), epoch


def _numbers(frame: pd.DataFrame, where: dict, wanted: dict, fields) -> np.ndarray:
    """The columns of ``fields`` as one float array (NaN where missing)."""
    out = np.empty((len(frame), len(fields)))
    for j, f in enumerate(fields):
        values = frame.iloc[:, where[f]]
        check_numbers(values, "source", wanted[f])
        out[:, j] = values.to_numpy(dtype=float, na_value=np.nan)
    return out


def _finite(values: np.ndarray, names: list) -> None:
    """An :class:`InputError` for the first row with a missing or infinite value, naming
    its first such column."""
    bad = ~np.isfinite(values)
    rows = np.flatnonzero(bad.any(axis=1))
    if rows.size:
        k = rows[0]
        j = int(np.flatnonzero(bad[k])[0])
        what = "a missing value (NaN)" if np.isnan(values[k, j]) else f"an infinite value ({values[k, j]})"
        raise input_error("source", f"column {names[j]!r}: {what} at {_row(k)}; no row is dropped silently: clean the log "
                                    "or pass only the rows to read", k)


def _increasing(t: np.ndarray, column) -> None:
    """An :class:`InputError` at the first stamp not above the one before it."""
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        k = bad[0] + 1
        how = "repeats the stamp before it" if t[k] == t[k - 1] else f"goes back from {t[k - 1]!r} s"
        raise input_error("source", f"time column {column!r} is not strictly increasing: {_row(k)} ({t[k]!r} s) {how}; "
                                    "rows are never reordered or dropped silently", k)


def _sampling(t: np.ndarray, column, max_gap, on_gap: str) -> SamplingReport:
    """The :class:`SamplingReport` of time stamps ``t`` (s), checked increasing, and the
    gap check against ``max_gap``."""
    choice(on_gap, ON_GAP, "on_gap")
    stated = None if max_gap is None else positive(max_gap, "max_gap")
    if len(t) < 2:
        raise input_error("source", f"needs at least 2 rows to have a sampling interval, got {len(t)}")
    _increasing(t, column)
    dt = np.diff(t)
    median = float(np.median(dt))
    limit = 1.5 * median if stated is None else stated
    after = np.flatnonzero(dt > limit) + 1
    gaps = pd.DataFrame({"row": after, "start_s": t[after - 1], "end_s": t[after], "length_s": dt[after - 1],
                         "missing_samples": np.rint(dt[after - 1] / median).astype(np.int64) - 1})
    if stated is not None and on_gap == "raise" and after.size:
        k = after[0]
        raise input_error("source", f"time column {column!r}: a gap of {dt[k - 1]:.6g} s before {_row(k)} ({t[k - 1]:.6g} to "
                                    f"{t[k]:.6g} s) exceeds max_gap = {stated:g} s ({after.size} such gap(s)); "
                                    "on_gap='report' lists them in the report instead", k)
    return SamplingReport(len(t), float(t[0]), float(t[-1]), median, 1.0 / median, limit, gaps)
