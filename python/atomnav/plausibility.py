"""Unit plausibility warnings: values that are valid numbers but implausible in their
declared SI unit, because they were given in another unit (g for m/s², °/s for rad/s, ms
for s, degrees for rad, nm for m, % for a fraction).

Such a value passes every range check and gives a wrong answer without a word (an IMU
table in g instead of m/s² at rest integrates to a height error of ½(9.8 − 1) m/s² × (10 s)²
= −440 m after 10 s), so each
check below raises a :class:`UnitWarning` naming the argument, the likely unit and the
factor that converts it to SI. The warning goes through the standard :mod:`warnings`
machinery and points at the user's line (the first frame outside atomnav)::

    import warnings, atomnav
    warnings.simplefilter("ignore", atomnav.UnitWarning)   # silence it
    warnings.simplefilter("error", atomnav.UnitWarning)    # make it an exception

Every threshold is a constant of this module, with the reason for its value. The checks
read cheap statistics computed once per call (the median of the first :data:`STEP_ROWS`
time steps, a mean, a spread or a maximum over at most :data:`SAMPLE_ROWS` evenly spaced
rows of a long record: a record in the wrong unit is wrong in most of its rows, and a
pass over every row cost 3 % of a strapdown run); non-finite
values are left to the input checks, which reject them. A value is flagged only when it
is beyond its SI limit and, multiplied by the factor, within it (a T of 100 is 100 ms; a T
of 1e300 is no plausible time in any unit, and is left to the input checks).
"""

from __future__ import annotations

import os
import sys
import warnings

import numpy as np

from . import _core, units
from ._validate import as_floats

#: Earth's rotation rate ω_ie (rad/s, WGS-84), from the core's ellipsoid constants.
EARTH_RATE: float = _core.ellipsoid_constants("WGS84")["omega"]

#: The mean specific-force magnitude of an Earth-bound record in m/s² is gravity, 9.78 to
#: 9.83 m/s², give or take the vehicle's mean acceleration over the record. A mean in this
#: band (m/s²) is the same record in g: 1 g at rest, up to 0.25 g more or 0.2 g less on
#: average while moving. No SI record is there short of near free fall.
ACCEL_G_BAND: tuple[float, float] = (0.8, 1.25)

#: Largest plausible angular rate (rad/s): ≈ 2000 °/s, the full range of a consumer MEMS
#: gyro; the fastest real platforms (spinning projectiles aside) rotate below it. A rate
#: beyond it is in °/s.
MAX_ANGULAR_RATE: float = 35.0

#: A static gyro reads Earth rate, 7.292115e-5 rad/s; in °/s the same reading is 57.3 times
#: larger, 4.18e-3. A static record whose mean rate is within this relative tolerance of
#: the latter is in °/s. 15 % covers the mean of a tactical-grade gyro (ARW 0.1 °/√h, bias
#: 1 °/h) over 100 s at 100 Hz; a navigation-grade one is within 1 %.
EARTH_RATE_TOLERANCE: float = 0.15

#: The static mean is compared with Earth rate in °/s within :data:`EARTH_RATE_TOLERANCE`
#: plus this many standard errors of the mean (the white-noise variance of the record over
#: its row count): a short record's mean scatters by its noise (a tactical gyro over 10 s
#: at 100 Hz: 12 % of Earth rate per axis), a long one's by its bias only.
EARTH_RATE_SIGMAS: float = 3.0

#: A record is static for the Earth-rate test when the variance of its angular rate about
#: the mean is at most this many times its white-noise variance (half the mean square of
#: successive differences, von Neumann 1941): at rest the rate varies by its sensor noise
#: only (ratio ≈ 1), while a moving platform's rate varies smoothly, far more over the
#: record than from one sample to the next.
STATIC_VARIANCE_RATIO: float = 4.0

#: Longest plausible IMU sample interval (s): strapdown IMUs sample at 1 Hz (satellite
#: accelerometers) or faster, so a step above 1 s is a millisecond time stamp (a 100 Hz log
#: stamped in ms steps by 10).
MAX_IMU_STEP: float = 1.0

#: Relative tolerance of a stated IMU interval ``dt`` against the median step of the
#: record's own time stamps: a 10 % difference is no clock jitter but a wrong ``dt`` (or a
#: factor 1000 within it: one of the two in ms).
STEP_TOLERANCE: float = 0.1

#: Largest plausible angle (rad) for a longitude or an Euler angle: one turn, 2π. Beyond
#: it the value is in degrees (37.6 for Moscow's longitude). A latitude in degrees beyond
#: π/2 is already an error of the input checks.
MAX_ANGLE: float = 2.0 * np.pi

#: Longest plausible atom-interferometer pulse separation T (s): fountains and drop towers
#: reach about 1 s, the long-baseline space proposals a few s; 10 s is beyond all of them,
#: so a larger T is in ms (T = 100 for 100 ms).
MAX_PULSE_SEPARATION: float = 10.0

#: Longest plausible laser wavelength (m): 100 µm, beyond the far infrared of any atom
#: interferometer (⁸⁷Rb: 780 nm). A larger "wavelength" is in nm (780.241).
MAX_WAVELENGTH: float = 1e-4

#: A fringe contrast, an offset or a probability is a fraction in [0, 1]; beyond 1 it is a
#: percentage (contrast 50 for 50 %).
MAX_FRACTION: float = 1.0

#: A measured population is a fraction in [0, 1] plus readout noise of a few per cent
#: (σ_p ≈ 0.03 in Tennstedt et al. 2021 and 2023); beyond 1.5 it is no noise but a
#: percentage.
MAX_POPULATION: float = 1.5

#: Statistics of long records (means, spreads) are read from at most this many evenly
#: spaced rows, so a check costs the same on any record length.
SAMPLE_ROWS: int = 2000

#: The sample interval of a record is the median of its first this many time steps (10 s
#: at 100 Hz: any gap or jitter is outvoted).
STEP_ROWS: int = 1_000

_DEG = units.DEG
_MS = 1e-3
_PACKAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "")


class UnitWarning(UserWarning):
    """A value is implausible in its declared unit.

    Attributes
    ----------
    parameter : str
        The argument of the function the user called.
    unit : str or None
        The unit the value most likely is in (``"g"``, ``"deg/s"``, ``"ms"``, ``"deg"``,
        ``"nm"``, ``"%"``), None when only a contradiction is known.
    factor : float
        Multiply the value by this to get the declared SI unit.
    """

    def __init__(self, message: str, parameter: str, unit: str | None, factor: float):
        super().__init__(message)
        self.parameter, self.unit, self.factor = parameter, unit, factor

    def __reduce__(self):
        return type(self), (str(self), self.parameter, self.unit, self.factor)


def _warn(parameter: str, quantity: str, unit: str | None, si: str, evidence: str, factor: float) -> None:
    """Warn that ``quantity`` of argument ``parameter`` is likely in ``unit`` rather than
    ``si`` (or, with no ``unit``, contradicts ``si``), shown at the first frame outside
    atomnav (the user's line)."""
    frame, level = sys._getframe(0), 1
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    looks = f"likely in {unit}, not {si}" if unit else f"contradicts {si}"
    message = f"{parameter}: {quantity} {looks} ({evidence}); multiply by {factor:.6g}"
    warnings.warn(UnitWarning(message, parameter, unit, factor), stacklevel=level)


def _floats(x) -> np.ndarray:
    """``x`` as a float array, empty if it is not numbers (the input checks report that)."""
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        return np.empty(0)


def _columns(a) -> np.ndarray:
    """The columns (3, n) of at most :data:`SAMPLE_ROWS` evenly spaced rows of an (N, 3)
    array ``a``, each contiguous (empty if ``a`` is not such an array of numbers)."""
    a = _floats(a)
    if a.ndim != 2 or a.shape[1] != 3 or not len(a):
        return np.empty((3, 0))
    return np.ascontiguousarray(a[:: max(1, len(a) // SAMPLE_ROWS)].T)


def _rows_sample(a):
    """At most :data:`SAMPLE_ROWS` evenly spaced rows of ``a`` (``a`` itself if it has fewer
    rows, or is not an array of rows)."""
    a = _floats(a)
    return a[:: max(1, len(a) // SAMPLE_ROWS)] if a.ndim == 2 else a


def _max_abs(a) -> float:
    """Largest magnitude in ``a`` (NaN if ``a`` is empty or holds a non-finite value)."""
    a = _floats(a)
    if a.size == 0:
        return np.nan
    m = max(float(a.max()), -float(a.min()))
    return m if np.isfinite(m) else np.nan


def _value(x) -> float:
    """A scalar ``x`` as a float (NaN if it is not one finite number)."""
    a = _floats(x)
    return float(a) if a.size == 1 and a.ndim == 0 and np.isfinite(a) else np.nan


def _median_step(t: np.ndarray) -> float:
    """Median time step (s) of the first :data:`STEP_ROWS` steps of ``t`` (NaN for fewer
    than two samples or non-finite stamps)."""
    t = _floats(t).reshape(-1)[: STEP_ROWS + 1]
    if len(t) < 2:
        return np.nan
    with np.errstate(all="ignore"):
        step = float(np.median(np.diff(t)))
    return step if np.isfinite(step) else np.nan


def _converts(value: float, limit: float, factor: float) -> bool:
    """``value`` is beyond ``limit`` in the declared unit, but within it once multiplied by
    ``factor`` (False for NaN)."""
    return limit < value and value * factor <= limit


def _near(value: float, target: float, tolerance: float) -> bool:
    return abs(value - target) <= tolerance * target


def _mean_norm(v: np.ndarray, scale: float) -> float:
    """Mean magnitude of the rows of ``v`` (N, 3) times ``scale`` (NaN if empty)."""
    x, y, z = _columns(v)
    if not len(x):
        return np.nan
    with np.errstate(all="ignore"):
        return float(np.sqrt(x * x + y * y + z * z).mean()) * _value(scale)


def _rate_scale(kind, step: float) -> float:
    """The factor from an IMU record of ``kind`` to rates: 1 for rates, 1/``step`` for
    increments (NaN without a usable median step, s)."""
    if isinstance(kind, str) and kind == "rates":
        return 1.0
    return 1.0 / step if np.isfinite(step) and step > 0 else np.nan


def swapped_blocks(time, gyro, accel, kind: str) -> str | None:
    """Evidence that the gyro and accel blocks of a plain IMU array were given in the other
    order (time, accel, gyro: the stream order of :data:`atomnav.imu.COLUMNS`).

    Read that way, the "gyro" block is a specific force: its mean magnitude is gravity,
    :data:`ACCEL_G_BAND` in m/s² (a sustained 450 to 700 °/s as a rate, which no navigation
    record has on average), while the "accel" block is an angular rate, below the band's
    lower end, where an Earth-bound specific force never is. Both at once is the swap.

    Parameters
    ----------
    time : array_like (N,)
        Time stamps (s), as read.
    gyro, accel : array_like (N, 3)
        The gyro and accel blocks as read, of ``kind``.
    kind : str
        ``"rates"`` (rad/s, m/s²) or ``"increments"`` (rad, m/s; scaled to rates by the
        median time step).

    Returns
    -------
    str or None
        The evidence (the two mean magnitudes), or None when the blocks are not swapped.

    Raises
    ------
    TypeError
        Anything that is not numbers (strings included), naming its argument.
    """
    time, gyro, accel = as_floats(time, "time"), as_floats(gyro, "gyro"), as_floats(accel, "accel")
    low, high = ACCEL_G_BAND[0] * units.G0, ACCEL_G_BAND[1] * units.G0
    scale = _rate_scale(kind, _median_step(time))
    rate, force = _mean_norm(gyro, scale), _mean_norm(accel, scale)
    if low <= rate <= high and force < low:
        return f"mean |gyro| = {rate:.3g} rad/s, Earth's gravity in m/s²; mean |accel| = {force:.3g} m/s², a rate"
    return None


def specific_force(f: np.ndarray, name: str, scale: float = 1.0) -> None:
    """Warn if a specific force has a mean magnitude in :data:`ACCEL_G_BAND`: the record
    is in g.

    Parameters
    ----------
    f : array_like (N, 3)
        Specific force (m/s²) or Δv (m/s).
    name : str
        The argument of the function the user called, named in the warning.
    scale : float
        Factor to m/s²: 1 for a specific force, 1/Δt (1/s) for Δv.

    Raises
    ------
    TypeError
        An ``f`` that is not numbers (strings included), naming ``f``.

    Warns
    -----
    UnitWarning
        The mean magnitude is gravity in g.
    """
    mean = _mean_norm(as_floats(f, "f"), scale)
    if ACCEL_G_BAND[0] <= mean <= ACCEL_G_BAND[1]:
        _warn(name, "specific force", "g", "m/s²", f"mean |f| = {mean:.3g}, Earth's gravity is 9.8 m/s²", units.G0)


def angular_rate(w, name: str, scale: float = 1.0, *, static: bool = False):
    """Warn if an angular rate is in °/s: it exceeds :data:`MAX_ANGULAR_RATE` anywhere
    or, with ``static``, it is static with a mean of 57.3 × Earth rate.

    Parameters
    ----------
    w : array_like (N, 3)
        Angular rate (rad/s) or Δθ (rad).
    name : str
        The argument of the function the user called, named in the warning.
    scale : float
        Factor to rad/s: 1 for rates, 1/Δt (1/s) for Δθ.
    static : bool
        ``w`` is a full IMU record that may be at rest: also test its mean against Earth
        rate in °/s (:data:`EARTH_RATE_TOLERANCE`, :data:`EARTH_RATE_SIGMAS`,
        :data:`STATIC_VARIANCE_RATIO`).

    Returns
    -------
    array_like
        ``w``, unchanged.

    Raises
    ------
    TypeError
        A ``w`` that is not numbers (strings included), naming ``name``.

    Warns
    -----
    UnitWarning
        The rate is likely in °/s.
    """
    scale = _value(scale)
    peak = _max_abs(_rows_sample(as_floats(w, name))) * scale
    if _converts(peak, MAX_ANGULAR_RATE, _DEG):
        _warn(name, "angular rate", "deg/s", "rad/s", f"max |ω| = {peak:.4g}, beyond {MAX_ANGULAR_RATE} rad/s", _DEG)
    elif static is True and (s := _columns(w)).size:
        with np.errstate(all="ignore"):
            mean = s.mean(axis=1)
            norm = float(np.sqrt(mean @ mean)) * scale
            noise = _white_variance(s) * scale * scale
            spread = EARTH_RATE_SIGMAS * float(np.sqrt(noise / s.shape[1]))
        if abs(norm - EARTH_RATE / _DEG) <= EARTH_RATE_TOLERANCE * EARTH_RATE / _DEG + spread and _static(s, mean):
            _warn(name, "angular rate", "deg/s", "rad/s",
                  f"static mean |ω| = {norm:.4g}, Earth rate is {EARTH_RATE:.4g} rad/s = {EARTH_RATE / _DEG:.4g} °/s", _DEG)
    return w


def _white_variance(s: np.ndarray) -> float:
    """White-noise variance of rates ``s`` (3, n), summed over the axes: half the mean square
    of successive differences (von Neumann 1941); 0 for one row."""
    if s.shape[1] < 2:
        return 0.0
    with np.errstate(all="ignore"):
        return float((np.diff(s, axis=1) ** 2).mean(axis=1).sum()) / 2


def _static(s: np.ndarray, mean: np.ndarray) -> bool:
    """Rates ``s`` (3, n) with means ``mean`` (3,) vary about them by no more than
    :data:`STATIC_VARIANCE_RATIO` times their white noise (or by rounding only)."""
    with np.errstate(all="ignore"):
        variance = float(s.var(axis=1).sum())
    noise = _white_variance(s)
    rounding = float(1e-9**2 * (mean @ mean))  # a noise-free constant rate varies by its rounding only
    return variance <= STATIC_VARIANCE_RATIO * noise + rounding


def time_steps(t, name: str):
    """Warn if the median step of IMU time stamps exceeds :data:`MAX_IMU_STEP`: they are
    in ms.

    Parameters
    ----------
    t : array_like (N,)
        Time stamps (s).
    name : str
        The argument of the function the user called, named in the warning.

    Returns
    -------
    array_like
        ``t``, unchanged.

    Raises
    ------
    TypeError
        A ``t`` that is not numbers (strings included), naming ``name``.

    Warns
    -----
    UnitWarning
        The time stamps are likely in ms.
    """
    _step(_median_step(as_floats(t, name)), name)
    return t


def _step(step: float, name: str) -> None:
    """:func:`time_steps` of a median step ``step`` (s)."""
    if _converts(step, MAX_IMU_STEP, _MS):
        _warn(name, "time stamps", "ms", "s", f"median step {step:.4g}, an IMU samples at least every {MAX_IMU_STEP} s", _MS)


def sample_interval(dt, name: str):
    """Warn if an IMU sample interval exceeds :data:`MAX_IMU_STEP`: it is in ms.

    Parameters
    ----------
    dt : float
        Sample interval (s).
    name : str
        The argument of the function the user called, named in the warning.

    Returns
    -------
    float
        ``dt``, unchanged.

    Warns
    -----
    UnitWarning
        The interval is likely in ms.
    """
    if _converts(_value(dt), MAX_IMU_STEP, _MS):
        _warn(name, "sample interval", "ms", "s", f"{_value(dt):.4g} s, an IMU samples at least every {MAX_IMU_STEP} s", _MS)
    return dt


def _stated_interval(step: float, dt: float, name: str, dt_name: str) -> None:
    """Warn if the stated interval ``dt`` (argument ``dt_name``) and the median ``step`` of
    the time stamps (argument ``name``) differ by more than :data:`STEP_TOLERANCE`, naming
    the one in ms when they differ by a factor 1000."""
    if not (np.isfinite(step) and step > 0 and np.isfinite(dt) and dt > 0):
        return
    ratio = step / dt
    evidence = f"median time_s step {step:.4g} vs dt = {dt:.4g} s"
    if _near(ratio, 1 / _MS, STEP_TOLERANCE):
        _warn(name, "time stamps", "ms", "s", evidence, _MS)
    elif _near(ratio, _MS, STEP_TOLERANCE):
        _warn(dt_name, "sample interval", "ms", "s", evidence, _MS)
    elif not _near(ratio, 1.0, STEP_TOLERANCE):
        _warn(dt_name, "sample interval", None, "the time stamps", evidence, ratio)


def imu(time, gyro, accel, kind: str, name: str = "imu", *, gyro_name: str | None = None, time_name: str | None = None,
        dt: float | None = None) -> None:
    """All checks of one IMU record: specific force in g, angular rate in °/s, time
    stamps or a stated interval in ms.

    Parameters
    ----------
    time : array_like (N,) or None
        Time stamps (s).
    gyro, accel : array_like (N, 3)
        Of ``kind``: rates (rad/s, m/s²) or increments (rad, m/s over the sample
        interval).
    kind : str
        ``"rates"`` or ``"increments"``.
    name : str
        The argument holding the record (and its accelerations).
    gyro_name, time_name : str, optional
        The arguments holding the gyro and the time stamps, if they differ from ``name``.
    dt : float, optional
        The stated sample interval (s), compared with the time stamps when both are given.

    Raises
    ------
    TypeError
        A ``time``, ``gyro`` or ``accel`` that is not numbers (strings included), naming
        it.

    Warns
    -----
    UnitWarning
        A value likely in g, °/s or ms, or a ``dt`` that contradicts the time stamps.
    """
    time, gyro, accel = (None if time is None else as_floats(time, "time")), as_floats(gyro, "gyro"), as_floats(accel, "accel")
    gyro_name = name if gyro_name is None else gyro_name
    time_name = name if time_name is None else time_name
    step = np.nan if time is None else _median_step(time)
    if dt is not None:
        dt = _value(dt)
        _stated_interval(step, dt, time_name, "dt")
        step = dt
    else:
        _step(step, time_name)
    scale = _rate_scale(kind, step)
    if not np.isfinite(scale):
        return  # no interval to turn increments into rates
    specific_force(accel, name, scale)
    angular_rate(gyro, gyro_name, scale, static=True)


def longitude(lon, name: str):
    """Warn if a longitude exceeds :data:`MAX_ANGLE` in magnitude: it is in degrees.

    Parameters
    ----------
    lon : float or array_like
        Longitude(s) (rad), any shape.
    name : str
        The argument of the function the user called, named in the warning.

    Returns
    -------
    float or array_like
        ``lon``, unchanged.

    Warns
    -----
    UnitWarning
        The longitude is likely in degrees.
    """
    peak = _max_abs(lon)
    if _converts(peak, MAX_ANGLE, _DEG):
        _warn(name, "longitude", "deg", "rad", f"|lon| = {peak:.4g}, beyond 2π", _DEG)
    return lon


def lla(p, name: str):
    """:func:`longitude` of positions, unless a latitude is beyond ±π/2 (an input error
    of its own).

    Parameters
    ----------
    p : array_like (..., 3)
        Positions: latitude (rad), longitude (rad), height (m).
    name : str
        The argument of the function the user called, named in the warning.

    Returns
    -------
    array_like
        ``p``, unchanged.

    Warns
    -----
    UnitWarning
        A longitude is likely in degrees.
    """
    a = _floats(p)
    if a.ndim and a.shape[-1] == 3 and a.size and not _max_abs(a[..., 0]) > np.pi / 2:
        longitude(a[..., 1], name)
    return p


def angles(a, name: str, quantity: str = "Euler angles"):
    """Warn if any angle exceeds :data:`MAX_ANGLE` in magnitude: it is in degrees.

    Parameters
    ----------
    a : float or array_like
        Angles (rad), any shape.
    name : str
        The argument of the function the user called, named in the warning.
    quantity : str
        What the angles are, for the message.

    Returns
    -------
    float or array_like
        ``a``, unchanged.

    Warns
    -----
    UnitWarning
        The angles are likely in degrees.
    """
    peak = _max_abs(a)
    if _converts(peak, MAX_ANGLE, _DEG):
        _warn(name, quantity, "deg", "rad", f"max |angle| = {peak:.4g}, beyond 2π", _DEG)
    return a


def pulse_separation(T, name: str, pulses: float = 1.0):
    """Warn if an interferometer time exceeds ``pulses`` × :data:`MAX_PULSE_SEPARATION`:
    it is in ms.

    Parameters
    ----------
    T : float
        Interferometer time (s).
    name : str
        The argument of the function the user called, named in the warning.
    pulses : float
        Pulse separations ``T`` spans (2 for a total interrogation time 2T).

    Returns
    -------
    float
        ``T``, unchanged.

    Warns
    -----
    UnitWarning
        The time is likely in ms.
    """
    limit = _value(pulses) * MAX_PULSE_SEPARATION
    if _converts(_value(T), limit, _MS):
        _warn(name, "pulse timing", "ms", "s", f"{_value(T):.4g} s, beyond {limit:g} s", _MS)
    return T


def wavelength(x, name: str):
    """Warn if a laser wavelength exceeds :data:`MAX_WAVELENGTH`: it is in nm.

    Parameters
    ----------
    x : float
        Wavelength (m).
    name : str
        The argument of the function the user called, named in the warning.

    Returns
    -------
    float
        ``x``, unchanged.

    Warns
    -----
    UnitWarning
        The wavelength is likely in nm.
    """
    if _converts(_value(x), MAX_WAVELENGTH, 1e-9):
        _warn(name, "wavelength", "nm", "m", f"{_value(x):.6g} m, beyond {MAX_WAVELENGTH:g} m", 1e-9)
    return x


def fraction(x, name: str, quantity: str = "fraction"):
    """Warn if a contrast, offset or probability exceeds :data:`MAX_FRACTION`: it is in %.

    Parameters
    ----------
    x : float or array_like
        Fraction(s) in [0, 1], any shape.
    name : str
        The argument of the function the user called, named in the warning.
    quantity : str
        What the values are, for the message.

    Returns
    -------
    float or array_like
        ``x``, unchanged.

    Warns
    -----
    UnitWarning
        The values are likely in %.
    """
    peak = _max_abs(x)
    if _converts(peak, MAX_FRACTION, 0.01):
        _warn(name, quantity, "%", "a fraction in [0, 1]", f"{peak:.4g}", 0.01)
    return x


def population(p, name: str):
    """Warn if a measured population exceeds :data:`MAX_POPULATION`: it is in %.

    Parameters
    ----------
    p : float or array_like
        Population(s), fractions in [0, 1] plus readout noise, any shape.
    name : str
        The argument of the function the user called, named in the warning.

    Returns
    -------
    float or array_like
        ``p``, unchanged.

    Warns
    -----
    UnitWarning
        The populations are likely in %.
    """
    peak = _max_abs(p)
    if _converts(peak, MAX_POPULATION, 0.01):
        _warn(name, "population", "%", "a fraction in [0, 1]", f"max {peak:.4g}", 0.01)
    return p
