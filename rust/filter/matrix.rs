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
        let i = m.iter().position(|x| !x.is_finite()).unwrap_or_default();
        // nalgebra storage is column-major: index i is (i % rows, i / rows).
        return Err(invalid(field, format!("non-finite entry at ({}, {})", i % m.nrows(), i / m.nrows())));
    }
    Ok(())
}

/// A covariance: square, finite, symmetric to 1e-9 relative, and positive definite
/// (`definite = true`) or positive semi-definite (`false`, e.g. a process noise).
// invariant: i, j < n = nrows = ncols (check_square above) and d, s have n entries.
#[allow(clippy::indexing_slicing)]
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
// invariant: n = min(rows, cols), so j·n + i < n² ≤ len (P is square in every caller).
#[allow(clippy::indexing_slicing)]
pub fn symmetrize(p: &mut DMatrix<f64>) {
    let n = p.nrows().min(p.ncols());
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
/// symmetric), and x ← Φx when `x` is given; `t` is scratch. U = ΦP, then the lower
/// triangle of Q + UΦᵀ, mirrored; every column is built as a sum of scaled columns. The common error-state sizes get a fixed-size kernel whose accumulators live
/// in vector registers, compiled for AVX-512 or AVX2 + FMA when the CPU has them: several
/// times faster than a general matmul dispatch at these sizes.
pub fn propagate_covariance(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut Vec<f64>) {
    assert!(p.len() == n * n && phi.len() == n * n && q.len() == n * n, "propagate_covariance: buffers must be n x n");
    assert!(x.as_ref().is_none_or(|x| x.len() == n), "propagate_covariance: x must have n entries");
    t.resize(2 * (n + 3) * n, 0.0);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU supports AVX-512F (checked just above).
        return unsafe { propagate_avx512(p, x, phi, q, n, t) };
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports AVX2 and FMA (checked just above).
        return unsafe { propagate_avx2_fma(p, x, phi, q, n, t) };
    }
    propagate_sizes::<1>(p, x, phi, q, n, t)
}

/// 32 registers of 8 values: four output columns at a time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn propagate_avx512(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut [f64]) {
    propagate_sizes::<4>(p, x, phi, q, n, t)
}

/// 16 registers of 4 values: two output columns at a time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn propagate_avx2_fma(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut [f64]) {
    propagate_sizes::<2>(p, x, phi, q, n, t)
}

/// Whether `n` states have a fixed-size register kernel in [`propagate_covariance`] (the
/// sizes of the match in `propagate_sizes`; every other size takes the general loop).
pub fn has_register_kernel(n: usize) -> bool {
    matches!(n, 9 | 15 | 16 | 17 | 18 | 21)
}

/// `J` output columns are built at once (J independent accumulator sets hide the
/// multiply-add latency; J divides 4).
#[inline(always)]
fn propagate_sizes<const J: usize>(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut [f64]) {
    match n {
        9 => propagate_fixed::<9, 12, J>(p, x, phi, q, t),
        15 => propagate_fixed::<15, 16, J>(p, x, phi, q, t),
        16 => propagate_fixed::<16, 16, J>(p, x, phi, q, t),
        17 => propagate_fixed::<17, 20, J>(p, x, phi, q, t),
        18 => propagate_fixed::<18, 20, J>(p, x, phi, q, t),
        21 => propagate_fixed::<21, 24, J>(p, x, phi, q, t),
        _ => propagate_any(p, x, phi, q, n, t),
    }
}

/// Σ_k a_k · column k of the column-major buffer `m` (n rows), added to `acc`, over
/// rows `rows` only.
// invariant: propagate_covariance asserts p, phi, q n × n and x of n entries and sizes t
// to 2(n+3)n ≥ 2·S·N; every index below stays inside those buffers.
#[allow(clippy::indexing_slicing)]
#[inline(always)]
fn add_columns(acc: &mut [f64], m: &[f64], n: usize, a: impl Fn(usize) -> f64, rows: std::ops::Range<usize>) {
    for k in 0..n {
        let ak = a(k);
        for (y, f) in acc[rows.clone()].iter_mut().zip(&m[k * n + rows.start..k * n + rows.end]) {
            *y = f.mul_add(ak, *y);
        }
    }
}

/// The C values from row `row0` of column `k` of a column-major buffer with columns of
/// `stride` values.
// invariant: propagate_covariance asserts p, phi, q n × n and x of n entries and sizes t
// to 2(n+3)n ≥ 2·S·N; every index below stays inside those buffers.
#[allow(clippy::indexing_slicing, clippy::expect_used)]
#[inline(always)]
fn chunk<const C: usize>(m: &[f64], stride: usize, k: usize, row0: usize) -> &[f64; C] {
    m[k * stride + row0..k * stride + row0 + C].try_into().expect("chunk of C values")
}

/// For J outputs j at once: acc_j + Σ_k a(j, k) · rows row0..row0+C of column k (k < n)
/// of the column-major buffer `m` (columns of `stride` values); the accumulators live in
/// vector registers, and each chunk of `m` is loaded once for all J.
// invariant: propagate_covariance asserts p, phi, q n × n and x of n entries and sizes t
// to 2(n+3)n ≥ 2·S·N; every index below stays inside those buffers.
#[allow(clippy::indexing_slicing, clippy::expect_used)]
#[inline(always)]
fn sum_columns<const C: usize, const J: usize>(mut acc: [[f64; C]; J], m: &[f64], stride: usize, row0: usize, n: usize, a: impl Fn(usize, usize) -> f64) -> [[f64; C]; J] {
    for (k, col) in m[..n * stride].chunks_exact(stride).enumerate() {
        let mk: &[f64; C] = col[row0..row0 + C].try_into().expect("chunk of C values");
        for (j, acc) in acc.iter_mut().enumerate() {
            let ak = a(j, k);
            for i in 0..C {
                acc[i] = mk[i].mul_add(ak, acc[i]);
            }
        }
    }
    acc
}

/// Copy the N × N column-major `m` into columns of S ≥ N values (zero padding), so that
/// every column operation is whole vector registers. Each padded column is assembled in
/// registers and stored whole: a column pieced together in memory from narrower stores
/// and read back at once cannot be store-forwarded, and the reload stalls until the
/// stores retire.
// invariant: propagate_covariance asserts p, phi, q n × n and x of n entries and sizes t
// to 2(n+3)n ≥ 2·S·N; every index below stays inside those buffers.
#[allow(clippy::indexing_slicing, clippy::expect_used)]
#[inline(always)]
fn pad<const N: usize, const S: usize>(m: &[f64], out: &mut [f64]) {
    let mut last = [0.0; S];
    last[..N].copy_from_slice(&m[(N - 1) * N..]);
    for k in 0..N {
        // S values from the start of column k (running into column k + 1), padding zeroed
        let mut c: [f64; S] = if k * N + S <= m.len() { m[k * N..k * N + S].try_into().expect("S values") } else { last };
        for v in &mut c[N..] {
            *v = 0.0;
        }
        out[k * S..(k + 1) * S].copy_from_slice(&c);
    }
}

/// Fixed size N, columns padded to S = N rounded up to a multiple of 4, J output columns
/// at a time; `t` holds 2·S·N values. U = ΦP, then P ← Q + UΦᵀ: the vector operands are
/// columns of Φ and U (stored whole, in padded columns), P is read only entry by entry, so
/// no reload has to wait for the narrower stores that wrote the previous P.
// invariant: propagate_covariance asserts p, phi, q n × n and x of n entries and sizes t
// to 2(n+3)n ≥ 2·S·N; every index below stays inside those buffers.
#[allow(clippy::indexing_slicing)]
#[inline(always)]
fn propagate_fixed<const N: usize, const S: usize, const J: usize>(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], t: &mut [f64]) {
    let (phi_p, u) = t.split_at_mut(S * N);
    pad::<N, S>(phi, phi_p);
    if let Some(x) = x {
        let [y] = sum_columns::<S, 1>([[0.0; S]], phi_p, S, 0, N, |_, k| x[k]);
        x.copy_from_slice(&y[..N]);
    }
    // U[:, j] = Σ_k Φ[:, k] P[k, j] (the last group's columns from N on are not used)
    for j0 in (0..N).step_by(J) {
        let cols = sum_columns::<S, J>([[0.0; S]; J], phi_p, S, 0, N, |j, k| if j0 + j < N { p[(j0 + j) * N + k] } else { 0.0 });
        for (j, c) in cols.iter().enumerate().take(N - j0) {
            u[(j0 + j) * S..(j0 + j + 1) * S].copy_from_slice(c);
        }
    }
    // P[:, j] = Q[:, j] + Σ_k U[:, k] Φ[j, k]; the upper triangle is then taken from the lower
    for j0 in (0..N).step_by(J) {
        let acc = std::array::from_fn(|j| {
            let mut c = [0.0; S];
            if j0 + j < N {
                c[..N].copy_from_slice(&q[(j0 + j) * N..(j0 + j + 1) * N]);
            }
            c
        });
        let cols = sum_columns::<S, J>(acc, u, S, 0, N, |j, k| phi_p[k * S + j0 + j]);
        for (j, c) in cols.iter().enumerate().take(N - j0) {
            p[(j0 + j) * N..(j0 + j + 1) * N].copy_from_slice(&c[..N]);
        }
    }
    mirror_lower(p, N);
}

/// The same for any n.
// invariant: propagate_covariance asserts p, phi, q n × n and x of n entries and sizes t
// to 2(n+3)n ≥ 2·S·N; every index below stays inside those buffers.
#[allow(clippy::indexing_slicing)]
#[inline(always)]
fn propagate_any(p: &mut [f64], x: Option<&mut [f64]>, phi: &[f64], q: &[f64], n: usize, t: &mut [f64]) {
    debug_assert!(!has_register_kernel(n), "n = {n} has a register kernel: has_register_kernel and propagate_sizes disagree");
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
// invariant: propagate_covariance asserts p, phi, q n × n and x of n entries and sizes t
// to 2(n+3)n ≥ 2·S·N; every index below stays inside those buffers.
#[allow(clippy::indexing_slicing)]
#[inline(always)]
pub(crate) fn mirror_lower(p: &mut [f64], n: usize) {
    for j in 0..n {
        for i in j + 1..n {
            p[i * n + j] = p[j * n + i];
        }
    }
}

/// Layout of n × n matrices in column-major buffers whose columns hold `stride` values
/// (rows n.. are zero padding, stride a multiple of C), processed in row chunks of C
/// values that live in vector registers: the products and the solve of the DARE doubling
/// (riccati.rs), for any n (one chunk when n ≤ C, several otherwise). Callers compile
/// these `inline(always)` methods inside an AVX2 + FMA region when the CPU has it.
#[derive(Clone, Copy)]
pub(crate) struct Padded<const C: usize> {
    pub n: usize,
    pub stride: usize,
}

// invariant: every buffer passed to these methods is a padded n × n buffer of
// buffer_len() = stride·n values (u: ≥ 2 padded columns, f: ≥ 2·cols values), allocated
// so by doubling_padded in riccati.rs; stride is a multiple of C, so every chunk is whole.
#[allow(clippy::indexing_slicing, clippy::expect_used)]
impl<const C: usize> Padded<C> {
    pub fn new(n: usize) -> Self {
        Self { n, stride: n.div_ceil(C).max(1) * C }
    }

    /// Values in one padded n × n buffer.
    pub fn buffer_len(&self) -> usize {
        self.stride * self.n
    }

    /// out[:, j] = (out[:, j] when `add`) + Σ_k m[:, k] b[k, j] for j < n (all padded rows).
    #[inline(always)]
    pub fn mul(&self, out: &mut [f64], add: bool, m: &[f64], b: &[f64]) {
        let (n, s) = (self.n, self.stride);
        for j in 0..n {
            let bj = &b[j * s..j * s + n];
            for r0 in (0..s).step_by(C) {
                let acc = if add { *chunk::<C>(out, s, j, r0) } else { [0.0; C] };
                // One chunk (n ≤ C): a constant stride lets the compiler drop the bounds checks.
                let [y] = if s == C { sum_columns::<C, 1>([acc], m, C, 0, n, |_, k| bj[k]) } else { sum_columns::<C, 1>([acc], m, s, r0, n, |_, k| bj[k]) };
                out[j * s + r0..j * s + r0 + C].copy_from_slice(&y);
            }
        }
    }

    /// Columns `cols` of the padded buffer `m`: B consecutive Gauss–Jordan steps at pivots
    /// p..p+B with the multiplier columns u_0..u_B (B padded columns of `u`), fused so that
    /// each column is loaded and stored once: f_b = col_j[p+b] − Σ_{a<b} f_a u_a[p+b],
    /// col_j ← col_j − Σ_b f_b u_b, with the chunks of u in registers across the columns;
    /// `f` is scratch for B·|cols| values.
    #[inline(always)]
    fn eliminate<const B: usize>(&self, m: &mut [f64], cols: std::ops::Range<usize>, p: usize, u: &[f64], f: &mut [f64]) {
        let s = self.stride;
        let f = &mut f[..B * cols.len()];
        for (fj, j) in f.chunks_exact_mut(B).zip(cols.clone()) {
            for b in 0..B {
                fj[b] = (0..b).fold(m[j * s + p + b], |acc, a| (-fj[a]).mul_add(u[a * s + p + b], acc));
            }
        }
        for r0 in (0..s).step_by(C) {
            let v: [[f64; C]; B] = std::array::from_fn(|b| *chunk::<C>(u, s, b, r0));
            for (fj, j) in f.chunks_exact(B).zip(cols.clone()) {
                let c: &mut [f64; C] = (&mut m[j * s + r0..j * s + r0 + C]).try_into().expect("chunk of C values");
                let nf: [f64; B] = std::array::from_fn(|b| -fj[b]);
                for i in 0..C {
                    c[i] = (0..B).fold(c[i], |acc, b| nf[b].mul_add(v[b][i], acc));
                }
            }
        }
    }

    /// Partial pivoting at step p: the row of the largest |W[i, p]| (i ≥ p) is swapped into
    /// row p in W's columns p.., in all `cols` columns of b and in the first `k` (not yet
    /// applied) multiplier columns of u; then u_k = W[:, p]/piv with u_k[p] = 1 − 1/piv, so
    /// that col − col[p]·u_k eliminates column p from every other row and divides row p by
    /// the pivot. False when W is singular.
    #[inline(always)]
    fn pivot(&self, w: &mut [f64], b: &mut [f64], cols: usize, p: usize, u: &mut [f64], k: usize) -> bool {
        let (n, s) = (self.n, self.stride);
        let mut r = p;
        for i in p + 1..n {
            if w[p * s + i].abs() > w[p * s + r].abs() {
                r = i;
            }
        }
        let piv = w[p * s + r];
        if piv == 0.0 || !piv.is_finite() {
            return false;
        }
        if r != p {
            for j in p..n {
                w.swap(j * s + p, j * s + r);
            }
            for j in 0..cols {
                b.swap(j * s + p, j * s + r);
            }
            for a in 0..k {
                u.swap(a * s + p, a * s + r);
            }
        }
        let inv = 1.0 / piv;
        for (ui, wi) in u[k * s..(k + 1) * s].iter_mut().zip(&w[p * s..(p + 1) * s]) {
            *ui = wi * inv;
        }
        u[k * s + p] = 1.0 - inv;
        true
    }

    /// Solve W Y = B in place by Gauss–Jordan elimination with partial pivoting: `b` holds
    /// `cols` padded right-hand-side columns and becomes Y; `w` is destroyed, `u` (two padded
    /// columns) and `f` (2·`cols` values) are scratch. Pivots are taken in pairs, each pair one
    /// fused rank-2 update of whole columns (no triangular-solve dependency chain). Returns
    /// false when W is singular.
    #[inline(always)]
    pub fn solve(&self, w: &mut [f64], b: &mut [f64], cols: usize, u: &mut [f64], f: &mut [f64]) -> bool {
        let (n, s) = (self.n, self.stride);
        let mut p = 0;
        while p < n {
            if !self.pivot(w, b, cols, p, u, 0) {
                return false;
            }
            if p + 1 == n {
                self.eliminate::<1>(b, 0..cols, p, u, f);
                break;
            }
            // Step p on W's column p + 1 alone, which the pivot of step p + 1 needs.
            self.eliminate::<1>(w, p + 1..p + 2, p, u, f);
            if !self.pivot(w, b, cols, p + 1, u, 1) {
                return false;
            }
            self.eliminate::<2>(w, p + 2..n, p, &u[..2 * s], f);
            self.eliminate::<2>(b, 0..cols, p, &u[..2 * s], f);
            p += 2;
        }
        true
    }

    /// out = mᵀ; returns the squared Frobenius norm of m.
    #[inline(always)]
    pub fn transpose(&self, out: &mut [f64], m: &[f64]) -> f64 {
        let (n, s) = (self.n, self.stride);
        let mut f2 = 0.0;
        for j in 0..n {
            for i in 0..n {
                let v = m[j * s + i];
                out[i * s + j] = v;
                f2 += v * v;
            }
        }
        f2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// The padded products and the Gauss–Jordan solve equal nalgebra's, with one chunk
    /// (n = 21 in chunks of 24) and several (n = 37 in chunks of 16).
    #[test]
    fn padded_mul_and_solve_match_dense() {
        fn check<const C: usize>(n: usize) {
            let d = Padded::<C>::new(n);
            let a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.4 + if i == j { 2.0 } else { 0.0 });
            let b = DMatrix::from_fn(n, n, |i, j| ((i * 5 + j * 13) % 17) as f64 / 17.0 - 0.5);
            let pad = |m: &DMatrix<f64>| {
                let mut v = vec![0.0; d.buffer_len()];
                for j in 0..n {
                    v[j * d.stride..j * d.stride + n].copy_from_slice(m.column(j).as_slice());
                }
                v
            };
            let unpad = |v: &[f64]| DMatrix::from_fn(n, n, |i, j| v[j * d.stride + i]);
            let (pa, pb) = (pad(&a), pad(&b));
            let mut out = pad(&b);
            d.mul(&mut out, true, &pa, &pb);
            let want = &a * &b + &b;
            assert!((unpad(&out) - &want).abs().max() < 1e-13 * want.abs().max(), "mul, n = {n}");
            let mut at = vec![0.0; d.buffer_len()];
            assert!((d.transpose(&mut at, &pa) - a.norm_squared()).abs() < 1e-12 * a.norm_squared());
            assert_eq!(unpad(&at), a.transpose());
            let (mut w, mut rhs) = (pa.clone(), [pb.clone(), pa.clone()].concat());
            assert!(d.solve(&mut w, &mut rhs, 2 * n, &mut vec![0.0; 2 * d.stride], &mut vec![0.0; 4 * n]));
            let lu = a.clone().lu();
            for (k, m) in [&b, &a].into_iter().enumerate() {
                let want = lu.solve(m).unwrap();
                let got = unpad(&rhs[k * d.buffer_len()..(k + 1) * d.buffer_len()]);
                assert!((got - &want).abs().max() < 1e-12 * want.abs().max(), "solve, n = {n}");
            }
            // A singular W is reported, not divided by.
            let mut z = vec![0.0; d.buffer_len()];
            assert!(!d.solve(&mut z, &mut pa.clone(), n, &mut vec![0.0; 2 * d.stride], &mut vec![0.0; 2 * n]));
        }
        check::<24>(21);
        check::<16>(37);
        check::<4>(1);
        check::<8>(6);
    }

    /// Every size path (fixed and general) equals nalgebra's ΦPΦᵀ + Q.
    #[test]
    fn propagate_matches_dense_product() {
        for n in [1, 9, 14, 15, 16, 17, 18, 21, 30] {
            let phi = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.4);
            let g = DMatrix::from_fn(n, n, |i, j| ((i * 5 + j * 13) % 17) as f64 / 17.0);
            let (p0, q) = (&g * g.transpose(), DMatrix::from_fn(n, n, |i, j| if i == j { 0.5 } else { 0.0 }));
            let want = &phi * &p0 * phi.transpose() + &q;
            let x0 = DVector::from_fn(n, |i, _| i as f64 - 3.0);
            // the dispatched kernel, then each column grouping compiled for any CPU
            for j in [0, 1, 2, 4] {
                let (mut p, mut x, mut t) = (p0.clone(), x0.clone(), Vec::new());
                let (pm, xm) = (p.as_mut_slice(), Some(x.as_mut_slice()));
                match j {
                    0 => propagate_covariance(pm, xm, phi.as_slice(), q.as_slice(), n, &mut t),
                    _ => {
                        t.resize(2 * (n + 3) * n, 0.0);
                        match j {
                            1 => propagate_sizes::<1>(pm, xm, phi.as_slice(), q.as_slice(), n, &mut t),
                            2 => propagate_sizes::<2>(pm, xm, phi.as_slice(), q.as_slice(), n, &mut t),
                            _ => propagate_sizes::<4>(pm, xm, phi.as_slice(), q.as_slice(), n, &mut t),
                        }
                    }
                }
                assert!((&p - &want).abs().max() < 1e-12 * want.abs().max(), "n = {n}, J = {j}");
                assert_eq!(p, p.transpose(), "n = {n}, J = {j}: not exactly symmetric");
                assert!((x - &phi * &x0).abs().max() < 1e-12 * x0.abs().max(), "n = {n}, J = {j}");
            }
        }
    }
}
