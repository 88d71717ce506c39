"""The aided strapdown INS (Rust core, ``rust/filter/aided.rs``): one engine for every
aiding sensor. A sensor's factory (:func:`position_aided_ins`, and the CAI and GNSS
factories of their packages) builds an :class:`AidedIns`; :meth:`AidedIns.run` feeds a
whole IMU record in chunks with a progress bar, :meth:`AidedIns.process` /
:meth:`AidedIns.finish` stream it yourself. Closed loop (feedback) or open loop
(estimation) is chosen at construction, and so is the vertical channel: free, or
damped by a reference (barometric) altitude per IMU sample (``vertical="damped"``, the
third-order baro loop, docs/departures.md#baro-damped-vertical-channel), which :meth:`AidedIns.run` then takes as
``h_ref``. The INS part of every factory is one frozen configuration, :class:`InsSetup`,
checked by the core when it is built and convertible to and from dict and JSON.

Smoothing: built with ``smooth=True`` (a field of :class:`InsSetup`, so an option of
every factory), the engine stores its forward pass and :meth:`AidedIns.smooth` runs the
Rauch–Tung–Striebel fixed-interval smoother (Rauch, Tung & Striebel 1965) backwards over
it in the Rust core; :meth:`AidedIns.run` then returns the smoothed solution with the
filtered one (:attr:`AidedResult.smoothed`)."""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import _core, plausibility
from .._validate import as_floats, finite_scalar, flag, input_error, instance, integer, path, positive, renamed, rows
from ._forward import ForwardStore, epoch_bytes
from ..strapdown import _table
from ..trajectory import imu_kind
from .engine import INS15, BiasModel, Config, Layout, _floats
from .riccati import _mat

#: Names of the vertical-channel options (from the core).
VERTICAL = tuple(_core.OPTIONS["Vertical"])


@dataclass(frozen=True, kw_only=True)
class InsSetup(Config):
    """The INS part every aided-INS factory shares (Rust ``filter::aided::InsSetup``),
    checked once by the core when built (an invalid field raises
    :class:`atomnav.InputError` naming it).

    Parameters
    ----------
    t0 : float
        Time of the initial state, s.
    lla0 : array_like (3,)
        Initial latitude, longitude (rad) and height (m).
    vel0 : array_like (3,)
        Initial NED velocity, m/s.
    q0 : array_like (4,)
        Initial attitude q_nb (body → NED, scalar first).
    kind : {"rates", "increments"}
        IMU output: rates (rad/s, m/s²) or increments (rad, m/s).
    p0 : array_like (n, n)
        Initial covariance, in the order of :data:`atomnav.filter.INS15`, then the
        sensor's extra states where the sensor does not supply them; SI units of the
        states, squared.
    accel_psd : float
        Accelerometer white-noise PSD, (m/s²)²/Hz.
    gyro_psd : float
        Gyro white-noise PSD, rad²/s.
    accel_bias, gyro_bias : BiasModel, default BiasModel()
        Bias processes (default random constant).
    ba0 : array_like (3,), default (0, 0, 0)
        Initial accelerometer bias estimate, m/s².
    bg0 : array_like (3,), default (0, 0, 0)
        Initial gyro bias estimate, rad/s.
    predict_every : int, default 1
        The filter predicts every ``predict_every`` IMU steps and at every measurement.
    method : {"van_loan", "first_order"}, default "van_loan"
        Discretisation (:func:`atomnav.filter.engine.discretize`).
    mode : {"closed", "open"}, default "closed"
        Closed loop (feedback) or open loop (estimation).
    sequential : bool, default False
        Scalar (decorrelated) updates.
    gate : float, optional
        χ² threshold on the NIS (default: no gate).
    ellipsoid : str, default "WGS84"
        Earth ellipsoid.
    vertical : str, default "free"
        One of :data:`VERTICAL`: "free" or "damped" (see Notes).
    zeta : float, optional
        Damping ratio ζ of the baro loop (default None: the core's 0.707).
    omega : float, optional
        Natural frequency ω of the baro loop, rad/s (default None: the core's 0.01 rad/s).
    baro_psd : float, default 0.0
        PSD of the white part n of the reference-altitude error, m²·s.
    baro_bias : BiasModel, optional
        Process of the reference-altitude bias b, m (default: b = 0).
    baro_bias_sigma0 : float, optional
        Initial σ of ``baro_bias``, m.
    smooth : bool, default False
        Store the forward pass for the smoother (see Notes).
    smooth_chunk : int, default 1000
        Epochs per chunk of the stored forward pass (≥ 1).
    smooth_memory : int, default 2**30
        Bytes of the forward pass held in memory (≥ 0); beyond, written to disk.
    smooth_dir : str or path-like, optional
        Directory for the on-disk forward pass (default: the system's temporary
        directory).
    mount : array_like (3, 3) or (3,), optional
        The IMU mount C_imu^b, as a DCM or (roll, pitch, yaw) in rad (see Notes; default
        None: the identity).

    Raises
    ------
    atomnav.InputError
        Naming the invalid field.

    Notes
    -----
    Vertical channel: ``vertical`` one of :data:`VERTICAL` — "free" (default) or
    "damped", then :meth:`AidedIns.run` needs ``h_ref``, the reference (barometric)
    altitude (m) per IMU sample; ``zeta``, ``omega`` (rad/s) of the baro loop (default None:
    the core's 0.707 and 0.01 rad/s)
    (K_v1 = 2ζω, K_v2 = ω² + 2γ/R₀, the gains of Demidov 2009); the reference-altitude error
    h_b − h = b + n: ``baro_psd`` the PSD of the white part n (m²·s; σ²Δt for independent
    samples of σ every Δt), ``baro_bias`` a :class:`BiasModel` of b carried as the state
    ``baro_bias`` (m, after the sensor's extra states) with initial σ
    ``baro_bias_sigma0`` (m); without it the filter assumes b = 0.

    Smoother (Rauch, Tung & Striebel 1965): ``smooth`` True stores the forward pass for
    :meth:`AidedIns.smooth` (and makes :meth:`AidedIns.run` return the smoothed solution),
    8 (4n² + 2n + 17 + n_extra) bytes per prediction epoch for n states (15 INS states:
    7 576 bytes; a 1-hour record with an epoch every 0.1 s: 273 MB), in chunks of
    ``smooth_chunk`` epochs (the unit of the backward pass) held in memory up to
    ``smooth_memory`` bytes, beyond that written to a temporary directory under
    ``smooth_dir`` (the system's temporary directory when None) and deleted with the
    engine.

    IMU mount: ``mount`` the rotation C_imu^b from the IMU's axes to the body axes
    (v_b = C v_imu), a (3, 3) DCM or (roll, pitch, yaw) in rad as for
    :func:`atomnav.rotation.dcm_from_euler`, kept as its DCM; None (default) is the
    identity. Every IMU sample is turned by it before the strapdown, so ``ba0``, ``bg0``
    and the estimated biases are in the body frame. The conventions are in
    ``docs/mounting.md``; a matrix that is no rotation raises :class:`atomnav.InputError`
    naming ``mount``.

    References
    ----------
    H. E. Rauch, F. Tung and C. T. Striebel, "Maximum likelihood estimates of linear
    dynamic systems", *AIAA Journal* 3 (1965). P. D. Groves, *Principles of GNSS,
    Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed. (2013), ch. 14.
    Demidov 2009 (gains of the baro loop).

    Examples
    --------
    >>> s = InsSetup(t0=0.0, lla0=(0.8, 0.2, 100.0), vel0=(0, 0, 0), q0=(1, 0, 0, 0),
    ...              kind="rates", p0=np.eye(15), accel_psd=1e-8, gyro_psd=1e-12)  # doctest: +SKIP
    >>> InsSetup.from_json(s.to_json()) == s                                      # doctest: +SKIP
    True
    """

    _NESTED = {"accel_bias": BiasModel, "gyro_bias": BiasModel, "baro_bias": BiasModel}

    t0: float
    lla0: tuple
    vel0: tuple
    q0: tuple
    kind: str
    p0: tuple
    accel_psd: float
    gyro_psd: float
    accel_bias: BiasModel = BiasModel()
    gyro_bias: BiasModel = BiasModel()
    ba0: tuple = (0.0, 0.0, 0.0)
    bg0: tuple = (0.0, 0.0, 0.0)
    predict_every: int = 1
    method: str = "van_loan"
    mode: str = "closed"
    sequential: bool = False
    gate: float | None = None
    ellipsoid: str = "WGS84"
    vertical: str = "free"
    zeta: float | None = None
    omega: float | None = None
    baro_psd: float = 0.0
    baro_bias: BiasModel | None = None
    baro_bias_sigma0: float | None = None
    smooth: bool = False
    smooth_chunk: int = 1000
    smooth_memory: int = 1 << 30
    smooth_dir: str | None = None
    mount: tuple | None = None

    def __post_init__(self):
        flag(self.smooth, "smooth")
        integer(self.smooth_chunk, "smooth_chunk", 1)
        integer(self.smooth_memory, "smooth_memory", 0)
        if self.smooth_dir is not None:
            d = path(self.smooth_dir, "smooth_dir")
            if not d.is_dir():
                raise input_error("smooth_dir", f"{str(d)!r} is not a directory")
            object.__setattr__(self, "smooth_dir", str(d))
        imu_kind(self.kind, None)  # the IMU record comes as plain arrays (AidedIns.run): kind=None is an InputError
        for name, n in (("lla0", 3), ("vel0", 3), ("q0", 4), ("ba0", 3), ("bg0", 3)):
            v = as_floats(getattr(self, name), name)
            if v.shape != (n,):
                raise input_error(name, f"expected shape ({n},), got {v.shape}")
            object.__setattr__(self, name, _floats(v))
        plausibility.lla(self.lla0, "lla0")
        p0 = _mat(self.p0, "p0")
        object.__setattr__(self, "p0", _floats(p0))
        for name in ("accel_bias", "gyro_bias") + (() if self.baro_bias is None else ("baro_bias",)):
            instance(getattr(self, name), BiasModel, name)
        opt = {name: None if getattr(self, name) is None else finite_scalar(getattr(self, name), name)
               for name in ("gate", "zeta", "omega", "baro_bias_sigma0")}
        if self.mount is not None:
            object.__setattr__(self, "mount", _floats(_mount_dcm(self.mount)))
        with renamed(lla="lla0", vel_ned="vel0", q_nb="q0"):  # the core checks the initial state as a strapdown state
            native = _core.AidedSetup(
                t0=finite_scalar(self.t0, "t0"), lla0=list(self.lla0), vel0=list(self.vel0), q0=list(self.q0), kind=self.kind, p0=p0,
                accel_psd=finite_scalar(self.accel_psd, "accel_psd"), gyro_psd=finite_scalar(self.gyro_psd, "gyro_psd"),
                accel_bias=self.accel_bias._parts(), gyro_bias=self.gyro_bias._parts(), ba0=list(self.ba0), bg0=list(self.bg0),
                predict_every=integer(self.predict_every, "predict_every", 1, 2**63 - 1),
                method=self.method, mode=self.mode, sequential=flag(self.sequential, "sequential"), ellipsoid=self.ellipsoid, vertical=self.vertical,
                baro_psd=finite_scalar(self.baro_psd, "baro_psd"),
                baro_bias=None if self.baro_bias is None else self.baro_bias._parts(),
                mount=None if self.mount is None else np.array(self.mount), **opt)
        object.__setattr__(self, "_native", native)

    @property
    def native(self) -> _core.AidedSetup:
        """The checked core object the sensor factories take."""
        return self._native

def _mount_dcm(mount) -> np.ndarray:
    """The IMU mount C_imu^b (3, 3) from a DCM or (roll, pitch, yaw) in rad (docs/mounting.md);
    whether it is a rotation is the core's check."""
    from ..rotation import dcm_from_euler

    m = as_floats(mount, "mount")
    if m.shape == (3,):
        with renamed(euler="mount"):
            return dcm_from_euler(m)
    if m.shape != (3, 3):
        raise input_error("mount", f"expected a (3, 3) DCM or the (3,) Euler angles (roll, pitch, yaw) in rad, got shape {m.shape}")
    return m


_AXES = "xyz"


@dataclass
class AidedResult:
    """Output of the aided INS.

    ``nav``: one row per prediction epoch — the navigation estimate in the columns of
    :data:`atomnav.trajectory.COLUMNS` (so ``Trajectory.errors(result.nav)`` works), the
    IMU bias estimates (``accel_bias_*_mps2``, ``gyro_bias_*_rad_s``), the extra blocks'
    estimates (``extra_<label>``) and σ of every state (``sigma_<label>``, SI units of the
    state). ``measurements``: one row per applied measurement — its time, row count, NIS
    (summed over rows), the number of rows the χ² gate rejected and ``source``, the name
    of the sensor that made it (str: "position_fixes", "velocity_fixes", "zero_velocity",
    "zero_rate", "gnss", "cai"; a measurement the sensor skipped, e.g. a GNSS epoch
    with too few satellites, has no row). ``innovation``: the
    innovations of all measurements, concatenated in order (``measurements.rows`` each).
    ``smoothed``: the smoothed solution when the engine was built with ``smooth=True``
    (:meth:`AidedIns.run`), else None. ``covariance``: the full error-state covariance of
    every epoch when asked for (``covariance=True`` of :meth:`AidedIns.run` or
    :meth:`AidedIns.process`), else None; :meth:`nees` checks it against a reference
    trajectory, :meth:`nis_band` the innovations against their χ² band.

    Attributes
    ----------
    nav : pandas.DataFrame
        One row per prediction epoch (as above).
    measurements : pandas.DataFrame
        One row per applied measurement: time_s (s), rows, nis, rejected_rows, source.
    innovation : numpy.ndarray (K,)
        Innovations of all measurements, concatenated (units of the measurement rows).
    smoothed : SmoothedResult or None
        The smoothed solution, or None.
    covariance : numpy.ndarray (E, n, n) or None
        Error-state covariance of every row of ``nav`` (after the epoch's updates), in the
        state order of :attr:`AidedIns.labels` (the 15 INS states of
        :data:`atomnav.filter.INS15` first), SI units of the states squared; None unless
        asked for.
    """

    nav: pd.DataFrame
    measurements: pd.DataFrame
    innovation: np.ndarray
    smoothed: SmoothedResult | None = None
    covariance: np.ndarray | None = None

    def nees(self, truth, blocks=("position", "velocity", "attitude")) -> pd.DataFrame:
        """Normalised estimation error squared of every epoch against a reference
        trajectory: εᵀP⁻¹ε over the chosen blocks, with ε = estimate − truth from
        :meth:`atomnav.trajectory.Trajectory.errors` (NED position m, NED velocity m/s,
        attitude error ψ rad) and P the matching blocks of :attr:`covariance`.

        For a consistent filter the NEES is χ²-distributed with ``dof`` degrees of
        freedom; averaged over R independent runs it lies in
        :func:`atomnav.filter.chi2_band` (dof, R) at about 95 % of epochs (Bar-Shalom, Li &
        Kirubarajan 2001, §5.4).

        Parameters
        ----------
        truth : atomnav.trajectory.Trajectory
            The reference motion; every row of :attr:`nav` must be one of its time stamps.
        blocks : sequence of {"position", "velocity", "attitude"}, default all three
            The navigation blocks checked.

        Returns
        -------
        pandas.DataFrame
            ``time_s`` (s), ``nees`` (dimensionless) and ``dof`` (3 per block).

        Raises
        ------
        atomnav.InputError
            Naming ``covariance`` when the run did not output it, or ``blocks``.
        """
        from ..trajectory import Trajectory

        instance(truth, Trajectory, "truth")
        if self.covariance is None:
            raise input_error("covariance", "this result has no covariance: run the aided INS with covariance=True")
        names = [blocks] if isinstance(blocks, str) else list(blocks)
        columns = {"position": "dpos", "velocity": "dvel", "attitude": "psi"}
        if not names or any(b not in columns for b in names) or len(set(names)) != len(names):
            raise input_error("blocks", f"expected distinct names among {list(columns)}, got {blocks!r}")
        err = truth.errors(self.nav)
        cols = [c for b in names for c in err.columns if c.startswith(columns[b] + "_")]
        idx = np.concatenate([np.arange(15)[Layout(INS15)[b]] for b in names])
        e = err[cols].to_numpy()
        p = self.covariance[:, idx[:, None], idx[None, :]]
        nees = np.einsum("ki,ki->k", e, np.linalg.solve(p, e[:, :, None])[:, :, 0])
        return pd.DataFrame({"time_s": err["time_s"].to_numpy(), "nees": nees, "dof": len(idx)})

    def nis_band(self, p: float = 0.95) -> pd.DataFrame:
        """The normalised innovation squared of every applied measurement against its
        two-sided χ² band: a measurement of m rows has NIS ~ χ²(m) for a consistent filter
        (Bar-Shalom, Li & Kirubarajan 2001, §5.4), so about a fraction ``p`` of the rows of
        one sensor should be ``inside``.

        Parameters
        ----------
        p : float, default 0.95
            Probability of the band, in (0, 1).

        Returns
        -------
        pandas.DataFrame
            :attr:`measurements` with ``nis_low``, ``nis_high`` (the band for the row's
            degrees of freedom) and ``inside`` (bool).
        """
        from .analysis import chi2_band

        out = self.measurements.copy()
        dofs, which = np.unique(out["rows"].to_numpy(), return_inverse=True)
        band = np.array([chi2_band(int(m), 1, p) for m in dofs]).reshape(-1, 2)  # one per distinct row count
        out["nis_low"], out["nis_high"] = band[which, 0], band[which, 1]
        out["inside"] = (out["nis"] >= out["nis_low"]) & (out["nis"] <= out["nis_high"])
        return out


@dataclass
class SmoothedResult:
    """Output of the Rauch–Tung–Striebel smoother (Rauch, Tung & Striebel 1965) over an
    aided-INS run (:meth:`AidedIns.smooth`). There is no smoothed NIS: the filtered
    ``measurements`` stay the record of the innovations.

    Attributes
    ----------
    nav : pandas.DataFrame
        One row per prediction epoch in the columns of :attr:`AidedResult.nav`: the
        smoothed navigation solution (rad, m, m/s, q_nb, rad), IMU bias estimates (m/s²,
        rad/s), extra-block estimates and the smoothed σ of every state
        (``sigma_<label>``, SI units of the state).
    covariance : numpy.ndarray or None
        The smoothed error-state covariance (E, n, n) in the order of
        :attr:`AidedIns.labels` (SI units of the states) when asked for, else None.
    """

    nav: pd.DataFrame
    covariance: np.ndarray | None = None


class AidedIns:
    """A running aided INS; build it with a sensor's factory function. It may be pickled
    or deep-copied between chunks (a checkpoint, or a Dask task): the copy, fed the rest of
    the record, continues bit for bit like the original.

    Parameters
    ----------
    core : atomnav._core.AidedIns
        The core engine a sensor's factory built.
    setup : InsSetup
        The INS configuration it was built with.
    """

    def __init__(self, core: _core.AidedIns, setup: InsSetup):
        self._core = instance(core, _core.AidedIns, "core")
        instance(setup, InsSetup, "setup")
        #: The INS configuration (save it beside the results: ``setup.to_json()``).
        self.setup = setup
        self.kind = setup.kind
        #: Labels of the state components in filter order, e.g. ``velocity[2]``.
        self.labels: list[str] = list(core.labels)
        self._store = None
        if setup.smooth:
            core.store_forward_pass()
            self._store = ForwardStore(setup.smooth_chunk, setup.smooth_memory, setup.smooth_dir)

    @property
    def forward_pass(self) -> ForwardStore | None:
        """The stored forward pass (``smooth=True``), else None: its ``chunks()`` give, per
        chunk, the index of its first epoch and the arrays ``phi`` (E, n, n) (Φ from the
        previous epoch, the first one from the start), ``qd`` (E, n, n), ``x_prior``,
        ``x_post`` (E, n) and ``p_prior``, ``p_post`` (E, n, n) (the filter's error-state
        moments before and after the epoch's update, before a closed loop's feedback), and
        ``nominal`` (E, 17 + n_extra) (t s, lat, lon rad, h m, v_NED m/s, q_nb, accel bias
        m/s², gyro bias rad/s, extra blocks: the solution after the epoch, the free INS in
        open loop)."""
        return self._store

    @property
    def epoch_bytes(self) -> int:
        """Bytes of the forward pass stored per prediction epoch: 8 (4n² + 2n + 17 +
        n_extra) for n states."""
        n = len(self.labels)
        return epoch_bytes(n, n - 15)

    @property
    def pending(self) -> int:
        """Measurements not yet applied (their time is after the last processed sample)."""
        return self._core.pending

    def _result(self, out) -> AidedResult:
        *solution, covariance, mt, mrows, innov, nis, rejected, source, _forward = out
        meas = pd.DataFrame({"time_s": mt, "rows": mrows, "nis": nis, "rejected_rows": rejected,
                             "source": pd.Series(source, dtype="str")})
        return AidedResult(self._nav(*solution), meas, innov, covariance=covariance)

    def _nav(self, nav, ba, bg, extra, sigma) -> pd.DataFrame:
        """The table of :attr:`AidedResult.nav` from the core's columns."""
        table = _table(nav).copy()
        for name, block, unit in (("accel_bias", ba, "mps2"), ("gyro_bias", bg, "rad_s")):
            for i, a in enumerate(_AXES):
                table[f"{name}_{a}_{unit}"] = block[:, i]
        for i, lab in enumerate(self.labels[15:]):
            table[f"extra_{lab}"] = extra[:, i]
        for i, lab in enumerate(self.labels):
            table[f"sigma_{lab}"] = sigma[:, i]
        return table

    def process(self, time, gyro, accel, h_ref=None, *, covariance: bool = False) -> AidedResult:
        """Feed one chunk of the IMU record: ``time`` (N,) s, ``gyro``/``accel`` (N, 3) as
        rates (rad/s, m/s²) or increments (rad, m/s) per the ``kind`` given at
        construction, ``h_ref`` (N,) m the reference altitude of a damped vertical
        channel (required then, refused with a free one); time must keep increasing
        across chunks.

        Parameters
        ----------
        time : array_like (N,)
            Sample times, s, increasing across chunks.
        gyro : array_like (N, 3)
            Angular rate, rad/s (rates) or angle increment, rad (increments).
        accel : array_like (N, 3)
            Specific force, m/s² (rates) or velocity increment, m/s (increments).
        h_ref : array_like (N,), optional
            Reference (barometric) altitude, m; required with a damped vertical channel,
            refused with a free one.
        covariance : bool, default False
            Also return the full error-state covariance of every epoch of the chunk
            (:attr:`AidedResult.covariance`, 8n² bytes per epoch): streaming the record
            chunk by chunk keeps the memory bounded.

        Returns
        -------
        AidedResult
            The epochs and measurements of this chunk.

        Raises
        ------
        ValueError
            Bad samples (non-finite, time not increasing), naming their index in the
            whole streamed record. If it stops on an error (bad sample, divergence, loss
            of positive definiteness), the exception's ``partial`` attribute is the
            :class:`AidedResult` of the epochs computed before it.

        Warns
        -----
        atomnav.UnitWarning
            A chunk whose accelerations look like g, gyro rates like °/s or time stamps
            like ms, naming ``accel``, ``gyro`` or ``time`` (:meth:`run` checks the whole
            record once).
        """
        t, g, a, h = _imu(time, gyro, accel, h_ref)
        self._plausible(t, g, a)
        with self._covariance_output(covariance):
            return self._call(self._core.process, t, g, a, h)

    @contextmanager
    def _covariance_output(self, covariance):
        """The core outputs every epoch's covariance inside the block when ``covariance``."""
        self._core.output_covariance(flag(covariance, "covariance"))
        try:
            yield
        finally:
            self._core.output_covariance(False)

    def _plausible(self, t, g, a) -> None:
        """The unit warnings of an IMU record (:func:`atomnav.plausibility.imu`): accelerations
        in g, gyro rates in °/s, time stamps in ms."""
        plausibility.imu(t, g, a, self.kind, "accel", gyro_name="gyro", time_name="time")

    def _call(self, fn, *args) -> AidedResult:
        if self._store is None:
            return self._outcome(fn, args)
        with self._store.lock:  # the engine call and the append of its forward pass, as one
            return self._outcome(fn, args)

    def _outcome(self, fn, args) -> AidedResult:
        try:
            out = fn(*args)
        except (ValueError, _core.NumericalError) as e:
            if isinstance(getattr(e, "partial", None), tuple):
                self._keep(e.partial)  # the engine has moved past these epochs
                e.partial = self._result(e.partial)
            raise
        self._keep(out)
        return self._result(out)

    def _keep(self, out) -> None:
        if self._store is not None:
            self._store.append(out[-1])

    def smooth(self, covariance: bool = False, progress: bool = False) -> SmoothedResult:
        """The Rauch–Tung–Striebel fixed-interval smoother (Rauch, Tung & Striebel 1965)
        over the epochs processed so far (call it after :meth:`finish`).

        The backward pass runs in the Rust core, chunk by chunk from the end of the stored
        forward pass (``smooth_chunk`` epochs at a time, chunks on disk memory-mapped),
        carrying the smoothed mean and covariance across chunk boundaries, so the result
        does not depend on the chunk size. In closed loop the smoothed error is referred to
        each epoch's corrected (output) solution; the derivation is in the core
        (``AidedIns::smooth_chunk``, ``rust/filter/aided.rs``).

        Parameters
        ----------
        covariance : bool
            Also return every smoothed error-state covariance (8n² bytes per epoch).
        progress : bool
            Show a progress bar over the chunks.

        Returns
        -------
        SmoothedResult
            The smoothed table (the columns of :attr:`AidedResult.nav`) and, with
            ``covariance``, the covariances (E, n, n) in SI units of the states. Before any
            epoch: an empty table.

        Raises
        ------
        atomnav.InputError
            Naming ``smooth`` when the engine was built without ``smooth=True``.

        Notes
        -----
        Memory: one chunk of the forward pass and its smoothed moments, 8 (5n² + 3n + 17 +
        n_extra) bytes per epoch of the chunk, plus the smoothed table.
        """
        covariance = flag(covariance, "covariance")
        progress = flag(progress, "progress")
        if self._store is None:
            raise input_error("smooth", "the forward pass was not stored: build the aided INS with smooth=True "
                                        "(an option of every factory, a field of InsSetup)")
        from tqdm.auto import tqdm  # imported here: tqdm.auto pulls in asyncio, which slows `import atomnav`

        with self._store.lock:
            chunks = self._store.chunks()
            navs, covs, after = [], [], None
            for first, c in tqdm(chunks[::-1], desc="smoother", unit="chunk", disable=not progress or len(chunks) < 2):
                out, xs, ps = self._core.smooth_chunk(c["phi"], c["x_prior"], c["p_prior"], c["x_post"], c["p_post"],
                                                      c["nominal"], after, first)
                after = (c["phi"][0], c["x_prior"][0], c["p_prior"][0], c["x_post"][0], c["p_post"][0], xs[0], ps[0])
                navs.append(self._nav(*out[:5]))
                if covariance:
                    covs.append(ps)
        if not navs:  # nothing processed yet: the table of the core's output for no epochs
            m, v = np.zeros((0, 0, 0)), np.zeros((0, 0))
            out, _, ps = self._core.smooth_chunk(m, v, m, v, m, v, None, 0)
            navs, covs = [self._nav(*out[:5])], [ps]
        nav = pd.concat(navs[::-1], ignore_index=True)
        return SmoothedResult(nav, np.concatenate(covs[::-1]) if covariance else None)

    def finish(self, *, covariance: bool = False) -> AidedResult:
        """End of the record: a last epoch at the last sample if steps are left over.

        Parameters
        ----------
        covariance : bool, default False
            Also return the covariance of the last epoch (:attr:`AidedResult.covariance`).

        Returns
        -------
        AidedResult
            The last epoch and its measurements (empty tables if none).
        """
        with self._covariance_output(covariance):
            return self._call(self._core.finish)

    def run(self, time, gyro, accel, h_ref=None, chunk_s: float = 60.0, progress: bool = True, *,
            covariance: bool = False, covariance_memory: int = 1 << 30) -> AidedResult:
        """Run a whole IMU record (see :meth:`process`; ``h_ref`` (N,) m with a damped
        vertical channel) in chunks of about ``chunk_s`` seconds (a fixed number of
        samples) with a progress bar. Every measurement must lie inside the record. The
        result is the same for any chunk length. Bad samples raise ``ValueError`` naming
        their index in the record (the Rust engine checks them chunk by chunk). On an
        error the exception's ``partial`` attribute holds every epoch computed before it.
        With ``smooth=True`` the result's ``smoothed`` is :meth:`smooth` over the record
        (the progress bar then also covers its chunks).

        Parameters
        ----------
        time : array_like (N,)
            Sample times, s (N ≥ 2); every measurement must lie inside [time[0], time[-1]].
        gyro : array_like (N, 3)
            Angular rate, rad/s (rates) or angle increment, rad (increments).
        accel : array_like (N, 3)
            Specific force, m/s² (rates) or velocity increment, m/s (increments).
        h_ref : array_like (N,), optional
            Reference (barometric) altitude, m, with a damped vertical channel.
        chunk_s : float, default 60.0
            Approximate chunk length, s.
        progress : bool, default True
            Show a progress bar.
        covariance : bool, default False
            Also return the full error-state covariance of every epoch
            (:attr:`AidedResult.covariance`, for :meth:`AidedResult.nees`).
        covariance_memory : int, default 2**30
            Largest number of bytes the covariances may take (8n² per epoch); a longer
            record is refused before it runs: stream it with :meth:`process`
            (``covariance=True`` per chunk) and keep what you need of each chunk.

        Returns
        -------
        AidedResult
            Every epoch and measurement of the record (and ``smoothed`` with
            ``smooth=True``).

        Raises
        ------
        ValueError
            Bad samples, naming their index in the record; ``partial`` holds every epoch
            computed before the error.
        atomnav.InputError
            Naming ``time`` (fewer than 2 samples, or a measurement outside the record),
            ``chunk_s``, or ``covariance`` when the covariances would take more than
            ``covariance_memory`` bytes.

        Warns
        -----
        atomnav.UnitWarning
            Accelerations in g, gyro rates in °/s or time stamps in ms, naming ``accel``,
            ``gyro`` or ``time``.
        """
        t, g, a, h = _imu(time, gyro, accel, h_ref)
        self._plausible(t, g, a)  # once, on the whole record (a chunk may look static while the record moves)
        positive(chunk_s, "chunk_s")
        progress = flag(progress, "progress")
        n = len(t)
        if n < 2:
            raise input_error("time", f"need >= 2 samples, got {n}")
        mt = np.asarray(self._core.measurement_times)
        outside = np.nonzero((mt < t[0]) | (mt > t[-1]))[0]
        if outside.size:
            i = outside[0]
            raise input_error("time", f"the measurement at {mt[i]:g} s (index {i}) is outside the IMU span [{t[0]:g}, {t[-1]:g}] s", i)
        # chunks of a fixed sample count from the mean step (one chunk when the end times
        # are not usable; the engine then names the bad sample)
        if flag(covariance, "covariance"):
            # at most one epoch per `predict_every` samples plus one per measurement
            epochs = n // self.setup.predict_every + len(mt) + 1
            need = 8 * len(self.labels) ** 2 * epochs
            if need > integer(covariance_memory, "covariance_memory", 0):
                raise input_error("covariance", f"the covariances of up to {epochs} epochs take {need / 2**20:.0f} MiB, more than "
                                                f"covariance_memory = {covariance_memory / 2**20:.0f} MiB: raise it, or stream the "
                                                "record with process(..., covariance=True) chunk by chunk")
        step = (t[-1] - t[0]) / (n - 1)
        size = max(1, int(chunk_s / step)) if np.isfinite(step) and step > 0 else n
        bounds = list(range(0, n, size)) + [n]
        parts = []
        from tqdm.auto import tqdm  # imported here: tqdm.auto pulls in asyncio, which slows `import atomnav`

        try:
            with self._covariance_output(covariance):
                for lo, hi in tqdm(list(zip(bounds[:-1], bounds[1:])), desc="aided INS", unit="chunk",
                                   disable=not progress or len(bounds) <= 2):
                    parts.append(self._call(self._core.process, t[lo:hi], g[lo:hi], a[lo:hi], None if h is None else h[lo:hi]))
                parts.append(self._call(self._core.finish))
        except (ValueError, _core.NumericalError) as e:
            if isinstance(getattr(e, "partial", None), AidedResult):
                e.partial = _concat(parts + [e.partial])
            raise
        result = _concat(parts)
        if self._store is not None:
            result.smoothed = self.smooth(progress=progress)
        return result


def _imu(time, gyro, accel, h_ref):
    """Shapes of an IMU chunk; finiteness and time order are the engine's checks."""
    def arr(x, width, name):
        a = np.ascontiguousarray(as_floats(x, name))
        want = (width is None and a.ndim == 1) or (width is not None and a.ndim == 2 and a.shape[1] == width)
        if not want:
            raise input_error(name, f"expected shape {'(N,)' if width is None else f'(N, {width})'}, got {a.shape}")
        return a

    t = arr(time, None, "time")
    g, a = arr(gyro, 3, "gyro"), arr(accel, 3, "accel")
    h = None if h_ref is None else arr(h_ref, None, "h_ref")
    for name, x in (("gyro", g), ("accel", a), ("h_ref", h)):
        if x is not None and len(x) != len(t):
            raise input_error(name, f"expected {len(t)} rows like time, got {len(x)}")
    return t, g, a, h


def _concat(parts: list[AidedResult]) -> AidedResult:
    covs = [p.covariance for p in parts if p.covariance is not None]
    return AidedResult(pd.concat([p.nav for p in parts], ignore_index=True),
                       pd.concat([p.measurements for p in parts], ignore_index=True),
                       np.concatenate([p.innovation for p in parts]),
                       covariance=np.concatenate(covs) if covs else None)


def position_aided_ins(t0: float, lla0, vel0, q0, kind: str, fix_time, fix_lla, fix_cov, *, p0, gyro_psd: float,
                       accel_psd: float, **options) -> AidedIns:
    """A position-aided 15-state INS.

    Fixes are applied at the first IMU epoch at or after their time. The INS arguments
    are the fields of :class:`InsSetup`.

    Parameters
    ----------
    t0 : float
        Time of the initial state, s.
    lla0 : array_like (3,)
        Initial latitude, longitude (rad) and height (m).
    vel0 : array_like (3,)
        Initial NED velocity, m/s.
    q0 : array_like (4,)
        Initial attitude q_nb (scalar first).
    kind : {"rates", "increments"}
        IMU output.
    fix_time : array_like (M,)
        Times of the fixes, s.
    fix_lla : array_like (M, 3)
        Fixed positions: latitude, longitude (rad) and height (m).
    fix_cov : array_like (M, 3, 3)
        NED covariance of each fix, m².
    p0 : array_like (15, 15)
        Initial covariance, SI units of the states squared.
    gyro_psd : float
        Gyro white-noise PSD, rad²/s (keyword-only, like every noise argument).
    accel_psd : float
        Accelerometer white-noise PSD, (m/s²)²/Hz.
    **options
        The other fields of :class:`InsSetup`: bias models, ``ba0``/``bg0``,
        ``predict_every``, ``method``, ``mode``, ``sequential``, ``gate``, ``ellipsoid``,
        the vertical channel and the smoother.

    Returns
    -------
    AidedIns
        The engine; feed it with :meth:`AidedIns.run`.

    Raises
    ------
    atomnav.InputError
        Naming the bad argument (``fix_time``, ``fix_lla``, ``fix_cov`` or a field of
        :class:`InsSetup`).

    Examples
    --------
    >>> ins = position_aided_ins(...)              # doctest: +SKIP
    >>> result = ins.run(time, gyro, accel)        # doctest: +SKIP
    >>> truth.errors(result.nav)                   # doctest: +SKIP
    """
    from .sources import _PositionFixArguments, aided_ins  # the one construction path (sources import this module)

    setup = InsSetup(t0=t0, lla0=lla0, vel0=vel0, q0=q0, kind=kind, p0=p0, accel_psd=accel_psd, gyro_psd=gyro_psd,
                     **options)
    # types and shapes named by this call's arguments; the values are checked by the source
    fix_time, fix_lla = as_floats(fix_time, "fix_time").ravel(), rows(fix_lla, 3, "fix_lla")
    with renamed(time="fix_time", lla="fix_lla", cov="fix_cov"):
        fixes = _PositionFixArguments(fix_time, fix_lla, as_floats(fix_cov, "fix_cov"))
    return aided_ins(setup, fixes)
