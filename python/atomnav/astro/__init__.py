"""Astro-inertial calibration: star-camera (virtual camera VF) to IMU (MF) mount from
attitude increments (Vasilyuk et al. 2024).

Conventions of this module (the paper's): ENU navigation frame, body axes
right-forward-up (MF), ``S_X2^X1`` maps X1 coordinates into X2, small errors are
right-multiplicative in the body frame, S = S̆ (I + [θ×]). The mount C = C_MF^VF maps VF into
MF. Euler angles β = (ψ, ϑ, γ) use C(β) = R_ψ R_ϑ R_γ (heading clockwise from North,
pitch nose-up) and appear only in reports. Project NED/FRD data converts with
:data:`NED_TO_ENU` (= FRD→right-forward-up, its own inverse): C_ENU^MF = T C_nb T,
ρ_MF = T ρ_FRD. All angles in rad, times in s.

P_β is the precision of the mount *conditional on the IMU calibration*: a constant
rotation of the gyro triad is indistinguishable from a mount error, so accuracy against
the nominal MF cannot beat about σ_φG/√2 per axis (docs/departures.md#precision-not-accuracy).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .. import _core, plausibility
from .._validate import as_floats, covariances, input_error, instance, integers, path as checked_path, positive, renamed, rows, scalar, vector
from .results import D17_CAVEAT, AstroIncrements, Calibration, Observations, StarAttitudes, _store_rows
from .scenario import Vasilyuk2024

NED_TO_ENU = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
"""T: NED→ENU and FRD→right-forward-up (T = Tᵀ = T⁻¹)."""

def _mats(x, name: str) -> np.ndarray:
    a = as_floats(x, name)
    if a.ndim == 2:
        a = a[None]
    if a.ndim != 3 or a.shape[1:] != (3, 3):
        raise input_error(name, f"expected shape (N, 3, 3), got {a.shape}")
    return np.ascontiguousarray(a)


def _rows3_unchecked(x, name: str) -> np.ndarray:
    """(N, 3) C-contiguous float64 with only the shape checked: the core's validation pass
    rejects NaN/inf naming the first bad row, so no second numpy pass over long records."""
    a = np.ascontiguousarray(as_floats(x, name))
    if a.ndim != 2 or a.shape[1] != 3:
        raise input_error(name, f"expected shape (N, 3), got {a.shape}")
    return a


def _single(fn, x):
    """``fn`` of Euler angles ``beta`` (rad; (3,) or (N, 3)), warned if they look like degrees."""
    a = as_floats(x, "beta")
    out = fn(plausibility.angles(rows(a, 3, "beta"), "beta"))
    return out[0] if a.ndim == 1 else out


def euler_dcm(beta) -> np.ndarray:
    """Rotation matrix C(ψ, ϑ, γ) = R_ψ(ψ) R_ϑ(ϑ) R_γ(γ) of Euler angles.

    Parameters
    ----------
    beta : array_like, shape (3,) or (N, 3)
        Euler angles β = (ψ, ϑ, γ), rad (heading clockwise from North, pitch nose-up,
        roll); angles that look like degrees give an :class:`atomnav.UnitWarning`.

    Returns
    -------
    numpy.ndarray, shape (3, 3) or (N, 3, 3)
        C(β): (3,) → (3, 3), (N, 3) → (N, 3, 3).
    """
    return _single(_core.astro_euler_dcm, beta)


def euler_from_dcm(c) -> np.ndarray:
    """Canonical Euler angles (ψ ∈ (−π, π], ϑ ∈ [−π/2, π/2], γ ∈ (−π, π]) of rotation matrices.

    Parameters
    ----------
    c : array_like, shape (3, 3) or (N, 3, 3)
        Rotation matrices C(β) = R_ψ R_ϑ R_γ.

    Returns
    -------
    numpy.ndarray, shape (3,) or (N, 3)
        β = (ψ, ϑ, γ), rad; (3, 3) → (3,), (N, 3, 3) → (N, 3). ψ and γ lie in (−π, π]
        (a −0.1° heading reads −0.1°, π reads +π), ϑ in [−π/2, π/2].

    Notes
    -----
    Euler angles appear only in reports; the estimation works on rotations
    (docs/departures.md#rotations-not-euler-angles).
    """
    c = as_floats(c, "c")
    out = _core.astro_euler_from_dcm(_mats(c, "c"))
    return out[0] if c.ndim == 2 else out


def d1(beta) -> np.ndarray:
    """Jacobian D1(β) of the mount error: θ^clb = D1 δβ (Vasilyuk et al. 2024, Eq. 8).

    Parameters
    ----------
    beta : array_like, shape (3,) or (N, 3)
        Euler angles β = (ψ, ϑ, γ), rad.

    Returns
    -------
    numpy.ndarray, shape (3, 3) or (N, 3, 3)
        D1(β), rad/rad.
    """
    return _single(lambda b: _core.astro_d1_d2(b)[0], beta)


def d2(beta) -> np.ndarray:
    """D2(β) = C(β) D1(β): θ^mfa = Cθ^avu − D2 δβ (Vasilyuk et al. 2024, Eq. 8).

    Parameters
    ----------
    beta : array_like, shape (3,) or (N, 3)
        Euler angles β = (ψ, ϑ, γ), rad.

    Returns
    -------
    numpy.ndarray, shape (3, 3) or (N, 3, 3)
        D2(β), rad/rad.
    """
    return _single(lambda b: _core.astro_d1_d2(b)[1], beta)


@dataclass(frozen=True)
class GyroErrorModel:
    """Gyro error budget of Vasilyuk et al. 2024.

    Parameters
    ----------
    sigma_phi_rad : float
        Misalignment σ_φ of the gyro triad, rad.
    sigma_k : float
        Scale-factor error σ_k, dimensionless (–).
    sigma_w_rad_sqrt_s : float
        Angle random walk σ_w, rad/√s.
    sigma_b_rad_s : float
        Rate bias σ_b, rad/s.
    mode : {"paper", "consistent"}, default "paper"
        "paper": errors white per sample, as the paper propagates them; "consistent":
        constant over the calibration (docs/departures.md#constant-gyro-errors).
    """

    sigma_phi_rad: float
    sigma_k: float
    sigma_w_rad_sqrt_s: float
    sigma_b_rad_s: float
    mode: str = "paper"

    @classmethod
    def vasilyuk2024(cls, mode: str = "paper") -> "GyroErrorModel":
        """The paper's budget (Vasilyuk et al. 2024): 3″, 1e-5, 0.0012 °/√h, 0.007 °/h.

        Parameters
        ----------
        mode : {"paper", "consistent"}, default "paper"
            How the errors are propagated, as for :class:`GyroErrorModel`.

        Returns
        -------
        GyroErrorModel
            σ_φ = 3″, σ_k = 1e-5, σ_w = 0.0012 °/√h, σ_b = 0.007 °/h, in the SI units of
            the fields (rad, –, rad/√s, rad/s).
        """
        return cls(*_core.astro_vasilyuk2024_gyro_budget(), mode=mode)

    def _sigmas(self):
        return (self.sigma_phi_rad, self.sigma_k, self.sigma_w_rad_sqrt_s, self.sigma_b_rad_s)


@dataclass(frozen=True)
class Increments:
    """Gyro increments between camera epochs, as returned by :func:`gyro_increments`.

    Attributes
    ----------
    q : numpy.ndarray, shape (M, 4)
        Increment quaternions, scalar first, with R(q) = ΔS^imu.
    dcm : numpy.ndarray, shape (M, 3, 3)
        ΔS^imu = R(q).
    cov : numpy.ndarray, shape (M, 3, 3)
        Increment covariance E^imu, rad².
    j_m : numpy.ndarray, shape (M, 3, 9), or None
        In "consistent" mode the sensitivity of the increment to vec_rowmajor(M_G) (the
        gyro misalignment/scale matrix), rad; else None.
    j_b : numpy.ndarray, shape (M, 3, 3), or None
        In "consistent" mode the sensitivity to the rate bias (rad/s → rad, i.e. s);
        else None.
    """

    q: np.ndarray
    dcm: np.ndarray
    cov: np.ndarray
    j_m: np.ndarray | None
    j_b: np.ndarray | None

    @property
    def sigma_rad(self) -> np.ndarray:
        """σ_ε^imu = √tr E^imu (rad)."""
        return np.sqrt(np.trace(self.cov, axis1=1, axis2=2))


def gyro_increments(t_start: float, period: float, rho, epochs, model: GyroErrorModel,
                    taylor_variant: str = "corrected") -> Increments:
    """Third-order asynchronous quaternion integration between camera epochs
    (Vasilyuk et al. 2024), with the increment covariance of the gyro error ``model``.

    Parameters
    ----------
    t_start : float
        Start time of the gyro record, s.
    period : float
        Gyro sampling period T, s (> 0).
    rho : array_like, shape (K, 3)
        Gyro angle increments in MF, rad; row j over [t_start + jT, t_start + (j+1)T].
    epochs : array_like, shape (N,)
        Camera epochs, s, strictly increasing and inside the record.
    model : GyroErrorModel
        Gyro error budget giving the increment covariance.
    taylor_variant : {"corrected", "paper_literal"}, default "corrected"
        Second-order quaternion term: "corrected" (c = 1/8) or "paper_literal" (c = 1/4)
        (docs/departures.md#second-order-quaternion-term).

    Returns
    -------
    Increments
        The M = N − 1 increments ΔS^imu between consecutive epochs, their covariance
        E^imu (rad²) and, in "consistent" mode, the sensitivities ``j_m``, ``j_b``.
    """
    instance(model, GyroErrorModel, "model")
    with renamed(gyro_increments="rho"):
        q, cov, sens = _core.astro_increments(scalar(t_start, "t_start"), positive(period, "period"),
                                              _rows3_unchecked(rho, "rho"), vector(epochs, None, "epochs"),
                                              model._sigmas(), model.mode, taylor_variant)
    jm, jb = sens if sens is not None else (None, None)
    return Increments(q=q, dcm=_core.dcm_from_quat_rows(q) if len(q) else np.zeros((0, 3, 3)), cov=cov, j_m=jm, j_b=jb)


def dead_reckoning_cov(t_start: float, period: float, rho, epochs, model: GyroErrorModel) -> np.ndarray:
    """Dead-reckoning attitude covariance P^imu at every epoch: the increment covariance
    recursion run from the first epoch.

    Parameters
    ----------
    t_start : float
        Start time of the gyro record, s.
    period : float
        Gyro sampling period T, s (> 0).
    rho : array_like, shape (K, 3)
        Gyro angle increments in MF, rad; row j over [t_start + jT, t_start + (j+1)T].
    epochs : array_like, shape (N,)
        Camera epochs, s, strictly increasing and inside the record.
    model : GyroErrorModel
        Gyro error budget.

    Returns
    -------
    numpy.ndarray, shape (N, 3, 3)
        P^imu at each epoch, rad².
    """
    instance(model, GyroErrorModel, "model")
    with renamed(gyro_increments="rho"):
        return _core.astro_dead_reckoning_cov(scalar(t_start, "t_start"), positive(period, "period"),
                                              _rows3_unchecked(rho, "rho"), vector(epochs, None, "epochs"),
                                              model._sigmas(), model.mode)


def observability(ds_avu) -> dict:
    """Identifiability of the mount from the star-attitude increments (Vasilyuk et al. 2024;
    thresholds in docs/departures.md#identifiability-thresholds).

    Parameters
    ----------
    ds_avu : array_like, shape (M, 3, 3)
        Star-attitude increments ΔS^avu in VF.

    Returns
    -------
    dict
        ``axes_vf`` (M, 3) unit rotation axes in VF (zero for a null rotation);
        ``angles`` (M,) rotation angles, rad; ``cluster`` (M,) cluster labels (−1 below
        0.5°); ``n_clusters`` (5° radius, axes taken as lines); ``eigenvalues`` (3,), ascending,
        and ``eigenvectors`` (3, 3) as columns of G = Σ(I − ΔS)(I − ΔS)ᵀ;
        ``kappa`` = λ_min/λ_max; ``weak_axis_vf`` (3,); ``verdict`` "ok" | "warn"
        (κ < 1e-4) | "reject" (κ < 1e-12).
    """
    return _core.astro_observability(_mats(ds_avu, "ds_avu"))


def _constant_terms(increments: Increments | None, model: GyroErrorModel | None):
    """(j_m, j_b, sigmas) of the consistent gyro mode, or three None."""
    if model is not None:
        instance(model, GyroErrorModel, "model")
    if increments is not None:
        instance(increments, Increments, "increments")
    if model is None or model.mode != "consistent":
        return None, None, None
    if increments is None or increments.j_m is None:
        raise input_error("increments", "the consistent gyro mode needs the Increments with j_m, j_b")
    return increments.j_m, increments.j_b, model._sigmas()


def calibrate(ds_imu, ds_avu, *, init: str = "axes", c0=None, solver: str = "so3", max_iter: int = 50,
              tol: float = 1e-9, residual_form: str = "full", covariance: str | None = None, e_imu=None, p_avu=None,
              increments: Increments | None = None, model: GyroErrorModel | None = None,
              gyro_error_model: str = "unspecified") -> Calibration:
    """Mount C_MF^VF from increment pairs ΔS^avu = Cᵀ ΔS^imu C (Vasilyuk et al. 2024, §3).

    Gauss–Newton on the increment residuals f_n, then the sandwich
    P_θ = (HᵀH)⁻¹HᵀΣ_fH(HᵀH)⁻¹ of the stacked residual covariance Σ_f. Consecutive star
    increments ΔS_n^avu = S_{n−1}ᵀS_n share the epoch S_n, so Σ_f has the neighbour blocks
    −P_n^avu ΔS_{n+1}; the reported P_β includes them by default
    (docs/departures.md#correlated-increment-residuals):

    - with ``e_imu`` and ``p_avu`` given, ``covariance="model"`` (the default then): Σ_f
      from those covariances, as :func:`model_covariance`;
    - without them, ``covariance="residual"`` (the default then): the same structure with
      one star-attitude covariance and one gyro-increment covariance estimated from the
      residuals (their lag-1 and lag-0 moments);
    - ``covariance="paper_sandwich"``: the paper's Σ_f = I ⊗ P_S, increments taken as
      independent (Vasilyuk et al. 2024, E18).

    The option names are ``_core.OPTIONS["CalibrationInit"]``, ``["CalibrationSolver"]``,
    ``["ResidualForm"]`` and ``["MountCovariance"]``.

    Parameters
    ----------
    ds_imu : array_like, shape (M, 3, 3)
        Gyro increments ΔS^imu in MF (e.g. :attr:`Increments.dcm`).
    ds_avu : array_like, shape (M, 3, 3)
        Star-attitude increments ΔS^avu in VF (from :func:`astro_increments`).
    init : {"axes", "zero", "given"}, default "axes"
        Starting point: closed-form alignment of rotation axes, the paper's β0 = 0, or
        ``c0``.
    c0 : array_like, shape (3, 3), optional
        Initial mount C_MF^VF for ``init="given"``.
    solver : {"so3", "paper_euler"}, default "so3"
        "so3": C ← C exp([Δθ×]) with the analytic Jacobian; "paper_euler": β ← β + Δβ with
        central differences, dx = 1e-6.
    max_iter : int, default 50
        Maximum number of Gauss–Newton iterations.
    tol : float, default 1e-9
        Stop at a step ≤ ``tol``, rad.
    residual_form : {"full", "diagonal"}, default "full"
        Form of the residual covariance P_S (reported as ``p_s``, used by
        ``covariance="paper_sandwich"``).
    covariance : {"model", "residual", "paper_sandwich"}, optional
        Form of P_θ, P_β and P^clb; default "model" when ``e_imu`` and ``p_avu`` are given,
        else "residual".
    e_imu : array_like, shape (M, 3, 3) or (3, 3), optional
        Gyro interval covariances E^imu in MF, rad² (e.g. :attr:`Increments.cov`); give
        with ``p_avu``.
    p_avu : array_like, shape (M + 1, 3, 3) or (3, 3), optional
        Star-attitude covariances P^avu of the M + 1 epochs in VF, rad² (e.g.
        :attr:`StarAttitudes.p_avu`); give with ``e_imu``.
    increments : Increments, optional
        The gyro increments; needed (with ``j_m``/``j_b``) when ``model.mode`` is
        "consistent", for the constant-error terms, as in :func:`model_covariance`.
    model : GyroErrorModel, optional
        Gyro error budget; only its "consistent" mode changes the result.
    gyro_error_model : str, default "unspecified"
        Provenance label of the gyro model, stored in the result.

    Returns
    -------
    Calibration
        The mount, its Euler angles and covariances (rad, rad²), the covariance form used
        (``covariance``) and the identifiability report.

    Raises
    ------
    atomnav.InputError
        When the trajectory cannot determine the mount (κ < 1e-12; the message names the
        null direction), or naming ``e_imu``/``p_avu`` when only one is given, when
        ``covariance="model"`` lacks them or another form is given them.
    atomnav.NumericalError
        When Gauss–Newton does not converge or stops at a wrong stationary point.

    Warns
    -----
    RuntimeWarning
        When the mount is weakly observable (κ < 1e-4), naming the weak direction in VF.

    Notes
    -----
    Without error covariances the residuals carry little information on gyro noise along
    an axis the trajectory keeps turning about (the star part of the score telescopes
    there); the residual σ of that angle is then noisy from run to run
    (docs/departures.md#correlated-increment-residuals). Give ``e_imu`` and ``p_avu``
    where they are known.
    """
    c0 = None if c0 is None else rows(c0, 3, "c0")
    jm, jb, sigmas = _constant_terms(increments, model)
    ds_imu = _mats(ds_imu, "ds_imu")
    m = len(ds_imu)
    d = _core.astro_calibrate(ds_imu, _mats(ds_avu, "ds_avu"), init=init, c0=c0, solver=solver,
                              max_iter=max_iter, tol=scalar(tol, "tol"), residual_form=residual_form, covariance=covariance,
                              e_imu=None if e_imu is None else covariances(e_imu, m, "e_imu"),
                              p_avu=None if p_avu is None else covariances(p_avu, m + 1, "p_avu"), j_m=jm, j_b=jb, sigmas=sigmas)
    if d["observability"]["verdict"] == "warn":
        k = d["observability"]["weak_axis_vf"]
        warnings.warn(f"weakly observable mount: kappa = {d['observability']['kappa']:.3e} < 1e-4, "
                      f"weak direction {np.round(k, 6)} in VF", RuntimeWarning, stacklevel=2)
    return Calibration(**d, gyro_error_model=gyro_error_model)


# --- star camera front end -------------------------------------------------------------

@dataclass(frozen=True)
class Catalog:
    """Star catalog.

    Converted on construction to float64 and int64 arrays: numbers given as strings are a
    ``TypeError``, a wrong shape or row count an :class:`atomnav.InputError`, both naming
    the field.

    Parameters
    ----------
    dirs : array_like, shape (N, 3)
        GCRS unit vectors of the stars (annual aberration applied).
    mags : array_like, shape (N,)
        Visual magnitudes.
    ids : array_like of int, shape (N,)
        Star identifiers.
    """

    dirs: np.ndarray
    mags: np.ndarray
    ids: np.ndarray

    def __post_init__(self):
        _store_rows(self, dirs=rows(self.dirs, 3, "dirs"), mags=vector(self.mags, None, "mags"), ids=integers(self.ids, "ids"))


def synthetic_catalog(m_lim: float = 5.6, seed: int = 1) -> Catalog:
    """Deterministic uniform sky (docs/departures.md#synthetic-star-catalog).

    Parameters
    ----------
    m_lim : float, default 5.6
        Limiting magnitude: round(10^(0.985 + 0.455 m_lim)) stars.
    seed : int, default 1
        Seed of xoshiro256** (seeded through SplitMix64, identical on every platform).

    Returns
    -------
    Catalog
        The synthetic stars.
    """
    return Catalog(*_core.astro_synthetic_catalog(scalar(m_lim, "m_lim"), seed))


def load_catalog(path) -> Catalog:
    """A user catalog from a CSV file.

    Parameters
    ----------
    path : str or os.PathLike
        CSV file with header ``id,ra_deg,dec_deg,mag`` (GCRS right ascension and
        declination in degrees) or ``id,x,y,z,mag`` (GCRS unit vectors).

    Returns
    -------
    Catalog
        The stars of the file.

    Raises
    ------
    atomnav.InputError
        Naming ``path`` when the file is not such a CSV, a direction is not a unit vector
        or an id is not an integer.
    """
    try:
        data = np.genfromtxt(checked_path(path), delimiter=",", names=True, dtype=float)
    except ValueError as e:  # a path with a NUL byte, or a file that is not such a CSV
        raise input_error("path", str(e)) from None
    names = set(data.dtype.names or ())
    if {"ra_deg", "dec_deg"} <= names:
        ra, dec = np.radians(data["ra_deg"]), np.radians(data["dec_deg"])
        dirs = np.column_stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])
    elif {"x", "y", "z"} <= names:
        dirs = np.column_stack([data["x"], data["y"], data["z"]])
    else:
        raise input_error("path", f"expected columns id,ra_deg,dec_deg,mag or id,x,y,z,mag in {path}, got {sorted(names)}")
    if "mag" not in names or "id" not in names:
        raise input_error("path", f"expected the columns id and mag in {path}, got {sorted(names)}")
    with renamed(catalog_directions="path", mag="path"):  # the file's rows are at fault
        dirs = rows(dirs, 3, "catalog_directions")
        mags = vector(np.atleast_1d(data["mag"]), None, "mag")
    norm = np.linalg.norm(dirs, axis=1)
    bad = np.nonzero(np.abs(norm - 1.0) > 1e-9)[0]
    if bad.size:
        raise input_error("path", f"catalog direction not a unit vector in row {bad[0]} (norm {norm[bad[0]]})", bad[0])
    ids = np.atleast_1d(data["id"])
    whole = np.isfinite(ids) & (ids == np.round(ids))
    if not whole.all():
        k = int(np.argmin(whole))
        raise input_error("path", f"catalog id {ids[k]} in row {k} is not an integer", k)
    return Catalog(dirs=dirs, mags=mags, ids=ids.astype(np.int64))


def refractive_index(height_m: float) -> float:
    """Refractive index of air n(H) = 1 + 2.7783e-4 (1 − 2.25577e-5 H)^4.25588
    (Vasilyuk et al. 2024).

    Parameters
    ----------
    height_m : float
        Height H, m (≥ −10 km).

    Returns
    -------
    float
        n(H), dimensionless. Above H = 1/2.25577e-5 ≈ 44.3 km the model's air density is
        zero and n = 1.
    """
    with renamed(height="height_m"):
        return _core.astro_refractive_index(scalar(height_m, "height_m"))


def refraction_correct(s, up, n: float) -> np.ndarray:
    """Remove refraction from observed unit directions about the local vertical, for a
    plane-parallel atmosphere (Snell's law, sin z_true = n sin z_obs).

    Parameters
    ----------
    s : array_like, shape (N, 3)
        Observed (apparent) unit directions.
    up : array_like, shape (N, 3)
        Local vertical unit vectors, same frame as ``s``.
    n : float
        Refractive index of air (≥ 1, dimensionless; see :func:`refractive_index`).

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        True unit directions.
    """
    with renamed(directions="s", n_refr="n"):
        return _core.astro_refraction(rows(s, 3, "s"), rows(up, 3, "up"), scalar(n, "n"), False)


def refraction_apply(s, up, n: float) -> np.ndarray:
    """Apparent directions of true unit directions (inverse of :func:`refraction_correct`,
    for simulation).

    Parameters
    ----------
    s : array_like, shape (N, 3)
        True unit directions.
    up : array_like, shape (N, 3)
        Local vertical unit vectors, same frame as ``s``.
    n : float
        Refractive index of air (≥ 1, dimensionless).

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Apparent (refracted) unit directions.
    """
    with renamed(directions="s", n_refr="n"):
        return _core.astro_refraction(rows(s, 3, "s"), rows(up, 3, "up"), scalar(n, "n"), True)


def star_attitudes(obs: Observations, n_epochs: int, cameras, sigma_s_rad: float, p_alpha=None,
                   up_gcrs=None, n_refr: float = 1.0, p_avu=None) -> StarAttitudes:
    """Star attitudes of the virtual camera VF per epoch and their covariance.

    Merges the cameras into VF, removes refraction, solves Wahba's problem per epoch and
    forms P^avu = σ_s²K + K(Σ Cᵢ Aᵢ D1(αⁱ) P_aⁱ D1ᵀ Aᵢ Cᵢᵀ)K
    (docs/departures.md#star-attitude-covariance), or takes the user's ``p_avu`` in place
    of that default model; it then flows into :func:`astro_increments`,
    :func:`model_covariance` and :meth:`Calibration.p_mfa`.

    Parameters
    ----------
    obs : Observations
        Star observations (epoch and camera indices, directions).
    n_epochs : int
        Number of epochs N (≥ 1).
    cameras : array_like, shape (I, 3, 3)
        Camera mounts C_VF^CFⁱ; camera 0 = identity.
    sigma_s_rad : float
        Star direction noise σ_s, rad.
    p_alpha : array_like, shape (I, 3, 3) or (3, 3), optional
        Covariance of each camera's mount angles αⁱ, rad² (one (3, 3) for every camera;
        default zero).
    up_gcrs : array_like, shape (N, 3), optional
        Local vertical in GCRS per epoch; refraction is removed about it (default: no
        refraction correction).
    n_refr : float, default 1.0
        Refractive index of air (dimensionless).
    p_avu : array_like, shape (N, 3, 3), optional
        User star-attitude covariance in VF, rad² (finite, symmetric, PSD), used instead of
        the default model.

    Returns
    -------
    StarAttitudes
        ``s_gcrs_vf`` (N, 3, 3) the star attitudes S_GCRS^VF, ``p_avu`` (N, 3, 3) P^avu in
        rad², ``stars`` (N,) the stars used per epoch; unpacks as
        ``s_gcrs_vf, p_avu, stars``.
    """
    instance(obs, Observations, "obs")
    cams = _mats(cameras, "cameras")
    pa = np.zeros_like(cams) if p_alpha is None else covariances(p_alpha, len(cams), "p_alpha")
    up = None if up_gcrs is None else rows(up_gcrs, 3, "up_gcrs")
    # the observations' fields are checked by the core under their own names: errors name ``obs``
    with renamed(epoch="obs", camera="obs", star_directions="obs", catalog_directions="obs"):
        return StarAttitudes(*_core.astro_star_attitudes(np.ascontiguousarray(obs.epoch, dtype=np.int64),
                                      np.ascontiguousarray(obs.camera, dtype=np.int64),
                                      rows(obs.s_cf, 3, "star_directions"), rows(obs.g, 3, "catalog_directions"),
                                      n_epochs, cameras=cams, p_alpha=pa, sigma_s=scalar(sigma_s_rad, "sigma_s_rad"), up_gcrs=up,
                                      n_refr=scalar(n_refr, "n_refr"), p_avu=None if p_avu is None else _mats(p_avu, "p_avu")))


def astro_increments(s_vf, p_avu) -> AstroIncrements:
    """Star-attitude increments ΔS_n^avu = S_{n−1}ᵀ S_n and their covariance
    E_n^avu = P_n + ΔS_nᵀ P_{n−1} ΔS_n (Vasilyuk et al. 2024).

    Parameters
    ----------
    s_vf : array_like, shape (N, 3, 3)
        Star attitudes S_GCRS^VF (rotation matrices).
    p_avu : array_like, shape (N, 3, 3) or (3, 3)
        Their covariances P^avu, rad² (one (3, 3) for every epoch).

    Returns
    -------
    AstroIncrements
        ``ds_avu`` (N − 1, 3, 3) the increments ΔS_n^avu and ``e_avu`` (N − 1, 3, 3) their
        covariances E_n^avu, rad²; unpacks as ``ds_avu, e_avu``.
    """
    s_vf = _mats(s_vf, "s_vf")
    return AstroIncrements(*_core.astro_astro_increments(s_vf, covariances(p_avu, len(s_vf), "p_avu")))


def model_covariance(cal: Calibration, ds_imu, ds_avu, e_imu, p_avu, increments: Increments | None = None,
                     model: GyroErrorModel | None = None):
    """Model-form mount covariance at ``cal``'s mount: the sandwich
    (HᵀH)⁻¹HᵀΣ_fH(HᵀH)⁻¹, converted to Euler angles.

    Σ_f has the diagonal blocks CᵀE_n^imuC + E_n^avu and the neighbour correlations of
    shared star attitudes.

    Parameters
    ----------
    cal : Calibration
        The calibration whose mount ``cal.c`` is used.
    ds_imu : array_like, shape (M, 3, 3)
        Gyro increments ΔS^imu in MF.
    ds_avu : array_like, shape (M, 3, 3)
        Star-attitude increments ΔS^avu in VF.
    e_imu : array_like, shape (M, 3, 3) or (3, 3)
        Gyro interval covariances E^imu, rad² (one (3, 3) for every interval).
    p_avu : array_like, shape (M + 1, 3, 3) or (3, 3)
        Star-attitude covariances P^avu, rad² (one (3, 3) for every epoch).
    increments : Increments, optional
        The gyro increments; needed (with ``j_m``/``j_b``) when ``model.mode`` is
        "consistent", for the constant-error cross terms.
    model : GyroErrorModel, optional
        Gyro error budget; only its "consistent" mode changes the result.

    Returns
    -------
    p_beta_model : numpy.ndarray, shape (3, 3)
        P_β^model, rad².
    p_beta_sys : numpy.ndarray, shape (3, 3)
        P_β^sys, rad²: the part of the constant-error cross terms (zero unless
        ``model.mode == "consistent"``).

    Raises
    ------
    atomnav.InputError
        Naming ``increments`` when the consistent mode lacks the sensitivities.
    """
    instance(cal, Calibration, "cal")
    extra = _constant_terms(increments, model)
    ds_imu = _mats(ds_imu, "ds_imu")
    m = len(ds_imu)
    return _core.astro_model_covariance(rows(cal.c, 3, "c"), ds_imu, _mats(ds_avu, "ds_avu"),
                                        covariances(e_imu, m, "e_imu"), covariances(p_avu, m + 1, "p_avu"), *extra)


def aberration(directions, velocity_mps) -> np.ndarray:
    """First-order stellar aberration: apparent unit directions normalize(s + v/c).

    Parameters
    ----------
    directions : array_like, shape (N, 3)
        Geometric unit directions s of the stars.
    velocity_mps : array_like, shape (3,) or (N, 3)
        Observer velocity, m/s, same frame, |v| < 1e-3 c.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Apparent unit directions.

    Notes
    -----
    Exact special relativity differs by O((v/c)²) ≈ 1e-8 rad at Earth's orbital 30 km/s.
    """
    with renamed(velocity="velocity_mps"):
        return _core.astro_aberration(rows(directions, 3, "directions"), rows(velocity_mps, 3, "velocity_mps"))


def simulate_observations(catalog: Catalog, s_gcrs_vf, up_gcrs, cameras, *, fov_half_rad: float, m_lim: float,
                          sigma_s_rad: float, n_refr: float, seed: int) -> Observations:
    """Camera simulator: stars brighter than ``m_lim``, above the horizon, within
    ``fov_half_rad`` of each camera's +z after refraction, with isotropic tangent noise.

    Parameters
    ----------
    catalog : Catalog
        The star catalog.
    s_gcrs_vf : array_like, shape (N, 3, 3)
        True attitudes S_GCRS^VF of the virtual camera per epoch.
    up_gcrs : array_like, shape (N, 3)
        Local vertical in GCRS per epoch.
    cameras : array_like, shape (I, 3, 3)
        Camera mounts C_VF^CFⁱ.
    fov_half_rad : float
        Half-angle of each camera's field of view, rad.
    m_lim : float
        Limiting magnitude.
    sigma_s_rad : float
        Isotropic tangent noise σ_s of the measured directions, rad.
    n_refr : float
        Refractive index of air (≥ 1, dimensionless).
    seed : int
        Noise seed, any integer in [0, 2**64).

    Returns
    -------
    Observations
        One row per observed star.
    """
    instance(catalog, Catalog, "catalog")
    d = _core.astro_simulate_observations(rows(catalog.dirs, 3, "catalog_directions"),
                                          vector(catalog.mags, None, "magnitudes"), _mats(s_gcrs_vf, "s_gcrs_vf"),
                                          rows(up_gcrs, 3, "up_gcrs"), _mats(cameras, "cameras"), fov_half=scalar(fov_half_rad, "fov_half_rad"),
                                          m_lim=scalar(m_lim, "m_lim"), sigma_s=scalar(sigma_s_rad, "sigma_s_rad"),
                                          n_refr=scalar(n_refr, "n_refr"), seed=seed)
    return Observations(**d)


__all__ = [
    "NED_TO_ENU", "D17_CAVEAT", "euler_dcm", "euler_from_dcm", "d1", "d2", "GyroErrorModel", "Increments",
    "gyro_increments", "dead_reckoning_cov", "observability", "Calibration", "calibrate", "Catalog",
    "synthetic_catalog", "load_catalog", "refractive_index", "refraction_correct", "refraction_apply",
    "Observations", "StarAttitudes", "star_attitudes", "AstroIncrements", "astro_increments", "model_covariance", "aberration", "simulate_observations",
    "Vasilyuk2024",
]
