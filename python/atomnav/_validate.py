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


def increasing(t: np.ndarray, name: str, what: str = "time") -> None:
    """``t`` strictly increasing; else an :class:`InputError` naming ``name`` (``what``: the
    quantity in the message, e.g. a column) and the first offending index."""
    d = np.diff(t)
    bad = np.nonzero(d <= 0)[0]
    if bad.size:
        k = bad[0] + 1
        kind = "duplicated" if t[k] == t[k - 1] else "decreasing"
        raise input_error(name, f"{what} not strictly increasing: {kind} stamp {t[k]} at index {k}", k)


def scalar(x, name: str) -> float:
    """``x`` as a float; a non-number or an array is a ``TypeError`` naming ``name``."""
    if isinstance(x, (str, bytes)) or np.ndim(x) != 0:
        raise TypeError(f"{name}: expected a number, got {type(x).__name__}")
    return float(as_floats(x, name))


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
    """``value`` if it is one of the string ``options``; a ``TypeError`` for a non-string."""
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected one of {sorted(options)} (str), got {type(value).__name__}")
    if value not in options:
        raise input_error(name, f"unknown option {value!r}; choose one of {sorted(options)}")
    return value


def instance(x, cls, name: str):
    """``x`` if it is an instance of ``cls`` (a class or tuple of classes), else a
    ``TypeError`` naming ``name`` (instead of an ``AttributeError`` from deep inside the
    call)."""
    if not isinstance(x, cls):
        want = " or ".join(c.__name__ for c in (cls if isinstance(cls, tuple) else (cls,)))
        raise TypeError(f"{name}: expected {want}, got {type(x).__name__}")
    return x


def integer(x, name: str, low: int = 0, high: int = 2**63 - 1) -> int:
    """``x`` as an int in [low, high] (an integral float such as 2.0 is accepted); a
    non-number is a ``TypeError``, a fraction or a value out of range an
    :class:`InputError`, both naming ``name``."""
    integral = isinstance(x, (int, np.integer)) or (isinstance(x, (float, np.floating)) and np.isfinite(x) and x == int(x))
    if isinstance(x, (bool, np.bool_)) or not integral:
        raise TypeError(f"{name}: expected an integer, got {type(x).__name__} {x!r}")
    if not low <= int(x) <= high:
        raise input_error(name, f"must be an integer in [{low}, {high}], got {x}")
    return int(x)


def flag(x, name: str) -> bool:
    """``x`` as a bool (Python or numpy); anything else is a ``TypeError`` naming ``name``."""
    if not isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {type(x).__name__}")
    return bool(x)


def nonnegative(x, name: str) -> float:
    """``x`` as a finite float >= 0 (−0.0 becomes 0.0: numpy's samplers reject a negative-zero
    scale)."""
    x = scalar(x, name)
    if not np.isfinite(x) or x < 0:
        raise input_error(name, f"must be finite and >= 0, got {x}")
    return abs(x)


def finite_result(value, name: str, what: str):
    """``value`` (a float or array computed from checked inputs) if it is finite; else an
    :class:`InputError` naming ``name``, the input whose size made ``what`` overflow."""
    if not np.all(np.isfinite(value)):
        raise input_error(name, f"{what} is outside the range of floats for this value")
    return value


def finite_scalar(x, name: str) -> float:
    """``x`` as a finite float."""
    x = scalar(x, name)
    if not np.isfinite(x):
        raise input_error(name, f"must be finite, got {x}")
    return x


def broadcast(x, shape: tuple, name: str) -> np.ndarray:
    """``x`` as a C-contiguous float64 array broadcast to ``shape``."""
    a = as_floats(x, name)
    try:
        return np.ascontiguousarray(np.broadcast_to(a, shape))
    except ValueError:
        raise input_error(name, f"expected shape {shape} or one that broadcasts to it, got {a.shape}") from None


def shaped(x, shape: tuple, name: str) -> np.ndarray:
    """``x`` (``prod(shape)`` finite numbers in any shape) as a C-contiguous float64 array of ``shape``."""
    a = as_floats(x, name)
    if a.size != int(np.prod(shape)):
        raise input_error(name, f"expected {int(np.prod(shape))} values (shape {shape}), got shape {a.shape}")
    a = np.ascontiguousarray(a.reshape(shape))
    finite(a.reshape(-1), name)
    return a


def generator(seed, name: str) -> np.random.Generator:
    """The numpy generator of ``seed`` (None, an int >= 0 or a ``numpy.random.Generator``)."""
    if seed is None or isinstance(seed, np.random.Generator):
        return np.random.default_rng(seed)
    integer(seed, name, 0, 2**64 - 1)
    return np.random.default_rng(int(seed))


def path(x, name: str = "path"):
    """``x`` (a str or path-like) as a :class:`pathlib.Path`; another type is a ``TypeError``
    and a name the operating system cannot take (an embedded NUL) an :class:`InputError`,
    both naming ``name``."""
    import os
    from pathlib import Path

    if not isinstance(x, (str, os.PathLike)):
        raise TypeError(f"{name}: expected a str or path-like, got {type(x).__name__}")
    p = Path(x)
    if "\x00" in str(p):
        raise input_error(name, "contains a NUL character, which no file name can hold")
    return p


def json_object(text, name: str) -> dict:
    """The JSON object (a dict) in ``text``; text that is no JSON object is an
    :class:`InputError` naming ``name``."""
    import json

    if not isinstance(text, (str, bytes)):
        raise TypeError(f"{name}: expected a JSON str, got {type(text).__name__}")
    try:
        d = json.loads(text)
    except json.JSONDecodeError as e:
        raise input_error(name, f"not JSON: {e}") from None
    if not isinstance(d, dict):
        raise input_error(name, f"expected a JSON object, got {type(d).__name__}")
    return d
