#!/usr/bin/env python
"""Fuzz the public Python boundary of atomnav: every public function, constructor and
method of ``atomnav`` and ``atomnav._core`` is called with arguments drawn by
``hypothesis`` from its signature, in a worker subprocess that may die or hang without
taking the caller down.

The API is enumerated from the modules (``atomnav._core`` and every public subpackage of
``atomnav``; public = no leading underscore, defined in that module), so a new function is
fuzzed without being listed here. Classes: the constructor (and static constructors such
as ``Motion.stationary``), then every method and property on an instance that an earlier
call built successfully (the call that built it is part of the reproducer).

Arguments (per parameter, from ``inspect.signature`` / pyo3's ``__text_signature__``):
arrays of many shapes (empty, 0-d, rows of width 1..15, square stacks), dtypes (float64,
float32, int64, bool, complex, object, str), layouts (C, Fortran, strided, negative
stride), special floats (NaN, ±inf, ±0, 5e-324, ±1e308), extreme integers (0, -1, 2**31,
2**63, 2**64), lists, numpy scalars, None, wrong types, option strings (every name in
``atomnav._core.OPTIONS`` and every string default of the API) and invalid strings, and
instances of the API's own classes.

Outcome classes: ``ok``, ``InputError`` (its ``.parameter`` must name a parameter of the
called function, else ``InputError(bad parameter)``), ``TypeError``, ``MemoryError``,
``NumericalError``, ``OSError`` (file functions given a path that does not exist) — and
the bad ones: any other exception, ``PanicException``, ``abort`` (the worker died by a
signal or exited), ``hang`` (no answer within the timeout; the worker is killed) and
``non-finite`` (NaN/inf in the output of a call whose inputs are all finite, unless the
function's docstring says its output "may be non-finite").

Speed: each hypothesis example draws a batch of calls (``BATCH``); two persistent worker
processes run batches while the next one is drawn and answer call by call, so an abort or
a hang (no answer within ``TIMEOUT_S``) is pinned to its call, reported with the call that
reproduces it, and the rest of the batch goes to a fresh worker (a warm spare). A callable
whose calls used up ``TIME_BUDGET_S`` of worker time (slow defaults, e.g. a whole hybrid
filter run) is not called again in that campaign.

Usage::

    python tests/fuzz.py --calls 20000 --seed 1 --out report.md
    python tests/fuzz.py --calls 5000 --seed 2 --only atomnav.noise,atomnav._core.allan_   # some modules
    python tests/fuzz.py --calls 1000000 --out long.md                                    # the long campaign

The report lists the calls made, outcome classes, the first reproducers of each bad
(callable, class) pair, the slowest calls and the callables by worker time.

The worker caps its address space (``RLIMIT_AS``, 4 GiB by default) so a huge allocation
is a ``MemoryError`` or a dead worker, never a machine out of memory.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import fnmatch
import heapq
import importlib
import inspect
import itertools
import math
import os
import pickle
import pkgutil
import select
import signal
import struct
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict, deque

import numpy as np

GOOD = ("ok", "InputError", "TypeError", "MemoryError", "NumericalError", "OSError")
"""Outcome classes that are a correct answer to an arbitrary call."""

SKIPPED = ("no instance", "quarantined", "over time budget", "setup")
"""Calls not made: a method of a class no call has built yet, a callable taken out of
the campaign after it hung or killed the worker (its first failure is reported) or after
its calls used ``TIME_BUDGET_S`` (slow defaults, e.g. a whole hybrid-filter run), or a
method whose instance could not be rebuilt."""

EXCLUDED_MODULES = {
    "atomnav.cli": "command-line entry point (argv parsing and whole reproductions)",
    "atomnav.reproduce": "paper reproductions that run for minutes from fixed configurations; "
                         "the functions they call are fuzzed directly",
}

EXCLUDED_CALLABLES = {
    name: "a paper's whole Monte-Carlo scenario at its published size (10-40 s a run by design); "
          "the configurations and the campaign runner it calls are fuzzed directly"
    for name in ("atomnav.cai.scenarios.car_mc", "atomnav.cai.scenarios.slalom", "atomnav.cai.scenarios.satellite",
                 "atomnav.cai.scenarios.hexapod")
}

NONFINITE_DOC = "may be non-finite"

SPECIAL_FLOATS = (math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, 1e308, -1e308)
EXTREME_INTS = (0, -1, 1, 2**31, 2**63, 2**64, -(2**63), 2**32 + 1)
INVALID_STRINGS = ("", "nope", "WGS-84", " rates", "RATES", "\x00", "ééé", "a" * 300)
TIMEOUT_S = 10.0
RECIPES = 12  # calls kept per class that built an instance of it
RECIPE_MAX_S = 0.05  # a call that built an instance is reused (rebuilt for every use) if it took less
TIME_BUDGET_S = 1.0  # worker seconds per callable in one campaign (hangs and aborts not counted)
MEMORY_LIMIT = 4 << 30
LITERAL_MAX = 24  # arrays up to this many elements are written out in a reproducer
QUARANTINE = {"hang": 1, "abort": 2}  # failures of a kind after which a function is not called again
CI_CALLS = 20_000  # the fixed-seed share CI runs; longer campaigns scale TIME_BUDGET_S with their length
JOBS = 2  # worker processes running batches side by side
BATCH = 64  # calls drawn by one hypothesis example and run by the worker in one go
BATCH_LENGTH = 6_000  # ... or fewer, so an example stays within hypothesis' choice buffer (8 KiB)
REPRO_KEEP = 3  # reproducers kept per bad (callable, class) pair
SLOWEST = 15  # slowest calls listed in the report
PROGRESS_S = 30.0  # seconds between progress reports
TOPUP_EXAMPLES = 20  # fewest examples a top-up round draws
IDLE_ROUNDS = 5  # top-up rounds in a row that made no call, after which a campaign stops
IDLE_BATCHES = 50  # ... after which a campaign stops (every callable quarantined or over budget)


# ----------------------------------------------------------------------------------------
# the API


@dataclasses.dataclass(frozen=True)
class Param:
    name: str
    default: object  # inspect.Parameter.empty when required; Ellipsis when unknown (pyo3 "...")
    positional_only: bool = False


@dataclasses.dataclass(frozen=True)
class Target:
    """One callable of the API. ``kind``: function, constructor, static (a static method,
    e.g. a named constructor), method or property (both need an instance of ``owner``)."""

    name: str  # dotted path, e.g. "atomnav.earth.lla_to_ecef" or "atomnav._core.Strapdown.run"
    module: str
    qualname: str
    kind: str
    owner: str | None
    params: tuple[Param, ...]
    nonfinite_documented: bool
    owner_params: tuple[str, ...] = ()  # a method's or property's instance was built from these

    def param_names(self) -> set[str]:
        """Names an ``InputError`` of this call may give: its parameters and, for a method or
        property, the constructor parameters of its instance (a field of the receiver, such
        as a sensor's ``T``, is an input of the call too)."""
        return {p.name for p in self.params} | set(self.owner_params)


def _params(obj, drop_self: bool) -> tuple[Param, ...] | None:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return None
    out = []
    for i, p in enumerate(sig.parameters.values()):
        if drop_self and i == 0 and p.name in ("self", "cls", "$self"):
            continue
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        # a dataclass field with a default factory shows a sentinel: optional, default unknown
        default = Ellipsis if repr(p.default) == "<factory>" else p.default
        out.append(Param(p.name, default, p.kind == p.POSITIONAL_ONLY))
    return tuple(out)


def _doc_nonfinite(*objs) -> bool:
    return any(NONFINITE_DOC in " ".join((getattr(o, "__doc__", None) or "").split()) for o in objs)


def public_modules():
    """``atomnav._core`` and every public (sub)module of ``atomnav`` not excluded."""
    import atomnav

    yield importlib.import_module("atomnav._core")
    for info in pkgutil.walk_packages(atomnav.__path__, "atomnav."):
        parts = info.name.split(".")
        if any(s.startswith("_") for s in parts[1:]):
            continue
        if any(info.name == m or info.name.startswith(m + ".") for m in EXCLUDED_MODULES):
            continue
        yield importlib.import_module(info.name)


def _defined_in(obj, mod) -> bool:
    return getattr(obj, "__module__", None) == mod.__name__


def enumerate_targets() -> list[Target]:
    """The public API, in a stable order."""
    targets: list[Target] = []
    for mod in public_modules():
        for name in sorted(vars(mod)):
            obj = vars(mod)[name]
            if name.startswith("_") or not _defined_in(obj, mod):
                continue
            path = f"{mod.__name__}.{name}"
            if path in EXCLUDED_CALLABLES:
                continue
            if inspect.isclass(obj):
                if issubclass(obj, BaseException):
                    continue
                targets.extend(_class_targets(mod.__name__, name, obj))
            elif inspect.isfunction(obj) or inspect.isbuiltin(obj):
                params = _params(obj, drop_self=False)
                if params is not None:
                    targets.append(Target(path, mod.__name__, name, "function", None, params, _doc_nonfinite(obj)))
    return targets


def _class_targets(module: str, name: str, cls) -> list[Target]:
    path = f"{module}.{name}"
    out = []
    params = _params(cls, drop_self=True)
    fields = tuple(p.name for p in params or ())
    if params is not None and not (cls.__init__ is object.__init__ and cls.__new__ is object.__new__ and not params):
        out.append(Target(path, module, name, "constructor", None, params, _doc_nonfinite(cls)))
    for attr in sorted(vars(cls)):
        if attr.startswith("_"):
            continue
        raw = vars(cls)[attr]
        member = getattr(cls, attr)
        q = f"{name}.{attr}"
        if isinstance(raw, (staticmethod, classmethod)):
            p = _params(member, drop_self=False)
            if p is not None:
                out.append(Target(f"{path}.{attr}", module, q, "static", None, p, _doc_nonfinite(member, cls)))
        elif isinstance(raw, property) or inspect.isgetsetdescriptor(raw) or inspect.ismemberdescriptor(raw):
            out.append(Target(f"{path}.{attr}", module, q, "property", path, (), _doc_nonfinite(raw, cls), fields))
        elif inspect.isfunction(raw) or inspect.ismethoddescriptor(raw):
            p = _params(member, drop_self=True)
            if p is not None:
                out.append(Target(f"{path}.{attr}", module, q, "method", path, p, _doc_nonfinite(member, cls), fields))
    return out


def resolve(module: str, qualname: str):
    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


# ----------------------------------------------------------------------------------------
# argument specifications: plain picklable data, built into values in the worker and
# written out as Python in a reproducer


def arr(shape, dtype="float64", layout="C", fill="normal", seed=0, specials=()):
    """The array an argument specification ``('arr', ...)`` stands for (used by
    reproducers of calls with large arrays)."""
    rng = np.random.default_rng(seed)
    shape = tuple(shape)
    size = int(np.prod(shape, dtype=np.int64))
    if fill == "increasing":
        base = np.cumsum(rng.uniform(0.01, 1.0, size))
    elif fill == "unit":
        base = rng.normal(size=size)
        w = shape[-1] if shape and shape[-1] else 1
        if size:
            base = (base.reshape(-1, w) / np.linalg.norm(base.reshape(-1, w), axis=1, keepdims=True)).ravel()
    elif fill == "eye":
        base = np.zeros(shape)
        if len(shape) >= 2:
            k = min(shape[-2:])
            base[..., range(k), range(k)] = 1.0
        base = base.ravel()
    elif fill == "small":
        base = rng.uniform(-1e-3, 1e-3, size)
    elif fill == "zeros":
        base = np.zeros(size)
    elif fill == "ints":
        base = rng.integers(-3, 10, size).astype(float)
    else:
        base = rng.normal(size=size)
    base = base.astype(float)
    for i, v in specials:
        if size:
            base[i % size] = v
    a = base.reshape(shape)
    if dtype == "object":
        a = a.astype(object)
    elif dtype.startswith("<U"):
        a = a.astype(dtype)
    elif dtype == "bool":
        a = a != 0
    else:
        with np.errstate(invalid="ignore", over="ignore"):
            a = a.astype(dtype)
    return _layout(a, layout)


def _layout(a, layout):
    if layout == "F":
        return np.asfortranarray(a)
    if layout == "strided" and a.ndim:
        return np.repeat(a, 2, axis=-1)[..., ::2]
    if layout == "reversed" and a.ndim:
        return np.ascontiguousarray(a[::-1])[::-1]
    return a


class _Object:
    def __repr__(self):
        return "object()"


def build(spec, cache=None):
    """The value an argument specification stands for."""
    if isinstance(spec, tuple) and spec and spec[0] in _BUILDERS:
        return _BUILDERS[spec[0]](spec, cache)
    if isinstance(spec, list):
        return [build(s, cache) for s in spec]
    return spec


def _build_call(spec, cache):
    _, target, kwargs, this = spec
    t = TARGETS_BY_NAME[target]
    fn = callee(t, build(this, cache) if this is not None else None)
    return fn(**{k: build(v, cache) for k, v in kwargs.items()})


_BUILDERS = {
    "arr": lambda s, c: arr(*s[1:]),
    "list": lambda s, c: arr(*s[1][1:]).tolist(),
    "npscalar": lambda s, c: np.dtype(s[1]).type(s[2]),
    "obj": lambda s, c: object(),
    "call": _build_call,
}


def callee(t: Target, instance=None):
    if t.kind in ("method", "property"):
        return getattr(instance, t.qualname.rsplit(".", 1)[1]) if t.kind == "method" else (
            lambda: getattr(instance, t.qualname.rsplit(".", 1)[1]))
    return resolve(t.module, t.qualname)


def render(spec) -> str:
    """A Python expression for an argument specification (names: np, atomnav, nan, inf, arr)."""
    if isinstance(spec, tuple) and spec and spec[0] == "arr":
        a = arr(*spec[1:])
        if a.size > LITERAL_MAX:
            return "arr({!r}, {!r}, {!r}, {!r}, {!r}, {})".format(*spec[1:6], _floats(spec[6]))
        if a.ndim == 0 or a.size == 0:
            lit = f"np.array({_floats(a.tolist())}, dtype={str(a.dtype)!r}).reshape({a.shape})"
        else:
            lit = f"np.array({_floats(a.tolist())}, dtype={str(a.dtype)!r})"
        return {"F": f"np.asfortranarray({lit})", "strided": f"np.repeat({lit}, 2, axis=-1)[..., ::2]",
                "reversed": f"np.ascontiguousarray({lit}[::-1])[::-1]"}.get(spec[3], lit) if a.ndim else lit
    if isinstance(spec, tuple) and spec and spec[0] == "list":
        a = arr(*spec[1][1:])
        return _floats(a.tolist()) if a.size <= LITERAL_MAX else f"{render(spec[1])}.tolist()"
    if isinstance(spec, tuple) and spec and spec[0] == "npscalar":
        return f"np.{np.dtype(spec[1]).name}({_floats(spec[2])})"
    if isinstance(spec, tuple) and spec and spec[0] == "obj":
        return "object()"
    if isinstance(spec, tuple) and spec and spec[0] == "call":
        return render_call(*spec[1:])
    if isinstance(spec, list):
        return "[" + ", ".join(render(s) for s in spec) + "]"
    return _floats(spec)


def _floats(v) -> str:
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    if isinstance(v, (list, tuple)):
        inner = ", ".join(_floats(x) for x in v)
        return f"[{inner}]" if isinstance(v, list) else f"({inner}{',' if len(v) == 1 else ''})"
    if isinstance(v, complex):
        return f"complex({_floats(v.real)}, {_floats(v.imag)})"
    return repr(v)


def render_call(target: str, kwargs: dict, this=None) -> str:
    t = TARGETS_BY_NAME[target]
    args = ", ".join(f"{k}={render(v)}" for k, v in kwargs.items())
    attr = t.qualname.rsplit(".", 1)[-1]
    if t.kind == "property":
        return f"({render(this)}).{attr}"
    if t.kind == "method":
        return f"({render(this)}).{attr}({args})"
    return f"{t.name}({args})"


# ----------------------------------------------------------------------------------------
# hypothesis strategies


TIME_NAMES = ("t", "time", "times", "t0", "tau", "fix_t", "epochs", "t_start", "tau0")
QUAT_NAMES = ("q", "q0", "q_nb", "a", "b")
SQUARE_NAMES = ("p0", "p", "phi", "q", "r", "qc", "f", "c", "dcm", "p_prior", "p_post", "cov", "fix_cov")
COUNT_NAMES = ("n", "m", "d", "steps", "n_epochs", "max_iter", "batch", "substeps", "predict_every", "chunk",
               "runs", "np", "order", "window", "half_width", "savgol_half_width", "first_index", "lags", "max_p",
               "max_q", "levels", "level", "repeats", "n_samples", "samples", "count", "every", "shots")


OPTION_NAMES = ("kind", "mode", "method", "ellipsoid", "data_type", "set", "noise_form", "vertical", "formulation",
                "init", "solver", "residual_form", "interpolation", "readout", "terms", "x0", "name", "datum",
                "taylor_variant", "data_kind", "gyro_error_model", "helmert", "model", "form", "apply")
INSTANCE_NAMES = ("ins", "eph", "sensor", "scenario", "motion", "res", "result", "channels", "setup", "core",
                  "truth", "traj", "trajectory", "catalog", "filter", "fit", "errors", "imu_accel", "imu_gyro",
                  "reference", "gravity", "obs", "noise", "aiding", "stream", "model", "calibration")


ROWS = (1, 2, 3, 5, 8, 0, 13)
"""Row counts N of one call (its arrays share N, so that lengths agree unless drawn not to)."""


def strategies(targets: list[Target]):
    """The strategy factory ``value(param, hostile, n)`` for one campaign (hypothesis is
    imported here so the worker does not need it)."""
    from hypothesis import strategies as st

    import atomnav._core as core

    options = sorted({o for names in core.OPTIONS.values() for o in names}
                     | {p.default for t in targets for p in t.params if isinstance(p.default, str)})
    floats = st.one_of(st.sampled_from(SPECIAL_FLOATS), st.floats(-100, 100), st.floats(1e-6, 1e3),
                       st.sampled_from((1.0, 0.5, 0.01, 100.0, 1e-9)))
    ints = st.one_of(st.sampled_from(EXTREME_INTS), st.integers(-3, 64), st.sampled_from((2, 3, 10, 100)))
    strings = st.one_of(st.sampled_from(options), st.sampled_from(INVALID_STRINGS))
    wrong = st.sampled_from((("obj",), {"a": 1}, b"rates", complex(1.0, 2.0), (1.0, "x"), {1.0, 2.0}, "1.0"))
    npscalar = st.tuples(st.just("npscalar"), st.sampled_from(("float32", "int64", "float64", "bool")),
                         st.sampled_from((0, 1, 3)))

    width = st.sampled_from((3, 3, 3, 4, 1, 2, 6, 7, 9, 15))
    form = st.sampled_from(("rows", "rows", "vector", "vector", "square", "stack", "scalar", "empty2", "matrix"))
    dtype = st.sampled_from(("float64",) * 8 + ("float32", "int64", "bool", "complex128", "object", "<U3"))
    layout = st.sampled_from(("C",) * 5 + ("F", "strided", "reversed"))
    specials = st.one_of(st.just(()), st.just(()), st.lists(
        st.tuples(st.integers(0, 10_000), st.sampled_from(SPECIAL_FLOATS)), min_size=1, max_size=2).map(tuple))
    fills = {"time": st.just("increasing"), "quat": st.sampled_from(("unit", "normal")),
             "square": st.sampled_from(("eye", "normal", "small")),
             "any": st.sampled_from(("normal", "small", "zeros", "ints", "increasing", "unit", "eye"))}

    @st.composite
    def array(d, fill, n):
        k = d(st.sampled_from((n,) * 12 + (0, 1, 2, n + 1, max(n - 1, 0), 30)))
        w, f = d(width), d(form)
        shape = {"rows": (k, w), "vector": (k,), "square": (w, w), "stack": (k, min(w, 6), min(w, 6)),
                 "scalar": (), "empty2": (0, w), "matrix": (w, d(width))}[f]
        return ("arr", shape, d(dtype), d(layout), d(fill), d(st.integers(0, 2**16)), d(specials))

    def fill_of(name: str) -> str:
        lname = name.lower()
        return ("time" if lname in TIME_NAMES else "quat" if lname in QUAT_NAMES else
                "square" if lname in SQUARE_NAMES else "any")

    def clean(n):
        return st.builds(lambda shape, fill, seed: ("arr", shape, "float64", "C", fill, seed, ()),
                         st.one_of(st.tuples(st.just(n), width), st.just((n,)), st.tuples(width, width),
                                   st.tuples(st.just(n), st.sampled_from((1, 2, 3, 6)),
                                             st.sampled_from((1, 2, 3, 6)))),
                         st.sampled_from(("normal", "small", "increasing", "unit", "eye")), st.integers(0, 2**16))

    instance = st.tuples(st.just("instance"), st.integers(0, 2**16))
    valid_options = st.sampled_from(options)
    cache: dict = {}

    def value(param: Param, hostile: bool, n: int):
        """The strategy for one parameter (built once per name, default, mood and row
        count ``n``): a plausible value, or (``hostile``) anything."""
        key = (param.name, repr(param.default), hostile, n)
        if key not in cache:
            cache[key] = _hostile(param, n) if hostile else _plausible(param, n)
        return cache[key]

    def _plausible(param: Param, n: int):
        lname = param.name.lower()
        d = param.default
        if d is not inspect.Parameter.empty and d is not Ellipsis and d is not None:
            same = {bool: st.booleans(), int: st.integers(0, 20), float: st.floats(1e-3, 10.0),
                    str: valid_options}.get(type(d))
            return st.one_of(st.just(d), same) if same is not None else st.just(d)
        if lname in COUNT_NAMES or "seed" in lname:
            return st.integers(0, 20)
        if lname in OPTION_NAMES:
            return valid_options
        if lname in INSTANCE_NAMES:
            return instance
        c = clean(n)
        if d is None:
            return st.one_of(st.none(), c, instance)
        return st.one_of(c, c, c.map(lambda s: ("list", s)), st.floats(1e-3, 100.0), instance)

    def _hostile(param: Param, n: int):
        arrays = array(fills[fill_of(param.name)], n)
        return st.one_of(arrays, arrays, arrays.map(lambda s: ("list", s)), floats, ints, st.none(), strings,
                         wrong, npscalar, st.booleans(), instance)

    return value


# ----------------------------------------------------------------------------------------
# the worker


def _finite(x, depth=0) -> bool:
    """True if no float in ``x`` (arrays, frames, containers, dataclasses) is NaN or inf."""
    if depth > 4:
        return True
    if isinstance(x, (float, np.floating, complex, np.complexfloating)):
        return bool(np.isfinite(x))
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "fc":
            return bool(np.isfinite(x).all())
        if x.dtype == object:
            return all(_finite(v, depth + 1) for v in x.ravel()[:10_000])
        return True
    if hasattr(x, "select_dtypes") and hasattr(x, "to_numpy"):  # DataFrame
        return _finite(x.select_dtypes(include=["number"]).to_numpy(dtype=float, na_value=np.nan), depth + 1)
    if hasattr(x, "dtype") and hasattr(x, "to_numpy"):  # Series
        return x.dtype.kind not in "fc" or _finite(x.to_numpy(), depth + 1)
    if isinstance(x, dict):
        return all(_finite(v, depth + 1) for v in x.values())
    if isinstance(x, (list, tuple)):
        return all(_finite(v, depth + 1) for v in x[:10_000])
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return all(_finite(getattr(x, f.name), depth + 1) for f in dataclasses.fields(x))
    return True


def _reads_keyword(fn, name) -> bool:
    """Whether ``fn`` takes ``**kwargs`` and ``name`` can be one of them: such a callable
    (e.g. ``Layout.covariance(**sigma)``, one keyword per state block) names the keyword it
    read or missed."""
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    return isinstance(name, str) and name.isidentifier() and any(p.kind == p.VAR_KEYWORD for p in params)


def classify(t: Target, fn, kwargs: dict) -> tuple[str, str, float, str | None]:
    """Call ``fn(**kwargs)``: (outcome class, message, seconds, class name of an API
    instance it returned)."""
    import atomnav

    start = time.perf_counter()
    made = None
    try:
        result = fn(**kwargs)
    except atomnav.InputError as e:
        p = getattr(e, "parameter", None)
        base = str(p).split(".")[0].split("[")[0] if p is not None else None
        cls = "InputError" if base in t.param_names() or _reads_keyword(fn, base) else "InputError(bad parameter)"
        return cls, f"parameter={p!r}: {e}", time.perf_counter() - start, None
    except TypeError as e:
        return "TypeError", str(e), time.perf_counter() - start, None
    except MemoryError as e:
        return "MemoryError", str(e), time.perf_counter() - start, None
    except atomnav.NumericalError as e:
        return "NumericalError", str(e), time.perf_counter() - start, None
    except OSError as e:
        return "OSError", str(e), time.perf_counter() - start, None
    except BaseException as e:  # noqa: BLE001 - every other exception is a finding
        name = type(e).__name__
        return ("PanicException" if name == "PanicException" else f"{name}"), str(e)[:500], \
            time.perf_counter() - start, None
    dt = time.perf_counter() - start
    qual = f"{type(result).__module__}.{type(result).__qualname__}"
    if qual in CONSTRUCTIBLE:
        made = qual
    if not t.nonfinite_documented and _finite(list(kwargs.values())) and not _finite(result):
        return "non-finite", "NaN or inf in the output of a call with finite inputs", dt, made
    return "ok", "", dt, made


def worker_main(out_fd: int) -> None:
    """Serve batches of calls read from stdin (length-prefixed pickles) until EOF,
    answering each call as soon as it returns."""
    import resource
    import warnings

    limit = int(os.environ.get("ATOMNAV_FUZZ_MEMORY", MEMORY_LIMIT))
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    warnings.simplefilter("ignore")
    _init_targets()
    out = os.fdopen(out_fd, "wb")
    inp = sys.stdin.buffer
    _send(out, "ready")
    while True:
        batch = _recv(inp)
        if batch is None:
            return
        for call in batch:
            _send(out, _serve(call))


def _serve(call: dict):
    """(outcome class, message, seconds of the call, class name of an API instance it
    returned, worker seconds in all: building the arguments and the instance too, seconds
    building the instance)."""
    start = time.perf_counter()
    t = TARGETS_BY_NAME[call["target"]]
    try:
        instance = build(call["this"]) if call["this"] is not None else None
        built = time.perf_counter() - start
        kwargs = {k: build(v) for k, v in call["kwargs"].items()}
    except BaseException as e:  # noqa: BLE001 - building an instance is itself a call of the API
        took = time.perf_counter() - start
        return "setup", f"{type(e).__name__}: {e}"[:300], 0.0, None, took, took
    return *classify(t, callee(t, instance), kwargs), time.perf_counter() - start, built


def _send(f, obj) -> None:
    data = pickle.dumps(obj)
    f.write(struct.pack("<I", len(data)) + data)
    f.flush()


def _recv(f):
    head = f.read(4)
    if len(head) < 4:
        return None
    return pickle.loads(f.read(struct.unpack("<I", head)[0]))


class Worker:
    """A worker subprocess running one batch of calls at a time: ``submit`` sends a batch,
    ``answer`` returns the answer to its next call, or ``abort``/``hang``."""

    def __init__(self, timeout: float):
        self.timeout = timeout
        r, w = os.pipe()
        env = dict(os.environ, RAYON_NUM_THREADS="2", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
                   MKL_NUM_THREADS="1", MPLBACKEND="Agg", PYTHONPATH=os.pathsep.join(
                       [os.path.dirname(os.path.abspath(__file__)), os.environ.get("PYTHONPATH", "")]))
        self.dir = tempfile.TemporaryDirectory(prefix="atomnav-fuzz-")
        self.proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker", str(w)],
                                     stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     pass_fds=(w,), cwd=self.dir.name, env=env, start_new_session=True)
        os.close(w)
        self.fd = r
        self.ready = False

    def _read(self, n: int, deadline: float) -> bytes | None:
        buf = b""
        while len(buf) < n:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self.fd], [], [], left)[0]:
                raise TimeoutError
            chunk = os.read(self.fd, n - len(buf))
            if not chunk:
                return None
            buf += chunk
        return buf

    def receive(self, timeout: float):
        deadline = time.monotonic() + timeout
        head = self._read(4, deadline)
        if head is None:
            return None
        body = self._read(struct.unpack("<I", head)[0], deadline)
        return None if body is None else pickle.loads(body)

    def wait_ready(self) -> None:
        if not self.ready:
            if self.receive(300.0) != "ready":
                raise RuntimeError(f"fuzz worker failed to start (exit code {self.proc.poll()})")
            self.ready = True

    def submit(self, batch: list[dict]) -> bool:
        """Send a batch; False if the worker is already dead."""
        self.wait_ready()
        data = pickle.dumps(batch)
        try:
            self.proc.stdin.write(struct.pack("<I", len(data)) + data)
            self.proc.stdin.flush()
        except (BrokenPipeError, OSError):
            return False
        return True

    def answer(self):
        """The answer to the next call of the batch. Waiting starts now, so a ``hang``
        (no answer within the timeout) is a call that ran for at least that long."""
        start = time.monotonic()
        try:
            answer = self.receive(self.timeout)
        except TimeoutError:
            self.close()
            return "hang", f"no answer within {self.timeout:g} s", self.timeout, None, self.timeout, 0.0
        except OSError:
            answer = None
        if answer is None:
            return self.died(time.monotonic() - start)
        return answer

    def died(self, seconds: float):
        code = self.proc.wait()
        self.close()
        how = f"killed by signal {signal.Signals(-code).name}" if code < 0 else f"exited with code {code}"
        return "abort", f"worker {how}", seconds, None, seconds, 0.0

    def close(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        with contextlib.suppress(OSError):
            self.proc.stdin.close()
        with contextlib.suppress(OSError):
            os.close(self.fd)
        self.dir.cleanup()


class Pool:
    """``jobs`` live workers and a warm spare, so a dead worker costs no import time."""

    def __init__(self, timeout: float, jobs: int):
        self.timeout = timeout
        self.workers = [Worker(timeout) for _ in range(jobs)]
        self.spare = Worker(timeout)
        self.restarts = 0
        POOLS.append(self)

    def replace(self, i: int) -> None:
        self.workers[i].close()
        self.workers[i], self.spare = self.spare, Worker(self.timeout)
        self.restarts += 1

    def close(self) -> None:
        for w in self.workers + [self.spare]:
            w.close()
        if self in POOLS:
            POOLS.remove(self)


POOLS: list[Pool] = []  # open pools, closed on SIGTERM


def _terminate(*_) -> None:
    """SIGTERM: kill the workers (they run in sessions of their own) and exit at once
    (hypothesis would treat a SystemExit raised inside a test as a failure to replay)."""
    for pool in list(POOLS):
        pool.close()
    os._exit(143)


# ----------------------------------------------------------------------------------------
# a campaign


TARGETS: list[Target] = []
TARGETS_BY_NAME: dict[str, Target] = {}
CONSTRUCTIBLE: set[str] = set()


def _init_targets() -> None:
    if not TARGETS:
        TARGETS.extend(enumerate_targets())
        TARGETS_BY_NAME.update({t.name: t for t in TARGETS})
        CONSTRUCTIBLE.update(t.owner for t in TARGETS if t.owner)


def select_targets(targets: list[Target], only: list[str] | None) -> list[Target]:
    """The targets whose dotted name starts with one of ``only`` (or matches it as a
    shell pattern, e.g. ``atomnav._core.*allan*``); all of them without ``only``."""
    if not only:
        return list(targets)
    return [t for t in targets if any(t.name.startswith(o) or fnmatch.fnmatchcase(t.name, o) for o in only)]


@dataclasses.dataclass
class Record:
    target: str
    outcome: str
    message: str
    seconds: float
    call: str


@dataclasses.dataclass
class Campaign:
    """Outcome counts of every call made, the first reproducers of each bad (callable,
    class) pair and the slowest calls. ``calls`` counts the calls made, not the ones
    skipped (``SKIPPED``)."""

    seed: int
    targets: list[Target]
    calls: int = 0
    seconds: float = 0.0
    restarts: int = 0
    waited: float = 0.0  # seconds the campaign waited for workers (the rest it spent drawing)
    counts: Counter = dataclasses.field(default_factory=Counter)  # outcome -> calls (skipped too)
    pairs: Counter = dataclasses.field(default_factory=Counter)  # (callable, outcome) -> calls
    spent: Counter = dataclasses.field(default_factory=Counter)  # callable -> worker seconds in all
    kept: list[Record] = dataclasses.field(default_factory=list)  # bad calls, REPRO_KEEP per pair
    slowest: list = dataclasses.field(default_factory=list)  # (seconds, n, target, outcome, call spec)

    def add(self, target: str, outcome: str, message: str = "", seconds: float = 0.0, call=None,
            total: float = 0.0) -> None:
        """One drawn call: its outcome, the seconds of the call itself and the worker
        seconds in all (building its arguments and instance too)."""
        self.counts[outcome] += 1
        self.pairs[(target, outcome)] += 1
        self.spent[target] += total
        if outcome in SKIPPED:
            return
        self.calls += 1
        if outcome not in GOOD and self.pairs[(target, outcome)] <= REPRO_KEEP:
            self.kept.append(Record(target, outcome, message, seconds, render_call(*call)))
        entry = (seconds, self.calls, target, outcome, call)
        if len(self.slowest) < SLOWEST:
            heapq.heappush(self.slowest, entry)
        elif seconds > self.slowest[0][0]:
            heapq.heapreplace(self.slowest, entry)

    def bad(self) -> list[Record]:
        """The kept reproducers of bad calls (``REPRO_KEEP`` per pair; ``n_bad`` counts all)."""
        return list(self.kept)

    @property
    def n_bad(self) -> int:
        return sum(n for (_, cls), n in self.pairs.items() if cls not in GOOD + SKIPPED)

    def first_failures(self) -> dict[tuple[str, str], tuple[Record, int]]:
        """First reproducing call and count per (callable, bad class)."""
        out: dict[tuple[str, str], tuple[Record, int]] = {}
        for r in self.kept:
            out.setdefault((r.target, r.outcome), (r, self.pairs[(r.target, r.outcome)]))
        return out

    def report(self) -> str:
        skipped = sum(self.counts[s] for s in SKIPPED)
        rate = self.calls / self.seconds if self.seconds else 0.0
        lines = [f"# atomnav fuzz campaign (seed {self.seed})", "",
                 f"{self.calls} calls made over {len(self.targets)} public callables in {self.seconds:.0f} s "
                 f"({rate:.0f} calls/s); {skipped} drawn calls not made ({', '.join(SKIPPED)}); "
                 f"{self.restarts} worker restarts; {sum(self.spent.values()):.0f} worker seconds; "
                 f"{self.waited:.0f} s waiting for workers.", "", "## Outcomes", "", "| class | calls | bad |",
                 "|---|---:|---|"]
        for cls, n in sorted(self.counts.items(), key=lambda kv: -kv[1]):
            lines.append(f"| {cls} | {n} | {'' if cls in GOOD + SKIPPED else 'yes'} |")
        fails = self.first_failures()
        funcs = sorted({k[0] for k in fails})
        lines += ["", f"## Failing callables ({len(funcs)}; {len(fails)} (callable, class) pairs)", ""]
        for (target, cls), (rec, n) in sorted(fails.items()):
            lines += [f"### `{target}` — {cls} ({n}×)", "", f"{_md(rec.message)}", "", "```python", rec.call, "```", ""]
        lines += ["## Slowest calls", "", "| s | callable | class | call |", "|---:|---|---|---|"]
        lines += [f"| {s:.2f} | `{target}` | {cls} | `{_md(render_call(*call))[:200]}` |"
                  for s, _, target, cls, call in sorted(self.slowest, reverse=True)]
        lines += ["", "## Callables by worker time", "", "| s | calls | callable |", "|---:|---:|---|"]
        made = Counter()
        for (target, cls), n in self.pairs.items():
            if cls not in SKIPPED:
                made[target] += n
        lines += [f"| {s:.2f} | {made[target]} | `{target}` |" for target, s in self.spent.most_common(SLOWEST)]
        ok = {target for (target, cls) in self.pairs if cls == "ok"}
        never = sorted(t.name for t in self.targets if t.name not in ok)
        lines += ["", f"## Callables never answered ok ({len(never)})", "", ", ".join(f"`{n}`" for n in never), ""]
        return "\n".join(lines)


def _md(s: str) -> str:
    return s.replace("\n", " ").replace("|", "\\|")[:400]


def _plain_dataclass(cls) -> bool:
    """A dataclass without checks of its own (``__post_init__``): any fields make one, so
    an instance it built is no evidence of a usable object (results are built by the
    functions that return them)."""
    return dataclasses.is_dataclass(cls) and not hasattr(cls, "__post_init__")


def _instances(spec, made: list):
    """An ``('instance', i)`` placeholder replaced by the i-th (mod) call that built an
    instance of an API class so far (None before any did)."""
    if isinstance(spec, tuple) and spec and spec[0] == "instance":
        return made[spec[1] % len(made)] if made else None
    return spec


REPRO_HEADER = "import numpy as np, atomnav; from numpy import nan, inf; from fuzz import arr"


class _Runner:
    """The state of one campaign: instance recipes, quarantine, time budgets, and the
    batches the workers run while the next one is drawn."""

    def __init__(self, c: Campaign, calls: int, timeout: float, budget: float, jobs: int):
        self.c = c
        self.target_calls = calls
        self.budget = budget
        self.recipes: dict[str, list] = defaultdict(list)  # class -> specs of calls that built one
        self.failures: Counter = Counter()
        self.slow_factories: set[str] = set()  # factories that took RECIPE_MAX_S or longer
        self.submitted = 0  # calls made or in flight
        self.pool = Pool(timeout, jobs)
        self.running: deque = deque()  # (worker, [(target, kwargs, this)]) of the batches running
        self.idle = 0  # drawn batches in a row of which no call was made
        self.batches = 0

    def prepare(self, drawn: list[tuple]) -> list[tuple]:
        """The calls of a drawn batch that will be made; the others are recorded as skipped.
        Instances and quarantine are looked up here, after every draw of the batch."""
        made = [s for specs in self.recipes.values() for s in specs]
        out = []
        for t, pick, kwargs, factory in drawn:
            if self.submitted + len(out) >= self.target_calls:
                break
            if any(self.failures[(t.name, k)] >= v for k, v in QUARANTINE.items()):
                self.c.add(t.name, "quarantined")
                continue
            if self.c.spent[t.name] > self.budget:
                self.c.add(t.name, "over time budget")
                continue
            this = None
            if t.owner is not None:
                if self.recipes[t.owner]:
                    this = self.recipes[t.owner][pick % len(self.recipes[t.owner])]
                elif factory and factory[1] not in self.slow_factories:
                    this = ("call", factory[1], {k: _instances(v, made) for k, v in factory[2].items()}, None)
                else:
                    self.c.add(t.name, "no instance")
                    continue
            out.append((t.name, {k: _instances(v, made) for k, v in kwargs.items()}, this))
        return out

    def submit(self, batch: list[tuple]) -> None:
        """Run a batch on a free worker (collecting the oldest running batch if none is)."""
        if not batch:
            return
        if len(self.running) == len(self.pool.workers):
            self.collect_oldest()
        busy = {i for i, _ in self.running}
        i = next(i for i in range(len(self.pool.workers)) if i not in busy)
        self.submitted += len(batch)
        self._send(i, batch)
        self.running.append((i, batch))

    def _send(self, i: int, batch: list[tuple]) -> None:
        while not self.pool.workers[i].submit([{"target": a, "kwargs": k, "this": s} for a, k, s in batch]):
            self.pool.replace(i)

    def collect(self) -> None:
        """The answers to every running batch."""
        while self.running:
            self.collect_oldest()

    def collect_oldest(self) -> None:
        """The answers to the oldest running batch. After an abort or a hang the rest of the
        batch goes to a fresh worker."""
        i, batch = self.running.popleft()
        k = 0
        while k < len(batch):
            waiting = time.monotonic()
            answer = self.pool.workers[i].answer()
            self.c.waited += time.monotonic() - waiting
            call = batch[k]
            k += 1
            self._record(call, *answer)
            if answer[0] in ("abort", "hang"):
                self.failures[(call[0], answer[0])] += 1
                self.pool.replace(i)
                rest = self.prepare_again(batch[k:])
                self.submitted -= len(batch) - k - len(rest)
                if rest:
                    self._send(i, rest)
                batch, k = rest, 0

    def prepare_again(self, rest: list[tuple]) -> list[tuple]:
        out = []
        for call in rest:
            if any(self.failures[(call[0], k)] >= v for k, v in QUARANTINE.items()):
                self.c.add(call[0], "quarantined")
            else:
                out.append(call)
        return out

    def _record(self, call: tuple, outcome: str, message: str, secs: float, made, total: float,
                built: float) -> None:
        target, kwargs, this = call
        if outcome == "setup":
            self.submitted -= 1
        self.c.add(target, outcome, message, secs, call, total)
        t = TARGETS_BY_NAME[target]
        if outcome == "ok" and made is not None and secs < RECIPE_MAX_S:
            self._recipe(made, ("call", target, kwargs, this), t)
        if t.owner is not None and this not in self.recipes[t.owner] and outcome not in ("abort", "hang"):
            # an instance built by a factory (no earlier call had built one)
            if outcome != "setup" and built < RECIPE_MAX_S:
                self._recipe(t.owner, this, TARGETS_BY_NAME[this[1]])
            elif built >= RECIPE_MAX_S:
                self.slow_factories.add(this[1])

    def _recipe(self, cls: str, spec: tuple, t: Target) -> None:
        if len(self.recipes[cls]) < RECIPES and spec not in self.recipes[cls] \
                and not (t.kind == "constructor" and _plain_dataclass(resolve(t.module, t.qualname))):
            self.recipes[cls].append(spec)


def campaign(calls: int, seed: int, timeout: float = TIMEOUT_S, progress=None, only=None,
             budget: float | None = None, jobs: int = JOBS) -> Campaign:
    """Make ``calls`` calls drawn by hypothesis (fixed ``seed``) in worker processes.

    Each hypothesis example draws a batch of calls; ``jobs`` workers run batches while
    the next one is drawn. ``only``: name prefixes or patterns of the callables to fuzz (all by
    default). ``budget``: worker seconds per callable (default ``TIME_BUDGET_S``, scaled
    up for campaigns longer than ``CI_CALLS``). ``progress(campaign so far)`` is called
    about every ``PROGRESS_S`` seconds."""
    from hypothesis import HealthCheck, Phase, given, settings, strategies as st
    from hypothesis import seed as hseed

    _init_targets()
    targets = select_targets(TARGETS, only)
    if not targets:
        raise ValueError(f"no public callable matches {only}")
    value = strategies(TARGETS)
    c = Campaign(seed, targets)
    if budget is None:
        budget = TIME_BUDGET_S * max(1.0, calls / CI_CALLS)
    run = _Runner(c, calls, timeout, budget, jobs)
    start = time.monotonic()
    last = [start]
    pick_target = st.integers(0, len(targets) - 1)
    pick_instance = st.integers(0, 2**16)
    pick_rows = st.sampled_from(ROWS)
    factories = {owner: [f for f in TARGETS if (f.name == owner and not _plain_dataclass(resolve(f.module, f.qualname)))
                         or (f.kind == "static" and f.name.startswith(owner + "."))]
                 for owner in {t.owner for t in targets if t.owner}}
    hostile_of = {k: st.integers(-2, k - 1) for k in range(max(len(t.params) for t in targets) + 1)}
    passed = {True: st.sampled_from((True,) * 30 + (False,)), False: st.sampled_from((True, True, False))}

    def draw_kwargs(draw, t: Target, hostile: int, n: int) -> dict:
        kwargs = {}
        for i, p in enumerate(t.params):
            if draw(passed[p.default is inspect.Parameter.empty]):
                kwargs[p.name] = draw(value(p, hostile in (i, -2), n))
        return kwargs

    def draw_call(draw):
        t = targets[draw(pick_target)]
        pick, n = draw(pick_instance), draw(pick_rows)
        # one hostile argument (or none, or all) among plausible ones
        kwargs = draw_kwargs(draw, t, draw(hostile_of[len(t.params)]), n)
        # a method also draws a plausible call of a factory of its class, its instance when
        # no earlier call has built one
        made = factories.get(t.owner)
        if made:
            f = made[draw(st.integers(0, len(made) - 1))]
            made = ("call", f.name, draw_kwargs(draw, f, -1, n), None)
        return t, pick, kwargs, made

    def one(data):
        # every draw is made whatever the state of the campaign (hypothesis replays choice
        # sequences); instances and quarantine are looked up once the batch is drawn, while
        # the previous batch runs
        cd = getattr(data, "conjecture_data", data)
        drawn = []
        while len(drawn) < BATCH and getattr(cd, "length", 0) < BATCH_LENGTH:
            drawn.append(draw_call(cd.draw))
        batch = run.prepare(drawn)
        run.batches += 1
        run.idle = 0 if batch else run.idle + 1
        run.submit(batch)
        if progress is not None and time.monotonic() - last[0] > PROGRESS_S:
            last[0] = time.monotonic()
            c.seconds, c.restarts = last[0] - start, run.pool.restarts
            progress(c)

    try:
        for round_ in itertools.count():  # each round tops up the calls the previous ones did not make
            # examples for the calls still to make, at the rate of made calls per batch so far
            per_batch = c.calls / run.batches if run.batches else BATCH
            # (at least TOPUP_EXAMPLES: a few draws can all be skipped; prepare() stops at `calls`)
            examples = max(math.ceil((calls - c.calls) / max(per_batch, 1.0)), TOPUP_EXAMPLES)
            before = c.calls
            empty_rounds = 0 if round_ == 0 else empty_rounds
            settings(max_examples=examples, database=None, deadline=None, phases=[Phase.generate],
                     suppress_health_check=list(HealthCheck), report_multiple_bugs=False)(
                hseed(seed if round_ == 0 else seed * 7919 + round_)(given(st.data())(one)))()
            run.collect()
            empty_rounds = empty_rounds + 1 if c.calls == before else 0
            # a short top-up round can draw only calls that are skipped: give up after a few
            if c.calls >= calls or empty_rounds > IDLE_ROUNDS or run.idle > IDLE_BATCHES:
                break
    finally:
        run.pool.close()
    c.seconds, c.restarts = time.monotonic() - start, run.pool.restarts
    return c


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--calls", type=int, default=CI_CALLS, help="calls to make (skipped draws not counted)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=TIMEOUT_S, help="seconds before a call counts as a hang")
    ap.add_argument("--only", action="append", default=None, metavar="PREFIX",
                    help="fuzz only the callables whose dotted name starts with PREFIX or matches it as a "
                         "shell pattern (comma-separated or repeated), e.g. atomnav.noise,atomnav._core.allan*")
    ap.add_argument("--budget", type=float, default=None,
                    help=f"worker seconds per callable (default {TIME_BUDGET_S:g}, scaled up beyond {CI_CALLS} calls)")
    ap.add_argument("--jobs", type=int, default=JOBS, help="worker processes")
    ap.add_argument("--out", default=None, help="markdown report (default: stdout)")
    ap.add_argument("--worker", type=int, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker is not None:
        worker_main(a.worker)
        return 0
    only = [o.strip() for arg in a.only for o in arg.split(",") if o.strip()] if a.only else None

    def write(c: Campaign) -> None:
        text = c.report() + f"\nReproducers assume `{REPRO_HEADER}` (run from tests/).\n"
        if a.out:
            with open(a.out, "w") as f:
                f.write(text)
        print(f"{c.calls} calls, {c.n_bad} bad, {c.seconds:.0f} s", file=sys.stderr, flush=True)

    signal.signal(signal.SIGTERM, _terminate)
    c = campaign(a.calls, a.seed, a.timeout, progress=write, only=only, budget=a.budget, jobs=a.jobs)
    write(c)
    if not a.out:
        print(c.report())
    return 1 if c.n_bad else 0


if __name__ == "__main__":
    sys.exit(main())
