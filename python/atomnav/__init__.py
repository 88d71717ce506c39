"""atomnav: hybrid quantum-classical inertial navigation.

A Rust core (``atomnav._core``) does the numerical work; these Python modules configure
it, validate input, and return numpy arrays / pandas DataFrames with units in the
column names. Conventions (units, frames, signs) are in the README and in
:mod:`atomnav.units`.
"""

from ._core import InputError, NumericalError
from .plausibility import UnitWarning
from . import units, rotation, earth, trajectory, strapdown, imu, diagnostics, cai, noise, filter, astro, gnss

__version__ = "0.1.0"

__all__ = ["InputError", "NumericalError", "UnitWarning", "units", "rotation", "earth", "trajectory", "strapdown", "imu", "diagnostics", "cai", "noise", "filter", "astro", "gnss", "__version__"]
