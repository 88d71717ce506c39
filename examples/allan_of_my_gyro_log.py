"""Your own data (d): Allan deviation and noise fit of my gyro log, turned into an IMU
error model for simulation.

    python examples/allan_of_my_gyro_log.py [workdir]

The script first writes the file a user would have into ``workdir`` (default: a new
temporary directory): ``gyro_static_8h.csv``, an 8-hour static record of a three-axis
gyro at 10 Hz in °/h, simulated with known angle random walk (ARW), bias instability and
rate random walk (RRW). It then runs the README's code on it: the overlapping Allan
deviation, the IEEE Std 952 fit of those three terms, and the fitted model as an
``ImuErrors`` driving the IMU simulator. The check: the fitted ARW, bias instability
and RRW lie within three standard deviations of the simulated values, the standard
deviation being the spread of the same fit over independent records of the same noise.
"""

import numpy as np
import pandas as pd

import atomnav as an
from _workdir import enter

workdir = enter()

# --- the user's file, simulated -------------------------------------------------------
ARW, BIAS_INSTABILITY, RRW = 0.02, 0.5, 3.0       # °/√h, °/h, °/h/√h
DT, N = 0.1, 8 * 3600 * 10                        # 10 Hz, 8 h
TRUTH = an.imu.ImuErrors(gyro=an.imu.TriadErrors(
    white=ARW * an.units.DEG_PER_SQRT_HOUR, bias_rw=RRW * an.units.DEG_PER_HOUR / 60,
    flicker=an.imu.Flicker(BIAS_INSTABILITY * an.units.DEG_PER_HOUR, f_lo=1e-5, f_hi=1.0)))
EARTH_RATE = an.earth.navigation_rates([[np.radians(52.4), 0.0, 50.0]], [[0.0, 0.0, 0.0]]).filter(
    like="earth_rate").to_numpy()[0]               # gyro at rest, level, x north, at 52.4°N (rad/s)
STATIC_ACCEL = np.array([0.0, 0.0, -9.81])          # specific force at rest, FRD (m/s²)


def static_gyro_log(seed):
    """Gyro rates (°/h) of an N-sample static record of the TRUTH noise."""
    sim = an.imu.ImuSimulator(TRUTH, DT, kind="rates", seed=seed)
    out = sim.corrupt(np.tile(STATIC_ACCEL, (N, 1)), np.tile(EARTH_RATE, (N, 1)))
    return out[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy() / an.units.DEG_PER_HOUR


log = pd.DataFrame(static_gyro_log(seed=1), columns=["gyro_x_deg_h", "gyro_y_deg_h", "gyro_z_deg_h"])
log.insert(0, "time_s", np.arange(N) * DT)
log.to_csv("gyro_static_8h.csv", index=False, float_format="%.6f")

# --- the README's walkthrough ---------------------------------------------------------
log = pd.read_csv("gyro_static_8h.csv")              # time_s, gyro_x_deg_h, gyro_y_deg_h, gyro_z_deg_h
tau0 = log["time_s"].diff().median()                 # sampling interval (s)
adev = an.noise.allan.allan_variance(log["gyro_x_deg_h"], tau0)   # tau_s, dev (°/h), 68 % interval dev_lo, dev_hi
print(adev[["tau_s", "dev", "dev_lo", "dev_hi"]].to_string())
fit = an.noise.allan.fit_allan(log["gyro_x_deg_h"], tau0, terms=("arw", "bias_instability", "rrw"))
errors = an.imu.ImuErrors.preset("tactical")         # keep the accelerometer of a datasheet ...
errors.gyro = fit.to_triad(an.units.DEG_PER_HOUR)    # ... and use the measured gyro noise (SI)
print(errors.summary().query("sensor == 'gyro'").to_string())  # ARW °/√h, RRW °/h/√h, bias instability °/h
sim = an.imu.ImuSimulator(errors, dt=0.01, kind="rates", seed=7)   # a 100 Hz IMU with that gyro, any motion

# --- check against the simulated noise ------------------------------------------------
def fitted(rates):
    """ARW (°/√h), bias instability (°/h), RRW (°/h/√h) of a rate series in °/h."""
    f = an.noise.allan.fit_allan(rates, DT, terms=("arw", "bias_instability", "rrw"))
    return np.array([f.arw / 60, f.bias_instability, f.rrw * 60])   # (°/h)·√s → °/√h, (°/h)/√s → °/h/√h


spread = np.std([fitted(axis) for seed in range(2, 12) for axis in static_gyro_log(seed).T], axis=0, ddof=1)
truth = np.array([ARW, BIAS_INSTABILITY, RRW])
for name, value, want, sd in zip(("ARW °/√h", "bias instability °/h", "RRW °/h/√h"), fitted(log["gyro_x_deg_h"]), truth, spread):
    print(f"{name}: fitted {value:.4g}, simulated {want:.4g}, standard deviation of the fit {sd:.2g}")
    assert abs(value - want) < 3 * sd, (name, value, want, sd)

# the simulator driven by the fitted model reproduces the fitted Allan curve: one hour at
# rest, its Allan deviation at 1, 10 and 100 s inside the 99 % interval around the fit
hour = sim.corrupt(np.tile(STATIC_ACCEL, (360_000, 1)), np.tile(EARTH_RATE, (360_000, 1)))["gyro_x_rad_s"]
check = an.noise.allan.allan_variance(hour / an.units.DEG_PER_HOUR, 0.01, taus=[1.0, 10.0, 100.0], confidence=0.99)
model = np.sqrt(fit.curve(check["tau_s"]))
print(pd.DataFrame({"tau_s": check["tau_s"], "simulated_dev": check["dev"], "fitted_dev": model}).to_string())
assert np.all((check["dev_lo"] <= model) & (model <= check["dev_hi"])), check
