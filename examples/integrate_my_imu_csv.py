"""Your own data (a): integrate my IMU log (CSV in field units) and compare with my
reference trajectory.

    python examples/integrate_my_imu_csv.py [workdir]

The script first writes the files a user would have into ``workdir`` (default: a new
temporary directory): ``imu_log.csv``, two minutes of a tactical-grade IMU at 100 Hz on a
moving, turning platform, with its own column names and field units (time in ms, angular
rate in °/s, specific force in g), and ``reference.csv``, the true trajectory (latitude,
longitude and Euler angles in degrees). It then runs the README's code on them: read the
log with an explicit column and unit map, integrate it with the strapdown INS from the
reference's first sample, and compare. The check: the horizontal position error stays
below the free-inertial error bound of the simulated sensor errors (their bias truth,
angle and velocity random walk).
"""

import numpy as np
import pandas as pd

import atomnav as an
from _workdir import enter

workdir = enter()

# --- the user's files, simulated -------------------------------------------------------
DURATION, RATE = 120.0, 100.0
truth = an.trajectory.sinusoidal(DURATION, rate_hz=RATE)                 # ±20 m, ±0.3 rad yaw swings
sensor = an.imu.corrupt(truth.ideal_imu("rates"), errors="tactical", dt=1.0 / RATE, kind="rates", seed=11)
gyro = sensor[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy() / an.units.DEG
accel = sensor[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy() / an.units.G0
pd.DataFrame({"t_ms": np.rint(sensor["time_s"].to_numpy() * 1000).astype(np.int64),
              "ax_g": accel[:, 0], "ay_g": accel[:, 1], "az_g": accel[:, 2],
              "wx_dps": gyro[:, 0], "wy_dps": gyro[:, 1], "wz_dps": gyro[:, 2],
              "temp_C": 25.0}).to_csv("imu_log.csv", index=False)
ref = truth.df
pd.DataFrame({"time": ref["time_s"], "lat_deg": np.degrees(ref["lat_rad"]), "lon_deg": np.degrees(ref["lon_rad"]),
              "alt_m": ref["h_m"], "vn": ref["vn_mps"], "ve": ref["ve_mps"], "vd": ref["vd_mps"],
              "roll_deg": np.degrees(ref["roll_rad"]), "pitch_deg": np.degrees(ref["pitch_rad"]),
              "heading_deg": np.degrees(ref["yaw_rad"])}).to_csv("reference.csv", index=False)

# --- the README's walkthrough ---------------------------------------------------------
log = an.io.read_imu(
    "imu_log.csv", kind="rates", time_unit="ms", max_gap=0.015,
    columns={"time": "t_ms", "gyro_x": "wx_dps", "gyro_y": "wy_dps", "gyro_z": "wz_dps",
             "accel_x": "ax_g", "accel_y": "ay_g", "accel_z": "az_g"},
    units={"gyro": "deg/s", "accel": "g"})
print(log.report)                                     # samples, rate, gaps longer than max_gap (s)
reference = an.io.read_trajectory(
    "reference.csv", units={"lat": "deg", "lon": "deg", "euler": "deg"},
    columns={"time": "time", "lat": "lat_deg", "lon": "lon_deg", "h": "alt_m", "vn": "vn", "ve": "ve", "vd": "vd",
             "roll": "roll_deg", "pitch": "pitch_deg", "yaw": "heading_deg"})
nav = an.strapdown.integrate(log.data, kind=log.kind, **reference.initial_state())   # log.data: SI, time_s, gyro_*_rad_s, ...
err = reference.errors(nav)                          # NED position (m), velocity (m/s) and attitude ψ (rad) errors
print(err[["time_s", "dpos_n_m", "dpos_e_m", "dpos_d_m", "psi_d_rad"]].iloc[::3000].to_string())

# --- check against the simulated sensor errors -----------------------------------------
# Free-inertial error growth over t ≪ the Schuler period (Titterton & Weston 2004, §12.3):
# a horizontal accelerometer error b_a gives ½ b_a t², a gyro error b_g tilts the
# platform by b_g t and gives f b_g t³/6 with f the specific force; white noise of
# density VRW and ARW gives position σ of VRW t^{3/2}/√3 and f ARW t^{5/2}/√20 per axis.
# The bias terms take the largest simulated bias (turn-on + flicker) as if it were
# constant and aligned; the noise terms are 3σ over both horizontal axes.
tactical = an.imu.ImuErrors.preset("tactical")
b_a = np.linalg.norm(sensor.filter(like="accel_bias_").to_numpy(), axis=1).max()     # m/s²
b_g = np.linalg.norm(sensor.filter(like="gyro_bias_").to_numpy(), axis=1).max()      # rad/s
f = np.linalg.norm(truth.ideal_imu("rates")[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy(), axis=1).max()
t = err["time_s"].to_numpy() - err["time_s"].iloc[0]
bound = (0.5 * b_a * t**2 + f * b_g * t**3 / 6
         + 3 * np.sqrt(2) * (tactical.accel.white * t**1.5 / np.sqrt(3) + f * tactical.gyro.white * t**2.5 / np.sqrt(20)))
horizontal = np.hypot(err["dpos_n_m"], err["dpos_e_m"]).to_numpy()
print(f"horizontal error after {t[-1]:.0f} s: {horizontal[-1]:.1f} m (bound {bound[-1]:.1f} m); "
      f"largest fraction of the bound {np.max(horizontal[1:] / bound[1:]):.2f}")
assert np.all(horizontal <= bound + 1e-6), np.argmax(horizontal - bound)
