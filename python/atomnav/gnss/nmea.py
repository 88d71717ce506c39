"""GNSS solutions as a receiver streams them: NMEA 0183 ``GGA`` (position, quality, number
of satellites, HDOP), ``RMC`` (date, speed and course over ground) and ``GST`` (the
receiver's σ of latitude, longitude and altitude), read into the same
:class:`~atomnav.gnss.PosSolution` as an RTKLIB ``.pos`` file.

The sentences are parsed by ``pynmea2`` (``pip install "atomnav[gnss]"``), which checks
each checksum; atomnav groups them into epochs by their UTC time of day and converts them
to SI units on the GPS time scale.

- **Height.** GGA gives the altitude above mean sea level and the geoid separation; the
  ellipsoidal height ``h_m`` is their sum.
- **Quality.** GGA's fix quality maps to RTKLIB's solution qualities as RTKLIB itself
  reads NMEA (Takasu 2013, ``solq_nmea`` in ``solution.c``): 1 single, 2 DGPS, 3 PPS (read
  as PPP), 4 RTK fix, 5 RTK float, 6 dead reckoning. Quality 0 (no fix, also written as an
  empty GGA), 7 (manual input) and 8 (simulation) are not measurements: those epochs are
  left out and counted in :attr:`~atomnav.gnss.PosSolution.skipped`.
- **σ.** GGA carries no σ. An epoch with a GST sentence takes its σ's, inflated by
  :data:`~atomnav.gnss.solution.SIGMA_GAINS` as a ``.pos`` file's formal σ's are; any
  other epoch takes the documented table :data:`NMEA_SIGMA_M` scaled by HDOP (GGA has no
  VDOP: the vertical σ is :data:`VERTICAL_OVER_HORIZONTAL` times the horizontal one).
  Either way the covariance columns are final, so
  :meth:`~atomnav.gnss.PosSolution.position_fixes` uses them as they are unless given
  gains; ``sigma_source`` says which rule each epoch took.
"""

from __future__ import annotations

import datetime as dt
import io
from os import PathLike
from typing import Mapping

import numpy as np
import pandas as pd

from .._validate import input_error
from .solution import NED_COV, QUALITY, SIGMA_GAINS, PosSolution, _cov_columns, _parse_epoch, _read_text, gps_minus_utc

#: GGA fix quality → RTKLIB quality name (RTKLIB's own NMEA reading; 0, 7 and 8 are not
#: measurements).
GGA_QUALITY = {1: "single", 2: "dgps", 3: "ppp", 4: "fix", 5: "float", 6: "dr"}
_NOT_MEASURED = (0, 7, 8)

#: Default horizontal σ per axis at HDOP 1 (m) for an epoch without GST: the accuracy one
#: can expect of each solution type (RTK fix ~2 cm, float ~0.3 m, DGPS/SBAS ~1 m, single
#: frequency SPS ~3 m, PPP ~0.1 m, dead reckoning 10 m). Your receiver's datasheet is the
#: better source: pass ``sigma`` to :func:`read_nmea`.
NMEA_SIGMA_M = {"fix": 0.02, "float": 0.3, "dgps": 1.0, "sbas": 1.0, "single": 3.0, "ppp": 0.1, "dr": 10.0}

#: Vertical over horizontal σ for the table rule (GGA carries HDOP but no VDOP; VDOP is
#: typically 1.5–2 × HDOP for GPS).
VERTICAL_OVER_HORIZONTAL = 2.0

_KNOT = 1852.0 / 3600.0  # m/s


def read_nmea(source: str | PathLike | io.TextIOBase, *, date=None, epoch=None,
              sigma: Mapping[str, float] | None = None) -> PosSolution:
    """Read an NMEA 0183 log (GGA, with RMC and GST when present).

    Parameters
    ----------
    source : str, path-like or text stream
        The log (``.gz``: read through gzip). Lines that are not GGA, RMC or GST sentences
        are ignored.
    date : date-like, optional
        UTC date of the first epoch, for a log without RMC sentences (RMC carries the
        date; GGA only the time of day). Later epochs roll over at midnight.
    epoch : datetime-like or "gps", optional
        Time 0 of ``time_s`` on the GPS time scale, as in :func:`~atomnav.gnss.read_pos`
        (default 1970-01-01).
    sigma : mapping, optional
        Horizontal σ per axis at HDOP 1 (m) per quality name for epochs without GST;
        default :data:`NMEA_SIGMA_M`. A quality left out is not used as a fix.

    Returns
    -------
    PosSolution
        ``data`` has ``time_s``, ``lat_rad``, ``lon_rad``, ``h_m`` (ellipsoidal: altitude
        + geoid separation), ``q`` (RTKLIB's Q), ``quality``, ``n_sats``, ``n_sats`` and ``age_s``
        (missing, ``<NA>``/NaN, when the GGA leaves them empty), ``hdop``, the NED covariance ``cov_nn_m2 ...``
        (m²), ``sigma_source`` (``"GST"`` or ``"table"``) and, with RMC,
        ``speed_mps`` and ``course_rad`` (over ground, from north). Time scale ``"UTC"``
        (converted to GPS time).

    Raises
    ------
    atomnav.InputError
        Naming ``source`` and the line (``.index``, counting from 1) for a sentence that
        fails its checksum or has none (a truncated line), an unknown GGA quality, or
        times that do not increase; ``date`` when the log has no RMC and no date is
        given; ``sigma`` for an unknown quality or a σ that is not finite and > 0.
    """
    try:
        import pynmea2
    except ImportError:  # pragma: no cover - the gnss extra
        raise ImportError('reading NMEA needs pynmea2: pip install "atomnav[gnss]"') from None
    table = _sigma_table(sigma)
    epochs: dict[dt.time, dict] = {}
    dates: dict[dt.time, dt.date] = {}
    skipped = 0
    for number, line in enumerate(_read_text(source).splitlines(), start=1):
        start = line.find("$")
        kind = line[start + 3:start + 6] if start >= 0 else ""
        if kind not in ("GGA", "RMC", "GST"):
            continue
        try:
            msg = pynmea2.parse(line[start:].strip(), check=True)
        except pynmea2.ParseError as err:
            raise input_error("source", f"line {number}: not a valid NMEA sentence ({err.args[0]}; a truncated "
                              "line has no checksum)", number) from None
        if kind == "RMC":
            if msg.timestamp is not None and msg.datestamp is not None and msg.status == "A":
                dates[msg.timestamp] = msg.datestamp
                epochs.setdefault(msg.timestamp, {}).update(
                    speed=_number(msg.spd_over_grnd) * _KNOT, course=np.radians(_number(msg.true_course)))
        elif kind == "GST":
            if msg.timestamp is not None:
                epochs.setdefault(msg.timestamp, {})["gst"] = (
                    _number(msg.std_dev_latitude), _number(msg.std_dev_longitude), _number(msg.std_dev_altitude))
        elif msg.gps_qual is None or msg.gps_qual in _NOT_MEASURED:
            skipped += 1
        elif msg.gps_qual not in GGA_QUALITY:
            raise input_error("source", f"line {number}: unknown GGA fix quality {msg.gps_qual}; NMEA 0183 defines "
                              "0 to 8", number)
        elif msg.timestamp is None:
            raise input_error("source", f"line {number}: a GGA with a fix but no time", number)
        else:
            epochs.setdefault(msg.timestamp, {})["gga"] = (number, msg)
    rows = [(t, e) for t, e in epochs.items() if "gga" in e]
    if not rows:
        raise input_error("source", "the log holds no GGA sentence with a fix")
    utc = _utc_times([t for t, _ in rows], dates, date)
    gps = utc + pd.to_timedelta([float(gps_minus_utc(u)) for u in utc], unit="s")
    epoch0 = _parse_epoch(epoch)
    time_s = ((gps - epoch0) / pd.Timedelta(seconds=1)).to_numpy(float)
    bad = np.flatnonzero(np.diff(time_s) <= 0)
    if len(bad):
        number = rows[bad[0] + 1][1]["gga"][0]
        raise input_error("source", f"line {number}: time does not increase", number)
    return _solution(rows, time_s, table, epoch0, skipped)


def _sigma_table(sigma) -> dict[str, float]:
    if sigma is not None and not isinstance(sigma, Mapping):
        raise TypeError(f"sigma: expected a mapping of quality name to σ (m), got {type(sigma).__name__}")
    table = dict(NMEA_SIGMA_M if sigma is None else sigma)
    for name, s in table.items():
        if name not in QUALITY.values():
            raise input_error("sigma", f"unknown quality {name!r}; one of {list(QUALITY.values())}")
        if not (isinstance(s, (int, float)) and np.isfinite(s) and s > 0):
            raise input_error("sigma", f"the σ of {name!r} must be a finite number > 0 (m), got {s!r}")
    return table


def _number(field) -> float:
    """A numeric NMEA field as float (NaN when the receiver leaves it empty)."""
    try:
        return float(field)
    except (TypeError, ValueError):
        return float("nan")


def _utc_times(times: list[dt.time], dates: dict, date) -> pd.DatetimeIndex:
    """Naive UTC timestamps of the epochs: each RMC's date where there is one, else the
    previous epoch's date (rolled over when the time of day goes back)."""
    if date is None and not dates:
        raise input_error("date", "the log has no RMC sentence, which carries the date: give the UTC date of the "
                          "first epoch")
    current = None
    if date is not None:
        try:
            current = pd.Timestamp(date).date()
        except (TypeError, ValueError) as err:
            raise input_error("date", f"expected a date, got {date!r} ({err})") from None
    else:
        current = next(dates[t] for t in times if t in dates)
    out, previous = [], None
    for t in times:
        if t in dates:
            current = dates[t]
        elif previous is not None and t < previous:
            current = current + dt.timedelta(days=1)
        previous = t
        out.append(dt.datetime.combine(current, t.replace(tzinfo=None)))
    return pd.DatetimeIndex(out)


def _solution(rows, time_s, table, epoch0, skipped) -> PosSolution:
    gga = [e["gga"][1] for _, e in rows]
    q_name = np.array([GGA_QUALITY[m.gps_qual] for m in gga])
    hdop = np.array([_number(m.horizontal_dil) for m in gga])
    gst = np.array([e.get("gst", (np.nan,) * 3) for _, e in rows], dtype=float)
    has_gst = np.isfinite(gst).all(axis=1)
    base = np.array([table.get(q, np.nan) for q in q_name]) * np.where(np.isfinite(hdop), hdop, 1.0)
    gain = np.array([SIGMA_GAINS.get(q, np.nan) for q in q_name])
    sn = np.where(has_gst, gst[:, 0] * gain, base)
    se = np.where(has_gst, gst[:, 1] * gain, base)
    sd = np.where(has_gst, gst[:, 2] * gain, base * VERTICAL_OVER_HORIZONTAL)
    cov = np.zeros((len(rows), 3, 3))
    cov[:, 0, 0], cov[:, 1, 1], cov[:, 2, 2] = sn**2, se**2, sd**2
    rtklib_q = {name: q for q, name in QUALITY.items()}
    data = {
        "time_s": time_s,
        "lat_rad": np.radians([m.latitude for m in gga]),
        "lon_rad": np.radians([m.longitude for m in gga]),
        "h_m": np.array([_number(m.altitude) + _number(m.geo_sep) for m in gga]),
        "q": np.array([rtklib_q[q] for q in q_name], dtype=np.int64),
        "quality": q_name,
        "n_sats": pd.array([_number(m.num_sats) for m in gga]).astype("Int64"),
        "age_s": np.array([_number(m.age_gps_data) for m in gga]),
        "hdop": hdop,
        **_cov_columns(cov, NED_COV),
        "sigma_source": np.where(has_gst, "GST", "table"),
    }
    if any("speed" in e for _, e in rows):
        data["speed_mps"] = np.array([e.get("speed", np.nan) for _, e in rows])
        data["course_rad"] = np.array([e.get("course", np.nan) for _, e in rows])
    kept = [q for q in table if q != "dr"]
    gains = {q: 1.0 for q in kept}
    return PosSolution(pd.DataFrame(data), epoch0, "UTC", default_gains=gains, skipped=skipped)
