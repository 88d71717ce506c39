"""The public API never kills the user's Python process: a fixed-seed share of fuzzed
calls (tests/fuzz.py: every public function, constructor and method of atomnav and
atomnav._core, arguments drawn by hypothesis from the signatures, batches of calls in
worker subprocesses that may abort or hang without taking the suite down) ends in no bad outcome — no exception other than InputError (naming a real
parameter), TypeError, MemoryError, NumericalError or OSError, no panic, no abort, no
hang, no NaN/inf output from finite input."""

import pytest

import fuzz
import fuzz_mistakes

CALLS = 20_000
SEED = 20261202


def _failures(c: fuzz.Campaign) -> str:
    lines = [f"{len(c.bad())} bad outcomes in {c.calls} calls; first reproducer per (callable, class):",
             fuzz.REPRO_HEADER]
    for (target, cls), (rec, n) in sorted(c.first_failures().items()):
        lines.append(f"# {target}: {cls} ({n}x): {rec.message[:200]}")
        lines.append(rec.call)
    return "\n".join(lines)


def _run(calls: int, seed: int) -> None:
    c = fuzz.campaign(calls, seed)
    assert c.calls == calls, f"the campaign made {c.calls} of {calls} calls"
    assert not c.bad(), _failures(c)


def test_fuzz_public_api():
    """The fixed-seed share CI runs: 20,000 calls with the whole contract."""
    _run(CALLS, SEED)


@pytest.mark.fuzz_long
@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_fuzz_public_api_long(seed):
    """Five more campaigns of 100,000 calls each (run with -m fuzz_long)."""
    _run(100_000, seed)


def _mistake_failures(c: fuzz_mistakes.Campaign) -> str:
    lines = [f"{c.n_bad} bad outcomes in {c.calls} mutated calls; first reproducer per (callable, class):",
             fuzz_mistakes.REPRO_HEADER]
    for (target, cls), (rec, n) in sorted(c.first_failures().items()):
        lines += [f"# {target}: {cls} ({n}x): {rec.message[:300]}", rec.call]
    return "\n".join(lines)


def _run_mistakes(thread_rounds: int) -> None:
    c = fuzz_mistakes.campaign(thread_rounds)
    assert c.calls > 0
    assert not c.n_bad, _mistake_failures(c)


def test_fuzz_realistic_mistakes():
    """The realistic mistakes (tests/fuzz_mistakes.py) on every catalogued clean call
    and stateful object: no result differs from the clean call's without an error or a
    warning, every unit mistake a documented rule can see warns or raises, 4 threads on one
    object never reach pyo3's borrow flag, and pickled or deep-copied objects continue bit
    for bit (a few seconds)."""
    _run_mistakes(fuzz_mistakes.THREAD_ROUNDS)


@pytest.mark.fuzz_long
def test_fuzz_realistic_mistakes_long():
    """The same with 20 thread rounds per stateful object (run with -m fuzz_long)."""
    _run_mistakes(20)
