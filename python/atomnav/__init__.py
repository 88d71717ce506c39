"""atomnav: hybrid quantum-classical inertial navigation.

A Rust core (``atomnav._core``) does the numerical work; these Python modules configure
it, validate input, and return numpy arrays / pandas DataFrames with units in the
column names. Conventions (units, frames, signs) are in the README and in
:mod:`atomnav.units`.

The submodules and names below are imported on first use (``atomnav.cai``,
``from atomnav import cai``, ``atomnav.UnitWarning`` all work), so ``import atomnav``
loads neither pandas nor scipy until they are needed.
"""

from __future__ import annotations

import importlib as _importlib
from typing import TYPE_CHECKING as _TYPE_CHECKING

from ._core import InputError, NumericalError

__version__ = "0.1.0"

#: Public submodules, imported on first attribute access. A new submodule is one entry here.
_SUBMODULES = ("units", "rotation", "earth", "trajectory", "strapdown", "imu", "diagnostics", "cai", "noise", "filter", "astro", "gnss", "io", "plots", "alignment", "campaign")

#: Public names defined in a submodule: name -> submodule. A new export is one entry here.
_NAMES = {"UnitWarning": "plausibility"}

__all__ = ["InputError", "NumericalError", *_NAMES, *_SUBMODULES, "__version__"]

if _TYPE_CHECKING:  # what static checkers and IDEs see; at run time __getattr__ below does it
    from . import alignment, astro, cai, campaign, diagnostics, earth, filter, gnss, imu, io, noise, plots, rotation, strapdown, trajectory, units
    from .plausibility import UnitWarning


def __getattr__(name: str):
    """Import a public submodule or name on first access (PEP 562)."""
    if name in _SUBMODULES:
        value = _importlib.import_module(f"{__name__}.{name}")
    elif name in _NAMES:
        value = getattr(_importlib.import_module(f"{__name__}.{_NAMES[name]}"), name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
