"""Estimation engine: Riccati / steady-state analysis, discretisation, error-state
Kalman filter, covariance analysis, consistency and Monte Carlo (Rust core in
``rust/filter``)."""

from .riccati import SteadyState, closed_loop_matrix, dare, kalman_recursion, riccati_scalar
from .aided import VERTICAL, AidedIns, AidedResult, InsSetup, SmoothedResult, position_aided_ins
from .sources import PositionFixes, Source, VelocityFixes, ZeroRate, ZeroVelocity, aided_ins
from .analysis import MonteCarlo, Scenario, chi2_band, covariance_analysis, monte_carlo
from .outages import OutageResult, outage_analysis, outage_windows, score_outages
from .constraints import NonHolonomic, StillPeriods, detect_still
from .engine import BIAS_KINDS, INS15, STANDARD_BLOCKS, BiasModel, Config, KalmanFilter, Layout, discretize, ins_error_model, rts_smooth

__all__ = ["SteadyState", "closed_loop_matrix", "dare", "kalman_recursion", "riccati_scalar",
           "BIAS_KINDS", "INS15", "STANDARD_BLOCKS", "BiasModel", "Config", "KalmanFilter", "Layout", "discretize", "ins_error_model", "rts_smooth",
           "MonteCarlo", "Scenario", "chi2_band", "covariance_analysis", "monte_carlo", "AidedIns", "AidedResult", "InsSetup", "SmoothedResult", "VERTICAL", "position_aided_ins",
           "PositionFixes", "Source", "VelocityFixes", "ZeroRate", "ZeroVelocity", "aided_ins",
           "OutageResult", "outage_analysis", "outage_windows", "score_outages",
           "NonHolonomic", "StillPeriods", "detect_still"]
