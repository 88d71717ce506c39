//! Scalar noise processes of one sensor axis, and the conversions between their
//! continuous (PSD) and per-sample parameterisations.
//!
//! Every process is simulated as its INCREMENT over a sample interval [t_k, t_k + Δt]:
//! the exact integral of the continuous process over the interval, drawn jointly with the
//! process state at the interval end. A rate-kind sample is that increment divided by Δt
//! (the interval-average rate), an increment-kind sample is the increment itself, so both
//! output kinds come from one code path (errors.rs).
//!
//! Density conventions (two-sided, IEEE Std 952-1997 Annex C):
//! - white noise of density N (ARW in rad/√s, VRW in m/s/√s = m/s²/√Hz):
//!   E[w(t) w(s)] = N² δ(t − s); two-sided PSD N², one-sided 2N²;
//! - bias random walk of density K (rad/s/√s, m/s²/√s): ḃ = w, E[w w] = K² δ, Var b(t) = K² t;
//! - first-order Gauss–Markov (Ornstein–Uhlenbeck) of stationary σ and correlation time τ:
//!   ṁ = −m/τ + w, E[w w] = 2σ²/τ · δ;
//! - flicker (bias instability B, IEEE 952 definition): two-sided PSD B²/(2π|f|), one-sided
//!   B²/(π f), Allan-deviation floor B·√(2 ln 2/π) ≈ 0.664 B.

use super::ImuKind;
use crate::error::{check_positive, invalid, Result};
use rand::Rng;
use rand_distr::StandardNormal;
use std::f64::consts::{LN_10, LN_2, PI};

fn check_density(field: &str, x: f64) -> Result<()> {
    if x.is_finite() && x >= 0.0 {
        Ok(())
    } else {
        Err(invalid(field, format!("must be finite and >= 0, got {x}")))
    }
}

/// `value` if finite; otherwise an error naming `field`, the argument whose extreme value
/// (e.g. Δt = 5e-324 s) made the result overflow.
fn finite(field: &str, value: f64, args: &str) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(invalid(field, format!("the result overflows for {args}")))
    }
}

/// Per-sample σ of white noise of density N at interval Δt: N/√Δt for a rate sample,
/// N·√Δt for an increment (σ_d² = q/Δt, q = N²).
pub fn white_sigma(density: f64, dt: f64, kind: ImuKind) -> Result<f64> {
    check_density("density", density)?;
    check_positive("dt", dt)?;
    finite("dt", density * dt.sqrt() * kind.per_increment(dt), &format!("density = {density}, dt = {dt} s"))
}

/// Density N (rad/√s or m/s/√s) of white noise whose per-sample σ is `sigma` at Δt; the
/// inverse of [`white_sigma`].
pub fn white_density(sigma: f64, dt: f64, kind: ImuKind) -> Result<f64> {
    check_density("sigma", sigma)?;
    check_positive("dt", dt)?;
    finite("dt", sigma / (dt.sqrt() * kind.per_increment(dt)), &format!("sigma = {sigma}, dt = {dt} s"))
}

/// σ of the per-sample bias step of a random walk of density K: K·√Δt.
pub fn random_walk_step_sigma(density: f64, dt: f64) -> Result<f64> {
    check_density("density", density)?;
    check_positive("dt", dt)?;
    finite("density", density * dt.sqrt(), &format!("density = {density}, dt = {dt} s"))
}

/// Density K of a random walk whose per-sample step has σ `step_sigma` at Δt.
pub fn random_walk_density(step_sigma: f64, dt: f64) -> Result<f64> {
    check_density("step_sigma", step_sigma)?;
    check_positive("dt", dt)?;
    finite("dt", step_sigma / dt.sqrt(), &format!("step_sigma = {step_sigma}, dt = {dt} s"))
}

/// Per-sample driving σ_u of the discrete Gauss–Markov m_{k+1} = e^{−Δt/τ} m_k + u_k with
/// stationary σ: σ_u = σ·√(1 − e^{−2Δt/τ}).
pub fn gauss_markov_driving_sigma(sigma: f64, tau: f64, dt: f64) -> Result<f64> {
    check_density("sigma", sigma)?;
    check_positive("tau", tau)?;
    check_positive("dt", dt)?;
    Ok(sigma * (-(-2.0 * dt / tau).exp_m1()).sqrt())
}

/// Stationary σ of the discrete Gauss–Markov driven by per-sample σ_u at Δt; the inverse of
/// [`gauss_markov_driving_sigma`]: σ_m = σ_gm/√(1 − e^{−2Δt/τ}).
pub fn gauss_markov_sigma(driving_sigma: f64, tau: f64, dt: f64) -> Result<f64> {
    check_density("driving_sigma", driving_sigma)?;
    check_positive("tau", tau)?;
    check_positive("dt", dt)?;
    finite("dt", driving_sigma / (-(-2.0 * dt / tau).exp_m1()).sqrt(), &format!("driving_sigma = {driving_sigma}, tau = {tau} s, dt = {dt} s"))
}

/// Amplitude spectral density of a Gauss–Markov process at frequencies f ≪ 1/(2πτ):
/// √(2σ²/τ)·τ = σ√(2τ) (two-sided).
pub fn gauss_markov_low_freq_asd(sigma: f64, tau: f64) -> Result<f64> {
    check_density("sigma", sigma)?;
    check_positive("tau", tau)?;
    finite("sigma", sigma * (2.0 * tau).sqrt(), &format!("sigma = {sigma}, tau = {tau} s"))
}

/// One-sided PSD B²/(π f) of flicker noise of bias instability B at frequency f (Hz).
pub fn flicker_psd(b: f64, f: f64) -> Result<f64> {
    check_density("b", b)?;
    check_positive("f", f)?;
    finite("f", b * b / (PI * f), &format!("b = {b}, f = {f} Hz"))
}

/// Allan-deviation floor of flicker noise: B·√(2 ln 2/π) (IEEE Std 952, Table C.1).
pub fn flicker_allan_floor(b: f64) -> Result<f64> {
    check_density("b", b)?;
    Ok(b * (2.0 * LN_2 / PI).sqrt())
}

/// A scalar process simulated interval by interval; `step` returns the integral of the
/// process over the next interval and advances its state to the interval end.
pub trait Increment {
    fn step<R: Rng>(&mut self, rng: &mut R) -> f64;
}

fn normal<R: Rng>(rng: &mut R) -> f64 {
    rng.sample(StandardNormal)
}

/// White noise of density N: increment N·√Δt·z.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct White {
    sigma_increment: f64,
}

impl White {
    pub fn new(density: f64, dt: f64) -> Self {
        Self { sigma_increment: density * dt.sqrt() }
    }
}

impl Increment for White {
    fn step<R: Rng>(&mut self, rng: &mut R) -> f64 {
        self.sigma_increment * normal(rng)
    }
}

/// Bias random walk b(t) = b_k + K·W(t − t_k), started at b = 0. Exact joint draw of the
/// step and the integral: with W over one interval, Var W(Δt) = Δt, Var ∫W = Δt³/3,
/// Cov = Δt²/2, so W(Δt) = √Δt z₁ and ∫W = Δt^{3/2}(z₁/2 + z₂/(2√3)).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct RandomWalk {
    dt: f64,
    /// K√Δt, σ of the step.
    step: f64,
    /// KΔt^{3/2}, scale of the in-interval integral.
    int: f64,
    b: f64,
}

impl RandomWalk {
    pub fn new(density: f64, dt: f64) -> Self {
        Self { dt, step: density * dt.sqrt(), int: density * dt * dt.sqrt(), b: 0.0 }
    }
}

impl Increment for RandomWalk {
    fn step<R: Rng>(&mut self, rng: &mut R) -> f64 {
        let (z1, z2) = (normal(rng), normal(rng));
        let integral = self.b * self.dt + self.int * (0.5 * z1 + z2 * (0.5 / 3f64.sqrt()));
        self.b += self.step * z1;
        integral
    }
}

/// f(x) = x − 2(1 − e^{−x}) + (1 − e^{−2x})/2 = Σ_{n≥3} (−1)^{n+1}(2^{n−1} − 2) xⁿ/n!, the
/// normalised variance of the noise part of ∫m over an interval (series below x = 0.5,
/// where the closed form cancels).
fn ou_integral_variance_factor(x: f64) -> f64 {
    if x >= 0.5 {
        return x + 2.0 * (-x).exp_m1() - 0.5 * (-2.0 * x).exp_m1();
    }
    let (mut sum, mut term) = (0.0, x * x / 2.0); // term = xⁿ/n!, starting at n = 2
    for n in 3..30 {
        term *= x / n as f64;
        let sign = if n % 2 == 1 { 1.0 } else { -1.0 };
        sum += sign * (2f64.powi(n - 1) - 2.0) * term;
    }
    sum
}

/// First-order Gauss–Markov (Ornstein–Uhlenbeck) process of stationary σ and correlation
/// time τ, started from its stationary distribution. Exact discretisation with
/// x = Δt/τ, a = e^{−x}:
///   m_{k+1} = a m_k + ε₁,            Var ε₁ = σ²(1 − a²)
///   ∫m      = τ(1 − a) m_k + ε₂,     Var ε₂ = 2σ²τ² f(x),  Cov(ε₁, ε₂) = σ²τ(1 − a)²
/// (integrals of the OU Green's function e^{−(t−u)/τ} against dW; stationary check:
/// Var ∫m = 2σ²τ²(x − 1 + e^{−x})). ε₁, ε₂ are drawn by a 2 × 2 Cholesky factor.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct GaussMarkov {
    a: f64,
    gain_int: f64,
    l11: f64,
    l21: f64,
    l22: f64,
    m: f64,
}

impl GaussMarkov {
    /// `rng` draws the initial state m₀ ~ N(0, σ²).
    pub fn new<R: Rng>(sigma: f64, tau: f64, dt: f64, rng: &mut R) -> Self {
        let x = dt / tau;
        let one_minus_a = -(-x).exp_m1();
        let var1 = sigma * sigma * -(-2.0 * x).exp_m1();
        let var2 = 2.0 * sigma * sigma * tau * tau * ou_integral_variance_factor(x);
        let cov = sigma * sigma * tau * one_minus_a * one_minus_a;
        let l11 = var1.sqrt();
        let l21 = if l11 > 0.0 { cov / l11 } else { 0.0 };
        let l22 = (var2 - l21 * l21).max(0.0).sqrt();
        Self { a: 1.0 - one_minus_a, gain_int: tau * one_minus_a, l11, l21, l22, m: sigma * normal(rng) }
    }
}

impl Increment for GaussMarkov {
    fn step<R: Rng>(&mut self, rng: &mut R) -> f64 {
        let (z1, z2) = (normal(rng), normal(rng));
        let integral = self.gain_int * self.m + self.l21 * z1 + self.l22 * z2;
        self.m = self.a * self.m + self.l11 * z1;
        integral
    }
}

/// Poles per decade of the flicker approximation.
pub const FLICKER_POLES_PER_DECADE: f64 = 2.0;
/// Extra poles beyond each edge of the requested band.
pub const FLICKER_EDGE_POLES: i32 = 3;

/// Flicker (1/f) noise as a sum of independent Gauss–Markov processes with log-spaced
/// correlation times (Keshner 1982, "1/f noise", Proc. IEEE 70(3); the standard
/// superposition-of-Lorentzians construction). Corner frequencies f_i = 1/(2πτ_i) are spaced
/// by r = 10^{1/2} (2 per decade) from f_lo/r³ to at least f_hi·r³ (3 extra poles past
/// each band edge); each has stationary variance σ_p² = B² ln r / π, because
/// Σ_i 4σ_p²τ_i/(1 + (2πfτ_i)²) ≈ (1/ln r)∫ 4σ_p²/(1 + (2πfτ)²) dτ = σ_p²/(f ln r).
/// Valid band: [f_lo, f_hi], where the one-sided PSD is B²/(πf) within −1.4 %/+0.1 %
/// for any band (edge loss and ripple of the Lorentzian sum, checked in the unit test);
/// below f_lo it flattens
/// (bounded variance N_p σ_p²), above f_hi it falls as 1/f². Streamable with bounded
/// memory, unlike Kasdin's fractional-difference filter, whose memory grows with the record.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Flicker {
    poles: Vec<GaussMarkov>,
}

impl Flicker {
    /// Correlation times τ_i (s) of the poles for the band [f_lo, f_hi] (Hz).
    pub fn correlation_times(f_lo: f64, f_hi: f64) -> Vec<f64> {
        let ln_r = LN_10 / FLICKER_POLES_PER_DECADE;
        let n_band = ((f_hi / f_lo).ln() / ln_r - 1e-9).ceil().max(0.0) as i32;
        (-FLICKER_EDGE_POLES..=n_band + FLICKER_EDGE_POLES)
            .map(|i| 1.0 / (2.0 * PI * f_lo * (i as f64 * ln_r).exp()))
            .collect()
    }

    /// Stationary σ of each pole for bias instability B.
    pub fn pole_sigma(b: f64) -> f64 {
        b * (LN_10 / FLICKER_POLES_PER_DECADE / PI).sqrt()
    }

    /// (σ, τ) of every pole for bias instability B (≥ 0) in the band [f_lo, f_hi] (Hz,
    /// 0 < f_lo < f_hi): the Gauss–Markov processes whose sum the simulator draws, for a
    /// linear analysis that augments its state with them.
    pub fn poles(b: f64, f_lo: f64, f_hi: f64) -> Result<Vec<(f64, f64)>> {
        check_density("b", b)?;
        check_positive("f_lo", f_lo)?;
        check_positive("f_hi", f_hi)?;
        if f_hi <= f_lo {
            return Err(invalid("f_hi", format!("must exceed f_lo = {f_lo}, got {f_hi}")));
        }
        let s = finite("b", Self::pole_sigma(b), &format!("b = {b}"))?;
        let args = format!("f_lo = {f_lo} Hz, f_hi = {f_hi} Hz");
        Self::correlation_times(f_lo, f_hi).into_iter().map(|tau| Ok((s, finite("f_lo", tau, &args)?))).collect()
    }

    /// `rng` draws the initial states of all poles (stationary start).
    pub fn new<R: Rng>(b: f64, f_lo: f64, f_hi: f64, dt: f64, rng: &mut R) -> Self {
        let s = Self::pole_sigma(b);
        Self { poles: Self::correlation_times(f_lo, f_hi).into_iter().map(|tau| GaussMarkov::new(s, tau, dt, rng)).collect() }
    }
}

impl Increment for Flicker {
    fn step<R: Rng>(&mut self, rng: &mut R) -> f64 {
        self.poles.iter_mut().map(|p| p.step(rng)).sum()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn overflow_from_a_tiny_step_is_an_error_naming_it() {
        use crate::error::NavError;
        let field = |r: Result<f64>| match r {
            Err(NavError::InvalidInput { field, .. }) => field,
            other => panic!("expected InvalidInput, got {other:?}"),
        };
        assert_eq!(field(super::flicker_psd(1.0, 5e-324)), "f");
        assert_eq!(field(super::gauss_markov_sigma(1.0, 1e300, 5e-324)), "dt");
        assert_eq!(field(super::gauss_markov_low_freq_asd(1e308, 3.81)), "sigma");
        assert_eq!(field(super::random_walk_step_sigma(1e308, 100.0)), "density");
        assert_eq!(super::random_walk_step_sigma(3.0, 4.0).unwrap_or(f64::NAN), 6.0); // K√Δt
        assert_eq!(super::gauss_markov_low_freq_asd(3.0, 2.0).unwrap_or(f64::NAN), 6.0); // σ√(2τ)
        // a small but representable step still gives the closed form N/√Δt
        let s = super::white_sigma(2.0, 1e-6, ImuKind::Rates).unwrap_or(f64::NAN);
        assert!((s / 2000.0 - 1.0).abs() < 1e-12, "{s}");
    }

    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha12Rng;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn tennstedt2023_noise_conversions() {
        // Tennstedt et al. 2023: 5e-5 m/s² and 1.4544e-5 rad/s per sample at 200 Hz
        let dt = 1.0 / 200.0;
        let qa = white_density(5e-5, dt, ImuKind::Rates).unwrap();
        assert!(rel(qa, 3.5355e-6) < 1e-4);
        assert!(rel(qa * qa, 1.25e-11) < 1e-12);
        let ng = white_density(1.4544e-5, dt, ImuKind::Rates).unwrap();
        assert!(rel(ng, 1.0284e-6) < 1e-4);
        assert!(rel(random_walk_step_sigma(9e-10f64.sqrt(), dt).unwrap(), 2.1213e-6) < 1e-4);
        assert!(rel(random_walk_step_sigma(2e-7, dt).unwrap(), 1.4142e-8) < 1e-4);
        assert!(rel(white_sigma(qa, dt, ImuKind::Rates).unwrap(), 5e-5) < 1e-14);
        assert!(rel(white_sigma(qa, dt, ImuKind::Increments).unwrap(), 5e-5 * dt) < 1e-14);
    }

    #[test]
    fn tennstedt2021_gauss_markov_numbers() {
        // Tennstedt et al. 2021 satellite Gauss–Markov: Δt = 1 s, τ = 10 s, σ_gm = 2e-12
        let s = gauss_markov_sigma(2e-12, 10.0, 1.0).unwrap();
        assert!(rel(s, 4.6975e-12) < 1e-4);
        assert!(rel(gauss_markov_driving_sigma(s, 10.0, 1.0).unwrap(), 2e-12) < 1e-14);
        assert!(rel(gauss_markov_low_freq_asd(s, 10.0).unwrap(), 2.10e-11) < 3e-3);
    }

    #[test]
    fn ou_factor_series_matches_closed_form() {
        for x in [0.05f64, 0.2, 0.49] {
            let closed = x + 2.0 * (-x).exp_m1() - 0.5 * (-2.0 * x).exp_m1();
            assert!(rel(ou_integral_variance_factor(x), closed) < 1e-10, "x = {x}");
        }
        assert!(rel(ou_integral_variance_factor(1e-6), 1e-18 / 3.0) < 1e-5);
    }

    #[test]
    fn gauss_markov_integral_variance_is_stationary_closed_form() {
        // Var ∫m over Δt = 2σ²τ²(x − 1 + e^{−x}) for a stationary OU process
        let (sigma, tau, dt) = (2.0, 0.5, 0.5);
        let mut rng = ChaCha12Rng::seed_from_u64(7);
        let mut gm = GaussMarkov::new(sigma, tau, dt, &mut rng);
        let n = 200_000;
        let v: f64 = (0..n).map(|_| gm.step(&mut rng).powi(2)).sum::<f64>() / n as f64;
        let x: f64 = dt / tau;
        let expect = 2.0 * sigma * sigma * tau * tau * (x - 1.0 + (-x).exp());
        assert!(rel(v, expect) < 0.03, "{v} vs {expect}");
    }

    #[test]
    fn flicker_lorentzian_sum_is_one_over_f_in_band() {
        // one-sided PSD of the pole sum, Σ 4σ_p²τ_i/(1 + (2πfτ_i)²), against B²/(πf)
        let b = 1.0;
        let s2 = Flicker::pole_sigma(b).powi(2);
        for (f_lo, f_hi) in [(1e-4, 1e-1), (1e-3, 1.0), (2e-4, 0.05), (1e-5, 3e-5), (0.01, 0.0100001)] {
            let taus = Flicker::correlation_times(f_lo, f_hi);
            for i in 0..=300 {
                let f = f_lo * (f_hi / f_lo).powf(i as f64 / 300.0);
                let s: f64 = taus.iter().map(|t| 4.0 * s2 * t / (1.0 + (2.0 * PI * f * t).powi(2))).sum();
                let ratio = s / flicker_psd(b, f).unwrap();
                assert!((0.986..=1.001).contains(&ratio), "band [{f_lo}, {f_hi}], f = {f}: {ratio}");
            }
        }
    }

    #[test]
    fn flicker_poles_are_the_simulated_ones() {
        // 3 decades at 2 poles per decade: 6 band steps and 3 edge poles on each side
        let poles = Flicker::poles(2.0, 1e-4, 0.1).unwrap();
        assert_eq!(poles.len(), 13);
        let taus = Flicker::correlation_times(1e-4, 0.1);
        for ((s, tau), t) in poles.iter().zip(&taus) {
            assert_eq!((*s, *tau), (Flicker::pole_sigma(2.0), *t));
        }
        // σ_p² = B² ln r / π with r = √10; the slowest pole at f_lo/r³
        assert!(rel(poles[0].0.powi(2), 4.0 * LN_10 / 2.0 / PI) < 1e-15);
        assert!(rel(poles[0].1, 10f64.powf(1.5) / (2.0 * PI * 1e-4)) < 1e-12);
        let field = |r: Result<Vec<(f64, f64)>>| r.map_or_else(|e| e.to_string(), |_| String::new());
        assert!(field(Flicker::poles(-1.0, 1e-4, 0.1)).starts_with("b:"));
        assert!(field(Flicker::poles(1.0, 0.0, 0.1)).starts_with("f_lo:"));
        assert!(field(Flicker::poles(1.0, 0.1, 0.1)).starts_with("f_hi:"));
        assert!(field(Flicker::poles(1.0, 5e-324, 1e-300)).starts_with("f_lo:"));
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let e = white_sigma(-1.0, 0.01, ImuKind::Rates).unwrap_err().to_string();
        assert!(e.starts_with("density:"), "{e}");
        let e = gauss_markov_driving_sigma(1.0, 0.0, 0.01).unwrap_err().to_string();
        assert!(e.starts_with("tau:"), "{e}");
        assert!(<ImuKind as crate::options::Choice>::parse("samples").is_err());
    }
}
