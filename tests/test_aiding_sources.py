"""Several measurement sources feeding one aided INS (atomnav.filter.aided_ins): velocity
fixes on the library's own simulated run (consistency against the truth, and against
position fixes alone), a composite of one source equal to the single-sensor factories,
bad input naming the argument of the user's call, and a pickle taken mid-record."""

import copy
import pickle

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import InputError
from atomnav.filter import BiasModel, InsSetup, PositionFixes, VelocityFixes, ZeroVelocity, aided_ins, position_aided_ins

RATE, DURATION = 100.0, 300.0
SIGMA_VEL, SIGMA_POS = 0.05, 2.0  # fix noise: m/s, m
VEL = ["dvel_n_mps", "dvel_e_mps", "dvel_d_mps"]


@pytest.fixture(scope="module")
def run():
    """A 5-minute sinusoidal run with a tactical-grade IMU (seeded), and 1 Hz velocity and
    position fixes of the truth with seeded white noise of σ SIGMA_VEL and SIGMA_POS."""
    truth = an.trajectory.sinusoidal(DURATION, rate_hz=RATE)
    meas = an.imu.corrupt(truth.ideal_imu("rates"), errors="tactical", dt=1 / RATE, kind="rates", seed=5)
    imu = (meas["time_s"].to_numpy(), meas[[f"gyro_{a}_rad_s" for a in "xyz"]].to_numpy(),
           meas[[f"accel_{a}_mps2" for a in "xyz"]].to_numpy())
    s0 = truth.initial_state()
    # the tactical preset: 1 mg / 1 °/h turn-on biases, 100 µg/√Hz and 0.1 °/√h white noise,
    # flicker bias instability (modelled as a slow random walk)
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])
    setup = InsSetup(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates", p0=p0,
                     accel_psd=1e-6, gyro_psd=1e-9, accel_bias=BiasModel("random_walk", psd=1e-9),
                     gyro_bias=BiasModel("random_walk", psd=1e-14), predict_every=10)
    rng = np.random.default_rng(11)
    t = np.arange(1.0, DURATION + 1e-9, 1.0)
    k = np.searchsorted(truth.time, t)
    assert np.array_equal(truth.time[k], t)
    vel = truth.vel_ned[k] + rng.standard_normal((len(t), 3)) * SIGMA_VEL
    lla = truth.lla[k]
    rm, rn = an.earth.radii(lla[:, 0])
    ned = rng.standard_normal((len(t), 3)) * SIGMA_POS
    fix_lla = lla + np.c_[ned[:, 0] / (rm + lla[:, 2]), ned[:, 1] / ((rn + lla[:, 2]) * np.cos(lla[:, 0])), -ned[:, 2]]
    return dict(truth=truth, imu=imu, setup=setup, t=t, vel=vel, lla=fix_lla)


def _velocity(r):
    return VelocityFixes(r["t"], r["vel"], np.eye(3) * SIGMA_VEL**2)


def _position(r):
    return PositionFixes(r["t"], r["lla"], np.eye(3) * SIGMA_POS**2)


def _velocity_error(r, result):
    err = r["truth"].errors(result.nav)
    return err[VEL].to_numpy(), result.nav[[f"sigma_velocity[{i}]" for i in range(3)]].to_numpy()


@pytest.mark.parametrize("mode", ["closed", "open"])
def test_velocity_fixes_keep_the_velocity_error_inside_its_3_sigma(run, mode):
    setup = InsSetup.from_dict({**run["setup"].to_dict(), "mode": mode})
    result = aided_ins(setup, _velocity(run)).run(*run["imu"], progress=False)
    dv, sigma = _velocity_error(run, result)
    assert len(result.nav) == 3000 and len(result.measurements) == 300
    inside = (np.abs(dv) <= 3 * sigma).mean(axis=0)
    assert (inside >= 0.95).all(), inside
    # the fixes bound the error: a free tactical INS drifts by metres per second in 5 minutes
    assert np.abs(dv[-600:]).max() < 6 * SIGMA_VEL


def test_position_and_velocity_together_beat_position_alone_in_velocity(run):
    both = aided_ins(run["setup"], [_position(run), _velocity(run)]).run(*run["imu"], progress=False)
    alone = aided_ins(run["setup"], [_position(run)]).run(*run["imu"], progress=False)
    rms = [np.sqrt((_velocity_error(run, r)[0] ** 2).sum(axis=1).mean()) for r in (both, alone)]
    assert rms[0] < 0.5 * rms[1], rms
    # equal times of two sources: both applied at each epoch, position first as given
    assert len(both.measurements) == 600
    assert np.array_equal(both.measurements["time_s"].to_numpy(), np.repeat(run["t"], 2))


def test_a_composite_of_one_source_is_the_position_factory_bit_for_bit(run):
    s = run["setup"]
    factory = position_aided_ins(s.t0, s.lla0, s.vel0, s.q0, "rates", run["t"], run["lla"],
                                 np.tile(np.eye(3) * SIGMA_POS**2, (len(run["t"]), 1, 1)), p0=np.array(s.p0),
                                 accel_psd=s.accel_psd, gyro_psd=s.gyro_psd, accel_bias=s.accel_bias,
                                 gyro_bias=s.gyro_bias, predict_every=s.predict_every)
    want = factory.run(*run["imu"], progress=False)
    got = aided_ins(s, [_position(run)]).run(*run["imu"], progress=False)
    pd.testing.assert_frame_equal(got.nav, want.nav, check_exact=True)
    pd.testing.assert_frame_equal(got.measurements, want.measurements, check_exact=True)
    assert np.array_equal(got.innovation, want.innovation)


def test_a_composite_of_one_gnss_source_is_the_tight_factory_bit_for_bit():
    from atomnav.gnss import GnssObservations, tight_ins
    from atomnav.gnss import scenarios as S

    case = S.build(S.Scenario(duration_s=60.0))
    factory = tight_ins(case["eph"], case["obs"], **case["args"])
    source = GnssObservations(case["eph"], case["obs"], factory.options)
    m = case["imu"]
    imu = (m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
           m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy())
    want = factory.run(*imu, h_ref=case["h_ref"], progress=False)
    got = aided_ins(factory.setup, source).run(*imu, h_ref=case["h_ref"], progress=False)
    assert len(want.measurements) > 0
    pd.testing.assert_frame_equal(got.nav, want.nav, check_exact=True)
    pd.testing.assert_frame_equal(got.measurements, want.measurements, check_exact=True)
    # the extra states of the GNSS sensor follow the INS states, named by it
    assert "extra_c_tau_gps[0]" in got.nav
    # a second GNSS source would carry the same states: refused, naming sources and it
    with pytest.raises(InputError, match='state block "c_tau_gps"') as e:
        aided_ins(factory.setup, [source, source])
    assert (e.value.parameter, e.value.index) == ("sources", 1)


def test_tables_by_column_name_equal_arrays(run):
    """A DataFrame in any column order, with extra columns and σ columns, reads like the
    arrays with the diagonal covariance."""
    t, vel = run["t"], run["vel"]
    sig = np.array([0.05, 0.07, 0.1])
    df = pd.DataFrame({"note": "x", "sigma_vd_mps": sig[2], "vd_mps": vel[:, 2], "ve_mps": vel[:, 1], "time_s": t,
                       "vn_mps": vel[:, 0], "sigma_vn_mps": sig[0], "sigma_ve_mps": sig[1]})
    from_table, from_arrays = VelocityFixes(df), VelocityFixes(t, vel, np.diag(sig**2))
    assert np.array_equal(from_table.time, from_arrays.time) and np.array_equal(from_table.value, from_arrays.value)
    assert np.array_equal(from_table.cov, from_arrays.cov)
    lla = run["lla"]
    pos = pd.DataFrame({"time_s": pd.to_timedelta(t, unit="s"), "lat_rad": lla[:, 0], "lon_rad": lla[:, 1], "h_m": lla[:, 2]})
    fixes = PositionFixes(pos, cov=np.eye(3))
    assert np.array_equal(fixes.time, t) and np.array_equal(fixes.value, lla) and fixes.cov.shape == (len(t), 3, 3)
    with pytest.raises(InputError, match="sigma_n_m") as e:
        PositionFixes(pos)
    assert e.value.parameter == "cov"


def test_a_copy_taken_mid_record_continues_bit_for_bit(run):
    t, g, a = run["imu"]
    ins = aided_ins(run["setup"], [_position(run), _velocity(run)])
    half = len(t) // 2 + 37
    ins.process(t[:half], g[:half], a[:half])
    twins = [pickle.loads(pickle.dumps(ins)), copy.deepcopy(ins)]
    assert all(c.labels == ins.labels and c.pending == ins.pending > 0 for c in twins)
    want = ins.process(t[half:], g[half:], a[half:])
    for twin in twins:
        got = twin.process(t[half:], g[half:], a[half:])
        pd.testing.assert_frame_equal(got.nav, want.nav, check_exact=True)
        pd.testing.assert_frame_equal(got.measurements, want.measurements, check_exact=True)


def test_a_source_feeds_any_number_of_ins(run):
    source = _velocity(run)
    t, g, a = (x[:500] for x in run["imu"])
    results = [aided_ins(run["setup"], source).process(t, g, a) for _ in range(2)]
    assert len(results[0].measurements) == 4
    pd.testing.assert_frame_equal(results[0].nav, results[1].nav, check_exact=True)


# ---- bad input names the argument of the call the user made ------------------------------

T = np.array([1.0, 2.0, 3.0])
V = np.zeros((3, 3))
COV = np.tile(np.eye(3) * 0.01, (3, 1, 1))
LLA = np.tile([0.8, 0.2, 100.0], (3, 1))


def _raises(call, parameter, index=None):
    with pytest.raises(InputError) as e:
        call()
    assert (e.value.parameter, e.value.index) == (parameter, index), str(e.value)
    return str(e.value)


def test_bad_shapes_name_the_argument():
    _raises(lambda: VelocityFixes(T, np.zeros((3, 2)), COV), "vel_ned")
    _raises(lambda: VelocityFixes(T, np.zeros((2, 3)), COV), "vel_ned")
    _raises(lambda: VelocityFixes(T, V, np.zeros((3, 3, 2))), "cov")
    _raises(lambda: VelocityFixes(T, V, COV[:2]), "cov")
    _raises(lambda: PositionFixes(T, LLA[:, :2], COV), "lla")
    _raises(lambda: PositionFixes(T[:, None], LLA, COV), "time")
    _raises(lambda: VelocityFixes(T, None, COV), "vel_ned")
    _raises(lambda: VelocityFixes(T, V), "cov")


def test_covariance_not_positive_definite_names_cov_and_its_row():
    cov = COV.copy()
    cov[1] = np.diag([0.01, -0.01, 0.01])
    assert "not positive definite" in _raises(lambda: VelocityFixes(T, V, cov), "cov", 1)
    cov[1] = [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]
    assert "not symmetric" in _raises(lambda: PositionFixes(T, LLA, cov), "cov", 1)


def test_nan_names_the_argument_and_its_row():
    v = V.copy()
    v[2, 1] = np.nan
    _raises(lambda: VelocityFixes(T, v, COV), "vel_ned", 2)
    _raises(lambda: VelocityFixes(np.array([1.0, np.nan, 3.0]), V, COV), "time", 1)
    cov = COV.copy()
    cov[0, 2, 2] = np.nan
    _raises(lambda: PositionFixes(T, LLA, cov), "cov", 0)
    df = pd.DataFrame({"time_s": T, "vn_mps": [0.0, pd.NA, 0.0], "ve_mps": 0.0, "vd_mps": 0.0}).astype("Float64")
    assert "vn_mps" in _raises(lambda: VelocityFixes(df, cov=COV), "time", 1)


def test_time_not_increasing_names_time_and_its_row():
    assert "decreasing" in _raises(lambda: VelocityFixes(np.array([1.0, 3.0, 2.0]), V, COV), "time", 2)
    assert "duplicated" in _raises(lambda: PositionFixes(np.array([1.0, 1.0, 2.0]), LLA, COV), "time", 1)


def test_latitude_beyond_half_pi_names_lla_and_its_row():
    lla = LLA.copy()
    lla[1, 0] = 45.8  # degrees
    _raises(lambda: PositionFixes(T, lla, COV), "lla", 1)


def test_a_source_feeds_any_number_of_ins_and_bad_source_lists_name_sources(run):
    zupt = ZeroVelocity(np.array([1.0, 2.0]), 0.01)
    fixes = _velocity(run)
    first = aided_ins(run["setup"], [fixes, zupt]).run(*run["imu"], progress=False)
    again = aided_ins(run["setup"], [fixes, zupt]).run(*run["imu"], progress=False)
    pd.testing.assert_frame_equal(first.nav, again.nav, check_exact=True)
    assert (first.measurements["source"] == "zero_velocity").sum() == 2
    with pytest.raises(TypeError, match="sources"):
        aided_ins(run["setup"], [fixes, "velocity.csv"])
    with pytest.raises(TypeError, match="sources"):
        aided_ins(run["setup"], "velocity.csv")
    with pytest.raises(TypeError, match="setup"):
        aided_ins({"t0": 0.0}, [fixes])


def test_fix_outside_the_imu_record_names_time(run):
    late = VelocityFixes(np.array([DURATION + 5.0]), np.zeros((1, 3)), np.eye(3))
    t, g, a = run["imu"]
    with pytest.raises(InputError, match="outside the IMU span") as e:
        aided_ins(run["setup"], [_velocity(run), late]).run(t, g, a, progress=False)
    assert e.value.parameter == "time"


# ---- which source each measurement came from ----------------------------------------------

def _first_epoch_at_or_after(imu_t, times):
    """The IMU sample at or after each time: where the engine applies a measurement."""
    return imu_t[np.searchsorted(imu_t, times, side="left")]


def test_each_measurement_names_its_source(run):
    """Position fixes every second (on the IMU grid) and velocity fixes every 2 s between
    IMU samples: the source column counts the fixes of each, its times are each source's
    fix times, its order is the merge of both by time, and the filter has an epoch at the
    first IMU sample at or after every fix. Chunked runs give the same table."""
    n = int(60 * RATE) + 1
    t, g, a = (x[:n] for x in run["imu"])
    t_pos = run["t"][run["t"] <= t[-1]]
    t_vel = np.arange(0.0, 58.0, 2.0) + 1.005  # 1.005, 3.005, ...: between the 10 ms samples
    k = np.searchsorted(run["truth"].time, t_vel)
    pos = PositionFixes(t_pos, run["lla"][: len(t_pos)], np.eye(3) * SIGMA_POS**2)
    vel = VelocityFixes(t_vel, run["truth"].vel_ned[k], np.eye(3) * SIGMA_VEL**2)
    results = [aided_ins(run["setup"], [vel, pos]).run(t, g, a, chunk_s=c, progress=False) for c in (60.0, 7.3)]
    meas = results[0].measurements
    assert meas["source"].value_counts().to_dict() == {"position_fixes": len(t_pos), "velocity_fixes": len(t_vel)}
    for name, times in (("position_fixes", t_pos), ("velocity_fixes", t_vel)):
        assert np.array_equal(meas.loc[meas["source"] == name, "time_s"].to_numpy(), times), name
    merged = np.r_[t_vel, t_pos]
    order = np.argsort(merged, kind="stable")
    labels = np.array(["velocity_fixes"] * len(t_vel) + ["position_fixes"] * len(t_pos))
    assert meas["source"].tolist() == labels[order].tolist()
    epochs = results[0].nav["time_s"].to_numpy()
    assert np.isin(_first_epoch_at_or_after(t, merged), epochs).all()
    assert not np.isin(t_vel, epochs).any()  # the fix times themselves are no IMU samples
    pd.testing.assert_frame_equal(results[1].measurements, meas, check_exact=True)
    # a sensor alone names itself
    alone = aided_ins(run["setup"], pos).run(t, g, a, progress=False).measurements
    assert (alone["source"] == "position_fixes").all() and len(alone) == len(t_pos)


def test_a_skipped_gnss_epoch_leaves_no_row_and_others_keep_their_source():
    """A GNSS epoch with one satellite left (first differences need two) is skipped by the
    sensor: no row for it, while a velocity fix at the same time keeps its row."""
    from atomnav.gnss import GnssObservations, tight_ins
    from atomnav.gnss import scenarios as S

    case = S.build(S.Scenario(duration_s=20.0))
    obs = case["obs"]
    lone = obs["time_s"] == 5.0
    obs = obs[~lone | (obs["sat"] == obs.loc[lone, "sat"].iloc[0])].reset_index(drop=True)
    factory = tight_ins(case["eph"], obs, **case["args"])
    assert factory.options.formulation == "first_difference"
    m = case["imu"]
    imu = (m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
           m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy())
    truth = case["trajectory"]
    vel = VelocityFixes(np.array([5.0, 6.0]), truth.vel_ned[np.searchsorted(truth.time, [5.0, 6.0])], np.eye(3) * 0.01)
    meas = aided_ins(factory.setup, [GnssObservations(case["eph"], obs, factory.options), vel]).run(
        *imu, h_ref=case["h_ref"], progress=False).measurements
    epochs = np.unique(obs["time_s"].to_numpy())
    gnss = meas.loc[meas["source"] == "gnss", "time_s"].to_numpy()
    assert np.array_equal(gnss, epochs[epochs != 5.0])
    assert meas.loc[meas["source"] == "velocity_fixes", "time_s"].tolist() == [5.0, 6.0]
    assert set(meas["source"]) == {"gnss", "velocity_fixes"}
