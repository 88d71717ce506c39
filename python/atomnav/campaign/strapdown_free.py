"""The campaign scenario ``strapdown_free``: the free (unaided) strapdown INS with a seeded
IMU of a named grade, and its covariance predictor, the linear covariance analysis of the
INS error model along the same trajectory (Groves 2013, §14.2; Titterton & Weston 2004,
§12.3)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pandas as pd

from .. import _core, strapdown, trajectory
from .. import imu as imu_errors
from .._validate import choice, input_error, integer, nonnegative, positive, scalar
from ..filter import BiasModel, ins_error_model
from ..filter.analysis import Scenario, covariance_analysis
from .scenario import predicted_by

#: The trajectories the scenario runs on.
MOTIONS = ("stationary", "sinusoidal")
#: Longest step (s) of the linear analysis: short against the 20 s shortest period of the
#: sinusoidal motion, and e^{|F|Δt} of the fastest flicker pole (τ ≈ 0.05 s) stays finite.
ANALYSIS_STEP_S = 1.0
#: Longest run (s): several Schuler periods (84 min), and a bounded linear analysis.
MAX_DURATION_S = 6 * 3600.0
_COLUMNS = ("pos_error_m", "hpos_error_m", "vel_error_mps", "att_error_rad")
_BIAS_STATES = {"accel": slice(9, 12), "gyro": slice(12, 15)}


def _points(imu, duration, motion, rate_hz, checkpoint_s, latitude_deg, bias_scale, noise_scale) -> tuple:
    """The checked parameters as a hashable tuple, in the order of the signature."""
    if not isinstance(imu, str):
        raise TypeError(f"imu: expected an IMU preset name (str), got {type(imu).__name__}")
    choice(imu, imu_errors.preset_names(), "imu")
    duration, rate_hz = positive(duration, "duration"), positive(rate_hz, "rate_hz")
    if duration > MAX_DURATION_S:
        raise input_error("duration", f"must be at most {MAX_DURATION_S:g} s, got {duration}")
    if duration * rate_hz > trajectory.MAX_SAMPLES:
        raise input_error("rate_hz", f"{duration} s at {rate_hz} Hz is more than {trajectory.MAX_SAMPLES} samples")
    motion = choice(motion, MOTIONS, "motion")
    checkpoint_s = positive(checkpoint_s, "checkpoint_s")
    if checkpoint_s > duration:
        raise input_error("checkpoint_s", f"must be at most the duration {duration} s, got {checkpoint_s}")
    samples = checkpoint_s * rate_hz
    if abs(samples - round(samples)) > 1e-9 * samples:
        raise input_error("checkpoint_s", f"must be a whole number of IMU samples (1/rate_hz = {1 / rate_hz:g} s), got {checkpoint_s}")
    latitude_deg = scalar(latitude_deg, "latitude_deg")
    if not abs(latitude_deg) < 90.0:
        raise input_error("latitude_deg", f"must be inside (-90, 90) degrees, got {latitude_deg}")
    return (imu, duration, motion, rate_hz, checkpoint_s, latitude_deg, nonnegative(bias_scale, "bias_scale"),
            nonnegative(noise_scale, "noise_scale"))


def _grade(key: tuple) -> imu_errors.ImuErrors:
    """The preset of ``key`` with its bias terms (fixed and turn-on bias, bias random walk,
    Gauss–Markov and flicker) scaled by ``bias_scale`` and its white noise by
    ``noise_scale``."""
    imu, *_, bias_scale, noise_scale = key
    errors = imu_errors.ImuErrors.preset(imu)
    for triad in (errors.accel, errors.gyro):
        gm, fl = triad._terms("imu")
        triad.bias = tuple(bias_scale * np.asarray(triad.bias, dtype=float))
        triad.bias_sigma *= bias_scale
        triad.bias_rw *= bias_scale
        triad.white *= noise_scale
        triad.gauss_markov = None if gm is None else imu_errors.GaussMarkov(bias_scale * gm.sigma, gm.tau)
        triad.flicker = None if fl is None else imu_errors.Flicker(bias_scale * fl.b, fl.f_lo, fl.f_hi)
    imu_errors.ImuSimulator(errors, 1.0 / key[3], "increments")  # checks the grade at this rate (flicker band below Nyquist)
    return errors


def _path(motion: str, duration: float, rate_hz: float, latitude_deg: float) -> trajectory.Trajectory:
    origin = (np.radians(latitude_deg), trajectory.MOSCOW[1], trajectory.MOSCOW[2])
    make = trajectory.stationary if motion == "stationary" else trajectory.sinusoidal
    return make(duration, rate_hz, origin=origin)


@lru_cache(maxsize=4)
def _truth(motion: str, duration: float, rate_hz: float, latitude_deg: float):
    """The trajectory and its ideal IMU increments, kept so the seeds of one parameter
    point share them; a run does not change them."""
    traj = _path(motion, duration, rate_hz, latitude_deg)
    return traj, traj.ideal_imu("increments")


def _checkpoints(key: tuple) -> np.ndarray:
    """Every multiple of ``checkpoint_s`` up to the duration (s)."""
    duration, checkpoint_s = key[1], key[4]
    return checkpoint_s * np.arange(1, int(np.floor(duration / checkpoint_s + 1e-9)) + 1)


def _table(times: np.ndarray, blocks) -> pd.DataFrame:
    return pd.DataFrame({"time_s": times, **dict(zip(_COLUMNS, (np.asarray(b, dtype=float) for b in blocks)))})


def _poles(triad: imu_errors.TriadErrors) -> list[tuple[float, float]]:
    """(σ, τ) of every Gauss–Markov process in one axis of ``triad``: its Gauss–Markov term
    and the poles whose sum :mod:`atomnav.imu` simulates its flicker term with (Keshner
    1982; the core's own poles)."""
    gm, fl = triad._terms("imu")
    poles = [] if gm is None or gm.sigma == 0 else [(gm.sigma, gm.tau)]
    return poles + ([] if fl is None or fl.b == 0 else _core.imu_flicker_poles(fl.b, fl.f_lo, fl.f_hi))


def _linear(errors: imu_errors.ImuErrors, imu: str) -> None:
    """Reject the error terms the linear analysis does not carry."""
    for name in ("accel", "gyro"):
        triad = getattr(errors, name)
        if np.any(np.asarray(triad.scale) != 0) or np.any(np.asarray(triad.misalignment) != 0):
            raise input_error("imu", f"preset {imu!r} has scale-factor or misalignment errors in its {name} triad; the linear "
                                     "analysis of this scenario carries biases (fixed, turn-on, random walk, Gauss–Markov, "
                                     "flicker) and white noise only")


def _variances(f: np.ndarray, qc: np.ndarray, steps: int, dt: float, p0: np.ndarray) -> np.ndarray:
    """Variance of the 9 navigation states after each of ``steps`` steps of the linear model
    ẋ = Fx + w (no measurement) with the (F, Q_c) of every step (or one for all), exactly
    (Van Loan) discretised: the covariance analysis of
    :class:`atomnav.filter.analysis.Scenario`. P₀ may be singular (the INS starts at the
    truth)."""
    n = p0.shape[0]
    scenario = Scenario(f, qc, np.full(steps, dt), p0, np.zeros((0, n)), np.zeros((0, 0)), [False] * (steps + 1))
    return covariance_analysis(scenario).to_numpy()[1:, 1:10] ** 2


def _with_poles(f: np.ndarray, column: int, sigma: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F, Q_c) of each model ``f`` of the navigation states driven by Gauss–Markov poles
    (σ, τ) that enter where the bias state ``column`` does, without white noise."""
    n = f.shape[1] + len(tau)
    fa = np.zeros((len(f), n, n))
    fa[:, :15, :15] = f
    fa[:, :15, 15:] = f[:, :, column][:, :, None]
    fa[:, 15:, 15:] = np.diag(-1.0 / tau)
    qa = np.zeros((len(f), n, n))
    qa[:, 15:, 15:] = np.diag(2.0 * sigma**2 / tau)
    return fa, qa


def _strapdown_free_covariance(*, imu="tactical", duration=600.0, motion="stationary", rate_hz=100.0, checkpoint_s=60.0,
                               latitude_deg=55.75, bias_scale=1.0, noise_scale=1.0) -> pd.DataFrame:
    """Predicted RMS over seeds of the errors of :func:`strapdown_free`: the linear covariance
    analysis of the 15-state INS error model (:func:`atomnav.filter.ins_error_model`, Groves
    2013, §14.2) along the trajectory, without measurements.

    The INS starts at the truth (zero navigation covariance). The bias states hold the
    grade's turn-on bias variance plus the square of its fixed bias (the second moment, so
    the prediction is √E[|e|²] over seeds), and its bias random walk; the white noise is
    the process noise. Every Gauss–Markov process of the grade, and each pole of the sum of
    Gauss–Markov processes its flicker term is simulated with (:mod:`atomnav.imu`), is
    independent of the rest: each sensor axis runs as its own linear system, the navigation
    states augmented with that axis's poles (stationary start), and the covariances add.
    The steps are at most :data:`ANALYSIS_STEP_S` long, the model taken at the middle of
    each and discretised exactly (Van Loan); at rest the model is constant. The covariance
    loop is :func:`atomnav.filter.analysis.covariance_analysis`.

    Parameters
    ----------
    imu, duration, motion, rate_hz, checkpoint_s, latitude_deg, bias_scale, noise_scale
        As for :func:`strapdown_free`.

    Returns
    -------
    pandas.DataFrame
        The rows of :func:`strapdown_free`: ``time_s`` and the predicted RMS norms
        ``pos_error_m``, ``hpos_error_m``, ``vel_error_mps`` and ``att_error_rad`` (√ of the
        trace of each block of the covariance).

    Raises
    ------
    atomnav.InputError
        As for :func:`strapdown_free`, and naming ``imu`` for a grade with scale-factor or
        misalignment errors.
    """
    key = _points(imu, duration, motion, rate_hz, checkpoint_s, latitude_deg, bias_scale, noise_scale)
    errors = _grade(key)
    _linear(errors, imu)
    times = _checkpoints(key)
    sub = int(np.ceil(key[4] / ANALYSIS_STEP_S - 1e-9))
    step = key[4] / sub
    mid = _path(key[2], len(times) * key[4], 2.0 / step, key[5])  # samples every step/2: the odd ones are the midpoints
    rates = mid.ideal_imu("rates")
    at = slice(1, 2 * len(times) * sub, 2)
    a, g = errors.accel, errors.gyro
    f, qc = ins_error_model(mid.lla[at], mid.vel_ned[at], mid.q_nb[at], rates[[f"accel_{x}_mps2" for x in "xyz"]].to_numpy()[at],
                            gyro_psd=g.white**2, accel_psd=a.white**2,
                            gyro_bias=BiasModel("random_walk", psd=g.bias_rw**2), accel_bias=BiasModel("random_walk", psd=a.bias_rw**2))
    steps = len(f)
    if np.all(f == f[0]) and np.all(qc == qc[0]):  # at rest: one model for every step
        f, qc = f[:1], qc[:1]
    p0 = np.zeros((15, 15))
    for name, triad in (("accel", a), ("gyro", g)):
        b = np.asarray(triad.bias, dtype=float)
        p0[_BIAS_STATES[name], _BIAS_STATES[name]] = np.diag(np.full(3, triad.bias_sigma**2)) + np.outer(b, b)
    var = _variances(f, qc, steps, step, p0)
    for name, triad in (("accel", a), ("gyro", g)):
        poles = _poles(triad)
        if poles:
            sigma, tau = np.array(poles).T
            for axis in range(3):  # each axis's poles start stationary, independent of the rest
                pa = np.diag(np.r_[np.zeros(15), sigma**2])
                var += _variances(*_with_poles(f, _BIAS_STATES[name].start + axis, sigma, tau), steps, step, pa)
    var = var[sub - 1::sub]
    return _table(times, (np.sqrt(var[:, s].sum(axis=1)) for s in (slice(0, 3), slice(0, 2), slice(3, 6), slice(6, 9))))


@predicted_by(_strapdown_free_covariance)
def strapdown_free(*, seed=0, imu="tactical", duration=600.0, motion="stationary", rate_hz=100.0, checkpoint_s=60.0,
                   latitude_deg=55.75, bias_scale=1.0, noise_scale=1.0) -> pd.DataFrame:
    """One run of the free (unaided) strapdown INS with a seeded IMU of grade ``imu``,
    started at the truth, its vertical channel free (Titterton & Weston 2004, §12.3).

    The IMU increments of the trajectory are corrupted by :func:`atomnav.imu.corrupt` with
    the grade's error model and the run's seed and integrated by
    :func:`atomnav.strapdown.integrate`; the errors against the truth are taken at every
    checkpoint. The trajectory and its ideal IMU are kept for the last few parameter
    points, so consecutive seeds of one point build them once; a run is the same bit for
    bit either way.

    Parameters
    ----------
    seed : int
        Seed of the IMU errors (0 … 2⁶⁴ − 1).
    imu : str
        IMU grade, an :meth:`atomnav.imu.ImuErrors.preset` name (``tactical``,
        ``navigation``, ``precise``, ``medium``, ``coarse``, ``mems``, ...).
    duration : float
        Length of the run (s), at most :data:`MAX_DURATION_S`.
    motion : {"stationary", "sinusoidal"}
        At rest, level and north-pointing (:func:`atomnav.trajectory.stationary`), or the
        default sinusoidal motion of :func:`atomnav.trajectory.sinusoidal` (metres of
        displacement, tenths of a radian of attitude, periods 20–60 s).
    rate_hz : float
        IMU sampling rate (Hz), at most :data:`atomnav.trajectory.MAX_SAMPLES` samples over
        the run; a grade with a flicker term needs its band below the Nyquist frequency
        rate_hz/2.
    checkpoint_s : float
        Spacing of the checkpoints (s), a whole number of IMU samples: the table has a row
        at every multiple of it up to ``duration``.
    latitude_deg : float
        Latitude of the site (degrees), inside (−90, 90); longitude 37.6° E, height 200 m.
    bias_scale : float
        Factor (≥ 0) on every bias term of the grade: fixed and turn-on bias, bias random
        walk, Gauss–Markov σ and flicker bias instability. A continuous grade between and
        beyond the named ones, for requirement searches (the bias a mission tolerates).
    noise_scale : float
        Factor (≥ 0) on the grade's white noise (ARW and VRW).

    Returns
    -------
    pandas.DataFrame
        One row per checkpoint: ``time_s``, and the norms of the INS errors against the
        truth ``pos_error_m`` (NED position), ``hpos_error_m`` (horizontal position),
        ``vel_error_mps`` (NED velocity) and ``att_error_rad`` (attitude ψ).

    Raises
    ------
    atomnav.InputError
        Naming ``seed``, ``imu`` (unknown), ``duration``, ``motion``, ``rate_hz`` (too many
        samples), ``accel.flicker.f_hi`` or ``gyro.flicker.f_hi`` (the grade's flicker band
        above the Nyquist frequency), ``checkpoint_s`` (longer than the run, or not a whole
        number of samples), ``latitude_deg``, ``bias_scale`` or ``noise_scale``.

    Notes
    -----
    ``strapdown_free.predict(**params)`` is the covariance predictor of the RMS over seeds
    (:func:`_strapdown_free_covariance`). At rest, over t well below the Schuler period
    (84 min), an accelerometer bias b gives a horizontal position error ½ b t² and a
    horizontal gyro bias ε one of g ε t³/6; the vertical channel diverges with the time
    constant √(R/2g) ≈ 9.5 min.

    References
    ----------
    P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
    Systems*, 2nd ed. (2013), §14.2. D. H. Titterton and J. L. Weston, *Strapdown Inertial
    Navigation Technology*, 2nd ed. (2004), §12.3. M. S. Keshner, "1/f noise", *Proc. IEEE*
    70(3) (1982).

    Examples
    --------
    >>> from atomnav.campaign.strapdown_free import strapdown_free
    >>> strapdown_free(seed=1, duration=120.0).columns.tolist()  # doctest: +SKIP
    ['time_s', 'pos_error_m', 'hpos_error_m', 'vel_error_mps', 'att_error_rad']
    """
    seed = integer(seed, "seed", 0, 2**64 - 1)
    key = _points(imu, duration, motion, rate_hz, checkpoint_s, latitude_deg, bias_scale, noise_scale)
    traj, ideal = _truth(key[2], key[1], key[3], key[5])
    meas = imu_errors.corrupt(ideal, errors=_grade(key), dt=1.0 / key[3], kind="increments", seed=seed)
    nav = strapdown.integrate(meas, **traj.initial_state())
    times = _checkpoints(key)
    err = traj.errors(nav.iloc[np.rint(times * key[3]).astype(int) - 1])
    e = err[["dpos_n_m", "dpos_e_m", "dpos_d_m", "dvel_n_mps", "dvel_e_mps", "dvel_d_mps", "psi_n_rad", "psi_e_rad", "psi_d_rad"]].to_numpy()
    return _table(times, (np.linalg.norm(e[:, s], axis=1) for s in (slice(0, 3), slice(0, 2), slice(3, 6), slice(6, 9))))
