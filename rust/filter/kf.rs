//! Error-state Kalman filter core: predict, stacked or sequential (decorrelated) update
//! in Joseph form, χ² gating, closed/open loop, positive-definiteness watch, RTS smoother.
//!
//! Measurement model: z = H δx + v, v ~ N(0, R), with z = predicted − measured (the
//! project's δx = estimate − true, spec cai-ekf §2.0); the estimated error δx̂ is removed
//! from the navigation solution by the caller (closed loop) or kept (open loop).

use super::matrix::{check_covariance, check_square, propagate_covariance, symmetrize};
use crate::error::{invalid, NavError, Result};
use nalgebra::{DMatrix, DVector};

/// How the filter's estimate reaches the navigation solution (spec gnss-ins-tight §2.11).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopMode {
    /// Feedback: after each update the caller applies δx̂ and the filter resets it to 0.
    Closed,
    /// Estimation: the INS runs free, δx̂ is propagated by Φ and kept.
    Open,
}

impl LoopMode {
    pub fn by_name(name: &str) -> Result<Self> {
        match name {
            "closed" => Ok(Self::Closed),
            "open" => Ok(Self::Open),
            _ => Err(invalid("loop_mode", format!("unknown mode {name:?} (expected \"closed\" or \"open\")"))),
        }
    }
}

/// Finite and strictly positive (false for NaN).
fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// Result of one update.
#[derive(Debug, Clone, PartialEq)]
pub struct UpdateReport {
    /// Innovation y = z − Hδx̂⁻ per row (sequential: of the decorrelated rows z̄ = L⁻¹z).
    pub innovation: Vec<f64>,
    /// Normalised innovation squared: one value yᵀS⁻¹y (stacked) or y²/s per row (sequential).
    pub nis: Vec<f64>,
    /// Rows (sequential) or all rows (stacked) rejected by the χ² gate.
    pub rejected: Vec<usize>,
}

/// Filter state (δx̂, P) and epoch counter.
#[derive(Debug, Clone)]
pub struct Kf {
    pub x: DVector<f64>,
    pub p: DMatrix<f64>,
    pub mode: LoopMode,
    /// Number of predictions done (the "epoch" named by numerical errors).
    pub epoch: usize,
    /// Work buffer of the covariance propagation (kept to avoid an allocation per step).
    scratch: Vec<f64>,
}

impl Kf {
    pub fn new(p0: DMatrix<f64>, mode: LoopMode) -> Result<Kf> {
        check_covariance("p0", &p0, None, true)?;
        Ok(Kf { x: DVector::zeros(p0.nrows()), p: p0, mode, epoch: 0, scratch: Vec::new() })
    }

    pub fn size(&self) -> usize {
        self.x.len()
    }

    fn check_pd(&self, stage: &str) -> Result<()> {
        let bad_diag = (0..self.size()).find(|&i| !positive(self.p[(i, i)]));
        if bad_diag.is_some() || self.p.clone().cholesky().is_none() {
            return Err(NavError::Numerical(format!(
                "covariance lost positive definiteness at epoch {} ({stage}){}",
                self.epoch,
                bad_diag.map_or(String::new(), |i| format!(": P[{i},{i}] = {}", self.p[(i, i)]))
            )));
        }
        Ok(())
    }

    /// δx̂ ← Φδx̂, P ← ΦPΦᵀ + Q_d (spec cai-ekf E35).
    pub fn predict(&mut self, phi: &DMatrix<f64>, qd: &DMatrix<f64>) -> Result<()> {
        let n = self.size();
        check_square("phi", phi, Some(n))?;
        check_square("qd", qd, Some(n))?;
        self.predict_unchecked(phi, qd)
    }

    /// `predict` without shape checks, for the inner loops whose matrices are built here.
    pub(crate) fn predict_unchecked(&mut self, phi: &DMatrix<f64>, qd: &DMatrix<f64>) -> Result<()> {
        self.epoch += 1;
        let n = self.size();
        let x = (self.mode == LoopMode::Open).then_some(self.x.as_mut_slice());
        propagate_covariance(self.p.as_mut_slice(), x, phi.as_slice(), qd.as_slice(), n, &mut self.scratch);
        if (0..self.size()).any(|i| !positive(self.p[(i, i)])) {
            return self.check_pd("predict");
        }
        Ok(())
    }

    /// Update with z (m), H (m × n), R (m × m). `sequential`: decorrelate with L = chol(R)
    /// (z̄ = L⁻¹z, H̄ = L⁻¹H) and process scalar rows (spec gnss-ins-tight Eq. 40);
    /// otherwise one stacked vector update. `gate`: χ² threshold — on yᵀS⁻¹y (stacked)
    /// or on each scalar row's y²/s (sequential); rejected rows are reported, not applied.
    /// Covariance in Joseph form P = (I − KH)P(I − KH)ᵀ + KRKᵀ.
    pub fn update(&mut self, z: &[f64], h: &DMatrix<f64>, r: &DMatrix<f64>, sequential: bool, gate: Option<f64>) -> Result<UpdateReport> {
        let n = self.size();
        let m = z.len();
        crate::error::check_finite("z", z, 1)?;
        if h.nrows() != m || h.ncols() != n {
            return Err(invalid("h", format!("expected {m}x{n} (measurements x states), got {}x{}", h.nrows(), h.ncols())));
        }
        check_covariance("r", r, Some(m), true)?;
        if let Some(g) = gate {
            if !positive(g) {
                return Err(invalid("gate", format!("chi-square threshold must be > 0, got {g}")));
            }
        }
        let report = if sequential { self.update_sequential(z, h, r, gate) } else { self.update_stacked(z, h, r, gate) }?;
        self.check_pd("update")?;
        Ok(report)
    }

    fn update_stacked(&mut self, z: &[f64], h: &DMatrix<f64>, r: &DMatrix<f64>, gate: Option<f64>) -> Result<UpdateReport> {
        let y = DVector::from_column_slice(z) - h * &self.x;
        let ph = &self.p * h.transpose();
        let s = h * &ph + r;
        let chol = s.clone().cholesky().ok_or_else(|| NavError::Numerical(format!("innovation covariance not positive definite at epoch {}", self.epoch)))?;
        let nis = y.dot(&chol.solve(&y));
        if gate.is_some_and(|g| nis > g) {
            return Ok(UpdateReport { innovation: y.as_slice().to_vec(), nis: vec![nis], rejected: (0..z.len()).collect() });
        }
        let k = chol.solve(&ph.transpose()).transpose();
        self.x += &k * &y;
        self.joseph(&k, h, r);
        Ok(UpdateReport { innovation: y.as_slice().to_vec(), nis: vec![nis], rejected: vec![] })
    }

    fn update_sequential(&mut self, z: &[f64], h: &DMatrix<f64>, r: &DMatrix<f64>, gate: Option<f64>) -> Result<UpdateReport> {
        let l = r.clone().cholesky().expect("R checked positive definite").l();
        let zb = l.solve_lower_triangular(&DVector::from_column_slice(z)).expect("L non-singular");
        let hb = l.solve_lower_triangular(h).expect("L non-singular");
        let n = self.size();
        let one = DMatrix::from_element(1, 1, 1.0);
        let (mut innovation, mut nis, mut rejected) = (vec![], vec![], vec![]);
        for i in 0..z.len() {
            let hi = DMatrix::from_fn(1, n, |_, j| hb[(i, j)]);
            let y = zb[i] - (&hi * &self.x)[0];
            let ph = &self.p * hi.transpose();
            let s = (&hi * &ph)[(0, 0)] + 1.0;
            innovation.push(y);
            nis.push(y * y / s);
            if gate.is_some_and(|g| y * y / s > g) {
                rejected.push(i);
                continue;
            }
            let k = ph / s;
            self.x += k.column(0) * y;
            self.joseph(&k, &hi, &one);
        }
        Ok(UpdateReport { innovation, nis, rejected })
    }

    fn joseph(&mut self, k: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) {
        let n = self.size();
        let a = DMatrix::identity(n, n) - k * h;
        self.p = &a * &self.p * a.transpose() + k * r * k.transpose();
        symmetrize(&mut self.p);
    }

    /// Closed loop: hand the estimated error to the caller and reset it to 0 (P unchanged,
    /// spec gnss-ins-tight §2.11 item 34). Open loop: returns the estimate, keeps it.
    pub fn take_correction(&mut self) -> DVector<f64> {
        let dx = self.x.clone();
        if self.mode == LoopMode::Closed {
            self.x.fill(0.0);
        }
        dx
    }
}

/// One stored step for the RTS smoother: the transition into this epoch and the prior
/// and posterior moments at it.
#[derive(Debug, Clone)]
pub struct StoredStep {
    pub phi: DMatrix<f64>,
    pub x_prior: DVector<f64>,
    pub p_prior: DMatrix<f64>,
    pub x_post: DVector<f64>,
    pub p_post: DMatrix<f64>,
}

/// Rauch–Tung–Striebel fixed-interval smoother over a stored open-loop run:
/// C_k = P⁺_k Φ_{k+1}ᵀ (P⁻_{k+1})⁻¹, x^s_k = x⁺_k + C_k(x^s_{k+1} − x⁻_{k+1}),
/// P^s_k = P⁺_k + C_k(P^s_{k+1} − P⁻_{k+1})C_kᵀ. `steps[0].phi` is unused.
pub fn rts(steps: &[StoredStep]) -> Result<Vec<(DVector<f64>, DMatrix<f64>)>> {
    let Some(last) = steps.last() else { return Ok(vec![]) };
    let mut out = vec![(last.x_post.clone(), last.p_post.clone())];
    for k in (0..steps.len() - 1).rev() {
        let next = &steps[k + 1];
        let chol = next
            .p_prior
            .clone()
            .cholesky()
            .ok_or_else(|| NavError::Numerical(format!("smoother: prior covariance not positive definite at step {}", k + 1)))?;
        // C = P⁺Φᵀ(P⁻)⁻¹  ⇔  P⁻ Cᵀ = Φ P⁺.
        let c = chol.solve(&(&next.phi * &steps[k].p_post)).transpose();
        let (xs, ps) = out.last().expect("non-empty");
        let x = &steps[k].x_post + &c * (xs - &next.x_prior);
        let mut p = &steps[k].p_post + &c * (ps - &next.p_prior) * c.transpose();
        symmetrize(&mut p);
        out.push((x, p));
    }
    out.reverse();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scalar random constant observed directly: P⁺ after k updates = 1/(1/P0 + k/R).
    #[test]
    fn sequential_equals_stacked_and_closed_form() {
        let r = DMatrix::from_row_slice(2, 2, &[2.0, 0.5, 0.5, 1.0]);
        let h = DMatrix::from_row_slice(2, 2, &[1.0, 0.3, -0.2, 1.0]);
        let p0 = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 3.0]);
        let mut a = Kf::new(p0.clone(), LoopMode::Open).unwrap();
        let mut b = Kf::new(p0, LoopMode::Open).unwrap();
        a.update(&[0.7, -0.4], &h, &r, false, None).unwrap();
        b.update(&[0.7, -0.4], &h, &r, true, None).unwrap();
        assert!((&a.x - &b.x).norm() < 1e-12 && (&a.p - &b.p).norm() < 1e-12);
        let mut c = Kf::new(DMatrix::from_element(1, 1, 2.0), LoopMode::Open).unwrap();
        for _ in 0..5 {
            c.update(&[1.0], &DMatrix::from_element(1, 1, 1.0), &DMatrix::from_element(1, 1, 0.5), false, None).unwrap();
        }
        assert!((c.p[(0, 0)] - 1.0 / (0.5 + 10.0)).abs() < 1e-14);
    }
}
