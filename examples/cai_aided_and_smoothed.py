"""Your own data (c): a CAI-aided INS on my IMU log and my interferometer shots, then
smoothed.

    python examples/cai_aided_and_smoothed.py [workdir]

The script first writes the files a user would have into ``workdir`` (default: a new
temporary directory): ``imu_200hz.csv``, 40 s of a navigation-grade IMU at 200 Hz in a
car (standing, accelerating, a sliding and a coordinated turn, a shock at 26 s; time in
s, angular rate rad/s, specific force m/s²), ``reference.csv``, the car's true
trajectory, and ``shots.csv``, the record of a six-channel cold-atom interferometer
(T = 25 ms, a shot every 50 ms): per shot its start time and, per channel, the measured
population and the laser phase the instrument applied. It then runs the README's code
on them: the CAI-aided INS (Tennstedt et al. 2023, §2.8) estimates the IMU biases from
the shots, and the Rauch–Tung–Striebel smoother (Rauch, Tung & Striebel 1965) runs back
over it. The check, against the simulated truth: the aided velocity error ends below the
free INS's; the smoothed velocity and bias errors are smaller than the filtered ones, and
the smoothed bias errors stay inside the smoother's 3σ.
"""

import numpy as np
import pandas as pd

import atomnav as an
from _workdir import enter

workdir = enter()

# --- the user's files, simulated -------------------------------------------------------
RATE = 200.0
truth = an.trajectory.car(rate_hz=RATE, origin=an.cai.HANNOVER, vibration=False)
ideal = truth.ideal_imu("rates")
sensor_log = an.imu.corrupt(ideal, errors="navigation", dt=1.0 / RATE, kind="rates", seed=1)
sensor_log[an.trajectory.IMU_COLUMNS["rates"]].to_csv("imu_200hz.csv", index=False)
truth.to_csv("reference.csv")
GYRO, ACCEL = ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"], ["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]
NAVIGATION = an.imu.ImuErrors.preset("navigation")
SENSOR = an.cai.CaiSensor(an.cai.Channels.cyclic(), 0.025, sigma_p=np.sqrt(1e-3), interpolation="cubic", omega_dot="pwl",
                          inflation=(NAVIGATION.accel.white**2, NAVIGATION.gyro.white**2))
T, CHANNELS = SENSOR.T, SENSOR.channels
shot_start = SENSOR.shots(0.5, truth.time[-1])           # one shot every 2T from 0.5 s
ideal_phase = an.cai.predict_phase(ideal["time_s"], ideal[ACCEL], ideal[GYRO], shot_start, T, CHANNELS,
                                   interpolation="cubic", omega_dot="pwl").total   # the instrument's true phase (rad)
# the instrument's real-time hybrid loop (Tennstedt et al. 2023, §2.8) steered every shot's
# laser phase to mid-fringe from its own bias-compensated prediction and recorded it with
# the measured population: emulated here by the same filter fed the true phase
noise = np.random.default_rng(5).normal(0.0, SENSOR.sigma_p, ideal_phase.shape)
s0 = truth.initial_state()
live = an.cai.cai_aided_ins(s0["t0"], s0["lla"], s0["vel_ned"], s0["q_nb"], SENSOR, shot_start, phase=ideal_phase,
                            noise=noise, kind="rates", setup=an.cai.seed003_filter())
live_nav = live.run(sensor_log["time_s"], sensor_log[GYRO], sensor_log[ACCEL], progress=False).nav
t_log = sensor_log["time_s"].to_numpy()
laser = np.empty_like(ideal_phase)
for j, ts in enumerate(shot_start):
    estimate = live_nav[live_nav["time_s"] <= ts + 1e-9].iloc[-1]     # before this shot's update
    window = sensor_log[(t_log > ts - 0.02) & (t_log <= ts + 2 * T + 1e-9)]  # the samples it had at the shot's end
    predicted = an.cai.predict_phase(window["time_s"], window[ACCEL], window[GYRO], [ts], T, CHANNELS,
                                     interpolation="cubic", omega_dot="pwl",
                                     bias_a=estimate.filter(like="accel_bias_").to_numpy(),
                                     bias_g=estimate.filter(like="gyro_bias_").to_numpy()).total[0]
    laser[j] = an.cai.steer_mid_fringe(predicted)
population = an.cai.readout(ideal_phase, laser, offset=SENSOR.offset, contrast=SENSOR.contrast) + noise
shots_file = pd.DataFrame({"shot_start_s": shot_start})
for j, name in enumerate(CHANNELS.names):
    shots_file[f"population_{name}"] = population[:, j]
    shots_file[f"laser_phase_{name}_rad"] = laser[:, j]
shots_file.to_csv("shots.csv", index=False)

# --- the README's walkthrough ---------------------------------------------------------
imu = pd.read_csv("imu_200hz.csv")                       # time_s, gyro_*_rad_s, accel_*_mps2
reference = an.trajectory.Trajectory.from_csv("reference.csv")
shots = pd.read_csv("shots.csv")                         # shot_start_s, population_<channel>, laser_phase_<channel>_rad
imu_noise = an.imu.ImuErrors.preset("navigation")        # your datasheet: densities and turn-on bias σ
sensor = an.cai.CaiSensor(an.cai.Channels.cyclic(), T=0.025, shot_period=0.05, offset=0.5, contrast=1.0,
                          sigma_p=np.sqrt(1e-3), interpolation="cubic", omega_dot="pwl",
                          inflation=(imu_noise.accel.white**2, imu_noise.gyro.white**2))  # IMU noise inside a shot
names = sensor.channels.names                            # x_A, x_B, y_A, y_B, z_A, z_B
setup = an.cai.FilterSetup(
    accel_psd=imu_noise.accel.white**2, gyro_psd=imu_noise.gyro.white**2,           # m²/s³, rad²/s
    accel_bias_psd=imu_noise.accel.bias_rw**2, gyro_bias_psd=imu_noise.gyro.bias_rw**2,  # m²/s⁵, rad²/s³
    predict_every=10,                                    # every 2T at 200 Hz
    sigma0=(1e-3, 1e-3, 1e-5, imu_noise.accel.bias_sigma, imu_noise.gyro.bias_sigma))  # m, m/s, rad, m/s², rad/s
start = reference.initial_state()
ins = an.cai.cai_aided_ins(start["t0"], start["lla"], start["vel_ned"], start["q_nb"], sensor, shots["shot_start_s"],
                           population=shots[[f"population_{n}" for n in names]],
                           laser_phase=shots[[f"laser_phase_{n}_rad" for n in names]], kind="rates", setup=setup,
                           smooth=True)                  # keep the forward pass for the RTS smoother
result = ins.run(imu["time_s"], imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]],
                 imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]], progress=False)
print(result.measurements["nis"].describe().to_string())   # NIS per shot, χ² with 6 degrees of freedom
filtered = reference.errors(result.nav)                  # NED position (m), velocity (m/s), attitude ψ (rad) errors
smoothed = reference.errors(result.smoothed.nav)         # the same for the Rauch–Tung–Striebel smoothed solution
print(result.smoothed.nav.filter(like="accel_bias_").iloc[::100].to_string())  # smoothed bias estimates (m/s²)

# --- check against the simulated truth --------------------------------------------------
def velocity_error(errors):
    """Norm of the NED velocity error (m/s) of each epoch."""
    return np.linalg.norm(errors[["dvel_n_mps", "dvel_e_mps", "dvel_d_mps"]].to_numpy(), axis=1)


free = reference.errors(an.strapdown.integrate(imu, kind="rates", **start))   # the same log without the CAI
end = free["time_s"] == filtered["time_s"].iloc[-1]
print(f"velocity error at {filtered['time_s'].iloc[-1]:.0f} s: CAI-aided {velocity_error(filtered)[-1]:.2e} m/s, "
      f"free INS {velocity_error(free)[end.to_numpy()][0]:.2e} m/s")
assert velocity_error(filtered)[-1] < velocity_error(free)[end.to_numpy()][0]
rms = lambda x: float(np.sqrt(np.mean(np.square(x))))
print(f"RMS velocity error: filtered {rms(velocity_error(filtered)):.2e} m/s, smoothed {rms(velocity_error(smoothed)):.2e} m/s")
assert rms(velocity_error(smoothed)) < rms(velocity_error(filtered))
# the bias estimates against the simulated biases: the smoother's are better, and inside its 3σ
at = np.searchsorted(truth.time, result.nav["time_s"].to_numpy() - 1e-9)
for sensor_name, unit in (("accel", "mps2"), ("gyro", "rad_s")):
    columns = [f"{sensor_name}_bias_{axis}_{unit}" for axis in "xyz"]
    true = sensor_log[columns].to_numpy()[at]
    error = {name: nav[columns].to_numpy() - true for name, nav in (("filtered", result.nav), ("smoothed", result.smoothed.nav))}
    sigma = result.smoothed.nav[[f"sigma_{sensor_name}_bias[{i}]" for i in range(3)]].to_numpy()
    inside = np.mean(np.abs(error["smoothed"]) < 3 * sigma)
    print(f"{sensor_name} bias RMS error: filtered {rms(error['filtered']):.2e}, smoothed {rms(error['smoothed']):.2e} "
          f"{unit}; smoothed errors inside 3σ on {100 * inside:.1f} % of the epochs")
    assert rms(error["smoothed"]) < rms(error["filtered"]) and inside >= 0.99, (sensor_name, inside)
