"""GNSS outage analysis (atomnav.filter.outages) on a simulated run with known truth.

Oracles: the trajectory's truth (Trajectory.errors at the scored fixes: noise-free fixes
are the truth, so the scored error is the navigation error), a run built by hand with the
withheld fixes removed (the analysis must run exactly that filter), and the free-inertial
drift bound of the simulated sensor over the window."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import InputError
from atomnav.filter import BiasModel, InsSetup, PositionFixes, aided_ins
from atomnav.filter.outages import outage_analysis, outage_windows

RATE, DURATION = 100.0, 120.0


@pytest.fixture(scope="module")
def run():
    """Two minutes of sinusoidal motion, a tactical-grade IMU (seeded), and noise-free
    position fixes of the truth at 1 Hz."""
    truth = an.trajectory.sinusoidal(DURATION, rate_hz=RATE)
    meas = an.imu.corrupt(truth.ideal_imu("rates"), errors="tactical", dt=1 / RATE, kind="rates", seed=5)
    imu = (meas["time_s"].to_numpy(), meas[[f"gyro_{a}_rad_s" for a in "xyz"]].to_numpy(),
           meas[[f"accel_{a}_mps2" for a in "xyz"]].to_numpy())
    s0 = truth.initial_state()
    p0 = np.diag(np.r_[[0.01] * 3, [1e-4] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])
    setup = InsSetup(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates", p0=p0,
                     accel_psd=1e-6, gyro_psd=1e-9, accel_bias=BiasModel("random_walk", psd=1e-9),
                     gyro_bias=BiasModel("random_walk", psd=1e-14), predict_every=10)
    t = np.arange(1.0, DURATION + 1e-9, 1.0)
    k = np.searchsorted(truth.time, t)
    fixes = PositionFixes(t, truth.lla[k], np.eye(3) * 0.01)
    return dict(truth=truth, imu=imu, setup=setup, fixes=fixes, meas=meas)


@pytest.fixture(scope="module")
def analysis(run):
    windows = outage_windows(run["fixes"].time, length=15.0, first=25.0, spacing=40.0)
    return windows, outage_analysis(run["setup"], run["fixes"], run["imu"], windows, progress=False)


def test_windows_follow_the_schedule(analysis):
    windows, out = analysis
    np.testing.assert_array_equal(windows, [[26.0, 41.0], [66.0, 81.0], [106.0, 121.0]][:len(windows)])
    assert len(windows) == 2  # a third window (106 to 121 s) would end after the last fix (120 s)
    assert list(out.table["solution"]) == ["forward", "forward", "smoothed", "smoothed"]
    assert (out.table["fixes"] == 15).all()


def test_the_run_is_the_filter_without_the_withheld_fixes(run, analysis):
    windows, out = analysis
    f = run["fixes"]
    inside = np.zeros(len(f), bool)
    for start, end in windows:
        inside |= (f.time >= start) & (f.time < end)
    kept = PositionFixes(f.time[~inside], f.value[~inside], f.cov[~inside])
    setup = InsSetup.from_dict({**run["setup"].to_dict(), "smooth": True})
    want = aided_ins(setup, kept).run(*run["imu"], progress=False)
    pd.testing.assert_frame_equal(out.result.nav, want.nav, check_exact=True)
    pd.testing.assert_frame_equal(out.result.smoothed.nav, want.smoothed.nav, check_exact=True)
    assert not np.isin(out.result.measurements["time_s"], f.time[inside]).any()


def test_scored_errors_are_the_navigation_errors_against_the_truth(run, analysis):
    _, out = analysis
    truth = run["truth"]
    for solution, nav in (("forward", out.result.nav), ("smoothed", out.result.smoothed.nav)):
        err = truth.errors(nav)  # NED errors at the solution's epochs, against the truth
        rows = out.errors[out.errors["solution"] == solution]
        want = np.column_stack([np.interp(rows["time_s"], err["time_s"], err[c]) for c in ("dpos_n_m", "dpos_e_m", "dpos_d_m")])
        got = rows[["error_n_m", "error_e_m", "error_d_m"]].to_numpy()
        # the two interpolate between solution epochs 0.1 s apart in different frames (NED at
        # the reference vs at the solution): they agree far below the metre-level drift
        np.testing.assert_allclose(got, want, atol=2e-3)
        table = out.table[out.table["solution"] == solution]
        for k, row in table.iterrows():
            w = rows[rows["window"] == row["window"]]
            assert row["max_error_m"] == pytest.approx(np.linalg.norm(want[w.index - rows.index[0]], axis=1).max(), abs=2e-3)


def test_drift_grows_in_the_outage_stays_inside_the_free_inertial_bound_and_smoothing_helps(run, analysis):
    _, out = analysis
    fwd = out.table[out.table["solution"] == "forward"]
    smo = out.table[out.table["solution"] == "smoothed"]
    # the forward error grows through the window: the end error is the largest or close to it
    assert (fwd["end_error_m"].to_numpy() >= 0.5 * fwd["max_error_m"].to_numpy()).all()
    # free-inertial bound over 15 s from the tactical preset: ½ b_a t² + f b_g t³/6 with the
    # largest simulated biases, plus 3σ of the white-noise random walks (Titterton & Weston 2004, §12.3)
    m = run["meas"]
    b_a = np.linalg.norm(m.filter(like="accel_bias_").to_numpy(), axis=1).max()
    b_g = np.linalg.norm(m.filter(like="gyro_bias_").to_numpy(), axis=1).max()
    tac = an.imu.ImuErrors.preset("tactical")
    t, f = 16.0, 9.9
    bound = 0.5 * b_a * t**2 + f * b_g * t**3 / 6 + 3 * np.sqrt(3) * (tac.accel.white * t**1.5 / np.sqrt(3))
    assert (fwd["max_error_m"] < bound).all(), (fwd["max_error_m"].tolist(), bound)
    assert (fwd["max_error_m"] > 0.05).all()  # the windows did withhold something
    assert (smo["max_error_m"].to_numpy() < fwd["max_error_m"].to_numpy()).all()
    # the stated σ covers the end error (3σ)
    assert (fwd["end_error_m"] < 3 * fwd["end_sigma_m"]).all()


@pytest.mark.parametrize("windows, row, words", [
    ([[0.0, 10.0]], 0, "outside the fixes"),
    ([[30.0, 45.0], [40.0, 50.0]], 1, "before window 0 ends"),
    ([[30.0, 20.0]], 0, "not an interval"),
    ([[30.5, 30.9]], 0, "holds no fix"),
])
def test_bad_windows_name_windows_and_row(run, windows, row, words):
    with pytest.raises(InputError, match=words) as e:
        outage_analysis(run["setup"], run["fixes"], run["imu"], windows, progress=False)
    assert (e.value.parameter, e.value.index) == ("windows", row)


def test_bad_schedules_name_the_argument(run):
    t = run["fixes"].time
    for kw, name in [(dict(length=15.0, first=110.0), "length"), (dict(length=15.0, first=25.0, spacing=10.0), "spacing"),
                     (dict(length=-1.0, first=25.0), "length"), (dict(length=15.0, first=-3.0), "first")]:
        with pytest.raises(InputError) as e:
            outage_windows(t, **kw)
        assert e.value.parameter == name
    for bad in (np.zeros(0), np.zeros((0, 1, 1)), [5.0], [[1.0, 2.0]]):
        with pytest.raises(InputError) as e:
            outage_windows(bad, length=15.0, first=0.0)
        assert e.value.parameter == "time"


def test_plot_draws_every_scored_fix_and_shades_the_windows(analysis):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    windows, out = analysis
    fig = an.plots.outages(out)
    ax = fig.axes[0]
    assert len(ax.patches) == len(windows)
    # solid lines: the errors, dashed: 3σ, window by window, forward first (the order of out.errors)
    solid = np.concatenate([ln.get_ydata() for ln in ax.lines if ln.get_linestyle() == "-"])
    dashed = np.concatenate([ln.get_ydata() for ln in ax.lines if ln.get_linestyle() == "--"])
    np.testing.assert_array_equal(solid, out.errors["error_m"].to_numpy())
    np.testing.assert_array_equal(dashed, 3.0 * out.errors["sigma_m"].to_numpy())
    assert ax.get_ylabel() == "3-D position error (m)" and ax.get_xlabel() == "time (s)"
    plt.close(fig)
    with pytest.raises(TypeError, match="result"):
        an.plots.outages(out.table)


def test_result_pickles(analysis):
    import pickle

    _, out = analysis
    back = pickle.loads(pickle.dumps(out))
    pd.testing.assert_frame_equal(back.table, out.table, check_exact=True)
    pd.testing.assert_frame_equal(back.errors, out.errors, check_exact=True)
    pd.testing.assert_frame_equal(back.result.smoothed.nav, out.result.smoothed.nav, check_exact=True)


def test_velocity_fixes_of_the_receiver_are_withheld_too(run):
    f = run["fixes"]
    truth = run["truth"]
    vel = an.filter.VelocityFixes(f.time, truth.vel_ned[np.searchsorted(truth.time, f.time)], np.eye(3) * 1e-4)
    windows = [[30.0, 45.0]]
    out = outage_analysis(run["setup"], f, run["imu"], windows, withhold=[vel], progress=False)
    applied = out.result.measurements
    assert not ((applied["time_s"] >= 30.0) & (applied["time_s"] < 45.0)).any()
    assert (applied["source"] == "velocity_fixes").sum() == len(f) - 15
    with pytest.raises(TypeError, match="withhold"):
        outage_analysis(run["setup"], f, run["imu"], windows, withhold=[an.filter.ZeroVelocity([10.0], 0.01)], progress=False)


def test_another_programs_solution_is_scored_the_same_way(run, analysis):
    """A solution table of another program (positions, and σ as RTKLIB writes it: NED
    covariance columns) is scored like atomnav's own."""
    windows, out = analysis
    nav = out.result.nav
    other = pd.DataFrame({"time_s": nav["time_s"], "lat_rad": nav["lat_rad"], "lon_rad": nav["lon_rad"], "h_m": nav["h_m"],
                          **{f"cov_{a}_m2": nav[f"sigma_position[{i}]"] ** 2 for i, a in enumerate(("nn", "ee", "dd"))}})
    table, errors = an.filter.score_outages(other, run["fixes"], windows, solution="forward")
    want = out.table[out.table["solution"] == "forward"].reset_index(drop=True)
    pd.testing.assert_frame_equal(table, want, check_exact=False, rtol=1e-12)
    bare, _ = an.filter.score_outages(other[["time_s", "lat_rad", "lon_rad", "h_m"]], run["fixes"], windows)
    assert "end_sigma_m" not in bare and not bare.isna().any().any()
    with pytest.raises(InputError) as e:
        an.filter.score_outages(other[other["time_s"] < 50.0], run["fixes"], windows)
    assert e.value.parameter == "nav"
    with pytest.raises(InputError, match="every axis") as e:
        an.filter.score_outages(other.drop(columns=["cov_dd_m2"]), run["fixes"], windows)
    assert e.value.parameter == "nav"
