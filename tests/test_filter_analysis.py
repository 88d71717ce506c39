"""Covariance analysis, NEES consistency, open vs closed loop, Monte Carlo (local and Dask)
on a linearised 15-state INS with 1 Hz position aiding."""

import numpy as np
import pytest

from atomnav import InputError
from atomnav.trajectory import sinusoidal
from atomnav.filter import (BiasModel, Layout, Scenario, chi2_band, covariance_analysis, dare, discretize,
                            ins_error_model, monte_carlo)

G = 9.80665
DT = 0.2  # filter step (s)


def ins_scenario(duration=120.0, method="van_loan", sequential=False, sigma_pos=1.0, moving=False):
    """Navigation-grade INS at 46° N with position fixes at 1 Hz: static, or (``moving``)
    on a horizontal sinusoidal path (±200 m N, ±150 m E), whose accelerations make yaw and
    the gyro biases observable."""
    steps = int(round(duration / DT))
    lay = Layout()
    if moving:
        truth = sinusoidal(duration, rate_hz=1 / DT, origin=(0.8, 0.2, 100.0), amp_ned=(200.0, 150.0, 2.0))
        lla, vel, q = truth.lla[1:], truth.vel_ned[1:], truth.q_nb[1:]
        f_b = truth.ideal_imu("rates")[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()[1:]
    else:
        one = lambda row: np.repeat(np.asarray([row], float), steps, axis=0)
        lla, vel, q, f_b = one([0.8, 0.2, 100.0]), one([0, 0, 0]), one([1, 0, 0, 0]), one([0, 0, -G])
    f, qc = ins_error_model(lla, vel, q, f_b, accel_psd=(5e-5) ** 2, gyro_psd=(1e-6) ** 2,
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


def _nees_fraction(method, seed, runs=100):
    """Fraction of epochs whose NEES averaged over ``runs`` runs lies in the 95 % χ² band
    (15 states), 10 min on the moving path."""
    return monte_carlo(ins_scenario(duration=600.0, method=method, moving=True), runs=runs, seed=seed).nees_inside(dof=15)


def test_nees_inside_chi2_band_100_runs():
    """Issue 3 acceptance: 100 runs, ≥ 90 % of epochs in the band (master seed 0: 0.976)."""
    assert _nees_fraction("van_loan", seed=0) >= 0.90


def test_monte_carlo_table_layout():
    mc = monte_carlo(ins_scenario(duration=10.0), runs=3, seed=1)
    assert list(mc.table.columns) == ["run", "time_s", "state", "error", "sigma"]
    assert len(mc.table) == 3 * len(mc.times) * 15
    assert mc.table["state"].iloc[14] == "gyro_bias[2]" and mc.table["time_s"].iloc[15] == DT


@pytest.mark.slow
def test_nees_first_order_discretisation_100_runs():
    """First-order Φ, Q_d at Δt = 0.2 s: as consistent as Van Loan (seed 0: 0.975 vs 0.976)."""
    assert _nees_fraction("first_order", seed=0) >= 0.90


@pytest.mark.slow
def test_nees_over_master_seeds():
    """The criterion over 12 independent master seeds. It is a statistic of correlated
    epochs — the slowly observable states (yaw, gyro biases) keep each run's draw for
    minutes, shifting a whole campaign's average NEES together — so a consistent filter
    fails it for some seeds (measured: 1 of 12, seed 11 at 0.854, with every state's
    mean normalised squared error within 0.8–1.1). Pooled, the fraction is ≈ 0.97."""
    fr = [_nees_fraction("van_loan", seed=s) for s in range(12)]
    assert np.mean(fr) >= 0.90 and sum(f >= 0.90 for f in fr) >= 10, fr


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
    with pytest.raises(ValueError, match=r"runs: must be an integer in \[1, ") as info:
        monte_carlo(ins_scenario(duration=2.0), runs=0, seed=1)
    assert isinstance(info.value, InputError) and info.value.parameter == "runs"


@pytest.mark.parametrize("name, value, error, match", [
    ("seed", -1, InputError, r"seed: must be an integer in \[0, 18446744073709551615\], got -1"),
    ("seed", 2**64, InputError, r"seed: must be an integer in \[0, 18446744073709551615\], got 18446744073709551616"),
    ("chunk", 0, InputError, r"chunk: must be an integer in \[1, 4294967296\], got 0"),
    ("retries", -1, InputError, r"retries: must be an integer in \[0, 1000\], got -1"),
    ("runs", 2.5, TypeError, "runs: expected an integer, got float 2.5"),
    ("seed", "1", TypeError, "seed: expected an integer, got str"),
])
def test_bad_monte_carlo_counts(name, value, error, match):
    kw = dict(runs=2, seed=1) | {name: value}
    with pytest.raises(error, match=match) as info:
        monte_carlo(ins_scenario(duration=2.0), **kw)
    if error is InputError:
        assert info.value.parameter == name


def test_local_result_numbers_every_run():
    mc = monte_carlo(ins_scenario(duration=4.0), runs=3, seed=2)
    assert list(mc.runs) == [0, 1, 2] and mc.nees.shape[0] == 3


def test_bad_scenario_measure_length():
    f = np.zeros((3, 1, 1))
    with pytest.raises(ValueError, match=r"measure: expected one flag per epoch \(4\), got 3"):
        Scenario(f, f, np.ones(3), [[1.0]], [[1.0]], [[1.0]], [True] * 3)


def test_bad_scenario_nonpositive_dt():
    f = np.zeros((3, 1, 1))
    with pytest.raises(ValueError, match=r"dt\[1\]: must be finite and > 0"):
        Scenario(f, f, [1.0, 0.0, 1.0], [[1.0]], [[1.0]], [[1.0]], [True] * 4)
