//! Mount calibration C = C_MF^VF from pairs of attitude increments (Vasilyuk et al. 2024 §3):
//! identifiability, closed-form start, Gauss–Newton on SO(3), the sandwich
//! covariance P_β, P^clb, P^mfa and the dead-reckoning consistency check.

use super::{d1, d2, euler_dcm, euler_from_dcm, nearest_rotation, rotation_angle, vee};
use crate::error::{check_positive, invalid, NavError, Result};
use crate::options::Choice;
use crate::math::{dcm_from_rotvec, rotvec_from_dcm, skew, Mat3, Vec3};
use super::increments::Mat39;
use nalgebra::{SMatrix, SymmetricEigen};

/// κ below which a trajectory cannot determine the mount, and below which it is weak (D16).
pub const KAPPA_REJECT: f64 = 1e-12;
pub const KAPPA_WARN: f64 = 1e-4;
/// Rotation threshold of the paper's criterion (0.5°) and the axis cluster radius (5°) (E15).
pub const ROTATION_THRESHOLD: f64 = 0.5 * std::f64::consts::PI / 180.0;
pub const CLUSTER_RADIUS: f64 = 5.0 * std::f64::consts::PI / 180.0;
/// Largest accepted |f_n| / chord(φ_n) over intervals rotating ≥ 0.5°: a stationary point
/// of the cost with a larger misfit is a wrong local minimum, reported as non-convergence.
pub const MAX_RELATIVE_MISFIT: f64 = 0.05;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    Ok,
    Warn,
    Reject,
}

impl Choice for Verdict {
    const PARAMETER: &'static str = "verdict";
    const CHOICES: &'static [(&'static str, Self)] = &[("ok", Verdict::Ok), ("warn", Verdict::Warn), ("reject", Verdict::Reject)];
}

/// E15: how well a set of astro increments determines the mount.
#[derive(Debug, Clone)]
pub struct Observability {
    /// Unit rotation axis k_n of every ΔS_n^avu in VF (zero for a null rotation) and φ_n (rad).
    pub axes_vf: Vec<Vec3>,
    pub angles: Vec<f64>,
    /// Cluster label of every interval with φ_n ≥ 0.5° (−1 otherwise); axes are lines, 5° radius.
    pub cluster: Vec<i64>,
    pub n_clusters: usize,
    /// Eigenvalues (ascending) and eigenvectors (columns) of G = Σ(I − ΔS)(I − ΔS)ᵀ.
    pub eigenvalues: Vec3,
    pub eigenvectors: Mat3,
    /// κ = λ_min/λ_max and the verdict of D16.
    pub kappa: f64,
    pub verdict: Verdict,
}

impl Observability {
    /// The weakest direction of the mount error θ^clb, in VF.
    pub fn weak_axis_vf(&self) -> Vec3 {
        self.eigenvectors.column(0).into_owned()
    }
}

/// Symmetric eigen-decomposition with ascending eigenvalues.
// invariant: idx is a permutation of 0..3 indexing the 3 eigenvalues and eigenvectors.
#[allow(clippy::indexing_slicing)]
fn sorted_eigen(m: &Mat3) -> (Vec3, Mat3) {
    let e = SymmetricEigen::new(*m);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    let vals = Vec3::new(e.eigenvalues[idx[0]], e.eigenvalues[idx[1]], e.eigenvalues[idx[2]]);
    let vecs = Mat3::from_columns(&[e.eigenvectors.column(idx[0]), e.eigenvectors.column(idx[1]), e.eigenvectors.column(idx[2])]);
    (vals, vecs)
}

/// Identifiability of the mount from the astro increments.
pub fn observability(ds_avu: &[Mat3]) -> Observability {
    let mut g = Mat3::zeros();
    let mut axes = Vec::with_capacity(ds_avu.len());
    let mut angles = Vec::with_capacity(ds_avu.len());
    let mut reps: Vec<Vec3> = Vec::new();
    let mut cluster = Vec::with_capacity(ds_avu.len());
    for s in ds_avu {
        let d = Mat3::identity() - s;
        g += d * d.transpose();
        let v = vee(s);
        let phi = rotation_angle(s);
        let k = if v.norm() > 0.0 { v / v.norm() } else { Vec3::zeros() };
        axes.push(k);
        angles.push(phi);
        cluster.push(if phi < ROTATION_THRESHOLD {
            -1
        } else {
            match reps.iter().position(|c| c.dot(&k).abs() >= CLUSTER_RADIUS.cos()) {
                Some(i) => i as i64,
                None => {
                    reps.push(k);
                    (reps.len() - 1) as i64
                }
            }
        });
    }
    let (vals, vecs) = sorted_eigen(&g);
    let kappa = if vals.z > 0.0 { vals.x.max(0.0) / vals.z } else { 0.0 };
    let verdict = if kappa < KAPPA_REJECT {
        Verdict::Reject
    } else if kappa < KAPPA_WARN {
        Verdict::Warn
    } else {
        Verdict::Ok
    };
    Observability { axes_vf: axes, angles, cluster, n_clusters: reps.len(), eigenvalues: vals, eigenvectors: vecs, kappa, verdict }
}

/// f_n = vee(ΔS_n^avuᵀ Cᵀ ΔS_n^imu C − I).
pub fn residual(c: &Mat3, ds_imu: &Mat3, ds_avu: &Mat3) -> Vec3 {
    vee(&(ds_avu.transpose() * c.transpose() * ds_imu * c - Mat3::identity()))
}

/// ∂f_n/∂θ for C → C exp([θ×]): column i = vee(ΔS_aᵀ(−[e_i×]M + M[e_i×])), M = CᵀΔS_iC (E17).
pub fn jacobian_block(c: &Mat3, ds_imu: &Mat3, ds_avu: &Mat3) -> Mat3 {
    let m = c.transpose() * ds_imu * c;
    let at = ds_avu.transpose();
    let cols: Vec<Vec3> = (0..3)
        .map(|i| {
            let e = skew(&Vec3::ith(i, 1.0));
            vee(&(at * (m * e - e * m)))
        })
        .collect();
    Mat3::from_columns(&cols)
}

/// Closed-form start: Wahba/SVD on (log ΔS_n^imu, log ΔS_n^avu), since v_imu = C v_avu (E17).
pub fn initial_alignment(ds_imu: &[Mat3], ds_avu: &[Mat3]) -> Mat3 {
    let b: Mat3 = ds_imu.iter().zip(ds_avu).map(|(i, a)| rotvec_from_dcm(i) * rotvec_from_dcm(a).transpose()).sum();
    nearest_rotation(&b)
}

/// Start of Gauss–Newton.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Init {
    /// Closed-form alignment of rotation axes (default).
    Axes,
    /// The paper's β0 = 0.
    Zero,
    /// A user rotation C_MF^VF.
    Given(Mat3),
}

/// The name of an [`Init`] (`init="axes"`); "given" takes its rotation from `c0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Start {
    Axes,
    Zero,
    Given,
}

impl Choice for Start {
    const PARAMETER: &'static str = "init";
    const CHOICES: &'static [(&'static str, Self)] = &[("axes", Start::Axes), ("zero", Start::Zero), ("given", Start::Given)];
}

impl Init {
    /// The start named `start` for a call that takes no starting rotation ("axes" or "zero").
    pub fn named(start: Start) -> Result<Init> {
        match start {
            Start::Given => Err(invalid("init", "'given' needs a starting rotation c0, which this call does not take; choose axes or zero")),
            _ => Init::new(start, None),
        }
    }

    /// The start named `start`; `c0` (a rotation) is required by "given" and refused otherwise.
    pub fn new(start: Start, c0: Option<Mat3>) -> Result<Init> {
        match (start, c0) {
            (Start::Axes, None) => Ok(Init::Axes),
            (Start::Zero, None) => Ok(Init::Zero),
            (Start::Given, Some(c)) => Ok(Init::Given(c)),
            (Start::Given, None) => Err(invalid("c0", "init='given' needs the starting rotation c0")),
            (_, Some(_)) => Err(invalid("c0", format!("c0 is only used with init='given', got init={:?}", start.name()))),
        }
    }
}

/// Residual covariance P_S of E18: the full 3×3 (default) or its diagonal (D6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResidualForm {
    Full,
    Diagonal,
}

impl Choice for ResidualForm {
    const PARAMETER: &'static str = "residual_form";
    const CHOICES: &'static [(&'static str, Self)] = &[("full", ResidualForm::Full), ("diagonal", ResidualForm::Diagonal)];
}

/// Gauss–Newton parametrisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solver {
    /// C_j = C_{j−1} exp([Δθ×]) with the analytic Jacobian (default).
    So3,
    /// The paper's β_j = β_{j−1} − (HᵀH)⁻¹Hᵀf with a central-difference Jacobian in β.
    PaperEuler,
}

impl Choice for Solver {
    const PARAMETER: &'static str = "solver";
    const CHOICES: &'static [(&'static str, Self)] = &[("so3", Solver::So3), ("paper_euler", Solver::PaperEuler)];
}

/// How the mount covariance P_β is formed (docs/departures.md#correlated-increment-residuals).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CovarianceForm {
    /// The sandwich with Σ_f from the given error covariances E_n^imu, P_j^avu, including
    /// the neighbour blocks of shared star epochs ([`model_covariance`]).
    Model,
    /// The same structure with one star-attitude covariance P̂ and one gyro-increment
    /// covariance Q̂ estimated from the residuals ([`residual_covariance`]).
    Residual,
    /// The paper's sandwich with P_S, increments taken as independent (Vasilyuk et al. 2024, E18).
    PaperSandwich,
}

impl Choice for CovarianceForm {
    const PARAMETER: &'static str = "covariance";
    const CHOICES: &'static [(&'static str, Self)] =
        &[("model", CovarianceForm::Model), ("residual", CovarianceForm::Residual), ("paper_sandwich", CovarianceForm::PaperSandwich)];
}

/// Error covariances of the increments: E_n^imu (MF, rad², one per interval), P_j^avu (VF,
/// rad², one per epoch) and, in the consistent gyro mode, the constant errors.
#[derive(Clone, Copy)]
pub struct IncrementErrors<'a> {
    pub e_imu: &'a [Mat3],
    pub p_avu: &'a [Mat3],
    pub constant: Option<&'a ConstantGyroErrors<'a>>,
}

impl<'a> IncrementErrors<'a> {
    /// The error models as given: E^imu and P^avu together or neither, and the constant
    /// gyro errors only with them.
    pub fn given(e_imu: Option<&'a [Mat3]>, p_avu: Option<&'a [Mat3]>, constant: Option<&'a ConstantGyroErrors<'a>>) -> Result<Option<Self>> {
        match (e_imu, p_avu) {
            (Some(e_imu), Some(p_avu)) => Ok(Some(IncrementErrors { e_imu, p_avu, constant })),
            (None, None) if constant.is_none() => Ok(None),
            (None, None) => Err(invalid("e_imu", "the constant gyro errors j_m, j_b need e_imu and p_avu")),
            (None, Some(_)) => Err(invalid("e_imu", "give e_imu with p_avu")),
            (Some(_), None) => Err(invalid("p_avu", "give p_avu with e_imu")),
        }
    }
}

#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub init: Init,
    pub solver: Solver,
    pub max_iter: usize,
    /// Stop when ‖Δθ‖ (SO(3)) or ‖Δβ‖ (Euler) ≤ tol (rad) (paper: 1e-9).
    pub tol: f64,
    pub residual_form: ResidualForm,
    /// How P_β is formed; `None` picks `Model` when the error covariances are given and
    /// `Residual` otherwise.
    pub covariance: Option<CovarianceForm>,
}

impl Default for Options {
    fn default() -> Self {
        Self { init: Init::Axes, solver: Solver::So3, max_iter: 50, tol: 1e-9, residual_form: ResidualForm::Full, covariance: None }
    }
}

impl Options {
    /// Checked options: at least one iteration, a finite positive tolerance (rad).
    pub fn new(init: Init, solver: Solver, max_iter: usize, tol: f64, residual_form: ResidualForm) -> Result<Options> {
        if max_iter == 0 {
            return Err(invalid("max_iter", "must be ≥ 1"));
        }
        check_positive("tol", tol)?;
        Ok(Options { init, solver, max_iter, tol, residual_form, covariance: None })
    }
}

#[derive(Debug, Clone)]
pub struct Calibration {
    /// C_MF^VF (maps VF into MF) and its canonical Euler angles β (rad) (D3).
    pub c: Mat3,
    pub beta: Vec3,
    pub iterations: usize,
    /// f_n at the solution (rad) and the largest |f_n|/chord(φ_n) of rotating intervals.
    pub residuals: Vec<Vec3>,
    pub relative_misfit: f64,
    /// P_S (rad²), P_θ of θ^clb (rad², VF), P_β (rad²), P^clb = D2 P_β D2ᵀ (rad², MF) (E18, Eq. 8).
    pub p_s: Mat3,
    pub p_theta: Mat3,
    pub p_beta: Mat3,
    pub p_clb: Mat3,
    /// The form P_θ, P_β and P^clb were computed in.
    pub covariance: CovarianceForm,
    /// Singular values of the stacked Jacobian H at the solution (descending) and their ratio.
    pub singular_values: Vec3,
    pub condition_number: f64,
    /// The weakest direction of θ^clb in MF (C times the VF one) and σ_weak = σ̂_f/√λ_min(G)
    /// (rad) with σ̂_f² = tr P_S / 3 (E15).
    pub weak_axis_mf: Vec3,
    pub sigma_weak: f64,
    pub observability: Observability,
}

/// Pairs of increments: equal, non-zero counts of rotation matrices.
pub fn check_increments(ds_imu: &[Mat3], ds_avu: &[Mat3]) -> Result<()> {
    if ds_imu.len() != ds_avu.len() {
        return Err(invalid("ds_avu", format!("expected {} increments like ds_imu, got {}", ds_imu.len(), ds_avu.len())));
    }
    if ds_imu.is_empty() {
        return Err(invalid("ds_imu", "need at least one increment"));
    }
    for (i, (a, b)) in ds_imu.iter().zip(ds_avu).enumerate() {
        crate::math::check_rotation("ds_imu", i, a)?;
        crate::math::check_rotation("ds_avu", i, b)?;
    }
    Ok(())
}

/// Normal equations Σ H_nᵀH_n and Σ H_nᵀf_n at C.
fn normal_equations(c: &Mat3, ds_imu: &[Mat3], ds_avu: &[Mat3]) -> (Mat3, Vec3) {
    let mut a = Mat3::zeros();
    let mut g = Vec3::zeros();
    for (i, s) in ds_imu.iter().zip(ds_avu) {
        let h = jacobian_block(c, i, s);
        a += h.transpose() * h;
        g += h.transpose() * residual(c, i, s);
    }
    (a, g)
}

/// The paper's Euler-angle Jacobian by central differences, step dx = 1e-6 rad (E17, D8):
/// H_n[:, χ] = [f_n(β + ½dx e_χ) − f_n(β − ½dx e_χ)]/dx; normal equations as above.
fn normal_equations_euler_fd(beta: &Vec3, ds_imu: &[Mat3], ds_avu: &[Mat3]) -> (Mat3, Vec3) {
    const DX: f64 = 1e-6;
    let cs: Vec<(Mat3, Mat3)> = (0..3).map(|i| (euler_dcm(&(beta + Vec3::ith(i, DX / 2.0))), euler_dcm(&(beta - Vec3::ith(i, DX / 2.0))))).collect();
    let c = euler_dcm(beta);
    let mut a = Mat3::zeros();
    let mut g = Vec3::zeros();
    for (i, s) in ds_imu.iter().zip(ds_avu) {
        let cols: Vec<Vec3> = cs.iter().map(|(p, m)| (residual(p, i, s) - residual(m, i, s)) / DX).collect();
        let h = Mat3::from_columns(&cols);
        a += h.transpose() * h;
        g += h.transpose() * residual(&c, i, s);
    }
    (a, g)
}

/// Gauss–Newton on SO(3) without error covariances: [`calibrate_with`] with `None`.
pub fn calibrate(ds_imu: &[Mat3], ds_avu: &[Mat3], opt: &Options) -> Result<Calibration> {
    calibrate_with(ds_imu, ds_avu, opt, None)
}

/// The covariance form of a call: `opt.covariance`, or `Model` when `errors` are given and
/// `Residual` otherwise; the error covariances are checked against the M increments.
fn covariance_form(opt: &Options, errors: Option<&IncrementErrors>, m: usize) -> Result<CovarianceForm> {
    let form = match (opt.covariance, errors) {
        (None | Some(CovarianceForm::Model), Some(_)) => CovarianceForm::Model,
        (None, None) => CovarianceForm::Residual,
        (Some(CovarianceForm::Model), None) => return Err(invalid("e_imu", "covariance='model' needs the error covariances e_imu and p_avu")),
        (Some(f), Some(_)) => return Err(invalid("e_imu", format!("e_imu and p_avu are only used with covariance='model', got covariance={:?}", f.name()))),
        (Some(f), None) => f,
    };
    if let Some(e) = errors {
        super::stars::check_covariances("e_imu", e.e_imu, m)?;
        super::stars::check_covariances("p_avu", e.p_avu, m + 1)?;
        if let Some(k) = e.constant {
            if k.sensitivities.len() != m {
                return Err(invalid("j_m", format!("expected {m} sensitivities, got {}", k.sensitivities.len())));
            }
        }
    }
    Ok(form)
}

/// Gauss–Newton on SO(3): C_j = C_{j−1} exp([Δθ×]), Δθ = −(HᵀH)⁻¹Hᵀf, stop at ‖Δθ‖ ≤ tol
/// (Vasilyuk et al. 2024 §3), then P_θ in the form of [`covariance_form`]: the model
/// sandwich of `errors`, the residual estimate of the same structure, or the paper's
/// sandwich (docs/departures.md#correlated-increment-residuals).
///
/// Errors: an unobservable trajectory (κ < 1e-12, the null direction named) is
/// `InvalidInput`; no convergence within `max_iter`, or convergence to a point whose
/// residuals are not small against the rotations (a wrong local minimum), is `Numerical`.
pub fn calibrate_with(ds_imu: &[Mat3], ds_avu: &[Mat3], opt: &Options, errors: Option<&IncrementErrors>) -> Result<Calibration> {
    check_increments(ds_imu, ds_avu)?;
    let form = covariance_form(opt, errors, ds_imu.len())?;
    if let Init::Given(c) = opt.init {
        crate::math::check_rotation("c0", 0, &c)?;
    }
    let obs = observability(ds_avu);
    if obs.verdict == Verdict::Reject {
        let k = obs.weak_axis_vf();
        return Err(invalid(
            "increments",
            format!(
                "mount unobservable: κ = {:.3e} < {KAPPA_REJECT:e} (rank-deficient Jacobian), null direction ({:.6}, {:.6}, {:.6}) in VF; {} axis cluster(s) of rotations ≥ 0.5°, need 2",
                obs.kappa, k.x, k.y, k.z, obs.n_clusters
            ),
        ));
    }
    let mut c = match opt.init {
        Init::Axes => initial_alignment(ds_imu, ds_avu),
        Init::Zero => Mat3::identity(),
        Init::Given(c) => c,
    };
    let mut iterations = None;
    let mut beta = euler_from_dcm(&c);
    for it in 1..=opt.max_iter {
        let (a, g) = match opt.solver {
            Solver::So3 => normal_equations(&c, ds_imu, ds_avu),
            Solver::PaperEuler => normal_equations_euler_fd(&beta, ds_imu, ds_avu),
        };
        let dth = match a.cholesky() {
            Some(ch) => -ch.solve(&g),
            None => return Err(NavError::Numerical(format!("Gauss–Newton: singular HᵀH at iteration {it}"))),
        };
        match opt.solver {
            Solver::So3 => c *= dcm_from_rotvec(&dth),
            Solver::PaperEuler => {
                beta += dth;
                c = euler_dcm(&beta);
            }
        }
        if !dth.norm().is_finite() {
            return Err(NavError::Numerical(format!("Gauss–Newton: non-finite step at iteration {it}")));
        }
        if dth.norm() <= opt.tol {
            iterations = Some(it);
            break;
        }
    }
    let Some(iterations) = iterations else {
        return Err(NavError::Numerical(format!("Gauss–Newton did not converge in {} iterations (tolerance {:e} rad)", opt.max_iter, opt.tol)));
    };
    let c = nearest_rotation(&c);
    let residuals: Vec<Vec3> = ds_imu.iter().zip(ds_avu).map(|(i, a)| residual(&c, i, a)).collect();
    let relative_misfit = residuals
        .iter()
        .zip(&obs.angles)
        .filter(|(_, &phi)| phi >= ROTATION_THRESHOLD)
        .map(|(f, &phi)| f.norm() / (2.0 * (0.5 * phi).sin()))
        .fold(0.0, f64::max);
    if relative_misfit > MAX_RELATIVE_MISFIT {
        return Err(NavError::Numerical(format!(
            "Gauss–Newton converged to a wrong stationary point (largest |f_n|/chord = {relative_misfit:.3} > {MAX_RELATIVE_MISFIT}); start from init='axes'"
        )));
    }
    // E18: P_S = (1/(N−1)) Σ f fᵀ (D6, D7)
    let m = residuals.len() as f64;
    let mut p_s: Mat3 = residuals.iter().map(|f| f * f.transpose()).sum::<Mat3>() / m;
    if opt.residual_form == ResidualForm::Diagonal {
        p_s = Mat3::from_diagonal(&p_s.diagonal());
    }
    let h = jacobian_blocks(&c, ds_imu, ds_avu);
    let a: Mat3 = h.iter().map(|h| h.transpose() * h).sum();
    let a_inv = a.try_inverse().ok_or_else(|| NavError::Numerical("singular HᵀH at the solution".into()))?;
    let p_theta = match (form, errors) {
        (CovarianceForm::Model, Some(e)) => model_theta(&c, &h, ds_avu, &a_inv, e).0,
        (CovarianceForm::Residual, _) => residual_theta(&h, &residuals, ds_avu, &a_inv),
        // the paper's sandwich, P_θ = (HᵀH)⁻¹(Σ H_nᵀ P_S H_n)(HᵀH)⁻¹ (E18)
        _ => a_inv * h.iter().map(|h| h.transpose() * p_s * h).sum::<Mat3>() * a_inv,
    };
    let beta = euler_from_dcm(&c);
    // θ = D1 δβ ⇒ P_β = D1⁻¹ P_θ D1⁻ᵀ; P^clb = D2 P_β D2ᵀ (Eq. 8)
    let p_beta = theta_to_beta(&beta, &p_theta)?;
    let p_clb = d2(&beta) * p_beta * d2(&beta).transpose();
    let (ev, _) = sorted_eigen(&a);
    let singular_values = Vec3::new(ev.z.max(0.0).sqrt(), ev.y.max(0.0).sqrt(), ev.x.max(0.0).sqrt());
    Ok(Calibration {
        c,
        beta,
        iterations,
        residuals,
        relative_misfit,
        p_s,
        p_theta,
        p_beta,
        p_clb,
        covariance: form,
        condition_number: singular_values.x / singular_values.z,
        singular_values,
        weak_axis_mf: c * obs.weak_axis_vf(),
        sigma_weak: (p_s.trace() / 3.0).sqrt() / obs.eigenvalues.x.max(0.0).sqrt(),
        observability: obs,
    })
}

/// The Jacobian blocks H_n of every increment pair at C.
fn jacobian_blocks(c: &Mat3, ds_imu: &[Mat3], ds_avu: &[Mat3]) -> Vec<Mat3> {
    ds_imu.iter().zip(ds_avu).map(|(i, a)| jacobian_block(c, i, a)).collect()
}

/// P_β = D1⁻¹ P_θ D1⁻ᵀ at the Euler angles β (Eq. 8).
fn theta_to_beta(beta: &Vec3, p_theta: &Mat3) -> Result<Mat3> {
    let d1_inv = d1(beta).try_inverse().ok_or_else(|| NavError::Numerical("Euler angles at gimbal lock (|ϑ| = 90°)".into()))?;
    Ok(d1_inv * p_theta * d1_inv.transpose())
}

/// The nearest positive semi-definite matrix of the symmetric part of `m` (negative
/// eigenvalues set to zero).
fn psd_part(m: &Mat3) -> Mat3 {
    let e = SymmetricEigen::new(0.5 * (m + m.transpose()));
    e.eigenvectors * Mat3::from_diagonal(&e.eigenvalues.map(|x| x.max(0.0))) * e.eigenvectors.transpose()
}

/// The two parts of HᵀΣ_fH for Σ_f of independent gyro increments with VF covariances
/// `gyro(n)` and star attitudes with covariances `p(j)` shared by neighbouring increments
/// (E13): the gyro part Σ H_nᵀ gyro(n) H_n and the star part
/// Σ H_nᵀ(P_{n+1} + ΔS_nᵀP_nΔS_n)H_n + Σ [H_nᵀ(−P_{n+1}ΔS_{n+1})H_{n+1} + transpose]
/// (= Σ_j L_jᵀP_jL_j with L_j = H_{j−1} − ΔS_jH_j, positive semi-definite).
// invariant: h and ds_avu have m entries (the callers' increments), p is read at j ≤ m;
// n + 1 < m where h[n + 1], ds_avu[n + 1] are read.
#[allow(clippy::indexing_slicing)]
fn score_covariance(h: &[Mat3], ds_avu: &[Mat3], gyro: impl Fn(usize) -> Mat3, p: impl Fn(usize) -> Mat3) -> (Mat3, Mat3) {
    let m = h.len();
    let (mut gyro_part, mut star) = (Mat3::zeros(), Mat3::zeros());
    for n in 0..m {
        gyro_part += h[n].transpose() * gyro(n) * h[n];
        star += h[n].transpose() * (p(n + 1) + ds_avu[n].transpose() * p(n) * ds_avu[n]) * h[n];
        if n + 1 < m {
            let x = h[n].transpose() * (-p(n + 1) * ds_avu[n + 1]) * h[n + 1];
            star += x + x.transpose();
        }
    }
    (gyro_part, star)
}

/// P_θ^model and its systematic part P_θ^sys (rad², VF) from the error covariances.
// invariant: e_imu and the sensitivities have h.len() entries, p_avu h.len() + 1
// (checked by the callers).
#[allow(clippy::indexing_slicing)]
fn model_theta(c: &Mat3, h: &[Mat3], ds_avu: &[Mat3], a_inv: &Mat3, errors: &IncrementErrors) -> (Mat3, Mat3) {
    let constant = errors.constant;
    // the constant part of E_n^imu enters through g_m, g_b below (all n, p pairs at once)
    let white = |n: usize| {
        let e = errors.e_imu[n];
        let e = match constant {
            Some(k) => {
                let (jm, jb) = &k.sensitivities[n];
                e - (jm * k.p_m * jm.transpose() + jb * jb.transpose() * k.sigma_b.powi(2))
            }
            None => e,
        };
        c.transpose() * e * c
    };
    let (gyro, star) = score_covariance(h, ds_avu, white, |j| errors.p_avu[j]);
    let p_sys = match constant {
        Some(k) => {
            let (mut g_m, mut g_b) = (SMatrix::<f64, 3, 9>::zeros(), Mat3::zeros());
            for (hn, (jm, jb)) in h.iter().zip(k.sensitivities) {
                g_m += hn.transpose() * c.transpose() * jm;
                g_b += hn.transpose() * c.transpose() * jb;
            }
            let (gm, gb) = (a_inv * g_m, a_inv * g_b);
            gm * k.p_m * gm.transpose() + gb * gb.transpose() * k.sigma_b.powi(2)
        }
        None => Mat3::zeros(),
    };
    (a_inv * (gyro + star) * a_inv + p_sys, p_sys)
}

/// P_θ from the residuals alone with the structure of [`model_covariance`]: one star-attitude
/// covariance P̂ (VF) from the lag-1 moment in the frame where it is constant,
/// E[f_n f_{n+1}ᵀ] ΔS_{n+1}ᵀ = −P, made positive semi-definite, and one gyro-increment
/// covariance Q̂ = mean(f_n f_nᵀ) − P̂ − mean(ΔS_nᵀP̂ΔS_n) (VF). Q̂ is the difference of
/// moments dominated by the star noise; when its part makes P_θ indefinite, the star
/// part alone (a lower bound, since the gyro part is positive semi-definite) is returned.
fn residual_theta(h: &[Mat3], f: &[Vec3], ds_avu: &[Mat3], a_inv: &Mat3) -> Mat3 {
    let m = f.len() as f64;
    let lag1: Mat3 = f.iter().zip(f.iter().skip(1)).zip(ds_avu.iter().skip(1)).map(|((a, b), s)| a * b.transpose() * s.transpose()).sum();
    let p_hat = if f.len() > 1 { psd_part(&(-lag1 / (m - 1.0))) } else { Mat3::zeros() };
    let lag0: Mat3 = f.iter().map(|x| x * x.transpose()).sum::<Mat3>() / m;
    let star0: Mat3 = ds_avu.iter().map(|s| s.transpose() * p_hat * s).sum::<Mat3>() / m;
    let q = lag0 - p_hat - star0;
    let q_hat = 0.5 * (q + q.transpose());
    let (gyro, star) = score_covariance(h, ds_avu, |_| q_hat, |_| p_hat);
    let full = a_inv * (gyro + star) * a_inv;
    if SymmetricEigen::new(full).eigenvalues.min() >= 0.0 {
        full
    } else {
        a_inv * star * a_inv
    }
}

/// Constant gyro errors of the consistent mode (E8): per-interval sensitivities
/// (J_m,n, J_b,n), P_m of vec_rowmajor(M_G) and σ_b (rad/s).
pub struct ConstantGyroErrors<'a> {
    pub sensitivities: &'a [(Mat39, Mat3)],
    pub p_m: SMatrix<f64, 9, 9>,
    pub sigma_b: f64,
}

/// The per-interval sensitivities (J_m,n, J_b,n) from the two stacks, of equal length.
pub fn sensitivity_pairs(j_m: Vec<Mat39>, j_b: Vec<Mat3>) -> Result<Vec<(Mat39, Mat3)>> {
    if j_m.len() != j_b.len() {
        return Err(invalid("j_b", format!("expected {} sensitivities like j_m, got {}", j_m.len(), j_b.len())));
    }
    Ok(j_m.into_iter().zip(j_b).collect())
}

/// Model-form covariance of β: P_β^model = (HᵀH)⁻¹HᵀΣ_fH(HᵀH)⁻¹ with Σ_f from the
/// error models — diagonal blocks CᵀE_n^imuC + E_n^avu, the E13 neighbour blocks
/// cov(ε_n, ε_{n+1}) = −P_n^avu ΔS_{n+1}, and with constant gyro errors the cross blocks
/// Cᵀ(J_m,n P_m J_m,pᵀ + J_b,n P_b J_b,pᵀ)C — and its systematic part
/// P_β^sys = G_mP_mG_mᵀ + G_bP_bG_bᵀ, G = −(HᵀH)⁻¹Σ_n H_nᵀCᵀJ_n. Returns (P_β^model, P_β^sys) in rad².
pub fn model_covariance(c: &Mat3, ds_imu: &[Mat3], ds_avu: &[Mat3], e_imu: &[Mat3], p_avu: &[Mat3], constant: Option<&ConstantGyroErrors>) -> Result<(Mat3, Mat3)> {
    let m = ds_imu.len();
    if ds_avu.len() != m {
        return Err(invalid("ds_avu", format!("expected {m} increments like ds_imu, got {}", ds_avu.len())));
    }
    if e_imu.len() != m || p_avu.len() != m + 1 {
        return Err(invalid("e_imu", format!("expected {m} interval covariances and {} epoch covariances", m + 1)));
    }
    if let Some(k) = constant.filter(|k| k.sensitivities.len() != m) {
        return Err(invalid("j_m", format!("expected {m} sensitivities, got {}", k.sensitivities.len())));
    }
    let h = jacobian_blocks(c, ds_imu, ds_avu);
    let a_inv = h.iter().map(|h| h.transpose() * h).sum::<Mat3>().try_inverse().ok_or_else(|| NavError::Numerical("singular HᵀH".into()))?;
    let (p_theta, p_sys) = model_theta(c, &h, ds_avu, &a_inv, &IncrementErrors { e_imu, p_avu, constant });
    let beta = euler_from_dcm(c);
    Ok((theta_to_beta(&beta, &p_theta)?, theta_to_beta(&beta, &p_sys)?))
}

/// P^mfa = C P^avu Cᵀ + P^clb: IMU attitude from stars through the calibrated mount (Eq. 8, E19).
pub fn p_mfa(c: &Mat3, p_avu: &Mat3, p_clb: &Mat3) -> Mat3 {
    c * p_avu * c.transpose() + p_clb
}

/// Form of P^diff.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiffForm {
    /// C P_n Cᵀ + Φ_nᵀ C P_1 Cᵀ Φ_n + (Φ_nᵀ − I) P^clb (Φ_n − I) + P_n^imu.
    Full,
    /// P_n^imu + P_n^mfa as in the paper.
    Paper,
}

impl Choice for DiffForm {
    const PARAMETER: &'static str = "p_diff";
    const CHOICES: &'static [(&'static str, Self)] = &[("full", DiffForm::Full), ("paper", DiffForm::Paper)];
}

/// Dead-reckoning check (E20): S_1^MF = S_1^VF Cᵀ (D9), S_n^MF = S_{n−1}^MF ΔS_n^imu,
/// θ_n^diff = vee((S_n^MF)ᵀ S_n^VF Cᵀ − I) and P_n^diff, for n = 2..N.
// invariant: s_vf, p_avu, p_imu have n ≥ 1 entries and ds_imu n − 1 (checked
// above); 1 ≤ k < n.
#[allow(clippy::indexing_slicing)]
pub fn dead_reckoning_check(
    c: &Mat3,
    s_vf: &[Mat3],
    ds_imu: &[Mat3],
    p_avu: &[Mat3],
    p_imu: &[Mat3],
    p_clb: &Mat3,
    form: DiffForm,
) -> Result<(Vec<Vec3>, Vec<Mat3>)> {
    let n = s_vf.len();
    if ds_imu.len() + 1 != n || p_avu.len() != n || p_imu.len() != n {
        return Err(invalid("ds_imu", format!("expected N − 1 = {} increments and N = {n} covariances", n.saturating_sub(1))));
    }
    let mut s_mf = s_vf[0] * c.transpose();
    let mut phi = Mat3::identity();
    let mut theta = Vec::with_capacity(n - 1);
    let mut cov = Vec::with_capacity(n - 1);
    let cp1 = c * p_avu[0] * c.transpose();
    for k in 1..n {
        s_mf *= ds_imu[k - 1];
        phi *= ds_imu[k - 1];
        theta.push(vee(&(s_mf.transpose() * s_vf[k] * c.transpose() - Mat3::identity())));
        let cpn = c * p_avu[k] * c.transpose();
        cov.push(match form {
            DiffForm::Full => {
                let d = phi - Mat3::identity();
                cpn + phi.transpose() * cp1 * phi + d.transpose() * p_clb * d + p_imu[k]
            }
            DiffForm::Paper => p_imu[k] + cpn + p_clb,
        });
    }
    Ok((theta, cov))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_rotation(rng: &mut ChaCha8Rng) -> Mat3 {
        // uniform on SO(3) through a uniform unit quaternion
        let g: [f64; 4] = std::array::from_fn(|_| rng.sample::<f64, _>(rand_distr::StandardNormal));
        let n = g.iter().map(|x| x * x).sum::<f64>().sqrt();
        crate::math::dcm_from_quat(&crate::math::quat(g[0] / n, g[1] / n, g[2] / n, g[3] / n))
    }

    /// Noise-free increments: ΔS^avu = Cᵀ ΔS^imu C for rotations about several MF axes.
    fn pairs(c: &Mat3, axes_mf: &[Vec3]) -> (Vec<Mat3>, Vec<Mat3>) {
        let imu: Vec<Mat3> = axes_mf.iter().map(dcm_from_rotvec).collect();
        let avu = imu.iter().map(|s| c.transpose() * s * c).collect();
        (imu, avu)
    }

    fn stand_like_axes() -> Vec<Vec3> {
        vec![
            Vec3::new(0.0, 0.0, 2.09),
            Vec3::new(0.0, 0.0, -1.4),
            Vec3::new(0.26, 0.0, 0.0),
            Vec3::new(0.0, 0.01, 2.7),
            Vec3::new(-0.26, 0.0, 0.05),
            Vec3::new(0.0, 0.0, 0.0015),
            Vec3::new(-0.12, 0.0, 0.0),
        ]
    }

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let h = 1e-6;
        for _ in 0..20 {
            let c = random_rotation(&mut rng);
            let (si, sa) = (random_rotation(&mut rng), random_rotation(&mut rng));
            let j = jacobian_block(&c, &si, &sa);
            for i in 0..3 {
                let e = Vec3::ith(i, h);
                let fd = (residual(&(c * dcm_from_rotvec(&e)), &si, &sa) - residual(&(c * dcm_from_rotvec(&-e)), &si, &sa)) / (2.0 * h);
                assert!((fd - j.column(i)).norm() < 1e-9, "{:e}", (fd - j.column(i)).norm());
            }
        }
    }

    #[test]
    fn q_about_increment_axis_commutes() {
        // E14: C̆Q with Q about the VF axis of ΔS^avu solves the same single-rotation equation.
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let c = random_rotation(&mut rng);
        let (imu, avu) = pairs(&c, &[Vec3::new(0.3, -0.5, 0.8)]);
        let k = rotvec_from_dcm(&avu[0]).normalize();
        for zeta in [0.3, 1.2, -2.0] {
            let q = dcm_from_rotvec(&(k * zeta));
            assert!((q * avu[0] - avu[0] * q).abs().max() < 1e-15);
            assert!(residual(&(c * q), &imu[0], &avu[0]).norm() < 1e-15);
        }
    }

    #[test]
    fn recovers_200_random_mounts_from_axes_and_detects_zero_start_failures() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut zero_ok = 0;
        for _ in 0..200 {
            let c = random_rotation(&mut rng);
            let (imu, avu) = pairs(&c, &stand_like_axes());
            let cal = calibrate(&imu, &avu, &Options::default()).unwrap();
            assert!(rotvec_from_dcm(&(cal.c.transpose() * c)).norm() < 1e-9);
            match calibrate(&imu, &avu, &Options { init: Init::Zero, ..Options::default() }) {
                Ok(z) => {
                    assert!(rotvec_from_dcm(&(z.c.transpose() * c)).norm() < 1e-9, "wrong answer reported as converged");
                    zero_ok += 1;
                }
                Err(NavError::Numerical(_)) => {}
                Err(e) => panic!("{e}"),
            }
        }
        assert!(zero_ok > 0 && zero_ok < 200, "{zero_ok}");
    }

    #[test]
    fn single_axis_and_static_are_unobservable() {
        let c = euler_dcm(&Vec3::new(0.17, -0.44, 0.035));
        for axes in [vec![Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -2.0)], vec![Vec3::new(0.0, 9e-4, 1.3e-3); 5]] {
            let (imu, avu) = pairs(&c, &axes);
            let e = calibrate(&imu, &avu, &Options::default()).unwrap_err();
            assert!(matches!(e, NavError::InvalidInput { .. }));
            // null direction = the common axis expressed in VF
            let k = (c.transpose() * axes[0]).normalize();
            let w = observability(&avu).weak_axis_vf();
            assert!(w.dot(&k).abs() > 1.0 - 1e-9, "{w:?} vs {k:?}");
            assert!(e.to_string().contains("null direction"));
        }
    }

    #[test]
    fn starts_and_options_are_checked() {
        let field = |r: Result<Init>| match r {
            Err(NavError::InvalidInput { field, .. }) => field,
            other => panic!("{other:?}"),
        };
        assert_eq!(Init::new(Start::parse("given").unwrap(), Some(Mat3::identity())).unwrap(), Init::Given(Mat3::identity()));
        assert_eq!(field(Init::new(Start::Given, None)), "c0");
        assert_eq!(field(Init::new(Start::Axes, Some(Mat3::identity()))), "c0");
        assert_eq!(field(Init::named(Start::Given)), "init");
        assert_eq!(Init::named(Start::Zero).unwrap(), Init::Zero);
        assert!(matches!(Options::new(Init::Axes, Solver::So3, 0, 1e-9, ResidualForm::Full), Err(NavError::InvalidInput { ref field, .. }) if field == "max_iter"));
        assert!(matches!(Options::new(Init::Axes, Solver::So3, 5, f64::NAN, ResidualForm::Full), Err(NavError::InvalidInput { ref field, .. }) if field == "tol"));
        for (e, p) in [(Solver::parse("lm").unwrap_err(), "solver"), (ResidualForm::parse("x").unwrap_err(), "residual_form"), (DiffForm::parse("x").unwrap_err(), "p_diff")] {
            assert!(matches!(e, NavError::InvalidInput { ref field, .. } if field == p), "{e}");
        }
        assert_eq!(Verdict::Warn.name(), "warn");
    }
}
