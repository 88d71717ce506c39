#!/usr/bin/env bash
# The README's test command: from a fresh clone, create .venv, build and install atomnav
# (release wheel through maturin), run the Python suite, then clippy's no-panic lints, the
# Rust unit and property tests, and compile (not run) the criterion benches so a broken
# bench fails here.
# Extra arguments go to pytest (e.g. `bash tests/run.sh -m slow` for the full-size runs).
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install ".[test]"
# RTKLIB's rnx2rtkp, the peer of the GNSS tests (they skip where it cannot be installed)
if ! command -v rnx2rtkp >/dev/null && command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    (apt-get update -qq && apt-get install -y -qq rtklib) >/dev/null 2>&1 || echo "rtklib not installed: the RTKLIB comparisons skip" >&2
fi
.venv/bin/python -m pytest tests "$@"
# No reachable panic in the core: unwrap, expect, panic! and unchecked indexing are denied
# in non-test code; each place where an invariant makes an index safe carries a justified
# #[allow] (tests may unwrap).
cargo clippy --version >/dev/null 2>&1 || rustup component add clippy
cargo clippy --release --lib --features python -- -D clippy::unwrap_used -D clippy::expect_used -D clippy::panic -D clippy::indexing_slicing
cargo test --release
cargo bench --no-run --quiet
