"""The package looks finished: typed (``py.typed`` and a stub of the compiled core that
lists exactly its public names), licensed, and quick to import.

The stub ``python/atomnav/_core.pyi`` is generated here from the extension's own
introspection (pyo3 sets ``__text_signature__`` on functions, methods and classes):
``python tests/test_packaging.py`` rewrites it after a binding is added or changed.
"""

from __future__ import annotations

import ast
import inspect
import os
import statistics
import subprocess
import sys
from pathlib import Path

import atomnav
import atomnav._core as core

PACKAGE = Path(atomnav.__file__).parent
REPO = Path(__file__).resolve().parent.parent
STUB = PACKAGE / "_core.pyi"
HEADER = '"""Type stub of the compiled core ``atomnav._core``: generated from its introspection by\n' \
         '``python tests/test_packaging.py``, which also checks it."""\n\nfrom typing import Any'


def _public(obj) -> list[str]:
    return [n for n in dir(obj) if not n.startswith("_")]


def _type(value) -> str:
    """Annotation of a constant from its value (element types of lists, tuples, dicts)."""
    def union(items) -> str:
        names = sorted({_type(x) for x in items})
        return " | ".join(names) if names else "Any"

    if isinstance(value, (list, tuple)) and not value:
        return f"{type(value).__name__}[Any]" if isinstance(value, list) else "tuple[()]"
    if isinstance(value, list):
        return f"list[{union(value)}]"
    if isinstance(value, tuple):
        kinds = [_type(x) for x in value]
        return f"tuple[{kinds[0]}, ...]" if len(set(kinds)) == 1 else f"tuple[{', '.join(kinds)}]"
    if isinstance(value, dict):
        return f"dict[{union(value.keys())}, {union(value.values())}]"
    return "None" if value is None else type(value).__name__


def _params(fn, drop_first: bool = False) -> str:
    """The parameter list of pyo3's ``__text_signature__`` ('$self'/'$type' dropped)."""
    sig = getattr(fn, "__text_signature__", None)
    if sig is None:
        raise AssertionError(f"{fn!r} has no __text_signature__")
    params = sig.strip()[1:-1]
    parts = [p.strip() for p in params.split(",")] if params.strip() else []
    if parts and parts[0].startswith("$"):
        parts = parts[1:]
    return ", ".join(parts)


def _class(name: str, cls: type) -> list[str]:
    base = cls.__mro__[1].__name__ if len(cls.__mro__) > 1 and cls.__mro__[1] is not object else None
    lines = [f"class {name}({base}):" if base else f"class {name}:"]
    body = []
    if cls.__text_signature__ is not None:
        params = _params(cls)
        body.append(f"    def __init__(self{', ' + params if params else ''}) -> None: ...")
    for attr in _public(cls):
        raw = inspect.getattr_static(cls, attr)
        if isinstance(raw, staticmethod):
            body += ["    @staticmethod", f"    def {attr}({_params(getattr(cls, attr))}): ..."]
        elif attr in cls.__dict__ and inspect.ismethoddescriptor(raw) and not hasattr(raw, "__set__"):
            params = _params(raw)
            body.append(f"    def {attr}(self{', ' + params if params else ''}): ...")
        elif attr in cls.__dict__:
            body.append(f"    {attr}: Any")
    return lines + (body or ["    ..."])


def render_stub() -> str:
    """The stub text of ``atomnav._core`` as its introspection gives it today."""
    out = [HEADER]
    for name in _public(core):
        obj = getattr(core, name)
        if isinstance(obj, type):
            out.append("\n".join(_class(name, obj)))
        elif callable(obj):
            out.append(f"def {name}({_params(obj)}): ...")
        else:
            out.append(f"{name}: {_type(obj)}")
    return "\n\n".join(out) + "\n"


def _stub_names(text: str) -> set[str]:
    names = set()
    for node in ast.parse(text).body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def test_stub_lists_exactly_the_public_names_of_the_core():
    stub = _stub_names(STUB.read_text())
    public = set(_public(core))
    assert not public - stub, f"bindings without a stub (run `python tests/test_packaging.py`): {sorted(public - stub)}"
    assert not stub - public, f"stub names the core no longer has: {sorted(stub - public)}"


def test_stub_matches_the_core_signatures():
    assert STUB.read_text() == render_stub(), "the stub is stale: run `python tests/test_packaging.py`"


def test_stub_names_every_method_and_parameter():
    """An oracle independent of the renderer: the stub's parameters of each function and
    constructor are those inspect.signature reads from the core."""
    tree = {n.name: n for n in ast.parse(STUB.read_text()).body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    for name, node in tree.items():
        obj = getattr(core, name)
        if isinstance(node, ast.FunctionDef):
            a = node.args
            stub_args = [x.arg for x in a.posonlyargs + a.args + [a.vararg] + a.kwonlyargs + [a.kwarg] if x is not None]
            assert stub_args == list(inspect.signature(obj).parameters), name
        else:
            methods = {m.name for m in node.body if isinstance(m, ast.FunctionDef)} - {"__init__"}
            assert methods == {m for m in _public(obj) if m in vars(obj) and callable(getattr(obj, m))}, name


def test_typed_and_licensed():
    assert (PACKAGE / "py.typed").is_file()
    assert STUB.is_file()
    lic = (REPO / "LICENSE").read_text()
    assert lic.startswith("MIT License") and "the atomnav developers" in lic
    assert 'license = { text = "MIT" }' in (REPO / "pyproject.toml").read_text()


def _fresh(code: str, tmp_path: Path) -> str:
    """Run ``code`` in a fresh interpreter with byte-code caching on (into tmp_path, as an
    installed package has its .pyc files) and return its stdout."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPYCACHEPREFIX"] = str(tmp_path / "pycache")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert run.returncode == 0, run.stderr
    return run.stdout


def test_import_is_quick(tmp_path):
    code = "import time; t = time.perf_counter(); import atomnav; print(time.perf_counter() - t)"
    _fresh(code, tmp_path)  # writes the byte-code caches
    median = statistics.median(float(_fresh(code, tmp_path)) for _ in range(5))
    assert median < 0.3, f"import atomnav took {median:.3f} s (median of 5)"


def test_heavy_libraries_are_imported_on_use(tmp_path):
    heavy = ("scipy.stats", "statsmodels", "matplotlib", "dask")
    code = ("import sys, atomnav\nheavy = {!r}\n"
            "print(*[m for m in heavy if m in sys.modules])\n"
            "for name in atomnav.__all__: getattr(atomnav, name)\n"
            "print(*[m for m in heavy if m in sys.modules])").format(heavy)
    bare, touched = _fresh(code, tmp_path).splitlines()
    assert bare == "", f"import atomnav loads {bare}"
    assert touched == "", f"the public submodules load {touched} at import"


def test_static_imports_match_the_lazy_ones():
    """What type checkers see (the TYPE_CHECKING block) is what __getattr__ serves."""
    tree = ast.parse((PACKAGE / "__init__.py").read_text())
    block = next(n for n in tree.body if isinstance(n, ast.If) and "TYPE_CHECKING" in ast.unparse(n.test))
    names = {a.asname or a.name for imp in block.body for a in imp.names}
    assert names == set(atomnav._SUBMODULES) | set(atomnav._NAMES)


def test_lazy_names_are_the_real_objects():
    import importlib

    for name in atomnav.__all__:
        obj = getattr(atomnav, name)
        if inspect.ismodule(obj):
            assert obj is importlib.import_module(f"atomnav.{name}")
    from atomnav import UnitWarning
    from atomnav.plausibility import UnitWarning as direct

    assert UnitWarning is direct and "cai" in dir(atomnav)


if __name__ == "__main__":
    STUB.write_text(render_stub())
    print(f"wrote {STUB}")
