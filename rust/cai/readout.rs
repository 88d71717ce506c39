//! CAI readout and fringe steering (Tennstedt et al. 2021, Eqs. 3–6): population
//! p = o − (C/2) cos(φ + φ0) of a shot with phase φ, offset o, contrast C and laser phase φ0;
//! the laser phase that puts a predicted phase φ̂ at mid-fringe is φ0 = (π/2 − φ̂) mod 2π.

use crate::error::{check_finite, invalid, Result};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Population o − (C/2) cos(φ) of a total phase φ = φ_atom + φ0 (rad).
pub fn population(offset: f64, contrast: f64, phase: f64) -> f64 {
    offset - 0.5 * contrast * phase.cos()
}

/// Slope ∂p/∂φ = (C/2) sin(φ) of the readout at total phase φ (rad).
pub fn slope(contrast: f64, phase: f64) -> f64 {
    0.5 * contrast * phase.sin()
}

/// Laser phase φ0 = (π/2 − φ̂) mod 2π (rad) putting the predicted phase φ̂ at mid-fringe.
pub fn steer_mid_fringe(phi_hat: f64) -> f64 {
    (FRAC_PI_2 - phi_hat).rem_euclid(TAU)
}

/// [`population`] of every element: total phases (rad) and contrasts of equal length.
pub fn populations(offset: f64, contrast: &[f64], phase: &[f64]) -> Result<Vec<f64>> {
    if contrast.len() != phase.len() {
        return Err(invalid("contrast", format!("expected {} values like the phase, got {}", phase.len(), contrast.len())));
    }
    check_finite("offset", &[offset], 1)?;
    check_finite("contrast", contrast, 1)?;
    check_finite("phi", phase, 1)?;
    Ok(contrast.iter().zip(phase).map(|(&c, &p)| population(offset, c, p)).collect())
}

/// [`steer_mid_fringe`] of every predicted phase (rad).
pub fn steer_all(phi_hat: &[f64]) -> Result<Vec<f64>> {
    check_finite("phi_hat", phi_hat, 1)?;
    Ok(phi_hat.iter().map(|&p| steer_mid_fringe(p)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// At mid-fringe the population is the offset and the slope is C/2 (Eq. 3 at φ = π/2).
    #[test]
    fn steered_phase_sits_at_mid_fringe() {
        for phi_hat in [-7.3, -0.2, 0.0, 1.0, 12.5] {
            let phi0 = steer_mid_fringe(phi_hat);
            assert!((0.0..TAU).contains(&phi0));
            let total = phi_hat + phi0;
            assert!((population(0.45, 0.8, total) - 0.45).abs() < 1e-12);
            assert!((slope(0.8, total) - 0.4).abs() < 1e-12);
        }
        // fringe extremes: p = o ∓ C/2 at φ = 0, π
        assert!((population(0.5, 1.0, 0.0) - 0.0).abs() < 1e-15);
        assert!((population(0.5, 1.0, PI) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn populations_check_lengths_and_finiteness() {
        assert!(populations(0.5, &[1.0], &[0.0, 1.0]).unwrap_err().to_string().starts_with("contrast:"));
        assert!(populations(0.5, &[1.0], &[f64::NAN]).unwrap_err().to_string().starts_with("phi:"));
        assert!(steer_all(&[f64::INFINITY]).unwrap_err().to_string().starts_with("phi_hat:"));
    }
}
