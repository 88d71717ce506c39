//! Sensor noise analysis (Niu et al. 2025): the Allan family with the
//! five-term IEEE-952 fit, the time interval error (MTIE, TIE rms), and ARIMA state-space Kalman filters (fixed, adaptive-R of
//! Niu et al. 2025 Eq. 17, Sage–Husa).

pub mod allan;
pub mod arma_filter;
pub mod nnls;
pub mod time_error;
