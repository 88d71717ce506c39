"""The campaign scenario ``gnss_tight``: one run of the tightly coupled GNSS/INS of Demidov
2009 (§2.12) on the thesis's simulated drive (:mod:`atomnav.gnss.scenarios`), with a GNSS
outage at the end of the run, and its covariance predictor, the filter's own covariance
along the truth."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .._validate import choice, input_error, integer, positive, scalar
from ..gnss import scenarios
from ..gnss.tight import tight_ins
from .scenario import predicted_by

#: The INS accuracy classes of Demidov 2009 (§3), as in :data:`atomnav.gnss.scenarios.INITIAL_ATTITUDE`.
IMU_CLASSES = tuple(scenarios.INITIAL_ATTITUDE)
#: Satellites of the nominal GPS constellation: ``satellites`` at this value uses every
#: satellite above the mask at each epoch.
ALL_SATELLITES = 24
#: Longest run (s): the thesis's longest experiment (40 min) and then some.
MAX_DURATION_S = 4 * 3600.0
#: Highest IMU rate (Hz).
MAX_RATE_HZ = 1000.0
_COLUMNS = ("pos_error_m", "hpos_error_m", "vel_error_mps", "att_error_rad")
_BLOCKS = (slice(0, 3), slice(0, 2), slice(3, 6), slice(6, 9))
_NAV_ERRORS = ("dpos_n_m", "dpos_e_m", "dpos_d_m", "dvel_n_mps", "dvel_e_mps", "dvel_d_mps", "psi_n_rad", "psi_e_rad", "psi_d_rad")
_SIGMAS = tuple(f"sigma_{b}[{i}]" for b in ("position", "velocity", "attitude") for i in range(3))


def _whole_seconds(x, name: str, low: float) -> float:
    x = scalar(x, name)
    if not (np.isfinite(x) and x >= low and x == np.round(x)):
        raise input_error(name, f"must be a whole number of seconds >= {low:g} (GNSS epochs are 1 s apart), got {x}")
    return x


def _scenario(seed: int, imu_class, outage_s, satellites, duration, checkpoint_s, rate_hz) -> scenarios.Scenario:
    """The checked parameters as the :class:`atomnav.gnss.scenarios.Scenario` they run."""
    imu_class = choice(imu_class, IMU_CLASSES, "imu_class")
    duration = positive(duration, "duration")
    if duration > MAX_DURATION_S:
        raise input_error("duration", f"must be at most {MAX_DURATION_S:g} s, got {duration}")
    checkpoint_s = _whole_seconds(checkpoint_s, "checkpoint_s", 1.0)
    if checkpoint_s > duration:
        raise input_error("checkpoint_s", f"must be at most the duration {duration} s, got {checkpoint_s}")
    outage_s = _whole_seconds(outage_s, "outage_s", 0.0)
    if outage_s >= duration:
        raise input_error("outage_s", f"must be shorter than the duration {duration} s, got {outage_s}")
    satellites = integer(satellites, "satellites", 0, ALL_SATELLITES)
    rate_hz = positive(rate_hz, "rate_hz")
    if abs(rate_hz - round(rate_hz)) > 1e-9 * rate_hz or rate_hz > MAX_RATE_HZ:
        raise input_error("rate_hz", f"must be a whole number of samples per 1 s GNSS epoch, at most {MAX_RATE_HZ:g}, got {rate_hz}")
    # the GNSS epochs in the last outage_s seconds, (duration − outage_s, duration], are withheld
    outage = None if outage_s == 0 else (duration - outage_s + 0.5, outage_s)
    return scenarios.Scenario(imu_class, duration_s=duration, n_sats=None if satellites == ALL_SATELLITES else satellites,
                              outage=outage, rate_hz=rate_hz, seed=seed)


def _sub_seed(seed: int) -> int:
    """The run's seed (0 … 2⁶⁴ − 1) hashed (numpy ``SeedSequence``) into the 63-bit seed of
    the thesis scenario, which also seeds its observation noise with the seed + 1000."""
    return int(np.random.SeedSequence(seed).generate_state(1, np.uint64)[0] >> np.uint64(1))


def _checkpoints(sc: scenarios.Scenario, checkpoint_s) -> np.ndarray:
    """Every multiple of ``checkpoint_s`` up to the duration (s)."""
    return float(checkpoint_s) * np.arange(1, int(np.floor(sc.duration_s / float(checkpoint_s) + 1e-9)) + 1)


def _rows(nav: pd.DataFrame, times: np.ndarray) -> np.ndarray:
    """Row of each checkpoint time in the filter's 1 Hz output."""
    t = nav["time_s"].to_numpy()
    k = np.minimum(np.searchsorted(t, times - 1e-9), len(t) - 1)
    if np.any(np.abs(t[k] - times) > 1e-9):
        raise RuntimeError(f"gnss_tight: the filter's outputs {t[:3]} … do not hold the checkpoints {times}")
    return k


def _table(times: np.ndarray, squared: np.ndarray) -> pd.DataFrame:
    """The scenario's table from squared errors (or variances) of the 9 navigation states."""
    return pd.DataFrame({"time_s": times, **{c: np.sqrt(squared[:, s].sum(axis=1)) for c, s in zip(_COLUMNS, _BLOCKS)}})


def _run(setup: dict):
    """The tightly coupled filter on a built setup (as :func:`atomnav.gnss.scenarios.run`)."""
    ins = tight_ins(setup["eph"], setup["obs"], **setup["args"])
    m = setup["imu"]
    return ins.run(m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
                   m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy(), h_ref=setup["h_ref"], chunk_s=300.0, progress=False)


def _gnss_tight_covariance(*, imu_class="precise", outage_s=0.0, satellites=ALL_SATELLITES, duration=300.0, checkpoint_s=30.0,
                           rate_hz=50.0) -> pd.DataFrame:
    """Predicted RMS over seeds of the errors of :func:`gnss_tight`: the filter's own
    covariance along the truth, from a run on error-free data
    (:func:`atomnav.gnss.scenarios.build` with ``error_free=True``: ideal IMU, noise-free
    observations and altitude, true initial state), which is the linear covariance
    analysis of the filter as built. Over every satellite on the drive the filter is
    consistent (its run-averaged NEES inside the χ² 95 % band at 99.3 % of the epochs,
    docs/consistency.md), so this is the RMS a Monte Carlo converges to; with a few
    satellites or a long outage the linearisation may stop being exact.

    Parameters
    ----------
    imu_class, outage_s, satellites, duration, checkpoint_s, rate_hz
        As for :func:`gnss_tight`.

    Returns
    -------
    pandas.DataFrame
        The rows of :func:`gnss_tight`: ``time_s`` and the predicted RMS norms
        ``pos_error_m``, ``hpos_error_m``, ``vel_error_mps`` and ``att_error_rad`` (√ of
        the trace of each block of the filter's covariance, from its σ).

    Raises
    ------
    atomnav.InputError
        As for :func:`gnss_tight`.
    """
    sc = _scenario(0, imu_class, outage_s, satellites, duration, checkpoint_s, rate_hz)
    nav = _run(scenarios.build(sc, error_free=True)).nav
    times = _checkpoints(sc, checkpoint_s)
    return _table(times, nav[list(_SIGMAS)].to_numpy()[_rows(nav, times)] ** 2)


@predicted_by(_gnss_tight_covariance)
def gnss_tight(*, seed=0, imu_class="precise", outage_s=0.0, satellites=ALL_SATELLITES, duration=300.0, checkpoint_s=30.0,
               rate_hz=50.0) -> pd.DataFrame:
    """One run of the tightly coupled GPS/INS of Demidov 2009 (§2.12, §4) on the thesis's
    simulated drive: level at 100 m/s from 55.75° N, 37.6° E, 200 m, the heading swinging
    with yaw rate 3 °/s·sin(2πt/600 s); nominal GPS constellation, 10° mask, code and rate
    σ 3 m and 0.05 m/s at 1 Hz; the vertical channel damped by a 1 Hz barometer
    (:mod:`atomnav.gnss.scenarios`). The run's seed draws the IMU errors, the observation
    and barometer noise and the initial error from the filter's P₀.

    Parameters
    ----------
    seed : int
        Seed of the run (0 … 2⁶⁴ − 1), hashed into the thesis scenario's seed.
    imu_class : {"precise", "medium", "coarse"}
        INS accuracy class of Demidov 2009 (§3): the IMU preset of that name and the
        initial attitude σ of :data:`atomnav.gnss.scenarios.INITIAL_ATTITUDE`.
    outage_s : float
        Length of a GNSS outage at the end of the run (s, a whole number below
        ``duration``): the epochs of the last ``outage_s`` seconds are withheld, so the
        last checkpoints show the INS drift; 0: none.
    satellites : int
        Satellites used: the ``satellites`` highest at the start, kept for the whole run
        (Demidov 2009, §4); 0: none (the baro-damped INS alone; so is 1, since the filter
        differences pairs of satellites); :data:`ALL_SATELLITES`
        (24, the whole nominal constellation, the default): every satellite above the mask
        at each epoch.
    duration : float
        Length of the run (s), at most :data:`MAX_DURATION_S`.
    checkpoint_s : float
        Spacing of the checkpoints (s, a whole number): the table has a row at every
        multiple of it up to ``duration``.
    rate_hz : float
        IMU sampling rate (Hz, a whole number up to :data:`MAX_RATE_HZ`); the filter
        predicts once per second.

    Returns
    -------
    pandas.DataFrame
        One row per checkpoint: ``time_s``, and the norms of the filter's errors against
        the truth ``pos_error_m`` (NED position), ``hpos_error_m`` (horizontal position),
        ``vel_error_mps`` (NED velocity) and ``att_error_rad`` (attitude ψ).

    Raises
    ------
    atomnav.InputError
        Naming ``seed``, ``imu_class``, ``outage_s``, ``satellites``, ``duration``,
        ``checkpoint_s`` or ``rate_hz``.

    Notes
    -----
    ``gnss_tight.predict(**params)`` is the covariance predictor of the RMS over seeds
    (:func:`_gnss_tight_covariance`). A 300 s run at 50 Hz takes about 0.2 s.

    References
    ----------
    O. V. Demidov, *Tight integration of GLONASS and GPS with inertial navigation systems
    of different accuracy classes*, thesis abstract, Moscow State University (2009), §2.12,
    §3, §4.

    Examples
    --------
    >>> from atomnav.campaign.gnss_tight import gnss_tight
    >>> gnss_tight(seed=1, outage_s=60.0).columns.tolist()  # doctest: +SKIP
    ['time_s', 'pos_error_m', 'hpos_error_m', 'vel_error_mps', 'att_error_rad']
    """
    seed = integer(seed, "seed", 0, 2**64 - 1)
    sc = _scenario(_sub_seed(seed), imu_class, outage_s, satellites, duration, checkpoint_s, rate_hz)
    setup = scenarios.build(sc)
    nav = _run(setup).nav
    times = _checkpoints(sc, checkpoint_s)
    err = setup["trajectory"].errors(nav.iloc[_rows(nav, times)])
    return _table(times, err[list(_NAV_ERRORS)].to_numpy() ** 2)
