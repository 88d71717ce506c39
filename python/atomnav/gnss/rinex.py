"""RINEX observation and navigation files (RINEX 2.11, 3 and 4 observation files, plain,
Hatanaka or gzip; RINEX 2 and 3 navigation files) through georinex (optional extra
``atomnav[gnss]``; no parser of our own, docs/departures.md#rinex-through-georinex), and a
small RINEX 3 writer for simulated data (tests and exchange).

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

from .._validate import input_error, instance, path as checked_path
from .ephemeris import GLONASS_COLUMNS, GPS_COLUMNS, Ephemerides
from .observations import C_LIGHT, _gps_week_start, doppler_to_rate, _gps_week_of, obs_arrays
from .solution import GPS_EPOCH, gps_minus_utc

WEEK_START = datetime(2017, 1, 1)   # a Sunday: GPS week 1930


def _week_start(week_start) -> datetime:
    return instance(week_start, datetime, "week_start")


def _num(x: float) -> str:
    return f"{x:19.12E}"


def _stamp(t: datetime) -> str:
    return f"{t.year:04d} {t.month:02d} {t.day:02d} {t.hour:02d} {t.minute:02d} {t.second:02d}"


def write_nav(path, eph: Ephemerides, n_leap: float = 18.0, week_start: datetime = WEEK_START) -> Path:
    """Write the broadcast sets of ``eph`` as a RINEX 3.04 mixed navigation file.

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
    lines = [f"{3.04:9.2f}{'':11}{'N: GNSS NAV DATA':20}{'M: Mixed':20}RINEX VERSION / TYPE",
             f"{'atomnav':20}{'':20}{'':20}PGM / RUN BY / DATE", f"{int(round(n_leap)):6d}{'':54}LEAP SECONDS",
             f"{'':60}END OF HEADER"]
    for _, e in gps.iterrows():
        toc = week_start + timedelta(seconds=float(e.toc))
        # Toe as seconds of its own GPS week, with that week's number
        since = (pd.Timestamp(week_start) - GPS_EPOCH).total_seconds() + float(e.toe)
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


def _load(path, what: str, **kw):
    path = checked_path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{what}: no RINEX file {path}")
    try:
        import georinex
    except ImportError as e:  # pragma: no cover - the extra is part of the test environment
        raise ImportError("reading RINEX needs the optional extra: pip install 'atomnav[gnss]'") from e
    import warnings
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)      # xarray defaults inside georinex
            return georinex.load(str(path), **kw), georinex.rinexheader(str(path))
    except Exception as e:  # georinex raises many types on malformed input
        raise input_error("path", f"malformed RINEX {what} file {path}: {e}") from None


def _seconds(times, week_start: datetime) -> np.ndarray:
    return (pd.to_datetime(np.asarray(times)) - pd.Timestamp(week_start)).total_seconds().to_numpy()


def _leap_seconds(header: dict, when) -> float:
    """GPS − UTC from the header's LEAP SECONDS line, else from the IERS table at the
    UTC time ``when``."""
    line = str(header.get("LEAP SECONDS", "")).split()
    if line and line[0].lstrip("-").isdigit():
        return float(line[0])
    return float(gps_minus_utc(pd.Timestamp(when)))


def read_nav(path, n_leap: float | None = None, datum: str = "identity", week_start: datetime | None = None) -> Ephemerides:
    """Broadcast ephemerides from RINEX navigation files (GPS and GLONASS records; RINEX 2
    ``.n``/``.g`` or RINEX 3 mixed), read through georinex.

    Parameters
    ----------
    path : str, os.PathLike or list of them
        The navigation file, or several (e.g. a RINEX 2 GPS ``.n`` and GLONASS ``.g``).
        Records of other systems are set aside.
    n_leap : float, optional
        GPS−UTC leap seconds, s; default: the file's LEAP SECONDS line, else the IERS
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
        Klobuchar coefficients of the GPS navigation message (ION ALPHA/BETA or
        GPSA/GPSB) when a file has them, and ``week_start``.

    Raises
    ------
    FileNotFoundError
        When a path is not a file.
    atomnav.InputError
        Naming ``path`` for a malformed file or files without GPS or GLONASS records.
    """
    paths = list(path) if isinstance(path, (list, tuple)) else [path]
    loaded = [_load(p, "nav") for p in paths]
    navs = [(nav, header) for nav, header in loaded if "sv" in nav.coords and len(nav.sv)]
    if not navs:
        raise input_error("path", f"no satellite records in {path}")
    times = pd.to_datetime(np.concatenate([nav.time.values for nav, _ in navs]))
    middle = times.sort_values()[len(times) // 2]
    week = pd.Timestamp(_week_start(week_start)) if week_start is not None else _gps_week_of(middle)
    iono = next((np.asarray(nav.attrs["ionospheric_corr_GPS"], float) for nav, _ in navs
                 if len(nav.attrs.get("ionospheric_corr_GPS", [])) == 8), None)
    leap = _leap_seconds(navs[0][1], middle) if n_leap is None else n_leap
    gps, glo = [], []
    for nav, _ in navs:
        for sv in nav.sv.values:
            d = nav.sel(sv=sv).dropna(dim="time", how="all")
            t = _seconds(d.time.values, week)
            if sv[0] == "G":
                for k in range(len(t)):
                    r = d.isel(time=k)
                    v = {c: float(r[c]) for c in ("sqrtA", "Eccentricity", "M0", "DeltaN", "Omega0", "Io", "omega",
                                                   "OmegaDot", "IDOT", "Cuc", "Cus", "Crc", "Crs", "Cic", "Cis",
                                                   "SVclockBias", "SVclockDrift", "SVclockDriftRate", "TGD", "Toe")}
                    if "health" in r and float(r["health"]) != 0.0:
                        continue
                    # Toe counts from the start of its own GPS week (the record's GPSWeek)
                    toe = v["Toe"] + (float(r["GPSWeek"]) * 604800.0 - (week - GPS_EPOCH).total_seconds()
                                      if "GPSWeek" in r and np.isfinite(float(r["GPSWeek"])) else 0.0)
                    gps.append([int(sv[1:]), toe, v["sqrtA"], v["Eccentricity"], v["M0"], v["DeltaN"], v["Omega0"],
                                v["Io"], v["omega"], v["OmegaDot"], v["IDOT"], v["Cuc"], v["Cus"], v["Crc"], v["Crs"],
                                v["Cic"], v["Cis"], t[k], v["SVclockBias"], v["SVclockDrift"], v["SVclockDriftRate"],
                                v["TGD"]])
            elif sv[0] == "R":
                for k in range(len(t)):
                    r = d.isel(time=k)
                    if "health" in r and float(r["health"]) != 0.0:
                        continue
                    f = {c: float(r[c]) for c in ("X", "Y", "Z", "dX", "dY", "dZ", "dX2", "dY2", "dZ2", "FreqNum",
                                                   "SVclockBias", "SVrelFreqBias")}
                    glo.append([int(sv[1:]), f["FreqNum"], t[k] + 10800.0, f["X"], f["Y"], f["Z"], f["dX"], f["dY"],
                                f["dZ"], f["dX2"], f["dY2"], f["dZ2"], -f["SVclockBias"], f["SVrelFreqBias"]])
    gps_t = pd.DataFrame(gps, columns=GPS_COLUMNS).drop_duplicates(["prn", "toe"])
    glo_t = pd.DataFrame(glo, columns=GLONASS_COLUMNS).drop_duplicates(["slot", "tb"])
    eph = Ephemerides(gps_t, glo_t, leap, datum, ionosphere=iono)
    eph.week_start = week
    return eph


#: Observation codes read, per system, in order of preference (the first present at an
#: epoch is used): the civil L1 code, then the P(Y) code, then other tracking modes; RINEX 2
#: names (C1, P1) and RINEX 3 names.
CODE_PREFERENCE = {"G": ("C1C", "C1", "C1W", "P1", "C1X", "C1P", "C1L", "C1S"),
                   "R": ("C1C", "C1", "C1P", "P1")}
#: Doppler codes read, per system, in order of preference.
DOPPLER_PREFERENCE = {"G": ("D1C", "D1", "D1W", "D1X", "D1P", "D1L", "D1S"), "R": ("D1C", "D1", "D1P")}
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
        when not tracked), ``rate_mps`` (m/s, NaN without Doppler), and the RINEX types
        used, ``code_type`` and ``doppler_type`` (empty when missing).
    header : dict
        ``marker``, ``receiver``, ``version``, ``time_system``, ``interval_s``,
        ``approx_position_m`` (ECEF, 3), ``antenna_delta_hen_m`` (3), ``glonass_channels``
        ({slot: k}).
    set_aside : Series
        Satellite-epochs of other systems (Galileo E, BeiDou C, QZSS J, SBAS S, IRNSS I),
        counted per system letter.
    missing : DataFrame
        Per epoch (``time_s``): GPS/GLONASS satellites ``n_sats``, those without code
        ``n_no_code`` and without Doppler ``n_no_doppler``.
    week_start : Timestamp
        Time 0 of ``time_s`` (GPS time).
    """

    table: pd.DataFrame
    header: dict
    set_aside: pd.Series
    missing: pd.DataFrame
    week_start: pd.Timestamp


def _glonass_channels(header: dict) -> dict:
    """{slot: channel} from the RINEX 3 GLONASS SLOT / FRQ # lines."""
    words = str(header.get("GLONASS SLOT / FRQ #", "")).split()
    out = {}
    for a, b in zip(words, words[1:]):
        if len(a) == 3 and a[0] == "R" and a[1:].isdigit() and b.lstrip("-").isdigit():
            out[int(a[1:])] = int(b)
    return out


def _numbers(header: dict, key: str, n: int) -> list:
    words = str(header.get(key, "")).split()[:n]
    try:
        return [float(w) for w in words] if len(words) == n else [float("nan")] * n
    except ValueError:
        return [float("nan")] * n


def _first(df: pd.DataFrame, system: np.ndarray, preference: dict) -> tuple[np.ndarray, np.ndarray]:
    """Per row, the first finite non-zero value among the system's preferred columns, and
    that column's name ('' when none)."""
    value = np.full(len(df), np.nan)
    name = np.full(len(df), "", dtype=object)
    for sys, codes in preference.items():
        rows = system == sys
        for c in codes:
            if c not in df:
                continue
            x = df[c].to_numpy(float)
            take = rows & np.isnan(value) & np.isfinite(x) & (x != 0.0)
            value[take], name[take] = x[take], c
    return value, name


def read_obs(path, eph: Ephemerides, week_start: datetime | None = None) -> RinexObservations:
    """Code and Doppler observations from a RINEX 2.11, 3 or 4 observation file (plain,
    Hatanaka ``.crx`` or gzip), read through georinex.

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
        The observation table with, per satellite, the first code and Doppler of
        :data:`CODE_PREFERENCE` and :data:`DOPPLER_PREFERENCE` present at each epoch (a
        blank, NaN or 0.0 field is missing), the header facts, the records of other
        systems set aside and counted, and what each epoch was missing.

    Raises
    ------
    FileNotFoundError
        When ``path`` is not a file.
    atomnav.InputError
        Naming ``path`` for a malformed file, a time system other than GPS, or a file
        without any code type atomnav reads.
    """
    instance(eph, Ephemerides, "eph")
    ds, header = _load(path, "obs")
    time_system = str(ds.attrs.get("time_system", "GPS")).strip() or "GPS"
    if time_system not in ("GPS", ""):
        raise input_error("path", f"{path}: time system {time_system!r}; atomnav reads GPS-time observation files")
    codes = sorted({c for v in CODE_PREFERENCE.values() for c in v} & set(ds.data_vars))
    if not codes:
        raise input_error("path", f"{path} has no code type atomnav reads ({sorted(CODE_PREFERENCE['G'])}; found "
                                  f"{sorted(ds.data_vars)})")
    dopplers = sorted({c for v in DOPPLER_PREFERENCE.values() for c in v} & set(ds.data_vars))
    # satellite-epochs of other systems with any observation
    other = np.array([not str(s).startswith(SYSTEMS) for s in ds.sv.values])
    seen = ds.isel(sv=np.flatnonzero(other)).to_array().notnull().any("variable").sum("time")
    set_aside = pd.Series(seen.values, index=[str(s)[0] for s in seen.sv.values]).groupby(level=0).sum()
    set_aside = set_aside[set_aside > 0].rename("satellite_epochs")
    df = ds[codes + dopplers].isel(sv=np.flatnonzero(~other)).to_dataframe().reset_index()
    system = df.sv.str[0].to_numpy()
    code, code_type = _first(df, system, CODE_PREFERENCE)
    rate_hz, doppler_type = _first(df, system, DOPPLER_PREFERENCE)
    keep = np.isfinite(code) | np.isfinite(rate_hz)
    df, system, code, code_type, rate_hz, doppler_type = (x[keep] for x in (df, system, code, code_type, rate_hz,
                                                                               doppler_type))
    week = (pd.Timestamp(_week_start(week_start)) if week_start is not None
            else getattr(eph, "week_start", None) or _gps_week_of(pd.Timestamp(ds.time.values.min())))
    from_header = _glonass_channels(header)
    known = set(eph.satellites)
    sat = df.sv.to_numpy()
    names, row_of = np.unique(sat, return_inverse=True)  # one look-up per satellite, not per row
    per_sat = np.array([(eph.channel(s) if s in known else from_header.get(int(s[1:]), 0)) if s[0] == "R" else 0
                        for s in names], dtype=np.int64)
    channel = per_sat[row_of.reshape(-1)]
    rate = doppler_to_rate(rate_hz, sat, channel)
    table = pd.DataFrame({"time_s": _seconds(df.time.values, week), "sat": sat, "channel": channel, "code_m": code,
                          "rate_mps": rate, "code_type": code_type, "doppler_type": doppler_type})
    table = table.sort_values(["time_s", "sat"]).reset_index(drop=True)
    missing = table.groupby("time_s").agg(n_sats=("sat", "size"), n_no_code=("code_m", lambda x: int(x.isna().sum())),
                                          n_no_doppler=("rate_mps", lambda x: int(x.isna().sum()))).reset_index()
    facts = {"marker": str(header.get("MARKER NAME", "")).strip(),
             "receiver": " ".join(str(header.get("REC # / TYPE / VERS", "")).split()[1:]),
             "version": float(ds.attrs.get("version", np.nan)), "time_system": time_system or "GPS",
             "interval_s": float(ds.attrs.get("interval", np.nan)),
             "approx_position_m": _numbers(header, "APPROX POSITION XYZ", 3),
             "antenna_delta_hen_m": _numbers(header, "ANTENNA: DELTA H/E/N", 3), "glonass_channels": from_header}
    return RinexObservations(table, facts, set_aside, missing, week)
