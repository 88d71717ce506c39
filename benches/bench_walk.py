"""Real-log pipeline throughput: the recorded walk (tests/data/real_walk) and a synthetic
1-hour log at 100 Hz with 4 Hz position and velocity fixes, each through atomnav's whole
pipeline (read, align in motion, aided INS with a GNSS outage, RTS smoother, score).
With the walk's source repository at hand (``--peer``: a checkout of
rtklibexplorer/GNSS_IMU), its published loosely coupled Python filter runs on the same
walk and the same outage, and both are timed and scored side by side.

    python benches/bench_walk.py [--hours 1] [--repeat 3] [--peer /path/to/GNSS_IMU]

Prints IMU samples per second of each run, the ratio atomnav / peer, and both outage
tables (largest and end-of-window 3-D error against the withheld fixed-RTK positions).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import atomnav as an
from timing import best_of, record

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))
import real_walk  # noqa: E402  (the README's walkthrough of the recorded walk)


def synthetic(hours: float, repeat: int) -> None:
    """A sinusoidal run of ``hours`` at 100 Hz, tactical IMU, 4 Hz fixes, one 15 s outage
    every 5 minutes: forward filter and smoother."""
    truth = an.trajectory.sinusoidal(hours * 3600.0, rate_hz=100.0)
    meas = an.imu.corrupt(truth.ideal_imu("rates"), errors="tactical", dt=0.01, kind="rates", seed=1)
    imu = (meas["time_s"].to_numpy(), meas[[f"gyro_{a}_rad_s" for a in "xyz"]].to_numpy(),
           meas[[f"accel_{a}_mps2" for a in "xyz"]].to_numpy())
    t = np.arange(0.25, truth.time[-1], 0.25)
    k = np.searchsorted(truth.time, t)
    fixes = an.filter.PositionFixes(t, truth.lla[k], np.eye(3) * 0.02**2)
    vel = an.filter.VelocityFixes(t, truth.vel_ned[k], np.eye(3) * 0.05**2)
    s0 = truth.initial_state()
    tac = an.imu.ImuErrors.preset("tactical")
    setup = an.filter.InsSetup(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates",
                               p0=np.diag(np.r_[[1e-2] * 3, [1e-2] * 3, [1e-4] * 3, [tac.accel.bias_sigma**2] * 3,
                                                [tac.gyro.bias_sigma**2] * 3]),
                               accel_psd=tac.accel.white**2, gyro_psd=tac.gyro.white**2, predict_every=10)
    windows = an.filter.outage_windows(t, length=15.0, first=60.0, spacing=300.0)
    seconds, out = best_of(lambda: an.filter.outage_analysis(setup, fixes, imu, windows, withhold=[vel], progress=False),
                           repeat)
    n = len(imu[0])
    print(f"\nsynthetic {hours:g} h at 100 Hz, 4 Hz fixes, {len(windows)} outages of 15 s: {n} samples in "
          f"{seconds:.2f} s = {n / seconds / 1e6:.2f} M samples/s (forward + smoother + scoring)")
    print(out.table.groupby("solution")[["max_error_m", "end_error_m"]].max().to_string())
    record(f"synthetic {hours:g} h pipeline (tactical IMU, 15 s outages)", None, None, out.table["max_error_m"].max(),
           unit="m largest outage error", note=f"{n / seconds / 1e6:.2f} M samples/s")


def peer(path: Path, repeat: int, windows, reference) -> tuple[float, dict]:
    """The source's filter on the walk, forward and with its velocity matching, on a
    scratch copy of its repository (its README: select the walk in GNSS_IMU.py's header)."""
    work = Path(tempfile.mkdtemp(prefix="gnss-imu-"))
    shutil.copytree(path / "src", work / "src")
    shutil.copytree(path / "data" / "walk_0827", work / "data" / "walk_0827")
    code = (work / "src" / "GNSS_IMU.py").read_text()
    for line in ("import drive_config as cfg\n", "dataDir = r'..\\data\\drive_0708'\n", "fileIn = '1934_sf'\n"):
        code = code.replace(line, "")
    sys.path.insert(0, str(work / "src"))
    import walk_config

    tables, times = {}, {}
    for name, match in (("peer forward", False), ("peer velocity matching", True)):

        def run():
            cfg = importlib.reload(walk_config)  # the script converts some settings in place: a fresh copy per run
            cfg.plot_results = cfg.plot_bias_data = cfg.plot_imu_data = cfg.plot_unc_data = False
            cfg.vel_match = match
            with contextlib.redirect_stdout(io.StringIO()):
                exec(compile(code, str(work / "src" / "GNSS_IMU.py"), "exec"),  # noqa: S102 - the peer's own script
                     {"cfg": cfg, "dataDir": str(work / "data" / "walk_0827"), "fileIn": "1730_sf", "__name__": "__main__"})
            return an.gnss.read_pos(work / "data" / "walk_0827" / "gnss_imu_1730_sf.pos")

        times[name], solution = best_of(run, repeat)
        tables[name] = an.filter.score_outages(solution.data, reference, windows, solution=name)[0]
    return times, tables


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hours", type=float, default=1.0, help="length of the synthetic log (h)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per timing (best of)")
    ap.add_argument("--peer", type=Path, help="a checkout of rtklibexplorer/GNSS_IMU (its src/ and data/walk_0827/)")
    args = ap.parse_args()

    seconds, walk = best_of(lambda: real_walk.solve(ROOT / "tests" / "data" / "real_walk"), args.repeat)
    n = walk.samples
    print(f"the recorded walk: {n} IMU samples in {seconds:.3f} s = {n / seconds / 1e6:.2f} M samples/s "
          "(read, align in motion, forward + smoother, score)")
    print(walk.outages.table.to_string(index=False))
    ours = walk.outages.table["max_error_m"].max()
    if args.peer is None:
        record("recorded walk pipeline", None, None, ours, unit="m largest outage error",
               note=f"{n / seconds / 1e6:.2f} M samples/s; peer needs --peer (rtklibexplorer/GNSS_IMU)")
    if args.peer is not None:
        times, tables = peer(args.peer, args.repeat, walk.outages.windows, walk.reference)
        for name, table in tables.items():
            print(f"\n{name}: {times[name]:.2f} s = {n / times[name] / 1e3:.1f} k samples/s; "
                  f"atomnav / peer speed ratio {times[name] / seconds:.0f}x")
            print(table.to_string(index=False))
            record("recorded walk pipeline", f"GNSS_IMU ({name})", times[name] / seconds, ours,
                   table["max_error_m"].max(), "m largest outage error")
    synthetic(args.hours, args.repeat)


if __name__ == "__main__":
    main()
