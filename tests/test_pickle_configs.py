"""Pickle and deepcopy of the configuration objects, the aided INS, the CAI, GNSS and
astro core objects and the result objects (the first seven stateful classes are in
test_threads_pickle.py).

The oracle is always the original object: the copy, given the same calls, returns
bit-for-bit the same outputs; an aided INS copied between chunks (mid-shot for the CAI)
continues exactly like the original."""

from __future__ import annotations

import copy
import dataclasses
import pickle
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import _core, astro, cai, gnss
from atomnav.filter import (BiasModel, InsSetup, Layout, MonteCarlo, NonHolonomic, PositionFixes, VelocityFixes, ZeroRate, ZeroVelocity,
                            aided_ins, monte_carlo, position_aided_ins)
from atomnav.filter.analysis import Scenario
from atomnav.filter.riccati import dare
from atomnav.gnss import GnssOptions, tight_ins
from atomnav.gnss.solution import read_pos
from atomnav.gnss.tight import GnssObservations
from atomnav.gnss import scenarios as gnss_scenarios
from atomnav.imu import ImuErrors
from atomnav.noise.allan import fit_allan
from atomnav.noise.arma import fit_arma, stationarity
from atomnav.noise.filters import PAPER_AR, PAPER_MA, PAPER_SIGMA2, ArimaStateSpace, kalman

LAT, LON, H = 0.8, 0.2, 100.0
OMEGA_IE = 7.292115e-5  # rad/s (WGS-84)


def _copies(obj):
    return [pickle.loads(pickle.dumps(obj)), copy.deepcopy(obj)]


def _state_bytes(core_obj) -> bytes:
    """The saved state of a core object: what its pickle carries."""
    return core_obj.__reduce__()[1][0]


def assert_same(a, b, where: str = "obj"):
    """``b`` equals ``a`` bit for bit, through dataclasses, dicts, sequences, arrays, tables
    and core objects (compared by their saved state)."""
    assert type(a) is type(b), where
    if isinstance(a, pd.DataFrame):
        pd.testing.assert_frame_equal(a, b, check_exact=True)
    elif isinstance(a, pd.Series):
        pd.testing.assert_series_equal(a, b, check_exact=True)
    elif isinstance(a, np.ndarray):
        np.testing.assert_array_equal(a, b, err_msg=where)
    elif type(a).__module__ == "atomnav._core":
        assert _state_bytes(a) == _state_bytes(b), where
    elif dataclasses.is_dataclass(a) or hasattr(a, "__dict__") and not isinstance(a, type):
        da, db = vars(a), vars(b)
        assert da.keys() == db.keys(), where
        for k in da:
            assert_same(da[k], db[k], f"{where}.{k}")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            assert_same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, float) and np.isnan(a):
        assert np.isnan(b), where
    else:
        assert a == b, where


def assert_result_equal(a, b):
    """Two aided-INS results (nav table, measurement table, innovations) bit for bit."""
    pd.testing.assert_frame_equal(a.nav, b.nav, check_exact=True)
    pd.testing.assert_frame_equal(a.measurements, b.measurements, check_exact=True)
    np.testing.assert_array_equal(a.innovation, b.innovation)


# ---- aided INS: a copy taken between chunks continues bit for bit ----------------------

def _static_record(duration=20.0, rate=100.0):
    """Level, north-facing, at rest with an accelerometer bias; position fixes every 1 s."""
    n = int(duration * rate) + 1
    t = np.arange(n) / rate
    gyro = np.tile([OMEGA_IE * np.cos(LAT), 0.0, -OMEGA_IE * np.sin(LAT)], (n, 1))
    accel = np.tile([0.0, 0.0, -an.earth.gravity(LAT, H)], (n, 1)) + [0.0, 0.0, 2e-3]
    fix_t = np.arange(1.0, duration + 1e-9, 1.0)
    rng = np.random.default_rng(4)
    fix_lla = np.c_[LAT + rng.standard_normal(len(fix_t)) * 1e-7, np.full(len(fix_t), LON), H + rng.standard_normal(len(fix_t))]
    return t, gyro, accel, fix_t, fix_lla


def _position_ins(**kw):
    t, _, _, fix_t, fix_lla = _static_record()
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-8] * 3, [(3e-3) ** 2] * 3, [(1e-7) ** 2] * 3])
    return position_aided_ins(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], "rates", fix_t, fix_lla,
                              np.tile(np.eye(3), (len(fix_t), 1, 1)), p0=p0, accel_psd=1e-10, gyro_psd=1e-16,
                              predict_every=10, **kw)


@pytest.mark.parametrize("mode", ["closed", "open"])
def test_position_aided_ins_copy_continues_bit_for_bit(mode):
    t, g, a, _, _ = _static_record()
    ins = _position_ins(mode=mode)
    cut = 1037  # not on a prediction epoch: steps since the last prediction are in the state
    ins.process(t[:cut], g[:cut], a[:cut])
    pending, copies = ins.pending, _copies(ins)
    want = [ins.process(t[cut:], g[cut:], a[cut:]), ins.finish()]
    for c in copies:
        assert c.pending == pending and c.labels == ins.labels
        got = [c.process(t[cut:], g[cut:], a[cut:]), c.finish()]
        for x, y in zip(want, got):
            assert_result_equal(x, y)
    assert len(want[0].measurements) > 5  # the copies went through fixes


def test_cai_aided_ins_copied_mid_shot_continues_bit_for_bit():
    """The CAI aiding buffers the IMU samples of the current shot and steers the laser
    phase from the filter: both are in the copy."""
    traj = an.trajectory.slalom(rate_hz=200.0, duration=2.0, ellipsoid="kinematic")
    imu = traj.ideal_imu("rates")
    s = traj.df.iloc[0]
    init = (float(s.time_s), s[["lat_rad", "lon_rad", "h_m"]].to_numpy(float), s[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(float),
            s[["qw", "qx", "qy", "qz"]].to_numpy(float))
    shots = 0.1 + 0.05 * np.arange(30)
    rng = np.random.default_rng(3)
    phase, noise = rng.uniform(-1.0, 1.0, (30, 6)), 0.01 * rng.standard_normal((30, 6))
    ins = cai.cai_aided_ins(*init, cai.seed003_sensor(), shots, phase=phase, noise=noise, kind="rates", ellipsoid="kinematic")
    t = imu.time_s.to_numpy()
    g = imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy()
    a = imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()
    cut = 131  # t = 0.655 s: inside the shot started at 0.65 s
    ins.process(t[:cut], g[:cut], a[:cut])
    copies = _copies(ins)
    want = [ins.process(t[cut:], g[cut:], a[cut:]), ins.finish()]
    for c in copies:
        got = [c.process(t[cut:], g[cut:], a[cut:]), c.finish()]
        for x, y in zip(want, got):
            assert_result_equal(x, y)
    assert len(want[0].measurements) > 10


def test_tight_gnss_ins_copy_continues_bit_for_bit():
    setup = gnss_scenarios.build(gnss_scenarios.Scenario(duration_s=60.0, formulation="clock_states"))
    ins = tight_ins(setup["eph"], setup["obs"], **setup["args"])
    m = setup["imu"]
    t = m["time_s"].to_numpy()
    g, a = m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(), m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy()
    h = setup["h_ref"]
    cut = 1234
    ins.process(t[:cut], g[:cut], a[:cut], h[:cut])
    copies = _copies(ins)
    want = [ins.process(t[cut:], g[cut:], a[cut:], h[cut:]), ins.finish()]
    for c in copies:
        got = [c.process(t[cut:], g[cut:], a[cut:], h[cut:]), c.finish()]
        for x, y in zip(want, got):
            assert_result_equal(x, y)
    assert len(want[0].measurements) > 30


def test_copied_configurations_build_identical_filters():
    """InsSetup (and its core AidedSetup) and GnssOptions: a filter built from the copies
    runs exactly like one built from the originals."""
    setup = gnss_scenarios.build(gnss_scenarios.Scenario(duration_s=20.0))
    args = dict(setup["args"])
    opts = GnssOptions(formulation=args.pop("formulation"))
    p0 = args.pop("p0_ins")
    ins_setup = InsSetup(**args, p0=p0, sequential=True, gate=10.83)
    m = setup["imu"]
    t = m["time_s"].to_numpy()
    g, a = m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(), m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy()
    want = tight_ins(setup["eph"], setup["obs"], opts, ins_setup).run(t, g, a, h_ref=setup["h_ref"], progress=False)
    for o, s in zip(_copies(opts), _copies(ins_setup)):
        assert o == opts and s.to_json() == ins_setup.to_json()
        assert _state_bytes(s.native) == _state_bytes(ins_setup.native)
        got = tight_ins(setup["eph"], setup["obs"], o, s).run(t, g, a, h_ref=setup["h_ref"], progress=False)
        assert_result_equal(want, got)


# ---- CAI core objects -------------------------------------------------------------------

def test_cai_motion_gravity_and_channels_copies_give_the_same_imu_and_oracle():
    channels = cai.Channels.cyclic(lever=(0.01, -0.02, 0.1))._native()
    gravity = _core.CaiGravity(np.array([0.1, -0.2, -9.8]), np.diag([-3e-6, -3e-6, 6e-6]), 0.3)
    sines = np.array([[0, 0.02, 1.3, 0.1], [2, 0.01, 0.7, -0.4]])
    motions = [cai.SineMotion(position_sines=sines, attitude_sines=sines)._native(), cai.YawDrive(3.0, 0.2, 7.0)._native()]
    t, shots, T = np.linspace(0.0, 2.0, 401), np.array([0.2, 0.9, 1.5]), 0.05
    for motion in motions:
        want = (*motion.imu(t, gravity), motion.oracle(shots, T, channels, gravity))
        for m, gr, ch in zip(_copies(motion), _copies(gravity), _copies(channels)):
            got = (*m.imu(t, gr), m.oracle(shots, T, ch, gr))
            for x, y in zip(want, got):
                np.testing.assert_array_equal(x, y)


def test_cai_predictor_setup_copy_predicts_the_same():
    from atomnav.cai.predictor import _setup

    t = np.arange(0.0, 1.0, 0.005)
    rng = np.random.default_rng(2)
    f = np.tile([0.0, 0.0, -9.8], (len(t), 1)) + 1e-3 * rng.standard_normal((len(t), 3))
    w = 1e-3 * rng.standard_normal((len(t), 3))
    _, core = _setup(t, f, w, [0.1, 0.5], 0.025, cai.Channels.cyclic(), None, "savgol", 2, "cubic", 2, None, 0.0, 0.0)
    want = (core.predict(), core.jacobian(True), core.jacobian(False, (1e-3, 1e-4, 1e-3, 1e-4)))
    for c in _copies(core):
        got = (c.predict(), c.jacobian(True), c.jacobian(False, (1e-3, 1e-4, 1e-3, 1e-4)))
        for x, y in zip(want, got):
            np.testing.assert_array_equal(x, y)


def test_cai_sensor_copies_give_the_same_in_shot_noise():
    sensor = cai.seed003_sensor()
    native = sensor._native()
    f = np.tile(np.eye(15) * 0.01, (5, 1, 1))
    want = _core.cai_in_shot_noise(native, 0.005, 1.25e-11, 1.0576e-12, f)
    for c in _copies(sensor) + [s._native() for s in _copies(sensor)] + _copies(native):
        got = _core.cai_in_shot_noise(c if isinstance(c, _core.CaiSensor) else c._native(), 0.005, 1.25e-11, 1.0576e-12, f)
        for x, y in zip(want, got):
            np.testing.assert_array_equal(x, y)


def test_cai_hybrid_scenario_copy_runs_the_same_monte_carlo():
    config = cai.ScenarioConfig(cai.seed003_sensor(), cai.seed003_filter(), truth_rate_hz=400.0)
    motion = _core.Motion.slalom(np.array(cai.HANNOVER), 5.0, 2.0, 10.0, 2.0)
    sensor, setup = config.sensor, config.setup
    core = _core.CaiHybrid(motion, sensor._native(), sensor.shots(sensor.first_shot, motion.duration), *ImuErrors.preset(config.imu)._to_core(),
                           None, setup.p0(sensor.n_extra()), gravity=config.gravity, rate_hz=config.rate_hz,
                           truth_rate_hz=config.truth_rate_hz, phase_source=config.phase_source, accel_psd=setup.accel_psd,
                           gyro_psd=setup.gyro_psd, accel_bias_psd=setup.accel_bias_psd, gyro_bias_psd=setup.gyro_bias_psd,
                           predict_every=setup.predict_every, aiding=True, draw_initial=True)
    want = core.monte_carlo(11, [0, 3])
    for c in _copies(core):
        got = c.monte_carlo(11, [0, 3])
        assert want.keys() == got.keys()
        for k in want:
            np.testing.assert_array_equal(want[k], got[k], err_msg=k)
        np.testing.assert_array_equal(c.shots, core.shots)
        for x, y in zip(c.ideal_imu(), core.ideal_imu()):
            np.testing.assert_array_equal(x, y)
    for c in _copies(config):
        assert c.to_json() == config.to_json()


# ---- astro and the linearised filter scenario -------------------------------------------

def test_astro_scenario_copy_runs_the_same_calibration():
    sc = astro.scenario.Vasilyuk2024()
    want_truth, want_run = sc.truth(), sc.run(5)
    (c,) = [pickle.loads(pickle.dumps(sc))]  # one copy: a run takes ~1 s
    assert_same(want_truth, c.truth())
    assert_same(want_run, c.run(5))
    d = copy.deepcopy(sc)
    assert _state_bytes(d._core) == _state_bytes(sc._core) and d.gyro_error_model == sc.gyro_error_model


def _filter_scenario():
    n_steps, dt = 40, 0.5
    f = np.tile([[0.0, 1.0], [0.0, -0.1]], (n_steps, 1, 1))
    qc = np.tile(np.diag([0.0, 1e-3]), (n_steps, 1, 1))
    measure = [k % 4 == 0 for k in range(n_steps + 1)]
    return Scenario(f, qc, np.full(n_steps, dt), np.diag([1.0, 0.1]), np.array([[1.0, 0.0]]), np.array([[0.04]]), measure)


def test_filter_scenario_copies_give_the_same_analysis_and_monte_carlo():
    sc = _filter_scenario()
    want_sig = sc._core.sigmas()
    want_mc = monte_carlo(sc, runs=3, seed=9)
    for c in _copies(sc) + [Scenario.__new__(Scenario)]:
        if not hasattr(c, "_core"):  # the core object alone, copied
            c = copy.copy(sc)
            c._core = pickle.loads(pickle.dumps(sc._core))
        np.testing.assert_array_equal(c._core.sigmas(), want_sig)
        assert_same(want_mc, monte_carlo(c, runs=3, seed=9))


# ---- every configuration and result object round-trips ----------------------------------

def _series():
    return np.random.default_rng(1).standard_normal(3000)


def _stored_forward_pass():
    ins = _position_ins(smooth=True, smooth_chunk=50, smooth_memory=50 * 7576)
    ins.run(*_static_record()[:3], progress=False)
    return ins.forward_pass


# ---- measurement sources: a copy feeds an INS exactly like the original ------------------

def _sources():
    _, _, _, fix_t, fix_lla = _static_record()
    cov = np.tile(np.eye(3), (len(fix_t), 1, 1))
    return {
        "PositionFixes": PositionFixes(fix_t, fix_lla, cov),
        "VelocityFixes": VelocityFixes(fix_t, np.zeros((len(fix_t), 3)), 1e-4 * cov),
        "ZeroVelocity": ZeroVelocity(fix_t, 0.01),
        "ZeroRate": ZeroRate(fix_t, 1e-16),
        # measured away from the IMU, stamped in another clock (docs/mounting.md)
        "PositionFixes mounted": PositionFixes(fix_t, fix_lla, cov, lever_arm=(0.5, -0.2, -1.0), time_offset=-0.25),
        "VelocityFixes mounted": VelocityFixes(fix_t, np.zeros((len(fix_t), 3)), 1e-4 * cov, lever_arm=(0.3, 0.1, -0.6),
                                               time_offset=-0.125),
        "ZeroVelocity mounted": ZeroVelocity(fix_t, 0.01, lever_arm=(0.0, 0.4, 0.2), time_offset=-0.5),
        "NonHolonomic": NonHolonomic(fix_t, 0.05, lever_arm=(-1.0, 0.2, 0.5)),
    }


@pytest.mark.parametrize("name", ["PositionFixes", "VelocityFixes", "ZeroVelocity", "ZeroRate", "PositionFixes mounted",
                                  "VelocityFixes mounted", "ZeroVelocity mounted", "NonHolonomic"])
def test_source_copies_feed_the_same_ins(name):
    source = _sources()[name]
    setup = _position_ins().setup
    record = _static_record()[:3]
    want = aided_ins(setup, source).run(*record, progress=False)
    assert len(want.measurements) >= 20
    if name.endswith("mounted"):  # the lever arm and the offset act, so a copy must carry them
        plain = aided_ins(setup, _sources()[name.split()[0]]).run(*record, progress=False)
        assert not np.array_equal(plain.nav.to_numpy(), want.nav.to_numpy())
        assert np.array_equal(want.measurements["time_s"], plain.measurements["time_s"] + source.time_offset)
    for c in _copies(source):
        assert_same(source, c, name)
        assert_result_equal(want, aided_ins(setup, c).run(*record, progress=False))


def test_gnss_observations_copy_feeds_the_same_ins():
    setup = gnss_scenarios.build(gnss_scenarios.Scenario(duration_s=20.0))
    source = GnssObservations(setup["eph"], setup["obs"], GnssOptions(formulation=setup["args"]["formulation"]))
    ins = tight_ins(setup["eph"], setup["obs"], **setup["args"])
    m = setup["imu"]
    imu = (m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
           m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy())
    want = aided_ins(ins.setup, source).run(*imu, h_ref=setup["h_ref"], progress=False)
    assert len(want.measurements) >= 19  # one row per GNSS epoch, every second
    for c in _copies(source):
        assert_result_equal(want, aided_ins(ins.setup, c).run(*imu, h_ref=setup["h_ref"], progress=False))


# ---- alignment results -------------------------------------------------------------------

def _alignment():
    still = an.trajectory.stationary(20.0, rate_hz=100.0)
    meas = an.imu.corrupt(still.ideal_imu("rates"), errors="tactical", dt=0.01, kind="rates", seed=3)
    lla = still.initial_state()["lla"]
    coarse = an.alignment.coarse(meas.iloc[:1000], lla, errors="tactical")
    return coarse, an.alignment.fine(meas.iloc[1000:], lla, coarse)


def _spp_result():
    eph = gnss.Ephemerides.nominal(0.0, 600.0, seed=1)
    lla = np.array([np.radians(55.75), np.radians(37.6), 200.0])
    obs = gnss.simulate(eph, [100.0, 101.0], np.tile(lla, (2, 1)), np.zeros((2, 3)), seed=3)
    return gnss.solve(eph, obs)


def _motion_alignment():
    car = an.trajectory.car(rate_hz=50.0, vibration=False)
    meas = an.imu.corrupt(car.ideal_imu("rates"), errors="mems", dt=0.02, kind="rates", seed=3)
    t = np.arange(1.0, 21.0)
    k = np.searchsorted(car.time, t - 1e-9)
    position = an.filter.PositionFixes(t, car.lla[k], np.eye(3))
    velocity = an.filter.VelocityFixes(t, car.vel_ned[k], 0.01 * np.eye(3))
    level = an.alignment.coarse(meas[meas.time_s <= 4.0], car.lla[0], errors="mems")
    return an.alignment.in_motion(meas, position, velocity, level)


CASES = {
    "Channels": lambda: cai.Channels.cyclic(),
    "CaiSensor": lambda: cai.seed003_sensor(),
    "FilterSetup": lambda: cai.seed003_filter(),
    "ScenarioConfig": lambda: cai.ScenarioConfig(cai.seed003_sensor(), cai.seed003_filter()),
    "SineMotion": lambda: cai.SineMotion(),
    "YawDrive": lambda: cai.YawDrive(2.0, 0.1, 5.0),
    "PhasePrediction": lambda: cai.predict_phase(np.arange(0, 1, 0.005), np.tile([0, 0, -9.8], (200, 1)), np.zeros((200, 3)), [0.1],
                                                 0.025, cai.Channels.cyclic()),
    "HybridResult": lambda: cai.slalom(1, duration=2.0, progress=False),
    "InsSetup": lambda: InsSetup(t0=0.0, lla0=[LAT, LON, H], vel0=[0, 0, 0], q0=[1, 0, 0, 0], kind="rates", p0=np.eye(15),
                                 accel_psd=1e-10, gyro_psd=1e-16, accel_bias=BiasModel("gauss_markov", tau=100.0, sigma=1e-3)),
    "BiasModel": lambda: BiasModel("random_walk", psd=1e-8),
    "Layout": lambda: Layout(),
    "AidedResult": lambda: _position_ins().run(*_static_record()[:3], progress=False),
    "SmoothedResult": lambda: _position_ins(smooth=True).run(*_static_record()[:3], progress=False).smoothed,
    # a stored forward pass partly on disk (every chunk beyond the first)
    "ForwardStore": lambda: _stored_forward_pass(),
    "MonteCarlo": lambda: monte_carlo(_filter_scenario(), runs=2, seed=1),
    "SteadyState": lambda: dare(np.eye(2) * 0.9, np.eye(2), np.eye(2), np.eye(2)),
    "GnssOptions": lambda: GnssOptions(formulation="clock_states", lever_arm=(0.1, 0.2, -0.3)),
    "GnssScenario": lambda: gnss_scenarios.Scenario(duration_s=60.0, outage=(10.0, 5.0)),
    "ImuErrors": lambda: ImuErrors.preset("tactical"),
    "GyroErrorModel": lambda: astro.GyroErrorModel.vasilyuk2024("consistent"),
    "Catalog": lambda: astro.synthetic_catalog(4.0, seed=2),
    "Increments": lambda: astro.gyro_increments(0.0, 0.005, np.full((400, 3), 1e-5), [0.5, 1.0, 1.9],
                                                astro.GyroErrorModel.vasilyuk2024("consistent")),
    "AllanFit": lambda: fit_allan(_series(), 0.01),
    "Stationarity": lambda: stationarity(_series()),
    "ArmaFit": lambda: fit_arma(_series(), order=(1, 1)),
    "ArimaStateSpace": lambda: ArimaStateSpace(ar=PAPER_AR, ma=PAPER_MA, sigma2=PAPER_SIGMA2),
    "PosSolution": lambda: read_pos(Path(__file__).parent / "data" / "real_walk" / "gnss_1730_sf.pos.gz"),
    "SppResult": _spp_result,
    "RinexObservations": lambda: gnss.rinex.read_obs(
        Path(__file__).parent / "data" / "rinex_stations" / "delf0010_cut.21o.gz",
        gnss.rinex.read_nav(Path(__file__).parent / "data" / "rinex_stations" / "brdc0010_cut.21n.gz")),
    "CoarseAlignment": lambda: _alignment()[0],
    "FineAlignment": lambda: _alignment()[1],
    "MotionAlignment": _motion_alignment,
    "KalmanResult": lambda: kalman(_series(), ArimaStateSpace(ar=PAPER_AR, ma=PAPER_MA, sigma2=PAPER_SIGMA2)),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_object_round_trips(name):
    obj = CASES[name]()
    for c in _copies(obj):
        assert_same(obj, c, name)


def test_every_public_class_is_covered():
    """A new public class of atomnav is added to a pickle test (here or in
    test_threads_pickle.py), or this test names it."""
    import importlib
    import inspect
    import pkgutil

    covered = set(CASES) | {
        # test_threads_pickle.py
        "Strapdown", "ImuSimulator", "ImuErrorSimulator", "KalmanFilter", "KalmanStream", "ArmaFilterConfig", "Motion",
        "Trajectory", "Ephemerides", "GnssEphemerides", "AllanStream",
        # test_io.py
        "ImuLog", "SamplingReport",
        # test_outages.py
        "OutageResult",
        # test_cai_own_data.py (and its warning, an exception)
        "IncompleteShotWarning",
        # test_cai_source.py (and the aided INS of aided_ins, with test_cai_own_data.py)
        "CaiShots", "SourcedIns",
        # tests above (sources); AidingSource is the core's single-use hand-over that a
        # source makes afresh for every INS (Source._native), never held by a user
        "PositionFixes", "VelocityFixes", "ZeroVelocity", "ZeroRate", "NonHolonomic", "GnssObservations", "Source", "AidingSource",
        # test_constraints.py
        "StillPeriods",
        # test_astro_stars.py
        "StarAttitudes", "AstroIncrements",
        # tests above
        "AidedIns", "AidedSetup", "CaiChannels", "CaiSetup", "CaiGravity", "CaiMotion", "CaiHybrid", "AstroScenario",
        "Vasilyuk2024", "Scenario", "Calibration", "Observations",
        # members of the classes above (TriadErrors, GaussMarkov, Flicker in ImuErrors; UpdateResult
        # is a tuple), the Comparison report (dataclass of tables, like AllanFit), bases and exceptions
        "TriadErrors", "GaussMarkov", "Flicker", "UpdateResult", "Comparison", "Config", "ConfigMixin", "Stateful",
        "MonteCarloIncomplete", "UnitWarning", "ImuRateWarning",
        # test_campaign_engine.py; test_campaign_cli.py
        "Campaign", "CampaignFile", "Executor",
    }
    public = set()
    for m in pkgutil.walk_packages(an.__path__, "atomnav."):
        if ".reproduce" in m.name or m.name.endswith(".cli"):
            continue
        mod = importlib.import_module(m.name)
        public |= {n for n, o in vars(mod).items() if inspect.isclass(o) and o.__module__ == m.name and not n.startswith("_")}
    assert public - covered == set()
