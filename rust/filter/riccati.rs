//! Steady-state Kalman filter: scalar closed forms of Tennstedt, Weddig & Schön (2021,
//! Eqs. 32–35) and the general discrete algebraic Riccati equation (DARE) solved by the
//! structure-preserving doubling algorithm (SDA): on the padded register-chunk kernels of
//! matrix.rs for small states, on faer (dense.rs) above the measured crossover.
//!
//! Filter form (Tennstedt et al. 2021, Eq. 31), a-priori covariance P⁻:
//!   P⁻ = Φ P⁻ Φᵀ + Q − Φ P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻ Φᵀ,
//! a-posteriori: P⁺ = P⁻ − P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ H P⁻, gain K∞ = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹ = P⁺ Hᵀ R⁻¹.

use super::dense::{self, Algebra};
use super::matrix::{check_covariance, check_square, symmetrize, Padded};
use crate::error::{check_count, invalid, try_vec, NavError, Result};
use nalgebra::DMatrix;

/// Scalar steady state for Φ = 1 (Tennstedt et al. 2021, Eqs. 32–35): (P⁻, P⁺) with
/// P⁻ = Q/2 + √(Q²/4 + QR/H²) and P⁺ = −Q/2 + √(Q²/4 + QR/H²) (the value their Table 1
/// lists). Evaluated as P⁻ = Q/2 + hypot(Q/2, s), P⁺ = s·(s/P⁻) with s = √Q √R / |H|, so that
/// neither QR nor QR/H² over- or underflows, and P⁺ without the cancellation of its
/// closed form (the product of the two roots of P² + QP − QR/H² = 0 is −QR/H²).
/// Q ≥ 0, R > 0, H ≠ 0, all finite; an H so small that the steady state exceeds the f64
/// range is rejected naming `h`.
pub fn scalar(q: f64, r: f64, h: f64) -> Result<(f64, f64)> {
    for (name, x) in [("q", q), ("r", r), ("h", h)] {
        if !x.is_finite() {
            return Err(invalid(name, format!("must be finite, got {x}")));
        }
    }
    if q < 0.0 {
        return Err(invalid("q", format!("must be >= 0, got {q}")));
    }
    if r <= 0.0 {
        return Err(invalid("r", format!("must be > 0, got {r}")));
    }
    if h == 0.0 {
        return Err(invalid("h", "must be non-zero (an unobserved random walk has no steady state)"));
    }
    let s = q.sqrt() * r.sqrt() / h.abs();
    let prior = 0.5 * q + (0.5 * q).hypot(s);
    if !prior.is_finite() {
        return Err(invalid("h", format!("too small ({h:e}): the steady-state variance sqrt(q r)/|h| exceeds the floating-point range")));
    }
    let post = if prior > 0.0 { s * (s / prior) } else { 0.0 };
    Ok((prior, post))
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

/// Validate (Φ, Q, H, R) of a DARE: Φ, Q n × n (n ≥ 1), H m × n, R m × m; Q symmetric PSD, R PD.
pub fn check_system(phi: &DMatrix<f64>, q: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<()> {
    check_square("phi", phi, None)?;
    let n = phi.nrows();
    if n == 0 {
        return Err(invalid("phi", "must have at least one state, got 0x0"));
    }
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
///
/// The doubling runs on the register kernels up to [`DARE_FAER_MIN`] states and on faer
/// from there on ([`dare_using`] chooses explicitly).
pub fn dare(phi: &DMatrix<f64>, q: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<SteadyState> {
    dare_using(phi, q, h, r, Algebra::by_size(phi.nrows(), DARE_FAER_MIN))
}

/// Where the DARE doubling moves from the padded register kernels to faer. `cargo bench
/// --bench filter -- crossover/dare` (thread CPU time, kernels/faer µs): n = 9: 21.6/68.1,
/// 15: 60.3/133, 21: 137/310, 30: 294/614, 45: 1280/1470, 52: 1796/1599, 60: 2963/2749,
/// 150: 46,600/28,000. The kernels win up to 45 and faer from 52 on.
pub const DARE_FAER_MIN: usize = 48;

/// [`dare`] with the algebra of the doubling chosen by the caller (benches and tests).
// invariant: check_system makes phi, q n × n (n ≥ 1) and h m × n, so i, j < n index
// phi, q, g (n × n), hs (m × n), d and x (n entries / n × n) in range.
#[allow(clippy::indexing_slicing)]
pub fn dare_using(phi: &DMatrix<f64>, q: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>, algebra: Algebra) -> Result<SteadyState> {
    check_system(phi, q, h, r)?;
    let n = phi.nrows();
    let d: Vec<f64> = (0..n).map(|i| if q[(i, i)] > 0.0 { q[(i, i)].sqrt() } else { 1.0 }).collect();
    // Scaled system: Φ' = D⁻¹ΦD, Q' = D⁻¹QD⁻¹, H' = HD; G = H'ᵀR⁻¹H' = BᵀB with B = L⁻¹H', R = LLᵀ.
    let hs = DMatrix::from_fn(h.nrows(), n, |i, j| h[(i, j)] * d[j]);
    let not_pd = || invalid("r", "not positive definite (Cholesky of r failed)");
    let chol = r.clone().cholesky().ok_or_else(not_pd)?;
    let b = chol.l().solve_lower_triangular(&hs).ok_or_else(not_pd)?;
    let g = b.tr_mul(&b);
    let mut x = DMatrix::zeros(n, n);
    let a0 = |i: usize, j: usize| phi[(j, i)] * d[i] / d[j];
    let g0 = |i: usize, j: usize| g[(i.max(j), i.min(j))];
    let x0 = |i: usize, j: usize| q[(i, j)] / (d[i] * d[j]);
    let iterations = match algebra {
        Algebra::Kernels => doubling(n, a0, g0, x0, &mut x),
        Algebra::Faer => doubling_faer(DMatrix::from_fn(n, n, a0), DMatrix::from_fn(n, n, g0), DMatrix::from_fn(n, n, x0), &mut x),
    }
    .ok_or_else(|| {
        invalid(
            "phi",
            "no stabilising DARE solution: (phi, h) is not detectable or (phi, q) is not stabilisable \
             (unobservable unstable mode, or an undamped mode driven by q); the doubling iteration diverged",
        )
    })?;
    let mut p_prior = DMatrix::from_fn(n, n, |i, j| x[(i, j)] * d[i] * d[j]);
    symmetrize(&mut p_prior);
    let (p_post, gain) = posterior(&p_prior, h, r)?;
    if !p_prior.iter().chain(p_post.iter()).chain(gain.iter()).all(|v| v.is_finite()) {
        return Err(NavError::Numerical("the DARE solution overflows the floating-point range".into()));
    }
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
// invariant: ws holds 8·len + 2s + 4n values split into buffers of len = s·n
// (2·len for rhs), and i, j < n ≤ s, so j·s + i < len.
#[allow(clippy::indexing_slicing)]
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

/// The doubling iteration of [`dare`] on faer (dense.rs), from A₀, G₀, H₀: the same
/// iteration and stopping rule as [`doubling_padded`], with blocked products and an LU
/// solve. Writes the limit of H_k to `x_out`; None when the iteration diverges or W is
/// singular.
// invariant: a, g, x are n × n (built by dare_using), w, t, dx likewise; i, j < n.
#[allow(clippy::indexing_slicing)]
fn doubling_faer(mut a: DMatrix<f64>, mut g: DMatrix<f64>, mut x: DMatrix<f64>, x_out: &mut DMatrix<f64>) -> Option<usize> {
    let n = a.nrows();
    let (mut w, mut t, mut dx) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    let mut rhs = DMatrix::zeros(n, 2 * n);
    for k in 1..=100 {
        // W = I + G H; [W⁻¹A | W⁻¹G] by one LU solve.
        dense::mul(dense::view_mut(&mut w), false, dense::view(&g), dense::view(&x));
        for i in 0..n {
            w[(i, i)] += 1.0;
        }
        rhs.columns_mut(0, n).copy_from(&a);
        rhs.columns_mut(n, n).copy_from(&g);
        if !dense::lu_solve(&w, &mut rhs) {
            return None;
        }
        let (wa, wg) = (dense::view(&rhs).subcols(0, n), dense::view(&rhs).subcols(n, n));
        // ΔH = Aᵀ (H W⁻¹A), lower triangle; H ← H + ΔH mirrored, exactly symmetric.
        dense::mul(dense::view_mut(&mut t), false, dense::view(&x), wa);
        dense::mul_lower(dense::view_mut(&mut dx), false, dense::view(&a).transpose(), dense::view(&t));
        let (mut change, mut size) = (0.0f64, 0.0f64);
        for j in 0..n {
            for i in j..n {
                let v = x[(i, j)] + dx[(i, j)];
                (x[(i, j)], x[(j, i)]) = (v, v);
                change = change.max(dx[(i, j)].abs());
                size = size.max(v.abs());
            }
        }
        // G ← G + A (W⁻¹G) Aᵀ, mirrored.
        dense::mul(dense::view_mut(&mut t), false, wg, dense::view(&a).transpose());
        dense::mul(dense::view_mut(&mut g), true, dense::view(&a), dense::view(&t));
        dense::mirror_lower(&mut g);
        let g_size = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !size.is_finite() || !g_size.is_finite() {
            return None;
        }
        // A ← A (W⁻¹A).
        dense::mul(dense::view_mut(&mut t), false, dense::view(&a), wa);
        std::mem::swap(&mut a, &mut t);
        if a.norm_squared() <= DOUBLING_TOL || change <= 1e-14 * size {
            *x_out = x;
            return Some(k);
        }
    }
    None
}

/// A-posteriori step (Tennstedt et al. 2021, Eq. 31) and gain K = P⁻Hᵀ(HP⁻Hᵀ + R)⁻¹;
/// returns (P⁺, K).
pub fn posterior(p_prior: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let s = h * p_prior * h.transpose() + r;
    let ph = p_prior * h.transpose();
    let chol = s.cholesky().ok_or_else(|| NavError::Numerical("innovation covariance H P Hᵀ + R is not positive definite".into()))?;
    // K = P Hᵀ S⁻¹  ⇔  S Kᵀ = H P.
    let gain = chol.solve(&ph.transpose()).transpose();
    let mut p_post = p_prior - &gain * ph.transpose();
    symmetrize(&mut p_post);
    Ok((p_post, gain))
}

/// Most steps of [`recursion`]: the recursion converges geometrically, so even the
/// slowest case of Tennstedt et al. (2021, Table 1 C, contraction 0.987 per step) is
/// at its steady state to round-off after a few thousand steps.
pub const MAX_RECURSION_STEPS: usize = 100_000_000;

/// The covariances of a Kalman recursion: `steps` stacked n × n matrices, row-major
/// (steps, n, n).
#[derive(Debug, Clone)]
pub struct Recursion {
    pub n: usize,
    pub prior: Vec<f64>,
    pub post: Vec<f64>,
}

/// The Kalman covariance recursion from P⁻₀: the a-priori and a-posteriori covariances of
/// steps 0..steps (Tennstedt et al. 2021, Eq. 31 iterated, no steady-state assumption).
/// `steps` in [1, [`MAX_RECURSION_STEPS`]]; the output is allocated before the first
/// step, as a `MemoryError` when the machine cannot hold it.
pub fn recursion(phi: &DMatrix<f64>, q: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>, p0: &DMatrix<f64>, steps: usize) -> Result<Recursion> {
    check_count("steps", steps, 1, MAX_RECURSION_STEPS)?;
    check_system(phi, q, h, r)?;
    let n = phi.nrows();
    check_covariance("p0", p0, Some(n), false)?;
    let len = steps.checked_mul(n * n).ok_or(NavError::OutOfMemory { field: "steps".into(), bytes: steps as u128 * (n * n * 8) as u128 })?;
    let (mut prior, mut post) = (try_vec("steps", len, 0.0)?, try_vec("steps", len, 0.0)?);
    let mut p = p0.clone();
    // n ≥ 1 (check_system), so every chunk is one n × n matrix.
    for (pr, po) in prior.chunks_exact_mut(n * n).zip(post.chunks_exact_mut(n * n)) {
        let (pp, _) = posterior(&p, h, r)?;
        let mut next = phi * &pp * phi.transpose() + q;
        symmetrize(&mut next);
        // row-major copies (P⁻₀ is symmetric only to the tolerance of check_covariance)
        pr.copy_from_slice(p.transpose().as_slice());
        po.copy_from_slice(pp.as_slice());
        p = next;
    }
    if let Some(i) = prior.iter().chain(&post).position(|v| !v.is_finite()) {
        return Err(NavError::Numerical(format!("the covariance of step {} overflows the floating-point range", (i % len) / (n * n))));
    }
    Ok(Recursion { n, prior, post })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m1(x: f64) -> DMatrix<f64> {
        DMatrix::from_element(1, 1, x)
    }

    /// Tennstedt et al. (2021) Table 1 A with H = ¼|A|kT0² (T0 = 10 s), Q = 1e-20, R = 1.024e-3.
    #[test]
    fn scalar_and_matrix_agree_on_table1_a() {
        let k = 4.0 * std::f64::consts::PI / 780.241e-9;
        let h = 0.25 * 0.15 * k * 100.0;
        let (q, r) = (1e-20, 1.024e-3);
        let (prior, pp) = scalar(q, r, h).unwrap();
        assert!((pp / 4.821853e-20 - 1.0).abs() < 1e-6, "{pp}");
        let s = dare(&m1(1.0), &m1(q), &m1(h), &m1(r)).unwrap();
        assert!((s.p_post[(0, 0)] / pp - 1.0).abs() < 1e-9);
        assert!((s.p_prior[(0, 0)] / prior - 1.0).abs() < 1e-9);
    }

    /// A test system: diagonal Φ 0.4..1.05 (a few unstable modes, observed through h) plus
    /// a weak coupling, PD Q, R = 0.5 I.
    fn system(n: usize, m: usize) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
        let phi = DMatrix::from_fn(n, n, |i, j| {
            if i == j { 0.4 + 0.65 * i as f64 / (n - 1) as f64 } else { 0.3 * (((i * 7 + j * 3) % 11) as f64 - 5.0) / (5.0 * n as f64) }
        });
        let g = DMatrix::from_fn(n, n, |i, j| (((i * 5 + j * 13) % 17) as f64 - 8.0) / 8.0);
        let q = &g * g.transpose() / n as f64 + DMatrix::identity(n, n) * 1e-3;
        let h = DMatrix::from_fn(m, n, |i, j| (((i * 3 + j * 11) % 7) as f64 - 3.0) / 3.0 + if i == j % m { 1.0 } else { 0.0 });
        (phi, q, h, DMatrix::identity(m, m) * 0.5)
    }

    /// Relative residual of the filter DARE (Tennstedt et al. 2021, Eq. 31) at P⁻.
    fn residual(phi: &DMatrix<f64>, q: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>, p: &DMatrix<f64>) -> f64 {
        let s = h * p * h.transpose() + r;
        let k = phi * p * h.transpose() * s.try_inverse().unwrap();
        let rhs = phi * p * phi.transpose() + q - &k * h * p * phi.transpose();
        (&rhs - p).abs().max() / p.abs().max()
    }

    /// Both algebras' doubling results satisfy the filter DARE to round-off, with one
    /// register chunk (n = 21), several (n = 40) and beyond (n = 60), for an unstable Φ
    /// (scipy agrees to 1e-14 on these systems). Each solution satisfies the equation to
    /// 1e-12 relative residual; the two differ by that residual times the conditioning of
    /// the DARE (6e-12 relative at n = 60), bounded here by 1e-10.
    #[test]
    fn dare_residual_vanishes_on_both_algebras() {
        for (n, m) in [(21, 6), (40, 7), (60, 8)] {
            let (phi, q, h, r) = system(n, m);
            let kern = dare_using(&phi, &q, &h, &r, Algebra::Kernels).unwrap();
            let faer = dare_using(&phi, &q, &h, &r, Algebra::Faer).unwrap();
            for (name, s) in [("kernels", &kern), ("faer", &faer)] {
                let res = residual(&phi, &q, &h, &r, &s.p_prior);
                assert!(res < 1e-12, "{name}, n = {n}: residual {res}");
                assert_eq!(s.p_prior, s.p_prior.transpose(), "{name}, n = {n}: not exactly symmetric");
            }
            let diff = (&kern.p_prior - &faer.p_prior).abs().max() / kern.p_prior.abs().max();
            assert!(diff < 1e-10, "n = {n}: kernels and faer differ by {diff}");
            // the dispatch: faer from DARE_FAER_MIN states on
            let auto = dare(&phi, &q, &h, &r).unwrap();
            assert_eq!(auto.p_prior, if n >= DARE_FAER_MIN { &faer.p_prior } else { &kern.p_prior }.clone(), "n = {n}");
        }
    }

    /// The faer doubling reports a system without a stabilising solution like the kernels.
    #[test]
    fn faer_doubling_rejects_unobservable_unstable_mode() {
        let phi = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 0.5]);
        let h = DMatrix::from_row_slice(1, 2, &[0.0, 1.0]);
        let err = dare_using(&phi, &DMatrix::identity(2, 2), &h, &m1(1.0), Algebra::Faer).unwrap_err();
        assert!(err.to_string().contains("not detectable"), "{err}");
    }

    /// The scalar closed form stays finite where QR/H² over- or underflows, is exact at
    /// Q = 0, and rejects an H whose steady state is beyond the f64 range.
    #[test]
    fn scalar_is_stable_and_rejects_overflow() {
        // QR/H² = 1e-300·1e-20/1e-160 underflows to 0 in the naive form: P⁻ = √(QR)/H (Q ≪ that)
        let (p, pp) = scalar(1e-300, 1e-20, 1e-80).unwrap();
        assert!((p / 1e-80 - 1.0).abs() < 1e-12 && (pp / 1e-80 - 1.0).abs() < 1e-12, "{p} {pp}");
        assert_eq!(scalar(0.0, 1.0, 1.0).unwrap(), (0.0, 0.0));
        // a tiny h: QR/H² overflows but √(QR)/|H| = 1e200 does not
        let (p, pp) = scalar(1.0, 1.0, 1e-200).unwrap();
        assert!((p / 1e200 - 1.0).abs() < 1e-12 && (pp / 1e200 - 1.0).abs() < 1e-12, "{p} {pp}");
        let e = scalar(1.0, 1.0, 1e-310).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "h"), "{e}");
    }

    /// The recursion checks its step count before allocating and needs a state.
    #[test]
    fn recursion_checks_steps_and_size() {
        let one = m1(1.0);
        for steps in [0, MAX_RECURSION_STEPS + 1, 1 << 40] {
            let e = recursion(&one, &one, &one, &one, &one, steps).unwrap_err();
            assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "steps"), "{e}");
        }
        let empty = DMatrix::zeros(0, 0);
        let e = recursion(&empty, &empty, &DMatrix::zeros(1, 0), &one, &empty, 3).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "phi"), "{e}");
        // Φ = 1, Q = 1, H = 1, R = 1 from P⁻₀ = 1: P⁺ = 1/2, P⁻₁ = 3/2, P⁺₁ = 3/5.
        let rec = recursion(&one, &one, &one, &one, &one, 2).unwrap();
        let want = [1.0, 1.5, 0.5, 0.6];
        assert_eq!(rec.n, 1);
        assert!(rec.prior.iter().chain(&rec.post).zip(want).all(|(a, b)| (a - b).abs() < 1e-15), "{rec:?}");
    }

    #[test]
    fn unobservable_unstable_mode_is_rejected() {
        let phi = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 0.5]);
        let h = DMatrix::from_row_slice(1, 2, &[0.0, 1.0]);
        let err = dare(&phi, &DMatrix::identity(2, 2), &h, &m1(1.0)).unwrap_err();
        assert!(err.to_string().contains("not detectable"));
    }
}
