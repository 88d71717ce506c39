"""Strapdown throughput: atomnav vs pyins (PyPI `python-ins`) on the same 1-hour,
100 Hz increment record, in one run. pyins is timed warm (numba compiled beforehand).

    pip install python-ins          # the peer, for this benchmark only
    python benches/bench_strapdown.py [--hours 1] [--repeat 3]

Prints samples/s of each and the ratio atomnav / pyins, and the final-position
difference between the two so both are seen doing the same work.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import pandas as pd

import atomnav as an
from timing import best_of, record




def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    try:
        import pyins.strapdown
        from pyins.util import TRAJECTORY_COLS
    except ImportError:
        raise SystemExit("pyins is not installed: pip install python-ins")

    traj = an.trajectory.sinusoidal(args.hours * 3600.0, rate_hz=100.0)
    imu = traj.ideal_imu("increments")
    init = traj.initial_state()
    n = len(imu)

    t_an, nav = best_of(lambda: an.strapdown.integrate(imu, **init, progress=False), args.repeat)

    # pyins: increments with a duplicated "before" sample (its convention), degrees for angles
    vals = imu.iloc[:, 1:].to_numpy()
    pyimu = pd.DataFrame(np.vstack([vals[:1], vals]), index=np.r_[init["t0"], imu["time_s"].to_numpy()],
                         columns=["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"])
    rph = np.rad2deg(traj.df[["roll_rad", "pitch_rad", "yaw_rad"]].to_numpy()[0])
    lla = traj.lla[0]
    pva = pd.Series([np.rad2deg(lla[0]), np.rad2deg(lla[1]), lla[2], *init["vel_ned"], *rph], index=TRAJECTORY_COLS)

    def run_pyins(data):
        inc = pyins.strapdown.compute_increments_from_imu(data, "increment")
        return pyins.strapdown.Integrator(pva).integrate(inc)

    run_pyins(pyimu.iloc[:1000])  # numba compile, excluded from the timing
    t_py, out = best_of(lambda: run_pyins(pyimu), args.repeat)

    d_an = an.earth.lla_to_ned(nav[["lat_rad", "lon_rad", "h_m"]].to_numpy()[-1], traj.lla[-1])
    last = out.iloc[-1]
    d_py = an.earth.lla_to_ned([np.deg2rad(last["lat"]), np.deg2rad(last["lon"]), last["alt"]], traj.lla[-1])
    print(f"record: {n} increments ({args.hours:g} h at 100 Hz), best of {args.repeat}")
    print(f"atomnav : {n / t_an:12.0f} samples/s  ({t_an:.3f} s)  final position error {np.linalg.norm(d_an):.2e} m")
    print(f"pyins   : {n / t_py:12.0f} samples/s  ({t_py:.3f} s)  final position error {np.linalg.norm(d_py):.2e} m")
    print(f"ratio atomnav/pyins throughput: {t_py / t_an:.1f}x")
    record(f"strapdown {args.hours:g} h at 100 Hz (increments)", "pyins", t_py / t_an, np.linalg.norm(d_an),
           np.linalg.norm(d_py), "m final position error (ideal IMU)", note=f"atomnav {n / t_an:.3g} samples/s")


if __name__ == "__main__":
    main()
