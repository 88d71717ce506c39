"""Result types of the astro-inertial calibration (shared by :mod:`atomnav.astro` and its
scenario runner, which both import them from here)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import input_error, integers, path as checked_path, rows

D17_CAVEAT = ("P_beta is precision conditional on the IMU calibration: a constant rotation of the gyro "
              "triad is indistinguishable from a mount error (accuracy vs the nominal MF >= ~sigma_phiG/sqrt(2)).")


_RESULT_ARRAYS = ("c", "beta", "residuals", "p_s", "p_theta", "p_beta", "p_clb", "singular_values", "weak_axis_mf")


@dataclass(kw_only=True)
class Calibration:
    """Calibrated mount C = C_MF^VF, as returned by :func:`atomnav.astro.calibrate`
    (Vasilyuk et al. 2024).

    Attributes
    ----------
    c : numpy.ndarray, shape (3, 3)
        The mount C = C_MF^VF.
    beta : numpy.ndarray, shape (3,)
        Its Euler angles β = (ψ, ϑ, γ), rad.
    iterations : int
        Gauss–Newton iterations.
    residuals : numpy.ndarray, shape (M, 3)
        Residuals f_n, rad.
    relative_misfit : float
        Largest |f_n|/chord(φ_n) over the rotating intervals (dimensionless).
    p_s : numpy.ndarray, shape (3, 3)
        Residual covariance P_S, rad².
    p_theta : numpy.ndarray, shape (3, 3)
        Covariance P_θ of the mount error θ^clb in VF, rad².
    p_beta : numpy.ndarray, shape (3, 3)
        Covariance P_β of the Euler angles, rad².
    p_clb : numpy.ndarray, shape (3, 3)
        Calibration error covariance P^clb = D2 P_β D2ᵀ in MF, rad² (Vasilyuk et al.
        2024, Eq. 8).
    covariance : {"model", "residual", "paper_sandwich"}
        The form P_θ, P_β and P^clb were computed in, as chosen by
        :func:`atomnav.astro.calibrate` (docs/departures.md#correlated-increment-residuals).
    singular_values : numpy.ndarray, shape (3,)
        Singular values of the stacked Jacobian H at the solution, descending.
    condition_number : float
        Their ratio, the condition number of H.
    weak_axis_mf : numpy.ndarray, shape (3,)
        Weakest direction of θ^clb in MF.
    sigma_weak : float
        σ_weak = σ̂_f/√λ_min(G) along it, rad, with σ̂_f² = tr P_S / 3.
    observability : dict
        The identifiability report of :func:`atomnav.astro.observability`.
    gyro_error_model : str, default "unspecified"
        Provenance of the gyro error model.
    caveat : str
        P_β is precision conditional on the IMU calibration: a constant rotation of the
        gyro triad is indistinguishable from a mount error (accuracy against the nominal MF
        ≥ ~σ_φG/√2).
    """

    c: np.ndarray
    beta: np.ndarray
    iterations: int
    residuals: np.ndarray
    relative_misfit: float
    p_s: np.ndarray
    p_theta: np.ndarray
    p_beta: np.ndarray
    p_clb: np.ndarray
    covariance: str
    singular_values: np.ndarray
    condition_number: float
    weak_axis_mf: np.ndarray
    sigma_weak: float
    observability: dict
    gyro_error_model: str = "unspecified"
    caveat: str = D17_CAVEAT

    @property
    def sigma_beta_rad(self) -> np.ndarray:
        """√diag P_β, rad, for (ψ, ϑ, γ)."""
        return np.sqrt(np.diag(self.p_beta))

    def p_mfa(self, p_avu) -> np.ndarray:
        """Covariance of the IMU attitude from a new star fix, P^mfa = C P^avu Cᵀ + P^clb
        (Vasilyuk et al. 2024, Eq. 8).

        Parameters
        ----------
        p_avu : array_like, shape (3, 3)
            Star-attitude covariance P^avu in VF, rad².

        Returns
        -------
        numpy.ndarray, shape (3, 3)
            P^mfa in MF, rad².
        """
        p = np.asarray(p_avu, dtype=float)
        return self.c @ p @ self.c.T + self.p_clb

    def save(self, path) -> None:
        """Save as .npz (arrays, scalars, observability, provenance, caveat).

        Parameters
        ----------
        path : str or os.PathLike
            Output file; read back with :meth:`load`.
        """
        obs = {f"obs_{k}": np.asarray(v) for k, v in self.observability.items()}
        np.savez(checked_path(path), **{k: getattr(self, k) for k in _RESULT_ARRAYS}, iterations=self.iterations,
                 relative_misfit=self.relative_misfit, condition_number=self.condition_number, sigma_weak=self.sigma_weak,
                 covariance=self.covariance, gyro_error_model=self.gyro_error_model, caveat=self.caveat, **obs)

    @classmethod
    def load(cls, path) -> "Calibration":
        """A calibration saved by :meth:`save`.

        Parameters
        ----------
        path : str or os.PathLike
            The .npz file.

        Returns
        -------
        Calibration
            The saved calibration.

        Raises
        ------
        atomnav.InputError
            Naming ``path`` when the file is not a calibration saved by :meth:`save`.
        """
        import zipfile

        try:
            with np.load(checked_path(path), allow_pickle=False) as z:
                kw = {k: z[k] for k in _RESULT_ARRAYS}
                obs = {k[4:]: (z[k].item() if z[k].ndim == 0 else z[k]) for k in z.files if k.startswith("obs_")}
                return cls(**kw, iterations=int(z["iterations"]), relative_misfit=float(z["relative_misfit"]),
                           condition_number=float(z["condition_number"]), sigma_weak=float(z["sigma_weak"]),
                           # files written before the covariance was recorded hold the paper's sandwich
                           covariance=str(z["covariance"]) if "covariance" in z.files else "paper_sandwich",
                           observability=obs,
                           gyro_error_model=str(z["gyro_error_model"]), caveat=str(z["caveat"]))
        except (ValueError, KeyError, EOFError, zipfile.BadZipFile) as e:  # not an .npz, or one without our arrays
            raise input_error("path", f"{path} is not a calibration saved by Calibration.save ({type(e).__name__}: {e})") from None


def _store_rows(obj, **fields) -> None:
    """Store the checked arrays ``fields`` (name → array) on the frozen dataclass ``obj``;
    each must have the row count of the first, else an :class:`InputError` naming it."""
    first, n = next(iter(fields)), len(next(iter(fields.values())))
    for name, value in fields.items():
        if len(value) != n:
            raise input_error(name, f"expected {n} rows like {first}, got {len(value)}")
        object.__setattr__(obj, name, value)


@dataclass(frozen=True)
class Observations:
    """Star observations, one row per star.

    Converted on construction to int64 and float64 arrays: numbers given as strings are a
    ``TypeError``, a wrong shape or row count an :class:`atomnav.InputError`, both naming
    the field.

    Parameters
    ----------
    epoch : array_like of int, shape (N,)
        Epoch index of each star.
    camera : array_like of int, shape (N,)
        Camera index of each star.
    s_cf : array_like, shape (N, 3)
        Measured unit direction in the camera frame.
    g : array_like, shape (N, 3)
        Catalog unit direction in GCRS.
    """

    epoch: np.ndarray
    camera: np.ndarray
    s_cf: np.ndarray
    g: np.ndarray

    def __post_init__(self):
        _store_rows(self, epoch=integers(self.epoch, "epoch"), camera=integers(self.camera, "camera"),
                    s_cf=rows(self.s_cf, 3, "s_cf"), g=rows(self.g, 3, "g"))


@dataclass(frozen=True, eq=False)
class StarAttitudes:
    """Star attitudes of the virtual camera VF per epoch, as returned by
    :func:`atomnav.astro.star_attitudes` (Vasilyuk et al. 2024).

    Unpacks in the order of its fields, ``s_gcrs_vf, p_avu, stars = star_attitudes(...)``.

    Attributes
    ----------
    s_gcrs_vf : numpy.ndarray, shape (N, 3, 3)
        Star attitudes S_GCRS^VF (rotation matrices, VF into GCRS).
    p_avu : numpy.ndarray, shape (N, 3, 3)
        Their covariances P^avu in VF, rad².
    stars : numpy.ndarray of int64, shape (N,)
        Stars used per epoch.
    """

    s_gcrs_vf: np.ndarray
    p_avu: np.ndarray
    stars: np.ndarray

    def __iter__(self):
        return iter((self.s_gcrs_vf, self.p_avu, self.stars))


@dataclass(frozen=True, eq=False)
class AstroIncrements:
    """Star-attitude increments between consecutive epochs, as returned by
    :func:`atomnav.astro.astro_increments` (Vasilyuk et al. 2024).

    Unpacks in the order of its fields, ``ds_avu, e_avu = astro_increments(...)``.

    Attributes
    ----------
    ds_avu : numpy.ndarray, shape (N − 1, 3, 3)
        Increments ΔS_n^avu = S_{n−1}ᵀ S_n in VF (rotation matrices).
    e_avu : numpy.ndarray, shape (N − 1, 3, 3)
        Their covariances E_n^avu = P_n + ΔS_nᵀ P_{n−1} ΔS_n, rad². Neighbouring increments
        share an epoch and are correlated; :func:`atomnav.astro.calibrate` takes the epoch
        covariances P^avu for that.
    """

    ds_avu: np.ndarray
    e_avu: np.ndarray

    def __iter__(self):
        return iter((self.ds_avu, self.e_avu))
