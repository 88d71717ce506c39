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
    """One solution per epoch of the observation table (see :func:`simulate`).

    ``options`` (:class:`GnssOptions`; its fields may also be given as keywords, e.g.
    ``use_tau=False``): ``use_tau`` estimates τ_GPS, corrections ``iono``/``tropo``,
    weights 1/σ² with ``sigma_code`` (GLONASS ``sigma_code_glonass``), optionally σ/sin E
    (``elevation_weight``), Doppler velocity with ``sigma_rate``. Columns
    :data:`SPP_COLUMNS`: ECEF and geodetic antenna position, ``clock_m`` = c·δt_r,
    τ_GPS and its σ (s, NaN when not estimated), the residual metric Σ|r_i|/(N − n) (m),
    DOP values, Doppler velocity (ECEF m/s) and c·δṫ_r (m/s)."""
    instance(eph, Ephemerides, "eph")
    opts, rest = split_options(options, option_fields)
    if rest:
        raise TypeError(f"solve() got an unexpected keyword argument {sorted(rest)[0]!r}")
    with renamed(t="obs"):  # an observation time outside the ephemerides' span is the table's
        return pd.DataFrame(_core.gnss_spp(eph._core, *obs_arrays(obs), opts.native), columns=SPP_COLUMNS)
