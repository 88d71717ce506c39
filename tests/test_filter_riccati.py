"""Steady-state Riccati analysis: Tennstedt, Weddig & Schön (2021) Table 1 and the general
DARE vs scipy."""

import numpy as np
import pytest
import scipy.linalg

from atomnav.filter import closed_loop_matrix, dare, kalman_recursion, riccati_scalar

K_EFF = 4 * np.pi / 780.241e-9  # rad/m (⁸⁷Rb D2, λ = 780.241 nm)
A_FRINGE, V_BAR, R_CAI = 0.15, 2.8, 1.024e-3
# (Q per step, H, paper P⁺): Tennstedt et al. (2021) Table 1 and Eqs. 34/35
TABLE1 = {
    "A_satellite_accel": (1e-20, 0.25 * A_FRINGE * K_EFF * 10.0**2, 4.82e-20),
    "B_navigation_accel": (2.5e-9, 0.25 * A_FRINGE * K_EFF * 0.04**2, 8.25e-10),
    "C_ring_laser_gyro": (4e-16, A_FRINGE * K_EFF * V_BAR * 0.04**2, 5.9e-14),
}


@pytest.mark.parametrize("case", sorted(TABLE1))
def test_table1_closed_form_dare_and_recursion(case):
    q, h, paper = TABLE1[case]
    p_prior, p_post = riccati_scalar(q, R_CAI, h)
    assert abs(p_post / paper - 1) < 5e-3
    assert abs((p_prior - p_post) / q - 1) < 1e-12  # Φ = 1: P⁻ = P⁺ + Q (E25)
    s = dare(1.0, q, h, R_CAI)
    assert abs(s.p_post[0, 0] / paper - 1) < 5e-3
    assert abs(s.p_post[0, 0] / p_post - 1) < 1e-9
    assert abs(s.p_prior[0, 0] / p_prior - 1) < 1e-9
    # Iterated Kalman recursion from a large prior converges to the DARE value.
    prior, post = kalman_recursion(1.0, q, h, R_CAI, np.array([[1e6 * q]]), 20000)
    assert abs(post[-1, 0, 0] / s.p_post[0, 0] - 1) < 1e-9
    assert abs(prior[-1, 0, 0] / s.p_prior[0, 0] - 1) < 1e-9


def test_table1_spec_digits_and_gain():
    # 6-digit values of P⁺ and 1 − K∞H from Tennstedt et al. (2021) Eqs. 32–35
    expect = {"A_satellite_accel": (4.821853e-20, 0.8282334), "B_navigation_accel": (8.245887e-10, 0.2480273),
              "C_ring_laser_gyro": (5.893330e-14, 0.9932584)}
    for case, (p_exp, phit) in expect.items():
        q, h, _ = TABLE1[case]
        s = dare(1.0, q, h, R_CAI)
        assert abs(s.p_post[0, 0] / p_exp - 1) < 1e-6
        assert abs(closed_loop_matrix(1.0, h, s.gain)[0, 0] / phit - 1) < 1e-6


def _random_system(rng, n):
    m = int(rng.integers(1, n + 1))
    phi = rng.standard_normal((n, n))
    phi *= rng.uniform(0.5, 1.2) / max(abs(np.linalg.eigvals(phi)))
    h = rng.standard_normal((m, n))
    g = rng.standard_normal((n, n))
    q = g @ g.T / n
    l = rng.standard_normal((m, m))
    r = l @ l.T + m * np.eye(m)
    return phi, q, h, r


def test_dare_matches_scipy_on_50_random_systems():
    rng = np.random.default_rng(20260511)
    worst = 0.0
    for k in range(50):
        n = 1 + k % 30
        phi, q, h, r = _random_system(rng, n)
        ref = scipy.linalg.solve_discrete_are(phi.T, h.T, q, r)
        got = dare(phi, q, h, r).p_prior
        worst = max(worst, np.max(np.abs(got - ref)) / np.max(np.abs(ref)))
    assert worst < 1e-9, worst


def test_dare_posterior_and_gain_are_consistent():
    rng = np.random.default_rng(3)
    phi, q, h, r = _random_system(rng, 6)
    s = dare(phi, q, h, r)
    # E24 residual, E25, K = P⁺HᵀR⁻¹ (Tennstedt et al. 2021, Eq. 29)
    res = phi @ s.p_post @ phi.T + q - s.p_prior
    assert np.max(np.abs(res)) < 1e-10 * np.max(np.abs(s.p_prior))
    assert np.allclose(s.gain, s.p_post @ h.T @ np.linalg.inv(r), rtol=1e-9, atol=1e-12)


def test_dare_rejects_non_stabilisable():
    phi = np.diag([2.0, 0.5])
    with pytest.raises(ValueError, match="not detectable"):
        dare(phi, np.eye(2), np.array([[0.0, 1.0]]), [[1.0]])


def test_dare_rejects_undamped_unobserved_mode_driven_by_noise():
    with pytest.raises(ValueError, match="not stabilisable"):
        dare(np.eye(2), np.eye(2), np.array([[0.0, 1.0]]), [[1.0]])


def test_dare_bad_input_non_square_phi():
    with pytest.raises(ValueError, match="phi: must be square"):
        dare(np.ones((2, 3)), np.eye(2), np.ones((1, 2)), [[1.0]])


def test_dare_bad_input_asymmetric_q():
    with pytest.raises(ValueError, match=r"q: not symmetric: entry \(1, 0\)"):
        dare(np.eye(2) * 0.5, [[1.0, 0.0], [0.5, 1.0]], np.ones((1, 2)), [[1.0]])


def test_dare_bad_input_indefinite_r():
    with pytest.raises(ValueError, match="r: not positive definite"):
        dare(0.5, 1.0, 1.0, [[-1.0]])


def test_dare_bad_input_mismatched_h():
    with pytest.raises(ValueError, match="h: expected 2 columns"):
        dare(np.eye(2) * 0.5, np.eye(2), np.ones((1, 3)), [[1.0]])


def test_dare_bad_input_nan():
    with pytest.raises(ValueError, match=r"q: non-finite value NaN at index \(0, 0\)"):
        dare(0.5, np.nan, 1.0, 1.0)


def test_riccati_scalar_bad_input():
    with pytest.raises(ValueError, match="r: must be > 0"):
        riccati_scalar(1e-20, 0.0, 1.0)


def test_reproduce_section_all_rows_pass(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from atomnav.reproduce import Report, discover

    _, fn = discover()["riccati_tennstedt2021"]
    rep = Report(outdir=tmp_path, section="riccati_tennstedt2021", quick=True)
    fn(rep)
    verdicts = [r["verdict"] for r in rep.rows]
    assert len(verdicts) == 9
    assert all(v == "pass" for v in verdicts), verdicts
    assert (tmp_path / "riccati_tennstedt2021_recursion.png").exists()


@pytest.mark.parametrize("n", [60, 150])
def test_dare_faer_path_matches_scipy(n):
    """Above the register kernels' sizes the doubling runs on faer: its P⁻ satisfies the
    filter DARE (Tennstedt et al. 2021, Eq. 31) to 1e-12 relative residual, like scipy's
    solve_discrete_are (the independent oracle), and the two agree."""
    rng = np.random.default_rng(n)
    phi = rng.standard_normal((n, n))
    phi *= 0.95 / max(abs(np.linalg.eigvals(phi)))
    g = rng.standard_normal((n, n))
    q = g @ g.T / n + 1e-3 * np.eye(n)
    m = n // 4
    h, r = rng.standard_normal((m, n)), np.eye(m)

    def residual(p):
        k = phi @ p @ h.T @ np.linalg.inv(h @ p @ h.T + r)
        return np.max(np.abs(phi @ p @ phi.T + q - k @ h @ p @ phi.T - p)) / np.max(np.abs(p))

    ref = scipy.linalg.solve_discrete_are(phi.T, h.T, q, r)
    got = dare(phi, q, h, r).p_prior
    assert residual(got) < 1e-12, residual(got)
    assert np.max(np.abs(got - ref)) / np.max(np.abs(ref)) < 1e-9
    assert np.array_equal(got, got.T)
