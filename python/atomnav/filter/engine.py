"""Error-state Kalman filter engine (Rust core, ``rust/filter``).

Conventions (binding, README "Conventions"): δx = estimate − true; attitude error ψ with
Ĉ_b^n = (I − [ψ×])C_b^n; sensor bias errors δb = b̂ − b. A measurement is given as
z = predicted − measured ≈ H δx + v. SI units throughout.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass

import numpy as np

from .. import _core, plausibility
from .._validate import as_floats, finite_scalar, flag, input_error, instance, integer, json_object, renamed, rows, vector
from .riccati import _mat

#: Standard blocks and their sizes (read from the core, ``rust/filter/layout.rs``); extra
#: blocks (lever arm, clock, ...) give their size.
STANDARD_BLOCKS = dict(_core.STATE_BLOCKS)
#: The 15-state INS layout (Groves 2013, §14.2.1; from the core).
INS15 = tuple(_core.INS15)
#: Bias process names (from the core).
BIAS_KINDS = tuple(_core.OPTIONS["BiasKind"])


def _plain(x):
    """A config value as JSON-ready Python (configs as dicts, arrays and tuples as lists)."""
    if isinstance(x, Config):
        return x.to_dict()
    if isinstance(x, (tuple, list, np.ndarray)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    return x


class Config:
    """Mixin of the frozen configuration dataclasses (:class:`BiasModel`,
    :class:`atomnav.filter.aided.InsSetup`, :class:`atomnav.gnss.GnssOptions`): save a run's
    configuration beside its results and rebuild it. ``_NESTED`` maps a field to the
    config class its dict is rebuilt with."""

    _NESTED: dict = {}

    def to_dict(self) -> dict:
        """Every field as plain Python.

        Returns
        -------
        dict
            Field name to value (nested configs as dicts, arrays as lists).
        """
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, d: dict):
        """The configuration of :meth:`to_dict`'s dict.

        Parameters
        ----------
        d : dict
            Field name to value; nested configs may be dicts.

        Returns
        -------
        Config
            An instance of the class it is called on.

        Raises
        ------
        atomnav.InputError
            Naming an unknown key.
        """
        instance(d, dict, "d")
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise input_error(unknown[0], f"not a field of {cls.__name__} (fields: {', '.join(sorted(names))})")
        kw = {k: cls._NESTED[k].from_dict(v) if k in cls._NESTED and isinstance(v, dict) else v for k, v in d.items()}
        return cls(**kw)

    def to_json(self, **kwargs) -> str:
        """:meth:`to_dict` as JSON.

        Parameters
        ----------
        **kwargs
            Passed to :func:`json.dumps` (e.g. ``indent``).

        Returns
        -------
        str
            The JSON text.
        """
        return json.dumps(self.to_dict(), **kwargs)

    @classmethod
    def from_json(cls, text: str):
        """The configuration of :meth:`to_json`'s text.

        Parameters
        ----------
        text : str
            A JSON object of the fields.

        Returns
        -------
        Config
            An instance of the class it is called on.

        Raises
        ------
        atomnav.InputError
            Naming ``text`` when it is not a JSON object, or an unknown key.
        """
        return cls.from_dict(json_object(text, "text"))


def _floats(x) -> tuple:
    """A vector or matrix as (nested) tuples of floats: hashable, comparable, JSON-ready."""
    a = as_floats(x, "x")
    return tuple(map(float, a)) if a.ndim <= 1 else tuple(_floats(r) for r in a)


def _block_spec(blocks) -> list[tuple[str, int | None]]:
    if isinstance(blocks, (str, bytes)) or not isinstance(blocks, (list, tuple)):
        raise TypeError(f"blocks: expected a sequence of block names or (name, size) pairs, got {type(blocks).__name__}")
    out = []
    for i, b in enumerate(blocks):
        if isinstance(b, str):
            out.append((b, None))
        elif isinstance(b, (list, tuple)) and len(b) == 2 and isinstance(b[0], str):
            out.append((b[0], integer(b[1], "blocks", 0, 2**20)))
        else:
            raise TypeError(f"blocks: element {i} is not a block name or a (name, size) pair: {b!r}")
    return out


class Layout:
    """State layout from named blocks, e.g. ``Layout(INS15 + (("clock", 2),))``.

    Indices are derived: ``layout["gyro_bias"]`` is a slice; an unknown name raises
    ValueError.

    Parameters
    ----------
    blocks : sequence of str or (str, int), default INS15
        Block names in state order: a standard block by name (:data:`STANDARD_BLOCKS`
        gives its size) or an extra block as a ``(name, size)`` pair.

    Raises
    ------
    TypeError
        ``blocks`` is not a sequence of names or (name, size) pairs.
    """

    def __init__(self, blocks=INS15):
        self._spec = _block_spec(blocks)
        self._ranges = {n: slice(a, b) for n, a, b in _core.layout_ranges(self._spec)}

    def __getitem__(self, name: str) -> slice:
        if not isinstance(name, str):
            raise TypeError(f"name: a Layout is indexed by block name (str), got {type(name).__name__}")
        if name not in self._ranges:
            raise input_error("name", f"unknown block name {name!r} (layout has: {', '.join(self._ranges)})")
        return self._ranges[name]

    @property
    def spec(self) -> list[tuple[str, int | None]]:
        return list(self._spec)

    @property
    def size(self) -> int:
        return max(s.stop for s in self._ranges.values())

    @property
    def labels(self) -> list[str]:
        """Name of every state component, e.g. ``velocity[2]``."""
        return [f"{n}[{i}]" for n, s in self._ranges.items() for i in range(s.stop - s.start)]

    def covariance(self, **sigma) -> np.ndarray:
        """A diagonal covariance (e.g. the initial P₀) from the σ of every block, named by
        the layout, so no index is counted by hand.

        Parameters
        ----------
        **sigma : float or array_like
            One keyword per block of the layout (every block, none other): its σ in the
            block's SI units (position m, velocity m/s, attitude rad, accel_bias m/s²,
            gyro_bias rad/s, ...), one value for the whole block or one per component.

        Returns
        -------
        numpy.ndarray (n, n)
            diag(σ²) in layout order.

        Raises
        ------
        atomnav.InputError
            Naming a block that is missing or not in the layout, or a σ that is negative,
            non-finite or of the wrong length.

        Examples
        --------
        >>> p0 = Layout().covariance(position=3.0, velocity=0.1, attitude=(1e-3, 1e-3, 1e-2),
        ...                          accel_bias=2e-3, gyro_bias=1e-5)  # doctest: +SKIP
        """
        unknown = [b for b in sigma if b not in self._ranges]
        if unknown:
            raise input_error(unknown[0], f"not a block of this layout (it has: {', '.join(self._ranges)})")
        missing = [b for b in self._ranges if b not in sigma]
        if missing:
            raise input_error(missing[0], f"no sigma given for the block {missing[0]!r}: give every block of the layout "
                                          f"({', '.join(self._ranges)})")
        diag = np.zeros(self.size)
        for name, block in self._ranges.items():
            width = block.stop - block.start
            v = np.atleast_1d(as_floats(sigma[name], name))
            if v.ndim != 1 or len(v) not in (1, width):
                raise input_error(name, f"expected one sigma or {width} (one per component), got shape {v.shape}")
            bad = np.nonzero(~np.isfinite(v) | (v < 0))[0]
            if bad.size:
                raise input_error(name, f"sigma must be finite and >= 0, got {v[bad[0]]} at index {bad[0]}", int(bad[0]))
            diag[block] = np.broadcast_to(v, (width,)) ** 2
        return np.diag(diag)


def discretize(f, qc, dt: float, method: str = "van_loan") -> tuple[np.ndarray, np.ndarray]:
    """(Φ, Q_d) of ẋ = Fx + w, E[wwᵀ] = Q_c δ(t−s), over dt (s).

    Parameters
    ----------
    f : array_like (n, n)
        System matrix F, 1/s.
    qc : array_like (n, n)
        Continuous process-noise PSD Q_c, squared state units per s.
    dt : float
        Interval, s.
    method : {"van_loan", "first_order"}, default "van_loan"
        "van_loan" (exact for constant F) or "first_order" (Φ = I + FΔt, Q_d = Q_cΔt).

    Returns
    -------
    phi : numpy.ndarray (n, n)
        Transition matrix Φ over ``dt``.
    qd : numpy.ndarray (n, n)
        Discrete process-noise covariance Q_d, squared state units.

    References
    ----------
    C. F. Van Loan, "Computing integrals involving the matrix exponential", *IEEE Trans.
    Automatic Control* 23 (1978). P. D. Groves, *Principles of GNSS, Inertial, and
    Multisensor Integrated Navigation Systems*, 2nd ed. (2013), ch. 3.
    """
    return _core.discretize_model(_mat(f, "f"), _mat(qc, "qc"), finite_scalar(dt, "dt"), method)


@dataclass(frozen=True)
class BiasModel(Config):
    """Per-axis bias process: ``kind`` one of :data:`BIAS_KINDS` — ``random_constant``,
    ``random_walk`` (psd in units²/s) or ``gauss_markov`` (tau in s, sigma = steady-state σ
    in the bias unit). The core checks the kind where the model is used and names that
    argument (e.g. ``accel_bias``).

    Parameters
    ----------
    kind : str, default "random_constant"
        One of :data:`BIAS_KINDS`.
    psd : float, default 0.0
        Random-walk PSD, bias unit²/s (m²/s⁵ for an accelerometer, rad²/s³ for a gyro);
        ``random_walk`` only.
    tau : float, default 0.0
        Gauss–Markov correlation time, s; ``gauss_markov`` only.
    sigma : float, default 0.0
        Gauss–Markov steady-state σ, bias unit (m/s² or rad/s); ``gauss_markov`` only.
    """

    kind: str = "random_constant"
    psd: float = 0.0
    tau: float = 0.0
    sigma: float = 0.0

    def _parts(self) -> tuple[str, float, float]:
        if self.kind == "gauss_markov":
            return (self.kind, finite_scalar(self.tau, "tau"), finite_scalar(self.sigma, "sigma"))
        return (self.kind, finite_scalar(self.psd, "psd"), 0.0)


def ins_error_model(lla, vel_ned, q_nb, f_b, *, gyro_psd: float, accel_psd: float,
                    gyro_bias: BiasModel = BiasModel(), accel_bias: BiasModel = BiasModel(),
                    layout: Layout | None = None, ellipsoid: str = "WGS84") -> tuple[np.ndarray, np.ndarray]:
    """Continuous 15-state NED INS error model F, Q_c (docs/departures.md#error-states-in-metres) along a trajectory.

    Parameters
    ----------
    lla : array_like (N, 3)
        Geodetic latitude, longitude (rad) and height (m).
    vel_ned : array_like (N, 3)
        NED velocity, m/s.
    q_nb : array_like (N, 4)
        Attitude quaternion body → NED, scalar first.
    f_b : array_like (N, 3)
        Compensated specific force in the body frame, m/s².
    gyro_psd : float
        Gyro white-noise PSD, rad²/s = ARW² (keyword-only, like every noise argument).
    accel_psd : float
        Accelerometer white-noise PSD, (m/s²)²/Hz = VRW².
    gyro_bias, accel_bias : BiasModel, default BiasModel()
        Bias processes (default random constant).
    layout : Layout, optional
        State layout (default the 15 states of :data:`INS15`).
    ellipsoid : str, default "WGS84"
        Earth ellipsoid.

    Returns
    -------
    f : numpy.ndarray (N, n, n)
        System matrices F, 1/s.
    qc : numpy.ndarray (N, n, n)
        Continuous process-noise PSDs Q_c.

    References
    ----------
    P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
    Systems*, 2nd ed. (2013), §14.2.
    """
    layout = Layout() if layout is None else instance(layout, Layout, "layout")
    instance(accel_bias, BiasModel, "accel_bias")
    instance(gyro_bias, BiasModel, "gyro_bias")
    f_b = rows(f_b, 3, "f_b")
    plausibility.specific_force(f_b, "f_b")
    with renamed(blocks="layout"):
        return _core.ins_error_dynamics(layout.spec, rows(lla, 3, "lla"), rows(vel_ned, 3, "vel_ned"),
                                        rows(q_nb, 4, "q_nb"), f_b,
                                        accel_psd=finite_scalar(accel_psd, "accel_psd"),
                                        gyro_psd=finite_scalar(gyro_psd, "gyro_psd"), accel_bias=accel_bias._parts(),
                                        gyro_bias=gyro_bias._parts(), ellipsoid=ellipsoid)


class UpdateResult(tuple):
    """What :meth:`KalmanFilter.update` returns: the tuple ``(innovation, nis, rejected)``,
    whose parts are also the attributes of those names, and ``skipped``, the list of the
    rows of z that were NaN (missing) and left out of the update.

    Parameters
    ----------
    values : sequence
        The three parts (innovation, nis, rejected).
    skipped : sequence of int, default ()
        Rows of z that were NaN.

    Attributes
    ----------
    innovation : numpy.ndarray (m,)
        Innovation per row of z (NaN at the skipped rows).
    nis : float or numpy.ndarray (m,)
        Normalised innovation squared.
    rejected : list of int
        Rows rejected by the χ² gate.
    skipped : list of int
        Rows of z that were NaN.
    """

    def __new__(cls, values, skipped=()):
        if isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
            raise TypeError(f"values: expected the three parts (innovation, nis, rejected), got {type(values).__name__}")
        if len(values) != 3:
            raise input_error("values", f"expected the three parts (innovation, nis, rejected), got {len(values)}")
        self = super().__new__(cls, values)
        self.skipped = list(skipped)
        return self

    innovation = property(lambda self: self[0], doc="Innovation per row of z (NaN at the skipped rows).")
    nis = property(lambda self: self[1], doc="Normalised innovation squared over the used rows.")
    rejected = property(lambda self: self[2], doc="Rows rejected by the χ² gate.")


class KalmanFilter:
    """Error-state Kalman filter.

    The state estimate δx̂ starts at ``x0`` (default 0) with covariance ``p0``; every
    :meth:`predict` propagates both (δx̂ ← Φδx̂, P ← ΦPΦᵀ + Q_d). ``mode`` decides what
    :meth:`take_correction` does: "closed" (feedback) hands δx̂ to the caller to correct the
    navigation solution and resets it to 0; "open" hands it over and keeps it. A covariance
    that loses positive definiteness raises :class:`atomnav.NumericalError` naming the
    epoch. One filter may be shared by threads (calls run one after another; the core holds
    the lock) and pickled or deep-copied between steps: the copy continues bit for bit.

    Parameters
    ----------
    p0 : array_like (n, n)
        Initial covariance (positive definite), squared state units.
    x0 : array_like (n,), optional
        Initial state estimate, state units (default zeros).
    mode : {"closed", "open"}, default "closed"
        "closed" (feedback: :meth:`take_correction` hands δx̂ to the caller and resets
        it) or "open" (δx̂ kept).
    covariance_update : {"joseph", "standard"}, default "joseph"
        Covariance form of :meth:`update`: Joseph P = (I − KH)P(I − KH)ᵀ + KRKᵀ, which
        stays symmetric positive semi-definite under rounding and for any gain, or the
        standard P = (I − KH)P (symmetrised), cheaper and textbook-equal for the optimal gain.

    References
    ----------
    P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
    Systems*, 2nd ed. (2013), ch. 3.

    Examples
    --------
    >>> kf = KalmanFilter(p0=np.eye(2), x0=[1.0, 0.0])              # doctest: +SKIP
    >>> kf.predict([[1.0, 0.1], [0.0, 1.0]], 1e-4 * np.eye(2))      # doctest: +SKIP
    >>> kf.x                                                        # doctest: +SKIP
    array([1., 0.])
    """

    def __init__(self, p0, *, x0=None, mode: str = "closed", covariance_update: str = "joseph"):
        x0 = None if x0 is None else vector(x0, None, "x0")
        self._core = _core.KalmanFilter(_mat(p0, "p0"), x0=x0, mode=mode, covariance_update=covariance_update)

    def predict(self, phi, qd, steps: int = 1) -> None:
        """δx̂ ← Φδx̂ and P ← ΦPΦᵀ + Q_d, ``steps`` times (multirate: pass
        Φ(ΔT), Q_d(ΔT) for ΔT = MΔt and steps=1).

        Parameters
        ----------
        phi : array_like (n, n)
            Transition matrix Φ over one step.
        qd : array_like (n, n)
            Process-noise covariance Q_d per step, squared state units.
        steps : int, default 1
            Number of steps (≥ 0).
        """
        if isinstance(steps, (int, np.integer)) and not isinstance(steps, (bool, np.bool_)) and steps == 1:
            self._core.predict(_mat(phi, "phi"), _mat(qd, "qd"))
        else:
            self._core.predict_many(_mat(phi, "phi"), _mat(qd, "qd"), integer(steps, "steps", 0, 2**64 - 1))

    def update(self, z, h, r, sequential: bool = False, gate: float | None = None) -> UpdateResult:
        """Update with z = Hδx + v (z = predicted − measured), R = cov(v).

        A NaN component of z is a missing measurement (a satellite not tracked, a channel
        dropped): the update uses only the other components, with their rows of z and H and
        their rows and columns of R, exactly as if the missing rows had not been given. The
        rows of H and R of a missing component are not read; a non-finite entry in the row
        of a used one, or ±inf in z, raises :class:`atomnav.InputError`. With every
        component missing, the state and covariance are left unchanged.

        Parameters
        ----------
        z : array_like, shape (m,)
            Measurement, in the units of the rows of H; NaN marks a missing component.
        h : array_like, shape (m, n)
            Measurement matrix.
        r : array_like, shape (m, m)
            Measurement noise covariance (positive definite over the used components).
        sequential : bool
            Decorrelate with L = chol(R) (z̄ = L⁻¹z, H̄ = L⁻¹H) and process scalar rows
            (Groves 2013, ch. 3) instead of one stacked vector update.
        gate : float, optional
            χ² threshold on the NIS: per row when ``sequential``, else on the whole NIS of
            the used components, whose number of degrees of freedom is ``m − len(skipped)``.

        Returns
        -------
        UpdateResult
            Unpacks as ``(innovation, nis, rejected)``: the innovation y = z − Hδx̂⁻ per row
            of z (of the decorrelated rows when ``sequential``), NaN at the skipped rows; the
            NIS, one value yᵀS⁻¹y over the used components (NaN when every component is
            missing) or y²/s per row (NaN at the skipped rows) when ``sequential``; the rows
            rejected by the gate. ``.skipped`` lists the rows of z that were NaN.
        """
        z = np.ascontiguousarray(np.atleast_1d(as_floats(z, "z")))
        if z.ndim != 1:
            raise input_error("z", f"expected a vector, got shape {z.shape}")
        *values, skipped = self._core.update(z, _mat(h, "h"), _mat(r, "r"), flag(sequential, "sequential"),
                                             None if gate is None else finite_scalar(gate, "gate"))
        return UpdateResult(values, skipped)

    def take_correction(self) -> np.ndarray:
        """Hand the estimated error δx̂ to the caller: in closed loop it is then reset to
        zero, in open loop it is kept.

        Returns
        -------
        numpy.ndarray (n,)
            δx̂ = estimate − true, in the state units, to be removed from the navigation
            solution.
        """
        return self._core.take_correction()

    @property
    def x(self) -> np.ndarray:
        return self._core.x

    @property
    def p(self) -> np.ndarray:
        return self._core.p

    @property
    def epoch(self) -> int:
        return self._core.epoch


def rts_smooth(phi, x_prior, p_prior, x_post, p_post) -> tuple[np.ndarray, np.ndarray]:
    """Rauch–Tung–Striebel smoother over a stored open-loop run of N epochs.

    Parameters
    ----------
    phi : array_like (N, n, n)
        Transition into epoch k (phi[0] unused).
    x_prior, x_post : array_like (N, n)
        A-priori and a-posteriori state estimates, state units.
    p_prior, p_post : array_like (N, n, n)
        A-priori and a-posteriori covariances, squared state units.

    Returns
    -------
    x : numpy.ndarray (N, n)
        Smoothed states.
    p : numpy.ndarray (N, n, n)
        Smoothed covariances.

    References
    ----------
    H. E. Rauch, F. Tung and C. T. Striebel, "Maximum likelihood estimates of linear
    dynamic systems", *AIAA Journal* 3 (1965).
    """
    a = [np.ascontiguousarray(as_floats(v, name)) for v, name in
         ((phi, "phi"), (x_prior, "x_prior"), (p_prior, "p_prior"), (x_post, "x_post"), (p_post, "p_post"))]
    for v, name, nd in zip(a, ("phi", "x_prior", "p_prior", "x_post", "p_post"), (3, 2, 3, 2, 3)):
        if v.ndim != nd:
            raise input_error(name, f"expected a {nd}-D array, got shape {v.shape}")
    return _core.rts(*a)
