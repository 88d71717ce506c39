//! Dynamic-size dense algebra on faer (blocked GEMM, partial-pivoting LU, blocked
//! Cholesky) for state sizes beyond the register kernels of matrix.rs: the DARE doubling
//! (riccati.rs), the covariance congruence A P Aᵀ + Q of the filter and the covariance
//! analyses (kf.rs, analysis.rs) and the RTS smoother step (kf.rs). The matrices stay
//! nalgebra `DMatrix` (column-major, contiguous); faer works on views of their storage,
//! so nothing is copied on the way in or out. Each caller dispatches on the state size at
//! the crossover measured by `benches/filter.rs`, stated next to its dispatch.

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::{Accum, MatMut, MatRef, Par, Side};
use nalgebra::DMatrix;

/// Which implementation a dense step runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Algebra {
    /// The hand-tuned register kernels of matrix.rs and nalgebra's own products.
    Kernels,
    /// faer's blocked dynamic-size routines.
    Faer,
}

impl Algebra {
    /// faer from `crossover` states on, the kernels below it.
    pub fn by_size(n: usize, crossover: usize) -> Self {
        if n >= crossover {
            Algebra::Faer
        } else {
            Algebra::Kernels
        }
    }
}

/// A faer view of a nalgebra matrix (no copy).
pub fn view(m: &DMatrix<f64>) -> MatRef<'_, f64> {
    MatRef::from_column_major_slice(m.as_slice(), m.nrows(), m.ncols())
}

/// A mutable faer view of a nalgebra matrix (no copy).
pub fn view_mut(m: &mut DMatrix<f64>) -> MatMut<'_, f64> {
    let (r, c) = m.shape();
    MatMut::from_column_major_slice_mut(m.as_mut_slice(), r, c)
}

/// dst ← (dst when `add`) + a b.
pub fn mul(dst: MatMut<'_, f64>, add: bool, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    matmul(dst, if add { Accum::Add } else { Accum::Replace }, a, b, 1.0, Par::Seq);
}

/// The lower triangle (with the diagonal) of dst ← (dst when `add`) + a b; the strict
/// upper triangle of dst is not touched.
pub fn mul_lower(dst: MatMut<'_, f64>, add: bool, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    let beta = if add { Accum::Add } else { Accum::Replace };
    let rect = BlockStructure::Rectangular;
    triangular::matmul(dst, BlockStructure::TriangularLower, beta, a, rect, b, rect, 1.0, Par::Seq);
}

/// Upper triangle ← lower triangle of a square matrix (exact symmetry).
pub fn mirror_lower(m: &mut DMatrix<f64>) {
    let n = m.nrows();
    super::matrix::mirror_lower(m.as_mut_slice(), n);
}

/// out ← A P Aᵀ + Q (Q optional) for a symmetric P: T = A P, then only the lower triangle
/// of T Aᵀ, mirrored, so `out` is exactly symmetric. `t` is n × n scratch.
pub fn congruence(out: &mut DMatrix<f64>, a: &DMatrix<f64>, p: &DMatrix<f64>, q: Option<&DMatrix<f64>>, t: &mut DMatrix<f64>) {
    mul(view_mut(t), false, view(a), view(p));
    if let Some(q) = q {
        out.copy_from(q);
    }
    mul_lower(view_mut(out), q.is_some(), view(t), view(a).transpose());
    mirror_lower(out);
}

/// Solve W Y = B in place by LU with partial pivoting (`b` becomes Y). False when W is
/// singular to working precision (a non-finite solution).
pub fn lu_solve(w: &DMatrix<f64>, b: &mut DMatrix<f64>) -> bool {
    view(w).partial_piv_lu().solve_in_place(view_mut(b));
    b.iter().all(|x| x.is_finite())
}

/// Solve P Y = B in place for a symmetric positive definite P by Cholesky (`b` becomes
/// Y). False when P is not positive definite.
pub fn cholesky_solve(p: &DMatrix<f64>, b: &mut DMatrix<f64>) -> bool {
    match view(p).llt(Side::Lower) {
        Ok(llt) => {
            llt.solve_in_place(view_mut(b));
            true
        }
        Err(_) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: usize, m: usize, seed: usize) -> DMatrix<f64> {
        DMatrix::from_fn(n, m, |i, j| (((i * 7 + j * 3 + seed) % 11) as f64 - 5.0) / 5.0)
    }

    /// The faer congruence, LU and Cholesky solves equal nalgebra's at sizes on both
    /// sides of faer's own block sizes.
    #[test]
    fn congruence_and_solves_match_nalgebra() {
        for n in [1, 7, 40, 70] {
            let a = sample(n, n, 1);
            let g = sample(n, n, 4);
            let p = &g * g.transpose() + DMatrix::identity(n, n);
            let q = DMatrix::identity(n, n) * 0.5;
            let want = &a * &p * a.transpose() + &q;
            let (mut out, mut t) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
            congruence(&mut out, &a, &p, Some(&q), &mut t);
            assert!((&out - &want).abs().max() < 1e-12 * want.abs().max(), "congruence n = {n}");
            assert_eq!(out, out.transpose(), "n = {n}: not exactly symmetric");
            let b = sample(n, 2 * n, 9);
            let mut y = b.clone();
            assert!(cholesky_solve(&p, &mut y));
            assert!((&p * &y - &b).abs().max() < 1e-11 * b.abs().max(), "cholesky n = {n}");
            let w = &a + DMatrix::identity(n, n) * 3.0;
            let mut y = b.clone();
            assert!(lu_solve(&w, &mut y));
            assert!((&w * &y - &b).abs().max() < 1e-11 * b.abs().max(), "lu n = {n}");
        }
        // singular and indefinite matrices are reported
        let mut y = DMatrix::identity(3, 3);
        assert!(!lu_solve(&DMatrix::zeros(3, 3), &mut y));
        assert!(!cholesky_solve(&(-DMatrix::<f64>::identity(3, 3)), &mut y));
    }
}
