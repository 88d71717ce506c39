"""Statistical reproduction of Vasilyuk et al. 2024 (spec §5.1–5.2) by Monte Carlo."""

import numpy as np
import pytest

from atomnav import astro, units

AS = units.ARCSEC
PAPER_SIGMA = np.array([6.0, 0.6, 0.6])  # ″, heading / pitch / roll


@pytest.fixture(scope="module")
def scn():
    return astro.Vasilyuk2024()


def _check(df, ratio_band):
    err = df[["err_psi_rad", "err_theta_rad", "err_gamma_rad"]].to_numpy() / AS
    sig = df[["sigma_psi_rad", "sigma_theta_rad", "sigma_gamma_rad"]].to_numpy() / AS
    mean_sigma = sig.mean(axis=0)
    assert np.all(mean_sigma > PAPER_SIGMA / 2) and np.all(mean_sigma < PAPER_SIGMA * 2), mean_sigma
    assert mean_sigma[0] / mean_sigma[1:].max() > 5  # heading ≈ 10× the tilts
    ratio = err.std(axis=0) / np.sqrt((sig ** 2).mean(axis=0))
    assert np.all(ratio > ratio_band[0]) and np.all(ratio < ratio_band[1]), ratio
    # θ^diff components inside ±3σ (full P^diff, D10) for ≥ 99 % of epochs
    assert df["inside_3sigma"].mean() >= 0.99


def test_monte_carlo_default_size(scn):
    _check(scn.monte_carlo(20, seed0=1000), (0.7, 1.4))


@pytest.mark.slow
def test_monte_carlo_full(scn):
    df = scn.monte_carlo(200, seed0=0)
    _check(df, (0.7, 1.4))
    assert df["chi2_diff"].mean() == pytest.approx(2.93, abs=0.3)  # spec row 24 (full form)


def test_single_run_quantities(scn):
    r = scn.run(7)
    cal = r["calibration"]
    assert cal.iterations <= 5 and cal.observability["verdict"] == "ok"
    assert np.abs(r["theta_error"]).max() < 60 * AS
    assert r["theta_diff"].shape == (72, 3) and r["p_diff"].shape == (72, 3, 3)
    # the sandwich covariance is a covariance of θ^clb in MF: P^clb = C P_θ Cᵀ
    assert np.allclose(cal.p_clb, cal.c @ cal.p_theta @ cal.c.T, rtol=1e-9, atol=0)


def test_consistent_mode_model_prediction_matches_spec():
    # spec §5.2 row 21: model + systematic prediction (6.53, 3.03, 3.37)″ with constant gyro errors
    r = astro.Vasilyuk2024(gyro_error_model="consistent").run(3)
    sd = np.sqrt(np.diag(r["p_beta_model"])) / AS
    assert np.allclose(sd, [6.53, 3.03, 3.37], rtol=0.1), sd
    assert np.all(np.diag(r["p_beta_sys"]) < np.diag(r["p_beta_model"]))


@pytest.mark.slow
def test_consistent_mode_predicts_constant_error_spread():
    df = astro.Vasilyuk2024(gyro_error_model="consistent").monte_carlo(200, seed0=0)
    err = df[["err_psi_rad", "err_theta_rad", "err_gamma_rad"]].to_numpy()
    model = df[["sigma_model_psi_rad", "sigma_model_theta_rad", "sigma_model_gamma_rad"]].to_numpy()
    ratio = err.std(axis=0) / np.sqrt((model ** 2).mean(axis=0))
    assert np.all(np.abs(ratio - 1) < 0.15), ratio
