"""Realistic mistakes with the aided INS, the CAI phase predictor, the INS error model, the
star-camera containers and the plausibility checks themselves never give a silent wrong
answer: a value in the wrong unit warns (atomnav.UnitWarning naming the argument, the unit
and the factor to SI), a bad value is an InputError naming the argument the user called
(and the row), and numbers given as strings are a TypeError naming it.

Oracles: the factors are the definitions of the units (standard gravity 9.80665 m/s²,
CGPM 1901; π/180 rad per degree; 1e-3 s per ms), the offending row is the row the test
corrupted, and a star attitude observed with the catalog's own directions through an
identity camera is the identity rotation (Wahba 1965)."""

import warnings

import numpy as np
import pytest

import atomnav as an
from atomnav import InputError, UnitWarning, earth

G0 = 9.80665  # standard gravity, m/s² per g (3rd CGPM, 1901)
DEG = np.pi / 180.0  # rad per degree
MS = 1e-3  # s per ms
LAT, LON, H = 0.8, 0.2, 100.0
OMEGA = 7.292115e-5  # Earth rate, rad/s (WGS-84)
N = 201  # 2 s at 100 Hz

FIX_TIME = np.array([0.5, 1.0, 1.5])
FIX_LLA = np.tile([LAT, LON, H], (3, 1))
NOISE = dict(p0=np.diag([1.0] * 3 + [0.01] * 3 + [1e-6] * 3 + [1e-4] * 3 + [1e-8] * 3), accel_psd=1e-6, gyro_psd=1e-10)


def _at_rest():
    """A level, north-facing IMU at rest (exact rates: Earth rate and −gravity in NED)."""
    t = np.arange(N) / 100.0
    gyro = np.tile([OMEGA * np.cos(LAT), 0.0, -OMEGA * np.sin(LAT)], (N, 1))
    accel = np.tile([0.0, 0.0, -earth.gravity(LAT, H)], (N, 1))
    return t, gyro, accel


def _aided(lla0=(LAT, LON, H), vel0=(0, 0, 0), q0=(1, 0, 0, 0), fix_lla=FIX_LLA):
    return an.filter.position_aided_ins(0.0, lla0, vel0, q0, "rates", FIX_TIME, fix_lla, np.tile(np.eye(3), (3, 1, 1)),
                                        **NOISE)


def _unit_warnings(record) -> list[UnitWarning]:
    return [w.message for w in record if issubclass(w.category, UnitWarning)]


@pytest.fixture
def no_unit_warning():
    """Inside the test, a UnitWarning is an error (a clean call must not warn)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnitWarning)
        yield


# ---- initial state and fixes of the aided INS -------------------------------------------

def test_position_aided_ins_initial_latitude_in_degrees_names_lla0():
    with pytest.raises(InputError, match="latitude") as e:
        _aided(lla0=(np.degrees(LAT), LON, H))
    assert (e.value.parameter, e.value.index) == ("lla0", None)


@pytest.mark.parametrize("field, value", [("vel0", (np.nan, 0.0, 0.0)), ("q0", (1.0, 0.1, 0.1, 0.1))])
def test_position_aided_ins_initial_velocity_and_attitude_errors_name_the_argument(field, value):
    with pytest.raises(InputError) as e:
        _aided(**{field: value})
    assert e.value.parameter == field


def test_cai_aided_ins_initial_latitude_in_degrees_names_lla0():
    sensor = an.cai.seed003_sensor()
    shots, phase = 0.1 + 0.05 * np.arange(3), np.zeros((3, len(sensor.channels)))
    with pytest.raises(InputError, match="latitude") as e:
        an.cai.cai_aided_ins(0.0, (np.degrees(LAT), LON, H), (0, 0, 0), (1, 0, 0, 0), sensor, shots, phase=phase,
                             noise=phase, kind="rates")
    assert e.value.parameter == "lla0"


def test_cai_aided_ins_initial_longitude_in_degrees_warns_naming_lla0():
    sensor = an.cai.seed003_sensor()
    shots, phase = 0.1 + 0.05 * np.arange(3), np.zeros((3, len(sensor.channels)))
    with pytest.warns(UnitWarning) as record:
        an.cai.cai_aided_ins(0.0, (LAT, 37.6, H), (0, 0, 0), (1, 0, 0, 0), sensor, shots, phase=phase, noise=phase, kind="rates")
    (w,) = _unit_warnings(record)
    assert (w.parameter, w.unit) == ("lla0", "deg")
    assert w.factor == pytest.approx(DEG, rel=1e-15)


def test_fix_latitude_in_degrees_is_an_input_error_naming_fix_lla_and_its_row():
    fix_lla = FIX_LLA.copy()
    fix_lla[2, 0] = np.degrees(LAT)  # before: NumericalError "diverged at sample 101" in run()
    with pytest.raises(InputError, match="latitude") as e:
        _aided(fix_lla=fix_lla)
    assert (e.value.parameter, e.value.index) == ("fix_lla", 2)


@pytest.mark.parametrize("argument", ["lla0", "fix_lla"])
def test_longitude_in_degrees_warns_naming_the_argument(argument):
    lla0, fix_lla = np.array([LAT, LON, H]), FIX_LLA.copy()
    if argument == "lla0":
        lla0[1] = np.degrees(LON)  # 11.5° east: beyond 2π as a number of radians
    else:
        fix_lla[:, 1] = np.degrees(LON)
    with pytest.warns(UnitWarning) as record:
        _aided(lla0=lla0, fix_lla=fix_lla)
    (w,) = _unit_warnings(record)
    assert (w.parameter, w.unit) == (argument, "deg")
    assert w.factor == pytest.approx(DEG, rel=1e-15)


def test_clean_aided_ins_does_not_warn(no_unit_warning):
    t, gyro, accel = _at_rest()
    result = _aided().run(t, gyro, accel, chunk_s=0.5, progress=False)
    assert abs(result.nav["h_m"].iloc[-1] - H) < 1.0  # at rest, fixed every 0.5 s at H


# ---- IMU records fed to the aided INS ------------------------------------------------------

@pytest.mark.parametrize("how", ["run", "process"])
def test_aided_ins_accelerations_in_g_warn_naming_accel(how):
    t, gyro, accel = _at_rest()
    ins = _aided()
    with pytest.warns(UnitWarning) as record:
        ins.run(t, gyro, accel / G0, chunk_s=0.5, progress=False) if how == "run" else ins.process(t, gyro, accel / G0)
    (w,) = _unit_warnings(record)  # run: once for the whole record, not once per chunk
    assert (w.parameter, w.unit) == ("accel", "g")
    assert w.factor == pytest.approx(G0, rel=1e-15)


@pytest.mark.parametrize("how", ["run", "process"])
def test_aided_ins_time_stamps_in_ms_warn_naming_time(how):
    t, gyro, accel = _at_rest()
    ins = _aided()
    with pytest.warns(UnitWarning) as record:
        ins.run(t / MS, gyro, accel, chunk_s=500.0, progress=False) if how == "run" else ins.process(t / MS, gyro, accel)
    (w,) = _unit_warnings(record)
    assert (w.parameter, w.unit) == ("time", "ms")
    assert w.factor == pytest.approx(MS, rel=1e-15)


def test_aided_ins_static_gyro_in_degrees_per_second_warns_naming_gyro():
    t, gyro, accel = _at_rest()
    with pytest.warns(UnitWarning) as record:
        _aided().run(t, gyro / DEG, accel, progress=False)
    (w,) = _unit_warnings(record)
    assert (w.parameter, w.unit) == ("gyro", "deg/s")
    assert w.factor == pytest.approx(DEG, rel=1e-15)


# ---- CAI phase predictor and the INS error model -------------------------------------------

@pytest.fixture(scope="module")
def sine():
    """A moving CAI platform: SineMotion positions and z-y-x Euler angles (rad), its IMU at
    200 Hz under 9.81 m/s² gravity."""
    motion = dict(position_poly=[[0, 1.0, 0.1], [0, 0.2, 0], [0, 0, 0]], position_sines=[[0, 2e-5, 9.7, 0.3]],
                  attitude_poly=[[0.01, 0, 0], [-0.02, 0, 0], [0.3, 0.05, 0]], attitude_sines=[[2, 5e-4, 3.7, 0.2]])
    t = np.arange(201) / 200.0
    f, w, _ = an.cai.motion_imu(an.cai.SineMotion(**motion), t, gravity=(0.0, 0.0, 9.81))
    return motion, t, f, w


@pytest.mark.parametrize("call", [an.cai.predict_phase, an.cai.predictor.check_jacobian])
def test_phase_predictor_accelerations_in_g_warn_naming_specific_force(sine, call):
    _, t, f, w = sine
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnitWarning)
        call(t, f, w, np.array([0.1, 0.5]), 0.05, an.cai.Channels.cyclic())  # the clean call is quiet
    with pytest.warns(UnitWarning) as record:
        call(t, f / G0, w, np.array([0.1, 0.5]), 0.05, an.cai.Channels.cyclic())
    got = _unit_warnings(record)  # check_jacobian: the same warning of its two predictor runs
    assert got and all((x.parameter, x.unit) == ("specific_force", "g") for x in got)
    assert all(x.factor == pytest.approx(G0, rel=1e-15) for x in got)


def test_sine_motion_euler_angles_in_degrees_warn_naming_attitude_poly(sine, no_unit_warning):
    motion, t, _, _ = sine
    an.cai.motion_imu(an.cai.SineMotion(**motion), t, gravity=(0.0, 0.0, 9.81))  # clean: quiet
    poly = np.array(motion["attitude_poly"], dtype=float)
    poly[:, 0] /= DEG  # the initial roll, pitch, yaw in degrees: yaw 0.3 rad → 17.2
    with pytest.warns(UnitWarning) as record:
        an.cai.motion_imu(an.cai.SineMotion(**{**motion, "attitude_poly": poly}), t, gravity=(0.0, 0.0, 9.81))
    (w,) = _unit_warnings(record)
    assert (w.parameter, w.unit) == ("attitude_poly", "deg")
    assert w.factor == pytest.approx(DEG, rel=1e-15)


def test_ins_error_model_specific_force_in_g_warns_naming_f_b(no_unit_warning):
    lla, vel, q = np.tile([LAT, LON, H], (5, 1)), np.zeros((5, 3)), np.tile([1.0, 0, 0, 0], (5, 1))
    f_b = np.tile([0.0, 0.0, -earth.gravity(LAT, H)], (5, 1))
    an.filter.engine.ins_error_model(lla, vel, q, f_b, gyro_psd=1e-10, accel_psd=1e-6)  # clean: quiet
    with pytest.warns(UnitWarning) as record:
        an.filter.engine.ins_error_model(lla, vel, q, f_b / G0, gyro_psd=1e-10, accel_psd=1e-6)
    (w,) = _unit_warnings(record)
    assert (w.parameter, w.unit) == ("f_b", "g")
    assert w.factor == pytest.approx(G0, rel=1e-15)


# ---- star catalog and observations ----------------------------------------------------------

STARS = np.array([[0.6, 0.0, 0.8], [0.0, 0.6, 0.8], [0.0, 0.0, 1.0]])


def test_catalog_converts_nested_lists_to_the_documented_arrays():
    cat = an.astro.Catalog(STARS.tolist(), [1, 2, 3], [7, 8, 9])
    assert isinstance(cat.dirs, np.ndarray) and cat.dirs.dtype == np.float64 and cat.dirs.shape == (3, 3)
    np.testing.assert_array_equal(cat.dirs, np.array(STARS.tolist()))
    np.testing.assert_array_equal(cat.mags, [1.0, 2.0, 3.0])
    assert cat.mags.dtype == np.float64 and cat.ids.dtype == np.int64
    np.testing.assert_array_equal(cat.ids, [7, 8, 9])


@pytest.mark.parametrize("field", ["dirs", "mags"])
def test_catalog_numbers_as_strings_are_a_type_error_naming_the_field(field):
    kw = dict(dirs=STARS, mags=np.array([1.0, 2.0, 3.0]), ids=np.arange(3))
    kw[field] = kw[field].astype(str)
    with pytest.raises(TypeError, match=rf"^{field}: "):
        an.astro.Catalog(**kw)


def test_catalog_rows_that_do_not_match_name_the_field():
    with pytest.raises(InputError) as e:
        an.astro.Catalog(STARS, [1.0, 2.0], np.arange(3))
    assert e.value.parameter == "mags"


def _obs(s_cf):
    return an.astro.results.Observations(np.array([0, 0, 0, 1, 1, 1]), np.zeros(6, dtype=np.int64), s_cf,
                                         np.vstack([STARS] * 2))


@pytest.mark.parametrize("field", ["s_cf", "g"])
def test_observations_numbers_as_strings_are_a_type_error_naming_the_field(field):
    kw = dict(epoch=np.array([0, 0, 0, 1, 1, 1]), camera=np.zeros(6, dtype=np.int64), s_cf=np.vstack([STARS] * 2),
              g=np.vstack([STARS] * 2))
    kw[field] = kw[field].astype(str)
    with pytest.raises(TypeError, match=rf"^{field}: "):
        an.astro.results.Observations(**kw)


def test_star_attitudes_of_observations_given_as_nested_lists_is_the_identity():
    obs = _obs(np.vstack([STARS] * 2).tolist())
    assert isinstance(obs.s_cf, np.ndarray) and obs.s_cf.dtype == np.float64
    s, _, stars = an.astro.star_attitudes(obs, 2, np.eye(3)[None], 7.8e-5)
    np.testing.assert_allclose(s, np.stack([np.eye(3)] * 2), atol=1e-12)  # camera = catalog directions: S = I
    np.testing.assert_array_equal(stars, [3, 3])


# ---- the plausibility checks, called directly ----------------------------------------------

@pytest.mark.parametrize("argument", ["time", "gyro", "accel"])
def test_plausibility_imu_numbers_as_strings_are_a_type_error_naming_the_argument(argument):
    t, gyro, accel = _at_rest()
    kw = dict(time=t, gyro=gyro, accel=accel)
    kw[argument] = kw[argument].astype(str)
    with pytest.raises(TypeError, match=rf"^{argument}: "):
        an.plausibility.imu(**kw, kind="rates")


def test_plausibility_specific_force_strings_are_a_type_error_naming_f():
    _, _, accel = _at_rest()
    with pytest.raises(TypeError, match=r"^f: "):
        an.plausibility.specific_force((accel / G0).astype(str), "f")
