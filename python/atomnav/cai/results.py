"""Monte-Carlo results of the CAI-aided INS scenarios (:class:`HybridResult`) and their
statistics.

Metric of the improvement report: at a time t, for each quantity (NED position, NED
velocity, attitude ψ) the RMS over Monte-Carlo runs of the error, per axis (√mean_r e_i²)
and of the norm (√mean_r |e|²); the improvement is IMU-only RMS / hybrid RMS (Tennstedt et
al. 2023, §4)."""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, field

import numpy as np
import pandas as pd

from .. import _core
from .._validate import as_floats, choice, finite, finite_scalar, input_error, instance, integer, scalar
from .predictor import K_RB87

#: Error columns of every run: NED position (m), NED velocity (m/s), ψ (rad) (from the core).
ERROR_COLUMNS = list(_core.NAV_ERROR_COLUMNS)
BIAS_COLUMNS = ["ba_x_mps2", "ba_y_mps2", "ba_z_mps2", "bg_x_rad_s", "bg_y_rad_s", "bg_z_rad_s"]
_QUANTITIES = {"position": slice(0, 3), "velocity": slice(3, 6), "attitude": slice(6, 9)}


@dataclass
class HybridResult:
    """Monte-Carlo result of one scenario, as :func:`atomnav.cai.run_campaign` returns it.

    R runs, E output epochs, N IMU samples, S shots, C channels, n filter states.

    Attributes
    ----------
    name : str
        Name of the scenario.
    params : dict
        The scenario's parameters (e.g. ``gravity``, ``lever_m``, ``duration_s``; the
        satellite scenario also ``T``, ``shot_period_s``, ``contrast``, ``sigma_p``,
        ``q_rw``).
    time : numpy.ndarray, shape (E,)
        Output epochs (s).
    hybrid, free : numpy.ndarray, shape (R, E, 9)
        Errors (:data:`ERROR_COLUMNS`: NED position m, NED velocity m/s, ψ rad) of the
        CAI-aided and of the IMU-only solutions.
    bias, bias_true : numpy.ndarray, shape (R, E, 6)
        Estimated and true biases (:data:`BIAS_COLUMNS`, m/s² and rad/s).
    sigma : numpy.ndarray, shape (R, E, n)
        Filter σ of every state (SI units).
    accel_error : numpy.ndarray, shape (R, N, 3)
        Accelerometer error (measured − ideal, m/s²) of every IMU sample at ``imu_time``.
    phase_error : numpy.ndarray, shape (R, S, C)
        True − predicted phase (rad) per shot and channel; NaN for a skipped shot.
    shots : numpy.ndarray, shape (S,)
        Shot start times (s).
    nees : numpy.ndarray, shape (R, E)
        NEES of the 15 INS states (navigation errors and b̂ − b) under the filter's P.
    imu_time : numpy.ndarray, shape (N,)
        IMU sample times (s).
    channel_names : list of str
        Names of the C channels.
    config : dict
        The scenario configuration (``ScenarioConfig.to_dict()``) the runs were made with.
    complete : bool
        False when the campaign stopped early (interrupt or error): the finished runs only.
    """

    name: str
    params: dict
    _: KW_ONLY
    time: np.ndarray
    hybrid: np.ndarray
    free: np.ndarray
    bias: np.ndarray
    bias_true: np.ndarray
    sigma: np.ndarray
    accel_error: np.ndarray
    phase_error: np.ndarray
    shots: np.ndarray
    nees: np.ndarray
    imu_time: np.ndarray
    channel_names: list = field(default_factory=list)
    #: The scenario configuration (``ScenarioConfig.to_dict()``) the runs were made with.
    config: dict = field(default_factory=dict)
    #: False when the campaign stopped early (interrupt or error): the finished runs only.
    complete: bool = True

    @property
    def runs(self) -> int:
        return self.hybrid.shape[0]

    def epoch(self, t: float) -> int:
        """Index of the output epoch nearest to a time.

        Parameters
        ----------
        t : float
            Time (s).

        Returns
        -------
        int
            Index into ``time`` of the nearest output epoch.
        """
        return int(np.argmin(np.abs(self.time - finite_scalar(t, "t"))))

    def errors(self, which: str = "hybrid") -> pd.DataFrame:
        """Navigation errors of every run as a long table.

        Parameters
        ----------
        which : {"hybrid", "free"}
            The CAI-aided or the IMU-only solution.

        Returns
        -------
        pandas.DataFrame
            One row per run and epoch: ``run``, ``time_s`` and :data:`ERROR_COLUMNS`
            (m, m/s, rad).
        """
        choice(which, ("hybrid", "free"), "which")
        e = getattr(self, which)
        r, n = e.shape[:2]
        df = pd.DataFrame(e.reshape(r * n, 9), columns=ERROR_COLUMNS)
        df.insert(0, "time_s", np.tile(self.time, r))
        df.insert(0, "run", np.repeat(np.arange(r), n))
        return df

    def rms(self, which: str = "hybrid") -> pd.DataFrame:
        """RMS over runs of the navigation error, per epoch.

        Parameters
        ----------
        which : {"hybrid", "free"}
            The CAI-aided or the IMU-only solution.

        Returns
        -------
        pandas.DataFrame
            One row per epoch: ``time_s``, the RMS per axis (:data:`ERROR_COLUMNS`) and of
            the norms ``pos_norm_m``, ``vel_norm_mps``, ``att_norm_rad``.
        """
        choice(which, ("hybrid", "free"), "which")
        e = getattr(self, which)
        df = pd.DataFrame(np.sqrt(np.mean(e**2, axis=0)), columns=ERROR_COLUMNS)
        for name, (q, sl) in zip(("pos_norm_m", "vel_norm_mps", "att_norm_rad"), _QUANTITIES.items()):
            df[name] = np.sqrt(np.mean(np.sum(e[:, :, sl] ** 2, axis=2), axis=0))
        df.insert(0, "time_s", self.time)
        return df

    def improvement(self, times) -> pd.DataFrame:
        """IMU-only / hybrid ratio of the RMS-over-runs error at given times (Tennstedt et al. 2023, §4).

        Parameters
        ----------
        times : float or array_like
            Times (s); each is taken at the nearest output epoch.

        Returns
        -------
        pandas.DataFrame
            One row per (time, quantity, axis): ``time_s``, ``quantity`` (position,
            velocity, attitude), ``axis`` (n, e, d, norm), ``imu_only_rms``,
            ``hybrid_rms`` (m, m/s or rad) and ``ratio`` (inf when the hybrid RMS is 0).
        """
        rows = []
        times = np.atleast_1d(as_floats(times, "times")).reshape(-1)
        finite(times, "times")
        for t in times:
            k = self.epoch(float(t))
            for q, sl in _QUANTITIES.items():
                f, h = self.free[:, k, sl], self.hybrid[:, k, sl]
                for axis, (a, b) in zip(("n", "e", "d", "norm"),
                                        [(f[:, i], h[:, i]) for i in range(3)] + [(np.linalg.norm(f, axis=1), np.linalg.norm(h, axis=1))]):
                    fr, hr = float(np.sqrt(np.mean(a**2))), float(np.sqrt(np.mean(b**2)))
                    rows.append({"time_s": float(self.time[k]), "quantity": q, "axis": axis, "imu_only_rms": fr, "hybrid_rms": hr,
                                 "ratio": fr / hr if hr > 0 else np.inf})
        return pd.DataFrame(rows)

    def bias_errors(self) -> pd.DataFrame:
        """Statistics over runs of the bias estimation error b̂ − b, per epoch.

        Returns
        -------
        pandas.DataFrame
            One row per epoch: ``time_s`` and, per component ``c`` of :data:`BIAS_COLUMNS`,
            the mean ``c_mean`` and empirical σ ``c_std`` over runs of b̂ − b, the mean
            filter σ ``c_sigma`` (m/s² or rad/s) and the share of runs inside the filter's
            3σ ``c_in3sigma``.
        """
        err = self.bias - self.bias_true
        sig = self.sigma[:, :, 9:15]
        d = {"time_s": self.time}
        for i, c in enumerate(BIAS_COLUMNS):
            d[f"{c}_mean"] = err[:, :, i].mean(axis=0)
            d[f"{c}_std"] = err[:, :, i].std(axis=0)
            d[f"{c}_sigma"] = sig[:, :, i].mean(axis=0)
            d[f"{c}_in3sigma"] = (np.abs(err[:, :, i]) <= 3 * sig[:, :, i]).mean(axis=0)
        return pd.DataFrame(d)

    def bias_table(self) -> pd.DataFrame:
        """Bias estimates of every run as a long table.

        Returns
        -------
        pandas.DataFrame
            ``run``, ``time_s`` and, per component of :data:`BIAS_COLUMNS`, the estimate,
            the truth (``_true``) and the filter σ (``_sigma``), in m/s² or rad/s.
        """
        r, n = self.bias.shape[:2]
        d = {"run": np.repeat(np.arange(r), n), "time_s": np.tile(self.time, r)}
        for i, c in enumerate(BIAS_COLUMNS):
            d[c] = self.bias[:, :, i].ravel()
            d[f"{c}_true"] = self.bias_true[:, :, i].ravel()
            d[f"{c}_sigma"] = self.sigma[:, :, 9 + i].ravel()
        return pd.DataFrame(d)

    def nees_table(self) -> pd.DataFrame:
        """NEES of every run and epoch as a long table.

        Returns
        -------
        pandas.DataFrame
            ``run``, ``time_s``, ``nees`` (dimensionless, 15 INS states; χ²(15) for a
            consistent filter).
        """
        r, n = self.nees.shape
        return pd.DataFrame({"run": np.repeat(np.arange(r), n), "time_s": np.tile(self.time, r), "nees": self.nees.ravel()})

    def nees_inside(self, p: float = 0.95) -> float:
        """Share of (run, epoch) NEES values inside the two-sided p band of χ²(15).

        Parameters
        ----------
        p : float
            Probability of the band, in (0, 1).

        Returns
        -------
        float
            Share of NEES values inside the band (0–1); p for a consistent filter.
        """
        from scipy.stats import chi2

        p = scalar(p, "p")
        if not 0 < p < 1:
            raise input_error("p", f"must be a probability in (0, 1), got {p}")
        lo, hi = chi2.ppf([(1 - p) / 2, (1 + p) / 2], 15)
        return float(np.mean((self.nees >= lo) & (self.nees <= hi)))

    def phase_exceedance(self, limit: float = np.pi / 2) -> float:
        """Share of shot-channels with |true − predicted phase| > ``limit``.

        Taken over the shots applied (a skipped shot's NaN phase error is left out).

        Parameters
        ----------
        limit : float
            Phase limit (rad); π/2 is the edge of the capture region.

        Returns
        -------
        float
            Share (0–1).

        Raises
        ------
        atomnav.InputError
            Naming ``phase_error`` when no shot was applied.
        """
        e = np.abs(self.phase_error[np.isfinite(self.phase_error)])
        if not e.size:
            raise input_error("phase_error", "no shot was applied, so there is no share to take")
        return float(np.mean(e > scalar(limit, "limit")))

    def phase_errors(self) -> pd.DataFrame:
        """Phase errors of every run, shot and channel as a long table.

        Returns
        -------
        pandas.DataFrame
            ``run``, ``shot_start_s``, ``channel``, ``phase_error_rad`` (true − predicted,
            rad).
        """
        r, s, c = self.phase_error.shape
        return pd.DataFrame({"run": np.repeat(np.arange(r), s * c), "shot_start_s": np.tile(np.repeat(self.shots, c), r),
                             "channel": np.tile(self.channel_names or list(range(c)), r * s), "phase_error_rad": self.phase_error.ravel()})


def _satellite_params(res) -> dict:
    """The parameters of a result of :func:`atomnav.cai.satellite`."""
    instance(res, HybridResult, "res")
    need = ("shot_period_s", "q_rw", "sigma_p", "contrast", "T")
    if not isinstance(res.params, dict) or any(k not in res.params for k in need):
        raise input_error("res", f"expected a result of atomnav.cai.satellite (params {need})")
    return res.params


def satellite_steady_state(res: HybridResult) -> dict:
    """Steady state of the satellite filter's along-track bias state against the scalar Riccati closed form.

    Closed form of Tennstedt et al. 2021, Eqs. 26–27, Table 1 case A, for the same Q, R
    and T.

    Parameters
    ----------
    res : HybridResult
        A result of :func:`atomnav.cai.satellite`.

    Returns
    -------
    dict
        ``filter_p_post``: filter P⁺ (median over the second half of the updates);
        ``closed_form_p_post`` and ``closed_form_p_prior``: closed-form P⁺ and P⁻
        ((m/s²)²); ``tracking_error_std``: empirical σ of the tracking error b̂ − b (m/s²;
        bias truth = random walk + Gauss–Markov); ``H`` = (C/2) k T² (population per
        m/s²), ``Q`` ((m/s²)² per shot) and ``R`` = σ_p² (population²) of the scalar
        model.

    Raises
    ------
    atomnav.InputError
        Naming ``res`` when it is not a result of :func:`atomnav.cai.satellite`.
    """
    from ..filter import riccati_scalar

    p = _satellite_params(res)
    t_shot, q, r, h = p["shot_period_s"], p["q_rw"] * p["shot_period_s"], p["sigma_p"] ** 2, 0.5 * p["contrast"] * K_RB87 * p["T"] ** 2
    upd = np.isclose(np.mod(res.time, t_shot), 0.0) & (res.time > 0)
    half = upd & (res.time >= res.time[-1] / 2)
    p_post = float(np.median(res.sigma[0, half, 9] ** 2))
    p_minus_cf, p_post_cf = riccati_scalar(q, r, h)
    err = res.bias[0, half, 0] - res.bias_true[0, half, 0]
    return {"filter_p_post": p_post, "closed_form_p_post": p_post_cf, "closed_form_p_prior": p_minus_cf, "tracking_error_std": float(np.std(err)),
            "H": h, "Q": q, "R": r}


def satellite_psd(res: HybridResult, nperseg: int = 2**15) -> pd.DataFrame:
    """One-sided Welch ASD of the along-track accelerometer error, IMU alone and CAI-corrected.

    Parameters
    ----------
    res : HybridResult
        A result of :func:`atomnav.cai.satellite` (its first run is used).
    nperseg : int
        Samples per Welch segment (at most the record length).

    Returns
    -------
    pandas.DataFrame
        ``frequency_hz``, ``imu_asd`` (IMU error) and ``filtered_asd`` (IMU error − b̂),
        in m/s²/√Hz, zero frequency left out. ``attrs["cai_asd"]`` is the white level of
        the CAI alone: σ_a √Δt_shot with σ_a = σ_p/((C/2) k T²) (Tennstedt et al. 2021,
        §4).
    """
    from scipy.signal import welch

    p = _satellite_params(res)
    nperseg = integer(nperseg, "nperseg", 2, 2**31 - 1)
    t = res.imu_time
    fs = 1.0 / float(np.median(np.diff(t)))
    e = res.accel_error[0, :, 0]
    # b̂ held from each output epoch until the next (the estimate the IMU output is corrected with)
    k = np.clip(np.searchsorted(res.time, t, side="right") - 1, 0, len(res.time) - 1)
    filt = e - np.where(t >= res.time[0], res.bias[0, k, 0], 0.0)
    f, p_imu = welch(e, fs=fs, nperseg=min(nperseg, len(e)))
    _, p_filt = welch(filt, fs=fs, nperseg=min(nperseg, len(e)))
    df = pd.DataFrame({"frequency_hz": f[1:], "imu_asd": np.sqrt(p_imu[1:]), "filtered_asd": np.sqrt(p_filt[1:])})
    sigma_a = p["sigma_p"] / (0.5 * p["contrast"] * K_RB87 * p["T"] ** 2)
    df.attrs["cai_asd"] = sigma_a * np.sqrt(p["shot_period_s"])
    return df
