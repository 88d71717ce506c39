//! Steady-state Kalman filter: scalar closed forms of seed 000 (spec cai-ekf E26/E27,
//! paper Eqs. 32–35) and the general discrete algebraic Riccati equation (DARE) solved by
//! the structure-preserving doubling algorithm (SDA) on the padded register-chunk kernels
//! of matrix.rs.
//!
//! Filter form (spec cai-ekf E24, paper Eq. 31), a-priori covariance P⁻:
//!   P⁻ = Φ P⁻ Φᵀ + Q − Φ P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻ Φᵀ,
//! a-posteriori (E25): P⁺ = P⁻ − P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻, gain K∞ = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ = P⁺ Hᵀ R⁻¹.

use super::matrix::{check_covariance, check_square, symmetrize, Padded};
use crate::error::{invalid, Result};
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
    // Scaled system: Φ' = D⁻¹ΦD, Q' = D⁻¹QD⁻¹, H' = HD; G = H'ᵀR⁻¹H' = BᵀB with B = L⁻¹H', R = LLᵀ.
    let hs = DMatrix::from_fn(h.nrows(), n, |i, j| h[(i, j)] * d[j]);
    let chol = r.clone().cholesky().ok_or_else(|| crate::error::NavError::Numerical("r: Cholesky failed".into()))?;
    let b = chol.l().solve_lower_triangular(&hs).expect("L has a positive diagonal");
    let g = b.tr_mul(&b);
    let mut x = DMatrix::zeros(n, n);
    let iterations = doubling(
        n,
        |i, j| phi[(j, i)] * d[i] / d[j],
        |i, j| g[(i.max(j), i.min(j))],
        |i, j| q[(i, j)] / (d[i] * d[j]),
        &mut x,
    )
    .ok_or_else(|| {
        invalid(
            "phi, h",
            "no stabilising DARE solution: (phi, h) is not detectable or (phi, q) is not stabilisable \
             (unobservable unstable mode, or an undamped mode driven by q); the doubling iteration diverged",
        )
    })?;
    let mut p_prior = DMatrix::from_fn(n, n, |i, j| x[(i, j)] * d[i] * d[j]);
    symmetrize(&mut p_prior);
    let (p_post, gain) = posterior(&p_prior, h, r)?;
    Ok(SteadyState { p_prior, p_post, gain, iterations })
}

/// The doubling iteration of [`dare`] from A₀, G₀, H₀ given entry-wise; writes the limit of
/// H_k (exactly symmetric) to `x` and returns the iteration count, or None when it
/// diverges. Runs on padded register-chunk buffers ([`Padded`]), compiled for AVX2 + FMA
/// when the CPU has them.
fn doubling(n: usize, a0: impl Fn(usize, usize) -> f64, g0: impl Fn(usize, usize) -> f64, x0: impl Fn(usize, usize) -> f64, x: &mut DMatrix<f64>) -> Option<usize> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports AVX2 and FMA (checked just above).
        return unsafe { doubling_avx2_fma(n, a0, g0, x0, x) };
    }
    doubling_sizes(n, a0, g0, x0, x)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn doubling_avx2_fma(n: usize, a0: impl Fn(usize, usize) -> f64, g0: impl Fn(usize, usize) -> f64, x0: impl Fn(usize, usize) -> f64, x: &mut DMatrix<f64>) -> Option<usize> {
    doubling_sizes(n, a0, g0, x0, x)
}

/// Chunk size C by n: one chunk of n rounded up to 4 up to n = 16, then 24 and 32; larger n in
/// chunks of 16 rows.
#[inline(always)]
fn doubling_sizes(n: usize, a0: impl Fn(usize, usize) -> f64, g0: impl Fn(usize, usize) -> f64, x0: impl Fn(usize, usize) -> f64, x: &mut DMatrix<f64>) -> Option<usize> {
    match n {
        0..=4 => doubling_padded(Padded::<4>::new(n), a0, g0, x0, x),
        5..=8 => doubling_padded(Padded::<8>::new(n), a0, g0, x0, x),
        9..=12 => doubling_padded(Padded::<12>::new(n), a0, g0, x0, x),
        13..=16 => doubling_padded(Padded::<16>::new(n), a0, g0, x0, x),
        17..=24 => doubling_padded(Padded::<24>::new(n), a0, g0, x0, x),
        25..=32 => doubling_padded(Padded::<32>::new(n), a0, g0, x0, x),
        _ => doubling_padded(Padded::<16>::new(n), a0, g0, x0, x),
    }
}

/// Stop once ‖A_k‖²_F ≤ this: H∞ − H_k = A_kᵀ H∞ (I + G_k H∞)⁻¹ A_k ⪯ A_kᵀ H∞ A_k (the identity
/// behind the SDA convergence proof, Lin & Xu 2006), so the remaining relative error of
/// H_k is at most ‖A_k‖²₂ ≤ ‖A_k‖²_F: this saves the last, confirming iteration.
const DOUBLING_TOL: f64 = 1e-14;

#[inline(always)]
fn doubling_padded<const C: usize>(
    d: Padded<C>,
    a0: impl Fn(usize, usize) -> f64,
    g0: impl Fn(usize, usize) -> f64,
    x0: impl Fn(usize, usize) -> f64,
    x_out: &mut DMatrix<f64>,
) -> Option<usize> {
    let (n, s, len) = (d.n, d.stride, d.buffer_len());
    // One allocation for the whole iteration: A, Aᵀ, G, H, W, [W⁻¹A | W⁻¹G], T, scratch.
    let mut ws = vec![0.0; 8 * len + 2 * s + 4 * n];
    let (a, rest) = ws.split_at_mut(len);
    let (at, rest) = rest.split_at_mut(len);
    let (g, rest) = rest.split_at_mut(len);
    let (x, rest) = rest.split_at_mut(len);
    let (w, rest) = rest.split_at_mut(len);
    let (rhs, rest) = rest.split_at_mut(2 * len);
    let (t, rest) = rest.split_at_mut(len);
    let (u, f) = rest.split_at_mut(2 * s);
    for j in 0..n {
        for i in 0..n {
            (a[j * s + i], g[j * s + i], x[j * s + i]) = (a0(i, j), g0(i, j), x0(i, j));
        }
    }
    d.transpose(at, a);
    for k in 1..=100 {
        // W = I + G H; [W⁻¹A | W⁻¹G] by one elimination.
        d.mul(w, false, g, x);
        for i in 0..n {
            w[i * s + i] += 1.0;
        }
        rhs[..len].copy_from_slice(a);
        rhs[len..].copy_from_slice(g);
        if !d.solve(w, rhs, 2 * n, u, f) {
            return None;
        }
        let (wa, wg) = rhs.split_at(len);
        // ΔH = Aᵀ (H W⁻¹A) into w (free after the solve); H ← H + ΔH with the lower triangle
        // mirrored, so H stays exactly symmetric.
        d.mul(t, false, x, wa);
        d.mul(w, false, at, t);
        let (mut change, mut size) = (0.0f64, 0.0f64);
        for j in 0..n {
            for i in j..n {
                let v = x[j * s + i] + w[j * s + i];
                (x[j * s + i], x[i * s + j]) = (v, v);
                change = change.max(w[j * s + i].abs());
                size = size.max(v.abs());
            }
        }
        // G ← G + A (W⁻¹G) Aᵀ, lower triangle mirrored.
        d.mul(t, false, wg, at);
        d.mul(g, true, a, t);
        let mut g_size = 0.0f64;
        for j in 0..n {
            for i in j..n {
                g[i * s + j] = g[j * s + i];
                g_size = g_size.max(g[j * s + i].abs());
            }
        }
        if !size.is_finite() || !g_size.is_finite() {
            return None;
        }
        // A ← A (W⁻¹A).
        d.mul(t, false, a, wa);
        a.copy_from_slice(t);
        let a_norm2 = d.transpose(at, a);
        // The bound on ‖A_k‖, or (for undamped modes that neither noise nor the gain
        // touches, whose A_k does not decay) a converged H.
        if a_norm2 <= DOUBLING_TOL || change <= 1e-14 * size {
            *x_out = DMatrix::from_fn(n, n, |i, j| x[j * s + i]);
            return Some(k);
        }
    }
    None
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

    /// The doubling result satisfies the filter DARE (spec cai-ekf E24) to round-off, with
    /// one register chunk (n = 21) and several (n = 40), for an unstable Φ (scipy agrees to 1e-14
    /// on these systems).
    #[test]
    fn dare_residual_vanishes_one_and_several_chunks() {
        for (n, m) in [(21, 6), (40, 7)] {
            // Diagonal 0.4..1.05 (a few unstable modes, observed through h) plus a weak coupling.
            let phi = DMatrix::from_fn(n, n, |i, j| {
                if i == j { 0.4 + 0.65 * i as f64 / (n - 1) as f64 } else { 0.3 * (((i * 7 + j * 3) % 11) as f64 - 5.0) / (5.0 * n as f64) }
            });
            let g = DMatrix::from_fn(n, n, |i, j| (((i * 5 + j * 13) % 17) as f64 - 8.0) / 8.0);
            let q = &g * g.transpose() / n as f64 + DMatrix::identity(n, n) * 1e-3;
            let h = DMatrix::from_fn(m, n, |i, j| (((i * 3 + j * 11) % 7) as f64 - 3.0) / 3.0 + if i == j % m { 1.0 } else { 0.0 });
            let r = DMatrix::identity(m, m) * 0.5;
            let p = dare(&phi, &q, &h, &r).unwrap().p_prior;
            let s = &h * &p * h.transpose() + &r;
            let k = &phi * &p * h.transpose() * s.try_inverse().unwrap();
            let rhs = &phi * &p * phi.transpose() + &q - &k * &h * &p * phi.transpose();
            assert!((&rhs - &p).abs().max() < 1e-12 * p.abs().max(), "n = {n}: {}", (&rhs - &p).abs().max() / p.abs().max());
        }
    }

    #[test]
    fn unobservable_unstable_mode_is_rejected() {
        let phi = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 0.5]);
        let h = DMatrix::from_row_slice(1, 2, &[0.0, 1.0]);
        let err = dare(&phi, &DMatrix::identity(2, 2), &h, &m1(1.0)).unwrap_err();
        assert!(err.to_string().contains("not detectable"));
    }
}
