//! In-shot IMU noise in the predicted CAI phase (docs/departures.md#in-shot-imu-noise-in-r):
//! the predictor is driven by the noisy IMU samples of the shot, so the
//! predicted phase carries their white noise. To first order
//!   δφ̂ = Σ_i s_i n_i,   s_i = ∂φ̂/∂(f_i, ω_i)  (channels × 6),
//! with n_i the noise of sample i (covariance diag(q_a, q_a, q_a, q_g, q_g, q_g)/Δt_i,
//! white PSDs q over the sample interval), so the phase covariance is Σ = Σ_i s_i Q_i s_iᵀ
//! ("R_eff = R + (C/2)² S Q_u Sᵀ
//! with S the phase sensitivity to the IMU samples of the shot").
//!
//! The sensitivities come from the predictor itself (central differences on a record at
//! rest), so every path of the configured interpolation and ω̇ option is included. For a
//! continuous record the paths are (derived from the atom motion with x(0) = 0, w = triangle weight):
//! - accelerometer: −∫ w k·C_sb n_a dt  (variance (2T³/3) q_a |k|²);
//! - gyro through the rotation of v0, Coriolis plus atom Euler term together: to first order
//!   x_h = (I − [θ(t)×]) v0 t, so φ_rot = −2T k·((θ(2T) − θ(T)) × v0) — the gyro noise enters
//!   with weight 2T on [T, 2T] only, variance 4T³ q_g |v0 × k|². The Coriolis-only estimate 2kv0√(2q_g/3)T^{3/2}
//!   is the Coriolis term alone (weight 2w, variance (8T³/3) q_g |v0 × k|²): with a ω̇
//!   consistent with the gyro (options "pwl", "savgol") the true variance is 1.5× larger,
//!   0.3667 rad instead of 0.2994 rad for the IMU of Tennstedt et al. 2023 at T = 25 ms;
//! - gyro through the lever-arm Euler term: −∫ w k·C_sb(ω̇ × l) dt = ∫ w' (l × C_sbᵀk)·ω dt,
//!   w' = ±1 on the two halves, variance 2T q_g |l × C_sbᵀk|²: 0.370 rad for l = 0.1 m ⊥ k at
//!   T = 25 ms — as large as the rest, and absent from the Coriolis-only estimate.

use super::predictor::{predict, Channel, Imu, OmegaDot, PredictorConfig};
use crate::error::{check_increasing, invalid, Result};
use crate::filter::discretize::expm;
use crate::math::Vec3;
use nalgebra::DMatrix;

/// Central-difference steps: the phase is linear in f at rest, and quadratic terms in ω
/// cancel in the central difference.
const STEP_F: f64 = 1e-3;
const STEP_W: f64 = 1e-6;

/// Sensitivity of the phases of the shot starting at `ts` to every sample of the record `t`
/// (a window around the shot), at rest: per sample i with a non-zero effect, (i, s_i) with
/// s_i (channels × 6) = ∂φ̂/∂(f_x, f_y, f_z, ω_x, ω_y, ω_z) of sample i (rad per m/s², rad
/// per rad/s). `cfg`'s ω̇ option is kept except `Given` (independent of the gyro: `Zero`).
// invariant: f and w have t.len() entries and i < t.len(); c < 6, so c or c − 3 is
// < 3 for a Vec3; predict returns one row per channel, j < m.
#[allow(clippy::indexing_slicing)]
pub fn sensitivity(t: &[f64], ts: f64, channels: &[Channel], cfg: &PredictorConfig) -> Result<Vec<(usize, DMatrix<f64>)>> {
    check_increasing("t", t)?;
    let mut cfg = cfg.clone();
    cfg.bias_a = Vec3::zeros();
    cfg.bias_g = Vec3::zeros();
    if let OmegaDot::Given(_) = cfg.omega_dot {
        cfg.omega_dot = OmegaDot::Zero;
    }
    let m = channels.len();
    let mut f = vec![Vec3::zeros(); t.len()];
    let mut w = vec![Vec3::zeros(); t.len()];
    let mut out = Vec::new();
    for i in 0..t.len() {
        let mut s = DMatrix::<f64>::zeros(m, 6);
        for c in 0..6 {
            let step = if c < 3 { STEP_F } else { STEP_W };
            let phase = |sign: f64, f: &mut [Vec3], w: &mut [Vec3]| -> Result<Vec<f64>> {
                if c < 3 { f[i][c] = sign * step } else { w[i][c - 3] = sign * step }
                let p = predict(Imu { t, f, w }, &[ts], channels, &cfg)?;
                if c < 3 { f[i][c] = 0.0 } else { w[i][c - 3] = 0.0 }
                Ok(p.iter().map(|r| r[0]).collect())
            };
            let (hi, lo) = (phase(1.0, &mut f, &mut w)?, phase(-1.0, &mut f, &mut w)?);
            for j in 0..m {
                s[(j, c)] = (hi[j] - lo[j]) / (2.0 * step);
            }
        }
        if s.iter().any(|x| *x != 0.0) {
            out.push((i, s));
        }
    }
    Ok(out)
}

/// Per-sample noise spacing Δt_i of the record (half the distance between the neighbours;
/// one-sided at the ends).
fn spacing(t: &[f64], i: usize) -> f64 {
    let n = t.len();
    // NaN for an index outside the record
    let at = |k: usize| t.get(k).copied().unwrap_or(f64::NAN);
    match (i, n) {
        (_, 0 | 1) => f64::NAN,
        (0, _) => at(1) - at(0),
        (i, n) if i == n - 1 => at(n - 1) - at(n - 2),
        (i, _) => 0.5 * (at(i + 1) - at(i - 1)),
    }
}

/// Phase covariance Σ (channels × channels, rad²) of the in-shot white IMU noise of PSD
/// q_a (m²/s³) and q_g (rad²/s) per axis, from the sensitivities of [`sensitivity`].
pub fn covariance(t: &[f64], sens: &[(usize, DMatrix<f64>)], q_a: f64, q_g: f64, m: usize) -> DMatrix<f64> {
    let mut sigma = DMatrix::<f64>::zeros(m, m);
    for (i, s) in sens {
        let dt = spacing(t, *i);
        let q = DMatrix::from_diagonal(&nalgebra::DVector::from_fn(6, |c, _| if c < 3 { q_a } else { q_g } / dt));
        sigma += s * q * s.transpose();
    }
    sigma
}

/// Cross-covariance E[w δφ̂ᵀ] (15 × channels) between the process noise w of the 15-state
/// INS error model over the filter step [t_s, t_s + 2T] and the in-shot phase noise of the
/// shot measured at its end, for the continuous model `f` (15 × 15, INS15 layout: the
/// noise enters like a negative bias, through F's bias columns 9..15) held over the step:
///   w = −Σ_i Φ(t_s + 2T − t_i) F_b n_i ω_i,  δφ̂ = Σ_i s_i n_i
///   ⇒ E[w δφ̂ᵀ] = −Σ_i ω_i Φ(t_s + 2T − t_i) F_b (Q_6/Δt_i) s_iᵀ,
/// ω_i = the sample's trapezoid weight inside the step (samples outside it, e.g. the cubic
/// stencil, belong to the neighbouring steps and are left out).
pub fn cross_covariance(f: &DMatrix<f64>, t: &[f64], ts: f64, t_sep: f64, sens: &[(usize, DMatrix<f64>)], q_a: f64, q_g: f64) -> Result<DMatrix<f64>> {
    if f.nrows() != 15 || f.ncols() != 15 {
        return Err(invalid("f", format!("expected the 15 × 15 INS error model, got {} × {}", f.nrows(), f.ncols())));
    }
    let end = ts + 2.0 * t_sep;
    let eps = 1e-9 * t_sep;
    let fb = f.columns(9, 6).into_owned();
    let m = sens.first().map_or(0, |s| s.1.nrows());
    let mut out = DMatrix::<f64>::zeros(15, m);
    for (k, (i, s)) in sens.iter().enumerate() {
        let ti = *t.get(*i).ok_or_else(|| crate::error::invalid_at("sens", k, format!("sample index {i} outside the record of {} samples", t.len())))?;
        if ti < ts - eps || ti > end + eps {
            continue;
        }
        let (prev, next) = (i.checked_sub(1).and_then(|j| t.get(j)).copied().unwrap_or(ti), t.get(i + 1).copied().unwrap_or(ti));
        let weight = 0.5 * (ti - prev.max(ts)).max(0.0) + 0.5 * (next.min(end) - ti).max(0.0);
        let dt = spacing(t, *i);
        let q = DMatrix::from_diagonal(&nalgebra::DVector::from_fn(6, |c, _| if c < 3 { q_a } else { q_g } / dt));
        out -= expm(&(f * (end - ti))) * &fb * q * s.transpose() * weight;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cai::predictor::Interpolation;
    use crate::math::Mat3;

    const K: f64 = 1.610576e7;

    fn cyclic(lever: Vec3) -> Vec<Channel> {
        (0..6).map(|c| Channel { k: Vec3::ith(c / 2, K), lever, c_sb: Mat3::identity(), v0: Vec3::ith((c / 2 + 1) % 3, if c % 2 == 0 { 2.8 } else { -2.8 }) }).collect()
    }

    fn cfg(omega_dot: OmegaDot) -> PredictorConfig {
        PredictorConfig { t_sep: 0.025, substeps: 1, gradient: None, bias_a: Vec3::zeros(), bias_g: Vec3::zeros(), omega_dot, interpolation: Interpolation::Linear }
    }

    /// Σ on a fine grid (4 kHz, 200 samples per shot) against the continuous closed forms
    /// of the module doc: accelerometer (2T³/3) q_a k², gyro rotation 4T³ q_g (k v0)² with a
    /// consistent ω̇ and (8T³/3) q_g (k v0)² (E38) without Euler terms, lever-arm Euler
    /// 2T q_g |l × k|²; A/B covariance = accelerometer − rotation part (opposite v0).
    #[test]
    fn covariance_matches_continuous_closed_forms() {
        let (qa, qg, t_sep): (f64, f64, f64) = (1.25e-11, 1.0576e-12, 0.025);
        let t: Vec<f64> = (0..=216).map(|i| -0.002 + i as f64 * 2.5e-4).collect();
        let acc = 2.0 * t_sep.powi(3) / 3.0 * qa * K * K;
        let rot = qg * (K * 2.8).powi(2) * t_sep.powi(3);
        for (omega_dot, rot_var) in [(OmegaDot::Zero, 8.0 / 3.0 * rot), (OmegaDot::Pwl, 4.0 * rot)] {
            let chs = cyclic(Vec3::zeros());
            let s = sensitivity(&t, 0.0, &chs, &cfg(omega_dot.clone())).unwrap();
            let sig = covariance(&t, &s, qa, qg, 6);
            assert!((sig[(0, 0)] / (acc + rot_var) - 1.0).abs() < 5e-3, "{omega_dot:?}: {} vs {}", sig[(0, 0)], acc + rot_var);
            // a difference of the two parts: relative to the variance (the step weight of the
            // rotation at T is resolved to O(Δt/T) on the grid)
            assert!((sig[(0, 1)] - (acc - rot_var)).abs() < 5e-3 * (acc + rot_var), "{omega_dot:?}: {} vs {}", sig[(0, 1)], acc - rot_var);
            assert!(sig[(0, 2)].abs() < 1e-6 * sig[(0, 0)]);
        }
        // lever arm 0.1 m along z: the x and y channels gain 2T q_g (k l)² (ω_y resp. ω_x)
        let chs = cyclic(Vec3::new(0.0, 0.0, 0.1));
        let s = sensitivity(&t, 0.0, &chs, &cfg(OmegaDot::Pwl)).unwrap();
        let sig = covariance(&t, &s, qa, qg, 6);
        let lever = 2.0 * t_sep * qg * (K * 0.1).powi(2);
        assert!((sig[(4, 4)] / (acc + 4.0 * rot) - 1.0).abs() < 5e-3, "z channel has k ∥ l: {}", sig[(4, 4)]);
        // the lever-arm weight w' jumps from +1 to −1 at T: resolved to O(Δt/T) = 1 % on this grid
        assert!((sig[(0, 0)] / (acc + 4.0 * rot + lever) - 1.0).abs() < 1e-2, "{} vs {}", sig[(0, 0)], acc + 4.0 * rot + lever);
        // Tennstedt et al. 2023 IMU numbers (module doc): 0.3667 rad rotation, 0.370 rad lever-arm Euler
        assert!(((4.0 * rot).sqrt() - 0.3667).abs() < 5e-4 && (lever.sqrt() - 0.370).abs() < 1e-3);
    }

    /// Cross-covariance with F = 0 except the bias columns (δv̇ = −δb_a + n_a, ψ̇ = δb_g − n_g),
    /// channel x-A (k = K x̂, v0 = 2.8 ŷ, v0 × k = −2.8K ẑ), continuous limit:
    /// δφ = −∫ w K n_a,x dt + 5.6 T K ∫_T^{2T} n_g,z dt, w_v,x = ∫ n_a,x, w_ψ,z = −∫ n_g,z, so
    /// E[w_v,x δφ] = −q_a K T² and E[w_ψ,z δφ] = −5.6 q_g K T²; position rows are zero.
    #[test]
    fn cross_covariance_matches_continuous_limit() {
        let (qa, qg, t_sep): (f64, f64, f64) = (1.25e-11, 1.0576e-12, 0.025);
        let t: Vec<f64> = (0..=216).map(|i| -0.002 + i as f64 * 2.5e-4).collect();
        let chs = cyclic(Vec3::zeros());
        let s = sensitivity(&t, 0.0, &chs, &cfg(OmegaDot::Pwl)).unwrap();
        let mut f = DMatrix::<f64>::zeros(15, 15);
        for a in 0..3 {
            f[(3 + a, 9 + a)] = -1.0;
            f[(6 + a, 12 + a)] = 1.0;
        }
        let c = cross_covariance(&f, &t, 0.0, t_sep, &s, qa, qg).unwrap();
        let (ev, epsi) = (-qa * K * t_sep * t_sep, -5.6 * qg * K * t_sep * t_sep);
        assert!((c[(3, 0)] / ev - 1.0).abs() < 5e-3, "{} vs {ev}", c[(3, 0)]);
        assert!((c[(8, 0)] / epsi - 1.0).abs() < 5e-3, "{} vs {epsi}", c[(8, 0)]);
        assert!(c.rows(0, 3).iter().all(|x| x.abs() < 1e-30));
    }
}
