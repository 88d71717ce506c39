"""Atom strapdown predictor against the inertial oracle and the constant-input closed form
(spec atom-strapdown-tennstedt2023.md §2.3, §4)."""

import numpy as np

from atomnav import cai, rotation

K = cai.K_RB87
T = 0.025


def vib_motion():
    """0.05 rad/s yaw rate, roll/pitch wobble, forward motion and vibration (≈0.07 m/s² at
    9.7 Hz, 0.03 m/s² at 6.1 Hz)."""
    return cai.SineMotion(
        position_poly=[[0, 1.0, 0.1], [0, 0.2, 0], [0, 0, 0]],
        position_sines=[[0, 2e-5, 9.7, 0.3], [1, 1e-5, 4.3, 1.0], [2, 2e-5, 6.1, -0.4]],
        attitude_poly=[[0.01, 0, 0], [-0.02, 0, 0], [0.3, 0.05, 0]],
        attitude_sines=[[0, 2e-3, 1.3, 0.0], [1, 1e-3, 2.1, 0.5], [2, 5e-4, 3.7, 0.2]],
    )


def channels():
    c_sb = rotation.dcm_from_euler(np.array([0.01, -0.02, 0.03]))
    return cai.Channels.cyclic(lever=(0.3, 0.0, 0.0), c_sb=c_sb.reshape(3, 3))


def predictor_error(rate, interpolation, shots, gravity=(0, 0, 9.81)):
    m = vib_motion()
    t = np.arange(0, round(1.0 * rate) + 1) / rate
    f, w, wd = cai.motion_imu(m, t, gravity=gravity)
    ch = channels()
    p = cai.predict_phase(t, f, w, shots, T, ch, angular_acceleration=wd, omega_dot="given", interpolation=interpolation)
    o = cai.oracle_phase(m, shots, T, ch, gravity=gravity)
    return np.abs(p.total - o).max()


SHOTS = 0.1003 + 0.1 * np.arange(8)  # not aligned with the samples


def test_predictor_matches_oracle_1khz():
    """Acceptance: rotation 0.05 rad/s, lever arm 0.3 m, vibration, T = 25 ms, 1 kHz IMU
    (cubic interpolation): |predictor − oracle| < 1e-3 rad per shot."""
    assert predictor_error(1000.0, "cubic", SHOTS) < 1e-3


def test_error_shrinks_with_imu_rate():
    """Linear interpolation: error ∝ h² (the spec's piecewise-linear inputs); cubic: ∝ h⁴."""
    lin = [predictor_error(r, "linear", SHOTS) for r in (1000.0, 2000.0, 4000.0)]
    cub = [predictor_error(r, "cubic", SHOTS) for r in (500.0, 1000.0)]
    assert 3.5 < lin[0] / lin[1] < 4.5 and 3.5 < lin[1] / lin[2] < 4.5, lin
    assert cub[0] / cub[1] > 10, cub


def test_constant_inputs_equal_closed_form():
    """Constant specific force and rate: predictor = (E10) within 1e-9 rad."""
    f0, w0 = np.array([0.3, -0.2, -9.81]), np.array([0.05, -0.03, 0.2])
    t = np.arange(0, 201) * 1e-3
    ch = cai.Channels.cyclic()
    p = cai.predict_phase(t, np.tile(f0, (201, 1)), np.tile(w0, (201, 1)), [0.0137, 0.0706], T, ch, omega_dot="pwl")
    want = cai.phase_constant(ch.k, ch.v0, w0, f0, T)
    assert np.abs(p.total - want).max() < 1e-9
    # the terms add up to the total
    assert np.abs(sum(p.terms[k] for k in cai.TERMS[1:]) - p.total).max() < 1e-9


def test_oracle_matches_spec_reference_on_constant_rotation():
    """Oracle, predictor and (E10) on a body turning at a constant rate with constant
    specific force (a circular path): all three agree; the closed form reproduces the spec's
    reference numbers φ = (8420.1364, 2199.7094, 95916.3943) rad (k = 4π/780.241 nm)."""
    want = np.array([8420.1364, 2199.7094, 95916.3943])
    ks = np.eye(3) * K
    phi = cai.phase_constant(ks, [0, 2.8, 0], [0.05, -0.03, 0.2], [0.3, -0.2, -9.81], T)
    assert np.abs(phi - want).max() < 1e-3


def test_ab_pair_properties():
    """A/B pairs (±v0): the sum cancels the rotation term, the difference cancels the
    acceleration term; rotation about k gives no phase (1e-9 relative)."""
    m = vib_motion()
    t = np.arange(0, 1001) * 1e-3
    f, w, wd = cai.motion_imu(m, t, gravity=(0, 0, 9.81))
    ch = channels()
    kw = dict(angular_acceleration=wd, omega_dot="given")
    p = cai.predict_phase(t, f, w, SHOTS, T, ch, **kw)
    a, b = p.total[:, 0::2], p.total[:, 1::2]
    # sum: twice the phase of an ensemble with v0 = 0
    ch0 = cai.Channels(ch.k, ch.lever, ch.c_sb, np.zeros_like(ch.v0))
    p0 = cai.predict_phase(t, f, w, SHOTS, T, ch0, **kw).total[:, 0::2]
    assert np.abs(a + b - 2 * p0).max() < 1e-9 * np.abs(a).max()
    # difference: independent of the specific force
    q = cai.predict_phase(t, np.zeros_like(f), w, SHOTS, T, ch, **kw)
    assert np.abs((a - b) - (q.total[:, 0::2] - q.total[:, 1::2])).max() < 1e-9 * np.abs(a - b).max()
    # rotation about k (ω ∥ k = x, no force, no lever arm): no phase
    chx = cai.Channels.cyclic()
    n = 201
    wx = np.zeros((n, 3))
    wx[:, 0] = 0.3 + 0.1 * np.sin(np.arange(n) * 1e-2)
    r = cai.predict_phase(np.arange(n) * 1e-3, np.zeros((n, 3)), wx, [0.05], T, chx, omega_dot="pwl")
    scale = K * 2.8 * T
    assert np.abs(r.total[:, :2]).max() < 1e-9 * scale
    assert np.abs(r.total[:, 2:]).max() > 1.0  # the other axes do see the rotation


def test_term_scaling_with_lever_arm():
    """Fig. 7 scaling: φ_cen, φ_eul vanish at l = 0; φ_acc, φ_rot do not depend on l."""
    m = cai.YawDrive()
    t = np.arange(12.0 * 2000, 13.0 * 2000 + 1) / 2000.0
    f, w, wd = cai.motion_imu(m, t)
    out = {}
    for l in (0.0, 1.0):
        ch = cai.Channels.cyclic(lever=(l, 0, 0))
        out[l] = cai.predict_phase(t, f, w, [12.475], T, ch, angular_acceleration=wd, omega_dot="given").terms
    assert np.abs(out[0.0]["cen"]).max() == 0 and np.abs(out[0.0]["eul"]).max() == 0
    for k in ("acc", "rot"):
        np.testing.assert_allclose(out[1.0][k], out[0.0][k], rtol=1e-9, atol=1e-9)
    assert np.abs(out[1.0]["cen"]).max() > 1.0


def test_fig7_reference_shot():
    """Spec §4 Fig. 7, shot centred at 12.5 s, l = [1, 0, 0] m, kinematic: x_A 2842.4041,
    x_B −2794.5907, y_A −503.3660 rad (oracle); predictor terms φ_rot ±2818.51, φ_cen 25.165,
    φ_acc(y_A) −503.305."""
    m = cai.YawDrive()
    ch = cai.Channels.cyclic(lever=(1.0, 0, 0))
    ts = 12.5 - T
    o = cai.oracle_phase(m, [ts], T, ch)[0]
    np.testing.assert_allclose(o[[0, 1, 2]], [2842.4041, -2794.5907, -503.3660], atol=2e-3)
    t = np.arange(12.4 * 2000, 12.6 * 2000 + 1) / 2000.0
    f, w, wd = cai.motion_imu(m, t)
    p = cai.predict_phase(t, f, w, [ts], T, ch, angular_acceleration=wd, omega_dot="given", interpolation="cubic")
    assert abs(p.total[0] - o).max() < 1e-6
    # the spec's ±2818.51 is the first-order value 2kTv0ω·T; the exact term is smaller by
    # ≈ 7(ωT)²/6 + the curvature of ω(t), 4.5e-6 relative
    np.testing.assert_allclose(p.terms["rot"][0, :2], [2818.51, -2818.51], rtol=1e-5)
    assert abs(p.terms["cen"][0, 0] - 25.165) < 1e-3
    assert abs(p.terms["acc"][0, 2] + 503.305) < 1e-3


def test_gravity_gradient_term():
    """φ_gg ≈ kΓv0T³ = 2.174e-3 rad for v0 along k (vertical gradient 3.086e-6 s⁻², no
    specific force), and the predictor with Γ agrees with the oracle with Γ."""
    gam = 3.086e-6
    G = np.diag([-gam / 2, -gam / 2, gam])
    ch = cai.Channels(np.array([[0, 0, K]]), (0, 0, 0), np.eye(3), np.array([[0, 0, 2.8]]))
    t = np.arange(0, 101) * 1e-3
    p = cai.predict_phase(t, np.zeros((101, 3)), np.zeros((101, 3)), [0.02], T, ch, gradient=G, omega_dot="zero")
    assert abs(p.terms["gg"][0, 0] - K * gam * 2.8 * T**3) < 1e-6
    assert abs(K * gam * 2.8 * T**3 - 2.174e-3) < 1e-6
    # rotating, accelerating body: predictor (Γ in s, frozen at the shot) vs oracle (Γ in i)
    m = vib_motion()
    t = np.arange(0, 1001) * 1e-3
    f, w, wd = cai.motion_imu(m, t, gravity=(0, 0, 9.81), gradient=G)
    chs = cai.Channels.cyclic()
    o = cai.oracle_phase(m, SHOTS[:3], T, chs, gravity=(0, 0, 9.81), gradient=G)
    for i, ts in enumerate(SHOTS[:3]):
        c_ib = _c_ib(m, ts)
        Gs = c_ib.T @ G @ c_ib
        p = cai.predict_phase(t, f, w, [ts], T, chs, gradient=Gs, angular_acceleration=wd, omega_dot="given",
                              interpolation="cubic")
        assert np.abs(p.total[0] - o[i]).max() < 1e-3


def _c_ib(m, t):
    """C_ib of a SineMotion at t from its Euler-angle signals."""
    ang = np.array([np.polyval(m.attitude_poly[a][::-1], t) + sum(
        s[1] * np.sin(2 * np.pi * s[2] * t + s[3]) for s in m.attitude_sines if s[0] == a) for a in range(3)])
    return rotation.dcm_from_euler(ang).reshape(3, 3)


def test_angular_acceleration_sources():
    """ω̇ for the Euler terms: the Savitzky–Golay derivative of the gyro (default for measured
    data) and the derivative of the gyro interpolant ("pwl") approach the simulator's exact
    ω̇; the 5-point formula is exact for a quadratic rate."""
    m = vib_motion()
    t = np.arange(0, 2001) / 2000.0
    f, w, wd = cai.motion_imu(m, t, gravity=(0, 0, 9.81))
    ch = channels()
    exact = cai.predict_phase(t, f, w, SHOTS, T, ch, angular_acceleration=wd, interpolation="cubic")
    for src, tol in (("savgol", 1e-3), ("pwl", 1e-3)):
        p = cai.predict_phase(t, f, w, SHOTS, T, ch, omega_dot=src, interpolation="cubic")
        assert np.abs(p.terms["eul"] - exact.terms["eul"]).max() < tol * np.abs(exact.terms["eul"]).max()
    # quadratic rate: ω = c t², ω̇ = 2ct exactly from the 5-point derivative
    n = 101
    tq = np.arange(n) * 1e-3
    wq = np.zeros((n, 3))
    wq[:, 2] = 0.5 * tq**2
    wdq = np.zeros((n, 3))
    wdq[:, 2] = tq
    chl = cai.Channels.cyclic(lever=(1.0, 0, 0))
    a = cai.predict_phase(tq, np.zeros((n, 3)), wq, [0.03], T, chl, omega_dot="savgol")
    b = cai.predict_phase(tq, np.zeros((n, 3)), wq, [0.03], T, chl, angular_acceleration=wdq)
    np.testing.assert_allclose(a.total, b.total, rtol=1e-12, atol=1e-9)
