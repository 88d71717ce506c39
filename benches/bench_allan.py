"""atomnav vs allantools: overlapping Allan deviation of 10⁷ rate samples at octave τ,
in one run, with the speed ratio; and the Eq. 17 adaptive Kalman filter over 10⁷
samples (wall time). Run: `.venv/bin/python benches/bench_allan.py [n]`."""

import sys
import time

import allantools
import numpy as np

from atomnav import _core
from atomnav.noise import allan, filters
from timing import best_of, record




def main(n: int = 10_000_000) -> None:
    rng = np.random.default_rng(105)
    y = 0.6851 + rng.normal(0.0, 0.1248, n)
    tau0 = 52.0
    t_core, core = best_of(lambda: _core.allan_var(y, tau0, "rate", "allan", "octave"), 3)
    t_api, table = best_of(lambda: allan.allan_variance(y, tau0), 3)
    t_peer, peer = best_of(lambda: allantools.oadev(y, rate=1 / tau0, data_type="freq", taus="octave"), 1)
    rel = np.max(np.abs(table["dev"].to_numpy() / peer[1] - 1))
    print(f"overlapping ADEV, {n:.0e} samples, {len(table)} octave τ (max relative difference {rel:.1e})")
    print(f"  allantools.oadev          {t_peer:8.3f} s")
    print(f"  atomnav core (_core)      {t_core:8.3f} s   ratio {t_peer / t_core:6.1f}x")
    print(f"  atomnav.noise.allan (+EDF/CI table) {t_api:8.3f} s   ratio {t_peer / t_api:6.1f}x")
    record(f"overlapping ADEV, {n:.0e} samples, octave tau (core)", "allantools.oadev", t_peer / t_core,
           note=f"max relative difference to the peer {rel:.1e}")
    record(f"overlapping ADEV, {n:.0e} samples, octave tau (with EDF/CI table)", "allantools.oadev", t_peer / t_api,
           note=f"max relative difference to the peer {rel:.1e}")
    model = filters.ArimaStateSpace.paper()
    for name, kw in [("fixed", {}), ("adaptive (differenced, Eq. 17)", {"adaptive": "differenced"})]:
        t_kf, _ = best_of(lambda: filters.kalman(y, model, record=False, **kw), 2)
        print(f"  Kalman {name:32s} {t_kf:8.3f} s for {n:.0e} samples ({t_kf / n * 1e9:.0f} ns/sample)")
        record(f"ARIMA Kalman {name}, {n:.0e} samples", None, None, note=f"{t_kf / n * 1e9:.0f} ns/sample")


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 10_000_000)
