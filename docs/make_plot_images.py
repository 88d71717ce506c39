"""Draw the images of docs/plots.md (docs/img/plots_*.png) from a short simulated run:
two minutes of sinusoidal motion, a tactical-grade IMU, 1 Hz position fixes, an hour of
a simulated gyro log, single-point positioning of a real station's RINEX 2.11 file
(DELF, tests/data/rinex_stations), and the README's design study: a campaign of the free
INS over IMU grade and bias scale (20 seeds per point, campaign seed 1) on a LocalCluster
of two workers, and the covariance sweep of bias scale against outage length. Run from
the repository root:

    .venv/bin/python docs/make_plot_images.py
"""

import tempfile
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

import atomnav as an  # noqa: E402

OUT = Path(__file__).parent / "img"


def campaign_figures() -> dict:
    """The three campaign figures of the README's design study (a temporary results folder)."""
    from distributed import Client, LocalCluster

    from atomnav import campaign

    study = campaign.Campaign(campaign.strapdown_free, {"imu": ["tactical", "navigation"], "bias_scale": [0.5, 1, 2]},
                              seeds=20, seed=1, fixed={"duration": 600.0})
    outage = campaign.sweep(campaign.strapdown_free, {"duration": [120.0 * k for k in range(1, 11)],
                                                      "bias_scale": [0.25 * k for k in range(1, 9)]},
                            fixed={"imu": "navigation"}, progress=False)
    with tempfile.TemporaryDirectory() as folder:
        with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0") as cluster, Client(cluster) as client:
            table = campaign.run(study, folder, client=client, progress=False)
        timing = campaign.timing(folder, study.name)
    return {
        "campaign_error_vs_parameter": campaign.plots.error_vs_parameter(campaign.compare(table, study), "bias_scale",
                                                                         "pos_error_m", by="imu"),
        "campaign_error_map": campaign.plots.error_map(outage, "bias_scale", "duration", "pos_error_m_cov", target=1000.0),
        "campaign_throughput": campaign.plots.throughput(timing),
    }


def main() -> None:
    OUT.mkdir(exist_ok=True)
    traj = an.trajectory.sinusoidal(120.0, rate_hz=100.0)
    meas = an.imu.corrupt(traj.ideal_imu("increments"), errors="tactical", dt=0.01, kind="increments", seed=7)
    st = traj.initial_state()
    fix_t = np.arange(1.0, 120.0, 1.0)
    rng = np.random.default_rng(3)
    fix_lla = traj.lla[np.searchsorted(traj.time, fix_t)]
    m_rad, n_rad = an.earth.radii(fix_lla[0, 0])
    noise = rng.standard_normal((len(fix_t), 3))  # 1 m per axis, NED
    fix_lla = fix_lla + noise * [1.0 / (m_rad + fix_lla[0, 2]), 1.0 / ((n_rad + fix_lla[0, 2]) * np.cos(fix_lla[0, 0])), -1.0]
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])
    ins = an.filter.position_aided_ins(st["t0"], st["lla"], st["vel_ned"], st["q_nb"], "increments", fix_t, fix_lla,
                                       np.tile(np.eye(3), (len(fix_t), 1, 1)), p0=p0, accel_psd=1e-6, gyro_psd=1e-10,
                                       predict_every=10)
    res = ins.run(meas["time_s"].to_numpy(), meas[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
                  meas[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy(), progress=False)
    err = traj.errors(res.nav)
    # NEES over the nine navigation states from the reported σ (cross-correlations ignored)
    sig = res.nav[[f"sigma_{b}[{i}]" for b in ("position", "velocity", "attitude") for i in range(3)]].to_numpy()
    nees = pd.DataFrame({"time_s": err["time_s"], "nees": ((err.iloc[:, 1:10].to_numpy() / sig) ** 2).sum(axis=1)})
    # an hour of a gyro at 10 Hz in °/h: ARW 0.1 °/√h and a 2 °/h bias
    w = 2.0 + 0.1 * 60.0 / np.sqrt(0.1) * rng.standard_normal(36000)
    table = an.noise.allan.allan_variance(w, 0.1)
    fit = an.noise.allan.fit_allan(w, 0.1, terms=("arw", "bias_instability"))
    stations = Path(__file__).parents[1] / "tests" / "data" / "rinex_stations"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # georinex's xarray deprecations
        eph = an.gnss.rinex.read_nav(stations / "brdc0010_cut.21n.gz")
        obs = an.gnss.rinex.read_obs(stations / "delf0010_cut.21o.gz", eph)
    delf = np.array([3924687.7020, 301132.7660, 5001910.7750])  # marker; the antenna is 0.05 m above
    figures = {
        "trajectory": an.plots.trajectory(an.strapdown.integrate(meas, **st), traj),
        "errors": an.plots.errors(err, res),
        "imu_errors": an.plots.imu_errors(res, truth=meas),
        "consistency": an.plots.consistency(nis=res, nees=nees, dof=9),
        "allan": an.plots.allan(table, fit, unit=an.units.DEG_PER_HOUR),
        "spp": an.plots.spp(an.gnss.solve(eph, obs.table[obs.table["sat"].str[0] == "G"], elevation_weight=True), delf),
        **campaign_figures(),
    }
    for name, fig in figures.items():
        fig.savefig(OUT / f"plots_{name}.png", dpi=55)  # each image under 100 kB


if __name__ == "__main__":
    main()
