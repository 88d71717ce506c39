//! Dense-matrix checks shared by the filter modules (nalgebra `DMatrix`, row-major I/O).

use crate::error::{invalid, Result};
use nalgebra::DMatrix;

/// Build an `r × c` matrix from row-major data, naming `field` on a size mismatch or
/// a non-finite entry.
pub fn from_rows(field: &str, data: &[f64], r: usize, c: usize) -> Result<DMatrix<f64>> {
    if data.len() != r * c {
        return Err(invalid(field, format!("expected {r}x{c} = {} values, got {}", r * c, data.len())));
    }
    crate::error::check_finite(field, data, c.max(1))?;
    Ok(DMatrix::from_row_slice(r, c, data))
}

/// Require a square matrix of size `n` (or any size when `n` is None).
pub fn check_square(field: &str, m: &DMatrix<f64>, n: Option<usize>) -> Result<()> {
    if m.nrows() != m.ncols() {
        return Err(invalid(field, format!("must be square, got {}x{}", m.nrows(), m.ncols())));
    }
    if let Some(n) = n {
        if m.nrows() != n {
            return Err(invalid(field, format!("expected {n}x{n}, got {}x{}", m.nrows(), m.ncols())));
        }
    }
    // x·0 is NaN exactly for NaN and ±inf: one vectorisable pass for the common case.
    if m.as_slice().iter().fold(0.0, |acc, x| acc + x * 0.0) != 0.0 {
        let i = m.iter().position(|x| !x.is_finite()).expect("a non-finite entry");
        // nalgebra storage is column-major: index i is (i % rows, i / rows).
        return Err(invalid(field, format!("non-finite entry at ({}, {})", i % m.nrows(), i / m.nrows())));
    }
    Ok(())
}

/// A covariance: square, finite, symmetric to 1e-9 relative, and positive definite
/// (`definite = true`) or positive semi-definite (`false`, e.g. a process noise).
pub fn check_covariance(field: &str, m: &DMatrix<f64>, n: Option<usize>, definite: bool) -> Result<()> {
    check_square(field, m, n)?;
    let scale = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for i in 0..m.nrows() {
        for j in 0..i {
            if (m[(i, j)] - m[(j, i)]).abs() > 1e-9 * scale {
                return Err(invalid(field, format!("not symmetric: entry ({i}, {j}) = {} but ({j}, {i}) = {}", m[(i, j)], m[(j, i)])));
            }
        }
    }
    let n = m.nrows();
    // PSD test: Cholesky of a slightly regularized matrix, scaled by the diagonal so
    // that states of very different magnitude (1e-20 and 1e3) are judged alike.
    let d: Vec<f64> = (0..n).map(|i| m[(i, i)]).collect();
    if let Some(i) = d.iter().position(|&x| x < 0.0 || (definite && x <= 0.0)) {
        return Err(invalid(field, format!("not positive {}definite: diagonal entry {i} is {}", if definite { "" } else { "semi-" }, d[i])));
    }
    let s: Vec<f64> = d.iter().map(|&x| if x > 0.0 { 1.0 / x.sqrt() } else { 1.0 }).collect();
    let mut c = DMatrix::from_fn(n, n, |i, j| m[(i, j)] * s[i] * s[j]);
    let eps = if definite { 0.0 } else { 1e-10 };
    for i in 0..n {
        c[(i, i)] += eps;
    }
    if c.cholesky().is_none() {
        return Err(invalid(field, format!("not positive {}definite (Cholesky failed)", if definite { "" } else { "semi-" })));
    }
    Ok(())
}

/// Symmetrize in place: P ← (P + Pᵀ)/2.
pub fn symmetrize(p: &mut DMatrix<f64>) {
    let n = p.nrows();
    let s = p.as_mut_slice();
    for j in 0..n {
        for i in j + 1..n {
            let a = 0.5 * (s[j * n + i] + s[i * n + j]);
            s[j * n + i] = a;
            s[i * n + j] = a;
        }
    }
}

/// P ← Φ P Φᵀ + Q for a symmetric P in a column-major n × n buffer (the result is exactly
/// symmetric), and x ← Φx when `x` is given; `t` is scratch. T = PΦᵀ, then
/// the lower triangle of Q + ΦT, mirrored; every column is built as a sum of scaled
/// columns. The common error-state sizes get a fixed-size kernel whose accumulator lives
/// in vector registers, compiled for AVX2 + FMA when the CPU has them: several times
/// faster than a general matmul dispatch at these sizes.
pub fn propagate_covariance(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut Vec<f64>) {
    assert!(p.len() == n * n && phi.len() == n * n && q.len() == n * n, "propagate_covariance: buffers must be n x n");
    assert!(x.as_ref().is_none_or(|x| x.len() == n), "propagate_covariance: x must have n entries");
    t.resize(3 * (n + 3) * n, 0.0);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports AVX2 and FMA (checked just above).
        return unsafe { propagate_avx2_fma(p, x, phi, q, n, t) };
    }
    propagate_sizes(p, x, phi, q, n, t)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn propagate_avx2_fma(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut [f64]) {
    propagate_sizes(p, x, phi, q, n, t)
}

#[inline(always)]
fn propagate_sizes(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut [f64]) {
    match n {
        9 => propagate_fixed::<9, 12>(p, x, phi, q, t),
        15 => propagate_fixed::<15, 16>(p, x, phi, q, t),
        16 => propagate_fixed::<16, 16>(p, x, phi, q, t),
        17 => propagate_fixed::<17, 20>(p, x, phi, q, t),
        18 => propagate_fixed::<18, 20>(p, x, phi, q, t),
        21 => propagate_fixed::<21, 24>(p, x, phi, q, t),
        _ => propagate_any(p, x, phi, q, n, t),
    }
}

/// Σ_k a_k · column k of the column-major buffer `m` (n rows), added to `acc`, over
/// rows `rows` only.
#[inline(always)]
fn add_columns(acc: &mut [f64], m: &[f64], n: usize, a: impl Fn(usize) -> f64, rows: std::ops::Range<usize>) {
    for k in 0..n {
        let ak = a(k);
        for (y, f) in acc[rows.clone()].iter_mut().zip(&m[k * n + rows.start..k * n + rows.end]) {
            *y = f.mul_add(ak, *y);
        }
    }
}

/// Column `k` of a column-major buffer with columns of S values.
#[inline(always)]
fn col<const S: usize>(m: &[f64], k: usize) -> &[f64; S] {
    m[k * S..(k + 1) * S].try_into().expect("column of S values")
}

/// acc + Σ_k a(k) · column k (k < N) of the column-major buffer `m` (columns of S values).
#[inline(always)]
fn sum_columns<const N: usize, const S: usize>(mut acc: [f64; S], m: &[f64], a: impl Fn(usize) -> f64) -> [f64; S] {
    for k in 0..N {
        let (ak, mk) = (a(k), col::<S>(m, k));
        for i in 0..S {
            acc[i] = mk[i].mul_add(ak, acc[i]);
        }
    }
    acc
}

/// Copy the N × N column-major `m` into columns of S ≥ N values (zero padding), so that
/// every column operation is whole vector registers.
#[inline(always)]
fn pad<const N: usize, const S: usize>(m: &[f64], out: &mut [f64]) {
    for k in 0..N {
        let mut c = [0.0; S];
        c[..N].copy_from_slice(&m[k * N..(k + 1) * N]);
        out[k * S..(k + 1) * S].copy_from_slice(&c);
    }
}

/// Fixed size N, columns padded to S = N rounded up to a multiple of 4; `t` holds 3·S·N.
#[inline(always)]
fn propagate_fixed<const N: usize, const S: usize>(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], t: &mut [f64]) {
    let (phi_p, rest) = t.split_at_mut(S * N);
    let (p_p, tt) = rest.split_at_mut(S * N);
    pad::<N, S>(phi, phi_p);
    pad::<N, S>(p, p_p);
    if let Some(x) = x {
        let y = sum_columns::<N, S>([0.0; S], phi_p, |k| x[k]);
        x.copy_from_slice(&y[..N]);
    }
    // T[:, j] = Σ_k P[:, k] Φ[j, k]
    for j in 0..N {
        tt[j * S..(j + 1) * S].copy_from_slice(&sum_columns::<N, S>([0.0; S], p_p, |k| phi[k * N + j]));
    }
    // P[:, j] = Q[:, j] + Σ_k Φ[:, k] T[k, j]; the upper triangle is then taken from the lower
    for j in 0..N {
        let mut acc = [0.0; S];
        acc[..N].copy_from_slice(&q[j * N..(j + 1) * N]);
        let acc = sum_columns::<N, S>(acc, phi_p, |k| tt[j * S + k]);
        p[j * N..(j + 1) * N].copy_from_slice(&acc[..N]);
    }
    mirror_lower(p, N);
}

/// The same for any n.
#[inline(always)]
fn propagate_any(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut [f64]) {
    if let Some(x) = x {
        let mut acc = vec![0.0; n];
        add_columns(&mut acc, phi, n, |k| x[k], 0..n);
        x.copy_from_slice(&acc);
    }
    t.fill(0.0);
    for j in 0..n {
        add_columns(&mut t[j * n..(j + 1) * n], p, n, |k| phi[k * n + j], 0..n);
    }
    p.copy_from_slice(q);
    for j in 0..n {
        add_columns(&mut p[j * n..(j + 1) * n], phi, n, |k| t[j * n + k], j..n);
    }
    mirror_lower(p, n);
}

/// Upper triangle ← lower triangle of a column-major n × n buffer.
#[inline(always)]
fn mirror_lower(p: &mut [f64], n: usize) {
    for j in 0..n {
        for i in j + 1..n {
            p[i * n + j] = p[j * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// Every size path (fixed and general) equals nalgebra's ΦPΦᵀ + Q.
    #[test]
    fn propagate_matches_dense_product() {
        for n in [1, 9, 14, 15, 21, 30] {
            let phi = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.4);
            let g = DMatrix::from_fn(n, n, |i, j| ((i * 5 + j * 13) % 17) as f64 / 17.0);
            let (p0, q) = (&g * g.transpose(), DMatrix::from_fn(n, n, |i, j| if i == j { 0.5 } else { 0.0 }));
            let want = &phi * &p0 * phi.transpose() + &q;
            let mut p = p0.clone();
            let x0 = DVector::from_fn(n, |i, _| i as f64 - 3.0);
            let mut x = x0.clone();
            propagate_covariance(p.as_mut_slice(), Some(x.as_mut_slice()), phi.as_slice(), q.as_slice(), n, &mut Vec::new());
            assert!((p - &want).abs().max() < 1e-12 * want.abs().max(), "n = {n}");
            assert!((x - &phi * &x0).abs().max() < 1e-12 * x0.abs().max(), "n = {n}");
        }
    }
}
