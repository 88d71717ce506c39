"""The CAI as the filter sees it (:class:`CaiSensor`), the filter tuning
(:class:`FilterSetup`), the in-shot IMU noise of a shot, the CAI shots as a measurement
source of the generic aided INS (:class:`CaiShots`) and the CAI-aided INS built from them
(:func:`cai_aided_ins`).

The Rust core (``rust/cai/aiding.rs``) plugs the CAI into the generic aided-INS engine:
every shot's six (or fewer) raw populations are stacked into one update, the predicted
readout comes from the atom-strapdown predictor driven by the bias-compensated IMU stream,
the laser phase is steered to mid-fringe from the filter's own prediction, the innovation
is nonlinear and H comes from the tangent-linear predictor (Tennstedt et al. 2023, §2.8;
Tennstedt et al. 2021, Eqs. 3–6, 33)."""

from __future__ import annotations

import copy
import warnings
from dataclasses import KW_ONLY, dataclass

import numpy as np
import pandas as pd

from .. import _core, plausibility
from .._core import InputError
from ..filter.sources import Source, SourcedIns, aided_ins
from .._validate import as_floats, choice, finite_scalar, flag, input_error, instance, integer, nonnegative, positive, scalar, vector
from ._config import ConfigMixin
from .predictor import Channels

#: Option names the core accepts (read from the core, which checks them).
OMEGA_DOT_OPTIONS = tuple(_core.OPTIONS["OmegaDot"])
INTERPOLATION_OPTIONS = tuple(_core.OPTIONS["Interpolation"])
FORCE_OPTIONS = tuple(_core.OPTIONS["ForceMode"])
INCOMPLETE_SHOTS_OPTIONS = tuple(_core.OPTIONS["IncompleteShots"])


@dataclass
class CaiSensor(ConfigMixin):
    """The interferometer as the filter sees it.

    The readout is p = o − (C/2) cos(φ + φ0) + n, n ~ N(0, σ_p²). Checked by the core
    when handed to it (:meth:`_native`); convertible to and from dict / JSON.

    Parameters
    ----------
    channels : Channels
        Interferometer geometry, e.g. ``Channels.cyclic`` for the six-channel sensor of
        Tennstedt et al. 2023.
    T : float
        Pulse separation (s).
    shot_period : float, optional
        Time between shot starts (s, ≥ 2T); None = 2T, no dead time.
    offset : float
        Readout offset o (population, 0–1).
    contrast : float
        Readout contrast C ∈ (0, 1].
    sigma_p : float
        Readout noise σ_p (population).
    inflation : tuple of float, optional
        White-noise PSDs (q_a m²/s³, q_g rad²/s) of the IMU(s) for the in-shot R
        inflation (Tennstedt et al. 2021, §2.4); None: no inflation.
    omega_dot : {"savgol", "pwl", "zero"}, optional
        Source of ω̇ for the Euler terms of the predictor (:data:`OMEGA_DOT_OPTIONS` but
        "given"), as in :func:`predict_phase`; None: the predictor's accurate default (ω̇
        from the gyro interpolant, docs/cai_predictor_accuracy.md).
    savgol_half_width : int
        Half width m of the Savitzky–Golay ω̇ window (2m + 1 samples).
    interpolation : {"linear", "cubic"}, optional
        Interpolation of the IMU inputs in the predictor (:data:`INTERPOLATION_OPTIONS`);
        None: the predictor's default (cubic).
    substeps : int
        RK4 steps per interval of the predictor's integration grid.
    jacobian_euler : bool
        Keep the Euler terms in H (needed when the lever arm is estimated: its main
        signature is the Euler term ω̇ × l).
    misalignment_psd : float, optional
        Estimate the CAI misalignment γ as three extra random-walk states with this PSD
        (rad²/s) (21-state filter of Tennstedt et al. 2021); None: not estimated.
    lever_arm_psd : float, optional
        Estimate a lever-arm correction l as three extra random-walk states with this
        PSD (m²/s); None: not estimated.
    force : {"bias", "direct"}
        "bias" = estimate biases (option b of Tennstedt et al. 2021, Eq. 11); "direct" =
        correct the specific force through a Gauss–Markov force-error block (option a).
    force_tau : float, optional
        Correlation time of the force-error block (s), with ``force="direct"``.
    force_sigma : float, optional
        σ of the force-error block (m/s²), with ``force="direct"``.
    first_shot : float
        Start of the first shot (s) after the record start in a Monte-Carlo campaign
        (:func:`atomnav.cai.run_campaign`; a shot whose Savitzky–Golay ω̇ window of
        2m + 1 samples does not fit between the record start and its end is skipped).
    """

    _NESTED = {"channels": Channels}

    channels: Channels
    T: float
    _: KW_ONLY
    shot_period: float | None = None
    offset: float = 0.5
    contrast: float = 1.0
    sigma_p: float = float(np.sqrt(1e-3))
    inflation: tuple | None = None
    omega_dot: str | None = None
    savgol_half_width: int = 2
    interpolation: str | None = None
    substeps: int = 1
    jacobian_euler: bool = False
    misalignment_psd: float | None = None
    lever_arm_psd: float | None = None
    force: str = "bias"
    force_tau: float | None = None
    force_sigma: float | None = None
    first_shot: float = 0.0

    def shots(self, t0: float, t_end: float) -> np.ndarray:
        """Shot start times from t0, one per ``shot_period``, the last ending by t_end.

        Parameters
        ----------
        t0 : float
            Start of the first shot (s).
        t_end : float
            Time (s) by which the last shot ends (its start + 2T).

        Returns
        -------
        numpy.ndarray, shape (S,)
            Shot start times (s).

        Raises
        ------
        atomnav.InputError
            Naming ``T`` or ``shot_period`` when the sensor's own timing is invalid.
        """
        T = scalar(self.T, "T")
        period = 2 * T if self.shot_period is None else scalar(self.shot_period, "shot_period")
        return _core.cai_shot_times(finite_scalar(t0, "t0"), finite_scalar(t_end, "t_end"), T, period)

    def n_extra(self) -> int:
        """Number of extra filter states (misalignment, lever arm, force error).

        Returns
        -------
        int
            3 per estimated block: 0, 3, 6 or 9.
        """
        return 3 * ((self.misalignment_psd is not None) + (self.lever_arm_psd is not None) + (self.force == "direct"))

    def _checked(self, name: str):
        """:meth:`_native` for the argument ``name`` of a call: a bad field is an
        :class:`atomnav.InputError` naming ``name.field`` (e.g. ``sensor.T``); a T in ms, or
        a contrast or offset in %, is an :class:`atomnav.UnitWarning` naming it alike."""
        plausibility.pulse_separation(self.T, f"{name}.T")
        plausibility.fraction(self.contrast, f"{name}.contrast", "contrast")
        plausibility.fraction(self.offset, f"{name}.offset", "offset")
        try:
            return self._native()
        except InputError as e:
            raise input_error(f"{name}.{e.parameter}", str(e), e.index) from None

    def _native(self):
        """The checked core sensor (``_core.CaiSensor``) that the Monte Carlo, :func:`cai_aided_ins`
        and :func:`in_shot_noise` take together with their shots."""
        return _core.CaiSensor(self.channels._native(), positive(self.T, "T"), offset=float(self.offset), contrast=float(self.contrast),
                               sigma_p=float(self.sigma_p), inflation=self.inflation, omega_dot=self.omega_dot,
                               savgol_half_width=self.savgol_half_width, interpolation=self.interpolation, substeps=self.substeps,
                               jacobian_euler=flag(self.jacobian_euler, "jacobian_euler"), misalignment=self.misalignment_psd, lever_arm=self.lever_arm_psd,
                               force=self.force, force_tau=self.force_tau, force_sigma=self.force_sigma)


@dataclass
class FilterSetup(ConfigMixin):
    """Filter tuning of the CAI-aided INS. Convertible to and from dict / JSON.

    Parameters
    ----------
    accel_psd : float
        Accelerometer white-noise PSD (m²/s³).
    gyro_psd : float
        Gyro white-noise PSD (rad²/s).
    accel_bias_psd : float
        Accelerometer bias random-walk PSD (m²/s⁵).
    gyro_bias_psd : float
        Gyro bias random-walk PSD (rad²/s³).
    predict_every : int
        Prediction interval in IMU steps.
    sigma0 : tuple of float
        Initial σ of (position m, velocity m/s, attitude rad, accel bias m/s², gyro bias
        rad/s), each for all three axes.
    sigma0_extra : tuple of float
        Initial σ of the extra CAI states (misalignment rad, lever arm m, force error
        m/s²), one per state.
    """

    accel_psd: float
    gyro_psd: float
    accel_bias_psd: float
    gyro_bias_psd: float
    predict_every: int
    sigma0: tuple = (1e-6, 1e-6, 1e-5, 2e-5, 1e-6)
    sigma0_extra: tuple = ()

    def p0(self, n_extra: int) -> np.ndarray:
        """Diagonal P0 of the 15 INS states and ``n_extra`` extra states.

        Parameters
        ----------
        n_extra : int
            Number of extra CAI states (:meth:`CaiSensor.n_extra`); must equal the length
            of ``sigma0_extra``.

        Returns
        -------
        numpy.ndarray, shape (15 + n_extra, 15 + n_extra)
            Initial covariance (SI units of the states).

        Raises
        ------
        atomnav.InputError
            Naming ``n_extra`` when it differs from the length of ``sigma0_extra``.
        """
        n_extra = integer(n_extra, "n_extra", 0, 2**20)
        s = np.repeat(vector(self.sigma0, 5, "sigma0"), 3)
        extra = vector(self.sigma0_extra, None, "sigma0_extra")
        if len(extra) != n_extra:
            raise input_error("n_extra", f"{n_extra} extra CAI states but {len(extra)} values in sigma0_extra")
        return np.diag(np.concatenate([s, extra]) ** 2)


def in_shot_noise(sensor: CaiSensor, dt: float, q_accel: float, q_gyro: float, f=None) -> tuple[np.ndarray, np.ndarray]:
    """In-shot IMU noise of one shot of ``sensor`` driven by an IMU sampled every ``dt`` s with
    white-noise PSDs ``q_accel`` (m²/s³) and ``q_gyro`` (rad²/s) (Tennstedt et al. 2021,
    §2.4, ``rust/cai/in_shot.rs``): the phase covariance Σ (C, C) rad² from the predictor's
    sensitivity to every sample — which, unlike the closed form of Tennstedt et al. 2023,
    Eq. 38, includes the atom Euler term (gyro variance 4T³q_g(kv0)² instead of
    (8/3)T³q_g(kv0)², i.e. 0.3667 instead of 0.2994 rad for the navigation IMU) and the
    lever-arm Euler term (2Tq_g|l × k|², 0.370 rad for l = 0.1 m ⊥ k) — and, for each
    15-state model ``f`` (S, 15, 15) held over a filter step of one shot, the
    cross-covariance E[w δφ̂ᵀ] (S, 15, C) of the step's process noise with the shot's phase
    noise (the readout senses the same IMU noise that drives the error).

    Parameters
    ----------
    sensor : CaiSensor
        The interferometer (C channels).
    dt : float
        IMU sample interval (s).
    q_accel : float
        Accelerometer white-noise PSD (m²/s³).
    q_gyro : float
        Gyro white-noise PSD (rad²/s).
    f : array_like, shape (S, 15, 15), optional
        15-state error models, each held over a filter step of one shot; None: no
        cross-covariance.

    Returns
    -------
    sigma : numpy.ndarray, shape (C, C)
        Phase covariance Σ (rad²).
    cross : numpy.ndarray, shape (S, 15, C)
        Cross-covariance E[w δφ̂ᵀ] of each step's process noise with the shot's phase
        noise (SI units of the states × rad).
    """
    instance(sensor, CaiSensor, "sensor")
    f = np.zeros((0, 15, 15)) if f is None else np.ascontiguousarray(as_floats(f, "f"))
    if f.ndim != 3:
        raise input_error("f", f"expected an (S, 15, 15) stack, got shape {f.shape}")
    return _core.cai_in_shot_noise(sensor._checked("sensor"), plausibility.sample_interval(positive(dt, "dt"), "dt"), nonnegative(q_accel, "q_accel"),
                                   nonnegative(q_gyro, "q_gyro"), f)


def expected_phase_exceedance(sensor: CaiSensor, dt: float, q_accel: float, q_gyro: float, limit: float = np.pi / 2) -> float:
    """Share of shot-channels expected to have |true − predicted phase| > ``limit`` (rad) from
    the in-shot IMU noise alone (Gaussian, σ_j² = Σ_jj of :func:`in_shot_noise`), averaged
    over the channels: mean_j 2Φ(−limit/σ_j). Bias-estimation errors and dynamics add to it.
    Six-channel sensor at 200 Hz: σ = 0.40 rad on every channel with l = 0 (→ 8.5e-5), but
    0.53 / 0.68 / 0.33 rad on x / y-A / y-B with l = [0, 0, 0.1] m, where the lever-arm Euler
    term adds 0.37 rad of gyro noise (→ 4.4e-3, 2.0 % on channel y-A).

    Parameters
    ----------
    sensor : CaiSensor
        The interferometer.
    dt : float
        IMU sample interval (s).
    q_accel : float
        Accelerometer white-noise PSD (m²/s³).
    q_gyro : float
        Gyro white-noise PSD (rad²/s).
    limit : float
        Phase limit (rad); π/2 is the edge of the capture region.

    Returns
    -------
    float
        Expected share of shot-channels beyond ``limit`` (0–1).
    """
    from scipy.stats import norm

    limit = positive(limit, "limit")
    sigma, _ = in_shot_noise(sensor, dt, q_accel, q_gyro)
    return float(np.mean(2 * norm.sf(limit / np.sqrt(np.diag(sigma)))))


def cai_aided_ins(t0: float, lla0, vel0, q0, sensor: CaiSensor, shots, *, phase=None, noise=None, population=None, laser_phase=None,
                  kind: str | None = None, setup: FilterSetup | None = None, p0=None, ba0=(0, 0, 0), bg0=(0, 0, 0), extra0=None,
                  method: str = "van_loan", mode: str = "closed", sequential: bool = False, gate: float | None = None,
                  ellipsoid: str = "WGS84", incomplete_shots: str = "skip", smooth: bool = False, smooth_chunk: int | None = None,
                  smooth_memory: int | None = None, smooth_dir: str | None = None) -> SourcedIns:
    """A CAI-aided INS on the generic engine, for your own IMU record and CAI shots.

    The filter is the error-state INS of :class:`atomnav.filter.AidedIns` with one stacked
    update per shot: the raw populations of every interferometer of ``sensor`` against the
    readout predicted from the bias-compensated IMU stream (Tennstedt et al. 2023, §2.8;
    Tennstedt et al. 2021, Eqs. 3–6, 33). Run it with ``.run(time, gyro, accel)`` on the
    whole record, or feed it chunk by chunk with ``.process``. It is
    :func:`atomnav.filter.aided_ins` fed by one :class:`CaiShots` source, with the INS
    set up from ``setup``; to add other sources (position fixes, ...), call that with
    your :class:`atomnav.filter.InsSetup` and sources.

    Parameters
    ----------
    t0 : float
        Time of the initial state (s), the first IMU time stamp.
    lla0 : array_like, shape (3,)
        Initial position: latitude (rad), longitude (rad), height (m).
    vel0 : array_like, shape (3,)
        Initial NED velocity (m/s).
    q0 : array_like, shape (4,)
        Initial attitude q_nb, Hamilton, scalar first, unit norm.
    sensor, shots, phase, noise, population, laser_phase, extra0, incomplete_shots
        The interferometer, its shots and their data, as for :class:`CaiShots`.
    kind : {"rates", "increments"}
        Kind of the IMU record (required: it comes as plain arrays).
    setup : FilterSetup, optional
        Filter noise and initial σ (default: the tuning of Tennstedt et al. 2023,
        :func:`atomnav.cai.seed003_filter`).
    p0 : array_like, shape (15 + E, 15 + E), optional
        Initial covariance (SI units of the states); overrides ``setup.p0``.
    ba0, bg0 : array_like, shape (3,)
        Initial accelerometer (m/s²) and gyro (rad/s) bias estimates.
    method, mode, sequential, gate, ellipsoid
        As in :func:`atomnav.filter.position_aided_ins`.
    smooth : bool
        Store the forward pass for the Rauch–Tung–Striebel smoother (Rauch, Tung &
        Striebel 1965): ``run`` then also returns the smoothed solution
        (``result.smoothed``), and :meth:`atomnav.filter.AidedIns.smooth` smooths a
        streamed record.
    smooth_chunk, smooth_memory, smooth_dir : optional
        Epochs per chunk of the stored forward pass, bytes held in memory before chunks
        go to disk, and the directory they go to, as in
        :class:`atomnav.filter.InsSetup` (None: its defaults).

    Returns
    -------
    atomnav.filter.sources.SourcedIns
        The filter (an :class:`atomnav.filter.AidedIns`); its results have the bias
        estimates (``accel_bias_*_mps2``, ``gyro_bias_*_rad_s``), σ of every state and the
        NIS of every applied shot.
    """
    from ..filter.aided import InsSetup
    from ..filter.engine import BiasModel
    from .scenarios import seed003_filter

    source = CaiShots(sensor, shots, phase=phase, noise=noise, population=population, laser_phase=laser_phase, extra0=extra0,
                      incomplete_shots=incomplete_shots)
    if setup is not None:
        instance(setup, FilterSetup, "setup")
    setup = setup or seed003_filter()
    smoothing = {name: value for name, value in (("smooth_chunk", smooth_chunk), ("smooth_memory", smooth_memory),
                                                  ("smooth_dir", smooth_dir)) if value is not None}
    ins = InsSetup(t0=t0, lla0=lla0, vel0=vel0, q0=q0, kind=kind, p0=setup.p0(sensor.n_extra()) if p0 is None else p0,
                   accel_psd=setup.accel_psd, gyro_psd=setup.gyro_psd,
                   accel_bias=BiasModel("random_walk", psd=setup.accel_bias_psd),
                   gyro_bias=BiasModel("random_walk", psd=setup.gyro_bias_psd), ba0=ba0, bg0=bg0,
                   predict_every=setup.predict_every, method=method, mode=mode, sequential=sequential, gate=gate,
                   ellipsoid=ellipsoid, smooth=smooth, **smoothing)
    return aided_ins(ins, [source])


class CaiShots(Source):
    """CAI shots as one measurement source of :func:`atomnav.filter.aided_ins`: one stacked
    update per shot, the raw populations of every interferometer of ``sensor`` against the
    readout predicted from the bias-compensated IMU stream (Tennstedt et al. 2023, §2.8;
    Tennstedt et al. 2021, Eqs. 3–6, 33).

    >>> ins = aided_ins(setup, [CaiShots(sensor, shots, population=p, laser_phase=phi),
    ...                         PositionFixes(fixes)])                        # doctest: +SKIP

    Parameters
    ----------
    sensor : CaiSensor
        The interferometer: any channels (k directions, lever arms, C_sb, launch
        velocities, see :class:`Channels`), pulse separation T (s), readout model.
    shots : array_like, shape (S,)
        Shot start times (s): pulses at +0, +T, +2T, the update at +2T. Any schedule of
        non-overlapping shots (e.g. ``sensor.shots(t_first, t_last)``).
    phase, noise : array_like, shape (S, C), optional
        Emulated instrument: the true phase (rad) and the population noise of every shot
        and channel; the filter steers the laser phase to mid-fringe inside the loop.
    population, laser_phase : array_like, shape (S, C), optional
        Recorded instrument: the measured population (0–1) and the laser phase (rad) the
        instrument applied. Give either ``phase`` and ``noise`` or these two.
    extra0 : array_like, shape (E,), optional
        Initial values of the sensor's extra states (misalignment rad, lever arm m, force
        error m/s², :meth:`CaiSensor.n_extra` of them); zeros by default.
    sigma0_extra : array_like, shape (E,), optional
        Their initial σ (same units), uncorrelated. Needed when the sensor has extra
        states and the setup's ``p0`` is the (15, 15) INS block; a ``p0`` over the whole
        state replaces it.
    incomplete_shots : {"skip", "error"}
        A shot whose interferometer window needs IMU samples before the record start or
        after its end — the pulses themselves, or a whole Savitzky–Golay ω̇ window of
        2m + 1 samples (``sensor.omega_dot = "savgol"``) that a shot in mid-record has
        before it — cannot be predicted. "skip" (the default) leaves it out with an
        :class:`IncompleteShotWarning` naming the shot's index, its start time and the
        samples it lacks; "error" refuses the record with an :class:`atomnav.InputError`
        naming ``shots``, the same facts and the shot's index. :meth:`incomplete` lists
        them beforehand. The INS's ``run`` checks the whole record before it starts;
        ``process`` checks the record start on its first chunk (a shot past the end of a
        streamed record is simply still pending).

    Every argument is checked here; a bad one raises :class:`atomnav.InputError` naming
    it (``sensor.T`` for a field of the sensor) and, for a table, its first bad row.
    """

    def __init__(self, sensor: CaiSensor, shots, *, phase=None, noise=None, population=None, laser_phase=None, extra0=None,
                 sigma0_extra=None, incomplete_shots: str = "skip"):
        #: The interferometer.
        self.sensor = instance(sensor, CaiSensor, "sensor")
        #: "skip" or "error" (see above).
        self.incomplete_shots = choice(incomplete_shots, INCOMPLETE_SHOTS_OPTIONS, "incomplete_shots")
        emulated = phase is not None or noise is not None
        if emulated == (population is not None or laser_phase is not None):
            raise input_error("population" if emulated else "phase",
                              "give either phase and noise (emulated instrument) or population and laser_phase (recorded)")
        a, b = (phase, noise) if emulated else (population, laser_phase)
        names = ("phase", "noise") if emulated else ("population", "laser_phase")
        if a is None or b is None:
            missing, given = (names[1], names[0]) if a is not None else (names[0], names[1])
            raise input_error(missing, f"required together with {given}")
        tables = []
        for x, name in zip((a, b), names):
            x = as_floats(x, name)
            if x.ndim != 2:
                raise input_error(name, f"expected a (shots, interferometers) array, got shape {x.shape}")
            tables.append(np.ascontiguousarray(x))
        if not emulated:
            plausibility.population(tables[0], "population")
        n_extra = sensor.n_extra()
        #: "emulated" (true phase and noise) or "recorded" (population and laser phase).
        self.data_kind = "emulated" if emulated else "recorded"
        #: Shot start times (S,), s.
        self.shots = vector(shots, None, "shots")
        #: The two (S, C) tables of the shots' data, in the order of the arguments.
        self.data = tuple(tables)
        #: Initial values of the extra states (E,).
        self.extra0 = vector(np.zeros(n_extra) if extra0 is None else extra0, n_extra, "extra0")
        #: Their initial σ (E,), or None.
        self.sigma0_extra = None
        if sigma0_extra is not None:
            sigma = vector(sigma0_extra, n_extra, "sigma0_extra")
            for i, v in enumerate(sigma):
                if v < 0:
                    raise input_error("sigma0_extra", f"must be >= 0, got {v} at index {i}", i)
            self.sigma0_extra = sigma
        self._sensor = sensor._checked("sensor")
        self._native()  # the core checks the shots and their tables now

    def _native(self) -> _core.AidingSource:
        var = None if self.sigma0_extra is None else self.sigma0_extra**2
        return _core.cai_source(self.extra0, var, self._sensor, self.shots, self.data_kind, *self.data, self.incomplete_shots)

    def incomplete(self, time) -> pd.DataFrame:
        """The shots the IMU record ``time`` cannot complete, as :func:`incomplete_shots` lists them.

        Parameters
        ----------
        time : array_like, shape (N,)
            The IMU time stamps (s), increasing.

        Returns
        -------
        pandas.DataFrame
            One row per incomplete shot: ``shot``, ``start_s``, ``samples_before``,
            ``samples_after`` and ``reason``.
        """
        return incomplete_shots(self.sensor, self.shots, time)

    def _report(self, time: np.ndarray, start_only: bool) -> list:
        """Report the shots ``time`` cannot complete (at its start only, or anywhere):
        warn, or raise for "error". Returns their indices."""
        found = _core.cai_incomplete_shots(self._sensor, self.shots, time)
        if start_only:
            found = [f for f in found if f[2] > 0]
        for index, ts, before, after, reason in found:
            if self.incomplete_shots == "error":
                raise input_error("shots", f"{reason} (incomplete_shots='error'; 'skip' leaves it out)", index)
            warnings.warn(IncompleteShotWarning(f"{reason}: skipped (incomplete_shots='skip')", index, ts, before, after), stacklevel=5)
        return [f[0] for f in found]

    def _check_record(self, time: np.ndarray, whole: bool) -> "CaiShots":
        """Report the shots the record cannot complete (see ``incomplete_shots``); for the
        whole record, with "skip", this source without them."""
        drop = self._report(time, start_only=not whole)
        return self._without(drop) if whole and drop else self

    def _without(self, drop) -> "CaiShots":
        """A copy without the shots of index ``drop``."""
        keep = np.setdiff1d(np.arange(len(self.shots)), drop)
        other = copy.copy(self)
        other.shots, other.data = self.shots[keep], tuple(x[keep] for x in self.data)
        return other

    def __len__(self) -> int:
        return len(self.shots)

    def __repr__(self) -> str:
        span = f", {self.shots[0]:g} to {self.shots[-1]:g} s" if len(self) else ""
        return f"CaiShots({len(self)} shots, {self.data_kind}{span})"


class IncompleteShotWarning(UserWarning):
    """A CAI shot the IMU record cannot complete was left out (``incomplete_shots="skip"``).

    Attributes
    ----------
    index : int
        The shot's index in ``shots``.
    time_s : float
        Its start time (s).
    before, after : int
        IMU samples it lacks before the record start and after the record end.
    """

    def __init__(self, message: str, index: int, time_s: float, before: int, after: int):
        super().__init__(message)
        self.index, self.time_s, self.before, self.after = index, time_s, before, after


def incomplete_shots(sensor: CaiSensor, shots, time) -> pd.DataFrame:
    """The shots a record cannot complete (see ``incomplete_shots`` of :func:`cai_aided_ins`).

    Parameters
    ----------
    sensor : CaiSensor
        The interferometer (T, ω̇ source and its window).
    shots : array_like, shape (S,)
        Shot start times (s).
    time : array_like, shape (N,)
        The IMU time stamps (s), increasing.

    Returns
    -------
    pandas.DataFrame
        One row per incomplete shot: ``shot`` (index), ``start_s``, ``samples_before``
        and ``samples_after`` (IMU samples it lacks before the record start and after
        its end, counted at the record's mean spacing) and ``reason``.
    """
    instance(sensor, CaiSensor, "sensor")
    found = _core.cai_incomplete_shots(sensor._checked("sensor"), vector(shots, None, "shots"), vector(time, None, "time"))
    return pd.DataFrame(found, columns=["shot", "start_s", "samples_before", "samples_after", "reason"])
