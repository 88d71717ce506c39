"""Named, seeded experiments of the thesis (Demidov 2009, §4): INS accuracy class ×
satellite count, GNSS outages, open- vs closed-loop, all on the tightly coupled filter.

``STAT``: stationary at 55.75°N, 37.6°E, 200 m, heading 30°. ``MOVE``: level drive at
100 m/s whose heading swings with yaw rate 3 °/s·sin(2πt/600 s) (turns of up to 3 °/s, the
manoeuvres that make heading observable; a smooth stand-in for straight legs and 180°
turns). GPS nominal constellation, 10° mask, code/rate σ 3 m / 0.05 m/s, ΔT = 1 s.
The INS's vertical channel is baro-damped (docs/departures.md#baro-damped-vertical-channel: ζ = 0.707,
ω_v = 0.01 rad/s): a barometric altitude at 1 Hz with white error σ = 1 m, held
over each second to the IMU rate, is the loop's reference; the filter models it as white
noise of PSD σ²·1 s = 1 m²·s (the loop's time constants, ~100 s, are far longer than the
1 s hold) and no bias, as simulated.
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, replace

import numpy as np
import pandas as pd

from .. import _core, imu, trajectory, units
from .._validate import finite_scalar, flag, input_error, instance, table, vector
from ..filter.aided import AidedResult
from ..filter.engine import BiasModel
from .ephemeris import Ephemerides
from .observations import simulate
from .tight import tight_ins

#: Initial attitude σ (tilt, heading) of each class (Demidov 2009, §3), rad.
INITIAL_ATTITUDE = {
    "precise": (20 * units.ARCSEC, 0.05 * units.DEG),
    "medium": (units.ARCMIN, 0.5 * units.DEG),
    "coarse": (0.3 * units.DEG, 3.0 * units.DEG),
}
ORIGIN = np.array(trajectory.MOSCOW)
#: Baro loop (Demidov 2009, §3): damping ratio, natural frequency (rad/s), white altitude error σ (m).
BARO_ZETA, BARO_OMEGA, BARO_SIGMA = 0.707, 0.01, 1.0
#: Code (m) and rate (m/s) σ of the observations of an error-free :func:`build`: a
#: nanometre, negligible against the filter's 3 m and 0.05 m/s.
ERROR_FREE_SIGMA = 1e-9


@dataclass(frozen=True)
class Scenario:
    """One experiment of the thesis (Demidov 2009, §4) on the tightly coupled filter.

    Parameters
    ----------
    imu_class : {"precise", "medium", "coarse"}, default "precise"
        INS accuracy class: IMU error preset and initial attitude σ
        (:data:`INITIAL_ATTITUDE`). The only positional field; the others are
        keyword-only.
    motion : {"MOVE", "STAT"}, default "MOVE"
        "MOVE": level drive at 100 m/s whose heading swings with yaw rate
        3 °/s·sin(2πt/600 s); "STAT": stationary at 55.75°N, 37.6°E, 200 m, heading 30°.
    duration_s : float, default 1200.0
        Length of the run, s.
    n_sats : int, optional
        None = every satellite above the mask, else the fixed n highest at the start
        (0 = free INS).
    outage : (float, float), optional
        (start s, length s) without GNSS.
    mode : {"closed", "open"}, default "closed"
        Closed- or open-loop error correction.
    formulation : str, default "first_difference"
        Tight-coupling formulation, one of :data:`atomnav.gnss.FORMULATIONS`.
    rate_hz : float, default 50.0
        IMU sampling rate, Hz.
    seed : int, default 0
        Seed of the IMU errors, satellite clocks, observation noise, initial error and
        barometer noise.
    vertical : {"damped", "free"}, default "damped"
        Vertical channel: damped by a 1 Hz barometric altitude (white error σ = 1 m;
        loop ζ = 0.707, ω_v = 0.01 rad/s), or free.
    """

    imu_class: str = "precise"
    _: KW_ONLY
    motion: str = "MOVE"
    duration_s: float = 1200.0
    n_sats: int | None = None
    outage: tuple[float, float] | None = None
    mode: str = "closed"
    formulation: str = "first_difference"
    rate_hz: float = 50.0
    seed: int = 0
    vertical: str = "damped"


SCENARIOS = {
    "precise_closed_1h": Scenario("precise", duration_s=3600.0),
    "precise_open_1h": Scenario("precise", duration_s=3600.0, mode="open"),
    "medium_closed_1h": Scenario("medium", motion="STAT", duration_s=3600.0),
    "medium_open_1h": Scenario("medium", motion="STAT", duration_s=3600.0, mode="open"),
    **{f"sats_{n}": Scenario("precise", duration_s=2400.0, n_sats=n) for n in (0, 2, 3)},
    "sats_all": Scenario("precise", duration_s=2400.0),
    **{f"outage_precise_{m}min": Scenario("precise", duration_s=900.0 + 60 * m + 600.0, outage=(900.0, 60.0 * m))
       for m in (1, 5, 10, 20)},
    **{f"outage_coarse_{m}min": Scenario("coarse", duration_s=900.0 + 60 * m + 600.0, outage=(900.0, 60.0 * m))
       for m in (1, 5, 10, 20)},
}


def _trajectory(sc: Scenario) -> trajectory.Trajectory:
    if sc.motion == "STAT":
        return trajectory.stationary(sc.duration_s, sc.rate_hz, origin=ORIGIN, euler=(0.0, 0.0, np.radians(30.0)))
    if sc.motion == "MOVE":
        return trajectory.drive_with_yaw(sc.rate_hz, origin=ORIGIN, speed=100.0, yaw_rate_amp=np.radians(3.0),
                                         period=600.0, duration=sc.duration_s)
    raise input_error("motion", f"unknown {sc.motion!r} (known: 'STAT', 'MOVE')")


def _scenario(sc) -> Scenario:
    """A :class:`Scenario`, or the one of :data:`SCENARIOS` of that name."""
    if isinstance(sc, str):
        if sc not in SCENARIOS:
            raise input_error("sc", f"unknown scenario {sc!r} (known: {', '.join(SCENARIOS)})")
        return SCENARIOS[sc]
    return instance(sc, Scenario, "sc")


def build(sc: Scenario | str, clock=(0.0, 0.0), *, error_free: bool = False) -> dict:
    """Everything a scenario run needs, simulated.

    Parameters
    ----------
    sc : Scenario or str
        The scenario, or the name of one of :data:`SCENARIOS`.
    clock : array_like, shape (2,), default (0, 0)
        True receiver clock (bias s, drift s/s): δt_r(t) = bias + drift·t, t (s) from the
        start of the run (the first GNSS epoch is at 1 s).
    error_free : bool, default False
        Error-free data for the same filter: the ideal IMU (bias truth 0), observations
        with code and rate σ of :data:`ERROR_FREE_SIGMA` drawn with seed 0 whatever
        ``sc.seed`` (the satellite clocks are broadcast and the atmosphere is modelled as
        simulated, so nothing else is in error), the exact barometric altitude and the
        true initial state; the filter's settings (P0, noise PSDs) unchanged. A run on it carries the filter's own
        covariance along the truth, the linear covariance analysis of the filter.

    Returns
    -------
    dict
        ``scenario`` (:class:`Scenario`); ``trajectory`` (truth,
        :class:`atomnav.trajectory.Trajectory`); ``imu``: corrupted IMU increments with
        their bias truth (DataFrame); ``eph`` (:class:`Ephemerides`) and ``obs``
        (observation table); ``args``: the keyword arguments of :func:`tight_ins`, with an
        initial error drawn from P0; ``h_ref``: the barometric reference altitude per IMU
        sample (m), None unless ``vertical="damped"``.

    Raises
    ------
    atomnav.InputError
        Naming ``sc`` for an unknown scenario name, or ``motion`` for an unknown motion.
    TypeError
        ``error_free`` is not a bool.
    """
    sc = _scenario(sc)
    clock = vector(clock, 2, "clock")
    error_free = flag(error_free, "error_free")
    rng = np.random.default_rng(sc.seed)
    traj = _trajectory(sc)
    dt = 1.0 / sc.rate_hz
    errors = imu.ImuErrors.preset(sc.imu_class)
    if error_free:
        meas = traj.ideal_imu("increments").assign(**dict.fromkeys(imu.BIAS_COLUMNS[0] + imu.BIAS_COLUMNS[1], 0.0))
    else:
        meas = imu.corrupt(traj.ideal_imu("increments"), errors=errors, dt=dt, kind="increments", seed=sc.seed)
    t_gnss = np.arange(1.0, sc.duration_s + 1e-9, 1.0)
    eph = Ephemerides.nominal(0.0, sc.duration_s, glonass=False, seed=sc.seed)
    idx = np.rint(t_gnss * sc.rate_hz).astype(int)
    lla, vel = traj.lla[idx], traj.vel_ned[idx]
    only = None
    if sc.n_sats is not None:
        only = eph.top(sc.n_sats, 0.0, traj.lla[0]) if sc.n_sats > 0 else []
    outages = [] if sc.outage is None else [(sc.outage[0], sc.outage[0] + sc.outage[1])]
    # the simulator's bias is the offset at its first epoch t_gnss[0], the run starts at 0
    noise = dict(sigma_code=ERROR_FREE_SIGMA, sigma_rate=ERROR_FREE_SIGMA, seed=0) if error_free else dict(seed=sc.seed + 1000)
    obs = simulate(eph, t_gnss, lla, vel, tau_gps=0.0, clock_bias=clock[0] + clock[1] * t_gnss[0], clock_drift=clock[1],
                   only=only, outages=outages, **noise)
    tilt, heading = INITIAL_ATTITUDE[sc.imu_class]
    a, g = errors.accel, errors.gyro
    p0 = np.diag(np.r_[[10.0 ** 2] * 3, [0.1 ** 2] * 3, [tilt ** 2, tilt ** 2, heading ** 2],
                       [a.bias_sigma ** 2] * 3, [g.bias_sigma ** 2] * 3])
    # initial error δx ~ N(0, P0) of the navigation states (core: filter/initial_error.rs)
    s0 = traj.initial_state()
    if error_free:
        lla0, vel0, q0 = s0["lla"], s0["vel_ned"], s0["q_nb"]
    else:
        lla0, vel0, q0 = _core.initial_error(np.asarray(s0["lla"], float).tolist(), np.asarray(s0["vel_ned"], float).tolist(),
                                             np.asarray(s0["q_nb"], float).tolist(), p0, rng.standard_normal(9))
    args = dict(t0=s0["t0"], lla0=lla0, vel0=vel0, q0=q0, kind="increments", p0_ins=p0,
                accel_psd=a.white ** 2, gyro_psd=g.white ** 2,
                accel_bias=BiasModel("random_walk", psd=a.bias_rw ** 2), gyro_bias=BiasModel("random_walk", psd=g.bias_rw ** 2),
                predict_every=int(round(sc.rate_hz)), mode=sc.mode, formulation=sc.formulation,
                vertical=sc.vertical, zeta=BARO_ZETA, omega=BARO_OMEGA, baro_psd=BARO_SIGMA ** 2 * 1.0)
    # barometric altimeter at 1 Hz, white error σ 1 m (Demidov 2009, §3), held to the IMU samples
    # (sample k covers (t_k − dt, t_k]: the reading of the second it ends in)
    t_imu = meas["time_s"].to_numpy()
    baro = BARO_SIGMA * rng.standard_normal(int(np.ceil(sc.duration_s)) + 1)
    h_true = np.interp(t_imu, traj.time, traj.lla[:, 2])
    h_ref = h_true if error_free else h_true + baro[np.ceil(np.round(t_imu, 9)).astype(int)]
    return dict(scenario=sc, trajectory=traj, imu=meas, eph=eph, obs=obs, args=args,
                h_ref=h_ref if sc.vertical == "damped" else None)


def errors_and_nees(setup: dict, result) -> pd.DataFrame:
    """Errors of every output epoch and the NEES over the 15 INS states from the reported
    σ: Σ(e_i/σ_i)².

    Parameters
    ----------
    setup : dict
        The dict of :func:`build` (its ``trajectory`` and ``imu``).
    result : atomnav.filter.aided.AidedResult
        The filter's result on that setup.

    Returns
    -------
    pandas.DataFrame
        ``time_s`` (s) and the errors of :meth:`atomnav.trajectory.Trajectory.errors`
        (NED position m, NED velocity m/s, attitude ψ rad), ``nees`` over position,
        velocity, ψ and the accelerometer/gyro bias errors, and ``horizontal_m`` (m).

    Raises
    ------
    TypeError
        When ``setup`` is not the dict of :func:`build`.

    Notes
    -----
    The engine reports σ, not the full covariance, so cross-correlations are ignored
    (the mean is still 15 for a consistent filter; the spread is wider than χ²₁₅).
    """
    if not isinstance(setup, dict) or any(k not in setup for k in ("trajectory", "imu")):
        raise TypeError("setup: expected the dict of build()")
    instance(result, AidedResult, "result")
    traj, meas = setup["trajectory"], setup["imu"]
    nav = result.nav
    err = traj.errors(nav)
    idx = np.clip(np.searchsorted(traj.time[1:], nav["time_s"].to_numpy()), 0, len(meas) - 1)
    truth_ba = meas[imu.BIAS_COLUMNS[0]].to_numpy()[idx]
    truth_bg = meas[imu.BIAS_COLUMNS[1]].to_numpy()[idx]
    eba = nav[[f"accel_bias_{a}_mps2" for a in "xyz"]].to_numpy() - truth_ba
    ebg = nav[[f"gyro_bias_{a}_rad_s" for a in "xyz"]].to_numpy() - truth_bg
    e = np.hstack([err.iloc[:, 1:10].to_numpy(), eba, ebg])
    labels = [c for c in nav.columns if c.startswith("sigma_")][:15]
    err["nees"] = ((e / nav[labels].to_numpy()) ** 2).sum(axis=1)
    err["horizontal_m"] = np.hypot(err["dpos_n_m"], err["dpos_e_m"])
    return err


def run(sc: Scenario | str, progress: bool = False, clock=(0.0, 0.0), **overrides) -> dict:
    """Build and run a scenario.

    Parameters
    ----------
    sc : Scenario or str
        The scenario, or the name of one of :data:`SCENARIOS`.
    progress : bool, default False
        Show a progress bar.
    clock : array_like, shape (2,), default (0, 0)
        True receiver clock (bias s, drift s/s): δt_r(t) = bias + drift·t, t (s) from the
        start of the run (the first GNSS epoch is at 1 s).
    **overrides
        Fields of :class:`Scenario` to replace (e.g. ``seed=3``).

    Returns
    -------
    dict
        ``setup`` (the dict of :func:`build`), ``result`` (the
        :class:`atomnav.filter.aided.AidedResult`) and ``errors`` (the table of
        :func:`errors_and_nees`).
    """
    sc = replace(_scenario(sc), **overrides)
    setup = build(sc, clock)
    ins = tight_ins(setup["eph"], setup["obs"], **setup["args"])
    m = setup["imu"]
    res = ins.run(m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
                  m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy(), h_ref=setup["h_ref"], chunk_s=300.0,
                  progress=progress)
    return dict(setup=setup, result=res, errors=errors_and_nees(setup, res))


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else float("nan")


def _horizontal(err) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and horizontal errors (m) of a table of :func:`errors_and_nees`."""
    t, e = table(err, ("time_s", "horizontal_m"), "err", finite=False).T
    if not len(t):
        raise input_error("err", "no epochs")
    return t, e


def outage_summary(err: pd.DataFrame, start: float, length: float) -> dict:
    """Horizontal error around an outage [start, start + length) s.

    Parameters
    ----------
    err : pandas.DataFrame
        A table of :func:`errors_and_nees` (``time_s`` s, ``horizontal_m`` m).
    start : float
        Start of the outage, s.
    length : float
        Length of the outage, s.

    Returns
    -------
    dict
        Horizontal errors, m: RMS over the 5 min before (``pre``), the error at its end
        (``end``), RMS 60–600 s after reacquisition (``post``) and RMS over 240–300 s after
        it (``at5``, the 5-minute recovery check). An RMS over a window without epochs is
        NaN: the output may be non-finite.

    Raises
    ------
    atomnav.InputError
        Naming ``err`` for a table without those columns or epochs, ``start`` when no
        epoch precedes the end of the outage.
    """
    t, e = _horizontal(err)
    start, length = finite_scalar(start, "start"), finite_scalar(length, "length")
    b = start + length
    if not np.any(t < b):
        raise input_error("start", f"no epoch before the end of the outage at {b} s")
    return dict(pre=_rms(e[(t > start - 300) & (t < start)]), end=float(e[t < b][-1]),
                post=_rms(e[(t > b + 60) & (t < b + 600)]), at5=_rms(e[(t > b + 240) & (t <= b + 300)]))


def last_rms(err: pd.DataFrame, window: float = 600.0) -> float:
    """Horizontal RMS error over the last ``window`` seconds.

    Parameters
    ----------
    err : pandas.DataFrame
        A table of :func:`errors_and_nees` (``time_s`` s, ``horizontal_m`` m).
    window : float, default 600.0
        Length of the final window, s.

    Returns
    -------
    float
        RMS horizontal error, m (NaN when no epoch falls in the window: the output may be
        non-finite).
    """
    t, e = _horizontal(err)
    return _rms(e[t > t.max() - finite_scalar(window, "window")])
