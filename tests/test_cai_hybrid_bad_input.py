"""Issue 5, bad input of the CAI-aided INS: clear ValueErrors naming the field."""

import numpy as np
import pytest

import atomnav as an
from atomnav import InputError, cai

T = 0.025


@pytest.fixture(scope="module")
def record():
    traj = an.trajectory.slalom(rate_hz=200.0, duration=2.0, ellipsoid="kinematic")
    imu = traj.ideal_imu("rates")
    s = traj.df.iloc[0]
    init = (float(s.time_s), s[["lat_rad", "lon_rad", "h_m"]].to_numpy(float), s[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(float),
            s[["qw", "qx", "qy", "qz"]].to_numpy(float))
    return init, imu


def _ins(record, shots, n_channels=6, **kw):
    init, _ = record
    sensor = cai.seed003_sensor()
    data = np.zeros((len(shots), n_channels))
    return cai.cai_aided_ins(*init, sensor, shots, phase=data, noise=data, ellipsoid="kinematic", **{"kind": "rates", **kw})


def _run(ins, record):
    _, imu = record
    return ins.run(imu.time_s, imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]], imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]],
                   progress=False)


def test_valid_record_runs(record):
    res = _run(_ins(record, 0.1 + 2 * T * np.arange(10)), record)
    assert len(res.measurements) == 10


def test_shot_ending_after_the_record(record):
    # 1.97 + 2T = 2.02 s, 0.02 s past the last sample at 200 Hz: 4 samples
    with pytest.raises(InputError, match=r"shots: shot 1 \(start 1.97 s\) needs 4 IMU sample\(s\) after the record end") as e:
        _run(_ins(record, [0.5, 1.97], incomplete_shots="error"), record)
    assert (e.value.parameter, e.value.index) == ("shots", 1)


def test_shot_starting_before_the_record(record):
    # 0.01 s before the first sample at 200 Hz: 2 samples
    with pytest.raises(InputError, match=r"shots: shot 0 \(start -0.01 s\) needs 2 IMU sample\(s\) before the record start") as e:
        _run(_ins(record, [-0.01, 0.5], incomplete_shots="error"), record)
    assert (e.value.parameter, e.value.index) == ("shots", 0)


def test_overlapping_shots(record):
    with pytest.raises(ValueError, match=r"shots: shot 2 starts at 0.23 s, before shot 1 ends"):
        _ins(record, [0.1, 0.2, 0.23])


def test_mismatched_number_of_interferometers(record):
    with pytest.raises(ValueError, match=r"phase: has 5 interferometers per shot, but the configuration has 6"):
        _ins(record, [0.1, 0.2], n_channels=5)


def test_mismatched_number_of_shots(record):
    init, _ = record
    with pytest.raises(ValueError, match=r"noise: expected 2 shots"):
        cai.cai_aided_ins(*init, cai.seed003_sensor(), [0.1, 0.2], phase=np.zeros((2, 6)), noise=np.zeros((3, 6)), kind="rates")


def test_recorded_and_emulated_data_are_exclusive(record):
    init, _ = record
    with pytest.raises(InputError, match=r"population: give either") as e:
        cai.cai_aided_ins(*init, cai.seed003_sensor(), [0.1], phase=np.zeros((1, 6)), noise=np.zeros((1, 6)), population=np.zeros((1, 6)), kind="rates")
    assert e.value.parameter == "population"
    with pytest.raises(InputError, match=r"phase: give either") as e:
        cai.cai_aided_ins(*init, cai.seed003_sensor(), [0.1], kind="rates")
    assert e.value.parameter == "phase"


def test_shot_period_shorter_than_the_shot():
    s = cai.seed003_sensor()
    s.shot_period = 0.04
    with pytest.raises(ValueError, match=r"shot_period: must be >= 2T"):
        s.shots(0.0, 10.0)


def test_zero_runs():
    with pytest.raises(InputError, match=r"runs: must be an integer in \[1, ") as e:
        cai.slalom(0, progress=False)
    assert e.value.parameter == "runs"


def test_in_shot_noise_rejects_a_non_positive_sample_interval():
    with pytest.raises(ValueError, match="dt"):
        cai.in_shot_noise(cai.seed003_sensor(), 0.0, 1e-11, 1e-12)


def test_in_shot_noise_rejects_a_model_that_is_not_15_by_15():
    with pytest.raises(ValueError, match="f:.*15 × 15"):
        cai.in_shot_noise(cai.seed003_sensor(), 0.005, 1e-11, 1e-12, np.zeros((2, 9, 9)))


def test_true_error_analysis_rejects_a_cross_covariance_of_the_wrong_shape():
    from atomnav.filter import Scenario
    from atomnav.filter.analysis import true_error_analysis

    scn = Scenario(np.zeros((3, 2, 2)), np.zeros((3, 2, 2)), np.ones(3), np.eye(2), np.eye(2), np.eye(2), [True] * 4)
    with pytest.raises(ValueError, match="cross: entry 0 is 2 × 1"):
        true_error_analysis(scn, np.eye(2), np.zeros((3, 2, 1)))
