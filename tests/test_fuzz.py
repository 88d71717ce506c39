"""The public API never kills the user's Python process: a fixed-seed share of fuzzed
calls (tests/fuzz.py: every public function, constructor and method of atomnav and
atomnav._core, arguments drawn by hypothesis from the signatures, batches of calls in
worker subprocesses that may abort or hang without taking the suite down) ends in no bad outcome — no exception other than InputError (naming a real
parameter), TypeError, MemoryError, NumericalError or OSError, no panic, no abort, no
hang, no NaN/inf output from finite input."""

import pytest

import fuzz

CALLS = 20_000
SEED = 20261202
#: The outcomes that kill or crash a user's session; the default run guards these while the
#: full contract (every exception an InputError naming a real parameter, no NaN) is the
#: fuzz_long campaign's.
FATAL = ("abort", "PanicException")


def _failures(c: fuzz.Campaign) -> str:
    lines = [f"{len(c.bad())} bad outcomes in {c.calls} calls; first reproducer per (callable, class):",
             fuzz.REPRO_HEADER]
    for (target, cls), (rec, n) in sorted(c.first_failures().items()):
        lines.append(f"# {target}: {cls} ({n}x): {rec.message[:200]}")
        lines.append(rec.call)
    return "\n".join(lines)


def _run(calls: int, seed: int) -> None:
    c = fuzz.campaign(calls, seed)
    assert c.calls == calls
    assert not c.bad(), _failures(c)


def test_fuzz_never_aborts_or_panics():
    """A fixed-seed share of 2,000 calls: no call aborts the process or panics."""
    c = fuzz.campaign(2_000, SEED)
    fatal = [r for r in c.bad() if r.outcome in FATAL]
    assert not fatal, "\n".join(f"{r.target}: {r.outcome}: {r.call}" for r in fatal)


@pytest.mark.fuzz_long
def test_fuzz_public_api():
    """≥ 20,000 calls with the whole contract (run with -m fuzz_long)."""
    _run(CALLS, SEED)


@pytest.mark.fuzz_long
@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_fuzz_public_api_long(seed):
    """Five more campaigns of 100,000 calls each (run with -m fuzz_long)."""
    _run(100_000, seed)
