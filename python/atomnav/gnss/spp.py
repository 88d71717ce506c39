"""Single-point positioning (Demidov 2009, §2.7; Rust ``gnss/spp.rs``): least squares for
position, receiver clock and τ_GPS per epoch, with an elevation mask, residual-based fault
detection and exclusion, the thesis's residual metric, the covariance of the estimate,
unweighted DOP and Doppler velocity; and the satellites of every epoch with their post-fit
residuals and weights, used or left out with the reason."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import _core
from .._validate import input_error, instance, renamed, table
from .ephemeris import Ephemerides
from .observations import obs_arrays
from .options import GnssOptions, split_options

#: Columns of :attr:`SppResult.epochs` (from the core).
SPP_COLUMNS = list(_core.SPP_COLUMNS)
#: Columns of :attr:`SppResult.satellites`.
SATELLITE_COLUMNS = ["time_s", "sat", "elevation_rad", "azimuth_rad", "residual_m", "sigma_m", "used", "excluded"]
#: The unknowns of :attr:`SppResult.covariance`, in order (from the core): ECEF position
#: ``x_m, y_m, z_m`` (m), receiver clock ``clock_m`` = c·δt_r (m), ``tau_gps_s`` (s).
COVARIANCE_STATES = tuple(_core.SPP_COVARIANCE_STATES)
#: Reasons a satellite is left out of an epoch's solution (from the core): ``no_code``
#: (NaN pseudorange: not tracked), ``no_ephemeris`` (no broadcast set valid then),
#: ``elevation`` (below ``elevation_mask``), ``fault`` (excluded by the residual test),
#: ``too_few_satellites`` (the epoch has fewer usable satellites than unknowns: no
#: solution), ``no_second_code`` (with ``ionosphere_free``: no second-frequency code).
EXCLUSIONS = tuple(_core.SPP_EXCLUSIONS)


@dataclass(frozen=True)
class SppResult:
    """Single-point positions and the satellites behind them (:func:`solve`).

    Attributes
    ----------
    epochs : DataFrame
        One row per solved epoch, columns :data:`SPP_COLUMNS`: ``time_s`` (s), ECEF
        (``x_m, y_m, z_m``, m) and geodetic (``lat_rad, lon_rad`` rad, ``h_m`` m) antenna
        position, ``clock_m`` = c·δt_r (m), τ_GPS and its σ (``tau_gps_s``,
        ``sigma_tau_gps_s``, s, NaN when not estimated), the residual metric
        Σ|r_i|/(N − n) (``residual_metric_m``, m), ``n_sats`` used, ``n_unknowns``,
        unweighted DOP of the satellites used (``gdop, pdop, hdop, vdop, tdop``: Q = (GᵀG)⁻¹
        with rows (−u_ENU, 1[, 1 on GLONASS rows when τ_GPS is estimated]), u the unit line
        of sight; GDOP² = PDOP² + TDOP²; Langley 1999), Doppler velocity (``vx_mps, vy_mps,
        vz_mps``, ECEF m/s; NaN with fewer than four used satellites with a Doppler) and
        c·δṫ_r (``clock_drift_mps``, m/s), ``n_excluded``, the weighted residual sum
        ``chi2`` (Σ r²/σ² over the used satellites), and the σ (m) of the position in ECEF
        (``sigma_x_m, sigma_y_m, sigma_z_m``) and local east, north, up (``sigma_e_m,
        sigma_n_m, sigma_u_m``) and of c·δt_r (``sigma_clock_m``), from :attr:`covariance`.
    satellites : DataFrame
        One row per satellite and epoch of the input, columns :data:`SATELLITE_COLUMNS`:
        elevation and azimuth (rad, from north through east) at the solution, post-fit
        residual (m; measured − predicted code at the solution), the code σ of its weight
        1/σ² (``sigma_m``, m: ``sigma_code``, or σ/sin E with ``elevation_weight``),
        ``used``, and ``excluded`` (one of :data:`EXCLUSIONS`, empty when used). Look
        angles, residual and σ are NaN where the satellite has no code or ephemeris, or the
        epoch no solution.
    covariance : ndarray, shape (n_epochs, 5, 5)
        Per row of ``epochs``, the least-squares covariance (HᵀWH)⁻¹ of the unknowns
        :data:`COVARIANCE_STATES` (x, y, z m, c·δt_r m, τ_GPS s; entries in m², m·s, s²),
        W = diag(1/σ²) of the used satellites; the τ_GPS row and column are NaN where τ_GPS
        is not estimated.
    """

    epochs: pd.DataFrame
    satellites: pd.DataFrame
    covariance: np.ndarray

    def exclusions(self) -> pd.Series:
        """Satellite-epochs left out, counted per reason.

        Returns
        -------
        Series
            Count per reason of :data:`EXCLUSIONS` (zeros included).
        """
        return self.satellites["excluded"].value_counts().reindex(list(EXCLUSIONS), fill_value=0)


def _second_code(obs: pd.DataFrame) -> np.ndarray:
    """The ``code2_m`` column (m; NaN where the second code was not tracked)."""
    code2 = np.ascontiguousarray(table(obs, ["code2_m"], "obs", finite=False)[:, 0])
    bad = np.flatnonzero(np.isinf(code2))
    if bad.size:
        raise input_error("obs", f"column 'code2_m': non-finite value {code2[bad[0]]} at index {bad[0]}", bad[0])
    return code2


def solve(eph: Ephemerides, obs: pd.DataFrame, options: GnssOptions | None = None, **option_fields) -> SppResult:
    """Single-point positioning: one least-squares solution per epoch of the observation
    table (Demidov 2009, §2.7).

    Each epoch starts from the previous solution; the signal's receive time is the stamp
    less the receiver clock estimate. A satellite without code (NaN), without a valid
    broadcast set, or below ``elevation_mask`` is left out; with ``fault_detection`` a
    satellite whose residuals fail the χ² test is excluded. An epoch with fewer usable
    satellites than unknowns has no row in ``epochs``; its satellites say why.

    Parameters
    ----------
    eph : Ephemerides
        Broadcast ephemerides.
    obs : pandas.DataFrame
        Observation table (``time_s`` GPS s, ``sat``, ``channel``, ``code_m`` m,
        ``rate_mps`` m/s, NaN where not tracked; see :func:`atomnav.gnss.simulate`), and
        ``code2_m`` (m, NaN where not tracked) with ``ionosphere_free``.
    options : GnssOptions, optional
        ``use_tau`` estimates τ_GPS, corrections ``iono``/``tropo``, weights 1/σ² with
        ``sigma_code`` (GLONASS ``sigma_code_glonass``), optionally σ/sin E
        (``elevation_weight``), ``elevation_mask``, ``fault_detection``,
        ``ionosphere_free``, Doppler velocity
        with ``sigma_rate`` (default ``GnssOptions()``).
    **option_fields
        Fields of :class:`GnssOptions` given as keywords (e.g. ``use_tau=False``),
        replacing those of ``options``.

    Returns
    -------
    SppResult
        ``epochs`` (one row per solved epoch, with σ and DOP), ``satellites`` (one row per
        input observation: post-fit residual, σ, used or why not) and ``covariance`` (one
        5 × 5 matrix per solved epoch).

    Raises
    ------
    TypeError
        For a keyword that is not a field of :class:`GnssOptions`.
    atomnav.InputError
        Naming ``obs`` for a malformed table, or when no satellite of an epoch has a
        broadcast set valid at its time (the ephemerides do not cover it).
    """
    instance(eph, Ephemerides, "eph")
    opts, rest = split_options(options, option_fields)
    if rest:
        raise TypeError(f"solve() got an unexpected keyword argument {sorted(rest)[0]!r}")
    code2 = _second_code(obs) if opts.ionosphere_free else None
    with renamed(t="obs"):  # an observation time outside the ephemerides' span is the table's
        epochs, sats, names, cov = _core.gnss_spp(eph._core, *obs_arrays(obs), opts.native, code2=code2)
    columns = dict(zip(_core.SPP_SATELLITE_COLUMNS, sats.T))
    code = columns.pop("excluded").astype(np.int64)
    reasons = np.array(("",) + EXCLUSIONS, dtype=object)[code]
    satellites = pd.DataFrame({"sat": names, **columns, "used": code == 0, "excluded": reasons})[SATELLITE_COLUMNS]
    k = len(COVARIANCE_STATES)
    return SppResult(pd.DataFrame(epochs, columns=SPP_COLUMNS), satellites, cov.reshape(-1, k, k))
