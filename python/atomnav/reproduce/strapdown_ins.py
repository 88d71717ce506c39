"""Reproduction section ``strapdown``: the strapdown INS against exact and closed-form
references: round trip of an ideal IMU, the Schuler test of Demidov 2009 Ch. 1,
closed-form free-inertial error growth."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import diagnostics, earth, strapdown, trajectory, units
from . import REPORTED, section


def _round_trip(seconds: float, kind: str) -> pd.DataFrame:
    traj = trajectory.sinusoidal(seconds, rate_hz=100.0)
    nav = strapdown.integrate(traj.ideal_imu(kind), **traj.initial_state(), kind=kind)
    if kind == "increments":
        nav = pd.concat([traj.df.iloc[:1], nav], ignore_index=True)
    return traj.errors(nav)


def _east_channel(t, g, r, ba_e=0.0, bg_n=0.0):
    """Closed-form east-channel Schuler loop at the equator (Titterton & Weston §12.3)."""
    ws = np.sqrt(g / r)
    return ba_e * (1 - np.cos(ws * t)) / ws**2 + r * bg_n * (t - np.sin(ws * t) / ws)


@section("strapdown", "Strapdown INS: round trip, Schuler test, free-inertial error growth")
def run(report):
    import matplotlib.pyplot as plt

    seconds = 120.0 if report.quick else 600.0
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.5))
    for kind in ("rates", "increments"):
        err = _round_trip(seconds, kind)
        pos = np.linalg.norm(err[["dpos_n_m", "dpos_e_m", "dpos_d_m"]].to_numpy(), axis=1)
        att = np.linalg.norm(err[["psi_n_rad", "psi_e_rad", "psi_d_rad"]].to_numpy(), axis=1)
        report.row(f"round trip {seconds:g} s, {kind}: 3-D position error (m) of the exact IMU of a sinusoidal motion", "0 (exact); < 0.05", float(pos[-1]), bool(pos[-1] < 0.05))
        report.row(f"round trip {seconds:g} s, {kind}: attitude error (rad) of the exact IMU of a sinusoidal motion", "0 (exact); < 1e-6", float(att[-1]), bool(att[-1] < 1e-6))
        ax[0].semilogy(err["time_s"], pos + 1e-12, label=kind)
        ax[1].semilogy(err["time_s"], att + 1e-16, label=kind)
    ax[0].set(xlabel="time (s)", ylabel="|position error| (m)", title="ideal IMU round trip")
    ax[1].set(xlabel="time (s)", ylabel="|attitude error| (rad)")
    ax[0].legend()
    report.figure(fig, "round_trip", "Round trip of an exact 100 Hz IMU from a sinusoidal trajectory (free vertical channel).")

    lat = np.deg2rad(55.75)
    sch = diagnostics.schuler_test(lat, v0=200.0, hours=3.0 if report.quick else 4.5)
    p3 = float(np.mean(sch["periods_min"][:3]))
    report.row("Schuler period, mean of 3 zero-crossing periods (min), Demidov 2009 Ch. 1", 84.4, p3, REPORTED, f"ratio {p3 / 84.4:.4f}")
    report.row("Schuler period 2π√(R₀/γ) at 55.75°N (min), Demidov 2009 Ch. 1", 84.4, sch["schuler_period_min"], REPORTED,
               f"ratio {sch['schuler_period_min'] / 84.4:.4f}")
    report.row("Schuler zero-crossing periods (min), mean in 84.0–84.25 as an independent integration gives", "—",
               ", ".join(f"{p:.2f}" for p in sch["periods_min"][:3]), bool(84.0 <= p3 <= 84.25), "independent integration: 84.14, 84.06, 84.14")
    report.row("Schuler position amplitude (km), Demidov 2009 Ch. 1", 161.0, sch["position_peak_m"] / 1e3, REPORTED,
               f"ratio {sch['position_peak_m'] / 161e3:.3f}")
    report.row("Schuler tilt amplitude (deg), Demidov 2009 Ch. 1", 1.45, float(np.rad2deg(sch["tilt_peak_rad"])), REPORTED,
               f"ratio {np.rad2deg(sch['tilt_peak_rad']) / 1.45:.3f}")
    e = sch["errors"]
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(e["time_s"] / 60, e["dvel_n_mps"], label="δv_N")
    ax.plot(e["time_s"] / 60, e["dvel_e_mps"], label="δv_E")
    ax.set(xlabel="time (min)", ylabel="velocity error (m/s)", title="Schuler test: stationary INS, 200 m/s initial north error")
    ax.legend()
    report.figure(fig, "schuler", "Velocity error of a stationary INS at 55.75°N started with 200 m/s north error; the Foucault rotation moves energy to east.")

    g, r = earth.gravity(0.0, 100.0), earth.radii(0.0)[1] + 100.0
    hours = 1.0 if report.quick else 2.0
    cases = [("accelerometer bias 1e-4 m/s² east", dict(accel_bias=(0, 1e-4, 0)), dict(ba_e=1e-4)),
             ("gyro bias 0.01 °/h north", dict(gyro_bias=(0.01 * units.DEG_PER_HOUR, 0, 0)), dict(bg_n=0.01 * units.DEG_PER_HOUR))]
    for name, bias, cf in cases:
        err = diagnostics.stationary_errors(0.0, hours, **bias)
        ref = _east_channel(err["time_s"].to_numpy(), g, r, **cf)
        dev = float(np.abs(err["dpos_e_m"].to_numpy() - ref).max() / np.abs(ref).max())
        report.row(f"{name}: east position vs the closed form of Titterton & Weston 2004 §12.3 over {hours:g} h (max dev / amplitude)",
                   "0 (closed form); < 0.02", dev, bool(dev < 0.02))
