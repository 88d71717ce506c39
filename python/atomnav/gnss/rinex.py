"""RINEX 3 observation and navigation files through georinex (optional extra
``atomnav[gnss]``; no parser of our own, docs/departures.md#rinex-through-georinex), and a small RINEX 3 writer for
simulated data (tests and exchange).

Time: GPS seconds since the start of the GPS week of ``week_start`` (a datetime in GPS
time); GLONASS navigation epochs are UTC, so t_GLO = UTC − week_start + 10800 s.
"""

from __future__ import annotations

from datetime import datetime, timedelta
from pathlib import Path

import numpy as np
import pandas as pd

from .._validate import input_error, instance, path as checked_path
from .ephemeris import GLONASS_COLUMNS, GPS_COLUMNS, Ephemerides
from .observations import C_LIGHT, _gps_week_start, doppler_to_rate, obs_arrays

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
             f"{'atomnav':20}{'':20}{'':20}PGM / RUN BY / DATE", f"{'':60}END OF HEADER"]
    for _, e in gps.iterrows():
        toc = week_start + timedelta(seconds=float(e.toc))
        vals = [e.af0, e.af1, e.af2, 0.0, e.crs, e.delta_n, e.m0, e.cuc, e.e, e.cus, e.sqrt_a, e.toe, e.cic, e.omega0,
                e.cis, e.i0, e.crc, e.omega, e.omega_dot, e.idot, 0.0, 1930.0, 0.0, 2.0, 0.0, e.tgd, 0.0, e.toe, 4.0, 0.0, 0.0]
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


def _load(path, what: str):
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
            return georinex.load(str(path))
    except Exception as e:  # georinex raises many types on malformed input
        raise input_error("path", f"malformed RINEX {what} file {path}: {e}") from None


def _seconds(times, week_start: datetime) -> np.ndarray:
    return (pd.to_datetime(np.asarray(times)) - pd.Timestamp(week_start)).total_seconds().to_numpy()


def read_nav(path, n_leap: float = 18.0, datum: str = "identity", week_start: datetime = WEEK_START) -> Ephemerides:
    """Broadcast ephemerides from a RINEX 3 navigation file (GPS and GLONASS records),
    read through georinex.

    Parameters
    ----------
    path : str or os.PathLike
        RINEX 3 navigation file.
    n_leap : float, default 18.0
        GPS−UTC leap seconds, s.
    datum : {"identity", "pz90_02_to_wgs84"}, default "identity"
        PZ-90 → WGS-84 transformation of the GLONASS states.
    week_start : datetime.datetime, default 2017-01-01
        Start (a Sunday, GPS time) of the GPS week the times are counted from; GLONASS
        epochs are UTC, t_GLO = UTC − week_start + 10800 s.

    Returns
    -------
    Ephemerides
        The broadcast sets of the file.

    Raises
    ------
    FileNotFoundError
        When ``path`` is not a file.
    atomnav.InputError
        Naming ``path`` for a malformed file or one without satellite records.
    """
    week_start = _week_start(week_start)
    nav = _load(path, "nav")
    if "sv" not in nav.coords or not len(nav.sv):
        raise input_error("path", f"no satellite records in {path}")
    gps, glo = [], []
    for sv in nav.sv.values:
        d = nav.sel(sv=sv).dropna(dim="time", how="all")
        t = _seconds(d.time.values, week_start)
        if sv[0] == "G":
            for k in range(len(t)):
                r = d.isel(time=k)
                v = {c: float(r[c]) for c in ("sqrtA", "Eccentricity", "M0", "DeltaN", "Omega0", "Io", "omega",
                                               "OmegaDot", "IDOT", "Cuc", "Cus", "Crc", "Crs", "Cic", "Cis",
                                               "SVclockBias", "SVclockDrift", "SVclockDriftRate", "TGD", "Toe")}
                gps.append([int(sv[1:]), v["Toe"], v["sqrtA"], v["Eccentricity"], v["M0"], v["DeltaN"], v["Omega0"],
                            v["Io"], v["omega"], v["OmegaDot"], v["IDOT"], v["Cuc"], v["Cus"], v["Crc"], v["Crs"],
                            v["Cic"], v["Cis"], t[k], v["SVclockBias"], v["SVclockDrift"], v["SVclockDriftRate"], v["TGD"]])
        elif sv[0] == "R":
            for k in range(len(t)):
                r = d.isel(time=k)
                f = {c: float(r[c]) for c in ("X", "Y", "Z", "dX", "dY", "dZ", "dX2", "dY2", "dZ2", "FreqNum",
                                               "SVclockBias", "SVrelFreqBias")}
                glo.append([int(sv[1:]), f["FreqNum"], t[k] + 10800.0, f["X"], f["Y"], f["Z"], f["dX"], f["dY"], f["dZ"],
                            f["dX2"], f["dY2"], f["dZ2"], -f["SVclockBias"], f["SVrelFreqBias"]])
    return Ephemerides(pd.DataFrame(gps, columns=GPS_COLUMNS), pd.DataFrame(glo, columns=GLONASS_COLUMNS), n_leap, datum)


def read_obs(path, eph: Ephemerides, week_start: datetime = WEEK_START) -> pd.DataFrame:
    """Observation table from a RINEX 3 observation file with C1C and D1C, read through
    georinex.

    Parameters
    ----------
    path : str or os.PathLike
        RINEX 3 observation file.
    eph : Ephemerides
        Ephemerides giving the GLONASS FDMA channels.
    week_start : datetime.datetime, default 2017-01-01
        Start (a Sunday, GPS time) of the GPS week the times are counted from.

    Returns
    -------
    pandas.DataFrame
        ``time_s`` (GPS s), ``sat``, ``channel``, ``code_m`` (m), ``rate_mps`` (m/s, NaN
        without D1C), GPS and GLONASS only, sorted by time and satellite.

    Raises
    ------
    FileNotFoundError
        When ``path`` is not a file.
    atomnav.InputError
        Naming ``path`` for a malformed file or one without C1C pseudoranges.
    """
    week_start = _week_start(week_start)
    instance(eph, Ephemerides, "eph")
    ds = _load(path, "obs")
    if "C1C" not in ds:
        raise input_error("path", f"{path} has no C1C pseudoranges (found {sorted(ds.data_vars)})")
    df = ds[["C1C", "D1C"] if "D1C" in ds else ["C1C"]].to_dataframe().reset_index().dropna(subset=["C1C"])
    df = df[df.sv.str[0].isin(["G", "R"])]
    sat = df.sv.to_numpy()
    channel = np.array([eph.channel(s) if s[0] == "R" else 0 for s in sat], dtype=np.int64)
    rate = doppler_to_rate(df["D1C"].to_numpy(), sat, channel) if "D1C" in df else np.full(len(df), np.nan)
    out = pd.DataFrame({"time_s": _seconds(df.time.values, week_start), "sat": sat, "channel": channel,
                        "code_m": df["C1C"].to_numpy(), "rate_mps": rate})
    return out.sort_values(["time_s", "sat"]).reset_index(drop=True)
