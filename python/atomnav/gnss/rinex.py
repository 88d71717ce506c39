"""RINEX observation and navigation files (RINEX 2.11, 3 and 4, plain, Hatanaka or gzip),
read in the core by the ``rinex`` crate (no parser of our own, docs/departures.md#rinex-reading),
and a small RINEX 3 writer for simulated data (tests and exchange).

Time: GPS seconds since the start of a GPS week (``week_start``, a datetime in GPS
time): by default the week of the navigation records' median time, shared by
:func:`read_obs`. GLONASS navigation epochs are UTC, so t_GLO = UTC − week_start +
10800 s.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np
import pandas as pd

from .. import _core
from .._validate import input_error, instance, path as checked_path
from .ephemeris import GLONASS_COLUMNS, GPS_COLUMNS, Ephemerides
from .observations import _gps_week_start, doppler_to_rate, _gps_week_of, obs_arrays
from .solution import GPS_EPOCH, gps_minus_utc

WEEK_START = datetime(2017, 1, 1)   # a Sunday: GPS week 1930


def _week_start(week_start) -> datetime:
    return instance(week_start, datetime, "week_start")


def _num(x: float) -> str:
    return f"{x:19.12E}"


def _stamp(t: datetime) -> str:
    return f"{t.year:04d} {t.month:02d} {t.day:02d} {t.hour:02d} {t.minute:02d} {t.second:02d}"


def write_nav(path, eph: Ephemerides, n_leap: float = 18.0, week_start: datetime = WEEK_START) -> Path:
    """Write the broadcast sets of ``eph`` as a RINEX 3.04 mixed navigation file, with
    its Klobuchar coefficients (GPSA/GPSB).

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    eph : Ephemerides
        The GPS and GLONASS broadcast sets.
    n_leap : float, default 18.0
        GPS−UTC leap seconds, s.
    week_start : datetime.datetime, default 2017-01-01
        Start (a Sunday, GPS time) of the GPS week the times refer to; GLONASS epochs are
        written in UTC, t_GLO = UTC − week_start + 10800 s.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    path, week_start = checked_path(path), _week_start(week_start)
    instance(eph, Ephemerides, "eph")
    gps, glo = eph.tables()
    alpha, beta = eph.ionosphere[:4], eph.ionosphere[4:]
    lines = [f"{3.04:9.2f}{'':11}{'N: GNSS NAV DATA':20}{'M: Mixed':20}RINEX VERSION / TYPE",
             f"{'atomnav':20}{'':20}{'':20}PGM / RUN BY / DATE",
             f"{'GPSA ':5}{''.join(f'{x:12.4E}' for x in alpha):48}{'':7}IONOSPHERIC CORR",
             f"{'GPSB ':5}{''.join(f'{x:12.4E}' for x in beta):48}{'':7}IONOSPHERIC CORR",
             f"{int(round(n_leap)):6d}{'':54}LEAP SECONDS", f"{'':60}END OF HEADER"]
    for _, e in gps.iterrows():
        toc = week_start + timedelta(seconds=float(e.toc))
        # Toe as seconds of its own GPS week, with that week's number
        since = _offset(week_start) + float(e.toe)
        week, toe = divmod(since, 604800.0)
        vals = [e.af0, e.af1, e.af2, 0.0, e.crs, e.delta_n, e.m0, e.cuc, e.e, e.cus, e.sqrt_a, toe, e.cic, e.omega0,
                e.cis, e.i0, e.crc, e.omega, e.omega_dot, e.idot, 0.0, week, 0.0, 2.0, 0.0, e.tgd, 0.0, toe, 4.0, 0.0, 0.0]
        lines.append(f"G{int(e.prn):02d} {_stamp(toc)}" + "".join(_num(v) for v in vals[:3]))
        lines += ["    " + "".join(_num(v) for v in vals[k:k + 4]) for k in range(3, 31, 4)]
    for _, e in glo.iterrows():
        utc = week_start + timedelta(seconds=float(e.tb) - 10800.0)
        vals = [-e.tau_n, e.gamma_n, 0.0, e.x / 1e3, e.vx / 1e3, e.ax / 1e3, 0.0, e.y / 1e3, e.vy / 1e3, e.ay / 1e3,
                e.channel, e.z / 1e3, e.vz / 1e3, e.az / 1e3, 0.0]
        lines.append(f"R{int(e.slot):02d} {_stamp(utc)}" + "".join(_num(v) for v in vals[:3]))
        lines += ["    " + "".join(_num(v) for v in vals[k:k + 4]) for k in range(3, 15, 4)]
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def write_obs(path, obs: pd.DataFrame, week_start: datetime = WEEK_START) -> Path:
    """Write an observation table as a RINEX 3.04 file with C1C (m) and D1C (Hz,
    D = −rate/λ_k).

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    obs : pandas.DataFrame
        Observation table (``time_s`` GPS s, ``sat``, ``channel``, ``code_m`` m,
        ``rate_mps`` m/s), as :func:`atomnav.gnss.simulate` gives it, read by column
        name as by :func:`atomnav.gnss.observations.obs_arrays` (``time_s`` may be naive
        GPS-time datetime64, which then dates the file itself).
    week_start : datetime.datetime, default 2017-01-01
        Start (a Sunday, GPS time) of the GPS week of ``time_s`` in seconds.

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    atomnav.InputError
        Naming ``obs`` for an empty or malformed table.
    """
    path, week_start = checked_path(path), _week_start(week_start)
    time, sats, channel, code, rate = obs_arrays(obs)
    if not len(obs):
        raise input_error("obs", "no observations to write")
    dated = _gps_week_start(obs)  # a datetime time column, read as seconds of its own GPS week
    week_start = week_start if dated is None else dated.to_pydatetime()
    lines = [f"{3.04:9.2f}{'':11}{'OBSERVATION DATA':20}{'M: Mixed':20}RINEX VERSION / TYPE",
             f"{'atomnav':20}{'':20}{'':20}PGM / RUN BY / DATE",
             f"{'G    2 C1C D1C':60}SYS / # / OBS TYPES", f"{'R    2 C1C D1C':60}SYS / # / OBS TYPES"]
    t0 = week_start + timedelta(seconds=float(time[0]))
    lines += [f"  {t0.year:04d}    {t0.month:02d}    {t0.day:02d}    {t0.hour:02d}    {t0.minute:02d}"
              f"{t0.second + t0.microsecond / 1e6:13.7f}     GPS         TIME OF FIRST OBS", f"{'':60}END OF HEADER"]
    lam = -doppler_to_rate(np.ones(len(obs)), sats, channel)
    epochs = pd.DataFrame({"sat": sats, "code_m": code, "doppler": -rate / lam})
    for t, ep in epochs.groupby(time, sort=True):
        s = week_start + timedelta(seconds=float(t))
        lines.append(f"> {s.year:04d} {s.month:02d} {s.day:02d} {s.hour:02d} {s.minute:02d}"
                     f"{s.second + s.microsecond / 1e6:11.7f}  0{len(ep):3d}")
        lines += [f"{sat}{c:14.3f}  {d:14.3f}  " for sat, c, d in zip(ep.sat, ep.code_m, ep.doppler)]
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def _offset(week: pd.Timestamp) -> float:
    """Seconds from the GPS epoch (1980-01-06) to ``week``."""
    return (pd.Timestamp(week) - GPS_EPOCH).total_seconds()


def _file(path, what: str) -> Path:
    path = checked_path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{what}: no RINEX file {path}")
    return path


def read_nav(path, n_leap: float | None = None, datum: str = "identity", week_start: datetime | None = None) -> Ephemerides:
    """Broadcast ephemerides from RINEX navigation files: the GPS LNAV and GLONASS FDMA
    records of RINEX 2 ``.n``/``.g``, RINEX 3 and RINEX 4 mixed files, plain or gzip, read
    in the core by the ``rinex`` crate (docs/departures.md#rinex-reading).

    Parameters
    ----------
    path : str, os.PathLike or list of them
        The navigation file, or several (e.g. a RINEX 2 GPS ``.n`` and GLONASS ``.g``).
        Records of other systems (and GPS CNAV) are set aside.
    n_leap : float, optional
        GPS−UTC leap seconds, s; default: the files' LEAP SECONDS line, else the IERS
        value at the records' median time.
    datum : {"identity", "pz90_02_to_wgs84"}, default "identity"
        PZ-90 → WGS-84 transformation of the GLONASS states.
    week_start : datetime.datetime, optional
        Start (a Sunday, GPS time) of the GPS week the times are counted from; default:
        the week of the records' median time. GLONASS epochs are UTC, t_GLO = UTC − week_start +
        10800 s. :func:`read_obs` counts from the same week (``Ephemerides.week_start``).

    Returns
    -------
    Ephemerides
        The healthy broadcast sets of the files (a set flagged unhealthy is left out), the
        Klobuchar coefficients of the GPS navigation message (ION ALPHA/BETA, GPSA/GPSB, or
        a RINEX 4 ION LNAV record) when a file has them, the time-system corrections,
        ``week_start`` and ``sources``.

    Raises
    ------
    FileNotFoundError
        When a path is not a file.
    atomnav.InputError
        Naming ``path``, the file and the line for a record that cannot be decoded, an
        unknown RINEX version, or files without GPS or GLONASS records.
    """
    paths = [_file(p, "nav") for p in (list(path) if isinstance(path, (list, tuple)) else [path])]
    if not paths:
        raise input_error("path", "an empty list names no navigation file")
    files = [_core.gnss_read_rinex_nav(str(p)) for p in paths]
    gps = np.vstack([f["gps"] for f in files])
    glo = np.vstack([f["glonass"] for f in files])
    if not len(gps) and not len(glo):
        raise input_error("path", f"no GPS or GLONASS records in {', '.join(map(str, paths))}")
    gf, rf = _core.RINEX_GPS_RECORD_FIELDS, _core.RINEX_GLONASS_RECORD_FIELDS
    gps = pd.DataFrame(gps, columns=gf)
    glo = pd.DataFrame(glo, columns=rf)
    calendar = np.sort(np.concatenate([gps["toc"].to_numpy(), glo["toc_utc"].to_numpy()]))
    middle = GPS_EPOCH + pd.Timedelta(seconds=float(calendar[len(calendar) // 2]))
    week = pd.Timestamp(_week_start(week_start)) if week_start is not None else _gps_week_of(middle)
    offset = _offset(week)
    iono = next((np.asarray(f["klobuchar"], float) for f in files if f["klobuchar"] is not None), None)
    leap = next((f["leap_seconds"] for f in files if f["leap_seconds"] is not None), None)
    leap = float(n_leap) if n_leap is not None else (float(leap) if leap is not None else float(gps_minus_utc(middle)))
    gps = gps[gps["health"] == 0.0]
    glo = glo[glo["health"] == 0.0]
    gps_t = pd.DataFrame({c: gps[c] for c in GPS_COLUMNS if c in gf and c not in ("toe", "toc")})
    gps_t["prn"] = gps["prn"].astype(int)
    # Toe counts from the start of its own GPS week (the record's week number)
    gps_t["toe"] = gps["toe_sow"] + gps["week"] * 604800.0 - offset
    gps_t["toc"] = gps["toc"] - offset
    glo_t = pd.DataFrame({c: glo[c] for c in GLONASS_COLUMNS if c in rf})
    glo_t["slot"], glo_t["channel"] = glo["slot"].astype(int), glo["channel"].astype(int)
    glo_t["tb"] = glo["toc_utc"] - offset + 10800.0
    glo_t["tau_n"] = -glo["minus_tau_n"]
    eph = Ephemerides(gps_t[GPS_COLUMNS].drop_duplicates(["prn", "toe"]), glo_t[GLONASS_COLUMNS].drop_duplicates(["slot", "tb"]),
                      leap, datum, ionosphere=iono)
    eph.week_start = week
    eph.sources = tuple(paths)
    eph.time_corrections = pd.DataFrame([c for f in files for c in f["time_corrections"]],
                                        columns=["system", "a0_s", "a1_s_per_s", "week", "seconds_of_week"])
    return eph


#: Observation codes read, per system letter, in order of preference (the first present at
#: an epoch is used): the civil L1 code, then the P(Y) code, then other tracking modes;
#: RINEX 2 names (C1, P1) beside RINEX 3 names.
CODE_PREFERENCE = _core.RINEX_CODE_L1
#: Second-frequency codes, in order of preference (for the ionosphere-free combination).
CODE2_PREFERENCE = _core.RINEX_CODE_L2
#: Doppler codes read, per system, in order of preference.
DOPPLER_PREFERENCE = _core.RINEX_DOPPLER_L1
#: Carrier-to-noise density (dB-Hz) on the first frequency, in order of preference.
SNR_PREFERENCE = _core.RINEX_SNR_L1
#: Systems positioned (others are set aside and counted).
SYSTEMS = ("G", "R")


@dataclass(frozen=True)
class RinexObservations:
    """An observation file read by :func:`read_obs`.

    Attributes
    ----------
    table : DataFrame
        One row per GPS or GLONASS satellite and epoch with a code or a Doppler:
        ``time_s`` (GPS s from ``week_start``), ``sat``, ``channel``, ``code_m`` (m, NaN
        when not tracked), ``rate_mps`` (m/s, NaN without Doppler), ``code2_m`` (the
        second-frequency code, m, NaN when not tracked), ``snr_dbhz`` (dB-Hz, NaN when not
        given), and the RINEX types used, ``code_type``, ``code2_type`` and
        ``doppler_type`` (empty when missing).
    header : dict
        ``marker``, ``receiver``, ``version``, ``time_system``, ``interval_s``,
        ``approx_position_m`` (ECEF, 3), ``antenna_delta_hen_m`` (3), ``glonass_channels``
        ({slot: k}), ``leap_seconds`` (None when the header has none).
    set_aside : Series
        Satellite-epochs of other systems (Galileo E, BeiDou C, QZSS J, SBAS S, IRNSS I),
        counted per system letter.
    missing : DataFrame
        Per epoch (``time_s``): GPS/GLONASS satellites ``n_sats``, those without code
        ``n_no_code`` and without Doppler ``n_no_doppler``.
    week_start : Timestamp
        Time 0 of ``time_s`` (GPS time).
    n_epochs : int
        Observation epochs in the file (event records excluded).
    """

    table: pd.DataFrame
    header: dict
    set_aside: pd.Series
    missing: pd.DataFrame
    week_start: pd.Timestamp
    n_epochs: int


def _names(index: np.ndarray, system: np.ndarray, preference: dict) -> np.ndarray:
    """The RINEX type names of preference-list indices (−1: missing, '')."""
    out = np.full(len(index), "", dtype=object)
    for sys, codes in preference.items():
        for k, c in enumerate(codes):
            out[(system == sys) & (index == k)] = c
    return out


def _check_coverage(path: Path, t: np.ndarray, eph: Ephemerides, header_lines: int, week: pd.Timestamp) -> None:
    """Refuse observations that no broadcast record can serve (GPS sets are valid 4 h
    around Toe in the fit interval of IS-GPS-200, GLONASS sets 30 min around tb)."""
    gps, glo = eph.tables()
    valid = [(gps["toe"].min() - 14400.0, gps["toe"].max() + 14400.0)] if len(gps) else []
    if len(glo):
        # tb is GLONASS time (UTC + 3 h); the leap seconds do not matter at this scale
        valid.append((glo["tb"].min() - 10800.0 - 1800.0, glo["tb"].max() - 10800.0 + 1800.0))
    if not len(t) or any(((t >= a) & (t <= b)).any() for a, b in valid):
        return
    when = lambda s: (week + pd.Timedelta(seconds=float(s))).strftime("%Y-%m-%d %H:%M:%S")
    spans = ", ".join(f"{when(a)} – {when(b)}" for a, b in valid)
    sources = ", ".join(str(s) for s in eph.sources) or "the ephemerides"
    raise input_error("path", f"{path}, line {header_lines + 1}, field EPOCH: observations {when(t.min())} – {when(t.max())} GPST "
                              f"lie outside what the navigation records of {sources} cover ({spans} GPST)")


def read_obs(path, eph: Ephemerides, week_start: datetime | None = None) -> RinexObservations:
    """Code, Doppler and SNR observations from a RINEX 2.11, 3 or 4 observation file
    (plain, Hatanaka ``.crx`` or gzip), read in the core by the ``rinex`` crate
    (docs/departures.md#rinex-reading).

    Parameters
    ----------
    path : str or os.PathLike
        RINEX observation file.
    eph : Ephemerides
        Ephemerides giving the GLONASS FDMA channels (for slots they lack, the file's
        GLONASS SLOT / FRQ # header line).
    week_start : datetime.datetime, optional
        Start (a Sunday, GPS time) of the GPS week of ``time_s``; default ``eph.week_start``
        (from :func:`read_nav`), else the week of the file's first epoch.

    Returns
    -------
    RinexObservations
        The observation table with, per satellite, the first code, second-frequency code,
        Doppler and SNR of :data:`CODE_PREFERENCE`, :data:`CODE2_PREFERENCE`,
        :data:`DOPPLER_PREFERENCE` and :data:`SNR_PREFERENCE` present at each epoch (a
        blank, NaN or 0.0 field is missing), the header facts, the records of other
        systems set aside and counted, and what each epoch was missing.

    Raises
    ------
    FileNotFoundError
        When ``path`` is not a file.
    atomnav.InputError
        Naming ``path``, the file, the line and the field for a record that cannot be
        decoded, an unknown RINEX version, epochs out of order, a time system other than
        GPS, observations outside what ``eph`` covers, or a file without any code type
        atomnav reads.
    """
    instance(eph, Ephemerides, "eph")
    path = _file(path, "obs")
    f = _core.gnss_read_rinex_obs(str(path))
    h = f["header"]
    if h["time_system"] not in ("GPST", "GPS"):
        raise input_error("path", f"{path}: time system {h['time_system']!r}; atomnav reads GPS-time observation files")
    if not (f["code_type"] >= 0).any():
        raise input_error("path", f"{path} has no code type atomnav reads ({CODE_PREFERENCE})")
    sat = np.asarray(f["sat"], dtype=object)
    system = np.array([s[0] for s in sat]) if len(sat) else np.array([], dtype=str)
    first = GPS_EPOCH + pd.Timedelta(seconds=float(f["time_s"].min()))
    week = (pd.Timestamp(_week_start(week_start)) if week_start is not None
            else getattr(eph, "week_start", None) or _gps_week_of(first))
    time_s = f["time_s"] - _offset(week)
    _check_coverage(path, time_s, eph, f["header_lines"], week)
    from_header = h["glonass_channels"]
    known = set(eph.satellites)
    names, row_of = np.unique(sat, return_inverse=True)  # one look-up per satellite, not per row
    per_sat = np.array([(eph.channel(s) if s in known else from_header.get(int(s[1:]), 0)) if s[0] == "R" else 0
                        for s in names], dtype=np.int64)
    channel = per_sat[row_of.reshape(-1)] if len(sat) else np.zeros(0, dtype=np.int64)
    table = pd.DataFrame({"time_s": time_s, "sat": sat, "channel": channel, "code_m": f["code_m"],
                          "rate_mps": doppler_to_rate(f["doppler_hz"], sat, channel), "code2_m": f["code2_m"],
                          "snr_dbhz": f["snr_dbhz"], "code_type": _names(f["code_type"], system, CODE_PREFERENCE),
                          "code2_type": _names(f["code2_type"], system, CODE2_PREFERENCE),
                          "doppler_type": _names(f["doppler_type"], system, DOPPLER_PREFERENCE)})
    flags = pd.DataFrame({"time_s": time_s, "n_sats": 1, "n_no_code": table.code_m.isna().astype(np.int64),
                          "n_no_doppler": table.rate_mps.isna().astype(np.int64)})
    missing = flags.groupby("time_s", sort=True).sum().reset_index()
    facts = {k: h[k] for k in ("marker", "receiver", "version", "interval_s", "approx_position_m", "antenna_delta_hen_m",
                               "glonass_channels", "leap_seconds")}
    facts["time_system"] = "GPS"
    set_aside = pd.Series(f["set_aside"], dtype=np.int64, name="satellite_epochs")
    return RinexObservations(table, facts, set_aside, missing, week, int(f["n_epochs"]))
