"""ARIMA state-space form and Kalman filters of Niu et al. 2025; the
numerical work runs in Rust.

Eq. 17 has two readings (docs/departures.md#reading-of-eq-17): ``"literal"`` takes y = ω (the raw rate);
``"differenced"`` takes y = d = ω_k − ω_{k−1}, the symbol's meaning everywhere else in
the paper. The default adaptive reading is ``"differenced"``: on model-B data only it
reproduces the paper's "adaptive better than fixed" (100/100 seeds); the
literal reading ties with the fixed filter, or loses to it with the paper's Q.
Sage–Husa is the standard form (docs/departures.md#sage-husa-filter) — the paper gives no equations for it.
"""

from __future__ import annotations

import json
from dataclasses import KW_ONLY, dataclass, field, fields

import numpy as np

from .. import _core
from .._stateful import Stateful, serialized
from .._validate import as_floats, finite, input_error, instance, positive, vector

#: The default reading of Eq. 17 (docs/departures.md#reading-of-eq-17).
DEFAULT_READING = "differenced"
READINGS = ("differenced", "literal")
#: Niu et al. 2025 Eq. 10: φ₁, φ₂, β₁, σ_a² (°/h)².
PAPER_AR = (-0.018, 0.029)
PAPER_MA = (-0.99,)
PAPER_SIGMA2 = 0.035


@dataclass(frozen=True)
class ArimaStateSpace:
    """ARIMA(p,d,q) in state-space form X_k = Φ X_{k−1} + B W_{k−1}, Y_k = H X_k + V_k
    (Niu et al. 2025 Eqs. 14, 16) with H = [1 0 … 0].

    ``ar`` = φ, ``ma`` = β (statsmodels' sign convention, Niu et al. 2025 Eqs. 6–8), ``sigma2`` = σ_a² in
    the rate unit squared. ``noise_form="paper"``: the paper's B with Q = σ²I
    (default); ``"exact"``: X = [ω…, a_k…], G = e₀ + e_r, scalar Q = σ² (docs/departures.md#arma-noise-form).

    Parameters
    ----------
    ar : sequence of float (p,)
        AR coefficients φ (statsmodels' sign convention).
    ma : sequence of float (q,)
        MA coefficients β.
    sigma2 : float
        Innovation variance σ_a², rate unit squared (> 0).
    d : int, default 1
        Order of differencing.
    noise_form : {"paper", "exact"}, default "paper"
        Form of the process noise, as above.

    References
    ----------
    G. E. P. Box and G. M. Jenkins, *Time Series Analysis: Forecasting and Control*
    (Holden-Day, 1970). X. Niu et al. 2025, Eqs. 6–8, 14, 16.
    """

    ar: tuple
    ma: tuple
    sigma2: float
    d: int = 1
    noise_form: str = "paper"
    _m: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for name in ("ar", "ma"):
            v = as_floats(getattr(self, name), name).reshape(-1)
            finite(v, name)
            object.__setattr__(self, name, tuple(float(c) for c in v))
        object.__setattr__(self, "_m", _core.arima_state_space(list(self.ar), list(self.ma), positive(self.sigma2, "sigma2"), self.d, self.noise_form))

    @classmethod
    def from_arma(cls, ar, ma, sigma2: float, d: int = 1, noise_form: str = "paper") -> "ArimaStateSpace":
        """The state-space form of an ARIMA(len(ar), d, len(ma)) model (checked as the
        constructor checks it).

        Parameters
        ----------
        ar, ma, sigma2, d, noise_form
            As in :class:`ArimaStateSpace`.

        Returns
        -------
        ArimaStateSpace
            The model.
        """
        return cls(ar, ma, sigma2, d, noise_form)

    @classmethod
    def paper(cls, noise_form: str = "paper") -> "ArimaStateSpace":
        """The paper's ARIMA(2,1,1): φ = (−0.018, 0.029), β₁ = −0.99, σ_a² = 0.035 (°/h)².

        Parameters
        ----------
        noise_form : {"paper", "exact"}, default "paper"
            As in :class:`ArimaStateSpace`.

        Returns
        -------
        ArimaStateSpace
            The model of Niu et al. 2025, Eq. 10 (rate in °/h).
        """
        return cls(PAPER_AR, PAPER_MA, PAPER_SIGMA2, 1, noise_form)

    @property
    def phi(self) -> np.ndarray:
        """Transition matrix Φ (n, n)."""
        return self._m["phi"]

    @property
    def b(self) -> np.ndarray:
        """Noise gain B."""
        return self._m["b"]

    @property
    def q(self) -> np.ndarray:
        """Noise covariance Q."""
        return self._m["q"]

    @property
    def process_noise(self) -> np.ndarray:
        """B Q Bᵀ (n, n)."""
        return self._m["qd"]

    @property
    def h(self) -> np.ndarray:
        """Measurement row H = [1 0 … 0]."""
        h = np.zeros(self.phi.shape[0])
        h[0] = 1.0
        return h

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of Φ (complex): the roots of the integrated AR polynomial, one of
        them 1 per difference."""
        return np.linalg.eigvals(self.phi)

    def _args(self) -> tuple:
        return (list(self.ar), list(self.ma), self.sigma2, int(self.d), self.noise_form)


@dataclass(frozen=True)
class ArmaFilterConfig:
    """Everything that defines a Kalman filter run on an ARIMA model, frozen, checked by
    the Rust core when created (mirror of ``noise::arma_filter::ArmaFilterConfig``); save
    it beside the results with :meth:`to_json`.

    ``ar``, ``ma``, ``sigma2``, ``d``, ``noise_form`` as in :class:`ArimaStateSpace`;
    ``r0`` the initial (and fixed) measurement variance (None: ``sigma2``, the paper's
    R₀ = Q); ``adaptive`` one of ``_core.OPTIONS["Adaptive"]`` ("fixed", "literal",
    "differenced" — Niu et al. 2025, Eq. 17 — or "sage_husa" with forgetting factor ``b``,
    optional Q adaptation ``adapt_q`` and fading ``fading``); ``x0`` "zeros" or "first";
    P₀ = ``p0``·I.

    Parameters
    ----------
    ar, ma : sequence of float
        AR coefficients φ (p,) and MA coefficients β (q,).
    sigma2 : float
        Innovation variance σ_a², rate unit squared.
    d : int, default 1
        Order of differencing.
    noise_form : {"paper", "exact"}, default "paper"
        As in :class:`ArimaStateSpace`.
    r0 : float, optional
        Initial (and, for "fixed", constant) measurement variance R₀, rate unit squared;
        None: ``sigma2`` (the paper's R₀ = Q).
    adaptive : {"fixed", "literal", "differenced", "sage_husa"}, default "fixed"
        Measurement-variance adaptation.
    b : float, default 0.98
        Sage–Husa forgetting factor.
    adapt_q : bool, default False
        Sage–Husa: adapt Q as well.
    fading : bool, default False
        Sage–Husa: strong-tracking fading factor.
    x0 : {"zeros", "first"}, default "zeros"
        Initial state: zeros (paper) or the first sample ω₁.
    p0 : float, default 1.0
        Initial covariance P₀ = p0·I, rate unit squared.
    """

    ar: tuple
    ma: tuple
    sigma2: float
    _: KW_ONLY
    d: int = 1
    noise_form: str = "paper"
    r0: float | None = None
    adaptive: str = "fixed"
    b: float = 0.98
    adapt_q: bool = False
    fading: bool = False
    x0: str = "zeros"
    p0: float = 1.0
    _core: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for name in ("ar", "ma"):
            object.__setattr__(self, name, tuple(float(c) for c in as_floats(getattr(self, name), name).reshape(-1)))
        object.__setattr__(self, "_core", _core.ArmaFilterConfig(**self.to_dict()))

    @classmethod
    def for_model(cls, model: ArimaStateSpace, **options) -> "ArmaFilterConfig":
        """The configuration of a filter on ``model`` with the given filter ``options``.

        Parameters
        ----------
        model : ArimaStateSpace
            Gives ``ar``, ``ma``, ``sigma2``, ``d`` and ``noise_form``.
        **options
            The filter fields (``r0``, ``adaptive``, ``b``, ``adapt_q``, ``fading``,
            ``x0``, ``p0``).

        Returns
        -------
        ArmaFilterConfig
            The checked configuration.
        """
        instance(model, ArimaStateSpace, "model")
        return cls(model.ar, model.ma, model.sigma2, d=model.d, noise_form=model.noise_form, **options)

    def to_dict(self) -> dict:
        """The fields as plain Python values.

        Returns
        -------
        dict
            Field name to value (lists for ``ar`` and ``ma``).
        """
        d = {f.name: getattr(self, f.name) for f in fields(self) if f.init}
        return {**d, "ar": list(self.ar), "ma": list(self.ma)}

    @classmethod
    def from_dict(cls, d: dict) -> "ArmaFilterConfig":
        """The configuration saved by :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            Field name to value.

        Returns
        -------
        ArmaFilterConfig
            The checked configuration.
        """
        return cls(**d)

    def to_json(self) -> str:
        """The configuration as JSON, to save beside the results.

        Returns
        -------
        str
            JSON object of :meth:`to_dict`.
        """
        return json.dumps(self.to_dict())

    @classmethod
    def from_json(cls, text: str) -> "ArmaFilterConfig":
        """The configuration saved by :meth:`to_json`.

        Parameters
        ----------
        text : str
            JSON object of the fields.

        Returns
        -------
        ArmaFilterConfig
            The checked configuration.

        Raises
        ------
        atomnav.InputError
            Naming ``text`` when it is not JSON.
        """
        try:
            d = json.loads(text)
        except json.JSONDecodeError as e:
            raise input_error("text", f"not JSON: {e}") from None
        return cls.from_dict(d)


@dataclass
class KalmanResult:
    """Result of a Kalman filter run on a rate series; the histories are empty when not
    recorded.

    Attributes
    ----------
    omega_hat : numpy.ndarray (N,)
        Filtered rate, unit of the input.
    r : numpy.ndarray (N,)
        Measurement variance used at each step, unit squared.
    gain : numpy.ndarray (N, n)
        Kalman gains.
    var : numpy.ndarray (N,)
        Posterior variance of ``omega_hat`` (the (0, 0) entry of P_k), unit squared: the
        filter's own uncertainty of the rate it estimates. Measured over 100 Monte-Carlo
        records of an ARMA(1,1) and an ARMA(2,1) rate in white noise (docs/consistency.md),
        the scatter of ω̂ − ω over √var is 0.997 with the true model and R (exact noise
        form), 1.04–1.08 in the paper's noise form, 1.006–1.009 with :func:`sage_husa`,
        and 0.75–0.84 (differenced) or 0.88–0.96 (literal) with the Eq. 17 adaptive R,
        which over-estimates R: conservative.
    """

    omega_hat: np.ndarray
    r: np.ndarray
    gain: np.ndarray
    var: np.ndarray


def _mode(adaptive) -> str:
    if adaptive is None or adaptive is False:
        return "fixed"
    if adaptive is True:
        return DEFAULT_READING
    return adaptive


def filter_series(omega, config: ArmaFilterConfig, *, record: bool = True) -> KalmanResult:
    """Kalman filter of the rate series ``omega`` as ``config`` describes (Niu et al.
    2025, Eq. 15); the R and gain histories only when ``record``.

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U (N ≥ 1).
    config : ArmaFilterConfig
        Model and filter settings.
    record : bool, default True
        Keep the R and gain histories.

    Returns
    -------
    KalmanResult
        Filtered rate and histories.
    """
    instance(config, ArmaFilterConfig, "config")
    w = vector(omega, None, "omega")
    if w.size == 0:
        raise input_error("omega", "empty series")
    return KalmanResult(*_core.kalman_filter(w, config._core, record=record))


def kalman(omega, model: ArimaStateSpace, r0: float | None = None, adaptive=None, x0: str = "zeros", p0: float = 1.0, record: bool = True) -> KalmanResult:
    """Kalman filter of the rate series ``omega`` on ``model`` (Niu et al. 2025, Eq. 15).

    ``adaptive``: None (fixed R ≡ r0), ``"differenced"`` (default reading of Eq. 17, also
    selected by ``True``) or ``"literal"``. ``r0`` defaults to model.sigma2 (the paper's
    R₀ = Q); ``x0="zeros"`` (paper) or ``"first"`` (start at ω₁); P₀ = p0·I.

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    model : ArimaStateSpace
        ARIMA model of the series.
    r0 : float, optional
        Measurement variance R₀, U² (default ``model.sigma2``).
    adaptive : None, bool or str, default None
        None/False (fixed), True or "differenced", or "literal".
    x0 : {"zeros", "first"}, default "zeros"
        Initial state.
    p0 : float, default 1.0
        Initial covariance P₀ = p0·I, U².
    record : bool, default True
        Keep the R and gain histories.

    Returns
    -------
    KalmanResult
        Filtered rate and histories.
    """
    cfg = ArmaFilterConfig.for_model(model, r0=r0, adaptive=_mode(adaptive), x0=x0, p0=p0)
    return filter_series(omega, cfg, record=record)


def sage_husa(omega, model: ArimaStateSpace, b: float = 0.98, *, adapt_q: bool = False, fading: bool = False, r0: float | None = None, x0: str = "zeros", p0: float = 1.0, record: bool = True) -> KalmanResult:
    """Sage–Husa adaptive filter (the standard form; Niu et al. 2025 give no equations for it):
    R̂_k = (1−d_k)R̂_{k−1} + d_k(ε_k² − HP⁻Hᵀ), d_k = (1−b)/(1−b^k); optional Q
    adaptation and strong-tracking fading factor (ρ = 0.95).

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    model : ArimaStateSpace
        ARIMA model of the series.
    b : float, default 0.98
        Forgetting factor.
    adapt_q : bool, default False
        Adapt Q as well.
    fading : bool, default False
        Apply the strong-tracking fading factor.
    r0 : float, optional
        Initial measurement variance R₀, U² (default ``model.sigma2``).
    x0 : {"zeros", "first"}, default "zeros"
        Initial state.
    p0 : float, default 1.0
        Initial covariance P₀ = p0·I, U².
    record : bool, default True
        Keep the R and gain histories.

    Returns
    -------
    KalmanResult
        Filtered rate and histories.

    References
    ----------
    A. P. Sage and G. W. Husa, "Adaptive filtering with unknown prior statistics",
    Proc. Joint Automatic Control Conference (1969).
    """
    cfg = ArmaFilterConfig.for_model(model, r0=r0, adaptive="sage_husa", b=b, adapt_q=adapt_q, fading=fading, x0=x0, p0=p0)
    return filter_series(omega, cfg, record=record)


def steady_state_gain(model: ArimaStateSpace, r: float):
    """Steady state of the fixed filter with measurement variance ``r``.

    Parameters
    ----------
    model : ArimaStateSpace
        ARIMA model.
    r : float
        Measurement variance, rate unit squared (> 0).

    Returns
    -------
    tuple
        (K∞ (n,), P⁻∞ (n, n), P⁺∞ (n, n)).
    """
    instance(model, ArimaStateSpace, "model")
    return _core.steady_state_gain(*model._args()[:3], r=positive(r, "r"), d=model.d, noise_form=model.noise_form)


class KalmanStream(Stateful):
    """Streaming form of :func:`kalman` / :func:`sage_husa`: ``update(chunk)`` returns the
    :class:`KalmanResult` of that chunk; the state carries over between chunks. One object
    may be shared by threads (calls run one after another) and pickled mid-stream.
    ``adaptive`` as in :class:`ArmaFilterConfig` (None or False: "fixed", True: the
    default reading of Eq. 17); :meth:`from_config` takes a saved configuration.

    Parameters
    ----------
    model : ArimaStateSpace
        ARIMA model of the series.
    adaptive : None, bool or str, default "fixed"
        As above.
    r0, b, adapt_q, fading, x0, p0
        As in :class:`ArmaFilterConfig`.
    record : bool, default True
        Keep the R and gain histories.
    """

    def __init__(self, model: ArimaStateSpace, adaptive="fixed", *, r0: float | None = None, b: float = 0.98, adapt_q: bool = False, fading: bool = False, x0: str = "zeros", p0: float = 1.0, record: bool = True):
        cfg = ArmaFilterConfig.for_model(model, r0=r0, adaptive=_mode(adaptive), b=b, adapt_q=adapt_q, fading=fading, x0=x0, p0=p0)
        self._f = _core.KalmanStream(cfg._core, record=record)
        self.config = cfg

    @classmethod
    def from_config(cls, config: ArmaFilterConfig, *, record: bool = True) -> "KalmanStream":
        """A stream of the filter a saved configuration describes.

        Parameters
        ----------
        config : ArmaFilterConfig
            Model and filter settings.
        record : bool, default True
            Keep the R and gain histories.

        Returns
        -------
        KalmanStream
            A stream at the start of the record.
        """
        instance(config, ArmaFilterConfig, "config")
        s = cls.__new__(cls)
        s._f, s.config = _core.KalmanStream(config._core, record=record), config
        return s

    @serialized
    def update(self, chunk) -> KalmanResult:
        """Filter the next samples; the state carries over from the previous chunk.

        Parameters
        ----------
        chunk : array_like (K,)
            Next rate samples, unit of the stream.

        Returns
        -------
        KalmanResult
            The result for this chunk.
        """
        return KalmanResult(*self._f.update(vector(chunk, None, "chunk")))
