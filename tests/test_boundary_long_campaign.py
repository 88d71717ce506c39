"""Calls that the million-call fuzz campaign (``python tests/fuzz.py --calls 1000000``)
found raising a foreign exception, naming a parameter the function does not have, or
returning NaN/inf from finite input. Each is the campaign's reproducer, checked against
the answer it must give: an ``InputError`` naming a real parameter, or a ``TypeError``."""

from __future__ import annotations

import numpy as np
import pytest

import atomnav
from atomnav import _core, astro, cai, diagnostics, rotation
from atomnav.cai import predictor
from atomnav.filter import engine, riccati
from atomnav.noise import allan, arma, baselines, synth
from atomnav.noise.filters import ArimaStateSpace, ArmaFilterConfig

TINY, HUGE = 5e-324, 1e308


def _input_error(parameter, call, index=None):
    with pytest.raises(atomnav.InputError) as e:
        call()
    assert e.value.parameter == parameter, str(e.value)
    if index is not None:
        assert e.value.index == index, str(e.value)
    return e.value


@pytest.mark.parametrize("call, parameter", [
    # the core named its own field instead of the caller's argument
    (lambda: _core.CaiGravity(g0=np.array([5.0, 7.0]), gradient=None, t_ref=0.0), "g0"),
    (lambda: _core.Motion.vasilyuk2024_stand(origin=np.zeros(13)), "origin"),
    (lambda: _core.Motion.stationary(origin=np.array([0.0]), duration=1.5, euler=np.array([0.27])), "origin"),
    (lambda: _core.Motion.vasilyuk2024_stand(origin=np.array([0.99, 1.23, 1.40])).truth(times=np.array([-3.8e-4, 3.4e-5])), "times"),
    # the Python wrappers name their own argument
    (lambda: atomnav.diagnostics.schuler_test(lat=100.0), "lat"),
    (lambda: atomnav.trajectory.stationary(10.0, origin=(3.0, 0.0, 0.0)), "origin"),
    (lambda: _core.astro_astro_increments(s_vf=np.ones((1, 1, 1)), p_avu=np.ones((1, 3, 3))), "s_vf"),
    (lambda: cai.slalom_covariance(duration=1e308), "duration"),
    (lambda: cai.slalom_covariance(duration=60.0, attitude_sigma=TINY), "attitude_sigma"),  # σ² = 0 named r
    # finite input, an output beyond the range of floats
    (lambda: _core.imu_gauss_markov_low_freq_asd(sigma=HUGE, tau=3.81), "sigma"),
    (lambda: _core.imu_random_walk_step_sigma(density=HUGE, dt=100.0), "density"),
    (lambda: predictor.k_eff(wavelength=TINY), "wavelength"),
    (lambda: predictor.total_from_t_sep(T=HUGE), "T"),
    (lambda: predictor.capture_limits(T=3.3e-209, v0=2.8), "T"),  # was ZeroDivisionError
    (lambda: engine.discretize(f=67.42249402142612, qc=100.0, dt=17.224185682635586, method="van_loan"), "dt"),
    (lambda: riccati.closed_loop_matrix(phi=-HUGE, h=2.0**64, gain=1e-9), "phi"),
    (lambda: allan.improvement_ratio(before=0.99999, after=HUGE), "after"),
    (lambda: synth.model_a(n=900, ar=-HUGE, ma=(-0.99,), burn_in=14), "ar"),
    (lambda: synth.model_b(n=900, tau0=0.0), "tau0"),  # was NaN
    (lambda: ArimaStateSpace.from_arma(ar=np.zeros(8), ma=HUGE, sigma2=0.001), "ma"),  # was an inf B Q Bᵀ
    (lambda: ArmaFilterConfig(ar=np.zeros(48), ma=100.0, sigma2=20.6, r0=77.0), "ar"),  # was "model"
    (lambda: synth.model_b(n=13, flicker_b=-HUGE), "flicker_b"),  # was numpy's "scale < 0"
    (lambda: synth.model_a(seed=-1, n=900), "seed"),  # was numpy's "expected non-negative integer"
    (lambda: arma.ljung_box(e=[1.4459627328942797], lags=-HUGE), "lags"),  # was "Maximum allowed size exceeded"
    (lambda: arma.durbin_watson(e=np.zeros(2)), "e"),  # was 0/0
    (lambda: baselines.butterworth_lowpass(omega=np.zeros(100), tau0=TINY, order=9), "tau0"),  # was scipy's ValueError
    (lambda: baselines.wavelet_denoise(omega=np.zeros(8), wavelet="paper_literal", level=17), "wavelet"),  # was pywt's
    (lambda: arma.ljung_box(e=[0.0] * 13, lags=10), "e"),  # was 0/0 NaN
    (lambda: allan.bias_stability(omega=np.array([1.7e308, -1.7e308])), "omega"),  # σ = 1.7e308·√2 = 2.4e308
    (lambda: atomnav.trajectory.nav_table([0.0], [[0.5, 0.5, 0.0]], [[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0, 0.0]]), "q_nb"),  # was "q"
    # a subnormal period or speed made the path's slope infinite; the NaN surfaced as "q_nb"
    (lambda: atomnav.trajectory.slalom(10.0, period=TINY), "period"),
    (lambda: atomnav.trajectory.slalom(10.0, speed=TINY), "speed"),
    (lambda: atomnav.trajectory.slalom(10.0, amp=HUGE, period=1e-10), "amp"),
    (lambda: atomnav.trajectory.sinusoidal(10.0, period_ned=(TINY, 1.0, 1.0)), "period_ned"),
    # a 1.2-million-sample stationary run took over 10 s
    (lambda: diagnostics.stationary_errors(lat=0.99999, hours=50.55306038528544, rate_hz=6.632903781541362), "hours"),
])
def test_the_campaign_findings_name_a_real_parameter(call, parameter):
    _input_error(parameter, call)


def test_an_overflowing_rotation_vector_names_its_row():
    rv = np.array([[-7.26e-4, 1e-3, 1e-3], [-7.26e-4, HUGE, -HUGE], [1e-3, 1e-3, 1e-3]])
    _input_error("rotvec", lambda: rotation.quat_from_rotvec(rv), index=1)
    q = rotation.quat_from_rotvec([0.0, 0.0, np.pi / 2])  # a quarter turn about z
    np.testing.assert_allclose(q, [np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)], atol=1e-15)


@pytest.mark.parametrize("call", [
    lambda: allan.allan_variance(data="axes", tau0=1.0),  # was numpy's ValueError
    lambda: allan.improvement_ratio(before=True, after=3, absolute=np.zeros((12, 3))),  # was "truth value ambiguous"
    lambda: ArimaStateSpace.from_arma(ar=[], ma=[0.1], sigma2="paper_literal"),  # was float()'s ValueError
    lambda: synth.model_a(n=5, ma=None),  # was scipy's NotImplementedError
    lambda: arma.select_arma(d=np.arange(8.0), max_p=np.ones((7, 3), dtype=bool), max_q=complex(1.0, 2.0)),  # was "truth value ambiguous"
    lambda: cai.accelerometer_sensor(T="all").shots(t0=28, t_end=2**63),  # was float()'s ValueError
])
def test_a_wrong_type_is_a_type_error(call):
    with pytest.raises(TypeError):
        call()


def test_files_that_are_not_the_expected_kind_name_path(tmp_path):
    table = tmp_path / "RATES"
    table.write_text("time_s,qw\n0.0,1.0\n")
    _input_error("path", lambda: astro.load_catalog(path=str(table)))
    _input_error("path", lambda: astro.Calibration.load(path=str(table)))  # was numpy's pickle ValueError
    bad_row = tmp_path / "catalog.csv"
    bad_row.write_text("id,x,y,z,mag\n1,1.0,0.0,0.0,2.0\n2,2.0,0.0,0.0,3.0\n")
    _input_error("path", lambda: astro.load_catalog(bad_row), index=1)


def test_the_checked_paths_still_give_the_closed_forms():
    # the checks must not change a representable answer
    assert predictor.k_eff(780.241e-9) == pytest.approx(4 * np.pi / 780.241e-9, rel=1e-15)
    assert predictor.total_from_t_sep(0.01) == 0.02
    lim = predictor.capture_limits(0.01)
    k = predictor.K_RB87
    assert lim["accelerometer"] == pytest.approx(np.pi / (2 * k * 1e-4), rel=1e-14)
    assert lim["gyro"] == pytest.approx(np.pi / (2 * 2 * k * 2.8 * 1e-4), rel=1e-14)
    np.testing.assert_allclose(allan.improvement_ratio([2.0, 4.0], [1.0, 5.0]), [50.0, -25.0])
    # 4 sin²(ωT/2)/ω² → T² as ω → 0, also where ω² underflows; and the closed form elsewhere
    T, w = 79.30004108279138, np.array([TINY, 1e-200, 0.3])
    np.testing.assert_allclose(cai.ideal_transfer(T, w), [T**2, T**2, 4 * np.sin(0.15 * T) ** 2 / 0.09], rtol=1e-14)
    assert np.isnan(allan.improvement_ratio(np.nan, 1.0))  # NaN in, NaN out, as documented
    # model A and B keep their seeded draws (the paper's reference numbers rest on them)
    y = synth.model_a()
    assert y.shape == (synth.N_SAMPLES,) and y.mean() == pytest.approx(synth.MEAN, abs=1e-12)


def test_bias_stability_of_rates_whose_squares_overflow():
    # was inf: the deviations ±5e307 square beyond the range of floats; σ = 5e307·√2
    assert allan.bias_stability(np.array([HUGE, 0.0], dtype=object)) == pytest.approx(HUGE / np.sqrt(2), rel=1e-15)
    assert allan.bias_stability(np.array([1.0, 2.0, 4.0, 7.0]), window=2) == pytest.approx(np.std([1.5, 5.5], ddof=1), rel=1e-15)
    assert allan.bias_stability(np.zeros(4)) == 0.0


def test_a_heading_beyond_the_range_of_squares_still_gives_a_rotation():
    # was a NaN quaternion named q_nb: the rotation vector's θ² overflowed
    tr = atomnav.trajectory.drive_with_yaw(rate_hz=2.0, duration=1.0, heading=HUGE)
    yaw = tr.df["yaw_rad"].to_numpy()
    np.testing.assert_allclose(yaw, np.arctan2(np.sin(HUGE), np.cos(HUGE)), atol=1e-9)  # ψ = ψ₀ + k(1 − cos) stays 1e308


def test_in_shot_noise_covers_a_shot_that_the_imu_spacing_does_not_divide():
    # was "shots: ... outside the IMU record": the grid ended at ⌊2T/dt⌋·dt < 2T
    sensor = cai.accelerometer_sensor(T=8.751752501183626)
    sigma, _ = cai.in_shot_noise(sensor, dt=12.209590018062322, q_accel=88.69, q_gyro=3.0)
    assert sigma.shape == (3, 3) and np.isfinite(sigma).all()
    assert (np.diag(sigma) > 0).all() and np.allclose(sigma, sigma.T, rtol=1e-12)
