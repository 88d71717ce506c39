"""CAI-aided INS: atomnav (Rust engine + CAI aiding) vs a pure-numpy reference implementation
of the same filter loop, timed side by side in one run; prints the ratios.

One 35 s car run (car profile of Tennstedt et al. 2023, kinematic mode, 200 Hz navigation IMU, 20 Hz CAI,
6 observations per shot, 15 states), both sides configured alike: strapdown per sample;
per shot the atom-strapdown RK4 predictor on the compensated IMU (linear inputs, ω̇ of the
piecewise-linear gyro), mid-fringe steering, nonlinear innovation, stacked 6-row update
(Joseph form), Van Loan prediction of the 15-state model, closed-loop feedback. The numpy
side is lighter where that is easy (flat strapdown without coning/sculling, forward
differences for H vectorised with the predictor), so the ratio is a lower bound. Then the
100-run Monte Carlo (``atomnav.cai.car_mc``) on this machine's cores, against 100 ×
the numpy run (extrapolated: running it would take minutes).

    python benches/bench_cai_hybrid.py [--runs 100]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
from scipy.linalg import expm

import atomnav as an
from atomnav import cai
from atomnav.cai import predict_phase

sys.path.insert(0, os.path.dirname(__file__))
from timing import best_of, record  # noqa: E402

T, DT = 0.025, 0.005


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def rotvec_dcm(phi):
    a = np.linalg.norm(phi)
    k = skew(phi)
    if a < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + np.sin(a) / a * k + (1 - np.cos(a)) / a**2 * k @ k


def phases(fw, ww, k, v0):
    """RK4 of (E5) (l = 0, C_sb = I) over one shot sampled at 0, h, ..., 2T: batch (B, C, 3)
    of IMU inputs fw, ww (B, 2m+1, 3), linear inputs, ω̇ per interval; returns (B, C)."""
    m = fw.shape[1] // 2
    cr = np.cross
    x = np.zeros((fw.shape[0], len(k), 3))
    v = np.broadcast_to(v0, x.shape).copy()

    def acc(f, w, wd, x, v):
        f, w, wd = f[:, None], w[:, None], wd[:, None]
        return -f - 2 * cr(w, v) - cr(w, cr(w, x)) - cr(wd, x)

    for j in range(2 * m):
        f0, f1, w0, w1 = fw[:, j], fw[:, j + 1], ww[:, j], ww[:, j + 1]
        wd = (w1 - w0) / DT
        fm, wm = 0.5 * (f0 + f1), 0.5 * (w0 + w1)
        k1x, k1v = v, acc(f0, w0, wd, x, v)
        k2x, k2v = v + 0.5 * DT * k1v, acc(fm, wm, wd, x + 0.5 * DT * k1x, v + 0.5 * DT * k1v)
        k3x, k3v = v + 0.5 * DT * k2v, acc(fm, wm, wd, x + 0.5 * DT * k2x, v + 0.5 * DT * k2v)
        k4x, k4v = v + DT * k3v, acc(f1, w1, wd, x + DT * k3x, v + DT * k3v)
        x = x + DT / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v = v + DT / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if j + 1 == m:
            x_mid = x
    return np.einsum("cj,bcj->bc", k, x - 2 * x_mid)


def numpy_run(t, gyro, accel, shots, phase, noise, sensor, setup, p0, vel0, q0):
    """The same closed-loop filter in numpy (see module docstring). Returns velocity (N, 3)."""
    ch = sensor.channels
    n = len(t)
    c_nb = np.asarray(an.rotation.dcm_from_quat(q0)).reshape(3, 3)
    vel = np.asarray(vel0, float).copy()
    ba, bg = np.zeros(3), np.zeros(3)
    P = p0.copy()
    half = 0.5 * sensor.contrast
    # the in-shot noise covariance from the predictor's sample sensitivities, as the Rust aiding
    R = sensor.sigma_p**2 * np.eye(6) + half**2 * cai.in_shot_noise(sensor, DT, *sensor.inflation)[0]
    qc = np.zeros((15, 15))
    qc[3:6, 3:6] = setup.accel_psd * np.eye(3)
    qc[6:9, 6:9] = setup.gyro_psd * np.eye(3)
    qc[9:12, 9:12] = setup.accel_bias_psd * np.eye(3)
    qc[12:15, 12:15] = setup.gyro_bias_psd * np.eye(3)
    m = int(round(T / DT))
    buf_f, buf_w = np.zeros((n, 3)), np.zeros((n, 3))
    out_v = np.zeros((n, 3))
    shot_end = {int(round(s / DT)) + 2 * m: j for j, s in enumerate(shots)}
    eps = np.r_[np.full(3, 1e-6), np.full(3, 1e-7)]
    last_epoch = 0
    for i in range(n):
        f, w = accel[i] - ba, gyro[i] - bg
        buf_f[i], buf_w[i] = f, w
        if i > 0:
            wm, fm = 0.5 * (w + buf_w[i - 1]), 0.5 * (f + buf_f[i - 1])
            c_mid = c_nb @ rotvec_dcm(0.5 * wm * DT)
            c_nb = c_nb @ rotvec_dcm(wm * DT)
            vel = vel + c_mid @ fm * DT
        if i in shot_end:
            j = shot_end[i]
            F = np.zeros((15, 15))
            F[0:3, 3:6] = np.eye(3)
            F[3:6, 6:9] = skew(c_nb @ f)
            F[3:6, 9:12] = -c_nb
            F[6:9, 12:15] = c_nb
            dt = (i - last_epoch) * DT
            vl = expm(np.block([[-F, qc], [np.zeros((15, 15)), F.T]]) * dt)
            phi = vl[15:, 15:].T
            P = phi @ P @ phi.T + phi @ vl[:15, 15:]
            last_epoch = i
            lo = i - 2 * m
            fw = np.repeat(buf_f[None, lo:i + 1], 7, axis=0)
            ww = np.repeat(buf_w[None, lo:i + 1], 7, axis=0)
            for p in range(6):  # perturbed bias estimates: the stream is compensated by −ε more
                (fw if p < 3 else ww)[p + 1, :, p % 3] -= eps[p]
            ph = phases(fw, ww, ch.k, ch.v0)
            jac = (ph[1:] - ph[0]).T / eps
            phi0 = np.mod(np.pi / 2 - ph[0], 2 * np.pi)
            pop = sensor.offset - half * np.cos(phase[j] + phi0) + noise[j]
            z = sensor.offset - half * np.cos(ph[0] + phi0) - pop
            H = np.zeros((6, 15))
            H[:, 9:15] = half * np.sin(ph[0] + phi0)[:, None] * jac
            S = H @ P @ H.T + R
            K = np.linalg.solve(S, H @ P).T
            dx = K @ z
            A = np.eye(15) - K @ H
            P = A @ P @ A.T + K @ R @ K.T
            vel = vel - dx[3:6]
            c_nb = (np.eye(3) + skew(dx[6:9])) @ c_nb
            ba, bg = ba - dx[9:12], bg - dx[12:15]
        out_v[i] = vel
    return out_v


def car_run(seconds: float = 35.0) -> dict:
    """The inputs of one car run of ``seconds``: truth, corrupted navigation IMU, shots,
    predicted phases and their noise, sensor and filter setup, initial state."""
    traj = an.trajectory.car(rate_hz=200.0, origin=cai.HANNOVER, ellipsoid="kinematic")
    n = int(round(seconds * 200)) + 1
    df = traj.df.iloc[:n]
    ideal = traj.ideal_imu("rates").iloc[:n]
    gcols, acols = ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"], ["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]
    meas = an.imu.corrupt(ideal, errors="navigation", dt=DT, kind="rates", seed=1)
    t = ideal["time_s"].to_numpy()
    sensor = cai.seed003_sensor((0.0, 0.0, 0.0), interpolation="linear", omega_dot="pwl")
    shots = sensor.shots(0.0, t[-1])
    phase = predict_phase(t, ideal[acols].to_numpy(), ideal[gcols].to_numpy(), shots, T, sensor.channels, omega_dot="pwl").total
    s0 = df.iloc[0]
    return dict(df=df, t=t, gyro=meas[gcols].to_numpy(), accel=meas[acols].to_numpy(), sensor=sensor,
                setup=cai.seed003_filter(), shots=shots, phase=phase,
                noise=np.random.default_rng(2).normal(0.0, sensor.sigma_p, phase.shape),
                lla0=s0[["lat_rad", "lon_rad", "h_m"]].to_numpy(float), vel0=s0[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(float),
                q0=s0[["qw", "qx", "qy", "qz"]].to_numpy(float))


def run_atomnav(d: dict):
    """One CAI-aided INS run of atomnav on the inputs of :func:`car_run`."""
    ins = cai.cai_aided_ins(0.0, d["lla0"], d["vel0"], d["q0"], d["sensor"], d["shots"], phase=d["phase"],
                            noise=d["noise"], setup=d["setup"], kind="rates", ellipsoid="kinematic")
    return ins.run(d["t"], d["gyro"], d["accel"], progress=False)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=100)
    args = ap.parse_args()
    d = car_run()
    df, t, gyro, accel, shots, phase, noise, sensor, setup, vel0, q0 = (
        d[k] for k in ("df", "t", "gyro", "accel", "shots", "phase", "noise", "sensor", "setup", "vel0", "q0"))
    n = len(t)
    t_rust, res = best_of(lambda: run_atomnav(d), 3)
    t0 = time.perf_counter()
    v_np = numpy_run(t, gyro, accel, shots, phase, noise, sensor, setup, setup.p0(0), vel0, q0)
    t_np = time.perf_counter() - t0
    truth_v = df[["vn_mps", "ve_mps", "vd_mps"]].to_numpy()
    nav = res.nav
    idx = np.searchsorted(t, nav["time_s"].to_numpy())
    e_rust = np.linalg.norm(nav[["vn_mps", "ve_mps", "vd_mps"]].to_numpy() - truth_v[idx], axis=1)
    e_np = np.linalg.norm(v_np - truth_v, axis=1)
    print(f"one 35 s car run: {n} IMU samples at 200 Hz, {len(shots)} shots x 6 channels, 15 states")
    print(f"  velocity error at 35 s: atomnav {e_rust[-1]:.2e} m/s, numpy reference {e_np[-1]:.2e} m/s (flat strapdown, forward-difference H)")
    print(f"  atomnav (Rust engine + CAI aiding): {t_rust:8.3f} s")
    print(f"  numpy reference loop:               {t_np:8.3f} s")
    print(f"  ratio numpy / atomnav:              {t_np / t_rust:8.1f}x   (target >= 30x)")
    record("CAI-aided INS, one 35 s car run", "numpy reference loop (own)", t_np / t_rust, e_rust[-1], e_np[-1],
           "m/s velocity error at 35 s")
    t0 = time.perf_counter()
    cai.car_mc(args.runs, progress=False)
    t_mc = time.perf_counter() - t0
    print(f"{args.runs}-run car Monte Carlo (40 s runs incl. truth and IMU simulation) on {os.cpu_count()} cores: {t_mc:.2f} s")
    print(f"  numpy reference, {args.runs} x one run (extrapolated): {args.runs * t_np * 40 / 35:.1f} s")
    print(f"  ratio:                                          {args.runs * t_np * 40 / 35 / t_mc:8.1f}x   (target >= 30x)")
    record(f"{args.runs}-run car Monte Carlo", "numpy reference loop (own, extrapolated)", args.runs * t_np * 40 / 35 / t_mc,
           note=f"{t_mc:.1f} s on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
