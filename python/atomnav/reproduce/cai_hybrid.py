"""CAI-aided navigation end to end: the slalom and car Monte Carlo of Tennstedt et al. 2023,
the satellite and hexapod scenarios of Tennstedt et al. 2021, each with its improvement over the IMU-only
strapdown (ratio of RMS-over-runs errors, see ``atomnav.cai.results``) and its plots."""

from __future__ import annotations

import numpy as np

from .. import cai
from . import NOT_REPRODUCED, REPORTED, section


def _band_plot(ax, res, col: int, label: str, scale: float = 1.0):
    """RMS over runs of the hybrid and IMU-only error of one column with the filter's ±σ."""
    t = res.time
    ax.semilogy(t, np.sqrt(np.mean(res.free[:, :, col] ** 2, axis=0)) * scale, "C3", lw=1, label="IMU only (RMS)")
    ax.semilogy(t, np.sqrt(np.mean(res.hybrid[:, :, col] ** 2, axis=0)) * scale, "C0", lw=1, label="hybrid (RMS)")
    ax.semilogy(t, res.sigma[:, :, col].mean(axis=0) * scale, "k:", lw=0.8, label="filter σ")
    ax.set_ylabel(label)
    ax.set_xlabel("time (s)")


def _errors_figure(report, res, name: str, caption: str):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.5))
    for ax, (col, lab) in zip(axes, [(3, "|δv_N| (m/s)"), (4, "|δv_E| (m/s)"), (9, "|δb_a,x| (m/s²)")]):
        if col < 9:
            _band_plot(ax, res, col, lab)
        else:
            err = res.bias[:, :, 0] - res.bias_true[:, :, 0]
            ax.semilogy(res.time, np.sqrt(np.mean(err**2, axis=0)), "C0", lw=1, label="bias error (RMS)")
            ax.semilogy(res.time, res.sigma[:, :, 9].mean(axis=0), "k:", lw=0.8, label="filter σ")
            ax.set_ylabel(lab)
            ax.set_xlabel("time (s)")
        ax.legend(fontsize=7)
    fig.tight_layout()
    report.figure(fig, name, caption)


def _improvement_rows(report, res, times, label: str):
    imp = res.improvement(times)
    for _, r in imp[imp["axis"] == "norm"].iterrows():
        report.row(f"{label}: {r['quantity']} error IMU-only/hybrid at {r['time_s']:.0f} s (RMS over runs, norm)", "—", round(r["ratio"], 2), REPORTED)
    return imp


def _slalom(report):
    runs = 8 if report.quick else 100
    kin = cai.slalom(runs, gravity="kinematic", progress=report.progress)
    ratio = kin.improvement([60.0]).query("quantity == 'velocity' and axis == 'norm'")["ratio"].iloc[0]
    report.row(f"slalom, kinematic: velocity error IMU-only/hybrid at 60 s ({runs} runs), Tennstedt et al. 2023", "> 100", round(ratio, 1), bool(ratio >= 100))
    _improvement_rows(report, kin, [25.0, 60.0], "slalom kinematic")
    # fringe slips (target: "slalom < 0.1 %"). The in-shot IMU noise alone sets the share:
    # with the scenario's l = [0, 0, 0.1] m the lever-arm Euler term adds 0.37 rad of gyro noise
    # to the x and y channels (σ up to 0.68 rad → ≈0.44 % expected), so < 0.1 % needs l = 0
    # (σ = 0.40 rad → 0.0085 %); both are shown, each against its in-shot-noise prediction.
    imu = (1.25e-11, 1.0576e-12)
    frac, pred = kin.phase_exceedance(), cai.expected_phase_exceedance(cai.seed003_sensor(), 0.005, *imu)
    report.row("slalom, l = [0, 0, 0.1] m: shot-channels with |phase error| > π/2 [%], within a factor 2 of the in-shot-noise prediction",
               "—", round(100 * frac, 3), bool(0.5 < frac / pred < 2),
               f"prediction {100 * pred:.3f} %: the lever-arm Euler term adds gyro noise, so the < 0.1 % of Tennstedt et al. 2023 "
               "needs l = 0 (next row); docs/departures.md#euler-lever-arm-term")
    no_lever = cai.slalom(8 if report.quick else 20, gravity="kinematic", lever=(0.0, 0.0, 0.0), progress=report.progress)
    frac0 = no_lever.phase_exceedance()
    pred0 = cai.expected_phase_exceedance(cai.seed003_sensor((0.0, 0.0, 0.0)), 0.005, *imu)
    report.row(f"slalom, l = 0: shot-channels with |phase error| > π/2 [%] ({no_lever.runs} runs), Tennstedt et al. 2023",
               "< 0.1", round(100 * frac0, 4), bool(frac0 < 1e-3), f"in-shot-noise prediction {100 * pred0:.4f} %")
    _errors_figure(report, kin, "cai_hybrid_slalom", f"Slalom, kinematic mode, {runs} runs: velocity errors of the IMU-only and hybrid solutions, accelerometer-bias error, filter σ")
    earth = cai.slalom(runs, gravity="earth", progress=report.progress)
    mc = earth.improvement([60.0]).query("quantity == 'velocity' and axis == 'norm'")["ratio"].iloc[0]
    cov = cai.slalom_covariance("earth")
    cov_ratio, own_ratio = float(cov["ratio_true"].iloc[-1]), float(cov["ratio"].iloc[-1])
    report.row("slalom, Earth gravity: velocity error IMU-only/hybrid at 60 s, Monte Carlo; Tennstedt et al. 2023", "> 100", round(mc, 2),
               NOT_REPRODUCED, "the CAI cannot observe the tilt from gyro white noise in Earth gravity, which caps the ratio at "
               "about 3–6; the paper's f is kinematic (row 1): docs/departures.md#kinematic-gravity-mode")
    report.row("slalom, Earth gravity: the true-error covariance analysis of the filter predicts the Monte-Carlo ratio within 30 %", "—",
               round(cov_ratio, 2), bool(abs(cov_ratio / mc - 1) < 0.3), f"{100 * (cov_ratio / mc - 1):+.1f} % from the Monte Carlo")
    report.row("slalom, Earth gravity: the filter's own covariance ratio (conservative: readout correlated with the IMU noise)",
               "—", round(own_ratio, 2), REPORTED)
    aided = cai.slalom_covariance("earth", attitude_sigma=1e-5)
    report.row("slalom, Earth gravity + attitude aid (1e-5 rad per shot): covariance ratio at 60 s lifts the cap (> 3 × CAI only)", "—",
               round(float(aided["ratio"].iloc[-1]), 1), bool(aided["ratio"].iloc[-1] > 3 * cov_ratio))
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.8))
    ax.semilogy(cov["time_s"], cov["ratio"], label="Earth gravity (CAI only)")
    ax.semilogy(aided["time_s"], aided["ratio"], label="Earth gravity + attitude aid")
    kc = cai.slalom_covariance("kinematic")
    ax.semilogy(kc["time_s"], kc["ratio"], label="kinematic mode")
    _save(report, fig, ax, ("time (s)", "free / hybrid RMS velocity error"), "cai_hybrid_slalom_cap",
          "Slalom, covariance analysis: the CAI cannot observe tilt, so in Earth gravity the gain is capped; an attitude aid lifts the cap")


def _save(report, fig, ax, labels, name, caption):
    """Label the axes (x, y), add the legend and save the figure into the report."""
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.legend(fontsize=8)
    report.figure(fig, name, caption)


def _car(report):
    runs = 8 if report.quick else 100
    res = cai.car_mc(runs, progress=report.progress)
    ratio = res.improvement([25.0]).query("quantity == 'velocity' and axis == 'norm'")["ratio"].iloc[0]
    report.row(f"car: velocity error IMU-only/hybrid at 25 s ({runs} runs), Tennstedt et al. 2023", "≈100 at best, ≥ 30", round(ratio, 1), bool(ratio >= 30))
    _improvement_rows(report, res, [10.0, 25.0, 40.0], "car")
    frac = res.phase_exceedance()
    report.row("car: shot-channels with |phase error| > π/2 [%] (lever arm 0; 1–40 %), Tennstedt et al. 2023", "≈14", round(100 * frac, 2), bool(0.01 <= frac <= 0.4))
    report.row("car: NEES inside the 95 % χ²(15) band [share of epochs] (filter consistent: ≥ 0.85)", "—", round(res.nees_inside(), 3),
               bool(res.nees_inside() >= 0.85))
    b = res.bias_errors()
    acc = float(np.mean([b[f"{c}_in3sigma"].mean() for c in cai.BIAS_COLUMNS[:3]]))
    report.row("car: accelerometer-bias error inside the filter's 3σ [share of shots] (≥ 0.95)", "—", round(acc, 3), bool(acc >= 0.95))
    lev = cai.car_mc(runs, lever=(0.0, 0.0, 0.1), progress=report.progress)
    r_lev = lev.improvement([25.0]).query("quantity == 'velocity' and axis == 'norm'")["ratio"].iloc[0]
    report.row("car, lever arm [0, 0, 0.1] m: velocity error ratio at 25 s / fringe slips [%]", "—", f"{r_lev:.1f} / {100 * lev.phase_exceedance():.2f}",
               REPORTED, "the Euler lever-arm term of the 15 Hz vibration: docs/departures.md#euler-lever-arm-term")
    _errors_figure(report, res, "cai_hybrid_car", f"Car Monte Carlo, kinematic mode, {runs} runs: velocity errors, accelerometer-bias error and filter σ")


def _satellite(report):
    res = cai.satellite(1.0 if report.quick else 4.0, progress=report.progress)
    st = cai.satellite_steady_state(res)
    report.row("satellite: steady-state accel-bias variance P⁺ [(m/s²)²] (within a factor 2), Tennstedt et al. 2021 Table 1", 4.82e-20,
               st["filter_p_post"], bool(0.5 <= st["filter_p_post"] / 4.821853e-20 <= 2))
    report.row("satellite: std of the bias tracking error [m/s²] (within 10 % of an independent computation)", "—", st["tracking_error_std"],
               bool(abs(st["tracking_error_std"] / 2.196e-10 - 1) < 0.1), "independent computation: 2.196e-10 m/s²")
    _improvement_rows(report, res, [res.time[-1]], "satellite")
    psd = cai.satellite_psd(res, nperseg=2**14 if report.quick else 2**15)
    f = psd["frequency_hz"].to_numpy()
    ratio = (psd["filtered_asd"] / psd["imu_asd"]).to_numpy() ** 2
    hi, lo = ratio[f > 0.1].mean(), ratio[f <= 3e-4].mean()
    report.row("satellite: PSD filtered / IMU above 0.1 Hz, Tennstedt et al. 2021 §5.2", "1 (± 10 %)", round(hi, 3), bool(abs(hi - 1) < 0.1))
    report.row("satellite: PSD filtered / IMU below 3e-4 Hz, Tennstedt et al. 2021 §5.2", "flattened (ASD ratio ≤ 0.2)", round(lo, 4), bool(lo < 0.04))
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.8))
    for col, lab in (("imu_asd", "IMU error"), ("filtered_asd", "IMU − b̂ (hybrid)")):
        ax.loglog(psd["frequency_hz"], psd[col], label=lab)
    ax.axhline(psd.attrs["cai_asd"], color="k", ls=":", label="CAI per-shot noise")
    _save(report, fig, ax, ("frequency (Hz)", "ASD (m/s²/√Hz)"), "cai_hybrid_satellite",
          "Satellite (Tennstedt et al. 2021, §5.2, drift variant): ASD of the accelerometer error, raw and CAI-corrected")


def _hexapod(report):
    runs = 1 if report.quick else 20
    res = cai.hexapod(runs, progress=report.progress)
    k = res.epoch(60.0)
    err = res.bias[:, k, :] - res.bias_true[:, k, :]
    inside = float(np.mean(np.all(np.abs(err) <= 3 * res.sigma[:, k, 9:15], axis=1)))
    report.row(f"hexapod: runs with all six bias errors within 3σ at 60 s ({runs} runs), Tennstedt et al. 2021 §5.3", "all (≥ 0.95 of runs)", inside,
               bool(inside >= 0.95))
    # absolute acceptance thresholds at 170 s; a consistent filter meets them in Π(1 − 2Φ(−thr/σ))
    # of runs, ≈ 91 % with the reference IMU's bias random walk (σ ≈ 4.2e-5 m/s², 2.0e-6 rad/s)
    from scipy.stats import norm

    thr = np.r_[np.full(3, 1e-4), np.full(3, 5e-6)]
    within = float(np.mean(np.all(np.abs(res.bias[:, -1] - res.bias_true[:, -1]) < thr, axis=1)))
    expect = float(np.prod(1 - 2 * norm.sf(thr / res.sigma[:, -1, 9:15].mean(axis=0))))
    report.row(f"hexapod: runs with |δb_a| < 1e-4 m/s², |δb_g| < 5e-6 rad/s at 170 s ({runs} runs)", "—", round(within, 2), REPORTED,
               f"the thresholds are 2.4σ of the reference IMU's bias random walk, so a consistent filter meets them in {expect:.2f} "
               "of runs: docs/departures.md#hexapod-scenario")
    _improvement_rows(report, res, [60.0, 170.0], "hexapod")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(12, 5), sharex=True)
    for i, ax in enumerate(axes.ravel()):
        ax.plot(res.time, res.bias[0, :, i], "C0", lw=1, label="estimate")
        ax.plot(res.time, res.bias_true[0, :, i], "k--", lw=1, label="injected (MEMS − reference)")
        ax.fill_between(res.time, res.bias[0, :, i] - 3 * res.sigma[0, :, 9 + i], res.bias[0, :, i] + 3 * res.sigma[0, :, 9 + i], alpha=0.2)
        ax.set_title(cai.BIAS_COLUMNS[i], fontsize=8)
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    report.figure(fig, "cai_hybrid_hexapod", "Hexapod (Tennstedt et al. 2021, §5.3): MEMS bias estimates with ±3σ vs the injected values (run 0)")


@section("cai_hybrid", "CAI-aided navigation end to end (Tennstedt et al. 2023 slalom and car, Tennstedt et al. 2021 satellite and hexapod)")
def run(report):
    _slalom(report)
    _car(report)
    _satellite(report)
    _hexapod(report)
