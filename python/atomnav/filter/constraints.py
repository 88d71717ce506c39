"""Vehicle and pedestrian constraints (Rust core, ``rust/filter/constraints.rs``).

- :func:`detect_still` finds the still periods of an IMU record, from which
  :class:`StillPeriods` makes zero-velocity (ZUPT) and zero-angular-rate (ZARU) updates;
- :class:`NonHolonomic` is the non-holonomic constraint of a wheeled vehicle.

Both feed :func:`atomnav.filter.aided_ins` like any other source.

>>> still = detect_still(t, gyro, accel, kind="rates", lla=lla0)          # doctest: +SKIP
>>> ins = aided_ins(setup, [fixes, still.zero_velocity(0.02),
...                         NonHolonomic(t[::10], 0.1)])                  # doctest: +SKIP

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
Systems*, 2nd ed. (2013), ch. 15 (zero updates and motion constraints).
I. Skog, P. Händel, J.-O. Nilsson, J. Rantakokko, "Zero-velocity detection — an
algorithm evaluation", IEEE Trans. Biomed. Eng. 57(11), 2657–2666 (2010).
G. Dissanayake, S. Sukkarieh, E. Nebot, H. Durrant-Whyte, "The aiding of a low-cost
strapdown inertial measurement unit using vehicle model constraints for land vehicle
applications", IEEE Trans. Robot. Autom. 17(5), 731–747 (2001).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core, earth, plausibility
from .._validate import choice, input_error, integer, nonnegative, positive, renamed, rows, vector
from .sources import Source, ZeroRate, ZeroVelocity

#: The IMU output kinds: rates (rad/s, m/s²) or increments (rad, m/s).
KINDS = ("rates", "increments")


@dataclass(frozen=True, eq=False)
class StillPeriods:
    """The still periods of an IMU record found by :func:`detect_still`.

    Attributes
    ----------
    time : ndarray (N,)
        The record's time stamps, s.
    still : ndarray of bool (N,)
        Whether each sample is still.
    first, last : ndarray of int (K,)
        First and last sample index (inclusive) of each still period, in time order.
    window : int
        Samples of the detection window.
    accel_threshold : float
        Threshold on | |f| − g |, m/s².
    gyro_threshold : float
        Threshold on |ω|, rad/s.
    gravity : float
        g used, m/s².
    """

    time: np.ndarray
    still: np.ndarray
    first: np.ndarray
    last: np.ndarray
    window: int
    accel_threshold: float
    gyro_threshold: float
    gravity: float

    @property
    def intervals(self) -> np.ndarray:
        """[start, end] of each still period (K, 2), s: the stamps of its first and last
        sample."""
        return np.column_stack([self.time[self.first], self.time[self.last]])

    def update_times(self, every: int | None = None) -> np.ndarray:
        """Update times inside the still periods: every ``every``-th sample of each period,
        from its first sample.

        Parameters
        ----------
        every : int, optional
            Samples between updates (≥ 1); default :attr:`window` (one update per window,
            as the GNSS_IMU filter applies them).

        Returns
        -------
        ndarray (M,)
            Times, s, increasing.

        Raises
        ------
        atomnav.InputError
            Naming ``every``: not ≥ 1.
        TypeError
            Naming ``every``: not an integer.
        """
        step = self.window if every is None else integer(every, "every", 1)
        idx = [np.arange(a, b + 1, step) for a, b in zip(self.first, self.last)]
        return self.time[np.concatenate(idx)] if idx else np.empty(0)

    def zero_velocity(self, sigma: float, *, every: int | None = None) -> ZeroVelocity:
        """Zero-velocity updates at :meth:`update_times`.

        Parameters
        ----------
        sigma : float
            Velocity noise σ, m/s (> 0).
        every : int, optional
            Samples between updates; default :attr:`window`.

        Returns
        -------
        ZeroVelocity
            The updates.

        Raises
        ------
        atomnav.InputError
            Naming ``sigma`` or ``every``.
        """
        return ZeroVelocity(self.update_times(every), sigma)

    def zero_rate(self, gyro_psd: float, sigma: float = 0.0, *, every: int | None = None) -> ZeroRate:
        """Zero-angular-rate updates at :meth:`update_times` whose mean gyro output is taken
        over still samples only (the motion before a still period is left out).

        Parameters
        ----------
        gyro_psd : float
            Gyro white-noise PSD, rad²/s (ARW², ≥ 0).
        sigma : float, default 0.0
            Allowance for motion, σ in rad/s (≥ 0; > 0 when ``gyro_psd`` is 0). The edges
            of a still period may hold slow motion under :attr:`gyro_threshold` (the
            start and end of a move): an allowance of that order keeps such an update
            consistent.
        every : int, optional
            Samples between updates; default :attr:`window`.

        Returns
        -------
        ZeroRate
            The updates.

        Raises
        ------
        atomnav.InputError
            Naming ``gyro_psd``, ``sigma`` or ``every``.
        """
        return _ZeroRateWhileStill(self.update_times(every), gyro_psd, sigma, self.intervals)

    def __repr__(self) -> str:
        return (f"StillPeriods({len(self.first)} periods, {int(self.still.sum())} of {len(self.time)} samples still, "
                f"window={self.window})")


class _ZeroRateWhileStill(ZeroRate):
    """:class:`ZeroRate` averaging the gyro over the still ``intervals`` (K, 2) s only."""

    def __init__(self, time, gyro_psd: float, sigma: float, intervals: np.ndarray):
        #: Still periods [start, end] (K, 2), s.
        self.intervals: np.ndarray = np.ascontiguousarray(intervals, dtype=float).reshape(-1, 2)
        super().__init__(time, gyro_psd, sigma)

    def _native(self) -> _core.AidingSource:
        return _core.zero_rate_while_still(self.time, self.gyro_psd, self.sigma, self.intervals)


def detect_still(time, gyro, accel, *, kind: str, lla=None, gravity: float | None = None, window: int = 50,
                 accel_threshold: float = 0.25, gyro_threshold: float = float(np.deg2rad(0.25)),
                 ellipsoid: str = "WGS84") -> StillPeriods:
    """The still periods of an IMU record.

    A sample passes when | |f| − g | < ``accel_threshold`` and |ω| < ``gyro_threshold``
    (increments are divided by their interval t_k − t_{k−1}; the first row by t_1 − t_0);
    a sample is still when it lies in a window of ``window`` consecutive passing samples,
    i.e. in a run of at least ``window`` passing samples (Groves 2013, ch. 15; the windowed
    test of Skog et al. 2010). The defaults are those of the loosely coupled filter after
    Groves 2013 published in rtklibexplorer's GNSS_IMU (2025): 50 samples, 0.25 m/s²,
    0.25 °/s.

    Parameters
    ----------
    time : array_like (N,)
        Sample times, s, strictly increasing.
    gyro : array_like (N, 3)
        Angular rate, rad/s (rates) or angle increment, rad (increments).
    accel : array_like (N, 3)
        Specific force, m/s² (rates) or velocity increment, m/s (increments).
    kind : str
        ``"rates"`` or ``"increments"``.
    lla : array_like (3,), optional
        The site (lat rad, lon rad, h m): g is its normal gravity. Give ``lla`` or
        ``gravity``.
    gravity : float, optional
        g, m/s² (> 0), instead of ``lla``.
    window : int, default 50
        Samples of the window (≥ 1, at most N).
    accel_threshold : float, default 0.25
        Threshold on | |f| − g |, m/s² (> 0).
    gyro_threshold : float, default 0.25 °/s
        Threshold on |ω|, rad/s (> 0).
    ellipsoid : str
        Earth model of ``lla``, one of ``atomnav._core.OPTIONS["Ellipsoid"]``.

    Returns
    -------
    StillPeriods
        The still samples and periods; its :meth:`~StillPeriods.zero_velocity` and
        :meth:`~StillPeriods.zero_rate` make the updates.

    Raises
    ------
    atomnav.InputError
        Naming ``time``, ``gyro`` or ``accel`` and the row (non-finite, not increasing,
        lengths that differ); ``kind``; ``lla`` (neither ``lla`` nor ``gravity``);
        ``gravity`` (both, or not > 0); ``window`` (< 1 or longer than the record);
        ``accel_threshold`` or ``gyro_threshold`` (not > 0).
    TypeError
        For a non-numeric argument, naming it.

    Warns
    -----
    atomnav.UnitWarning
        A site or IMU samples that look like another unit (degrees, g).
    """
    kind = choice(kind, KINDS, "kind")
    t, g, a = vector(time, None, "time"), rows(gyro, 3, "gyro"), rows(accel, 3, "accel")
    window = integer(window, "window", 1)
    if gravity is not None and lla is not None:
        raise input_error("gravity", "give lla (its normal gravity is used) or gravity, not both")
    if gravity is None:
        if lla is None:
            raise input_error("lla", "required (the site, for its normal gravity) unless gravity is given")
        site = plausibility.lla(vector(lla, 3, "lla"), "lla")
        with renamed(lat="lla", h="lla"):  # earth.gravity's arguments are the site's elements
            gravity = earth.gravity(site[0], site[2], ellipsoid)
    g0 = positive(gravity, "gravity")
    if len(g) == len(t) == len(a) and len(t) >= 2:
        plausibility.imu(t, g, a, kind, "accel", gyro_name="gyro", time_name="time")
    still, runs = _core.detect_still(t, g, a, kind, window, positive(accel_threshold, "accel_threshold"),
                                     positive(gyro_threshold, "gyro_threshold"), g0)
    runs = np.asarray(runs, dtype=np.int64).reshape(-1, 2)
    return StillPeriods(t, np.asarray(still, dtype=bool), runs[:, 0], runs[:, 1], window, float(accel_threshold),
                        float(gyro_threshold), g0)


class NonHolonomic(Source):
    """Non-holonomic constraint of a wheeled vehicle (Dissanayake et al. 2001): the point at
    ``lever_arm`` from the IMU (body frame; e.g. the rear axle's middle) moves neither
    sideways nor vertically in the body frame.

    Model: with u the point's NED velocity, u = v + Ĉ_b^n(ω̂_ib^b × l) − ω_ie^n × Ĉ_b^n l,
    z = [Ĉ_n^b û]_{y,z} − 0 (m/s), R = σ²I; H acts on the velocity, attitude and (with a
    lever arm) gyro-bias error states. An update is skipped while the estimated speed is
    below ``min_speed``. Give the times you want, e.g. every 10th IMU sample
    (``time[::10]``); a vehicle that skids or hops breaks the model.

    Parameters
    ----------
    time : array_like (M,)
        Update times, s, strictly increasing.
    sigma : float
        Noise σ of the lateral and the vertical velocity, m/s (> 0).
    lever_arm : array_like (3,), optional
        The constrained point from the IMU, body frame (FRD), m; default the IMU.
    min_speed : float, default 0.0
        No update below this speed, m/s (≥ 0).

    Raises
    ------
    atomnav.InputError
        Naming ``time`` (and the row), ``sigma``, ``lever_arm`` (and the component) or
        ``min_speed``.
    TypeError
        For a non-numeric argument, naming it.
    """

    def __init__(self, time, sigma: float, *, lever_arm=None, min_speed: float = 0.0):
        #: Update times (M,), s.
        self.time: np.ndarray = vector(time, None, "time")
        #: Noise σ, m/s.
        self.sigma: float = positive(sigma, "sigma")
        #: The constrained point from the IMU (3,), m, body frame; None: the IMU.
        self.lever_arm: tuple | None = None if lever_arm is None else tuple(float(x) for x in vector(lever_arm, 3, "lever_arm"))
        #: No update below this speed, m/s.
        self.min_speed: float = nonnegative(min_speed, "min_speed")
        self._native()  # the core checks every time now

    def _native(self) -> _core.AidingSource:
        return _core.non_holonomic(self.time, self.sigma, lever_arm=self.lever_arm, min_speed=self.min_speed)

    def __repr__(self) -> str:
        return f"NonHolonomic({len(self.time)} updates, sigma={self.sigma:g} m/s, lever_arm={self.lever_arm})"
