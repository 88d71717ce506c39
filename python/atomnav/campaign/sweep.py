"""Sweeps of a campaign scenario over its parameters and the requirement boundary they imply.

A scenario's covariance predictor (``scenario.predict``, see
:func:`atomnav.campaign.scenario.predicted_by`) gives the RMS error of every metric at a
parameter point in one call, without drawing a run: :func:`sweep` evaluates it over a
grid (``method="covariance"``), or runs the seeded Monte Carlo of the same grid and sets
its RMS over the seeds beside the prediction (``method="monte_carlo"``, through
:func:`compare`), so the covariance analysis is checked where it is used (Gelb 1974,
ch. 7 on covariance and sensitivity analysis; Bar-Shalom, Li and Kirubarajan 2001,
§5.4 on checking a covariance against Monte-Carlo errors). :func:`requirements` finds,
on the covariance path, the parameter value at which a metric reaches its required
maximum: the edge of the feasible region.

Every table has units in its column names; parameters are columns named as the
scenario's parameters.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from .._validate import (choice, finite_scalar, flag, input_error, instance, integer, locate, positive, renamed,
                         table as read_table)

#: Methods of :func:`sweep`.
METHODS = ("covariance", "monte_carlo")
#: Suffixes of a metric's columns in a :func:`sweep` / :func:`compare` report: the
#: Monte-Carlo RMS over the seeds, its standard error, the covariance prediction and the
#: ratio of the two (Monte Carlo / covariance).
MC, MC_SE, COV, RATIO = "_mc", "_mc_se", "_cov", "_ratio"


def sweep(scenario, points, *, method: str = "covariance", seeds: int = 100, seed: int = 0, at=None, fixed=None,
          folder=None, client=None, scheduler=None, progress: bool = True) -> pd.DataFrame:
    """The error metrics of a scenario over a grid of parameter points, predicted by its
    covariance analysis or measured by Monte Carlo beside the prediction.

    Parameters
    ----------
    scenario : callable
        A campaign scenario ``f(*, seed, **params)`` (:mod:`atomnav.campaign.scenario`)
        with a covariance predictor ``f.predict(**params)``
        (:func:`atomnav.campaign.scenario.predicted_by`).
    points : dict or list of dict
        The parameter points, as :class:`atomnav.campaign.plan.Campaign` takes them: a
        dict name -> list of values (the cartesian product, last name fastest) or a list
        of dicts.
    method : {"covariance", "monte_carlo"}
        ``"covariance"``: one predictor call per point (cheap: 10 000 points of a
        closed-form predictor take seconds). ``"monte_carlo"``: ``seeds`` runs per point
        by :func:`atomnav.campaign.run`, reported by :func:`compare`.
    seeds : int
        Monte-Carlo runs per point (≥ 2; ``"monte_carlo"`` only).
    seed : int
        Campaign seed (0 … 2⁶⁴ − 1): run r of the campaign draws from (seed, r) only.
    at : float, optional
        The checkpoint time (s) at which the metrics are reported; by default each
        point's last checkpoint.
    fixed : dict, optional
        Parameters shared by every point.
    folder : str or path-like
        Where the Monte-Carlo runs are kept (and resumed from); required by
        ``"monte_carlo"``, refused by ``"covariance"``.
    client : dask.distributed.Client, optional
        Runs the Monte Carlo on this client (``"monte_carlo"`` only).
    scheduler : str, optional
        Address ``"tcp://host:port"`` of a Dask scheduler to run the Monte Carlo on
        (``"monte_carlo"`` only).
    progress : bool
        Show a progress bar (over points, or over runs).

    Returns
    -------
    pandas.DataFrame
        One row per point in grid order: ``point``, one column per parameter, ``time_s``
        (s), then per metric of the scenario (e.g. ``pos_error_m``) its prediction
        ``<metric>_cov``. With ``"monte_carlo"`` also ``seeds`` (runs found for the point)
        and per metric ``<metric>_mc`` (RMS over the seeds), ``<metric>_mc_se`` (its
        standard error) and ``<metric>_ratio`` (``_mc`` / ``_cov``), as :func:`compare`.

    Raises
    ------
    atomnav.InputError
        Naming ``method`` (unknown), ``points`` (empty, or an unknown parameter name),
        ``fixed``, ``seeds``, ``at`` (not a checkpoint), ``scenario`` (no predictor, or a
        prediction that is not finite), ``folder`` (missing for ``"monte_carlo"``), or
        ``folder`` / ``client`` / ``scheduler`` given to ``"covariance"``.

    Examples
    --------
    The free INS's position error after 10 min for three bias levels, predicted, then
    measured over 200 seeds each beside the prediction:

    >>> from atomnav.campaign.strapdown_free import strapdown_free
    >>> grid = {"bias_scale": [0.5, 1.0, 2.0]}
    >>> predicted = sweep(strapdown_free, grid, progress=False)  # doctest: +SKIP
    >>> measured = sweep(strapdown_free, grid, method="monte_carlo", seeds=200,
    ...                  folder="campaigns")  # doctest: +SKIP
    """
    from .plan import Campaign
    from .scenario import predictor

    method = choice(method, METHODS, "method")
    progress = flag(progress, "progress")
    predict = predictor(scenario)
    at = None if at is None else finite_scalar(at, "at")
    if method == "covariance":
        for name, value in (("folder", folder), ("client", client), ("scheduler", scheduler)):
            if value is not None:
                raise input_error(name, "is used by method='monte_carlo' only; the covariance sweep runs in this process")
        campaign = Campaign(scenario, points, seeds=1, seed=seed, fixed=fixed)
        return _predictions(predict, [campaign.point(i) for i in range(campaign.n_points)], _shown(campaign), at, progress)
    integer(seeds, "seeds", 2)
    if folder is None:
        raise input_error("folder", "method='monte_carlo' keeps its runs on disk: give the folder to write them to")
    from .execute import run

    campaign = Campaign(scenario, points, seeds=seeds, seed=seed, fixed=fixed)
    return compare(run(campaign, folder, client=client, scheduler=scheduler, progress=progress), campaign, at)


def compare(table, campaign, at=None) -> pd.DataFrame:
    """The Monte-Carlo RMS of every metric per parameter point of a campaign, beside the
    scenario's covariance prediction and their ratio.

    Parameters
    ----------
    table : pandas.DataFrame
        The campaign's table (:func:`atomnav.campaign.run` or
        :func:`atomnav.campaign.load`), or some of its rows: ``point``, ``time_s`` (s) and
        the scenario's metric columns, one row per run and checkpoint (other columns are
        not read: a point's parameters are the campaign's).
    campaign : atomnav.campaign.Campaign
        The campaign that made the table; its scenario has a covariance predictor
        ``scenario.predict``.
    at : float, optional
        The checkpoint time (s) to report; by default each point's last checkpoint.

    Returns
    -------
    pandas.DataFrame
        One row per point of the table, sorted by point: ``point``, the parameters that
        vary or are fixed, ``time_s`` (s), ``seeds`` (runs of the point) and per metric
        ``<metric>_mc`` — the RMS √(mean e²) over the seeds —, ``<metric>_mc_se`` — its
        standard error, sd(e²) / (2 · RMS · √seeds) by the delta method (Casella and
        Berger 2002, §5.5.4) —, ``<metric>_cov`` — the prediction, an RMS over seeds by
        its definition — and ``<metric>_ratio`` = ``_mc`` / ``_cov`` (1 for a covariance
        analysis that matches the Monte Carlo).

    Raises
    ------
    atomnav.InputError
        Naming ``table`` (a missing column, a metric with NaN or inf, a point that is not
        one of the campaign's, a point with fewer than 2 runs), ``at`` (not a checkpoint
        of some point) or ``campaign`` (its scenario has no predictor).
    """
    from .plan import Campaign
    from .scenario import predictor

    instance(table, pd.DataFrame, "table")
    instance(campaign, Campaign, "campaign")
    with renamed(scenario="campaign"):
        predict = predictor(campaign.scenario)
    at = None if at is None else finite_scalar(at, "at")
    point, times = read_table(table, ["point", "time_s"], "table", epoch=None).T
    keys = np.unique(point)
    alien = keys[(keys != np.round(keys)) | (keys < 0) | (keys >= campaign.n_points)]
    if alien.size:
        raise input_error("table", f"column 'point': {alien[0]:g} is not a point of the campaign (0 … {campaign.n_points - 1})")
    chosen = []
    for key in keys:
        checkpoints = np.unique(times[point == key])
        chosen.append(checkpoints[_checkpoint(checkpoints, at, f"the runs of point {key:g}")])
    chosen = np.array(chosen)
    keys = keys.astype(np.int64)
    _same_parameters(table, campaign, point, keys)
    report = _predictions(predict, [campaign.point(int(k)) for k in keys], _shown(campaign), chosen, False)
    report["point"] = keys
    metrics = [c[: -len(COV)] for c in report.columns if c.endswith(COV)]
    rows = times == chosen[np.searchsorted(keys, point)]
    squares = pd.DataFrame(read_table(table.loc[rows], metrics, "table") ** 2, columns=metrics).groupby(point[rows])
    n = squares.size().to_numpy()
    if np.any(n < 2):
        few = np.argmax(n < 2)
        raise input_error("table", f"point {keys[few]} has {n[few]} run at {chosen[few]} s; an RMS over seeds and its "
                                   "standard error need 2 or more")
    mean, sd = squares.mean(), squares.std(ddof=1)
    columns = {"seeds": n}
    for m in metrics:
        rms = np.sqrt(mean[m].to_numpy())
        with np.errstate(divide="ignore", invalid="ignore"):
            se = np.where(rms > 0, sd[m].to_numpy() / (2.0 * rms * np.sqrt(n)), 0.0)
        cov = report[m + COV].to_numpy()
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(cov > 0, rms / cov, np.where(rms > 0, np.inf, 1.0))
        columns.update({m + MC: rms, m + MC_SE: se, m + COV: cov, m + RATIO: ratio})
    return pd.concat([report.drop(columns=[m + COV for m in metrics]), pd.DataFrame(columns)], axis=1)


def requirements(scenario, target: dict, at, space: dict, *, fixed=None, tol: float = 1e-6, samples: int = 17,
                 method: str = "covariance", progress: bool = False) -> pd.DataFrame:
    """The boundary of the parameter region in which a scenario meets its error
    requirements, by bisection on its covariance prediction.

    A point is feasible when every metric of ``target`` is at most its required value
    at time ``at``. The method assumes that this feasibility changes once along the
    bisected parameter (each metric monotonic in it, as a drift grows with a noise
    density or a bias): it scans ``samples`` evenly spaced values, then bisects the
    bracket in which the prediction crosses the requirement. It does not trust that
    assumption: a scan in which feasibility changes more than once, or a bisection step
    whose prediction leaves the range spanned by its bracket, marks the row
    ``"non-monotonic"`` (boundary NaN) with a ``RuntimeWarning`` instead of returning
    one of several crossings. A bump narrower than the scan's spacing that does not
    fall on a bisection step is not seen.

    Parameters
    ----------
    scenario : callable
        A campaign scenario with a covariance predictor ``scenario.predict``.
    target : dict
        Metric column -> largest allowed RMS value in the metric's unit, e.g.
        ``{"pos_error_m": 10.0}``.
    at : float
        The checkpoint time (s) at which the requirement applies.
    space : dict
        Parameter -> its range: a tuple ``(low, high)`` for a continuous parameter, a list
        of values for a discrete one. One or two continuous parameters: the last is
        bisected; with two, the first takes ``samples`` evenly spaced values and the
        boundary is found for each (a curve). Every combination of the discrete values
        gets its own boundary.
    fixed : dict, optional
        Further parameters, the same for every point.
    tol : float
        Width of the final bisection bracket relative to ``high - low`` of the bisected
        parameter, in (0, 1): the boundary is within ``tol · (high - low) / 2`` of the
        crossing.
    samples : int
        Scan points per continuous parameter (3 … 10 001).
    method : {"covariance"}
        How a point is evaluated: the covariance predictor (the Monte Carlo confirms a
        boundary through :func:`sweep` with ``method="monte_carlo"``).
    progress : bool
        Show a progress bar over the boundaries.

    Returns
    -------
    pandas.DataFrame
        One row per boundary: the discrete parameters (and the scanned continuous one),
        the bisected parameter's boundary value (column named as the parameter), the
        predicted metrics of ``target`` there (columns named as the metrics) and
        ``feasible``: ``"below"`` (values up to the boundary meet the requirement),
        ``"above"``, ``"all"`` / ``"none"`` (no crossing in the range; boundary and
        metrics NaN) or ``"non-monotonic"`` (see above; boundary and metrics NaN).

    Raises
    ------
    atomnav.InputError
        Naming ``space`` (empty, an unknown parameter, a bad range, not one or two
        continuous parameters), ``target`` (empty, an unknown metric, a value that is
        not > 0), ``fixed`` (an unknown parameter, or one also in ``space``), ``at``
        (not a checkpoint), ``tol``, ``samples``, ``method`` or ``scenario`` (no
        predictor, a prediction that is not finite).

    Warns
    -----
    RuntimeWarning
        When a row is ``"non-monotonic"``, naming its parameters and where.

    Examples
    --------
    The largest bias scale of a tactical IMU whose free INS stays within 100 m after
    2 min, per motion:

    >>> from atomnav.campaign.strapdown_free import strapdown_free
    >>> requirements(strapdown_free, {"pos_error_m": 100.0}, 120.0,
    ...              {"motion": ["stationary", "sinusoidal"], "bias_scale": (0.1, 3.0)},
    ...              fixed={"duration": 120.0})  # doctest: +SKIP
           motion  bias_scale  pos_error_m feasible
    0  stationary    0.794720    99.999870    below
    1  sinusoidal    0.808731    99.999872    below
    """
    from tqdm.auto import tqdm

    from .plan import Campaign
    from .scenario import check_params, predictor

    choice(method, ("covariance",), "method")
    progress = flag(progress, "progress")
    predict = predictor(scenario)
    at = finite_scalar(at, "at")
    tol = positive(tol, "tol")
    if tol >= 1.0:
        raise input_error("tol", f"is relative to the parameter's range and must be < 1, got {tol}")
    samples = integer(samples, "samples", 3, 10_001)
    continuous, discrete = _space(scenario, space)
    fixed = dict(instance(fixed, dict, "fixed")) if fixed is not None else {}
    check_params(scenario, fixed, "fixed")
    both = sorted(set(fixed) & set(space))
    if both:
        raise input_error("fixed", f"parameter {both[0]!r} is also in space; give it in one of them")
    *scanned, (name, (low, high)) = continuous.items()
    grid = {**discrete, **{k: list(np.linspace(lo, hi, samples)) for k, (lo, hi) in scanned}}
    if grid:
        campaign = Campaign(scenario, grid, fixed=fixed)
        combos = [campaign.point(i) for i in range(campaign.n_points)]
    else:
        combos = [fixed]
    limits = _targets(target, _predict_at(predict, {**combos[0], name: low}, at)[1])
    rows = []
    for combo in tqdm(combos, desc="requirements", unit="boundary", disable=not progress):
        value, side = _boundary(lambda x: _predict_at(predict, {**combo, name: x}, at)[1], limits, low, high, samples, tol)
        if side == "non-monotonic":
            shown = {k: combo[k] for k in grid}
            warnings.warn(f"the requirement {target} is not met on one side of a single value of {name!r} in "
                          f"[{low}, {high}] at {shown}: the prediction is not monotonic there; narrow the range",
                          RuntimeWarning, stacklevel=2)
        at_boundary = _predict_at(predict, {**combo, name: value}, at)[1] if np.isfinite(value) else {}
        rows.append({**{k: combo[k] for k in grid}, name: value,
                     **{m: at_boundary.get(m, np.nan) for m in limits}, "feasible": side})
    return pd.DataFrame(rows)


def _predict_at(predict, params: dict, at) -> tuple[float, dict]:
    """The checkpoint time (s) and the predicted metrics (name -> value) of the prediction
    at ``params``, read at checkpoint ``at`` (None: the last one)."""
    df = predict(**params)
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"scenario: its predictor returned {type(df).__name__}, expected a pandas.DataFrame")
    names = list(df.columns)
    data = df.to_numpy()  # numbers only: float64 (the common case, without per-column checks)
    if data.dtype != np.float64 or len(set(names)) != len(names) or "time_s" not in names:
        data = read_table(df, names, "scenario", finite=False)  # a TypeError or InputError naming the column
    j = names.index("time_s")
    k = _checkpoint(data[:, j], at, f"the prediction at {params}")
    values = {m: float(data[k, i]) for i, m in enumerate(names) if i != j}
    bad = [m for m, v in values.items() if not np.isfinite(v)]
    if bad:
        raise input_error("scenario", f"predicted {bad[0]} = {values[bad[0]]} at {params}, {data[k, j]} s")
    return float(data[k, j]), values


def _shown(campaign) -> list[str]:
    """The parameters a report shows: those that vary over the campaign's points, then the
    fixed ones (as the campaign's table)."""
    varied = campaign.varied()
    return [*varied, *(k for k in campaign.fixed if k not in varied)]


def _same_parameters(table: pd.DataFrame, campaign, point: np.ndarray, keys: np.ndarray) -> None:
    """An :class:`InputError` naming ``table`` unless its parameter columns (those it has of
    the campaign's varied and fixed parameters; lists as JSON text, as the campaign's
    table keeps them) hold the campaign's value of each row's point."""
    import json

    for name in _shown(campaign):
        if name not in table.columns:
            continue
        column = table.iloc[:, locate(table, [name], "table")[0]].to_numpy()
        for key in keys:
            want = campaign.point(int(key))[name]
            want = json.dumps(list(want)) if isinstance(want, (list, tuple)) else want
            for v in column[point == key]:
                if not _equal(v, want):
                    v = v.item() if isinstance(v, np.generic) else v
                    raise input_error("table", f"column {name!r} holds {v!r} at point {key} where the campaign has "
                                               f"{want!r}: the table is not this campaign's")


def _equal(value, want) -> bool:
    """``value`` (from a table) is the parameter value ``want``: a string only equals a
    string; a missing value (NaN, ``pd.NA``) equals nothing."""
    if isinstance(value, str) != isinstance(want, str):
        return False
    try:
        return bool(value == want)
    except TypeError:  # pd.NA
        return False


def _checkpoint(times: np.ndarray, at, what: str) -> int:
    """The index of checkpoint ``at`` (s; None: the last) in ``times`` (s, increasing), of
    ``what``."""
    if not len(times):
        raise input_error("scenario", f"{what} has no checkpoint")
    if at is None:
        return len(times) - 1
    hit = np.flatnonzero(np.abs(times - at) <= 1e-9 * max(1.0, abs(at)))
    if not hit.size:
        raise input_error("at", f"{at} s is not a checkpoint of {what}; its checkpoints are {times.tolist()} s")
    return int(hit[0])


def _predictions(predict, points: list, shown: list, at, progress: bool) -> pd.DataFrame:
    """The predictions at ``points`` (dicts of all parameters) at checkpoint ``at`` (one
    time or None for every point, or one time per point): ``point``, the parameters
    ``shown``, ``time_s`` and ``<metric>_cov`` per metric."""
    from tqdm.auto import tqdm

    rows = []
    for i, params in enumerate(tqdm(points, desc="covariance", unit="point", disable=not progress)):
        t, values = _predict_at(predict, params, at if at is None or np.ndim(at) == 0 else at[i])
        rows.append({"point": i, **{k: params[k] for k in shown}, "time_s": t, **{m + COV: v for m, v in values.items()}})
    return pd.DataFrame(rows)


def _space(scenario, space) -> tuple[dict, dict]:
    """The continuous (name -> (low, high)) and discrete (name -> list) parameters of
    ``space``, checked."""
    from .scenario import check_params

    instance(space, dict, "space")
    if not space:
        raise input_error("space", "is empty; give one or two continuous parameters as (low, high)")
    check_params(scenario, space, "space")
    continuous, discrete = {}, {}
    for name, values in space.items():
        if isinstance(values, tuple):
            if len(values) != 2:
                raise input_error("space", f"{name!r}: a continuous range is (low, high), got {len(values)} values")
            low, high = (finite_scalar(v, f"space[{name!r}]") for v in values)
            if not low < high:
                raise input_error("space", f"{name!r}: the range (low, high) needs low < high, got ({low}, {high})")
            continuous[name] = (low, high)
        elif isinstance(values, list):
            if not values:
                raise input_error("space", f"{name!r}: the list of discrete values is empty")
            discrete[name] = values
        else:
            raise TypeError(f"space: {name!r} expected a tuple (low, high) or a list of values, got {type(values).__name__}")
    if not 1 <= len(continuous) <= 2:
        raise input_error("space", f"needs one or two continuous parameters as (low, high), got {len(continuous)}")
    return continuous, discrete


def _targets(target, metrics: dict) -> dict:
    """``target`` (metric -> largest allowed value), checked against the predicted
    ``metrics``."""
    instance(target, dict, "target")
    if not target:
        raise input_error("target", "is empty; give metric -> largest allowed value, e.g. {'pos_error_m': 10.0}")
    for m in target:
        if m not in metrics:
            raise input_error("target", f"unknown metric {m!r}; the scenario predicts {list(metrics)}")
    return {m: positive(v, f"target[{m!r}]") for m, v in target.items()}


def _boundary(evaluate, limits: dict, low: float, high: float, samples: int, tol: float) -> tuple[float, str]:
    """The value in [low, high] where max over ``limits`` of metric / limit crosses 1 and
    the feasible side, by a scan of ``samples`` values and bisection to ``tol`` of the
    range (see :func:`requirements`)."""

    def excess(x: float) -> float:
        values = evaluate(x)
        return max(values[m] / v for m, v in limits.items())

    xs = np.linspace(low, high, samples)
    f = np.array([excess(x) for x in xs])
    ok = f <= 1.0
    changes = np.flatnonzero(ok[1:] != ok[:-1])
    if not changes.size:
        return np.nan, "all" if ok[0] else "none"
    if changes.size > 1:
        return np.nan, "non-monotonic"
    k = changes[0]
    a, b, fa, fb = xs[k], xs[k + 1], f[k], f[k + 1]
    slack = 1e-12 * max(abs(fa), abs(fb))
    while b - a > tol * (high - low):
        m = 0.5 * (a + b)
        fm = excess(m)
        if not min(fa, fb) - slack <= fm <= max(fa, fb) + slack:
            return np.nan, "non-monotonic"
        if (fm <= 1.0) == (fa <= 1.0):
            a, fa = m, fm
        else:
            b, fb = m, fm
    return 0.5 * (a + b), "below" if ok[0] else "above"
