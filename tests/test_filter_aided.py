"""Position-aided 15-state INS on the project strapdown: closed and open loop."""

import numpy as np
import pytest

from atomnav import earth
from atomnav.filter import chi2_band, position_aided_ins

LAT, LON, H = 0.8, 0.2, 100.0
OMEGA = 7.292115e-5


def static_case(duration=200.0, rate=100.0, seed=4, mode="closed"):
    """Level, north-facing, at rest: exact rates are ω_ie^n and −gⁿ; IMU biases added."""
    n = int(duration * rate) + 1
    t = np.arange(n) / rate
    gyro = np.tile([OMEGA * np.cos(LAT), 0.0, -OMEGA * np.sin(LAT)], (n, 1))
    accel = np.tile([0.0, 0.0, -earth.gravity(LAT, H)], (n, 1))
    ba_true, bg_true = np.array([0.0, 0.0, 2e-3]), np.array([0.0, 0.0, 0.0])
    rng = np.random.default_rng(seed)
    fix_t = np.arange(1.0, duration + 1e-9, 1.0)
    m = len(fix_t)
    sig = 1.0
    ned = rng.standard_normal((m, 3)) * sig
    m_rad, n_rad = earth.radii(LAT)
    rm, rp = m_rad + H, n_rad + H
    fix_lla = np.c_[LAT + ned[:, 0] / rm, LON + ned[:, 1] / (rp * np.cos(LAT)), H - ned[:, 2]]
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-8] * 3, [(3e-3) ** 2] * 3, [(1e-7) ** 2] * 3])
    table, fixes = position_aided_ins(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], "rates", t, gyro + bg_true,
                                      accel + ba_true, fix_t, fix_lla, np.tile(np.eye(3) * sig**2, (m, 1, 1)), p0,
                                      accel_psd=1e-10, gyro_psd=1e-16, predict_every=10, mode=mode)
    return table, fixes, ba_true


def test_closed_loop_estimates_vertical_accel_bias_and_is_consistent():
    table, fixes, ba = static_case()
    last = table.iloc[-1]
    sigma = last["sigma_accel_bias[2]"]
    assert sigma < 2e-4
    assert abs(last["accel_bias_z_mps2"] - ba[2]) < 3 * sigma
    assert abs(last["h_m"] - H) < 3.0
    lo, hi = chi2_band(3, len(fixes))
    assert lo <= fixes["nis"].mean() <= hi
    assert not fixes["rejected"].any()


def test_open_and_closed_loop_agree_on_bias_estimate():
    closed, _, ba = static_case(duration=100.0, mode="closed")
    opened, _, _ = static_case(duration=100.0, mode="open")
    a, b = closed["accel_bias_z_mps2"].iloc[-1], opened["accel_bias_z_mps2"].iloc[-1]
    assert abs(a - b) < 1e-3 * ba[2]
    assert abs(closed["h_m"].iloc[-1] - opened["h_m"].iloc[-1]) < 1e-3


def _args():
    t = np.arange(11) * 0.1
    g = np.zeros((11, 3))
    a = np.tile([0, 0, -9.8], (11, 1))
    return dict(t0=0.0, lla0=[LAT, LON, H], vel0=[0, 0, 0], q0=[1, 0, 0, 0], kind="rates", time=t, gyro=g, accel=a,
                fix_time=[0.5], fix_lla=[[LAT, LON, H]], fix_cov=np.eye(3)[None], p0=np.eye(15),
                accel_psd=1e-8, gyro_psd=1e-12)


def test_bad_fix_time_outside_imu_span():
    kw = _args()
    kw["fix_time"] = [1.5]
    with pytest.raises(ValueError, match=r"fixes: time 1.5 s at index 0 is outside the IMU span \[0, 1\] s"):
        position_aided_ins(**kw)


def test_bad_nan_fix():
    kw = _args()
    kw["fix_lla"] = [[LAT, np.nan, H]]
    with pytest.raises(ValueError, match="fix_lla: non-finite value nan at index 0"):
        position_aided_ins(**kw)


def test_bad_p0_size():
    kw = _args()
    kw["p0"] = np.eye(9)
    with pytest.raises(ValueError, match="p0: expected 15x15, got 9x9"):
        position_aided_ins(**kw)


def test_bad_fix_covariance():
    kw = _args()
    kw["fix_cov"] = -np.eye(3)[None]
    with pytest.raises(ValueError, match=r"fixes\[0\] covariance: not positive definite"):
        position_aided_ins(**kw)

