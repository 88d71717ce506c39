"""GNSS outages on a recorded or simulated run: withhold the position fixes over chosen
windows, run the aided INS (forward filter and Rauch–Tung–Striebel smoother, Rauch, Tung &
Striebel 1965) on the rest, and score the solution against the withheld fixes — how far
the INS drifts while it bridges each gap, and what σ it states at the end of it.

>>> windows = outage_windows(fixes.time, length=15.0, first=25.0)          # doctest: +SKIP
>>> out = outage_analysis(setup, fixes, (time, gyro, accel), windows)      # doctest: +SKIP
>>> print(out.table)                     # per window: forward and smoothed, max and end error
>>> atomnav.plots.outages(out)           # error and 3σ against time, the windows shaded
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import earth, rotation
from .._validate import as_floats, finite_scalar, input_error, instance, positive, renamed, table
from .aided import AidedResult, InsSetup
from .sources import PositionFixes, _Fixes, aided_ins

#: Columns of :attr:`OutageResult.table`.
TABLE_COLUMNS = ("window", "start_s", "end_s", "solution", "fixes", "max_error_m", "end_error_m", "end_sigma_m")
#: Columns of :attr:`OutageResult.errors`.
ERROR_COLUMNS = ("time_s", "window", "solution", "error_n_m", "error_e_m", "error_d_m", "error_m", "sigma_m")
_SIGMA_GROUPS = (tuple(f"sigma_position[{i}]" for i in range(3)),  # a solution's position σ (m) or variances (m²)
                 ("cov_nn_m2", "cov_ee_m2", "cov_dd_m2"))
_POSITION = ("time_s", "lat_rad", "lon_rad", "h_m")
_QUATERNION = ("qw", "qx", "qy", "qz")


@dataclass(frozen=True)
class OutageResult:
    """What :func:`outage_analysis` found.

    Attributes
    ----------
    windows : ndarray (K, 2)
        The outage windows [start, end), s, on the IMU clock.
    table : DataFrame
        One row per window and solution (``"forward"``, ``"smoothed"``): the window's
        number, start and end (s), the number of withheld fixes scored, the largest and the
        end-of-window 3-D error (m) against them, and the solution's 3-D position σ (m,
        √(σ_N² + σ_E² + σ_D²)) at the last scored fix.
    errors : DataFrame
        One row per scored fix and solution: time (s), window, solution, NED error and its
        3-D norm (m), and the 3-D σ (m), for plots (:func:`atomnav.plots.outages`).
    result : AidedResult
        The aided-INS run without the withheld fixes (its ``smoothed`` holds the smoother).
    """

    windows: np.ndarray
    table: pd.DataFrame
    errors: pd.DataFrame
    result: AidedResult


def outage_windows(time, *, length: float, first: float, spacing: float | None = None) -> np.ndarray:
    """Outage windows over a fix record: ``length`` s each, the first starting ``first`` s
    after the first fix, then one every ``spacing`` s (start to start) while a whole window
    still ends before the last fix.

    Parameters
    ----------
    time : array_like (M,)
        Times of the fixes, s.
    length : float
        Length of each window, s.
    first : float
        Start of the first window after the first fix, s.
    spacing : float, optional
        Start-to-start distance between windows, s (≥ ``length``); default: one window.

    Returns
    -------
    ndarray (K, 2)
        [start, end) of each window, s.

    Raises
    ------
    atomnav.InputError
        Naming ``length``, ``first`` or ``spacing`` when no whole window fits in the record
        or windows would overlap.
    """
    t = as_floats(time, "time")
    if t.ndim != 1 or len(t) < 2 or not np.all(np.isfinite(t[[0, -1]])):
        raise input_error("time", f"expected the (M,) finite times of at least two fixes, got shape {t.shape}")
    length, first = positive(length, "length"), finite_scalar(first, "first")
    if first < 0:
        raise input_error("first", f"must be >= 0 s after the first fix, got {first}")
    start = t[0] + first
    if spacing is None:
        starts = np.array([start])
    else:
        spacing = positive(spacing, "spacing")
        if spacing < length:
            raise input_error("spacing", f"{spacing} s is shorter than the window length {length} s: windows would overlap")
        starts = start + spacing * np.arange(int(np.floor((t[-1] - length - start) / spacing)) + 1)
    windows = np.column_stack([starts, starts + length])
    if not len(windows) or windows[-1, 1] > t[-1]:
        raise input_error("length" if spacing is None else "first",
                          f"a {length} s window from {first} s after the first fix ends after the last fix "
                          f"({t[-1] - t[0]:g} s after the first)")
    return windows


def outage_analysis(setup: InsSetup, fixes: PositionFixes, imu, windows, *, withhold=(), sources=(),
                    reference: PositionFixes | None = None, progress: bool = True) -> OutageResult:
    """Withhold ``fixes`` over ``windows``, run the aided INS and its smoother on the rest,
    and score both against the withheld fixes.

    Parameters
    ----------
    setup : InsSetup
        The INS; smoothing is switched on for this run whatever ``setup.smooth`` says.
    fixes : PositionFixes
        The GNSS positions (at the antenna: their lever arm, if any, applies).
    imu : tuple (time, gyro, accel)
        The IMU record as :meth:`AidedIns.run` takes it: time (N,) s, gyro and accel (N, 3)
        of ``setup.kind``.
    windows : array_like (K, 2)
        Outage windows [start, end), s on the IMU clock (a fix stamped t is at t plus its
        ``time_offset``), in time order and not overlapping (e.g. from
        :func:`outage_windows`).
    withhold : sequence of PositionFixes or VelocityFixes, optional
        Other fixes of the same receiver, withheld over the windows too (its velocities).
    sources : sequence of sources, optional
        Other measurement sources kept throughout (zero-velocity updates, constraints).
    reference : PositionFixes, optional
        The positions to score against (e.g. only the fixed-ambiguity epochs); default: the
        withheld fixes themselves.
    progress : bool
        Show a progress bar over the IMU record.

    Returns
    -------
    OutageResult
        Per window and solution, the largest and end-of-window 3-D error (m) and the 3-D σ
        (m) at the window's end; the errors at every scored fix; the run.

    Raises
    ------
    atomnav.InputError
        Naming ``windows`` and its row for a window outside the fixes, overlapping the one
        before, or holding no fix to score.
    TypeError
        For a ``setup`` that is no :class:`InsSetup` or ``fixes`` that are no
        :class:`PositionFixes`.
    """
    instance(setup, InsSetup, "setup")
    instance(fixes, PositionFixes, "fixes")
    for k, other in enumerate(withhold):
        if not isinstance(other, _Fixes):
            raise TypeError(f"withhold: item {k} is a {type(other).__name__}, not PositionFixes or VelocityFixes")
    scored = fixes if reference is None else instance(reference, PositionFixes, "reference")
    w = _windows(windows, fixes.time + getattr(fixes, "time_offset", 0.0))
    smoothing = InsSetup.from_dict({**setup.to_dict(), "smooth": True})
    kept = [f.select(~_inside(f.time + getattr(f, "time_offset", 0.0), w)) for f in (fixes, *withhold)]
    result = aided_ins(smoothing, [*kept, *sources]).run(*imu, progress=progress)
    scores = [score_outages(nav, scored, w, solution=name) for name, nav in (("forward", result.nav),
                                                                            ("smoothed", result.smoothed.nav))]
    return OutageResult(w, pd.concat([t for t, _ in scores], ignore_index=True),
                        pd.concat([e for _, e in scores], ignore_index=True), result)


def score_outages(nav: pd.DataFrame, reference: PositionFixes, windows, *, solution: str = "solution",
                  lever_arm=None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Score any navigation solution against reference positions inside outage windows:
    atomnav's (``AidedResult.nav``) or another program's (e.g. an RTKLIB-format output
    read by :func:`atomnav.gnss.read_pos`, whose ``data`` has the same position columns).

    Parameters
    ----------
    nav : DataFrame
        The solution: ``time_s`` (s, increasing), ``lat_rad``, ``lon_rad``, ``h_m`` and,
        for a lever arm, ``qw, qx, qy, qz``; its 3-D σ is read from ``sigma_position[i]``
        (m) or ``cov_nn_m2, cov_ee_m2, cov_dd_m2`` (m²) when it has them.
    reference : PositionFixes
        The positions scored against; its ``lever_arm`` (if any) places the solution's
        point at the reference's antenna, and its ``time_offset`` (if any) puts its stamps
        on the solution's (IMU) clock.
    windows : array_like (K, 2)
        Outage windows [start, end), s.
    solution : str
        The name of the solution in the tables.
    lever_arm : array_like (3,), optional
        Antenna position from the solution's point in the body frame, m (default: the
        reference's own lever arm, else none).

    Returns
    -------
    table : DataFrame
        :data:`TABLE_COLUMNS`, one row per window (``end_sigma_m`` NaN-free: the column is
        left out for a solution without σ).
    errors : DataFrame
        :data:`ERROR_COLUMNS` at every scored reference position.

    Raises
    ------
    atomnav.InputError
        Naming ``windows`` and its row for a window holding no reference position, or
        ``nav`` for a solution that does not cover a window, a missing, duplicated or
        ambiguous column (``qw, qx, qy, qz`` are needed with a lever arm) or a latitude
        beyond ±π/2.
    TypeError
        Naming ``nav`` for a column that holds no numbers, or a ``time_s`` of
        datetimes (it is seconds on the IMU clock).
    """
    instance(reference, PositionFixes, "reference")
    ref_time = reference.time + getattr(reference, "time_offset", 0.0)  # on the IMU clock
    w = _windows(windows, ref_time)
    lever = getattr(reference, "lever_arm", None) if lever_arm is None else as_floats(lever_arm, "lever_arm")
    nav = _solution(nav, lever is not None and np.any(lever))
    sigma_of = _sigma_source(nav)
    rows, errors = [], []
    for k, (start, end) in enumerate(w):
        pick = (ref_time >= start) & (ref_time < end)
        if not pick.any():
            raise input_error("windows", f"window {k} [{start:g}, {end:g}) s holds no fix of the reference to score", k)
        t = ref_time[pick]
        if t[0] < nav["time_s"].iloc[0] or t[-1] > nav["time_s"].iloc[-1]:
            raise input_error("nav", f"the solution ({nav['time_s'].iloc[0]:g} to {nav['time_s'].iloc[-1]:g} s) does not "
                              f"cover window {k} [{start:g}, {end:g}) s")
        with renamed(lla="nav"):  # the solution's positions, the reference's being checked already
            err = _errors(nav, t, reference.value[pick], lever)
        norm = np.linalg.norm(err, axis=1)
        frame = {"time_s": t, "window": k, "solution": solution, "error_n_m": err[:, 0], "error_e_m": err[:, 1],
                 "error_d_m": err[:, 2], "error_m": norm}
        row = {"window": k, "start_s": start, "end_s": end, "solution": solution, "fixes": len(t),
               "max_error_m": norm.max(), "end_error_m": norm[-1]}
        if sigma_of is not None:
            frame["sigma_m"] = sigma_of(t)
            row["end_sigma_m"] = frame["sigma_m"][-1]
        rows.append(row)
        errors.append(pd.DataFrame(frame))
    return pd.DataFrame(rows), pd.concat(errors, ignore_index=True)


def _solution(nav, attitude: bool) -> pd.DataFrame:
    """The columns of the solution ``nav`` that the score reads, by name, as floats: time
    in seconds, position, the attitude when ``attitude`` (a lever arm) and σ when it has
    them (extra columns ignored; a missing, duplicated or non-number column, or datetimes,
    name ``nav``)."""
    instance(nav, pd.DataFrame, "nav")
    groups = [_QUATERNION] if attitude else []
    columns = set(map(str, nav.columns))
    for g in _SIGMA_GROUPS:
        if columns & set(g) and not set(g) <= columns:
            raise input_error("nav", f"has {sorted(columns & set(g))} but not {sorted(set(g) - columns)}: "
                              "give every axis's σ or none")
    groups += [g for g in _SIGMA_GROUPS if set(g) <= columns][:1]
    names = [*_POSITION, *(c for g in groups for c in g)]
    return pd.DataFrame(table(nav, names, "nav", epoch=None, finite=False), columns=names)


def _sigma_source(nav: pd.DataFrame):
    """A function of time giving the solution's 3-D position σ (m), or None without σ."""
    nt = nav["time_s"].to_numpy()
    for cols, power in zip(_SIGMA_GROUPS, (2, 1)):
        if set(cols) <= set(nav.columns):
            return lambda t, cols=cols, power=power: np.sqrt(sum(np.interp(t, nt, nav[c]) ** power for c in cols))
    return None


def _windows(windows, fix_time: np.ndarray) -> np.ndarray:
    w = as_floats(windows, "windows")
    if w.ndim != 2 or w.shape[1] != 2 or not len(w):
        raise input_error("windows", f"expected shape (K, 2) of [start, end) in s, got {w.shape}")
    for k, (start, end) in enumerate(w):
        if not (np.isfinite(start) and np.isfinite(end) and start < end):
            raise input_error("windows", f"window {k} [{start}, {end}) s is not an interval", k)
        if start < fix_time[0] or end > fix_time[-1]:
            raise input_error("windows", f"window {k} [{start:g}, {end:g}) s lies outside the fixes "
                              f"({fix_time[0]:g} to {fix_time[-1]:g} s)", k)
        if k and start < w[k - 1, 1]:
            raise input_error("windows", f"window {k} starts at {start:g} s, before window {k - 1} ends", k)
    return w


def _inside(t: np.ndarray, windows: np.ndarray) -> np.ndarray:
    return np.any((t[:, None] >= windows[:, 0]) & (t[:, None] < windows[:, 1]), axis=1)


def _errors(nav: pd.DataFrame, t: np.ndarray, lla_ref: np.ndarray, lever_arm) -> np.ndarray:
    """NED error (m) of the solution ``nav`` (interpolated to ``t``, at the point
    ``lever_arm`` from the IMU in the body frame) against the positions ``lla_ref``."""
    nt = nav["time_s"].to_numpy()
    lla = np.column_stack([np.interp(t, nt, nav[c]) for c in ("lat_rad", "lon_rad", "h_m")])
    ecef = earth.lla_to_ecef(lla)
    if lever_arm is not None and np.any(lever_arm):
        q = np.column_stack([np.interp(t, nt, nav[c]) for c in _QUATERNION])
        c_bn = rotation.dcm_from_quat(q / np.linalg.norm(q, axis=1, keepdims=True))
        c_ne = np.stack([earth.dcm_ned_to_ecef(la, lo) for la, lo in lla[:, :2]])
        ecef = ecef + np.einsum("kij,kjl,l->ki", c_ne, c_bn, np.asarray(lever_arm, float))
    d = ecef - earth.lla_to_ecef(lla_ref)
    c_ne_ref = np.stack([earth.dcm_ned_to_ecef(la, lo) for la, lo in lla_ref[:, :2]])
    return np.einsum("kji,kj->ki", c_ne_ref, d)
