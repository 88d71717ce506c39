"""Non-model baselines of Niu et al. 2025, §5.2, with the paper's settings."""

from __future__ import annotations

import numpy as np

from .._validate import choice, finite_result, flag, input_error, integer, positive, vector

#: Highest Butterworth order taken: beyond it the second-order sections' poles crowd the unit
#: circle and the filter is numerically meaningless for a record of this kind.
MAX_BUTTERWORTH_ORDER = 24


def butterworth_lowpass(omega, tau0: float, fc: float = 0.002, order: int = 2, zero_phase: bool = True) -> np.ndarray:
    """Butterworth low-pass at cutoff ``fc`` (Hz) of a series sampled every ``tau0`` s:
    ``butter(order, fc, fs=1/tau0, output='sos')`` with ``sosfiltfilt`` (zero phase, the
    default: |H|⁴, no lag) or causal ``sosfilt`` started at the first sample (docs/departures.md#low-pass-baseline).

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    tau0 : float
        Sampling interval, s.
    fc : float, default 0.002
        Cutoff frequency, Hz, below the Nyquist frequency 1/(2 tau0).
    order : int, default 2
        Butterworth order, 1 … ``MAX_BUTTERWORTH_ORDER``.
    zero_phase : bool, default True
        True for forward-backward ``sosfiltfilt``, False for causal ``sosfilt``.

    Returns
    -------
    numpy.ndarray (N,)
        Filtered series, unit U.

    Raises
    ------
    atomnav.InputError
        Naming ``tau0``, ``fc``, ``order`` or ``omega`` (too short for zero-phase
        filtering).
    """
    from scipy.signal import butter, sosfilt, sosfilt_zi, sosfiltfilt

    x = vector(omega, None, "omega")
    with np.errstate(over="ignore"):
        fs = float(finite_result(1.0 / np.float64(positive(tau0, "tau0")), "tau0", "the sample rate 1/τ₀"))
    fc = positive(fc, "fc")
    order, zero_phase = integer(order, "order", 1, MAX_BUTTERWORTH_ORDER), flag(zero_phase, "zero_phase")
    if fc >= fs / 2:
        raise input_error("fc", f"cutoff {fc} Hz must be below the Nyquist frequency {fs / 2} Hz")
    if not 2.0 * fc / fs > 0.0:
        raise input_error("fc", f"cutoff {fc} Hz is too small against the sample rate {fs} Hz (fc/fs underflows)")
    sos = butter(order, fc, fs=fs, output="sos")
    if zero_phase:
        need = 3 * (2 * sos.shape[0] + 1)
        if x.size <= need:
            raise input_error("omega", f"series of {x.size} samples is too short for zero-phase filtering (needs > {need})")
        return sosfiltfilt(sos, x)
    y, _ = sosfilt(sos, x, zi=sosfilt_zi(sos) * x[0])
    return y


def wavelet_denoise(omega, wavelet: str = "db4", level: int = 5, threshold: str = "universal", mode: str = "soft") -> np.ndarray:
    """Wavelet-threshold denoising (VisuShrink, docs/departures.md#wavelet-baseline): ``wavedec(ω, wavelet,
    level, mode='symmetric')``; σ̂ = median|cD₁|/0.6745; λ = σ̂√(2 ln N); ``mode``
    ("soft" or "hard") threshold on every detail level, approximation kept; inverse
    transform truncated to N.

    Parameters
    ----------
    omega : array_like (N,)
        Rate series, unit U.
    wavelet : str, default "db4"
        PyWavelets discrete wavelet name.
    level : int, default 5
        Decomposition levels (≥ 1, at most ``pywt.dwt_max_level`` for N).
    threshold : {"universal"}, default "universal"
        Threshold rule: the universal λ = σ̂√(2 ln N).
    mode : {"soft", "hard"}, default "soft"
        Thresholding of the detail coefficients.

    Returns
    -------
    numpy.ndarray (N,)
        Denoised series, unit U.

    Raises
    ------
    TypeError
        ``wavelet`` is not a str.
    atomnav.InputError
        Naming ``wavelet``, ``threshold``, ``mode``, ``level`` or ``omega`` (too short for
        ``level``).

    References
    ----------
    D. L. Donoho and I. M. Johnstone, "Ideal spatial adaptation by wavelet shrinkage",
    *Biometrika* 81 (1994).
    """
    import pywt

    x = vector(omega, None, "omega")
    if not isinstance(wavelet, str):
        raise TypeError(f"wavelet: expected a str (a PyWavelets name), got {type(wavelet).__name__}")
    choice(threshold, ("universal",), "threshold")
    choice(mode, ("soft", "hard"), "mode")
    if wavelet not in pywt.wavelist(kind="discrete"):
        raise input_error("wavelet", f"unknown discrete wavelet {wavelet!r}; see pywt.wavelist(kind='discrete')")
    level = integer(level, "level", 1)
    max_level = pywt.dwt_max_level(x.size, pywt.Wavelet(wavelet).dec_len)
    if level > max_level:
        raise input_error("omega", f"series of {x.size} samples is too short for a {level}-level {wavelet} decomposition (max {max_level})")
    coeffs = pywt.wavedec(x, wavelet, level=level, mode="symmetric")
    sigma = np.median(np.abs(coeffs[-1])) / 0.6745
    lam = sigma * np.sqrt(2.0 * np.log(x.size))
    out = [coeffs[0]] + [pywt.threshold(c, lam, mode=mode) for c in coeffs[1:]]
    return pywt.waverec(out, wavelet, mode="symmetric")[: x.size]
