//! Error-state Kalman filter core: predict, stacked or sequential (decorrelated) update
//! in Joseph or standard form, χ² gating, closed/open loop, positive-definiteness watch,
//! RTS smoother.
//!
//! Measurement model: z = H δx + v, v ~ N(0, R), with z = predicted − measured (the
//! project's δx = estimate − true, README "Conventions"); the estimated error δx̂ is removed
//! from the navigation solution by the caller (closed loop) or kept (open loop).

use super::dense::{self, Algebra};
use super::matrix::{check_covariance, check_square, has_register_kernel, propagate_covariance, symmetrize};
use crate::error::{invalid, invalid_at, NavError, Result};
use nalgebra::{DMatrix, DVector};

/// How the filter's estimate reaches the navigation solution. In both modes a prediction
/// propagates δx̂ by Φ; the modes differ in what [`Kf::take_correction`] does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopMode {
    /// Feedback: the caller takes δx̂ (usually after each update) to correct the navigation
    /// solution, and the filter resets it to 0.
    Closed,
    /// Estimation: the INS runs free, δx̂ is kept.
    Open,
}

impl crate::options::Choice for LoopMode {
    const PARAMETER: &'static str = "mode";
    const CHOICES: &'static [(&'static str, Self)] = &[("closed", LoopMode::Closed), ("open", LoopMode::Open)];
}

/// The covariance form of the measurement update (Groves 2013, ch. 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpdateForm {
    /// P = (I − KH)P(I − KH)ᵀ + KRKᵀ: symmetric and positive semi-definite for any gain.
    #[default]
    Joseph,
    /// P = (I − KH)P, the textbook form (symmetrised after the product).
    Standard,
}

impl crate::options::Choice for UpdateForm {
    const PARAMETER: &'static str = "covariance_update";
    const CHOICES: &'static [(&'static str, Self)] = &[("joseph", UpdateForm::Joseph), ("standard", UpdateForm::Standard)];
}

/// Finite and strictly positive (false for NaN).
fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// Result of one update. Row indices are those of the z given; the rows of its NaN
/// (missing) components are `skipped` and hold NaN in `innovation` (and in `nis` when
/// sequential).
#[derive(Debug, Clone, PartialEq)]
pub struct UpdateReport {
    /// Innovation y = z − Hδx̂⁻ per row (sequential: of the decorrelated rows z̄ = L⁻¹z of
    /// the used components).
    pub innovation: Vec<f64>,
    /// Normalised innovation squared over the used components: one value yᵀS⁻¹y (stacked;
    /// NaN when every component is missing) or y²/s per row (sequential).
    pub nis: Vec<f64>,
    /// Rows (sequential) or all used rows (stacked) rejected by the χ² gate.
    pub rejected: Vec<usize>,
    /// Rows whose z component is NaN: missing, left out of the update.
    pub skipped: Vec<usize>,
}

/// The first non-finite entry of `m` in the given rows and columns: (row, column, value).
fn first_non_finite(m: &DMatrix<f64>, rows: &[usize], cols: &[usize]) -> Option<(usize, usize, f64)> {
    let cells = rows.iter().flat_map(|&i| cols.iter().map(move |&j| (i, j)));
    cells.into_iter().find_map(|(i, j)| m.get((i, j)).filter(|v| !v.is_finite()).map(|&v| (i, j, v)))
}

/// Filter state (δx̂, P) and epoch counter.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Kf {
    pub x: DVector<f64>,
    pub p: DMatrix<f64>,
    #[serde(with = "crate::options::by_name")]
    pub mode: LoopMode,
    /// Covariance form of the measurement update.
    #[serde(default, with = "crate::options::by_name")]
    pub form: UpdateForm,
    /// Number of predictions done (the "epoch" named by numerical errors).
    pub epoch: usize,
    /// Work buffer of the covariance propagation (kept to avoid an allocation per step).
    scratch: Vec<f64>,
    /// Algebra of the covariance products (by state size, [`KF_FAER_MIN`]).
    algebra: Algebra,
    /// n × n work matrices of the faer path (empty on the kernel path).
    work: (DMatrix<f64>, DMatrix<f64>),
}

/// Where the covariance products of the filter (predict ΦPΦᵀ + Q, Joseph update) move
/// from the register kernels of matrix.rs and nalgebra to faer: from this size on, except
/// at the sizes with a fixed-size register kernel ([`has_register_kernel`]: 9, 15–18,
/// 21), which stay on it. `cargo bench --bench filter -- crossover/predict` (steady-state
/// predict, thread CPU time, kernels/faer µs): n = 9: 0.52/1.26, 12: 2.34/1.62,
/// 15: 1.32/2.30, 21: 4.31/4.19, 30: 18.0/9.3, 45: 51.6/20.9, 60: 96.2/43.4,
/// 150: 1244/442. The general loop loses to faer from 12 on; the fixed 15-state kernel
/// wins by 1.7×, and the 21-state one ties.
pub const KF_FAER_MIN: usize = 12;

impl Kf {
    /// A filter from P₀ (positive definite, at least one state).
    pub fn new(p0: DMatrix<f64>, mode: LoopMode) -> Result<Kf> {
        check_covariance("p0", &p0, None, true)?;
        let n = p0.nrows();
        if n == 0 {
            return Err(invalid("p0", "must have at least one state, got 0x0"));
        }
        let kf = Kf { x: DVector::zeros(n), p: p0, mode, form: UpdateForm::Joseph, epoch: 0, scratch: Vec::new(), algebra: Algebra::Kernels, work: (DMatrix::zeros(0, 0), DMatrix::zeros(0, 0)) };
        let algebra = if has_register_kernel(n) { Algebra::Kernels } else { Algebra::by_size(n, KF_FAER_MIN) };
        Ok(kf.with_algebra(algebra))
    }

    /// The same filter starting from the estimate `x0` (n entries, finite) instead of 0.
    pub fn with_state(mut self, x0: &[f64]) -> Result<Kf> {
        let n = self.size();
        if x0.len() != n {
            return Err(invalid("x0", format!("expected {n} entries like p0, got {}", x0.len())));
        }
        if let Some((i, v)) = x0.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(invalid_at("x0", i, format!("non-finite value {v} at index {i}")));
        }
        self.x = DVector::from_column_slice(x0);
        Ok(self)
    }

    /// The same filter with its measurement updates in `form`.
    pub fn with_update_form(mut self, form: UpdateForm) -> Kf {
        self.form = form;
        self
    }

    /// The same filter with its covariance products on `algebra` (benches and tests; the
    /// default is chosen by state size).
    pub fn with_algebra(mut self, algebra: Algebra) -> Kf {
        let n = self.size();
        self.algebra = algebra;
        self.work = match algebra {
            Algebra::Faer => (DMatrix::zeros(n, n), DMatrix::zeros(n, n)),
            Algebra::Kernels => (DMatrix::zeros(0, 0), DMatrix::zeros(0, 0)),
        };
        self
    }

    pub fn size(&self) -> usize {
        self.x.len()
    }

    fn check_pd(&self, stage: &str) -> Result<()> {
        let bad_diag = self.p.diagonal().iter().enumerate().find(|(_, &d)| !positive(d)).map(|(i, &d)| (i, d));
        if bad_diag.is_some() || self.p.clone().cholesky().is_none() {
            return Err(NavError::Numerical(format!(
                "covariance lost positive definiteness at epoch {} ({stage}){}",
                self.epoch,
                bad_diag.map_or(String::new(), |(i, d)| format!(": P[{i},{i}] = {d}"))
            )));
        }
        Ok(())
    }

    /// δx̂ ← Φδx̂, P ← ΦPΦᵀ + Q_d (Tennstedt et al. 2021, Eq. 31), for a Q_d
    /// that is a covariance by construction: only the shapes are checked.
    pub fn predict(&mut self, phi: &DMatrix<f64>, qd: &DMatrix<f64>) -> Result<()> {
        let n = self.size();
        check_square("phi", phi, Some(n))?;
        check_square("qd", qd, Some(n))?;
        self.predict_unchecked(phi, qd)
    }

    /// `steps` predictions with the same (Φ, Q_d) of user input (Q_d checked to be an
    /// n × n covariance, once).
    pub fn predict_many(&mut self, phi: &DMatrix<f64>, qd: &DMatrix<f64>, steps: usize) -> Result<()> {
        let n = self.size();
        check_square("phi", phi, Some(n))?;
        check_covariance("qd", qd, Some(n), false)?;
        (0..steps).try_for_each(|_| self.predict_unchecked(phi, qd))
    }

    /// `predict` without shape checks, for the inner loops whose matrices are built here.
    pub(crate) fn predict_unchecked(&mut self, phi: &DMatrix<f64>, qd: &DMatrix<f64>) -> Result<()> {
        self.epoch += 1;
        let n = self.size();
        match self.algebra {
            // δx̂ = 0 (a closed loop after its feedback) stays 0: skip the product
            Algebra::Kernels => {
                let x = self.x.iter().any(|&v| v != 0.0).then_some(self.x.as_mut_slice());
                propagate_covariance(self.p.as_mut_slice(), x, phi.as_slice(), qd.as_slice(), n, &mut self.scratch);
            }
            Algebra::Faer => {
                if self.x.iter().any(|&v| v != 0.0) {
                    self.x = phi * &self.x;
                }
                let (out, t) = &mut self.work;
                dense::congruence(out, phi, &self.p, Some(qd), t);
                std::mem::swap(&mut self.p, out);
            }
        }
        // the diagonal of the column-major n × n P: every (n + 1)-th value
        if self.p.as_slice().iter().step_by(n + 1).any(|&d| !positive(d)) {
            return self.check_pd("predict");
        }
        Ok(())
    }

    /// Update with z (m), H (m × n), R (m × m). `sequential`: decorrelate with L = chol(R)
    /// (z̄ = L⁻¹z, H̄ = L⁻¹H) and process scalar rows;
    /// otherwise one stacked vector update. `gate`: χ² threshold — on yᵀS⁻¹y (stacked)
    /// or on each scalar row's y²/s (sequential); rejected rows are reported, not applied.
    /// Covariance in the filter's [`UpdateForm`]: Joseph P = (I − KH)P(I − KH)ᵀ + KRKᵀ
    /// (default) or standard P = (I − KH)P.
    ///
    /// A NaN component of z is a missing measurement: the update uses the components that
    /// are not NaN, with their rows of z and H and their rows and columns of R (the rows of
    /// H and R of a missing component are not read), so the NIS and the gate are over the
    /// used components. With every component missing nothing is updated. ±inf in z, and a
    /// non-finite H or R entry of a used component, are invalid input.
    pub fn update(&mut self, z: &[f64], h: &DMatrix<f64>, r: &DMatrix<f64>, sequential: bool, gate: Option<f64>) -> Result<UpdateReport> {
        let n = self.size();
        let m = z.len();
        if let Some((i, v)) = z.iter().enumerate().find(|(_, v)| v.is_infinite()) {
            return Err(invalid_at("z", i, format!("infinite value {v} at index {i} (NaN marks a missing component)")));
        }
        if h.nrows() != m || h.ncols() != n {
            return Err(invalid("h", format!("expected {m}x{n} (measurements x states), got {}x{}", h.nrows(), h.ncols())));
        }
        if r.shape() != (m, m) {
            return Err(invalid("r", format!("expected {m}x{m} (measurements x measurements), got {}x{}", r.nrows(), r.ncols())));
        }
        if let Some(g) = gate {
            if !positive(g) {
                return Err(invalid("gate", format!("chi-square threshold must be > 0, got {g}")));
            }
        }
        let (used, skipped): (Vec<usize>, Vec<usize>) = (0..m).partition(|&i| z.get(i).is_some_and(|v| !v.is_nan()));
        if let Some((i, j, v)) = first_non_finite(h, &used, &(0..n).collect::<Vec<_>>()) {
            return Err(invalid_at("h", i, format!("non-finite value {v} at ({i}, {j}), the row of a measured (non-NaN) component of z")));
        }
        if let Some((i, j, v)) = first_non_finite(r, &used, &used) {
            return Err(invalid_at("r", i, format!("non-finite value {v} at ({i}, {j}), between measured (non-NaN) components of z")));
        }
        let report = if skipped.is_empty() {
            check_covariance("r", r, Some(m), true)?;
            self.update_used(z, h, r, sequential, gate)?
        } else {
            let zu: Vec<f64> = z.iter().copied().filter(|v| !v.is_nan()).collect();
            let ru = r.select_rows(&used).select_columns(&used);
            check_covariance("r", &ru, None, true).map_err(|e| match e {
                NavError::InvalidInput { field, reason, index } => {
                    NavError::InvalidInput { field, reason: format!("{reason} (its rows and columns of the measured components {used:?}, numbered from 0 there)"), index }
                }
                other => other,
            })?;
            let used_report = if used.is_empty() {
                UpdateReport { innovation: vec![], nis: if sequential { vec![] } else { vec![f64::NAN] }, rejected: vec![], skipped: vec![] }
            } else {
                self.update_used(&zu, &h.select_rows(&used), &ru, sequential, gate)?
            };
            // back to the rows of z: NaN at the skipped ones
            let spread = |values: &[f64]| {
                let mut out = vec![f64::NAN; m];
                used.iter().zip(values).for_each(|(&i, &v)| out.get_mut(i).into_iter().for_each(|o| *o = v));
                out
            };
            UpdateReport {
                innovation: spread(&used_report.innovation),
                nis: if sequential { spread(&used_report.nis) } else { used_report.nis },
                rejected: used_report.rejected.iter().filter_map(|&k| used.get(k).copied()).collect(),
                skipped,
            }
        };
        Ok(report)
    }

    /// The update of a z without missing components (checked by [`Kf::update`]).
    fn update_used(&mut self, z: &[f64], h: &DMatrix<f64>, r: &DMatrix<f64>, sequential: bool, gate: Option<f64>) -> Result<UpdateReport> {
        let report = if sequential { self.update_sequential(z, h, r, gate) } else { self.update_stacked(z, h, r, gate) }?;
        self.check_pd("update")?;
        // finite z, H, R and P can still give an innovation beyond the f64 range
        if !report.innovation.iter().chain(&report.nis).all(|v| v.is_finite()) {
            return Err(NavError::Numerical(format!("innovation overflows the floating-point range at epoch {}", self.epoch)));
        }
        Ok(report)
    }

    fn update_stacked(&mut self, z: &[f64], h: &DMatrix<f64>, r: &DMatrix<f64>, gate: Option<f64>) -> Result<UpdateReport> {
        let y = DVector::from_column_slice(z) - h * &self.x;
        let ph = &self.p * h.transpose();
        let s = h * &ph + r;
        let chol = s.clone().cholesky().ok_or_else(|| NavError::Numerical(format!("innovation covariance not positive definite at epoch {}", self.epoch)))?;
        let nis = y.dot(&chol.solve(&y));
        if gate.is_some_and(|g| nis > g) {
            return Ok(UpdateReport { innovation: y.as_slice().to_vec(), nis: vec![nis], rejected: (0..z.len()).collect(), skipped: vec![] });
        }
        let k = chol.solve(&ph.transpose()).transpose();
        self.x += &k * &y;
        self.update_covariance(&k, h, r);
        Ok(UpdateReport { innovation: y.as_slice().to_vec(), nis: vec![nis], rejected: vec![], skipped: vec![] })
    }

    // invariant: i < m = z.len() = rows of hb (update checks h m × n), j < n; the
    // products hi·x and hi·ph are 1 × 1.
    #[allow(clippy::indexing_slicing)]
    fn update_sequential(&mut self, z: &[f64], h: &DMatrix<f64>, r: &DMatrix<f64>, gate: Option<f64>) -> Result<UpdateReport> {
        // check_covariance judged a diagonally scaled copy of R: R itself is factorised here.
        let not_pd = || invalid("r", "not positive definite (Cholesky of r failed)");
        let l = r.clone().cholesky().ok_or_else(not_pd)?.l();
        let zb = l.solve_lower_triangular(&DVector::from_column_slice(z)).ok_or_else(not_pd)?;
        let hb = l.solve_lower_triangular(h).ok_or_else(not_pd)?;
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
            self.update_covariance(&k, &hi, &one);
        }
        Ok(UpdateReport { innovation, nis, rejected, skipped: vec![] })
    }

    fn update_covariance(&mut self, k: &DMatrix<f64>, h: &DMatrix<f64>, r: &DMatrix<f64>) {
        let n = self.size();
        let a = DMatrix::identity(n, n) - k * h;
        if self.form == UpdateForm::Standard {
            self.p = &a * &self.p;
            symmetrize(&mut self.p);
            return;
        }
        let krk = k * r * k.transpose();
        match self.algebra {
            Algebra::Kernels => self.p = &a * &self.p * a.transpose() + krk,
            Algebra::Faer => {
                let (out, t) = &mut self.work;
                dense::congruence(out, &a, &self.p, Some(&krk), t);
                std::mem::swap(&mut self.p, out);
            }
        }
        symmetrize(&mut self.p);
    }

    /// Closed loop: hand the estimated error to the caller and reset it to 0 (P unchanged,
    /// feedback correction). Open loop: returns the estimate, keeps it.
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

/// The stored steps of a run given as one sequence per quantity (all as long as `phi`).
pub fn stored_steps(phi: Vec<DMatrix<f64>>, x_prior: Vec<DVector<f64>>, p_prior: Vec<DMatrix<f64>>, x_post: Vec<DVector<f64>>, p_post: Vec<DMatrix<f64>>) -> Result<Vec<StoredStep>> {
    let n_steps = phi.len();
    for (name, len) in [("x_prior", x_prior.len()), ("p_prior", p_prior.len()), ("x_post", x_post.len()), ("p_post", p_post.len())] {
        if len != n_steps {
            return Err(invalid(name, format!("expected {n_steps} steps like phi, got {len}")));
        }
    }
    let parts = phi.into_iter().zip(x_prior).zip(p_prior).zip(x_post).zip(p_post);
    Ok(parts.map(|((((phi, x_prior), p_prior), x_post), p_post)| StoredStep { phi, x_prior, p_prior, x_post, p_post }).collect())
}

/// Rauch–Tung–Striebel fixed-interval smoother over a stored open-loop run:
/// C_k = P⁺_k Φ_{k+1}ᵀ (P⁻_{k+1})⁻¹, x^s_k = x⁺_k + C_k(x^s_{k+1} − x⁻_{k+1}),
/// P^s_k = P⁺_k + C_k(P^s_{k+1} − P⁻_{k+1})C_kᵀ. `steps[0].phi` is unused. Runs on
/// nalgebra below [`RTS_FAER_MIN`] states and on faer from there on.
pub fn rts(steps: &[StoredStep]) -> Result<Vec<(DVector<f64>, DMatrix<f64>)>> {
    let n = steps.first().map_or(0, |s| s.p_post.nrows());
    rts_using(steps, Algebra::by_size(n, RTS_FAER_MIN))
}

/// Where the RTS smoother moves from nalgebra to faer. `cargo bench --bench filter --
/// crossover/rts` (100 stored steps, 30 at n = 150; thread CPU time, nalgebra/faer ms):
/// n = 9: 0.44/0.49 and 0.58/0.40 in two runs (a tie within their scatter), 12: 0.89/0.49,
/// 15: 1.21/0.89, 21: 2.55/1.53, 60: 33.4/15.4, 150: 96.6/42.4. faer wins from 12 on.
pub const RTS_FAER_MIN: usize = 12;

/// Every stored step has n × n matrices and n-vectors (n of the first step's P⁺).
fn check_steps(steps: &[StoredStep]) -> Result<usize> {
    let n = steps.first().map_or(0, |s| s.p_post.nrows());
    let finite = |field: &str, k: usize, v: &[f64]| match v.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(crate::error::invalid_at(field, k, format!("step {k} holds the non-finite value {x}"))),
        None => Ok(()),
    };
    for (k, s) in steps.iter().enumerate() {
        for (field, m) in [("phi", &s.phi), ("p_prior", &s.p_prior), ("p_post", &s.p_post)] {
            if m.shape() != (n, n) {
                return Err(crate::error::invalid_at(field, k, format!("step {k} is {}x{}, expected {n}x{n}", m.nrows(), m.ncols())));
            }
            finite(field, k, m.as_slice())?;
        }
        for (field, v) in [("x_prior", &s.x_prior), ("x_post", &s.x_post)] {
            if v.len() != n {
                return Err(crate::error::invalid_at(field, k, format!("step {k} has {} entries, expected {n}", v.len())));
            }
            finite(field, k, v.as_slice())?;
        }
    }
    Ok(n)
}

/// [`rts`] with the algebra chosen by the caller (benches and tests).
pub fn rts_using(steps: &[StoredStep], algebra: Algebra) -> Result<Vec<(DVector<f64>, DMatrix<f64>)>> {
    rts_chunk_using(steps, None, 0, algebra)
}

/// The RTS smoother over one chunk of consecutive stored steps, for a record smoothed
/// chunk by chunk from its end (memory-bounded): `after` is the step that follows the
/// chunk (its Φ, x⁻ and P⁻ are read) with its smoothed (x^s, P^s), the carry from the
/// chunk after this one; None for the last chunk of the record, which starts from its
/// last posterior. `first` is the index of `steps[0]` in the whole record (named by
/// errors). Smoothing a record in chunks this way equals [`rts`] on the whole record.
pub fn rts_chunk(steps: &[StoredStep], after: Option<(&StoredStep, DVector<f64>, DMatrix<f64>)>, first: usize) -> Result<Vec<(DVector<f64>, DMatrix<f64>)>> {
    let n = steps.first().map_or(0, |s| s.p_post.nrows());
    rts_chunk_using(steps, after, first, Algebra::by_size(n, RTS_FAER_MIN))
}

/// [`rts_chunk`] with the algebra chosen by the caller.
fn rts_chunk_using(steps: &[StoredStep], after: Option<(&StoredStep, DVector<f64>, DMatrix<f64>)>, first: usize, algebra: Algebra) -> Result<Vec<(DVector<f64>, DMatrix<f64>)>> {
    let n = check_steps(steps)?;
    if steps.is_empty() {
        return Ok(vec![]);
    }
    let mut rest = steps.iter().enumerate().rev();
    let mut out = Vec::with_capacity(steps.len());
    // the step after the current one and its smoothed moments
    let (mut next, mut xs, mut ps) = match after {
        Some((s, x, p)) => {
            if check_steps(std::slice::from_ref(s))? != n || x.len() != n || p.shape() != (n, n) {
                return Err(invalid("after", format!("expected the following step and its smoothed moments over the {n} states of the chunk")));
            }
            (s, x, p)
        }
        None => match rest.next() {
            Some((_, last)) => {
                out.push((last.x_post.clone(), last.p_post.clone()));
                (last, last.x_post.clone(), last.p_post.clone())
            }
            None => return Ok(vec![]),
        },
    };
    let (mut ct, mut u) = match algebra {
        Algebra::Faer => (DMatrix::zeros(n, n), DMatrix::zeros(n, n)),
        Algebra::Kernels => (DMatrix::zeros(0, 0), DMatrix::zeros(0, 0)),
    };
    for (k, cur) in rest {
        let k = first + k;
        let not_pd = || NavError::Numerical(format!("smoother: prior covariance not positive definite at step {}", k + 1));
        // C = P⁺Φᵀ(P⁻)⁻¹  ⇔  P⁻ Cᵀ = Φ P⁺.
        let (x, mut p) = match algebra {
            Algebra::Kernels => {
                let chol = next.p_prior.clone().cholesky().ok_or_else(not_pd)?;
                let c = chol.solve(&(&next.phi * &cur.p_post)).transpose();
                (&cur.x_post + &c * (&xs - &next.x_prior), &cur.p_post + &c * (&ps - &next.p_prior) * c.transpose())
            }
            Algebra::Faer => {
                dense::mul(dense::view_mut(&mut ct), false, dense::view(&next.phi), dense::view(&cur.p_post));
                if !dense::cholesky_solve(&next.p_prior, &mut ct) {
                    return Err(not_pd());
                }
                // P^s = P⁺ + Cᵀᵀ (D Cᵀ) with D = P^s_{k+1} − P⁻_{k+1}; lower triangle, mirrored.
                let d = &ps - &next.p_prior;
                dense::mul(dense::view_mut(&mut u), false, dense::view(&d), dense::view(&ct));
                let mut p = cur.p_post.clone();
                dense::mul_lower(dense::view_mut(&mut p), true, dense::view(&ct).transpose(), dense::view(&u));
                dense::mirror_lower(&mut p);
                (&cur.x_post + ct.tr_mul(&(&xs - &next.x_prior)), p)
            }
        };
        symmetrize(&mut p);
        if !x.iter().chain(p.iter()).all(|v| v.is_finite()) {
            return Err(NavError::Numerical(format!("smoother: the smoothed estimate of step {k} overflows the floating-point range")));
        }
        out.push((x.clone(), p.clone()));
        (next, xs, ps) = (cur, x, p);
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

    /// A NaN component of z is the update without its row of z and H and its row and
    /// column of R; every component NaN leaves the state unchanged.
    #[test]
    fn missing_component_is_the_reduced_update() {
        let p0 = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0]);
        let h = DMatrix::from_row_slice(3, 3, &[1.0, 0.3, 0.0, -0.2, 1.0, 0.4, 0.5, 0.0, 1.0]);
        let r = DMatrix::from_row_slice(3, 3, &[2.0, 0.5, 0.1, 0.5, 1.0, 0.2, 0.1, 0.2, 1.5]);
        for sequential in [false, true] {
            let mut a = Kf::new(p0.clone(), LoopMode::Open).unwrap();
            let mut b = Kf::new(p0.clone(), LoopMode::Open).unwrap();
            let mut h_nan = h.clone();
            h_nan[(1, 2)] = f64::NAN; // the row of a missing component is not read
            let rep = a.update(&[0.7, f64::NAN, -0.4], &h_nan, &r, sequential, None).unwrap();
            let keep = [0, 2];
            b.update(&[0.7, -0.4], &h.select_rows(&keep), &r.select_rows(&keep).select_columns(&keep), sequential, None).unwrap();
            assert!((&a.x - &b.x).norm() < 1e-12 && (&a.p - &b.p).norm() < 1e-12, "sequential = {sequential}");
            assert_eq!(rep.skipped, vec![1]);
            assert!(rep.innovation[1].is_nan() && rep.innovation[0].is_finite() && rep.innovation[2].is_finite());
            let mut c = Kf::new(p0.clone(), LoopMode::Open).unwrap();
            let rep = c.update(&[f64::NAN; 3], &h, &r, sequential, None).unwrap();
            assert_eq!((rep.skipped, &c.x, &c.p), (vec![0, 1, 2], &DVector::zeros(3), &p0));
            // a non-finite H entry of a measured component is still invalid
            let e = c.update(&[0.7, 1.0, f64::NAN], &h_nan, &r, sequential, None).unwrap_err();
            assert!(matches!(&e, NavError::InvalidInput { field, index: Some(1), .. } if field == "h"), "{e}");
        }
    }

    fn sample(n: usize, m: usize, seed: usize) -> DMatrix<f64> {
        DMatrix::from_fn(n, m, |i, j| (((i * 7 + j * 3 + seed) % 11) as f64 - 5.0) / 25.0)
    }

    /// A stored open-loop run of `len` steps of an n-state filter on `algebra`.
    fn run(n: usize, len: usize, algebra: Algebra) -> (Vec<StoredStep>, Kf) {
        // stable Φ and a well-conditioned Q: P stays within a few orders of magnitude
        let phi = DMatrix::identity(n, n) * 0.9 + sample(n, n, 1) * (0.5 / n as f64);
        let g = sample(n, n, 4);
        let q = &g * g.transpose() / n as f64 + DMatrix::identity(n, n) * 0.1;
        let (h, r) = (sample(3, n, 2) * 5.0, DMatrix::identity(3, 3) * 0.3);
        let mut kf = Kf::new(DMatrix::identity(n, n), LoopMode::Open).unwrap().with_algebra(algebra);
        let steps = (0..len)
            .map(|k| {
                let (x_prior, p_prior) = (kf.x.clone(), kf.p.clone());
                kf.update(&[0.3 * k as f64, -0.2, 0.1], &h, &r, k % 2 == 0, None).unwrap();
                let s = StoredStep { phi: phi.clone(), x_prior, p_prior, x_post: kf.x.clone(), p_post: kf.p.clone() };
                kf.predict_many(&phi, &q, 2).unwrap();
                s
            })
            .collect();
        (steps, kf)
    }

    /// The faer path of predict, both updates and the RTS smoother equals the kernel /
    /// nalgebra path below and above the crossovers, and keeps P exactly symmetric.
    #[test]
    fn faer_filter_and_smoother_equal_kernels() {
        for n in [5, KF_FAER_MIN.max(RTS_FAER_MIN) + 3] {
            let (sk, kk) = run(n, 12, Algebra::Kernels);
            let (sf, kf) = run(n, 12, Algebra::Faer);
            let scale = kk.p.abs().max();
            assert!((&kk.p - &kf.p).abs().max() < 1e-12 * scale, "n = {n}: P differs");
            assert!((&kk.x - &kf.x).abs().max() < 1e-12 * kk.x.abs().max(), "n = {n}: x differs");
            assert_eq!(kf.p, kf.p.transpose(), "n = {n}");
            drop(sk);
            let (a, b) = (rts_using(&sf, Algebra::Kernels).unwrap(), rts_using(&sf, Algebra::Faer).unwrap());
            for (k, ((xa, pa), (xb, pb))) in a.iter().zip(&b).enumerate() {
                let d = (pa - pb).abs().max() / pa.abs().max();
                assert!(d < 1e-12, "n = {n}, step {k}: P^s differs by {d}");
                assert!((xa - xb).abs().max() < 1e-12 * xa.abs().max(), "n = {n}, step {k}: x^s differs");
            }
            // the dispatch by size gives one of the two
            let auto = rts(&sf).unwrap();
            let want = if n >= RTS_FAER_MIN { b } else { rts_using(&sf, Algebra::Kernels).unwrap() };
            assert_eq!(auto[0].1, want[0].1, "n = {n}");
        }
        // the filter's own dispatch: a register kernel where one exists, faer from
        // KF_FAER_MIN on otherwise
        let algebra = |n: usize| Kf::new(DMatrix::identity(n, n), LoopMode::Open).unwrap().algebra;
        assert_eq!(algebra(KF_FAER_MIN - 1), Algebra::Kernels);
        assert_eq!(algebra(KF_FAER_MIN), Algebra::Faer);
        assert_eq!(algebra(15), Algebra::Kernels);
        assert_eq!(algebra(21), Algebra::Kernels);
        assert_eq!(algebra(22), Algebra::Faer);
    }

    /// Smoothing a record chunk by chunk from its end, carrying the smoothed moments of
    /// each chunk's first step, equals smoothing it whole, on both algebras.
    #[test]
    fn chunks_equal_whole() {
        for (n, algebra) in [(5, Algebra::Kernels), (RTS_FAER_MIN + 3, Algebra::Faer)] {
            let (steps, _) = run(n, 12, algebra);
            let whole = rts_using(&steps, algebra).unwrap();
            for size in [1, 5, 12] {
                let mut got: Vec<(DVector<f64>, DMatrix<f64>)> = vec![];
                for lo in (0..12).step_by(size).rev() {
                    let hi = (lo + size).min(12);
                    let after = steps.get(hi).map(|s| (s, got[0].0.clone(), got[0].1.clone()));
                    let mut part = rts_chunk_using(&steps[lo..hi], after, lo, algebra).unwrap();
                    part.extend(got);
                    got = part;
                }
                assert_eq!(got, whole, "n = {n}, chunks of {size}");
            }
        }
    }

    /// Bad input to the core is an error, never a panic: an empty P₀, mismatched stored
    /// steps, an indefinite R for the sequential update.
    #[test]
    fn bad_input_is_an_error() {
        let e = Kf::new(DMatrix::zeros(0, 0), LoopMode::Open).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "p0"), "{e}");
        let (mut steps, _) = run(4, 3, Algebra::Kernels);
        steps[2].p_prior = DMatrix::identity(3, 3);
        let e = rts(&steps).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, index: Some(2), .. } if field == "p_prior"), "{e}");
        let mut kf = Kf::new(DMatrix::identity(2, 2), LoopMode::Open).unwrap();
        let r = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        let e = kf.update(&[0.0, 0.0], &DMatrix::identity(2, 2), &r, true, None).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "r"), "{e}");
        let e = kf.predict_many(&DMatrix::identity(2, 2), &(-DMatrix::identity(2, 2)), 3).unwrap_err();
        assert!(matches!(&e, NavError::InvalidInput { field, .. } if field == "qd"), "{e}");
    }
}
