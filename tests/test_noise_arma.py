"""ARMA pipeline on statsmodels (spec §4b.1–2, E19): forced-order recovery on model A,
stationarity verdicts, order grid, Durbin–Watson and Ljung–Box."""

import numpy as np
import pytest

from atomnav.noise import arma, synth
from atomnav.noise.filters import PAPER_AR, PAPER_MA, PAPER_SIGMA2


@pytest.fixture(scope="module")
def model_a():
    return synth.model_a()


@pytest.fixture(scope="module")
def fit_a(model_a):
    return arma.fit_arma(model_a, order=(2, 1))


def test_forced_arma21_recovers_paper_coefficients(fit_a):
    truth = {"ar.L1": PAPER_AR[0], "ar.L2": PAPER_AR[1], "ma.L1": PAPER_MA[0], "sigma2": PAPER_SIGMA2}
    est = {"ar.L1": fit_a.ar[0], "ar.L2": fit_a.ar[1], "ma.L1": fit_a.ma[0], "sigma2": fit_a.sigma2}
    for k, t in truth.items():
        assert abs(est[k] - t) < 2 * fit_a.se[k], (k, est[k], fit_a.se[k])
    # spec §4b.1 reference values for this seed.
    np.testing.assert_allclose([fit_a.ar[0], fit_a.ar[1], fit_a.ma[0], fit_a.sigma2], [-0.0467, 0.0102, -0.9844, 0.03500], atol=6e-5)
    assert fit_a.dw == pytest.approx(2.0022, abs=1e-4)


@pytest.mark.slow
def test_recovery_within_3se_over_seeds():
    # spec §4b.1: Monte-Carlo rule 3 SE, seeds 5000–5019.
    for seed in range(5000, 5020):
        f = arma.fit_arma(synth.model_a(seed=seed), order=(2, 1))
        for est, t, k in [(f.ar[0], PAPER_AR[0], "ar.L1"), (f.ar[1], PAPER_AR[1], "ar.L2"), (f.ma[0], PAPER_MA[0], "ma.L1"), (f.sigma2, PAPER_SIGMA2, "sigma2")]:
            assert abs(est - t) < 3 * f.se[k], (seed, k)


def test_stationarity_verdicts(model_a):
    d = arma.difference(model_a)
    s = arma.stationarity(d)
    assert s.passed and s.adf_stat == pytest.approx(-11.77, abs=0.01) and s.kpss_p >= 0.1
    assert s.verdict.startswith("stationary")
    raw = arma.stationarity(model_a)
    assert not raw.passed and not raw.kpss_stationary and "NOT" in raw.verdict
    b = arma.stationarity(arma.difference(synth.model_b()))
    assert b.passed and b.adf_stat == pytest.approx(-10.89, abs=0.01)
    assert not arma.stationarity(synth.model_b()).kpss_stationary


def test_difference_round_trip(model_a):
    d = arma.difference(model_a)
    assert d.size == model_a.size - 1
    np.testing.assert_allclose(arma.undifference(d, model_a[0]), model_a, rtol=0, atol=1e-12)


@pytest.mark.slow
def test_full_order_grid_table(model_a):
    t = arma.select_arma(arma.difference(model_a))
    assert len(t) == 16 and set(t.columns) >= {"p", "q", "aic", "bic", "llf"}
    # spec §4b.1: AIC and BIC both choose (0, 1) on this data, not the generating (2, 1).
    best_aic = t.loc[t["aic"].idxmin()]
    assert (best_aic.p, best_aic.q) == (0, 1) and (t.iloc[0].p, t.iloc[0].q) == (0, 1)
    row = t[(t.p == 2) & (t.q == 1)].iloc[0]
    assert row.aic == pytest.approx(-450.95, abs=0.01) and row.bic == pytest.approx(-431.74, abs=0.01)


def test_order_grid_table(model_a):
    # Reduced grid in the default run (statsmodels fits dominate the time).
    t = arma.select_arma(arma.difference(model_a), max_p=1, max_q=1)
    assert len(t) == 4 and set(t.columns) >= {"p", "q", "aic", "bic", "llf"}
    best = t.iloc[0]
    assert (best.p, best.q) == (0, 1) and t["aic"].idxmin() == 0
    assert best.aic == pytest.approx(-452.88, abs=0.01) and best.bic == pytest.approx(-443.28, abs=0.01)
    # AIC = 2n_p − 2 ln L and BIC = n_p ln n − 2 ln L with n_p including σ².
    n_p = t.p + t.q + 1
    np.testing.assert_allclose(t.aic, 2 * n_p - 2 * t.llf, rtol=1e-12)
    np.testing.assert_allclose(t.bic, n_p * np.log(899) - 2 * t.llf, rtol=1e-12)


def test_acf_pacf_band():
    z = np.random.default_rng(20250226).normal(size=900)
    t = arma.acf_pacf(z)
    assert t.acf[0] == 1 and len(t) == 41
    assert t.band.iloc[0] == pytest.approx(1.96 / 30)
    assert np.mean(np.abs(t.acf[1:]) > t.band[1:]) < 0.15


def test_durbin_watson_oracles():
    # spec §4a.9
    assert arma.durbin_watson([1, -1, 1, -1]) == pytest.approx(3.0)
    assert arma.durbin_watson(np.ones(10)) == 0.0
    z = np.random.default_rng(20250226).normal(size=100_000)
    assert arma.durbin_watson(z) == pytest.approx(2.00226, abs=1e-5)
    z9 = np.random.default_rng(20250226).normal(size=900)
    assert arma.durbin_watson(z9) == pytest.approx(2.0346, abs=1e-4)


def test_ljung_box_residuals_white(fit_a):
    assert fit_a.ljung_box["lb_pvalue"].min() > 0.01
    ar1 = np.zeros(900)
    e = np.random.default_rng(1).normal(size=900)
    for k in range(1, 900):
        ar1[k] = 0.5 * ar1[k - 1] + e[k]
    assert arma.ljung_box(ar1)["lb_pvalue"].max() < 1e-6
