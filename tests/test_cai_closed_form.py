"""Closed forms, scale factors, dynamic range and the seed-000 conventions
(spec atom-strapdown-tennstedt2023.md §4, cai-ekf-tennstedt2021.md §4)."""

import numpy as np
import pytest

from atomnav import cai


def phase_first_order(k, v0, angular_rate, specific_force, T):
    """Independent oracle: the first-order phase −T² k·f_s − 2T² k·(ω×v0) (rad) of
    Tennstedt et al. 2021, Eq. 10, in numpy, per row of k (C, 3); the Rust closed forms
    (exact, series, the paper's own convention) are compared against it."""
    k = np.atleast_2d(np.asarray(k, float))
    v0 = np.broadcast_to(np.asarray(v0, float), k.shape)
    return -T**2 * k @ np.asarray(specific_force, float) + cai.sagnac_phase(k, v0, angular_rate, T)


def in_shot_noise_covariance(channels, q_accel, q_gyro, T):
    """Independent oracle: covariance (C, C) (rad²) of the predicted phases of one shot from
    white IMU noise of PSDs q_accel (m²/s³) and q_gyro (rad²/s), the closed form of
    Tennstedt et al. 2023, Eq. 38, with the A/B correlation: to leading order the noise acts
    as an atom acceleration −C_sb n_a and a Coriolis acceleration −2(C_sb n_g)×v0, so with
    ∫w² = 2T³/3: Σ = (2T³/3)[q_a K Kᵀ + 4 q_g V Vᵀ], K_j = C_sb,jᵀ k_j,
    V_j = C_sb,jᵀ (v0_j × k_j). It leaves out the Euler terms, so it is compared against the
    predictor with ω̇ = 0 (the Rust in-shot covariance, ``cai.in_shot_noise``, includes them)."""
    kb = np.einsum("cji,cj->ci", channels.c_sb, channels.k)
    vb = np.einsum("cji,cj->ci", channels.c_sb, np.cross(channels.v0, channels.k))
    return 2 * T**3 / 3 * (q_accel * kb @ kb.T + 4 * q_gyro * vb @ vb.T)

K = cai.K_RB87


def test_k_eff():
    assert cai.k_eff() == pytest.approx(1.610576e7, rel=1e-6)
    assert cai.k_eff(780e-9) == pytest.approx(1.611073e7, rel=1e-6)


def test_dynamic_range_and_noise_seed003():
    """Seed 003: π/(kT²) at T = 10 ms, k = 4π/780 nm ≈ 1.95e-3 m/s² ("≈ 2 mm/s²");
    σ_p² = 1e-3 at mid-fringe → σ_φ ≈ 63 mrad, σ_a ≈ 6.3e-6 m/s² at T = 25 ms."""
    assert cai.dynamic_range(0.010, cai.k_eff(780e-9)) == pytest.approx(1.95e-3, rel=2e-3)
    assert cai.dynamic_range(0.010) == pytest.approx(1.9506e-3, rel=1e-4)
    assert cai.dynamic_range(0.025) == pytest.approx(3.1210e-4, rel=1e-4)
    s_phi = cai.phase_noise(np.sqrt(1e-3))
    assert s_phi == pytest.approx(0.063246, rel=1e-5)
    assert cai.acceleration_noise(s_phi, 0.025) == pytest.approx(6.2830e-6, rel=1e-4)


def test_scale_factors():
    """kT² = 1610.576 / 10066.10 rad/(m/s²); Sagnac 2kv0T² = 56 370.1; Euler kv0T³ = 704.63;
    gravity phase kgT² = 98 714.7 at 25 ms (g = 9.80665)."""
    assert cai.scale_factors(0.010)["acceleration"] == pytest.approx(1610.576, rel=1e-6)
    s = cai.scale_factors(0.025)
    assert s["acceleration"] == pytest.approx(10066.10, rel=1e-6)
    assert s["sagnac"] == pytest.approx(56370.1, rel=1e-6)
    assert s["euler"] == pytest.approx(704.63, rel=1e-5)
    assert s["acceleration"] * 9.80665 == pytest.approx(98714.7, rel=1e-6)
    # Earth rate (7.292115e-5 rad/s) through the Sagnac scale: 4.1106 rad
    assert s["sagnac"] * 7.292115e-5 == pytest.approx(4.1106, rel=1e-4)


def test_capture_limits_hexapod():
    """Seed 000 spec: T = 5 ms, v0 = 2.8 m/s → 3.9012e-3 m/s², 6.9664e-4 rad/s."""
    c = cai.capture_limits(0.005)
    assert c["accelerometer"] == pytest.approx(3.9012e-3, rel=1e-4)
    assert c["gyro"] == pytest.approx(6.9664e-4, rel=1e-4)


def test_interrogation_time_conversion():
    assert cai.t_sep_from_total(0.04) == 0.02
    assert cai.total_from_t_sep(0.02) == 0.04
    # seed 000 Table 1 scale factors at T0 = 0.04 s: ¼kT0² = 6442.302, ½kv̄T0² = 36076.89
    T = cai.t_sep_from_total(0.04)
    assert cai.scale_factors(T)["acceleration"] == pytest.approx(6442.302, rel=1e-6)
    assert cai.scale_factors(T)["sagnac"] == pytest.approx(36076.89, rel=1e-6)  # ½kv̄T0² = 2kv0T²


def test_seed000_convention_mapping():
    """φ_000(k, v̄, T0) = φ_lib,first-order(−k, v0 = −v̄, T = T0/2), abs 1e-9 rad."""
    k = np.eye(3) * K
    vbar = np.array([[0, 2.8, 0], [0, 0, -2.8], [2.8, 0, 0]])
    w, f = np.array([1e-3, -2e-3, 5e-4]), np.array([0.1, -0.05, 9.8])
    a = cai.phase_seed000(k, vbar, w, f, 0.04)
    b = phase_first_order(-k, -vbar, w, f, cai.t_sep_from_total(0.04))
    assert np.abs(a - b).max() < 1e-9


def test_series_vs_exact():
    """(E11) vs (E10) within 5e-3 rad on the spec case; the Sagnac term is the series'
    second term."""
    k = np.eye(3) * K
    v0, w, f = [0, 2.8, 0], np.array([0.05, -0.03, 0.2]), np.array([0.3, -0.2, -9.81])
    ex = cai.phase_constant(k, v0, w, f, 0.025)
    ser = cai.phase_series(k, v0, w, f, 0.025)
    assert np.abs(ex - ser).max() < 5e-3
    first = phase_first_order(k, v0, w, f, 0.025)
    assert np.abs(ex - first).max() > 0.1  # third-order terms matter at this rate
    sag = cai.sagnac_phase(k, np.tile(v0, (3, 1)), w, 0.025)
    assert sag[0] == pytest.approx(-2 * 0.025**2 * K * np.cross(w, v0)[0], rel=1e-12)


def test_series_euler_term_vs_predictor():
    """The ω̇ term of (E11), −3T³k·(ω̇×v0) (Coriolis of the growing rate + Euler on the
    atom), against the predictor (independent RK4 integration) on ω = ω̇ (t − t_s), f = 0."""
    n = 201
    t = np.arange(n) * 1e-4
    wd = np.array([0.1, 0.0, 0.0])
    w = np.outer(t - 0.01, wd)
    ch = cai.Channels(np.eye(3) * K, (0, 0, 0), np.eye(3), [0, 0, 2.8])
    p = cai.predict_phase(t, np.zeros((n, 3)), w, [0.01], 0.005, ch, omega_dot="pwl")
    ser = cai.phase_series(ch.k, ch.v0, [0, 0, 0], [0, 0, 0], 0.005, angular_acceleration=wd)
    assert ser[1] == pytest.approx(-3 * 0.005**3 * K * np.cross(wd, [0, 0, 2.8])[1], rel=1e-12)
    assert np.abs(p.total[0] - ser).max() < 1e-5


def test_series_gradient_terms_vs_predictor():
    """Gradient terms of (E11), T³k·Γv0 − 7/12 T⁴k·Γf (spec: 2.174e-3 and 1.111e-4 rad at
    T = 25 ms, Γ = 3.086e-6 s⁻², v0 = 2.8 m/s, f = g), against the predictor's φ_gg."""
    gam = 3.086e-6
    G = np.diag([-gam / 2, -gam / 2, gam])
    n = 101
    t = np.arange(n) * 1e-3
    f = np.tile([0.0, 0.0, -9.80665], (n, 1))
    ch = cai.Channels(np.array([[0, 0, K]]), (0, 0, 0), np.eye(3), [0, 0, 2.8])
    p = cai.predict_phase(t, f, np.zeros((n, 3)), [0.02], 0.025, ch, omega_dot="zero", gradient=G)
    v_term, f_term = 0.025**3 * K * gam * 2.8, -7 / 12 * 0.025**4 * K * gam * f[0, 2]
    assert v_term == pytest.approx(2.174e-3, rel=1e-3) and f_term == pytest.approx(1.111e-4, rel=1e-3)
    assert p.terms["gg"][0, 0] == pytest.approx(v_term + f_term, rel=1e-6)


def test_in_shot_imu_noise_phase():
    """(E38) with the (E36) PSDs q_a = 1.25e-11 m²/s³, q_g = 1.0576e-12 rad²/s at T = 25 ms:
    0.1838 rad (accel), 0.2994 rad (gyro); checked by Monte Carlo through the predictor
    (2000 shots of 2 kHz white noise with per-sample σ = √(q/Δt), spec (E33)), ±5 %."""
    s = cai.in_shot_noise_phase(1.25e-11, 1.0576e-12, 0.025)
    assert s["accel"] == pytest.approx(0.1838, rel=1e-3) and s["gyro"] == pytest.approx(0.2994, rel=1e-3)
    rng = np.random.default_rng(7)
    dt, T, shots = 5e-4, 0.025, 2000
    n = int(shots * 2 * T / dt) + 1
    t = np.arange(n) * dt
    ch = cai.Channels(np.array([[K, 0, 0]]), (0, 0, 0), np.eye(3), [0, 2.8, 0])
    starts = np.arange(shots) * 2 * T
    fa = rng.normal(0, np.sqrt(1.25e-11 / dt), (n, 3))
    pa = cai.predict_phase(t, fa, np.zeros((n, 3)), starts, T, ch, omega_dot="zero").total[:, 0]
    wg = rng.normal(0, np.sqrt(1.0576e-12 / dt), (n, 3))
    pg = cai.predict_phase(t, np.zeros((n, 3)), wg, starts, T, ch, omega_dot="zero").total[:, 0]
    assert np.std(pa) == pytest.approx(s["accel"], rel=0.05)
    assert np.std(pg) == pytest.approx(s["gyro"], rel=0.05)


def test_in_shot_noise_covariance_six_channels():
    """Full 6 × 6 covariance (A/B correlated) vs Monte Carlo through the predictor with
    white noise on all IMU axes, misaligned C_sb: diagonal ±6 %, correlations ±0.05."""
    from atomnav import rotation

    c_sb = rotation.dcm_from_euler(np.array([0.1, -0.2, 0.3])).reshape(3, 3)
    ch = cai.Channels.cyclic(c_sb=c_sb)
    qa, qg, T = 1.25e-11, 1.0576e-12, 0.025
    cov = in_shot_noise_covariance(ch, qa, qg, T)
    np.testing.assert_allclose(np.sqrt(cov[0, 0]), np.hypot(*cai.in_shot_noise_phase(qa, qg, T).values()), rtol=1e-12)
    rng = np.random.default_rng(8)
    dt, shots = 5e-4, 2000
    n = int(shots * 2 * T / dt) + 1
    t = np.arange(n) * dt
    f = rng.normal(0, np.sqrt(qa / dt), (n, 3))
    w = rng.normal(0, np.sqrt(qg / dt), (n, 3))
    p = cai.predict_phase(t, f, w, np.arange(shots) * 2 * T, T, ch, omega_dot="zero").total
    emp = np.cov(p.T)
    np.testing.assert_allclose(np.diag(emp), np.diag(cov), rtol=0.12)  # variance: ±6 % in σ
    d = np.sqrt(np.diag(cov))
    np.testing.assert_allclose(emp / np.outer(np.sqrt(np.diag(emp)), np.sqrt(np.diag(emp))), cov / np.outer(d, d), atol=0.05)
