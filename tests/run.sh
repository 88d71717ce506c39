#!/usr/bin/env bash
# The README's test command: from a fresh clone, create .venv, build and install atomnav
# (release wheel through maturin), run the Python suite, then the Rust unit tests, and
# compile (not run) the criterion benches so a broken bench fails here.
# Extra arguments go to pytest (e.g. `bash tests/run.sh -m slow` for the full-size runs).
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install ".[test]"
.venv/bin/python -m pytest tests "$@"
cargo test --release
cargo bench --no-run --quiet
