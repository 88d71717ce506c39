"""The campaign scenario ``cai_car``: one Monte-Carlo run of the CAI-aided INS on the car
profile of Tennstedt et al. 2023 (§2.8), with its covariance predictor, the linear analysis
of the filter's true error (the filter is suboptimal: its R is inflated by the in-shot IMU
noise that also drives the navigation error)."""

from __future__ import annotations

import json
import warnings
from functools import lru_cache
from typing import NamedTuple

import numpy as np
import pandas as pd

from .. import _core
from .._validate import choice, finite_scalar, flag, input_error, integer, positive, scalar
from ..cai.campaign import _scenario
from ..cai.predictor import K_RB87, Channels
from ..cai.scenarios import GRAVITY_OPTIONS, HANNOVER, ScenarioConfig, _cai_error_model
from ..cai.sensor import CaiSensor, FilterSetup
from ..imu import ImuErrors, ImuSimulator, TriadErrors, flicker_allan_floor, preset_names
from ..plausibility import UnitWarning
from .scenario import predicted_by

#: IMU rate of the scenario (Hz), as in Tennstedt et al. 2023.
RATE_HZ = 200.0
#: Length of the car profile (s).
DURATION_S = 40.0
#: Launch speed of the A/B ensembles (m/s), Tennstedt et al. 2023, §2.8.
V0_MPS = 2.8
#: Initial σ of position (m), velocity (m/s) and attitude (rad) in the filter: the run
#: starts at the truth (see :func:`atomnav.cai.seed003_filter`).
NAV_SIGMA0 = (1e-6, 1e-6, 1e-7)
#: Largest expected share of shot-channels beyond ±π/2 from the in-shot IMU noise for which
#: the predictor trusts its linear analysis without a warning: a phase σ of 0.48 rad (the
#: navigation grade: 0.40 rad at T = 25 ms, 0.82 rad at T = 40 ms).
MAX_LINEAR_EXCEEDANCE = 1e-3
#: The same for the first shot from the turn-on biases: a phase σ of 0.61 rad (the
#: navigation grade: 0.52 rad at T = 40 ms, which its Monte Carlo bears).
MAX_START_EXCEEDANCE = 1e-2
#: IMU samples before a shot start that the filter's in-shot predictor holds (the core's
#: interpolation stencil pad, for the cubic / "pwl" predictor); with those up to the shot's
#: end it predicts the shot's phase.
SHOT_PAD = _core.CAI_STENCIL_PAD
_COLUMNS = ("pos_error_m", "vel_error_mps", "att_error_rad")


def _grade(imu) -> ImuErrors:
    """The preset ``imu``, checked at the car's IMU rate :data:`RATE_HZ` (its flicker
    bands below the Nyquist frequency)."""
    if not isinstance(imu, str):
        raise TypeError(f"imu: expected an IMU preset name (str), got {type(imu).__name__}")
    errors = ImuErrors.preset(choice(imu, preset_names(), "imu"))
    try:
        ImuSimulator(errors, 1.0 / RATE_HZ, "rates")
    except _core.InputError as e:
        raise input_error("imu", f"preset {imu!r} cannot be simulated at the car's {RATE_HZ:g} Hz: {e}") from None
    for name in ("accel", "gyro"):
        if _bias_model(getattr(errors, name))[0] == 0.0:
            raise input_error("imu", f"preset {imu!r} has no bias in its {name} triad: the filter's {name} bias state would start "
                                     "with σ = 0, a singular initial covariance the aided INS cannot start from")
    return errors


def _linear_grade(imu: str) -> None:
    """Refuse, naming ``imu``, a preset with errors the linear analysis does not carry: it
    carries a random turn-on bias, white noise and a bias random walk per triad."""
    errors = ImuErrors.preset(imu)
    for name in ("accel", "gyro"):
        triad = getattr(errors, name)
        extra = [term for term, present in (("a fixed bias", np.any(np.asarray(triad.bias) != 0)),
                                             ("scale-factor errors", np.any(np.asarray(triad.scale) != 0)),
                                             ("misalignment", np.any(np.asarray(triad.misalignment) != 0)),
                                             ("a Gauss–Markov term", triad.gauss_markov is not None),
                                             ("a flicker term", triad.flicker is not None)) if present]
        if extra:
            raise input_error("imu", f"preset {imu!r} has {', '.join(extra)} in its {name} triad; the linear analysis of this scenario "
                                     "carries only a random turn-on bias, white noise and a bias random walk. For this grade "
                                     "use the Monte Carlo: cai_car runs, sweep(cai_car, points, method=\"monte_carlo\", ...) "
                                     "or atomnav.campaign.run")


def _bias_model(triad: TriadErrors) -> tuple[float, float]:
    """The filter's model of the biases of one triad, a random constant plus a random walk:
    its initial σ (m/s² or rad/s) and random-walk PSD (m²/s⁵ or rad²/s³).

    Second moments add over the triad's terms. Initial variance: the turn-on σ², the
    largest fixed bias² of the three axes (a bias the filter does not know is to it a draw
    of that second moment; its σ is one for all axes), the Gauss–Markov σ² and the
    flicker's variance at the start, Σσᵢ² over the Gauss–Markov poles the simulator sums
    it from, each started stationary (:mod:`atomnav.imu`). Random-walk PSD: the triad's
    K², the Gauss–Markov driving PSD 2σ²/τ and, for flicker of bias instability B
    (one-sided PSD B²/(πf)), the random walk equivalent to its bias instability over the
    profile: the Allan variance of B²/(πf) is flat at (2 ln 2/π) B² for 1/f_hi ≪ τ ≪
    1/f_lo, that of a rate random walk of PSD K² is K² τ/3 (IEEE Std 952-1997, Annex C;
    El-Sheimy et al. 2008), and they meet at the profile's length
    :data:`DURATION_S` for K² = 3 (2 ln 2/π) B² / DURATION_S. Within the profile that
    random walk wanders no further than the flicker in the Allan sense (its Allan
    deviation rises as √τ to the floor), while the flicker's level, the slow poles that
    stay put for the whole drive, is in the initial σ. Scale-factor and misalignment
    errors are not modelled.
    """
    gm, fl = triad._terms("imu")
    var0 = triad.bias_sigma**2 + float(np.max(np.abs(triad.bias))) ** 2
    psd = triad.bias_rw**2
    if gm is not None:
        var0 += gm.sigma**2
        psd += 2.0 * gm.sigma**2 / gm.tau
    if fl is not None and fl.b > 0:
        var0 += sum(sigma**2 for sigma, _ in _core.imu_flicker_poles(fl.b, fl.f_lo, fl.f_hi))
        psd += 3.0 * flicker_allan_floor(fl.b) ** 2 / DURATION_S
    return float(np.sqrt(var0)), float(psd)


def _points(T, shot_rate, imu, lever, gravity, vibration, contrast, checkpoint_s) -> tuple:
    """The checked parameters as a hashable key: (T, shot period, IMU errors as JSON, lever,
    gravity, vibration, contrast, checkpoint spacing, filter steps per prediction)."""
    T = positive(T, "T")
    steps = 2 * T * RATE_HZ
    if abs(steps - round(steps)) > 1e-9 * steps or round(steps) < 1:
        raise input_error("T", f"2T must be a whole number of {1e3 / RATE_HZ:g} ms IMU samples (the filter predicts every 2T), got T = {T} s")
    if 2 * T > DURATION_S:
        raise input_error("T", f"a shot of 2T = {2 * T} s does not fit the {DURATION_S:g} s profile")
    rate = scalar(shot_rate, "shot_rate")
    if not (np.isfinite(rate) and rate >= 0.0):
        raise input_error("shot_rate", f"must be finite and >= 0 (0: one shot per 2T), got {rate}")
    if rate * 2 * T > 1 + 1e-12:
        raise input_error("shot_rate", f"{rate} Hz exceeds one shot per 2T = {1 / (2 * T):g} Hz (shots cannot overlap)")
    if 0.0 < rate < 1.0 / DURATION_S:
        raise input_error("shot_rate", f"{rate} Hz gives fewer than one shot per {DURATION_S:g} s profile (0: one shot per 2T)")
    period = 2 * T if rate == 0.0 else 1.0 / rate
    if abs(period / (2 * T) - round(period / (2 * T))) > 1e-9 * period / (2 * T):
        raise input_error("shot_rate", f"the shot period 1/shot_rate = {period:g} s must be a whole number of filter steps 2T = {2 * T:g} s: the "
                                       "filter updates at the first IMU sample at or after a shot's end, and one ending between its steps "
                                       "adds an epoch there and shifts every later step")
    errors = _grade(imu)
    contrast = scalar(contrast, "contrast")
    if not 0.0 < contrast <= 1.0:
        raise input_error("contrast", f"must be in (0, 1], got {contrast}")
    checkpoint_s = positive(checkpoint_s, "checkpoint_s")
    if checkpoint_s > DURATION_S:
        raise input_error("checkpoint_s", f"must be at most the {DURATION_S:g} s profile, got {checkpoint_s}")
    return (T, period, json.dumps(errors._to_core()), finite_scalar(lever, "lever"), choice(gravity, GRAVITY_OPTIONS, "gravity"),
            flag(vibration, "vibration"), contrast, checkpoint_s, int(round(steps)))


def _configuration(key: tuple) -> ScenarioConfig:
    """The CAI, the filter derived from the IMU grade, and the scenario of ``key``."""
    T, period, imu_json, lever, gravity, _, contrast, _, steps = key
    accel, gyro = (TriadErrors._from_core(d) for d in json.loads(imu_json))
    q = (accel.white**2, gyro.white**2)
    sensor = CaiSensor(Channels.cyclic(K_RB87, V0_MPS, lever=(0.0, 0.0, lever)), T, shot_period=period, contrast=contrast, inflation=q,
                       interpolation="cubic", omega_dot="pwl")
    (sigma_a, psd_a), (sigma_g, psd_g) = _bias_model(accel), _bias_model(gyro)
    setup = FilterSetup(*q, psd_a, psd_g, steps, sigma0=(*NAV_SIGMA0, sigma_a, sigma_g))
    imu = ImuErrors(accel, gyro)
    return ScenarioConfig(sensor, setup, imu=imu, gravity=gravity, rate_hz=RATE_HZ)


@lru_cache(maxsize=4)
def _core_scenario(key: tuple):
    """The built core scenario of ``key`` (truth, ideal IMU, true phases, filter), kept so
    the seeds of one parameter point share it; a run does not change it."""
    return _scenario(_motion(key), _configuration(key))[0]


def _motion(key: tuple) -> _core.Motion:
    """The car profile at Hannover, heading north, with or without its vibration."""
    return _core.Motion.car(np.asarray(HANNOVER, dtype=float), 0.0, key[5])


def _checkpoints(key: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Output epochs (indices into the filter's epochs every 2T from 0) nearest to every
    multiple of the checkpoint spacing and the end of the profile, and their times (s)."""
    *_, checkpoint_s, steps = key
    step_s = steps / RATE_HZ
    last = int(np.floor(DURATION_S / step_s + 1e-9))
    want = np.append(np.arange(checkpoint_s, DURATION_S + 1e-9, checkpoint_s), DURATION_S)
    idx = np.unique(np.clip(np.round(want / step_s).astype(int), 1, last))
    return idx, idx * steps / RATE_HZ


def _warn_nonlinear(sensor: CaiSensor, h: np.ndarray, p0: np.ndarray, r_true: np.ndarray) -> None:
    """Warn when the phase noise leaves the linear regime: the in-shot IMU noise of every shot
    (from the readout's true R) puts more than :data:`MAX_LINEAR_EXCEEDANCE`, or the turn-on
    biases (P0 through H) put more than :data:`MAX_START_EXCEEDANCE` of the first shot's
    channels beyond the ±π/2 capture range."""
    from scipy.stats import norm

    half_c = 0.5 * sensor.contrast
    for what, var, limit in (("in-shot IMU noise gives", np.diag(r_true) - sensor.sigma_p**2, MAX_LINEAR_EXCEEDANCE),
                             ("turn-on biases give", np.diag(h @ p0 @ h.T), MAX_START_EXCEEDANCE)):
        sigma = np.sqrt(np.maximum(var, 0.0)) / half_c
        share = float(np.mean(2 * norm.sf(0.5 * np.pi / np.maximum(sigma, 1e-300))))
        if share > limit:
            warnings.warn(f"cai_car: the {what} a phase σ of up to {sigma.max():.2f} rad, {share:.1%} of the shot-channels "
                          "beyond ±π/2; the linear analysis ignores the readout's sine and fringe slips and understates the RMS "
                          "(by 31–61 % at 40 s for the navigation grade at T = 40 ms, in-shot phase σ 0.82 rad)",
                          RuntimeWarning, stacklevel=3)


class _Linear(NamedTuple):
    """The linear model of a parameter point, one epoch per filter step (2T)."""

    config: ScenarioConfig
    ellipsoid: str
    model: tuple  # (f, qc, h, r, r_true, cross) of _cai_error_model
    measure: np.ndarray  # (epochs,) bool: a shot ends at the epoch
    step_s: float


def _linear_model(key: tuple) -> _Linear:
    """The error model of :func:`atomnav.cai.scenarios._cai_error_model` along the car
    profile of ``key``, and the epochs its shots end at."""
    from ..trajectory import Trajectory

    config = _configuration(key)
    sensor, steps = config.sensor, key[-1]
    ell = _core.cai_gravity_ellipsoid(config.gravity)
    traj = Trajectory.from_motion(_motion(key), RATE_HZ / steps, ell)
    with warnings.catch_warnings():
        if config.gravity == "kinematic":  # without gravity the car's |f| ≈ 1 m/s² is no force in g
            warnings.simplefilter("ignore", UnitWarning)
        model = _cai_error_model(traj, sensor, config.setup, ell, 1.0 / RATE_HZ)
    step_s = steps / RATE_HZ
    measure = np.zeros(len(traj.time), dtype=bool)
    ends = sensor.shots(sensor.first_shot, DURATION_S) + 2 * sensor.T
    measure[np.clip(np.round(ends / step_s).astype(int), 1, len(measure) - 1)] = True
    return _Linear(config, ell, model, measure, step_s)


def _systematic_error(key: tuple, lin: _Linear) -> np.ndarray:
    """Mean over seeds of the 15-state error (epochs, 15): the response of the filter to the
    seed-independent phase error of every shot, true phase minus the filter's prediction
    from the error-free IMU. The true phase comes from the truth at the scenario's
    ``truth_rate_hz`` with the exact ω̇; the filter predicts when the shot ends, from the
    200 Hz samples it holds then (the :data:`SHOT_PAD` samples before the shot start up to
    its end, so the cubic tangent at the end is one-sided). Under the profile's 4.3–15.1 Hz
    vibration this error is ≈ 0.3 rad per channel at T = 20 ms, and shots every 10T
    alias the 15.1 Hz line to 0.1 Hz: a navigation error common to all seeds that grows and
    shrinks with a 10 s period. The error enters as a known input, δx⁺ = (I − KH)δx⁻ + K d
    with the gains of the filter's own model, d = (C/2)(φ_true − φ_filter) per channel."""
    from ..cai.predictor import predict_phase
    from ..filter.engine import KalmanFilter, discretize
    from ..trajectory import Trajectory

    config = lin.config
    sensor, setup = config.sensor, config.setup
    shots = sensor.shots(sensor.first_shot, DURATION_S)
    opts = dict(interpolation=sensor.interpolation, tolerance_rad=np.inf)

    def ideal(rate):
        imu = Trajectory.from_motion(_motion(key), rate, lin.ellipsoid).ideal_imu("rates").to_numpy()
        return imu[:, 0], imu[:, 4:7], imu[:, 1:4], imu[:, 7:10]

    t, f, w, wd = ideal(config.truth_rate_hz)
    true = predict_phase(t, f, w, shots, sensor.T, sensor.channels, angular_acceleration=wd, **opts).total
    t, f, w, _ = ideal(RATE_HZ)
    h_s = 1.0 / RATE_HZ
    first = np.searchsorted(t, shots - 1e-6 * h_s) - SHOT_PAD
    last = np.searchsorted(t, shots + 2 * sensor.T - 1e-6 * h_s)
    filt = np.array([predict_phase(t[i:j + 1], f[i:j + 1], w[i:j + 1], [ts], sensor.T, sensor.channels, omega_dot=sensor.omega_dot, **opts).total[0]
                     for ts, i, j in zip(shots, np.maximum(first, 0), last)])
    d = 0.5 * sensor.contrast * (true - filt)
    f_err, qc, h, r, *_ = lin.model
    kf = KalmanFilter(setup.p0(0), mode="open")
    mean, j = [np.zeros(15)], 0
    for k in range(len(f_err)):
        kf.predict(*discretize(f_err[k], qc[k], lin.step_s))
        if lin.measure[k + 1]:
            kf.update(d[j], h, r)
            j += 1
        mean.append(np.asarray(kf.x))
    return np.array(mean)


def _table(times: np.ndarray, pos, vel, att) -> pd.DataFrame:
    return pd.DataFrame({"time_s": times, **dict(zip(_COLUMNS, (np.asarray(pos), np.asarray(vel), np.asarray(att))))})


def _cai_car_covariance(*, T=0.025, shot_rate=0.0, imu="navigation", lever=0.0, gravity="earth", vibration=True, contrast=1.0,
                        checkpoint_s=5.0) -> pd.DataFrame:
    """Predicted RMS over seeds of the errors of :func:`cai_car`: the linear analysis of the
    true error of the filter as built (:func:`atomnav.filter.analysis.true_error_analysis`).

    The 15-state error model runs along the car profile one filter step (2T) at a time, with
    the IMU's turn-on biases in P0, its bias random walks and white noise; every shot is one
    stacked update at the step it ends in, H from the predictor at the mean specific force,
    the filter's R inflated by the in-shot IMU noise while the true readout noise is the
    in-shot noise itself, correlated with the step's process noise (Tennstedt et al. 2021,
    §2.4). The error's mean over seeds is not zero: the filter predicts each shot's phase
    from the 200 Hz IMU samples it holds when the shot ends, and under the profile's
    vibration that prediction misses the true phase by the same amount in every run (≈ 0.3
    rad per channel at T = 20 ms); the prediction adds the filter's response to it, RMS² =
    tr P + |mean|² per block. Shots every 10T at T = 20 ms alias the 15.1 Hz vibration to
    0.1 Hz, and this mean is then up to 0.95 of the RMS, rising and falling with a 10 s
    period. The readout's sine is linearised, so fringe slips (phase errors beyond ±π/2)
    are outside this analysis: against 60 Monte-Carlo seeds of the navigation grade, with
    shots every 2T, 4T or 10T, the Monte-Carlo RMS is 0.82–1.16 × the prediction at every
    filter epoch after 1 s for T = 10, 20 and 25 ms, while at T = 40 ms (in-shot phase σ
    0.82 rad) it is 1.31–1.61 × at 40 s, the readout's nonlinearity (with half the IMU's
    white noise and no vibration: 1.01–1.05 ×).

    Parameters
    ----------
    T, shot_rate, imu, lever, gravity, vibration, contrast, checkpoint_s
        As for :func:`cai_car`.

    Returns
    -------
    pandas.DataFrame
        The rows of :func:`cai_car`: ``time_s`` and the predicted RMS norms
        ``pos_error_m``, ``vel_error_mps``, ``att_error_rad`` (√ of the trace of each
        3 × 3 block of the true-error covariance).

    Raises
    ------
    atomnav.InputError
        As for :func:`cai_car`, and naming ``imu`` for a grade with errors the linear
        analysis does not carry (fixed bias, scale factor, misalignment, Gauss–Markov or
        flicker terms: ``tactical``, ``mems``); its Monte Carlo runs.

    Warns
    -----
    RuntimeWarning
        When the in-shot phase noise puts more than :data:`MAX_LINEAR_EXCEEDANCE` of the
        shot-channels, or the turn-on biases more than :data:`MAX_START_EXCEEDANCE` of the
        first shot's, beyond ±π/2: the prediction then understates the RMS.
    """
    from ..filter import Scenario
    from ..filter.analysis import true_error_analysis

    key = _points(T, shot_rate, imu, lever, gravity, vibration, contrast, checkpoint_s)
    _linear_grade(imu)
    lin = _linear_model(key)
    f, qc, h, r, r_true, cross = lin.model
    setup = lin.config.setup
    _warn_nonlinear(lin.config.sensor, h, setup.p0(0), r_true)
    times = np.arange(len(lin.measure)) * lin.step_s
    scn = Scenario(f, qc, np.diff(times), setup.p0(0), h, r, lin.measure.tolist(), times=times)
    sig = true_error_analysis(scn, r_true, cross).iloc[:, 1:16].to_numpy()
    mean = _systematic_error(key, lin)
    idx, t = _checkpoints(key)
    return _table(t, *(np.sqrt((sig[idx, 3 * i:3 * i + 3] ** 2 + mean[idx, 3 * i:3 * i + 3] ** 2).sum(axis=1)) for i in range(3)))


@predicted_by(_cai_car_covariance)
def cai_car(*, seed=0, T=0.025, shot_rate=0.0, imu="navigation", lever=0.0, gravity="earth", vibration=True, contrast=1.0,
            checkpoint_s=5.0) -> pd.DataFrame:
    """One Monte-Carlo run of the CAI-aided INS on the car profile of Tennstedt et al. 2023
    (§2.8): the 40 s car-like drive with vibration, the 26 s shock and the ×2 vibration
    window 33–35 s at Hannover; a 200 Hz IMU of grade ``imu``; the six-channel CAI (k =
    4π/780.241 nm along each body axis, ±2.8 m/s ensembles, σ_p² = 1e-3, predictor with
    cubic inputs and ω̇ from the gyro interpolant as :func:`atomnav.cai.seed003_sensor`);
    the 15-state filter predicting every 2T.

    The filter follows the IMU grade: its white-noise and bias random-walk PSDs are the
    grade's, its initial bias σ the grade's turn-on bias σ, and the CAI's R is inflated by
    the grade's in-shot white noise (Tennstedt et al. 2021, §2.4). A grade with terms the
    filter's bias model (a random constant plus a random walk) lacks runs with a filter
    that approximates them: a fixed bias and a Gauss–Markov σ widen the initial bias σ, a
    Gauss–Markov term adds its driving PSD 2σ²/τ to the random walk, a flicker term its
    level at the start to the initial σ and the random walk equivalent to its bias
    instability over the 40 s profile (IEEE Std 952-1997; El-Sheimy et al. 2008);
    scale-factor and misalignment errors are not modelled. Such a grade has no covariance
    prediction (``cai_car.predict`` refuses it). The run starts at the
    truth. The built scenario (truth, ideal IMU, true phases) is kept for the last few
    parameter points, so consecutive seeds of one point build it once; a run is the same
    bit for bit either way.

    Parameters
    ----------
    seed : int
        Seed of the run (0 … 2⁶⁴ − 1): the IMU errors and the readout noise.
    T : float
        Pulse separation (s); 2T must be a whole number of 5 ms IMU samples.
    shot_rate : float
        Shots per second (Hz), at most 1/(2T), the shot period 1/shot_rate a whole number
        of filter steps 2T; 0: one shot per 2T, the most there can be.
    imu : str
        IMU grade, an :meth:`atomnav.imu.ImuErrors.preset` name (:func:`atomnav.imu.preset_names`)
        with a bias in each triad that can be simulated at 200 Hz: every built-in grade
        but the satellite accelerometers ``electrostatic_space`` and
        ``electrostatic_space_drift`` (no gyro errors: the filter's gyro-bias state would
        start with σ = 0). The predictor takes only the grades whose errors are a random
        turn-on bias, white noise and a bias random walk (``navigation``, ``precise``,
        ``medium``, ``coarse``). The CAI's capture range is ±π/2 of phase: the turn-on
        accelerometer bias σ_b gives a phase σ of k T² σ_b (0.20 rad for ``navigation`` at
        T = 25 ms, 2.0 rad for ``precise``), so the coarser grades slip fringes at all but
        the shortest T. For ``tactical`` the phase error is 6 rad RMS even at T = 5 ms and
        the hybrid follows the free INS (RMS position error at 40 s 1.00–1.02 × the free
        INS's 13.2 m, 30 seeds, T = 5–25 ms); ``mems`` is aided at T = 5 ms (0.32 m against
        6.7 m free) and slips fringes beyond (T = 10 ms: 1.23 ×).
    lever : float
        IMU → release-point lever arm along the body z axis (m); its Euler phase
        k T² l ω̇ must be predicted from the 200 Hz gyro under the profile's 15.1 Hz
        angular vibration (see :func:`atomnav.cai.car_mc`).
    gravity : {"earth", "kinematic"}
        "earth" (WGS84 gravity and Earth rate) or "kinematic" (none, the paper's
        kinematic mode).
    vibration : bool
        Include the profile's vibration: 4.3, 9.7 and 15.1 Hz sines, ×2 in 33–35 s and ×3
        vertically around the 26 s shock (the shock itself stays).
    contrast : float
        Readout contrast C ∈ (0, 1].
    checkpoint_s : float
        Spacing of the checkpoints (s): the filter epochs nearest to its multiples and the
        end of the profile.

    Returns
    -------
    pandas.DataFrame
        One row per checkpoint: ``time_s``, and the norms of the hybrid solution's errors
        against the truth ``pos_error_m`` (NED position), ``vel_error_mps`` (NED
        velocity) and ``att_error_rad`` (attitude ψ).

    Raises
    ------
    atomnav.InputError
        Naming ``seed``, ``T``, ``shot_rate`` (above 1/(2T), or its period off the 2T
        steps), ``imu`` (unknown, a flicker band beyond the 100 Hz Nyquist frequency, or
        a triad without bias), ``lever``, ``gravity``, ``vibration``, ``contrast`` or
        ``checkpoint_s``.

    Notes
    -----
    ``cai_car.predict(**params)`` is the covariance predictor of the RMS over seeds.

    References
    ----------
    Tennstedt, B., Rajagopalan, A., Weddig, N. B., Abend, S., Schön, S., Rasel, E. M.
    (2023). Atom Strapdown: toward integrated quantum inertial navigation systems.
    NAVIGATION 70(4), §2.8. Tennstedt, B., Weddig, N., Schön, S. (2021). Improved inertial
    navigation with cold atom interferometry. Gyroscopy and Navigation, §2.4. IEEE Std
    952-1997, Annex C (Allan variance of the noise terms). El-Sheimy, N., Hou, H., Niu, X.
    (2008). Analysis and modeling of inertial sensors using Allan variance. IEEE Trans.
    Instrum. Meas. 57(1).

    Examples
    --------
    >>> from atomnav.campaign.cai_car import cai_car
    >>> cai_car(seed=1, T=0.025).columns.tolist()  # doctest: +SKIP
    ['time_s', 'pos_error_m', 'vel_error_mps', 'att_error_rad']
    """
    seed = integer(seed, "seed", 0, 2**64 - 1)
    key = _points(T, shot_rate, imu, lever, gravity, vibration, contrast, checkpoint_s)
    run = _core_scenario(key).monte_carlo(seed, [0])
    _, t = _checkpoints(key)
    time = np.asarray(run["time"])
    k = np.minimum(np.searchsorted(time, t - 1e-9), len(time) - 1)
    if np.any(np.abs(time[k] - t) > 1e-9):
        raise RuntimeError(f"cai_car: the filter's epochs {time[:3]} … do not hold the checkpoints {t}")
    e = np.asarray(run["hybrid"])[0, k]
    return _table(t, *(np.linalg.norm(e[:, 3 * i:3 * i + 3], axis=1) for i in range(3)))
