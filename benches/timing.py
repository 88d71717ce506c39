"""Wall-clock helper shared by the side-by-side benchmark scripts in this folder."""

import time


def best_of(fn, repeat: int):
    """Run ``fn()`` ``repeat`` times; return (best wall time in s, last result)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out
