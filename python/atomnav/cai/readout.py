"""CAI readout and fringe handling (Tennstedt et al. 2021 Eqs. 8–10; docs/departures.md#one-readout-model):
population p = o − (C/2) cos(φ + φ0), offset o, contrast C ∈ (0, 1], laser phase φ0."""

from __future__ import annotations

import numpy as np

from .. import _core, plausibility
from .._validate import as_floats, finite, finite_scalar, generator, input_error, nonnegative


def _contrast(contrast) -> np.ndarray:
    c = as_floats(contrast, "contrast")
    bad = np.atleast_1d(~((c > 0) & (c <= 1)) | ~np.isfinite(c)).reshape(-1)
    if bad.any():
        i = int(np.argmax(bad))
        raise input_error("contrast", f"must be in (0, 1], got {np.atleast_1d(c).reshape(-1)[i]} at index {i}", i)
    return c


def readout(phi, phi0=0.0, *, offset=0.5, contrast=1.0, sigma_p: float = 0.0, sigma_phi: float = 0.0,
            sigma_contrast: float = 0.0, seed=None) -> np.ndarray:
    """Population p = o − (C/2) cos(φ + φ0 + n_φ) + n_p with C → C + n_C.

    Tennstedt et al. 2021, Eqs. 8–10. The noise σ's are per-shot standard deviations,
    drawn with ``seed``.

    Parameters
    ----------
    phi : float or array_like
        Interferometer phase φ (rad), any shape.
    phi0 : float or array_like
        Laser phase φ0 (rad), broadcast against ``phi``.
    offset : float
        Population offset o (0–1).
    contrast : float or array_like
        Contrast C ∈ (0, 1], broadcast against ``phi``.
    sigma_p : float
        Standard deviation of the additive population noise n_p (population units).
    sigma_phi : float
        Standard deviation of the phase noise n_φ (rad).
    sigma_contrast : float
        Standard deviation of the contrast noise n_C.
    seed : int, numpy.random.Generator or None
        Seed (an int ≥ 0) or generator of the noise draws; None draws fresh entropy.

    Returns
    -------
    float or numpy.ndarray
        Population p, with the broadcast shape of ``phi``, ``phi0`` and ``contrast``
        (a float for scalar inputs).
    """
    phi = as_floats(phi, "phi")
    finite(np.atleast_1d(phi).reshape(-1), "phi")
    phi0 = as_floats(phi0, "phi0")
    finite(np.atleast_1d(phi0).reshape(-1), "phi0")
    offset = plausibility.fraction(finite_scalar(offset, "offset"), "offset", "offset")
    c = _contrast(contrast)
    sigma_p, sigma_phi, sigma_contrast = (nonnegative(s, name) for name, s in (
        ("sigma_p", sigma_p), ("sigma_phi", sigma_phi), ("sigma_contrast", sigma_contrast)))
    rng = generator(seed, "seed")
    try:
        shape = np.broadcast(phi, phi0, c).shape
    except ValueError:
        raise input_error("phi0", f"shape {phi0.shape} does not broadcast with phi {phi.shape} and contrast {c.shape}") from None
    n_phi = rng.normal(0.0, sigma_phi, shape) if sigma_phi else 0.0
    n_c = rng.normal(0.0, sigma_contrast, shape) if sigma_contrast else 0.0
    n_p = rng.normal(0.0, sigma_p, shape) if sigma_p else 0.0
    total, c_eff = (np.ascontiguousarray(np.broadcast_to(x, shape), dtype=float).ravel() for x in (phi + phi0 + n_phi, c + n_c))
    p = _core.cai_readout(offset, c_eff, total).reshape(shape) + n_p
    return p[()] if np.ndim(p) == 0 else p


def steer_mid_fringe(phi_hat) -> np.ndarray:
    """Laser phase φ0 = (π/2 − φ̂) mod 2π putting the predicted phase at mid-fringe.

    Parameters
    ----------
    phi_hat : float or array_like
        Predicted phase φ̂ (rad), any shape.

    Returns
    -------
    float or numpy.ndarray
        Laser phase φ0 (rad) in [0, 2π), the shape of ``phi_hat``.
    """
    phi_hat = as_floats(phi_hat, "phi_hat")
    phi0 = _core.cai_steer_mid_fringe(np.ascontiguousarray(phi_hat).ravel()).reshape(phi_hat.shape)
    return phi0[()] if phi0.ndim == 0 else phi0


def invert_readout(p, phi0=0.0, *, offset=0.5, contrast=1.0, flank: str = "rising") -> np.ndarray:
    """Phase φ of a readout on a known flank of the fringe p = o − (C/2) cos(φ + φ0).

    Readouts beyond the fringe extremes are clipped to them.

    Parameters
    ----------
    p : float or array_like
        Measured population (0–1), any shape.
    phi0 : float or array_like
        Laser phase φ0 (rad), broadcast against ``p``.
    offset : float
        Population offset o (0–1).
    contrast : float or array_like
        Contrast C ∈ (0, 1], broadcast against ``p``.
    flank : {"rising", "falling"}
        "rising": φ + φ0 ∈ [0, π] (p grows with φ); "falling": φ + φ0 ∈ [−π, 0].

    Returns
    -------
    float or numpy.ndarray
        Phase φ (rad), the broadcast shape of ``p``, ``phi0`` and ``contrast``.
    """
    if not isinstance(flank, str) or flank not in ("rising", "falling"):
        raise input_error("flank", f"unknown option {flank!r}; choose 'falling', 'rising'")
    c = _contrast(contrast)
    p = as_floats(p, "p")
    finite(np.atleast_1d(p).reshape(-1), "p")
    plausibility.population(p, "p")
    phi0 = as_floats(phi0, "phi0")
    finite(np.atleast_1d(phi0).reshape(-1), "phi0")
    try:
        u = np.clip(2.0 * (plausibility.fraction(finite_scalar(offset, "offset"), "offset", "offset") - p) / c, -1.0, 1.0)
        psi = np.arccos(u)
        return (psi if flank == "rising" else -psi) - phi0
    except ValueError:
        raise input_error("contrast", f"shape {c.shape} does not broadcast with p {p.shape} and phi0 {phi0.shape}") from None


def fringes_crossed(phi) -> np.ndarray:
    """Number of whole fringes (2π) between zero phase and each predicted phase.

    Parameters
    ----------
    phi : float or array_like
        Predicted phase (rad), any shape.

    Returns
    -------
    int or numpy.ndarray of int64
        floor(|φ| / 2π), the shape of ``phi``.
    """
    phi = as_floats(phi, "phi")
    finite(np.atleast_1d(phi).reshape(-1), "phi")
    return np.floor(np.abs(phi) / (2 * np.pi)).astype(np.int64)


def capture_region(delta) -> np.ndarray:
    """Capture region of a true-minus-predicted phase Δ (Tennstedt et al. 2021, Fig. 3).

    Parameters
    ----------
    delta : float or array_like
        True minus predicted phase Δ (rad), any shape.

    Returns
    -------
    str or numpy.ndarray of str
        The shape of ``delta``: "A" where |Δ| < π/2 (correct update), "B" where
        π/2 ≤ |Δ| < π (right sign, too small), "slip" otherwise.
    """
    a = np.abs(as_floats(delta, "delta"))
    finite(np.atleast_1d(a).reshape(-1), "delta")
    return np.where(a < np.pi / 2, "A", np.where(a < np.pi, "B", "slip"))
