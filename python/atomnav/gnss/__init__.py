"""GNSS for tight GPS + GLONASS / INS integration (Demidov 2009):
broadcast orbits, nominal constellations, observation simulation, single-point
positioning with the system-time offset τ_GPS, and the tightly coupled aided INS; and
the solution files of other GNSS programs (RTKLIB ``.pos``, NMEA 0183) as position
and velocity fixes."""

from .ephemeris import GLONASS_COLUMNS, GPS_COLUMNS, Ephemerides, glonass_propagate
from .observations import OBS_COLUMNS, doppler_to_rate, simulate
from .options import FORMULATIONS, GnssOptions
from . import rinex
from .nmea import read_nmea
from .solution import PosSolution, read_pos
from .spp import SPP_COLUMNS, SppResult, solve
from .tight import GnssObservations, tight_ins

__all__ = ["Ephemerides", "GPS_COLUMNS", "GLONASS_COLUMNS", "glonass_propagate", "OBS_COLUMNS", "simulate",
           "doppler_to_rate", "FORMULATIONS", "GnssOptions", "SPP_COLUMNS", "SppResult", "solve", "tight_ins", "GnssObservations",
           "PosSolution", "read_pos", "read_nmea", "rinex"]
