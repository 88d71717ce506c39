"""CAI-aided navigation on your own data: a Monte-Carlo campaign on a trajectory read back
from a CSV file with your own sensor and IMU error model, shots the IMU record cannot
complete, interrupted campaigns, and bad input to the public runner."""

import copy
import dataclasses
import pickle
import warnings

import numpy as np
import pytest
from scipy.stats import chi2

import atomnav as an
from atomnav import InputError, _core, cai
from atomnav.imu import ImuErrors, TriadErrors

RATE = 200.0
T = 0.025
Q_A, Q_G = 1.25e-11, 1.0576e-12  # white-noise PSDs of the simulated IMU (m²/s³, rad²/s)
BA_SIGMA, BG_SIGMA = 2e-5, 1e-6  # turn-on bias σ (m/s², rad/s), also the filter's P0
KINEMATIC = _core.cai_gravity_ellipsoid("kinematic")
CSV_COLUMNS = ["time_s", "lat_rad", "lon_rad", "h_m", "vn_mps", "ve_mps", "vd_mps", "roll_rad", "pitch_rad", "yaw_rad"]


def _user_trajectory(tmp_path, duration):
    """A slalom written to CSV with Euler angles (as a user's reference file) and read back:
    a trajectory from data, without a motion model."""
    gen = an.trajectory.slalom(rate_hz=RATE, duration=duration, origin=cai.HANNOVER, ellipsoid=KINEMATIC)
    path = tmp_path / "reference.csv"
    gen.df[CSV_COLUMNS].to_csv(path, index=False)
    traj = an.trajectory.Trajectory.from_csv(path, ellipsoid=KINEMATIC)
    assert traj.motion is None
    return gen, traj


def _user_sensor(**kw):
    """Two interferometers 60° apart in the body x-y plane (atoms at rest, v0 = 0), released
    5 cm below the IMU: they observe the x and y accelerometer biases, not z."""
    k = cai.K_RB87 * np.array([[1.0, 0.0, 0.0], [np.cos(np.pi / 3), np.sin(np.pi / 3), 0.0]])
    channels = cai.Channels(k, (0.0, 0.0, 0.05), np.eye(3), np.zeros(3), ["a", "b"])
    return cai.CaiSensor(channels, T, inflation=(Q_A, Q_G), **{"interpolation": "cubic", "omega_dot": "pwl", **kw})


def _user_imu():
    return ImuErrors(TriadErrors(bias_sigma=BA_SIGMA, white=np.sqrt(Q_A), bias_rw=1e-6),
                     TriadErrors(bias_sigma=BG_SIGMA, white=np.sqrt(Q_G), bias_rw=2e-7))


def _config(**kw):
    # the filter's model is the simulated IMU's: white PSDs, bias random walks (1e-6², 2e-7²), P0
    setup = cai.FilterSetup(Q_A, Q_G, 1e-12, 4e-14, 10, sigma0=(1e-6, 1e-6, 1e-7, BA_SIGMA, BG_SIGMA))
    fields = {"sensor": _user_sensor(), "setup": setup, "imu": _user_imu(), "gravity": "kinematic", "rate_hz": RATE, "truth_rate_hz": None,
              "draw_initial": True}
    return cai.ScenarioConfig(**{**fields, **kw})


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    gen, traj = _user_trajectory(tmp_path_factory.mktemp("own"), 20.0)
    config = _config()
    return gen, config, cai.run_campaign(traj, config, runs=20, seed=5, name="own", progress=False)


def test_accelerometer_bias_converges_to_the_simulated_bias(campaign):
    _, _, res = campaign
    assert res.runs == 20 and res.complete
    err = res.bias[:, -1, :] - res.bias_true[:, -1, :]
    sigma = res.sigma[:, -1, 9:15]
    # x and y: observed by the two interferometers; the estimate is within 3σ of the truth
    # in every run and σ has shrunk well below the prior
    assert np.all(np.abs(err[:, :2]) <= 3 * sigma[:, :2]), np.abs(err[:, :2] / sigma[:, :2]).max()
    assert np.all(sigma[:, :2] < 0.2 * BA_SIGMA), sigma[0, :2]
    # z: perpendicular to both k, unobserved: σ only grows from its prior (random walk)
    assert np.all(sigma[:, 2] >= BA_SIGMA), sigma[0, 2]
    # the long table carries the same numbers under unit-named columns
    table = res.bias_table()
    last = table[table.time_s == res.time[-1]]
    np.testing.assert_array_equal(last["ba_x_mps2"] - last["ba_x_mps2_true"], err[:, 0])
    np.testing.assert_array_equal(last["ba_y_mps2_sigma"], sigma[:, 1])


def test_nees_over_runs_is_in_its_chi2_band(campaign):
    _, _, res = campaign
    runs = res.runs
    # NEES of the 15 INS states: the mean over runs is χ²(15 R)/R for a consistent filter
    lo, hi = chi2.ppf([0.025, 0.975], 15 * runs) / runs
    assert lo <= res.nees.mean() <= hi, (res.nees.mean(), lo, hi)
    # each (run, epoch) value against χ²(15): about 95 % inside its 95 % band
    lo1, hi1 = chi2.ppf([0.025, 0.975], 15)
    inside = np.mean((res.nees >= lo1) & (res.nees <= hi1))
    assert inside >= 0.9, inside
    np.testing.assert_array_equal(res.nees_table()["nees"], res.nees.ravel())


def test_truth_of_the_table_and_result_tables(campaign):
    gen, config, res = campaign
    # the simulated truth (strapdown of the table's ideal IMU) stays on the user's table
    assert res.params["table_departure_m"] < 1e-3
    # shots every 2T from the record start, ending inside it
    np.testing.assert_allclose(res.shots, np.arange(0.0, 20.0 - 2 * T + 1e-9, 2 * T), atol=1e-12)
    err = res.errors()
    assert {"run", "time_s", "dpos_n_m", "dvel_e_mps"} <= set(err.columns) and len(err) == res.runs * len(res.time)
    # the configuration (with the user's ImuErrors) is saved with the result and rebuilds it
    again = cai.ScenarioConfig.from_dict(res.config)
    assert isinstance(again.imu, ImuErrors) and again.to_dict() == config.to_dict()
    assert again.imu.accel.bias_sigma == BA_SIGMA and again.imu.gyro.bias_rw == 2e-7
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.rate_hz = 100.0


# ---- shots at the record's edges ------------------------------------------------------------

@pytest.fixture(scope="module")
def record():
    traj = an.trajectory.slalom(rate_hz=RATE, duration=2.0, origin=cai.HANNOVER, ellipsoid=KINEMATIC)
    imu = traj.ideal_imu("rates")
    cols = (["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"], ["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"])
    return traj, (imu.time_s.to_numpy(), imu[cols[0]].to_numpy(), imu[cols[1]].to_numpy())


def _ins(traj, shots, **kw):
    # a Savitzky–Golay ω̇ of half width 8: a 17-sample window, which a shot in mid-record
    # has before it; a shot at t = 0 holds 11 samples (0 … 2T at 200 Hz), so it needs 6 more
    sensor = _user_sensor(omega_dot="savgol", savgol_half_width=8)
    data = np.zeros((len(shots), 2))
    return cai.cai_aided_ins(traj.time[0], traj.lla[0], traj.vel_ned[0], traj.q_nb[0], sensor, shots, phase=data, noise=data,
                             kind="rates", ellipsoid=KINEMATIC, **kw)


SHOTS = np.array([0.0, 0.5, 1.0, 1.97])  # the last ends at 2.02 s, 0.02 s (4 samples) after the record


def test_shots_the_record_cannot_complete_are_skipped_with_a_warning(record):
    traj, imu = record
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = _ins(traj, SHOTS).run(*imu, progress=False)
    found = [w.message for w in caught if isinstance(w.message, cai.IncompleteShotWarning)]
    assert [(w.index, w.time_s, w.before, w.after) for w in found] == [(0, 0.0, 6, 0), (3, 1.97, 0, 4)]
    assert "shot 0 (start 0 s) needs 6 IMU sample(s) before the record start" in str(found[0])
    assert "shot 3 (start 1.97 s) needs 4 IMU sample(s) after the record end" in str(found[1])
    assert not any("Savitzky" in str(w.message) for w in caught)
    # the two complete shots are applied, at their last pulse
    np.testing.assert_allclose(res.measurements.time_s, SHOTS[1:3] + 2 * T)
    table = cai.incomplete_shots(_user_sensor(omega_dot="savgol", savgol_half_width=8), SHOTS, imu[0])
    assert table[["shot", "samples_before", "samples_after"]].values.tolist() == [[0, 6, 0], [3, 0, 4]]


def test_streamed_record_skips_a_shot_at_its_start(record):
    traj, imu = record
    with pytest.warns(cai.IncompleteShotWarning, match=r"shot 0 \(start 0 s\) needs 6 IMU sample"):
        res = _ins(traj, SHOTS[:3]).process(*(x[:150] for x in imu))
    np.testing.assert_allclose(res.measurements.time_s, [0.5 + 2 * T])


@pytest.mark.parametrize("shots, index, text", [
    (SHOTS[:3], 0, r"shot 0 \(start 0 s\) needs 6 IMU sample\(s\) before the record start"),
    (SHOTS[1:], 2, r"shot 2 \(start 1.97 s\) needs 4 IMU sample\(s\) after the record end"),
])
def test_shots_the_record_cannot_complete_are_an_error_on_request(record, shots, index, text):
    traj, imu = record
    with pytest.raises(InputError, match=text) as e:
        _ins(traj, shots, incomplete_shots="error").run(*imu, progress=False)
    assert (e.value.parameter, e.value.index) == ("shots", index)


def test_cai_aided_ins_copies_run_the_same(record):
    traj, imu = record
    ins = _ins(traj, SHOTS[1:3])
    copies = [copy.deepcopy(ins), pickle.loads(pickle.dumps(ins))]
    want = ins.run(*imu, progress=False)
    for c in copies:
        got = c.run(*imu, progress=False)
        np.testing.assert_array_equal(got.nav.to_numpy(), want.nav.to_numpy())


def test_monte_carlo_skips_a_shot_at_the_start_with_a_warning(tmp_path):
    _, traj = _user_trajectory(tmp_path, 1.0)
    config = _config(sensor=_user_sensor(omega_dot="savgol", savgol_half_width=8))
    with pytest.warns(cai.IncompleteShotWarning, match=r"shot 0 \(start 0 s\) needs 6 IMU sample"):
        res = cai.run_campaign(traj, config, runs=2, progress=False)
    assert np.isnan(res.phase_error[:, 0, :]).all() and np.isfinite(res.phase_error[:, 1:, :]).all()
    # the skipped shot is missing, not a shot inside the limit: every applied one exceeds 0 rad
    assert res.phase_exceedance(0.0) == 1.0


# ---- interrupted campaigns ------------------------------------------------------------------

@pytest.fixture(scope="module")
def short(tmp_path_factory):
    return _user_trajectory(tmp_path_factory.mktemp("short"), 2.0)[1]


def test_interrupt_keeps_the_finished_runs(short):
    done = []

    def stop(finished, runs):
        done.append(finished)
        raise KeyboardInterrupt

    with pytest.warns(RuntimeWarning, match="interrupted after"):
        res = cai.run_campaign(short, _config(), runs=8, seed=3, progress=False, callback=stop)
    assert not res.complete and res.runs == done[0] < 8
    # the kept runs are those runs of the whole campaign (seeded by run index)
    whole = cai.run_campaign(short, _config(), runs=8, seed=3, progress=False)
    assert whole.complete
    np.testing.assert_array_equal(res.hybrid, whole.hybrid[:res.runs])
    np.testing.assert_array_equal(res.bias_true, whole.bias_true[:res.runs])


def test_an_error_during_the_runs_carries_the_finished_ones(short):
    def fail(finished, runs):
        if finished > 1:
            raise an.NumericalError("diverged")

    with pytest.raises(an.NumericalError) as e:
        cai.run_campaign(short, _config(), runs=8, seed=3, progress=False, callback=fail)
    assert e.value.partial is not None and not e.value.partial.complete and 2 <= e.value.partial.runs < 8


# ---- bad input to the public API ------------------------------------------------------------

def _uneven(traj):
    df = traj.df.copy()
    df.loc[7:, "time_s"] += 1e-4
    return an.trajectory.Trajectory.from_dataframe(df, ellipsoid=KINEMATIC)


@pytest.mark.parametrize("case, parameter, index", [
    ("uneven time", "trajectory", 7),
    ("rate", "trajectory", 1),
    ("truth rate", "truth_rate_hz", None),
    ("runs", "runs", None),
    ("seed", "seed", None),
    ("phase source", "phase_source", None),
    ("sensor", "config.sensor.T", None),
])
def test_bad_campaign_input_names_the_parameter(short, case, parameter, index):
    calls = {
        "uneven time": lambda: cai.run_campaign(_uneven(short), _config(), runs=1, progress=False),
        "rate": lambda: cai.run_campaign(short, _config(rate_hz=100.0), runs=1, progress=False),
        "truth rate": lambda: cai.run_campaign(short, _config(truth_rate_hz=2000.0), runs=1, progress=False),
        "runs": lambda: cai.run_campaign(short, _config(), runs=0, progress=False),
        "seed": lambda: cai.run_campaign(short, _config(), seed=-1, progress=False),
        "phase source": lambda: cai.run_campaign(short, _config(phase_source="oracle"), runs=1, progress=False),
        "sensor": lambda: cai.run_campaign(short, _config(sensor=dataclasses.replace(_user_sensor(), T=-1.0)), runs=1, progress=False),
    }
    with pytest.raises(InputError) as e:
        calls[case]()
    assert (e.value.parameter, e.value.index) == (parameter, index), str(e.value)


@pytest.mark.parametrize("call, parameter", [
    (lambda t: cai.run_campaign(t.df, _config()), "trajectory"),
    (lambda t: cai.run_campaign(t, _config(imu=3.0)), "config.imu"),
    (lambda t: cai.run_campaign(t, _config(), callback="print"), "callback"),
    (lambda t: cai.run_campaign(t, {"sensor": None}), "config"),
])
def test_wrong_types_are_type_errors_naming_the_parameter(short, call, parameter):
    with pytest.raises(TypeError, match=parameter):
        call(short)


def test_bad_incomplete_shots_option(record):
    traj, _ = record
    with pytest.raises(InputError) as e:
        _ins(traj, SHOTS[1:3], incomplete_shots="maybe")
    assert e.value.parameter == "incomplete_shots"
