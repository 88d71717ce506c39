"""Campaign throughput: one campaign of short runs (default 1,000 free-inertial runs of 60 s,
a few tens of ms each) in this process and on a dask.distributed LocalCluster of 1 and of 2
single-threaded worker processes, side by side; prints the wall time, the speed-up of
2 workers over 1 (goal ≥ 1.8×), the scheduler overhead per run,
(wall time × workers − Σ run time) / runs, from the per-run ``elapsed_s`` the campaign
stores, and the share of the wall time the workers spent running (busy %). A mean run
time that grows with the workers means the cores were not free: the speed-up is then
bounded by the machine, the busy share still says what the scheduling costs. Clusters are started and their workers warmed (scenario module imported) before
the clock starts; every executor writes to a fresh folder, so nothing is resumed.

    python benches/bench_campaign.py [--runs 1000] [--duration 60] [--scenario strapdown_free|toy]

``toy`` is the random walk of tests/campaign_toy.py (``--steps`` Gaussian steps per run).
On a machine shared with other jobs, run it alone: the speed-up needs two free cores.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
import tempfile
import time
from pathlib import Path

from atomnav import campaign

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import record  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
POINTS = 4  # parameter points; runs / POINTS seeds each


def study(scenario: str, runs: int, duration: float, steps: int) -> campaign.Campaign:
    """``runs`` runs over ``POINTS`` parameter points of the chosen scenario."""
    if scenario == "toy":
        sys.path.insert(0, str(ROOT / "tests"))  # the workers are spawned with this process's module path
        import campaign_toy

        return campaign.Campaign(campaign_toy.random_walk, {"sigma_m": [[s] * 3 for s in (0.5, 1.0, 2.0, 4.0)]},
                                 seeds=runs // POINTS, fixed={"steps": steps}, name="toy")
    from atomnav.campaign.strapdown_free import strapdown_free

    return campaign.Campaign(strapdown_free, {"bias_scale": [0.5, 1.0, 2.0, 4.0]}, seeds=runs // POINTS,
                             fixed={"duration": duration, "checkpoint_s": duration / 6}, name="strapdown_free")


def timed(plan: campaign.Campaign, client=None, threads: int | None = None) -> tuple[float, float]:
    """(wall time, Σ run time) in s of the whole campaign, into a fresh folder."""
    folder = tempfile.mkdtemp(prefix="bench-campaign-")
    t0 = time.perf_counter()
    campaign.run(plan, folder, client=client, threads=threads, progress=False)
    wall = time.perf_counter() - t0
    return wall, float(campaign.timing(folder, plan.name)["elapsed_s"].sum())


def on_cluster(plan: campaign.Campaign, workers: int) -> tuple[float, float, float]:
    """(cluster start-up s, wall s, Σ run s) on a LocalCluster of ``workers`` single-threaded processes."""
    from distributed import Client, LocalCluster

    t0 = time.perf_counter()
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        client.wait_for_workers(workers)
        client.run(importlib.import_module, plan.scenario.__module__)
        start = time.perf_counter() - t0
        return (start, *timed(plan, client))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=1000, help="runs of the campaign")
    ap.add_argument("--scenario", choices=("strapdown_free", "toy"), default="strapdown_free", help="what each run does")
    ap.add_argument("--duration", type=float, default=60.0, help="strapdown_free: run length (s of navigation)")
    ap.add_argument("--steps", type=int, default=200_000, help="toy: random-walk steps per run")
    args = ap.parse_args()

    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    plan = study(args.scenario, args.runs, args.duration, args.steps)
    plan.scenario(seed=0, **plan.point(0))  # imports and caches of this process, outside the clock
    rows = [("in process, 1 thread", 1, 0.0, *timed(plan, threads=1)),
            ("in process, 2 threads", 2, 0.0, *timed(plan, threads=2))]
    for workers in (1, 2):
        rows.append((f"LocalCluster, {workers} worker{'s' * (workers > 1)}", workers, *on_cluster(plan, workers)))

    print(f"{plan.name}: {plan.n_runs} runs over {plan.n_points} points")
    print(f"{'executor':24s} {'start s':>8s} {'wall s':>8s} {'runs/s':>8s} {'mean run ms':>12s} {'overhead/run ms':>16s} "
          f"{'busy %':>7s}")
    for label, slots, start, wall, busy in rows:
        overhead = (wall * slots - busy) / plan.n_runs
        print(f"{label:24s} {start:8.2f} {wall:8.2f} {plan.n_runs / wall:8.1f} {busy / plan.n_runs * 1e3:12.2f} "
              f"{overhead * 1e3:16.2f} {100 * busy / (wall * slots):7.1f}")
    one, two = rows[2][3], rows[3][3]
    print(f"speed-up of 2 workers over 1: {one / two:.2f}x (goal >= 1.8x); "
          f"2 workers vs in process (1 thread): {rows[0][3] / two:.2f}x")
    record(f"campaign of {plan.n_runs} {plan.name} runs", None, None,
           note=f"2 workers over 1: {one / two:.2f}x (goal 1.8x); 2 workers {plan.n_runs / two:.1f} runs/s")


if __name__ == "__main__":
    main()
