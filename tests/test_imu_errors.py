"""IMU error model and simulation (atomnav.imu) against independent oracles: closed-form
variances and spectra of the noise processes, exact linear algebra for the deterministic
errors, source values of the presets, and one test per bad-input case."""

import math

import numpy as np
import pandas as pd
import pytest

import atomnav
from atomnav import imu

DEG = math.pi / 180.0
G0 = 9.80665


def _zeros(n):
    return np.zeros((n, 3)), np.zeros((n, 3))


def _errors(**kw):
    """The same triad errors on accelerometer and gyro."""
    return imu.ImuErrors(imu.TriadErrors(**kw), imu.TriadErrors(**kw))


def _bias_truth(df):
    return df[imu.BIAS_COLUMNS[0] + imu.BIAS_COLUMNS[1]].to_numpy()


def _measured(df, kind="rates"):
    f, w = imu.COLUMNS[kind]
    return df[f + w].to_numpy()


# --------------------------------------------------------------------------- conversions


def test_conversions_reproduce_seed003_noise_numbers():
    # seed-003 spec (E36): 5e-5 m/s² and 1.4544e-5 rad/s per sample at 200 Hz
    dt = 1 / 200
    assert imu.white_density(5e-5, dt) == pytest.approx(3.5355e-6, rel=1e-4)
    assert imu.white_density(1.4544e-5, dt) == pytest.approx(1.0284e-6, rel=1e-4)
    assert imu.white_density(1.4544e-5, dt) / (DEG / 60) == pytest.approx(0.00354, rel=2e-3)
    assert imu.white_sigma(3.5355e-6, dt) == pytest.approx(5e-5, rel=1e-4)
    assert imu.white_sigma(3.5355e-6, dt, "increments") == pytest.approx(5e-5 * dt, rel=1e-4)
    assert imu.random_walk_step_sigma(math.sqrt(9e-10), dt) == pytest.approx(2.1213e-6, rel=1e-4)
    assert imu.random_walk_step_sigma(2e-7, dt) == pytest.approx(1.4142e-8, rel=1e-4)
    assert imu.random_walk_density(1.4142e-8, dt) == pytest.approx(2e-7, rel=1e-4)


def test_conversions_reproduce_seed000_gauss_markov_numbers():
    # seed-000 spec §4 "Satellite: GM": Δt = 1 s, τ = 10 s, σ_gm = 2e-12 m/s²
    s = imu.gauss_markov_sigma(2e-12, 10.0, 1.0)
    assert s == pytest.approx(4.6975e-12, rel=1e-4)
    assert imu.gauss_markov_driving_sigma(s, 10.0, 1.0) == pytest.approx(2e-12, rel=1e-12)
    assert imu.gauss_markov_low_freq_asd(s, 10.0) == pytest.approx(2.10e-11, rel=3e-3)


def test_flicker_conversions_match_ieee952():
    # IEEE Std 952 Table C.1: Allan floor of bias instability B is B·√(2 ln 2/π) = 0.6643 B
    assert imu.flicker_allan_floor(1.0) == pytest.approx(0.664282, rel=1e-5)
    assert imu.flicker_psd(2.0, 0.5) == pytest.approx(4.0 / (math.pi * 0.5), rel=1e-14)


# --------------------------------------------------------------------------- deterministic errors


def _deterministic():
    rng = np.random.default_rng(5)
    def triad():
        m = rng.normal(0, 1e-3, (3, 3))
        np.fill_diagonal(m, 0.0)
        return imu.TriadErrors(bias=tuple(rng.normal(0, 1e-2, 3)), scale=tuple(rng.normal(0, 1e-3, 3)), misalignment=m)
    return imu.ImuErrors(triad(), triad())


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_scale_misalignment_bias_are_exact(kind):
    e = _deterministic()
    dt = 0.01
    rng = np.random.default_rng(6)
    f, w = rng.normal(0, 10, (100, 3)), rng.normal(0, 1, (100, 3))
    out = imu.corrupt(f, w, errors=e, dt=dt, kind=kind)
    per = dt if kind == "increments" else 1.0
    for t, y, cols in ((e.accel, f, imu.COLUMNS[kind][0]), (e.gyro, w, imu.COLUMNS[kind][1])):
        expect = y @ (np.eye(3) + np.diag(t.scale) + t.misalignment).T + np.asarray(t.bias) * per
        np.testing.assert_allclose(out[cols].to_numpy(), expect, rtol=0, atol=1e-14 * np.abs(y).max())
    np.testing.assert_array_equal(out[imu.BIAS_COLUMNS[0]].to_numpy(), np.tile(e.accel.bias, (100, 1)))


def test_increments_are_the_integral_of_rates_for_the_deterministic_part():
    # ω(t) = a + c sin(2πt/P): exact increments over coarse intervals of 0.1 s; the coarse
    # increment output must equal the sum of 100 fine rate outputs (0.001 s) times 0.001 s.
    a, c, p = np.array([0.1, -0.2, 0.3]), np.array([1.0, 2.0, -0.5]), 0.37
    def increment(t0, h):
        return a * h + c * p / (2 * np.pi) * (np.cos(2 * np.pi * t0 / p) - np.cos(2 * np.pi * (t0 + h) / p))[:, None]
    e = _deterministic()
    coarse, fine = 0.1, 0.001
    t_c, t_f = np.arange(20) * coarse, np.arange(2000) * fine
    dth = increment(t_c, coarse)
    inc = imu.corrupt(dth, 10 * dth, errors=e, dt=coarse, kind="increments")
    w_f = increment(t_f, fine) / fine  # interval-average rates
    rate = imu.corrupt(w_f, 10 * w_f, errors=e, dt=fine, kind="rates")
    integral = _measured(rate).reshape(20, 100, 6).sum(axis=1) * fine
    np.testing.assert_allclose(_measured(inc, "increments"), integral, rtol=1e-11, atol=1e-14)


def test_increment_equals_rate_times_dt_with_all_noise_terms_for_the_same_seed():
    e = imu.ImuErrors.preset("tactical")
    e.accel.gauss_markov = imu.GaussMarkov(1e-3, 3.0)
    e.gyro.bias_rw = 1e-6
    dt = 0.01
    rng = np.random.default_rng(7)
    f, w = rng.normal(0, 1, (500, 3)), rng.normal(0, 0.1, (500, 3))
    r = imu.corrupt(f, w, errors=e, dt=dt, kind="rates", seed=11)
    i = imu.corrupt(f * dt, w * dt, errors=e, dt=dt, kind="increments", seed=11)
    np.testing.assert_allclose(_measured(i, "increments"), _measured(r) * dt, rtol=1e-12, atol=1e-18)
    np.testing.assert_array_equal(_bias_truth(i), _bias_truth(r))


# --------------------------------------------------------------------------- noise statistics


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_white_noise_sigma_matches_the_psd_conversion(kind):
    n_density, dt, n = 2e-3, 0.005, 200_000
    out = imu.corrupt(*_zeros(n), errors=_errors(white=n_density), dt=dt, kind=kind, seed=1)
    sigma = n_density / math.sqrt(dt) if kind == "rates" else n_density * math.sqrt(dt)
    ratio = _measured(out, kind).var(axis=0, ddof=1) / sigma**2
    # sample variance / σ² ~ χ²_{n−1}/(n−1): standard deviation √(2/(n−1)); 5σ band
    assert np.all(np.abs(ratio - 1) < 5 * math.sqrt(2 / (n - 1))), ratio
    assert np.all(_bias_truth(out) == 0.0)


def test_bias_random_walk_variance_grows_as_k2_t_across_seeds():
    k, dt, n, seeds = 1e-3, 0.1, 50, 1000
    ends, mids, firsts, integrals = [], [], [], []
    for s in range(seeds):
        out = imu.corrupt(*_zeros(n), errors=_errors(bias_rw=k), dt=dt, kind="increments", seed=s)
        b = _bias_truth(out)
        ends.append(b[-1])
        mids.append(b[9])
        firsts.append(b[0])
        integrals.append(_measured(out, "increments").sum(axis=0))
    m = seeds * 6  # realisations (6 axes per run)
    tol = 5 * math.sqrt(2 / m)
    # bias truth of sample j is the average of b over [j dt, (j+1) dt]: Var = K²(j dt + dt/3)
    # (j = 0 tests the within-interval integral alone: Var = K² dt/3)
    for j, x in ((n - 1, ends), (9, mids), (0, firsts)):
        assert np.mean(np.square(x)) / (k**2 * (j * dt + dt / 3)) == pytest.approx(1, abs=tol)
    # the summed increments are ∫_0^T b dt: Var = K² T³/3
    t = n * dt
    assert np.mean(np.square(integrals)) / (k**2 * t**3 / 3) == pytest.approx(1, abs=tol)


def test_gauss_markov_stationary_variance_and_autocorrelation_at_tau():
    sigma, tau, dt, n = 2e-3, 1.0, 0.01, 400_000
    out = imu.corrupt(*_zeros(n), errors=_errors(gauss_markov=imu.GaussMarkov(sigma, tau)), dt=dt, kind="rates", seed=3)
    b = _bias_truth(out)
    x = dt / tau  # interval averaging: Var = 2σ²(x − 1 + e^{−x})/x² (≈ σ²(1 − x/3))
    var_avg = 2 * sigma**2 * (x - 1 + math.exp(-x)) / x**2
    # T/τ = 4000 correlation times; spread over 12 seeds: 0.012 (variance ratio) and
    # 0.0056 (lag-τ autocorrelation), so the bands are ≈ 4σ and 5σ
    assert np.mean(b.var(axis=0)) / var_avg == pytest.approx(1, abs=0.045)
    lag = round(tau / dt)
    rho = np.mean([np.corrcoef(b[:-lag, j], b[lag:, j])[0, 1] for j in range(6)])
    assert rho == pytest.approx(math.exp(-1), abs=0.03)


def test_gauss_markov_increment_variance_is_the_integrated_ou_closed_form():
    # Δt = τ: Var ∫m over one interval = 2σ²τ²(x − 1 + e^{−x}) with x = 1, i.e. 0.736 σ²τ²
    # (σ²Δt² if the in-interval correlation were ignored)
    sigma, tau, n = 2e-3, 1.0, 100_000
    e = _errors(gauss_markov=imu.GaussMarkov(sigma, tau))
    d = _measured(imu.corrupt(*_zeros(n), errors=e, dt=tau, kind="increments", seed=12), "increments")
    expect = 2 * sigma**2 * tau**2 * math.exp(-1)
    # consecutive increments correlate (ρ₁ = (1 − e^{−1})²/(2e^{−1}) = 0.54, ρ_k = ρ₁e^{−(k−1)}),
    # inflating the variance of the estimate by 1 + 2Σρ_k² ≈ 1.7; 5σ band over 6 axes
    assert np.mean(d.var(axis=0)) / expect == pytest.approx(1, abs=5 * math.sqrt(2 * 1.7 / (6 * n)))


def test_flicker_psd_has_slope_minus_one_and_ieee_level_in_its_band():
    b, f_lo, f_hi, dt, n = 1e-3, 1e-3, 1.0, 0.1, 2**20
    e = imu.ImuErrors(accel=imu.TriadErrors(flicker=imu.Flicker(b, f_lo, f_hi)))
    x = _bias_truth(imu.corrupt(*_zeros(n), errors=e, dt=dt, kind="rates", seed=4))[:, :3]
    # averaged Hann-windowed periodogram (numpy), one-sided: 2|X|²Δt/Σw²
    seg = 2**14
    win = np.hanning(seg)
    segs = x[: n - n % seg].reshape(-1, seg, 3) - x.mean(axis=0)
    spec = np.abs(np.fft.rfft(segs * win[None, :, None], axis=1)) ** 2
    psd = 2 * dt * spec.mean(axis=(0, 2)) / np.sum(win**2)
    f = np.fft.rfftfreq(seg, dt)
    band = (f >= 5e-3) & (f <= 0.5)
    # spread over 5 seeds: slope −1.006 ± 0.004, level 0.995 ± 0.004; the model itself is
    # within −1.4 % of B²/(πf) in the band
    slope = np.polyfit(np.log(f[band]), np.log(psd[band]), 1)[0]
    assert slope == pytest.approx(-1.0, abs=0.03)
    level = np.mean(psd[band] * math.pi * f[band] / b**2)  # oracle: B²/(πf)
    assert level == pytest.approx(1.0, abs=0.04)


def _overlapping_adev(x, dt, m):
    """Overlapping Allan deviation of rate samples at τ = mΔt (textbook cumulative-sum form)."""
    c = np.concatenate([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)]) * dt
    d = c[2 * m :] - 2 * c[m:-m] + c[: -2 * m]
    return np.sqrt(np.mean(d**2, axis=0) / (2 * (m * dt) ** 2))


def test_navigation_preset_allan_deviation_matches_seed003_spec():
    # seed-003 spec §4 "Allan deviation of simulated IMU": 1 h at 200 Hz, ADEV_a(1 s) =
    # 3.5355e-6 m/s² from white noise alone, and √(q_a/τ + q_ra τ/3) with the random walk; ±5 %
    dt, n = 1 / 200, 720_000
    nav = imu.ImuErrors.preset("navigation")
    nav.accel.bias_sigma = 0.0
    f_cols = imu.COLUMNS["rates"][0]
    white_only = imu.ImuErrors(imu.TriadErrors(white=nav.accel.white))
    a = imu.corrupt(*_zeros(n), errors=white_only, dt=dt, kind="rates", seed=13)[f_cols].to_numpy()
    assert np.mean(_overlapping_adev(a, dt, 200)) == pytest.approx(3.5355e-6, rel=0.05)
    a = imu.corrupt(*_zeros(n), errors=nav, dt=dt, kind="rates", seed=13)[f_cols].to_numpy()
    for tau in (1.0, 10.0):
        expect = math.sqrt(1.25e-11 / tau + 9e-10 * tau / 3)
        assert np.mean(_overlapping_adev(a, dt, round(tau / dt))) == pytest.approx(expect, rel=0.05)


# --------------------------------------------------------------------------- seeds and streaming


def _full():
    e = imu.ImuErrors.preset("tactical")
    for t in (e.accel, e.gyro):
        t.scale = (1e-4, -2e-4, 3e-4)
        t.bias_rw = 1e-5
        t.gauss_markov = imu.GaussMarkov(1e-4, 5.0)
    return e


def test_same_seed_same_numbers_different_seed_different_numbers():
    f, w = np.ones((300, 3)), np.ones((300, 3))
    a = imu.corrupt(f, w, errors=_full(), dt=0.01, kind="rates", seed=123)
    b = imu.corrupt(f, w, errors=_full(), dt=0.01, kind="rates", seed=123)
    c = imu.corrupt(f, w, errors=_full(), dt=0.01, kind="rates", seed=124)
    pd.testing.assert_frame_equal(a, b)
    assert not np.any(a.to_numpy() == c.to_numpy())


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_chunked_stream_equals_one_batch_call(kind):
    rng = np.random.default_rng(8)
    f, w = rng.normal(0, 1, (1000, 3)), rng.normal(0, 1, (1000, 3))
    batch = imu.corrupt(f, w, errors=_full(), dt=0.01, kind=kind, seed=9)
    sim = imu.ImuSimulator(_full(), 0.01, kind, seed=9)
    cuts = [0, 1, 1, 38, 538, 1000]
    chunks = [sim.corrupt(f[lo:hi], w[lo:hi]) for lo, hi in zip(cuts[:-1], cuts[1:])]
    pd.testing.assert_frame_equal(pd.concat(chunks), batch, check_exact=True)


def test_dataframe_stream_in_and_out():
    f, w = np.ones((4, 3)), np.zeros((4, 3))
    cols = imu.COLUMNS["increments"]
    df = pd.DataFrame(np.hstack([f, w]), columns=cols[0] + cols[1])
    df.insert(0, "time_s", np.arange(4) * 0.5)
    out = imu.corrupt(df, errors="mems", dt=0.5, kind="increments", seed=2)
    ref = imu.corrupt(f, w, errors="mems", dt=0.5, kind="increments", seed=2)
    np.testing.assert_array_equal(out["time_s"].to_numpy(), df["time_s"].to_numpy())
    pd.testing.assert_frame_equal(out.drop(columns="time_s"), ref)


def test_accel_and_gyro_are_independent_streams():
    n = 100_000
    e = _errors(white=1.0)
    out = _measured(imu.corrupt(*_zeros(n), errors=e, dt=1.0, kind="rates", seed=10))
    r = np.corrcoef(out.T)[:3, 3:]
    assert np.all(np.abs(r) < 5 / math.sqrt(n)), r
    # changing the accelerometer model leaves the gyro realisation untouched, and adding a
    # term leaves the other terms' realisations untouched
    e2 = _errors(white=1.0)
    e2.accel.white = 3.0
    e2.accel.gauss_markov = imu.GaussMarkov(0.5, 2.0)
    df2 = imu.corrupt(*_zeros(n), errors=e2, dt=1.0, kind="rates", seed=10)
    out2, bias2 = _measured(df2), _bias_truth(df2)
    np.testing.assert_array_equal(out2[:, 3:], out[:, 3:])
    # true input is zero, so measured − bias truth is the white noise alone
    np.testing.assert_allclose(out2[:, :3] - bias2[:, :3], 3 * out[:, :3], rtol=0, atol=1e-12)


def test_turn_on_bias_is_constant_per_run_with_the_given_sigma():
    sigma, seeds = 2e-3, 400
    draws = []
    for s in range(seeds):
        b = _bias_truth(imu.corrupt(*_zeros(5), errors=_errors(bias_sigma=sigma, bias=(1.0, 0, 0)), dt=0.1, kind="rates", seed=s))
        assert np.all(b == b[0])
        draws.append(b[0] - [1.0, 0, 0, 1.0, 0, 0])
    m = seeds * 6
    assert np.mean(np.square(draws)) / sigma**2 == pytest.approx(1, abs=5 * math.sqrt(2 / m))


# --------------------------------------------------------------------------- presets


def test_presets_carry_their_source_values():
    nav = imu.ImuErrors.preset("navigation")  # seed-003 spec (E36)
    assert imu.white_sigma(nav.accel.white, 1 / 200) == pytest.approx(5e-5, rel=1e-12)
    assert imu.white_sigma(nav.gyro.white, 1 / 200) == pytest.approx(1.4544e-5, rel=1e-12)
    assert nav.accel.bias_rw**2 == pytest.approx(9e-10, rel=1e-12)
    assert nav.gyro.bias_rw**2 == pytest.approx(4e-14, rel=1e-12)
    mems = imu.ImuErrors.preset("mems")  # seed-000 spec decision 13
    assert mems.accel.bias == pytest.approx((2e-3, -1.5e-3, 1e-3))
    assert mems.gyro.bias == pytest.approx((5e-5, -4e-5, 3e-5))
    assert (mems.accel.white, mems.gyro.white) == pytest.approx((5e-5, 1.5e-5))
    assert (mems.accel.bias_rw**2, mems.gyro.bias_rw**2) == pytest.approx((1e-12, 1e-16), rel=1e-12)
    es = imu.ImuErrors.preset("electrostatic_space")  # seed-000 spec decision 12
    assert es.accel.white == pytest.approx(1e-10)
    gm = es.accel.gauss_markov
    assert gm.tau == 10.0
    assert gm.sigma * math.sqrt(1 - math.exp(-2 * 1.0 / gm.tau)) == pytest.approx(2e-12, rel=1e-12)
    assert imu.ImuErrors.preset("electrostatic_space_drift").accel.bias_rw**2 == pytest.approx(1e-21, rel=1e-12)
    # Demidov 2009 classes (spec gnss-ins-tight-demidov2009.md §3), field units by hand
    for name, drift_dph, bias_ug, arw, vrw_ug in (
        ("precise", 0.05, 20, 0.003, 10),
        ("medium", 1, 200, 0.05, 50),
        ("coarse", 30, 3000, 0.5, 200),
    ):
        p = imu.ImuErrors.preset(name)
        assert p.gyro.bias_sigma == pytest.approx(drift_dph * DEG / 3600, rel=1e-12)
        assert p.accel.bias_sigma == pytest.approx(bias_ug * 1e-6 * G0, rel=1e-12)
        assert p.gyro.white == pytest.approx(arw * DEG / 60, rel=1e-12)
        assert p.accel.white == pytest.approx(vrw_ug * 1e-6 * G0, rel=1e-12)
        # random walk of 1 % of the bias per √h
        assert p.gyro.bias_rw * 60 == pytest.approx(0.01 * p.gyro.bias_sigma, rel=1e-12)
        assert p.accel.bias_rw * 60 == pytest.approx(0.01 * p.accel.bias_sigma, rel=1e-12)


def test_summary_gives_field_units():
    s = imu.ImuErrors.preset("medium").summary().set_index(["sensor", "parameter"])["value_field"]
    assert s["gyro", "bias_sigma"] == pytest.approx(1.0)
    assert s["gyro", "white"] == pytest.approx(0.05)
    assert s["accel", "bias_sigma"] == pytest.approx(200.0)
    assert s["accel", "white"] == pytest.approx(50.0)
    assert s["gyro", "bias_rw"] == pytest.approx(0.01)  # °/h per √h


def test_user_presets_extend_the_registry():
    e = _errors(white=1e-4, bias=(1e-3, 0, 0))
    imu.register_preset("test_quantum_grade", e)
    assert "test_quantum_grade" in imu.preset_names()
    got = imu.ImuErrors.preset("test_quantum_grade")
    assert got.accel.white == 1e-4 and got is not e
    f = np.zeros((3, 3))
    pd.testing.assert_frame_equal(imu.corrupt(f, f, errors="test_quantum_grade", dt=0.1, kind="rates"), imu.corrupt(f, f, errors=e, dt=0.1, kind="rates"))


# --------------------------------------------------------------------------- bad input, one test per case


def _raises(match, fn, *a, **kw):
    with pytest.raises(ValueError, match=match):
        fn(*a, **kw)


def test_bad_nan_in_accel_names_field_and_index():
    f, w = _zeros(10)
    f[7, 1] = np.nan
    _raises(r"accel: non-finite value nan at index 7", imu.corrupt, f, w, errors="mems", dt=0.01, kind="rates")


def test_bad_inf_in_gyro_names_field_and_index():
    f, w = _zeros(10)
    w[2, 0] = np.inf
    _raises(r"gyro: non-finite value inf at index 2", imu.corrupt, f, w, errors="mems", dt=0.01, kind="rates")


def test_bad_stream_shape():
    _raises(r"accel: expected shape \(N, 3\), got \(10, 2\)", imu.corrupt, np.zeros((10, 2)), np.zeros((10, 3)), errors="mems", dt=0.01, kind="rates")


def test_bad_stream_lengths_differ():
    _raises(r"gyro: expected 10 rows like accel, got 9", imu.corrupt, np.zeros((10, 3)), np.zeros((9, 3)), errors="mems", dt=0.01, kind="rates")


def test_bad_gyro_missing():
    _raises(r"gyro: required", imu.corrupt, np.zeros((10, 3)), errors="mems", dt=0.01, kind="rates")


def test_bad_dataframe_columns():
    df = pd.DataFrame(np.zeros((2, 6)), columns=imu.COLUMNS["rates"][0] + imu.COLUMNS["rates"][1])
    _raises(r"accel: missing column\(s\) \['dv_x_mps'.*expected \['dv_x_mps'", imu.corrupt, df, errors="mems", dt=0.01, kind="increments")


def test_bad_zero_dt():
    _raises(r"dt: must be finite and > 0, got 0", imu.ImuSimulator, "mems", 0.0)


def test_bad_negative_dt():
    _raises(r"dt: must be finite and > 0, got -0.01", imu.ImuSimulator, "mems", -0.01)


def test_bad_unknown_preset_lists_known_names():
    _raises(r"preset: unknown option 'strategic'.*'coarse'.*'navigation'", imu.ImuErrors.preset, "strategic")


def test_bad_unknown_preset_in_simulator():
    # the simulator's own argument is named (fuzz seed 20261202: it named ImuErrors.preset's)
    _raises(r"errors: unknown option 'nav'.*'tactical'", imu.ImuSimulator, "nav", 0.01)


def test_bad_unknown_kind():
    _raises(r"kind: unknown option .samples.; choose one of rates, increments", imu.ImuSimulator, "mems", 0.01, "samples")


def test_bad_negative_white_density():
    _raises(r"accel.white: must be finite and >= 0, got -1", imu.ImuSimulator, _errors(white=-1.0), 0.01)


def test_bad_negative_bias_rw():
    _raises(r"accel.bias_rw: must be finite and >= 0", imu.ImuSimulator, _errors(bias_rw=-1e-3), 0.01)


def test_bad_negative_bias_sigma():
    _raises(r"accel.bias_sigma: must be finite and >= 0", imu.ImuSimulator, _errors(bias_sigma=-1e-3), 0.01)


def test_bad_negative_gauss_markov_sigma():
    e = imu.ImuErrors(gyro=imu.TriadErrors(gauss_markov=imu.GaussMarkov(-1.0, 1.0)))
    _raises(r"gyro.gauss_markov.sigma: must be finite and >= 0", imu.ImuSimulator, e, 0.01)


def test_bad_zero_gauss_markov_tau():
    e = imu.ImuErrors(accel=imu.TriadErrors(gauss_markov=imu.GaussMarkov(1.0, 0.0)))
    _raises(r"accel.gauss_markov.tau: must be finite and > 0, got 0", imu.ImuSimulator, e, 0.01)


def test_bad_negative_gauss_markov_tau():
    e = imu.ImuErrors(accel=imu.TriadErrors(gauss_markov=imu.GaussMarkov(1.0, -2.0)))
    _raises(r"accel.gauss_markov.tau: must be finite and > 0, got -2", imu.ImuSimulator, e, 0.01)


def test_bad_flicker_band_above_nyquist():
    e = imu.ImuErrors(accel=imu.TriadErrors(flicker=imu.Flicker(1e-3, 1e-3, 10.0)))
    _raises(r"accel.flicker.f_hi: must not exceed the Nyquist frequency 5 Hz", imu.ImuSimulator, e, 0.1)


def test_bad_flicker_band_inverted():
    e = imu.ImuErrors(gyro=imu.TriadErrors(flicker=imu.Flicker(1e-3, 1e-2, 1e-3)))
    _raises(r"gyro.flicker.f_hi: must exceed f_lo", imu.ImuSimulator, e, 0.1)


def test_bad_bias_length():
    _raises(r"accel.bias: expected shape \(3,\), got \(2,\)", imu.ImuSimulator, _errors(bias=(1.0, 2.0)), 0.01)


def test_bad_nan_bias_names_index():
    _raises(r"accel.bias: non-finite value nan at index 1", imu.ImuSimulator, _errors(bias=(0.0, np.nan, 0.0)), 0.01)


def test_bad_misalignment_shape():
    e = imu.ImuErrors(gyro=imu.TriadErrors(misalignment=np.zeros((2, 3))))
    _raises(r"gyro.misalignment: expected shape \(3, 3\), got \(2, 3\)", imu.ImuSimulator, e, 0.01)


def test_bad_nan_misalignment_names_row_and_column():
    m = np.zeros((3, 3))
    m[2, 0] = np.nan
    e = imu.ImuErrors(accel=imu.TriadErrors(misalignment=m))
    _raises(r"accel.misalignment: non-finite value at index \(2, 0\)", imu.ImuSimulator, e, 0.01)


def test_bad_misalignment_diagonal():
    m = np.zeros((3, 3))
    m[1, 1] = 1e-3
    e = imu.ImuErrors(gyro=imu.TriadErrors(misalignment=m))
    _raises(r"gyro.misalignment: diagonal must be zero.*index \(1, 1\)", imu.ImuSimulator, e, 0.01)


def test_bad_negative_seed():
    _raises(r"seed: must be an integer in \[0, 2\*\*64\), got -1", imu.ImuSimulator, "mems", 0.01, seed=-1)


def test_bad_register_builtin_name():
    _raises(r"name: .mems. is a built-in preset", imu.register_preset, "mems", imu.ImuErrors())


def test_bad_conversion_zero_dt():
    _raises(r"dt: must be finite and > 0, got 0", imu.white_sigma, 1e-3, 0.0)


def test_bad_conversion_nonpositive_tau():
    _raises(r"tau: must be finite and > 0, got -1", imu.gauss_markov_sigma, 1e-3, -1.0, 0.01)


def test_bad_chunk_leaves_the_simulator_state_unchanged():
    f, w = np.ones((20, 3)), np.ones((20, 3))
    sim = imu.ImuSimulator(_full(), 0.01, "rates", seed=5)
    bad = f.copy()
    bad[4, 2] = np.nan
    _raises(r"accel: non-finite value nan at index 4", sim.corrupt, bad, w)
    pd.testing.assert_frame_equal(sim.corrupt(f, w), imu.corrupt(f, w, errors=_full(), dt=0.01, kind="rates", seed=5))


def test_corrupts_a_trajectory_imu_table_and_feeds_the_strapdown():
    """The generator's IMU table (time_s + project column names) goes straight through the
    simulator and into the strapdown; a constant accelerometer bias alone then gives
    the closed-form early error ½·b·t² (t ≪ Schuler period)."""
    import atomnav as an

    traj = an.trajectory.stationary(20.0, 100.0)
    ideal = traj.ideal_imu("increments")
    e = imu.ImuErrors()
    e.accel.bias = np.array([1e-3, 0.0, 0.0])
    meas = imu.corrupt(ideal, errors=e, dt=0.01, kind="increments", seed=1)
    np.testing.assert_array_equal(meas["time_s"], ideal["time_s"])
    nav = an.strapdown.integrate(meas, **traj.initial_state())
    err = traj.errors(pd.concat([traj.df.iloc[:1], nav], ignore_index=True))
    assert err["dpos_n_m"].iloc[-1] == pytest.approx(0.5 * 1e-3 * 20.0**2, rel=2e-3)


def test_preset_errors_name_the_called_parameter():
    for fn in (lambda: imu.ImuErrors.preset("RATES"), lambda: atomnav._core.imu_preset("kinematic")):
        with pytest.raises(atomnav.InputError) as e:
            fn()
        assert e.value.parameter == "preset", str(e.value)
    with pytest.raises(atomnav.InputError) as e:
        atomnav._core.ellipsoid_constants("WGS-84")
    assert e.value.parameter == "ellipsoid"
    with pytest.raises(TypeError, match="^errors: "):
        imu.register_preset("mine", "tactical")


@pytest.mark.parametrize("call, parameter", [
    (lambda: imu.white_sigma(1.0, 5e-324), "dt"),
    (lambda: imu.gauss_markov_sigma(1.0, 1e300, 5e-324), "dt"),
    (lambda: imu.flicker_psd(1.0, 5e-324), "f"),
])
def test_step_too_small_is_an_input_error(call, parameter):
    # dt = 5e-324 gave inf from finite input
    with pytest.raises(atomnav.InputError) as e:
        call()
    assert e.value.parameter == parameter, str(e.value)

