"""The papers' trajectories against the numbers their specs state."""

import numpy as np
import pytest

import atomnav as an
from atomnav import InputError, trajectory
from atomnav import rotation as R
from atomnav.trajectory import Trajectory


def _at(traj, t):
    return traj.df.iloc[int(np.argmin(np.abs(traj.time - t)))]


def test_vasilyuk2024_stand_rotation_angles():
    """Spec astro-calibration §5.1: the inertial rotation between the two camera epochs
    that bracket move j (epochs 6j−5 and 6j−4, 21 s apart, Earth rotation included) is
    119.9, 80.1, 15.0, 154.9, 51.9, 15.0, 57.1, 7.0, 130.1, 50.1, 7.0, 89.9 degrees. Here
    it is what the ideal gyros see: their increments integrated between the epochs."""
    rate = 100.0
    traj = an.trajectory.vasilyuk2024_stand(rate_hz=rate)
    dth = traj.ideal_imu("increments")[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy()
    epoch = lambda n: 0.5023 + 21.0007 * (n - 1)
    angles = []
    for j in range(1, 13):
        k0, k1 = round(epoch(6 * j - 5) * rate), round(epoch(6 * j - 4) * rate)  # at rest: grid rounding is harmless
        q = an.strapdown.integrate_attitude([1.0, 0, 0, 0], dth[k0:k1])[-1]
        angles.append(np.rad2deg(np.linalg.norm(R.rotvec_from_quat(q))))
    expected = [119.9, 80.1, 15.0, 154.9, 51.9, 15.0, 57.1, 7.0, 130.1, 50.1, 7.0, 89.9]
    np.testing.assert_allclose(angles, expected, atol=0.051)
    assert traj.time[-1] >= epoch(73)


def test_hexapod_sequence():
    """Spec cai-ekf decision 13: 170 s, 10 s static, roll blocks [+a, −a, +a/2, −a/2] ×3
    with 1 s ramps and 5 s holds, pitch the same 5 s later, a = 0.0654 rad."""
    traj = an.trajectory.hexapod(rate_hz=100.0)
    roll, pitch = traj.df["roll_rad"].to_numpy(), traj.df["pitch_rad"].to_numpy()
    assert traj.time[-1] == pytest.approx(170.0)
    assert np.abs(roll[traj.time < 10.0]).max() == 0.0 and np.abs(roll[traj.time > 154.0]).max() < 1e-15
    assert roll.max() == pytest.approx(0.0654, abs=1e-12) and roll.min() == pytest.approx(-0.0654, abs=1e-12)
    assert _at(traj, 13.5)["roll_rad"] == pytest.approx(0.0654, abs=1e-9)  # first hold 11–16 s
    assert _at(traj, 18.5)["pitch_rad"] == pytest.approx(0.0654, abs=1e-9)  # pitch 5 s later
    assert _at(traj, 37.5)["roll_rad"] == pytest.approx(0.0327, abs=1e-9)  # third step, half tilt


def test_slalom_geometry():
    """Spec atom-strapdown §2.8: north = 5t, east = 2 sin(2πt/10), heading = atan2(ė, ṅ)."""
    traj = an.trajectory.slalom(rate_hz=50.0)
    ned = an.earth.lla_to_ned(traj.lla, traj.lla[0])
    t = traj.time
    # position is integrated on the ellipsoid: N ↔ (M+h)Δφ, so allow the curvature term
    np.testing.assert_allclose(ned[:, 0], 5 * t, atol=2e-3)
    np.testing.assert_allclose(ned[:, 1], 2 * np.sin(2 * np.pi * t / 10), atol=2e-3)
    yaw = np.arctan2(2 * 2 * np.pi / 10 * np.cos(2 * np.pi * t / 10), 5.0)
    np.testing.assert_allclose(traj.df["yaw_rad"], yaw, atol=1e-12)


def test_drive_with_yaw_rate():
    """Seed 003 Fig. 7: yaw rate 0.05 sin(2πt/50) rad/s at 1 m/s forward speed."""
    traj = an.trajectory.drive_with_yaw(rate_hz=20.0)
    yaw = np.unwrap(traj.df["yaw_rad"].to_numpy())
    t = traj.time
    np.testing.assert_allclose(yaw, 0.05 * 50 / (2 * np.pi) * (1 - np.cos(2 * np.pi * t / 50)), atol=1e-12)
    np.testing.assert_allclose(np.hypot(traj.df["vn_mps"], traj.df["ve_mps"]), 1.0, atol=1e-12)


def test_car_speed_profile():
    """Spec car_mc: static to 5 s, 1 m/s² from 5 s with a 1 s raised-cosine ramp, so the
    speed at 12 s is 6.5 m/s; the shock at 26 s adds 3·0.05·√(2π) = 0.376 m/s."""
    traj = an.trajectory.car(rate_hz=200.0, vibration=False)
    speed = np.hypot(traj.df["vn_mps"], traj.df["ve_mps"])
    assert speed[traj.time < 5.0].max() == 0.0
    assert _at(traj, 12.0)["vn_mps"] == pytest.approx(6.5, abs=1e-9)  # course still north
    before, after = float(np.interp(25.7, traj.time, speed)), float(np.interp(26.3, traj.time, speed))
    assert after - before - 0.5 * 0.6 == pytest.approx(3 * 0.05 * np.sqrt(2 * np.pi), rel=1e-3)


def test_car_vibration_amplitude():
    """Vibration: three sines of 0.05 m/s² (4.3, 9.7, 15.1 Hz) on every axis after the
    static phase: the vertical acceleration is within 3·0.05 m/s² in 6–12 s and zero
    while static."""
    traj = an.trajectory.car(rate_hz=400.0)
    imu = traj.ideal_imu("rates")
    fz = imu["accel_z_mps2"].to_numpy()
    g = an.earth.gravity(traj.lla[0, 0], traj.lla[0, 2])
    t = imu["time_s"].to_numpy()
    static = t < 4.0
    np.testing.assert_allclose(fz[static], -g, atol=1e-9)
    moving = (t > 6.0) & (t < 12.0)
    dev = np.abs(fz[moving] + g)
    assert 0.05 < dev.max() <= 0.15 + 0.01


# --- boundary fuzz findings: a wrong type is a TypeError naming the parameter, a bad value an
# InputError naming a real parameter of the call ------------------------------------------


@pytest.mark.parametrize("call, parameter", [
    (lambda: Trajectory(np.zeros((1, 3))), "df"),
    (lambda: Trajectory.from_dataframe(np.nan), "df"),
    (lambda: Trajectory.from_motion(34.8, 1.0), "motion"),
    (lambda: Trajectory.from_csv({1.0, 2.0}), "path"),
])
def test_wrong_types_are_type_errors_naming_the_parameter(call, parameter):
    with pytest.raises(TypeError, match=parameter):
        call()


def test_trajectory_methods_check_their_arguments():
    traj = trajectory.stationary(1.0, 10.0)
    with pytest.raises(TypeError, match="nav"):
        traj.errors({"a": 1})
    with pytest.raises(TypeError, match="path"):
        traj.to_csv(np.zeros(3))
    with pytest.raises(TypeError, match="ax"):
        traj.plot(ax=np.zeros(3))
    with pytest.raises(InputError) as e:
        Trajectory(traj.df[["time_s"]])
    assert e.value.parameter == "df"
    with pytest.raises(InputError) as e:
        Trajectory.from_dataframe(traj.df).ideal_imu("increments")
    assert e.value.parameter == "kind"


@pytest.mark.parametrize("rate_hz", [1e308, 1e300])
def test_sample_count_is_checked_before_allocation(rate_hz):
    with pytest.raises(InputError) as e:
        trajectory.stationary(10.0, rate_hz)
    assert e.value.parameter == "rate_hz"
