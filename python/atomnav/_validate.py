"""Input checks shared by the Python wrappers. Every failure is an
:class:`atomnav.InputError` (a ``ValueError``) whose ``parameter`` names the argument and,
for series, whose ``index`` is the first offending row."""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from ._core import InputError


def input_error(parameter: str, reason: str, index: int | None = None) -> InputError:
    """An :class:`InputError` for argument ``parameter`` (message ``"parameter: reason"``)."""
    err = InputError(f"{parameter}: {reason}")
    err.parameter = parameter
    err.index = None if index is None else int(index)
    return err


@contextmanager
def renamed(**names: str):
    """Inside the block, an :class:`InputError` of the core about argument ``old`` (a
    wrapper's stacked or converted argument) names ``names[old]``, the caller's parameter."""
    try:
        yield
    except InputError as e:
        new = names.get(getattr(e, "parameter", None))
        if new is None:
            raise
        old = e.parameter
        msg = str(e)
        raise input_error(new, msg[len(old) + 2:] if msg.startswith(f"{old}: ") else msg, e.index) from None


def floats(x, name: str) -> np.ndarray:
    """``x`` as a float64 array of any shape with no NaN/inf (``TypeError`` or
    :class:`InputError` naming ``name``)."""
    a = as_floats(x, name)
    finite(a, name)
    return a


def as_floats(x, name: str) -> np.ndarray:
    """``x`` as a float64 array; anything that is not numbers is a ``TypeError`` naming
    ``name``."""
    if x is None:
        raise TypeError(f"{name}: expected numbers, got None")
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: expected numbers, got {type(x).__name__} ({e})") from None


def instance(x, cls, name: str):
    """``x`` itself if it is a ``cls``; otherwise a ``TypeError`` naming ``name`` (instead of
    an ``AttributeError`` from deep inside the call)."""
    if not isinstance(x, cls):
        raise TypeError(f"{name}: expected {cls.__name__}, got {type(x).__name__}")
    return x


def rows(x, width: int, name: str) -> np.ndarray:
    """``x`` as a C-contiguous float64 array of shape (N, width); a single row of length
    ``width`` is promoted to (1, width)."""
    a = as_floats(x, name)
    if a.ndim == 1 and a.shape[0] == width:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != width:
        raise input_error(name, f"expected shape (N, {width}), got {a.shape}")
    finite(a, name)
    return np.ascontiguousarray(a)


def vector(x, length: int | None, name: str) -> np.ndarray:
    """``x`` as a 1-D float64 array (of exactly ``length`` elements when given)."""
    a = as_floats(x, name)
    if a.ndim != 1 or (length is not None and a.shape[0] != length):
        want = f"({length},)" if length is not None else "(N,)"
        raise input_error(name, f"expected shape {want}, got {a.shape}")
    finite(a, name)
    return np.ascontiguousarray(a)


def finite(a: np.ndarray, name: str) -> None:
    a = np.atleast_1d(a)
    bad = ~np.isfinite(a)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise input_error(name, f"non-finite value {a[tuple(idx)]} at index {idx[0]}", idx[0])


def increasing(t: np.ndarray, name: str) -> None:
    d = np.diff(t)
    bad = np.nonzero(d <= 0)[0]
    if bad.size:
        k = bad[0] + 1
        what = "duplicated" if t[k] == t[k - 1] else "decreasing"
        raise input_error(name, f"time not strictly increasing: {what} stamp {t[k]} at index {k}", k)


def scalar(x, name: str) -> float:
    """``x`` as a float; a non-number or an array is a ``TypeError`` naming ``name``."""
    if isinstance(x, (str, bytes)) or np.ndim(x) != 0:
        raise TypeError(f"{name}: expected a number, got {type(x).__name__}")
    return float(as_floats(x, name))


def integer(x, name: str, minimum: int = 0) -> int:
    """``x`` as an int ≥ ``minimum`` (an integral float such as 2.0 is accepted); a
    non-number is a ``TypeError`` naming ``name``."""
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected an int, got {type(x).__name__}")
    if not (np.isfinite(x) and int(x) == x and x >= minimum):
        raise input_error(name, f"must be an integer ≥ {minimum}, got {x}")
    return int(x)


def positive(x: float, name: str) -> float:
    x = scalar(x, name)
    if not np.isfinite(x) or x <= 0:
        raise input_error(name, f"must be finite and > 0, got {x}")
    return x


def probability(x, name: str) -> float:
    """``x`` as a float strictly inside (0, 1) (a confidence level or a quantile)."""
    x = scalar(x, name)
    if not 0.0 < x < 1.0:
        raise input_error(name, f"must be a probability in (0, 1), got {x}")
    return x


def choice(value: str, options, name: str) -> str:
    if value not in options:
        raise input_error(name, f"unknown option {value!r}; choose one of {sorted(options)}")
    return value
