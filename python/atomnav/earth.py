"""Earth models: WGS-84 and PZ-90.11 ellipsoids, normal gravity, radii, Earth and
transport rate, LLA ↔ ECEF ↔ NED.

Positions are ``(lat rad, lon rad, h m)`` rows. Every function takes
``ellipsoid="WGS84"`` or ``"PZ90.11"``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from . import _core, plausibility
from ._validate import floats, input_error, renamed, rows, scalar, vector

#: Heights (m) a navigation state may have, from the deepest ocean trench to low Earth
#: orbit: (min, max). A height outside is an :class:`InputError`.
HEIGHT_RANGE = _core.HEIGHT_RANGE


def ellipsoid(name: str = "WGS84") -> dict:
    """Constants of an ellipsoid.

    Parameters
    ----------
    name : str
        ``"WGS84"`` (default) or ``"PZ90.11"`` (one of ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    dict
        ``a`` (m), ``f``, ``gm`` (m³/s²), ``omega`` (rad/s), ``e2``, ``b`` (m),
        ``gamma_e`` and ``gamma_p`` (m/s², closed-form normal gravity at equator and pole)
        and ``name``.

    References
    ----------
    WGS-84: NIMA TR8350.2, 3rd ed., 2000. PZ-90.11: GLONASS ICD, 2016.
    """
    with renamed(ellipsoid="name"):
        return _core.ellipsoid_constants(name)


def lla_to_ecef(lla, ellipsoid: str = "WGS84") -> np.ndarray:
    """ECEF coordinates of geodetic positions.

    Parameters
    ----------
    lla : array_like (N, 3) or (3,)
        Geodetic positions: latitude (rad), longitude (rad), height (m).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    ndarray (N, 3) or (3,)
        ECEF coordinates (m).
    """
    r = _core.lla_to_ecef_rows(plausibility.lla(rows(lla, 3, "lla"), "lla"), ellipsoid)
    return r[0] if np.ndim(lla) == 1 else r


def ecef_to_lla(ecef, ellipsoid: str = "WGS84") -> np.ndarray:
    """Geodetic positions of ECEF points; latitude iterated to 1e-12 rad.

    Parameters
    ----------
    ecef : array_like (N, 3) or (3,)
        ECEF coordinates (m).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    ndarray (N, 3) or (3,)
        Latitude (rad), longitude (rad), height (m).

    Raises
    ------
    InputError
        Naming ``ecef`` and the row: the Earth's centre, where geodetic coordinates are
        undefined.
    """
    r = _core.ecef_to_lla_rows(rows(ecef, 3, "ecef"), ellipsoid)
    return r[0] if np.ndim(ecef) == 1 else r


def ecef_to_ned(ecef, origin_lla, ellipsoid: str = "WGS84") -> np.ndarray:
    """NED coordinates of ECEF points relative to a geodetic origin.

    Parameters
    ----------
    ecef : array_like (N, 3) or (3,)
        ECEF coordinates (m).
    origin_lla : array_like (3,)
        The geodetic origin: latitude (rad), longitude (rad), height (m).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    ndarray (N, 3) or (3,)
        North, east, down (m).
    """
    r = _core.ecef_to_ned_rows(rows(ecef, 3, "ecef"), plausibility.lla(vector(origin_lla, 3, "origin_lla"), "origin_lla"), ellipsoid)
    return r[0] if np.ndim(ecef) == 1 else r


def ned_to_ecef(ned, origin_lla, ellipsoid: str = "WGS84") -> np.ndarray:
    """ECEF points of NED coordinates relative to a geodetic origin.

    Parameters
    ----------
    ned : array_like (N, 3) or (3,)
        North, east, down (m).
    origin_lla : array_like (3,)
        The geodetic origin: latitude (rad), longitude (rad), height (m).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    ndarray (N, 3) or (3,)
        ECEF coordinates (m).
    """
    r = _core.ned_to_ecef_rows(rows(ned, 3, "ned"), plausibility.lla(vector(origin_lla, 3, "origin_lla"), "origin_lla"), ellipsoid)
    return r[0] if np.ndim(ned) == 1 else r


def lla_to_ned(lla, origin_lla, ellipsoid: str = "WGS84") -> np.ndarray:
    """NED coordinates of geodetic points relative to a geodetic origin.

    Parameters
    ----------
    lla : array_like (N, 3) or (3,)
        Geodetic positions: latitude (rad), longitude (rad), height (m).
    origin_lla : array_like (3,)
        The geodetic origin: latitude (rad), longitude (rad), height (m).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    ndarray (N, 3) or (3,)
        North, east, down (m).
    """
    return ecef_to_ned(lla_to_ecef(lla, ellipsoid), origin_lla, ellipsoid)


def dcm_ned_to_ecef(lat: float, lon: float) -> np.ndarray:
    """The rotation C_n^e from NED to ECEF at a geodetic position.

    Parameters
    ----------
    lat, lon : float
        Latitude and longitude (rad).

    Returns
    -------
    ndarray (3, 3)
        C_n^e: its columns are the north, east, down axes in ECEF.
    """
    return _core.dcm_ned_to_ecef_py(scalar(lat, "lat"), plausibility.longitude(scalar(lon, "lon"), "lon"))


def parameters(lla, ellipsoid: str = "WGS84") -> pd.DataFrame:
    """Radii of curvature, normal gravity and Schuler frequency at each position.

    Parameters
    ----------
    lla : array_like (N, 3) or (3,)
        Geodetic positions: latitude (rad), longitude (rad), height (m).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    DataFrame
        One row per position: ``M_m`` (meridian radius, m), ``N_m`` (prime-vertical
        radius, m), ``gravity_mps2`` (Somigliana with height correction, m/s²),
        ``dgravity_dlat_mps2_per_rad`` (m/s²/rad), ``schuler_rad_s``
        (√(γ/(√(MN)+h)), rad/s).

    Raises
    ------
    InputError
        Naming ``lla`` and the row: a height outside :data:`HEIGHT_RANGE`, where normal
        gravity and the Schuler frequency lose their meaning.

    References
    ----------
    Normal gravity: NIMA TR8350.2, 3rd ed., 2000, ch. 4 (WGS-84 ellipsoidal gravity
    formula).
    """
    p = _core.earth_params_rows(plausibility.lla(rows(lla, 3, "lla"), "lla"), ellipsoid)
    return pd.DataFrame(p, columns=["M_m", "N_m", "gravity_mps2", "dgravity_dlat_mps2_per_rad", "schuler_rad_s"])


def gravity(lat, h=0.0, ellipsoid: str = "WGS84") -> np.ndarray:
    """Normal gravity magnitude γ (positive down), Somigliana with the second-order
    height correction.

    Parameters
    ----------
    lat : float or array_like (N,)
        Latitude(s) (rad).
    h : float or array_like (N,)
        Height(s) (m), broadcast against ``lat``.
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    float or ndarray (N,)
        γ (m/s²); a float for a single latitude and height.

    Raises
    ------
    InputError
        Naming ``h``: a height outside :data:`HEIGHT_RANGE`, or heights that do not
        broadcast against the latitudes.

    References
    ----------
    NIMA TR8350.2, 3rd ed., 2000, ch. 4 (WGS-84 ellipsoidal gravity formula).
    """
    lat, h = _series(lat, "lat"), _series(h, "h")
    try:
        lat, h = np.broadcast_arrays(lat, h)
    except ValueError:
        raise input_error("h", f"{h.size} heights for {lat.size} latitudes") from None
    with renamed(lla="lat"):
        g = _core.earth_params_rows(np.column_stack([lat, np.zeros_like(lat), h]), ellipsoid, h_field="h")[:, 2]
    return g[0] if g.size == 1 else g


def _series(x, name: str) -> np.ndarray:
    """A scalar or 1-D series of finite numbers as a 1-D float64 array."""
    a = np.atleast_1d(floats(x, name))
    if a.ndim != 1:
        raise input_error(name, f"expected a number or shape (N,), got {a.shape}")
    return a


def radii(lat, ellipsoid: str = "WGS84"):
    """Meridian M and prime-vertical N radii of curvature.

    Parameters
    ----------
    lat : float or array_like (N,)
        Latitude(s) (rad).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    M, N : float or ndarray (N,)
        Meridian and prime-vertical radii of curvature (m); floats for one latitude.
    """
    lat = _series(lat, "lat")
    with renamed(lla="lat"):
        p = _core.earth_params_rows(np.column_stack([lat, 0 * lat, 0 * lat]), ellipsoid)
    m, n = p[:, 0], p[:, 1]
    return (m[0], n[0]) if m.size == 1 else (m, n)


def schuler_period(lat: float, h: float = 0.0, ellipsoid: str = "WGS84") -> float:
    """Schuler period 2π/ω_s with ω_s = √(γ/R₀), R₀ = √(MN) + h.

    Parameters
    ----------
    lat : float
        Latitude (rad).
    h : float
        Height (m).
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    float
        The Schuler period (s), about 84 min at the surface.

    Raises
    ------
    InputError
        Naming ``h``: a height outside :data:`HEIGHT_RANGE`.
    """
    lla = np.array([[scalar(lat, "lat"), 0.0, scalar(h, "h")]])
    floats(lla[:, 0], "lat"), floats(lla[:, 2], "h")
    with renamed(lla="lat"):
        w = _core.earth_params_rows(lla, ellipsoid, h_field="h")[0, 4]
    return 2 * np.pi / w


def navigation_rates(lla, vel_ned, ellipsoid: str = "WGS84") -> pd.DataFrame:
    """Earth rate ω_ie^n and transport rate ω_en^n in NED for each position and velocity.

    ω_ie^n = Ω (cos φ, 0, −sin φ) and ω_en^n = (v_E/(N+h), −v_N/(M+h), −v_E tan φ/(N+h)).

    Parameters
    ----------
    lla : array_like (N, 3) or (3,)
        Geodetic positions: latitude (rad), longitude (rad), height (m).
    vel_ned : array_like (N, 3) or (3,)
        NED velocity (m/s), one row per row of ``lla``.
    ellipsoid : str
        Earth model, ``"WGS84"`` (default) or ``"PZ90.11"`` (one of
        ``atomnav._core.OPTIONS["Ellipsoid"]``).

    Returns
    -------
    DataFrame
        ``earth_rate_{N,E,D}_rad_s`` and ``transport_rate_{N,E,D}_rad_s`` (rad/s), one row
        per position.

    Raises
    ------
    InputError
        Naming ``lla`` and the row: a height outside :data:`HEIGHT_RANGE`. Naming
        ``vel_ned``: a row count other than that of ``lla``.
    """
    p, v = plausibility.lla(rows(lla, 3, "lla"), "lla"), rows(vel_ned, 3, "vel_ned")
    if len(v) != len(p):
        raise input_error("vel_ned", f"expected {len(p)} rows like lla, got {len(v)}")
    x = np.hstack([p, v])
    with renamed(lla_vel="lla"):
        r = _core.nav_rates_rows(np.ascontiguousarray(x), ellipsoid)
    cols = [f"{w}_{a}_rad_s" for w in ("earth_rate", "transport_rate") for a in ("N", "E", "D")]
    return pd.DataFrame(r, columns=cols)
