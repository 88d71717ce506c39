"""Initial alignment of a strapdown INS at rest (Rust core, ``rust/filter/alignment.rs``).

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

>>> c = coarse(imu, lla, errors="tactical")                  # doctest: +SKIP
>>> print(c)                                                 # attitude and its accuracy
>>> f = fine(later_imu, lla, c)                              # doctest: +SKIP
>>> nav = atomnav.strapdown.integrate(rest_of_imu, **f.state)  # doctest: +SKIP
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from . import _core, plausibility, units
from ._validate import choice, finite, flag, input_error, instance, positive, renamed, vector
from .filter.aided import AidedResult, InsSetup, _concat
from .filter.engine import BiasModel
from .filter.sources import ZeroRate, ZeroVelocity, aided_ins
from .imu import KINDS, ImuErrors
from .strapdown import _imu_arrays, _imu_errors
from .trajectory import imu_kind

_ARCMIN = np.pi / (180.0 * 60.0)
#: Most update epochs at which :func:`fine` keeps the filter covariance (spread evenly).
COVARIANCE_EPOCHS = 50


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
    gravity: float
    earth_rate_h: float
    spread: tuple
    errors: ImuErrors
    ellipsoid: str

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
            f"Coarse alignment: {self.time_s - self.t0:.1f} s at rest, {self.samples} samples ({self.kind}), "
            f"at {lat:.4f}° {lon:.4f}°, {self.lla[2]:.1f} m",
            *_attitude_lines(self.euler, self.euler_sigma),
            "  attainable accuracy (1σ), from the sensor biases | noise (white and faster than the record):",
            f"    levelling north/east  {_angle(bias[0])}, {_angle(bias[1])} | {_angle(noise[0])}, {_angle(noise[1])}"
            f"   (accel bias / g = {self.gravity:.4f} m/s²)",
            f"    heading               {_angle(bias[2])} | {_angle(noise[2])}"
            f"   (gyro bias / Ω cos φ = {self.earth_rate_h / units.DEG_PER_HOUR:.3f} °/h)",
            f"  static test: spread {self.spread[0]:.2f} (specific force), {self.spread[1]:.2f} (angular rate); limit 5",
        ]
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
    kind = choice(imu_kind(kind, imu, "imu"), KINDS, "kind")
    model = _errors(errors)
    site = vector(lla, 3, "lla")
    plausibility.lla(site, "lla")
    t, g, a = _read(imu, kind)
    with _imu_errors(kind, g, a, 0):
        d = _core.coarse_alignment(t, g, a, kind, site, *model._to_core(), ellipsoid=ellipsoid)
    arr = {k: np.asarray(d[k], dtype=float) for k in ("q_nb", "euler", "euler_sigma", "psi_cov", "psi_cov_noise", "mean_f", "mean_w")}
    return CoarseAlignment(t0=d["t0"], time_s=d["t1"], samples=d["samples"], kind=kind, lla=site, gravity=d["gravity"],
                           earth_rate_h=d["earth_rate_h"], spread=tuple(d["spread"]), errors=model, ellipsoid=ellipsoid, **arr)


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
    accel_errors, gyro_errors = model._to_core()
    p0, (accel_psd, accel_walk, gyro_psd, gyro_walk) = _core.fine_alignment_p0(
        site, coarse.q_nb, psi_cov_noise=coarse.psi_cov_noise, mean_f=coarse.mean_f, mean_w=coarse.mean_w,
        gravity=coarse.gravity, horizon=span, accel_errors=accel_errors, gyro_errors=gyro_errors,
        pos_sigma=positive(pos_sigma, "pos_sigma"), vel_sigma=positive(vel_sigma, "vel_sigma"), ellipsoid=coarse.ellipsoid)
    with renamed(lla0="lla"):
        setup = InsSetup(t0=t0, lla0=site, vel0=(0.0, 0.0, 0.0), q0=coarse.q_nb, kind=kind, p0=p0, accel_psd=accel_psd,
                         gyro_psd=gyro_psd, accel_bias=BiasModel(kind="random_walk", psd=accel_walk),
                         gyro_bias=BiasModel(kind="random_walk", psd=gyro_walk),
                         predict_every=max(1, int(round(predict_s / step))), ellipsoid=coarse.ellipsoid)
    sources = [ZeroVelocity(times, zupt_sigma)] + ([ZeroRate(times, gyro_psd, rate_sigma)] if rate_updates else [])
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
