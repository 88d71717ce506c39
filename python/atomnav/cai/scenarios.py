"""The CAI-aided INS scenarios of Tennstedt et al. 2023 (car, slalom) and Tennstedt et al.
2021 (satellite, hexapod): sensor and filter presets, the scenario configuration
(:class:`ScenarioConfig`), the Monte-Carlo scenarios and the covariance-only slalom
analysis, with the IMU-only strapdown as baseline."""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import numpy as np
import pandas as pd

from .. import _core
from .._validate import finite_result, finite_scalar, flag, input_error, instance, positive, renamed, vector
from ..imu import ImuErrors
from ._config import ConfigMixin, _ImuModel
from .campaign import run_campaign
from .predictor import K_RB87, Channels, phase_jacobian
from .results import HybridResult
from .sensor import CaiSensor, FilterSetup, in_shot_noise

#: Site of the vehicle scenarios of Tennstedt et al. 2023 (Hannover, 52.38° N), their origin.
HANNOVER = (np.deg2rad(52.38), np.deg2rad(9.72), 60.0)

#: Option names the core accepts (read from the core, which checks them).
GRAVITY_OPTIONS = tuple(_core.OPTIONS["Gravity"])
PHASE_SOURCE_OPTIONS = tuple(_core.OPTIONS["PhaseSource"])
#: Longest satellite record (days at 1 Hz; the core holds every sample of a run).
MAX_SATELLITE_DAYS = 1000.0


@dataclass(frozen=True)
class ScenarioConfig(ConfigMixin):
    """Everything of a Monte-Carlo scenario but its motion.

    Checked by the core when the scenario is built; convertible to and from dict / JSON,
    and saved in :attr:`HybridResult.config`.

    Parameters
    ----------
    sensor : CaiSensor
        The CAI.
    setup : FilterSetup
        The filter tuning.
    imu : str or atomnav.imu.ImuErrors
        The navigation IMU: an :meth:`atomnav.imu.ImuErrors.preset` name or an
        :class:`atomnav.imu.ImuErrors`.
    reference : str or atomnav.imu.ImuErrors, optional
        The reference IMU the CAI is emulated from when ``phase_source`` is
        "reference": a preset name or an :class:`atomnav.imu.ImuErrors`.
    gravity : {"kinematic", "earth"}
        :data:`GRAVITY_OPTIONS`: "kinematic" = no gravity or Earth rate, "earth" = WGS84.
    rate_hz : float
        IMU rate (Hz).
    truth_rate_hz : float, optional
        Rate (Hz) of the truth the ideal phases are computed on ("ideal" phase source;
        may equal ``rate_hz``). None for a trajectory sampled from data, or with a
        reference IMU.
    phase_source : {"ideal", "reference"}
        :data:`PHASE_SOURCE_OPTIONS`, the source of the instrument's true phase: "ideal"
        = a perfect CAI on the truth sampled at ``truth_rate_hz``; "reference" = a CAI
        emulated from the ``reference`` IMU.
    aiding : bool
        False: the same filter without CAI updates.
    draw_initial : bool
        Draw the initial navigation error from P0 instead of starting at the truth.
    """

    _NESTED = {"sensor": CaiSensor, "setup": FilterSetup, "imu": _ImuModel, "reference": _ImuModel}

    sensor: CaiSensor
    setup: FilterSetup
    _: KW_ONLY
    imu: str | ImuErrors = "navigation"
    reference: str | ImuErrors | None = None
    gravity: str = "kinematic"
    rate_hz: float = 200.0
    truth_rate_hz: float | None = 2000.0
    phase_source: str = "ideal"
    aiding: bool = True
    draw_initial: bool = False


def seed003_sensor(lever=(0.0, 0.0, 0.1), v0: float = 2.8, T: float = 0.025, inflation=(1.25e-11, 1.0576e-12),
                   interpolation: str = "cubic", omega_dot: str = "pwl") -> CaiSensor:
    """The six-channel CAI of Tennstedt et al. 2023 (§2.8): k = 4π/780.241 nm along each
    body axis, ensembles A/B with ±v0 = 2.8 m/s along the next axis, IMU → release-point
    lever arm ``lever`` (m), T = 25 ms, one shot per 2T, σ_p² = 1e-3, R inflated by the
    navigation IMU's white noise (Tennstedt et al. 2021, §2.4). The predictor interpolates the 200 Hz IMU
    with cubic Hermite splines and takes ω̇ from the same interpolant ("pwl"): with linear
    inputs and the Savitzky–Golay ω̇ of the paper's default, the 15.1 Hz, 0.005 rad/s angular
    vibration of the car profile is mispredicted by several rad (its Coriolis and atom-Euler
    phases are ≈170 and ≈330 rad), and most shots slip a fringe.

    Parameters
    ----------
    lever : array_like, shape (3,)
        IMU → release-point lever arm in the body frame (m).
    v0 : float
        Launch speed of the A/B ensembles (m/s).
    T : float
        Pulse separation (s).
    inflation : tuple of float, optional
        White-noise PSDs (q_a m²/s³, q_g rad²/s) of the IMU for the in-shot R inflation;
        None: no inflation. The inflation makes the filter conservative by design: it
        treats the in-shot IMU noise as independent readout noise, though the same noise
        drives the step's velocity and tilt errors. Measured over Monte-Carlo runs on a
        3 m/s slalom and a drive with a sinusoidal yaw rate (lever arm 0): actual scatter /
        reported σ 0.38–0.68 (position), 0.39–0.60 (velocity), 0.51–0.68 (attitude), mean
        NEES ≈ 10 of 15 states. Without it σ is closer for the navigation states
        (0.61–1.09) but the bias states are overconfident (mean NEES ≈ 140).
    interpolation : {"linear", "cubic"}
        Interpolation of the IMU inputs in the predictor.
    omega_dot : {"pwl", "savgol", "zero"}
        Source of ω̇ for the Euler terms (see :class:`CaiSensor`).

    Returns
    -------
    CaiSensor
        The sensor.
    """
    return CaiSensor(Channels.cyclic(K_RB87, v0, lever=lever), T, inflation=inflation, interpolation=interpolation, omega_dot=omega_dot)


def accelerometer_sensor(lever=(0.0, 0.0, 0.1), T: float = 0.025, inflation=(1.25e-11, 1.0576e-12)) -> CaiSensor:
    """Accelerometer-only CAI: one channel per body axis with atoms at rest in s (v0 = 0), so
    the readout carries no Coriolis phase and observes the accelerometer biases only (the
    gyro biases enter only through the small mixed term 2T³k·(ω×f)).

    Channels x, y, z with k = 4π/780.241 nm; the predictor interpolates the IMU with
    cubic splines and takes ω̇ from the interpolant ("pwl"), as :func:`seed003_sensor`.

    Parameters
    ----------
    lever : array_like, shape (3,)
        IMU → release-point lever arm in the body frame (m).
    T : float
        Pulse separation (s).
    inflation : tuple of float, optional
        White-noise PSDs (q_a m²/s³, q_g rad²/s) of the IMU for the in-shot R inflation;
        None: no inflation.

    Returns
    -------
    CaiSensor
        The sensor.
    """
    ch = Channels(np.eye(3) * K_RB87, lever, np.eye(3), np.zeros(3), ["x", "y", "z"])
    return CaiSensor(ch, T, inflation=inflation, interpolation="cubic", omega_dot="pwl")


def seed003_filter(attitude_sigma0: float = 1e-7) -> FilterSetup:
    """The 15-state filter of Tennstedt et al. 2023: the navigation IMU's noise (Eq. 36), prediction every
    2T (10 steps at 200 Hz), start at the truth with the paper's P0 for the biases
    (2e-5 m/s², 1e-6 rad/s) and position, velocity ≈ 0 (1e-6). The attitude σ0 is 1e-7 rad
    (≈ 0, like position and velocity) rather than the paper's 1e-5 rad: the start IS the truth, and an attitude σ0 of 1e-5 rad on an exact start
    leaves the NEES below its χ² band in the first seconds (car: 83–85 % of epochs inside,
    < 85 % required, instead of ≈ 90 %). Drawing a real 1e-5 rad initial tilt instead is no
    remedy: the CAI cannot observe it (the phase does not depend on the navigation attitude), and in kinematic mode
    1e-5 rad × 1 m/s² × 20 s = 2e-4 m/s of velocity error, five times the 25 s hybrid error
    (≈ 4e-5 m/s): with the slalom's 25 s free-INS error of 3.8e-3 m/s the gain is capped at ≈ 19; in Earth gravity
    1e-5 rad × 9.81 m/s² × 60 s = 5.9e-3 m/s, above the 60 s hybrid error (≈ 3.8e-3 m/s).

    Parameters
    ----------
    attitude_sigma0 : float
        Initial attitude σ (rad).

    Returns
    -------
    FilterSetup
        PSDs 1.25e-11 m²/s³ (accel), 1.0576e-12 rad²/s (gyro), bias random walks
        9e-10 m²/s⁵ and 4e-14 rad²/s³, prediction every 10 IMU steps, initial σ
        (1e-6 m, 1e-6 m/s, ``attitude_sigma0`` rad, 2e-5 m/s², 1e-6 rad/s).
    """
    return FilterSetup(1.25e-11, 1.0576e-12, 9e-10, 4e-14, 10, sigma0=(1e-6, 1e-6, positive(attitude_sigma0, "attitude_sigma0"), 2e-5, 1e-6))


def car_mc(runs: int = 100, seed: int = 2023, *, gravity: str = "kinematic", lever=(0.0, 0.0, 0.0), vibration: bool = True,
           origin=HANNOVER, heading: float = 0.0, progress: bool = True) -> HybridResult:
    """Car Monte Carlo of Tennstedt et al. 2023 (§2.8): 40 s car-like profile with vibration,
    the 26 s shock and the ×2 vibration window 33–35 s; 200 Hz navigation-grade IMU
    (preset ``navigation``), T = 25 ms, filter every 2T, ``runs`` runs; ``gravity`` =
    "kinematic" (the paper's kinematic mode) or "earth".

    Lever arm: the paper's value is lost; the default here is l = 0 (the paper's §2.8 suggests [0, 0, 0.1] m). Why: the 15.1 Hz, 0.005 rad/s angular vibration has
    ω̇ = 0.005 · 2π · 15.1 = 0.474 rad/s², so with l = 0.1 m the lever-arm Euler phase
    k T² l ω̇ = 10066 · 0.1 · 0.474 ≈ 477 rad must be predicted from the 200 Hz gyro; the
    derivative of its cubic interpolant errs by up to 3.7 % at 15.1 Hz (≈ 18 rad before the
    shot's averaging), and the lever arm also carries 0.37 rad of in-shot gyro noise into the
    phase (2Tq_g(kl)², :func:`in_shot_noise`). Measured over 100 runs: the 25 s velocity
    gain drops from 36.3 to 26.6 (< 30 required) and fringe slips rise from 1.84 % to
    5.83 %; the report of :mod:`atomnav.reproduce` shows both.

    Parameters
    ----------
    runs : int
        Number of Monte-Carlo runs.
    seed : int
        Master seed (0 … 2⁶⁴ − 1); run r uses stream r, so any subset reproduces.
    gravity : {"kinematic", "earth"}
        "kinematic" (the paper's kinematic mode) or "earth".
    lever : array_like, shape (3,)
        IMU → release-point lever arm in the body frame (m).
    vibration : bool
        Include the vibration, the shock and the vibration window of the profile.
    origin : array_like (3,), default Hannover (52.38° N, 9.72° E, 60 m)
        Start of the profile: latitude (rad), longitude (rad), height (m).
    heading : float, default 0.0
        Initial heading of the car, rad.
    progress : bool
        Show a progress bar over runs.

    Returns
    -------
    HybridResult
        The Monte-Carlo result (see :func:`atomnav.cai.run_campaign`).
    """
    motion = _core.Motion.car(vector(origin, 3, "origin"), finite_scalar(heading, "heading"),
                              bool(instance(vibration, (bool, np.bool_), "vibration")))
    config = ScenarioConfig(seed003_sensor(lever), seed003_filter(), gravity=gravity)
    return run_campaign(motion, config, runs=runs, seed=seed, name="car_mc", progress=progress,
                        params={"gravity": gravity, "lever_m": tuple(lever), "vibration": vibration,
                                "origin": tuple(map(float, origin)), "heading_rad": float(heading)})


def slalom(runs: int = 100, seed: int = 2024, *, gravity: str = "kinematic", duration: float = 60.0, lever=(0.0, 0.0, 0.1),
           aiding: bool = True, sensor: CaiSensor | None = None, setup: FilterSetup | None = None,
           origin=HANNOVER, speed: float = 5.0, amp: float = 2.0, period: float = 10.0,
           progress: bool = True) -> HybridResult:
    """Smooth slalom of Tennstedt et al. 2023 (§2.8): north = ``speed``·t m, east =
    ``amp``·sin(2πt/``period``) m, level, heading along the path, 60 s (the paper's 5 m/s,
    2 m, 10 s by default; :func:`atomnav.trajectory.slalom` is the same motion); otherwise
    as :func:`car_mc`. ``aiding=False`` runs
    the same filter without CAI updates; ``sensor`` / ``setup`` replace the paper's CAI and
    filter (e.g. :func:`accelerometer_sensor`, the 21-state filter with misalignment and
    lever-arm states, or option a).

    Parameters
    ----------
    runs : int
        Number of Monte-Carlo runs.
    seed : int
        Master seed (0 … 2⁶⁴ − 1); run r uses stream r, so any subset reproduces.
    gravity : {"kinematic", "earth"}
        "kinematic" (the paper's kinematic mode) or "earth".
    duration : float
        Length of the profile (s).
    lever : array_like, shape (3,)
        IMU → release-point lever arm in the body frame (m) of the paper's CAI (ignored
        when ``sensor`` is given).
    aiding : bool
        False: the same filter without CAI updates.
    sensor : CaiSensor, optional
        Replaces the paper's CAI (:func:`seed003_sensor`).
    setup : FilterSetup, optional
        Replaces the paper's filter (:func:`seed003_filter`).
    origin : array_like (3,), default Hannover (52.38° N, 9.72° E, 60 m)
        Start of the path: latitude (rad), longitude (rad), height (m).
    speed : float, default 5.0
        Speed along north, m/s.
    amp : float, default 2.0
        East amplitude of the slalom, m.
    period : float, default 10.0
        Period of the slalom, s.
    progress : bool
        Show a progress bar over runs.

    Returns
    -------
    HybridResult
        The Monte-Carlo result (see :func:`atomnav.cai.run_campaign`).
    """
    if sensor is not None:
        instance(sensor, CaiSensor, "sensor")._checked("sensor")
    if setup is not None:
        instance(setup, FilterSetup, "setup")
    instance(aiding, (bool, np.bool_), "aiding")
    motion = _core.Motion.slalom(vector(origin, 3, "origin"), finite_scalar(speed, "speed"), finite_scalar(amp, "amp"),
                                 positive(period, "period"), positive(duration, "duration"))
    config = ScenarioConfig(seed003_sensor(lever) if sensor is None else sensor, seed003_filter() if setup is None else setup,
                            gravity=gravity, aiding=flag(aiding, "aiding"))
    return run_campaign(motion, config, runs=runs, seed=seed, name="slalom", progress=progress,
                        params={"gravity": gravity, "lever_m": tuple(lever), "duration_s": duration,
                                "origin": tuple(map(float, origin)), "speed_mps": float(speed), "amp_m": float(amp), "period_s": float(period)})


def satellite(days: float = 4.0, seed: int = 2021, *, drift: bool = True, progress: bool = True) -> HybridResult:
    """Satellite scenario of Tennstedt et al. 2021 (§2.8, Eqs. 36–37): along-track
    accelerometer axis of an electrostatic accelerometer at 1 Hz (white 1e-10 m/s²/√Hz +
    Gauss–Markov τ = 10 s, driving σ 2e-12 m/s²; ``drift`` adds the bias random walk
    q_rw = 1e-21 m²/s⁵), one CAI shot every 10 s with T0 = 10 s (T = 5 s), |A| = 0.15
    (C = 0.3), R = 1.024e-3; the filter's bias model is the random walk q_rw
    (Q = 1e-20 (m/s²)² per shot, Table 1 case A). Kinematic frame (drag-free, no
    gravity); one run; output at every shot; at most ``MAX_SATELLITE_DAYS`` days.

    Parameters
    ----------
    days : float
        Length of the record (days), at most ``MAX_SATELLITE_DAYS``.
    seed : int
        Seed of the run (0 … 2⁶⁴ − 1).
    drift : bool
        Add the bias random walk q_rw to the accelerometer (preset
        ``electrostatic_space_drift`` instead of ``electrostatic_space``).
    progress : bool
        Show a progress bar over runs.

    Returns
    -------
    HybridResult
        The Monte-Carlo result (see :func:`atomnav.cai.run_campaign`).
    """
    days = positive(days, "days")
    if days > MAX_SATELLITE_DAYS:
        raise input_error("days", f"must be <= {MAX_SATELLITE_DAYS} (one IMU sample per second), got {days}")
    instance(drift, (bool, np.bool_), "drift")
    motion = _core.Motion.stationary(vector(HANNOVER, 3, "origin"), days * 86400.0, np.zeros(3))
    ch = Channels(np.array([[K_RB87, 0.0, 0.0]]), np.zeros(3), np.eye(3), np.zeros(3), ["x"])
    sensor = CaiSensor(ch, 5.0, contrast=0.3, sigma_p=0.032, inflation=(1e-20, 0.0), omega_dot="zero")
    setup = FilterSetup(1e-20, 1e-30, 1e-21, 0.0, 10, sigma0=(1e-6, 1e-9, 1e-9, 1e-9, 1e-12))
    config = ScenarioConfig(sensor, setup, imu="electrostatic_space_drift" if drift else "electrostatic_space", gravity="kinematic",
                            rate_hz=1.0, truth_rate_hz=1.0)
    return run_campaign(motion, config, runs=1, seed=seed, name="satellite", progress=progress,
                        params={"days": days, "drift": drift, "T": sensor.T, "shot_period_s": 2 * sensor.T, "contrast": sensor.contrast,
                             "sigma_p": sensor.sigma_p, "q_rw": setup.accel_bias_psd})


def hexapod(runs: int = 100, seed: int = 2000, *, origin=HANNOVER, max_tilt: float = 0.0654, pitch_delay: float = 5.0,
            heading: float = 0.0, progress: bool = True) -> HybridResult:
    """Hexapod scenario of Tennstedt et al. 2021 (§5.3): 170 s tilt sequence at 1 kHz; a MEMS IMU
    (preset ``mems``: biases (2e-3, −1.5e-3, 1e-3) m/s², (5e-5, −4e-5, 3e-5) rad/s) corrected
    by a CAI emulated from a navigation-grade reference IMU (preset ``navigation``):
    T = 5 ms, one shot per 10 ms, cyclic ±2.8 m/s ensembles, R = 1e-3, Earth gravity. The
    estimated biases are relative to the reference IMU (truth = MEMS − reference).

    Parameters
    ----------
    runs : int
        Number of Monte-Carlo runs.
    seed : int
        Master seed (0 … 2⁶⁴ − 1); run r uses stream r, so any subset reproduces.
    origin : array_like (3,), default Hannover (52.38° N, 9.72° E, 60 m)
        Site: latitude (rad), longitude (rad), height (m).
    max_tilt : float, default 0.0654
        Largest tilt of the sequence, rad (the paper's 3.75°).
    pitch_delay : float, default 5.0
        Delay of the pitch tilts after the roll tilts, s.
    heading : float, default 0.0
        Heading of the hexapod, rad.
    progress : bool
        Show a progress bar over runs.

    Returns
    -------
    HybridResult
        The Monte-Carlo result (see :func:`atomnav.cai.run_campaign`).
    """
    motion = _core.Motion.hexapod(vector(origin, 3, "origin"), finite_scalar(max_tilt, "max_tilt"),
                                  finite_scalar(pitch_delay, "pitch_delay"), finite_scalar(heading, "heading"))
    mems, nav = ImuErrors.preset("mems"), ImuErrors.preset("navigation")
    q_a = mems.accel.white**2 + nav.accel.white**2
    q_g = mems.gyro.white**2 + nav.gyro.white**2
    sensor = CaiSensor(Channels.cyclic(K_RB87, 2.8), 0.005, inflation=(q_a, q_g))
    setup = FilterSetup(mems.accel.white**2, mems.gyro.white**2, mems.accel.bias_rw**2 + nav.accel.bias_rw**2,
                        mems.gyro.bias_rw**2 + nav.gyro.bias_rw**2, 10, sigma0=(1e-6, 1e-6, 1e-5, 3e-3, 1e-4))
    config = ScenarioConfig(sensor, setup, imu="mems", reference="navigation", gravity="earth", rate_hz=1000.0, truth_rate_hz=None,
                            phase_source="reference")
    return run_campaign(motion, config, runs=runs, seed=seed, name="hexapod", progress=progress,
                        params={"origin": tuple(map(float, origin)), "max_tilt_rad": float(max_tilt),
                                "pitch_delay_s": float(pitch_delay), "heading_rad": float(heading)})


def slalom_covariance(gravity: str = "earth", *, duration: float = 60.0, attitude_sigma: float | None = None,
                      lever=(0.0, 0.0, 0.1)) -> pd.DataFrame:
    """Covariance-only analysis of the slalom (estimation engine, ``atomnav.filter.Scenario``):
    the 15-state error model along the exact trajectory, one stacked CAI update per shot
    (H = (C/2) ∂φ/∂(b_a, b_g) from the predictor at the mean specific force, R inflated by the
    in-shot IMU noise exactly as the Monte-Carlo filter does, :func:`in_shot_noise`). With
    ``attitude_sigma`` (rad) every shot also carries a direct attitude measurement ψ + n (a
    star camera; GNSS heading/tilt acts alike). Returns per epoch the RMS velocity-error norm
    √tr P_vv of the free INS, of the hybrid filter's own covariance (``hybrid_vel_rms_mps``,
    ``ratio``) and of its true error (``hybrid_true_vel_rms_mps``, ``ratio_true``).

    The true error (:func:`atomnav.filter.analysis.true_error_analysis`) differs from the
    filter's own σ because the readout is not independent of the process noise: the phase
    predicted from the IMU carries the in-shot IMU noise (which is why R is inflated), and
    that same noise drives the velocity and tilt errors of the step. The filter, treating it
    as independent readout noise, is conservative: in Earth gravity its true velocity error
    is ≈ 0.6 × its σ (the differential A/B readout senses the gyro noise over [T, 2T] with
    correlation 1/√2 to the tilt increment of the step). The Monte Carlo shows the true error.

    Why the gain is capped in Earth gravity (Tennstedt et al. 2023, kinematic vs Earth mode): the CAI phase
    depends on specific force and rate, never on the navigation attitude, so H has zero
    attitude columns; the tilt driven by gyro white noise (ARW) stays unobserved and projects
    gravity into the velocity (δv̇ = [f^n×]ψ, |f^n| ≈ g). That error is common to the free and
    the hybrid solution, which caps their ratio; in kinematic mode f^n is the small vehicle
    acceleration and the cap disappears; an attitude aid observes ψ directly and lifts it.

    Parameters
    ----------
    gravity : {"earth", "kinematic"}
        "earth" (WGS84) or "kinematic" (no gravity or Earth rate).
    duration : float
        Length of the slalom (s).
    attitude_sigma : float, optional
        σ (rad) of a direct attitude measurement ψ + n at every shot; None: none.
    lever : array_like, shape (3,)
        IMU → release-point lever arm in the body frame (m).

    Returns
    -------
    pandas.DataFrame
        One row per epoch: ``time_s``, the RMS velocity-error norms √tr P_vv
        ``free_vel_rms_mps`` (free INS), ``hybrid_vel_rms_mps`` (the hybrid filter's own
        covariance), ``hybrid_true_vel_rms_mps`` (its true error), in m/s, and the ratios
        ``ratio`` = free / hybrid and ``ratio_true`` = free / hybrid true.
    """
    from ..filter import Scenario, covariance_analysis
    from ..filter.analysis import true_error_analysis
    from ..trajectory import slalom as slalom_trajectory

    ell = _core.cai_gravity_ellipsoid(gravity)
    sensor, setup = seed003_sensor(lever), seed003_filter()
    with renamed(rate_hz="duration"):  # the shot rate is fixed: only the duration can make too many epochs
        traj = slalom_trajectory(rate_hz=1.0 / (2 * sensor.T), origin=HANNOVER, duration=positive(duration, "duration"), ellipsoid=ell)
    f, qc, h, r, r_true, cross = _cai_error_model(traj, sensor, setup, ell, 0.005)
    m = len(sensor.channels)
    if attitude_sigma is not None:
        ha = np.zeros((3, 15))
        ha[:, 6:9] = np.eye(3)
        h = np.vstack([h, ha])
        with np.errstate(over="ignore", under="ignore"):
            var = np.float64(positive(attitude_sigma, "attitude_sigma"))**2
        if not var > 0.0:
            raise input_error("attitude_sigma", f"σ = {attitude_sigma} rad is so small that σ² underflows to 0 (a singular R)")
        ra = finite_result(var, "attitude_sigma", "the attitude variance") * np.eye(3)
        r, r_true = (np.block([[x, np.zeros((m, 3))], [np.zeros((3, m)), ra]]) for x in (r, r_true))
        cross = np.concatenate([cross, np.zeros((len(cross), 15, 3))], axis=2)
    dt = np.diff(traj.time)
    p0 = setup.p0(0)
    n = len(dt)
    vel = lambda cov: np.sqrt((cov.iloc[:, 4:7].to_numpy() ** 2).sum(axis=1))  # noqa: E731
    free = vel(covariance_analysis(Scenario(f, qc, dt, p0, h, r, [False] * (n + 1), times=traj.time)))
    scn = Scenario(f, qc, dt, p0, h, r, [False] + [True] * n, times=traj.time)
    hyb, true = vel(covariance_analysis(scn)), vel(true_error_analysis(scn, r_true, cross))
    return pd.DataFrame({"time_s": traj.time, "free_vel_rms_mps": free, "hybrid_vel_rms_mps": hyb, "hybrid_true_vel_rms_mps": true,
                         "ratio": free / hyb, "ratio_true": free / true})


def _cai_error_model(traj, sensor: CaiSensor, setup: FilterSetup, ellipsoid: str, dt: float):
    """The linear model of the CAI-aided INS along ``traj``, sampled once per filter step, each
    step the window of one shot: the 15-state error model (F, Q_c per step, with the bias
    random walks of ``setup``), one stacked CAI update H = (C/2) ∂φ/∂(b_a, b_g) from the
    predictor at the mean specific force, the filter's R (σ_p² plus the in-shot IMU noise of
    the sensor's inflation PSDs), the true R (the in-shot noise of the IMU, whose white PSDs
    are the filter's) and the cross-covariance of each step's process noise with its shot's
    readout noise (:func:`in_shot_noise`, Tennstedt et al. 2021, §2.4), for an IMU sampled
    every ``dt`` s.

    Returns ``(f, qc, h, r, r_true, cross)``: f, qc (steps, 15, 15), h (C, 15), r and r_true
    (C, C), cross (steps, 15, C)."""
    from ..filter import BiasModel, ins_error_model

    f_b = traj.ideal_imu("rates")[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()
    df = traj.df
    f, qc = ins_error_model(df[["lat_rad", "lon_rad", "h_m"]].to_numpy(), df[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(),
                            df[["qw", "qx", "qy", "qz"]].to_numpy(), f_b, gyro_psd=setup.gyro_psd, accel_psd=setup.accel_psd,
                            gyro_bias=BiasModel("random_walk", psd=setup.gyro_bias_psd),
                            accel_bias=BiasModel("random_walk", psd=setup.accel_bias_psd),
                            ellipsoid=ellipsoid)
    # H of one shot at the mean specific force (the phase Jacobian varies little along the path)
    t = np.arange(0.0, 2 * sensor.T + 1e-12, dt)
    fm = np.tile(f_b.mean(axis=0), (len(t), 1))
    jac = phase_jacobian(t, fm, np.zeros_like(fm), [0.0], sensor.T, sensor.channels, omega_dot="zero")[0]
    half_c = 0.5 * sensor.contrast
    m = len(sensor.channels)
    h = np.zeros((m, 15))
    h[:, 9:15] = half_c * jac[:, :6]
    # the filter's R (its inflation PSDs) and the truth (the IMU's noise, the filter's PSDs)
    sigma_f, _ = in_shot_noise(sensor, dt, *sensor.inflation)
    sigma_t, cross = in_shot_noise(sensor, dt, setup.accel_psd, setup.gyro_psd, f[:-1])
    r = sensor.sigma_p**2 * np.eye(m) + half_c**2 * sigma_f
    r_true = sensor.sigma_p**2 * np.eye(m) + half_c**2 * sigma_t
    return f[:-1], qc[:-1], h, r, r_true, half_c * cross
