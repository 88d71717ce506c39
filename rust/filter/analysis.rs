//! Linearised scenarios: covariance-only analysis and Monte-Carlo runs of the error-state
//! filter against a truth that follows the same linear error model exactly.
//!
//! A scenario is a sequence of continuous (F_k, Q_c,k) over steps Δt_k (from the INS
//! error model along a trajectory, `ins::error_dynamics`), an initial covariance P₀ and a
//! measurement z = Hδx + v, v ~ N(0, R), at flagged epochs. P₀ may be singular (e.g. an
//! INS started at the truth) for the covariance analyses; the Monte Carlo, whose filter
//! and NEES invert P, needs it positive definite. The truth is always
//! discretised exactly (Van Loan); the filter uses the method asked for, so the effect
//! of the first-order option on consistency can be measured.

use super::dense::{self, Algebra};
use super::discretize::{discretize, Discretization};
use super::kf::{Kf, LoopMode};
use super::matrix::{check_covariance, check_square};
use crate::error::{invalid, NavError, Result};
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// Where the true-error analysis moves from nalgebra's products to faer. `cargo bench
/// --bench filter -- crossover/true_sigmas` (10 epochs; thread CPU time, nalgebra/faer ms,
/// two runs): n = 21: 0.36/0.35 and 0.35/0.30, 45: 1.74/1.70 and 1.62/1.60,
/// 52: 2.25/2.23, 60: 3.63/3.25 and 3.18/2.57, 150: 42.1/42.7 and 40.8/43.0. A tie
/// (within ±5 %) except at 60, where faer is 11–19 % faster; faer from there on, where
/// the two differ by no more than their scatter at 150.
pub const ANALYSIS_FAER_MIN: usize = 56;

#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Scenario {
    /// model[k]: the discretised model of step k (k → k+1), an index into the four lists
    /// below; consecutive steps with the same (F, Q_c, Δt) share one (a vehicle at rest).
    model: Vec<usize>,
    /// Filter transition and process noise per distinct model.
    phi: Vec<DMatrix<f64>>,
    qd: Vec<DMatrix<f64>>,
    /// Truth transition and a square root of its process noise per distinct model.
    phi_true: Vec<DMatrix<f64>>,
    sqrt_qd_true: Vec<DMatrix<f64>>,
    p0: DMatrix<f64>,
    sqrt_p0: DMatrix<f64>,
    h: DMatrix<f64>,
    r: DMatrix<f64>,
    sqrt_r: DMatrix<f64>,
    /// measure[k]: a measurement at epoch k (epoch 0 = initial time, k = 1..=steps after step k).
    measure: Vec<bool>,
    sequential: bool,
}

/// Symmetric square root S (S Sᵀ = A) of a PSD matrix via its eigen-decomposition
/// (clips round-off negative eigenvalues to 0; Cholesky would fail on singular Q_d).
/// An empty matrix (no measurement rows) is its own root; a non-finite one (a discretised
/// model that overflowed) is a numerical error, as is a decomposition that does not converge.
fn sqrt_psd(field: &str, a: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    if a.is_empty() {
        return Ok(a.clone());
    }
    if !a.iter().all(|x| x.is_finite()) {
        return Err(NavError::Numerical(format!("{field}: non-finite covariance (the model overflows the floating-point range)")));
    }
    // the tolerance of SymmetricEigen::new, with an iteration limit instead of its panic
    let e = SymmetricEigen::try_new(a.clone(), f64::EPSILON, 1_000_000).ok_or_else(|| NavError::Numerical(format!("{field}: eigen-decomposition did not converge")))?;
    let d = DMatrix::from_diagonal(&e.eigenvalues.map(|x| x.max(0.0).sqrt()));
    Ok(&e.eigenvectors * d * e.eigenvectors.transpose())
}

/// Appends the σ of every state of epoch `k` from P's diagonal (round-off negatives
/// clipped to 0); a non-finite diagonal (a model that overflows the floating-point range)
/// is a numerical error, not a silent NaN or 0.
fn push_sigmas(out: &mut Vec<f64>, p: &DMatrix<f64>, k: usize) -> Result<()> {
    if let Some(x) = p.diagonal().iter().find(|x| !x.is_finite()) {
        return Err(NavError::Numerical(format!("epoch {k}: covariance diagonal {x} (the model overflows the floating-point range)")));
    }
    out.extend(p.diagonal().iter().map(|x| x.max(0.0).sqrt()));
    Ok(())
}

/// P ← A P Aᵀ + Q on one algebra, with the work matrices of its faer path.
struct Congruence {
    algebra: Algebra,
    out: DMatrix<f64>,
    t: DMatrix<f64>,
}

impl Congruence {
    fn new(n: usize, algebra: Algebra) -> Congruence {
        Congruence { algebra, out: DMatrix::zeros(n, n), t: DMatrix::zeros(n, n) }
    }

    fn apply(&mut self, p: &mut DMatrix<f64>, a: &DMatrix<f64>, q: &DMatrix<f64>) {
        match self.algebra {
            Algebra::Kernels => *p = a * &*p * a.transpose() + q,
            Algebra::Faer => {
                dense::congruence(&mut self.out, a, p, Some(q), &mut self.t);
                std::mem::swap(p, &mut self.out);
            }
        }
    }
}

impl Scenario {
    /// `f`, `qc`: continuous models per step, or one model for every step (a
    /// time-invariant system); `dt`: step lengths (s); `measure`: one flag per epoch
    /// (steps + 1); `p0`: positive semi-definite.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        f: &[DMatrix<f64>],
        qc: &[DMatrix<f64>],
        dt: &[f64],
        p0: DMatrix<f64>,
        h: DMatrix<f64>,
        r: DMatrix<f64>,
        measure: Vec<bool>,
        method: Discretization,
        sequential: bool,
    ) -> Result<Scenario> {
        let steps = dt.len();
        if !(f.len() == steps || f.len() == 1) || qc.len() != f.len() {
            return Err(invalid("f, qc", format!("expected one model per step of dt ({steps}) or one for every step, got {} and {}", f.len(), qc.len())));
        }
        if measure.len() != steps + 1 {
            return Err(invalid("measure", format!("expected one flag per epoch ({}), got {}", steps + 1, measure.len())));
        }
        check_covariance("p0", &p0, None, false)?;
        let n = p0.nrows();
        if n == 0 {
            return Err(invalid("p0", "must have at least one state, got 0x0"));
        }
        // one check and discretisation per run of equal consecutive steps (a vehicle at rest)
        let (mut model, mut distinct) = (Vec::with_capacity(steps), Vec::<(&DMatrix<f64>, &DMatrix<f64>, f64)>::new());
        // (cycle repeats a single model over every step; zip stops after the last step of dt)
        for (k, step) in f.iter().cycle().zip(qc.iter().cycle()).zip(dt).map(|((fk, qk), &dk)| (fk, qk, dk)).enumerate() {
            if distinct.last() != Some(&step) {
                let (fk, qk, dk) = step;
                check_square(&format!("f[{k}]"), fk, Some(n))?;
                check_covariance(&format!("qc[{k}]"), qk, Some(n), false)?;
                crate::error::check_positive(&format!("dt[{k}]"), dk)?;
                distinct.push(step);
            }
            model.push(distinct.len().saturating_sub(1));
        }
        if h.ncols() != n {
            return Err(invalid("h", format!("expected {n} columns (state size), got {}", h.ncols())));
        }
        check_covariance("r", &r, Some(h.nrows()), true)?;
        let filt: Vec<_> = distinct.par_iter().map(|&(fk, qk, dk)| discretize(fk, qk, dk, method)).collect();
        let truth: Vec<_> = (distinct.par_iter().zip(&filt))
            .map(|(&(fk, qk, dk), filt_k)| {
                let (p, q) = if method == Discretization::VanLoan { filt_k.clone() } else { discretize(fk, qk, dk, Discretization::VanLoan) };
                Ok((p, sqrt_psd("qc", &q)?))
            })
            .collect::<Result<_>>()?;
        let (phi, qd) = filt.into_iter().unzip();
        let (phi_true, sqrt_qd_true) = truth.into_iter().unzip();
        let (sqrt_p0, sqrt_r) = (sqrt_psd("p0", &p0)?, sqrt_psd("r", &r)?);
        Ok(Scenario { model, phi, qd, phi_true, sqrt_qd_true, sqrt_p0, p0, sqrt_r, h, r, measure, sequential })
    }

    pub fn size(&self) -> usize {
        self.p0.nrows()
    }

    pub fn epochs(&self) -> usize {
        self.measure.len()
    }

    /// Covariance-only analysis: σ of every state after each epoch's update (epochs × n,
    /// row-major): P⁻ = Φ P⁺ Φᵀ + Q, P⁺ = (I−KH) P⁻ (I−KH)ᵀ + K R Kᵀ (Joseph form, exact
    /// for a singular P too), on nalgebra below [`ANALYSIS_FAER_MIN`] states and on faer
    /// from there on.
    // invariant: Scenario::new makes measure (epochs) one longer than model (steps), whose
    // entries index phi and qd (private fields), and P n × n, so k − 1 < steps for
    // 0 < k < epochs and i < n.
    #[allow(clippy::indexing_slicing)]
    pub fn sigmas(&self) -> Result<Vec<f64>> {
        let n = self.size();
        let mut p = self.p0.clone();
        let mut congruence = Congruence::new(n, Algebra::by_size(n, ANALYSIS_FAER_MIN));
        let mut out = Vec::with_capacity(self.epochs() * n);
        for k in 0..self.epochs() {
            if k > 0 {
                let m = self.model[k - 1];
                congruence.apply(&mut p, &self.phi[m], &self.qd[m]);
            }
            if self.measure[k] {
                let (gain, ikh) = self.gain(k, &p)?;
                congruence.apply(&mut p, &ikh, &(&gain * &self.r * gain.transpose()));
            }
            push_sigmas(&mut out, &p, k)?;
        }
        Ok(out)
    }

    /// Gain K = P Hᵀ S⁻¹ (S = H P Hᵀ + R) of the filter's update at epoch `k` from its
    /// prior covariance `p`, and I − KH.
    fn gain(&self, k: usize, p: &DMatrix<f64>) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
        let s = &self.h * p * self.h.transpose() + &self.r;
        let chol = s.cholesky().ok_or_else(|| NavError::Numerical(format!("epoch {k}: innovation covariance not positive definite")))?;
        let gain = chol.solve(&(&self.h * p)).transpose();
        let ikh = DMatrix::<f64>::identity(p.nrows(), p.nrows()) - &gain * &self.h;
        Ok((gain, ikh))
    }

    /// True-error covariance analysis of the filter as built (suboptimal-filter analysis):
    /// the gains K come from the filter's own model (its P, R), while the true measurement
    /// noise has covariance `r_true` and is correlated with the process noise of the step
    /// that ends at the measurement epoch: `cross[k − 1]` = E[w_{k−1} v_kᵀ] (n × m), e.g. a
    /// CAI whose readout also senses the IMU noise of its shot. With e⁺ = (I − KH)e⁻ − Kv:
    ///   P⁻ = Φ P⁺ Φᵀ + Q,
    ///   P⁺ = (I−KH) P⁻ (I−KH)ᵀ + K R_t Kᵀ − (I−KH) S Kᵀ − K Sᵀ (I−KH)ᵀ.
    /// Returns the σ of the true error after each epoch (epochs × n, row-major); with
    /// R_t = R and S = 0 it is [`Scenario::sigmas`] (for a Van Loan filter).
    ///
    /// The covariance products run on nalgebra below [`ANALYSIS_FAER_MIN`] states and on
    /// faer from there on.
    pub fn true_sigmas(&self, r_true: &DMatrix<f64>, cross: &[DMatrix<f64>]) -> Result<Vec<f64>> {
        self.true_sigmas_using(r_true, cross, Algebra::by_size(self.size(), ANALYSIS_FAER_MIN))
    }

    /// [`Scenario::true_sigmas`] with the algebra chosen by the caller (benches and tests).
    // invariant: Scenario::new makes measure (epochs) one longer than model (steps), whose
    // entries index phi, qd, phi_true, sqrt_qd_true (private fields), and P n × n, so
    // k − 1 < steps for 0 < k < epochs and i < n. cross has one entry per step (checked above).
    #[allow(clippy::indexing_slicing)]
    pub fn true_sigmas_using(&self, r_true: &DMatrix<f64>, cross: &[DMatrix<f64>], algebra: Algebra) -> Result<Vec<f64>> {
        let n = self.size();
        let m = self.h.nrows();
        check_covariance("r_true", r_true, Some(m), false)?;
        if cross.len() != self.model.len() {
            return Err(invalid("cross", format!("expected one n × m matrix per step ({}), got {}", self.model.len(), cross.len())));
        }
        if let Some((k, c)) = cross.iter().enumerate().find(|(_, c)| c.nrows() != n || c.ncols() != m) {
            return Err(crate::error::invalid_at("cross", k, format!("entry {k} is {} × {}, expected {n} × {m}", c.nrows(), c.ncols())));
        }
        let mut pf = self.p0.clone();
        let mut pt = self.p0.clone();
        let mut congruence = Congruence::new(n, algebra);
        let mut out = Vec::with_capacity(self.epochs() * n);
        for k in 0..self.epochs() {
            if k > 0 {
                let j = self.model[k - 1];
                congruence.apply(&mut pf, &self.phi[j], &self.qd[j]);
                let sq = &self.sqrt_qd_true[j];
                congruence.apply(&mut pt, &self.phi_true[j], &(sq * sq.transpose()));
            }
            if self.measure[k] {
                let (gain, ikh) = self.gain(k, &pf)?;
                congruence.apply(&mut pf, &ikh, &(&gain * &self.r * gain.transpose()));
                let c = if k > 0 { cross[k - 1].clone() } else { DMatrix::zeros(n, m) };
                let corr = &ikh * &c * gain.transpose();
                congruence.apply(&mut pt, &ikh, &(&gain * r_true * gain.transpose() - &corr - corr.transpose()));
            }
            push_sigmas(&mut out, &pt, k)?;
        }
        Ok(out)
    }

    /// One Monte-Carlo run with the seed of run `run` under `master_seed` (ChaCha20
    /// stream = run index, so any subset of runs reproduces the same numbers anywhere).
    /// Its filter and NEES need a positive definite P₀: a singular one is an error naming
    /// `p0`.
    // invariant: Scenario::new makes measure (epochs) one longer than model (steps), whose
    // entries index phi, qd, phi_true, sqrt_qd_true (private fields), and P n × n, so
    // k − 1 < steps for 0 < k < epochs and i < n. res.nis has one entry per epoch.
    #[allow(clippy::indexing_slicing)]
    pub fn run(&self, master_seed: u64, run: u64, mode: LoopMode) -> Result<RunResult> {
        let n = self.size();
        let m = self.h.nrows();
        let mut rng = ChaCha20Rng::seed_from_u64(master_seed);
        rng.set_stream(run);
        let mut normal = |k: usize| DVector::<f64>::from_iterator(k, (0..k).map(|_| StandardNormal.sample(&mut rng)));
        // e: error of the navigation solution the filter works on (estimate − truth).
        let mut e = &self.sqrt_p0 * normal(n);
        let mut kf = Kf::new(self.p0.clone(), mode)?;
        let epochs = self.epochs();
        let mut res = RunResult { error: Vec::with_capacity(epochs * n), sigma: Vec::with_capacity(epochs * n), nees: Vec::with_capacity(epochs), nis: vec![f64::NAN; epochs] };
        for k in 0..epochs {
            if k > 0 {
                let j = self.model[k - 1];
                e = &self.phi_true[j] * &e + &self.sqrt_qd_true[j] * normal(n);
                kf.predict_unchecked(&self.phi[j], &self.qd[j])?;
            }
            if self.measure[k] {
                let z = &self.h * &e + &self.sqrt_r * normal(m);
                let rep = kf.update(z.as_slice(), &self.h, &self.r, self.sequential, None)?;
                res.nis[k] = rep.nis.iter().sum();
                // Closed loop: apply the correction to the navigation solution, reset δx̂.
                if mode == LoopMode::Closed {
                    e -= kf.take_correction();
                }
            }
            // Error of the output estimate X̂ = X ⊖ δx̂ (δx̂ = 0 in closed loop).
            let err = &e - &kf.x;
            // the filter checks only P's diagonal after a prediction: P itself is factorised here
            let chol = kf.p.clone().cholesky().ok_or_else(|| NavError::Numerical(format!("run {run}, epoch {k}: covariance lost positive definiteness")))?;
            res.nees.push(err.dot(&chol.solve(&err)));
            res.error.extend(err.iter());
            res.sigma.extend((0..n).map(|i| kf.p[(i, i)].sqrt()));
        }
        Ok(res)
    }

    /// Runs `runs` in parallel (rayon), in the order given.
    pub fn monte_carlo(&self, master_seed: u64, runs: &[u64], mode: LoopMode) -> Result<Vec<RunResult>> {
        check_covariance("p0", &self.p0, None, true).map_err(|e| match e {
            NavError::InvalidInput { field, reason, index } => {
                NavError::InvalidInput { field, reason: format!("{reason}; the Monte Carlo's filter and NEES need a positive definite P0"), index }
            }
            other => other,
        })?;
        runs.par_iter().map(|&r| self.run(master_seed, r, mode)).collect()
    }
}

/// One run: per epoch, the output error and σ of every state (epochs × n, row-major),
/// NEES εᵀP⁻¹ε and the NIS of the epoch's update (NaN without a measurement).
#[derive(Debug, Clone)]
pub struct RunResult {
    pub error: Vec<f64>,
    pub sigma: Vec<f64>,
    pub nees: Vec<f64>,
    pub nis: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-D random walk observed directly: the filter covariance equals the scalar
    /// closed-form recursion P⁺ = (P⁻R)/(P⁻ + R), P⁻ = P⁺ + qΔt.
    #[test]
    fn sigmas_follow_scalar_recursion() {
        let steps = 20;
        let f = vec![DMatrix::zeros(1, 1); steps];
        let qc = vec![DMatrix::from_element(1, 1, 0.3); steps];
        let s = Scenario::new(&f, &qc, &vec![0.5; steps], DMatrix::from_element(1, 1, 2.0), DMatrix::from_element(1, 1, 1.0), DMatrix::from_element(1, 1, 0.4), vec![true; steps + 1], Discretization::VanLoan, false).unwrap();
        let sig = s.sigmas().unwrap();
        let mut p: f64 = 2.0;
        for (k, sg) in sig.iter().enumerate() {
            if k > 0 {
                p += 0.15;
            }
            p = p * 0.4 / (p + 0.4);
            assert!((sg * sg / p - 1.0).abs() < 1e-12);
        }
    }

    /// A scalar random walk x observed as z = x + v, where v = u_k − u'_k shares the last
    /// step's process noise u_k (w = u_k): S = E[w v] = q, R_t = q + r'. The true error
    /// variance follows the scalar recursion with the filter's own gain.
    #[test]
    fn true_sigmas_follow_scalar_recursion_with_correlated_noise() {
        let steps = 15;
        let (q, rp, r_f) = (0.3, 0.1, 0.5);
        let f = vec![DMatrix::zeros(1, 1); steps];
        let qc = vec![DMatrix::from_element(1, 1, q); steps];
        let s = Scenario::new(&f, &qc, &vec![1.0; steps], DMatrix::from_element(1, 1, 2.0), DMatrix::from_element(1, 1, 1.0), DMatrix::from_element(1, 1, r_f), vec![true; steps + 1], Discretization::VanLoan, false).unwrap();
        let cross = vec![DMatrix::from_element(1, 1, q); steps];
        let sig = s.true_sigmas(&DMatrix::from_element(1, 1, q + rp), &cross).unwrap();
        let (mut pf, mut pt): (f64, f64) = (2.0, 2.0);
        for (k, sg) in sig.iter().enumerate() {
            let c = if k > 0 { pf += q; pt += q; q } else { 0.0 };
            let g = pf / (pf + r_f);
            pf = (1.0 - g) * pf;
            pt = (1.0 - g).powi(2) * pt + g * g * (q + rp) - 2.0 * (1.0 - g) * g * c;
            assert!((sg * sg / pt - 1.0).abs() < 1e-12, "epoch {k}: {} vs {pt}", sg * sg);
        }
        // no correlation and R_t = R: the filter's own covariance
        let own = s.true_sigmas(&DMatrix::from_element(1, 1, r_f), &vec![DMatrix::zeros(1, 1); steps]).unwrap();
        assert!(own.iter().zip(s.sigmas().unwrap()).all(|(a, b)| (a - b).abs() < 1e-12));
    }

    /// The faer true-error analysis equals nalgebra's above the crossover, and the filter
    /// σ of `sigmas` (on faer there too) equal the R_t = R, S = 0 analysis.
    #[test]
    fn true_sigmas_faer_equals_nalgebra() {
        let (n, steps) = (ANALYSIS_FAER_MIN + 2, 6);
        let f: Vec<_> = (0..steps).map(|k| DMatrix::from_fn(n, n, |i, j| if i == j { -0.05 } else { 0.01 * (((i * 7 + j * 3 + k) % 11) as f64 - 5.0) })).collect();
        let qc = vec![DMatrix::identity(n, n) * 0.2; steps];
        let h = DMatrix::from_fn(3, n, |i, j| if j % 3 == i { 1.0 } else { 0.0 });
        let r = DMatrix::identity(3, 3) * 0.5;
        let s = Scenario::new(&f, &qc, &vec![0.5; steps], DMatrix::identity(n, n), h, r.clone(), vec![true; steps + 1], Discretization::VanLoan, false).unwrap();
        let cross = vec![DMatrix::from_element(n, 3, 0.01); steps];
        let a = s.true_sigmas_using(&(&r * 1.5), &cross, Algebra::Kernels).unwrap();
        let b = s.true_sigmas_using(&(&r * 1.5), &cross, Algebra::Faer).unwrap();
        assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12 * x), "{a:?} {b:?}");
        let own = s.true_sigmas(&r, &vec![DMatrix::zeros(n, 3); steps]).unwrap();
        assert!(own.iter().zip(s.sigmas().unwrap()).all(|(x, y)| (x - y).abs() < 1e-12 * x));
    }

    /// A singular P₀ (the first state known exactly) in a 2-state random walk: both states
    /// propagate as P = P₀ + q t without measurements, so the first σ is √(q t), and equal
    /// consecutive steps share one discretisation while the changed one does not; the
    /// Monte Carlo refuses the singular P₀, naming it.
    #[test]
    fn singular_p0_in_the_covariance_analysis() {
        let (steps, q) = (8, 0.3);
        let f = vec![DMatrix::zeros(2, 2); steps];
        let mut qc = vec![DMatrix::identity(2, 2) * q; steps];
        qc[5] = DMatrix::identity(2, 2) * (2.0 * q);
        let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![0.0, 1.0]));
        let s = Scenario::new(&f, &qc, &vec![0.5; steps], p0, DMatrix::zeros(0, 2), DMatrix::zeros(0, 0), vec![false; steps + 1], Discretization::VanLoan, false).unwrap();
        assert_eq!(s.model, vec![0, 0, 0, 0, 0, 1, 2, 2]);
        // one model for every step: the same analysis as the stack of equal models
        let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![0.0, 1.0]));
        let one = Scenario::new(&f[..1], &qc[..1], &vec![0.5; steps], p0.clone(), DMatrix::zeros(0, 2), DMatrix::zeros(0, 0), vec![false; steps + 1], Discretization::VanLoan, false).unwrap();
        let stack = Scenario::new(&f, &vec![DMatrix::identity(2, 2) * q; steps], &vec![0.5; steps], p0, DMatrix::zeros(0, 2), DMatrix::zeros(0, 0), vec![false; steps + 1], Discretization::VanLoan, false).unwrap();
        assert_eq!((one.model.len(), one.sigmas().unwrap()), (steps, stack.sigmas().unwrap()));
        let sig = s.sigmas().unwrap();
        let mut v = [0.0, 1.0];
        for k in 0..=steps {
            if k > 0 {
                let dq = if k == 6 { 2.0 * q } else { q } * 0.5;
                v = [v[0] + dq, v[1] + dq];
            }
            for i in 0..2 {
                assert!((sig[2 * k + i] - v[i].sqrt()).abs() < 1e-14, "epoch {k}, state {i}: {} vs {}", sig[2 * k + i], v[i].sqrt());
            }
        }
        let own = s.true_sigmas(&DMatrix::zeros(0, 0), &vec![DMatrix::zeros(2, 0); steps]).unwrap();
        assert!(own.iter().zip(&sig).all(|(a, b)| (a - b).abs() < 1e-14));
        let e = s.monte_carlo(1, &[0], LoopMode::Closed).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "p0"), "{e}");
    }

    /// A scenario without states is rejected, not divided by.
    #[test]
    fn empty_scenario_is_rejected() {
        let e = Scenario::new(&[], &[], &[], DMatrix::zeros(0, 0), DMatrix::zeros(0, 0), DMatrix::zeros(0, 0), vec![true], Discretization::VanLoan, false).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "p0"), "{e}");
    }
}
