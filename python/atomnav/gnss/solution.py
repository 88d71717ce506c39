"""GNSS solution files written by another program: RTKLIB's ``.pos`` format, read into a
table in SI units and into position and velocity fixes for the aided INS.

RTKLIB (Takasu, *RTKLIB ver. 2.4.2 Manual*, 2013, Appendix B.2 "Solution file format")
writes one epoch per line after ``%`` header lines, the last of which names the columns:

- time: ``GPST``, ``UTC`` or ``JST`` as ``yyyy/mm/dd hh:mm:ss.sss`` or as GPS week and
  seconds of week;
- position: latitude and longitude in degrees (``latitude(deg)``) or degrees, minutes and
  seconds (``latitude(d'")``) and ellipsoidal height, or ECEF ``x-ecef(m) y-ecef(m)
  z-ecef(m)``;
- ``Q`` (solution quality, :data:`QUALITY`), ``ns`` (number of satellites);
- σ of each axis and the signed square roots of the covariances (``sdne`` is
  sign(c_ne)·√|c_ne|; north-east-up, or ECEF ``sdxy sdyz sdzx``), ``age(s)``, ``ratio``;
- velocities with the same σ's when the file has them (``vn(m/s) ve(m/s) vu(m/s) sdvn
  sdve sdvu sdvne sdveu sdvun``, or ECEF ``vx-ecef(m/s) ...``).

Formal σ's of float and single solutions are optimistic. :meth:`PosSolution.position_fixes`
and :meth:`PosSolution.velocity_fixes` therefore scale the file's covariances by a gain per
quality, :data:`SIGMA_GAINS` (σ × 1 for fix, × 2 for float, × 5 for single: the gains of
the loosely coupled filter of Everett 2025, ``rtklibexplorer/GNSS_IMU``), overridable.
"""

from __future__ import annotations

import gzip
import io
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Mapping

import numpy as np
import pandas as pd

from .. import earth
from .._validate import input_error
from ..filter.sources import PositionFixes, VelocityFixes

#: RTKLIB's solution quality flags (Q): 1 fix, 2 float, 3 SBAS, 4 DGPS, 5 single, 6 PPP,
#: 7 dead reckoning (RTKLIB ``SOLQ_*``).
QUALITY = {1: "fix", 2: "float", 3: "sbas", 4: "dgps", 5: "single", 6: "ppp", 7: "dr"}

#: Default multiplier on the file's σ per quality (covariance × gain²); a quality missing
#: here is not used as a fix.
SIGMA_GAINS = {"fix": 1.0, "float": 2.0, "sbas": 5.0, "dgps": 5.0, "single": 5.0, "ppp": 1.0}

#: GPS − UTC (s) from each date on (IERS Bulletin C; GPS time began equal to UTC on
#: 1980-01-06).
LEAP_SECONDS = (("1981-07-01", 1), ("1982-07-01", 2), ("1983-07-01", 3), ("1985-07-01", 4), ("1988-01-01", 5),
                ("1990-01-01", 6), ("1991-01-01", 7), ("1992-07-01", 8), ("1993-07-01", 9), ("1994-07-01", 10),
                ("1996-01-01", 11), ("1997-07-01", 12), ("1999-01-01", 13), ("2006-01-01", 14), ("2009-01-01", 15),
                ("2012-07-01", 16), ("2015-07-01", 17), ("2017-01-01", 18))

#: Start of GPS time (1980-01-06 00:00:00 on the GPS time scale).
GPS_EPOCH = pd.Timestamp("1980-01-06")

_TIME_SCALES = {"GPST": None, "UTC": 0.0, "JST": 9.0}  # hours ahead of UTC (None: GPS time)
_LLH = ("latitude(deg)", "longitude(deg)", "height(m)")
_DMS = ("latitude(d'\")", "longitude(d'\")", "height(m)")
_XYZ = ("x-ecef(m)", "y-ecef(m)", "z-ecef(m)")
_NEU_SIGMA = ("sdn(m)", "sde(m)", "sdu(m)", "sdne(m)", "sdeu(m)", "sdun(m)")
_XYZ_SIGMA = ("sdx(m)", "sdy(m)", "sdz(m)", "sdxy(m)", "sdyz(m)", "sdzx(m)")
_NEU_VEL = ("vn(m/s)", "ve(m/s)", "vu(m/s)", "sdvn", "sdve", "sdvu", "sdvne", "sdveu", "sdvun")
_XYZ_VEL = ("vx-ecef(m/s)", "vy-ecef(m/s)", "vz-ecef(m/s)", "sdvx", "sdvy", "sdvz", "sdvxy", "sdvyz", "sdvzx")

#: Columns of :attr:`PosSolution.data` (the velocity columns only when the file has them).
COLUMNS = ("time_s", "lat_rad", "lon_rad", "h_m", "q", "quality", "n_sats", "age_s", "ratio")
NED_COV = tuple(f"cov_{a}{b}_m2" for a, b in ("nn", "ee", "dd", "ne", "ed", "dn"))
VEL_COLUMNS = ("vn_mps", "ve_mps", "vd_mps")
VEL_COV = tuple(f"cov_v{a}{b}_m2s2" for a, b in ("nn", "ee", "dd", "ne", "ed", "dn"))


@dataclass(frozen=True)
class PosSolution:
    """A GNSS solution file read by :func:`read_pos`.

    Attributes
    ----------
    data : DataFrame
        One row per epoch: ``time_s`` (s since ``epoch``, GPS time scale), ``lat_rad``,
        ``lon_rad``, ``h_m``, ``q`` (RTKLIB's Q), ``quality`` (its name in
        :data:`QUALITY`), ``n_sats``, ``age_s``, ``ratio``, the NED position covariance
        ``cov_nn_m2 ... cov_dn_m2`` (m²) and, when the file has velocities, ``vn_mps,
        ve_mps, vd_mps`` and their covariance ``cov_vnn_m2s2 ...`` (m²/s²).
    epoch : Timestamp
        Time 0 of ``time_s`` (GPS time scale).
    time_scale : str
        The file's time scale: ``"GPST"``, ``"UTC"`` or ``"JST"`` (converted to GPS time).
    default_gains : mapping
        Multiplier on the covariance columns' σ per quality when
        :meth:`position_fixes` is given none: :data:`SIGMA_GAINS` for a ``.pos`` file
        (formal σ's), 1 for an NMEA log (its σ's are already final, see
        :func:`~atomnav.gnss.read_nmea`). A quality without a gain is not used.
    skipped : int
        Epochs left out because the receiver had no solution (NMEA quality 0, 7 or 8).
    """

    data: pd.DataFrame
    epoch: pd.Timestamp
    time_scale: str
    default_gains: Mapping[str, float] = field(default_factory=lambda: dict(SIGMA_GAINS))
    skipped: int = 0

    @property
    def has_velocity(self) -> bool:
        """Whether the file holds velocities."""
        return VEL_COLUMNS[0] in self.data

    def counts(self) -> pd.Series:
        """Number of epochs per quality.

        Returns
        -------
        Series
            Epoch count indexed by quality name (``fix``, ``float``, ...).
        """
        return self.data["quality"].value_counts()

    def position_fixes(self, gains: Mapping[str, float] | None = None, *, lever_arm=None) -> PositionFixes:
        """The epochs as position fixes for :func:`atomnav.filter.aided_ins`.

        Parameters
        ----------
        gains : mapping, optional
            Multiplier on the file's σ per quality name (covariance × gain²); default
            :attr:`default_gains`. A quality without a gain is left out.
        lever_arm : array_like (3,), optional
            Antenna position from the IMU in the body frame, m, passed to
            :class:`~atomnav.filter.PositionFixes` when given.

        Returns
        -------
        PositionFixes
            One fix per epoch of a quality with a gain, covariance in NED (m²).
        """
        rows, scale = self._kept(gains)
        cov = _stack(rows, NED_COV) * scale[:, None, None]
        extra = {} if lever_arm is None else {"lever_arm": lever_arm}
        return PositionFixes(rows["time_s"].to_numpy(), rows[["lat_rad", "lon_rad", "h_m"]].to_numpy(), cov, **extra)

    def velocity_fixes(self, gains: Mapping[str, float] | None = None, *, lever_arm=None) -> VelocityFixes:
        """The epochs' velocities as NED velocity fixes (as :meth:`position_fixes`).

        Parameters
        ----------
        gains : mapping, optional
            Multiplier on the file's velocity σ per quality name; default :attr:`default_gains`.
        lever_arm : array_like (3,), optional
            Antenna position from the IMU in the body frame, m.

        Returns
        -------
        VelocityFixes
            One fix per epoch of a quality with a gain, covariance in NED (m²/s²).

        Raises
        ------
        atomnav.InputError
            Naming ``source`` when the file has no velocity columns.
        """
        if not self.has_velocity:
            raise input_error("source", f"the file has no velocity columns (RTKLIB writes them as {list(_NEU_VEL[:3])})")
        rows, scale = self._kept(gains)
        cov = _stack(rows, VEL_COV) * scale[:, None, None]
        extra = {} if lever_arm is None else {"lever_arm": lever_arm}
        return VelocityFixes(rows["time_s"].to_numpy(), rows[list(VEL_COLUMNS)].to_numpy(), cov, **extra)

    def _kept(self, gains) -> tuple[pd.DataFrame, np.ndarray]:
        """The rows of a quality with a gain, and each row's covariance factor (gain²)."""
        gains = dict(self.default_gains if gains is None else gains)
        for name, g in gains.items():
            if name not in SIGMA_GAINS and name != "dr":
                raise input_error("gains", f"unknown quality {name!r}; one of {list(QUALITY.values())}")
            if not (isinstance(g, (int, float)) and np.isfinite(g) and g > 0):
                raise input_error("gains", f"the gain of {name!r} must be a finite number > 0, got {g!r}")
        keep = self.data["quality"].isin(list(gains))
        rows = self.data[keep]
        return rows, rows["quality"].map(gains).to_numpy(float) ** 2


def read_pos(source: str | PathLike | io.TextIOBase, *, epoch=None) -> PosSolution:
    """Read an RTKLIB solution file (``.pos``).

    Parameters
    ----------
    source : str, path-like or text stream
        The file (``.gz``: read through gzip).
    epoch : datetime-like or "gps", optional
        Time 0 of ``time_s``, on the GPS time scale: a ``pandas.Timestamp`` (or anything
        it reads), ``"gps"`` for the start of GPS time (1980-01-06), or by default
        1970-01-01 (GPS-scale seconds since 1970, the stamps of many IMU loggers).

    Returns
    -------
    PosSolution
        The epochs in SI units with their NED covariances (see :class:`PosSolution`).

    Raises
    ------
    atomnav.InputError
        Naming ``source`` and the file's line number (``.index``, counting from 1) for a
        header without the column line, an unknown time scale or position format, a line
        with fewer fields than the header names (a truncated line), a field that is not a
        number, an unknown Q, or times that do not increase.
    """
    lines = _read_text(source).splitlines()
    header = [i for i, ln in enumerate(lines) if ln.startswith("%")]
    labels = lines[header[-1]].lstrip("%").split() if header else []
    if not labels or labels[0] not in _TIME_SCALES:
        raise input_error("source", "no RTKLIB column header: the last '%' line must name the columns, starting with "
                          f"the time scale, one of {list(_TIME_SCALES)}", (header[-1] + 1) if header else None)
    scale, names = labels[0], labels[1:]
    position = _position_format(names, header[-1] + 1)
    data_lines = [(i + 1, ln) for i, ln in enumerate(lines) if ln.strip() and not ln.startswith("%")]
    if not data_lines:
        raise input_error("source", "the file holds no epochs")
    dated = "/" in data_lines[0][1].split()[0]
    per_position = 3 if position is _DMS else 1
    fields = 2 + 2 * per_position + (len(names) - 2)  # date and time (or week and seconds), lat and lon
    split = [line.split() for _, line in data_lines]
    for (number, _), f in zip(data_lines, split):
        if len(f) < fields:
            raise input_error("source", f"line {number} has {len(f)} fields, the header names {fields} (a truncated "
                              "line)", number)
    # fields beyond the named ones (some programs append their own) are ignored, as RTKLIB does
    raw = pd.DataFrame([f[:fields] for f in split])
    time = _gps_time(raw, dated, scale, data_lines)
    values = _numbers(raw.iloc[:, 2:], data_lines)
    if per_position == 3:
        lat, lon = (_dms(values[:, k:k + 3]) for k in (0, 3))
        values = np.column_stack([lat, lon, values[:, 6:]])
    cols = dict(zip(names, values.T))
    epoch0 = _parse_epoch(epoch)
    time_s = (time - epoch0) / pd.Timedelta(seconds=1)
    bad = np.flatnonzero(np.diff(time_s) <= 0)
    if len(bad):
        raise input_error("source", f"line {data_lines[bad[0] + 1][0]}: time does not increase", data_lines[bad[0] + 1][0])
    q = cols["Q"]
    unknown = np.flatnonzero(~np.isin(q, list(QUALITY)))
    if len(unknown):
        number = data_lines[unknown[0]][0]
        raise input_error("source", f"line {number}: unknown solution quality Q = {q[unknown[0]]:g}; RTKLIB's are "
                          f"{QUALITY}", number)
    out = {"time_s": time_s.to_numpy(float)}
    if position is _XYZ:
        lla, cov = _from_ecef(np.column_stack([cols[c] for c in _XYZ]), _cov(cols, _XYZ_SIGMA))
    else:
        lla = np.column_stack([np.radians(cols[position[0]]), np.radians(cols[position[1]]), cols["height(m)"]])
        cov = _neu_to_ned(_cov(cols, _NEU_SIGMA))
    out.update(lat_rad=lla[:, 0], lon_rad=lla[:, 1], h_m=lla[:, 2], q=q.astype(np.int64),
               quality=pd.Series(q.astype(np.int64)).map(QUALITY).to_numpy(), n_sats=cols["ns"].astype(np.int64),
               age_s=cols["age(s)"], ratio=cols["ratio"])
    out.update(_cov_columns(cov, NED_COV))
    if set(_NEU_VEL) <= set(cols):
        v = np.column_stack([cols["vn(m/s)"], cols["ve(m/s)"], -cols["vu(m/s)"]])
        out.update(dict(zip(VEL_COLUMNS, v.T)), **_cov_columns(_neu_to_ned(_cov(cols, _NEU_VEL[3:])), VEL_COV))
    elif set(_XYZ_VEL) <= set(cols):
        v_e = np.column_stack([cols[c] for c in _XYZ_VEL[:3]])
        rot = np.stack([earth.dcm_ned_to_ecef(la, lo) for la, lo in lla[:, :2]])
        v = np.einsum("kji,kj->ki", rot, v_e)
        cov_v = np.einsum("kji,kjl,klm->kim", rot, _cov(cols, _XYZ_VEL[3:]), rot)
        out.update(dict(zip(VEL_COLUMNS, v.T)), **_cov_columns(cov_v, VEL_COV))
    return PosSolution(pd.DataFrame(out), epoch0, scale)


def gps_minus_utc(when: pd.Timestamp) -> int:
    """GPS − UTC in s (leap seconds since 1980) at the UTC time ``when``.

    Parameters
    ----------
    when : Timestamp
        A UTC time on or after 1980-01-06.

    Returns
    -------
    int
        The leap seconds of :data:`LEAP_SECONDS` in force then.
    """
    return max([n for date, n in LEAP_SECONDS if when >= pd.Timestamp(date)], default=0)


def _read_text(source) -> str:
    """The whole text of a solution file.

    Parameters
    ----------
    source : str, path-like or text stream
        The file (``.gz``: read through gzip) or an open text stream.

    Returns
    -------
    str
        Its text.
    """
    if hasattr(source, "read"):
        return source.read()
    if not isinstance(source, (str, PathLike)):
        raise TypeError(f"source: expected a path or a text stream, got {type(source).__name__}")
    path = Path(source)
    if "\x00" in str(path):
        raise input_error("source", f"not a file name: {str(path)!r} holds a null byte")
    with (gzip.open(path, "rt", encoding="utf-8") if path.suffix == ".gz" else open(path, encoding="utf-8")) as f:
        return f.read()


def _position_format(names: list[str], line: int) -> tuple[str, ...]:
    for fmt in (_LLH, _DMS, _XYZ):
        if tuple(names[:3]) == fmt:
            return fmt
    raise input_error("source", f"line {line}: position columns {names[:3]} are none of RTKLIB's lat/lon/height "
                      "(deg or d'\") or ECEF (the ENU baseline format needs the base position: write lat/lon/height)",
                      line)


def _numbers(frame: pd.DataFrame, data_lines) -> np.ndarray:
    values = frame.apply(pd.to_numeric, errors="coerce").to_numpy(float)
    bad = np.argwhere(~np.isfinite(values))
    if len(bad):
        row, col = bad[0]
        number = data_lines[row][0]
        raise input_error("source", f"line {number}: field {col + 3} {frame.iat[row, col]!r} is not a number", number)
    return values


def _gps_time(raw: pd.DataFrame, dated: bool, scale: str, data_lines) -> pd.Series:
    """The epochs' times on the GPS time scale (naive Timestamps)."""
    if dated:
        t = pd.to_datetime(raw[0] + " " + raw[1], format="%Y/%m/%d %H:%M:%S.%f", errors="coerce")
    else:
        week, tow = (pd.to_numeric(raw[k], errors="coerce") for k in (0, 1))
        t = GPS_EPOCH + pd.to_timedelta(week * 7 * 86400.0 + tow, unit="s")
    if t.isna().any():
        number = data_lines[int(np.flatnonzero(t.isna())[0])][0]
        raise input_error("source", f"line {number}: the time is not an RTKLIB time "
                          "('yyyy/mm/dd hh:mm:ss.sss' or GPS week and seconds of week)", number)
    ahead = _TIME_SCALES[scale]
    if ahead is None:
        return t
    utc = t - pd.Timedelta(hours=ahead)
    return utc + pd.to_timedelta(np.array([gps_minus_utc(x) for x in utc], dtype=float), unit="s")


def _parse_epoch(epoch) -> pd.Timestamp:
    """Time 0 of a solution's ``time_s``.

    Parameters
    ----------
    epoch : datetime-like, "gps" or None
        A time on the GPS time scale without a time zone, ``"gps"`` for 1980-01-06, or
        None for 1970-01-01.

    Returns
    -------
    Timestamp
        The epoch (naive, GPS time scale).
    """
    if epoch is None:
        return pd.Timestamp("1970-01-01")
    if isinstance(epoch, str) and epoch == "gps":
        return GPS_EPOCH
    try:
        e = pd.Timestamp(epoch)
    except (TypeError, ValueError) as err:
        raise input_error("epoch", f"expected a date and time or 'gps', got {epoch!r} ({err})") from None
    if e.tzinfo is not None:
        raise input_error("epoch", "give a time on the GPS time scale without a time zone")
    return e


def _dms(d: np.ndarray) -> np.ndarray:
    """Degrees from (degrees, minutes, seconds) rows; the sign is that of the degrees."""
    sign = np.where(np.signbit(d[:, 0]), -1.0, 1.0)
    return sign * (np.abs(d[:, 0]) + d[:, 1] / 60.0 + d[:, 2] / 3600.0)


def _cov(cols: dict, names: tuple[str, ...]) -> np.ndarray:
    """(N, 3, 3) covariances from RTKLIB's σ's and signed square roots of covariances
    (a, b, c, ab, bc, ca)."""
    sa, sb, sc, ab, bc, ca = (cols[n] for n in names)
    signed = lambda x: np.sign(x) * x * x  # noqa: E731 - RTKLIB writes sign(c)·sqrt(|c|)
    c = np.zeros((len(sa), 3, 3))
    c[:, 0, 0], c[:, 1, 1], c[:, 2, 2] = sa**2, sb**2, sc**2
    c[:, 0, 1] = c[:, 1, 0] = signed(ab)
    c[:, 1, 2] = c[:, 2, 1] = signed(bc)
    c[:, 2, 0] = c[:, 0, 2] = signed(ca)
    return c


_NEU_TO_NED = np.diag([1.0, 1.0, -1.0])


def _neu_to_ned(c: np.ndarray) -> np.ndarray:
    return _NEU_TO_NED @ c @ _NEU_TO_NED


def _from_ecef(xyz: np.ndarray, cov_e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    lla = earth.ecef_to_lla(xyz)
    rot = np.stack([earth.dcm_ned_to_ecef(la, lo) for la, lo in lla[:, :2]])
    return lla, np.einsum("kji,kjl,klm->kim", rot, cov_e, rot)


def _cov_columns(cov: np.ndarray, names: tuple[str, ...]) -> dict:
    """The six distinct entries of (N, 3, 3) covariances as named columns.

    Parameters
    ----------
    cov : ndarray (N, 3, 3)
        Symmetric covariances.
    names : tuple of str
        Column names of the entries (0,0), (1,1), (2,2), (0,1), (1,2), (2,0).

    Returns
    -------
    dict
        Column name → (N,) array.
    """
    idx = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))
    return {n: cov[:, i, j] for n, (i, j) in zip(names, idx)}


def _stack(rows: pd.DataFrame, names: tuple[str, ...]) -> np.ndarray:
    nn, ee, dd, ne, ed, dn = (rows[n].to_numpy(float) for n in names)
    return np.stack([np.stack([nn, ne, dn], -1), np.stack([ne, ee, ed], -1), np.stack([dn, ed, dd], -1)], -2)

