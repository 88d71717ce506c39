"""Fringe tracking and ML noise identification (seed 000 §3; spec cai-ekf-tennstedt2021.md
(E15)–(E21), §4)."""

import numpy as np
import pytest

from atomnav import cai

TRUE = dict(p0=0.5, phi=1.0, amplitude=0.15, sigma_p0=0.025, sigma_phi=0.23, sigma_A=0.02)
A_TRUE = TRUE["sigma_p0"] ** 2 + TRUE["sigma_A"] ** 2  # a = 1.025e-3
R_MID_TRUE = TRUE["sigma_p0"] ** 2 + (TRUE["amplitude"] * TRUE["sigma_phi"]) ** 2  # a + b = 1.8153e-3


@pytest.fixture(scope="module")
def data():
    """4200 readouts spread over the fringe by vibration, tracked by the fringe EKF."""
    p, psi = cai.simulate_fringe(4200, seed=11, **TRUE)
    track = cai.fringe_track(p, psi, zeta0=(0.4, 0.0, 0.1))
    return p, psi, track


def test_fringe_ekf_tracks_parameters(data):
    """|p̂0 − p0| < 0.003, |φ̂ − φ| < 0.03 rad, |Â − A e^{−σφ²/2}| < 0.004 (spec §4)."""
    _, _, tr = data
    last = tr.iloc[-1]
    assert abs(last.p0 - 0.5) < 0.003
    assert abs(last.phi_rad - 1.0) < 0.03
    assert abs(last.A - 0.15 * np.exp(-0.23**2 / 2)) < 0.004
    assert (tr.A > 0).all() and (np.abs(tr.phi_rad) <= np.pi).all()


@pytest.mark.parametrize("method", ["gradient", "newton"])
def test_ml_identifiable_quantities(data, method):
    """σ_A fixed at its value: (σ_p0, σ_φ) within 10 %; the identifiable a and a + b (R at
    mid-fringe) within 10 %, on the whole record and as the mean of 200-sample batches;
    ≤ 100 iterations."""
    x, phi, amp = cai.residuals(*data)
    for batch in (None, 200):
        r = cai.identify_noise(x, phi, amp, free=("p0", "phi"), theta0=(0.02, 0.2, 0.02), method=method, batch=batch)
        assert r.converged.all() and r.iterations.max() <= 100
        m = r.mean(numeric_only=True)
        assert m.sigma_p0 == pytest.approx(0.025, rel=0.1)
        assert m.sigma_phi_rad == pytest.approx(0.23, rel=0.1)
        assert m.a == pytest.approx(A_TRUE, rel=0.1)
        assert m.R_mid == pytest.approx(R_MID_TRUE, rel=0.1)


def test_newton_needs_fewer_iterations(data):
    x, phi, amp = cai.residuals(*data)
    kw = dict(free=("p0", "phi"), theta0=(0.02, 0.2, 0.02), batch=200)
    ga = cai.identify_noise(x, phi, amp, method="gradient", **kw)
    nr = cai.identify_noise(x, phi, amp, method="newton", **kw)
    assert nr.iterations.sum() < ga.iterations.sum()
    np.testing.assert_allclose(nr.log_likelihood, ga.log_likelihood, rtol=1e-9)


def test_degeneracy_same_identifiable_pair(data):
    """Fixing σ_A at different values moves (σ_p0, σ_φ) along the degenerate line but leaves
    (a, b) and ln L (nearly) unchanged; the variance Hessian has a ≈ 0 eigenvalue."""
    x, phi, amp = cai.residuals(*data)
    r1 = cai.identify_noise(x, phi, amp, theta0=(0.02, 0.2, 0.02))
    r2 = cai.identify_noise(x, phi, amp, theta0=(0.02, 0.2, 0.0))
    assert abs(r1.sigma_p0[0] - r2.sigma_p0[0]) > 0.003
    assert r1.a[0] == pytest.approx(r2.a[0], rel=0.01) and r1.R_mid[0] == pytest.approx(r2.R_mid[0], rel=0.01)
    assert r1.hessian_eig_ratio[0] < 1e-2


def test_sliding_window_warm_start(data):
    x, phi, amp = cai.residuals(*data)
    n = 260
    s = cai.identify_noise(x[:n], phi[:n], amp[:n], batch=200, sliding=True)
    assert len(s) == n - 200 + 1
    last = cai.identify_noise(x[n - 200:n], phi[n - 200:n], amp[n - 200:n])
    assert s.sigma_phi_rad.iloc[-1] == pytest.approx(last.sigma_phi_rad[0], rel=1e-5)
    assert s.iterations.iloc[1:].mean() < last.iterations[0] + 1
    np.testing.assert_allclose(cai.readout_variance(s.a, s.b, np.pi / 2), s.R_mid)


def test_sliding_window_leaves_zero_boundary(data):
    """A window whose ML σ_φ reaches 0 must not trap the warm-started windows after it (the
    gradient in θ vanishes at θ = 0): over the whole record the last sliding window equals a
    fresh estimate on the same 200 samples."""
    x, phi, amp = cai.residuals(*data)
    s = cai.identify_noise(x, phi, amp, batch=200, sliding=True)
    assert (s.sigma_phi_rad < 1e-3).any()  # this record has windows at the boundary
    fresh = cai.identify_noise(x[-200:], phi[-200:], amp[-200:])
    assert s.sigma_phi_rad.iloc[-1] == pytest.approx(fresh.sigma_phi_rad[0], rel=1e-4)
    assert s.sigma_p0.iloc[-1] == pytest.approx(fresh.sigma_p0[0], rel=1e-4)
