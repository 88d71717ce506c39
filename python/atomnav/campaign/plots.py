"""The figures of a campaign: an error metric against a parameter (Monte Carlo with its
uncertainty beside the covariance prediction), an error map over two parameters with
the requirement's contour, and the run time and throughput of the workers.

Each function returns a :class:`matplotlib.figure.Figure` (made with
``matplotlib.pyplot``, as :mod:`atomnav.plots`; matplotlib is imported inside the
functions). Tables are read by column name: :func:`atomnav.campaign.sweep.sweep` and
:func:`~atomnav.campaign.sweep.compare` reports for the first two, the run times of
:func:`atomnav.campaign.timing` for :func:`throughput`.
A missing column is an :class:`atomnav.InputError` naming the argument and the column.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .._validate import flag, input_error, instance, locate, positive, table as read_table
from ..plots import _pyplot
from .sweep import COV, MC, MC_SE


def _at(report: pd.DataFrame) -> str:
    """Title suffix naming the checkpoint time(s) of a report (its ``time_s``, s)."""
    times = np.unique(read_table(report, ["time_s"], "report", epoch=None))
    return f" at t = {times[0]:g} s" if times.size == 1 else f" at t = {times.min():g} … {times.max():g} s"


def error_vs_parameter(report, parameter: str, metric: str, *, monte_carlo: bool = True, by: str | None = None,
                       z: float = 1.96):
    """An error metric against one parameter: the covariance prediction as a line and the
    Monte-Carlo RMS with error bars.

    Parameters
    ----------
    report : pandas.DataFrame
        A :func:`atomnav.campaign.sweep.sweep` or :func:`~atomnav.campaign.sweep.compare`
        report: ``time_s`` (s, the checkpoint, named in the title), the ``parameter``
        column, ``<metric>_cov`` (drawn as a line) and, with ``monte_carlo``,
        ``<metric>_mc`` and ``<metric>_mc_se`` (drawn as points with error bars).
    parameter : str
        The numeric parameter on the horizontal axis.
    metric : str
        The metric, e.g. ``"pos_error_m"`` (its unit is in its name).
    monte_carlo : bool
        Draw the Monte-Carlo RMS; False for a covariance sweep, which has none.
    by : str, optional
        A further parameter column: one series per value of it. Without it, each value
        of ``parameter`` must appear once.
    z : float
        Half-width of the error bars in standard errors of the Monte-Carlo RMS (1.96:
        a 95 % interval of a normal estimate).

    Returns
    -------
    matplotlib.figure.Figure
        One axes: ``parameter`` horizontally, the metric's RMS vertically; per series the
        covariance prediction (solid line, label "covariance") and the Monte-Carlo RMS
        (points with ± z standard errors, label "Monte Carlo").

    Raises
    ------
    atomnav.InputError
        Naming ``report`` (a missing column, a repeated ``parameter`` value within a
        series) or ``z``.
    """
    instance(report, pd.DataFrame, "report")
    instance(parameter, str, "parameter")
    instance(metric, str, "metric")
    monte_carlo = flag(monte_carlo, "monte_carlo")
    z = positive(z, "z")
    names = [parameter, metric + COV] + [metric + MC, metric + MC_SE] * monte_carlo
    if monte_carlo and metric + MC not in report.columns and metric + COV in report.columns:
        raise input_error("report", f"has no Monte Carlo column {metric + MC!r}: a covariance sweep? give monte_carlo=False")
    values = pd.DataFrame(read_table(report, names, "report"), columns=names)
    if by is not None:
        locate(report, [by], "report")
        groups = list(values.groupby(report[by].to_numpy(), sort=True))
    else:
        groups = [(None, values)]
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
    for i, (key, g) in enumerate(groups):
        g = g.sort_values(parameter)
        x = g[parameter].to_numpy()
        repeated = np.flatnonzero(np.diff(x) == 0)
        if repeated.size:
            raise input_error("report", f"{parameter} = {x[repeated[0]]} appears more than once"
                                        f"{'' if by is None else f' for {by} = {key}'}; select the rows or give by=")
        suffix = "" if by is None else f", {by} = {key}"
        ax.plot(x, g[metric + COV].to_numpy(), "-", color=f"C{i}", lw=1.2, label="covariance" + suffix)
        if monte_carlo:
            ax.errorbar(x, g[metric + MC].to_numpy(), yerr=z * g[metric + MC_SE].to_numpy(), fmt="o", ms=4, capsize=3,
                        color=f"C{i}", label=f"Monte Carlo (± {z:g} SE){suffix}")
    ax.set_xlabel(parameter)
    ax.set_ylabel(f"RMS {metric}")
    ax.set_title(f"RMS {metric} against {parameter}{_at(report)}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def error_map(report, x: str, y: str, column: str, *, target: float | None = None):
    """A heat map of an error column over two parameters, with the requirement's contour.

    Parameters
    ----------
    report : pandas.DataFrame
        A report over the full grid of ``x`` × ``y`` (each pair once) with ``time_s``
        (s, the checkpoint, named in the title), e.g. a covariance
        :func:`atomnav.campaign.sweep.sweep`.
    x, y : str
        The numeric parameters on the horizontal and vertical axes.
    column : str
        The column drawn, e.g. ``"pos_error_m_cov"`` or ``"pos_error_m_mc"``.
    target : float, optional
        The requirement (largest allowed value, in the column's unit): drawn as the
        contour where the column equals it (linear interpolation between grid points).

    Returns
    -------
    matplotlib.figure.Figure
        One axes with the grid cells coloured by ``column`` (a colour bar), and the
        contour at ``target`` (label "requirement …").

    Raises
    ------
    atomnav.InputError
        Naming ``report`` (a missing column, or rows that are not the full grid, each
        pair once, of at least 2 × 2 values) or ``target``.
    """
    instance(report, pd.DataFrame, "report")
    for name, value in (("x", x), ("y", y), ("column", column)):
        instance(value, str, name)
    if target is not None:
        target = positive(target, "target")
    d = read_table(report, [x, y, column], "report")
    xs, ys = np.unique(d[:, 0]), np.unique(d[:, 1])
    pairs = len(np.unique(d[:, :2], axis=0))
    if len(xs) < 2 or len(ys) < 2 or not len(d) == pairs == len(xs) * len(ys):
        raise input_error("report", f"expected the full grid of {x} × {y}, each pair once and at least 2 × 2, got {len(d)} "
                                    f"rows over {len(xs)} × {len(ys)} values")
    z = np.empty((len(ys), len(xs)))
    z[np.searchsorted(ys, d[:, 1]), np.searchsorted(xs, d[:, 0])] = d[:, 2]
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 5), layout="constrained")
    mesh = ax.pcolormesh(xs, ys, z, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label=column)
    if target is not None:
        ax.contour(xs, ys, z, levels=[target], colors="C3", linewidths=1.5)
        ax.plot([], [], "-", color="C3", lw=1.5, label=f"requirement {column} = {target:g}")
        ax.legend(fontsize=8)
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.set_title(f"{column} over {x} × {y}{_at(report)}")
    return fig


def throughput(timing):
    """Run time and throughput of a campaign's workers.

    Parameters
    ----------
    timing : pandas.DataFrame
        The run times of a campaign (:func:`atomnav.campaign.timing`): ``run``,
        ``elapsed_s`` (the wall time of the scenario call on its worker, s) and
        ``worker`` (the worker's name), one row per run (a repeated run counts once).

    Returns
    -------
    matplotlib.figure.Figure
        Left: the run time (s) of every run against its run number, coloured by worker.
        Right: per worker the throughput, runs per second of run time (runs / Σ
        ``elapsed_s``), with the number of runs above each bar.

    Raises
    ------
    atomnav.InputError
        Naming ``timing``: a missing column, or a run time that is not finite and > 0.
    """
    instance(timing, pd.DataFrame, "timing")
    locate(timing, ["run", "elapsed_s", "worker"], "timing")
    runs = timing.drop_duplicates("run")
    d = read_table(runs, ["run", "elapsed_s"], "timing")
    bad = np.flatnonzero(d[:, 1] <= 0)
    if bad.size:
        raise input_error("timing", f"column 'elapsed_s': run {d[bad[0], 0]:g} took {d[bad[0], 1]} s; expected > 0", bad[0])
    workers = runs["worker"].astype(str).to_numpy()
    names = sorted(set(workers))
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    rates, counts = [], []
    for i, w in enumerate(names):
        mine = workers == w
        left.plot(d[mine, 0], d[mine, 1], ".", ms=4, color=f"C{i % 10}", label=w)
        counts.append(int(np.count_nonzero(mine)))
        rates.append(counts[-1] / d[mine, 1].sum())
    left.set_xlabel("run")
    left.set_ylabel("run time (s)")
    left.set_title(f"Run time of {len(d)} runs")
    left.grid(True, alpha=0.3)
    left.legend(fontsize=7, title="worker")
    bars = right.bar(names, rates, color=[f"C{i % 10}" for i in range(len(names))])
    right.bar_label(bars, labels=[f"{c} runs" for c in counts], fontsize=7)
    right.set_xlabel("worker")
    right.set_ylabel("throughput (runs per s of run time)")
    right.set_title(f"Throughput of {len(names)} workers")
    right.tick_params(axis="x", labelrotation=30)
    return fig
