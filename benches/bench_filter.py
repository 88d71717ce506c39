"""Kalman filter engine vs peers, in one run:

* 15-state predict step (P ← ΦPΦᵀ + Q): atomnav (Rust loop over steps, one call) vs
  filterpy ``KalmanFilter.predict`` called per step (how it is used); the per-call
  atomnav path from Python is printed as well.
* 21-state DARE: atomnav (structure-preserving doubling) vs ``scipy.linalg.solve_discrete_are``.

    pip install filterpy scipy
    python benches/bench_filter.py [--steps 20000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.linalg

from atomnav.filter import KalmanFilter, dare
from timing import best_of, record




def system(n, m, rng):
    phi = rng.standard_normal((n, n))
    phi *= 0.95 / max(abs(np.linalg.eigvals(phi)))
    g = rng.standard_normal((n, n))
    q = g @ g.T / n + 1e-3 * np.eye(n)
    return phi, q, rng.standard_normal((m, n)), np.eye(m)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    from filterpy.kalman import KalmanFilter as FpKF

    rng = np.random.default_rng(1)
    phi, q, h, r = system(15, 3, rng)
    fp = FpKF(dim_x=15, dim_z=3)
    fp.F, fp.Q, fp.P = phi, q, np.eye(15)

    def run_fp():
        for _ in range(args.steps):
            fp.predict()

    kf = KalmanFilter(np.eye(15), mode="open")
    t_fp = best_of(run_fp, args.repeat)[0] / args.steps
    t_an = best_of(lambda: kf.predict(phi, q, steps=args.steps), args.repeat)[0] / args.steps
    n_call = max(args.steps // 10, 1)

    def run_calls():
        for _ in range(n_call):
            kf.predict(phi, q)

    t_call = best_of(run_calls, args.repeat)[0] / n_call
    print(f"15-state predict: filterpy {t_fp * 1e6:.2f} us/step, atomnav {t_an * 1e6:.2f} us/step "
          f"-> ratio {t_fp / t_an:.1f}x  (atomnav one Python call per step: {t_call * 1e6:.2f} us, ratio {t_fp / t_call:.1f}x)")
    record("15-state predict, one call for all steps", "filterpy KalmanFilter.predict", t_fp / t_an,
           note=f"{t_an * 1e6:.2f} us/step")
    record("15-state predict, one Python call per step", "filterpy KalmanFilter.predict", t_fp / t_call,
           note=f"{t_call * 1e6:.2f} us/step")

    phi, q, h, r = system(21, 6, rng)
    ref = scipy.linalg.solve_discrete_are(phi.T, h.T, q, r)
    got = dare(phi, q, h, r).p_prior
    reps = 50
    t_sp = best_of(lambda: [scipy.linalg.solve_discrete_are(phi.T, h.T, q, r) for _ in range(reps)], args.repeat)[0] / reps
    t_da = best_of(lambda: [dare(phi, q, h, r) for _ in range(reps)], args.repeat)[0] / reps
    rel = np.max(np.abs(got - ref)) / np.max(np.abs(ref))
    print(f"21-state DARE: scipy {t_sp * 1e6:.1f} us, atomnav {t_da * 1e6:.1f} us -> ratio {t_sp / t_da:.1f}x "
          f"(max rel. difference {rel:.1e})")
    record("21-state DARE", "scipy.linalg.solve_discrete_are", t_sp / t_da,
           note=f"max relative difference to the peer {rel:.1e}")


if __name__ == "__main__":
    main()
