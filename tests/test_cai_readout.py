"""Readout, mid-fringe steering, inversion on a flank, fringe counting
(spec cai-ekf-tennstedt2021.md (E3)–(E6))."""

import numpy as np
import pytest

from atomnav import cai


def test_readout_model_and_inversion():
    phi = np.linspace(-20, 20, 101)
    phi0 = cai.steer_mid_fringe(phi + 0.3)  # predicted phase off by 0.3 rad
    p = cai.readout(phi, phi0, offset=0.45, contrast=0.8)
    np.testing.assert_allclose(p, 0.45 - 0.4 * np.cos(phi + phi0), rtol=0, atol=1e-15)
    # steering puts φ̂ + φ0 at π/2 (mod 2π): the readout sits on the rising flank
    np.testing.assert_allclose(np.mod(phi + 0.3 + phi0, 2 * np.pi), np.pi / 2, atol=1e-12)
    back = cai.invert_readout(p, phi0, offset=0.45, contrast=0.8, flank="rising")
    np.testing.assert_allclose(np.mod(back - phi + np.pi, 2 * np.pi) - np.pi, 0, atol=1e-9)


def test_falling_flank_and_mid_fringe_value():
    assert cai.readout(np.pi / 2) == pytest.approx(0.5)
    p = cai.readout(-1.0)
    assert cai.invert_readout(p, flank="falling") == pytest.approx(-1.0)
    assert cai.invert_readout(p, flank="rising") == pytest.approx(1.0)


def test_readout_noise_statistics():
    """Mid-fringe phase noise σ_φ maps to population noise (C/2)σ_φ; σ_p adds in quadrature."""
    n = 200_000
    p = cai.readout(np.zeros(n), np.pi / 2, sigma_p=0.01, sigma_phi=0.05, seed=1)
    assert np.std(p) == pytest.approx(np.hypot(0.01, 0.5 * 0.05), rel=0.01)
    pc = cai.readout(np.zeros(n), 0.0, sigma_contrast=0.04, seed=2)  # at the fringe minimum
    assert np.std(pc) == pytest.approx(0.02, rel=0.01)


def test_fringes_and_capture():
    assert list(cai.fringes_crossed([0.1, 2 * np.pi + 0.1, -13.0])) == [0, 1, 2]
    assert list(cai.capture_region([0.1, 2.0, -4.0])) == ["A", "B", "slip"]
