"""ARMA identification on statsmodels (Niu et al. 2025 Eqs. 6–13; settings in
docs/departures.md#statsmodels-defaults): differencing and its
inverse, ADF and KPSS with a plain verdict, ACF/PACF with bands, the AIC/BIC order grid,
exact-ML fit and residual diagnostics. Nothing here re-implements statsmodels."""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .._validate import choice, finite_result, flag, input_error, integer, scalar, vector


def _series(x, name: str, min_len: int) -> np.ndarray:
    a = vector(x, None, name)
    if a.size < min_len:
        raise input_error(name, f"series of {a.size} samples is too short; at least {min_len} are needed")
    if np.all(a == a[0]):
        raise input_error(name, f"constant series (every value is {a[0]}); nothing to model")
    return a


def difference(omega, d: int = 1) -> np.ndarray:
    """d-th difference (Niu et al. 2025 Eq. 11; docs/departures.md#first-difference): d_k = ω_k − ω_{k−1}, length N − d.

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    d : int, default 1
        Order of differencing (N > d).

    Returns
    -------
    numpy.ndarray (N − d,)
        The d-th difference, unit U.

    References
    ----------
    G. E. P. Box and G. M. Jenkins, *Time Series Analysis: Forecasting and Control*
    (Holden-Day, 1970).
    """
    d = integer(d, "d")
    x = vector(omega, None, "omega")
    if x.size <= d:
        raise input_error("omega", f"series of {x.size} samples is too short to difference {d} times")
    return np.diff(x, n=d)


def undifference(diffs, initial) -> np.ndarray:
    """Inverse of :func:`difference` for d = 1: ω = [ω₁, ω₁ + cumsum(d)].

    Parameters
    ----------
    diffs : array_like (N − 1,)
        First differences, unit U.
    initial : float
        First value ω₁ of the series, unit U.

    Returns
    -------
    numpy.ndarray (N,)
        The series ω, unit U.
    """
    dd = vector(diffs, None, "diffs")
    w0 = scalar(initial, "initial")
    return np.concatenate([[w0], w0 + np.cumsum(dd)])


@dataclass
class Stationarity:
    """ADF (H₀: unit root) and KPSS (H₀: level-stationary) results. ``passed`` when ADF
    rejects its null (p < alpha) and KPSS does not reject its null (p > alpha).
    KPSS p-values are clipped by statsmodels to [0.01, 0.10].

    Returned by :func:`stationarity`.

    Attributes
    ----------
    adf_stat, adf_p : float
        Augmented Dickey–Fuller statistic and its p-value.
    kpss_stat, kpss_p : float
        KPSS statistic and its p-value (clipped to [0.01, 0.10]).
    alpha : float
        Significance level of both verdicts.
    """

    adf_stat: float
    adf_p: float
    kpss_stat: float
    kpss_p: float
    alpha: float

    @property
    def adf_rejects_unit_root(self) -> bool:
        return self.adf_p < self.alpha

    @property
    def kpss_stationary(self) -> bool:
        return self.kpss_p > self.alpha

    @property
    def passed(self) -> bool:
        return self.adf_rejects_unit_root and self.kpss_stationary

    @property
    def verdict(self) -> str:
        adf = f"ADF {'rejects' if self.adf_rejects_unit_root else 'does not reject'} a unit root (stat {self.adf_stat:.3f}, p = {self.adf_p:.3g})"
        kp = f"KPSS {'does not reject' if self.kpss_stationary else 'rejects'} stationarity (stat {self.kpss_stat:.3f}, p {'≥' if self.kpss_p >= 0.1 else '≤' if self.kpss_p <= 0.01 else '='} {self.kpss_p:.3g})"
        return f"{'stationary' if self.passed else 'NOT shown stationary'}: {adf}; {kp}"


def stationarity(z, regression: str = "c", alpha: float = 0.05) -> Stationarity:
    """ADF (``adfuller(regression, autolag='AIC')``) and KPSS (``kpss(regression,
    nlags='auto')``) on the series z (docs/departures.md#statsmodels-defaults).

    Parameters
    ----------
    z : array_like (N,)
        Series to test (N ≥ 20, not constant).
    regression : {"c", "ct"}, default "c"
        "c" (level) or "ct" (trend); Matlab's defaults differ, hence exposed.
    alpha : float, default 0.05
        Significance level of the verdicts.

    Returns
    -------
    Stationarity
        Both statistics, their p-values and the verdict.
    """
    from statsmodels.tsa.stattools import adfuller, kpss
    from statsmodels.tools.sm_exceptions import InterpolationWarning

    regression = choice(regression, ("c", "ct"), "regression")
    x = _series(z, "z", 20)
    with warnings.catch_warnings():
        # KPSS p-values outside its table are clipped (documented above); newer
        # statsmodels announce a result-object return type (FutureWarning).
        warnings.simplefilter("ignore", InterpolationWarning)
        warnings.simplefilter("ignore", FutureWarning)
        adf = adfuller(x, regression=regression, autolag="AIC")
        k = kpss(x, regression=regression, nlags="auto")
    return Stationarity(float(adf[0]), float(adf[1]), float(k[0]), float(k[1]), alpha)


def acf_pacf(z, nlags: int = 40) -> pd.DataFrame:
    """ACF (``acf(fft=True)``) and PACF (``pacf(method='ywadjusted')``) to ``nlags`` with the
    ±1.96/√N white-noise band.

    Parameters
    ----------
    z : array_like (N,)
        Series (N ≥ 2·nlags + 2, not constant).
    nlags : int, default 40
        Largest lag (≥ 1).

    Returns
    -------
    pandas.DataFrame
        ``nlags`` + 1 rows; columns lag, acf, pacf, band.

    References
    ----------
    G. E. P. Box and G. M. Jenkins, *Time Series Analysis: Forecasting and Control*
    (Holden-Day, 1970).
    """
    from statsmodels.tsa.stattools import acf, pacf

    nlags = integer(nlags, "nlags", 1)
    x = _series(z, "z", 2 * nlags + 2)
    band = 1.96 / np.sqrt(x.size)
    return pd.DataFrame({"lag": np.arange(nlags + 1), "acf": acf(x, nlags=nlags, fft=True), "pacf": pacf(x, nlags=nlags, method="ywadjusted"), "band": band})


def _min_len(p: int, q: int) -> int:
    # p + q + 1 parameters (σ² included); ask for ten observations per parameter.
    return 10 * (p + q + 1)


def _arima(d, p: int, q: int):
    from statsmodels.tsa.arima.model import ARIMA

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ARIMA(d, order=(p, 0, q), trend="n").fit()


def select_arma(d, max_p: int = 3, max_q: int = 3) -> pd.DataFrame:
    """AIC and BIC of ARMA(p, q) fits to the (already differenced) series d for every
    p ≤ max_p, q ≤ max_q (docs/departures.md#order-selection). AIC = 2n_p − 2 ln L, BIC = n_p ln n − 2 ln L, n_p
    including σ².

    Parameters
    ----------
    d : array_like (N,)
        The (already differenced) series; at least 10·(max_p + max_q + 1) samples.
    max_p, max_q : int, default 3
        Largest AR and MA orders of the grid.

    Returns
    -------
    pandas.DataFrame
        One row per (p, q); columns p, q, llf, aic, bic, sorted by BIC.

    References
    ----------
    G. E. P. Box and G. M. Jenkins, *Time Series Analysis: Forecasting and Control*
    (Holden-Day, 1970).
    """
    max_p, max_q = integer(max_p, "max_p"), integer(max_q, "max_q")
    x = _series(d, "d", _min_len(max_p, max_q))
    rows = []
    for p in range(max_p + 1):
        for q in range(max_q + 1):
            r = _arima(x, p, q)
            rows.append({"p": p, "q": q, "llf": r.llf, "aic": r.aic, "bic": r.bic})
    return pd.DataFrame(rows).sort_values("bic", ignore_index=True)


@dataclass(kw_only=True)
class ArmaFit:
    """Exact-ML ARMA(p, q) fit of d (statsmodels), returned by :func:`fit_arma`.

    Attributes
    ----------
    order : tuple of int
        (p, q).
    ar : numpy.ndarray (p,)
        AR coefficients φ.
    ma : numpy.ndarray (q,)
        MA coefficients β.
    sigma2 : float
        Innovation variance σ_a², U².
    se : dict
        Standard errors by parameter name (``ar.L1``, ``ma.L1``, ``sigma2``).
    residuals : numpy.ndarray (N,)
        The one-step residuals, unit U.
    dw : float
        Their Durbin–Watson statistic.
    ljung_box : pandas.DataFrame
        The Ljung–Box table (:func:`ljung_box`).
    aic, bic : float
        Akaike and Bayesian information criteria.

    References
    ----------
    G. E. P. Box and G. M. Jenkins, *Time Series Analysis: Forecasting and Control*
    (Holden-Day, 1970).
    """

    order: tuple
    ar: np.ndarray
    ma: np.ndarray
    sigma2: float
    se: dict
    residuals: np.ndarray
    dw: float
    ljung_box: pd.DataFrame
    aic: float
    bic: float


def fit_arma(omega, order=(2, 1), differenced: bool = False, lags: int = 10) -> ArmaFit:
    """Fit ARMA(p, q) = ``order`` by exact ML to the first difference of ``omega`` (i.e.
    ARIMA(p,1,q) on ω), or to ``omega`` itself when ``differenced=True``.
    ``ARIMA(d, order=(p,0,q), trend='n')`` (docs/departures.md#statsmodels-defaults).

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U; at least 10·(p + q + 1) samples (one more when differenced
        here).
    order : tuple of int, default (2, 1)
        (p, q).
    differenced : bool, default False
        True when ``omega`` is already the series to model.
    lags : int, default 10
        Lags of the Ljung–Box test of the residuals.

    Returns
    -------
    ArmaFit
        Coefficients, σ_a², standard errors and residual diagnostics.

    Raises
    ------
    TypeError
        ``order`` is not a pair.
    atomnav.InputError
        Naming ``order``, ``differenced`` or ``omega`` (too short, constant, or a pure
        ramp).

    References
    ----------
    G. E. P. Box and G. M. Jenkins, *Time Series Analysis: Forecasting and Control*
    (Holden-Day, 1970).
    """
    try:
        p, q = order
    except (TypeError, ValueError):
        raise TypeError(f"order: expected a pair of ints (p, q), got {order!r}") from None
    p, q = integer(p, "order"), integer(q, "order")
    differenced = flag(differenced, "differenced")
    need = _min_len(p, q) + (0 if differenced else 1)
    w = _series(omega, "omega", need)
    d = w if differenced else np.diff(w)
    if np.all(d == d[0]):
        raise input_error("omega", "the differenced series is constant (a pure ramp); nothing to model")
    r = _arima(d, p, q)
    names = list(r.model.param_names)
    par = dict(zip(names, np.asarray(r.params)))
    se = dict(zip(names, np.asarray(r.bse)))
    res = np.asarray(r.resid)
    return ArmaFit(
        order=(p, q),
        ar=np.array([par[f"ar.L{i}"] for i in range(1, p + 1)]),
        ma=np.array([par[f"ma.L{i}"] for i in range(1, q + 1)]),
        sigma2=float(par["sigma2"]),
        se=se,
        residuals=res,
        dw=durbin_watson(res),
        ljung_box=ljung_box(res, lags),
        aic=float(r.aic),
        bic=float(r.bic),
    )


def durbin_watson(e) -> float:
    """DW = Σ(e_k − e_{k−1})² / Σe_k² (Niu et al. 2025 Eq. 13); 2 for white residuals, 0 for a
    constant series.

    Parameters
    ----------
    e : array_like (N,)
        Residuals (N ≥ 2, not all zero).

    Returns
    -------
    float
        The Durbin–Watson statistic, in [0, 4].
    """
    from statsmodels.stats.stattools import durbin_watson as dw

    x = vector(e, None, "e")
    if x.size < 2:
        raise input_error("e", f"series of {x.size} samples is too short; at least 2 are needed")
    if not np.any(x):
        raise input_error("e", "every residual is zero: Σe² = 0 and DW is undefined")
    with np.errstate(over="ignore", invalid="ignore"):
        return float(finite_result(dw(x), "e", "Σ(e_k − e_{k−1})² / Σe_k²"))


def ljung_box(e, lags: int = 10) -> pd.DataFrame:
    """Ljung–Box Q test of the residuals at lags 1…``lags``.

    Parameters
    ----------
    e : array_like (N,)
        Residuals (N > lags + 1, not constant).
    lags : int, default 10
        Largest lag (≥ 1).

    Returns
    -------
    pandas.DataFrame
        One row per lag; columns lb_stat, lb_pvalue.

    References
    ----------
    G. M. Ljung and G. E. P. Box, "On a measure of lack of fit in time series models",
    *Biometrika* 65 (1978).
    """
    from statsmodels.stats.diagnostic import acorr_ljungbox

    x = vector(e, None, "e")
    lags = integer(lags, "lags", 1)
    if x.size <= lags + 1:
        raise input_error("e", f"series of {x.size} samples is too short for {lags} lags")
    if np.all(x == x[0]):
        raise input_error("e", "constant residuals have no autocorrelation (0/0)")
    return acorr_ljungbox(x, lags=lags)
