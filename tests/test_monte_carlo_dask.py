"""Distributed Monte Carlo survives killed workers: on a LocalCluster of three worker
processes, killing one worker at a random moment (also while the inputs are being sent),
or two of the three, leaves every finished run in the result, identical to the
in-process campaign (run i draws the random stream i of the seed wherever it executes).
When no worker is left and none comes back, the campaign ends within its ``timeout``
with the finished runs and the missing ones named.

Every test is bounded: a watchdog (SIGALRM) fails it after ``LIMIT_S`` seconds, cluster
start and teardown included, and prints every thread's stack first."""

import faulthandler
import os
import random
import signal
import sys
import threading
import time

import numpy as np
import pytest

from atomnav.filter import analysis
from atomnav.filter.analysis import MonteCarloIncomplete, monte_carlo
from test_filter_analysis import ins_scenario

distributed = pytest.importorskip("distributed")

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGALRM"), reason="the watchdog needs SIGALRM")

RUNS, CHUNK, SEED = 24, 2, 11
LIMIT_S = 240  # hard bound of one test on a loaded two-core machine (typically 10-80 s)


@pytest.fixture(scope="module")
def scenario():
    return ins_scenario(duration=120.0)


@pytest.fixture(scope="module")
def local(scenario):
    return monte_carlo(scenario, runs=RUNS, seed=SEED)


@pytest.fixture
def watchdog():
    """Fail the test (with every thread's stack on stderr) if it runs over ``LIMIT_S``."""
    def expire(signum, frame):
        faulthandler.dump_traceback(file=sys.stderr, all_threads=True)
        raise TimeoutError(f"test still running after {LIMIT_S} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(LIMIT_S)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


@pytest.fixture
def cluster(watchdog):
    """A fresh cluster of three worker processes per test (its nannies restart killed
    workers), closed at the end whatever happened, under the watchdog."""
    with distributed.LocalCluster(n_workers=3, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50) as c:
        yield c


@pytest.fixture
def client(cluster):
    with distributed.Client(cluster, set_as_default=False) as c:
        c.wait_for_workers(3, timeout=120)
        yield c


def _kill(cluster, how_many: int) -> list[int]:
    """SIGKILL ``how_many`` of the live worker processes (their nannies start new ones);
    the pids come from the nannies in this process, so killing asks nothing of the
    cluster."""
    pids = sorted(p for p in (n.pid for n in list(cluster.workers.values())) if p)
    victims = random.sample(pids, min(how_many, len(pids)))
    for pid in victims:
        os.kill(pid, signal.SIGKILL)
    return victims


def _kill_at_first_submit(cluster, client, monkeypatch, how_many: int) -> list[int]:
    """Make the client's first ``submit`` (the scenario going to the cluster) kill
    ``how_many`` workers just before it sends; returns the list the victims' pids go to."""
    submit, fired = client.submit, []

    def killing_submit(*a, **kw):
        if not fired:
            fired.extend(_kill(cluster, how_many))
        return submit(*a, **kw)

    monkeypatch.setattr(client, "submit", killing_submit)
    return fired


def _check(result, local):
    """Every run in ``result`` equals the in-process run of the same number."""
    rows = local.table[local.table["run"].isin(result.runs)].reset_index(drop=True)
    assert result.table.reset_index(drop=True).equals(rows)
    at = np.searchsorted(local.runs, result.runs)
    assert np.array_equal(result.nees, local.nees[at]) and np.array_equal(result.nis, local.nis[at], equal_nan=True)


def _campaign(scenario, client, local, runs=RUNS):
    """Run the campaign; a complete result must equal the local one, an incomplete one
    must carry every finished run unchanged and name the missing ones."""
    try:
        result = monte_carlo(scenario, runs=runs, seed=SEED, client=client, chunk=CHUNK)
    except MonteCarloIncomplete as e:
        _check(e.partial, local)
        assert sorted(set(e.partial.runs) | set(e.missing)) == list(range(runs)) and e.missing
        return e.partial
    _check(result, local)
    assert list(result.runs) == list(range(runs))
    return result


def test_killing_a_worker_while_inputs_are_sent_loses_nothing(scenario, local, cluster, client, monkeypatch):
    """The first submission (the scenario going to the cluster) kills a worker first.
    In the default run: the one kill test CI always exercises."""
    fired = _kill_at_first_submit(cluster, client, monkeypatch, 1)
    result = _campaign(scenario, client, local, runs=12)
    assert fired and len(result.runs) == 12


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("victims", [1, 2])
def test_killing_workers_at_a_random_moment_keeps_every_finished_run(scenario, local, cluster, client, victims, seed):
    """Kill ``victims`` of the three worker processes after a random delay (before any
    run finished, mid-campaign or near the end)."""
    random.seed(seed * 10 + victims)
    delay = random.uniform(0.0, 1.5)
    killer = threading.Timer(delay, _kill, args=(cluster, victims))
    killer.start()
    try:
        result = _campaign(scenario, client, local)
    finally:
        killer.cancel()
        killer.join()
    assert len(result.runs) == RUNS, f"runs lost after killing {victims} worker(s) at {delay:.2f} s"


@pytest.mark.slow
def test_two_workers_killed_while_inputs_are_sent_lose_nothing(scenario, local, cluster, client, monkeypatch):
    """Two of three killed as the scenario goes to the cluster: one worker (and the
    restarted ones) compute every run."""
    fired = _kill_at_first_submit(cluster, client, monkeypatch, 2)
    result = _campaign(scenario, client, local)
    assert len(fired) == 2 and len(result.runs) == RUNS


def _slow_after_first():
    """``_runs`` whose groups after the first take 20 s (a closure: pickled by value to
    the workers)."""
    real = analysis._runs

    def runs(scn, seed, ids, mode):
        if ids[0] > 0:
            time.sleep(20.0)
        return real(scn, seed, ids, mode)

    return runs


@pytest.mark.slow
def test_no_worker_left_ends_in_time_with_the_finished_runs(scenario, local, cluster, client, monkeypatch):
    """Every worker goes away for good as soon as one group is fetched (the cluster
    scaled to zero while the others still compute): the campaign does not wait for ever,
    it raises within about ``timeout`` s per group left, with every fetched run unchanged
    and the others named missing."""
    monkeypatch.setattr(analysis, "_runs", _slow_after_first())
    fetch, fetched = distributed.Future.result, []

    def fetch_then_scale_down(self, *a, **kw):
        value = fetch(self, *a, **kw)
        fetched.append(self.key)
        if len(fetched) == 1:
            cluster.scale(0)
        return value

    monkeypatch.setattr(distributed.Future, "result", fetch_then_scale_down)
    start = time.monotonic()
    with pytest.raises(MonteCarloIncomplete, match=r"of 24 Monte-Carlo runs not computed") as info:
        monte_carlo(scenario, runs=RUNS, seed=SEED, client=client, chunk=CHUNK, retries=0, timeout=5.0)
    assert time.monotonic() - start < 120.0
    e = info.value
    assert len(e.partial.runs) == CHUNK * len(fetched) and e.missing
    assert sorted([*e.partial.runs, *e.missing]) == list(range(RUNS))
    assert any(isinstance(x, TimeoutError) for x in e.errors), e.errors
    _check(e.partial, local)


@pytest.mark.slow
def test_runs_that_keep_failing_are_reported_with_the_finished_ones(scenario, local, client, monkeypatch):
    """A group that fails on every attempt (here: the one holding run 5) is retried, then
    reported in ``MonteCarloIncomplete.missing``; every other run is in ``.partial``."""
    real = analysis._runs

    def flaky(scn, seed, runs, mode):  # a closure: pickled by value to the workers
        if 5 in runs:
            raise RuntimeError("lost run")
        return real(scn, seed, runs, mode)

    monkeypatch.setattr(analysis, "_runs", flaky)
    with pytest.raises(MonteCarloIncomplete, match="2 of 24 Monte-Carlo runs not computed") as info:
        monte_carlo(scenario, runs=RUNS, seed=SEED, client=client, chunk=CHUNK, retries=1)
    e = info.value
    assert e.missing == [4, 5] and len(e.errors) == 1 and "lost run" in str(e.errors[0])
    assert list(e.partial.runs) == [r for r in range(RUNS) if r not in (4, 5)]
    _check(e.partial, local)


@pytest.mark.parametrize("timeout, error", [(0.0, "timeout"), (float("nan"), "timeout"), (float("inf"), "timeout")])
def test_timeout_must_be_a_positive_finite_number(scenario, timeout, error):
    with pytest.raises(ValueError, match=error) as info:
        monte_carlo(scenario, runs=2, seed=1, client=object(), timeout=timeout)
    assert info.value.parameter == "timeout"
    with pytest.raises(TypeError, match="timeout"):
        monte_carlo(scenario, runs=2, seed=1, client=object(), timeout="60")
