//! Gyro attitude increments between asynchronous camera epochs and their covariance
//! (Vasilyuk et al. 2024 §2.2).
//!
//! IMU record: increment `rho[j]` (rad, MF axes) covers [t_start + jT, t_start + (j+1)T].
//! Interval n runs from epoch t_{E,n−1} to t_{E,n}; its increment q_n maps MF at t_{E,n}
//! into MF at t_{E,n−1}: R(q_n) = ΔS_n^imu = S_{MF,n−1}^{MF,n}.

use crate::error::{check_increasing, check_positive, invalid, Result};
use crate::options::Choice;
use crate::math::{dcm_from_quat, quat, quat_normalize, skew, Mat3, Quat, Vec3};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// Scalar-part coefficient c of the E4 intra-sample quaternion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaylorVariant {
    /// c = 1/8: the third-order Picard expansion (project default).
    Corrected,
    /// c = 1/4 as printed in the paper.
    PaperLiteral,
}

impl Choice for TaylorVariant {
    const PARAMETER: &'static str = "taylor_variant";
    const CHOICES: &'static [(&'static str, Self)] = &[("corrected", Self::Corrected), ("paper_literal", Self::PaperLiteral)];
}

impl TaylorVariant {
    fn c(self) -> f64 {
        match self {
            Self::Corrected => 0.125,
            Self::PaperLiteral => 0.25,
        }
    }
}

/// How the constant gyro errors (M_G, δb_G) are propagated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GyroErrorMode {
    /// White from sample to sample (paper, E2/E7).
    Paper,
    /// Constant over the calibration: sensitivities J_m, J_b (E8).
    Consistent,
}

impl Choice for GyroErrorMode {
    const PARAMETER: &'static str = "gyro_error_model";
    const CHOICES: &'static [(&'static str, Self)] = &[("paper", Self::Paper), ("consistent", Self::Consistent)];
}

/// Gyro error budget of E1: σ_φG misalignment (rad), σ_kG scale factor (–), σ_wG angle
/// random walk (rad/√s), σ_bG bias (rad/s).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GyroErrorModel {
    pub sigma_phi: f64,
    pub sigma_k: f64,
    pub sigma_w: f64,
    pub sigma_b: f64,
    #[serde(with = "crate::options::by_name")]
    pub mode: GyroErrorMode,
}

pub type Mat39 = SMatrix<f64, 3, 9>;

impl GyroErrorModel {
    /// The paper's budget: 3″, 1e-5, 0.0012 °/√h, 0.007 °/h.
    pub fn vasilyuk2024(mode: GyroErrorMode) -> Self {
        use crate::units::{ARCSEC, DEG_PER_HOUR, DEG_PER_SQRT_HOUR};
        Self { sigma_phi: 3.0 * ARCSEC, sigma_k: 1e-5, sigma_w: 0.0012 * DEG_PER_SQRT_HOUR, sigma_b: 0.007 * DEG_PER_HOUR, mode }
    }

    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("sigma_phi", self.sigma_phi), ("sigma_k", self.sigma_k), ("sigma_w", self.sigma_w), ("sigma_b", self.sigma_b)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(name, format!("must be finite and ≥ 0, got {v}")));
            }
        }
        Ok(())
    }

    /// Per-sample covariance P_ρk of E2 at the measured increment ρ (rad²). It is diagonal;
    /// this is its diagonal.
    pub fn sample_var(&self, rho: &Vec3, period: f64) -> Vec3 {
        let (x2, y2, z2) = (rho.x * rho.x, rho.y * rho.y, rho.z * rho.z);
        let sp2 = self.sigma_phi * self.sigma_phi;
        let sk2 = self.sigma_k * self.sigma_k;
        let white = (self.sigma_b * period).powi(2) + self.sigma_w * self.sigma_w * period;
        Vec3::new(sp2 * (y2 + z2) + sk2 * x2 + white, sp2 * (x2 + z2) + sk2 * y2 + white, sp2 * (x2 + y2) + sk2 * z2 + white)
    }

    /// P_m = diag(σk², σφ², σφ², σφ², σk², σφ², σφ², σφ², σk²) of vec_rowmajor(M_G) (E8).
    pub fn p_m(&self) -> SMatrix<f64, 9, 9> {
        let (k, p) = (self.sigma_k.powi(2), self.sigma_phi.powi(2));
        SMatrix::<f64, 9, 9>::from_diagonal(&SMatrix::<f64, 9, 1>::from_column_slice(&[k, p, p, p, k, p, p, p, k]))
    }
}

/// (I − [ρ×]) E (I − [ρ×])ᵀ + diag(d) for symmetric E (E7, d the diagonal of the added
/// sample covariance): with S = [ρ×] and X = E S this is E + X + Xᵀ − S X (Sᵀ = −S, so
/// S E = −Xᵀ). Written out over the non-zero entries of S and the six unique entries of the
/// symmetric result: 30 multiplications instead of the 54 of two dense 3×3 products, and
/// three additions for the diagonal instead of nine for a dense sum (the hot loop of the
/// calibration benchmark).
#[inline(always)]
// invariant: fixed-size 3 × 3 and 3-arrays indexed by i, k < 3.
#[allow(clippy::indexing_slicing)]
fn transport(e: &Mat3, rho: &Vec3, d: &Vec3) -> Mat3 {
    let (x, y, z) = (rho.x, rho.y, rho.z);
    // X = E S, S columns (0, z, −y), (−z, 0, x), (y, −x, 0)
    let xm = |i: usize| [e[(i, 1)] * z - e[(i, 2)] * y, e[(i, 2)] * x - e[(i, 0)] * z, e[(i, 0)] * y - e[(i, 1)] * x];
    let (x0, x1, x2) = (xm(0), xm(1), xm(2));
    // (S X)[i, k]: rows of S (0, −z, y), (z, 0, −x), (−y, x, 0)
    let sx = |i: usize, k: usize| match i {
        0 => y * x2[k] - z * x1[k],
        1 => z * x0[k] - x * x2[k],
        _ => x * x1[k] - y * x0[k],
    };
    let xr = [x0, x1, x2];
    let r = |i: usize, k: usize| e[(i, k)] + xr[i][k] + xr[k][i] - sx(i, k);
    let (a, b, c, m, f, g) = (r(0, 0) + d.x, r(0, 1), r(0, 2), r(1, 1) + d.y, r(1, 2), r(2, 2) + d.z);
    Mat3::new(a, b, c, b, m, f, c, f, g)
}

/// Error state of one interval (E7/E8), started at zero; only the selected mode's terms
/// are propagated.
#[derive(Debug, Clone, Copy)]
struct ErrorPropagator {
    mode: GyroErrorMode,
    /// Paper: E7 with the full E2 per-sample covariance. Consistent: E7 with the ARW term
    /// only (W_n of E8).
    e: Mat3,
    /// Consistent: sensitivity of ε to vec_rowmajor(M_G) and to the rate bias (rad/s) (E8).
    j_m: Mat39,
    j_b: Mat3,
}

impl ErrorPropagator {
    fn zero(mode: GyroErrorMode) -> Self {
        Self { mode, e: Mat3::zeros(), j_m: Mat39::zeros(), j_b: Mat3::zeros() }
    }

    /// One sample: E ← (I − [ρ×]) E (I + [ρ×]) + P_ρ (E7, D12); in consistent mode also
    /// J_m ← (I − [ρ×])J_m + I₃⊗ρᵀ and J_b ← (I − [ρ×])J_b + T I (E8).
    // inlined into the per-interval loop so that E stays in registers
    #[inline(always)]
    // invariant: fixed-size: J_m is 3 × 9, so (i, 3i + j) with i, j < 3 is in range.
    #[allow(clippy::indexing_slicing)]
    fn step(&mut self, rho: &Vec3, model: &GyroErrorModel, period: f64) {
        match self.mode {
            GyroErrorMode::Paper => self.e = transport(&self.e, rho, &model.sample_var(rho, period)),
            GyroErrorMode::Consistent => {
                let a = Mat3::identity() - skew(rho);
                self.e = transport(&self.e, rho, &Vec3::repeat(model.sigma_w * model.sigma_w * period));
                self.j_m = a * self.j_m;
                for i in 0..3 {
                    for j in 0..3 {
                        self.j_m[(i, 3 * i + j)] += rho[j];
                    }
                }
                self.j_b = a * self.j_b + Mat3::identity() * period;
            }
        }
    }

    /// E_n: E7 (paper) or J_m P_m J_mᵀ + J_b P_b J_bᵀ + W (consistent).
    fn cov(&self, model: &GyroErrorModel) -> Mat3 {
        match self.mode {
            GyroErrorMode::Paper => self.e,
            GyroErrorMode::Consistent => {
                self.j_m * model.p_m() * self.j_m.transpose() + self.j_b * self.j_b.transpose() * model.sigma_b.powi(2) + self.e
            }
        }
    }

    fn sensitivities(&self) -> Option<(Mat39, Mat3)> {
        (self.mode == GyroErrorMode::Consistent).then_some((self.j_m, self.j_b))
    }
}

/// A gyro increment record: `rho[j]` (rad) over [t_start + jT, t_start + (j+1)T]. The rows
/// are `Vec3` or plain `[f64; 3]` (so that a numpy buffer is read in place, without a copy).
#[derive(Debug, Clone, Copy)]
pub struct ImuRecord<'a, R = Vec3> {
    pub t_start: f64,
    pub period: f64,
    pub rho: &'a [R],
}

impl<R: Copy + Into<Vec3> + Sync> ImuRecord<'_, R> {
    #[inline]
    // invariant: j < rho.len(): locate clamps to the last sample and check_epochs keeps
    // every epoch inside the record, so the interval loops stop below rho.len().
    #[allow(clippy::indexing_slicing)]
    fn rho(&self, j: usize) -> Vec3 {
        self.rho[j].into()
    }

    fn validate(&self) -> Result<()> {
        check_positive("period", self.period)?;
        if !self.t_start.is_finite() {
            return Err(invalid("t_start", format!("must be finite, got {}", self.t_start)));
        }
        // One branch-free pass before looking for the first bad row: x − x is 0 for a finite
        // x and NaN for ±inf or NaN, so the sum over the record is 0 exactly when every
        // value is finite.
        #[allow(clippy::eq_op)] // v − v is the finiteness test, not a mistake
        let any_bad = self.rho.iter().fold(0.0, |sum, &v| {
            let v: Vec3 = v.into();
            sum + (v - v).sum()
        }) != 0.0;
        match any_bad.then(|| self.rho.iter().position(|&v| !Into::<Vec3>::into(v).iter().all(|x| x.is_finite()))).flatten() {
            None => Ok(()),
            Some(i) => Err(invalid("gyro_increments", format!("non-finite value at index {i}"))),
        }
    }

    /// Sample index j and fraction x ∈ [0, 1) of an instant inside the record.
    fn locate(&self, t: f64) -> (usize, f64) {
        let u = (t - self.t_start) / self.period;
        let j = (u.floor() as usize).min(self.rho.len().saturating_sub(1));
        (j, u - j as f64)
    }

    /// Epochs strictly increasing and bracketed by IMU samples.
    fn check_epochs(&self, epochs: &[f64]) -> Result<()> {
        check_increasing("epochs", epochs)?;
        let end = self.t_start + self.rho.len() as f64 * self.period;
        if let Some((i, t)) = epochs.iter().enumerate().find(|(_, &t)| t < self.t_start || t >= end) {
            return Err(invalid("epochs", format!("epoch {t} s at index {i} outside the IMU record [{}, {}) s", self.t_start, end)));
        }
        Ok(())
    }

    /// Δρ_j = ρ_j − ρ_{j−1}, zero for the first sample of the record (E3, D14).
    fn drho(&self, j: usize) -> Vec3 {
        if j == 0 { Vec3::zeros() } else { self.rho(j) - self.rho(j - 1) }
    }

    /// The increment between instants `ta` < `tb` (E5–E8) in one pass over the samples
    /// touched: q_1 = r(x_a)* ∘ r(x_end of the first sample), then whole samples r(1), then
    /// r(x_b); E7/E8 over every sample from the one holding `ta` to the one holding `tb`.
    /// The quaternion is normalised once at the end: |q ∘ r| = |q| |r|, so normalising
    /// after every product (E5) only rescales and leaves the direction unchanged.
    fn interval(&self, ta: f64, tb: f64, model: &GyroErrorModel, variant: TaylorVariant) -> Increment {
        let ((ja, xa), (jb, xb)) = (self.locate(ta), self.locate(tb));
        let r = |j: usize, x: f64| intra_sample(&self.rho(j), &self.drho(j), x, variant);
        let first_end = if ja == jb { xb } else { 1.0 };
        let mut q = r(ja, xa).conjugate() * r(ja, first_end);
        let mut p = ErrorPropagator::zero(model.mode);
        let mut prev = self.rho(ja);
        p.step(&prev, model, self.period);
        // the whole samples inside the interval, as a slice: no bounds check per sample
        for &row in self.rho.get(ja + 1..jb).unwrap_or_default() {
            let rho: Vec3 = row.into();
            q *= full_sample(&rho, &(rho - prev));
            p.step(&rho, model, self.period);
            prev = rho;
        }
        if jb > ja {
            q *= r(jb, xb);
            p.step(&self.rho(jb), model, self.period);
        }
        Increment { q: quat_normalize(&q), cov: p.cov(model), sensitivities: p.sensitivities() }
    }
}

/// Intra-sample quaternion r(x), x = τ/T ∈ [0, 1], of the linear-rate model:
/// r0 = 1 − |ρ|²x²/8 − c(ρ·Δρ)(x³ − x²),
/// r_v = (ρ/2)(x − |ρ|²x³/24) + (Δρ/4)(x² − x) + (ρ×Δρ)x³/24.
pub fn intra_sample(rho: &Vec3, drho: &Vec3, x: f64, variant: TaylorVariant) -> Quat {
    if x == 1.0 {
        return full_sample(rho, drho);
    }
    let r2 = rho.norm_squared();
    let (x2, x3) = (x * x, x * x * x);
    let r0 = 1.0 - r2 * x2 / 8.0 - variant.c() * rho.dot(drho) * (x3 - x2);
    let rv = rho * (0.5 * (x - r2 * x3 / 24.0)) + drho * (0.25 * (x2 - x)) + rho.cross(drho) * (x3 / 24.0);
    quat(r0, rv.x, rv.y, rv.z)
}

/// r(1) of E4 for a whole sample (x³ − x² = x² − x = 0): r0 = 1 − |ρ|²/8,
/// r_v = (ρ/2)(1 − |ρ|²/24) + ρ×Δρ/24, the same for both Taylor variants.
fn full_sample(rho: &Vec3, drho: &Vec3) -> Quat {
    let r2 = rho.norm_squared();
    let rv = rho * (0.5 - r2 / 48.0) + rho.cross(drho) / 24.0;
    quat(1.0 - r2 / 8.0, rv.x, rv.y, rv.z)
}

/// The increment of one interval and its error model.
#[derive(Debug, Clone, Copy)]
pub struct Increment {
    /// q_n with R(q_n) = ΔS_n^imu (E5, E6).
    pub q: Quat,
    /// E_n^imu (rad²) of the model's mode (E7 or E8).
    pub cov: Mat3,
    /// Consistent mode: ∂ε_n/∂vec_rowmajor(M_G) and ∂ε_n/∂b (b in rad/s) (E8).
    pub sensitivities: Option<(Mat39, Mat3)>,
}

impl Increment {
    pub fn dcm(&self) -> Mat3 {
        dcm_from_quat(&self.q)
    }
}

/// Increments between consecutive epochs (N epochs → N − 1 increments), E3–E8; the
/// intervals are independent and run in parallel.
pub fn integrate_increments<R: Copy + Into<Vec3> + Sync>(rec: &ImuRecord<R>, epochs: &[f64], model: &GyroErrorModel, variant: TaylorVariant) -> Result<Vec<Increment>> {
    rec.validate()?;
    model.validate()?;
    rec.check_epochs(epochs)?;
    // Zipped slices, not filtered windows: an indexed iterator, so rayon collects straight into
    // one Vec of the known length (a filter_map collects per-thread lists and appends them).
    let ends = epochs.get(1..).unwrap_or_default();
    Ok(epochs.par_iter().zip(ends).map(|(&a, &b)| rec.interval(a, b, model, variant)).collect())
}

/// Continuous dead-reckoning covariance P_n^imu at every epoch: E7/E8 run from
/// the start of the sample holding the first epoch, linearly interpolated at t_En.
pub fn dead_reckoning_cov<R: Copy + Into<Vec3> + Sync>(rec: &ImuRecord<R>, epochs: &[f64], model: &GyroErrorModel) -> Result<Vec<Mat3>> {
    rec.validate()?;
    model.validate()?;
    rec.check_epochs(epochs)?;
    let mut out = Vec::with_capacity(epochs.len());
    let mut p = ErrorPropagator::zero(model.mode);
    let Some(&t0) = epochs.first() else { return Ok(out) };
    let mut j = rec.locate(t0).0;
    for &t in epochs {
        let (jt, x) = rec.locate(t);
        while j < jt {
            p.step(&rec.rho(j), model, rec.period);
            j += 1;
        }
        let before = p.cov(model);
        let mut next = p;
        next.step(&rec.rho(jt), model, rec.period);
        out.push(before * (1.0 - x) + next.cov(model) * x);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{dcm_from_rotvec, rotvec_from_quat};

    /// Fine-step RK4 of q̇ = ½ q∘(0, ω) with 64 substeps per IMU sample: the oracle.
    fn rk4(w: &dyn Fn(f64) -> Vec3, t0: f64, t1: f64, steps: usize) -> Quat {
        let f = |q: &Quat, t: f64| {
            let v = w(t);
            q * quat(0.0, v.x, v.y, v.z) * 0.5
        };
        let h = (t1 - t0) / steps as f64;
        let mut q = quat(1.0, 0.0, 0.0, 0.0);
        for i in 0..steps {
            let t = t0 + i as f64 * h;
            let k1 = f(&q, t);
            let k2 = f(&(q + k1 * (h / 2.0)), t + h / 2.0);
            let k3 = f(&(q + k2 * (h / 2.0)), t + h / 2.0);
            let k4 = f(&(q + k3 * h), t + h);
            q = quat_normalize(&(q + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)));
        }
        q
    }

    #[test]
    fn linear_rate_matches_fine_step_integration() {
        // ω(t) = a + b t, non-commuting a, b; rate up to ≈ 30°/s at 200 Hz; asynchronous epochs.
        let (a, b) = (Vec3::new(0.3, -0.2, 0.4), Vec3::new(-0.05, 0.08, 0.03));
        let w = |t: f64| a + b * t;
        let period = 0.005;
        let n = 1200;
        // exact sample increments: ∫ω over [jT, (j+1)T] = T ω(mid) for a linear rate
        let rho: Vec<Vec3> = (0..n).map(|j| w((j as f64 + 0.5) * period) * period).collect();
        let rec = ImuRecord { t_start: 0.0, period, rho: &rho };
        let epochs = [0.0123, 0.0141, 1.3377, 2.5, 5.9987];
        let model = GyroErrorModel::vasilyuk2024(GyroErrorMode::Paper);
        let inc = integrate_increments(&rec, &epochs, &model, TaylorVariant::Corrected).unwrap();
        for (k, e) in epochs.windows(2).enumerate() {
            let steps = (((e[1] - e[0]) / period).ceil() as usize).max(1) * 64;
            let truth = rk4(&w, e[0], e[1], steps);
            let err = rotvec_from_quat(&(truth.conjugate() * inc[k].q)).norm();
            assert!(err < 1e-12, "interval {k}: {err:e} rad");
            // DCM(q) equals exp([φ×]) with φ the rotation vector of q
            let phi = rotvec_from_quat(&inc[k].q);
            assert!((inc[k].dcm() - dcm_from_rotvec(&phi)).abs().max() < 1e-15);
        }
    }

    #[test]
    fn scalar_part_identity_row3() {
        // r0(x) − (1 − |θ(x)|²/8) = |Δρ|²(x²−x)²/32 exactly for c = 1/8.
        let (rho, d) = (Vec3::new(0.1, 0.05, -0.08), Vec3::new(0.03, -0.02, 0.04));
        let x = 2.0 / 3.0;
        let th = rho * x + d * ((x * x - x) / 2.0);
        let gap = intra_sample(&rho, &d, x, TaylorVariant::Corrected).w - (1.0 - th.norm_squared() / 8.0);
        assert!((gap - d.norm_squared() * (x * x - x).powi(2) / 32.0).abs() < 1e-15);
        assert!((gap - 4.4753e-6).abs() < 1e-10);
        let lit = intra_sample(&rho, &d, x, TaylorVariant::PaperLiteral).w - (1.0 - th.norm_squared() / 8.0);
        assert!((lit - (-1.77e-5)).abs() < 1e-7, "{lit:e}");
    }

    #[test]
    fn static_sigma_matches_spec_row13() {
        // Level, 21 s, Earth rate at 55.6°, paper budget: σ_ε = √tr E = 0.5716″ (paper),
        // 0.6258″ (consistent).
        let (lat, om, period) = (55.6f64.to_radians(), 7.292115e-5, 0.005);
        let w = Vec3::new(0.0, om * lat.cos(), om * lat.sin()); // ENU, level MF
        let rho = vec![w * period; 4400];
        let rec = ImuRecord { t_start: 0.0, period, rho: &rho };
        let ep = [0.5023, 21.503];
        for (mode, want) in [(GyroErrorMode::Paper, 0.5716), (GyroErrorMode::Consistent, 0.6258)] {
            let m = GyroErrorModel::vasilyuk2024(mode);
            let inc = integrate_increments(&rec, &ep, &m, TaylorVariant::Corrected).unwrap();
            let s = inc[0].cov.trace().sqrt() / crate::units::ARCSEC;
            assert!((s / want - 1.0).abs() < 0.01, "{mode:?}: {s}″");
        }
    }

    #[test]
    fn bad_epochs_are_rejected() {
        let rho = vec![Vec3::zeros(); 100];
        let rec = ImuRecord { t_start: 0.0, period: 0.01, rho: &rho };
        let m = GyroErrorModel::vasilyuk2024(GyroErrorMode::Paper);
        let e = integrate_increments(&rec, &[0.1, 0.05], &m, TaylorVariant::Corrected).unwrap_err();
        assert!(e.to_string().contains("index 1"), "{e}");
        let e = integrate_increments(&rec, &[0.1, 1.0], &m, TaylorVariant::Corrected).unwrap_err();
        assert!(e.to_string().contains("outside the IMU record"), "{e}");
    }
}
