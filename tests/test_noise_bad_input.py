"""Bad input → ValueError naming the field (and the first offending index for series)."""

import numpy as np
import pytest

from atomnav.noise import allan, arma, baselines, filters

W = np.random.default_rng(0).normal(size=200)


def test_series_shorter_than_model_needs():
    with pytest.raises(ValueError, match=r"omega: series of 20 samples is too short; at least 41"):
        arma.fit_arma(W[:20], order=(2, 1))
    with pytest.raises(ValueError, match=r"data: series of 2 samples is too short"):
        allan.allan_variance(W[:2], 1.0)
    with pytest.raises(ValueError, match=r"omega: series of 100 samples is too short for a 5-level db4"):
        baselines.wavelet_denoise(W[:100])


def test_nan_names_index():
    x = W.copy()
    x[17] = np.inf  # a NaN rate sample is a gap to the Allan family (tests/test_nan_missing.py)
    with pytest.raises(ValueError, match=r"data: non-finite value inf at index 17$"):
        allan.allan_variance(x, 1.0)
    x[17] = np.nan
    with pytest.raises(ValueError, match=r"omega: non-finite value nan at index 17"):
        filters.kalman(x, filters.ArimaStateSpace.paper())
    with pytest.raises(ValueError, match=r"omega: non-finite value nan at index 17"):
        arma.fit_arma(x)


def test_constant_series():
    c = np.full(300, 0.6851)
    # a stuck sensor has zero Allan variance (allantools and Stable32 give 0)
    assert (allan.allan_variance(c, 52.0)["var"] == 0.0).all()
    with pytest.raises(ValueError, match=r"omega: constant series"):
        arma.fit_arma(c)
    assert (allan.allan_variance(np.arange(50.0), 1.0, data_type="phase")["var"] == 0.0).all()


def test_tau_larger_than_half_the_record():
    with pytest.raises(ValueError, match=r"m: averaging factor 100 at index 2 has 1 terms"):
        allan.allan_variance(W, 1.0, m=[1, 2, 100])
    with pytest.raises(ValueError, match=r"index 1"):
        allan.allan_variance(W, 2.0, taus=[2.0, 202.0])
    with pytest.raises(ValueError, match=r"m: averaging factor 67 at index 0"):
        allan.allan_variance(W, 1.0, m=[67], kind="hadamard")


@pytest.mark.parametrize("tau0", [0.0, -52.0, np.nan])
def test_non_positive_sample_interval(tau0):
    with pytest.raises(ValueError, match=r"tau0: must be finite and > 0"):
        allan.allan_variance(W, tau0)
    with pytest.raises(ValueError, match=r"tau0: must be finite and > 0"):
        baselines.butterworth_lowpass(W, tau0)
