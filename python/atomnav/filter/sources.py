"""Measurement sources for one aided INS (Rust core, ``rust/filter/sources.rs``).

Each aiding sensor is a source — :class:`PositionFixes`, :class:`VelocityFixes`, the
zero-velocity and zero-angular-rate updates :class:`ZeroVelocity` and :class:`ZeroRate`,
and the sources other modules make (CAI shots, GNSS) — and
:func:`aided_ins` builds one :class:`~atomnav.filter.AidedIns` fed by all of them. The
measurements of all sources are applied in time order (equal times in the order the
sources are given), each at the first IMU epoch at or after its time; the sources' extra
states (clock, lever arm, ...) follow the 15 INS states in source order.

>>> setup = InsSetup(t0=0.0, lla0=lla0, vel0=vel0, q0=q0, kind="rates", p0=p0,
...                  accel_psd=1e-8, gyro_psd=1e-12)                        # doctest: +SKIP
>>> ins = aided_ins(setup, [PositionFixes(fixes_df), VelocityFixes(t, v, cov)])  # doctest: +SKIP
>>> result = ins.run(time, gyro, accel)                                       # doctest: +SKIP
"""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd

from .. import _core, plausibility
from .._validate import as_floats, covariances, input_error, instance, nonnegative, positive, rows, scalar, table, vector
from .aided import AidedIns, InsSetup
from .engine import _floats


class Source:
    """A measurement source for :func:`aided_ins`. The same source may feed any number of
    aided INS: each gets its own copy of the measurements. A subclass makes the core's
    source in :meth:`_native`."""

    def _native(self) -> _core.AidingSource:
        raise NotImplementedError

    def _check_record(self, time: np.ndarray, whole: bool) -> "Source":
        """This source for the IMU record ``time`` (s, increasing; ``whole``: the whole
        record, else its first chunk): itself, or a copy without the measurements the
        record cannot take, which it reports."""
        return self


class _Mounted(Source):
    """A source that measures at a lever arm from the IMU and stamps its measurements in
    its own clock (the conventions are in ``docs/mounting.md``).

    ``lever_arm`` (3,) m, body frame, from the IMU to the point measured (an antenna, the
    point at rest; None: the IMU itself); ``time_offset`` (s): a measurement stamped t
    was made at t + ``time_offset`` in the IMU's clock (IMU stamps that lag the true time
    by 0.125 s, with measurements stamped in true time: ``time_offset=0.125``). A
    non-finite value raises :class:`atomnav.InputError` naming it, and so does an offset
    longer than the IMU record run."""

    def _mount(self, lever_arm, time_offset) -> None:
        #: Lever arm (3,) m in the body frame, or None.
        self.lever_arm: tuple | None = None if lever_arm is None else _floats(_lever(lever_arm))
        #: Time offset of the stamps, s (IMU time = stamp + time_offset).
        self.time_offset: float = scalar(time_offset, "time_offset")

    def _check_record(self, time: np.ndarray, whole: bool) -> "Source":
        span = time[-1] - time[0]
        if whole and abs(self.time_offset) > span:
            raise input_error("time_offset", f"{self.time_offset:g} s is longer than the IMU record ({span:g} s): "
                                             "is it in seconds?")
        return self


class _Fixes(_Mounted):
    """Fixes of a 3-vector: times (M,) s, values (M, 3) and covariances (M, 3, 3), or a
    table with :attr:`COLUMNS` and, without ``cov``, :attr:`SIGMA_COLUMNS`."""

    #: Columns of a table (DataFrame) of this source: time, then the 3-vector.
    COLUMNS: tuple[str, ...] = ()
    #: Columns with the σ of each component (a diagonal covariance), read when ``cov`` is None.
    SIGMA_COLUMNS: tuple[str, ...] = ()
    #: Name of the 3-vector argument.
    VALUE = ""

    def __init__(self, time, value=None, cov=None, *, epoch=None, lever_arm=None, time_offset=0.0):
        self._mount(lever_arm, time_offset)
        if isinstance(time, pd.DataFrame):
            if value is not None:
                raise input_error(self.VALUE, f"given together with a table: the table's columns {list(self.COLUMNS[1:])} are the {self.VALUE}")
            t, value, sigma = self._read(time, cov is None, epoch)
            cov = np.apply_along_axis(np.diag, 1, sigma**2) if cov is None else cov
        else:
            if value is None:
                raise input_error(self.VALUE, f"required (or give a DataFrame with the columns {list(self.COLUMNS)})")
            if cov is None:
                raise input_error("cov", "required: the (M, 3, 3) covariances, or one (3, 3) for every fix")
            t = vector(time, None, "time")
        value = rows(value, 3, self.VALUE)
        #: Times of the fixes (M,), s.
        self.time: np.ndarray = t
        #: The fixes (M, 3), SI units.
        self.value: np.ndarray = self._plausible(value)
        #: Their covariances (M, 3, 3), SI units squared.
        self.cov: np.ndarray = covariances(cov, len(t), "cov")
        self._native()  # the core checks every fix now, naming this call's arguments

    def _read(self, df: pd.DataFrame, with_sigma: bool, epoch):
        """Time (s), values (M, 3) and, when ``with_sigma``, σ (M, 3) from a table."""
        names = self.COLUMNS + (self.SIGMA_COLUMNS if with_sigma else ())
        if with_sigma and not set(self.SIGMA_COLUMNS) <= set(df.columns):
            raise input_error("cov", f"required unless the table has the columns {list(self.SIGMA_COLUMNS)}")
        data = table(df, names, "time", epoch=epoch, epoch_name="epoch")
        return np.ascontiguousarray(data[:, 0]), data[:, 1:4], data[:, 4:7]

    def _plausible(self, value: np.ndarray) -> np.ndarray:
        return value

    def select(self, keep) -> "_Fixes":
        """These fixes at the rows where ``keep`` is True, every other field kept.

        Parameters
        ----------
        keep : array_like of bool (M,)
            One flag per fix.

        Returns
        -------
        PositionFixes or VelocityFixes
            A new source of the same class with the kept fixes.
        """
        mask = np.asarray(keep)
        if mask.dtype != bool or mask.shape != self.time.shape:
            raise input_error("keep", f"expected {len(self.time)} booleans, one per fix, got {mask.dtype} {mask.shape}")
        out = copy.copy(self)
        out.time, out.value, out.cov = self.time[mask], self.value[mask], self.cov[mask]
        return out

    def __len__(self) -> int:
        return len(self.time)

    def __repr__(self) -> str:
        span = f", {self.time[0]:g} to {self.time[-1]:g} s" if len(self) else ""
        return f"{type(self).__name__}({len(self)} fixes{span})"


class PositionFixes(_Fixes):
    """Position fixes: ``time`` (M,) s, ``lla`` (M, 3) (lat rad, lon rad, h m) and their NED
    covariances ``cov`` (M, 3, 3) m² (or one (3, 3) for every fix), z = NED(INS + C_b^n l −
    fix) for the ``lever_arm`` l from the IMU to the antenna.

    ``time`` may instead be a DataFrame with the columns ``time_s, lat_rad, lon_rad, h_m``
    and, unless ``cov`` is given, ``sigma_n_m, sigma_e_m, sigma_d_m`` (σ of the north,
    east and down errors, m; uncorrelated). A ``time_s`` column of datetimes counts seconds
    from ``epoch`` (the epoch of the IMU record's time); timedelta64 is its seconds.
    Every fix is checked here: time finite and strictly increasing, positions finite
    with latitudes within ±π/2, covariances symmetric positive definite; a bad one raises
    :class:`atomnav.InputError` naming ``time``, ``lla`` or ``cov`` and its row.
    Longitudes in degrees warn (:class:`atomnav.UnitWarning`).

    Parameters
    ----------
    time : array_like (M,) or pandas.DataFrame
        Times of the fixes, s; or a table with the columns above.
    lla : array_like (M, 3), optional
        Latitude, longitude (rad) and height (m) of each fix; not with a table.
    cov : array_like (M, 3, 3) or (3, 3), optional
        NED covariance of each fix, m² (one (3, 3) for every fix); required unless the
        table has the σ columns.
    epoch : datetime-like, optional
        Epoch of the IMU record's time: a ``time_s`` column of datetimes counts seconds
        from it (datetimes without an epoch are a ``TypeError``).
    lever_arm : array_like (3,), optional
        From the IMU to the antenna (the point the fixes locate), m, body frame (``docs/mounting.md``); None
        (default): the IMU itself.
    time_offset : float
        Offset of the stamps, s: a fix stamped t was made at t + ``time_offset`` in
        the IMU clock (IMU stamps that lag the true time by 0.125 s:
        ``time_offset=0.125``); default 0.

    Raises
    ------
    atomnav.InputError
        Naming ``time``, ``lla`` or ``cov`` and the bad row; ``lever_arm`` or
        ``time_offset`` for a non-finite value, and ``time_offset`` when it is longer than
        the IMU record run.

    Warns
    -----
    atomnav.UnitWarning
        Longitudes that look like degrees.
    """

    COLUMNS = ("time_s", "lat_rad", "lon_rad", "h_m")
    SIGMA_COLUMNS = ("sigma_n_m", "sigma_e_m", "sigma_d_m")
    VALUE = "lla"

    def __init__(self, time, lla=None, cov=None, *, epoch=None, lever_arm=None, time_offset=0.0):
        super().__init__(time, lla, cov, epoch=epoch, lever_arm=lever_arm, time_offset=time_offset)

    def _plausible(self, value):
        return plausibility.lla(value, self.VALUE)

    def _native(self) -> _core.AidingSource:
        return _core.position_fixes(self.time, self.value, self.cov, lever_arm=self.lever_arm, time_offset=self.time_offset)


class _PositionFixArguments(PositionFixes):
    """The fixes of :func:`atomnav.filter.position_aided_ins`, whose unit warnings name its
    argument ``fix_lla`` (a module-level class, so an INS built from it pickles)."""

    VALUE = "fix_lla"


class VelocityFixes(_Fixes):
    """NED velocity fixes: ``time`` (M,) s, ``vel_ned`` (M, 3) m/s and their covariances
    ``cov`` (M, 3, 3) m²/s² (or one (3, 3) for every fix), z = v̂_l − v_fix with v̂_l the
    velocity at the ``lever_arm`` l, v + C_b^n(ω_ib^b × l) − ω_ie^n × C_b^n l.

    ``time`` may instead be a DataFrame with the columns ``time_s, vn_mps, ve_mps,
    vd_mps`` and, unless ``cov`` is given, ``sigma_vn_mps, sigma_ve_mps, sigma_vd_mps``
    (σ of each component, m/s; uncorrelated); time as for :class:`PositionFixes`. Every
    fix is checked here (time finite and strictly increasing, velocities finite,
    covariances symmetric positive definite); a bad one raises :class:`atomnav.InputError`
    naming ``time``, ``vel_ned`` or ``cov`` and its row.

    Parameters
    ----------
    time : array_like (M,) or pandas.DataFrame
        Times of the fixes, s; or a table with the columns above.
    vel_ned : array_like (M, 3), optional
        NED velocity of each fix, m/s; not with a table.
    cov : array_like (M, 3, 3) or (3, 3), optional
        Covariance of each fix, m²/s² (one (3, 3) for every fix); required unless the
        table has the σ columns.
    epoch : datetime-like, optional
        Epoch of the IMU record's time: a ``time_s`` column of datetimes counts seconds
        from it (datetimes without an epoch are a ``TypeError``).
    lever_arm : array_like (3,), optional
        From the IMU to the point whose velocity the fixes give, m, body frame (``docs/mounting.md``); None
        (default): the IMU itself.
    time_offset : float
        Offset of the stamps, s: a fix stamped t was made at t + ``time_offset`` in
        the IMU clock (IMU stamps that lag the true time by 0.125 s:
        ``time_offset=0.125``); default 0.

    Raises
    ------
    atomnav.InputError
        Naming ``time``, ``vel_ned`` or ``cov`` and the bad row; ``lever_arm`` or
        ``time_offset`` as for :class:`PositionFixes`.
    """

    COLUMNS = ("time_s", "vn_mps", "ve_mps", "vd_mps")
    SIGMA_COLUMNS = ("sigma_vn_mps", "sigma_ve_mps", "sigma_vd_mps")
    VALUE = "vel_ned"

    def __init__(self, time, vel_ned=None, cov=None, *, epoch=None, lever_arm=None, time_offset=0.0):
        super().__init__(time, vel_ned, cov, epoch=epoch, lever_arm=lever_arm, time_offset=time_offset)

    def _native(self) -> _core.AidingSource:
        return _core.velocity_fixes(self.time, self.value, self.cov, lever_arm=self.lever_arm, time_offset=self.time_offset)


class ZeroVelocity(_Mounted):
    """Zero-velocity updates (ZUPT; Groves 2013, *Principles of GNSS, Inertial, and
    Multisensor Integrated Navigation Systems*, 2nd ed., §15.3) at ``time`` (M,) s, with
    velocity noise σ ``sigma`` (m/s): z = v̂_l − 0 for the point at rest at the
    ``lever_arm`` l (v̂_l as for :class:`VelocityFixes`). A bad ``time`` or ``sigma``
    raises :class:`atomnav.InputError` naming it (and the row).

    Parameters
    ----------
    time : array_like (M,)
        Times of the updates, s.
    sigma : float
        Velocity noise σ, m/s (> 0).
    lever_arm : array_like (3,), optional
        From the IMU to the point at rest, m, body frame (``docs/mounting.md``); None
        (default): the IMU itself.
    time_offset : float
        Offset of the stamps, s: a update stamped t was made at t + ``time_offset`` in
        the IMU clock (IMU stamps that lag the true time by 0.125 s:
        ``time_offset=0.125``); default 0.

    Raises
    ------
    atomnav.InputError
        Naming ``time`` (and the row) or ``sigma``; ``lever_arm`` or ``time_offset`` as
        for :class:`PositionFixes`.
    """

    def __init__(self, time, sigma: float, *, lever_arm=None, time_offset=0.0):
        #: Times of the updates (M,), s.
        self.time: np.ndarray = vector(time, None, "time")
        #: Velocity noise σ, m/s.
        self.sigma: float = positive(sigma, "sigma")
        self._mount(lever_arm, time_offset)
        self._native()  # the core checks every time now

    def _native(self) -> _core.AidingSource:
        return _core.zero_velocity(self.time, self.sigma, lever_arm=self.lever_arm, time_offset=self.time_offset)

    def __repr__(self) -> str:
        return f"ZeroVelocity({len(self.time)} updates, sigma={self.sigma:g} m/s)"


class ZeroRate(Source):
    """Zero-angular-rate updates (ZARU; Groves 2013, §15.3) at ``time`` (M,) s: the
    Earth-relative body rate ω̂_ib − Ĉ_n^b ω_ie^n, from the mean bias-compensated gyro
    output since the previous update, is zero. Noise: the gyro white-noise PSD
    ``gyro_psd`` (rad²/s, ARW²) over the time averaged, plus ``sigma`` (rad/s) for motion
    the record may hold. It reads the IMU kind of the INS it feeds.

    Parameters
    ----------
    time : array_like (M,)
        Times of the updates, s.
    gyro_psd : float
        Gyro white-noise PSD, rad²/s (ARW², ≥ 0).
    sigma : float, default 0.0
        Allowance for motion, σ in rad/s (≥ 0).

    Raises
    ------
    atomnav.InputError
        Naming ``time`` (and the row), ``gyro_psd`` or ``sigma``.

    References
    ----------
    P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
    Systems*, 2nd ed. (2013), §15.3.
    """

    def __init__(self, time, gyro_psd: float, sigma: float = 0.0):
        #: Times of the updates (M,), s.
        self.time: np.ndarray = vector(time, None, "time")
        #: Gyro white-noise PSD, rad²/s.
        self.gyro_psd: float = nonnegative(gyro_psd, "gyro_psd")
        #: Allowance for motion, σ in rad/s.
        self.sigma: float = nonnegative(sigma, "sigma")
        self._native()

    def _native(self) -> _core.AidingSource:
        return _core.zero_rate(self.time, self.gyro_psd, self.sigma)

    def __repr__(self) -> str:
        return f"ZeroRate({len(self.time)} updates, gyro_psd={self.gyro_psd:g} rad²/s, sigma={self.sigma:g} rad/s)"


def _lever(lever_arm) -> np.ndarray:
    """A lever arm as a vector; its length and values are the core's checks."""
    a = as_floats(lever_arm, "lever_arm")
    if a.ndim != 1:
        raise input_error("lever_arm", f"expected the 3 values (m, body frame), got shape {a.shape}")
    return a


def aided_ins(setup: InsSetup, sources) -> "SourcedIns":
    """One aided INS fed by several measurement sources.

    Parameters
    ----------
    setup : InsSetup
        The INS: initial state, IMU kind, noise, filter options. Its ``p0`` is either the
        (15, 15) covariance of the INS states — then sources with extra states (GNSS
        clock, CAI lever arm, ...) add their own initial covariance after it — or the
        covariance of the whole state (INS states, then every source's extra states in
        source order), which replaces the sources' own.
    sources : source or sequence of sources
        :class:`PositionFixes`, :class:`VelocityFixes`, :class:`ZeroVelocity`,
        :class:`ZeroRate`, :class:`atomnav.gnss.tight.GnssObservations`,
        :class:`atomnav.cai.CaiShots`.
        Each source's measurements must lie inside the IMU record. Equal times of
        different sources are applied at the same epoch in the order given.

    Returns
    -------
    SourcedIns
        An :class:`AidedIns`: run it with ``.run(time, gyro, accel)``; ``labels`` lists
        the states.

    Raises
    ------
    atomnav.InputError
        Naming ``sources`` (and the source's place in ``.index``) for two sources with a
        state of the same name, or a source with extra states but no initial covariance
        when ``setup.p0`` is (15, 15).
    TypeError
        For a ``setup`` that is no :class:`InsSetup` or a source that is no source.
    """
    instance(setup, InsSetup, "setup")
    sources = _listed(sources)
    return SourcedIns(_native_ins(setup, sources), setup, sources)


def _listed(sources) -> list:
    """``sources`` (one source or a sequence of them) as a list; a ``TypeError`` naming
    ``sources`` for anything else."""
    if isinstance(sources, Source):
        return [sources]
    if isinstance(sources, (str, bytes, pd.DataFrame)) or not hasattr(sources, "__iter__"):
        raise TypeError(f"sources: expected a measurement source or a sequence of them, got {type(sources).__name__}")
    sources = list(sources)
    for i, s in enumerate(sources):
        if not isinstance(s, Source):
            raise TypeError(f"sources: item {i} is a {type(s).__name__}, not a measurement source "
                            "(PositionFixes, VelocityFixes, ...)")
    return sources


def _native_ins(setup: InsSetup, sources: list) -> _core.AidedIns:
    """The core aided INS of ``setup`` fed by ``sources`` (a list of sources)."""
    native = [s._native() for s in sources]
    return _core.aided_ins_from_sources(setup.native, native)


class SourcedIns(AidedIns):
    """The aided INS of :func:`aided_ins`: an :class:`AidedIns` whose sources check the IMU
    record before it starts — :class:`atomnav.cai.CaiShots` reports the shots the record
    cannot complete. When a source leaves measurements out, ``run`` rebuilds the filter
    without them.

    Parameters
    ----------
    core : atomnav._core.AidedIns
        The core engine built from ``setup`` and ``sources``.
    setup : InsSetup
        The INS configuration.
    sources : list of Source
        The measurement sources, in order.
    """

    def __init__(self, core: _core.AidedIns, setup: InsSetup, sources: list):
        super().__init__(core, setup)
        self._sources = sources  # the sources the filter is rebuilt from
        self._started = False

    def _start(self, time, whole: bool) -> None:
        """Let every source check the record ``time`` once, before its first sample
        (``whole``: the whole record, from :meth:`run`)."""
        t = as_floats(time, "time")
        if self._started or t.ndim != 1 or len(t) < 2:  # the engine names a bad time
            return
        t = np.ascontiguousarray(t)
        checked = []
        for s in self._sources:  # a loop, not a comprehension: a source's warning points at the caller
            checked.append(s._check_record(t, whole))
        if any(c is not s for c, s in zip(checked, self._sources)):
            self._core = _native_ins(self.setup, checked)
            if self._store is not None:
                self._core.store_forward_pass()
        self._started = True

    def process(self, time, gyro, accel, *args, **kwargs):
        """See :meth:`AidedIns.process`; the first chunk is the record start, which the
        sources check.

        Parameters
        ----------
        time : array_like (N,)
            Sample times, s.
        gyro : array_like (N, 3)
            Angular rate, rad/s (rates) or angle increment, rad (increments).
        accel : array_like (N, 3)
            Specific force, m/s² (rates) or velocity increment, m/s (increments).
        *args, **kwargs
            The other arguments of :meth:`AidedIns.process` (``h_ref``).

        Returns
        -------
        AidedResult
            The epochs and measurements of this chunk.
        """
        self._start(time, whole=False)
        return super().process(time, gyro, accel, *args, **kwargs)

    def run(self, time, gyro, accel, *args, **kwargs):
        """See :meth:`AidedIns.run`; the sources check the whole record before it starts.

        Parameters
        ----------
        time : array_like (N,)
            Sample times, s.
        gyro : array_like (N, 3)
            Angular rate, rad/s (rates) or angle increment, rad (increments).
        accel : array_like (N, 3)
            Specific force, m/s² (rates) or velocity increment, m/s (increments).
        *args, **kwargs
            The other arguments of :meth:`AidedIns.run` (``h_ref``, ``chunk_s``,
            ``progress``).

        Returns
        -------
        AidedResult
            Every epoch and measurement of the record.
        """
        self._start(time, whole=True)
        return super().run(time, gyro, accel, *args, **kwargs)
