"""ARIMA state-space form and Kalman filters of seed 002 (spec E7–E11, D5–D12); the
numerical work runs in Rust.

Eq. 17 has two readings (spec E10, D7): ``"literal"`` takes y = ω (the raw rate);
``"differenced"`` takes y = d = ω_k − ω_{k−1}, the symbol's meaning everywhere else in
the paper. The default adaptive reading is ``"differenced"``: on model-B data only it
reproduces the paper's "adaptive better than fixed" (100/100 seeds, spec §4b.5); the
literal reading ties with the fixed filter, or loses to it with the paper's Q.
Sage–Husa is the standard form (spec E11) — the paper gives no equations for it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._validate import choice, finite, positive, vector

#: The default reading of Eq. 17 (spec D7, binding).
DEFAULT_READING = "differenced"
READINGS = ("differenced", "literal")
#: Seed 002 Eq. 10 (spec E5): φ₁, φ₂, β₁, σ_a² (°/h)².
PAPER_AR = (-0.018, 0.029)
PAPER_MA = (-0.99,)
PAPER_SIGMA2 = 0.035


@dataclass(frozen=True)
class ArimaStateSpace:
    """ARIMA(p,d,q) in state-space form X_k = Φ X_{k−1} + B W_{k−1}, Y_k = H X_k + V_k
    (seed 002 Eqs. 14, 16) with H = [1 0 … 0].

    ``ar`` = φ, ``ma`` = β (statsmodels' sign convention, spec E4), ``sigma2`` = σ_a² in
    the rate unit squared. ``noise_form="paper"``: the paper's B with Q = σ²I
    (default); ``"exact"``: X = [ω…, a_k…], G = e₀ + e_r, scalar Q = σ² (spec D5)."""

    ar: tuple
    ma: tuple
    sigma2: float
    d: int = 1
    noise_form: str = "paper"
    _m: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for name in ("ar", "ma"):
            v = np.asarray(getattr(self, name), dtype=float).reshape(-1)
            finite(v, name)
            object.__setattr__(self, name, tuple(float(c) for c in v))
        choice(self.noise_form, ("paper", "exact"), "noise_form")
        if int(self.d) != self.d or self.d < 0:
            raise ValueError(f"d: differencing order must be an integer ≥ 0, got {self.d}")
        object.__setattr__(self, "_m", _core.arima_state_space(list(self.ar), list(self.ma), positive(self.sigma2, "sigma2"), int(self.d), self.noise_form))

    @classmethod
    def from_arma(cls, ar, ma, sigma2: float, d: int = 1, noise_form: str = "paper") -> "ArimaStateSpace":
        return cls(tuple(ar), tuple(ma), float(sigma2), d, noise_form)

    @classmethod
    def paper(cls, noise_form: str = "paper") -> "ArimaStateSpace":
        """The paper's ARIMA(2,1,1): φ = (−0.018, 0.029), β₁ = −0.99, σ_a² = 0.035 (°/h)²."""
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


@dataclass
class KalmanResult:
    """Filtered rate ``omega_hat`` (N,), the measurement variance ``r`` used at each step
    (N,) and the gains ``gain`` (N, n); the histories are empty when not recorded."""

    omega_hat: np.ndarray
    r: np.ndarray
    gain: np.ndarray


def _mode(adaptive) -> str:
    if adaptive is None or adaptive is False:
        return "fixed"
    if adaptive is True:
        return DEFAULT_READING
    return choice(adaptive, READINGS, "adaptive")


def _check_x0(x0: str) -> str:
    return choice(x0, ("zeros", "first"), "x0")


def kalman(omega, model: ArimaStateSpace, r0: float | None = None, adaptive=None, x0: str = "zeros", p0: float = 1.0, record: bool = True) -> KalmanResult:
    """Kalman filter of the rate series ``omega`` on ``model`` (seed 002 Eq. 15).

    ``adaptive``: None (fixed R ≡ r0), ``"differenced"`` (default reading of Eq. 17, also
    selected by ``True``) or ``"literal"``. ``r0`` defaults to model.sigma2 (the paper's
    R₀ = Q); ``x0="zeros"`` (paper) or ``"first"`` (start at ω₁); P₀ = p0·I."""
    w = vector(omega, None, "omega")
    if w.size == 0:
        raise ValueError("omega: empty series")
    r0 = model.sigma2 if r0 is None else positive(r0, "r0")
    xh, r, g = _core.kalman_filter(w, *model._args(), r0=r0, mode=_mode(adaptive), x0=_check_x0(x0), p0=positive(p0, "p0"), record=record)
    return KalmanResult(xh, r, g)


def sage_husa(omega, model: ArimaStateSpace, b: float = 0.98, adapt_q: bool = False, fading: bool = False, r0: float | None = None, x0: str = "zeros", p0: float = 1.0, record: bool = True) -> KalmanResult:
    """Sage–Husa adaptive filter (standard form, spec E11/D12 — not from the paper):
    R̂_k = (1−d_k)R̂_{k−1} + d_k(ε_k² − HP⁻Hᵀ), d_k = (1−b)/(1−b^k); optional Q
    adaptation and strong-tracking fading factor (ρ = 0.95)."""
    w = vector(omega, None, "omega")
    if w.size == 0:
        raise ValueError("omega: empty series")
    r0 = model.sigma2 if r0 is None else positive(r0, "r0")
    xh, r, g = _core.kalman_filter(w, *model._args(), r0=r0, mode="sage_husa", b=float(b), adapt_q=adapt_q, fading=fading, x0=_check_x0(x0), p0=positive(p0, "p0"), record=record)
    return KalmanResult(xh, r, g)


def steady_state_gain(model: ArimaStateSpace, r: float):
    """Steady state of the fixed filter with measurement variance ``r``:
    (K∞ (n,), P⁻∞ (n, n), P⁺∞ (n, n))."""
    return _core.steady_state_gain(*model._args()[:3], r=positive(r, "r"), d=model.d, noise_form=model.noise_form)


class KalmanStream:
    """Streaming form of :func:`kalman` / :func:`sage_husa`: ``update(chunk)`` returns the
    :class:`KalmanResult` of that chunk; the state carries over between chunks.
    ``mode``: "fixed", "differenced", "literal" or "sage_husa"."""

    def __init__(self, model: ArimaStateSpace, mode: str = "fixed", r0: float | None = None, b: float = 0.98, adapt_q: bool = False, fading: bool = False, x0: str = "zeros", p0: float = 1.0, record: bool = True):
        mode = choice(mode, ("fixed", "sage_husa") + READINGS, "mode")
        r0 = model.sigma2 if r0 is None else positive(r0, "r0")
        self._f = _core.KalmanStream(*model._args(), r0=r0, mode=mode, b=float(b), adapt_q=adapt_q, fading=fading, x0=_check_x0(x0), p0=positive(p0, "p0"), record=record)

    def update(self, chunk) -> KalmanResult:
        return KalmanResult(*self._f.update(vector(chunk, None, "chunk")))
