"""Mounting and timing of a real installation (docs/mounting.md): the IMU turned in its
housing (the mount C_imu^b of :class:`atomnav.filter.InsSetup`), a GNSS antenna at a lever
arm from the IMU and IMU time stamps that lag (the ``lever_arm`` and ``time_offset`` of a
source). Oracle: the simulator's truth. The same sensor, at body axes, fed fixes of the
IMU's own position without delay is the ideal run; configured with the mount, the lever
arm and the time offset, the turned, offset and delayed installation must navigate as
well as it, and leaving the lever arm (or the offset) out must visibly cost accuracy."""

import pickle

import numpy as np
import pytest

import atomnav as an
from atomnav import InputError
from atomnav.filter import BiasModel, InsSetup, PositionFixes, VelocityFixes, ZeroVelocity, aided_ins

RATE, DURATION, FIX_HZ, SIGMA_FIX, SIGMA_VEL = 100.0, 300.0, 2.0, 1.0, 0.02  # Hz, s, Hz, m, m/s
OMEGA_IE = 7.292115e-5  # rad/s (WGS-84)
DELAY = 0.125  # s: the IMU stamps a sample measured at true time T with T + DELAY
LEVER = 0.65 * np.array([0.45, -0.3, -0.84]) / np.linalg.norm([0.45, -0.3, -0.84])  # m, body frame
POS, VEL, ATT = (["dpos_n_m", "dpos_e_m", "dpos_d_m"], ["dvel_n_mps", "dvel_e_mps", "dvel_d_mps"],
                 ["psi_n_rad", "psi_e_rad", "psi_d_rad"])


def _dcm(roll, pitch, yaw):
    """C = Rz(yaw) Ry(pitch) Rx(roll), written out (the independent oracle of the Euler convention)."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


# upside down and turned 90° in its housing, and a few degrees off the vehicle axes
MOUNT = _dcm(np.pi, 0.0, -np.pi / 2) @ _dcm(*np.deg2rad([0.5, -6.8, 5.4]))  # C_imu^b


def _truth(name):
    if name == "car":  # 10 m/s with a sinusoidal yaw rate: heading swings ±23°
        return an.trajectory.drive_with_yaw(rate_hz=RATE, speed=10.0, yaw_rate_amp=0.05, period=50.0, duration=DURATION)
    return an.trajectory.sinusoidal(DURATION, rate_hz=RATE)  # roll, pitch and yaw all swing


@pytest.fixture(scope="module", params=["car", "sinusoidal"])
def scene(request):
    """The truth, the turned IMU's tactical-grade output (seeded) in its own axes, and the
    same samples turned to body axes (the ideal mount: the same sensor, the same error
    realisation); 2 Hz fixes with 1 m noise (seeded) of the IMU's position and of the
    antenna's, p_ant = p + C_b^n l; and velocity fixes with 2 cm/s noise (seeded) of the
    IMU's and the antenna's velocity, v_ant = v + C_b^n(ω_eb^b × l) from the truth's
    ω_ib^b and the Earth rate."""
    truth = _truth(request.param)
    ideal = truth.ideal_imu("rates")
    g_b = ideal[[f"gyro_{a}_rad_s" for a in "xyz"]].to_numpy()
    f_b = ideal[[f"accel_{a}_mps2" for a in "xyz"]].to_numpy()
    # f_imu = C_b^imu f_b, row by row: f_b @ C_imu^b
    meas = an.imu.corrupt(f_b @ MOUNT, g_b @ MOUNT, errors="tactical", dt=1 / RATE, kind="rates", seed=5)
    g_imu = meas[[f"gyro_{a}_rad_s" for a in "xyz"]].to_numpy()
    f_imu = meas[[f"accel_{a}_mps2" for a in "xyz"]].to_numpy()
    t_fix = np.arange(1.0, DURATION, 1 / FIX_HZ)
    k = np.searchsorted(truth.time, t_fix)
    assert np.array_equal(truth.time[k], t_fix)
    noise = np.random.default_rng(11).standard_normal((len(t_fix), 3)) * SIGMA_FIX
    lla = truth.lla[k]
    rm, rn = an.earth.radii(lla[:, 0])

    def lla_of(ned):  # the NED offset ned (m) from the IMU's truth, in lat/lon/h
        return lla + np.c_[ned[:, 0] / (rm + lla[:, 2]), ned[:, 1] / ((rn + lla[:, 2]) * np.cos(lla[:, 0])), -ned[:, 2]]

    c_bn = an.rotation.dcm_from_quat(truth.q_nb[k])
    lever_n = np.einsum("kij,j->ki", c_bn, LEVER)
    w_ie = OMEGA_IE * np.c_[np.cos(lla[:, 0]), np.zeros(len(k)), -np.sin(lla[:, 0])]
    v_turn = np.einsum("kij,kj->ki", c_bn, np.cross(g_b[k], LEVER)) - np.cross(w_ie, lever_n)
    v_noise = np.random.default_rng(12).standard_normal((len(t_fix), 3)) * SIGMA_VEL
    return dict(truth=truth, t=ideal["time_s"].to_numpy(), imu=(g_imu, f_imu), body=(g_imu @ MOUNT.T, f_imu @ MOUNT.T),
                t_fix=t_fix, fix_imu=lla_of(noise), fix_antenna=lla_of(noise + lever_n),
                vel_imu=truth.vel_ned[k] + v_noise, vel_antenna=truth.vel_ned[k] + v_turn + v_noise)


def _setup(truth, offset=0.0, **kw):
    s0 = truth.initial_state()
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])
    return InsSetup(t0=s0["t0"] + offset, lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates", p0=p0,
                    accel_psd=1e-6, gyro_psd=1e-9, accel_bias=BiasModel("random_walk", psd=1e-9),
                    gyro_bias=BiasModel("random_walk", psd=1e-14), predict_every=10, **kw)


def _rms(scene, imu, fixes, offset=0.0, mount=None):
    """3-D RMS of the position (m), velocity (m/s) and attitude (rad) errors after the
    first 10 s of the run in the IMU clock offset by ``offset`` from the truth's."""
    truth = scene["truth"]
    nav = aided_ins(_setup(truth, offset, mount=mount), fixes).run(scene["t"] + offset, *imu, progress=False).nav
    t = nav["time_s"].to_numpy() - offset
    i = np.rint((t - truth.time[0]) * RATE).astype(int)  # the truth's own stamps, not a rounded shift of them
    assert np.abs(truth.time[i] - t).max() < 1e-9
    err = truth.errors(nav.assign(time_s=truth.time[i]))
    err = err[err["time_s"] > 10.0]
    return np.array([np.sqrt((err[c].to_numpy() ** 2).sum(axis=1).mean()) for c in (POS, VEL, ATT)])


def _fixes(scene, where, **kw):
    return PositionFixes(scene["t_fix"], scene[where], np.eye(3) * SIGMA_FIX**2, **kw)


@pytest.fixture(scope="module")
def table(scene):
    """RMS errors (position m, velocity m/s, attitude rad) of the ideal installation, the
    configured hard one, and the hard one with the lever arm or the time offset left out."""
    imu = scene["imu"]
    rows = {
        "ideal": _rms(scene, scene["body"], _fixes(scene, "fix_imu")),
        "configured": _rms(scene, imu, _fixes(scene, "fix_antenna", lever_arm=LEVER, time_offset=DELAY), DELAY, MOUNT),
        "no lever arm": _rms(scene, imu, _fixes(scene, "fix_antenna", time_offset=DELAY), DELAY, MOUNT),
        "no time offset": _rms(scene, imu, _fixes(scene, "fix_antenna", lever_arm=LEVER), DELAY, MOUNT),
    }
    print("\n" + "\n".join(f"{k:15s} position {v[0]:.4f} m  velocity {v[1]:.5f} m/s  attitude {np.rad2deg(v[2]) * 60:.3f}'"
                           for k, v in rows.items()))
    return rows


def test_configured_hard_mount_navigates_like_the_ideal_mount(table):
    ratio = table["configured"] / table["ideal"]
    assert np.all(np.abs(ratio - 1) < 0.05), ratio


def test_the_lever_arm_and_the_time_offset_each_act(table):
    # left out, the 0.65 m lever arm biases every fix; 0.125 s of lag at speed misplaces it
    assert table["no lever arm"][0] > 1.2 * table["configured"][0], table
    assert table["no time offset"][0] > 1.2 * table["configured"][0], table


def test_velocity_fixes_at_the_antenna_need_their_lever_arm(scene):
    """Velocity fixes of the antenna (next to its position fixes): configured, the errors
    equal the ideal installation's; without the velocity fixes' lever arm, the turning
    antenna's ω × l biases them and the velocity error grows."""
    imu, cov = scene["imu"], np.eye(3) * SIGMA_VEL**2
    position = _fixes(scene, "fix_antenna", lever_arm=LEVER, time_offset=DELAY)

    def velocity(**kw):
        return VelocityFixes(scene["t_fix"], scene["vel_antenna"], cov, time_offset=DELAY, **kw)

    ideal = _rms(scene, scene["body"], [_fixes(scene, "fix_imu"), VelocityFixes(scene["t_fix"], scene["vel_imu"], cov)])
    configured = _rms(scene, imu, [position, velocity(lever_arm=LEVER)], DELAY, MOUNT)
    left_out = _rms(scene, imu, [position, velocity()], DELAY, MOUNT)
    assert np.all(np.abs(configured / ideal - 1) < 0.05), (configured, ideal)
    assert left_out[1] > 1.2 * configured[1], (left_out, configured)


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_the_mount_turns_every_sample_to_the_body_axes(kind):
    """Rates or increments in the turned IMU's axes, with the mount, navigate as the same
    samples turned to body axes by numpy: the same solution to rounding."""
    truth = an.trajectory.sinusoidal(60.0, rate_hz=RATE)
    imu = truth.ideal_imu(kind).to_numpy()
    t, body = imu[:, 0], (imu[:, 1:4], imu[:, 4:7])
    fix_t = truth.time[100::100]
    fixes = PositionFixes(fix_t, truth.lla[100::100], np.eye(3))
    s0 = truth.initial_state()
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])

    def nav(samples, mount=None):
        setup = InsSetup(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind=kind, p0=p0,
                         accel_psd=1e-6, gyro_psd=1e-9, predict_every=10, mount=mount)
        return aided_ins(setup, fixes).run(t, *samples, progress=False).nav

    want = nav(body)
    got = nav([x @ MOUNT for x in body], MOUNT)  # the IMU's axes: C_b^imu x, row by row
    err = truth.errors(want).iloc[:, 1:].to_numpy() - truth.errors(got).iloc[:, 1:].to_numpy()
    assert len(want) == len(got) > 500
    assert np.abs(err).max() < 1e-9, np.abs(err).max(axis=0)
    # the samples are not merely equal in the body axes: unmounted, they navigate elsewhere
    wrong = truth.errors(nav([x @ MOUNT for x in body])).iloc[:, 1:4].to_numpy()
    assert np.abs(wrong).max() > 100.0


def test_mount_as_euler_angles_is_the_same_dcm():
    truth = an.trajectory.stationary(1.0)
    s = _setup(truth, mount=(np.pi, 0.0, -np.pi / 2))
    np.testing.assert_allclose(np.array(s.mount), _dcm(np.pi, 0.0, -np.pi / 2), atol=1e-15)
    np.testing.assert_allclose(np.array(s.mount), [[0, -1, 0], [-1, 0, 0], [0, 0, -1]], atol=1e-15)


def test_mount_is_saved_with_the_setup():
    s = _setup(an.trajectory.stationary(1.0), mount=MOUNT)
    assert np.array_equal(np.array(s.mount), MOUNT)
    assert InsSetup.from_dict(s.to_dict()) == s
    assert InsSetup.from_json(s.to_json()) == s
    assert InsSetup.from_json(s.to_json()).mount == s.mount
    assert pickle.loads(pickle.dumps(s)) == s
    assert _setup(an.trajectory.stationary(1.0)).to_dict()["mount"] is None  # the identity, saved as no mount


def test_the_core_turns_the_samples_by_the_saved_mount(scene):
    """An INS rebuilt from the saved (JSON) setup and a pickled copy of the native setup
    both turn the samples: each gives the configured run's solution bit for bit."""
    fixes = _fixes(scene, "fix_antenna", lever_arm=LEVER, time_offset=DELAY)
    s = _setup(scene["truth"], DELAY, mount=MOUNT)
    record = (scene["t"] + DELAY, *scene["imu"])
    want = aided_ins(s, fixes).run(*record, progress=False).nav
    for copy in (InsSetup.from_json(s.to_json()), pickle.loads(pickle.dumps(s))):
        assert copy.native is not s.native
        np.testing.assert_array_equal(aided_ins(copy, fixes).run(*record, progress=False).nav.to_numpy(), want.to_numpy())


# ---- bad input names the field -------------------------------------------------------

@pytest.mark.parametrize("mount", [np.diag([1.0, 1.0, -1.0]), 1.01 * MOUNT, MOUNT + 1e-3, [[1.0, 0.0], [0.0, 1.0]],
                                   (0.0, np.nan, 0.0)])
def test_a_mount_that_is_no_rotation_names_mount(mount):
    with pytest.raises(InputError) as e:
        _setup(an.trajectory.stationary(1.0), mount=mount)
    assert e.value.parameter == "mount"


@pytest.mark.parametrize("make", [
    lambda lever: PositionFixes([1.0, 2.0], np.tile([0.97, 0.65, 150.0], (2, 1)), np.eye(3), lever_arm=lever),
    lambda lever: VelocityFixes([1.0, 2.0], np.zeros((2, 3)), np.eye(3), lever_arm=lever),
    lambda lever: ZeroVelocity([1.0, 2.0], 0.01, lever_arm=lever),
])
@pytest.mark.parametrize("lever", [(0.1, np.nan, 0.3), (np.inf, 0.0, 0.0)])
def test_a_lever_arm_with_nan_names_lever_arm(make, lever):
    with pytest.raises(InputError) as e:
        make(lever)
    assert e.value.parameter == "lever_arm"


@pytest.mark.parametrize("offset", [125.0, -125.0])
def test_a_time_offset_longer_than_the_record_names_time_offset(offset):
    truth = an.trajectory.stationary(100.0, rate_hz=10.0)
    imu = truth.ideal_imu("rates")
    fixes = PositionFixes([50.0], truth.lla[500:501], np.eye(3), time_offset=offset)  # in ms by mistake
    ins = aided_ins(_setup(truth), fixes)
    with pytest.raises(InputError) as e:
        ins.run(imu["time_s"], imu[[f"gyro_{a}_rad_s" for a in "xyz"]], imu[[f"accel_{a}_mps2" for a in "xyz"]], progress=False)
    assert e.value.parameter == "time_offset"


def test_a_non_finite_time_offset_names_time_offset():
    with pytest.raises(InputError) as e:
        ZeroVelocity([1.0], 0.01, time_offset=np.nan)
    assert e.value.parameter == "time_offset"
