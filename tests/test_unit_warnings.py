"""Unit plausibility warnings (atomnav.UnitWarning): each unit mistake of a user warns with
the argument, the likely unit and the factor, the factor turns the value into the right SI
input (checked against closed forms and scipy), the standard warnings filters silence or
raise it, and the library's own SI data never warns."""

import dataclasses
import pickle
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

import atomnav as an

G0 = 9.80665  # standard gravity, m/s² (3rd CGPM, 1901)
DEG = np.pi / 180
MS = 1e-3
NM = 1e-9
PERCENT = 0.01
MOSCOW_LAT = np.deg2rad(55.75)


def _unit_warnings(call):
    """Run ``call`` recording every warning; the result (or the exception it raised) and
    the UnitWarnings."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            out = call()
        except Exception as e:  # a unit mistake may also make the computation fail afterwards
            out = e
    return out, [w for w in caught if issubclass(w.category, an.UnitWarning)]


def _warns(call, parameter, unit, factor):
    """``call`` gives exactly one UnitWarning, about ``parameter`` in ``unit`` with ``factor``,
    shown at the caller's line in this file; returns the call's result."""
    out, caught = _unit_warnings(call)
    assert len(caught) == 1, [str(w.message) for w in caught]
    w = caught[0]
    assert (w.message.parameter, w.message.unit) == (parameter, unit), str(w.message)
    assert w.message.factor == pytest.approx(factor, rel=1e-12)
    text = str(w.message)
    assert text.startswith(f"{parameter}: ") and f"multiply by {factor:.6g}" in text
    if unit is not None:
        assert f"in {unit}" in text
    assert w.filename == __file__, f"shown at {w.filename}:{w.lineno}, not at the user's line"
    return out


def _silent(call):
    """``call`` gives no UnitWarning (raised as an error if it did); returns its result."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", an.UnitWarning)
        return call()


def _scaled(df, prefixes, factor):
    """A copy of ``df`` with the columns starting with ``prefixes`` (not the bias truth)
    multiplied by ``factor``."""
    out = df.copy()
    cols = [c for c in out.columns if c.startswith(prefixes) and "bias" not in c]
    out[cols] = out[cols] * factor
    return out


ACCEL = ("accel_", "dv_")
GYRO = ("gyro_", "dtheta_")


@pytest.fixture(scope="module")
def sinusoidal():
    traj = an.trajectory.sinusoidal(10.0, rate_hz=100.0)
    meas = {kind: an.imu.corrupt(traj.ideal_imu(kind), errors="tactical", dt=0.01, kind=kind, seed=7) for kind in ("rates", "increments")}
    return traj, meas


@pytest.fixture(scope="module")
def at_rest():
    traj = an.trajectory.stationary(60.0, rate_hz=100.0)
    meas = {kind: an.imu.corrupt(traj.ideal_imu(kind), errors="navigation", dt=0.01, kind=kind, seed=3) for kind in ("rates", "increments")}
    return traj, meas


# ---- the class and the filters -------------------------------------------------------

def test_unit_warning_is_a_user_warning_exported_at_top_level():
    assert issubclass(an.UnitWarning, UserWarning)
    assert "UnitWarning" in an.__all__


def test_ignore_filter_silences_it():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.simplefilter("ignore", an.UnitWarning)
        k = an.cai.k_eff(780.241)
    assert caught == []
    assert k == pytest.approx(4 * np.pi / 780.241, rel=1e-15)


def test_error_filter_raises_it():
    with warnings.catch_warnings():
        warnings.simplefilter("error", an.UnitWarning)
        with pytest.raises(an.UnitWarning, match="wavelength") as info:
            an.cai.k_eff(780.241)
    assert (info.value.parameter, info.value.unit, info.value.factor) == ("wavelength", "nm", NM)


def test_unit_warning_pickles_with_its_fields():
    with warnings.catch_warnings():
        warnings.simplefilter("error", an.UnitWarning)
        with pytest.raises(an.UnitWarning) as info:
            an.cai.phase_noise(0.03, 50.0)
    copy = pickle.loads(pickle.dumps(info.value))
    assert (type(copy), str(copy), copy.parameter, copy.unit, copy.factor) == (
        an.UnitWarning, str(info.value), "contrast", "%", PERCENT)


# ---- accelerations in g --------------------------------------------------------------

@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_integrate_with_accelerations_in_g_warns(sinusoidal, kind):
    traj, meas = sinusoidal
    clean = _silent(lambda: an.strapdown.integrate(meas[kind], **traj.initial_state(), kind=kind))
    in_g = _scaled(meas[kind], ACCEL, 1 / G0)
    wrong = _warns(lambda: an.strapdown.integrate(in_g, **traj.initial_state(), kind=kind), "imu", "g", G0)
    # what the warning prevents: the height runs away by hundreds of metres in 10 s
    assert abs(wrong["h_m"].iloc[-1] - clean["h_m"].iloc[-1]) > 100.0
    # and its factor is the fix
    fixed = _silent(lambda: an.strapdown.integrate(_scaled(in_g, ACCEL, G0), **traj.initial_state(), kind=kind))
    np.testing.assert_allclose(fixed["h_m"], clean["h_m"], atol=1e-6)


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_corrupt_with_accelerations_in_g_warns(sinusoidal, kind):
    traj, _ = sinusoidal
    in_g = _scaled(traj.ideal_imu(kind), ACCEL, 1 / G0)
    _warns(lambda: an.imu.corrupt(in_g, errors="tactical", dt=0.01, kind=kind, seed=7), "accel", "g", G0)


def test_corrupt_arrays_in_g_at_rest_warn():
    f = np.tile([0.0, 0.0, -1.0], (200, 1))  # 1 g up, in g
    w = np.zeros((200, 3))
    _warns(lambda: an.imu.corrupt(f, w, errors="navigation", dt=0.01, kind="rates"), "accel", "g", G0)


# ---- gyro rates in °/s ---------------------------------------------------------------

@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_integrate_static_gyro_in_degrees_per_second_warns(at_rest, kind):
    traj, meas = at_rest
    in_deg = _scaled(meas[kind], GYRO, 1 / DEG)
    _warns(lambda: an.strapdown.integrate(in_deg, **traj.initial_state(), kind=kind), "imu", "deg/s", DEG)


def test_corrupt_static_gyro_in_degrees_per_second_warns(at_rest):
    traj, _ = at_rest
    ideal = traj.ideal_imu("rates")
    f = ideal[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()
    w_deg = np.rad2deg(ideal[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy())
    _warns(lambda: an.imu.corrupt(f, w_deg, errors="navigation", dt=0.01, kind="rates"), "gyro", "deg/s", DEG)


def test_rate_beyond_35_rad_s_warns():
    f = np.tile([0.0, 0.0, -G0], (100, 1))
    w_deg = np.tile([0.0, 0.0, 57.29577951308232], (100, 1))  # a turntable at 1 rad/s, in °/s
    _warns(lambda: an.imu.corrupt(f, w_deg, errors="navigation", dt=0.01, kind="rates"), "gyro", "deg/s", DEG)


def test_fast_turn_in_degrees_per_second_is_flagged_by_the_phase_predictor():
    _warns(lambda: an.cai.phase_constant([[an.cai.K_RB87, 0, 0]], [0, 2.8, 0], [0.0, 0.0, 100.0], [0.0, 0.0, 0.0], 0.025),
           "angular_rate", "deg/s", DEG)


# ---- time stamps and sample intervals in ms ------------------------------------------

@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_integrate_with_millisecond_time_stamps_warns(sinusoidal, kind):
    traj, meas = sinusoidal
    ms = meas[kind].assign(time_s=meas[kind]["time_s"] * 1000.0)  # a 100 Hz log: median step 10
    state = {**traj.initial_state(), "t0": traj.initial_state()["t0"] * 1000.0}
    _warns(lambda: an.strapdown.integrate(ms, **state, kind=kind), "imu", "ms", MS)


def test_corrupt_with_time_stamps_in_ms_against_dt_warns(sinusoidal):
    traj, _ = sinusoidal
    ideal = traj.ideal_imu("rates")
    ms = ideal.assign(time_s=ideal["time_s"] * 1000.0)
    _warns(lambda: an.imu.corrupt(ms, errors="tactical", dt=0.01, kind="rates"), "accel", "ms", MS)


def test_simulator_dt_in_ms_warns():
    _warns(lambda: an.imu.ImuSimulator("navigation", dt=10.0), "dt", "ms", MS)


def test_dt_that_contradicts_time_stamps_warns(sinusoidal):
    traj, _ = sinusoidal
    ideal = traj.ideal_imu("rates")  # 100 Hz, stated as 200 Hz
    _warns(lambda: an.imu.corrupt(ideal, errors="tactical", dt=0.005, kind="rates"), "dt", None, 2.0)


# ---- longitude in degrees ------------------------------------------------------------

def test_lla_to_ecef_with_longitude_in_degrees_warns():
    wrong = _warns(lambda: an.earth.lla_to_ecef([MOSCOW_LAT, 37.6, 200.0]), "lla", "deg", DEG)
    right = _silent(lambda: an.earth.lla_to_ecef([MOSCOW_LAT, 37.6 * DEG, 200.0]))
    # the fixed call puts Moscow at 37.6° E: atan2(y, x) of its ECEF position
    assert np.arctan2(right[1], right[0]) == pytest.approx(np.deg2rad(37.6), abs=1e-12)
    assert np.linalg.norm(wrong - right) > 1e6


def test_integrate_with_initial_longitude_in_degrees_warns(sinusoidal):
    traj, meas = sinusoidal
    state = traj.initial_state()
    state["lla"] = [state["lla"][0], 37.6, state["lla"][2]]
    _warns(lambda: an.strapdown.integrate(meas["increments"], **state), "lla", "deg", DEG)


def test_trajectory_origin_with_longitude_in_degrees_warns():
    _warns(lambda: an.trajectory.stationary(1.0, origin=(MOSCOW_LAT, 37.6, 200.0)), "origin", "deg", DEG)


def test_trajectory_table_with_longitude_in_degrees_warns(sinusoidal):
    traj, _ = sinusoidal
    df = traj.df.assign(lon_rad=np.rad2deg(traj.df["lon_rad"]))
    _warns(lambda: an.trajectory.Trajectory.from_dataframe(df), "df", "deg", DEG)


def test_latitude_in_degrees_stays_an_error_without_a_warning():
    out, caught = _unit_warnings(lambda: an.earth.lla_to_ecef([55.75, 37.6, 200.0]))
    assert isinstance(out, an.InputError) and out.parameter == "lla"
    assert caught == []


# ---- Euler angles in degrees ---------------------------------------------------------

def test_quat_from_euler_in_degrees_warns_and_the_factor_matches_scipy():
    euler_deg = [10.0, 20.0, 30.0]
    _warns(lambda: an.rotation.quat_from_euler(euler_deg), "euler", "deg", DEG)
    q = _silent(lambda: an.rotation.quat_from_euler(np.array(euler_deg) * DEG))
    x, y, z, w = Rotation.from_euler("ZYX", euler_deg[::-1], degrees=True).as_quat()  # yaw, pitch, roll
    np.testing.assert_allclose(q * np.sign(q[0]), np.array([w, x, y, z]) * np.sign(w), atol=1e-15)


def test_dcm_from_euler_in_degrees_warns():
    _warns(lambda: an.rotation.dcm_from_euler([0.0, 0.0, 90.0]), "euler", "deg", DEG)


def test_stationary_euler_in_degrees_warns():
    _warns(lambda: an.trajectory.stationary(1.0, euler=(0.0, 0.0, 90.0)), "euler", "deg", DEG)


def test_generator_heading_in_degrees_warns():
    _warns(lambda: an.trajectory.sinusoidal(1.0, heading=30.0), "heading", "deg", DEG)


def test_trajectory_table_with_euler_columns_in_degrees_warns(sinusoidal):
    traj, _ = sinusoidal
    df = traj.df.drop(columns=["qw", "qx", "qy", "qz"])
    df[["roll_rad", "pitch_rad", "yaw_rad"]] = np.rad2deg(df[["roll_rad", "pitch_rad", "yaw_rad"]])
    _warns(lambda: an.trajectory.Trajectory.from_dataframe(df), "df", "deg", DEG)


# ---- CAI pulse separation in ms ------------------------------------------------------

def test_phase_constant_with_T_in_ms_warns_and_the_factor_gives_the_closed_form():
    k, f = [[an.cai.K_RB87, 0.0, 0.0]], [1.0, 0.0, 0.0]
    _warns(lambda: an.cai.phase_constant(k, [0, 0, 0], [0, 0, 0], f, 100.0), "T", "ms", MS)
    phase = _silent(lambda: an.cai.phase_constant(k, [0, 0, 0], [0, 0, 0], f, 100.0 * MS))
    # constant specific force, no rotation: φ = −T² k·f
    assert phase[0] == pytest.approx(-(0.1**2) * an.cai.K_RB87 * 1.0, rel=1e-12)


def test_sensor_T_in_ms_warns_naming_the_sensor_field():
    sensor = an.cai.seed003_sensor(T=25.0)
    _warns(lambda: an.cai.in_shot_noise(sensor, 1.0, 1.25e-11, 1.0576e-12), "sensor.T", "ms", MS)


def test_total_interrogation_time_in_ms_warns():
    _warns(lambda: an.cai.phase_seed000([[an.cai.K_RB87, 0, 0]], [0, 0, 0], [0, 0, 0], [1.0, 0, 0], 50.0), "T_total", "ms", MS)


@pytest.mark.parametrize("call", [
    lambda: an.cai.capture_limits(25.0),
    lambda: an.cai.dynamic_range(25.0),
    lambda: an.cai.ideal_transfer(25.0, [1.0]),
], ids=["capture_limits", "dynamic_range", "ideal_transfer"])
def test_every_T_in_ms_warns(call):
    _warns(call, "T", "ms", MS)


def test_dark_time_in_ms_warns():
    _warns(lambda: an.cai.response_area(25.0, 1e-5), "t_dark", "ms", MS)


# ---- wavelength in nm ----------------------------------------------------------------

def test_k_eff_of_a_wavelength_in_nm_warns_and_the_factor_gives_4pi_over_lambda():
    _warns(lambda: an.cai.k_eff(780.241), "wavelength", "nm", NM)
    k = _silent(lambda: an.cai.k_eff(780.241 * NM))
    assert k == pytest.approx(4 * np.pi / 780.241e-9, rel=1e-15)


# ---- contrast, offset and populations in % -------------------------------------------

def test_phase_noise_with_contrast_in_percent_warns_and_the_factor_gives_2_sigma_over_c():
    _warns(lambda: an.cai.phase_noise(0.03, 50.0), "contrast", "%", PERCENT)
    assert _silent(lambda: an.cai.phase_noise(0.03, 50.0 * PERCENT)) == pytest.approx(2 * 0.03 / 0.5, rel=1e-15)


def test_sensor_contrast_in_percent_warns_naming_the_sensor_field():
    sensor = dataclasses.replace(an.cai.seed003_sensor(), contrast=50.0)
    _warns(lambda: an.cai.in_shot_noise(sensor, 0.005, 1.25e-11, 1.0576e-12), "sensor.contrast", "%", PERCENT)


def test_readout_jacobian_with_contrast_in_percent_warns():
    _warns(lambda: an.cai.readout_jacobian(np.ones((1, 1, 12)), 0.0, np.pi / 2, contrast=50.0), "contrast", "%", PERCENT)


def test_population_in_percent_warns_instead_of_clipping():
    _warns(lambda: an.cai.invert_readout(50.0), "p", "%", PERCENT)
    # a mid-fringe population of 0.5 is a phase of π/2 on the rising flank (p = ½ − ½ cos φ)
    assert _silent(lambda: an.cai.invert_readout(50.0 * PERCENT)) == pytest.approx(np.pi / 2, abs=1e-15)


def test_readout_offset_in_percent_warns():
    _warns(lambda: an.cai.readout(0.3, offset=50.0), "offset", "%", PERCENT)


# ---- no warning on correct SI data ---------------------------------------------------

TRAJECTORIES = {
    "sinusoidal": lambda: an.trajectory.sinusoidal(60.0, rate_hz=100.0),
    "stationary": lambda: an.trajectory.stationary(60.0, rate_hz=100.0),
    "car": lambda: an.trajectory.car(),
    "hexapod": lambda: an.trajectory.hexapod(),
}


@pytest.fixture(scope="module", params=list(TRAJECTORIES))
def generated(request):
    return request.param, _silent(TRAJECTORIES[request.param])


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_ideal_imu_of_every_generator_integrates_without_warning(generated, kind):
    _, traj = generated
    _silent(lambda: an.strapdown.integrate(traj.ideal_imu(kind), **traj.initial_state(), kind=kind))


@pytest.mark.parametrize("preset", an.imu.preset_names())
@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_every_preset_and_kind_corrupts_and_integrates_without_warning(generated, preset, kind):
    name, traj = generated
    if name == "hexapod":  # 1 kHz: every preset at its full rate would cost 20 s; 200 Hz keeps the motion
        traj = _silent(lambda: an.trajectory.hexapod(rate_hz=200.0))
    dt = float(np.median(np.diff(traj.time)))
    meas = _silent(lambda: an.imu.corrupt(traj.ideal_imu(kind), errors=preset, dt=dt, kind=kind, seed=11))
    _silent(lambda: an.strapdown.integrate(meas, **traj.initial_state(), kind=kind))


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_streamed_chunks_of_a_moving_record_do_not_warn(generated, kind):
    _, traj = generated
    imu = traj.ideal_imu(kind)
    sd = an.strapdown.Strapdown(**traj.initial_state(), kind=kind)
    for lo in range(0, len(imu), 4099):
        _silent(lambda: sd.run(imu.iloc[lo:lo + 4099]))


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_moving_chunk_whose_mean_rate_is_near_57_earth_rates_does_not_warn(kind):
    # a 4099-row chunk of this 10-minute motion has a mean |ω| of 3.93e-3 rad/s, within 6 % of
    # Earth rate in °/s (4.18e-3): only the static test (its rate varies smoothly, far beyond
    # its sample-to-sample change) tells it from a gyro at rest read in °/s
    traj = an.trajectory.sinusoidal(600.0, rate_hz=100.0)
    imu = traj.ideal_imu(kind)
    sd = an.strapdown.Strapdown(**traj.initial_state(), kind=kind)
    for lo in range(0, len(imu), 4099):
        _silent(lambda: sd.run(imu.iloc[lo:lo + 4099]))


def test_si_cai_inputs_do_not_warn():
    sensor = an.cai.seed003_sensor()
    _silent(lambda: an.cai.k_eff())
    _silent(lambda: an.cai.phase_constant([[an.cai.K_RB87, 0, 0]], [0, 2.8, 0], [0, 0, 1e-3], [0, 0, -9.81], 0.025))
    _silent(lambda: an.cai.capture_limits(5.0))  # the satellite's T
    _silent(lambda: an.cai.phase_seed000([[an.cai.K_RB87, 0, 0]], [0, 0, 0], [0, 0, 0], [1.0, 0, 0], 10.0))
    _silent(lambda: an.cai.in_shot_noise(sensor, 0.005, 1.25e-11, 1.0576e-12))
    _silent(lambda: an.cai.invert_readout(an.cai.readout(np.linspace(0, 3, 50), sigma_p=0.03, seed=1)))
