//! The synthetic reproduction `vasilyuk2024_like` and its Monte-Carlo runner.
//!
//! Frame boundary: the stand motion of `trajectory::generators::vasilyuk2024_stand` is in
//! NED/FRD (C_nb = R_y(tilt) R_z(turntable)); the paper's ENU/right-forward-up frames are
//! obtained with T = [[0,1,0],[1,0,0],[0,0,−1]] (T = Tᵀ = T⁻¹, det T = 1):
//! C_ENU^MF = T C_nb T, ρ_MF = T ρ_FRD. This gives C_ENU^MF = R_ϑ(τ) R_ψ(ψ_t) as in §5.1.

use super::calibration::{calibrate, dead_reckoning_check, model_covariance, Calibration, ConstantGyroErrors, DiffForm, Options};
use super::increments::{dead_reckoning_cov, integrate_increments, GyroErrorMode, GyroErrorModel, ImuRecord, TaylorVariant};
use super::stars::{astro_increments, refractive_index, simulate_observations, star_attitudes, Camera, Catalog, Observations};
use super::euler_dcm;
use crate::earth::{dcm_ned_to_ecef, WGS84};
use crate::error::Result;
use crate::imu::ideal::ideal_increments;
use crate::math::{rotvec_from_dcm, Mat3, Vec3};
use crate::trajectory::generators::vasilyuk2024_stand;
use crate::units::{ARCSEC, DEG};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// NED ↔ ENU and FRD ↔ right-forward-up: swap the first two axes and flip the third.
const T_SWAP: Mat3 = Mat3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);

/// Everything fixed across Monte-Carlo runs: truth and sensor configuration.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Scenario {
    /// Camera epochs t_En (s) and the IMU record (t_start, period T, true increments ρ̆ in MF).
    pub epochs: Vec<f64>,
    pub t_start: f64,
    pub period: f64,
    pub rho_true: Vec<Vec3>,
    /// True S_GCRS^VF and local up (GCRS) at every epoch.
    pub s_gcrs_vf: Vec<Mat3>,
    pub up_gcrs: Vec<Vec3>,
    /// True mount C_MF^VF = C(β̆).
    pub c_true: Mat3,
    pub cameras: Vec<Camera>,
    pub catalog: Catalog,
    /// Field-of-view half-angle (rad), magnitude limit, per-star noise σ_s (rad), refractive index.
    pub fov_half: f64,
    pub m_lim: f64,
    pub sigma_s: f64,
    pub n_refr: f64,
    pub gyro: GyroErrorModel,
}

/// The default catalog seed: 108.8 stars per epoch (88–122), as in the paper's 108.7 (88–123).
pub const CATALOG_SEED: u64 = 3;

/// The synthetic scenario after Vasilyuk et al. (2024): site 55.6° N 38.2° E, 150 m;
/// β̆ = (10°, −25°, 2°); 3 cameras at C_MF^CFⁱ = R_ψ(120°(i−1)) C̆ with 12° half-angle;
/// uniform catalog to m = 5.6 (`catalog_seed`); σ_s = 16″; 200 Hz gyro with the paper's
/// budget in `mode`.
pub fn vasilyuk2024_like(catalog_seed: u64, mode: GyroErrorMode) -> Result<Scenario> {
    let (lat, lon, h) = (55.6 * DEG, 38.2 * DEG, 150.0);
    let motion = vasilyuk2024_stand(Vec3::new(lat, lon, h))?;
    let period = 0.005;
    let k = (motion.duration / period).floor() as usize;
    let times: Vec<f64> = (0..=k).map(|i| i as f64 * period).collect();
    let truth = motion.truth(&WGS84, &times)?;
    let (_, dth) = ideal_increments(&motion, &WGS84, &truth);
    let rho_true: Vec<Vec3> = dth.iter().map(|r| T_SWAP * r).collect();
    let epochs: Vec<f64> = (0..73).map(|n| 0.5023 + 21.0007 * n as f64).collect();
    // S_GCRS^ENU(t) = R_z(Ωt)[E N U]_ECEF
    let ned = dcm_ned_to_ecef(lat, lon);
    let enu = Mat3::from_columns(&[ned.column(1).into_owned(), ned.column(0).into_owned(), -ned.column(2)]);
    let s_gcrs_enu = |t: f64| {
        let (s, c) = (WGS84.omega * t).sin_cos();
        Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0) * enu
    };
    let c_true = euler_dcm(&Vec3::new(10.0 * DEG, -25.0 * DEG, 2.0 * DEG));
    let s_gcrs_vf = epochs.iter().map(|&t| s_gcrs_enu(t) * (T_SWAP * motion.kinematics(t).c_nb * T_SWAP) * c_true).collect();
    let up_gcrs = epochs.iter().map(|&t| s_gcrs_enu(t) * Vec3::z()).collect();
    let cameras = (0..3)
        .map(|i| Camera { c_vf_cf: c_true.transpose() * euler_dcm(&Vec3::new(120.0 * DEG * i as f64, 0.0, 0.0)) * c_true, p_alpha: Mat3::zeros() })
        .collect();
    Ok(Scenario {
        epochs,
        t_start: 0.0,
        period,
        rho_true,
        s_gcrs_vf,
        up_gcrs,
        c_true,
        cameras,
        catalog: Catalog::synthetic(5.6, catalog_seed)?,
        fov_half: 12.0 * DEG,
        m_lim: 5.6,
        sigma_s: 16.0 * ARCSEC,
        n_refr: refractive_index(h)?,
        gyro: GyroErrorModel::vasilyuk2024(mode),
    })
}

/// Measured increments ρ = ρ̆ + M_G ρ̆ + δb T + w: M_G and δb redrawn every
/// sample (`Paper` truth) or once (`Consistent` truth); w ~ N(0, σ_w² T) white.
pub fn corrupt_gyro<R: Rng>(rho: &[Vec3], model: &GyroErrorModel, period: f64, rng: &mut R) -> Vec<Vec3> {
    let mut n = || rng.sample::<f64, _>(StandardNormal);
    let draw = |n: &mut dyn FnMut() -> f64| {
        let m = Mat3::from_fn(|i, j| n() * if i == j { model.sigma_k } else { model.sigma_phi });
        (m, Vec3::new(n(), n(), n()) * model.sigma_b)
    };
    let (mut m, mut b) = draw(&mut n);
    rho.iter()
        .map(|r| {
            if model.mode == GyroErrorMode::Paper {
                (m, b) = draw(&mut n);
            }
            r + m * r + b * period + Vec3::new(n(), n(), n()) * (model.sigma_w * period.sqrt())
        })
        .collect()
}

/// One simulated calibration: inputs, estimates and the validation quantities.
#[derive(Debug, Clone)]
pub struct Run {
    pub observations: Observations,
    pub stars_per_epoch: Vec<usize>,
    pub s_vf: Vec<Mat3>,
    pub p_avu: Vec<Mat3>,
    pub ds_imu: Vec<Mat3>,
    pub e_imu: Vec<Mat3>,
    pub ds_avu: Vec<Mat3>,
    pub e_avu: Vec<Mat3>,
    pub calibration: Calibration,
    /// P_β^model and its systematic part P_β^sys (rad², E18) from the scenario's gyro mode.
    pub p_beta_model: Mat3,
    pub p_beta_sys: Mat3,
    /// β̂ − β̆ (rad) and the VF rotation error log(C̆ᵀ Ĉ) (rad).
    pub beta_error: Vec3,
    pub theta_error: Vec3,
    /// θ_n^diff and P_n^diff for n = 2..N (E20).
    pub theta_diff: Vec<Vec3>,
    pub p_diff: Vec<Mat3>,
}

/// The full chain of one run with noise seed `seed`.
pub fn run(scn: &Scenario, seed: u64, opt: &Options, diff_form: DiffForm) -> Result<Run> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let rho = corrupt_gyro(&scn.rho_true, &scn.gyro, scn.period, &mut rng);
    let obs = simulate_observations(&scn.catalog, &scn.s_gcrs_vf, &scn.up_gcrs, &scn.cameras, scn.fov_half, scn.m_lim, scn.sigma_s, scn.n_refr, &mut rng)?;
    let att = star_attitudes(&obs, scn.epochs.len(), &scn.cameras, scn.sigma_s, Some((&scn.up_gcrs, scn.n_refr)), None)?;
    let rec = ImuRecord { t_start: scn.t_start, period: scn.period, rho: &rho };
    let inc = integrate_increments(&rec, &scn.epochs, &scn.gyro, TaylorVariant::Corrected)?;
    let (ds_imu, e_imu): (Vec<Mat3>, Vec<Mat3>) = inc.iter().map(|i| (i.dcm(), i.cov)).unzip();
    let (ds_avu, e_avu) = astro_increments(&att.s, &att.p);
    let cal = calibrate(&ds_imu, &ds_avu, opt)?;
    let sens: Vec<_> = inc.iter().filter_map(|i| i.sensitivities).collect();
    let constant = (scn.gyro.mode == GyroErrorMode::Consistent).then(|| ConstantGyroErrors { sensitivities: &sens, p_m: scn.gyro.p_m(), sigma_b: scn.gyro.sigma_b });
    let (p_beta_model, p_beta_sys) = model_covariance(&cal.c, &ds_imu, &ds_avu, &e_imu, &att.p, constant.as_ref())?;
    let p_imu = dead_reckoning_cov(&rec, &scn.epochs, &scn.gyro)?;
    let (theta_diff, p_diff) = dead_reckoning_check(&cal.c, &att.s, &ds_imu, &att.p, &p_imu, &cal.p_clb, diff_form)?;
    let beta_true = super::euler_from_dcm(&scn.c_true);
    Ok(Run {
        beta_error: cal.beta - beta_true,
        theta_error: rotvec_from_dcm(&(scn.c_true.transpose() * cal.c)),
        observations: obs,
        stars_per_epoch: att.stars,
        s_vf: att.s,
        p_avu: att.p,
        ds_imu,
        e_imu,
        ds_avu,
        e_avu,
        calibration: cal,
        p_beta_model,
        p_beta_sys,
        theta_diff,
        p_diff,
    })
}

/// Summary of one Monte-Carlo run.
#[derive(Debug, Clone, Copy)]
pub struct RunSummary {
    pub beta_error: Vec3,
    /// √diag P_β (residual form) and √diag P_β^model (rad).
    pub sigma_beta: Vec3,
    pub sigma_beta_model: Vec3,
    /// Fraction of θ^diff components inside their ±3σ bands and the mean χ² of θ^diff.
    pub inside_3sigma: f64,
    pub chi2_diff: f64,
    pub iterations: usize,
}

/// Runs with seeds seed0, seed0 + 1, … (mod 2⁶⁴; sequential: deterministic and single-core).
pub fn monte_carlo(scn: &Scenario, runs: usize, seed0: u64, opt: &Options, diff_form: DiffForm) -> Result<Vec<RunSummary>> {
    (0..runs as u64)
        .map(|k| {
            let r = run(scn, seed0.wrapping_add(k), opt, diff_form)?;
            let comps = 3 * r.theta_diff.len();
            let inside: usize = r
                .theta_diff
                .iter()
                .zip(&r.p_diff)
                .map(|(t, p)| (0..3).filter(|&i| t[i].abs() <= 3.0 * p[(i, i)].sqrt()).count())
                .sum();
            let chi2: f64 = r
                .theta_diff
                .iter()
                .zip(&r.p_diff)
                .map(|(t, p)| p.try_inverse().map_or(f64::INFINITY, |pi| (t.transpose() * pi * t).x))
                .sum::<f64>()
                / r.theta_diff.len() as f64;
            let sd = |p: &Mat3| Vec3::new(p[(0, 0)].sqrt(), p[(1, 1)].sqrt(), p[(2, 2)].sqrt());
            Ok(RunSummary {
                beta_error: r.beta_error,
                sigma_beta: sd(&r.calibration.p_beta),
                sigma_beta_model: sd(&r.p_beta_model),
                inside_3sigma: inside as f64 / comps as f64,
                chi2_diff: chi2,
                iterations: r.calibration.iterations,
            })
        })
        .collect()
}
