"""Unit conversion factors (multiply to get SI). The values come from the Rust core
(``rust/units.rs``), the single source of truth.

Example: ``0.05 * units.DEG_PER_HOUR`` is a 0.05 °/h gyro bias in rad/s.
"""

from ._core import unit_constants as _unit_constants

_C = _unit_constants()
G0: float = _C["G0"]  #: standard gravity, m/s²
DEG: float = _C["DEG"]  #: degree → rad
ARCSEC: float = _C["ARCSEC"]  #: arc second → rad
ARCMIN: float = _C["ARCMIN"]  #: arc minute → rad
HOUR: float = _C["HOUR"]  #: hour → s
DEG_PER_HOUR: float = _C["DEG_PER_HOUR"]  #: °/h → rad/s
DEG_PER_SQRT_HOUR: float = _C["DEG_PER_SQRT_HOUR"]  #: °/√h → rad/√s
MICRO_G: float = _C["MICRO_G"]  #: µg → m/s²
MILLI_G: float = _C["MILLI_G"]  #: mg → m/s²
MICRO_G_PER_SQRT_HZ: float = _C["MICRO_G_PER_SQRT_HZ"]  #: µg/√Hz → m/s/√s
MPS_PER_SQRT_HOUR: float = _C["MPS_PER_SQRT_HOUR"]  #: m/s/√h → m/s/√s
PPM: float = _C["PPM"]  #: ppm → 1
