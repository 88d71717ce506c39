"""Allan family, time deviation and time interval error, and the metrics of Niu et
al. 2025.

All functions are unit-agnostic: a rate series in some unit U sampled every ``tau0``
seconds gives variances in U², fit coefficients A_k in U²·s^k, ARW in U·√s, bias
instability in U, RRW in U/√s. :meth:`AllanFit.arw_in` converts with the factors of
:mod:`atomnav.units` (e.g. U = °/h → ARW in rad/√s or °/√h).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import _core, units
from ..imu import Flicker, TriadErrors
from .._stateful import Stateful, serialized
from .._validate import as_floats, finite_result, flag, input_error, instance, integer, positive, probability, renamed, scalar, table as read_table, vector

#: Option names, listed (and checked) by the Rust core.
KINDS = tuple(_core.OPTIONS["AllanKind"])
DATA_TYPES = tuple(_core.OPTIONS["DataType"])
TAU_SETS = tuple(_core.OPTIONS["TauGrid"])
NOISE_TYPES = tuple(_core.OPTIONS["NoiseType"])
#: Names of the five-term coefficients A₋₂ … A₂ (Niu et al. 2025 Eq. 19).
TERMS = ("quantization", "arw", "bias_instability", "rrw", "ramp")


def _series(x, name: str, min_len: int = 1, check_finite: bool = True) -> np.ndarray:
    """1-D float64 series of at least ``min_len`` samples; ``check_finite=False`` leaves
    the NaN/inf check (same message) to the Rust core, which does it in its first pass."""
    if check_finite:
        a = vector(x, None, name)
    else:
        a = np.ascontiguousarray(as_floats(x, name))
        if a.ndim != 1:
            raise input_error(name, f"expected shape (N,), got {a.shape}")
    if a.size < min_len:
        raise input_error(name, f"series of {a.size} samples is too short; at least {min_len} are needed")
    return a


def _m_list(m, taus, tau0: float):
    """Averaging factors from ``m`` (integers) or ``taus`` (seconds); None when ``m`` is
    the name of a set (which the core resolves)."""
    if taus is not None:
        t = vector(taus, None, "taus")
        mm = np.rint(t / tau0)
        bad = np.nonzero((mm < 1) | (np.abs(mm * tau0 - t) > 1e-9 * np.maximum(t, tau0)))[0]
        if bad.size:
            raise input_error("taus", f"τ = {t[bad[0]]} s at index {bad[0]} is not a positive multiple of tau0 = {tau0} s", bad[0])
        return [int(v) for v in mm]
    # a set name or a sequence of integers, both checked by the core (which names the index)
    return None if isinstance(m, str) else m


def _table(m, tau, var, n, missing: int, kind: str, n_phase: int, noise: str, confidence: float) -> pd.DataFrame:
    from scipy.stats import chi2

    edf = _core.allan_edf(kind, noise, n_phase, m.tolist())
    alpha = 1.0 - confidence
    lo = var * edf / chi2.ppf(1.0 - alpha / 2.0, edf)
    hi = var * edf / chi2.ppf(alpha / 2.0, edf)
    table = pd.DataFrame({"m": m, "tau_s": tau, "var": var, "dev": np.sqrt(var), "n_terms": n, "edf": edf, "dev_lo": np.sqrt(lo), "dev_hi": np.sqrt(hi)})
    table.attrs["n_missing"] = int(missing)
    return table


def allan_variance(data, tau0: float, m="octave", kind: str = "allan", data_type: str = "rate", taus=None, noise: str = "white_fm", confidence: float = 0.683) -> pd.DataFrame:
    """Allan-family variance of a rate series (or of a phase/angle series) sampled every
    ``tau0`` s.

    Parameters
    ----------
    data : array_like (N,)
        Rate samples in some unit U (e.g. rad/s, °/h), or with ``data_type="phase"`` their
        integral (e.g. angle, rad). NaN marks a missing rate sample (see Notes).
    tau0 : float
        Sampling interval, s.
    m : str or sequence of int, default "octave"
        Averaging factors: "octave" (1, 2, 4, …), "decade" (1, 2, 4, 10, 20, 40, …),
        "all", or a list of integers. Factors that leave fewer than two terms are dropped
        from the named sets and rejected (with :class:`atomnav.InputError` naming ``m``
        and the index) in a user list.
    kind : {"allan", "modified", "hadamard"}, default "allan"
        Overlapping Allan, modified Allan or overlapping Hadamard variance.
    data_type : {"rate", "phase"}, default "rate"
        "phase": ``data`` are the integral of the rate (e.g. angle in rad), the variance
        is then of the rate ((rad/s)²).
    taus : array_like (K,), optional
        Averaging times, s, positive multiples of ``tau0``; given, they replace ``m``.
    noise : str, default "white_fm"
        Power-law noise type assumed by the equivalent degrees of freedom, one of
        :data:`NOISE_TYPES` ("white_pm", "flicker_pm", "white_fm", "flicker_fm",
        "random_walk_fm": α = 2 … −2 of S_y(f) ∝ f^α).
    confidence : float, default 0.683
        Probability of the χ² confidence interval, in (0, 1).

    Returns
    -------
    pandas.DataFrame
        One row per averaging factor. Columns: ``m``, ``tau_s`` (s), ``var`` (U²),
        ``dev`` (U), ``n_terms``, ``edf`` (equivalent degrees of freedom for the given
        ``noise`` type, dimensionless: Howe's approximations for the overlapping Allan
        variance (NIST SP 1065 Table 12); for the modified Allan and Hadamard variances
        the exact EDF of the sampled estimator for white PM, white FM and random-walk FM
        at (d+1)m ≤ 100 (d = 2 modified, 3 Hadamard) and Greenhall & Riley 2003
        otherwise, see Notes; with gaps, that of a gap-free record of the same number of
        samples), and the χ² confidence
        interval ``dev_lo``, ``dev_hi`` (U) at ``confidence``. ``table.attrs["n_missing"]``
        counts the NaN samples.

    Raises
    ------
    atomnav.InputError
        Naming ``tau0``, ``confidence``, ``data`` (NaN in phase data, ±inf anywhere),
        ``m`` or ``taus``.

    Notes
    -----
    **Gaps.** A NaN rate sample is missing (a gap is marked, not filled: Riley, NIST
    SP 1065, "Gaps, jumps, and outliers"). Every term of the sum whose rate samples
    include a NaN is left out and the variance is the mean of the others, the rule of
    allantools' gap-resistant ``gradev``: a term spans 2m rate samples for the Allan,
    3m − 1 for the modified and 3m for the Hadamard variance, so the result is the terms
    of each gap-free stretch pooled. Leading and trailing NaN are trimmed, as allantools
    does (for a record without interior NaN the result equals allantools' ``oadev``,
    ``mdev`` and ``ohdev``; with interior NaN those return NaN). ``n_terms`` counts the
    terms used, and ``table.attrs["n_missing"]`` the NaN samples. NaN in phase data, and
    ±inf anywhere, raise :class:`atomnav.InputError`. A constant series (a stuck or
    quantised sensor) has variance 0 at every τ.

    **Confidence interval.** ``var·edf/χ²`` quantiles at ``confidence``. The EDF of the
    modified Allan and Hadamard variances is 2E[V]²/Var[V] of the estimator V: summed
    exactly over the correlation of its overlapping terms (Greenhall & Riley 2003 Eq. 10
    with the autocovariance of the samples) where the differenced noise has finite memory
    and m is small, Greenhall & Riley's algorithm (as Stable32 and allantools'
    ``edf_greenhall``) otherwise. Over 2000 records of 4096 samples of white and
    random-walk rate noise the 68.3 % interval covers the true variance in 0.67–0.70 of
    records at m = 1 … 16 for every kind (docs/departures.md, "Allan EDF").

    References
    ----------
    IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure for
    Single-Axis Interferometric Fiber Optic Gyros*, Annex C. IEEE Std 1139-2008,
    *Standard Definitions of Physical Quantities for Fundamental Frequency and Time
    Metrology*. W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065
    (2008). C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on
    finite differences", Proc. 35th PTTI Meeting (2003). D. A. Howe, D. W. Allan and
    J. A. Barnes, "Properties of signal sources and measurement methods", Proc. 35th
    Frequency Control Symposium (1981) (the Allan EDF of NIST SP 1065 Table 12).
    """
    tau0 = positive(tau0, "tau0")
    confidence = probability(confidence, "confidence")
    x = _series(data, "data", check_finite=False)
    ms = _m_list(m, taus, tau0)
    mm, tau, var, n, missing = _core.allan_var(x, tau0, data_type, kind, **({"set": m} if ms is None else {"m": ms}))
    return _table(mm, tau, var, n, missing, kind, _phase_points(x.size - missing, data_type), noise, confidence)


def time_deviation(data, tau0: float, m="octave", data_type: str = "phase", taus=None, noise: str = "white_pm", confidence: float = 0.683) -> pd.DataFrame:
    """Time deviation TDEV σ_x(τ) = τ/√3 · MDEV(τ) of a phase (time-error) series or of a
    rate series sampled every ``tau0`` s (NIST SP 1065 §5.2.6).

    Parameters
    ----------
    data : array_like (N,)
        Phase (time error) in some unit X (e.g. s, rad), or with ``data_type="rate"`` a
        rate in some unit U (e.g. fractional frequency); NaN marks a missing rate sample,
        as in :func:`allan_variance`.
    tau0 : float
        Sampling interval, s.
    m : str or sequence of int, default "octave"
        Averaging factors, as in :func:`allan_variance` (those of the modified Allan
        variance: at least two terms, 3m − 1 ≤ N − 2 for phase data).
    data_type : {"phase", "rate"}, default "phase"
        Whether ``data`` is the phase or its rate.
    taus : array_like (K,), optional
        Averaging times, s, positive multiples of ``tau0``; given, they replace ``m``.
    noise : str, default "white_pm"
        Noise type for the equivalent degrees of freedom, as in :func:`allan_variance`.
    confidence : float, default 0.683
        Probability of the χ² confidence interval, in (0, 1).

    Returns
    -------
    pandas.DataFrame
        The table of :func:`allan_variance` with ``kind="modified"`` scaled by τ²/3:
        columns ``m``, ``tau_s`` (s), ``var`` (time variance, X² for phase data, (U·s)²
        for rate data), ``dev`` (TDEV, X or U·s), ``n_terms``, ``edf`` (that of the
        modified Allan variance, which the scaling does not change), ``dev_lo``,
        ``dev_hi`` (X or U·s).

    Raises
    ------
    atomnav.InputError
        Naming ``tau0``, ``confidence``, ``data``, ``m`` or ``taus``.

    References
    ----------
    W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065 (2008), §5.2.6.
    D. W. Allan, M. A. Weiss and J. L. Jespersen, "A frequency-domain view of time-domain
    characterization of clocks and time and frequency distribution systems", Proc. 45th
    Frequency Control Symposium (1991).

    Examples
    --------
    >>> x = np.cumsum(np.random.default_rng(1).normal(size=1000)) * 1e-9  # phase, s
    >>> time_deviation(x, tau0=1.0)[["tau_s", "dev"]]
    """
    tau0 = positive(tau0, "tau0")
    confidence = probability(confidence, "confidence")
    x = _series(data, "data", check_finite=False)
    ms = _m_list(m, taus, tau0)
    mm, tau, var, n, missing = _core.time_var(x, tau0, data_type, **({"set": m} if ms is None else {"m": ms}))
    return _table(mm, tau, var, n, missing, "modified", _phase_points(x.size - missing, data_type), noise, confidence)


def time_interval_error(phase, tau0: float, m="octave", taus=None) -> pd.DataFrame:
    """Maximum and rms time interval error (MTIE, TIE rms) of a phase (time-error) series
    sampled every ``tau0`` s.

    MTIE(mτ₀) is the largest peak-to-peak phase excursion over any m + 1 consecutive
    samples (ITU-T G.810 Appendix II; NIST SP 1065 §5.2.14); TIE rms(mτ₀) is
    √(mean of (x_{i+m} − x_i)²) over the N − m differences (NIST SP 1065 §5.2.15).
    Phase data only: a rate (fractional frequency) y is integrated first,
    ``x = tau0 * np.concatenate([[0.0], np.cumsum(y)])``; its mean is part of the time
    error and must not be removed.

    Parameters
    ----------
    phase : array_like (N,)
        Phase (time error) samples in some unit X (e.g. s, ns, rad), finite, N ≥ 3.
    tau0 : float
        Sampling interval, s.
    m : str or sequence of int, default "octave"
        Averaging factors (τ = mτ₀): "octave", "decade", "all" as in
        :func:`allan_variance`, or a list of integers; each must leave at least two windows
        (m ≤ N − 2): the named sets stop there, a larger listed factor raises
        :class:`atomnav.InputError` naming ``m`` and its index.
    taus : array_like (K,), optional
        Averaging times, s, positive multiples of ``tau0``; given, they replace ``m``.

    Returns
    -------
    pandas.DataFrame
        One row per factor. Columns ``m``, ``tau_s`` (s), ``mtie`` and ``tie_rms`` (both in
        the unit X of ``phase``), ``n_windows`` (N − m).

    Raises
    ------
    atomnav.InputError
        Naming ``phase`` (NaN, ±inf, fewer than 3 samples), ``tau0``, ``m`` or ``taus``.

    Notes
    -----
    MTIE is computed by one pass per τ with monotonic deques of the window's candidate
    maxima and minima, O(N) per τ rather than O(N·m).

    References
    ----------
    ITU-T Recommendation G.810, *Definitions and terminology for synchronization
    networks* (1996). W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065
    (2008), §5.2.14–5.2.15.

    Examples
    --------
    >>> x = np.cumsum(np.random.default_rng(1).normal(size=1000)) * 1e-9  # phase, s
    >>> time_interval_error(x, tau0=1.0)[["tau_s", "mtie", "tie_rms"]]
    """
    tau0 = positive(tau0, "tau0")
    x = _series(phase, "phase", check_finite=False)
    ms = _m_list(m, taus, tau0)
    with renamed(data="phase"):
        mm, tau, mtie, tie, n = _core.time_interval_error(x, tau0, **({"set": m} if ms is None else {"m": ms}))
    return pd.DataFrame({"m": mm, "tau_s": tau, "mtie": mtie, "tie_rms": tie, "n_windows": n})


def _phase_points(samples: int, data_type: str) -> int:
    """Phase points of a gap-free record of ``samples`` samples (rate: one more)."""
    return samples + 1 if data_type == "rate" else samples


class AllanStream(Stateful):
    """Streaming Allan, modified Allan and Hadamard variance at fixed averaging factors,
    for records that do not fit in memory (memory: 3·max(m)+1 samples).

    The stream gives what :func:`allan_variance` gives for the samples fed so far, NaN
    rate samples (gaps) included; :meth:`result` raises :class:`atomnav.InputError`
    naming ``m`` while a factor has fewer than two terms, as the batch does. One object
    may be shared by threads (calls run one after another) and pickled mid-record.

    Parameters
    ----------
    m : sequence of int
        Averaging factors (explicit integers: a set name is rejected, the record length
        being unknown).
    tau0 : float
        Sampling interval, s.
    data_type : {"rate", "phase"}, default "rate"
        As in :func:`allan_variance`.
    noise : str, default "white_fm"
        Noise type for the equivalent degrees of freedom, as in :func:`allan_variance`.
    confidence : float, default 0.683
        Probability of the χ² confidence interval, in (0, 1).

    Raises
    ------
    atomnav.InputError
        Naming ``m``, ``tau0`` or ``confidence``.

    See Also
    --------
    allan_variance : the batch computation.

    References
    ----------
    W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065 (2008).

    Examples
    --------
    >>> s = AllanStream([1, 2, 4], tau0=1.0)
    >>> for chunk in chunks: s.update(chunk)
    >>> s.result("allan")
    """

    def __init__(self, m, tau0: float, data_type: str = "rate", noise: str = "white_fm", confidence: float = 0.683):
        self.tau0 = positive(tau0, "tau0")
        self.data_type = data_type
        self.noise = noise
        self.confidence = probability(confidence, "confidence")
        ms = _m_list(m, None, self.tau0)
        if ms is None:
            raise input_error("m", "give explicit averaging factors for a stream (the record length is unknown)")
        self._s = _core.AllanStream(ms, self.tau0, self.data_type)
        self.n_samples = 0

    @serialized
    def update(self, chunk) -> None:
        """Add the next samples.

        Parameters
        ----------
        chunk : array_like (K,)
            Next samples, in the units of the stream (rate U, or phase with
            ``data_type="phase"``); NaN marks a missing rate sample.
        """
        c = _series(chunk, "chunk", check_finite=False)
        self._s.update(c)
        self.n_samples += c.size

    @serialized
    def result(self, kind: str = "allan") -> pd.DataFrame:
        """The table of :func:`allan_variance` for the samples seen so far.

        Parameters
        ----------
        kind : {"allan", "modified", "hadamard"}, default "allan"
            Which variance, as in :func:`allan_variance`.

        Returns
        -------
        pandas.DataFrame
            The table of :func:`allan_variance` (columns ``m``, ``tau_s``, ``var``,
            ``dev``, ``n_terms``, ``edf``, ``dev_lo``, ``dev_hi``).

        Raises
        ------
        atomnav.InputError
            Naming ``m`` and the samples it needs while a factor has fewer than two terms.
        """
        mm, tau, var, n, missing = self._s.result(kind)
        return _table(mm, tau, var, n, missing, kind, _phase_points(self.n_samples - missing, self.data_type), self.noise, self.confidence)


@dataclass(kw_only=True)
class AllanFit:
    """Five-term fit σ²(τ) = Σ_{k=−2}^{2} A_k τ^k (Niu et al. 2025 Eq. 19, IEEE Std 952).

    Returned by :func:`fit_allan` and :func:`fit_allan_table`; rate unit U, τ in s.

    Attributes
    ----------
    coeffs : numpy.ndarray (5,)
        A₋₂ … A₂, in U²·s^k.
    quantization : float
        Q_q = √(A₋₂/3), U·s.
    arw : float
        Angle random walk N = √A₋₁, U·√s: the paper's SS (Eq. 20).
    bias_instability : float
        B = √(πA₀/(2 ln 2)), U: the paper's LS (Eq. 21).
    rrw : float
        Rate random walk K = √(3A₁), U/√s.
    ramp : float
        Rate ramp R = √(2A₂), U/s.
    points : int
        Number of Allan points used by the fit.
    tau_min, tau_max : float
        τ range of the fit, s (0 and inf when not limited).
    table : pandas.DataFrame
        The :func:`allan_variance` table that was fitted.

    References
    ----------
    IEEE Std 952-1997, Annex C. X. Niu et al. 2025, Eqs. 19–21.
    """

    coeffs: np.ndarray
    quantization: float
    arw: float
    bias_instability: float
    rrw: float
    ramp: float
    points: int
    tau_min: float
    tau_max: float
    table: pd.DataFrame = field(repr=False)

    def curve(self, tau) -> np.ndarray:
        """Fitted Allan variance at ``tau``.

        Parameters
        ----------
        tau : float or array_like
            Averaging time(s), s.

        Returns
        -------
        float or numpy.ndarray
            Σ A_k τ^k, U², in the shape of ``tau``.
        """
        t = as_floats(tau, "tau")
        return sum(self.coeffs[k] * t ** (k - 2) for k in range(5))

    def arw_in(self, rate_unit: float, arw_unit: float) -> float:
        """ARW converted to another unit.

        Parameters
        ----------
        rate_unit : float
            SI factor of the data's unit (e.g. ``units.DEG_PER_HOUR``).
        arw_unit : float
            SI factor of the wanted unit (e.g. ``units.DEG_PER_SQRT_HOUR``, or 1.0 for
            rad/√s).

        Returns
        -------
        float
            ``arw · rate_unit / arw_unit``, in the wanted unit.
        """
        return self.arw * rate_unit / arw_unit

    def to_triad(self, rate_unit: float = 1.0, *, f_lo: float | None = None, f_hi: float | None = None) -> TriadErrors:
        """The fitted noise as the error model of one triad, for :class:`atomnav.imu.ImuErrors`
        and :class:`atomnav.imu.ImuSimulator`.

        Parameters
        ----------
        rate_unit : float
            SI factor of the fitted data's unit (``units.DEG_PER_HOUR`` for a gyro log in
            °/h, ``units.MICRO_G`` for an accelerometer log in µg; 1.0 for rad/s or m/s²).
        f_lo, f_hi : float, optional
            Band (Hz) of the flicker term that gives the bias-instability floor. Defaults:
            ``f_lo`` = 1/(10 τ_max), a decade below the longest τ of the table, so the floor
            holds over every fitted τ; ``f_hi`` = 1/(2τ₀), the Nyquist frequency of the log
            (τ₀ its sampling interval; a simulator with a longer interval needs a lower ``f_hi``).

        Returns
        -------
        TriadErrors
            The same ARW, bias instability and RRW in SI (IEEE Std 952-1997, Annex C):
            ``white`` N (rad/√s or m/s/√s), ``flicker`` of bias instability B (rad/s or
            m/s²), ``bias_rw`` K (rad/s/√s or m/s²/√s); no fixed bias, scale factor or
            misalignment. A fit with a quantization or ramp term, which the IMU error model
            does not have, is an :class:`atomnav.InputError` naming ``terms`` (fit with
            ``terms=("arw", "bias_instability", "rrw")``).
        """
        extra = [t for t in ("quantization", "ramp") if getattr(self, t) > 0]
        if extra:
            raise input_error("terms", f"the fit has a {extra[0]} term, which the IMU error model lacks; "
                                       "fit with terms=('arw', 'bias_instability', 'rrw')")
        unit = positive(rate_unit, "rate_unit")
        m, tau = read_table(self.table, ["m", "tau_s"], "table").T
        f_lo = float(0.1 / tau.max()) if f_lo is None else positive(f_lo, "f_lo")
        f_hi = float(0.5 * m[0] / tau[0]) if f_hi is None else positive(f_hi, "f_hi")
        flicker = Flicker(self.bias_instability * unit, f_lo, f_hi) if self.bias_instability > 0 else None
        return TriadErrors(white=self.arw * unit, bias_rw=self.rrw * unit, flicker=flicker)


def fit_allan_table(table: pd.DataFrame, n_samples: int, terms=TERMS, tau_min: float | None = None, tau_max: float | None = None) -> AllanFit:
    """Five-term fit to an :func:`allan_variance` table (overlapping Allan).

    Weighted NNLS with weights 1/σ_j², σ_j = AVAR_j/√max(1, ⌊N/m_j⌋ − 1); only the
    named ``terms`` are free, only points with tau_min ≤ τ ≤ tau_max (s) and positive
    variance are used (docs/departures.md#allan-fit).

    Parameters
    ----------
    table : pandas.DataFrame
        An :func:`allan_variance` table; columns ``m`` (integers ≥ 1), ``tau_s`` (s) and
        ``var`` (U²) are read.
    n_samples : int
        Number N of samples of the series the table was computed from (≥ 1).
    terms : sequence of str, default TERMS
        Free terms, from ("quantization", "arw", "bias_instability", "rrw", "ramp").
    tau_min, tau_max : float, optional
        τ range of the points used, s (default: all).

    Returns
    -------
    AllanFit
        The coefficients and the derived noise parameters.

    Raises
    ------
    atomnav.InputError
        Naming ``table``, ``n_samples``, ``terms``, ``tau_min`` or ``tau_max``.

    References
    ----------
    IEEE Std 952-1997, Annex C. X. Niu et al. 2025, Eq. 19.
    """
    m, tau, var = read_table(table, ["m", "tau_s", "var"], "table").T  # an allan_variance table, by name
    bad = np.flatnonzero(~(m >= 1) | (m != np.round(m)))
    if bad.size:
        raise input_error("table", f"column 'm': averaging factor {m[bad[0]]} at index {bad[0]} is not an integer >= 1", bad[0])
    n_samples = integer(n_samples, "n_samples", 1)
    bad = [t for t in terms if t not in TERMS]
    if bad:
        raise input_error("terms", f"unknown term {bad[0]!r}; choose from {TERMS}")
    mask = [t in terms for t in TERMS]
    lo = 0.0 if tau_min is None else scalar(tau_min, "tau_min")
    hi = np.inf if tau_max is None else scalar(tau_max, "tau_max")
    d = _core.allan_fit(m.astype(np.uint64).tolist(), np.ascontiguousarray(tau), np.ascontiguousarray(var), n_samples, mask, lo, hi)
    return AllanFit(coeffs=np.asarray(d["coeffs"]), quantization=d["quantization"], arw=d["arw"], bias_instability=d["bias_instability"],
                    rrw=d["rrw"], ramp=d["ramp"], points=d["points"], tau_min=lo, tau_max=hi, table=table)


def fit_allan(omega, tau0: float, terms=TERMS, tau_min: float | None = None, tau_max: float | None = None, m="octave") -> AllanFit:
    """Overlapping Allan variance of the rate series ``omega`` at ``m`` (default octave τ)
    and its five-term fit (:func:`fit_allan_table`).

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    tau0 : float
        Sampling interval, s.
    terms : sequence of str, default TERMS
        Free terms of the fit, as in :func:`fit_allan_table`.
    tau_min, tau_max : float, optional
        τ range of the fit, s (default: all points).
    m : str or sequence of int, default "octave"
        Averaging factors, as in :func:`allan_variance`.

    Returns
    -------
    AllanFit
        The five-term fit, with its Allan table.
    """
    x = _series(omega, "omega")
    # too few Allan points in the τ range is a record too short unless the range was given
    with renamed(data="omega", **{"tau_min/tau_max": "omega" if tau_min is None and tau_max is None else "tau_min"}):
        return fit_allan_table(allan_variance(x, tau0, m=m), x.size, terms, tau_min, tau_max)


def short_term_sensitivity(omega, tau0: float, **fit_kw) -> float:
    """Short-term sensitivity SS = √A₋₁ (Niu et al. 2025 Eq. 20).

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    tau0 : float
        Sampling interval, s.
    **fit_kw
        Passed to :func:`fit_allan` (``terms``, ``tau_min``, ``tau_max``, ``m``).

    Returns
    -------
    float
        SS in U·√s; divide by 60 for °/√h when U = °/h and τ in s (or use
        :meth:`AllanFit.arw_in`).
    """
    return fit_allan(omega, tau0, **fit_kw).arw


def long_term_stability(omega, tau0: float, **fit_kw) -> float:
    """Long-term stability LS = √(π A₀ / (2 ln 2)) (Niu et al. 2025 Eq. 21).

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    tau0 : float
        Sampling interval, s.
    **fit_kw
        Passed to :func:`fit_allan` (``terms``, ``tau_min``, ``tau_max``, ``m``).

    Returns
    -------
    float
        LS (the bias instability B), in the rate unit U.
    """
    return fit_allan(omega, tau0, **fit_kw).bias_instability


def ss_deg_per_sqrt_hour(fit: AllanFit) -> float:
    """SS of a fit to a rate in °/h with τ in s, in °/√h (Niu et al. 2025 Eq. 20: √A₋₁/60).

    Parameters
    ----------
    fit : AllanFit
        Fit to a rate series in °/h sampled with τ in s.

    Returns
    -------
    float
        Short-term sensitivity, °/√h.
    """
    instance(fit, AllanFit, "fit")
    return fit.arw_in(units.DEG_PER_HOUR, units.DEG_PER_SQRT_HOUR)


def bias(omega) -> float:
    """Bias: the mean of the series.

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.

    Returns
    -------
    float
        Mean, in the rate unit U.
    """
    return float(np.mean(_series(omega, "omega")))


def bias_stability(omega, window: int = 1) -> float:
    """Bias stability (Niu et al. 2025): standard deviation (ddof = 1) of the ⌊N/w⌋
    non-overlapping means of ``window`` samples (incomplete tail dropped), in the rate
    unit. The paper does not state its window; the default ``window = 1`` averages nothing.
    Report ``window`` with the value.

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U; at least 2·``window`` samples.
    window : int, default 1
        Samples per averaging window (≥ 1).

    Returns
    -------
    float
        Standard deviation of the window means, in the rate unit U.
    """
    w = integer(window, "window", 1)
    x = _series(omega, "omega", min_len=2 * w)
    k = x.size // w
    used = x[: k * w]
    scale = np.max(np.abs(used))  # sums and squares of rates beyond 1.3e154 overflow: scale to |x| ≤ 1 first
    if scale == 0:
        return 0.0
    with np.errstate(over="ignore"):
        sigma = np.std((used / scale).reshape(k, w).mean(axis=1), ddof=1) * scale
    return float(finite_result(sigma, "omega", "the standard deviation of the window means"))


def improvement_ratio(before, after, absolute: bool = False):
    """Improvement ratio in percent (Niu et al. 2025 Eq. 18): (M_raw − M_filt)/M_raw·100, signed
    by default (docs/departures.md#signed-improvement-ratio: negative means the filter made the metric worse);
    ``absolute=True`` gives the paper's |M_raw − M_filt|/M_raw·100.

    Parameters
    ----------
    before : float or array_like
        Metric of the raw series, M_raw (non-zero).
    after : float or array_like
        Metric of the filtered series, M_filt, in the unit and shape of ``before`` (or a
        scalar).
    absolute : bool, default False
        True for the paper's absolute value.

    Returns
    -------
    float or numpy.ndarray
        Improvement ratio, %, in the broadcast shape of ``before`` and ``after``.

    Raises
    ------
    atomnav.InputError
        Naming ``before`` (a zero metric) or ``after`` (a shape mismatch).
    """
    b = as_floats(before, "before")
    a = as_floats(after, "after")
    absolute = flag(absolute, "absolute")
    if a.shape != b.shape and a.size != 1 and b.size != 1:
        raise input_error("after", f"expected the shape of before {b.shape}, got {a.shape}")
    if np.any(b == 0):
        raise input_error("before", "metric is zero, the ratio is undefined")
    with np.errstate(over="ignore", invalid="ignore"):
        r = (b - a) / b * 100.0
    if np.isfinite(a).all() and np.isfinite(b).all():  # NaN in, NaN out; finite in, finite out
        finite_result(r, "after", "the ratio (M_raw − M_filt)/M_raw")
    return np.abs(r) if absolute else r
