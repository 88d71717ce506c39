"""Broadcast ephemerides of GPS (Keplerian elements, IS-GPS-200) and GLONASS (state
vectors, GLONASS ICD) and nominal constellations (circular orbits of the nominal planes and slots).

Times are GPS system time in seconds (t = 0 at the start of a GPS week); GLONASS sets are
referenced to GLONASS time, T_GPS − T_GLO = ΔT_leap + τ_GPS with ΔT_leap = n_leap − 10800 s.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _core, plausibility
from .._validate import as_floats, finite_scalar, instance, integer, rows, table, vector

#: Columns of a GPS ephemeris table (angles rad, times GPS s, clock s, s/s, s/s²).
GPS_COLUMNS = ["prn", "toe", "sqrt_a", "e", "m0", "delta_n", "omega0", "i0", "omega", "omega_dot", "idot",
               "cuc", "cus", "crc", "crs", "cic", "cis", "toc", "af0", "af1", "af2", "tgd"]
#: Columns of a GLONASS ephemeris table (tb GLONASS s; PZ-90 m, m/s, m/s²; tau_n s).
GLONASS_COLUMNS = ["slot", "channel", "tb", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az", "tau_n", "gamma_n"]


def _table(df, columns, name) -> np.ndarray:
    if df is None:
        return np.zeros((0, len(columns)))
    if isinstance(df, pd.DataFrame):
        df = table(df, columns, name, finite=False)  # by name; values are the core's checks
    a = as_floats(df, name)
    return rows(a, len(columns), name) if a.size else np.zeros((0, len(columns)))


class Ephemerides:
    """Broadcast ephemerides of both systems: GPS Keplerian sets (IS-GPS-200) and GLONASS
    state vectors (GLONASS ICD 2008) (Rust ``gnss/ephemeris.rs``).

    Parameters
    ----------
    gps : pandas.DataFrame, optional
        GPS sets with the columns :data:`GPS_COLUMNS` (angles rad, times GPS s, clock s,
        s/s, s/s²); None: no GPS satellites.
    glonass : pandas.DataFrame, optional
        GLONASS sets with the columns :data:`GLONASS_COLUMNS` (tb GLONASS s; PZ-90 m, m/s,
        m/s²; tau_n s); None: no GLONASS satellites.
    n_leap : float, default 18.0
        GPS−UTC leap seconds, s (15 in 2009, 18 since 2017).
    datum : {"identity", "pz90_02_to_wgs84"}, default "identity"
        PZ-90 → WGS-84 transformation.
    ionosphere : array_like (8,), optional
        The navigation message's Klobuchar coefficients α₀..α₃ (s, s/semicircle, s/sc²,
        s/sc³) and β₀..β₃ (s, s/sc, s/sc², s/sc³), as RINEX writes them (ION ALPHA/BETA,
        GPSA/GPSB; IS-GPS-200 20.3.3.5.1.7); default: the set broadcast on 2009-01-01.
    _core_obj : optional
        Internal: an already built core object (as :meth:`nominal` makes); not for users.

    Attributes
    ----------
    week_start : Timestamp or None
        Start (GPS time) of the GPS week the sets' times count from, when they come from a
        file (:func:`atomnav.gnss.rinex.read_nav`); None otherwise.
    time_corrections : DataFrame or None
        The files' time-system corrections (GPUT, GLUT, GLGP, ...: ``system``, ``a0_s``,
        ``a1_s_per_s``, ``week``, ``seconds_of_week``), when read from files; None otherwise.
    sources : tuple of pathlib.Path
        The navigation files the sets were read from (empty when not read from files).
    """

    week_start = None
    time_corrections = None
    sources = ()

    def __init__(self, gps: pd.DataFrame | None = None, glonass: pd.DataFrame | None = None,
                 n_leap: float = 18.0, datum: str = "identity", *, ionosphere=None, _core_obj=None):
        self._core = instance(_core_obj, _core.GnssEphemerides, "_core_obj") if _core_obj is not None else _core.GnssEphemerides(
            _table(gps, GPS_COLUMNS, "gps"), _table(glonass, GLONASS_COLUMNS, "glonass"), finite_scalar(n_leap, "n_leap"), datum,
            ionosphere=ionosphere)

    @property
    def ionosphere(self) -> np.ndarray:
        """The Klobuchar coefficients α₀..α₃, β₀..β₃ applied when ``iono`` is on.

        Returns
        -------
        ndarray (8,)
            α (s, s/semicircle, s/sc², s/sc³) then β (s, s/sc, s/sc², s/sc³).
        """
        return np.array(self._core.ionosphere)

    @classmethod
    def nominal(cls, t_start: float, t_end: float, gps: bool = True, glonass: bool = True, tau_gps: float = 0.0,
                n_leap: float = 18.0, clocks: bool = True, seed: int = 0) -> "Ephemerides":
        """Nominal 24-satellite GPS (6 planes) and GLONASS (3 planes, FDMA channels)
        constellations: circular orbits of the nominal planes and slots.

        Parameters
        ----------
        t_start, t_end : float
            GPS times covered, s (seconds of the GPS week).
        gps : bool, default True
            Include the GPS constellation.
        glonass : bool, default True
            Include the GLONASS constellation.
        tau_gps : float, default 0.0
            True GPS−GLONASS system-time offset τ_GPS used to reference the GLONASS sets, s.
        n_leap : float, default 18.0
            GPS−UTC leap seconds, s.
        clocks : bool, default True
            Random satellite clocks (bias b ~ U(±0.5 ms), drift ~ N(0, 1e-11²) s/s); False:
            ideal clocks.
        seed : int, default 0
            Seed of the satellite clocks, in [0, 2**64).

        Returns
        -------
        Ephemerides
            The nominal broadcast sets.
        """
        return cls(_core_obj=_core.GnssEphemerides.nominal(
            finite_scalar(t_start, "t_start"), finite_scalar(t_end, "t_end"), gps, glonass, finite_scalar(tau_gps, "tau_gps"),
            finite_scalar(n_leap, "n_leap"), clocks, integer(seed, "seed", 0, 2**64 - 1)))

    def tables(self) -> tuple[pd.DataFrame, pd.DataFrame]:
        """The broadcast sets as tables.

        Returns
        -------
        gps : pandas.DataFrame
            GPS sets, columns :data:`GPS_COLUMNS`.
        glonass : pandas.DataFrame
            GLONASS sets, columns :data:`GLONASS_COLUMNS`.
        """
        return (pd.DataFrame(self._core.gps_table(), columns=GPS_COLUMNS),
                pd.DataFrame(self._core.glonass_table(), columns=GLONASS_COLUMNS))

    @property
    def satellites(self) -> list[str]:
        """Satellite names, GPS first ("G01", ..., "R24")."""
        return list(self._core.satellites())

    def channel(self, sat: str) -> int:
        """FDMA channel k of a GLONASS satellite.

        Parameters
        ----------
        sat : str
            Satellite name, e.g. "G01" or "R05".

        Returns
        -------
        int
            Frequency channel k (−7..6); 0 for GPS.
        """
        return self._core.channel(sat)

    def state(self, sat: str, t, tau_gps: float = 0.0) -> pd.DataFrame:
        """Satellite position, velocity and clock at GPS times ``t``.

        Parameters
        ----------
        sat : str
            Satellite name, e.g. "G01" or "R05".
        t : float or array_like, shape (N,)
            GPS times, s; GLONASS sets are evaluated at t − ΔT_leap − ``tau_gps``.
        tau_gps : float, default 0.0
            GPS−GLONASS system-time offset τ_GPS, s.

        Returns
        -------
        pandas.DataFrame
            One row per time: WGS-84 ECEF position ``x_m, y_m, z_m`` (m) and velocity
            ``vx_mps, vy_mps, vz_mps`` (m/s), satellite clock ``clock_s`` (s) and
            ``clock_rate`` (s/s).
        """
        t = np.atleast_1d(as_floats(t, "t"))
        s = self._core.state(sat, vector(t, None, "t"), finite_scalar(tau_gps, "tau_gps"))
        return pd.DataFrame(s, columns=["x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps", "clock_s", "clock_rate"])

    def look_angles(self, sat: str, t, lla) -> pd.DataFrame:
        """Elevation and azimuth of a satellite seen from a geodetic position.

        Parameters
        ----------
        sat : str
            Satellite name, e.g. "G01" or "R05".
        t : float or array_like, shape (N,)
            GPS times, s.
        lla : array_like, shape (3,)
            Receiver latitude (rad), longitude (rad), height (m).

        Returns
        -------
        pandas.DataFrame
            One row per time: ``elevation_rad``, ``azimuth_rad`` (rad).

        Warns
        -----
        atomnav.UnitWarning
            Naming ``lla``: a longitude likely in degrees.
        """
        t = np.atleast_1d(as_floats(t, "t"))
        a = self._core.look_angles(sat, vector(t, None, "t"), plausibility.lla(vector(lla, 3, "lla"), "lla"))
        return pd.DataFrame(a, columns=["elevation_rad", "azimuth_rad"])

    def top(self, n: int, t: float, lla, mask_deg: float = 10.0) -> list[str]:
        """The ``n`` highest satellites above the mask at time ``t`` (for fixed subsets).

        Parameters
        ----------
        n : int
            Number of satellites (≥ 0).
        t : float
            GPS time, s.
        lla : array_like, shape (3,)
            Receiver latitude (rad), longitude (rad), height (m).
        mask_deg : float, default 10.0
            Elevation mask, degrees.

        Returns
        -------
        list of str
            Up to ``n`` satellite names, highest first.
        """
        n, t, lla = integer(n, "n", 0), finite_scalar(t, "t"), plausibility.lla(vector(lla, 3, "lla"), "lla")
        mask = np.radians(finite_scalar(mask_deg, "mask_deg"))
        el = {s: self.look_angles(s, [t], lla)["elevation_rad"].iloc[0] for s in self.satellites}
        up = sorted((s for s in el if el[s] >= mask), key=lambda s: -el[s])
        return up[:n]


def glonass_propagate(pos, vel, acc, dt: float, step: float = 30.0, j2: float = 1082625.75e-9) -> np.ndarray:
    """RK4 propagation of a GLONASS PZ-90 state with constant luni-solar acceleration
    (GLONASS ICD 2008, A.3.1.2).

    Parameters
    ----------
    pos : array_like, shape (3,)
        PZ-90 position, m.
    vel : array_like, shape (3,)
        PZ-90 velocity, m/s.
    acc : array_like, shape (3,)
        Constant luni-solar acceleration, m/s².
    dt : float
        Propagation interval, s (may be negative).
    step : float, default 30.0
        Largest RK4 step, s (> 0).
    j2 : float, default 1082625.75e-9
        Second zonal harmonic J2 of the geopotential (dimensionless; PZ-90 value).

    Returns
    -------
    numpy.ndarray, shape (6,)
        [x, y, z, vx, vy, vz] after ``dt``, m and m/s.

    Raises
    ------
    atomnav.InputError
        The equations of motion hold outside the Earth: a position whose radius is below
        the equatorial radius a_e = 6 378 136 m names ``pos``; an orbit that descends
        below it (at an RK4 step point) or leaves the floating-point range within ``dt``
        names ``vel``.
    """
    return _core.glonass_propagate(vector(pos, 3, "pos"), vector(vel, 3, "vel"), vector(acc, 3, "acc"),
                                   finite_scalar(dt, "dt"), finite_scalar(step, "step"), finite_scalar(j2, "j2"))
