"""Cold-atom interferometer: atom strapdown phase prediction from IMU data (Tennstedt et al. 2023), the
inertial oracle, closed forms, readout and fringe handling, sensitivity function and
convolution predictor, fringe noise identification (Tennstedt et al. 2021, §3), and the
CAI-aided INS with its Monte-Carlo scenarios (``sensor``, ``scenarios``, ``campaign``,
``results``)."""

from .predictor import (
    JACOBIAN_PARAMS, K_RB87, LAMBDA_RB87, TERMS, Channels, ImuRateWarning, PhasePrediction, SineMotion, YawDrive,
    acceleration_noise, capture_limits, in_shot_noise_phase, check_jacobian, dynamic_range, k_eff, motion_imu, oracle_phase,
    phase_constant, phase_jacobian, phase_noise, phase_seed000, phase_series, predict_phase,
    readout_jacobian, sagnac_phase, scale_factors, t_sep_from_total, total_from_t_sep,
)
from .readout import capture_region, fringes_crossed, invert_readout, readout, steer_mid_fringe
from .sensitivity import convolution_phase, ideal_transfer, response_area, sensitivity
from .noise_id import fringe_track, identify_noise, readout_variance, residuals, simulate_fringe

from .sensor import (
    CaiSensor, CaiShots, FilterSetup, IncompleteShotWarning, cai_aided_ins, expected_phase_exceedance, in_shot_noise, incomplete_shots,
)
from .results import BIAS_COLUMNS, ERROR_COLUMNS, HybridResult, satellite_psd, satellite_steady_state
from .campaign import run_campaign
from .scenarios import (
    HANNOVER, ScenarioConfig, accelerometer_sensor, car_mc, hexapod, satellite, seed003_filter, seed003_sensor, slalom,
    slalom_covariance,
)

__all__ = [name for name in dir() if not name.startswith("_")]
