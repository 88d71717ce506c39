"""Cold-atom interferometer: atom strapdown phase prediction from IMU data (seed 003), the
inertial oracle, closed forms, readout and fringe handling, sensitivity function and
convolution predictor, and fringe noise identification (seed 000 §3)."""

from .predictor import (
    JACOBIAN_PARAMS, K_RB87, LAMBDA_RB87, TERMS, Channels, PhasePrediction, SineMotion, YawDrive,
    acceleration_noise, capture_limits, in_shot_noise_covariance, in_shot_noise_phase, check_jacobian, dynamic_range, k_eff, motion_imu, oracle_phase,
    paper_jacobian, phase_constant, phase_first_order, phase_jacobian, phase_noise, phase_seed000, phase_series, predict_phase,
    readout_jacobian, sagnac_phase, scale_factors, t_sep_from_total, total_from_t_sep,
)
from .readout import capture_region, fringes_crossed, invert_readout, readout, steer_mid_fringe
from .sensitivity import convolution_phase, ideal_transfer, response_area, sensitivity
from .noise_id import fringe_track, identify_noise, readout_variance, residuals, simulate_fringe

from . import hybrid

__all__ = [name for name in dir() if not name.startswith("_")]
