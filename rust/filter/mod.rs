//! Estimation engine: error-state Kalman filter, discretisation, Riccati analysis,
//! consistency measures. Dense algebra on nalgebra `DMatrix` (state sizes 1–30),
//! the DARE doubling on the padded register-chunk kernels of matrix.rs.

pub mod matrix;
pub mod dense;
pub mod riccati;
pub mod discretize;
pub mod layout;
pub mod kf;
pub mod ins;
pub mod analysis;
pub mod aided;
pub mod sources;
pub mod initial_error;
pub mod alignment;
pub mod constraints;
