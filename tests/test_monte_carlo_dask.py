"""Distributed Monte Carlo survives killed workers: on a LocalCluster of three worker
processes, killing one worker at a random moment (also while the inputs are being sent),
or two of the three, leaves every finished run in the result, identical to the
in-process campaign (run i draws the random stream i of the seed wherever it executes)."""

import os
import random
import signal
import threading

import numpy as np
import pytest

from atomnav.filter.analysis import MonteCarloIncomplete, monte_carlo
from test_filter_analysis import ins_scenario

distributed = pytest.importorskip("distributed")

# each test starts a cluster of three worker processes and kills some of them: outside the
# default run (bash tests/run.sh -m slow)
pytestmark = pytest.mark.slow

RUNS, CHUNK, SEED = 24, 2, 11


@pytest.fixture(scope="module")
def scenario():
    return ins_scenario(duration=120.0)


@pytest.fixture(scope="module")
def local(scenario):
    return monte_carlo(scenario, runs=RUNS, seed=SEED)


@pytest.fixture
def client():
    """A fresh cluster of three worker processes per test (its nannies restart killed
    workers)."""
    with distributed.LocalCluster(n_workers=3, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50) as cluster, distributed.Client(cluster) as c:
        c.wait_for_workers(3, timeout=120)
        yield c


def _kill(client, how_many: int) -> list[int]:
    """SIGKILL ``how_many`` worker processes (their nannies start new ones)."""
    pids = sorted(client.run(os.getpid).values())
    victims = random.sample(pids, how_many)
    for pid in victims:
        os.kill(pid, signal.SIGKILL)
    return victims


def _check(result, local):
    """Every run in ``result`` equals the in-process run of the same number."""
    rows = local.table[local.table["run"].isin(result.runs)].reset_index(drop=True)
    assert result.table.reset_index(drop=True).equals(rows)
    at = np.searchsorted(local.runs, result.runs)
    assert np.array_equal(result.nees, local.nees[at]) and np.array_equal(result.nis, local.nis[at], equal_nan=True)


def _campaign(scenario, client, local):
    """Run the campaign; a complete result must equal the local one, an incomplete one
    must carry every finished run unchanged and name the missing ones."""
    try:
        result = monte_carlo(scenario, runs=RUNS, seed=SEED, client=client, chunk=CHUNK)
    except MonteCarloIncomplete as e:
        _check(e.partial, local)
        assert sorted(set(e.partial.runs) | set(e.missing)) == list(range(RUNS)) and e.missing
        return e.partial
    _check(result, local)
    assert list(result.runs) == list(range(RUNS))
    return result


def test_killing_a_worker_while_inputs_are_sent_loses_nothing(scenario, local, client, monkeypatch):
    """The first submission (the scenario going to the cluster) kills a worker first."""
    submit, fired = client.submit, []

    def killing_submit(*a, **kw):
        if not fired:
            fired.extend(_kill(client, 1))
        return submit(*a, **kw)

    monkeypatch.setattr(client, "submit", killing_submit)
    result = _campaign(scenario, client, local)
    assert fired and len(result.runs) == RUNS


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("victims", [1, 2])
def test_killing_workers_at_a_random_moment_keeps_every_finished_run(scenario, local, client, victims, seed):
    """Kill ``victims`` of the three worker processes after a random delay (before any
    run finished, mid-campaign or near the end)."""
    random.seed(seed * 10 + victims)
    delay = random.uniform(0.0, 1.5)
    killer = threading.Timer(delay, _kill, args=(client, victims))
    killer.start()
    try:
        result = _campaign(scenario, client, local)
    finally:
        killer.join()
    assert len(result.runs) == RUNS, f"runs lost after killing {victims} worker(s) at {delay:.2f} s"


def test_runs_that_keep_failing_are_reported_with_the_finished_ones(scenario, local, client, monkeypatch):
    """A group that fails on every attempt (here: the one holding run 5) is retried, then
    reported in ``MonteCarloIncomplete.missing``; every other run is in ``.partial``."""
    from atomnav.filter import analysis

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
