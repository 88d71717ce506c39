"""Strapdown throughput: atomnav vs pyins (PyPI `python-ins`) on the same ideal increment
records, in one run. pyins is timed warm (numba compiled beforehand).

    pip install python-ins          # the peer, for this benchmark only
    python benches/bench_strapdown.py [--hours 1] [--repeat 3]

Two workloads of ``--hours`` at 100 Hz, each integrated by both from the true initial state:
atomnav's sinusoidal motion with its ideal IMU, and pyins' own sine-velocity motion with the
ideal IMU of ``pyins.sim`` (the case of pyins' test_integrate_sine_velocity). Each ideal IMU is
exact for its generator's normal-gravity model, so the other library gets it re-derived for
its own (``_pyins_compat.regravitate``); fed unchanged, the two models' 1e-6 m/s² difference
alone drives the vertical channel ~1e2 m off within the hour. Prints the time per step of each,
the ratio, and the final position, velocity and attitude errors of both.
"""

from __future__ import annotations

import argparse

import atomnav as an
from timing import best_of, record

try:
    import pyins.sim
    import pyins.strapdown

    import _pyins_compat as pc
except ImportError:  # main says how to install it
    pc = None

NAV_LLA, NAV_VEL, NAV_Q = ["lat_rad", "lon_rad", "h_m"], ["vn_mps", "ve_mps", "vd_mps"], ["qw", "qx", "qy", "qz"]
DV = an.trajectory.IMU_COLUMNS["increments"][4:]


def run_pyins(imu, pva):
    inc = pyins.strapdown.compute_increments_from_imu(imu, "increment")
    return pyins.strapdown.Integrator(pva).integrate(inc)


def compare(workload, imu, init, py_imu, pva, truth, repeat, fed):
    """Time both on one record, print per-step times and final errors, record the result."""
    n = len(imu)
    run_pyins(py_imu.iloc[:1000], pva)  # numba compiles on the first call: kept out of the timing
    t_an, nav = best_of(lambda: an.strapdown.integrate(imu, **init, progress=False), repeat)
    t_py, out = best_of(lambda: run_pyins(py_imu, pva), repeat)
    last = nav.iloc[-1]
    e_an = pc.final_errors(last[NAV_LLA].to_numpy(float), last[NAV_VEL].to_numpy(float), last[NAV_Q].to_numpy(float), *truth)
    e_py = pc.final_errors(*(x[-1] for x in pc.pyins_state(out.iloc[-1:])), *truth)
    print(f"\n{workload}: {n} increments, best of {repeat}")
    for name, t, (p, v, a) in [("atomnav", t_an, e_an), ("pyins", t_py, e_py)]:
        print(f"  {name:8s}: {1e9 * t / n:8.1f} ns/step ({t:.3f} s)  final error: position {p:.2e} m, "
              f"velocity {v:.2e} m/s, attitude {a:.2e} rad")
    print(f"  ratio atomnav/pyins throughput: {t_py / t_an:.1f}x")
    record(workload, "pyins", t_py / t_an, e_an[0], e_py[0], "m final position error (ideal IMU)",
           note=f"atomnav {n / t_an:.3g} samples/s; final velocity error atomnav {e_an[1]:.2g} / pyins {e_py[1]:.2g} m/s, "
                f"attitude {e_an[2]:.2g} / {e_py[2]:.2g} rad; {fed} fed the IMU re-derived for its normal gravity")


def atomnav_motion(hours):
    """atomnav's sinusoidal motion and ideal IMU, and the same IMU under pyins' gravity."""
    traj = an.trajectory.sinusoidal(hours * 3600.0, rate_hz=100.0)
    imu, init = traj.ideal_imu("increments"), traj.initial_state()
    for_pyins = imu.copy()
    for_pyins[DV] = pc.regravitate(imu[DV].to_numpy(), traj.time, traj.lla, traj.q_nb, pc.gravity_atomnav, pc.gravity_pyins)
    pva = pc.pyins_pva(traj.lla[0], traj.vel_ned[0], traj.df[["roll_rad", "pitch_rad", "yaw_rad"]].to_numpy()[0])
    truth = traj.lla[-1], traj.vel_ned[-1], traj.q_nb[-1]
    return imu, init, pc.pyins_imu(for_pyins, init["t0"]), pva, truth


def pyins_motion(hours):
    """pyins' sine-velocity motion and ideal IMU, and the same IMU under atomnav's gravity."""
    ref, py_imu = pyins.sim.generate_sine_velocity_motion(0.01, hours * 3600.0, [55.0, 37.0, 1500.0], [5.0, -3.0, 0.2],
                                                          velocity_change_amplitude=1.0, sensor_type="increment")
    lla, vel, q = pc.pyins_state(ref)
    imu = pc.atomnav_imu(py_imu)
    imu[DV] = pc.regravitate(imu[DV].to_numpy(), ref.index.to_numpy(), lla, q, pc.gravity_pyins, pc.gravity_atomnav)
    init = {"t0": float(ref.index[0]), "lla": lla[0], "vel_ned": vel[0], "q_nb": q[0]}
    return imu, init, py_imu, ref.iloc[0], (lla[-1], vel[-1], q[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    if pc is None:
        raise SystemExit("pyins is not installed: pip install python-ins")

    workloads = [(f"strapdown {args.hours:g} h at 100 Hz (increments)", atomnav_motion, "pyins"),
                 (f"strapdown {args.hours:g} h at 100 Hz, pyins.sim sine-velocity motion (increments)", pyins_motion, "atomnav")]
    for workload, make, fed in workloads:
        compare(workload, *make(args.hours), args.repeat, fed)


if __name__ == "__main__":
    main()
