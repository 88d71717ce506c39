"""The pyo3 layer (`rust/py/`) only converts: numpy in and out, options by name, errors,
the GIL. Algorithms, sample loops, threads and physics constants belong to the core, where
`cargo test` compiles and tests them. This scans the binding source to keep it that way."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

BINDINGS = Path(__file__).resolve().parents[1] / "rust" / "py"
# conversion helpers (numpy <-> nalgebra, dicts) are the one place allowed to iterate
CONVERSION_MODULE = "convert.rs"

LOOP = re.compile(r"(?<![\w.])(for\s+[\w(),\s&]+\s+in\b|while\b|loop\s*\{)")
THREAD = re.compile(r"\b(thread|spawn|mpsc|rayon|crossbeam|par_iter|into_par_iter)\b")
# any float literal but a zero initialiser
FLOAT = re.compile(r"(?<![\w.])(?!0\.0(?![\d.eE]))(\d+\.\d*(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+)(?![\w.])")


def _strip(source: str) -> str:
    """The code without comments, string literals or `#[pyo3(signature = ...)]` attributes
    (signature defaults are user-facing option values, documented with the function)."""
    out, i, n = [], 0, len(source)
    while i < n:
        if source.startswith("//", i):
            j = source.find("\n", i)
            i = n if j < 0 else j
        elif source.startswith("#[pyo3(", i):
            depth, j = 0, i + 1
            while j < n:
                depth += source[j] == "["
                depth -= source[j] == "]"
                if depth == 0:
                    break
                j += 1
            out.append("\n" * source.count("\n", i, j + 1))
            i = j + 1
        elif source[i] == '"':
            j = i + 1
            while j < n and source[j] != '"':
                j += 2 if source[j] == "\\" else 1
            out.append("\n" * source.count("\n", i, j + 1))
            i = j + 1
        elif source.startswith("'", i) and re.match(r"'(\\.|[^\\'])'", source[i:i + 4]):
            i += len(re.match(r"'(\\.|[^\\'])'", source[i:i + 4]).group(0))
        else:
            out.append(source[i])
            i += 1
    return "".join(out)


def _findings(path: Path) -> list[str]:
    code = _strip(path.read_text())
    found = []
    for lineno, line in enumerate(code.splitlines(), 1):
        where = f"{path.name}:{lineno}: {line.strip()}"
        if path.name != CONVERSION_MODULE and LOOP.search(line):
            found.append("loop " + where)
        if THREAD.search(line):
            found.append("thread " + where)
        if FLOAT.search(line):
            found.append("constant " + where)
    return found


def test_scanner_detects_what_it_forbids(tmp_path):
    sample = tmp_path / "sample.rs"
    sample.write_text(
        '#[pyo3(signature = (x, tol=1e-9))]\n'
        'fn f(x: f64) -> f64 {\n'
        '    // for k in 0..n { 2.5 }\n'
        '    let s = "0.5 for x in y";\n'
        '    for k in 0..3 { }\n'
        '    std::thread::spawn(|| ());\n'
        '    x * 299792458.0\n'
        '}\n')
    kinds = sorted(f.split()[0] for f in _findings(sample))
    assert kinds == ["constant", "loop", "thread"]


@pytest.mark.parametrize("path", sorted(BINDINGS.glob("*.rs")), ids=lambda p: p.name)
def test_binding_only_converts(path):
    assert _findings(path) == []
