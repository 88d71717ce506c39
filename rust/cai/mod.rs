//! Cold-atom interferometer (CAI): the "atom strapdown" phase predictor (Tennstedt et al. 2023), its
//! inertial oracle, constant-input closed forms, the sensitivity function / convolution
//! predictor, and the fringe noise identification of Tennstedt et al. 2021 §3.
//!
//! Conventions (Tennstedt et al. 2023 §2): pulses at 0, T, 2T of
//! a shot; φ = k·D[x], D[x] = x(0) − 2x(T) + x(2T); atom position x in the sensor frame s
//! (origin at the release point); atom motion driven by the SPECIFIC FORCE
//! (docs/departures.md#specific-force-drives-the-atoms);
//! measured = true + bias, the estimated bias is subtracted.

pub mod aiding;
pub mod closed_form;
pub mod hybrid;
pub mod in_shot;
pub mod noise_id;
pub mod oracle;
pub mod predictor;
pub mod readout;
pub mod sensitivity;

pub use predictor::{Channel, OmegaDot, PredictorConfig};
