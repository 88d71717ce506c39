"""Monte-Carlo consistency of the position-aided INS: the NEES built from the full
covariance the engine returns (``covariance=True``) against the actual error of each run.

The IMU errors are drawn exactly from the filter's model (white noise of the stated PSD,
random-constant biases drawn from P₀), the initial error from P₀'s navigation block and the
fixes from their stated covariance, so a consistent filter's run-averaged NEES lies in the
χ² band (Bar-Shalom, Li & Kirubarajan 2001, §5.4) at about 95 % of epochs. The initial
error, the fix noise and the error convention (ψ: C_nb(est) = (I − [ψ×]) C_nb(true)) are
built here with scipy, independently of the engine.

Two motion programs, neither a paper's: a sinusoidal motion in position and attitude,
and a drive with a sinusoidal yaw rate at 3 m/s. Reduced size (50 runs, 60 s) in CI, full
size (50 runs, 300 s, both programs) under ``slow``.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from atomnav import earth, trajectory
from atomnav.filter import chi2_band, position_aided_ins

RATE = 100.0
ACCEL_PSD, GYRO_PSD = (1e-3) ** 2, (1e-5) ** 2          # (m/s²)²/Hz, rad²/s
SIGMA0 = np.r_[[2.0] * 3, [0.1] * 3, [2e-3, 2e-3, 1e-2], [5e-3] * 3, [2e-5] * 3]
P0 = np.diag(SIGMA0**2)
FIX_SIGMA, FIX_EVERY = 1.5, 1.0                          # m, s


def _program(name, duration):
    if name == "sinusoidal":
        return trajectory.sinusoidal(duration, RATE, origin=(0.6, 0.3, 250.0))
    return trajectory.drive_with_yaw(RATE, origin=(-0.5, 2.0, 40.0), speed=3.0, yaw_rate_amp=0.1, period=40.0,
                                     duration=duration, heading=1.0)


def _ned_to_lla(lla, ned):
    """Small NED offsets (m) added to positions (rad, rad, m) on WGS-84 (closed form)."""
    lla = np.atleast_2d(lla)
    m, n = earth.radii(lla[:, 0])
    return np.c_[lla[:, 0] + ned[:, 0] / (m + lla[:, 2]), lla[:, 1] + ned[:, 1] / ((n + lla[:, 2]) * np.cos(lla[:, 0])),
                 lla[:, 2] - ned[:, 2]]


def _run(truth, imu, rng):
    t = imu["time_s"].to_numpy()
    dt = 1.0 / RATE
    x0 = rng.standard_normal(15) * SIGMA0                   # P₀ is diagonal: independent draws
    ba, bg = x0[9:12], x0[12:15]
    gyro = imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy() + bg + rng.standard_normal((len(t), 3)) * np.sqrt(GYRO_PSD / dt)
    accel = imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy() + ba + rng.standard_normal((len(t), 3)) * np.sqrt(ACCEL_PSD / dt)
    init = truth.initial_state()
    lla0 = _ned_to_lla(init["lla"], x0[None, 0:3])[0]
    vel0 = np.asarray(init["vel_ned"]) + x0[3:6]
    # estimate = (I − [ψ×]) truth, taken as the exact rotation exp(−[ψ×]) C_nb
    q = np.asarray(init["q_nb"])
    c_est = Rotation.from_rotvec(-x0[6:9]).as_matrix() @ Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()
    qe = Rotation.from_matrix(c_est).as_quat()
    q0 = np.r_[qe[3], qe[:3]]
    fix_i = np.arange(int(FIX_EVERY * RATE), len(t), int(FIX_EVERY * RATE))
    fix_lla = _ned_to_lla(truth.lla[fix_i], rng.standard_normal((len(fix_i), 3)) * FIX_SIGMA)
    ins = position_aided_ins(t[0], lla0, vel0, q0, "rates", t[fix_i], fix_lla, np.eye(3) * FIX_SIGMA**2,
                             p0=P0, gyro_psd=GYRO_PSD, accel_psd=ACCEL_PSD, predict_every=10)
    return ins.run(t, gyro, accel, progress=False, covariance=True)


def _nees_fraction(program, runs, duration, seed=11):
    truth = _program(program, duration)
    imu = truth.ideal_imu("rates")
    rng = np.random.default_rng(seed)
    nees = np.mean([_run(truth, imu, rng).nees(truth)["nees"].to_numpy() for _ in range(runs)], axis=0)
    lo, hi = chi2_band(9, runs)
    return np.mean((nees >= lo) & (nees <= hi)), np.mean(nees)


@pytest.mark.parametrize("program", ["sinusoidal", "drive_with_yaw"])
def test_nees_from_the_returned_covariance_50_runs_reduced(program):
    inside, mean = _nees_fraction(program, runs=50, duration=60.0)
    assert inside >= 0.90, (inside, mean)


@pytest.mark.slow
@pytest.mark.parametrize("program", ["sinusoidal", "drive_with_yaw"])
def test_nees_from_the_returned_covariance_50_runs_full(program):
    inside, mean = _nees_fraction(program, runs=50, duration=300.0)
    assert inside >= 0.90, (inside, mean)
