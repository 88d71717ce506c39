"""Issue 2 acceptance: rotation conversions round-trip to 1e-12; coning-motion attitude
integration matches the analytic attitude within 1e-9 rad after 100 s at 100 Hz."""

import numpy as np
import pytest

import atomnav as an
from atomnav import rotation as R


@pytest.fixture
def euler(rng):
    e = rng.uniform(-np.pi, np.pi, (2000, 3))
    e[:, 1] = rng.uniform(-1.5, 1.5, 2000)  # keep away from gimbal lock for the Euler round trip
    return e


def test_round_trips(euler):
    q = R.quat_from_euler(euler)
    np.testing.assert_allclose(R.euler_from_quat(q), euler, atol=1e-12, rtol=0)
    np.testing.assert_allclose(R.quat_from_dcm(R.dcm_from_quat(q)), q, atol=1e-12, rtol=0)
    np.testing.assert_allclose(R.euler_from_dcm(R.dcm_from_euler(euler)), euler, atol=1e-12, rtol=0)
    rv = R.rotvec_from_quat(q)
    qq = R.quat_from_rotvec(rv)
    np.testing.assert_allclose(np.abs(np.sum(qq * q, axis=1)), 1.0, atol=1e-12)
    np.testing.assert_allclose(R.rotvec_from_dcm(R.dcm_from_rotvec(rv)), rv, atol=1e-12, rtol=0)


def test_against_independent_formulas(euler):
    """Rz(yaw) Ry(pitch) Rx(roll) built by hand; Rodrigues for the rotation vector."""
    r, p, y = euler[7]
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    np.testing.assert_allclose(R.dcm_from_euler(euler[7]), rz @ ry @ rx, atol=1e-15)
    v = np.array([0.3, -1.2, 0.5])
    th = np.linalg.norm(v)
    k = R.skew(v / th)
    np.testing.assert_allclose(R.dcm_from_rotvec(v), np.eye(3) + np.sin(th) * k + (1 - np.cos(th)) * k @ k, atol=1e-15)
    np.testing.assert_allclose(R.skew(v) @ [1.0, 2.0, 3.0], np.cross(v, [1.0, 2.0, 3.0]), atol=1e-15)


def test_multiplication_composes_matrices(rng):
    a = R.quat_from_euler(rng.uniform(-1, 1, (50, 3)))
    b = R.quat_from_euler(rng.uniform(-1, 1, (50, 3)))
    np.testing.assert_allclose(R.dcm_from_quat(R.quat_multiply(a, b)), R.dcm_from_quat(a) @ R.dcm_from_quat(b), atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(R.quat_normalize(3.0 * a), axis=1), 1.0, atol=1e-15)


def test_coning_motion_attitude():
    """Coning: q(t) = [cos(β/2), sin(β/2)(0, cos Ωt, sin Ωt)] has body rate
    ω = (−2 sin²(β/2) Ω, −sin β Ω sin Ωt, sin β Ω cos Ωt) (from ω = 2 q*⊗q̇); its exact
    increments are closed-form integrals of ω."""
    beta, omega, dt, n = np.deg2rad(1.0), 2 * np.pi * 1.0, 0.01, 10_000
    t = np.arange(-2, n + 1) * dt  # two intervals before t = 0 give the previous increments
    q_true = np.column_stack([np.full(n + 3, np.cos(beta / 2)), np.zeros(n + 3), np.sin(beta / 2) * np.cos(omega * t), np.sin(beta / 2) * np.sin(omega * t)])
    dth = np.column_stack([
        np.full(n + 2, -2 * np.sin(beta / 2) ** 2 * omega * dt),
        np.sin(beta) * (np.cos(omega * t[1:]) - np.cos(omega * t[:-1])),
        np.sin(beta) * (np.sin(omega * t[1:]) - np.sin(omega * t[:-1])),
    ])
    q = an.strapdown.integrate_attitude(q_true[2], dth[2:], dtheta_prev=dth[:2])
    err = R.attitude_error_angle(q[-1:], q_true[-1:])[0]
    assert err < 1e-9, f"coning attitude error {err} rad after 100 s"
    # without the coning correction the same algorithm drifts by orders of magnitude more
    q_naive = q_true[2]
    for d in dth[2:]:
        q_naive = R.quat_multiply(q_naive, R.quat_from_rotvec(d))
    assert R.attitude_error_angle(q_naive[None], q_true[-1:])[0] > 100 * err
    # without the previous increment: the one-time error |Δθ₀×Δθ₁|/12 of the first step
    q_cold = an.strapdown.integrate_attitude(q_true[2], dth[2:])
    one_time = np.linalg.norm(np.cross(dth[1], dth[2])) / 12
    cold = R.attitude_error_angle(q_cold[-1:], q_true[-1:])[0]
    assert 0.5 * one_time < cold < 2 * one_time, (cold, one_time)


def test_euler_angles_are_in_the_half_open_interval():
    """roll and yaw in (−π, π]: a rotation of −π about an axis reads +π (the same rotation),
    and a small negative yaw stays negative (not 2π − ε)."""
    import atomnav as an

    for euler in ([-np.pi, 0.0, -np.pi], [np.pi, 0.0, np.pi]):
        for out in (an.rotation.euler_from_dcm(an.rotation.dcm_from_euler(euler)),
                    an.rotation.euler_from_quat(an.rotation.quat_from_euler(euler))):
            assert out[0] == pytest.approx(np.pi, abs=1e-12) and out[2] == pytest.approx(np.pi, abs=1e-12), out
            assert -np.pi < out[0] <= np.pi and -np.pi < out[2] <= np.pi
    out = an.rotation.euler_from_dcm(an.rotation.dcm_from_euler([-1e-3, 0.0, -1e-3]))
    assert out[0] == pytest.approx(-1e-3, rel=1e-9) and out[2] == pytest.approx(-1e-3, rel=1e-9)
