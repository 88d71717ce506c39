"""Wall-clock helper shared by the side-by-side benchmark scripts in this folder, and the
one machine-readable result line per workload that ``run_all.py`` collects."""

import json
import time

TAG = "ATOMNAV-RESULT"


def best_of(fn, repeat: int):
    """Run ``fn()`` ``repeat`` times; return (best wall time in s, last result)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def record(workload: str, peer: str | None, ratio: float | None, atomnav_accuracy: float | None = None,
           peer_accuracy: float | None = None, unit: str = "", note: str = "") -> None:
    """Print one tagged JSON line: ``ratio`` is atomnav speed / peer speed (None: no peer
    timed); the accuracies (None: not measured) are in ``unit`` on the same data; ``note``
    carries what the row needs besides (an absolute rate, an agreement between the two)."""
    def num(x):
        return None if x is None else float(x)

    print(TAG, json.dumps({"workload": workload, "peer": peer, "ratio": num(ratio),
                           "atomnav_accuracy": num(atomnav_accuracy), "peer_accuracy": num(peer_accuracy),
                           "unit": unit, "note": note}), flush=True)
