"""IMU sensor errors: configuration, grade presets, noise conversions and a seeded,
streamable simulator that corrupts an ideal IMU stream (Rust: ``rust/imu/``).

Model per triad (measured = true + error)::

    ỹ = (I + diag(scale) + misalignment) y + bias + b_rw(t) + m_gm(t) + m_flicker(t) + w

``y`` is specific force f (m/s²) and angular rate ω (rad/s) for ``kind="rates"``, or the
increments Δv (m/s) and Δθ (rad) over the sample interval Δt for ``kind="increments"``;
for increments every error term is its exact integral over the interval (bias gives
bias·Δt, white noise has σ = N·√Δt), and a rate sample is the increment divided by Δt.

Parameters are continuous densities (two-sided, IEEE Std 952):

- ``white`` N: VRW in m/s/√s (= m/s²/√Hz) or ARW in rad/√s; per-sample σ = N/√Δt (rate);
- ``bias_rw`` K: m/s²/√s or rad/s/√s; Var b(t) = K² t;
- ``gauss_markov``: stationary σ (m/s², rad/s) and correlation time τ (s);
- ``flicker``: bias instability B (m/s², rad/s), one-sided PSD B²/(πf) in [f_lo, f_hi] Hz,
  realised as a sum of Gauss–Markov processes with log-spaced correlation times (2 per
  decade, 3 extra past each band edge; PSD within −1.4 %/+0.1 % of B²/(πf) inside the
  band, flat below it, falling as 1/f² above it);
- ``bias`` (fixed, per axis) and ``bias_sigma`` (σ of a random turn-on bias drawn once).

The conversion functions below translate between densities and per-sample values; field
units (°/h, °/√h, µg, µg/√Hz) are in :mod:`atomnav.units`.

Randomness: one master ``seed``; the accelerometer and gyro triads and each noise term
draw from their own ChaCha12 stream of that seed (see ``rust/imu/errors.rs``), so the
same seed gives the same numbers on every machine, feeding the stream in chunks gives
exactly the numbers of one batch call, and switching a term on or off does not change
the others' realisations.

Stream columns (DataFrame in and out): rate ``accel_{x,y,z}_mps2``, ``gyro_{x,y,z}_rad_s``;
increment ``dv_{x,y,z}_mps``, ``dtheta_{x,y,z}_rad``; an optional ``time_s`` is carried
through. The error truth is ``accel_bias_{x,y,z}_mps2`` and ``gyro_bias_{x,y,z}_rad_s``:
the true bias (fixed + turn-on + random walk + Gauss–Markov + flicker) averaged over each
sample interval, in rate units for both kinds.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from . import _core, plausibility, units
from ._stateful import Stateful, serialized
from ._validate import as_floats, choice, input_error, instance, locate, renamed, rows, scalar, seconds, table, vector
from .trajectory import imu_kind

KINDS = tuple(_core.OPTIONS["ImuKind"])
_AXES = ("x", "y", "z")
COLUMNS = {
    "rates": ([f"accel_{a}_mps2" for a in _AXES], [f"gyro_{a}_rad_s" for a in _AXES]),
    "increments": ([f"dv_{a}_mps" for a in _AXES], [f"dtheta_{a}_rad" for a in _AXES]),
}
BIAS_COLUMNS = ([f"accel_bias_{a}_mps2" for a in _AXES], [f"gyro_bias_{a}_rad_s" for a in _AXES])


@dataclass(frozen=True)
class GaussMarkov:
    """First-order Gauss–Markov term. Where a triad takes one, a ``(sigma, tau)`` tuple is
    read as this.

    Parameters
    ----------
    sigma : float
        Stationary σ (m/s² for an accelerometer, rad/s for a gyro).
    tau : float
        Correlation time (s).
    """

    sigma: float
    tau: float


@dataclass(frozen=True)
class Flicker:
    """Flicker (1/f) term. Where a triad takes one, a tuple ``(b,)``, ``(b, f_lo)`` or
    ``(b, f_lo, f_hi)`` is read as this.

    Parameters
    ----------
    b : float
        Bias instability B (m/s² or rad/s): one-sided PSD B²/(πf).
    f_lo, f_hi : float
        The band (Hz) in which the PSD is B²/(πf), by default 1e-4 to 0.1 Hz; ``f_hi``
        must not exceed the Nyquist frequency 1/(2Δt).
    """

    b: float
    f_lo: float = 1e-4
    f_hi: float = 0.1


@dataclass
class TriadErrors:
    """Errors of one sensor triad (accelerometer: m/s² units, gyro: rad/s units):
    measured = (I + diag(scale) + misalignment) · true + bias terms + noise.

    Fields may be set after construction; they are checked when used: a string where a
    number is expected (``white = '1e-4'``) or a term of another type is a ``TypeError``
    naming the field (``gyro.white``).

    Parameters
    ----------
    bias : array_like (3,)
        Fixed bias per axis (m/s² or rad/s).
    bias_sigma : float
        σ of a random turn-on bias per axis, drawn once (m/s² or rad/s).
    scale : array_like (3,)
        Scale-factor errors (dimensionless; 1e-6 = 1 ppm).
    misalignment : array_like (3, 3)
        Axis misalignment (dimensionless) with zero diagonal.
    white : float
        White-noise density N: VRW (m/s/√s) or ARW (rad/√s).
    bias_rw : float
        Bias random-walk density K (m/s²/√s or rad/s/√s).
    gauss_markov : GaussMarkov or tuple, optional
        A :class:`GaussMarkov` or a ``(sigma, tau)`` tuple.
    flicker : Flicker or tuple, optional
        A :class:`Flicker` or a tuple of its fields in order.
    """

    bias: tuple = (0.0, 0.0, 0.0)
    bias_sigma: float = 0.0
    scale: tuple = (0.0, 0.0, 0.0)
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    white: float = 0.0
    bias_rw: float = 0.0
    gauss_markov: GaussMarkov | None = None
    flicker: Flicker | None = None

    def _terms(self, name: str) -> tuple[GaussMarkov | None, Flicker | None]:
        """``gauss_markov`` and ``flicker`` as their classes (a tuple of fields accepted)."""
        return (_term(self.gauss_markov, GaussMarkov, f"{name}.gauss_markov"), _term(self.flicker, Flicker, f"{name}.flicker"))

    def _to_core(self, name: str) -> dict:
        m = as_floats(self.misalignment, f"{name}.misalignment")
        if m.shape != (3, 3):
            raise input_error(f"{name}.misalignment", f"expected shape (3, 3), got {m.shape}")
        gm, fl = self._terms(name)
        return {
            "bias": vector(self.bias, 3, f"{name}.bias").tolist(),
            "bias_sigma": scalar(self.bias_sigma, f"{name}.bias_sigma"),
            "scale": vector(self.scale, 3, f"{name}.scale").tolist(),
            "misalignment": m.ravel().tolist(),  # finiteness and zero diagonal checked in Rust
            "white": scalar(self.white, f"{name}.white"),
            "bias_rw": scalar(self.bias_rw, f"{name}.bias_rw"),
            "gauss_markov": None if gm is None else (scalar(gm.sigma, f"{name}.gauss_markov.sigma"), scalar(gm.tau, f"{name}.gauss_markov.tau")),
            "flicker": None if fl is None else tuple(scalar(getattr(fl, f), f"{name}.flicker.{f}") for f in ("b", "f_lo", "f_hi")),
        }

    @classmethod
    def _from_core(cls, d: dict) -> "TriadErrors":
        gm, fl = d["gauss_markov"], d["flicker"]
        return cls(
            bias=tuple(d["bias"]),
            bias_sigma=d["bias_sigma"],
            scale=tuple(d["scale"]),
            misalignment=np.asarray(d["misalignment"], dtype=float).reshape(3, 3),
            white=d["white"],
            bias_rw=d["bias_rw"],
            gauss_markov=None if gm is None else GaussMarkov(*gm),
            flicker=None if fl is None else Flicker(*fl),
        )


def _term(value, cls, name: str):
    """``value`` (None, a ``cls`` or a tuple/list of its fields in order) as a ``cls`` or
    None; anything else is a ``TypeError`` naming ``name``."""
    if value is None or isinstance(value, cls):
        return value
    fields = cls.__dataclass_fields__
    if isinstance(value, (tuple, list)):
        try:
            return cls(*value)
        except TypeError:
            pass
    raise TypeError(f"{name}: expected a {cls.__name__} or a tuple of its fields {tuple(fields)}, got {type(value).__name__} {value!r}")


_USER_PRESETS: dict[str, "ImuErrors"] = {}


@dataclass
class ImuErrors:
    """The error model of an IMU. ``ImuErrors.preset(preset)`` gives a named grade;
    :func:`register_preset` adds user grades.

    Parameters
    ----------
    accel, gyro : TriadErrors
        The accelerometer (m/s² units) and gyro (rad/s units) triads; error-free by
        default.
    """

    accel: TriadErrors = field(default_factory=TriadErrors)
    gyro: TriadErrors = field(default_factory=TriadErrors)

    def _to_core(self) -> tuple[dict, dict]:
        return self.accel._to_core("accel"), self.gyro._to_core("gyro")

    def validate(self) -> "ImuErrors":
        """Check every parameter.

        Returns
        -------
        ImuErrors
            This object, unchanged.

        Raises
        ------
        InputError
            (a ``ValueError``) naming the first invalid parameter (e.g. ``gyro.white``).
        """
        _core.imu_validate_errors(*self._to_core())
        return self

    @classmethod
    def preset(cls, preset: str) -> "ImuErrors":
        """A copy of a named grade.

        Parameters
        ----------
        preset : str
            Built-in ``navigation`` (RLG IMU of Tennstedt et al. 2023), ``tactical``
            (typical class values), ``mems`` (hexapod MEMS of Tennstedt et al. 2021),
            ``electrostatic_space`` / ``electrostatic_space_drift`` (satellite
            accelerometer of Tennstedt et al. 2021), ``precise`` / ``medium`` / ``coarse``
            (Demidov 2009 classes), or a name added with :func:`register_preset`
            (:func:`preset_names`). Sources are in ``rust/imu/presets.rs``.

        Returns
        -------
        ImuErrors
            A copy: changing it changes no preset.
        """
        if not isinstance(preset, str):
            raise TypeError(f"preset: expected a str, got {type(preset).__name__}")
        choice(preset, preset_names(), "preset")
        if preset in _USER_PRESETS:
            return copy.deepcopy(_USER_PRESETS[preset])
        a, g = _core.imu_preset(preset)
        return cls(TriadErrors._from_core(a), TriadErrors._from_core(g))

    def summary(self) -> pd.DataFrame:
        """The parameters in SI and in the units datasheets use.

        Returns
        -------
        DataFrame
            One row per (sensor, parameter), columns ``sensor``, ``parameter``,
            ``value_si``, ``unit_si``, ``value_field``, ``unit_field``; field units µg,
            µg/√Hz, µg/√h, °/h, °/√h, °/h/√h.
        """
        sqrt_h = np.sqrt(units.HOUR)
        out = []
        for sensor, t, si, u, u_name, dens, dens_name in (
            ("accel", self.accel, "m/s^2", units.MICRO_G, "ug", units.MICRO_G_PER_SQRT_HZ, "ug/sqrt(Hz)"),
            ("gyro", self.gyro, "rad/s", units.DEG_PER_HOUR, "deg/h", units.DEG_PER_SQRT_HOUR, "deg/sqrt(h)"),
        ):
            gm, fl = t._terms(sensor)
            items = [(f"bias_{a}", b, si, b / u, u_name) for a, b in zip(_AXES, t.bias)]
            items += [
                ("bias_sigma", t.bias_sigma, si, t.bias_sigma / u, u_name),
                ("white", t.white, f"{si}*sqrt(s)", t.white / dens, dens_name),
                ("bias_rw", t.bias_rw, f"{si}/sqrt(s)", t.bias_rw * sqrt_h / u, f"{u_name}/sqrt(h)"),
                ("gauss_markov_sigma", gm.sigma if gm else 0.0, si, (gm.sigma if gm else 0.0) / u, u_name),
                ("flicker_b", fl.b if fl else 0.0, si, (fl.b if fl else 0.0) / u, u_name),
            ]
            out += [dict(sensor=sensor, parameter=p, value_si=v, unit_si=us, value_field=vf, unit_field=uf) for p, v, us, vf, uf in items]
        return pd.DataFrame(out)


def preset_names() -> list[str]:
    """The names :meth:`ImuErrors.preset` accepts.

    Returns
    -------
    list of str
        Built-in preset names followed by user-registered ones.
    """
    return list(_core.imu_preset_names()) + list(_USER_PRESETS)


def register_preset(name: str, errors: ImuErrors) -> None:
    """Add a named user preset (validated; a built-in name cannot be replaced).

    Parameters
    ----------
    name : str
        The preset's name, for :meth:`ImuErrors.preset`.
    errors : ImuErrors
        The error model; a copy is kept.
    """
    if not isinstance(name, str):
        raise TypeError(f"name: expected a str, got {type(name).__name__}")
    if name in _core.imu_preset_names():
        raise input_error("name", f"{name!r} is a built-in preset and cannot be replaced")
    _USER_PRESETS[str(name)] = copy.deepcopy(instance(errors, ImuErrors, "errors").validate())


class ImuSimulator(Stateful):
    """Seeded, stateful corruption of an ideal IMU stream. Successive :meth:`corrupt`
    calls continue the random processes, so chunks give the numbers of one batch call.

    ``kind``, ``dt`` and ``errors`` are fixed at construction (read-only: build a new
    simulator for another kind). One simulator may be shared by threads (calls run one
    after another) and pickled or deep-copied mid-record: the copy continues the same
    random streams bit for bit.

    Parameters
    ----------
    errors : ImuErrors or str
        The error model, or the name of a preset (:func:`preset_names`); a copy is kept.
    dt : float
        Sampling interval (s).
    kind : str, optional
        Output kind, ``"rates"`` or ``"increments"``. None (default) takes the kind of the
        column names of the first DataFrame :meth:`corrupt` reads
        (:func:`atomnav.trajectory.imu_kind`) and fixes it then (:attr:`kind` is None
        until then); arrays need ``kind`` given here.
    seed : int
        Master seed of the random streams (module docstring).

    Warns
    -----
    atomnav.UnitWarning
        ``dt`` beyond 1 s, likely in ms (:func:`atomnav.plausibility.sample_interval`).
    """

    def __init__(self, errors: ImuErrors | str, dt: float, kind: str | None = None, seed: int = 0):
        if isinstance(errors, str):
            with renamed(preset="errors"):
                errors = ImuErrors.preset(errors)
        instance(errors, ImuErrors, "errors")
        self._dt = scalar(dt, "dt")
        self._errors = copy.deepcopy(errors)
        self._seed = seed  # to draw the same streams for the kind of the first table when none is given
        self._sim = _core.ImuErrorSimulator(*errors._to_core(), self._dt, "rates" if kind is None else kind, seed)
        self._kind = kind
        plausibility.sample_interval(self._dt, "dt")
        self._k = 0

    @property
    def kind(self) -> str | None:
        """Output kind, ``"rates"`` or ``"increments"`` (read-only; None until the first
        table when not given)."""
        return self._kind

    @property
    def dt(self) -> float:
        """Sampling interval (s, read-only)."""
        return self._dt

    @property
    def errors(self) -> ImuErrors:
        """A copy of the error model (changing it does not change this simulator)."""
        return copy.deepcopy(self._errors)

    @serialized
    def corrupt(self, accel, gyro=None) -> pd.DataFrame:
        """Corrupt the next chunk.

        Parameters
        ----------
        accel : array_like (N, 3) or DataFrame
            True specific force (m/s²), or Δv (m/s) for increments; or one DataFrame with
            the stream columns of this kind (module docstring), read by name (extra
            columns ignored; with ``kind=None`` the first one fixes the kind); its errors
            name ``accel`` and the column.
        gyro : array_like (N, 3), optional
            True angular rate (rad/s), or Δθ (rad) for increments; required with an array
            ``accel``, None with a DataFrame.

        Returns
        -------
        DataFrame
            Indexed by the running sample number: the measured columns (same names as the
            input) and the bias truth columns :data:`BIAS_COLUMNS`. A ``time_s`` column is
            carried through as given (datetime64 included). No other column is carried: a
            time column under another name (``time``) is ignored like any extra column,
            and the output then has none.
        """
        sim, kind = self._sim, self._kind
        if kind is None:  # the first table fixes the kind; no sample was drawn yet
            kind = imu_kind(None, accel, "accel")
            if kind != "rates":
                sim = _core.ImuErrorSimulator(*self._errors._to_core(), self._dt, kind, self._seed)
        fcols, wcols = COLUMNS[kind]
        gyro_name = "accel" if gyro is None else "gyro"  # a DataFrame in accel holds the gyro too
        t = None
        if isinstance(accel, pd.DataFrame):
            if gyro is not None:
                raise input_error("gyro", "must be None when accel is a DataFrame")
            df = accel
            measured = table(df, fcols + wcols, "accel")  # by name: order and extra columns do not matter
            accel, gyro = measured[:, :3], measured[:, 3:]
            if "time_s" in df.columns:  # carried through as given; read in seconds (type-checked) for the checks
                time_column = df.iloc[:, locate(df, ["time_s"], "accel")[0]]
                t = seconds(time_column, "accel", "time_s")
        elif gyro is None:
            raise input_error("gyro", "required when accel is an array")
        f, w = rows(accel, 3, "accel"), rows(gyro, 3, "gyro")
        if len(w) != len(f):
            raise input_error("gyro", f"expected {len(f)} rows like accel, got {len(w)}")
        plausibility.imu(t, w, f, kind, "accel", gyro_name=gyro_name, dt=self.dt)
        fm, wm, fb, wb = sim.corrupt(f, w)
        self._sim, self._kind = sim, kind
        index = pd.RangeIndex(self._k, self._k + len(f), name="sample")
        self._k += len(f)
        df = pd.DataFrame(np.hstack([fm, wm, fb, wb]), columns=fcols + wcols + BIAS_COLUMNS[0] + BIAS_COLUMNS[1], index=index)
        if t is not None:
            df.insert(0, "time_s", time_column.to_numpy())
        return df


def corrupt(accel, gyro=None, *, errors: ImuErrors | str, dt: float, kind: str | None = None, seed: int = 0) -> pd.DataFrame:
    """One-shot :class:`ImuSimulator` ``(errors, dt, kind, seed).corrupt(accel, gyro)``.

    Parameters
    ----------
    accel, gyro
        As for :meth:`ImuSimulator.corrupt`: (N, 3) arrays of true specific force (m/s²)
        and angular rate (rad/s), or Δv (m/s) and Δθ (rad); or one DataFrame in ``accel``.
    errors, dt, seed
        As for :class:`ImuSimulator`: the error model (or a preset name), the sampling
        interval (s) and the master seed.
    kind : str, optional
        ``"rates"`` or ``"increments"``; None (default) is the kind of the column names of
        the DataFrame ``accel`` (:func:`atomnav.trajectory.imu_kind`), and arrays need
        ``kind``.

    Returns
    -------
    DataFrame
        As :meth:`ImuSimulator.corrupt` returns it.
    """
    return ImuSimulator(errors, dt, imu_kind(kind, accel, "accel"), seed).corrupt(accel, gyro)


def white_sigma(density: float, dt: float, kind: str = "rates") -> float:
    """Per-sample σ of white noise of density N at interval Δt: N/√Δt (rates) or N·√Δt
    (increments).

    Parameters
    ----------
    density : float
        Density N (m/s/√s or rad/√s).
    dt : float
        Sample interval Δt (s).
    kind : str
        ``"rates"`` (default) or ``"increments"``.

    Returns
    -------
    float
        σ per sample: m/s² or rad/s (rates), m/s or rad (increments).
    """
    return _core.imu_white_sigma(scalar(density, "density"), scalar(dt, "dt"), kind)


def white_density(sigma: float, dt: float, kind: str = "rates") -> float:
    """Density N of white noise with per-sample σ at Δt (inverse of :func:`white_sigma`).

    Parameters
    ----------
    sigma : float
        σ per sample: m/s² or rad/s (rates), m/s or rad (increments).
    dt : float
        Sample interval Δt (s).
    kind : str
        ``"rates"`` (default) or ``"increments"``.

    Returns
    -------
    float
        Density N (m/s/√s or rad/√s).
    """
    return _core.imu_white_density(scalar(sigma, "sigma"), scalar(dt, "dt"), kind)


def random_walk_step_sigma(density: float, dt: float) -> float:
    """σ of the per-sample bias step K·√Δt of a random walk of density K.

    Parameters
    ----------
    density : float
        Density K (m/s²/√s or rad/s/√s).
    dt : float
        Sample interval Δt (s).

    Returns
    -------
    float
        σ of the bias step per sample (m/s² or rad/s).
    """
    return _core.imu_random_walk_step_sigma(scalar(density, "density"), scalar(dt, "dt"))


def random_walk_density(step_sigma: float, dt: float) -> float:
    """Density K of a random walk whose per-sample step has σ ``step_sigma`` at Δt
    (inverse of :func:`random_walk_step_sigma`).

    Parameters
    ----------
    step_sigma : float
        σ of the bias step per sample (m/s² or rad/s).
    dt : float
        Sample interval Δt (s).

    Returns
    -------
    float
        Density K (m/s²/√s or rad/s/√s).
    """
    return _core.imu_random_walk_density(scalar(step_sigma, "step_sigma"), scalar(dt, "dt"))


def gauss_markov_driving_sigma(sigma: float, tau: float, dt: float) -> float:
    """Per-sample driving σ_u = σ√(1 − e^{−2Δt/τ}) of m_{k+1} = e^{−Δt/τ} m_k + u_k.

    Parameters
    ----------
    sigma : float
        Stationary σ (m/s² or rad/s).
    tau : float
        Correlation time τ (s).
    dt : float
        Sample interval Δt (s).

    Returns
    -------
    float
        σ_u (m/s² or rad/s).
    """
    return _core.imu_gauss_markov_driving_sigma(scalar(sigma, "sigma"), scalar(tau, "tau"), scalar(dt, "dt"))


def gauss_markov_sigma(driving_sigma: float, tau: float, dt: float) -> float:
    """Stationary σ of the discrete Gauss–Markov with per-sample driving σ_u at Δt
    (inverse of :func:`gauss_markov_driving_sigma`).

    Parameters
    ----------
    driving_sigma : float
        σ_u (m/s² or rad/s).
    tau : float
        Correlation time τ (s).
    dt : float
        Sample interval Δt (s).

    Returns
    -------
    float
        Stationary σ (m/s² or rad/s).
    """
    return _core.imu_gauss_markov_sigma(scalar(driving_sigma, "driving_sigma"), scalar(tau, "tau"), scalar(dt, "dt"))


def gauss_markov_low_freq_asd(sigma: float, tau: float) -> float:
    """Low-frequency amplitude spectral density σ√(2τ) of a Gauss–Markov process.

    Parameters
    ----------
    sigma : float
        Stationary σ (m/s² or rad/s).
    tau : float
        Correlation time τ (s).

    Returns
    -------
    float
        ASD (m/s²/√Hz or rad/s/√Hz).
    """
    return _core.imu_gauss_markov_low_freq_asd(scalar(sigma, "sigma"), scalar(tau, "tau"))


def flicker_psd(b: float, f: float) -> float:
    """One-sided PSD B²/(πf) of flicker noise of bias instability B.

    Parameters
    ----------
    b : float
        Bias instability B (m/s² or rad/s).
    f : float
        Frequency (Hz).

    Returns
    -------
    float
        PSD ((m/s²)²/Hz or (rad/s)²/Hz).
    """
    return _core.imu_flicker_psd(scalar(b, "b"), scalar(f, "f"))


def flicker_allan_floor(b: float) -> float:
    """Allan-deviation floor B·√(2 ln 2/π) of flicker noise.

    Parameters
    ----------
    b : float
        Bias instability B (m/s² or rad/s).

    Returns
    -------
    float
        Allan deviation floor (m/s² or rad/s).
    """
    return _core.imu_flicker_allan_floor(scalar(b, "b"))
