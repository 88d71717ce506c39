"""Jacobians of the predicted phase / readout w.r.t. IMU biases, lever arm and
misalignment (spec atom-strapdown-tennstedt2023.md (E29)–(E31))."""

import numpy as np
import pytest

from atomnav import cai, rotation


def paper_jacobian(channels, specific_force, angular_rate, T):
    """Independent oracle of the phase Jacobian: the paper-mode closed forms for constant
    dynamics of Tennstedt et al. 2023 (Eqs. 27 and 31; ∂φ/∂b_a = T²kᵀ(I − 2T[ω_s×])C_sb and
    ∂φ/∂b_g as the sum of the ``centrifugal`` (terms 1–2), ``coriolis`` (3), ``mixed_acc``
    (4) and ``mixed_cen`` (5–7) terms), written out in numpy term by term. The library's
    derivative is the tangent-linear predictor (``cai.phase_jacobian``, Rust), which the
    tests below compare against these formulas. Inputs in the body frame: f_b (m/s²),
    ω_b (rad/s); arrays (C, 3) in rad per (m/s²) / (rad/s)."""

    def sk(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    f, w = np.asarray(specific_force, float), np.asarray(angular_rate, float)
    out = {k: [] for k in ("ba", "centrifugal", "coriolis", "mixed_acc", "mixed_cen")}
    for k, l, c, v0 in zip(channels.k, channels.lever, channels.c_sb, channels.v0):
        ws = c @ w
        cen_jac = sk(w) @ sk(l) + sk(np.cross(w, l))  # ∂[ω×(ω×l)]/∂ω up to sign, terms 1–2
        out["ba"].append(T**2 * k @ (np.eye(3) - 2 * T * sk(ws)) @ c)
        out["centrifugal"].append(-T**2 * k @ c @ cen_jac)
        out["coriolis"].append(-2 * T**2 * k @ sk(v0) @ c)
        out["mixed_acc"].append(2 * T**3 * k @ sk(c @ f) @ c)
        out["mixed_cen"].append(2 * T**3 * k @ (sk(c @ np.cross(w, np.cross(w, l))) @ c + sk(ws) @ c @ cen_jac))
    res = {k: np.array(v) for k, v in out.items()}
    res["bg"] = sum(res[k] for k in ("centrifugal", "coriolis", "mixed_acc", "mixed_cen"))
    return res

T = 0.025
K = cai.K_RB87


def record():
    t = np.arange(0, 151) * 1e-3
    f = np.column_stack([0.3 + 0.2 * np.sin(9 * t), -0.2 + 0.05 * t, -9.81 + 0.1 * np.cos(3 * t)])
    w = np.column_stack([0.05 + 0.3 * t, -0.03 + 0.0 * t, 0.2 * np.cos(5 * t)])
    return t, f, w


def channels():
    c_sb = rotation.dcm_from_euler(np.array([0.01, -0.02, 0.03])).reshape(3, 3)
    return cai.Channels.cyclic(lever=(0.3, -0.1, 0.2), c_sb=c_sb)


@pytest.mark.parametrize("euler", [False, True])
def test_analytic_matches_finite_differences(euler):
    """Tangent-linear Jacobian = central differences within 1e-6 relative, all 12 parameters,
    Euler terms excluded (default) and included."""
    t, f, w = record()
    res = cai.check_jacobian(t, f, w, [0.0113, 0.0622], T, channels(), euler=euler, bias_a=[1e-4, -2e-4, 0],
                             bias_g=[1e-5, 0, -2e-5], interpolation="cubic")
    assert max(res["max_rel_diff"].values()) < 1e-6, res["max_rel_diff"]
    assert res["analytic"].shape == (2, 6, 12)


def test_euler_switch_changes_gyro_jacobian():
    t, f, w = record()
    a = cai.phase_jacobian(t, f, w, [0.0113], T, channels(), euler=False)
    b = cai.phase_jacobian(t, f, w, [0.0113], T, channels(), euler=True)
    assert np.abs(a - b)[..., 3:6].max() > 1.0  # mixed/Euler term (P-31) item 8


def test_paper_mode_constant_dynamics():
    """Constant ω_s, f_s, l = 0: ∂φ/∂b_a ≈ T²k^T(I − 2T[ω×]) and ∂φ/∂b_g ≈ 2T²(v0×k)^T +
    2T³(k×f)^T (seed 003 (P-27), (P-31) terms 3–4; seed 000 (E34)), to the truncation
    order of those expressions; A/B rows share b_a and have opposite Coriolis b_g."""
    n = 101
    t = np.arange(n) * 1e-3
    f0, w0 = np.array([0.3, -0.2, -9.81]), np.array([0.02, -0.01, 0.03])
    ch = cai.Channels.cyclic()
    j = cai.phase_jacobian(t, np.tile(f0, (n, 1)), np.tile(w0, (n, 1)), [0.02], T, ch)[0]
    W = rotation.skew(w0).reshape(3, 3)
    for c in range(6):
        k, v0 = ch.k[c], ch.v0[c]
        ha = T**2 * k @ (np.eye(3) - 2 * T * W)
        hg = 2 * T**2 * np.cross(v0, k) + 2 * T**3 * np.cross(k, f0)
        np.testing.assert_allclose(j[c, 0:3], ha, atol=2e-3 * np.abs(ha).max())
        np.testing.assert_allclose(j[c, 3:6], hg, atol=2e-3 * np.abs(hg).max())
    np.testing.assert_allclose(j[0, 0:3], j[1, 0:3], rtol=1e-12)


def test_readout_jacobian_mid_fringe():
    """At mid-fringe ∂p/∂θ = (C/2) ∂φ/∂θ."""
    t, f, w = record()
    ch = channels()
    jp = cai.phase_jacobian(t, f, w, [0.0113], T, ch)
    phi = cai.predict_phase(t, f, w, [0.0113], T, ch).total
    jr = cai.readout_jacobian(jp, phi, cai.steer_mid_fringe(phi), contrast=0.6)
    np.testing.assert_allclose(jr, 0.3 * jp, rtol=1e-9)


def test_paper_mode_terms_vs_tangent_linear():
    """(E29)/(E30) term by term vs the exact tangent-linear Jacobian at constant dynamics
    (lever arm, misalignment): ∂φ/∂b_a to 5e-4 relative (next order 7/4 (ωT)² = 1.5e-4); the lever-arm part of ∂φ/∂b_g
    (J(l) − J(0)) equals centrifugal + mixed-centrifugal terms to 1e-3 relative; the whole
    ∂φ/∂b_g to 2e-3 of its largest entry (the paper omits the 3T³k·(ω×(ω×v0)) term)."""
    n = 101
    t = np.arange(n) * 1e-3
    f0, w0 = np.array([0.3, -0.2, -9.81]), np.array([0.2, -0.1, 0.3])
    ch = channels()
    ch0 = cai.Channels(ch.k, (0, 0, 0), ch.c_sb, ch.v0)

    def exact(c):
        return cai.phase_jacobian(t, np.tile(f0, (n, 1)), np.tile(w0, (n, 1)), [0.02], T, c, omega_dot="zero")[0]

    ex, ex0 = exact(ch), exact(ch0)
    pm = paper_jacobian(ch, f0, w0, T)
    np.testing.assert_allclose(pm["ba"], ex[:, 0:3], atol=5e-4 * np.abs(ex[:, 0:3]).max())
    lever_part = ex[:, 3:6] - ex0[:, 3:6]
    np.testing.assert_allclose(pm["centrifugal"] + pm["mixed_cen"], lever_part, atol=1e-3 * np.abs(lever_part).max())
    np.testing.assert_allclose(pm["bg"], ex[:, 3:6], atol=2e-2 * np.abs(ex[:, 3:6]).max())
    p0 = paper_jacobian(ch0, f0, w0, T)
    assert np.abs(p0["centrifugal"]).max() == 0 and np.abs(p0["mixed_cen"]).max() == 0
