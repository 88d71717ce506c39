//! Discretisation of ẋ = F x + w, E[w wᵀ] = Q_c δ(t − s), over a step Δt.
//!
//! Van Loan (1978): with M = [[−F, Q_c], [0, Fᵀ]] Δt and E = exp(M) = [[·, E₁₂], [0, E₂₂]],
//! Φ = E₂₂ᵀ and Q_d = Φ E₁₂.
//! First-order option: Φ = I + FΔt, Q_d = Q_c Δt.

use crate::error::Result;
use nalgebra::DMatrix;

/// How Φ and Q_d are computed from F and Q_c.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Discretization {
    /// Exact for constant F over the step (matrix exponential).
    VanLoan,
    /// Φ = I + FΔt, Q_d = Q_cΔt: cheaper, O(Δt²) error per step.
    FirstOrder,
}

impl crate::options::Choice for Discretization {
    const PARAMETER: &'static str = "method";
    const CHOICES: &'static [(&'static str, Self)] = &[("van_loan", Discretization::VanLoan), ("first_order", Discretization::FirstOrder)];
}

/// Matrix exponential by scaling and squaring with an 18-term Taylor series: the
/// argument is scaled to ‖A‖₁/2ˢ ≤ 1/2, where the truncation error is below 2⁻⁵⁴/18!.
pub fn expm(a: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let norm = (0..n).map(|j| a.column(j).iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
    // at most 1100 squarings: any finite norm needs ≤ 1025, and an infinite one (an input
    // that overflowed) would otherwise ask for i32::MAX of them
    let s = if norm > 0.5 { (norm / 0.5).log2().ceil().min(1100.0) as i32 } else { 0 };
    let x = a * 0.5f64.powi(s);
    let mut term = DMatrix::<f64>::identity(n, n);
    let mut sum = term.clone();
    for k in 1..=18 {
        term = &term * &x / k as f64;
        sum += &term;
    }
    for _ in 0..s {
        sum = &sum * &sum;
    }
    sum
}

/// [`discretize`] of user input: F square, Q_c a covariance of the same size, `dt` > 0.
pub fn discretize_checked(f: &DMatrix<f64>, qc: &DMatrix<f64>, dt: f64, method: Discretization) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    super::matrix::check_square("f", f, None)?;
    super::matrix::check_covariance("qc", qc, Some(f.nrows()), false)?;
    crate::error::check_positive("dt", dt)?;
    let (phi, qd) = discretize(f, qc, dt, method);
    if !(phi.iter().chain(qd.iter()).all(|x| x.is_finite())) {
        return Err(crate::error::invalid("dt", format!("exp(F·dt) over dt = {dt} s exceeds the range of floats (|F|·dt too large)")));
    }
    Ok((phi, qd))
}

/// (Φ, Q_d) over `dt` for continuous F (n × n) and white-noise intensity Q_c = G Q Gᵀ (n × n).
pub fn discretize(f: &DMatrix<f64>, qc: &DMatrix<f64>, dt: f64, method: Discretization) -> (DMatrix<f64>, DMatrix<f64>) {
    let n = f.nrows();
    match method {
        Discretization::FirstOrder => (DMatrix::identity(n, n) + f * dt, qc * dt),
        Discretization::VanLoan => {
            let mut m = DMatrix::<f64>::zeros(2 * n, 2 * n);
            m.view_mut((0, 0), (n, n)).copy_from(&(-f * dt));
            m.view_mut((0, n), (n, n)).copy_from(&(qc * dt));
            m.view_mut((n, n), (n, n)).copy_from(&(f.transpose() * dt));
            let e = expm(&m);
            let phi = e.view((n, n), (n, n)).transpose();
            let mut qd = &phi * e.view((0, n), (n, n));
            super::matrix::symmetrize(&mut qd);
            (phi, qd)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_overflowing_transition_names_dt() {
        // e^(67.4 · 17.2) ≈ e^1161 is beyond f64 (e^709.8)
        let (f, qc) = (DMatrix::from_element(1, 1, 67.42249402142612), DMatrix::from_element(1, 1, 100.0));
        for method in [Discretization::VanLoan, Discretization::FirstOrder] {
            let dt = if method == Discretization::VanLoan { 17.224185682635586 } else { 1e307 };
            match discretize_checked(&f, &qc, dt, method) {
                Err(crate::error::NavError::InvalidInput { field, .. }) => assert_eq!(field, "dt"),
                other => panic!("{other:?}"),
            }
        }
        let (phi, _) = discretize_checked(&f, &qc, 0.01, Discretization::VanLoan).unwrap();
        assert!((phi[(0, 0)] - (67.42249402142612_f64 * 0.01).exp()).abs() < 1e-12 * phi[(0, 0)]);
    }

    /// Double integrator ẋ₁ = x₂, ẋ₂ = w: Q_d = q [[Δt³/3, Δt²/2], [Δt²/2, Δt]].
    #[test]
    fn van_loan_double_integrator() {
        let f = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let qc = DMatrix::from_row_slice(2, 2, &[0.0, 0.0, 0.0, 2.0]);
        let dt = 0.7;
        let (phi, qd) = discretize(&f, &qc, dt, Discretization::VanLoan);
        let expect = [2.0 * dt.powi(3) / 3.0, dt * dt, dt * dt, 2.0 * dt];
        for (i, e) in expect.iter().enumerate() {
            assert!((qd[(i / 2, i % 2)] - e).abs() < 1e-14 * e.abs().max(1.0), "{qd}");
        }
        assert!((phi[(0, 1)] - dt).abs() < 1e-15);
    }

    /// Gauss–Markov ẋ = −x/τ + w: Φ = e^{−Δt/τ}, Q_d = qτ/2 (1 − e^{−2Δt/τ}).
    #[test]
    fn van_loan_gauss_markov() {
        let (tau, q, dt) = (10.0, 3e-6, 4.0);
        let (phi, qd) = discretize(&DMatrix::from_element(1, 1, -1.0 / tau), &DMatrix::from_element(1, 1, q), dt, Discretization::VanLoan);
        assert!((phi[(0, 0)] / (-dt / tau).exp() - 1.0).abs() < 1e-14);
        let e = q * tau / 2.0 * (1.0 - (-2.0 * dt / tau).exp());
        assert!((qd[(0, 0)] / e - 1.0).abs() < 1e-13);
    }
}
