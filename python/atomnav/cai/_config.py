"""Dict / JSON conversion of the CAI configuration dataclasses, so that a run's
configuration can be saved beside its results and rebuilt from it. The values are checked
once, by the core, when a configuration is handed to it."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from .._validate import instance, json_object
from ..imu import ImuErrors, TriadErrors


def _plain(value):
    """A JSON-ready copy of a field value: nested configurations as dicts, arrays and
    tuples as (nested) lists, numpy scalars as Python numbers."""
    if hasattr(value, "to_dict"):
        return value.to_dict()
    if isinstance(value, ImuErrors):
        return dict(zip(("accel", "gyro"), value._to_core()))
    if isinstance(value, (np.ndarray, tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _tuples(value):
    """Lists read back from JSON as tuples (the dataclasses hold pairs and triples as tuples)."""
    return tuple(_tuples(v) for v in value) if isinstance(value, list) else value


class _ImuModel:
    """Reads back an IMU error model field of a configuration: a preset name as is, a dict
    written by :meth:`ConfigMixin.to_dict` as an :class:`atomnav.imu.ImuErrors`."""

    @staticmethod
    def from_dict(value):
        if isinstance(value, dict):
            return ImuErrors(TriadErrors._from_core(value["accel"]), TriadErrors._from_core(value["gyro"]))
        return value


class ConfigMixin:
    """``to_dict`` / ``from_dict`` / ``to_json`` / ``from_json`` for a dataclass whose nested
    configuration fields are listed in ``_NESTED`` (field name → class with ``from_dict``)
    and whose array fields are listed in ``_ARRAYS`` (read back as lists, converted by the
    class)."""

    _NESTED: dict = {}
    _ARRAYS: tuple = ()

    def to_dict(self) -> dict:
        """The configuration as a dict of plain Python values (JSON-ready)."""
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, d: dict):
        """The configuration of a dict written by :meth:`to_dict`; unknown keys are a
        ``TypeError`` naming them."""
        instance(d, dict, "d")
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise TypeError(f"{cls.__name__}.from_dict: unknown field(s) {', '.join(unknown)}")
        kwargs = {}
        for k, v in d.items():
            if k in cls._NESTED and v is not None:
                kwargs[k] = cls._NESTED[k].from_dict(v)
            elif k in cls._ARRAYS:
                kwargs[k] = v
            else:
                kwargs[k] = _tuples(v)
        return cls(**kwargs)

    def to_json(self, **kwargs) -> str:
        """:meth:`to_dict` as a JSON string (``kwargs`` go to :func:`json.dumps`)."""
        return json.dumps(self.to_dict(), **kwargs)

    @classmethod
    def from_json(cls, text: str):
        """The configuration of a JSON string written by :meth:`to_json`."""
        return cls.from_dict(json_object(text, "text"))
