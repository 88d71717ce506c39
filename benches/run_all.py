"""Run every benchmark of this folder, one after another, and write the table of results.

Each ``bench_*.py`` runs in its own process under the build lock (``flock``, so that no
build or other benchmark shares the cores with it), with a time limit, and prints one
tagged line per workload (``timing.record``). The table in ``--out`` gives, per workload,
the peer, the ratio atomnav speed / peer speed, the accuracy of both on the same data, and
the date; below it the machine (CPU, cores, Python, atomnav, git commit) and, per script,
its arguments, the load average before it, its wall time and how it ended. A script that
fails or runs out of time is a row saying so; the others still run.

    python benches/run_all.py [--only NAME ...] [--out benches/results.md] [--timeout 1800]

Exit code 1 if any script failed or timed out.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import shutil
import signal
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

from timing import TAG

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
STATIONS = ROOT / "tests" / "data" / "rinex_stations"

# name -> (arguments, note for the table); defaults are the scripts' own unless a note says why
SCRIPTS: dict[str, tuple[list[str], str]] = {
    "allan": ([], ""),
    "astro": ([], ""),
    "cai": ([], ""),
    "cai_hybrid": ([], ""),
    "campaign": ([], ""),
    "filter": ([], ""),
    "gnss": ([], "numpy loop over 10 min of data (the script's default; the 1-h case is --minutes 60)"),
    "rinex": (["--obs", str(STATIONS / "ESBC00DNK_R_20201770000_01D_30S_MO_cut.rnx.gz"),
               "--nav", str(STATIONS / "ESBC00DNK_R_20201770000_01D_MN_cut12h.rnx.gz"),
               "--truth", "3582104.7678", "532590.1779", "5232755.1405"],
              "the 12-epoch cut of the ESBC day in tests/data (the full day is not in the repository); "
              "georinex not timed (--georinex takes minutes on a full day)"),
    "strapdown": ([], ""),
    "walk": ([], "without --peer (a checkout of rtklibexplorer/GNSS_IMU): atomnav alone"),
}


def machine() -> dict[str, str]:
    """CPU model, cores, Python, atomnav version and git commit of this run."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        version = metadata.version("atomnav")
    except metadata.PackageNotFoundError:
        version = "not installed"
    git = ["git", "-C", str(ROOT)]
    try:
        commit = subprocess.run([*git, "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run([*git, "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True).stdout.strip()
        commit += " (with uncommitted changes)" if dirty else ""
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    return {"CPU": cpu, "cores": str(os.cpu_count()), "Python": platform.python_version(), "atomnav": version,
            "git commit": commit, "platform": platform.platform()}


def run_one(name: str, extra: list[str], timeout: float, lock: str | None) -> dict:
    """Run ``bench_<name>.py``; return its records, status, load average before, wall time and output tail."""
    cmd = [sys.executable, str(HERE / f"bench_{name}.py"), *extra]
    if lock and shutil.which("flock"):
        cmd = ["flock", lock, *cmd]
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
        status = "ok" if proc.returncode == 0 else f"failed (exit code {proc.returncode})"
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # the script and anything it started (flock, dask workers)
        out, _ = proc.communicate()
        status = f"timed out after {timeout:g} s"
    records = [json.loads(line[len(TAG):]) for line in out.splitlines() if line.startswith(TAG + " ")]
    if status == "ok" and not records:
        status = "failed (no result record printed)"
    date = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return {"name": name, "args": extra, "records": records, "status": status, "load": load,
            "seconds": time.perf_counter() - t0, "date": date, "tail": out.strip().splitlines()[-5:]}


def _num(x: float | None, missing: str, unit: str = "") -> str:
    return missing if x is None else f"{x:.3g}" + (f" {unit}" if unit else "")


def table(runs: list[dict], info: dict[str, str]) -> str:
    """The Markdown page of the results."""
    lines = ["# Benchmark results", "",
             "Written by `python benches/run_all.py`; ratio = atomnav speed / peer speed on the same workload, "
             "accuracies on the same data (units in the cell).", "",
             "| bench | workload | peer | ratio | atomnav accuracy | peer accuracy | date | note |",
             "|---|---|---|---|---|---|---|---|"]
    for run in runs:
        if run["status"] != "ok":
            cause = run["status"] + (": " + " / ".join(run["tail"][-2:]).replace("|", "\\|") if run["tail"] else "")
            lines.append(f"| {run['name']} | **{run['status']}** | | | | | {run['date']} | {cause} |")
            continue
        for r in run["records"]:
            peer = r["peer"] or "no peer"
            ratio = _num(r["ratio"], "—") + ("×" if r["ratio"] is not None else "")
            unit = r.get("unit", "")
            lines.append(f"| {run['name']} | {r['workload']} | {peer} | {ratio} | "
                         f"{_num(r['atomnav_accuracy'], 'not printed', unit)} | "
                         f"{_num(r['peer_accuracy'], 'not printed' if r['peer'] else '—', unit)} | "
                         f"{run['date']} | {r.get('note', '')} |")
    lines += ["", "## Machine", ""] + [f"- {k}: {v}" for k, v in info.items()]
    lines += ["", "## Runs", "", "| bench | arguments | load average before | wall time s | status | notes |",
              "|---|---|---|---|---|---|"]
    for run in runs:
        args = " ".join(a.replace(str(ROOT) + os.sep, "") for a in run["args"]) or "(defaults)"
        lines.append(f"| {run['name']} | `{args}` | {run['load']:.2f} | {run['seconds']:.1f} | {run['status']} | "
                     f"{SCRIPTS[run['name']][1]} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="+", choices=sorted(SCRIPTS), metavar="NAME",
                    help=f"run only these benches (of: {', '.join(SCRIPTS)})")
    ap.add_argument("--out", type=Path, default=HERE / "results.md", help="Markdown file to write (default: %(default)s)")
    ap.add_argument("--timeout", type=float, default=1800.0, help="time limit per script, s (default: %(default)s)")
    ap.add_argument("--lock", default="/tmp/atomnav-build.lock",
                    help="file each script runs under with flock, '' for none (default: %(default)s)")
    args = ap.parse_args(argv)
    info = machine()
    runs = []
    for name in args.only or SCRIPTS:
        print(f"bench_{name}.py ...", flush=True)
        run = run_one(name, SCRIPTS[name][0], args.timeout, args.lock or None)
        print(f"  {run['status']} in {run['seconds']:.1f} s, {len(run['records'])} records", flush=True)
        runs.append(run)
        args.out.write_text(table(runs, info))  # each finished script is on disk at once
    return int(any(run["status"] != "ok" for run in runs))


if __name__ == "__main__":
    sys.exit(main())
