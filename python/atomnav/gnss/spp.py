"""Single-point positioning (spec gnss-ins-tight §2.7): least squares for position,
receiver clock and τ_GPS per epoch, the thesis's residual metric, DOP, Doppler velocity."""

from __future__ import annotations

import pandas as pd

from .. import _core
from .ephemeris import Ephemerides
from .observations import obs_arrays

SPP_COLUMNS = ["time_s", "x_m", "y_m", "z_m", "lat_rad", "lon_rad", "h_m", "clock_m", "tau_gps_s", "sigma_tau_gps_s",
               "residual_metric_m", "n_sats", "n_unknowns", "gdop", "pdop", "hdop", "vdop", "tdop",
               "vx_mps", "vy_mps", "vz_mps", "clock_drift_mps"]


def solve(eph: Ephemerides, obs: pd.DataFrame, use_tau: bool = True, iono: bool = True, tropo: bool = True,
          sigma_code: float = 3.0, sigma_code_glonass: float | None = None, sigma_rate: float = 0.05,
          elevation_weight: bool = False) -> pd.DataFrame:
    """One solution per epoch of the observation table (see :func:`simulate`).

    ``use_tau``: estimate τ_GPS (5 unknowns when GLONASS is present; False gives the
    thesis's "no-τ" diagnostic); corrections ``iono``/``tropo``; weights 1/σ² with
    ``sigma_code`` (GLONASS ``sigma_code_glonass``), optionally σ/sin E. Columns
    :data:`SPP_COLUMNS`: ECEF and geodetic antenna position, ``clock_m`` = c·δt_r,
    τ_GPS and its σ (s, NaN when not estimated), the residual metric Σ|r_i|/(N − n) (m),
    DOP values, Doppler velocity (ECEF m/s) and c·δṫ_r (m/s)."""
    s = _core.gnss_spp(eph._core, *obs_arrays(obs), bool(use_tau), bool(iono), bool(tropo), float(sigma_code),
                       float(sigma_code if sigma_code_glonass is None else sigma_code_glonass), float(sigma_rate),
                       bool(elevation_weight))
    return pd.DataFrame(s, columns=SPP_COLUMNS)
