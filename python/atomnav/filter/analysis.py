"""Covariance-only analysis, consistency (NEES/NIS) and Monte Carlo on a linearised
scenario (Rust core ``rust/filter/analysis.rs``).

A :class:`Scenario` is a sequence of continuous error models (F_k, Q_c,k) over steps
Δt_k (e.g. :func:`atomnav.filter.ins_error_model` along a trajectory), an initial
covariance P₀ and a measurement z = Hδx + v, v ~ N(0, R), at flagged epochs. Truth
errors follow the exactly discretised model; the filter uses ``method``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import _core
from .._validate import as_floats, flag, input_error, instance, integer, scalar
from .riccati import _mat


class Scenario:
    """Linearised scenario (see module docstring).

    Picklable (it keeps its inputs), so it can be shipped to Dask workers.

    Parameters
    ----------
    f : array_like (N, n, n) or (1, n, n)
        Continuous system matrices F_k per step, 1/s, or one F for every step (a
        time-invariant system).
    qc : array_like (N, n, n) or (1, n, n)
        Continuous process-noise PSDs Q_c,k per step, squared state units per s, or one
        for every step (as many as ``f``).
    dt : array_like (N,)
        Step lengths, s.
    p0 : array_like (n, n)
        Initial covariance P₀, squared state units: positive semi-definite, so singular
        (e.g. an INS started at the truth) for :func:`covariance_analysis` and
        :func:`true_error_analysis`; :func:`monte_carlo`, whose filter and NEES invert
        P, needs it positive definite.
    h : array_like (m, n)
        Measurement matrix H.
    r : array_like (m, m)
        Measurement noise covariance R, squared measurement units.
    measure : sequence of bool (N + 1,)
        A measurement at epoch k (epoch 0 is the start).
    times : array_like (N + 1,), optional
        Epoch times for the tables, s (default cumulative dt).
    labels : list of str, optional
        State names (default ``x[i]``).
    method : {"van_loan", "first_order"}, default "van_loan"
        Discretisation used by the filter (:func:`atomnav.filter.engine.discretize`).
    sequential : bool, default False
        Decorrelated scalar updates instead of one stacked update.

    Raises
    ------
    TypeError
        ``measure`` is not a sequence of bools, or ``labels`` not a list of names.
    atomnav.InputError
        Naming the argument of a bad shape (``f``, ``qc``, ``times``, ``labels``, …).
    """

    def __init__(self, f, qc, dt, p0, h, r, measure, *, times=None, labels=None,
                 method: str = "van_loan", sequential: bool = False):
        flags = np.asarray(measure, dtype=object).ravel()
        if not all(isinstance(m, (bool, np.bool_)) for m in flags):
            raise TypeError("measure: expected a sequence of bools (a measurement at epoch k or not)")
        self._args = dict(
            f=np.ascontiguousarray(as_floats(f, "f")),
            qc=np.ascontiguousarray(as_floats(qc, "qc")),
            dt=np.ascontiguousarray(as_floats(dt, "dt").ravel()),
            p0=_mat(p0, "p0"), h=_mat(h, "h"), r=_mat(r, "r"),
            measure=[bool(m) for m in flags],
            method=instance(method, str, "method"), sequential=flag(sequential, "sequential"),
        )
        for name in ("f", "qc"):
            if self._args[name].ndim != 3:
                raise input_error(name, f"expected an (N, n, n) stack, got shape {self._args[name].shape}")
        self._core = self._build()
        n = self._args["p0"].shape[0]
        self.times = np.concatenate([[0.0], np.cumsum(self._args["dt"])]) if times is None else as_floats(times, "times")
        if self.times.shape != (len(self._args["measure"]),):
            raise input_error("times", f"expected {len(self._args['measure'])} epochs, got shape {self.times.shape}")
        if labels is not None and (isinstance(labels, (str, bytes)) or not isinstance(labels, (list, tuple))):
            raise TypeError(f"labels: expected a list of state names, got {type(labels).__name__}")
        self.labels = list(labels) if labels is not None else [f"x[{i}]" for i in range(n)]
        if len(self.labels) != n:
            raise input_error("labels", f"expected {n} names, got {len(self.labels)}")

    def _build(self):
        a = self._args
        return _core.Scenario(a["f"], a["qc"], a["dt"], a["p0"], a["h"], a["r"], a["measure"], method=a["method"], sequential=a["sequential"])

    def __getstate__(self):
        return {"args": self._args, "times": self.times, "labels": self.labels}

    def __setstate__(self, s):
        self._args, self.times, self.labels = s["args"], s["times"], s["labels"]
        self._core = self._build()

    @property
    def size(self) -> int:
        return len(self.labels)


def covariance_analysis(scenario: Scenario) -> pd.DataFrame:
    """σ of every state after each epoch (no noise simulated).

    Parameters
    ----------
    scenario : Scenario
        The linearised scenario.

    Returns
    -------
    pandas.DataFrame
        One row per epoch (N + 1); columns time_s (s) and one column per state label
        (units of the state).
    """
    s = instance(scenario, Scenario, "scenario")._core.sigmas()
    df = pd.DataFrame(s, columns=scenario.labels)
    df.insert(0, "time_s", scenario.times)
    return df


def true_error_analysis(scenario: Scenario, r_true, cross) -> pd.DataFrame:
    """σ of the TRUE error of the filter as built (suboptimal-filter analysis): the gains
    come from the scenario's own model (its P and R), while the real measurement noise has
    covariance ``r_true`` (m, m) and is correlated with the process noise of the step before
    each measurement, ``cross`` (steps, n, m) = E[w_{k−1} v_kᵀ] (e.g. a CAI readout that
    also senses the IMU noise of its shot). With ``r_true`` = R and zero ``cross`` it equals
    :func:`covariance_analysis`.

    Parameters
    ----------
    scenario : Scenario
        The linearised scenario; its P and R give the gains.
    r_true : array_like (m, m)
        Covariance of the real measurement noise, squared measurement units.
    cross : array_like (steps, n, m)
        E[w_{k−1} v_kᵀ], the correlation of the process noise of the step before each
        measurement with its measurement noise.

    Returns
    -------
    pandas.DataFrame
        Columns as in :func:`covariance_analysis`: time_s (s) and the σ of the true
        error of every state (units of the state).
    """
    instance(scenario, Scenario, "scenario")
    cross = np.ascontiguousarray(as_floats(cross, "cross"))
    if cross.ndim != 3:
        raise input_error("cross", f"expected a (steps, n, m) stack, got shape {cross.shape}")
    s = scenario._core.true_sigmas(_mat(r_true, "r_true"), cross)
    df = pd.DataFrame(s, columns=scenario.labels)
    df.insert(0, "time_s", scenario.times)
    return df


def chi2_band(dof: int, runs: int, p: float = 0.95) -> tuple[float, float]:
    """Two-sided p band of the run-average of ``runs`` χ²(dof) variables (NEES or NIS):
    χ²_{runs·dof} quantiles / runs.

    Parameters
    ----------
    dof : int
        Degrees of freedom of each variable (the state or measurement size).
    runs : int
        Number of runs averaged.
    p : float, default 0.95
        Probability of the band, 0 < p < 1.

    Returns
    -------
    (float, float)
        Lower and upper bound of the run-averaged statistic.

    References
    ----------
    Y. Bar-Shalom, X. R. Li and T. Kirubarajan, *Estimation with Applications to
    Tracking and Navigation* (2001), §5.4.
    """
    dof, runs = integer(dof, "dof", 1, 2**32), integer(runs, "runs", 1, 2**32)
    p = scalar(p, "p")
    if not 0 < p < 1:
        raise input_error("p", f"must be a probability in (0, 1), got {p}")
    from scipy.stats import chi2  # imported here: scipy.stats alone takes longer than `import atomnav` may

    lo, hi = chi2.ppf([(1 - p) / 2, (1 + p) / 2], runs * dof)
    return float(lo / runs), float(hi / runs)


@dataclass
class MonteCarlo:
    """Monte-Carlo result: the tidy table (run, time_s, state, error, sigma) and NEES/NIS
    per run and epoch (NIS NaN where no measurement); ``runs`` holds the run number of
    each row of ``nees``/``nis`` (all runs 0…R−1, or the finished ones of an incomplete
    campaign, see :class:`MonteCarloIncomplete`).

    Attributes
    ----------
    table : pandas.DataFrame
        Tidy table: run, time_s (s), state, error and sigma (units of the state).
    nees : numpy.ndarray (R, N + 1)
        NEES per run and epoch.
    nis : numpy.ndarray (R, N + 1)
        NIS per run and epoch (NaN where no measurement).
    times : numpy.ndarray (N + 1,)
        Epoch times, s.
    runs : numpy.ndarray (R,)
        Run number of each row of ``nees``/``nis``.
    """

    table: pd.DataFrame
    nees: np.ndarray
    nis: np.ndarray
    times: np.ndarray
    runs: np.ndarray

    def nees_inside(self, dof: int, p: float = 0.95) -> float:
        """Fraction of epochs whose run-averaged NEES lies in the two-sided p χ² band.

        Parameters
        ----------
        dof : int
            Degrees of freedom of the NEES (the state size).
        p : float, default 0.95
            Probability of the band (:func:`chi2_band`).

        Returns
        -------
        float
            Fraction in [0, 1].
        """
        lo, hi = chi2_band(dof, self.nees.shape[0], p)
        m = self.nees.mean(axis=0)
        return float(np.mean((m >= lo) & (m <= hi)))


class MonteCarloIncomplete(RuntimeError):
    """Some runs of a distributed Monte Carlo could not be computed (their tasks kept
    failing, e.g. every worker that ran them died). Nothing finished is lost:
    ``partial`` is the :class:`MonteCarlo` of the finished runs (``partial.runs`` their
    numbers), ``missing`` the run numbers not computed and ``errors`` the last exception
    of each failed group of runs."""

    def __init__(self, partial: MonteCarlo, missing: list[int], errors: list[BaseException]):
        super().__init__(f"{len(missing)} of {len(missing) + len(partial.runs)} Monte-Carlo runs not computed "
                         f"(runs {missing[:10]}{' …' if len(missing) > 10 else ''}); last error: {errors[-1]!r}")
        self.partial, self.missing, self.errors = partial, missing, errors


def _runs(scenario: Scenario, seed: int, runs: list[int], mode: str):
    instance(scenario, Scenario, "scenario")
    return scenario._core.monte_carlo(int(seed), [int(r) for r in runs], mode)


def _same(x):
    return x


def _workers(client) -> int:
    """Number of workers the scheduler has now (0 if it cannot be asked)."""
    try:
        return len(client.nthreads())
    except Exception:  # noqa: BLE001 - a scheduler that cannot answer has no worker for us
        return 0


def _distributed(client, scenario: Scenario, seed: int, groups: list[list[int]], mode: str, retries: int,
                 timeout: float | None):
    """Run the groups on a Dask cluster; returns ({group index: result}, [errors]).

    The scenario reaches the workers as the result of a task (not scattered data), so the
    scheduler recomputes it when the worker that holds it dies; each group is resubmitted
    up to ``retries`` times when its task fails (e.g. ``KilledWorker``), and results are
    fetched as they complete, so a failure later on does not lose them. Nothing waits
    without bound: when the cluster has had no worker for ``timeout`` s, or a finished
    result cannot be fetched within ``timeout`` s, the groups not yet done are given up
    (cancelled) and reported as errors."""
    import time

    from distributed import as_completed

    scn = client.submit(_same, scenario, pure=False, retries=retries)
    done, errors, tries, pending = {}, [], {}, {}

    def send(i: int):
        fut = client.submit(_runs, scn, seed, groups[i], mode, pure=False, retries=retries)
        pending[fut] = i
        return fut

    # the client's own event loop: not the default client's, which may be another one
    queue = as_completed([send(i) for i in range(len(groups))], loop=client.loop)
    seen, asked = time.monotonic(), 0.0
    while not queue.is_empty():
        batch = queue.next_batch(block=False)
        if not batch:
            now = time.monotonic()
            if timeout is not None and now - asked >= 1.0:
                asked = now
                if _workers(client):
                    seen = now
                elif now - seen > timeout:
                    errors.append(TimeoutError(f"no worker in the cluster for {timeout} s"))
                    break
            time.sleep(0.05)
            continue
        for fut in batch:
            i = pending.pop(fut)
            try:
                done[i] = fut.result(timeout=timeout)
            except Exception as e:  # noqa: BLE001 - a failed group is retried or reported with the finished runs
                tries[i] = tries.get(i, 0) + 1
                if tries[i] <= retries:
                    queue.add(send(i))
                else:
                    errors.append(e)
            fut.release()
    for fut in pending:
        fut.cancel()
    scn.release()
    return done, errors


def _result(scenario: Scenario, runs: list[int], parts) -> MonteCarlo:
    err, sig, nees, nis = (np.concatenate([p[i] for p in parts]) for i in range(4))
    e, n = err.shape[1:]
    ids = np.asarray(runs, dtype=np.int64)
    table = pd.DataFrame({
        "run": np.repeat(ids, e * n),
        "time_s": np.tile(np.repeat(scenario.times, n), len(ids)),
        "state": pd.Categorical(np.tile(scenario.labels, len(ids) * e), categories=scenario.labels),
        "error": err.ravel(),
        "sigma": sig.ravel(),
    })
    return MonteCarlo(table, nees, nis, scenario.times, ids)


def monte_carlo(scenario: Scenario, runs: int, seed: int, mode: str = "closed", client=None,
                chunk: int = 10, retries: int = 3, *, timeout: float | None = 60.0) -> MonteCarlo:
    """``runs`` independent runs; run i uses the random stream i of ``seed`` (ChaCha20),
    so the result does not depend on where or in which grouping runs execute.

    Default: all local cores (rayon). With a ``dask.distributed.Client``, runs are sent
    in groups of ``chunk`` to the cluster and the identical table is returned. Workers
    may die meanwhile: a group whose task fails is resubmitted up to ``retries`` times
    (the cluster recomputes lost inputs when workers return); if some groups still fail,
    :class:`MonteCarloIncomplete` is raised carrying every finished run in ``.partial``.
    The same happens, for the runs not yet done, when the cluster has had no worker for
    ``timeout`` seconds (none came back) or a finished result could not be fetched within
    ``timeout`` s; ``timeout=None`` waits for workers without bound.

    Parameters
    ----------
    scenario : Scenario
        The linearised scenario.
    runs : int
        Number of runs (≥ 1).
    seed : int
        Master seed (0 … 2⁶⁴ − 1).
    mode : {"closed", "open"}, default "closed"
        Loop mode of the filter, as in :class:`atomnav.filter.engine.KalmanFilter`.
    client : dask.distributed.Client, optional
        Cluster to run on (default: all local cores).
    chunk : int, default 10
        Runs per task on the cluster.
    retries : int, default 3
        Resubmissions of a failed group (0 … 1000).
    timeout : float or None, default 60.0
        Seconds without a worker, or to fetch a finished result, before giving up.

    Returns
    -------
    MonteCarlo
        Errors, sigmas, NEES and NIS of every run.

    Raises
    ------
    MonteCarloIncomplete
        Some groups failed; ``.partial`` carries every finished run.
    TypeError
        ``timeout`` is not a number or None, or ``client`` not a Dask client.
    atomnav.InputError
        Naming ``runs``, ``seed``, ``chunk``, ``retries`` or ``timeout``, or ``p0`` when
        the scenario's P₀ is singular.
    """
    runs, seed = integer(runs, "runs", 1, 2**32), integer(seed, "seed", 0, 2**64 - 1)
    chunk, retries = integer(chunk, "chunk", 1, 2**32), integer(retries, "retries", 0, 1000)
    ids = list(range(runs))
    _runs(scenario, seed, [], mode)  # no run: the core's checks (a positive definite P₀) before any is sent
    if client is None:
        return _result(scenario, ids, [_runs(scenario, seed, ids, mode)])
    groups = [ids[i:i + chunk] for i in range(0, len(ids), chunk)]
    if timeout is not None:
        if isinstance(timeout, (bool, np.bool_)) or not isinstance(timeout, (int, float, np.integer, np.floating)):
            raise TypeError(f"timeout: expected a number of seconds or None, got {type(timeout).__name__}")
        if not 0 < timeout < np.inf:  # also rejects NaN
            raise input_error("timeout", f"must be a finite number of seconds > 0, or None; got {timeout}")
    if not callable(getattr(client, "submit", None)):
        raise TypeError(f"client: expected a dask.distributed Client or None, got {type(client).__name__}")
    done, errors = _distributed(client, scenario, seed, groups, mode, retries, timeout)
    order = sorted(done)
    e, n = len(scenario.times), scenario.size
    none = (np.empty((0, e, n)), np.empty((0, e, n)), np.empty((0, e)), np.empty((0, e)))
    result = _result(scenario, [r for i in order for r in groups[i]], [none] + [done[i] for i in order])
    if len(done) < len(groups):
        raise MonteCarloIncomplete(result, [r for i, g in enumerate(groups) if i not in done for r in g], errors)
    return result
