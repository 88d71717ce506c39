"""Initial alignment of a strapdown INS: at rest (Rust core, ``rust/filter/alignment.rs``),
and in motion from GNSS velocity.

:func:`coarse` levels from the mean specific force (roll, pitch) and gyrocompasses from
the mean angular rate (heading) of a static IMU record, and states the accuracy the
sensor's biases and noise allow (Titterton & Weston 2004, *Strapdown Inertial
Navigation Technology*, 2nd ed., §10.3; Groves 2013, *Principles of GNSS, Inertial, and
Multisensor Integrated Navigation Systems*, 2nd ed., §5.6):

- levelling: δroll ≈ b_a,y/g, δpitch ≈ b_a,x/g (the horizontal accelerometer bias in
  the level frame over gravity), plus the white-noise part VRW/(g√T);
- heading: δψ ≈ b_g,E/(Ω cos φ) (the east gyro bias over the horizontal Earth rate),
  plus ARW/(Ω cos φ √T) and the tilt error times tan φ.

:func:`fine` then runs the aided INS of :mod:`atomnav.filter` on a static record from
the coarse attitude with zero-velocity and zero-angular-rate updates (Groves 2013,
§15.3), estimating the attitude and the IMU biases together; its initial covariance keeps
the correlation between the coarse attitude error and the biases that caused it.
:class:`atomnav.filter.ZeroVelocity` and :class:`atomnav.filter.ZeroRate` are these
updates as measurement sources for any aided INS built with
:func:`atomnav.filter.aided_ins`.

:func:`in_motion` is for gyros that cannot find north at rest (MEMS: a gyro bias above
the horizontal Earth rate Ω cos φ ≤ 15 °/h leaves :func:`coarse` a heading of any value;
it does not refuse, and its stated heading σ shows it): it keeps the levelling of
:func:`coarse` alone, takes the heading from the direction of the GNSS velocity once the
vehicle moves faster than a threshold (Groves 2013, §5.6.2), and starts the aided INS
there with that heading's σ in its initial covariance — a coarse-heading step before the
Kalman filter, so the filter's small-angle attitude error model never sees the large
initial heading error (Groves 2013, §14.4.3).

>>> c = coarse(imu, lla, errors="tactical")                  # doctest: +SKIP
>>> print(c)                                                 # attitude and its accuracy
>>> f = fine(later_imu, lla, c)                              # doctest: +SKIP
>>> nav = atomnav.strapdown.integrate(rest_of_imu, **f.state)  # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pandas as pd

from . import _core, earth, plausibility, rotation, units
from ._validate import choice, finite, flag, increasing, input_error, instance, nonnegative, positive, renamed, vector
from .filter.aided import AidedResult, InsSetup, _concat
from .filter.engine import BiasModel
from .filter.sources import PositionFixes, VelocityFixes, ZeroRate, ZeroVelocity, aided_ins
from .imu import KINDS, ImuErrors
from .strapdown import _imu_arrays, _imu_errors
from .trajectory import imu_kind

_ARCMIN = np.pi / (180.0 * 60.0)
#: Most update epochs at which :func:`fine` keeps the filter covariance (spread evenly).
COVARIANCE_EPOCHS = 50
#: Index of the heading error ψ_D (``attitude[2]``) in :data:`atomnav.filter.INS15`.
_HEADING = 8
#: The gyro bias states (``gyro_bias[0..2]``) of :data:`atomnav.filter.INS15`.
_GYRO_BIAS = slice(12, 15)
#: σ of the velocity at the end of the rest (m/s) for carrying the attitude to the
#: heading fix, and of the placeholder heading there (rad), which the fix replaces.
_REST_SIGMA = 0.01
#: Two time stamps within this (s) are the same epoch.
_TIME_TOLERANCE = 1e-6


def _errors(errors) -> ImuErrors:
    """The error model: an :class:`ImuErrors` or the name of a preset."""
    if isinstance(errors, str):
        with renamed(preset="errors"):
            return ImuErrors.preset(errors)
    return instance(errors, ImuErrors, "errors")


def _angle(x: float) -> str:
    """An angle (rad) in degrees, or in arcmin (arcsec) when small."""
    if not np.isfinite(x):
        return "undefined"
    if abs(x) >= np.deg2rad(1.0):
        return f"{np.rad2deg(x):.3f} deg"
    if abs(x) >= _ARCMIN:
        return f"{x / _ARCMIN:.2f} arcmin"
    return f"{x / _ARCMIN * 60.0:.2f} arcsec"


def _attitude_lines(euler, sigma) -> list[str]:
    names = ("roll", "pitch", "yaw (heading)")
    return [f"  {n:<14} {np.rad2deg(e):>11.5f} deg   ± {_angle(s)} (1σ)" for n, e, s in zip(names, euler, sigma)]


def _read(imu, kind: str):
    """(time, gyro, accel) of a static record: a DataFrame by column name, or an (N, 7)
    array in the column order of ``atomnav.trajectory.IMU_COLUMNS[kind]``; warns for
    values in the wrong unit (:mod:`atomnav.plausibility`)."""
    t, g, a = _imu_arrays(imu, kind)
    plausibility.imu(t, g, a, kind)
    return np.ascontiguousarray(t), np.ascontiguousarray(g), np.ascontiguousarray(a)


@dataclass(frozen=True, kw_only=True)
class CoarseAlignment:
    """The result of :func:`coarse`. Angles in rad; ``print`` it for a summary in degrees
    and arcminutes.

    Attributes
    ----------
    t0, time_s : float
        First and last time stamp of the record used (s); the attitude holds at ``time_s``.
    samples : int
        Samples averaged.
    kind : str
        IMU output kind of the record.
    lla : ndarray (3,)
        The site (lat rad, lon rad, h m).
    q_nb : ndarray (4,)
        Attitude, scalar first.
    euler, euler_sigma : ndarray (3,)
        (roll, pitch, yaw) and their σ (rad); roll and yaw σ are inf at pitch ±90°.
    psi_cov, psi_cov_noise : ndarray (3, 3)
        Covariance (rad²) of the attitude error ψ (north, east, down; Ĉ = (I − [ψ×])C): the
        whole, and the part from noise alone — white noise and bias processes with a
        correlation time shorter than the record, which average down over it (the rest is
        from the biases).
    mean_f, mean_w : ndarray (3,)
        Mean specific force (m/s²) and angular rate (rad/s) in the body frame.
    gyro_bias, gyro_bias_cov : ndarray (3,), (3, 3)
        The gyro bias (rad/s, body frame) seen at rest and its covariance (rad²/s²). For
        :func:`level`: the mean angular rate less the vertical Earth rate, with the noise
        of the mean and the horizontal Earth rate of an unknown heading, combined with the
        error model's bias σ (a zero-angular-rate update, Groves 2013, §15.3.3); it is
        the start of :func:`in_motion`'s bias estimate. For :func:`coarse`: zero and the
        error model's bias covariance (the bias and the heading are not separable there).
    gravity, earth_rate_h : float
        Normal gravity (m/s²) and horizontal Earth rate Ω cos φ (rad/s) at the site.
    spread : tuple of float
        Variation of the specific force and angular rate between ten windows of the record,
        in units of what the sensor noise and bias drift explain (a record is static up to
        5).
    errors : ImuErrors
        The sensor error model the accuracy is computed from.
    ellipsoid : str
        Earth model.
    gyrocompassed : bool
        True for :func:`coarse` (heading from the Earth rate); False for :func:`level`
        (yaw 0, heading not determined).
    """

    t0: float
    time_s: float
    samples: int
    kind: str
    lla: np.ndarray
    q_nb: np.ndarray
    euler: np.ndarray
    euler_sigma: np.ndarray
    psi_cov: np.ndarray
    psi_cov_noise: np.ndarray
    mean_f: np.ndarray
    mean_w: np.ndarray
    gyro_bias: np.ndarray
    gyro_bias_cov: np.ndarray
    gravity: float
    earth_rate_h: float
    spread: tuple
    errors: ImuErrors
    ellipsoid: str
    gyrocompassed: bool = True

    @property
    def state(self) -> dict:
        """The initial state at ``time_s`` as keyword arguments of
        :func:`atomnav.strapdown.integrate` (at rest: zero velocity)."""
        return {"t0": self.time_s, "lla": self.lla.copy(), "vel_ned": np.zeros(3), "q_nb": self.q_nb.copy()}

    def __str__(self) -> str:
        bias = np.sqrt(np.clip(np.diag(self.psi_cov - self.psi_cov_noise), 0.0, None))
        noise = np.sqrt(np.diag(self.psi_cov_noise))
        lat, lon = np.rad2deg(self.lla[:2])
        lines = [
            f"{'Coarse alignment' if self.gyrocompassed else 'Levelling'}: {self.time_s - self.t0:.1f} s at rest, "
            f"{self.samples} samples ({self.kind}), at {lat:.4f}° {lon:.4f}°, {self.lla[2]:.1f} m",
            *_attitude_lines(self.euler, self.euler_sigma),
            "  attainable accuracy (1σ), from the sensor biases | noise (white and faster than the record):",
            f"    levelling north/east  {_angle(bias[0])}, {_angle(bias[1])} | {_angle(noise[0])}, {_angle(noise[1])}"
            f"   (accel bias / g = {self.gravity:.4f} m/s²)",
        ]
        if self.gyrocompassed:
            lines += [f"    heading               {_angle(bias[2])} | {_angle(noise[2])}"
                      f"   (gyro bias / Ω cos φ = {self.earth_rate_h / units.DEG_PER_HOUR:.3f} °/h)",
                      f"  static test: spread {self.spread[0]:.2f} (specific force), {self.spread[1]:.2f} (angular rate); limit 5"]
        else:
            lines += ["    heading               not determined (levelling only: take it from elsewhere, e.g. in_motion)"]
        return "\n".join(lines)

    def _repr_pretty_(self, p, cycle) -> None:
        p.text(str(self))


def coarse(imu, lla, *, errors, kind: str | None = None, ellipsoid: str = "WGS84") -> CoarseAlignment:
    """Static coarse alignment: levelling and gyrocompassing from the record's means.

    Parameters
    ----------
    imu : DataFrame or array (N, 7)
        A record at rest: time (s), gyro and accel of ``kind``; a DataFrame is read by
        column name (``atomnav.trajectory.IMU_COLUMNS[kind]``, any order, extra columns
        ignored), a plain array only in that column order. With increments the first row
        is left out (its interval starts before the record).
    lla : array (3,)
        The site: latitude (rad), longitude (rad), height (m).
    errors : ImuErrors or str
        The sensor error model (or a preset name, ``atomnav.imu.preset_names()``): its
        biases and noise give the attainable accuracy and the noise level of the static
        test.
    kind : str, optional
        ``"rates"`` (rad/s, m/s²) or ``"increments"`` (rad, m/s); None (default): the kind
        of the table's column names (:func:`atomnav.trajectory.imu_kind`), required for a
        plain array.
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]``.

    Returns
    -------
    CoarseAlignment
        The attitude at the end of the record, its σ, and ``state`` for
        :func:`atomnav.strapdown.integrate`.

    Raises
    ------
    InputError
        Naming ``imu``: a non-finite row or a time stamp out of order (the row in
        ``.index``, the column in the message), fewer than 100 samples, a record that is
        not static (its specific force or rate varies between ten windows more than five
        times what the noise and bias drift of ``errors`` explain), or a mean specific
        force that is not gravity (accelerations in g, increments read as rates).
        Naming ``lla``: a latitude beyond ±89°, where the horizontal Earth rate is too
        small to find north. Naming ``kind``: an unknown kind.
    TypeError
        For a column that does not hold numbers, or ``errors`` of another type.
    """
    return _align(True, imu, lla, errors, kind, ellipsoid)


def level(imu, lla, *, errors, kind: str | None = None, ellipsoid: str = "WGS84") -> CoarseAlignment:
    """Levelling alone: roll and pitch from the mean specific force of a record held still,
    for any gyro and at any latitude, when the heading comes from elsewhere
    (:func:`in_motion`: the GNSS track).

    :func:`coarse` also gyrocompasses, which needs a record static to within the sensor
    noise; a device held by hand, or a vehicle at a stop with its engine running, moves
    more than that. Levelling needs only that the mean specific force is gravity: the
    record's ten window means may scatter up to 0.25 m/s² per axis (the accelerometer
    threshold of a zero-velocity detector, Skog et al. 2010), and their measured scatter
    is added to the stated tilt σ (Titterton & Weston 2004, §10.3: a horizontal specific
    force error δf tilts the levelled frame by δf/g).

    Parameters
    ----------
    imu : DataFrame or array (N, 7)
        A record held still, as for :func:`coarse`.
    lla : array (3,)
        The site: latitude (rad), longitude (rad), height (m).
    errors : ImuErrors or str
        The sensor error model (or a preset name): its accelerometer bias and noise give
        the tilt accuracy.
    kind : str, optional
        ``"rates"`` or ``"increments"``; None (default): the kind of the table's columns.
    ellipsoid : str
        Earth model, one of ``atomnav._core.OPTIONS["Ellipsoid"]``.

    Returns
    -------
    CoarseAlignment
        Roll and pitch with their σ; yaw 0 (the body x axis's horizontal projection taken
        as north) with σ π/√3 (rad), a heading uniform over ±180°: not determined.

    Raises
    ------
    InputError
        Naming ``imu``: a bad row, fewer than 100 samples, window means that scatter by
        more than 0.25 m/s², a mean specific force that is not gravity, or a body x axis
        that is vertical (no yaw reference). Naming ``kind``: an unknown kind.
    TypeError
        For a column that does not hold numbers, or ``errors`` of another type.
    """
    return _align(False, imu, lla, errors, kind, ellipsoid)


def _align(gyrocompassed: bool, imu, lla, errors, kind, ellipsoid) -> CoarseAlignment:
    """The coarse alignment of ``imu``, or its levelling alone (``gyrocompassed`` False)."""
    kind = choice(imu_kind(kind, imu, "imu"), KINDS, "kind")
    model = _errors(errors)
    site = vector(lla, 3, "lla")
    plausibility.lla(site, "lla")
    t, g, a = _read(imu, kind)
    with _imu_errors(kind, g, a, 0):
        d = _core.coarse_alignment(t, g, a, kind, site, *model._to_core(), ellipsoid=ellipsoid, gyrocompass=gyrocompassed)
    arr = {k: np.asarray(d[k], dtype=float) for k in ("q_nb", "euler", "euler_sigma", "psi_cov", "psi_cov_noise", "mean_f", "mean_w",
                                                      "gyro_bias", "gyro_bias_cov")}
    return CoarseAlignment(t0=d["t0"], time_s=d["t1"], samples=d["samples"], kind=kind, lla=site, gravity=d["gravity"],
                           earth_rate_h=d["earth_rate_h"], spread=tuple(d["spread"]), errors=model, ellipsoid=ellipsoid,
                           gyrocompassed=gyrocompassed, **arr)


@dataclass(frozen=True, kw_only=True)
class FineAlignment:
    """The result of :func:`fine`. Angles in rad; ``print`` it for a summary.

    Attributes
    ----------
    state : dict
        The aligned state at the end of the record (``t0``, ``lla``, ``vel_ned``, ``q_nb``):
        keyword arguments of :func:`atomnav.strapdown.integrate`.
    euler, euler_sigma : ndarray (3,)
        (roll, pitch, yaw) at the end and their σ (rad).
    psi_cov : ndarray (3, 3)
        Covariance (rad²) of the attitude error ψ (north, east, down) at the end.
    accel_bias, gyro_bias : ndarray (3,)
        Bias estimates (m/s², rad/s) at the end: ``ba0``/``bg0`` of an aided INS that
        continues from here.
    accel_bias_sigma, gyro_bias_sigma : ndarray (3,)
        σ of ``accel_bias`` (m/s²) and ``gyro_bias`` (rad/s) at the end.
    covariance_time : ndarray (M,)
        Times (s) of the zero-motion updates at which the covariance is kept: at most
        :data:`COVARIANCE_EPOCHS`, spread evenly, the last one included.
    covariance : ndarray (M, 15, 15)
        The filter's covariance after each of these updates, in the order of ``labels``.
    labels : list of str
        The state components, e.g. ``attitude[2]``.
    result : AidedResult
        The whole filter output (navigation, bias estimates and σ per epoch; NIS per update).
    coarse : CoarseAlignment
        The alignment it started from.
    """

    state: dict
    euler: np.ndarray
    euler_sigma: np.ndarray
    psi_cov: np.ndarray
    accel_bias: np.ndarray
    gyro_bias: np.ndarray
    accel_bias_sigma: np.ndarray
    gyro_bias_sigma: np.ndarray
    covariance_time: np.ndarray
    covariance: np.ndarray
    labels: list
    result: AidedResult
    coarse: CoarseAlignment

    def __str__(self) -> str:
        return "\n".join([
            f"Fine alignment: {len(self.result.measurements)} zero-motion measurements; attitude at {self.state['t0']:.3f} s",
            *_attitude_lines(self.euler, self.euler_sigma),
            "  accel bias (µg)  " + ", ".join(f"{b / units.MICRO_G:.1f} ± {s / units.MICRO_G:.1f}" for b, s in zip(self.accel_bias, self.accel_bias_sigma)),
            "  gyro bias (°/h)  " + ", ".join(f"{b / units.DEG_PER_HOUR:.3f} ± {s / units.DEG_PER_HOUR:.3f}" for b, s in zip(self.gyro_bias, self.gyro_bias_sigma)),
        ])

    def _repr_pretty_(self, p, cycle) -> None:
        p.text(str(self))


def _setup(level: CoarseAlignment, model: ImuErrors, q_imu, *, t0: float, lla, horizon: float, step: float,
           predict_s: float, pos_sigma: float, vel_sigma: float, mount=None) -> InsSetup:
    """The aided INS at rest at ``t0`` after the levelling (and gyrocompassing) ``level``
    of an IMU with attitude ``q_imu`` (C_imu^n) mounted as ``mount`` (C_imu^b,
    ``docs/mounting.md``; None: the IMU axes are the body axes): the body attitude
    C_imu^n (C_imu^b)ᵀ; an initial covariance that keeps the correlation of the attitude
    error with the biases that caused it (``rust/filter/alignment.rs``, ``fine_p0``, in the
    IMU axes, then turned to the body axes of the bias states); and the process noise of
    ``model`` over ``horizon`` s."""
    with renamed(lla0="lla"):  # the core checks the state and the mount before they are used
        setup = InsSetup(t0=t0, lla0=lla, vel0=(0.0, 0.0, 0.0), q0=q_imu, kind=level.kind, p0=np.eye(15), accel_psd=0.0,
                         gyro_psd=0.0, predict_every=max(1, int(round(predict_s / step))), ellipsoid=level.ellipsoid,
                         mount=mount)
    c_ib = _mount_of(setup)
    accel_errors, gyro_errors = model._to_core()
    p0, (accel_psd, accel_walk, gyro_psd, gyro_walk) = _core.fine_alignment_p0(
        lla, np.asarray(setup.q0), psi_cov_noise=level.psi_cov_noise, mean_f=level.mean_f, mean_w=level.mean_w,
        gravity=level.gravity, horizon=horizon, accel_errors=accel_errors, gyro_errors=gyro_errors,
        pos_sigma=pos_sigma, vel_sigma=vel_sigma, ellipsoid=level.ellipsoid)
    turn = np.eye(15)
    turn[9:12, 9:12] = c_ib  # the bias states (INS15 order) in body axes: δb_b = C_imu^b δb_imu
    turn[12:15, 12:15] = c_ib
    q_nb = setup.q0 if setup.mount is None else rotation.quat_from_dcm(rotation.dcm_from_quat(setup.q0) @ c_ib.T)
    return dataclasses.replace(setup, q0=q_nb, p0=turn @ p0 @ turn.T, accel_psd=accel_psd, gyro_psd=gyro_psd,
                               accel_bias=BiasModel(kind="random_walk", psd=accel_walk),
                               gyro_bias=BiasModel(kind="random_walk", psd=gyro_walk))


def _mount_of(setup: InsSetup) -> np.ndarray:
    """The IMU mount C_imu^b of ``setup`` (3, 3); the identity without one."""
    return np.eye(3) if setup.mount is None else np.array(setup.mount)


def fine(imu, lla, coarse: CoarseAlignment, *, errors=None, interval: float = 1.0, zupt_sigma: float = 0.01,
         rate_updates: bool = True, rate_sigma: float = 0.0, pos_sigma: float = 1.0, vel_sigma: float = 0.01,
         predict_s: float = 0.1) -> FineAlignment:
    """Fine alignment: the aided INS on a static record with zero-velocity and
    zero-angular-rate updates, from the coarse attitude.

    Best on the part of the record after the one ``coarse`` used: its noise is then
    independent of the coarse attitude error, as the filter assumes. The filter's
    attitude error model is small-angle: with a heading error of several degrees (a
    tactical-grade gyro at mid latitudes leaves 5–15°) its stated heading σ is
    optimistic (by up to a factor of two for a tactical-grade IMU simulated at 56°N).

    Parameters
    ----------
    imu : DataFrame or array (N, 7)
        A record at rest, of the kind of ``coarse`` (read as by :func:`coarse`). The filter
        starts at its first sample (rates) or one sample interval before its first row
        (increments, read as evenly sampled there).
    lla : array (3,)
        The site (lat rad, lon rad, h m).
    coarse : CoarseAlignment
        The starting attitude and the correlation of its error with the biases.
    errors : ImuErrors or str, optional
        The sensor error model of the filter; by default the one ``coarse`` used.
    interval : float
        Time between updates (s).
    zupt_sigma : float
        σ of the zero-velocity measurement (m/s).
    rate_updates : bool
        Apply zero-angular-rate updates at the same epochs.
    rate_sigma : float
        Motion allowance of the zero-rate update (rad/s) on top of the gyro noise.
    pos_sigma, vel_sigma : float
        Initial σ of the position (m) and velocity (m/s).
    predict_s : float
        Time between filter predictions (s; at least one IMU step).

    Returns
    -------
    FineAlignment
        The aligned state, the attitude and bias estimates with σ, and the filter output.

    Raises
    ------
    InputError
        Naming ``imu`` for a bad row (``.index``), or fewer than two samples; naming
        ``interval`` when no update falls inside the record; naming the option for a
        value out of range.
    """
    instance(coarse, CoarseAlignment, "coarse")
    model = coarse.errors if errors is None else _errors(errors)
    site = vector(lla, 3, "lla")
    plausibility.lla(site, "lla")
    interval, zupt_sigma, predict_s = positive(interval, "interval"), positive(zupt_sigma, "zupt_sigma"), positive(predict_s, "predict_s")
    rate_updates = flag(rate_updates, "rate_updates")
    kind = coarse.kind
    t, g, a = _read(imu, kind)
    if len(t) < 2:
        raise input_error("imu", f"need >= 2 samples, got {len(t)}")
    finite(t[:2], "imu")
    step = t[1] - t[0]
    t0 = t[0] if kind == "rates" else t[0] - step
    span = t[-1] - t0
    if not span > 0:
        raise input_error("imu", f"the record must move forward in time: {t[0]} s to {t[-1]} s")
    times = t0 + interval * np.arange(1, int(np.floor(span / interval * (1 + 1e-12))) + 1)
    if not len(times):
        raise input_error("interval", f"{interval} s leaves no update inside the record of {span:g} s")
    setup = _setup(coarse, model, coarse.q_nb, t0=t0, lla=site, horizon=span, step=step, predict_s=predict_s,
                   pos_sigma=positive(pos_sigma, "pos_sigma"), vel_sigma=positive(vel_sigma, "vel_sigma"))
    sources = [ZeroVelocity(times, zupt_sigma)] + ([ZeroRate(times, setup.gyro_psd, rate_sigma)] if rate_updates else [])
    ins = aided_ins(setup, sources)
    # feed the record up to the updates where the covariance is kept, reading it after each
    kept = np.unique(np.linspace(0, len(times) - 1, min(len(times), COVARIANCE_EPOCHS)).round().astype(int))
    ends = np.searchsorted(t, times[kept], side="left") + 1
    parts, cov = [], []
    lo = 0
    with _imu_errors(kind, g, a, 0):
        for hi in ends:
            parts.append(ins.process(t[lo:hi], g[lo:hi], a[lo:hi]))
            cov.append(ins._core.covariance)
            lo = hi
        parts.append(ins.process(t[lo:], g[lo:], a[lo:]))
        parts.append(ins.finish())
    result = _concat(parts)
    cov = np.asarray(cov)
    labels = ins.labels
    last = result.nav.iloc[-1]
    q = last[["qw", "qx", "qy", "qz"]].to_numpy(dtype=float)
    euler = last[["roll_rad", "pitch_rad", "yaw_rad"]].to_numpy(dtype=float)
    att = [labels.index(f"attitude[{i}]") for i in range(3)]
    psi_cov = ins._core.covariance[np.ix_(att, att)]

    def sigma(block: str) -> np.ndarray:
        return np.array([last[f"sigma_{block}[{i}]"] for i in range(3)])

    return FineAlignment(
        state={"t0": float(last["time_s"]), "lla": last[["lat_rad", "lon_rad", "h_m"]].to_numpy(dtype=float),
               "vel_ned": last[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(dtype=float), "q_nb": q},
        euler=euler, euler_sigma=np.asarray(_core.alignment_euler_sigma(euler, np.ascontiguousarray(psi_cov))), psi_cov=psi_cov,
        accel_bias=last[[f"accel_bias_{x}_mps2" for x in "xyz"]].to_numpy(dtype=float),
        gyro_bias=last[[f"gyro_bias_{x}_rad_s" for x in "xyz"]].to_numpy(dtype=float),
        accel_bias_sigma=sigma("accel_bias"), gyro_bias_sigma=sigma("gyro_bias"),
        covariance_time=times[kept], covariance=cov, labels=labels, result=result, coarse=coarse)


@dataclass(frozen=True, kw_only=True)
class MotionAlignment:
    """The result of :func:`in_motion`: the start of an aided INS at the first GNSS
    velocity fix fast enough to give the heading. Angles in rad; ``print`` it for a
    summary.

    Attributes
    ----------
    t0 : float
        The IMU time stamp at that fix, or the last one before it (s): the aided INS
        starts here.
    fix_time : float
        Time of the heading fix (s) in the IMU's clock (its stamp plus the fixes'
        ``time_offset``); the fixes up to it are in the start state (:meth:`later` leaves
        them out).
    lla : ndarray (3,)
        Position of the IMU at ``t0``: latitude (rad), longitude (rad), height (m).
    vel_ned : ndarray (3,)
        NED velocity of the IMU at ``t0`` (m/s): the velocity fix, less its lever-arm term.
    q_nb : ndarray (4,)
        Body attitude at ``t0``, scalar first: roll and pitch levelled at rest and carried
        to ``t0`` by the gyros, yaw along the track.
    euler, euler_sigma : ndarray (3,)
        (roll, pitch, yaw) at ``t0`` and their σ (rad).
    speed : float
        Horizontal speed of the fix (m/s).
    heading_sigma : float
        σ of the heading from the velocity fix alone (rad): the cross-track velocity σ over
        ``speed``; ``euler_sigma[2]`` adds ``slip_sigma``.
    p0 : ndarray (15, 15)
        Initial covariance in the order of :data:`atomnav.filter.INS15` (m, m/s, rad,
        m/s², rad/s).
    psi_cov : ndarray (3, 3)
        Its attitude block: covariance (rad²) of the attitude error ψ (north, east, down;
        Ĉ = (I − [ψ×])C).
    setup : InsSetup
        The aided INS from this state (``p0``, the process noise of the IMU error model),
        for :func:`atomnav.filter.aided_ins` with the fixes after the heading fix
        (:meth:`later`) and the IMU record from ``t0`` (:meth:`after`); change a field
        with :func:`dataclasses.replace`.
    level : CoarseAlignment
        The levelling at rest it started from (its heading is not used).
    """

    t0: float
    fix_time: float
    lla: np.ndarray
    vel_ned: np.ndarray
    q_nb: np.ndarray
    euler: np.ndarray
    euler_sigma: np.ndarray
    speed: float
    heading_sigma: float
    p0: np.ndarray
    psi_cov: np.ndarray
    setup: InsSetup
    level: CoarseAlignment

    @property
    def state(self) -> dict:
        """The start state as keyword arguments of :func:`atomnav.strapdown.integrate`."""
        return {"t0": self.t0, "lla": self.lla.copy(), "vel_ned": self.vel_ned.copy(), "q_nb": self.q_nb.copy()}

    def after(self, imu) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The part of an IMU record the aided INS of :attr:`setup` takes: the rows after
        ``t0`` (increments, whose first interval then starts at ``t0``), or from ``t0`` on
        (rates).

        Parameters
        ----------
        imu : DataFrame or array (N, 7)
            The record, of the kind of the levelling (read as by :func:`coarse`).

        Returns
        -------
        time, gyro, accel : ndarray (M,), (M, 3), (M, 3)
            Those rows, as ``run`` and ``process`` of the aided INS take them.

        Warns
        -----
        atomnav.UnitWarning
            Naming ``imu``: time stamps, rates or specific forces likely in another unit.
        """
        t, g, a = _read(imu, self.level.kind)
        first = _first_row(t, self.t0, self.level.kind)
        return t[first:], g[first:], a[first:]

    def later(self, fixes):
        """The fixes after the heading fix, for the aided INS of :attr:`setup` (those up
        to it are in the start state: used again, they would count twice).

        Parameters
        ----------
        fixes : PositionFixes or VelocityFixes
            The GNSS fixes.

        Returns
        -------
        PositionFixes or VelocityFixes
            A copy with the later fixes.
        """
        instance(fixes, (PositionFixes, VelocityFixes), "fixes")
        return fixes.select(_imu_clock(fixes) > self.fix_time + _TIME_TOLERANCE)

    def __str__(self) -> str:
        lat, lon = np.rad2deg(self.lla[:2])
        return "\n".join([
            f"Alignment in motion: heading from the GNSS velocity at {self.t0:.3f} s ({self.speed:.2f} m/s), "
            f"levelled at rest until {self.level.time_s:.3f} s; at {lat:.6f}° {lon:.6f}°, {self.lla[2]:.1f} m",
            *_attitude_lines(self.euler, self.euler_sigma),
        ])

    def _repr_pretty_(self, p, cycle) -> None:
        p.text(str(self))


def _heading(vel: np.ndarray) -> tuple[float, np.ndarray]:
    """Track angle atan2(v_E, v_N) (rad) of a NED velocity and its gradient
    (−v_E, v_N, 0)/s² with respect to the velocity (s the horizontal speed)."""
    vn, ve = vel[0], vel[1]
    s2 = vn * vn + ve * ve
    return float(np.arctan2(ve, vn)), np.array([-ve / s2, vn / s2, 0.0])


def _imu_clock(fixes) -> np.ndarray:
    """Times (s) of GNSS fixes in the IMU's clock: stamp + ``time_offset``
    (``docs/mounting.md``)."""
    return fixes.time + fixes.time_offset


def _lever_velocity(fixes, c_bn: np.ndarray, body_rate: np.ndarray) -> np.ndarray:
    """The velocity (m/s, NED) of the point at ``fixes.lever_arm`` relative to the IMU,
    C_b^n (ω_ib^b × l), for the body rate ``body_rate`` (rad/s; the Earth-rate term, below
    1e-4 m/s per metre of lever arm, is left out)."""
    if fixes.lever_arm is None:
        return np.zeros(3)
    return c_bn @ np.cross(body_rate, np.asarray(fixes.lever_arm))


def _first_row(t: np.ndarray, t0: float, kind: str) -> int:
    """The first row of an IMU record (times ``t``, s) that an INS starting at ``t0`` takes:
    the first after ``t0`` (increments: its interval starts at ``t0``), or the first from
    ``t0`` on (rates)."""
    return int(np.searchsorted(t, t0, side="right" if kind == "increments" else "left"))


def _predict(setup: InsSetup, t, g, a, end: int) -> tuple[pd.Series, np.ndarray]:
    """Run the free inertial solution of ``setup`` (no aiding) over the IMU rows before
    ``end``; the last navigation row and the covariance there."""
    ins = aided_ins(setup, [])
    first = _first_row(t, setup.t0, setup.kind)
    with _imu_errors(setup.kind, g, a, 0):
        res = _concat([ins.process(t[first:end], g[first:end], a[first:end]), ins.finish()])
    return res.nav.iloc[-1], ins._core.covariance


def in_motion(imu, position, velocity, level: CoarseAlignment, *, mount=None, speed: float = 1.0,
              slip_sigma: float = np.deg2rad(1.0), errors=None, predict_s: float = 0.1) -> MotionAlignment:
    """Alignment in motion: levelling at rest, heading from the GNSS velocity once the
    vehicle moves, then the aided INS from that epoch.

    For an IMU whose gyros cannot find north at rest (a MEMS gyro's bias exceeds the
    horizontal Earth rate of at most 15 °/h), heading comes from the direction of travel
    (Groves 2013, §5.6.2; a coarse-heading step before the Kalman filter, one of the
    remedies for large heading errors of §14.4.3):

    1. Levelling: roll and pitch from the mean specific force at rest, the levelling of
       :func:`coarse` (its gyrocompassed heading is not used, whatever the gyro), and
       the gyro bias the rest saw (:attr:`CoarseAlignment.gyro_bias`: the mean angular
       rate less the Earth rate, a zero-angular-rate update; zero after :func:`coarse`).
    2. Carrying: the free inertial solution, corrected by that bias, from the end of the
       rest to the first velocity fix whose horizontal speed exceeds ``speed``, which
       carries roll and pitch (and their error, growing with the gyro noise and the
       bias's remaining error) to that fix.
    3. Heading: the yaw is set to the track angle atan2(v_E, v_N) of that fix, with
       σ² = (v_N² σ_E² + v_E² σ_N² − 2 v_N v_E σ_NE)/s⁴ (the cross-track velocity σ over the
       horizontal speed s), plus ``slip_sigma``².
    4. The start: position (the last position fix up to then, moved by the fix velocity
       to the fix time) and velocity (the fix) with their covariances, the attitude error
       covariance of the levelling carried to the fix, the heading σ, and the
       correlation of the heading error with the velocity error of the same fix.

    The fixes' lever arms and time offsets are applied as the aided INS applies them
    (``docs/mounting.md``): the heading is the track of the IMU's velocity, the antenna's
    less C_b^n (ω × l) at the last IMU sample, and the position the antenna's less C_b^n l.
    It assumes the body x axis points along the track at that fix: forward motion of a
    vehicle without side slip, or a walker holding the IMU pointing ahead. Otherwise the
    heading is off by the angle between them (180° when reversing, 90° for an IMU whose
    x axis points sideways and no ``mount`` says so): give the mount, and ``slip_sigma``
    for the angle that remains.

    Parameters
    ----------
    imu : DataFrame or array (N, 7)
        The IMU record of the kind of ``level``, covering the rest that ``level`` used and
        the motion after it up to the heading fix (read as by :func:`coarse`; it may go
        on beyond).
    position : PositionFixes
        GNSS position fixes (rad, rad, m) with NED covariances (m²).
    velocity : VelocityFixes
        GNSS NED velocity fixes (m/s) with covariances (m²/s²).
    level : CoarseAlignment
        The levelling at rest: :func:`coarse` on the part of ``imu`` at rest (any gyro
        grade; a site within 1° of a pole, where :func:`coarse` refuses to gyrocompass, is
        refused), whatever heading it found, in the IMU's axes. Its static test holds a
        hand-held device to the sensor noise: give it a few quiet seconds (on a recorded
        walk, 3 s of the 10 s the walker stood still passed).
    mount : array_like (3, 3) or (3,), optional
        The IMU mount C_imu^b from the IMU's axes to the body axes, a DCM or (roll, pitch,
        yaw) in rad (``docs/mounting.md``); None (default): the IMU's axes are the body's.
        It goes into :attr:`MotionAlignment.setup`.
    speed : float
        Horizontal speed (m/s) above which a velocity fix gives the heading; default 1 m/s.
    slip_sigma : float
        σ of the angle between the body x axis and the track at that fix (rad): side slip,
        a crab angle, a walker's sway; default 1°, a vehicle driving straight.
    errors : ImuErrors or str, optional
        The sensor error model of the filter; by default the one ``level`` used.
    predict_s : float
        Time between filter predictions (s; at least one IMU step).

    Returns
    -------
    MotionAlignment
        The start state at the heading fix, its covariance, and an :class:`InsSetup` of
        the aided INS from there.

    Raises
    ------
    InputError
        Naming ``mount`` for a matrix that is no rotation; ``speed`` or ``slip_sigma`` out
        of range (``speed`` ≤ 0, ``slip_sigma`` < 0); ``velocity`` when no fix after the
        rest is faster than ``speed``; ``position`` when it has no fix up to that one;
        ``imu`` for a bad row (``.index``) or a record that does not span the end of the
        rest to the heading fix.
    TypeError
        For ``position``, ``velocity`` or ``level`` of another type.

    Examples
    --------
    >>> level = coarse(imu_at_rest, lla, errors="mems")          # doctest: +SKIP
    >>> a = in_motion(imu, position, velocity, level, mount=(np.pi, 0.0, -np.pi / 2))  # doctest: +SKIP
    >>> ins = aided_ins(a.setup, [a.later(position), a.later(velocity)])  # doctest: +SKIP
    >>> result = ins.run(*a.after(imu))                          # doctest: +SKIP
    """
    instance(position, PositionFixes, "position")
    instance(velocity, VelocityFixes, "velocity")
    instance(level, CoarseAlignment, "level")
    speed, predict_s = positive(speed, "speed"), positive(predict_s, "predict_s")
    slip_sigma = nonnegative(slip_sigma, "slip_sigma")
    model = level.errors if errors is None else _errors(errors)
    v_time, p_time = _imu_clock(velocity), _imu_clock(position)
    horizontal = np.hypot(velocity.value[:, 0], velocity.value[:, 1])
    fast = np.nonzero((v_time > level.time_s) & (horizontal > speed))[0]
    if not fast.size:
        later = horizontal[v_time > level.time_s]
        raise input_error("velocity", f"no fix after the rest (which ends at {level.time_s:g} s) is faster than speed={speed:g} m/s "
                                      f"horizontally (the fastest: {later.max() if later.size else 0.0:g} m/s), so the track gives no heading")
    j = fast[0]
    t_h, vel_cov = float(v_time[j]), velocity.cov[j]
    t, g, a = _read(imu, level.kind)
    finite(t, "imu")
    increasing(t, "imu", "time")
    if not len(t) or t[-1] < t_h - _TIME_TOLERANCE:
        raise input_error("imu", f"the record ends {f'at {t[-1]:g} s' if len(t) else 'empty'}, before the heading fix at {t_h:g} s")
    if t[0] > level.time_s + _TIME_TOLERANCE:
        raise input_error("imu", f"the record starts at {t[0]:g} s, after the end of the rest at {level.time_s:g} s")
    end = int(np.searchsorted(t, t_h + _TIME_TOLERANCE, side="right"))
    finite(np.column_stack([g[:end], a[:end]]), "imu")  # the rows carried (the core would count from the rest)
    t0 = float(t[end - 1])  # the IMU stamp at the fix, or the last one before it
    horizon = max(float(t[-1] - level.time_s), t0 - level.time_s)
    step = (t[-1] - t[0]) / max(len(t) - 1, 1)

    def carry(turn: float) -> tuple[InsSetup, pd.Series, np.ndarray]:
        """The free inertial solution from the end of the rest, with the levelled attitude
        turned there by ``turn`` (rad) about the down axis."""
        q_turn = np.array([np.cos(turn / 2), 0.0, 0.0, np.sin(turn / 2)])
        setup = _setup(level, model, rotation.quat_multiply(q_turn, level.q_nb), t0=level.time_s, lla=level.lla,
                       horizon=horizon, step=step, predict_s=predict_s, pos_sigma=1.0, vel_sigma=_REST_SIGMA, mount=mount)
        p = np.array(setup.p0)
        p[_HEADING, :], p[:, _HEADING] = 0.0, 0.0  # the heading at rest is not known: set at the fix
        p[_HEADING, _HEADING] = _REST_SIGMA ** 2
        # the gyro bias the rest saw (the levelled tilt does not depend on it), in body axes
        c_ib = _mount_of(setup)
        p[_GYRO_BIAS, :], p[:, _GYRO_BIAS] = 0.0, 0.0
        p[_GYRO_BIAS, _GYRO_BIAS] = c_ib @ level.gyro_bias_cov @ c_ib.T
        setup = dataclasses.replace(setup, bg0=c_ib @ level.gyro_bias)
        return (setup, *_predict(dataclasses.replace(setup, p0=p), t, g, a, end))

    def track_at(roll: float, pitch: float, yaw: float) -> tuple[np.ndarray, float, np.ndarray]:
        """The IMU's velocity at the fix (the antenna's less the lever-arm term at this
        attitude), its track angle and the gradient of that angle."""
        v = velocity.value[j] - _lever_velocity(velocity, rotation.dcm_from_euler([roll, pitch, yaw]), body_rate)
        return (v, *_heading(v))

    # carry the levelled attitude to the fix; turn it at rest by the difference of its yaw
    # there to the track, and carry it again, so its error is propagated in the right axes
    setup, last, _ = carry(0.0)
    body_rate = _mount_of(setup) @ (g[end - 1] if level.kind == "rates" else g[end - 1] / step)
    _, track, _ = track_at(last["roll_rad"], last["pitch_rad"], last["yaw_rad"])
    setup, last, cov = carry(np.angle(np.exp(1j * (track - last["yaw_rad"]))))
    vel, track, grad = track_at(last["roll_rad"], last["pitch_rad"], track)
    euler = np.array([last["roll_rad"], last["pitch_rad"], track])
    q0 = rotation.quat_from_euler(euler)
    c_bn = rotation.dcm_from_quat(q0)
    # the start: fixes for position and velocity (moved from the antenna to the IMU), the
    # carried tilt, the track heading
    k = int(np.searchsorted(p_time, t_h + _TIME_TOLERANCE, side="right")) - 1
    if k < 0:
        raise input_error("position", f"no fix at or before the heading fix at {t_h:g} s (the first at {p_time[0]:g} s)")
    dt = t0 - p_time[k]
    arm = np.zeros(3) if position.lever_arm is None else c_bn @ np.asarray(position.lever_arm)
    lla = earth.ecef_to_lla(earth.ned_to_ecef(vel * dt - arm, position.value[k], level.ellipsoid), level.ellipsoid).reshape(3)
    pos, vel_block, att = (slice(3 * i, 3 * i + 3) for i in range(3))
    cov[pos, :], cov[:, pos], cov[vel_block, :], cov[:, vel_block] = 0.0, 0.0, 0.0, 0.0
    cov[_HEADING, :], cov[:, _HEADING] = 0.0, 0.0
    cov[pos, pos] = position.cov[k] + dt * dt * vel_cov
    cov[vel_block, vel_block] = vel_cov
    heading_var = float(grad @ vel_cov @ grad)
    cov[_HEADING, _HEADING] = heading_var + slip_sigma ** 2
    cov[_HEADING, vel_block] = -grad @ vel_cov  # ψ_D = −δyaw, δyaw = ∇yaw · δv
    cov[vel_block, _HEADING] = cov[_HEADING, vel_block]
    # the position error from the lever arm turned by the attitude error: p = p_fix − Ĉ l,
    # so δp = n_p − [(C l)×] ψ (to first order)
    lever = np.eye(len(cov))
    lever[pos, att] = -rotation.skew(arm)
    cov = lever @ cov @ lever.T
    psi_cov = cov[att, att].copy()
    with renamed(lla0="position"):
        start = dataclasses.replace(setup, t0=t0, lla0=lla, vel0=vel, q0=q0, p0=cov)
    return MotionAlignment(t0=t0, fix_time=t_h, lla=lla, vel_ned=vel, q_nb=q0, euler=euler,
                           euler_sigma=np.asarray(_core.alignment_euler_sigma(euler, np.ascontiguousarray(psi_cov))),
                           speed=float(horizontal[j]), heading_sigma=float(np.sqrt(heading_var)), p0=cov, psi_cov=psi_cov,
                           setup=start, level=level)
