"""The campaign engine: the same campaign gives the same table in this process, on a Dask
LocalCluster of two worker processes, after an interruption and resume, after a worker is
killed mid-campaign, and after the client process itself is killed; bad campaigns are
refused naming the parameter.

The scenario is a 3-D random walk with a closed-form RMS (√(3 q t)), so the numbers are
also checked against an oracle, not only against each other."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav.campaign import Campaign, load, run, timing

distributed = pytest.importorskip("distributed")

GRID = {"q": [0.5, 1.0, 2.0, 4.0, 8.0], "steps": [10, 20]}   # 10 points
SEEDS = 20                                                  # × 20 = 200 runs


def random_walk(*, seed=0, q=1.0, steps=20, dt=0.5, sleep_s=0.0):
    """A 3-D random walk with step variance q·dt per axis; its error norm has RMS √(3 q t)."""
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(0.0, np.sqrt(q * dt), (steps, 3)), axis=0)
    if sleep_s:
        time.sleep(sleep_s)
    return pd.DataFrame({"time_s": dt * np.arange(1, steps + 1), "pos_error_m": np.linalg.norm(x, axis=1)})


def campaign(**kw):
    return Campaign(random_walk, kw.pop("points", GRID), seeds=kw.pop("seeds", SEEDS), seed=kw.pop("seed", 7), **kw)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    return run(campaign(), tmp_path_factory.mktemp("ref"), threads=2, progress=False)


@pytest.fixture(scope="module")
def cluster():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as lc, Client(lc) as client:
        yield client


def test_table_layout_and_oracle(reference):
    assert len(reference) == sum(s for s in GRID["steps"]) * len(GRID["q"]) * SEEDS
    assert list(reference.columns) == ["run", "point", "replicate", "seed", "q", "steps", "time_s", "pos_error_m"]
    assert reference["run"].is_monotonic_increasing and reference["run"].nunique() == 200
    # every run's seed is the campaign's, and the run's table is the scenario's at that seed
    c = campaign()
    for r in (0, 57, 199):
        rows = reference[reference["run"] == r]
        p = c.point(r // SEEDS)
        assert int(rows["seed"].iloc[0]) == c.run_seed(r)
        expected = random_walk(seed=c.run_seed(r), **p)
        np.testing.assert_array_equal(rows["pos_error_m"].to_numpy(), expected["pos_error_m"].to_numpy())
    # the RMS over 20 seeds and the steps of a point against √(3 q t): the mean of norm²/(3qt)
    # over 20 runs × (10 or 20) correlated steps is ≈ 1 ± 0.15 (3σ of the run average)
    last = reference.groupby("run").tail(1)
    ratio = (last["pos_error_m"] ** 2 / (3 * last["q"] * last["time_s"])).groupby(last["point"]).mean()
    assert ratio.between(0.4, 1.9).all()
    assert abs(ratio.mean() - 1.0) < 0.15


def test_seeds_depend_on_campaign_seed_and_run_only():
    a, b = campaign(), Campaign(random_walk, [{"q": 9.0}] * 11, seeds=SEEDS, seed=7)
    assert [a.run_seed(r) for r in range(200)] == [b.run_seed(r) for r in range(200)]
    assert len({a.run_seed(r) for r in range(200)}) == 200
    assert a.run_seed(3) != campaign(seed=8).run_seed(3)


def test_dask_local_cluster_gives_the_same_table(reference, cluster, tmp_path):
    got = run(campaign(fixed={"sleep_s": 0.002}), tmp_path, client=cluster, progress=False)
    pd.testing.assert_frame_equal(got.drop(columns="sleep_s"), reference)
    workers = set(timing(tmp_path, "random_walk")["worker"])
    assert len(workers) == 2 and "local" not in workers


def test_interrupted_then_resumed_gives_the_same_table(reference, tmp_path):
    seen = []

    def stop_half(done, total):
        seen.append(done)
        if done >= total // 2:
            raise KeyboardInterrupt

    slow = campaign(fixed={"sleep_s": 0.01})
    with pytest.raises(KeyboardInterrupt):
        run(slow, tmp_path, threads=2, progress=False, callback=stop_half)
    first = load(tmp_path, "random_walk")["run"].nunique()
    assert 100 <= first < 200
    resumed = []
    got = run(slow, tmp_path, threads=2, progress=False, callback=lambda d, t: resumed.append(d))
    pd.testing.assert_frame_equal(got.drop(columns="sleep_s"), reference)
    assert resumed[0] > first and resumed[-1] == 200   # only the missing runs were computed


def test_killed_worker_loses_nothing(reference, tmp_path):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as lc, Client(lc) as client:
        pids = list(client.run(os.getpid).values())
        killed = []

        def kill_one(done, total):
            if done >= 40 and not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(done)

        got = run(campaign(points={**GRID}, fixed={"sleep_s": 0.01}), tmp_path, client=client, batch=2, progress=False,
                  callback=kill_one)
    assert killed and killed[0] < 200
    pd.testing.assert_frame_equal(got.drop(columns="sleep_s"), reference)


def test_killed_client_process_resumes(reference, tmp_path):
    script = textwrap.dedent(f"""
        import sys; sys.path.insert(0, {os.path.dirname(__file__)!r})
        from test_campaign_engine import campaign, run
        run(campaign(fixed={{"sleep_s": 0.02}}), {str(tmp_path)!r}, threads=1, progress=False)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script])
    runs = tmp_path / "random_walk" / "runs"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list(runs.glob("point=*/part-*.parquet"))) < 3:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = load(tmp_path, "random_walk")["run"].nunique()
    assert 0 < before < 200
    got = run(campaign(fixed={"sleep_s": 0.02}), tmp_path, threads=2, progress=False)
    pd.testing.assert_frame_equal(got.drop(columns="sleep_s"), reference)


def test_campaign_pickles_whole():
    import pickle

    c = campaign(fixed={"dt": 0.25})
    back = pickle.loads(pickle.dumps(c))
    assert back == c and back.n_runs == c.n_runs and [back.run_seed(r) for r in (0, 199)] == [c.run_seed(r) for r in (0, 199)]
    assert back.point(7) == c.point(7)


def test_config_saved_beside_the_runs(tmp_path):
    c = campaign(points={"q": [1.0]}, seeds=3)
    run(c, tmp_path, progress=False)
    saved = json.loads((tmp_path / "random_walk" / "campaign.json").read_text())
    assert saved["scenario"] == "test_campaign_engine:random_walk" and saved["seeds"] == 3 and saved["points"] == {"q": [1.0]}
    assert Campaign.from_dict(saved) == c


@pytest.mark.parametrize("kwargs, parameter", [
    (dict(points={"qq": [1.0]}), "points"),
    (dict(points={"q": []}), "points"),
    (dict(points={}), "points"),
    (dict(points=[]), "points"),
    (dict(points=[{"q": 1.0}, {"nope": 2}]), "points"),
    (dict(fixed={"nope": 1}), "fixed"),
    (dict(seeds=0), "seeds"),
    (dict(seed=-1), "seed"),
    (dict(points={"q": [float("nan")]}), "points"),
    (dict(name="a/b"), "name"),
])
def test_bad_campaigns_name_the_parameter(kwargs, parameter):
    with pytest.raises(an.InputError) as e:
        campaign(**kwargs)
    assert e.value.parameter == parameter


def test_bad_types():
    with pytest.raises(TypeError):
        Campaign(random_walk, {"q": 1.0})
    with pytest.raises(TypeError):
        Campaign(lambda q=1.0: None, {"q": [1.0]})        # no seed keyword
    with pytest.raises(TypeError):
        run("campaign", "/tmp")


def test_seed_collision_in_one_folder(tmp_path):
    run(campaign(points={"q": [1.0]}, seeds=2), tmp_path, progress=False)
    with pytest.raises(an.InputError) as e:
        run(campaign(points={"q": [2.0]}, seeds=2, name="other"), tmp_path, progress=False)
    assert e.value.parameter == "seed"
    run(campaign(points={"q": [2.0]}, seeds=2, name="other", seed=8), tmp_path, progress=False)   # another seed is fine


def test_folder_holding_another_campaigns_configuration(tmp_path):
    run(campaign(points={"q": [1.0]}, seeds=2), tmp_path, progress=False)
    with pytest.raises(an.InputError) as e:
        run(campaign(points={"q": [1.0, 2.0]}, seeds=2), tmp_path, progress=False)
    assert e.value.parameter == "folder" and "points" in str(e.value)


def test_unreachable_scheduler_is_a_connection_error(tmp_path):
    with pytest.raises(ConnectionError, match="scheduler"):
        run(campaign(points={"q": [1.0]}), tmp_path, scheduler="tcp://127.0.0.1:9", progress=False)


def test_dataset_reads_with_pandas_and_without_the_scenario(reference, tmp_path):
    """The runs are a Hive-partitioned Parquet dataset any reader takes, and load() needs
    only the folder: the campaign's configuration is read, its scenario not imported."""
    run(campaign(), tmp_path, progress=False)
    raw = pd.read_parquet(tmp_path / "random_walk" / "runs").astype({"point": np.int64})
    raw = raw.sort_values(["run", "time_s"]).reset_index(drop=True)[list(reference.columns)]
    pd.testing.assert_frame_equal(raw, reference)
    config = tmp_path / "random_walk" / "campaign.json"
    config.write_text(config.read_text().replace("test_campaign_engine:random_walk", "gone_module:random_walk"))
    pd.testing.assert_frame_equal(load(tmp_path, "random_walk"), reference)


def test_malformed_scheduler_address_names_scheduler(tmp_path):
    with pytest.raises(an.InputError) as e:
        run(campaign(points={"q": [1.0]}), tmp_path, scheduler="nonsense", progress=False)
    assert e.value.parameter == "scheduler"
