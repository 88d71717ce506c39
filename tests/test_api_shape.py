"""The public API's shape: no function or constructor takes more than 8 positional
parameters (the rest are keyword-only or a typed configuration object), and every option
the core lists in `_core.OPTIONS` is rejected by name when misspelt."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

import atomnav
from atomnav import _core

MAX_POSITIONAL = 8
POSITIONAL = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)


def public_modules():
    yield atomnav
    yield _core
    for info in pkgutil.walk_packages(atomnav.__path__, "atomnav."):
        if not info.name.split(".")[-1].startswith("_"):
            yield importlib.import_module(info.name)


def public_callables():
    """(qualified name, callable) for every public function, class and method defined in
    atomnav (not re-exported from other libraries)."""
    seen = set()
    for module in public_modules():
        for name, obj in vars(module).items():
            if name.startswith("_") or id(obj) in seen:
                continue
            owner = getattr(obj, "__module__", "") or ""
            if not (owner.startswith("atomnav") or owner == "_core" or module is _core):
                continue
            if inspect.isclass(obj):
                seen.add(id(obj))
                yield f"{module.__name__}.{name}", obj
                for mname, meth in vars(obj).items():
                    if not mname.startswith("_") and callable(meth):
                        yield f"{module.__name__}.{name}.{mname}", meth
            elif callable(obj) and not inspect.ismodule(obj):
                seen.add(id(obj))
                yield f"{module.__name__}.{name}", obj


def positional_count(obj) -> int | None:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return None
    names = [p.name for p in sig.parameters.values() if p.kind in POSITIONAL]
    return len([n for n in names if n not in ("self", "cls", "$self", "$cls")])


def test_public_api_is_enumerated():
    names = {n for n, _ in public_callables()}
    assert "atomnav.strapdown.integrate" in names
    assert any(n.startswith("atomnav._core.") for n in names)


def test_no_callable_takes_more_than_eight_positional_parameters():
    wide = sorted(f"{name} ({n})" for name, obj in public_callables()
                  if (n := positional_count(obj)) is not None and n > MAX_POSITIONAL)
    assert wide == []


@pytest.mark.parametrize("option", sorted(_core.OPTIONS))
def test_option_lists_are_published(option):
    names = _core.OPTIONS[option]
    assert names and all(isinstance(n, str) and n for n in names)
    assert len(set(names)) == len(names)
