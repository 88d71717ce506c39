"""Sensitivity function, finite pulses and the convolution predictor vs atom strapdown
(seed 003 Eqs. 13–14; spec atom-strapdown-tennstedt2023.md (E18)–(E20), §4)."""

import numpy as np
import pytest

import atomnav
from atomnav import cai

TD, TAU = 0.010, 7.5e-6
K = cai.K_RB87


def gauss_integral(fn, a, b, n=40):
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (b - a) * np.sum(w * fn(0.5 * (b - a) * x + 0.5 * (a + b)))


@pytest.mark.parametrize("tau", [TAU, 1e-3])
def test_area_of_response(tau):
    """∫ f dt over the piecewise-smooth response = (T + 2τ)(T + 4τ/π) to 1e-9 relative."""
    f = lambda t: cai.sensitivity(t, TD, tau)[1]
    knots = [0.0, tau, TD + tau, TD + 2 * tau]
    total = sum(gauss_integral(f, s * a, s * b) * s for a, b in zip(knots, knots[1:]) for s in (1, -1))
    want = (TD + 2 * tau) * (TD + 4 * tau / np.pi)
    assert total == pytest.approx(want, rel=1e-9)
    assert cai.response_area(TD, tau) == pytest.approx(want, rel=1e-15)


def test_spec_values():
    """f(0) = 0.0100095493 s, ∫f = 1.002456362e-4 s²; outside ±(T_d + 2τ) f = g = 0."""
    g, f = cai.sensitivity([0.0, TD + 2.5 * TAU, -TD - 2.5 * TAU], TD, TAU)
    assert f[0] == pytest.approx(0.0100095493, abs=1e-10)
    assert cai.response_area(TD, TAU) == pytest.approx(1.002456362e-4, rel=1e-9)
    assert np.all(f[1:] == 0) and np.all(g[1:] == 0)


def test_ideal_transfer():
    """4 sin²(ωT/2)/ω² at T = 25 ms: 6.237160e-4 (1 Hz), 5.066059e-4 (10 Hz), 2.533030e-4 (20 Hz)."""
    v = cai.ideal_transfer(0.025, 2 * np.pi * np.array([1.0, 10.0, 20.0]))
    np.testing.assert_allclose(v, [6.237160e-4, 5.066059e-4, 2.533030e-4], rtol=1e-6)


def strapdown_vs_convolution(tau, accel, t):
    """Phases of shots (π pulse at the centres) by convolution and by the predictor."""
    T = TD + 1.5 * tau
    centres = np.array([0.015, 0.040, 0.065])
    a = accel(t)
    conv = cai.convolution_phase(t, a, centres, t_dark=TD, tau=tau, k=K)
    # atom acceleration a along k = −k̂·f_s: feed f = (0, 0, −a), k along z, at rest
    f = np.zeros((len(t), 3))
    f[:, 2] = -a
    ch = cai.Channels(np.array([[0, 0, K]]), (0, 0, 0), np.eye(3), [0, 0, 0])
    # both linear in a; the convolution integrates the samples piecewise linearly, so the
    # predictor does too (its cubic default is 2e-8 closer to the exact integral)
    sd = cai.predict_phase(t, f, np.zeros_like(f), centres - T, T, ch, omega_dot="zero", interpolation="linear")
    return conv, sd.total[:, 0]


def vibration(t):
    return 0.05 * np.sin(2 * np.pi * 4.3 * t + 0.2) + 0.03 * np.sin(2 * np.pi * 9.7 * t) + 0.02 * np.cos(2 * np.pi * 15.1 * t)


def test_convolution_matches_strapdown_on_vibration():
    """100 kHz smooth synthetic vibration: the two phases agree within 0.1 %; with τ → 0
    the remaining difference vanishes (it is the finite-pulse effect)."""
    t = np.arange(0, 8001) * 1e-5
    conv, sd = strapdown_vs_convolution(TAU, vibration, t)
    rel = np.abs(conv / sd - 1)
    assert rel.max() < 1e-3
    conv0, sd0 = strapdown_vs_convolution(1e-12, vibration, t)
    assert np.abs(conv0 / sd0 - 1).max() < 1e-8
    assert rel.max() > 100 * np.abs(conv0 / sd0 - 1).max()


def test_finite_pulse_offset_constant_acceleration():
    """Constant acceleration: strapdown (pulse centres) / convolution − 1 = T²/∫f − 1
    = −2.0459e-4 (spec §4)."""
    t = np.arange(0, 8001) * 1e-5
    conv, sd = strapdown_vs_convolution(TAU, lambda t: np.full_like(t, 0.01), t)
    T = TD + 1.5 * TAU
    want = T**2 / cai.response_area(TD, TAU) - 1
    assert want == pytest.approx(-2.0459e-4, rel=1e-4)
    np.testing.assert_allclose(sd / conv - 1, want, rtol=1e-6)


def test_pulse_timing_whose_area_overflows_is_named():
    # fuzz seed 13: T_d = 1e308 s returned an infinite area
    with pytest.raises(atomnav.InputError) as e:
        cai.response_area(1e308, 100.0)
    assert e.value.parameter == "t_dark"


def test_transfer_whose_phase_overflows_is_named():
    # fuzz seed 14: T = 1e308 s made ωT/2 infinite and the transfer NaN
    with pytest.raises(atomnav.InputError) as e:
        cai.ideal_transfer(1e308, 51.0)
    assert e.value.parameter == "T"
    with pytest.raises(atomnav.InputError) as e:
        cai.ideal_transfer(1e150, [1.0, 1e160])
    assert (e.value.parameter, e.value.index) == ("omega", 1)
