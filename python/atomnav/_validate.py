"""Input checks shared by the Python wrappers. Every failure is a ``ValueError`` that
names the field and, for series, the first offending index."""

from __future__ import annotations

import numpy as np


def rows(x, width: int, name: str) -> np.ndarray:
    """``x`` as a C-contiguous float64 array of shape (N, width); a single row of length
    ``width`` is promoted to (1, width)."""
    a = np.asarray(x, dtype=float)
    if a.ndim == 1 and a.shape[0] == width:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name}: expected shape (N, {width}), got {a.shape}")
    finite(a, name)
    return np.ascontiguousarray(a)


def vector(x, length: int | None, name: str) -> np.ndarray:
    """``x`` as a 1-D float64 array (of exactly ``length`` elements when given)."""
    a = np.asarray(x, dtype=float)
    if a.ndim != 1 or (length is not None and a.shape[0] != length):
        want = f"({length},)" if length is not None else "(N,)"
        raise ValueError(f"{name}: expected shape {want}, got {a.shape}")
    finite(a, name)
    return np.ascontiguousarray(a)


def finite(a: np.ndarray, name: str) -> None:
    bad = ~np.isfinite(a)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise ValueError(f"{name}: non-finite value {a[tuple(idx)]} at index {idx[0]}")


def increasing(t: np.ndarray, name: str) -> None:
    d = np.diff(t)
    bad = np.nonzero(d <= 0)[0]
    if bad.size:
        k = bad[0] + 1
        what = "duplicated" if t[k] == t[k - 1] else "decreasing"
        raise ValueError(f"{name}: time not strictly increasing: {what} stamp {t[k]} at index {k}")


def positive(x: float, name: str) -> float:
    x = float(x)
    if not np.isfinite(x) or x <= 0:
        raise ValueError(f"{name}: must be finite and > 0, got {x}")
    return x


def choice(value: str, options, name: str) -> str:
    if value not in options:
        raise ValueError(f"{name}: unknown option {value!r}; choose one of {sorted(options)}")
    return value
