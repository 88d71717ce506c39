"""Reproduction section ``gnss``: tight GPS + GLONASS / INS integration
(Demidov 2009): the τ_GPS experiment, INS class × satellite
count, open- vs closed-loop NEES, outage recovery."""

from __future__ import annotations

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from .. import earth
from ..gnss import Ephemerides, GnssOptions, simulate, solve
from ..gnss import scenarios as S
from . import REPORTED, section

LLA = np.array([np.radians(55.75), np.radians(37.6), 200.0])
TAU = -340e-9


def _tau_experiment(report, hours: float):
    t = np.arange(0.0, hours * 3600.0, 600.0)
    eph = Ephemerides.nominal(0.0, t[-1] + 600.0, tau_gps=TAU, seed=1)
    obs = simulate(eph, t, np.tile(LLA, (len(t), 1)), np.zeros((len(t), 3)), tau_gps=TAU, clock_bias=1e-4, seed=2)
    o = obs.sort_values(["time_s", "elevation_rad"], ascending=[True, False])
    obs = pd.concat([o[o.sat.str[0] == "G"].groupby("time_s").head(8), o[o.sat.str[0] == "R"].groupby("time_s").head(4)])
    obs = obs.sort_values(["time_s", "sat"]).reset_index(drop=True)
    truth = earth.lla_to_ecef(LLA)
    # the thesis's least squares has no fault exclusion (without τ every GLONASS residual is a "fault")
    plain = GnssOptions(fault_detection=False)
    sol = {"joint + τ": solve(eph, obs, plain).epochs, "joint, no τ": solve(eph, obs, plain, use_tau=False).epochs,
           "GPS only": solve(eph, obs[obs.sat.str[0] == "G"], plain).epochs}
    xyz = ["x_m", "y_m", "z_m"]
    paper = {"joint + τ": 4.0, "joint, no τ": 65.0, "GPS only": 3.0}
    for k, s in sol.items():
        report.row(f"residual metric (m), {k}; Demidov 2009 Eq. 23", paper[k], float(s.residual_metric_m.mean()), REPORTED,
                   f"ratio {s.residual_metric_m.mean() / paper[k]:.2f}")
    m = {k: s.residual_metric_m.mean() for k, s in sol.items()}
    report.row("metric joint+τ ÷ GPS-only (< 2), Demidov 2009", "4/3", m["joint + τ"] / m["GPS only"], bool(m["joint + τ"] < 2 * m["GPS only"]))
    report.row("metric no-τ ÷ joint+τ (> 10), Demidov 2009", "65/4", m["joint, no τ"] / m["joint + τ"], bool(m["joint, no τ"] > 10 * m["joint + τ"]))
    tau = sol["joint + τ"].tau_gps_s.to_numpy()
    report.row("τ_GPS mean (ns), within 25 ns; Demidov 2009", -340.0, tau.mean() * 1e9, bool(abs(tau.mean() - TAU) < 25e-9))
    report.row("τ_GPS single-epoch std (ns)", "—", tau.std() * 1e9, REPORTED)
    bias = np.linalg.norm((sol["joint, no τ"][xyz].to_numpy() - truth).mean(axis=0))
    report.row("position bias without τ_GPS (m) (> 30), Demidov 2009", "≈ 104", bias, bool(bias > 30))
    d = sol["joint + τ"][xyz].to_numpy() - sol["GPS only"][xyz].to_numpy()
    report.row("joint+τ vs GPS-only, RMS (m), Demidov 2009", "≈ 2", float(np.sqrt((d ** 2).sum(1).mean())), REPORTED)


@section("gnss", "Tight GPS + GLONASS / INS (Demidov 2009): τ_GPS, classes × satellites, OL vs CL, outages")
def run(report):
    import matplotlib.pyplot as plt

    q = report.quick
    _tau_experiment(report, 6.0 if q else 24.0)

    # class × satellite count: horizontal RMS over the last 10 min (fixed top-n satellites),
    # over 40 min also when quick (with the baro-damped vertical channel three
    # satellites need longer than 20 min to separate the altitude offset of the vertical
    # accelerometer bias from the horizontal)
    dur = 2400.0
    table = {}
    for cls in tqdm(("precise", "medium", "coarse"), desc="class × satellites", disable=not report.progress, leave=False):
        for n in (None, 3, 2, 0):
            table[(cls, "all" if n is None else n)] = S.last_rms(S.run(S.Scenario(cls, duration_s=dur, n_sats=n))["errors"])
    # the acceptance 3 ≤ 3 × all is for the precise class; the others are reported: with the
    # baro-damped channel the vertical accelerometer bias holds the altitude off by
    # b_a/ω_v² (≈ 300 m for the coarse class's 3 mg), which two first-difference rows
    # separate from the horizontal slowly
    for cls in ("precise", "medium", "coarse"):
        full, three, two, free = (table[(cls, k)] for k in ("all", 3, 2, 0))
        report.row(f"{cls}: horizontal RMS last 10 min, all / 3 / 2 / 0 satellites (m); 3 ÷ all, Demidov 2009",
                   "3 ≤ 3 × all (precise class)" if cls == "precise" else "—",
                   f"{full:.2f} / {three:.2f} / {two:.0f} / {free:.0f}; {three / full:.1f}",
                   bool(three <= 3 * full) if cls == "precise" else REPORTED)

    # open vs closed loop NEES over time
    dur = 1200.0 if q else 3600.0
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True)
    worst = {}
    for a, cls in zip(ax, tqdm(("precise", "medium"), desc="open vs closed loop", disable=not report.progress, leave=False)):
        for mode in ("closed", "open"):
            e = S.run(S.Scenario(cls, motion="MOVE" if cls == "precise" else "STAT", duration_s=dur, mode=mode))["errors"]
            d3 = np.sqrt(e.dpos_n_m ** 2 + e.dpos_e_m ** 2 + e.dpos_d_m ** 2)
            worst[(cls, mode)] = float(d3[e.time_s > 60.0].max())
            w = e.groupby((e.time_s // 300).astype(int))
            a.semilogy(w.time_s.mean() / 60, w.nees.mean(), "o-", label=f"{mode} loop")
            inside = float(((e.nees > 4.60) & (e.nees < 32.80)).mean())
            report.row(f"{cls} INS, {mode} loop: fraction of epochs in the χ²₁₅ 99 % band; final error (m), Demidov 2009",
                       "CL consistent, OL fails (1 °/h)", f"{inside:.2f}; {e.horizontal_m.iloc[-1]:.2f}", REPORTED)
        a.axhspan(4.60, 32.80, color="0.9")
        a.set(xlabel="time (min)", title=f"{cls} INS", ylabel="NEES (5-min mean, 15 states, diagonal)")
        a.legend()
    report.figure(fig, "nees", "Open- vs closed-loop NEES (diagonal, 15 INS states), grey: χ²₁₅ 99 % band.")
    ol, cl = worst[("precise", "open")], worst[("precise", "closed")]
    report.row(f"precise INS (baro-damped vertical), max 3-D position error after 1 min over {dur / 60:.0f} min, "
               "open / closed loop (m), Demidov 2009", "OL ≤ 2 m, ≈ CL (within 20 %)", f"{ol:.2f} / {cl:.2f}",
               bool(ol < 2.0 and cl < 2.0 and abs(ol / cl - 1) <= 0.2))

    # outages
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8))
    lengths = (5, 20) if q else (1, 5, 10, 20)
    for a, cls in zip(ax, tqdm(("precise", "coarse"), desc="outages", disable=not report.progress, leave=False)):
        for m in lengths:
            e = S.run(f"outage_{cls}_{m}min")["errors"]
            s = S.outage_summary(e, 900.0, 60.0 * m)
            report.row(f"{cls} INS, {m}-min outage: error at end / RMS 1–10 min after / at 4–5 min (m); at 4–5 min ≤ 2 × before, Demidov 2009",
                       "0.05 °/h insensitive; 30 °/h ≤ 5–10 min", f"{s['end']:.1f} / {s['post']:.2f} / {s['at5']:.2f}",
                       bool(s["at5"] <= 2 * s["pre"]))
            a.semilogy(e.time_s / 60, e.horizontal_m, label=f"{m} min")
        a.set(xlabel="time (min)", ylabel="horizontal error (m)", title=f"{cls} INS, outage from 15 min")
        a.legend()
    report.figure(fig, "outages", "Horizontal error through GNSS outages starting at 15 min (MOVE, closed loop).")
