//! Non-negative least squares, Lawson & Hanson (1974) active-set algorithm, as in
//! `scipy.optimize.nnls`. Used by the five-term Allan fit (docs/departures.md#allan-fit).

use crate::error::{NavError, Result};
use nalgebra::{DMatrix, DVector};

/// min ‖A x − b‖₂ subject to x ≥ 0. `A` is m×n (small, dense).
// invariant: x, w, z have n entries and passive n flags; idx holds indices j < n and
// c < idx.len() = columns of ap and rows of zp.
#[allow(clippy::indexing_slicing)]
pub fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<DVector<f64>> {
    let (m, n) = a.shape();
    let norm1 = (0..n).map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
    let tol = 10.0 * f64::EPSILON * norm1 * (m.max(n) as f64);
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    // Candidates whose gradient was positive by rounding only: with them passive the
    // least-squares solution puts them at ≤ 0 at once (a term whose true coefficient is
    // exactly 0, e.g. an Allan fit of noise-free variances). Lawson & Hanson's own
    // routine rejects such a candidate (its w is set to 0) until x next changes;
    // without this the loop adds and drops it until it runs out of iterations.
    let mut rounding_only = vec![false; n];
    let max_iter = 3 * n + 30;
    'outer: for _ in 0..max_iter {
        let w = a.transpose() * (b - a * &x);
        // Lawson–Hanson step 2: the most violating inactive variable.
        let t = (0..n).filter(|&j| !passive[j] && !rounding_only[j] && w[j] > tol).max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(t) = t else { return Ok(x) };
        passive[t] = true;
        let mut first = true;
        // Inner loop: least squares on the passive set, step back into the feasible region.
        loop {
            let idx: Vec<usize> = (0..n).filter(|&j| passive[j]).collect();
            let ap = DMatrix::from_fn(m, idx.len(), |r, c| a[(r, idx[c])]);
            let zp = ap
                .svd(true, true)
                .solve(b, f64::EPSILON)
                .map_err(|e| NavError::Numerical(format!("nnls: least-squares subproblem failed: {e}")))?;
            let mut z = DVector::zeros(n);
            for (c, &j) in idx.iter().enumerate() {
                z[j] = zp[c];
            }
            if first && z[t] <= tol {
                passive[t] = false;
                rounding_only[t] = true;
                continue 'outer;
            }
            first = false;
            if idx.iter().all(|&j| z[j] > tol) {
                x = z;
                break;
            }
            let alpha = idx
                .iter()
                .filter(|&&j| z[j] <= tol)
                .map(|&j| x[j] / (x[j] - z[j]))
                .fold(f64::INFINITY, f64::min);
            x += (z - &x) * alpha;
            for &j in &idx {
                if x[j] <= tol {
                    x[j] = 0.0;
                    passive[j] = false;
                }
            }
        }
        rounding_only.fill(false);
    }
    Err(NavError::Numerical("nnls: no convergence".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unconstrained_solution_when_positive() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        let b = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let x = nnls(&a, &b).unwrap();
        assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn clamps_negative_component() {
        // Unconstrained optimum is (2, -1); with x ≥ 0 the optimum is (x0, 0), x0 = a·b/|a|².
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0]);
        let b = DVector::from_vec(vec![1.0, -1.0]);
        let x = nnls(&a, &b).unwrap();
        assert!((x[0] - 1.0).abs() < 1e-12 && x[1] == 0.0);
    }
}
