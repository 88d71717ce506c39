"""Levelling alone (atomnav.alignment.level): roll and pitch from a record held still, for
a device held by hand or a gyro that cannot find north.

Oracles: the simulated attitude truth, coarse's levelling on a truly static record (the
same levelling), the specific-force window means computed here with numpy (their scatter,
over g, is the tilt allowance), and the roll and pitch of the recorded walk's mean
specific force computed here (atan2(−f_y, −f_z), atan2(f_x, √(f_y² + f_z²)))."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import InputError, alignment

EULER = (0.02, -0.03, 0.7)
RATE, DURATION = 100.0, 60.0
ACCEL = [f"accel_{a}_mps2" for a in "xyz"]
WALK = Path(__file__).parent / "data" / "real_walk" / "imu_1730_sf.csv.gz"


@pytest.fixture(scope="module")
def still():
    traj = an.trajectory.stationary(DURATION, rate_hz=RATE, euler=EULER)
    meas = an.imu.corrupt(traj.ideal_imu("rates"), errors="tactical", dt=1 / RATE, kind="rates", seed=4)
    return meas, traj.lla[0]


def _swaying(meas: pd.DataFrame, amplitude: float) -> pd.DataFrame:
    """The record with a slow sway of the specific force (m/s², per axis), as a hand's,
    of zero mean over the record (so the mean specific force, and the attitude, stay)."""
    t = meas["time_s"].to_numpy()
    out = meas.copy()
    for i, c in enumerate(ACCEL):
        sway = amplitude * np.sin(2 * np.pi * t / (7.0 + 3 * i) + i)
        out[c] = out[c] + (sway - sway.mean())
    return out


def _window_means(x: np.ndarray) -> np.ndarray:
    """Means of ten equal windows (boundaries n·k // 10, the last window the longest)."""
    b = [len(x) * k // 10 for k in range(11)]
    return np.array([x[lo:hi].mean(axis=0) for lo, hi in zip(b[:-1], b[1:])])


def test_level_is_coarse_levelling_with_an_undetermined_heading(still):
    meas, lla = still
    c, lv = alignment.coarse(meas, lla, errors="tactical"), alignment.level(meas, lla, errors="tactical")
    np.testing.assert_allclose(lv.euler[:2], c.euler[:2], atol=1e-12)
    np.testing.assert_allclose(lv.euler_sigma[:2], c.euler_sigma[:2], rtol=1e-3)
    assert np.all(np.abs(lv.euler[:2] - np.array(EULER[:2])) < 3 * lv.euler_sigma[:2])
    assert lv.euler[2] == 0.0 and lv.euler_sigma[2] == pytest.approx(np.pi / np.sqrt(3))
    assert lv.psi_cov[2, 0] == lv.psi_cov[2, 1] == 0.0


def test_a_swaying_record_is_levelled_with_its_sway_in_the_tilt_sigma(still):
    meas, lla = still
    sway = _swaying(meas, 0.05)
    with pytest.raises(InputError, match="not static"):
        alignment.coarse(sway, lla, errors="tactical")
    lv, calm = alignment.level(sway, lla, errors="tactical"), alignment.level(meas, lla, errors="tactical")
    # the added tilt variance: the scatter of the ten window means (per body axis), over
    # ten windows, seen through levelling (tilt = horizontal specific force error / g)
    np.testing.assert_allclose(lv.q_nb, calm.q_nb, atol=1e-12)  # the sway has zero mean
    scatter = [_window_means(r[ACCEL].to_numpy()).var(axis=0, ddof=1) / 10 for r in (sway, meas)]
    c_nb = an.rotation.dcm_from_quat(lv.q_nb)
    g = lv.gravity
    m = np.array([[0.0, 1.0 / g, 0.0], [-1.0 / g, 0.0, 0.0]]) @ c_nb  # ψ_N, ψ_E from body f errors
    np.testing.assert_allclose(lv.psi_cov[:2, :2] - calm.psi_cov[:2, :2], m @ np.diag(scatter[0] - scatter[1]) @ m.T,
                               rtol=1e-9, atol=1e-18)
    assert np.all(np.abs(lv.euler[:2] - np.array(EULER[:2])) < 3 * lv.euler_sigma[:2])


def test_walking_is_not_held_still(still):
    meas, lla = still
    with pytest.raises(InputError, match="not held still") as e:
        alignment.level(_swaying(meas, 1.0), lla, errors="tactical")
    assert e.value.parameter == "imu"


def test_levels_near_a_pole_where_gyrocompassing_cannot(still):
    traj = an.trajectory.stationary(20.0, rate_hz=RATE, euler=EULER, origin=(np.radians(89.6), 0.3, 10.0))
    meas = an.imu.corrupt(traj.ideal_imu("rates"), errors="tactical", dt=1 / RATE, kind="rates", seed=4)
    with pytest.raises(InputError) as e:
        alignment.coarse(meas, traj.lla[0], errors="tactical")
    assert e.value.parameter == "lla"
    lv = alignment.level(meas, traj.lla[0], errors="tactical")
    assert np.all(np.abs(lv.euler[:2] - np.array(EULER[:2])) < 3 * lv.euler_sigma[:2])


def test_the_recorded_walk_levels_at_rest():
    """The walker's first 10 s: gyrocompassing refuses the hand-held device (not static);
    levelling gives the roll and pitch of the mean specific force (IMU axes)."""
    with gzip.open(WALK, "rt") as fh:
        raw = pd.read_csv(fh, header=None).to_numpy()
    rest = raw[raw[:, 0] < raw[0, 0] + 10.0]
    imu = np.column_stack([rest[:, 0], rest[:, 4:7], rest[:, 1:4] * 9.80665])
    lla = (np.radians(40.0966916), np.radians(-105.1471665), 1601.435)
    with pytest.raises(InputError, match="not static"):
        alignment.coarse(imu, lla, errors="mems", kind="rates")
    lv = alignment.level(imu, lla, errors="mems", kind="rates")
    f = imu[:, 4:7].mean(axis=0)
    roll, pitch = np.arctan2(-f[1], -f[2]), np.arctan2(f[0], np.hypot(f[1], f[2]))
    np.testing.assert_allclose(lv.euler[:2], [roll, pitch], atol=1e-9)


def test_bad_input_names_the_argument(still):
    meas, lla = still
    with pytest.raises(InputError) as e:
        alignment.level(meas.iloc[:50], lla, errors="tactical")
    assert e.value.parameter == "imu"
    with pytest.raises(InputError) as e:
        alignment.level(meas, lla, errors="tactical", kind="rate")
    assert e.value.parameter == "kind"
    in_g = meas.assign(**{c: meas[c] / 9.80665 for c in ACCEL})
    with pytest.raises(InputError, match="not the local gravity"):
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", an.UnitWarning)
            alignment.level(in_g, lla, errors="tactical")
    with pytest.raises(TypeError, match="errors"):
        alignment.level(meas, lla, errors=3)


def test_summary_says_the_heading_is_not_determined(still):
    meas, lla = still
    text = str(alignment.level(meas, lla, errors="tactical"))
    assert text.startswith("Levelling") and "not determined" in text and "static test" not in text
    assert "static test" in str(alignment.coarse(meas, lla, errors="tactical"))


def _still_with_gyro_bias(seed: int, bias: np.ndarray, gyro_white: float, yaw: float):
    """A static record at heading ``yaw`` whose gyro reads the Earth rate plus ``bias``
    (rad/s) and white noise of density ``gyro_white`` (rad/s/√Hz), added here."""
    traj = an.trajectory.stationary(20.0, rate_hz=RATE, euler=(0.02, -0.03, yaw))
    meas = traj.ideal_imu("rates")
    rng = np.random.default_rng(seed)
    gyro = [f"gyro_{a}_rad_s" for a in "xyz"]
    meas[gyro] = meas[gyro].to_numpy() + bias + gyro_white * np.sqrt(RATE) * rng.standard_normal((len(meas), 3))
    meas[ACCEL] = meas[ACCEL].to_numpy() + 1e-3 * rng.standard_normal((len(meas), 3))
    return meas, traj.lla[0]


def test_the_rest_gyro_bias_is_the_mean_rate_less_the_earth_rate_within_its_sigma():
    """Over 40 static records with known gyro biases of 0.1-0.3 °/s (a MEMS gyro's) and
    random headings, the bias seen at rest is off from the truth by what its covariance
    says (mean NEES within the 95 % band of χ²(120)/40), though the horizontal Earth rate
    is unknown to a levelling; and the vertical Earth rate is taken out (a bias of zero
    reads zero up to that covariance)."""
    deg = np.pi / 180
    errors = an.imu.ImuErrors(accel=an.imu.TriadErrors(white=1e-4, bias_sigma=0.05),
                              gyro=an.imu.TriadErrors(white=0.004 * deg, bias_sigma=0.2 * deg))
    rng = np.random.default_rng(11)
    nees = []
    for seed in range(40):
        bias = rng.uniform(0.1, 0.3, 3) * deg * rng.choice([-1.0, 1.0], 3)
        meas, lla = _still_with_gyro_bias(seed, bias, 0.004 * deg, rng.uniform(-np.pi, np.pi))
        lv = alignment.level(meas, lla, errors=errors)
        e = lv.gyro_bias - bias
        nees.append(float(e @ np.linalg.solve(lv.gyro_bias_cov, e)))
    assert 2.28 < np.mean(nees) < 3.80, np.mean(nees)
    # noise-free and unbiased: what remains is the horizontal Earth rate, whose direction
    # a levelling does not know; the vertical Earth rate is taken out
    meas, lla = _still_with_gyro_bias(0, np.zeros(3), 0.0, 0.3)
    lv = alignment.level(meas, lla, errors=errors)
    w = meas[[f"gyro_{a}_rad_s" for a in "xyz"]].to_numpy().mean(axis=0)  # ω_ie^b
    down = an.rotation.dcm_from_euler([0.02, -0.03, 0.3])[2]             # the down axis in the body frame
    np.testing.assert_allclose(lv.gyro_bias, w - (w @ down) * down, rtol=1e-4, atol=1e-12)
    assert abs(w @ down) > 3e-5  # the vertical Earth rate that was removed


def test_a_gyrocompass_leaves_the_gyro_bias_to_the_error_model(still):
    meas, lla = still
    c = alignment.coarse(meas, lla, errors="tactical")
    assert np.all(c.gyro_bias == 0.0)
    assert np.all(np.diag(c.gyro_bias_cov) > 0) and np.all(c.gyro_bias_cov == np.diag(np.diag(c.gyro_bias_cov)))
