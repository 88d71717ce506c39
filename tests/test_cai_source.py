"""CAI shots as a measurement source of the aided INS (atomnav.cai.CaiShots with
atomnav.filter.aided_ins), cai_aided_ins as the INS of one such source, and the CAI-aided
filter smoothed (Rauch, Tung & Striebel 1965)."""

import copy
import pickle
import warnings

import numpy as np
import pytest
from scipy.linalg import block_diag

import atomnav as an
from atomnav import InputError, _core, cai
from atomnav.filter import InsSetup, PositionFixes, aided_ins
from atomnav.filter.aided import AidedIns
from atomnav.filter.engine import BiasModel

RATE = 200.0
GYRO = ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]
ACCEL = ["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]
NAVIGATION = an.imu.ImuErrors.preset("navigation")


@pytest.fixture(scope="module")
def record():
    """A 6-s slalom at 200 Hz with a navigation-grade IMU (known biases), the six-channel
    sensor of Tennstedt et al. 2023 and the true phase of every shot (from the ideal IMU)."""
    traj = an.trajectory.slalom(rate_hz=RATE, duration=6.0, origin=cai.HANNOVER)
    ideal = traj.ideal_imu("rates")
    imu = an.imu.corrupt(ideal, errors="navigation", dt=1.0 / RATE, kind="rates", seed=1)
    sensor = cai.CaiSensor(cai.Channels.cyclic(), 0.025, interpolation="cubic", omega_dot="pwl",
                           inflation=(NAVIGATION.accel.white**2, NAVIGATION.gyro.white**2))
    shots = sensor.shots(0.5, traj.time[-1])
    phase = cai.predict_phase(ideal["time_s"], ideal[ACCEL], ideal[GYRO], shots, sensor.T, sensor.channels,
                              interpolation="cubic", omega_dot="pwl").total
    noise = np.random.default_rng(3).normal(0.0, sensor.sigma_p, phase.shape)
    return traj, imu, sensor, shots, phase, noise


def _filter_setup():
    """The filter's model is the simulated IMU's (white PSDs, bias random walks, turn-on σ)."""
    n = NAVIGATION
    return cai.FilterSetup(n.accel.white**2, n.gyro.white**2, n.accel.bias_rw**2, n.gyro.bias_rw**2, 10,
                           sigma0=(1e-3, 1e-3, 1e-5, n.accel.bias_sigma, n.gyro.bias_sigma))


def _ins_setup(traj, p0, **kw):
    """The InsSetup cai_aided_ins builds from _filter_setup(), written out by hand."""
    f = _filter_setup()
    s = traj.initial_state()
    return InsSetup(t0=s["t0"], lla0=s["lla"], vel0=s["vel_ned"], q0=s["q_nb"], kind="rates", p0=p0,
                    accel_psd=f.accel_psd, gyro_psd=f.gyro_psd, accel_bias=BiasModel("random_walk", psd=f.accel_bias_psd),
                    gyro_bias=BiasModel("random_walk", psd=f.gyro_bias_psd), predict_every=f.predict_every, **kw)


def _cai_ins(record, **kw):
    traj, _, sensor, shots, phase, noise = record
    s = traj.initial_state()
    return cai.cai_aided_ins(s["t0"], s["lla"], s["vel_ned"], s["q_nb"], sensor, shots, phase=phase, noise=noise, kind="rates",
                             setup=_filter_setup(), **kw)


def _run(ins, imu):
    return ins.run(imu["time_s"], imu[GYRO], imu[ACCEL], progress=False)


def _assert_same(want, got):
    np.testing.assert_array_equal(got.nav.to_numpy(), want.nav.to_numpy())
    assert list(got.nav.columns) == list(want.nav.columns)
    for column in ("time_s", "rows", "nis", "rejected_rows"):
        np.testing.assert_array_equal(got.measurements[column].to_numpy(), want.measurements[column].to_numpy())


# ---- one construction path -------------------------------------------------------------------

def test_cai_aided_ins_is_the_aided_ins_of_one_cai_source(record):
    """cai_aided_ins equals aided_ins(setup, [CaiShots(...)]) bit for bit."""
    traj, imu, sensor, shots, phase, noise = record
    setup = _ins_setup(traj, _filter_setup().p0(0))
    want = _run(_cai_ins(record), imu)
    got = _run(aided_ins(setup, [cai.CaiShots(sensor, shots, phase=phase, noise=noise)]), imu)
    _assert_same(want, got)
    assert len(want.measurements) == len(shots) > 100


def test_the_same_source_feeds_several_ins(record):
    traj, imu, sensor, shots, phase, noise = record
    source = cai.CaiShots(sensor, shots, phase=phase, noise=noise)
    setup = _ins_setup(traj, _filter_setup().p0(0))
    _assert_same(_run(aided_ins(setup, source), imu), _run(aided_ins(setup, [source]), imu))


def test_cai_shots_and_position_fixes_feed_one_ins(record):
    """Position fixes added to the shots: every fix and shot is applied, in time order, and
    the position error (against the truth) drops below the CAI-only filter's."""
    traj, imu, sensor, shots, phase, noise = record
    setup = _ins_setup(traj, _filter_setup().p0(0))
    t_fix = np.arange(1.0, 6.0, 1.0)
    at = np.searchsorted(traj.time, t_fix)
    fixes = PositionFixes(t_fix, traj.lla[at], np.diag([0.01, 0.01, 0.01]))
    both = _run(aided_ins(setup, [cai.CaiShots(sensor, shots, phase=phase, noise=noise), fixes]), imu)
    alone = _run(aided_ins(setup, cai.CaiShots(sensor, shots, phase=phase, noise=noise)), imu)
    times = both.measurements["time_s"].to_numpy()
    assert len(times) == len(shots) + len(t_fix) and np.all(np.diff(times) >= 0)
    np.testing.assert_allclose(np.sort(np.concatenate([shots + 2 * sensor.T, t_fix])), times, rtol=0, atol=1e-6)

    def position_rms(result):
        e = traj.errors(result.nav)
        return float(np.sqrt(np.mean(e[["dpos_n_m", "dpos_e_m", "dpos_d_m"]].to_numpy() ** 2)))

    # the INS starts on the truth (1 mm prior): the fixes' 10 cm σ bound the error, not
    # make it smaller than a millimetre-level CAI-aided drift; the fixes are applied though
    assert position_rms(both) < 1.0 and position_rms(alone) < 1.0


def test_extra_states_take_their_initial_sigma_from_the_source(record):
    """A sensor with a lever-arm block: sigma0_extra on the source with the 15 x 15 INS p0
    runs exactly like the whole P0 (block diagonal) in the setup; without either, an
    InputError naming sources."""
    traj, imu, _, shots, phase, noise = record
    sensor = cai.CaiSensor(cai.Channels.cyclic(), 0.025, interpolation="cubic", omega_dot="pwl", jacobian_euler=True,
                           lever_arm_psd=1e-12, inflation=(NAVIGATION.accel.white**2, NAVIGATION.gyro.white**2))
    sigma = np.array([1e-3, 2e-3, 3e-3])
    p15 = _filter_setup().p0(0)
    split = _run(aided_ins(_ins_setup(traj, p15), cai.CaiShots(sensor, shots, phase=phase, noise=noise, sigma0_extra=sigma)), imu)
    whole = _run(aided_ins(_ins_setup(traj, block_diag(p15, np.diag(sigma**2))), cai.CaiShots(sensor, shots, phase=phase, noise=noise)), imu)
    _assert_same(split, whole)
    assert [c for c in split.nav.columns if "lever" in c] == [f"{p}cai_lever_arm[{i}]" for p in ("extra_", "sigma_") for i in range(3)]
    with pytest.raises(InputError, match="no initial covariance") as e:
        aided_ins(_ins_setup(traj, p15), cai.CaiShots(sensor, shots, phase=phase, noise=noise))
    assert (e.value.parameter, e.value.index) == ("sources", 0)


# ---- smoothing -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def smoothed(record):
    return _run(_cai_ins(record, smooth=True), record[1])


def test_smoothed_accelerometer_bias_is_better_than_the_filtered(record, smoothed):
    """Against the simulated biases: the smoothed σ of the accelerometer bias is never above
    the filtered one, and the smoothed bias error RMS is below the filtered one."""
    _, imu, *_ = record
    res = smoothed
    sigma = [f"sigma_accel_bias[{i}]" for i in range(3)]
    f, s = res.nav[sigma].to_numpy(), res.smoothed.nav[sigma].to_numpy()
    assert np.all(s <= f), np.max(s / f)
    assert np.all(s[0] < f[0])                        # the later shots observe the biases at the start too
    at = np.searchsorted(imu["time_s"].to_numpy(), res.nav["time_s"].to_numpy() - 1e-9)
    true = imu[["accel_bias_x_mps2", "accel_bias_y_mps2", "accel_bias_z_mps2"]].to_numpy()[at]
    columns = ["accel_bias_x_mps2", "accel_bias_y_mps2", "accel_bias_z_mps2"]
    rms = {k: float(np.sqrt(np.mean((r.nav[columns].to_numpy() - true) ** 2))) for k, r in (("filtered", res), ("smoothed", res.smoothed))}
    assert rms["smoothed"] < rms["filtered"], rms


def test_smoother_options_reach_the_setup(record, smoothed, tmp_path):
    """smooth_chunk, smooth_memory and smooth_dir are those of the INS setup: a forward
    pass in chunks of 7 epochs written to tmp_path (no memory allowed) smooths to the same
    solution as the default, held in memory."""
    ins = _cai_ins(record, smooth=True, smooth_chunk=7, smooth_memory=0, smooth_dir=str(tmp_path))
    assert (ins.setup.smooth, ins.setup.smooth_chunk, ins.setup.smooth_memory, ins.setup.smooth_dir) == (True, 7, 0, str(tmp_path))
    ins.process(record[1]["time_s"][:400], record[1][GYRO][:400], record[1][ACCEL][:400])
    assert any(tmp_path.rglob("*")), "the forward pass was not written to smooth_dir"
    ins = _cai_ins(record, smooth=True, smooth_chunk=7, smooth_memory=0, smooth_dir=str(tmp_path))
    res = _run(ins, record[1])
    np.testing.assert_allclose(res.smoothed.nav.to_numpy(), smoothed.smoothed.nav.to_numpy(), rtol=1e-12, atol=0)
    with pytest.raises(InputError) as e:
        _cai_ins(record, smooth=True, smooth_chunk=0)
    assert e.value.parameter == "smooth_chunk"


def test_smoothing_survives_a_skipped_shot(record):
    """A shot the record cannot complete is left out before the run; the rebuilt filter still
    stores its forward pass for the smoother."""
    traj, imu, sensor, _, phase, noise = record
    s = traj.initial_state()
    shots = np.array([0.5, 1.0, traj.time[-1] - 0.01])
    with pytest.warns(cai.IncompleteShotWarning, match="shot 2"):
        res = _run(cai.cai_aided_ins(s["t0"], s["lla"], s["vel_ned"], s["q_nb"], sensor, shots, phase=phase[:3], noise=noise[:3],
                                     kind="rates", setup=_filter_setup(), smooth=True), imu)
    assert len(res.measurements) == 2 and res.smoothed is not None and len(res.smoothed.nav) == len(res.nav)


# ---- incomplete shots in a composite ------------------------------------------------------------

def test_incomplete_shots_in_a_composite(record):
    """Next to position fixes, a shot at the record start is skipped with a warning
    ("skip", the filter rebuilt without it) or refused naming shots and its index
    ("error"), as cai_aided_ins does; CaiShots.incomplete lists it beforehand."""
    traj, imu, _, _, phase, noise = record
    sensor = cai.CaiSensor(cai.Channels.cyclic(), 0.025, omega_dot="savgol", savgol_half_width=8)
    shots = np.array([0.0, 0.5, 1.0])
    setup = _ins_setup(traj, _filter_setup().p0(0))
    fixes = PositionFixes([2.0], traj.lla[[400]], np.eye(3))
    source = cai.CaiShots(sensor, shots, phase=phase[:3], noise=noise[:3])
    assert source.incomplete(imu["time_s"])[["shot", "samples_before"]].values.tolist() == [[0, 6]]
    with pytest.warns(cai.IncompleteShotWarning, match=r"shot 0 \(start 0 s\) needs 6 IMU sample") as caught:
        res = _run(aided_ins(setup, [source, fixes]), imu)
    assert [w.message.index for w in caught if isinstance(w.message, cai.IncompleteShotWarning)] == [0]
    assert caught[0].filename == __file__
    np.testing.assert_allclose(res.measurements["time_s"], [0.55, 1.05, 2.0], atol=1e-6)
    # the filter without the skipped shot is the filter of the other two
    without = _run(aided_ins(setup, [cai.CaiShots(sensor, shots[1:], phase=phase[1:3], noise=noise[1:3]), fixes]), imu)
    _assert_same(without, res)
    with pytest.raises(InputError, match="needs 6 IMU sample") as e:
        _run(aided_ins(setup, [fixes, cai.CaiShots(sensor, shots, phase=phase[:3], noise=noise[:3], incomplete_shots="error")]), imu)
    assert (e.value.parameter, e.value.index) == ("shots", 0)


def test_copies_of_a_composite_mid_record_continue_the_same(record):
    traj, imu, sensor, shots, phase, noise = record
    setup = _ins_setup(traj, _filter_setup().p0(0))
    ins = aided_ins(setup, [cai.CaiShots(sensor, shots, phase=phase, noise=noise), PositionFixes([3.0], traj.lla[[600]], np.eye(3))])
    t, g, a = imu["time_s"].to_numpy(), imu[GYRO].to_numpy(), imu[ACCEL].to_numpy()
    ins.process(t[:500], g[:500], a[:500])
    copies = [pickle.loads(pickle.dumps(ins)), copy.deepcopy(ins)]
    want = [ins.process(t[500:], g[500:], a[500:]), ins.finish()]
    for c in copies:
        assert type(c) is type(ins)
        for x, y in zip(want, [c.process(t[500:], g[500:], a[500:]), c.finish()]):
            _assert_same(x, y)
    assert len(want[0].measurements) > 50


# ---- copies and bad input ------------------------------------------------------------------------

def test_copies_of_the_source_build_the_same_filter(record):
    traj, imu, sensor, shots, phase, noise = record
    source = cai.CaiShots(sensor, shots, population=np.full(phase.shape, 0.5), laser_phase=phase)
    setup = _ins_setup(traj, _filter_setup().p0(0))
    want = _run(aided_ins(setup, source), imu)
    for c in (pickle.loads(pickle.dumps(source)), copy.deepcopy(source)):
        assert type(c) is cai.CaiShots and c.data_kind == "recorded" and repr(c) == repr(source)
        for a, b in zip(c.data, source.data):
            np.testing.assert_array_equal(a, b)
        _assert_same(want, _run(aided_ins(setup, c), imu))


def _shots(record, **kw):
    _, _, sensor, shots, phase, noise = record
    args = {"phase": phase, "noise": noise, **kw}
    return cai.CaiShots(args.pop("sensor", sensor), args.pop("shots", shots), **{k: v for k, v in args.items() if v is not None})


@pytest.mark.parametrize("kw, parameter, index", [
    ({"phase": np.zeros((3, 6))}, "phase", None),                                 # 3 shots of data for many shots
    ({"noise": np.zeros(5)}, "noise", None),                                      # not a table
    ({"noise": None}, "noise", None),                                             # phase without noise
    ({"population": np.full((1, 6), 0.5)}, "population", None),                   # both instruments
    ({"phase": None, "noise": None}, "phase", None),                              # no data
    ({"incomplete_shots": "drop"}, "incomplete_shots", None),
    ({"extra0": np.zeros(3)}, "extra0", None),                                    # the sensor has no extra states
    ({"sigma0_extra": np.ones(3)}, "sigma0_extra", None),
    ({"shots": np.array([0.5, 0.51])}, "shots", None),                            # overlapping shots
])
def test_bad_arguments_name_themselves(record, kw, parameter, index):
    if "shots" in kw:
        kw = {**kw, "phase": np.zeros((2, 6)), "noise": np.zeros((2, 6))}
    with pytest.raises(InputError) as e:
        _shots(record, **kw)
    assert (e.value.parameter, e.value.index) == (parameter, index)


def test_bad_rows_and_types(record):
    phase = record[4].copy()
    phase[7, 2] = np.nan
    with pytest.raises(InputError) as e:
        _shots(record, phase=phase)
    assert (e.value.parameter, e.value.index) == ("phase", 7)
    lever = cai.CaiSensor(cai.Channels.cyclic(), 0.025, lever_arm_psd=1e-12)
    with pytest.raises(InputError) as e:
        _shots(record, sensor=lever, sigma0_extra=[1e-3, -1e-3, 1e-3])
    assert (e.value.parameter, e.value.index) == ("sigma0_extra", 1)
    with pytest.raises(InputError) as e:
        _shots(record, sensor=cai.CaiSensor(cai.Channels.cyclic(), -0.025))
    assert e.value.parameter == "sensor.T"
    with pytest.raises(TypeError, match="sensor"):
        _shots(record, sensor="six channels")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(_shots(record)) == len(record[3])
