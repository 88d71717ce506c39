"""Initial alignment (atomnav.alignment) on simulated static records with known truth: a
tactical-grade IMU at rest for 5 min at 100 Hz, corrupted by the library's IMU simulator.

Oracles, independent of the code under test: the attitude truth of the trajectory (as a
DCM from scipy), the simulator's bias truth columns, the tactical preset's noise
densities, and the closed forms of static alignment (Titterton & Weston 2004, §10.3):
levelling tilts the estimated down axis by the accelerometer bias across it over g, and
gyrocompassing turns north by the east gyro bias over the horizontal Earth rate (exactly:
atan2(b_E, Ω cos φ + b_N)), each plus the white noise averaged over the record."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

import atomnav as an
from atomnav import alignment

EULER = (0.01, -0.02, 0.7)  # roll, pitch, yaw (rad) of the vehicle at rest
OMEGA = 7.292115e-5  # WGS-84 Earth rate (rad/s)
RATE_HZ, DURATION = 100.0, 300.0
COARSE_ROWS = 6001  # the first 60 s: the coarse alignment of the fine-alignment runs
TRUTH = Rotation.from_euler("ZYX", EULER[::-1]).as_matrix()  # C_b^n = Rz Ry Rx
TACTICAL = an.imu.ImuErrors.preset("tactical")
ACCEL_BIAS = [f"accel_bias_{a}_mps2" for a in "xyz"]
GYRO_BIAS = [f"gyro_bias_{a}_rad_s" for a in "xyz"]


@pytest.fixture(scope="module")
def site():
    traj = an.trajectory.stationary(DURATION, rate_hz=RATE_HZ, euler=EULER)
    return traj.ideal_imu("rates"), traj.lla[0]


def record(ideal: pd.DataFrame, seed: int) -> pd.DataFrame:
    return an.imu.corrupt(ideal, errors="tactical", dt=1.0 / RATE_HZ, kind="rates", seed=seed)


def dcm(q) -> np.ndarray:
    return Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()


def coarse_residuals(ideal, lla, seed: int, with_noise: bool) -> tuple[np.ndarray, np.ndarray, object]:
    """(tilt of the estimated down axis across the true one in the body frame, 2;
    heading error) minus their closed forms, in units of the white-noise σ of each, and
    the alignment. The closed forms take the simulator's bias truth averaged over the
    record and, ``with_noise``, its white-noise realisation too (measured − ideal − bias)."""
    meas = record(ideal, seed)
    c = alignment.coarse(meas, lla, errors="tactical", kind="rates")
    est = dcm(c.q_nb)
    horizon = len(meas) / RATE_HZ  # the time the means average over
    accel, gyro = [f"accel_{a}_mps2" for a in "xyz"], [f"gyro_{a}_rad_s" for a in "xyz"]
    g = np.linalg.norm(meas[accel].to_numpy().mean(axis=0))  # |f̄|: −f̄/|f̄| is (g d − b)/|f̄| exactly
    ba, bg = meas[ACCEL_BIAS].to_numpy().mean(axis=0), meas[GYRO_BIAS].to_numpy().mean(axis=0)
    if with_noise:
        ba, bg = (meas[accel].to_numpy() - ideal[accel].to_numpy()).mean(axis=0), (meas[gyro].to_numpy() - ideal[gyro].to_numpy()).mean(axis=0)
    # levelling: the estimated down axis in the body frame moves by −(b_a across it)/g
    down = TRUTH.T @ np.array([0.0, 0.0, 1.0])
    across = np.linalg.svd(np.eye(3) - np.outer(down, down))[0][:, :2]  # two body axes across down
    tilt = across.T @ (est.T @ np.array([0.0, 0.0, 1.0]) - down)
    limit = -across.T @ ba / g
    sigma_tilt = TACTICAL.accel.white / np.sqrt(horizon) / g
    # gyrocompassing: north turns by atan2(b_E, Ω cos φ + b_N), less tan φ times the north tilt
    ban, bgn = TRUTH @ ba, TRUTH @ bg
    heading = np.arctan2(bgn[1], OMEGA * np.cos(lla[0]) + bgn[0]) - np.tan(lla[0]) * ban[1] / g
    yaw_error = np.angle(np.exp(1j * (c.euler[2] - EULER[2])))  # yaw_est − yaw = −ψ_D
    sigma_heading = TACTICAL.gyro.white / np.sqrt(horizon) / (OMEGA * np.cos(lla[0]))
    return (tilt - limit) / sigma_tilt, (-yaw_error - heading) / sigma_heading, (c, sigma_tilt, sigma_heading)


@pytest.mark.parametrize("seed", range(5))
def test_coarse_attitude_is_the_closed_form_of_the_simulated_errors(site, seed):
    """With the simulated errors known in full (biases and noise), the coarse attitude is
    their closed form up to second-order terms (a few % of the noise σ here)."""
    tilt, heading, _ = coarse_residuals(*site, seed, with_noise=True)
    assert np.all(np.abs(tilt) < 0.05) and abs(heading) < 0.05, (tilt, heading)


def test_stated_accuracy_is_the_closed_form_of_the_error_model(site):
    """For turn-on biases σ_a, σ_g and white noise N_a, N_g (no slower processes), the
    stated variances of ψ are (σ_a/g)² (tilts) and (σ_g/(Ω cos φ))² + (tan φ σ_a/g)²
    (heading), plus the same forms of the white-noise terms N/√T, which are also stated
    on their own."""
    ideal, lla = site
    errors = an.imu.ImuErrors.preset("tactical")
    errors.accel.flicker = errors.gyro.flicker = None
    meas = an.imu.corrupt(ideal, errors=errors, dt=1.0 / RATE_HZ, kind="rates", seed=1)
    c = alignment.coarse(meas, lla, errors=errors, kind="rates")
    horizon, lat = len(meas) / RATE_HZ, lla[0]
    g = np.linalg.norm(ideal[[f"accel_{a}_mps2" for a in "xyz"]].to_numpy().mean(axis=0))
    wh = OMEGA * np.cos(lat)
    noise_tilt, noise_gyro = errors.accel.white / np.sqrt(horizon) / g, errors.gyro.white / np.sqrt(horizon) / wh
    bias_tilt, bias_gyro = errors.accel.bias_sigma / g, errors.gyro.bias_sigma / wh
    want_noise = np.array([noise_tilt, noise_tilt, np.hypot(noise_gyro, np.tan(lat) * noise_tilt)]) ** 2
    want_bias = np.array([bias_tilt, bias_tilt, np.hypot(bias_gyro, np.tan(lat) * bias_tilt)]) ** 2
    np.testing.assert_allclose(np.diag(c.psi_cov_noise), want_noise, rtol=1e-3)
    np.testing.assert_allclose(np.diag(c.psi_cov) - np.diag(c.psi_cov_noise), want_bias, rtol=1e-3)


def test_coarse_attitude_is_within_3_sigma_of_the_bias_limit(site):
    """Acceptance: roll/pitch within 3σ of accel bias / g and heading within 3σ of gyro
    bias / (Ω cos φ), σ the white noise averaged over the record. Jointly over 20 seeds
    (two tilts and the heading each): the sum of the 60 squared normalised residuals
    stays below the χ² quantile of the 3σ probability (0.9973)."""
    z = []
    for seed in range(20):
        tilt, heading, _ = coarse_residuals(*site, seed, with_noise=False)
        z += list(tilt) + [heading]
    assert np.sum(np.square(z)) < chi2.ppf(0.9973, len(z)), z


def test_coarse_summary_reads_in_degrees_with_units(site):
    ideal, lla = site
    c = alignment.coarse(record(ideal, 0), lla, errors="tactical", kind="rates")
    text = str(c)
    for word in ("roll", "pitch", "yaw", "deg", "arcmin", "°/h", "static test"):
        assert word in text, text
    state = c.state
    assert set(state) == {"t0", "lla", "vel_ned", "q_nb"} and state["t0"] == DURATION


def attitude_nees(ideal, lla, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """NEES of the fine-alignment attitude at the kept update epochs, and their times."""
    meas = record(ideal, seed)
    c = alignment.coarse(meas.iloc[:COARSE_ROWS], lla, errors="tactical", kind="rates")
    f = alignment.fine(meas.iloc[COARSE_ROWS:], lla, c)
    nav = f.result.nav
    rows = np.searchsorted(nav["time_s"].to_numpy(), f.covariance_time - 1e-6)
    att = [f.labels.index(f"attitude[{i}]") for i in range(3)]
    out = []
    for k, row in enumerate(rows):
        q = nav.iloc[row][["qw", "qx", "qy", "qz"]].to_numpy(dtype=float)
        # Ĉ = (I − [ψ×])C ≈ exp(−[ψ×])C, so ψ is the rotation vector of C Ĉᵀ
        psi = Rotation.from_matrix(TRUTH @ dcm(q).T).as_rotvec()
        p = f.covariance[k][np.ix_(att, att)]
        out.append(psi @ np.linalg.solve(p, psi))
    return np.array(out), f.covariance_time


def nees_fraction_in_band(site, seeds: int) -> float:
    """Share of epochs whose NEES averaged over `seeds` runs is inside the two-sided 95 %
    band of χ²(3·seeds)/seeds (Bar-Shalom, Li & Kirubarajan 2001, §5.4.2)."""
    ideal, lla = site
    nees = np.mean([attitude_nees(ideal, lla, s)[0] for s in range(seeds)], axis=0)
    lo, hi = chi2.ppf([0.025, 0.975], 3 * seeds) / seeds
    return float(np.mean((nees >= lo) & (nees <= hi)))


# Not met yet: the averaged attitude NEES rises from about 3.3 to 4.6 over the 240 s
# (the upper bound is 4.2 for 20 seeds): 46 % of epochs in band with 20 seeds, 24 % with
# 100. Ruled out: the ZUPT model (the engine's velocity
# fixes give identical results), the ψ–bias correlation of P0, the IMU kind, the
# prediction rate, a specific force with the bias-estimate error in F. Found: in the
# engine's open-loop mode the tilts are consistent and the heading NEES grows with the
# size of the heading error (a tactical gyro leaves 0.1–0.3 rad at 56°N, beyond the
# small-angle ψ model; with a tenth of the gyro bias it is in band); in closed loop the
# north tilt is also overconfident whenever both the heading and the horizontal
# accelerometer bias are uncertain (with either known, it is consistent). Both point at the
# second-order term ψ_D·ψ_tilt of the small-angle model (0.1 rad × 1 mrad, the size of
# the tilt signal itself), which changes as closed-loop feedback turns the heading; a
# large-heading error model is the likely fix.
# Further hypotheses, 20 seeds, band [2.02, 4.16], share of epochs in band (averaged NEES
# at the start and at the end of the 240 s): as is 46 % (3.3 → 4.6). Unmodelled bias
# wander is ruled out: with the preset's flicker switched off in the simulator and in the
# filter's model (the only slow process of "tactical": no Gauss-Markov, bias_rw = 0) it is
# 6 % (3.3 → 8.3), worse, so the random-walk bias noise the filter derives from the
# flicker acts as inflation, not as a missing process. Zero-rate updates add to it but are
# not the cause: zero-velocity updates only give 66 % (3.3 → 4.3); without flicker too, 16 %
# (3.4 → 7.0). What is left grows as the filter's covariance shrinks, the signature of the
# nonlinear (second-order heading × tilt) error above.
# A second pass over the same record started from the first pass's attitude (with the
# coarse P0 and its ψ-bias correlation unchanged) is worse: 12 % (3.2 → 5.4).
NEES_NOT_MET = pytest.mark.xfail(strict=True, reason="fine-alignment attitude NEES above its 95 % band (see comment)")


@NEES_NOT_MET
def test_fine_alignment_nees_in_band_20_seeds(site):
    assert nees_fraction_in_band(site, 20) >= 0.9


@NEES_NOT_MET
@pytest.mark.slow
def test_fine_alignment_nees_in_band_100_seeds(site):
    assert nees_fraction_in_band(site, 100) >= 0.9


def test_a_moving_record_is_not_static(site):
    ideal, lla = site
    moving = an.trajectory.sinusoidal(DURATION, rate_hz=RATE_HZ).ideal_imu("rates")
    meas = an.imu.corrupt(moving, errors="tactical", dt=1.0 / RATE_HZ, kind="rates", seed=0)
    with pytest.raises(an.InputError, match="not static") as e:
        alignment.coarse(meas, lla, errors="tactical", kind="rates")
    assert e.value.parameter == "imu"


def test_too_short_a_record_names_imu(site):
    ideal, lla = site
    with pytest.raises(an.InputError, match="too short") as e:
        alignment.coarse(record(ideal, 0).iloc[:99], lla, errors="tactical", kind="rates")
    assert e.value.parameter == "imu"


@pytest.mark.parametrize("lat", [np.pi / 2, -np.pi / 2, np.deg2rad(89.5)])
def test_heading_is_unobservable_at_the_poles(site, lat):
    ideal, lla = site
    with pytest.raises(an.InputError, match="pole") as e:
        alignment.coarse(record(ideal, 0), (lat, lla[1], lla[2]), errors="tactical", kind="rates")
    assert e.value.parameter == "lla"


def test_nan_rows_name_imu_and_the_row(site):
    ideal, lla = site
    meas = record(ideal, 0)
    meas.loc[1234, "gyro_y_rad_s"] = np.nan
    with pytest.raises(an.InputError, match="gyro_y_rad_s") as e:
        alignment.coarse(meas, lla, errors="tactical", kind="rates")
    assert (e.value.parameter, e.value.index) == ("imu", 1234)
    c = alignment.coarse(record(ideal, 0).iloc[:COARSE_ROWS], lla, errors="tactical", kind="rates")
    with pytest.raises(an.InputError, match="gyro_y_rad_s") as e:
        alignment.fine(meas.iloc[1000:2000], lla, c)
    assert (e.value.parameter, e.value.index) == ("imu", 234)


def test_wrong_kind(site):
    ideal, lla = site
    meas = record(ideal, 0)
    with pytest.raises(an.InputError) as e:
        alignment.coarse(meas, lla, errors="tactical", kind="rate")
    assert e.value.parameter == "kind"
    # a rate table read as increments lacks the increment columns
    with pytest.raises(an.InputError, match="dtheta_x_rad") as e:
        alignment.coarse(meas, lla, errors="tactical", kind="increments")
    assert e.value.parameter == "imu"
    # increments given as rates: the mean "specific force" is g·Δt, not gravity
    inc = an.imu.corrupt(an.trajectory.stationary(60, rate_hz=RATE_HZ, euler=EULER).ideal_imu("increments"),
                         errors="tactical", dt=1.0 / RATE_HZ, kind="increments", seed=0)
    as_rates = inc.rename(columns=dict(zip(an.trajectory.IMU_COLUMNS["increments"], an.trajectory.IMU_COLUMNS["rates"])))
    with pytest.raises(an.InputError, match="gravity") as e:
        alignment.coarse(as_rates, lla, errors="tactical", kind="rates")
    assert e.value.parameter == "imu"


def test_increment_records_align_like_rate_records(site):
    """The same static attitude from an increment record (first row left out)."""
    _, lla = site
    inc = an.imu.corrupt(an.trajectory.stationary(DURATION, rate_hz=RATE_HZ, euler=EULER).ideal_imu("increments"),
                         errors="tactical", dt=1.0 / RATE_HZ, kind="increments", seed=2)
    c = alignment.coarse(inc, lla, errors="tactical")  # the kind read from the column names
    assert c.kind == "increments" and c.samples == len(inc) - 1
    tilt = np.linalg.norm((dcm(c.q_nb).T - TRUTH.T) @ np.array([0.0, 0.0, 1.0]))
    assert tilt < 5 * np.sqrt(c.psi_cov[0, 0] + c.psi_cov[1, 1])


def test_an_unknown_preset_names_errors(site):
    ideal, lla = site
    with pytest.raises(an.InputError, match="hadamard") as e:
        alignment.coarse(record(ideal, 0), lla, errors="hadamard", kind="rates")
    assert e.value.parameter == "errors"
