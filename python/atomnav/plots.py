"""The plots a navigation engineer looks at first, one call each on atomnav's results.

Every function returns a :class:`matplotlib.figure.Figure` (made with
``matplotlib.pyplot``, so ``plt.show()`` and notebooks display it) whose axes carry
their units, a title and a legend. matplotlib (and scipy.stats for the χ² bands) are
imported inside the functions: ``import atomnav`` does not load them.

- :func:`trajectory` — map view (east, north in m from the first point) of any solution
  with ``lat_rad, lon_rad, h_m`` columns, with an optional reference;
- :func:`errors` — NED position, velocity and attitude errors (``Trajectory.errors``)
  with the ±3σ envelope of an aided INS;
- :func:`imu_errors` — accelerometer and gyro bias estimates with ±3σ and the true
  biases when known;
- :func:`consistency` — NIS per measurement and NEES with their two-sided χ² bands
  (Bar-Shalom, Li and Kirubarajan 2001, §5.4);
- :func:`allan` — Allan deviation with its confidence interval and the fitted noise
  terms (IEEE Std 952-1997, Annex C).

Tables are read by column name (extra columns are ignored; a missing one is an
:class:`atomnav.InputError` naming the argument and the column); time is ``time_s`` in
seconds (or timedelta64; a datetime64 column is a ``TypeError``). NaN marks a missing
value: it is left out of the plot and the number of rows left out is given in the
legend; ±inf is an :class:`atomnav.InputError` naming the argument, the column and the
row.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from . import _core, earth, plausibility, units
from ._validate import flag, floats, input_error, instance, integer, locate, positive, probability, renamed, table as read_table
from .filter.aided import AidedResult
from .filter.analysis import chi2_band
from .filter.outages import OutageResult
from .gnss.spp import SppResult
from .imu import BIAS_COLUMNS
from .trajectory import Trajectory

#: Columns of a navigation solution that :func:`trajectory` reads (rad, rad, m).
POSITION_COLUMNS = ["lat_rad", "lon_rad", "h_m"]
#: Columns of :meth:`atomnav.trajectory.Trajectory.errors` that :func:`errors` reads:
#: NED position (m), NED velocity (m/s), ψ (rad), three of each.
ERROR_COLUMNS = list(_core.NAV_ERROR_COLUMNS)
_NED = ("north", "east", "down")
_XYZ = ("x", "y", "z")
#: The state blocks of :data:`ERROR_COLUMNS` in the aided INS's state (the σ columns of
#: :class:`atomnav.filter.aided.AidedResult` are ``sigma_<block>[i]``, i = N, E, D).
_ERROR_BLOCKS = tuple(name for name, _ in _core.STATE_BLOCKS[:3])
_BIAS_BLOCKS = tuple(name for name, _ in _core.STATE_BLOCKS[3:5])


def _sigma_columns(block: str, size: int = 3) -> list[str]:
    """The σ columns of state block ``block`` in an :class:`AidedResult` table."""
    return [f"sigma_{block}[{i}]" for i in range(size)]


def _read(df, names, parameter: str) -> tuple[np.ndarray, np.ndarray]:
    """Columns ``time_s`` and ``names`` of table ``df``: the time (s, finite; timedelta64
    as its seconds, datetime64 a ``TypeError``: the series of one figure share a time axis
    in seconds, which a date in one table cannot join) and the values (N, len(names)), NaN
    where missing; ±inf is an :class:`InputError` naming the column and its row."""
    values = read_table(df, names, parameter, finite=False)
    _no_inf(values, names, parameter)
    if pd.api.types.is_datetime64_any_dtype(df.dtypes.iloc[locate(df, ["time_s"], parameter)[0]]):
        raise TypeError(f"{parameter}: column 'time_s' holds datetimes; give the time in seconds (or as timedelta64), "
                        "e.g. (t - t.iloc[0]).dt.total_seconds(), the same way for every table of the figure")
    return read_table(df, ["time_s"], parameter).ravel(), values


def _no_inf(values: np.ndarray, names, parameter: str) -> None:
    """An :class:`InputError` naming ``parameter``, the column and the first row of an
    infinite value in ``values`` (N, len(names)); NaN is a missing value."""
    bad = np.argwhere(np.isinf(values))
    if bad.size:
        row, col = bad[0]
        raise input_error(parameter, f"column {names[col]!r}: infinite value at index {row} (NaN marks a missing value)", row)


def _missing(count: int, what: str = "row") -> str:
    """Legend suffix for ``count`` missing (NaN) rows or values left out."""
    return f" ({count} {what}{'' if count == 1 else 's'} with NaN left out)" if count else ""


def _pyplot():
    import matplotlib.pyplot as plt

    return plt


# ---- trajectory ---------------------------------------------------------------------

def _positions(x, parameter: str) -> tuple[np.ndarray, int]:
    """Positions (lat rad, lon rad, h m) of a solution table or :class:`Trajectory`
    without the rows that have a NaN, and the number of those rows."""
    df = x.df if isinstance(x, Trajectory) else x
    instance(df, pd.DataFrame, parameter)
    lla = read_table(df, POSITION_COLUMNS, parameter, finite=False)
    _no_inf(lla, POSITION_COLUMNS, parameter)
    keep = ~np.isnan(lla).any(axis=1)
    if not keep.any():
        raise input_error(parameter, f"no row has a position (all {len(lla)} rows have NaN in {POSITION_COLUMNS})")
    return plausibility.lla(np.ascontiguousarray(lla[keep]), parameter), int(np.count_nonzero(~keep))


def _ned(lla: np.ndarray, origin: np.ndarray, ellipsoid: str, parameter: str) -> np.ndarray:
    """NED (m) of ``lla`` from ``origin``, as :func:`atomnav.earth.lla_to_ned` computes
    it but naming the caller's argument in errors (its unit check, which would name
    ``lla``, is :func:`_positions`'s)."""
    with renamed(lla=parameter, origin_lla=parameter):
        return _core.ecef_to_ned_rows(_core.lla_to_ecef_rows(lla, ellipsoid), origin, ellipsoid)


def trajectory(nav, reference=None, *, ellipsoid: str | None = None):
    """Map view of a navigation solution: north against east, in m from its first point.

    Parameters
    ----------
    nav : pandas.DataFrame or atomnav.trajectory.Trajectory
        Any solution with columns ``lat_rad``, ``lon_rad`` (rad) and ``h_m`` (m): the
        output of :func:`atomnav.strapdown.integrate`, ``AidedResult.nav``,
        :attr:`Trajectory.df`, :func:`atomnav.gnss.spp.solve`. Rows with a NaN position
        (an epoch without a solution) are left out and counted in the legend.
    reference : pandas.DataFrame or atomnav.trajectory.Trajectory, optional
        A reference trajectory (same columns), drawn from the same origin.
    ellipsoid : str, optional
        Ellipsoid of the positions, ``"WGS84"`` or ``"PZ90.11"``; by default that of
        ``nav`` when it is a :class:`Trajectory`, else ``"WGS84"``.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: east (m) horizontally, north (m) vertically, equal scales; the solution,
        the reference and the origin (a marker) in the legend.
    """
    lla, missing = _positions(nav, "nav")
    origin = lla[0]
    if ellipsoid is None:
        ellipsoid = nav.ellipsoid if isinstance(nav, Trajectory) else "WGS84"
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 6))
    ned = _ned(lla, origin, ellipsoid, "nav")
    ax.plot(ned[:, 1], ned[:, 0], "-", color="C0", lw=1.2, label="solution" + _missing(missing))
    if reference is not None:
        ref, ref_missing = _positions(reference, "reference")
        ned = _ned(ref, origin, ellipsoid, "reference")
        ax.plot(ned[:, 1], ned[:, 0], "--", color="k", lw=1, label="reference" + _missing(ref_missing))
    ax.plot([0.0], [0.0], "o", color="C3", label="origin (first point)")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"Trajectory from {np.degrees(origin[0]):.6f}° N, {np.degrees(origin[1]):.6f}° E, {origin[2]:.1f} m")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


# ---- errors with ±3σ ----------------------------------------------------------------

def _nav_table(x) -> pd.DataFrame:
    """``x.nav`` of an :class:`AidedResult`, else ``x`` (a table)."""
    return x.nav if isinstance(x, AidedResult) else x


def _envelope(ax, t: np.ndarray, centre, sigma: np.ndarray, label: str) -> None:
    """The lines centre ± 3σ (the second one without a legend entry)."""
    ax.plot(t, centre + 3.0 * sigma, "--", color="C1", lw=0.8, label=label)
    ax.plot(t, centre - 3.0 * sigma, "--", color="C1", lw=0.8, label="_nolegend_")


#: Rows of :func:`errors`: quantity, display unit and its SI factor (ψ in degrees).
_ERROR_ROWS = (("position error", "m", 1.0), ("velocity error", "m/s", 1.0), ("attitude error ψ", "°", units.DEG))


def errors(err, sigma=None):
    """Position, velocity and attitude errors against a reference, with ±3σ envelopes.

    Parameters
    ----------
    err : pandas.DataFrame
        Errors (estimate − truth) as :meth:`atomnav.trajectory.Trajectory.errors` gives
        them: ``time_s`` (s) and :data:`ERROR_COLUMNS` (NED position error in m, NED
        velocity error in m/s, attitude error ψ in rad, navigation frame).
    sigma : atomnav.filter.aided.AidedResult or pandas.DataFrame, optional
        The aided INS's σ: its ``nav`` table (or the result itself) with ``time_s`` and
        ``sigma_position[i]``, ``sigma_velocity[i]``, ``sigma_attitude[i]``, i = 0, 1, 2
        for north, east, down (m, m/s, rad). Drawn as ±3σ at its own time stamps.

    Returns
    -------
    matplotlib.figure.Figure
        A 3 × 3 grid: rows position (m), velocity (m/s), attitude ψ (°); columns north,
        east, down; time (s) on the bottom row.
    """
    instance(err, pd.DataFrame, "err")
    t, e = _read(err, ERROR_COLUMNS, "err")
    if sigma is not None:
        sig_table = _nav_table(sigma)
        instance(sig_table, pd.DataFrame, "sigma")
        ts, s = _read(sig_table, [c for b in _ERROR_BLOCKS for c in _sigma_columns(b)], "sigma")
    plt = _pyplot()
    fig, axes = plt.subplots(3, 3, figsize=(12, 8), sharex=True, layout="constrained")
    for r, (quantity, unit, factor) in enumerate(_ERROR_ROWS):
        for c, axis in enumerate(_NED):
            j = 3 * r + c
            ax = axes[r, c]
            ax.plot(t, e[:, j] / factor, "-", color="C0", lw=1, label="error" + _missing(int(np.isnan(e[:, j]).sum())))
            if sigma is not None:
                _envelope(ax, ts, 0.0, s[:, j] / factor, "±3σ" + _missing(int(np.isnan(s[:, j]).sum())))
            ax.set_ylabel(f"{axis} {quantity} ({unit})")
            ax.set_title(f"{quantity}, {axis}", fontsize=9)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    fig.suptitle("Navigation errors (estimate − reference)" + (" with ±3σ" if sigma is not None else ""))
    return fig


# ---- IMU error estimates ------------------------------------------------------------

#: Rows of :func:`imu_errors`: sensor, estimate columns, σ block, display unit, SI factor.
_BIAS_ROWS = (("accelerometer bias", BIAS_COLUMNS[0], _BIAS_BLOCKS[0], "µg", units.MICRO_G),
              ("gyro bias", BIAS_COLUMNS[1], _BIAS_BLOCKS[1], "°/h", units.DEG_PER_HOUR))


def imu_errors(result, truth=None):
    """Accelerometer and gyro bias estimates of an aided INS with ±3σ, and the true biases.

    Parameters
    ----------
    result : atomnav.filter.aided.AidedResult or pandas.DataFrame
        The result (or its ``nav`` table): ``time_s`` (s), the estimates
        ``accel_bias_{x,y,z}_mps2`` (m/s²) and ``gyro_bias_{x,y,z}_rad_s`` (rad/s), and
        their σ ``sigma_accel_bias[i]``, ``sigma_gyro_bias[i]`` (i = x, y, z).
    truth : pandas.DataFrame, optional
        The true biases in the same columns with ``time_s``, e.g. the output of
        :func:`atomnav.imu.corrupt`.

    Returns
    -------
    matplotlib.figure.Figure
        A 2 × 3 grid: accelerometer biases (µg) and gyro biases (°/h) on the body axes
        x, y, z against time (s); the estimate, estimate ± 3σ and the truth.
    """
    nav = _nav_table(result)
    instance(nav, pd.DataFrame, "result")
    columns = [c for _, est, block, _, _ in _BIAS_ROWS for c in [*est, *_sigma_columns(block)]]
    t, v = _read(nav, columns, "result")
    if truth is not None:
        instance(truth, pd.DataFrame, "truth")
        tt, b = _read(truth, [c for _, est, _, _, _ in _BIAS_ROWS for c in est], "truth")
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True, layout="constrained")
    for r, (sensor, _, _, unit, factor) in enumerate(_BIAS_ROWS):
        est, sig = v[:, 6 * r:6 * r + 3] / factor, v[:, 6 * r + 3:6 * r + 6] / factor
        for c, axis in enumerate(_XYZ):
            ax = axes[r, c]
            ax.plot(t, est[:, c], "-", color="C0", lw=1, label="estimate" + _missing(int(np.isnan(est[:, c]).sum())))
            _envelope(ax, t, est[:, c], sig[:, c], "±3σ" + _missing(int(np.isnan(sig[:, c]).sum())))
            if truth is not None:
                ax.plot(tt, b[:, 3 * r + c] / factor, "-", color="k", lw=1, label="true")
            ax.set_ylabel(f"{axis} {sensor} ({unit})")
            ax.set_title(f"{sensor}, {axis}", fontsize=9)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    fig.suptitle("IMU error estimates with ±3σ")
    return fig


# ---- NIS / NEES ---------------------------------------------------------------------

def _band_panel(ax, t: np.ndarray, x: np.ndarray, dof: np.ndarray, p: float, name: str) -> None:
    """Points ``x`` at ``t`` with the two-sided p band of χ²(dof) (per point) and, in the
    legend, the band values and the share of points inside it."""
    bands = {k: chi2_band(int(k), 1, p) for k in np.unique(dof)}
    lo = np.array([bands[k][0] for k in dof])
    hi = np.array([bands[k][1] for k in dof])
    present = ~np.isnan(x)
    inside = int(np.count_nonzero((x[present] >= lo[present]) & (x[present] <= hi[present])))
    used = int(np.count_nonzero(present))
    ax.plot(t, x, ".", ms=3, color="C0", label=name + _missing(len(x) - used, "value"))
    values = ", ".join(f"χ²({k}) [{a:.3g}, {b:.3g}]" for k, (a, b) in bands.items())
    share = f"{100.0 * inside / used:.1f} % of {used} inside" if used else "no value"
    ax.plot(t, lo, "-", color="C1", lw=0.8, label=f"{100 * p:g} % band {values}: {share}")
    ax.plot(t, hi, "-", color="C1", lw=0.8, label="_nolegend_")
    if used and np.all(x[present] > 0):
        ax.set_yscale("log")
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{name} (dimensionless)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


#: Largest degrees of freedom of a χ² band (that of :func:`atomnav.filter.analysis.chi2_band`).
_MAX_DOF = 2**32


def consistency(nis=None, nees=None, dof=None, *, p: float = 0.95):
    """NIS per measurement and/or NEES against their two-sided χ² bands.

    A consistent filter's normalised innovation squared (NIS) of an m-row measurement is
    χ²(m) distributed, and its normalised estimation error squared (NEES) of n states
    χ²(n) (Bar-Shalom, Li and Kirubarajan 2001, §5.4.2): about a share ``p`` of the points
    should lie inside the band.

    Parameters
    ----------
    nis : atomnav.filter.aided.AidedResult or pandas.DataFrame, optional
        The result (or its ``measurements`` table): ``time_s`` (s), ``nis`` and ``rows``,
        the number of rows of each measurement (its degrees of freedom).
    nees : pandas.DataFrame, optional
        ``time_s`` (s) and ``nees``, e.g. Σ (e_i/σ_i)² over the states of
        :meth:`atomnav.trajectory.Trajectory.errors` and the σ of an aided INS.
    dof : int
        Degrees of freedom of the NEES (the number of states in it); required with
        ``nees``, refused without it.
    p : float
        Probability of the band, in (0, 1).

    Returns
    -------
    matplotlib.figure.Figure
        One panel per quantity given (NIS above NEES): the values against time (s), the
        band limits as lines, and in the legend the band values and the share of points
        inside (NaN values, e.g. of a measurement whose rows were all missing, are left
        out of the share and counted).
    """
    if nis is None and nees is None:
        raise input_error("nis", "give nis, nees or both")
    if nees is None and dof is not None:
        raise input_error("dof", "is the NEES's degrees of freedom, and no nees was given (the NIS's are its rows column)")
    p = probability(p, "p")
    panels = []
    if nis is not None:
        meas = nis.measurements if isinstance(nis, AidedResult) else nis
        instance(meas, pd.DataFrame, "nis")
        t, v = _read(meas, ["nis", "rows"], "nis")
        rows = v[:, 1]
        bad = np.flatnonzero(~((rows >= 1) & (rows <= _MAX_DOF) & (rows == np.round(rows))))
        if bad.size:
            raise input_error("nis", f"column 'rows': {rows[bad[0]]} at index {bad[0]} is not a row count in [1, {_MAX_DOF}]", bad[0])
        panels.append((t, v[:, 0], rows.astype(np.int64), "NIS"))
    if nees is not None:
        instance(nees, pd.DataFrame, "nees")
        if dof is None:
            raise input_error("dof", "the NEES needs its degrees of freedom (the number of states in it)")
        k = integer(dof, "dof", 1, _MAX_DOF)
        t, v = _read(nees, ["nees"], "nees")
        panels.append((t, v[:, 0], np.full(len(t), k, dtype=np.int64), "NEES"))
    plt = _pyplot()
    fig, axes = plt.subplots(len(panels), 1, figsize=(9, 3.5 * len(panels)), squeeze=False, layout="constrained")
    for ax, (t, x, k, name) in zip(axes[:, 0], panels):
        _band_panel(ax, t, x, k, p, name)
        ax.set_title(f"{name} with its two-sided {100 * p:g} % χ² band")
    return fig


# ---- Allan deviation ----------------------------------------------------------------

#: Display of :func:`allan` per sensor (``angular=True``: gyro, else accelerometer): the
#: rate unit and its SI factor, then for each term of :data:`atomnav.noise.allan.TERMS`
#: its name, unit and SI factor (IEEE Std 952-1997 names; accelerometer terms as in
#: IEEE Std 1293-2018).
_ALLAN_DISPLAY = {
    True: (("°/h", units.DEG_PER_HOUR),
           (("quantization", "″", units.ARCSEC), ("ARW", "°/√h", units.DEG_PER_SQRT_HOUR),
            ("bias instability", "°/h", units.DEG_PER_HOUR), ("RRW", "°/h/√h", units.DEG_PER_HOUR / np.sqrt(units.HOUR)),
            ("rate ramp", "°/h²", units.DEG_PER_HOUR / units.HOUR))),
    False: (("µg", units.MICRO_G),
            (("quantization", "m/s", 1.0), ("VRW", "µg/√Hz", units.MICRO_G_PER_SQRT_HZ),
             ("bias instability", "µg", units.MICRO_G), ("acceleration random walk", "µg/√h", units.MICRO_G / np.sqrt(units.HOUR)),
             ("ramp", "µg/h", units.MICRO_G / units.HOUR))),
}


def allan(table, fit=None, *, unit: float = 1.0, angular: bool = True):
    """Allan deviation of a sensor log with its confidence interval and the fitted terms.

    Parameters
    ----------
    table : pandas.DataFrame
        An :func:`atomnav.noise.allan.allan_variance` table: ``tau_s`` (s), ``dev`` and
        its confidence interval ``dev_lo``, ``dev_hi`` (the rate unit of the data). Rows
        with NaN are left out and counted in the legend.
    fit : atomnav.noise.allan.AllanFit, optional
        The five-term fit (:func:`atomnav.noise.allan.fit_allan`) of the same data: each
        term with a non-zero coefficient is drawn as a line, its value and unit in the
        legend (e.g. "ARW 0.12 °/√h"), and the sum of the terms as a line.
    unit : float
        SI factor of the data's rate unit (multiply to get rad/s or m/s²), e.g.
        ``atomnav.units.DEG_PER_HOUR`` for a gyro log in °/h; 1.0 for SI data.
    angular : bool
        True for a gyro (shown in °/h; quantization in ″, ARW in °/√h, bias instability in
        °/h, RRW in °/h/√h, rate ramp in °/h²), False for an accelerometer (µg;
        quantization in m/s, VRW in µg/√Hz, bias instability in µg, acceleration random
        walk in µg/√h, ramp in µg/h).

    Returns
    -------
    matplotlib.figure.Figure
        Log–log axes: τ (s) against the Allan deviation in the display unit.
    """
    from .noise.allan import TERMS, AllanFit

    instance(table, pd.DataFrame, "table")
    angular = flag(angular, "angular")
    scale = positive(unit, "unit")
    if fit is not None:
        instance(fit, AllanFit, "fit")
    (rate_unit, rate_factor), terms = _ALLAN_DISPLAY[bool(angular)]
    columns = ["tau_s", "dev", "dev_lo", "dev_hi"]
    d = read_table(table, columns, "table", finite=False)
    _no_inf(d, columns, "table")
    keep = ~np.isnan(d).any(axis=1)
    tau, dev, lo, hi = (d[keep] * [1.0, *[scale / rate_factor] * 3]).T
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 5))
    _allan_points(ax, tau, dev, lo, hi, color="k", capsize=2, label="Allan deviation" + _missing(int(np.count_nonzero(~keep))))
    if fit is not None and tau.size:
        grid = np.geomspace(tau.min(), tau.max(), 100)
        for k, (name, (label, term_unit, term_factor)) in enumerate(zip(TERMS, terms)):
            a = fit.coeffs[k]
            if a > 0:
                value = getattr(fit, name) * scale / term_factor
                ax.plot(grid, np.sqrt(a * grid ** (k - 2)) * scale / rate_factor, ":", lw=1,
                        label=f"{label} {value:.3g} {term_unit}")
        _allan_fit(ax, fit, grid, scale / rate_factor, color="C3", lw=1.2, label="five-term fit")
    _allan_axes(ax, rate_unit)
    ax.set_title(f"Allan deviation of the {'gyro' if angular else 'accelerometer'} log")
    return fig


def _allan_points(ax, tau, dev, lo, hi, **style) -> None:
    """Allan deviation points ``dev`` at ``tau`` with their confidence interval [lo, hi]
    as error bars (also drawn by :func:`atomnav.noise.report.plot_allan`)."""
    ax.errorbar(tau, dev, yerr=[dev - lo, hi - dev], fmt="o", ms=4, **style)


def _allan_fit(ax, fit, tau, scale: float, **style) -> None:
    """The deviation √σ²(τ) of a five-term fit at ``tau`` times ``scale`` (a negative sum
    drawn as 0)."""
    ax.plot(tau, np.sqrt(np.maximum(fit.curve(tau), 0.0)) * scale, "-", **style)


def _allan_axes(ax, unit: str) -> None:
    """Log–log axes of an Allan plot, τ in s and the deviation in ``unit``, with a legend."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("averaging time τ (s)")
    ax.set_ylabel(f"Allan deviation ({unit})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


# ---- GNSS outages ------------------------------------------------------------------

def outages(result):
    """GNSS outages bridged by the INS: the 3-D position error and 3σ of the forward filter
    and of the smoother at every withheld fix, against time, the windows shaded.

    Parameters
    ----------
    result : atomnav.filter.outages.OutageResult
        The result of :func:`atomnav.filter.outages.outage_analysis`.

    Returns
    -------
    matplotlib.figure.Figure
        One axis: time (s) against the 3-D error (m), solid with dots, and 3σ (m), dashed,
        per solution; the outage windows shaded grey.
    """
    instance(result, OutageResult, "result")
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(10, 4), layout="constrained")
    for k, (start, end) in enumerate(result.windows):
        ax.axvspan(start, end, color="0.9", label="GNSS withheld" if k == 0 else "_nolegend_")
    for i, (solution, rows) in enumerate(result.errors.groupby("solution", sort=False)):
        for k, (_, w) in enumerate(rows.groupby("window")):
            first = k == 0
            ax.plot(w["time_s"], w["error_m"], "-o", ms=2, color=f"C{i}", label=f"{solution} error" if first else "_nolegend_")
            ax.plot(w["time_s"], 3.0 * w["sigma_m"], "--", lw=0.8, color=f"C{i}", label=f"{solution} 3σ" if first else "_nolegend_")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("3-D position error (m)")
    ax.set_title("Drift in the GNSS outages, against the withheld fixes")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def spp(result, reference=None):
    """Single-point positioning at a glance: the satellites' sky tracks, their post-fit
    residuals, and (with a reference position) the east/north/up error with the DOP.

    Parameters
    ----------
    result : atomnav.gnss.SppResult
        The result of :func:`atomnav.gnss.solve`.
    reference : array_like (3,), optional
        The antenna's true ECEF position, m (a station's published coordinate plus its
        antenna height).

    Returns
    -------
    matplotlib.figure.Figure
        A polar sky plot (azimuth from north, clockwise; elevation 90° at the centre) with
        used satellites as dots and left-out ones as crosses; the count of left-out
        satellite-epochs per reason; the residuals (m) of the used satellites against time;
        and, with ``reference``, the E/N/U error (m) against time with
        PDOP on a second axis.

    Raises
    ------
    atomnav.InputError
        Naming ``reference`` when it is not a finite ECEF position.
    """
    instance(result, SppResult, "result")
    if reference is not None:
        reference = floats(reference, "reference").reshape(-1)
        if reference.shape != (3,) or np.linalg.norm(reference) < 6.0e6:
            raise input_error("reference", "expected an ECEF position (x, y, z) in m near the Earth's surface")
    plt = _pyplot()
    layout = [["sky", "why"], ["res", "res"]] + ([["enu", "enu"]] if reference is not None else [])
    fig, axes = plt.subplot_mosaic(layout, figsize=(8.5, 2.6 * len(layout)), layout="constrained",
                                   per_subplot_kw={"sky": {"projection": "polar"}})
    sky = axes["sky"]
    sky.set_theta_zero_location("N")
    sky.set_theta_direction(-1)
    sats = result.satellites
    seen = sats[np.isfinite(sats["elevation_rad"])]
    for i, (name, s) in enumerate(seen.groupby("sat")):
        used = s[s["used"]]
        sky.plot(used["azimuth_rad"], 90.0 - np.degrees(used["elevation_rad"]), ".", ms=2, color=f"C{i % 10}")
        out = s[~s["used"]]
        sky.plot(out["azimuth_rad"], 90.0 - np.degrees(out["elevation_rad"]), "x", ms=3, color=f"C{i % 10}")
        sky.annotate(name, (s["azimuth_rad"].iloc[-1], 90.0 - np.degrees(s["elevation_rad"].iloc[-1])), fontsize=6)
    sky.set_rlim(0.0, 90.0)
    sky.set_yticks([0, 30, 60, 90], ["90°", "60°", "30°", "0°"])
    sky.set_title("Sky tracks (× left out)", fontsize=9)
    counts = axes["why"]
    reasons = result.exclusions()
    counts.barh(reasons.index, reasons.to_numpy(), color="C3")
    counts.set_xlabel("satellite-epochs left out")
    counts.set_title(f"{int(sats['used'].sum())} satellite-epochs used", fontsize=9)
    res = axes["res"]
    for i, (name, s) in enumerate(seen.groupby("sat")):
        used = s[s["used"]]
        res.plot(used["time_s"], used["residual_m"], "-", lw=0.8, color=f"C{i % 10}", label=name if len(used) else "_nolegend_")
    res.set_xlabel("time (s)")
    res.set_ylabel("post-fit residual of used satellites (m)")
    res.grid(True, alpha=0.3)
    res.legend(fontsize=6, ncol=8)
    if reference is not None:
        e = result.epochs
        lla = earth.ecef_to_lla(reference)
        enu = (earth.dcm_ned_to_ecef(lla[0], lla[1]).T @ (e[["x_m", "y_m", "z_m"]].to_numpy() - reference).T).T
        ax = axes["enu"]
        for k, (label, v) in enumerate((("east", enu[:, 1]), ("north", enu[:, 0]), ("up", -enu[:, 2]))):
            ax.plot(e["time_s"], v, lw=0.9, color=f"C{k}", label=label)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("position error (m)")
        ax.grid(True, alpha=0.3)
        dop = ax.twinx()
        dop.plot(e["time_s"], e["pdop"], "k:", lw=0.8, label="PDOP")
        dop.set_ylabel("PDOP")
        ax.legend(loc="upper left", fontsize=8)
        dop.legend(loc="upper right", fontsize=8)
    return fig
