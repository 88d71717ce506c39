"""The public API documents itself in numpydoc form (parsed by numpydoc itself): every public function, method and
class of ``atomnav`` that takes arguments has a ``Parameters`` section naming each of
them (a class: in its own docstring, or ``Attributes`` for a result a user only
receives), and every function or method that returns something a ``Returns`` (or
``Yields``) section. A new public callable without them fails here, by name."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import warnings

import pytest
from numpydoc.docscrape import NumpyDocString

import atomnav as an

SKIP_MODULES = (".reproduce", ".cli", "._")  # the report generator, the CLI (argparse help), private modules


def public_modules():
    out = []
    for m in pkgutil.walk_packages(an.__path__, "atomnav."):
        if any(s in m.name for s in SKIP_MODULES) or m.name.endswith("_core"):
            continue
        out.append(importlib.import_module(m.name))
    return out


def documented_names(entries) -> set[str]:
    """Names of the entries of a numpydoc Parameters/Attributes section (``a, b : type``
    documents both; ``*args``/``**kwargs`` keep no stars)."""
    return {n.strip().lstrip("*") for e in entries for n in e.name.split(",")}


def parameters(obj) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [p.name for p in sig.parameters.values() if p.name not in ("self", "cls")]


def returns_something(func) -> bool:
    ann = inspect.signature(func).return_annotation
    return ann not in (None, "None") and not (ann is inspect.Signature.empty and func.__name__.startswith("__"))


def callables():
    """(qualified name, object, kind) of every public function, class and method."""
    seen = set()
    for mod in public_modules():
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != mod.__name__ or id(obj) in seen:
                continue
            seen.add(id(obj))
            if inspect.isfunction(obj):
                yield f"{mod.__name__}.{name}", obj, "function"
            elif inspect.isclass(obj) and not issubclass(obj, BaseException):
                yield f"{mod.__name__}.{name}", obj, "class"
                for mname, m in vars(obj).items():
                    if mname.startswith("_") or not (inspect.isfunction(m) or isinstance(m, (staticmethod, classmethod))):
                        continue
                    yield f"{mod.__name__}.{name}.{mname}", getattr(obj, mname), "method"


def problems(name, obj, kind) -> list[str]:
    doc = inspect.getdoc(obj) or ""
    if not doc:
        return [f"{name}: no docstring"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpydoc warns of sections it does not know
        parsed = NumpyDocString(doc)
    out = []
    if kind == "class":
        params = [f.name for f in dataclasses.fields(obj) if f.init] if dataclasses.is_dataclass(obj) else parameters(obj)
        documented = documented_names(parsed["Parameters"]) | documented_names(parsed["Attributes"])
    else:
        params = parameters(obj)
        documented = documented_names(parsed["Parameters"])
        if returns_something(obj) and not (parsed["Returns"] or parsed["Yields"]):
            out.append(f"{name}: no Returns section")
    missing = [p for p in params if p not in documented]
    if missing:
        out.append(f"{name}: parameters not documented {missing}")
    return out


ALL = sorted((n, o, k) for n, o, k in callables())


@pytest.mark.parametrize("module", sorted({n.rsplit(".", 1)[0] if k != "method" else n.rsplit(".", 2)[0]
                                           for n, _, k in ALL}))
def test_public_api_is_documented_in_numpydoc(module):
    bad = [p for n, o, k in ALL if (n.rsplit(".", 2)[0] if k == "method" else n.rsplit(".", 1)[0]) == module
           for p in problems(n, o, k)]
    assert not bad, "\n".join(bad)
