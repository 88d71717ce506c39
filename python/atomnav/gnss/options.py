"""One set of GNSS processing options (Rust ``gnss/options.rs``, the role of RTKLIB's
``prcopt_t``; Takasu 2013): measurement noise, atmosphere corrections, single-point
options and the tightly coupled filter's formulation, lever arm and clock models. Every
GNSS function takes one (:func:`atomnav.gnss.simulate`, :func:`atomnav.gnss.solve`,
:func:`atomnav.gnss.tight_ins`); the core checks it when it is built."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .. import _core
from .._validate import instance
from ..filter.engine import Config, _floats

#: Names of the tight-coupling formulations (from the core).
FORMULATIONS = tuple(_core.OPTIONS["Formulation"])


@dataclass(frozen=True, kw_only=True)
class GnssOptions(Config):
    """GNSS processing options; an invalid field raises :class:`atomnav.InputError` naming it.

    All fields are keyword-only.

    Parameters
    ----------
    sigma_code : float, default 3.0
        Code σ, m.
    sigma_code_glonass : float, optional
        GLONASS code σ, m; None = ``sigma_code``.
    sigma_rate : float, default 0.05
        Pseudorange-rate σ, m/s.
    iono : bool, default True
        Klobuchar ionosphere with the navigation message's coefficients
        (:attr:`Ephemerides.ionosphere`: a navigation file's ION ALPHA/BETA or GPSA/GPSB,
        the set of 2009-01-01 for nominal constellations), in simulation and correction.
    tropo : bool, default True
        Saastamoinen troposphere, in simulation and correction.
    use_tau : bool, default True
        Single-point positioning estimates τ_GPS (5 unknowns when GLONASS is present);
        False gives the "no-τ" diagnostic of Demidov 2009.
    elevation_weight : bool, default False
        Single-point positioning weights with σ/sin E.
    elevation_mask : float, default 10° (0.1745 rad)
        Single-point positioning and tight coupling leave out satellites below this
        elevation, rad.
    fault_detection : bool, default True
        Single-point positioning tests the weighted residuals against χ² (0.1 % false
        alarms) and, while the test fails with two or more redundant satellites,
        excludes the satellite whose removal fits best (RAIM FDE, as RTKLIB's
        ``raim_fde``; Takasu 2013).
    ionosphere_free : bool, default False
        Single-point positioning with the ionosphere-free combination of the first and
        second codes (``code2_m``, as :func:`atomnav.gnss.rinex.read_obs` gives it;
        Groves 2013, Eq. 9.50) instead of the Klobuchar correction; satellites without a
        second code are excluded ("no_second_code"), and the code σ are scaled by the
        combination's noise gain (×2.98 GPS, ×2.96 GLONASS).
    formulation : str, default "first_difference"
        Tight coupling, one of :data:`FORMULATIONS`: "first_difference" (between-satellite
        differences with c·τ_GPS as an extra state) or "clock_states" (undifferenced rows
        with the receiver clock states).
    lever_arm : array_like, shape (3,), default (0, 0, 0)
        IMU → antenna lever arm in body axes, m.
    use_rate : bool, default True
        Tight coupling uses the pseudorange rates.
    tau0 : float, default 0.0
        Initial τ_GPS, s.
    sigma_tau0 : float, default 1e-6
        Initial σ of τ_GPS, s.
    tau_psd : float, default (0.1 ns)²/h
        Random-walk PSD of τ_GPS, s²/s.
    clock0 : array_like, shape (2,), default (0, 0)
        Initial receiver clock states (c·δt_r m, c·δṫ_r m/s).
    sigma_clock0 : array_like, shape (2,), default (3e5, 300)
        Their initial σ (m, m/s).
    clock_h0 : float, default 2e-19
        Oscillator white-frequency coefficient h₀, s (Brown & Hwang 2012, Table 9.1: a
        TCXO).
    clock_hm2 : float, default 2e-20
        Oscillator random-walk-frequency coefficient h₋₂, 1/s (Brown & Hwang 2012,
        Table 9.1).
    """

    sigma_code: float = 3.0
    sigma_code_glonass: float | None = None
    sigma_rate: float = 0.05
    iono: bool = True
    tropo: bool = True
    use_tau: bool = True
    elevation_weight: bool = False
    elevation_mask: float = math.radians(10.0)
    fault_detection: bool = True
    ionosphere_free: bool = False
    formulation: str = "first_difference"
    lever_arm: tuple = (0.0, 0.0, 0.0)
    use_rate: bool = True
    tau0: float = 0.0
    sigma_tau0: float = 1e-6
    tau_psd: float = (0.1e-9) ** 2 / 3600.0
    clock0: tuple = (0.0, 0.0)
    sigma_clock0: tuple = (3e5, 300.0)
    clock_h0: float = 2e-19
    clock_hm2: float = 2e-20

    def __post_init__(self):
        for name in ("lever_arm", "clock0", "sigma_clock0"):
            object.__setattr__(self, name, _floats(getattr(self, name)))
        kw = {k: getattr(self, k) for k in self.to_dict()}
        kw["lever_arm"], kw["clock0"], kw["sigma_clock0"] = list(self.lever_arm), list(self.clock0), list(self.sigma_clock0)
        object.__setattr__(self, "_native", _core.GnssOptions(**kw))

    @property
    def native(self) -> _core.GnssOptions:
        """The checked core object."""
        return self._native


def split_options(options: GnssOptions | None, kw: dict) -> tuple[GnssOptions, dict]:
    """Split keywords into GNSS option fields and the rest.

    Parameters
    ----------
    options : GnssOptions or None
        Base options (None: ``GnssOptions()``).
    kw : dict
        Keywords, some of them fields of :class:`GnssOptions`.

    Returns
    -------
    options : GnssOptions
        ``options`` with the fields among ``kw`` replaced.
    rest : dict
        The other keywords.
    """
    instance(kw, dict, "kw")
    names = set(GnssOptions.__dataclass_fields__)
    mine = {k: v for k, v in kw.items() if k in names}
    rest = {k: v for k, v in kw.items() if k not in names}
    base = GnssOptions() if options is None else instance(options, GnssOptions, "options")
    return (GnssOptions.from_dict({**base.to_dict(), **mine}) if mine else base), rest
