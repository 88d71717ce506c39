"""ARIMA state space and Kalman filters: spec §4a.1–5 oracles, parity with a dense numpy
implementation of seed 002 Eqs. 15 and 17 and of Sage–Husa (spec E11), streaming."""

import numpy as np
import pytest
from scipy.linalg import solve_discrete_are

from atomnav.noise import allan, filters, synth
from atomnav.noise.filters import ArimaStateSpace


@pytest.fixture(scope="module")
def paper():
    return ArimaStateSpace.paper()


def test_eq12_coefficients_and_noise(paper):
    np.testing.assert_allclose(paper.phi[0], [0.982, 0.047, -0.029], rtol=1e-9)
    np.testing.assert_array_equal(paper.phi[1:], [[1, 0, 0], [0, 1, 0]])
    qd = paper.process_noise
    assert qd[0, 0] == pytest.approx(0.0693035, rel=1e-9)
    assert np.count_nonzero(qd) == 1
    np.testing.assert_array_equal(paper.h, [1, 0, 0])


def test_eigenvalues(paper):
    ev = np.sort(paper.eigenvalues.real)
    np.testing.assert_allclose(ev, [-0.1795315, 0.1615315, 1.0], atol=1e-7)
    np.testing.assert_allclose(ev, np.sort(np.roots([1, -0.982, -0.047, 0.029]).real), atol=1e-12)
    assert np.all(paper.eigenvalues.imag == 0)


@pytest.mark.parametrize("p,q", [(0, 1), (1, 0), (3, 2), (1, 3)])
def test_general_orders_companion_form(p, q):
    rng = np.random.default_rng(p * 10 + q)
    ar, ma = rng.uniform(-0.4, 0.4, p), rng.uniform(-0.4, 0.4, q)
    m = ArimaStateSpace.from_arma(ar, ma, 0.5)
    # (1 − Σφ Lⁱ)(1 − L) = 1 − Σ c Lⁱ
    c = -np.polymul(np.r_[1.0, -ar], [1.0, -1.0])[1:]
    n = max(p + 1, q + 1)
    assert m.phi.shape == (n, n)
    np.testing.assert_allclose(m.phi[0, : p + 1], c, atol=1e-15)
    assert m.process_noise[0, 0] == pytest.approx(0.5 * (1 + np.sum(ma**2)))
    e = ArimaStateSpace.from_arma(ar, ma, 0.5, noise_form="exact")
    assert e.phi.shape == (p + 1 + q,) * 2


def test_steady_state_gain(paper):
    k, pm, pp = filters.steady_state_gain(paper, 0.035)
    np.testing.assert_allclose(np.round(k, 3), [0.730, 0.196, 0.058], atol=1e-12)
    h = paper.h[None, :]
    ref = solve_discrete_are(paper.phi.T, h.T, paper.process_noise, np.array([[0.035]]))
    np.testing.assert_allclose(pm, ref, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(k, ref[:, 0] / (ref[0, 0] + 0.035), rtol=1e-9)
    assert pm[0, 0] == pytest.approx(0.094497, abs=1e-6) and pp[0, 0] == pytest.approx(0.025540, abs=1e-6)
    # spec §4a.4: closed loop, DC gain 1, white-noise power gain 0.57436.
    a = (np.eye(3) - np.outer(k, paper.h)) @ paper.phi
    ev = np.sort_complex(np.linalg.eigvals(a))
    np.testing.assert_allclose(ev, np.sort_complex([-0.160568, 0.209235 - 0.070958j, 0.209235 + 0.070958j]), atol=2e-6)
    assert (paper.h @ np.linalg.solve(np.eye(3) - a, k)) == pytest.approx(1.0, abs=1e-12)
    x, gains = k.copy(), []
    for _ in range(400):
        gains.append(x[0])
        x = a @ x
    assert np.sum(np.square(gains)) == pytest.approx(0.57436, abs=1e-5)


def test_gain_history_converges_to_steady_state(paper):
    z = synth.model_a()[:20]
    res = filters.kalman(z, paper)
    k, _, _ = filters.steady_state_gain(paper, 0.035)
    np.testing.assert_allclose(res.gain[9:], np.broadcast_to(k, (11, 3)), atol=1e-8)


def test_exact_form_innovation_variance_is_sigma2():
    # With (almost) no measurement noise the exact ARIMA state space predicts ω one step
    # ahead with innovation variance σ² (invertible MA): P⁻∞₀₀ → σ².
    m = ArimaStateSpace.from_arma([0.3, -0.2], [-0.5], 0.7, noise_form="exact")
    _, pm, _ = filters.steady_state_gain(m, 1e-12)
    assert pm[0, 0] == pytest.approx(0.7, rel=1e-8)


def test_eq17_oracle():
    # spec §4a.5: y = [1, 3, 2, 5, 4].
    m = ArimaStateSpace.paper()
    y = np.array([1.0, 3.0, 2.0, 5.0, 4.0])
    lit = filters.kalman(y, m, adaptive="literal").r
    np.testing.assert_allclose(lit, [0.035, 2, 1.25, 7 / 3, 1.875], rtol=1e-14)
    dif = filters.kalman(y, m, adaptive="differenced").r
    np.testing.assert_allclose(dif, [0.035, 0.035, 4.5, 6.25, 41 / 6], rtol=1e-14)


def _batch_r(z, k, reading):
    """Eq. 17 batch form for step k (1-based): Σ(y_i − y_{i−1})²/(2·count)."""
    y = z[:k] if reading == "literal" else np.diff(z[:k])
    dy = np.diff(y)
    return np.sum(dy**2) / (2 * dy.size) if dy.size else None


def _ref_filter(z, phi, qd, r0, mode, b=0.98, adapt_q=False, fading=False):
    """Dense numpy implementation of seed 002 Eq. 15 with Eq. 17 in batch form, and
    Sage–Husa per spec E11 (with the Q-update positivity guard)."""
    n = phi.shape[0]
    x, p, r, qd = np.zeros(n), np.eye(n), r0, qd.copy()
    v, bk, out, rs = 0.0, 1.0, [], []
    for k in range(1, z.size + 1):
        xp, f = phi @ x, phi @ p @ phi.T
        eps = z[k - 1] - xp[0]
        lam = 1.0
        if mode in ("literal", "differenced"):
            rb = _batch_r(z, k, mode)
            r = r if rb is None else rb
        elif mode == "sage_husa":
            if fading:
                v = eps**2 if k == 1 else (0.95 * v + eps**2) / 1.95
                lam = max(1.0, (v - qd[0, 0] - r) / f[0, 0])
            bk *= b
            dk = (1 - b) / (1 - bk)
            rn = (1 - dk) * r + dk * (eps**2 - (lam * f[0, 0] + qd[0, 0]))
            r = rn if rn > 0 else (1 - dk) * r + dk * eps**2
        pm = lam * f + qd
        kk = pm[:, 0] / (pm[0, 0] + r)
        x = xp + kk * eps
        p = pm - np.outer(kk, pm[0])
        p = (p + p.T) / 2
        if mode == "sage_husa" and adapt_q:
            qn = (1 - dk) * qd + dk * (np.outer(kk, kk) * eps**2 + p - f)
            if np.all(np.diag(qn) >= 0):
                qd = qn
        out.append(x[0])
        rs.append(r)
    return np.array(out), np.array(rs)


CASES = [
    ("fixed", {}),
    ("literal", {}),
    ("differenced", {}),
    ("sage_husa", {}),
    ("sage_husa", {"adapt_q": True, "fading": True}),
]


@pytest.mark.parametrize("mode,kw", CASES)
@pytest.mark.parametrize("form", ["paper", "exact"])
def test_parity_with_numpy_reference(mode, kw, form):
    z = synth.model_b(seed=11)[:300]
    m = ArimaStateSpace.from_arma([0.01, 0.02], [-0.95], 0.016, noise_form=form)
    if mode == "sage_husa":
        res = filters.sage_husa(z, m, **kw)
    else:
        res = filters.kalman(z, m, adaptive=None if mode == "fixed" else mode)
    ref, rref = _ref_filter(z, m.phi, m.process_noise, m.sigma2, mode, **kw)
    np.testing.assert_allclose(res.omega_hat, ref, rtol=1e-10, atol=1e-12)
    # Eq. 17 recursion equals its batch formula (spec §4a.5) to 1e-12.
    np.testing.assert_allclose(res.r, rref, rtol=1e-12 if mode != "sage_husa" else 1e-10)


def test_literal_r_equals_avar_tau0():
    w = synth.model_b()
    r = filters.kalman(w, ArimaStateSpace.paper(), adaptive="literal").r
    avar = allan.allan_variance(w, 52.0, m=[1])["var"].iloc[0]
    assert r[-1] == pytest.approx(avar, rel=1e-12)


def test_paper_parameters_on_model_a():
    # spec §5: BS₁ filtered with Q = R₀ = 0.035.
    w = synth.model_a()
    m = ArimaStateSpace.paper()
    got = [allan.bias_stability(filters.kalman(w, m, adaptive=a).omega_hat) for a in (None, "literal", "differenced")]
    np.testing.assert_allclose(got, [0.14296, 0.14392, 0.11777], atol=1e-5)


def test_streaming_equals_batch():
    w = synth.model_b(seed=3)
    m = ArimaStateSpace.paper()
    for mode in ("fixed", "differenced", "literal", "sage_husa"):
        s = filters.KalmanStream(m, adaptive=mode)
        parts = [s.update(c) for c in np.array_split(w, 7)]
        got = np.concatenate([p.omega_hat for p in parts])
        ref = filters.sage_husa(w, m) if mode == "sage_husa" else filters.kalman(w, m, adaptive=None if mode == "fixed" else mode)
        np.testing.assert_array_equal(got, ref.omega_hat)
        np.testing.assert_array_equal(np.concatenate([p.gain for p in parts]), ref.gain)


def test_x0_first_removes_transient():
    w = synth.model_b()
    m = ArimaStateSpace.paper()
    first = filters.kalman(w, m, x0="first").omega_hat
    zeros = filters.kalman(w, m).omega_hat
    # From X̂₀ = ω₁·1 the prediction is exact (rows of Φ sum to 1); from X̂₀ = 0 the first
    # estimate is K₁₀·ω₁ with P⁻₀₀ = |Φ row 0|² + (BQBᵀ)₀₀ and R₀ = Q.
    assert first[0] == pytest.approx(w[0], abs=1e-15)
    pm00 = np.sum(m.phi[0] ** 2) + m.process_noise[0, 0]
    assert zeros[0] == pytest.approx(w[0] * pm00 / (pm00 + 0.035), rel=1e-12)
