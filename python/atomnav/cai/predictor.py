"""Atom strapdown: CAI phase prediction from an IMU stream (Tennstedt et al. 2023), its Jacobians, the
inertial oracle with analytic body motions, and the constant-input closed forms.

Conventions (Tennstedt et al. 2023 Eqs. 1–8; docs/departures.md#specific-force-drives-the-atoms):
pulses at t_s, t_s + T, t_s + 2T;
φ = k·(x(0) − 2x(T) + x(2T)) with x the atom position in the sensor frame s; the atom
is driven by the SPECIFIC FORCE at the s origin, so a constant specific force f_s gives
φ = −T² k·f_s. measured = true + bias; estimated biases are subtracted.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import _core, plausibility
from .._validate import (as_floats, broadcast, finite, finite_result, finite_scalar, flag, input_error, instance, nonnegative,
                         positive, renamed, rows, scalar, shaped, vector)
from ._config import ConfigMixin

#: ⁸⁷Rb D2 wavelength (m) and the two-photon effective wave number 4π/λ (rad/m).
LAMBDA_RB87 = 780.241e-9
K_RB87 = 4.0 * np.pi / LAMBDA_RB87

#: Columns of the phase breakdown (docs/departures.md#per-term-breakdown); the terms after ``total`` sum to it.
TERMS = tuple(_core.CAI_TERMS)
#: Columns of the Jacobians: accelerometer bias (m/s²), gyro bias (rad/s), lever arm (m),
#: misalignment γ (rad, C_sb = exp(−[γ×]) C_sb,0).
JACOBIAN_PARAMS = tuple(_core.CAI_JACOBIAN_PARAMS)


def k_eff(wavelength: float = LAMBDA_RB87) -> float:
    """Effective two-photon wave number 4π/λ of a wavelength λ.

    Parameters
    ----------
    wavelength : float
        Laser wavelength λ (m); default the ⁸⁷Rb D2 line, :data:`LAMBDA_RB87`.

    Returns
    -------
    float
        k_eff = 4π/λ (rad/m).
    """
    with np.errstate(over="ignore"):
        return float(finite_result(4.0 * np.pi / np.float64(plausibility.wavelength(positive(wavelength, "wavelength"), "wavelength")), "wavelength", "the wave number 4π/λ"))


@dataclass
class Channels(ConfigMixin):
    """Interferometer channels: wave vectors, lever arms, mounting and launch velocities.

    Convertible to and from dict / JSON (``to_dict``, ``from_dict``, ``to_json``,
    ``from_json``).

    Parameters
    ----------
    k : array_like, shape (C, 3)
        Effective wave vector of each channel in the sensor frame s (rad/m).
    lever : array_like, shape (C, 3) or (3,)
        Lever arm from the IMU to the release point of each channel in the body frame b
        (m); one row is used for all channels.
    c_sb : array_like, shape (C, 3, 3) or (3, 3)
        Rotation b → s of each channel (may carry a misalignment); one matrix is used for
        all channels.
    v0 : array_like, shape (C, 3) or (3,)
        Initial atom velocity relative to s, in s (m/s).
    names : list of str, optional
        A name per channel (default ``ch0``, ``ch1``, ...).
    """

    _ARRAYS = ("k", "lever", "c_sb", "v0", "names")

    k: np.ndarray
    lever: np.ndarray
    c_sb: np.ndarray
    v0: np.ndarray
    names: list = field(default_factory=list)

    def __post_init__(self):
        self.k = rows(self.k, 3, "k")
        n = len(self.k)
        self.lever = rows(broadcast(self.lever, (n, 3), "lever"), 3, "lever")
        self.v0 = rows(broadcast(self.v0, (n, 3), "v0"), 3, "v0")
        self.c_sb = broadcast(self.c_sb, (n, 3, 3), "c_sb")
        if self.names is None or (isinstance(self.names, (list, tuple)) and not self.names):
            self.names = [f"ch{j}" for j in range(n)]
        if not isinstance(self.names, (list, tuple)) or not all(isinstance(x, str) for x in self.names):
            raise TypeError(f"names: expected a list of str, got {type(self.names).__name__}")
        if len(self.names) != n:
            raise input_error("names", f"expected {n} names, got {len(self.names)}")

    def __len__(self) -> int:
        return len(self.k)

    def _native(self):
        """The channels as validated by the Rust core (for the predictor and the oracle)."""
        return _core.CaiChannels(self.k, self.lever, self.c_sb, self.v0)

    @classmethod
    def cyclic(cls, k: float = K_RB87, v0: float = 2.8, lever=(0.0, 0.0, 0.0), c_sb=None) -> "Channels":
        """Six channels of the multi-axis sensor of Tennstedt et al. 2023.

        k along e_j, ensembles A/B with v0 = ±v0 e_{(j+1) mod 3} (the geometry is
        described in ``docs/departures.md#ensemble-geometry``); names x_A, x_B, y_A, ...

        Parameters
        ----------
        k : float
            Magnitude of the effective wave number (rad/m).
        v0 : float
            Launch speed of the atoms relative to the sensor (m/s).
        lever : array_like, shape (3,) or (6, 3)
            Lever arm from the IMU to the release point, body frame (m).
        c_sb : array_like, shape (3, 3) or (6, 3, 3), optional
            Rotation b → s (default identity).

        Returns
        -------
        Channels
            The six channels x_A, x_B, y_A, y_B, z_A, z_B.
        """
        k, v0 = finite_scalar(k, "k"), finite_scalar(v0, "v0")
        ks, vs, names = [], [], []
        for j, ax in enumerate("xyz"):
            for s, ab in ((1.0, "A"), (-1.0, "B")):
                ks.append(np.eye(3)[j] * k)
                vs.append(np.eye(3)[(j + 1) % 3] * s * v0)
                names.append(f"{ax}_{ab}")
        return cls(np.array(ks), lever, np.eye(3) if c_sb is None else c_sb, np.array(vs), names)


def _gradient(gradient):
    """Gravity-gradient tensor (3, 3) 1/s² as the core takes it; None = no gradient."""
    return None if gradient is None else shaped(gradient, (3, 3), "gradient")


def _setup(t, specific_force, angular_rate, shots, T, channels, angular_acceleration, omega_dot,
           savgol_half_width, interpolation, substeps, gradient, bias_a, bias_g):
    """Validated shot start times (s) and the core predictor set up on them; options left
    None take the core's defaults."""
    instance(channels, Channels, "channels")
    t = vector(t, None, "t")
    f = np.ascontiguousarray(as_floats(specific_force, "specific_force"))
    w = np.ascontiguousarray(as_floats(angular_rate, "angular_rate"))
    for name, a in (("specific_force", f), ("angular_rate", w)):
        if a.shape != (len(t), 3):
            raise input_error(name, f"expected shape ({len(t)}, 3), got {a.shape}")
    plausibility.time_steps(t, "t")
    plausibility.specific_force(f, "specific_force")
    plausibility.angular_rate(w, "angular_rate")
    wd = None
    if angular_acceleration is not None:
        wd = np.ascontiguousarray(as_floats(angular_acceleration, "angular_acceleration"))
        if wd.shape != (len(t), 3):
            raise input_error("angular_acceleration", f"expected shape ({len(t)}, 3), got {wd.shape}")
    shots = np.ascontiguousarray(np.atleast_1d(as_floats(shots, "shots")))
    return shots, _core.CaiSetup(t, f, w, shots, channels._native(), plausibility.pulse_separation(finite_scalar(T, "T"), "T"), omega_dot=omega_dot, angular_acceleration=wd,
                                 savgol_half_width=savgol_half_width, interpolation=interpolation, substeps=substeps,
                                 gradient=_gradient(gradient),
                                 bias_a=vector(broadcast(bias_a, (3,), "bias_a"), 3, "bias_a"),
                                 bias_g=vector(broadcast(bias_g, (3,), "bias_g"), 3, "bias_g"))


@dataclass
class PhasePrediction:
    """Predicted phases of every shot and channel, with their breakdown into terms.

    ``total`` is the sum of the terms acc, rot, cen, eul, mix, gg (the breakdown is
    described in ``docs/departures.md#per-term-breakdown``).

    Attributes
    ----------
    shots : numpy.ndarray, shape (S,)
        Shot start times (s).
    channels : Channels
        The C interferometer channels.
    terms : dict of str to numpy.ndarray
        Phase (rad) per term, each an array (S, C), keyed by :data:`TERMS` (``total``
        first).
    error_bound_rad : numpy.ndarray, shape (S, C)
        Bound of the discretisation error of ``total`` estimated from the IMU samples
        (rad; ``docs/cai_predictor_accuracy.md``); inf where the record holds too few
        samples around a shot to estimate it.
    """

    shots: np.ndarray
    channels: Channels
    terms: dict
    error_bound_rad: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.terms["total"]

    def frame(self) -> pd.DataFrame:
        """The prediction as a long table.

        Returns
        -------
        pandas.DataFrame
            One row per shot and channel: ``shot_start_s``, ``channel``, one
            ``<term>_rad`` column per term of :data:`TERMS` (rad) and ``error_bound_rad``
            (rad).
        """
        n, c = self.total.shape
        d = {"shot_start_s": np.repeat(self.shots, c), "channel": np.tile(self.channels.names, n)}
        d.update({f"{k}_rad": v.ravel() for k, v in self.terms.items()})
        d["error_bound_rad"] = self.error_bound_rad.ravel()
        return pd.DataFrame(d)


def predict_phase(t, specific_force, angular_rate, shots, T: float, channels: Channels, *, angular_acceleration=None,
                  omega_dot: str | None = None, savgol_half_width: int | None = None, interpolation: str | None = None,
                  substeps: int | None = None, gradient=None, bias_a=0.0, bias_g=0.0,
                  tolerance_rad: float = 0.01) -> PhasePrediction:
    """Atom strapdown phase of every shot and channel, with breakdown (Tennstedt et al. 2023, Eqs. 5–8).

    Departures from the paper are described in
    ``docs/departures.md#full-phase-predictor``. The discretisation error is bounded from
    the IMU samples (``docs/cai_predictor_accuracy.md``); an :class:`ImuRateWarning`
    names the bound and the IMU rate needed when it exceeds ``tolerance_rad``.

    Parameters
    ----------
    t : array_like, shape (N,)
        IMU sample times (s), increasing.
    specific_force : array_like, shape (N, 3)
        Specific force in the IMU body frame (m/s²).
    angular_rate : array_like, shape (N, 3)
        Angular rate in the IMU body frame (rad/s).
    shots : float or array_like, shape (S,)
        Start times (s) of non-overlapping shots: pulses at t_s, t_s + T, t_s + 2T, inside
        the record; they need not coincide with samples.
    T : float
        Pulse separation (s).
    channels : Channels
        The interferometer channels (C of them).
    angular_acceleration : array_like, shape (N, 3), optional
        Angular acceleration ω̇ in the body frame (rad/s²), e.g. from a simulator.
    omega_dot : {"given", "pwl", "savgol", "zero"}, optional
        Source of ω̇ for the Euler terms: "given" (default when ``angular_acceleration``
        is passed), "pwl" (default otherwise: derivative of the gyro interpolant, whose
        lever-arm Euler term keeps the interpolation's order), "savgol" (quadratic
        Savitzky–Golay derivative of the gyro over 2m + 1 samples, error ∝ h²), "zero" (no
        Euler terms).
    savgol_half_width : int, optional
        Half width m of the Savitzky–Golay window (2m + 1 samples); default 2.
    interpolation : {"cubic", "linear"}, optional
        Interpolation of the IMU inputs between samples; default "cubic" (integrated error
        ∝ h⁴, h the sample interval; "linear": ∝ h², Tennstedt et al. 2023's setup).
    substeps : int, optional
        RK4 steps per interval of the integration grid (the IMU sample times and the pulse
        times); default 1.
    gradient : array_like, shape (3, 3), optional
        Gravity-gradient tensor Γ_b0 in the IMU body frame b at each shot's start (1/s²),
        e.g. C_bi Γ_i C_ib for a tensor Γ_i in an inertial frame; the predictor turns it
        into each channel's frame (C_sb) and with the body during the shot. None: no
        gradient.
    bias_a : float or array_like, shape (3,)
        Estimated accelerometer bias (m/s²), subtracted from ``specific_force``
        (measured = true + bias).
    bias_g : float or array_like, shape (3,)
        Estimated gyro bias (rad/s), subtracted from ``angular_rate``.
    tolerance_rad : float
        Largest acceptable discretisation error (rad); a larger error bound gives an
        :class:`ImuRateWarning` (``np.inf``: never).

    Returns
    -------
    PhasePrediction
        Phases (rad) of shape (S, C), total and per term, and the error bound.

    Warns
    -----
    ImuRateWarning
        When the error bound exceeds ``tolerance_rad``: the message names the bound (rad)
        and the IMU rate (Hz) at which it falls below the tolerance.
    """
    tolerance = scalar(tolerance_rad, "tolerance_rad")
    if not tolerance > 0:
        raise input_error("tolerance_rad", f"must be > 0 (np.inf: never warn), got {tolerance}")
    shots, setup = _setup(t, specific_force, angular_rate, shots, T, channels, angular_acceleration, omega_dot,
                          savgol_half_width, interpolation, substeps, gradient, bias_a, bias_g)
    out = setup.predict().reshape(len(shots), len(channels), len(TERMS))
    bound, needed, rate = setup.error_bound(min(tolerance, np.finfo(float).max))
    bound = bound.reshape(len(shots), len(channels))
    if bound.size and bound.max() > tolerance:
        _warn_rate(bound.max(), tolerance, rate, needed)
    return PhasePrediction(shots, channels, {k: out[:, :, i] for i, k in enumerate(TERMS)}, bound)


class ImuRateWarning(RuntimeWarning):
    """The IMU record is too coarse for the requested phase accuracy (see
    ``docs/cai_predictor_accuracy.md``)."""


def _warn_rate(bound, tolerance, rate, needed):
    """Warn that the error bound (rad) exceeds the tolerance (rad) at the record's rate (Hz)."""
    msg = (f"the predicted phase may be off by up to {bound:.3g} rad, above tolerance_rad = {tolerance:.3g} rad, "
           f"at the IMU rate of {rate:.6g} Hz (interpolation error of the IMU samples; "
           f"docs/cai_predictor_accuracy.md): ")
    if needed is None:
        msg += ("no IMU rate reaches the tolerance with these options (omega_dot='zero' omits the Euler terms, or the "
                "record is too short around a shot to estimate the bound)")
    else:
        msg += f"an IMU rate of at least {needed:.6g} Hz is needed"
    warnings.warn(msg, ImuRateWarning, stacklevel=3)


def phase_jacobian(t, specific_force, angular_rate, shots, T: float, channels: Channels, *, euler: bool = False,
                   fd_steps=None, angular_acceleration=None, omega_dot: str | None = None,
                   savgol_half_width: int | None = None, interpolation: str | None = None, substeps: int | None = None,
                   gradient=None, bias_a=0.0, bias_g=0.0) -> np.ndarray:
    """Jacobian ∂φ/∂(b_a, b_g, l, γ) of the predicted phase.

    Analytic tangent-linear derivative of the predictor of :func:`predict_phase` at the
    given bias estimates; Euler terms (ω̇) are excluded from the linearisation unless
    ``euler``.

    Parameters
    ----------
    t : array_like, shape (N,)
        IMU sample times (s), increasing.
    specific_force : array_like, shape (N, 3)
        Specific force in the IMU body frame (m/s²).
    angular_rate : array_like, shape (N, 3)
        Angular rate in the IMU body frame (rad/s).
    shots : float or array_like, shape (S,)
        Start times (s) of non-overlapping shots: pulses at t_s, t_s + T, t_s + 2T, inside
        the record; they need not coincide with samples.
    T : float
        Pulse separation (s).
    channels : Channels
        The interferometer channels (C of them).
    euler : bool
        Keep the Euler terms (ω̇) in the linearisation.
    fd_steps : array_like, shape (4,), optional
        Steps (db_a m/s², db_g rad/s, dl m, dγ rad): compute the same derivative by
        central finite differences of :func:`predict_phase` instead (the checker).
    angular_acceleration : array_like, shape (N, 3), optional
        Angular acceleration ω̇ in the body frame (rad/s²), e.g. from a simulator.
    omega_dot : {"given", "pwl", "savgol", "zero"}, optional
        Source of ω̇ for the Euler terms: "given" (default when ``angular_acceleration``
        is passed), "pwl" (default otherwise: derivative of the gyro interpolant, whose
        lever-arm Euler term keeps the interpolation's order), "savgol" (quadratic
        Savitzky–Golay derivative of the gyro over 2m + 1 samples, error ∝ h²), "zero" (no
        Euler terms).
    savgol_half_width : int, optional
        Half width m of the Savitzky–Golay window (2m + 1 samples); default 2.
    interpolation : {"cubic", "linear"}, optional
        Interpolation of the IMU inputs between samples; default "cubic" (integrated error
        ∝ h⁴, h the sample interval; "linear": ∝ h², Tennstedt et al. 2023's setup).
    substeps : int, optional
        RK4 steps per interval of the integration grid (the IMU sample times and the pulse
        times); default 1.
    gradient : array_like, shape (3, 3), optional
        Gravity-gradient tensor Γ_b0 in the IMU body frame b at each shot's start (1/s²),
        e.g. C_bi Γ_i C_ib for a tensor Γ_i in an inertial frame; the predictor turns it
        into each channel's frame (C_sb) and with the body during the shot. None: no
        gradient.
    bias_a : float or array_like, shape (3,)
        Estimated accelerometer bias (m/s²), subtracted from ``specific_force``
        (measured = true + bias).
    bias_g : float or array_like, shape (3,)
        Estimated gyro bias (rad/s), subtracted from ``angular_rate``.

    Returns
    -------
    numpy.ndarray, shape (S, C, 12)
        Columns :data:`JACOBIAN_PARAMS`, in rad per (m/s², rad/s, m, rad).
    """
    shots, setup = _setup(t, specific_force, angular_rate, shots, T, channels, angular_acceleration, omega_dot,
                          savgol_half_width, interpolation, substeps, gradient, bias_a, bias_g)
    steps = None if fd_steps is None else tuple(vector(fd_steps, 4, "fd_steps"))
    return setup.jacobian(flag(euler, "euler"), steps).reshape(len(shots), len(channels), len(JACOBIAN_PARAMS))


def check_jacobian(*args, fd_steps=(1e-3, 1e-4, 1e-3, 1e-4), **kwargs) -> dict:
    """Compare :func:`phase_jacobian` with its finite-difference version.

    Parameters
    ----------
    *args
        Positional arguments of :func:`phase_jacobian` (t, specific_force, angular_rate,
        shots, T, channels).
    fd_steps : array_like, shape (4,)
        Finite-difference steps (db_a m/s², db_g rad/s, dl m, dγ rad).
    **kwargs
        Keyword arguments of :func:`phase_jacobian`.

    Returns
    -------
    dict
        ``analytic`` and ``finite_difference``: the two (S, C, 12) Jacobians (rad per
        parameter unit); ``max_rel_diff``: the maximum relative difference per parameter
        of :data:`JACOBIAN_PARAMS`.
    """
    an = phase_jacobian(*args, **kwargs)
    fd = phase_jacobian(*args, fd_steps=fd_steps, **kwargs)
    scale = np.maximum(np.abs(an), 1e-12 + 1e-9 * np.abs(an).max())
    rel = (np.abs(an - fd) / scale).reshape(-1, 12).max(axis=0)
    return {"analytic": an, "finite_difference": fd, "max_rel_diff": dict(zip(JACOBIAN_PARAMS, rel))}


def readout_jacobian(phase_jac, phi_hat, phi0, contrast: float = 1.0) -> np.ndarray:
    """Readout Jacobian ∂p/∂θ = (C/2) sin(φ̂ + φ0) ∂φ/∂θ of p = o − (C/2) cos(φ̂ + φ0).

    Tennstedt et al. 2021, Eq. 10; at mid-fringe (φ̂ + φ0 = π/2) it is (C/2) ∂φ/∂θ.
    Shapes broadcast over (shots, channels).

    Parameters
    ----------
    phase_jac : array_like, shape (S, C, P)
        Phase Jacobian ∂φ/∂θ (rad per parameter unit), e.g. from :func:`phase_jacobian`.
    phi_hat : float or array_like, shape (S, C)
        Predicted phase φ̂ (rad).
    phi0 : float or array_like, shape (S, C)
        Laser phase φ0 (rad).
    contrast : float
        Fringe contrast C ∈ (0, 1].

    Returns
    -------
    numpy.ndarray, shape (S, C, P)
        ∂p/∂θ (population per parameter unit).
    """
    jac = as_floats(phase_jac, "phase_jac")
    phi_hat, phi0 = as_floats(phi_hat, "phi_hat"), as_floats(phi0, "phi0")
    for a, name in ((jac, "phase_jac"), (phi_hat, "phi_hat"), (phi0, "phi0")):
        finite(a.reshape(-1), name)
    s = 0.5 * plausibility.fraction(finite_scalar(contrast, "contrast"), "contrast", "contrast") * np.sin(broadcast(phi_hat, jac.shape[:-1], "phi_hat")
                                                          + broadcast(phi0, jac.shape[:-1], "phi0"))
    return s[..., None] * jac


# --- analytic motions and the inertial oracle ------------------------------------------

_EMPTY_SINES = np.zeros((0, 4))


@dataclass
class SineMotion:
    """IMU motion in an inertial frame, polynomial plus sines per axis.

    Per axis c0 + c1 t + c2 t² + Σ A sin(2πft + ϕ) for the position (m) and for the
    z-y-x Euler angles roll, pitch, yaw (rad).

    Parameters
    ----------
    position_poly : array_like, shape (3, 3)
        Row = axis, columns c0 (m), c1 (m/s), c2 (m/s²).
    position_sines : array_like, shape (M, 4)
        Rows [axis, amplitude m, frequency Hz, phase rad].
    attitude_poly : array_like, shape (3, 3)
        Row = Euler angle (roll, pitch, yaw), columns c0 (rad), c1 (rad/s), c2 (rad/s²).
    attitude_sines : array_like, shape (M, 4)
        Rows [axis, amplitude rad, frequency Hz, phase rad].
    """

    position_poly: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    position_sines: np.ndarray = field(default_factory=lambda: _EMPTY_SINES)
    attitude_poly: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    attitude_sines: np.ndarray = field(default_factory=lambda: _EMPTY_SINES)

    def _native(self):
        attitude_poly, attitude_sines = rows(self.attitude_poly, 3, "attitude_poly"), rows(self.attitude_sines, 4, "attitude_sines")
        plausibility.angles(attitude_poly[:, 0], "attitude_poly")  # c0: the Euler angles at t = 0
        plausibility.angles(attitude_sines[:, 1], "attitude_sines", "Euler angle amplitudes")
        return _core.CaiMotion.sine(rows(self.position_poly, 3, "position_poly"),
                                    rows(self.position_sines, 4, "position_sines"), attitude_poly, attitude_sines)


@dataclass
class YawDrive:
    """Drive of Tennstedt et al. 2023, Fig. 7: level, forward along body x, sinusoidal yaw rate.

    Parameters
    ----------
    speed : float
        Forward speed along body x (m/s).
    yaw_rate_amplitude : float
        Amplitude of the yaw rate ω_z = amplitude · sin(2πt/period) (rad/s).
    period : float
        Period of the yaw rate (s).
    """

    speed: float = 1.0
    yaw_rate_amplitude: float = 0.05
    period: float = 50.0

    def _native(self):
        return _core.CaiMotion.yaw_drive(finite_scalar(self.speed, "speed"), finite_scalar(self.yaw_rate_amplitude, "yaw_rate_amplitude"),
                                         positive(self.period, "period"))


def _gravity(gravity, gradient, t_ref):
    """The core gravity model: uniform g (m/s²) and gradient (1/s²) about the IMU at t_ref (s)."""
    return _core.CaiGravity(vector(gravity, 3, "gravity"), _gradient(gradient), finite_scalar(t_ref, "t_ref"))


def motion_imu(motion, t, *, gravity=(0.0, 0.0, 0.0), gradient=None, t_ref: float = 0.0):
    """Ideal IMU output of an analytic motion, body frame.

    Parameters
    ----------
    motion : SineMotion or YawDrive
        The analytic body motion.
    t : float or array_like, shape (N,)
        Times (s).
    gravity : array_like, shape (3,)
        Uniform gravity g in the inertial frame (m/s²); zero = kinematic mode.
    gradient : array_like, shape (3, 3), optional
        Gravity-gradient tensor Γ_i in the inertial frame (1/s²), about the IMU position
        at ``t_ref``; None: no gradient.
    t_ref : float
        Time (s) of the position the gradient is taken about.

    Returns
    -------
    specific_force : numpy.ndarray, shape (N, 3)
        Specific force (m/s²).
    angular_rate : numpy.ndarray, shape (N, 3)
        Angular rate (rad/s).
    angular_acceleration : numpy.ndarray, shape (N, 3)
        Angular acceleration (rad/s²).
    """
    instance(motion, (SineMotion, YawDrive), "motion")
    g = _gravity(gravity, gradient, t_ref)
    return motion._native().imu(vector(np.atleast_1d(as_floats(t, "t")), None, "t"), g)


def oracle_phase(motion, shots, T: float, channels: Channels, *, gravity=(0.0, 0.0, 0.0), gradient=None,
                 t_ref: float = 0.0) -> np.ndarray:
    """Exact phase from the inertial oracle.

    The atom flies ballistically in the inertial frame and is transformed into the
    rotating sensor frame at the pulses.

    Parameters
    ----------
    motion : SineMotion or YawDrive
        The analytic body motion.
    shots : float or array_like, shape (S,)
        Shot start times (s): pulses at t_s, t_s + T, t_s + 2T.
    T : float
        Pulse separation (s).
    channels : Channels
        The C interferometer channels.
    gravity : array_like, shape (3,)
        Uniform gravity g in the inertial frame (m/s²); zero = kinematic mode.
    gradient : array_like, shape (3, 3), optional
        Gravity-gradient tensor Γ_i (1/s²) about the IMU position at ``t_ref``.
    t_ref : float
        Time (s) of the position the gradient is taken about.

    Returns
    -------
    numpy.ndarray, shape (S, C)
        Phase (rad).
    """
    instance(motion, (SineMotion, YawDrive), "motion")
    instance(channels, Channels, "channels")
    g = _gravity(gravity, gradient, t_ref)
    shots = np.atleast_1d(as_floats(shots, "shots"))
    out = motion._native().oracle(vector(shots, None, "shots"), plausibility.pulse_separation(finite_scalar(T, "T"), "T"), channels._native(), g)
    return out.reshape(len(shots), len(channels))


# --- closed forms ----------------------------------------------------------------------


def _closed(kind, k, v0, angular_rate, specific_force, T, angular_acceleration=(0, 0, 0), gradient=None):
    k = rows(k, 3, "k")
    v0 = rows(broadcast(v0, k.shape, "v0"), 3, "v0")
    return _core.cai_phase_closed_form(kind, k, v0, vector(angular_rate, 3, "angular_rate"),
                                       vector(specific_force, 3, "specific_force"),
                                       vector(angular_acceleration, 3, "angular_acceleration"),
                                       _gradient(gradient), finite_scalar(T, "T"))


def phase_constant(k, v0, angular_rate, specific_force, T: float) -> np.ndarray:
    """Exact phase for constant angular rate and specific force.

    Closed-form solution of the atom motion in the rotating sensor frame.

    Parameters
    ----------
    k : array_like, shape (C, 3)
        Effective wave vectors in the sensor frame s (rad/m).
    v0 : array_like, shape (C, 3) or (3,)
        Initial atom velocities relative to s (m/s).
    angular_rate : array_like, shape (3,)
        Constant angular rate ω_s in s (rad/s).
    specific_force : array_like, shape (3,)
        Constant specific force f_s in s (m/s²).
    T : float
        Pulse separation (s).

    Returns
    -------
    numpy.ndarray, shape (C,)
        Phase per row of ``k`` (rad).
    """
    return _closed("exact", k, v0, plausibility.angular_rate(angular_rate, "angular_rate"), specific_force, plausibility.pulse_separation(T, "T"))


def phase_series(k, v0, angular_rate, specific_force, T: float, angular_acceleration=(0.0, 0.0, 0.0),
                 gradient=None) -> np.ndarray:
    """Fourth-order series in T of :func:`phase_constant`, including ω̇ and gravity-gradient terms.

    Parameters
    ----------
    k : array_like, shape (C, 3)
        Effective wave vectors in the sensor frame s (rad/m).
    v0 : array_like, shape (C, 3) or (3,)
        Initial atom velocities relative to s (m/s).
    angular_rate : array_like, shape (3,)
        Constant angular rate ω_s in s (rad/s).
    specific_force : array_like, shape (3,)
        Constant specific force f_s in s (m/s²).
    T : float
        Pulse separation (s).
    angular_acceleration : array_like, shape (3,)
        Constant angular acceleration ω̇ in s (rad/s²).
    gradient : array_like, shape (3, 3), optional
        Gravity-gradient tensor Γ in s (1/s²); None: no gradient.

    Returns
    -------
    numpy.ndarray, shape (C,)
        Phase per row of ``k`` (rad).
    """
    return _closed("series", k, v0, plausibility.angular_rate(angular_rate, "angular_rate"), specific_force, plausibility.pulse_separation(T, "T"),
                   angular_acceleration, gradient)


def phase_seed000(k, vbar, angular_rate, specific_force, T_total: float) -> np.ndarray:
    """Phase of Tennstedt et al. 2021, Eq. 52 in the paper's convention: k·(¼ f − ½ ω×v̄) T0².

    Equals the library's first-order phase with k → −k, v0 = −v̄, T = T0/2 (see
    ``docs/departures.md#phase-convention-of-eq-52``).

    Parameters
    ----------
    k : array_like, shape (C, 3)
        Effective wave vectors (rad/m).
    vbar : array_like, shape (C, 3) or (3,)
        Mean atom velocity v̄ of the paper (m/s).
    angular_rate : array_like, shape (3,)
        Constant angular rate ω (rad/s).
    specific_force : array_like, shape (3,)
        Constant specific force f (m/s²).
    T_total : float
        Total interrogation time T0 = 2T (s).

    Returns
    -------
    numpy.ndarray, shape (C,)
        Phase per row of ``k`` (rad).
    """
    with renamed(v0="vbar", T="T_total"):
        return _closed("seed000", k, vbar, plausibility.angular_rate(angular_rate, "angular_rate"), specific_force,
                       plausibility.pulse_separation(T_total, "T_total", pulses=2))


def sagnac_phase(k, v0, angular_rate, T: float) -> np.ndarray:
    """Sagnac (Coriolis) term −2T² k·(ω×v0) of the phase.

    Parameters
    ----------
    k : array_like, shape (C, 3) or (3,)
        Effective wave vectors (rad/m).
    v0 : array_like, shape (C, 3) or (3,)
        Initial atom velocities relative to the sensor (m/s).
    angular_rate : array_like, shape (3,)
        Angular rate ω (rad/s).
    T : float
        Pulse separation (s).

    Returns
    -------
    numpy.ndarray, shape (C,)
        Sagnac phase per row of ``k`` (rad).
    """
    k = rows(np.atleast_2d(as_floats(k, "k")), 3, "k")
    v0 = rows(broadcast(v0, k.shape, "v0"), 3, "v0")
    w = plausibility.angular_rate(vector(angular_rate, 3, "angular_rate"), "angular_rate")
    with np.errstate(over="ignore", invalid="ignore"):
        phase = -2.0 * np.float64(plausibility.pulse_separation(finite_scalar(T, "T"), "T")) ** 2 * np.einsum("ij,ij->i", k, np.cross(w, v0))
    return finite_result(phase, "T", "the Sagnac phase")


def t_sep_from_total(T_total: float) -> float:
    """Pulse separation T = T0/2 of Tennstedt et al. 2021's total interrogation time T0.

    See ``docs/departures.md#interrogation-time-t0``.

    Parameters
    ----------
    T_total : float
        Total interrogation time T0 (s).

    Returns
    -------
    float
        Pulse separation T (s).
    """
    return 0.5 * plausibility.pulse_separation(positive(T_total, "T_total"), "T_total", pulses=2)


def total_from_t_sep(T: float) -> float:
    """Tennstedt et al. 2021's total interrogation time T0 = 2T.

    Parameters
    ----------
    T : float
        Pulse separation (s).

    Returns
    -------
    float
        Total interrogation time T0 (s).
    """
    with np.errstate(over="ignore"):
        return float(finite_result(2.0 * np.float64(plausibility.pulse_separation(positive(T, "T"), "T")), "T", "2T"))


def scale_factors(T: float, k: float = K_RB87, v0: float = 2.8) -> dict:
    """Phase scale factors of acceleration, rotation (Sagnac) and angular acceleration (Euler).

    Parameters
    ----------
    T : float
        Pulse separation (s).
    k : float
        Effective wave number (rad/m).
    v0 : float
        Atom launch speed relative to the sensor (m/s).

    Returns
    -------
    dict
        ``acceleration`` kT² (rad per m/s²), ``sagnac`` 2kv0T² (rad per rad/s),
        ``euler`` kv0T³ (rad per rad/s²).
    """
    T, k, v0 = np.float64(plausibility.pulse_separation(positive(T, "T"), "T")), finite_scalar(k, "k"), finite_scalar(v0, "v0")
    with np.errstate(over="ignore"):
        out = {"acceleration": k * T**2, "sagnac": 2 * k * v0 * T**2, "euler": k * v0 * T**3}
    return {key: float(finite_result(v, "T", f"the {key} scale factor")) for key, v in out.items()}


def dynamic_range(T: float, k: float = K_RB87) -> float:
    """Acceleration span of one fringe flank, π/(kT²) (Tennstedt et al. 2023, Eq. 3).

    Parameters
    ----------
    T : float
        Pulse separation (s).
    k : float
        Effective wave number (rad/m).

    Returns
    -------
    float
        Dynamic range (m/s²).
    """
    return np.pi / _kt2(k, T)


def _kt2(k: float, T: float) -> float:
    """The acceleration scale factor kT² (rad per m/s²), checked to be a positive float."""
    with np.errstate(over="ignore", under="ignore"):
        scale = positive(k, "k") * np.float64(plausibility.pulse_separation(positive(T, "T"), "T")) ** 2
    if not 0 < scale < np.inf:
        raise input_error("T", f"kT² = {scale} rad/(m/s²) is outside the range of floats")
    return scale


def capture_limits(T: float, k: float = K_RB87, v0: float = 2.8) -> dict:
    """Largest bias errors keeping the phase error below π/2 (Tennstedt et al. 2021, Fig. 3).

    Parameters
    ----------
    T : float
        Pulse separation (s).
    k : float
        Effective wave number (rad/m).
    v0 : float
        Atom launch speed relative to the sensor (m/s).

    Returns
    -------
    dict
        ``accelerometer`` π/(2kT²) (m/s²) and ``gyro`` π/(2·2kv0T²) (rad/s).
    """
    s = scale_factors(T, positive(k, "k"), positive(v0, "v0"))
    with np.errstate(over="ignore", divide="ignore"):
        limits = {"accelerometer": 0.5 * np.pi / np.float64(s["acceleration"]), "gyro": 0.5 * np.pi / np.float64(s["sagnac"])}
    return {key: float(finite_result(v, "T", f"the {key} capture limit (a scale factor that underflows to 0)")) for key, v in limits.items()}


def in_shot_noise_phase(q_accel: float, q_gyro: float, T: float, k: float = K_RB87, v0: float = 2.8) -> dict:
    """Phase standard deviation caused by IMU white noise inside one shot.

    From Var = q k² ∫w² dt with ∫w² = 2T³/3 (Tennstedt et al. 2021, §2.4).

    Parameters
    ----------
    q_accel : float
        Accelerometer white-noise PSD q_a (m²/s³).
    q_gyro : float
        Gyro white-noise PSD q_g (rad²/s).
    T : float
        Pulse separation (s).
    k : float
        Effective wave number (rad/m).
    v0 : float
        Atom launch speed relative to the sensor (m/s).

    Returns
    -------
    dict
        ``accel`` k√(2q_a/3) T^{3/2} and ``gyro`` (Sagnac) 2kv0√(2q_g/3) T^{3/2}, in rad.
    """
    T = np.float64(plausibility.pulse_separation(positive(T, "T"), "T"))
    q_accel, q_gyro = nonnegative(q_accel, "q_accel"), nonnegative(q_gyro, "q_gyro")
    k, v0 = finite_scalar(k, "k"), finite_scalar(v0, "v0")
    with np.errstate(over="ignore", invalid="ignore"):
        out = {"accel": k * np.sqrt(2 * q_accel / 3) * T**1.5, "gyro": 2 * k * v0 * np.sqrt(2 * q_gyro / 3) * T**1.5}
    return {key: float(finite_result(v, "T", f"the {key} phase noise")) for key, v in out.items()}


def phase_noise(sigma_p: float, contrast: float = 1.0) -> float:
    """Phase noise 2σ_p/C of a mid-fringe readout with population noise σ_p.

    Parameters
    ----------
    sigma_p : float
        Population noise σ_p (population units).
    contrast : float
        Fringe contrast C ∈ (0, 1].

    Returns
    -------
    float
        Phase noise (rad).
    """
    with np.errstate(over="ignore"):
        noise = 2.0 * np.float64(positive(sigma_p, "sigma_p")) / plausibility.fraction(positive(contrast, "contrast"), "contrast", "contrast")
    return float(finite_result(noise, "sigma_p", "2σ_p/C"))


def acceleration_noise(sigma_phi: float, T: float, k: float = K_RB87) -> float:
    """Acceleration noise σ_φ/(kT²) of a phase noise σ_φ.

    Parameters
    ----------
    sigma_phi : float
        Phase noise σ_φ (rad).
    T : float
        Pulse separation (s).
    k : float
        Effective wave number (rad/m).

    Returns
    -------
    float
        Acceleration noise (m/s²).
    """
    with np.errstate(over="ignore"):
        noise = finite_scalar(sigma_phi, "sigma_phi") / np.float64(_kt2(k, T))
    return float(finite_result(noise, "T", "σ_φ/(kT²) (kT² too small)"))
