"""The Monte-Carlo runner of the CAI-aided INS (:func:`run_campaign`), for the built-in
scenarios and for your own trajectory, sensor and IMU: the scenario is built once in the
core (truth and ideal IMU, the true phases of the chosen source, the closed-loop Van Loan
filter), then seeded runs (ChaCha20, stream = run index, so any subset reproduces
anywhere) run in parallel in the core, in chunks that report progress."""

from __future__ import annotations

import os
import warnings

import numpy as np

from .. import _core
from .._validate import flag, input_error, instance, integer
from ..imu import ImuErrors
from .results import HybridResult
from .sensor import IncompleteShotWarning

#: Largest number of Monte-Carlo runs of one campaign (each keeps its whole error history).
MAX_RUNS = 100_000


def run_campaign(trajectory, config, *, runs: int = 100, seed: int = 0, name: str = "campaign", progress: bool = True,
                 callback=None, params: dict | None = None) -> HybridResult:
    """Monte Carlo of a CAI-aided INS against the IMU-only INS on a known trajectory.

    Every run draws the IMU errors of ``config.imu`` and the CAI readout noise, runs the
    CAI-aided filter and the free strapdown on the same IMU record, and keeps their
    errors against the truth, the bias estimates with their truth and σ, the NEES and the
    per-shot phase errors (Tennstedt et al. 2023, §2.8 and §4). The built-in scenarios
    (:func:`atomnav.cai.car_mc`, :func:`atomnav.cai.slalom`, ...) are calls of this
    function.

    Parameters
    ----------
    trajectory : atomnav.trajectory.Trajectory or atomnav._core.Motion
        The true motion. A trajectory read from data (:meth:`Trajectory.from_csv`,
        :meth:`Trajectory.from_dataframe`) must be sampled evenly at ``config.rate_hz``:
        its ideal IMU comes from its samples by second-order finite differences of the
        velocity and attitude, and the truth is the strapdown integral of that ideal IMU
        from the first sample (so an error-free IMU navigates exactly on it; how far it
        departs from your table is ``params["table_departure_m"]`` of the result), with
        ``config.truth_rate_hz = None``. A generated trajectory (or a motion model) is
        sampled exactly at ``config.rate_hz`` over its duration.
    config : ScenarioConfig
        The CAI (any channels, T, lever arms; shots every ``sensor.shot_period`` from
        ``sensor.first_shot`` s after the record start), the filter setup, the IMU error
        model (a preset name or an :class:`atomnav.imu.ImuErrors`), gravity, rates and
        phase source.
    runs : int
        Number of Monte-Carlo runs (1 … :data:`MAX_RUNS`).
    seed : int
        Master seed (0 … 2⁶⁴ − 1); run r uses stream r, so any subset reproduces.
    name : str
        Name kept with the result.
    progress : bool
        Show a progress bar over runs.
    callback : callable, optional
        ``callback(done, runs)`` after each chunk of runs (one run per core).
    params : dict, optional
        Parameters kept with the result beside ``config.to_dict()``.

    Returns
    -------
    HybridResult
        Arrays per run and epoch, and DataFrames with units in the column names
        (:meth:`HybridResult.errors`, :meth:`~HybridResult.rms`,
        :meth:`~HybridResult.bias_table`, :meth:`~HybridResult.nees_table`,
        :meth:`~HybridResult.phase_errors`). ``complete`` is False when the campaign
        was interrupted.

    Raises
    ------
    atomnav.InputError
        For an invalid configuration or trajectory (naming the field, and the row of the
        trajectory). An error during the runs carries the finished runs as the
        exception's ``partial`` attribute (a :class:`HybridResult`, or None before the
        first chunk ended).

    Notes
    -----
    A ``KeyboardInterrupt`` (or one raised by ``callback``) stops the campaign after the
    runs finished so far and returns them (``complete = False``, with a
    ``RuntimeWarning``); before the first chunk ended it propagates. A shot the record
    cannot complete (a Savitzky–Golay ω̇ window at the record start) is skipped with an
    :class:`IncompleteShotWarning` (NaN in ``phase_error``).
    """
    from tqdm.auto import tqdm

    from .scenarios import ScenarioConfig

    instance(name, str, "name")
    instance(config, ScenarioConfig, "config")
    runs, seed = integer(runs, "runs", 1, MAX_RUNS), integer(seed, "seed", 0, 2**64 - 1)
    progress = flag(progress, "progress")
    if callback is not None and not callable(callback):
        raise TypeError(f"callback: expected a callable callback(done, runs), got {type(callback).__name__}")
    params = dict(instance(params, dict, "params")) if params is not None else {}
    core, departure = _scenario(trajectory, config)
    if departure is not None:
        params["table_departure_m"] = departure
    imu_time = core.ideal_imu()[0]
    native = config.sensor._checked("config.sensor")
    for index, ts, before, after, reason in _core.cai_incomplete_shots(native, np.asarray(core.shots), imu_time):
        warnings.warn(IncompleteShotWarning(f"{reason}: skipped in every run", index, ts, before, after), stacklevel=2)
    chunk = max(1, os.cpu_count() or 1)
    parts = []

    def result(complete: bool) -> HybridResult | None:
        return _result(name, params, config, core, parts, complete) if parts else None

    try:
        with tqdm(total=int(runs), desc=name, disable=not progress, unit="run") as bar:
            for lo in range(0, int(runs), chunk):
                ids = list(range(lo, min(lo + chunk, int(runs))))
                parts.append(core.monte_carlo(int(seed), ids))
                bar.update(len(ids))
                if callback is not None:
                    callback(ids[-1] + 1, int(runs))
    except KeyboardInterrupt:
        if not parts:
            raise
        done = sum(len(p["nees"]) for p in parts)
        warnings.warn(f"{name}: interrupted after {done} of {runs} runs; returning the finished runs", RuntimeWarning, stacklevel=2)
        return result(False)
    except Exception as e:
        e.partial = result(False)
        raise
    return result(True)


def _imu_model(value, name: str) -> ImuErrors:
    """An IMU error model given by preset name or as :class:`atomnav.imu.ImuErrors`."""
    if isinstance(value, str):
        return ImuErrors.preset(value)
    return instance(value, ImuErrors, name)


def _scenario(trajectory, config):
    """The core scenario of ``trajectory`` under ``config``, and for a trajectory from data
    how far (m) the simulated truth departs from its table (else None)."""
    from ..trajectory import Trajectory

    instance(trajectory, (Trajectory, _core.Motion), "trajectory")
    motion = trajectory if isinstance(trajectory, _core.Motion) else trajectory.motion
    sensor, setup = config.sensor, config.setup
    native = sensor._checked("config.sensor")
    if motion is not None:
        truth, t0, t_end = motion, 0.0, motion.duration
    else:
        if len(trajectory) < 3:
            raise input_error("trajectory", f"needs at least 3 samples, got {len(trajectory)}")
        truth = tuple(np.ascontiguousarray(x) for x in (trajectory.time, trajectory.lla, trajectory.vel_ned, trajectory.q_nb))
        t0, t_end = float(truth[0][0]), float(truth[0][-1])
    shots = sensor.shots(t0 + sensor.first_shot, t_end)
    reference = None if config.reference is None else _imu_model(config.reference, "config.reference")._to_core()
    core = _core.CaiHybrid(truth, native, shots, *_imu_model(config.imu, "config.imu")._to_core(), reference,
                           setup.p0(sensor.n_extra()), gravity=config.gravity, rate_hz=float(config.rate_hz),
                           truth_rate_hz=None if config.truth_rate_hz is None else float(config.truth_rate_hz),
                           phase_source=config.phase_source, accel_psd=float(setup.accel_psd), gyro_psd=float(setup.gyro_psd),
                           accel_bias_psd=float(setup.accel_bias_psd), gyro_bias_psd=float(setup.gyro_bias_psd),
                           predict_every=setup.predict_every, aiding=flag(config.aiding, "config.aiding"),
                           draw_initial=flag(config.draw_initial, "config.draw_initial"))
    if motion is not None:
        return core, None
    lla, vel, q = core.truth()
    err = _core.nav_errors(lla, vel, q, *truth[1:], ellipsoid=_core.cai_gravity_ellipsoid(config.gravity))
    return core, float(np.max(np.linalg.norm(err[:, :3], axis=1)))


def _result(name: str, params: dict, config, core, parts: list, complete: bool) -> HybridResult:
    """The runs of ``parts`` (chunks of the core's Monte Carlo) as one result."""
    cat = {k: np.concatenate([p[k] for p in parts]) for k in parts[0] if k not in ("time", "imu_time")}
    return HybridResult(name, dict(params), time=parts[0]["time"], hybrid=cat["hybrid"], free=cat["free"], bias=cat["bias"],
                        bias_true=cat["bias_true"], sigma=cat["sigma"], accel_error=cat["accel_error"], phase_error=cat["phase_error"],
                        shots=np.asarray(core.shots), nees=cat["nees"][:, :, 0], imu_time=parts[0]["imu_time"],
                        channel_names=list(config.sensor.channels.names), config=config.to_dict(), complete=complete)
