"""Single-point positioning (Demidov 2009, §2.7; Rust ``gnss/spp.rs``): least squares for
position, receiver clock and τ_GPS per epoch, the thesis's residual metric, DOP, Doppler
velocity."""

from __future__ import annotations

import pandas as pd

from .. import _core
from .._validate import instance, renamed
from .ephemeris import Ephemerides
from .observations import obs_arrays
from .options import GnssOptions, split_options

#: Columns of :func:`solve` (from the core).
SPP_COLUMNS = list(_core.SPP_COLUMNS)


def solve(eph: Ephemerides, obs: pd.DataFrame, options: GnssOptions | None = None, **option_fields) -> pd.DataFrame:
    """Single-point positioning: one least-squares solution per epoch of the observation
    table (Demidov 2009, §2.7).

    Parameters
    ----------
    eph : Ephemerides
        Broadcast ephemerides.
    obs : pandas.DataFrame
        Observation table (``time_s`` GPS s, ``sat``, ``channel``, ``code_m`` m,
        ``rate_mps`` m/s; see :func:`atomnav.gnss.simulate`).
    options : GnssOptions, optional
        ``use_tau`` estimates τ_GPS, corrections ``iono``/``tropo``, weights 1/σ² with
        ``sigma_code`` (GLONASS ``sigma_code_glonass``), optionally σ/sin E
        (``elevation_weight``), Doppler velocity with ``sigma_rate`` (default
        ``GnssOptions()``).
    **option_fields
        Fields of :class:`GnssOptions` given as keywords (e.g. ``use_tau=False``),
        replacing those of ``options``.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`SPP_COLUMNS`: ``time_s`` (s), ECEF (``x_m, y_m, z_m``, m) and
        geodetic (``lat_rad, lon_rad`` rad, ``h_m`` m) antenna position, ``clock_m`` =
        c·δt_r (m), τ_GPS and its σ (``tau_gps_s``, ``sigma_tau_gps_s``, s, NaN when not
        estimated), the residual metric Σ|r_i|/(N − n) (``residual_metric_m``, m),
        ``n_sats``, ``n_unknowns``, DOP values, Doppler velocity (``vx_mps, vy_mps,
        vz_mps``, ECEF m/s) and c·δṫ_r (``clock_drift_mps``, m/s).

    Raises
    ------
    TypeError
        For a keyword that is not a field of :class:`GnssOptions`.
    """
    instance(eph, Ephemerides, "eph")
    opts, rest = split_options(options, option_fields)
    if rest:
        raise TypeError(f"solve() got an unexpected keyword argument {sorted(rest)[0]!r}")
    with renamed(t="obs"):  # an observation time outside the ephemerides' span is the table's
        return pd.DataFrame(_core.gnss_spp(eph._core, *obs_arrays(obs), opts.native), columns=SPP_COLUMNS)
