//! Steady-state Kalman filter: scalar closed forms of seed 000 (spec cai-ekf E26/E27,
//! paper Eqs. 32–35) and the general discrete algebraic Riccati equation (DARE) solved by
//! the structure-preserving doubling algorithm (SDA) on faer.
//!
//! Filter form (spec cai-ekf E24, paper Eq. 31), a-priori covariance P⁻:
//!   P⁻ = Φ P⁻ Φᵀ + Q − Φ P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻ Φᵀ,
//! a-posteriori (E25): P⁺ = P⁻ − P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻, gain K∞ = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ = P⁺ Hᵀ R⁻¹.

use super::matrix::{check_covariance, check_square, symmetrize};
use crate::error::{invalid, Result};
use faer::linalg::solvers::Solve;
use faer::Mat;
use nalgebra::DMatrix;

/// Scalar a-priori steady state for Φ = 1 (spec cai-ekf E26):
/// P⁻ = Q/2 + √(Q²/4 + QR/H²).
pub fn scalar_prior(q: f64, r: f64, h: f64) -> f64 {
    0.5 * q + (0.25 * q * q + q * r / (h * h)).sqrt()
}

/// Scalar a-posteriori steady state for Φ = 1 (spec cai-ekf E27, paper Eqs. 32/33; the
/// value Table 1 lists): P⁺ = −Q/2 + √(Q²/4 + QR/H²), evaluated as (QR/H²)/P⁻ to avoid
/// cancellation (the product of the two roots of P² + QP − QR/H² = 0 is −QR/H²).
pub fn scalar_posterior(q: f64, r: f64, h: f64) -> f64 {
    q * r / (h * h) / scalar_prior(q, r, h)
}

/// Steady-state solution of the filter DARE.
#[derive(Debug, Clone)]
pub struct SteadyState {
    /// A-priori covariance P⁻ (n × n).
    pub p_prior: DMatrix<f64>,
    /// A-posteriori covariance P⁺ (n × n).
    pub p_post: DMatrix<f64>,
    /// Gain K∞ (n × m).
    pub gain: DMatrix<f64>,
    /// Doubling iterations used.
    pub iterations: usize,
}

fn to_faer(m: &DMatrix<f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

fn to_na(m: &Mat<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

fn max_abs(m: &Mat<f64>) -> f64 {
    let mut a = 0.0f64;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            a = a.max(m[(i, j)].abs());
        }
    }
    a
}

/// Validate (Φ, Q, H, R) of a DARE: Φ, Q n × n, H m × n, R m × m; Q symmetric PSD, R PD.
pub fn check_system(phi: &DMatrix<f64>, q: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<()> {
    check_square("phi", phi, None)?;
    let n = phi.nrows();
    check_covariance("q", q, Some(n), false)?;
    if h.ncols() != n {
        return Err(invalid("h", format!("expected {n} columns (state size), got {}", h.ncols())));
    }
    check_covariance("r", r, Some(h.nrows()), true)?;
    Ok(())
}

/// A-priori DARE by structure-preserving doubling (Chu, Fan, Lin 2005) applied to the
/// dual (control) form X = AᵀX(I + GX)⁻¹A + H₀ with A = Φᵀ, G = HᵀR⁻¹H, H₀ = Q:
///   W = I + G_k H_k,
///   A_{k+1} = A_k W⁻¹ A_k,  G_{k+1} = G_k + A_k W⁻¹ G_k A_kᵀ,  H_{k+1} = H_k + A_kᵀ H_k W⁻¹ A_k,
/// H_k → P⁻ quadratically. The state is first scaled by D = diag(√Q_ii) (1 where Q_ii = 0)
/// so that states of very different magnitude (1e-20 (m/s²)² biases) are conditioned alike.
/// A system whose (Φ, H) is not detectable or whose (Φ, Q^½) has uncontrollable modes
/// on the unit circle has no stabilising solution: the doubling diverges and this
/// returns InvalidInput naming it.
pub fn dare(phi: &DMatrix<f64>, q: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<SteadyState> {
    check_system(phi, q, h, r)?;
    let n = phi.nrows();
    let d: Vec<f64> = (0..n).map(|i| if q[(i, i)] > 0.0 { q[(i, i)].sqrt() } else { 1.0 }).collect();
    // Scaled system: Φ' = D⁻¹ΦD, Q' = D⁻¹QD⁻¹, H' = HD.
    let phis = DMatrix::from_fn(n, n, |i, j| phi[(i, j)] * d[j] / d[i]);
    let qs = DMatrix::from_fn(n, n, |i, j| q[(i, j)] / (d[i] * d[j]));
    let hs = DMatrix::from_fn(h.nrows(), n, |i, j| h[(i, j)] * d[j]);
    let rf = to_faer(r);
    let hf = to_faer(&hs);
    let rinv_h = rf.partial_piv_lu().solve(&hf);
    let mut a = to_faer(&phis).transpose().to_owned();
    let mut g = hf.transpose() * &rinv_h;
    let mut x = to_faer(&qs);
    let eye = Mat::<f64>::identity(n, n);
    let max_iter = 100;
    for k in 1..=max_iter {
        let w = &eye + &g * &x;
        let lu = w.partial_piv_lu();
        let w_a = lu.solve(&a); // W⁻¹A
        let w_g = lu.solve(&g); // W⁻¹G
        let x_new = &x + a.transpose() * (&x * &w_a);
        let g_new = &g + &a * (&w_g * a.transpose());
        let a_new = &a * &w_a;
        let change = max_abs(&(&x_new - &x));
        let size = max_abs(&x_new);
        if !size.is_finite() || !max_abs(&g_new).is_finite() {
            break;
        }
        x = x_new;
        g = g_new;
        a = a_new;
        // Symmetrize X and G against round-off drift.
        x = Mat::from_fn(n, n, |i, j| 0.5 * (x[(i, j)] + x[(j, i)]));
        g = Mat::from_fn(n, n, |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
        if change <= 1e-14 * size {
            let ps = to_na(&x);
            let mut p_prior = DMatrix::from_fn(n, n, |i, j| ps[(i, j)] * d[i] * d[j]);
            symmetrize(&mut p_prior);
            let (p_post, gain) = posterior(&p_prior, h, r)?;
            return Ok(SteadyState { p_prior, p_post, gain, iterations: k });
        }
    }
    Err(invalid(
        "phi, h",
        "no stabilising DARE solution: (phi, h) is not detectable or (phi, q) is not stabilisable \
         (unobservable unstable mode, or an undamped mode driven by q); the doubling iteration diverged",
    ))
}

/// A-posteriori step (spec cai-ekf E25) and gain K = P⁻Hᵀ(HP⁻Hᵀ + R)⁻¹; returns (P⁺, K).
pub fn posterior(p_prior: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let s = h * p_prior * h.transpose() + r;
    let ph = p_prior * h.transpose();
    let chol = s.cholesky().ok_or_else(|| crate::error::NavError::Numerical("innovation covariance H P Hᵀ + R is not positive definite".into()))?;
    // K = P Hᵀ S⁻¹  ⇔  S Kᵀ = H P.
    let gain = chol.solve(&ph.transpose()).transpose();
    let mut p_post = p_prior - &gain * ph.transpose();
    symmetrize(&mut p_post);
    Ok((p_post, gain))
}

/// A sequence of covariance matrices, one per step.
pub type Covariances = Vec<DMatrix<f64>>;

/// The Kalman covariance recursion from P⁻₀: returns the a-priori and a-posteriori
/// covariances of steps 0..steps (spec cai-ekf E24/E25 iterated, no steady-state assumption).
pub fn recursion(
    phi: &DMatrix<f64>,
    q: &DMatrix<f64>,
    h: &DMatrix<f64>,
    r: &DMatrix<f64>,
    p0: &DMatrix<f64>,
    steps: usize,
) -> Result<(Covariances, Covariances)> {
    check_system(phi, q, h, r)?;
    check_covariance("p0", p0, Some(phi.nrows()), false)?;
    let mut prior = Vec::with_capacity(steps);
    let mut post = Vec::with_capacity(steps);
    let mut p = p0.clone();
    for _ in 0..steps {
        let (pp, _) = posterior(&p, h, r)?;
        let mut next = phi * &pp * phi.transpose() + q;
        symmetrize(&mut next);
        prior.push(p);
        post.push(pp);
        p = next;
    }
    Ok((prior, post))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m1(x: f64) -> DMatrix<f64> {
        DMatrix::from_element(1, 1, x)
    }

    /// spec cai-ekf §4: Table 1 A with H = ¼|A|kT0² (T0 = 10 s), Q = 1e-20, R = 1.024e-3.
    #[test]
    fn scalar_and_matrix_agree_on_table1_a() {
        let k = 4.0 * std::f64::consts::PI / 780.241e-9;
        let h = 0.25 * 0.15 * k * 100.0;
        let (q, r) = (1e-20, 1.024e-3);
        let pp = scalar_posterior(q, r, h);
        assert!((pp / 4.821853e-20 - 1.0).abs() < 1e-6, "{pp}");
        let s = dare(&m1(1.0), &m1(q), &m1(h), &m1(r)).unwrap();
        assert!((s.p_post[(0, 0)] / pp - 1.0).abs() < 1e-9);
        assert!((s.p_prior[(0, 0)] / scalar_prior(q, r, h) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn unobservable_unstable_mode_is_rejected() {
        let phi = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 0.5]);
        let h = DMatrix::from_row_slice(1, 2, &[0.0, 1.0]);
        let err = dare(&phi, &DMatrix::identity(2, 2), &h, &m1(1.0)).unwrap_err();
        assert!(err.to_string().contains("not detectable"));
    }
}
