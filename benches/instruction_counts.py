"""Instructions executed inside atomnav's compiled core by each benchmark's atomnav
workload, counted with valgrind's callgrind.

On a shared or virtual machine, wall-clock times of the same build scatter by 10-40 %
between runs, more than the changes worth checking. The instruction count of the
compiled core does not scatter, so comparing two commits' counts tells whether atomnav's
own work grew. (It does not see cache misses or how the work is spread over threads.)

Each workload is a scaled-down version of the atomnav side of one ``bench_*.py`` script:
the same calls, on a shorter record. It is counted twice, once with only its inputs built
and once with the timed call too; the difference is the call's cost. Only instructions in
the ``_core`` extension module are counted: not Python, numpy or the C library.

    apt-get install valgrind
    python benches/instruction_counts.py --out now.json            # every workload
    python benches/instruction_counts.py --only strapdown,dare      # a few
    python benches/instruction_counts.py --compare base.json now.json
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)


def _strapdown():
    import atomnav as an
    traj = an.trajectory.sinusoidal(300.0, rate_hz=100.0)
    imu, init = traj.ideal_imu("increments"), traj.initial_state()
    return lambda: an.strapdown.integrate(imu, **init, progress=False)


def _kf_predict():
    import numpy as np

    from atomnav.filter import KalmanFilter
    from bench_filter import system
    phi, q, _, _ = system(15, 3, np.random.default_rng(1))
    kf = KalmanFilter(np.eye(15), mode="open")
    return lambda: kf.predict(phi, q, steps=20_000)


def _dare():
    import numpy as np

    from atomnav.filter import dare
    from bench_filter import system
    rng = np.random.default_rng(1)
    system(15, 3, rng)  # the 21-state system is the second one drawn, as in bench_filter
    phi, q, h, r = system(21, 6, rng)
    return lambda: [dare(phi, q, h, r) for _ in range(20)]


def _allan():
    import numpy as np

    from atomnav.noise import allan
    y = np.random.default_rng(3).standard_normal(1_000_000)
    return lambda: allan.allan_variance(y, 0.01)


def _astro():
    from bench_astro import atomnav_chain, inputs
    data = inputs()
    return lambda: atomnav_chain(*data)


def _cai_predictor():
    import numpy as np

    from atomnav import cai
    n = 2001
    t = np.arange(n) * 1e-3
    f = np.column_stack([0.3 * np.sin(4.3 * t), 0.1 * np.cos(9.7 * t), np.full(n, -9.81)])
    w = np.column_stack([0.01 * np.sin(1.3 * t), np.full(n, 0.02), 0.05 * np.cos(0.1 * t)])
    shots = np.arange((n - 2) // 50) * 0.05
    ch = cai.Channels.cyclic(lever=(0.0, 0.0, 0.1))
    return lambda: cai.predict_phase(t, f, w, shots, 0.025, ch, omega_dot="pwl")


def _cai_hybrid():
    from bench_cai_hybrid import car_run, run_atomnav
    d = car_run(5.0)
    return lambda: run_atomnav(d)


def _gnss():
    from bench_gnss import run_atomnav, workload
    setup, imu, _ = workload(0.5)
    return lambda: run_atomnav(setup, imu)


#: name -> (builder of the timed call, the bench script it scales down)
WORKLOADS = {
    "strapdown": (_strapdown, "bench_strapdown.py: 300 s of 100 Hz increments (1 h in the bench)"),
    "kf_predict": (_kf_predict, "bench_filter.py: 15-state predict, 20,000 steps in one call"),
    "dare": (_dare, "bench_filter.py: 21-state DARE, 20 solves (50 in the bench)"),
    "allan": (_allan, "bench_allan.py: overlapping Allan table of 1e6 samples (1e7 in the bench)"),
    "astro": (_astro, "bench_astro.py: the whole astro chain, as in the bench"),
    "cai_predictor": (_cai_predictor, "bench_cai.py: 2 s at 1 kHz (10 s in the bench)"),
    "cai_hybrid": (_cai_hybrid, "bench_cai_hybrid.py: a 5 s car run (35 s in the bench)"),
    "gnss": (_gnss, "bench_gnss.py: 30 s tightly coupled (10 min in the bench)"),
}

CORE = re.compile(r"_core[.\w-]*\.so$")


def core_instructions(callgrind_out: str) -> int:
    """Instructions executed in the ``_core`` extension: the self cost of every function
    whose object file is ``_core*.so``, from a callgrind output file (name compression
    resolved, a name being defined by whichever of ``ob=`` and ``cob=`` meets it first;
    the inclusive cost line after each ``calls=`` is skipped)."""
    objects: dict[str, str] = {}
    in_core, skip_next, total = False, False, 0
    with open(callgrind_out) as f:
        for line in f:
            if line.startswith(("ob=", "cob=")):  # both define compressed object names
                m = re.match(r"c?ob=(\(\d+\))?\s*(.*)", line.rstrip("\n"))
                ref, name = m.group(1), m.group(2)
                if ref and name:
                    objects[ref] = name
                if line.startswith("ob="):
                    in_core = bool(CORE.search(name or objects.get(ref, "")))
            elif line.startswith("calls="):
                skip_next = True
            elif line[:1].isdigit() or line[:1] in "+-*":
                if skip_next:
                    skip_next = False
                elif in_core:
                    total += int(line.split()[1])
    return total


def _count(name: str, call: bool) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "callgrind.out")
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, __file__,
               "--inside", name] + (["--call"] if call else [])
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       env={**os.environ, "RAYON_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"})
        return core_instructions(out)


def count(name: str) -> int:
    """Core instructions of one call of workload ``name`` (its inputs' cost removed)."""
    return _count(name, True) - _count(name, False)


def compare(base: dict, now: dict) -> int:
    print("| workload | base | now | change |")
    print("| --- | ---: | ---: | ---: |")
    worst = 0.0
    for name in base:
        if name in now:
            change = now[name] / base[name] - 1.0
            worst = max(worst, change)
            print(f"| {name} | {base[name]:,} | {now[name]:,} | {100 * change:+.2f} % |")
    print(f"\nlargest increase: {100 * worst:+.2f} %")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", default=None, help="comma-separated workloads (default: all)")
    ap.add_argument("--out", default=None, help="write the counts as JSON")
    ap.add_argument("--compare", nargs=2, metavar=("BASE", "NOW"), help="compare two JSON files")
    ap.add_argument("--inside", choices=sorted(WORKLOADS), help=argparse.SUPPRESS)
    ap.add_argument("--call", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.compare:
        with open(a.compare[0]) as b, open(a.compare[1]) as n:
            return compare(json.load(b), json.load(n))
    if a.inside:  # under valgrind: build the inputs, and make the call if asked
        run = WORKLOADS[a.inside][0]()
        if a.call:
            run()
        return 0
    names = a.only.split(",") if a.only else list(WORKLOADS)
    unknown = [n for n in names if n not in WORKLOADS]
    if unknown:
        ap.error(f"unknown workload(s) {', '.join(unknown)}; known: {', '.join(WORKLOADS)}")
    counts = {}
    for name in names:
        counts[name] = count(name)
        print(f"{name:14s} {counts[name]:>16,} instructions   ({WORKLOADS[name][1]})", flush=True)
    if a.out:
        with open(a.out, "w") as f:
            json.dump(counts, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
