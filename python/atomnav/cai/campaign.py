"""The Monte-Carlo driver of the CAI-aided INS scenarios: the scenario is built once in the
core (truth at the IMU and the truth rates, the true phases of the chosen source, the
closed-loop Van Loan filter), then seeded runs (ChaCha20, stream = run index, so any
subset reproduces anywhere) run in parallel in the core, in chunks that report progress."""

from __future__ import annotations

import os

import numpy as np

from .. import _core
from .._validate import flag, instance, integer
from ..imu import ImuErrors
from .results import HybridResult

#: Largest number of Monte-Carlo runs of one campaign (each keeps its whole error history).
MAX_RUNS = 100_000


def run_campaign(name: str, motion, config, *, runs: int = 1, seed: int = 0, progress: bool = True,
                 params: dict | None = None) -> HybridResult:
    """Build the scenario of ``motion`` (an ``atomnav._core.Motion``) under ``config``
    (:class:`atomnav.cai.ScenarioConfig`) in the core and run ``runs`` seeded Monte-Carlo
    runs (chunks of one run per core in parallel; tqdm progress over runs). ``params`` are
    the scenario's parameters kept with the result beside ``config.to_dict()``."""
    from tqdm.auto import tqdm

    from .scenarios import ScenarioConfig

    instance(name, str, "name")
    instance(motion, _core.Motion, "motion")
    instance(config, ScenarioConfig, "config")
    runs, seed = integer(runs, "runs", 1, MAX_RUNS), integer(seed, "seed", 0, 2**64 - 1)
    instance(progress, (bool, np.bool_), "progress")
    if params is not None:
        instance(params, dict, "params")
    sensor, setup = config.sensor, config.setup
    native = sensor._checked("config.sensor")
    shots = sensor.shots(sensor.first_shot, motion.duration)
    reference = None if config.reference is None else ImuErrors.preset(config.reference)._to_core()
    core = _core.CaiHybrid(motion, native, shots, *ImuErrors.preset(config.imu)._to_core(), reference,
                           setup.p0(sensor.n_extra()), gravity=config.gravity, rate_hz=float(config.rate_hz),
                           truth_rate_hz=None if config.truth_rate_hz is None else float(config.truth_rate_hz),
                           phase_source=config.phase_source, accel_psd=float(setup.accel_psd), gyro_psd=float(setup.gyro_psd),
                           accel_bias_psd=float(setup.accel_bias_psd), gyro_bias_psd=float(setup.gyro_bias_psd),
                           predict_every=setup.predict_every, aiding=flag(config.aiding, "aiding"), draw_initial=flag(config.draw_initial, "draw_initial"))
    chunk = max(1, os.cpu_count() or 1)
    parts = []
    with tqdm(total=int(runs), desc=name, disable=not progress, unit="run") as bar:
        for lo in range(0, int(runs), chunk):
            ids = list(range(lo, min(lo + chunk, int(runs))))
            parts.append(core.monte_carlo(int(seed), ids))
            bar.update(len(ids))
    cat = {k: np.concatenate([p[k] for p in parts]) for k in parts[0] if k not in ("time", "imu_time")}
    return HybridResult(name, dict(params or {}), time=parts[0]["time"], hybrid=cat["hybrid"], free=cat["free"], bias=cat["bias"],
                        bias_true=cat["bias_true"], sigma=cat["sigma"], accel_error=cat["accel_error"], phase_error=cat["phase_error"],
                        shots=np.asarray(core.shots), nees=cat["nees"][:, :, 0], imu_time=parts[0]["imu_time"],
                        channel_names=list(sensor.channels.names), config=config.to_dict())
