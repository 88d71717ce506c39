"""cai_aided_ins(smooth=True): the CAI-aided INS keeps its forward pass and run() returns
the Rauch–Tung–Striebel smoothed solution, whose covariance is never above the filter's
(P_s = P_f + C (P_s,next − P_p,next) Cᵀ with P_s,next ≤ P_p,next; Rauch, Tung & Striebel 1965)
and equal to it at the last epoch."""

import numpy as np
import pytest

import atomnav as an
from atomnav import cai


def _run(smooth):
    traj = an.trajectory.slalom(rate_hz=200.0, duration=4.0)
    imu = an.imu.corrupt(traj.ideal_imu("rates"), errors="navigation", dt=0.005, kind="rates", seed=2)
    sensor = cai.seed003_sensor((0.0, 0.0, 0.0))
    shots = sensor.shots(0.5, traj.time[-1])
    phase = cai.predict_phase(imu["time_s"], imu.filter(like="accel_").iloc[:, :3], imu.filter(like="gyro_").iloc[:, :3],
                              shots, sensor.T, sensor.channels, interpolation="cubic", omega_dot="pwl").total
    s = traj.initial_state()
    ins = cai.cai_aided_ins(s["t0"], s["lla"], s["vel_ned"], s["q_nb"], sensor, shots, phase=phase,
                            noise=np.random.default_rng(1).normal(0.0, sensor.sigma_p, phase.shape), kind="rates", smooth=smooth)
    return ins.run(imu["time_s"], imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]],
                   imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]], progress=False)


def test_smoothed_sigma_never_above_the_filtered():
    res = _run(True)
    sigma = [c for c in res.nav.columns if c.startswith("sigma_")]
    f, s = res.nav[sigma].to_numpy(), res.smoothed.nav[sigma].to_numpy()
    assert len(res.measurements) > 50
    assert np.all(s <= f * (1 + 1e-9)), np.max(s / f)
    np.testing.assert_allclose(s[-1], f[-1], rtol=1e-9)
    # the biases are observed by the shots: smoothing lowers their σ before the end
    bias = [c for c in sigma if "bias" in c]
    assert np.all(res.smoothed.nav[bias].to_numpy()[0] < 0.9 * res.nav[bias].to_numpy()[0])


def test_without_smooth_there_is_no_smoothed_solution():
    assert _run(False).smoothed is None


def test_smooth_must_be_a_bool():
    with pytest.raises(TypeError, match="smooth"):
        cai.cai_aided_ins(0.0, (0.9, 0.2, 100.0), (0, 0, 0), (1, 0, 0, 0), cai.seed003_sensor(), [0.5],
                          phase=np.zeros((1, 6)), noise=np.zeros((1, 6)), kind="rates", smooth="yes")
