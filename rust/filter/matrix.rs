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
    if let Some(i) = m.iter().position(|x| !x.is_finite()) {
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
    for i in 0..n {
        for j in 0..i {
            let a = 0.5 * (p[(i, j)] + p[(j, i)]);
            p[(i, j)] = a;
            p[(j, i)] = a;
        }
    }
}
