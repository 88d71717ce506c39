//! Sensitivity function and convolution predictor with finite rectangular pulses
//! (Tennstedt et al. 2023 Eqs. 13–14).
//!
//! π pulse (duration 2τ) centred at t = 0, π/2 pulses (τ) at ±(T_d + 1.5τ), Rabi frequency
//! Ω_R = π/(2τ), dark time T_d. The phase response g(t) (E18) is odd; the acceleration
//! response f(t) = −∫_{−∞}^t g (E19) is even and, for t ≥ 0 (integrating (E18) piecewise):
//!   0 ≤ t ≤ τ:               f = T_d + 2τ/π + cos(Ω_R t)/Ω_R
//!   τ ≤ t ≤ T_d + τ:         f = T_d + τ − t + 2τ/π
//!   T_d + τ ≤ t ≤ T_d + 2τ:  f = (1 + cos(Ω_R (t − T_d)))/Ω_R
//!   t ≥ T_d + 2τ:            f = 0.
//! τ = 0 gives the triangle T − |t| of instantaneous pulses.

use crate::error::{check_finite, check_increasing, invalid, Result};
use std::f64::consts::PI;

/// Pulse timing: dark time T_d (s) and π/2-pulse duration τ (s, ≥ 0).
#[derive(Clone, Copy, Debug)]
pub struct Pulses {
    pub t_dark: f64,
    pub tau: f64,
}

impl Pulses {
    pub fn new(t_dark: f64, tau: f64) -> Result<Self> {
        if !(t_dark.is_finite() && t_dark > 0.0) {
            return Err(invalid("t_dark", format!("must be finite and > 0, got {t_dark}")));
        }
        if !(tau.is_finite() && tau >= 0.0) {
            return Err(invalid("tau", format!("must be finite and >= 0, got {tau}")));
        }
        let pulses = Pulses { t_dark, tau };
        if !pulses.area().is_finite() {
            return Err(invalid("t_dark", format!("pulse timing T_d = {t_dark} s, τ = {tau} s is too long: the response area overflows")));
        }
        Ok(pulses)
    }

    /// Half width of the support, T_d + 2τ (s).
    pub fn half_width(&self) -> f64 {
        self.t_dark + 2.0 * self.tau
    }

    /// Pulse-centre separation T = T_d + 1.5τ (s).
    pub fn t_sep(&self) -> f64 {
        self.t_dark + 1.5 * self.tau
    }

    /// Breakpoints of f on t ≥ 0 (the pieces are smooth in between).
    fn knots(&self) -> [f64; 3] {
        [self.tau, self.t_dark + self.tau, self.half_width()]
    }

    /// Phase response g(t) (E18), odd.
    pub fn g(&self, t: f64) -> f64 {
        let (a, tau, td) = (t.abs(), self.tau, self.t_dark);
        let v = if a <= tau {
            if tau == 0.0 { 1.0 } else { (PI / (2.0 * tau) * a).sin() }
        } else if a <= td + tau {
            1.0
        } else if a <= td + 2.0 * tau {
            -(PI / (2.0 * tau) * (td - a)).sin()
        } else {
            0.0
        };
        if t < 0.0 { -v } else { v }
    }

    /// Acceleration response f(t) (s) (E19), even.
    pub fn f(&self, t: f64) -> f64 {
        let (a, tau, td) = (t.abs(), self.tau, self.t_dark);
        let two_tau_pi = 2.0 * tau / PI;
        if a <= tau {
            // cos(Ω_R t)/Ω_R with Ω_R = π/(2τ); tends to τ·2/π·1 → 0 as τ → 0.
            td + two_tau_pi + two_tau_pi * (PI / (2.0 * tau) * a).cos()
        } else if a <= td + tau {
            td + tau - a + two_tau_pi
        } else if a <= td + 2.0 * tau {
            two_tau_pi * (1.0 + (PI / (2.0 * tau) * (a - td)).cos())
        } else {
            0.0
        }
    }

    /// ∫ f dt in closed form, (T_d + 2τ)(T_d + 4τ/π) (s²).
    pub fn area(&self) -> f64 {
        self.half_width() * (self.t_dark + 4.0 * self.tau / PI)
    }
}

/// 5-point Gauss–Legendre rule on [−1, 1].
const GL5: [(f64, f64); 5] = [
    (0.0, 0.5688888888888889),
    (-0.5384693101056831, 0.4786286704993665),
    (0.5384693101056831, 0.4786286704993665),
    (-0.906179845948554, 0.2369268850561891),
    (0.906179845948554, 0.2369268850561891),
];

/// ∫ f(t − t_c) a(t) dt (s · unit of a) with a piecewise linear between its samples and f
/// exact: 5-point Gauss–Legendre on every piece between sample times and f's breakpoints.
// invariant: t has ≥ 2 samples and a as many (checked above); i is clamped to
// [0, t.len() − 2], so i and i + 1 are in range.
#[allow(clippy::indexing_slicing)]
pub fn response_integral(p: &Pulses, t: &[f64], a: &[f64], t_centre: f64) -> Result<f64> {
    check_increasing("t", t)?;
    check_finite("acceleration", a, 1)?;
    check_finite("t_centre", &[t_centre], 1)?;
    if a.len() != t.len() {
        return Err(invalid("acceleration", format!("length {} differs from t length {}", a.len(), t.len())));
    }
    let hw = p.half_width();
    let (lo, hi) = (t_centre - hw, t_centre + hw);
    let &[t_first, .., t_last] = t else {
        return Err(invalid("t", format!("need at least 2 samples, got {}", t.len())));
    };
    if lo < t_first || hi > t_last {
        return Err(invalid("t_centre", format!("pulse window [{lo}, {hi}] s outside the acceleration record")));
    }
    let mut knots: Vec<f64> = p.knots().iter().flat_map(|&k| [t_centre - k, t_centre + k]).collect();
    knots.push(t_centre);
    knots.extend(t.iter().copied().filter(|&x| x > lo && x < hi));
    knots.retain(|&x| x >= lo && x <= hi);
    knots.sort_by(|x, y| x.total_cmp(y));
    knots.dedup();
    let mut sum = 0.0;
    for w in knots.windows(2) {
        let &[x0, x1] = w else { continue };
        let mid = 0.5 * (x0 + x1);
        let i = t.partition_point(|&x| x <= mid).clamp(1, t.len() - 1) - 1;
        let slope = (a[i + 1] - a[i]) / (t[i + 1] - t[i]);
        let h = 0.5 * (x1 - x0);
        for &(u, wgt) in &GL5 {
            let x = mid + h * u;
            sum += h * wgt * p.f(x - t_centre) * (a[i] + slope * (x - t[i]));
        }
    }
    Ok(sum)
}

/// Convolution phase (E20) φ = k ∫ f(t − t_c) a(t) dt (rad) for shots centred on the π
/// pulse at `centres`; a = acceleration of the atoms relative to the sensor along k (m/s²).
pub fn convolution_phase(p: &Pulses, k: f64, t: &[f64], a: &[f64], centres: &[f64]) -> Result<Vec<f64>> {
    centres.iter().map(|&c| Ok(k * response_integral(p, t, a, c)?)).collect()
}

/// Ideal-pulse transfer ∫ (T − |t|) cos(ωt) dt = 4 sin²(ωT/2)/ω² (s²) (E20).
/// Sensitivity g(t) and response f(t) of `p` at every time (s, pulse centred at 0).
pub fn sensitivity_samples(p: &Pulses, t: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
    crate::error::check_finite("t", t, 1)?;
    Ok((t.iter().map(|&x| p.g(x)).collect(), t.iter().map(|&x| p.f(x)).collect()))
}

/// [`ideal_transfer`] at every angular frequency (rad/s) for pulse separation `t_sep` (s).
pub fn ideal_transfers(t_sep: f64, omega: &[f64]) -> Result<Vec<f64>> {
    crate::error::check_positive("T", t_sep)?;
    crate::error::check_finite("omega", omega, 1)?;
    if !(t_sep * t_sep).is_finite() {
        return Err(invalid("T", format!("T = {t_sep} s is too long: T² overflows")));
    }
    if let Some(i) = omega.iter().position(|&w| !(0.5 * w * t_sep).is_finite()) {
        return Err(crate::error::invalid_at("omega", i, format!("ωT/2 overflows at index {i} for T = {t_sep} s")));
    }
    Ok(omega.iter().map(|&w| ideal_transfer(t_sep, w)).collect())
}

/// 4 sin²(ωT/2)/ω², evaluated as T² (sin x / x)² with x = ωT/2 so that an ω whose square
/// underflows (|ω| < 1e-154 rad/s) still gives T² instead of 0/0.
pub fn ideal_transfer(t_sep: f64, omega: f64) -> f64 {
    let x = 0.5 * omega * t_sep;
    if x == 0.0 {
        t_sep * t_sep
    } else {
        t_sep * t_sep * (x.sin() / x).powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// "Finite pulses" reference values: f(0) = 0.0100095493 s, ∫f = 1.002456362e-4 s².
    #[test]
    fn spec_finite_pulse_values() {
        let p = Pulses::new(0.01, 7.5e-6).unwrap();
        assert!((p.f(0.0) - 0.0100095493).abs() < 1e-10);
        assert!((p.area() - 1.002456362e-4).abs() < 1e-13);
    }

    /// f' = −g (E19) and continuity across the knots.
    #[test]
    fn derivative_is_minus_g() {
        let p = Pulses::new(0.01, 1e-3).unwrap();
        for &t in &[-0.0105, -0.0103, -0.004, -5e-4, 3e-4, 2e-3, 0.0104, 0.0108] {
            let h = 1e-7;
            let d = (p.f(t + h) - p.f(t - h)) / (2.0 * h);
            assert!((d + p.g(t)).abs() < 1e-6, "t = {t}: f' = {d}, g = {}", p.g(t));
        }
        for k in p.knots() {
            assert!((p.f(k - 1e-13) - p.f(k + 1e-13)).abs() < 1e-12);
        }
    }
}
