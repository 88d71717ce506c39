"""Your own data (e): single-point positioning and tightly coupled GNSS/INS from my RINEX
files and IMU log.

    python examples/spp_and_tight_from_rinex.py [workdir]

The script first writes the files a user would have into ``workdir`` (default: a new
temporary directory): a RINEX 3 navigation file (GPS and GLONASS broadcast ephemerides),
a RINEX 3 observation file (C1C code, D1C Doppler at 1 Hz) of a receiver in a car, and
``imu_100hz.csv``, the car's 100 Hz tactical-grade IMU log (time in GPS seconds of the
week, angular rate rad/s, specific force m/s²), for a five-minute drive at 15 m/s with
the heading swinging by ±57°. It then runs the README's code on those files: single-point
positioning with the GPS–GLONASS time offset τ_GPS (Demidov 2009, §2.7) and the tightly
coupled filter on between-satellite differences (Demidov 2009, §2.12), started from the
first fix alone. The check: the SPP error has the statistics its geometry predicts
(σ_code·HDOP) and the tightly coupled solution is better than SPP and inside its own
3σ bounds.
"""

import numpy as np
import pandas as pd

import atomnav as an
from atomnav.gnss import rinex                  # RINEX 2/3/4, Hatanaka, gzip: read in the core
from _workdir import enter

workdir = enter()

# --- the user's files, simulated -------------------------------------------------------
DURATION, RATE = 300.0, 100.0
truth = an.trajectory.drive_with_yaw(RATE, origin=(np.radians(52.38), np.radians(9.72), 60.0), speed=15.0,
                                     yaw_rate_amp=np.radians(3.0), period=120.0, duration=DURATION,
                                     heading=np.radians(30.0))
log = an.imu.corrupt(truth.ideal_imu("rates"), errors="tactical", dt=1.0 / RATE, kind="rates", seed=3)
log[an.trajectory.IMU_COLUMNS["rates"]].to_csv("imu_100hz.csv", index=False)   # no bias truth in a user's log
eph_true = an.gnss.Ephemerides.nominal(0.0, DURATION, seed=1)        # GPS + GLONASS
t_gnss = np.arange(0.0, DURATION + 0.5, 1.0)
at = np.rint(t_gnss * RATE).astype(int)
obs_true = an.gnss.simulate(eph_true, t_gnss, truth.lla[at], truth.vel_ned[at], tau_gps=-340e-9,
                            clock_bias=2e-4, clock_drift=1e-8, seed=2)   # code σ 3 m, rate σ 0.05 m/s
rinex.write_nav("brdc.nav.rnx", eph_true)
rinex.write_obs("rover.obs.rnx", obs_true)

# --- the README's walkthrough ---------------------------------------------------------
eph = rinex.read_nav("brdc.nav.rnx")                  # GPS and GLONASS broadcast ephemerides
obs = rinex.read_obs("rover.obs.rnx", eph).table      # time_s (GPS s of week), sat, channel, code_m, rate_mps
spp = an.gnss.solve(eph, obs).epochs                  # per epoch: lat_rad, lon_rad, h_m, clock_m, tau_gps_s, DOP, ECEF velocity
print(spp[["time_s", "lat_rad", "lon_rad", "h_m", "tau_gps_s", "n_sats", "hdop"]].head().to_string())

imu = pd.read_csv("imu_100hz.csv")                    # time_s (GPS s of week), gyro_*_rad_s, accel_*_mps2
first = spp.iloc[0]                                   # start from the first fix: level, heading along the track
lla0 = first[["lat_rad", "lon_rad", "h_m"]].to_numpy(float)
vel0 = an.earth.dcm_ned_to_ecef(lla0[0], lla0[1]).T @ first[["vx_mps", "vy_mps", "vz_mps"]].to_numpy(float)
q0 = an.rotation.quat_from_euler([0.0, 0.0, np.arctan2(vel0[1], vel0[0])])
datasheet = an.imu.ImuErrors.preset("tactical")       # or your IMU's values: an.imu.ImuErrors(accel=..., gyro=...)
acc, gyr = datasheet.accel, datasheet.gyro
p0 = np.diag([5.0**2] * 3 + [0.3**2] * 3 + [np.radians(1.0)**2] * 2 + [np.radians(3.0)**2]
             + [acc.bias_sigma**2] * 3 + [gyr.bias_sigma**2] * 3)   # position m, velocity m/s, ψ rad, biases
ins = an.gnss.tight_ins(eph, obs, t0=first["time_s"], lla0=lla0, vel0=vel0, q0=q0, kind="rates", p0_ins=p0,
                        accel_psd=acc.white**2, gyro_psd=gyr.white**2,
                        accel_bias=an.filter.BiasModel("random_walk", psd=acc.bias_rw**2),
                        gyro_bias=an.filter.BiasModel("random_walk", psd=gyr.bias_rw**2),
                        predict_every=100)             # covariance propagated once a second (100 IMU samples)
result = ins.run(imu["time_s"], imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]],
                 imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]], progress=False)
print(result.nav[["time_s", "lat_rad", "lon_rad", "h_m", "sigma_position[0]", "sigma_position[1]"]].tail().to_string())

# --- check against the simulated receiver ---------------------------------------------
ned = an.earth.lla_to_ned(spp[["lat_rad", "lon_rad", "h_m"]].to_numpy(), truth.lla[0]) - \
      an.earth.lla_to_ned(truth.lla[at], truth.lla[0])
spp_rms = np.sqrt(np.mean(ned[:, 0] ** 2 + ned[:, 1] ** 2))
predicted = 3.0 * np.sqrt(np.mean(spp["hdop"] ** 2))              # σ_code·HDOP, RMS over the epochs
err = truth.errors(result.nav)
settled = err["time_s"] > 60.0
tight_rms = np.sqrt(np.mean(err["dpos_n_m"][settled] ** 2 + err["dpos_e_m"][settled] ** 2))
sigma = result.nav[["sigma_position[0]", "sigma_position[1]", "sigma_position[2]"]].to_numpy()[settled.to_numpy()]
inside = np.mean(np.abs(err[["dpos_n_m", "dpos_e_m", "dpos_d_m"]].to_numpy()[settled.to_numpy()]) < 3 * sigma)
print(f"SPP horizontal RMS {spp_rms:.2f} m (σ_code·HDOP predicts {predicted:.2f} m); "
      f"tight GNSS/INS after 60 s {tight_rms:.2f} m, {100 * inside:.1f} % of the N/E/D errors inside 3σ")
# the mean square of n independent epochs has a relative standard deviation of at most
# √(2/n) (one dominant axis), its root half that: 3 of those either side
assert abs(spp_rms / predicted - 1.0) < 3.0 * np.sqrt(0.5 / len(spp)), (spp_rms, predicted)
assert tight_rms < spp_rms, (tight_rms, spp_rms)
assert inside >= 0.99, inside                   # 99.73 % for a consistent Gaussian filter
