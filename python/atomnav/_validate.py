"""Input checks shared by the Python wrappers. Every failure is an
:class:`atomnav.InputError` (a ``ValueError``) whose ``parameter`` names the argument and,
for series, whose ``index`` is the first offending row; a wrong type is a ``TypeError``
naming the argument (numeric strings are not numbers).

Tables. Every function that takes a pandas DataFrame reads it by column name through
:func:`table`: the order of the columns does not matter and extra columns are ignored. A
wanted column that is missing, or that appears more than once (a duplicated name, e.g.
from ``pd.concat``, or a MultiIndex level matching several columns), is an
:class:`InputError` naming the argument and the column. Columns must hold numbers:
nullable dtypes (``Float64``, ``Int64``) are read with ``pd.NA`` as NaN, which is then
rejected like any NaN with its row in ``.index``; object, string, boolean and datetime
columns are a ``TypeError`` naming the argument and the column.

Time. A time column (``time_s``) may also be datetime64 (naive or tz-aware) or
timedelta64. A timedelta64 is an elapsed time and converts to its seconds. A datetime64
converts to seconds since an epoch: the function's own epoch where it has one (a
``datetime`` ``t0`` of :func:`atomnav.strapdown.integrate`, the ``epoch`` of
:meth:`atomnav.trajectory.Trajectory.from_dataframe`, the start of the GPS week for GNSS
observations), else the first sample; both sides must be tz-aware or both naive, and
tz-aware times are compared in UTC. Integer nanoseconds are never read as seconds.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np
import pandas as pd

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


_FLOAT64 = np.dtype(np.float64)


def as_floats(x, name: str) -> np.ndarray:
    """``x`` as a float64 array; anything that is not numbers (None, strings even when
    they spell numbers, datetimes, complex numbers, ragged nesting) is a ``TypeError``
    naming ``name``. A pandas object's ``pd.NA`` becomes NaN."""
    if type(x) is np.ndarray and x.dtype is _FLOAT64:
        return x  # the common case first: a per-step call from a Python loop pays no more checks
    if x is None or isinstance(x, (str, bytes)):
        raise TypeError(f"{name}: expected numbers, got {type(x).__name__} {x!r}")
    if isinstance(x, (pd.Series, pd.DataFrame)):
        frame = x.to_frame() if isinstance(x, pd.Series) else x
        for column, values in frame.items():
            check_numbers(values, name, column)
        return x.to_numpy(dtype=float, na_value=np.nan)
    try:
        a = np.asarray(x)
    except ValueError as e:  # ragged nesting
        raise TypeError(f"{name}: expected numbers in a regular (N, ...) shape, got {type(x).__name__} ({e})") from None
    if a.dtype.kind in "USMmcV" or (a.dtype.kind == "O" and any(isinstance(v, (str, bytes)) for v in a.flat)):
        raise TypeError(f"{name}: expected numbers, got an array of {a.dtype}")
    try:
        return np.asarray(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: expected numbers, got {type(x).__name__} ({e})") from None


def check_numbers(values: pd.Series, parameter: str, column) -> None:
    """A ``TypeError`` naming ``parameter`` and ``column`` unless the column holds numbers
    (a numeric dtype, nullable or not, or objects that are all numbers or missing)."""
    dtype = values.dtype
    if pd.api.types.is_bool_dtype(dtype) or pd.api.types.is_complex_dtype(dtype):
        ok = False
    elif pd.api.types.is_numeric_dtype(dtype):
        ok = True
    else:
        ok = dtype == object and pd.api.types.infer_dtype(values, skipna=True) in ("floating", "integer", "mixed-integer-float", "empty")
    if not ok:
        raise TypeError(f"{parameter}: column {column!r} holds {dtype} values, expected numbers (strings are not read as numbers)")


#: ``epoch`` of :func:`table` for a datetime column read relative to its first sample.
FIRST_SAMPLE = "first sample"


def timestamp(x):
    """``x`` as a :class:`pandas.Timestamp` if it is a point in time (``datetime``,
    ``numpy.datetime64``, ``pandas.Timestamp``), else None (a number of seconds)."""
    import datetime

    if isinstance(x, (datetime.datetime, np.datetime64)):
        return pd.Timestamp(x)
    return None


def _utc_naive(t):
    """Datetimes ``t`` (a Series or a Timestamp) as naive UTC (naive ones as they are)."""
    if isinstance(t, pd.Series):
        return t if t.dt.tz is None else t.dt.tz_convert("UTC").dt.tz_localize(None)
    return t if t.tz is None else t.tz_convert("UTC").tz_localize(None)


def seconds(values: pd.Series, parameter: str, column, epoch=FIRST_SAMPLE, epoch_name: str = "epoch") -> np.ndarray:
    """A time column as float seconds (NaN where missing): numbers as they are,
    timedelta64 as its seconds, datetime64 as seconds since ``epoch`` (a datetime, or
    :data:`FIRST_SAMPLE`; None: this call has no epoch and datetimes are a
    ``TypeError``). Other dtypes are a ``TypeError`` naming ``parameter`` and
    ``column``; ``epoch_name`` says in that message how to give an epoch. A tz-aware
    column with a naive epoch, or the reverse, is an :class:`InputError` naming
    ``parameter``."""
    dtype = values.dtype
    if pd.api.types.is_timedelta64_dtype(dtype):
        return _timedelta_seconds(values.to_numpy())
    if not pd.api.types.is_datetime64_any_dtype(dtype):
        check_numbers(values, parameter, column)
        return values.to_numpy(dtype=float, na_value=np.nan)
    if epoch is None:
        raise TypeError(f"{parameter}: column {column!r} holds datetimes but no {epoch_name} was given to count seconds from; "
                        "give one, or the column in seconds (or as timedelta64)")
    if epoch is FIRST_SAMPLE:
        present = values.dropna()
        if present.empty:  # nothing to place in time: every row is missing
            return np.full(len(values), np.nan)
        epoch = present.iloc[0]
    epoch = pd.Timestamp(epoch)
    if (values.dt.tz is None) != (epoch.tz is None):
        raise input_error(parameter, f"column {column!r} is {'naive' if values.dt.tz is None else 'tz-aware'} but the epoch "
                                     f"{epoch} is not: give both with a time zone or both without")
    return _timedelta_seconds(_utc_naive(values).to_numpy() - _utc_naive(epoch).to_datetime64())


def _timedelta_seconds(d: np.ndarray) -> np.ndarray:
    """timedelta64 values as float seconds, NaN for NaT (one correctly rounded division of
    the integer count by the unit's count per second)."""
    unit, count = np.datetime_data(d.dtype)
    per_second = np.timedelta64(1, "s") / np.timedelta64(count, unit)
    out = d.view(np.int64) / per_second
    out[np.isnat(d)] = np.nan
    return out


def table(df, names, parameter: str, *, order: str = "C", epoch=FIRST_SAMPLE, epoch_name: str = "epoch",
          time=("time_s",), finite=True) -> np.ndarray:
    """The columns ``names`` of DataFrame ``df`` (argument ``parameter``) as one float64
    array (N, len(names)) in memory ``order`` ("C" or "F"), read by name (module
    docstring: extra columns ignored; missing, duplicated or ambiguous columns an
    :class:`InputError`; non-numbers a ``TypeError``). Columns named in ``time`` convert
    through :func:`seconds` with ``epoch``. With ``finite`` True (or a collection of the
    column names it applies to), a NaN (also ``pd.NA``) or inf is an :class:`InputError`
    naming the column, its row in ``.index``."""
    instance(df, pd.DataFrame, parameter)
    where = locate(df, names, parameter)
    if all(df.dtypes.iloc[k] == np.float64 for k in where):  # plain floats: one block read, often without a copy
        out = np.asarray(df.iloc[:, where].to_numpy(dtype=np.float64), order=order)
    else:
        out = np.empty((len(df), len(names)), order=order)
        for j, (name, k) in enumerate(zip(names, where)):
            values = df.iloc[:, k]
            out[:, j] = seconds(values, parameter, name, epoch, epoch_name) if name in time else _numbers(values, parameter, name)
    if finite:
        for j, name in enumerate(names):
            if finite is not True and name not in finite:
                continue
            bad = np.flatnonzero(~np.isfinite(out[:, j]))
            if bad.size:
                raise input_error(parameter, f"column {name!r}: non-finite value {out[bad[0], j]} at index {bad[0]}", bad[0])
    return out


def _numbers(values: pd.Series, parameter: str, column) -> np.ndarray:
    check_numbers(values, parameter, column)
    return values.to_numpy(dtype=float, na_value=np.nan)


def locate(df: pd.DataFrame, names, parameter: str) -> list[int]:
    """The positions of columns ``names`` in ``df``: a missing column, or one whose name
    matches several columns, is an :class:`InputError` naming ``parameter`` (and listing
    the columns expected, or the ambiguous one)."""
    where, missing = [], []
    for name in names:
        try:
            k = df.columns.get_loc(name)
        except KeyError:
            missing.append(name)
            continue
        if not isinstance(k, (int, np.integer)):  # a slice or a mask of the matching columns
            count = len(range(len(df.columns))[k]) if isinstance(k, slice) else int(np.count_nonzero(k))
            raise input_error(parameter, f"column {name!r} is ambiguous: {count} columns match it (a duplicated name, e.g. "
                                         "from pd.concat, or a MultiIndex level); keep exactly one")
        where.append(int(k))
    if missing:
        raise input_error(parameter, f"missing column(s) {missing}; expected {list(names)} (extra columns are ignored)")
    return where


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
    """``x`` as a float; a non-number, a bool or an array is a ``TypeError`` naming ``name``."""
    try:
        shaped = np.ndim(x) != 0
    except ValueError:  # ragged nesting
        shaped = True
    if isinstance(x, (str, bytes, bool, np.bool_)) or shaped:
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


def integers(x, name: str) -> np.ndarray:
    """``x`` as a 1-D C-contiguous int64 array (row indices, ids); anything that is not
    integers (floats, bools, strings, ragged nesting) is a ``TypeError``, another shape or
    a value beyond int64 an :class:`InputError`, both naming ``name``."""
    try:
        a = np.asarray(x)
    except ValueError as e:  # ragged nesting
        raise TypeError(f"{name}: expected integers in a regular (N,) shape, got {type(x).__name__} ({e})") from None
    if a.size == 0 and a.dtype.kind == "f":  # an empty list reads as float64
        a = a.astype(np.int64)
    if a.dtype.kind not in "iu":
        raise TypeError(f"{name}: expected integers, got an array of {a.dtype}")
    if a.ndim != 1:
        raise input_error(name, f"expected shape (N,), got {a.shape}")
    big = np.flatnonzero(a > np.iinfo(np.int64).max) if a.dtype.kind == "u" else ()
    if len(big):
        raise input_error(name, f"value {a[big[0]]} at index {big[0]} is beyond int64", big[0])
    return np.ascontiguousarray(a, dtype=np.int64)


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


def covariances(x, n: int, name: str, size: int = 3) -> np.ndarray:
    """``x`` as a C-contiguous (n, size, size) stack of covariances: the stack itself, or one
    (size, size) matrix that serves all n (the values are the core's to check)."""
    a = as_floats(x, name)
    if a.shape == (size, size):
        return np.ascontiguousarray(np.broadcast_to(a, (n, size, size)))
    if a.shape != (n, size, size):
        raise input_error(name, f"expected shape ({n}, {size}, {size}), or one ({size}, {size}) matrix for all {n}, got {a.shape}")
    return np.ascontiguousarray(a)


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
