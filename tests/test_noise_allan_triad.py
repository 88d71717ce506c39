"""AllanFit.to_triad: a five-term Allan fit as the error model of an IMU triad (IEEE Std
952-1997, Annex C: σ²(τ) = N²/τ + (2 ln 2/π) B² + K²τ/3)."""

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import units
from atomnav.noise import allan

TAU0 = 0.1
M = 2 ** np.arange(15)
N, B, K = 1.2, 0.5, 0.05  # ARW (°/h)·√s, bias instability °/h, RRW (°/h)/√s


def closed_form_fit(extra="", size=0.0):
    """The fit of the exact Allan variance of white + flicker + rate random walk in °/h,
    plus a quantization (3Q²/τ²) or ramp (R²τ²/2) term of ``size`` when ``extra`` names it."""
    tau = TAU0 * M
    var = N**2 / tau + 2 * np.log(2) / np.pi * B**2 + K**2 * tau / 3
    var = var + {"": 0.0, "quantization": 3 * size**2 / tau**2, "ramp": size**2 * tau**2 / 2}[extra]
    terms = ("arw", "bias_instability", "rrw") + ((extra,) if extra else ())
    return allan.fit_allan_table(pd.DataFrame({"m": M, "tau_s": tau, "var": var}), 288_000, terms=terms)


def test_densities_in_si():
    """white = N, flicker b = B, bias_rw = K, each times the SI factor of °/h; nothing else."""
    triad = closed_form_fit().to_triad(units.DEG_PER_HOUR)
    deg_h = np.pi / 180 / 3600
    np.testing.assert_allclose([triad.white, triad.flicker.b, triad.bias_rw], [N * deg_h, B * deg_h, K * deg_h], rtol=1e-9)
    assert triad.bias == (0.0, 0.0, 0.0) and triad.scale == (0.0, 0.0, 0.0) and triad.gauss_markov is None
    # field units: 0.02 °/√h, 3 °/h/√h
    summary = an.imu.ImuErrors(gyro=triad).summary().set_index(["sensor", "parameter"])["value_field"]
    np.testing.assert_allclose([summary["gyro", "white"], summary["gyro", "bias_rw"], summary["gyro", "flicker_b"]],
                               [N / 60, K * 60, B], rtol=1e-9)


def test_flicker_band():
    """Default band: a decade below the longest τ up to the log's Nyquist frequency; given
    bands pass through."""
    fit = closed_form_fit()
    band = fit.to_triad().flicker
    assert band.f_lo == pytest.approx(0.1 / (TAU0 * M[-1]), rel=1e-12)
    assert band.f_hi == pytest.approx(1 / (2 * TAU0), rel=1e-12)
    given = fit.to_triad(f_lo=1e-5, f_hi=0.5).flicker
    assert (given.f_lo, given.f_hi) == (1e-5, 0.5)


def test_simulated_triad_has_the_fitted_allan_deviation():
    """A gyro simulated from the triad has the closed-form Allan deviation at the τ of
    each term, within the 99 % χ² interval of the estimate."""
    triad = closed_form_fit().to_triad(units.DEG_PER_HOUR, f_lo=1e-5, f_hi=1.0)
    n = 8 * 3600 * 10
    sim = an.imu.ImuSimulator(an.imu.ImuErrors(gyro=triad), TAU0, kind="rates", seed=3)
    accel = np.tile([0.0, 0.0, -9.81], (n, 1))
    gyro = sim.corrupt(accel, np.zeros((n, 3)))["gyro_x_rad_s"] / units.DEG_PER_HOUR
    table = allan.allan_variance(gyro, TAU0, m=[1, 512, 16384], confidence=0.99)
    tau = table["tau_s"].to_numpy()
    want = np.sqrt(N**2 / tau + 2 * np.log(2) / np.pi * B**2 + K**2 * tau / 3)
    assert np.all(table["dev_lo"] <= want) and np.all(want <= table["dev_hi"]), (table, want)


@pytest.mark.parametrize("extra, size", [("quantization", 0.01), ("ramp", 1e-4)])
def test_terms_the_imu_model_lacks(extra, size):
    """A quantization or ramp term has no counterpart in ImuErrors: InputError naming terms."""
    fit = closed_form_fit(extra, size)
    assert getattr(fit, extra) == pytest.approx(size, rel=1e-6)
    with pytest.raises(an.InputError, match=extra) as e:
        fit.to_triad()
    assert e.value.parameter == "terms"


@pytest.mark.parametrize("kw, name", [({"rate_unit": 0.0}, "rate_unit"), ({"f_lo": -1.0}, "f_lo"), ({"f_hi": np.nan}, "f_hi")])
def test_bad_arguments(kw, name):
    with pytest.raises(an.InputError) as e:
        closed_form_fit().to_triad(**kw)
    assert e.value.parameter == name
