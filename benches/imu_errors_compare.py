"""Side-by-side timing: atomnav.imu.corrupt versus a vectorised numpy/scipy implementation
of the same model (white noise, bias random walk and first-order Gauss–Markov, all with
exact in-interval integrals) on 10⁶ samples of both triads. Prints both times and the ratio.

Run: .venv/bin/python benches/imu_errors_compare.py
"""

import math
import time

import numpy as np
from scipy.signal import lfilter

from atomnav import imu

N, DT = 1_000_000, 1e-3
WHITE, K, SIGMA, TAU = 1e-4, 1e-6, 1e-4, 5.0


def peer(f, w, seed):
    """The imu model in numpy: per-axis increments, divided by Δt (rate samples)."""
    rng = np.random.default_rng(seed)
    out = []
    for y in (f, w):
        z = rng.standard_normal((6, *y.shape))
        white = WHITE * math.sqrt(DT) * z[0]
        steps = K * math.sqrt(DT) * z[1]
        b = np.cumsum(steps, axis=0) - steps  # b at interval start, b(0) = 0
        rw = b * DT + K * DT**1.5 * (0.5 * z[1] + z[2] / (2 * math.sqrt(3)))
        a = math.exp(-DT / TAU)
        x = DT / TAU
        l11 = SIGMA * math.sqrt(1 - a * a)
        cov, var2 = SIGMA**2 * TAU * (1 - a) ** 2, 2 * SIGMA**2 * TAU**2 * (x - 2 * (1 - a) + (1 - a * a) / 2)
        l21 = cov / l11
        l22 = math.sqrt(max(var2 - l21 * l21, 0.0))
        e1 = l11 * z[3]
        e1[0] += SIGMA * z[5][0]  # stationary start
        m_end = lfilter([1.0], [1.0, -a], e1, axis=0)  # m_{k+1} = a m_k + ε₁
        m_start = np.vstack([SIGMA * z[5][:1], m_end[:-1]])
        gm = TAU * (1 - a) * m_start + l21 * z[3] + l22 * z[4]
        out.append(y + (white + rw + gm) / DT)
    return out


def main():
    f = np.tile([0.1, -0.2, -9.8], (N, 1))
    w = np.tile([1e-3, 2e-3, 0.1], (N, 1))
    t = imu.TriadErrors(white=WHITE, bias_rw=K, gauss_markov=imu.GaussMarkov(SIGMA, TAU))
    e = imu.ImuErrors(t, t)
    best = {}
    for name, fn in (("atomnav", lambda: imu.corrupt(f, w, errors=e, dt=DT, kind="rates", seed=1)), ("numpy/scipy", lambda: peer(f, w, 1))):
        fn()
        times = []
        for _ in range(3):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        best[name] = min(times)
        print(f"{name:12s} {best[name] * 1e3:8.1f} ms  ({N} samples, both triads)")
    print(f"ratio numpy/atomnav = {best['numpy/scipy'] / best['atomnav']:.2f} (> 1: atomnav faster)")


if __name__ == "__main__":
    main()
