"""Covariance analysis, NEES consistency, open vs closed loop, Monte Carlo (local and Dask)
on a linearised 15-state INS with 1 Hz position aiding."""

import numpy as np
import pytest

from atomnav.filter import (BiasModel, Layout, Scenario, chi2_band, covariance_analysis, dare, discretize,
                            ins_error_model, monte_carlo)

G = 9.80665
DT = 0.2  # filter step (s)


def ins_scenario(duration=120.0, method="van_loan", sequential=False, sigma_pos=1.0):
    """Static navigation-grade INS at 46° N, position fixes at 1 Hz."""
    steps = int(round(duration / DT))
    lay = Layout()
    one = lambda row: np.repeat(np.asarray([row], float), steps, axis=0)
    f, qc = ins_error_model(one([0.8, 0.2, 100.0]), one([0, 0, 0]), one([1, 0, 0, 0]), one([0, 0, -G]),
                            accel_psd=(5e-5) ** 2, gyro_psd=(1e-6) ** 2,
                            accel_bias=BiasModel("random_walk", psd=1e-10),
                            gyro_bias=BiasModel("gauss_markov", tau=300.0, sigma=1e-6), layout=lay)
    p0 = np.diag(np.r_[[4.0] * 3, [0.01] * 3, [1e-6] * 3, [(1e-3) ** 2] * 3, [(1e-6) ** 2] * 3])
    h = np.zeros((3, 15))
    h[:, lay["position"]] = np.eye(3)
    every = int(round(1.0 / DT))
    measure = [k % every == 0 and k > 0 for k in range(steps + 1)]
    return Scenario(f, qc, np.full(steps, DT), p0, h, np.eye(3) * sigma_pos**2, measure,
                    labels=lay.labels, method=method, sequential=sequential)


def test_covariance_analysis_matches_numpy_recursion():
    scn = ins_scenario(duration=20.0)
    sig = covariance_analysis(scn)
    a = scn._args
    phi, qd = discretize(a["f"][0], a["qc"][0], DT)
    p = a["p0"].copy()
    out = []
    for k, m in enumerate(a["measure"]):
        if k > 0:
            p = phi @ p @ phi.T + qd
        if m:
            s = a["h"] @ p @ a["h"].T + a["r"]
            kk = p @ a["h"].T @ np.linalg.inv(s)
            p = (np.eye(15) - kk @ a["h"]) @ p @ (np.eye(15) - kk @ a["h"]).T + kk @ a["r"] @ kk.T
        out.append(np.sqrt(np.diag(p)))
    assert np.allclose(sig.drop(columns="time_s").to_numpy(), np.array(out), rtol=1e-9, atol=0)
    assert list(sig.columns[:3]) == ["time_s", "position[0]", "position[1]"]


def test_covariance_steady_state_equals_dare():
    """A constant-model scenario's σ at a measurement epoch tends to the DARE a-posteriori σ."""
    q = [[0.0, 0.0], [0.0, 0.4]]
    f = np.repeat([[[0.0, 1.0], [0.0, -0.1]]], 400, axis=0)
    scn = Scenario(f, np.repeat([q], 400, axis=0), np.full(400, 0.5), np.eye(2), [[1.0, 0.0]], [[0.2]], [True] * 401)
    phi, qd = discretize(f[0], q, 0.5)
    ss = dare(phi, qd, [[1.0, 0.0]], [[0.2]])
    last = covariance_analysis(scn).iloc[-1]
    assert last["x[0]"] ** 2 == pytest.approx(ss.p_post[0, 0], rel=1e-9)
    assert last["x[1]"] ** 2 == pytest.approx(ss.p_post[1, 1], rel=1e-9)


def _nees_fraction(runs, method, seeds, duration=120.0):
    """Fraction of (master seed, epoch) pairs whose run-averaged NEES lies in the 95 % χ²
    band, pooled over independent master seeds. One master seed alone is a poor sample:
    unobservable states (yaw, vertical gyro bias) keep each run's initial draw, so the
    epochs of one campaign are strongly correlated and a consistent filter fails the
    "≥ 90 % of epochs" criterion for about a third of single seeds (measured 4 of 12
    with 100 runs); pooled over seeds the expected fraction is 0.95."""
    scn = ins_scenario(method=method, duration=duration)
    fr = [monte_carlo(scn, runs=runs, seed=s).nees_inside(dof=15) for s in seeds]
    return float(np.mean(fr)), fr


def test_nees_inside_chi2_band_reduced():
    frac, fr = _nees_fraction(30, "van_loan", range(8), duration=60.0)
    assert frac >= 0.90, fr


def test_monte_carlo_table_layout():
    mc = monte_carlo(ins_scenario(duration=10.0), runs=3, seed=1)
    assert list(mc.table.columns) == ["run", "time_s", "state", "error", "sigma"]
    assert len(mc.table) == 3 * len(mc.times) * 15
    assert mc.table["state"].iloc[14] == "gyro_bias[2]" and mc.table["time_s"].iloc[15] == DT


@pytest.mark.slow
def test_nees_inside_chi2_band_100_runs():
    frac, fr = _nees_fraction(100, "van_loan", range(10))
    assert frac >= 0.90, fr


@pytest.mark.slow
def test_nees_first_order_discretisation_100_runs():
    # Documented result (report): at Δt = 0.2 s the first-order Φ, Q_d keep the NEES in the band.
    frac, fr = _nees_fraction(100, "first_order", range(10))
    assert frac >= 0.90, fr


def test_nis_average_inside_band():
    mc = monte_carlo(ins_scenario(), runs=30, seed=7)
    lo, hi = chi2_band(3, 30)
    m = mc.nis[:, ~np.isnan(mc.nis[0])].mean(axis=0)
    assert m.size == 120
    assert np.mean((m >= lo) & (m <= hi)) >= 0.9


def test_open_and_closed_loop_give_the_same_estimate():
    scn = ins_scenario(duration=60.0)
    a = monte_carlo(scn, runs=3, seed=99, mode="open").table
    b = monte_carlo(scn, runs=3, seed=99, mode="closed").table
    assert np.array_equal(a["sigma"].to_numpy(), b["sigma"].to_numpy())
    err = a["error"].to_numpy()
    assert np.max(np.abs(err - b["error"].to_numpy()) / (np.abs(err) + 1e-300)) < 1e-6


def test_sequential_and_stacked_monte_carlo_agree():
    a = monte_carlo(ins_scenario(duration=30.0), runs=2, seed=3).table
    b = monte_carlo(ins_scenario(duration=30.0, sequential=True), runs=2, seed=3).table
    assert np.allclose(a["error"], b["error"], rtol=1e-8, atol=1e-12)


def test_seeds_are_per_run():
    scn = ins_scenario(duration=10.0)
    full = monte_carlo(scn, runs=4, seed=5).table
    again = monte_carlo(scn, runs=4, seed=5).table
    other = monte_carlo(scn, runs=4, seed=6).table
    assert full.equals(again) and not np.allclose(full["error"], other["error"])


def test_dask_local_cluster_gives_identical_table():
    distributed = pytest.importorskip("distributed")
    scn = ins_scenario(duration=20.0)
    local = monte_carlo(scn, runs=6, seed=123)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = monte_carlo(scn, runs=6, seed=123, client=client, chunk=2)
    assert local.table.equals(remote.table)
    assert np.array_equal(local.nees, remote.nees)


def test_bad_monte_carlo_runs():
    with pytest.raises(ValueError, match="runs: must be >= 1"):
        monte_carlo(ins_scenario(duration=2.0), runs=0, seed=1)


def test_bad_scenario_measure_length():
    f = np.zeros((3, 1, 1))
    with pytest.raises(ValueError, match=r"measure: expected one flag per epoch \(4\), got 3"):
        Scenario(f, f, np.ones(3), [[1.0]], [[1.0]], [[1.0]], [True] * 3)


def test_bad_scenario_nonpositive_dt():
    f = np.zeros((3, 1, 1))
    with pytest.raises(ValueError, match=r"dt\[1\]: must be finite and > 0"):
        Scenario(f, f, [1.0, 0.0, 1.0], [[1.0]], [[1.0]], [[1.0]], [True] * 4)
