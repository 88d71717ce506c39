//! Fringe noise identification (Tennstedt et al. 2021, §3).
//!
//! Readout p_i = p0 + A cos(φ + ψ_i) with noise on the offset (σ_p0), the phase (σ_φ) and
//! the amplitude (σ_A). A small EKF tracks ζ = [p0, φ, A]; the residuals
//! x_i = p_i − (p̂0 + Â cos φ_i) have variance (E17)
//!   σ_i² = Σ_j c_ij θ_j²,  c_i = [1, A² sin² φ_i, cos² φ_i],  θ = [σ_p0, σ_φ, σ_A],
//! and θ is found by maximum likelihood (E18). Since sin² + cos² = 1, σ_i² = a + b sin² φ_i
//! with a = σ_p0² + σ_A², b = A²σ_φ² − σ_A²: only (a, b) are identifiable, so at most two
//! of the three components may be free (the third is fixed at a given value).

use crate::error::{check_finite, invalid, NavError, Result};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use std::f64::consts::PI;

/// Fringe-tracking EKF settings (E15)/(E16).
#[derive(Clone, Debug)]
pub struct FringeEkf {
    /// Initial ζ = [p0, φ (rad), A].
    pub zeta0: [f64; 3],
    /// Initial standard deviations of ζ.
    pub sigma0: [f64; 3],
    /// Random-walk variance of ζ per shot (docs/departures.md#fringe-tracking: 1e-9, 1e-7, 1e-9).
    pub q: [f64; 3],
    /// Readout noise variance R.
    pub r: f64,
}

/// Track ζ over the readouts `p` with known input phases `psi` (rad); returns ζ after each
/// update (A kept > 0, φ wrapped to (−π, π]).
// invariant: fixed-size 3-vectors and 3 × 3 matrices indexed by constants < 3; the
// product hᵀ P h is 1 × 1.
#[allow(clippy::indexing_slicing)]
pub fn fringe_track(p: &[f64], psi: &[f64], cfg: &FringeEkf) -> Result<Vec<[f64; 3]>> {
    check_finite("p", p, 1)?;
    check_finite("psi", psi, 1)?;
    if p.len() != psi.len() {
        return Err(invalid("psi", format!("length {} differs from p length {}", psi.len(), p.len())));
    }
    if !(cfg.r.is_finite() && cfg.r > 0.0) {
        return Err(invalid("r", format!("must be finite and > 0, got {}", cfg.r)));
    }
    let mut z = Vector3::from(cfg.zeta0);
    let mut pm = Matrix3::from_diagonal(&Vector3::from(cfg.sigma0.map(|s| s * s)));
    let q = Matrix3::from_diagonal(&Vector3::from(cfg.q));
    let mut out = Vec::with_capacity(p.len());
    for (&pi, &si) in p.iter().zip(psi) {
        pm += q;
        let ph = z[1] + si;
        let h = Vector3::new(1.0, -z[2] * ph.sin(), ph.cos());
        let s = (h.transpose() * pm * h)[0] + cfg.r;
        let k = pm * h / s;
        z += k * (pi - (z[0] + z[2] * ph.cos()));
        let ikh = Matrix3::identity() - k * h.transpose();
        pm = ikh * pm * ikh.transpose() + k * k.transpose() * cfg.r; // Joseph form
        if z[2] < 0.0 {
            z[2] = -z[2];
            z[1] += PI;
            let j = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
            pm = j * pm * j;
        }
        z[1] = crate::math::wrap_pi(z[1]);
        out.push([z[0], z[1], z[2]]);
    }
    Ok(out)
}

/// Optimiser of the likelihood.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Gradient ascent (E19): θ ← θ + β J with β = α/F_jj per component (the expected
    /// Fisher diagonal, ∝ N, so β ∝ 1/N) and α from the quadratic model along the step,
    /// halved until ln L increases.
    Gradient,
    /// Newton–Raphson (E20) with the observed Hessian, Fisher scoring where the Hessian is
    /// not negative definite, pseudo-inverse for singular directions, step halving until
    /// ln L increases.
    Newton,
}

impl crate::options::Choice for Method {
    const PARAMETER: &'static str = "method";
    const CHOICES: &'static [(&'static str, Self)] = &[("gradient", Method::Gradient), ("newton", Method::Newton)];
}

/// Most iterations of one ML estimate (Newton converges in tens; the gradient method in
/// hundreds to thousands).
pub const MAX_ML_ITER: usize = 100_000;

#[derive(Clone, Debug)]
pub struct MlConfig {
    pub method: Method,
    /// Which of (σ_p0, σ_φ, σ_A) are estimated; the others stay at `theta0`.
    pub free: [bool; 3],
    pub theta0: [f64; 3],
    pub max_iter: usize,
    /// Convergence: max relative change of the free θ below `tol`.
    pub tol: f64,
}

#[derive(Clone, Debug)]
pub struct MlResult {
    pub theta: [f64; 3],
    pub iterations: usize,
    pub converged: bool,
    pub log_likelihood: f64,
    /// Identifiable combinations a = σ_p0² + σ_A², b = Ā²σ_φ² − σ_A² (Ā = mean amplitude).
    pub a: f64,
    pub b: f64,
    /// Eigenvalues (ascending in magnitude) of the 3 × 3 Hessian of ln L w.r.t. (σ_p0², σ_φ², σ_A²)
    /// at the estimate: one is ≈ 0 (the unidentifiable direction).
    pub hessian_eigenvalues: [f64; 3],
    /// Standard errors of (σ_p0, σ_φ, σ_A) from the observed information of the free
    /// variances, (−H_ff)⁻¹, by the delta method σ(θ) = σ(θ²)/(2θ); 0 for a component
    /// held fixed, +∞ where the information is not positive definite (an estimate on the
    /// boundary).
    pub se_theta: [f64; 3],
    /// Standard errors of the identifiable a and b from the same covariance.
    pub se_a: f64,
    pub se_b: f64,
}

struct Data<'a> {
    x: &'a [f64],
    c: Vec<[f64; 3]>,
}

// invariant: c has one row per sample of x (built so in ml_identify), i < x.len(),
// and j, m < 3 index its fixed-size rows and the 3-vectors θ, g, h, f.
#[allow(clippy::indexing_slicing)]
impl Data<'_> {
    fn var(&self, i: usize, th: &[f64; 3]) -> f64 {
        (0..3).map(|j| self.c[i][j] * th[j] * th[j]).sum()
    }
    /// ln L (E18) without the constant.
    fn loglik(&self, th: &[f64; 3]) -> f64 {
        (0..self.x.len())
            .map(|i| {
                let s2 = self.var(i, th);
                -0.5 * s2.ln() - self.x[i] * self.x[i] / (2.0 * s2)
            })
            .sum()
    }
    /// Gradient J (E19), observed Hessian (E20) and expected Fisher information in θ.
    fn derivatives(&self, th: &[f64; 3]) -> (Vector3<f64>, Matrix3<f64>, Matrix3<f64>) {
        let mut g = Vector3::zeros();
        let mut h = Matrix3::zeros();
        let mut f = Matrix3::zeros();
        for i in 0..self.x.len() {
            let s2 = self.var(i, th);
            let x2 = self.x[i] * self.x[i];
            let u = x2 / (s2 * s2) - 1.0 / s2;
            let w = 1.0 / (s2 * s2) - 2.0 * x2 / (s2 * s2 * s2);
            for j in 0..3 {
                let dj = self.c[i][j] * th[j];
                g[j] += u * dj;
                h[(j, j)] += u * self.c[i][j];
                for m in 0..3 {
                    let dm = self.c[i][m] * th[m];
                    h[(j, m)] += 2.0 * w * dj * dm;
                    f[(j, m)] += 2.0 * dj * dm / (s2 * s2);
                }
            }
        }
        (g, h, f)
    }
}

/// Maximum-likelihood (σ_p0, σ_φ, σ_A) from residuals `x`, fringe phases `phi` (rad) and
/// amplitudes `amp` (one per sample). All three free is rejected: they are not jointly
/// identifiable (only a, b are).
// invariant: free holds indices j < 3 of the fixed-size θ arrays and 3-vectors;
// r < free.len(), the size of gs, hs, fs, d and step; the 3 × 3 Hessian has 3 eigenvalues.
#[allow(clippy::indexing_slicing)]
pub fn ml_identify(x: &[f64], phi: &[f64], amp: &[f64], cfg: &MlConfig) -> Result<MlResult> {
    let n = x.len();
    check_finite("x", x, 1)?;
    check_finite("phi", phi, 1)?;
    check_finite("amplitude", amp, 1)?;
    if phi.len() != n || amp.len() != n {
        return Err(invalid("phi", format!("phi ({}) and amplitude ({}) must have the length of x ({n})", phi.len(), amp.len())));
    }
    if n < 3 {
        return Err(invalid("x", format!("need at least 3 samples, got {n}")));
    }
    if cfg.free.iter().all(|&f| f) {
        return Err(invalid(
            "free",
            "(sigma_p0, sigma_phi, sigma_A) are jointly unidentifiable: the residual variance is a + b sin^2(phi) with \
             a = sigma_p0^2 + sigma_A^2, b = A^2 sigma_phi^2 - sigma_A^2; fix one component (e.g. sigma_A)",
        ));
    }
    if !cfg.free.iter().any(|&f| f) {
        return Err(invalid("free", "at least one component must be free"));
    }
    for (j, &t) in cfg.theta0.iter().enumerate() {
        if !t.is_finite() || t < 0.0 || (cfg.free[j] && t == 0.0) {
            return Err(invalid("theta0", format!("component {j} must be finite, >= 0 (> 0 when free), got {t}")));
        }
    }
    let data = Data { x, c: amp.iter().zip(phi).map(|(&a, &ph)| [1.0, (a * ph.sin()).powi(2), ph.cos().powi(2)]).collect() };
    if (0..n).any(|i| data.var(i, &cfg.theta0) <= 0.0) {
        return Err(invalid("theta0", "start value gives zero variance for some samples"));
    }
    let free: Vec<usize> = (0..3).filter(|&j| cfg.free[j]).collect();
    let sub = |v: &Vector3<f64>| DVector::from_iterator(free.len(), free.iter().map(|&j| v[j]));
    let subm = |m: &Matrix3<f64>| DMatrix::from_fn(free.len(), free.len(), |r, c| m[(free[r], free[c])]);
    let mut th = cfg.theta0;
    let mut ll = data.loglik(&th);
    let mut converged = false;
    let mut iterations = 0;
    while iterations < cfg.max_iter {
        iterations += 1;
        let (g, h, fi) = data.derivatives(&th);
        let (gs, hs, fs) = (sub(&g), subm(&h), subm(&fi));
        let step: DVector<f64> = match cfg.method {
            Method::Gradient => {
                let d = DVector::from_fn(free.len(), |r, _| gs[r] / fs[(r, r)]);
                // α maximising the quadratic model ln L(θ + αd) ≈ ln L + α Jᵀd − ½α² dᵀFd.
                let alpha = gs.dot(&d) / (d.transpose() * &fs * &d)[0];
                d * alpha
            }
            Method::Newton => {
                let neg_def = hs.clone().symmetric_eigen().eigenvalues.iter().all(|&e| e < 0.0);
                let m = if neg_def { -hs } else { fs };
                // damped pseudo-inverse (docs/departures.md#identifiable-readout-noise):
                // singular directions (a component at 0) get no step
                let svd = m.svd(true, true);
                let eps = 1e-12 * svd.singular_values.max();
                svd.solve(&gs, eps).map_err(|e| NavError::Numerical(format!("ML Newton step: {e}")))?
            }
        };
        let mut scale = 1.0;
        let (mut new_th, mut new_ll);
        loop {
            new_th = th;
            for (r, &j) in free.iter().enumerate() {
                new_th[j] = (th[j] + scale * step[r]).abs();
            }
            new_ll = data.loglik(&new_th);
            if new_ll.is_finite() && new_ll >= ll - 1e-12 * ll.abs() {
                break;
            }
            scale *= 0.5;
            if scale < 1e-10 {
                return Err(NavError::Numerical("ML: no ascent step found".into()));
            }
        }
        let change = free.iter().map(|&j| (new_th[j] - th[j]).abs() / new_th[j].max(1e-300)).fold(0.0, f64::max);
        th = new_th;
        ll = new_ll;
        if change < cfg.tol {
            converged = true;
            break;
        }
    }
    // Hessian w.r.t. the variances s_j = θ_j²: ∂²lnL/∂s_j∂s_m = Σ (1/(2σ⁴) − x²/σ⁶) c_ij c_im.
    let mut hv = Matrix3::zeros();
    for (xi, ci) in x.iter().zip(&data.c) {
        let c = Vector3::from(*ci);
        let s2: f64 = (0..3).map(|j| c[j] * th[j] * th[j]).sum();
        let w = 0.5 / (s2 * s2) - xi * xi / (s2 * s2 * s2);
        hv += w * c * c.transpose();
    }
    let mut eig: Vec<f64> = hv.symmetric_eigen().eigenvalues.iter().copied().collect();
    eig.sort_by(|p, q| p.abs().total_cmp(&q.abs()));
    let a_mean2 = (amp.iter().sum::<f64>() / n as f64).powi(2);
    let cov = free_variance_covariance(&hv, &free);
    let se_theta = std::array::from_fn(|j| match &cov {
        Some(c) => if c[(j, j)] > 0.0 { c[(j, j)].sqrt() / (2.0 * th[j]) } else { 0.0 },
        None => if free.contains(&j) { f64::INFINITY } else { 0.0 },
    });
    // a = s₀ + s₂, b = Ā² s₁ − s₂ in the variances s = θ²
    let linear = |w: Vector3<f64>| cov.as_ref().map_or(f64::INFINITY, |c| (w.transpose() * c * w)[(0, 0)].max(0.0).sqrt());
    let (se_a, se_b) = (linear(Vector3::new(1.0, 0.0, 1.0)), linear(Vector3::new(0.0, a_mean2, -1.0)));
    Ok(MlResult {
        theta: th,
        iterations,
        converged,
        log_likelihood: ll - 0.5 * n as f64 * (2.0 * PI).ln(),
        a: th[0] * th[0] + th[2] * th[2],
        b: a_mean2 * th[1] * th[1] - th[2] * th[2],
        hessian_eigenvalues: [eig[0], eig[1], eig[2]],
        se_theta,
        se_a,
        se_b,
    })
}

/// Covariance of the variances (σ_p0², σ_φ², σ_A²) from the observed information
/// (−H)⁻¹ restricted to the `free` ones (zero rows and columns for the fixed ones); None
/// when that information is not positive definite.
// invariant: free holds indices < 3 of the 3 × 3 matrices; r, k < free.len().
#[allow(clippy::indexing_slicing)]
fn free_variance_covariance(hv: &Matrix3<f64>, free: &[usize]) -> Option<Matrix3<f64>> {
    let k = free.len();
    let info = nalgebra::DMatrix::from_fn(k, k, |r, c| -hv[(free[r], free[c])]);
    let inv = info.cholesky()?.inverse();
    let mut cov = Matrix3::zeros();
    for r in 0..k {
        for c in 0..k {
            cov[(free[r], free[c])] = inv[(r, c)];
        }
    }
    Some(cov)
}

/// ML over consecutive batches of `batch` samples (each from `cfg.theta0`), or over a
/// sliding window of `batch` samples ending at every sample from `batch − 1` on, each
/// warm-started from the previous estimate (`sliding`; free components floored at 10 % of
/// `cfg.theta0`).
pub fn ml_windows(x: &[f64], phi: &[f64], amp: &[f64], cfg: &MlConfig, batch: usize, sliding: bool) -> Result<Vec<MlResult>> {
    if batch < 3 || batch > x.len() {
        return Err(invalid("batch", format!("must be in [3, {}], got {batch}", x.len())));
    }
    if phi.len() != x.len() || amp.len() != x.len() {
        return Err(invalid("phi", format!("phi ({}) and amplitude ({}) must have the length of x ({})", phi.len(), amp.len(), x.len())));
    }
    let mut out = Vec::new();
    if sliding {
        let mut c = cfg.clone();
        for ((xw, pw), aw) in x.windows(batch).zip(phi.windows(batch)).zip(amp.windows(batch)) {
            let r = ml_identify(xw, pw, aw, &c)?;
            // warm start, floored at 10 % of the initial value: J_j ∝ θ_j, so a component
            // that reached the boundary 0 in one window could never leave it again
            for ((t0, &free), (&rj, &init)) in c.theta0.iter_mut().zip(&cfg.free).zip(r.theta.iter().zip(&cfg.theta0)) {
                *t0 = if free { rj.max(0.1 * init) } else { init };
            }
            out.push(r);
        }
    } else {
        for ((xw, pw), aw) in x.chunks_exact(batch).zip(phi.chunks_exact(batch)).zip(amp.chunks_exact(batch)) {
            out.push(ml_identify(xw, pw, aw, cfg)?);
        }
    }
    Ok(out)
}
