"""Design studies at scale: a campaign of the free INS over IMU grade and bias level, run in
this process and again on a Dask LocalCluster, resumed, swept by its covariance analysis,
its requirement boundary found and confirmed by Monte Carlo, and drawn.

    python examples/design_study.py [workdir]

The script runs the README's code in ``workdir`` (default: a new temporary directory) and
checks what the README says of it:

- the same campaign gives the same table bit for bit in this process and on two Dask
  worker processes (each run's seed depends on the campaign seed and the run id only);
- resuming a finished campaign computes nothing, and resuming one with a parameter
  point's runs deleted computes exactly those runs;
- the Monte-Carlo RMS over N seeds agrees with the covariance prediction inside the χ²
  band of an RMS over N seeds (below);
- the requirement boundary of the navigation-grade IMU lies between a point whose
  Monte-Carlo RMS meets the requirement and one whose RMS does not, each by more than
  two standard errors;
- the three campaign figures are written as PNG files.

The band. In one run the squared position error is |e|² = Σ_i λ_i χ²₁,i over the
eigenvalues λ_i of its covariance P (plus a deterministic part from a fixed bias), so
E|e|² = tr P, the predicted mean square. The mean square over N independent seeds, MS,
has N·MS/tr P = Σ_i (λ_i/tr P)·χ²_N,i, a weighted sum of χ²_N variables with weights
summing to one; its spread is largest when one eigenvalue carries the whole trace, where
it is χ²_N itself (a deterministic part only narrows it). So RMS/predicted = √(MS/tr P)
lies in √(χ²_N quantiles / N) with at least the quantiles' probability; α = 1 % is split
over every ratio checked (Bonferroni).

Dask starts its worker processes by importing the main module again ("spawn"); a script
whose work runs at its top level, as this one does to show the README's code as it is,
forks them instead (``distributed.worker.multiprocessing-method``). A script of your own
runs its campaign under ``if __name__ == "__main__":`` and needs no such setting.
"""

import os
import shutil

import dask
import numpy as np
import pandas as pd
from scipy.stats import chi2

from _workdir import enter

workdir = enter()


def assert_in_chi2_band(report, metrics, alpha=0.01):
    """Every ``<metric>_ratio`` (Monte-Carlo RMS / prediction) of ``report`` inside the
    two-sided χ²_N band of an RMS over N seeds (see the module docstring)."""
    ratios = report[[m + "_ratio" for m in metrics]].to_numpy()
    n = report["seeds"].to_numpy()[:, None]
    a = alpha / ratios.size
    lo, hi = np.sqrt(chi2.ppf(a / 2, n) / n), np.sqrt(chi2.ppf(1 - a / 2, n) / n)
    print(f"  RMS / predicted over N = {sorted(set(n.ravel().tolist()))} seeds: {ratios.min():.3f} … {ratios.max():.3f}; "
          f"band {lo.min():.3f} … {hi.max():.3f}")
    assert np.all((lo <= ratios) & (ratios <= hi)), (report.filter(like="_ratio"), lo.ravel(), hi.ravel())


# --- the README's walkthrough: a campaign in this process -----------------------------
from atomnav import campaign

study = campaign.Campaign(campaign.strapdown_free, {"imu": ["tactical", "navigation"], "bias_scale": [0.5, 1, 2]},
                          seeds=20, seed=1, fixed={"duration": 600.0})
table = campaign.run(study, "results")            # in this process (a thread per core)

print(f"{study.n_runs} runs, {len(table)} rows: {list(table.columns)}")
assert len(table) == study.n_runs * 10  # a checkpoint every 60 s

# --- the same campaign from nothing on a LocalCluster of two worker processes ---------
os.rename("results", "in_process")
dask.config.set({"distributed.worker.multiprocessing-method": "fork"})  # see the module docstring
from distributed import Client, LocalCluster
with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
    table = campaign.run(study, "results", client=client)

pd.testing.assert_frame_equal(table, campaign.load("in_process", "strapdown_free"), check_exact=True)
workers = sorted(campaign.timing("results", "strapdown_free")["worker"].unique())
print(f"LocalCluster: the same {study.n_runs} runs bit for bit, on workers {workers}")
assert len(workers) == 2, workers

# --- resuming: nothing to do, then only what is missing --------------------------------
writes = []
again = campaign.run(study, "results", progress=False, callback=lambda done, total: writes.append((done, total)))
assert writes == [], writes  # a finished campaign writes nothing
pd.testing.assert_frame_equal(again, table, check_exact=True)
shutil.rmtree("results/strapdown_free/runs/point=3")  # as if killed before point 3 was written
again = campaign.run(study, "results", progress=False, callback=lambda done, total: writes.append((done, total)))
computed = writes[-1][0] - (study.n_runs - study.seeds)
print(f"resume: 0 runs computed when finished, {computed} with point 3 deleted")
assert computed == study.seeds and writes[-1] == (study.n_runs, study.n_runs), writes
pd.testing.assert_frame_equal(again, table, check_exact=True)
ran = campaign.timing("results", "strapdown_free")
assert set(ran.loc[ran["point"] == 3, "worker"]) == {"local"} and "local" not in set(ran.loc[ran["point"] != 3, "worker"])

# --- the README's sweeps and requirements ----------------------------------------------
strapdown_free = campaign.strapdown_free
predicted = campaign.sweep(strapdown_free, {"bias_scale": [0.25, 0.5, 1, 2, 4]})   # covariance: <metric>_cov
edge = campaign.requirements(strapdown_free, {"pos_error_m": 1000.0}, at=600.0,
                             space={"bias_scale": (0.1, 10.0), "imu": ["tactical", "navigation"]})
check = campaign.sweep(strapdown_free, {"imu": ["navigation"], "bias_scale": [0.75, 1.25]}, method="monte_carlo",
                       seeds=100, folder="mc")  # the Monte Carlo either side of navigation's boundary

print(edge.to_string())
print(check[["imu", "bias_scale", "seeds", "pos_error_m_mc", "pos_error_m_mc_se", "pos_error_m_cov"]].to_string())
METRICS = ["pos_error_m", "hpos_error_m", "vel_error_mps", "att_error_rad"]
assert_in_chi2_band(check, METRICS)
# the boundary: feasible below it; the Monte Carlo meets 1 km at 0.75 and misses it at 1.25
boundary = edge.set_index("imu")
assert boundary["feasible"].tolist() == ["below", "below"]
assert 0.75 < boundary.loc["navigation", "bias_scale"] < 1.25
rms, se = check["pos_error_m_mc"].to_numpy(), check["pos_error_m_mc_se"].to_numpy()
assert rms[0] + 2 * se[0] < 1000.0 < rms[1] - 2 * se[1], (rms, se)

# --- the README's figures ----------------------------------------------------------------
report = campaign.compare(table, study)          # the study's Monte Carlo beside its covariance prediction
campaign.plots.error_vs_parameter(report, "bias_scale", "pos_error_m", by="imu").savefig("error_vs_bias.png")
outage = campaign.sweep(strapdown_free, {"duration": [120.0 * k for k in range(1, 11)],
                                         "bias_scale": [0.25 * k for k in range(1, 9)]}, fixed={"imu": "navigation"})
campaign.plots.error_map(outage, "bias_scale", "duration", "pos_error_m_cov", target=1000.0).savefig("error_map.png")
campaign.plots.throughput(campaign.timing("results", "strapdown_free")).savefig("throughput.png")

# the study's Monte Carlo against the covariance sweep (whose default grade is tactical)
tactical = report[report["imu"] == "tactical"].set_index("bias_scale")
for m in METRICS:
    np.testing.assert_array_equal(tactical[m + "_cov"], predicted.set_index("bias_scale").loc[tactical.index, m + "_cov"])
assert_in_chi2_band(report, METRICS)
for name in ("error_vs_bias.png", "error_map.png", "throughput.png"):
    with open(name, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n", name
    print(f"{workdir / name}: {os.path.getsize(name) / 1e3:.0f} kB")
