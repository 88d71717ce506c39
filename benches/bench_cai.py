"""Atom strapdown predictor: atomnav (Rust) vs a straightforward numpy implementation of
the same equations (Tennstedt et al. 2023 Eqs. 5–8: RK4 per IMU interval, linear inputs, ω̇ from the
piecewise-linear gyro), timed side by side in one run; prints the ratio.

    python benches/bench_cai.py [--seconds 10] [--slow-seconds 1]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from atomnav import cai
from timing import record


def numpy_predict(t, f, w, shots, T, k, lever, v0):
    """Per shot, per channel: RK4 of ẍ = −f_s − 2ω×ẋ − ω×(ω×x) − ω̇×x with x(0) = 0,
    ẋ(0) = v0, f_s = f + ω̇×l + ω×(ω×l) (C_sb = I), on the IMU grid plus the pulse times."""
    out = np.empty((len(shots), len(k)))
    wd_int = np.diff(w, axis=0) / np.diff(t)[:, None]

    def inputs(tt):
        i = min(max(np.searchsorted(t, tt, side="right") - 1, 0), len(t) - 2)
        a = (tt - t[i]) / (t[i + 1] - t[i])
        return f[i] + a * (f[i + 1] - f[i]), w[i] + a * (w[i + 1] - w[i]), wd_int[i]

    for s, ts in enumerate(shots):
        knots = np.unique(np.concatenate([[ts, ts + T, ts + 2 * T], t[(t > ts) & (t < ts + 2 * T)]]))
        for c in range(len(k)):
            x, v = np.zeros(3), v0[c].copy()
            x_mid = None

            def acc(fb, wb, wdb, x, v):
                fs = fb + np.cross(wdb, lever[c]) + np.cross(wb, np.cross(wb, lever[c]))
                return -fs - 2 * np.cross(wb, v) - np.cross(wb, np.cross(wb, x)) - np.cross(wdb, x)

            for a, b in zip(knots[:-1], knots[1:]):
                h = b - a
                i0 = inputs(0.5 * (a + b))  # interval of the step
                st = [inputs(a), inputs(0.5 * (a + b)), inputs(b)]
                st = [(u[0], u[1], i0[2]) for u in st]
                k1x, k1v = v, acc(*st[0], x, v)
                k2x, k2v = v + 0.5 * h * k1v, acc(*st[1], x + 0.5 * h * k1x, v + 0.5 * h * k1v)
                k3x, k3v = v + 0.5 * h * k2v, acc(*st[1], x + 0.5 * h * k2x, v + 0.5 * h * k2v)
                k4x, k4v = v + h * k3v, acc(*st[2], x + h * k3x, v + h * k3v)
                x = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
                v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
                if abs(b - (ts + T)) < 1e-12:
                    x_mid = x
            out[s, c] = k[c] @ (x - 2 * x_mid)
    return out


def numpy_predict_vectorised(t, f, w, shots, T, k, lever, v0):
    """The same RK4, vectorised over all shots and channels (arrays (S, C, 3)); needs shot
    starts and pulse times on the IMU grid (uniform step h)."""
    h = t[1] - t[0]
    m = int(round(T / h))
    i0 = np.rint((shots - t[0]) / h).astype(int)
    wd_int = np.diff(w, axis=0) / h
    cr = np.cross
    x = np.zeros((len(shots), len(k), 3))
    v = np.broadcast_to(v0, x.shape).copy()

    def acc(fb, wb, wdb, x, v):
        fb, wb, wdb = fb[:, None, :], wb[:, None, :], wdb[:, None, :]
        fs = fb + cr(wdb, lever) + cr(wb, cr(wb, lever))
        return -fs - 2 * cr(wb, v) - cr(wb, cr(wb, x)) - cr(wdb, x)

    for j in range(2 * m):
        i = i0 + j
        st = [(f[i], w[i]), (0.5 * (f[i] + f[i + 1]), 0.5 * (w[i] + w[i + 1])), (f[i + 1], w[i + 1])]
        wdb = wd_int[i]
        k1x, k1v = v, acc(*st[0], wdb, x, v)
        k2x, k2v = v + 0.5 * h * k1v, acc(*st[1], wdb, x + 0.5 * h * k1x, v + 0.5 * h * k1v)
        k3x, k3v = v + 0.5 * h * k2v, acc(*st[1], wdb, x + 0.5 * h * k2x, v + 0.5 * h * k2v)
        k4x, k4v = v + h * k3v, acc(*st[2], wdb, x + h * k3x, v + h * k3v)
        x = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if j + 1 == m:
            x_mid = x
    return np.einsum("cj,scj->sc", k, x - 2 * x_mid)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=10.0, help="record length (s) at 1 kHz")
    ap.add_argument("--slow-seconds", type=float, default=1.0, help="part of the record given to the per-shot numpy loop")
    args = ap.parse_args()
    n = int(args.seconds * 1000) + 1
    t = np.arange(n) * 1e-3
    f = np.column_stack([0.3 * np.sin(4.3 * t), 0.1 * np.cos(9.7 * t), np.full(n, -9.81)])
    w = np.column_stack([0.01 * np.sin(1.3 * t), np.full(n, 0.02), 0.05 * np.cos(0.1 * t)])
    T = 0.025
    shots = np.arange((n - 2) // 50) * 0.05
    ch = cai.Channels.cyclic(lever=(0.0, 0.0, 0.1))
    n_slow = int(args.slow_seconds * 1000) + 1
    slow_shots = shots[shots + 2 * T <= t[n_slow - 1]]

    t0 = time.perf_counter()
    ref = numpy_predict(t[:n_slow], f[:n_slow], w[:n_slow], slow_shots, T, ch.k, ch.lever, ch.v0)
    rate_np = n_slow / (time.perf_counter() - t0)

    t0 = time.perf_counter()
    ref_v = numpy_predict_vectorised(t, f, w, shots, T, ch.k, ch.lever, ch.v0)
    rate_nv = n / (time.perf_counter() - t0)

    reps = 5
    t0 = time.perf_counter()
    for _ in range(reps):
        ours = cai.predict_phase(t, f, w, shots, T, ch, omega_dot="pwl").total
    rate_an = n * reps / (time.perf_counter() - t0)

    err = max(np.abs(ours[: len(slow_shots)] - ref).max(), np.abs(ours - ref_v).max())
    print(f"record: {n} IMU samples at 1 kHz, {len(shots)} shots x {len(ch)} channels, T = {T} s")
    print(f"numpy straightforward (per shot, per channel; first {args.slow_seconds:g} s): {rate_np:12.0f} IMU samples/s")
    print(f"numpy vectorised over shots and channels:                  {rate_nv:12.0f} IMU samples/s")
    print(f"atomnav (Rust, with the per-term breakdown):               {rate_an:12.0f} IMU samples/s")
    print(f"max |phase difference| = {err:.2e} rad (same equations)")
    print(f"speed-up atomnav / numpy straightforward = {rate_an / rate_np:.0f}x (target >= 50x)")
    print(f"speed-up atomnav / numpy vectorised      = {rate_an / rate_nv:.0f}x")
    note = f"atomnav {rate_an:.3g} IMU samples/s; max phase difference {err:.1e} rad"
    record("CAI phase predictor (1 kHz IMU)", "numpy straightforward (own reference)", rate_an / rate_np, note=note)
    record("CAI phase predictor (1 kHz IMU)", "numpy vectorised (own reference)", rate_an / rate_nv, note=note)


if __name__ == "__main__":
    main()
