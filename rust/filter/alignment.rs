//! Initial alignment of a strapdown INS at rest (Titterton & Weston 2004, ch. 10;
//! Groves 2013, §5.6).
//!
//! **Coarse alignment** ([`coarse`]): levelling from the mean specific force and
//! gyrocompassing from the mean angular rate of a static record. The navigation axes
//! expressed in the body frame are d = −f̄/|f̄| (down), e = d × ω̄/|d × ω̄| (east: Earth
//! rate ω_ie^n = Ω(cos φ, 0, −sin φ) has no east component) and n = e × d, so
//! C_b^n = [n e d]ᵀ, orthonormal by construction. With the attitude error ψ of the
//! project (Ĉ_b^n = (I − [ψ×])C_b^n) and the sensor errors b_a, b_g resolved in the
//! navigation frame (b^n = C_b^n b), the two conditions Ĉ f̄ ∥ −D and (Ĉ ω̄)_E = 0 give,
//! to first order,
//!
//!   ψ_N = b^n_a,E / g,   ψ_E = −b^n_a,N / g,   ψ_D = b^n_g,E / (Ω cos φ) − ψ_N tan φ,
//!
//! the limits of Titterton & Weston 2004, §10.3.1 (δφ ≈ B_y/g, δθ ≈ B_x/g,
//! δψ ≈ D_y/(Ω cos L)) in these conventions, with the same relations for the white-noise
//! part of the means (variance N²/T for a density N over a record of T s). [`coarse`]
//! returns this ψ covariance and its roll/pitch/yaw counterpart.
//!
//! **Fine alignment** runs the aided INS of `aided.rs` on the static record with
//! zero-velocity ([`ZeroVelocity`]) and zero-angular-rate ([`ZeroRate`]) updates
//! (Groves 2013, §15.3.1 and §15.3.3; two sources of `sources.rs`), from the coarse attitude and the initial
//! covariance of [`fine_p0`], which keeps the correlation between the coarse attitude
//! error and the sensor biases that caused it.

use super::aided::{Aiding, AidingContext, Measurement};
use super::layout::Layout;
use super::sources::Mounting;
use crate::earth::Ellipsoid;
use crate::error::{check_finite, invalid, Result};
use crate::imu::errors::{ImuErrorModel, TriadErrors};
use crate::imu::noise::Flicker;
use crate::imu::ImuKind;
use crate::math::{dcm_from_quat, euler_from_dcm, quat_from_dcm, skew, Mat3, Quat, Vec3};
use crate::strapdown::{NavState, SampleCheck};
use nalgebra::DMatrix;

/// Fewest samples a static record needs: ten windows of ten samples for the static test.
pub const MIN_SAMPLES: usize = 100;
/// Number of equal windows whose means the static test compares.
pub const STATIC_WINDOWS: usize = 10;
/// A record is static while the spread of its window means stays within this many
/// standard deviations of what the sensor noise and bias drift explain.
pub const STATIC_RATIO: f64 = 5.0;
/// Gyrocompassing needs |latitude| ≤ this (rad, 89°): within 1° of a pole the horizontal
/// Earth rate Ω cos φ is below 0.27 °/h, beneath the bias of all but strategic-grade gyros,
/// so the heading is unobservable.
pub const MAX_LATITUDE: f64 = 89.0 * std::f64::consts::PI / 180.0;
/// The mean specific force of a static record is local gravity: a relative difference
/// beyond this is no static record (accelerations in g, increments read as rates).
pub const GRAVITY_TOLERANCE: f64 = 0.1;
/// Levelling alone ([`level`]) accepts a record held still by hand or on a vehicle at a
/// stop: the window means of its specific force may scatter up to this (m/s², per axis),
/// the accelerometer threshold of a zero-velocity detector (Skog et al. 2010); their
/// measured scatter enters the stated tilt accuracy.
pub const LEVEL_SPREAD: f64 = 0.25;
/// Variance of a heading that levelling alone leaves undetermined (rad²): uniform over
/// ±π, π²/3.
pub const UNKNOWN_HEADING_VAR: f64 = std::f64::consts::PI * std::f64::consts::PI / 3.0;

/// What the coarse alignment takes the heading from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Heading {
    /// Gyrocompassing: north from the mean angular rate (the Earth rate).
    Gyrocompass,
    /// None: yaw 0 (the body x axis's horizontal projection taken as north), its variance
    /// [`UNKNOWN_HEADING_VAR`]; for gyros that cannot find north, heading from elsewhere.
    Unknown,
}

/// The error budget of one sensor triad over a record of `horizon` s: each bias process
/// (Gauss–Markov, and the Gauss–Markov poles that realise flicker, `imu::noise::Flicker`)
/// counts as white noise (PSD 2σ²τ, its low-frequency level) when its correlation time is
/// shorter than the horizon T, and as a bias random walk (PSD 2σ²/τ, initial variance σ²)
/// otherwise. For the mean over T, whose exact variance is
/// 2σ²(τ/T)[1 − (τ/T)(1 − e^{−T/τ})], the white form 2σ²τ/T is exact as τ/T → 0 and
/// at most 2.7 times too large at τ = T, where the constant form σ² takes over (1.36
/// times too large there, exact as τ/T → ∞).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriadBudget {
    /// White-noise PSD (density², units²·s): N² plus the fast processes.
    pub white_psd: f64,
    /// Random-walk PSD of the slow bias processes and the bias random walk (units²/s).
    pub walk_psd: f64,
    /// Variance per axis of the bias at the record start: fixed bias², turn-on σ², the
    /// slow processes and the scale-factor/misalignment error on the static mean.
    pub bias_var: Vec3,
    /// Variance of every time-varying bias process over the horizon (static test).
    pub drift_var: f64,
}

impl TriadBudget {
    /// The budget of triad `e` measuring the static mean `mean` over `horizon` s.
    pub fn of(e: &TriadErrors, mean: &Vec3, horizon: f64) -> TriadBudget {
        let mut processes: Vec<(f64, f64)> = e.gauss_markov.iter().map(|g| (g.sigma, g.tau)).collect();
        if let Some(f) = e.flicker {
            let s = Flicker::pole_sigma(f.b);
            processes.extend(Flicker::correlation_times(f.f_lo, f.f_hi).into_iter().map(|tau| (s, tau)));
        }
        let (mut white_psd, mut walk_psd, mut slow, mut drift) = (e.white * e.white, e.bias_rw * e.bias_rw, 0.0, 0.0);
        for (s, tau) in processes {
            drift += s * s;
            if tau >= horizon {
                slow += s * s;
                walk_psd += 2.0 * s * s / tau;
            } else {
                white_psd += 2.0 * s * s * tau;
            }
        }
        let matrix_error = (e.sensor_matrix() - Mat3::identity()) * mean;
        let bias_var = e.bias.zip_map(&matrix_error, |b, m| b * b + m * m + e.bias_sigma * e.bias_sigma + slow);
        TriadBudget { white_psd, walk_psd, bias_var, drift_var: drift + e.bias_rw * e.bias_rw * horizon }
    }
}

/// Sensitivity of the coarse attitude error ψ to the accelerometer and gyro errors in
/// the navigation frame (module docs): ψ = L_a b_a^n + L_g b_g^n.
fn sensitivities(gravity: f64, omega: f64, lat: f64) -> (Mat3, Mat3) {
    let (s, c) = lat.sin_cos();
    let la = Mat3::new(0.0, 1.0 / gravity, 0.0, -1.0 / gravity, 0.0, 0.0, 0.0, -s / (c * gravity), 0.0);
    let lg = Mat3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0 / (omega * c), 0.0);
    (la, lg)
}

/// Result of the coarse alignment.
#[derive(Debug, Clone, PartialEq)]
pub struct CoarseAlignment {
    /// Span of the record used (s): the first and last time stamp.
    pub t0: f64,
    pub t1: f64,
    /// Samples averaged (an increment record's first row, whose interval starts before
    /// the record, is left out).
    pub samples: usize,
    /// Attitude q_nb and its Euler angles (roll, pitch, yaw), rad.
    pub q_nb: Quat,
    pub euler: Vec3,
    /// Mean specific force (m/s²) and angular rate (rad/s) in the body frame.
    pub mean_f: Vec3,
    pub mean_w: Vec3,
    /// Normal gravity γ (m/s²) and horizontal Earth rate Ω cos φ (rad/s) at the site.
    pub gravity: f64,
    pub earth_rate_h: f64,
    /// Covariance of ψ (rad², NED): the whole, and the part from noise alone (white noise
    /// and the bias processes faster than the record, [`TriadBudget`]).
    pub psi_cov: Mat3,
    pub psi_cov_noise: Mat3,
    /// σ of (roll, pitch, yaw) (rad); roll and yaw are +inf at pitch ±90°.
    pub euler_sigma: Vec3,
    /// Spread of the window means over what noise and drift explain, for the specific
    /// force and the angular rate (static while both are ≤ [`STATIC_RATIO`]).
    pub spread: (f64, f64),
    /// The gyro bias seen at rest (rad/s, body axes) and its covariance (rad²/s²): for a
    /// levelling ([`rest_gyro_bias`]); for a gyrocompass, where the bias and the heading
    /// are not separable, zero and the error model's bias covariance.
    pub gyro_bias: Vec3,
    pub gyro_bias_cov: Mat3,
}

/// The gyro bias from a rest of unknown heading (a zero-angular-rate update, Groves 2013,
/// §15.3.3, applied to the mean of the record): the mean rate `mean_w` (rad/s, body
/// axes) less the vertical Earth rate, which the levelled attitude `c_nb` (C_b^n, any
/// yaw) knows, measures the bias with noise: the white noise of the mean, `white_var`
/// (rad²/s²), and the horizontal Earth rate Ω cos φ in an unknown direction (variance
/// (Ω cos φ)²/2 per horizontal axis). Combined with the prior covariance `prior`
/// (the error model's bias), it gives the estimate and its covariance (the Kalman update
/// of a zero prior; the prior unchanged if the two together are singular).
pub fn rest_gyro_bias(c_nb: &Mat3, lat: f64, omega: f64, mean_w: &Vec3, prior: &Mat3, white_var: f64) -> (Vec3, Mat3) {
    let (s, c) = lat.sin_cos();
    let c_bn = c_nb.transpose();
    let vertical = c_bn * Vec3::new(0.0, 0.0, -omega * s);
    let h2 = (omega * c).powi(2) / 2.0;
    let noise = Mat3::identity() * white_var + c_bn * Mat3::from_diagonal(&Vec3::new(h2, h2, 0.0)) * c_nb;
    match (prior + noise).try_inverse() {
        Some(inv) => {
            let gain = prior * inv;
            let cov = (Mat3::identity() - gain) * prior;
            (gain * (mean_w - vertical), (cov + cov.transpose()) / 2.0)
        }
        None => (Vec3::zeros(), *prior),
    }
}

/// Mean of rows [lo, hi) of `x`: the arithmetic mean of rate samples, or the sum of
/// increments over the time they span (t[hi − 1] − t[lo − 1]; lo ≥ 1).
fn window_mean(t: &[f64], x: &[Vec3], kind: ImuKind, lo: usize, hi: usize) -> Vec3 {
    let sum = x.get(lo..hi).map_or(Vec3::zeros(), |rows| rows.iter().sum());
    match kind {
        ImuKind::Rates => sum / (hi - lo) as f64,
        ImuKind::Increments => {
            let span = match (t.get(hi.wrapping_sub(1)), t.get(lo.wrapping_sub(1))) {
                (Some(a), Some(b)) => a - b,
                _ => f64::NAN,
            };
            sum / span
        }
    }
}

/// Spread of the window means over its expectation: the largest over the axes of the
/// sample standard deviation of the means of [`STATIC_WINDOWS`] windows, divided by
/// √(white_psd/T_w + drift_var) (T_w the window's length). A record that is constant to
/// rounding is static whatever the noise model.
fn spread(t: &[f64], x: &[Vec3], kind: ImuKind, first: usize, budget: &TriadBudget, step: f64) -> f64 {
    let n = x.len() - first;
    let var = window_scatter(t, x, kind, first);
    let window = (n / STATIC_WINDOWS) as f64 * step;
    let expected = (budget.white_psd / window + budget.drift_var).sqrt();
    let floor = 1e-12 * window_mean(t, x, kind, first, x.len()).norm() + f64::MIN_POSITIVE;
    var.iter().map(|v| v.sqrt() / expected.max(floor)).fold(0.0, f64::max)
}

/// Per-axis variance (m²/s⁴) of the [`STATIC_WINDOWS`] window means of `x` about their mean.
fn window_scatter(t: &[f64], x: &[Vec3], kind: ImuKind, first: usize) -> Vec3 {
    let n = x.len() - first;
    let bounds: Vec<usize> = (0..=STATIC_WINDOWS).map(|k| first + n * k / STATIC_WINDOWS).collect();
    let means: Vec<Vec3> = bounds.windows(2).filter_map(|w| match *w {
        [lo, hi] => Some(window_mean(t, x, kind, lo, hi)),
        _ => None,
    }).collect();
    let k = means.len() as f64;
    let mid: Vec3 = means.iter().sum::<Vec3>() / k;
    means.iter().map(|m| (m - mid).component_mul(&(m - mid))).sum::<Vec3>() / (k - 1.0)
}

/// Coarse alignment of a static record: time stamps `t` (s, strictly increasing), gyro
/// and accel samples of `kind`, at the site `lla` (rad, rad, m) on `ell`, with the
/// sensor error model `errors` (for the accuracy and the static test).
///
/// Errors name `time`/`gyro`/`accel` for a bad sample (non-finite, time order), `imu`
/// for a record too short, not static, or whose mean specific force is not gravity, and
/// `lla` for a site beyond ±[`MAX_LATITUDE`].
pub fn coarse(t: &[f64], gyro: &[Vec3], accel: &[Vec3], kind: ImuKind, lla: &Vec3, ell: &Ellipsoid, errors: &ImuErrorModel) -> Result<CoarseAlignment> {
    align(t, gyro, accel, kind, lla, ell, errors, Heading::Gyrocompass)
}

/// Levelling alone: roll and pitch from the mean specific force of a record held still
/// (by hand, or a vehicle at a stop; its window means may scatter up to [`LEVEL_SPREAD`],
/// and the measured scatter enters the stated tilt σ), yaw 0 with variance
/// [`UNKNOWN_HEADING_VAR`], for any gyro and any latitude. Errors as [`coarse`].
pub fn level(t: &[f64], gyro: &[Vec3], accel: &[Vec3], kind: ImuKind, lla: &Vec3, ell: &Ellipsoid, errors: &ImuErrorModel) -> Result<CoarseAlignment> {
    align(t, gyro, accel, kind, lla, ell, errors, Heading::Unknown)
}

#[allow(clippy::too_many_arguments)]
fn align(t: &[f64], gyro: &[Vec3], accel: &[Vec3], kind: ImuKind, lla: &Vec3, ell: &Ellipsoid, errors: &ImuErrorModel, heading: Heading) -> Result<CoarseAlignment> {
    errors.validate()?;
    check_finite("lla", lla.as_slice(), 1)?;
    crate::earth::check_latitude("lla", lla.x, 0)?;
    if heading == Heading::Gyrocompass && lla.x.abs() > MAX_LATITUDE {
        return Err(invalid("lla", format!(
            "latitude {:.4}° is within 1° of a pole: the horizontal Earth rate Ω cos φ = {:.3} °/h is too small to find north by gyrocompassing",
            lla.x.to_degrees(), (ell.omega * lla.x.cos()).to_degrees() * 3600.0)));
    }
    SampleCheck { kind, damped: false, prev_t: f64::NEG_INFINITY, primed: true }.check(t, gyro, accel, None, 0)?;
    let first = usize::from(kind == ImuKind::Increments);
    let n = t.len().saturating_sub(first);
    let (Some(&t0), Some(&t1)) = (t.first(), t.last()) else {
        return Err(invalid("imu", format!("too short for a static alignment: 0 samples, need >= {MIN_SAMPLES}")));
    };
    if n < MIN_SAMPLES {
        return Err(invalid("imu", format!("too short for a static alignment: {n} samples{}, need >= {MIN_SAMPLES} ({STATIC_WINDOWS} windows for the static test)",
            if first > 0 { " after the first increment (its interval starts before the record)" } else { "" })));
    }
    let span = t1 - t0;
    let step = span / (t.len() - 1) as f64;
    let horizon = n as f64 * step;
    let (mean_f, mean_w) = (window_mean(t, accel, kind, first, t.len()), window_mean(t, gyro, kind, first, t.len()));
    let loc = ell.local(lla.x, lla.z);
    let gravity = loc.gravity;
    if ((mean_f.norm() - gravity) / gravity).abs() > GRAVITY_TOLERANCE {
        return Err(invalid("imu", format!(
            "the mean specific force {:.4} m/s² is not the local gravity {gravity:.4} m/s² that a record at rest measures \
             (accelerations in g, increments read as rates, or a record that is not static)", mean_f.norm())));
    }
    let (ba, bg) = (TriadBudget::of(&errors.accel, &mean_f, horizon), TriadBudget::of(&errors.gyro, &mean_w, horizon));
    let spread = (spread(t, accel, kind, first, &ba, step), spread(t, gyro, kind, first, &bg, step));
    let scatter = window_scatter(t, accel, kind, first);
    match heading {
        Heading::Gyrocompass if spread.0 > STATIC_RATIO || spread.1 > STATIC_RATIO => {
            let (what, r) = if spread.0 >= spread.1 { ("specific force", spread.0) } else { ("angular rate", spread.1) };
            return Err(invalid("imu", format!(
                "not static: the {what} varies between the {STATIC_WINDOWS} windows of the record {r:.1} times more than the sensor noise and bias drift of `errors` explain (at most {STATIC_RATIO}); \
                 a record held by hand can only be levelled (alignment.level)")));
        }
        Heading::Unknown if scatter.max() > LEVEL_SPREAD * LEVEL_SPREAD => {
            return Err(invalid("imu", format!(
                "not held still: the specific force's window means scatter by {:.3} m/s² (σ), more than {LEVEL_SPREAD} m/s²", scatter.max().sqrt())));
        }
        _ => {}
    }
    let down = -mean_f.normalize();
    let east_raw = match heading {
        Heading::Gyrocompass => down.cross(&mean_w),
        Heading::Unknown => down.cross(&Vec3::x()),  // yaw 0: north along the body x axis's horizontal projection
    };
    if east_raw.norm() <= 1e-6 {
        return Err(invalid("imu", match heading {
            Heading::Gyrocompass => "the mean angular rate is parallel to gravity: no horizontal Earth rate to find north from",
            Heading::Unknown => "the body x axis is vertical: its horizontal projection gives no yaw reference",
        }));
    }
    let east = east_raw.normalize();
    let north = east.cross(&down);
    let c_nb = Mat3::from_rows(&[north.transpose(), east.transpose(), down.transpose()]);
    let q_nb = quat_from_dcm(&c_nb);
    let euler = euler_from_dcm(&c_nb);
    let (la, lg) = sensitivities(gravity, ell.omega, lla.x);
    let (ma, mg) = (la * c_nb, lg * c_nb);
    let psi_cov_noise = la * la.transpose() * (ba.white_psd / horizon) + lg * lg.transpose() * (bg.white_psd / horizon);
    // the bias seen by the means: its value at the start, plus a random walk's mean drift (variance qT/3)
    let bias_cov = |b: &TriadBudget| Mat3::from_diagonal(&b.bias_var.add_scalar(b.walk_psd * horizon / 3.0));
    let mut psi_cov = ma * bias_cov(&ba) * ma.transpose() + mg * bias_cov(&bg) * mg.transpose() + psi_cov_noise;
    let mut psi_cov_noise = psi_cov_noise;
    if heading == Heading::Unknown {
        // the motion the record held: the scatter of its window means, averaged over them
        let motion = ma * Mat3::from_diagonal(&(scatter / STATIC_WINDOWS as f64)) * ma.transpose();
        for p in [&mut psi_cov, &mut psi_cov_noise] {
            *p += motion;
            p.row_mut(2).fill(0.0);
            p.column_mut(2).fill(0.0);
            p[(2, 2)] = UNKNOWN_HEADING_VAR;
        }
    }
    let euler_sigma = euler_sigma(&euler, &psi_cov);
    let (gyro_bias, gyro_bias_cov) = match heading {
        Heading::Unknown => rest_gyro_bias(&c_nb, lla.x, ell.omega, &mean_w, &bias_cov(&bg), bg.white_psd / horizon),
        Heading::Gyrocompass => (Vec3::zeros(), bias_cov(&bg)),
    };
    Ok(CoarseAlignment { t0, t1, samples: n, q_nb, euler, mean_f, mean_w, gravity, earth_rate_h: ell.omega * lla.x.cos(), psi_cov, psi_cov_noise, euler_sigma,
                         spread, gyro_bias, gyro_bias_cov })
}

/// The start of a fine alignment after a coarse one at `lla` (attitude `q_nb`, the coarse
/// white-noise attitude covariance `psi_cov_noise` and static means `mean_f`, `mean_w`,
/// normal gravity `gravity`), over a record of `horizon` s with the sensor error model
/// `errors`: the initial covariance over the 15 INS states ([`fine_p0`], position σ
/// `pos_sigma` m, velocity σ `vel_sigma` m/s) and the filter's noise model (accel white
/// PSD, accel bias random-walk PSD, gyro white PSD, gyro bias random-walk PSD).
#[allow(clippy::too_many_arguments)]
pub fn fine_start(lla: &Vec3, q_nb: &Quat, psi_cov_noise: &Mat3, mean_f: &Vec3, mean_w: &Vec3, gravity: f64, horizon: f64,
                  errors: &ImuErrorModel, pos_sigma: f64, vel_sigma: f64, ell: &Ellipsoid) -> Result<(DMatrix<f64>, [f64; 4])> {
    errors.validate()?;
    crate::error::check_positive("horizon", horizon)?;
    let (ba, bg) = (TriadBudget::of(&errors.accel, mean_f, horizon), TriadBudget::of(&errors.gyro, mean_w, horizon));
    let p0 = fine_p0(&Layout::ins_with(&[])?, q_nb, lla.x, gravity, ell.omega, psi_cov_noise, &ba, &bg, pos_sigma, vel_sigma)?;
    Ok((p0, [ba.white_psd, ba.walk_psd, bg.white_psd, bg.walk_psd]))
}

/// σ of (roll, pitch, yaw) from the covariance of ψ: a small rotation δθ of the
/// navigation frame changes the Euler angles by δe with δθ = A δe,
/// A = [R_z(yaw) R_y(pitch) x̂, R_z(yaw) ŷ, ẑ], and Ĉ = (I − [ψ×])C means δθ = −ψ.
pub fn euler_sigma(euler: &Vec3, psi_cov: &Mat3) -> Vec3 {
    let (sp, cp) = euler.y.sin_cos();
    let (sy, cy) = euler.z.sin_cos();
    let a = Mat3::new(cy * cp, -sy, 0.0, sy * cp, cy, 0.0, -sp, 0.0, 1.0);
    match a.try_inverse() {
        Some(ai) if cp.abs() > 1e-9 => (ai * psi_cov * ai.transpose()).diagonal().map(|v| v.max(0.0).sqrt()),
        _ => Vec3::new(f64::INFINITY, psi_cov.diagonal().x.max(psi_cov.diagonal().y).sqrt(), f64::INFINITY),
    }
}

/// Numerical floors of the fine-alignment P₀ (attitude rad, accel m/s², gyro rad/s), so
/// an error-free sensor model still gives a positive definite matrix; far below any
/// real sensor's contribution.
const P0_FLOOR: (f64, f64, f64) = (1e-9, 1e-9, 1e-12);

/// P₀ over the 15 INS states ([`Layout`] order) of a fine alignment that starts from the
/// coarse attitude `q_nb` at latitude `lat` with zero bias estimates: position σ
/// `pos_sigma` (m), velocity σ `vel_sigma` (m/s), the coarse attitude error ψ = L_a b_a^n +
/// L_g b_g^n + noise (module docs) with the bias budgets `ba`, `bg` of the fine record
/// (initial variances `bias_var`) and the coarse white-noise part `psi_cov_noise`, and
/// the bias states δb = b̂ − b = −b, so Cov(ψ, δb) = −L C_b^n Σ_b.
#[allow(clippy::too_many_arguments)]
pub fn fine_p0(layout: &Layout, q_nb: &Quat, lat: f64, gravity: f64, omega: f64, psi_cov_noise: &Mat3, ba: &TriadBudget, bg: &TriadBudget, pos_sigma: f64, vel_sigma: f64) -> Result<DMatrix<f64>> {
    crate::error::check_positive("pos_sigma", pos_sigma)?;
    crate::error::check_positive("vel_sigma", vel_sigma)?;
    let c_nb = dcm_from_quat(q_nb);
    let (la, lg) = sensitivities(gravity, omega, lat);
    let (ma, mg) = (la * c_nb, lg * c_nb);
    let (sa, sg) = (Mat3::from_diagonal(&ba.bias_var), Mat3::from_diagonal(&bg.bias_var));
    let floor = |s: f64| Mat3::identity() * (s * s);
    let psi = ma * sa * ma.transpose() + mg * sg * mg.transpose() + psi_cov_noise + floor(P0_FLOOR.0);
    let n = layout.size();
    let mut p = DMatrix::<f64>::zeros(n, n);
    let mut put = |r: &str, c: &str, m: &Mat3| -> Result<()> {
        let (r, c) = (layout.range(r)?.start, layout.range(c)?.start);
        p.view_mut((r, c), (3, 3)).copy_from(m);
        p.view_mut((c, r), (3, 3)).copy_from(&m.transpose());
        Ok(())
    };
    put("position", "position", &floor(pos_sigma))?;
    put("velocity", "velocity", &floor(vel_sigma))?;
    put("attitude", "attitude", &psi)?;
    put("accel_bias", "accel_bias", &(sa + floor(P0_FLOOR.1)))?;
    put("gyro_bias", "gyro_bias", &(sg + floor(P0_FLOOR.2)))?;
    put("attitude", "accel_bias", &(-ma * sa))?;
    put("attitude", "gyro_bias", &(-mg * sg))?;
    Ok(p)
}

/// Zero-velocity update (ZUPT; Groves 2013, §15.3.1): the point at the lever arm of its
/// [`Mounting`] (the IMU by default) is at rest, so z = v̂_point − 0 (predicted −
/// measured), H = [0 I 0 …] on the velocity block plus the lever-arm columns of
/// [`Mounting::velocity`], R = σ²I.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ZeroVelocity {
    times: Vec<f64>,
    sigma: f64,
    #[serde(default)]
    mounting: Mounting,
}

impl ZeroVelocity {
    /// Updates at `times` (s) with velocity noise σ `sigma` (m/s, > 0).
    pub fn new(times: Vec<f64>, sigma: f64) -> Result<Self> {
        crate::error::check_positive("sigma", sigma)?;
        check_finite("zero_velocity", &times, 1)?;
        Ok(ZeroVelocity { times, sigma, mounting: Mounting::default() })
    }

    /// These updates at the lever arm and time offset of `mounting` (the times given to
    /// [`Self::new`] are the stamps).
    pub fn with_mounting(mut self, mounting: Mounting) -> Self {
        self.times = mounting.imu_times(&self.times);
        self.mounting = mounting;
        self
    }

    fn model(&self, ctx: &AidingContext) -> Result<Measurement> {
        let mut h = DMatrix::<f64>::zeros(3, ctx.layout.size());
        h.view_mut((0, ctx.layout.range("velocity")?.start), (3, 3)).fill_with_identity();
        let mut z = ctx.nav.vel;
        self.mounting.add_velocity_terms(ctx, &mut z, &mut h)?;
        Ok(Measurement { z: z.as_slice().to_vec(), h, r: DMatrix::identity(3, 3) * (self.sigma * self.sigma) })
    }
}

#[typetag::serde]
impl Aiding for ZeroVelocity {
    fn name(&self) -> &str {
        "zero_velocity"
    }
    fn times(&self) -> &[f64] {
        &self.times
    }
    fn measure(&mut self, _j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        self.model(ctx).map(Some)
    }
}

/// Zero-angular-rate update (ZARU; Groves 2013, §15.3.3): at rest the body turns with
/// the Earth only, so the Earth-relative rate ω̂_eb = ω̂_ib − Ĉ_n^b ω_ie^n(φ̂) is measured
/// as zero. ω̂_ib is the mean bias-compensated gyro rate since the previous update (rates
/// weighted by their interval, or increments summed over the time they span), so
/// R = (N²/T + σ²)I for the gyro white-noise PSD N² over the T s averaged, plus an
/// allowance σ (rad/s) for motion the record may hold (e.g. vibration).
///
/// Linearisation (δx = estimate − true, Ĉ_n^b = C_n^b(I + [ψ×]), ω̃ = ω_ib + b_g + n,
/// ω_ib = C_n^b ω_ie^n at rest, δφ = δr_N/R_M):
/// z = C_n^b ω_ie^n + b_g + n̄ − b̂_g − C_n^b(I + [ψ×])ω_ie^n(φ + δφ)
///   = Ĉ_n^b[ω_ie^n×] ψ − δb_g + Ĉ_n^b Ω(sin φ, 0, cos φ) δr_N/R_M + n̄,
/// so H has Ĉ_n^b[ω_ie^n×] on the attitude block, −I on the gyro-bias block and the
/// latitude term on the north position column.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ZeroRate {
    times: Vec<f64>,
    #[serde(with = "crate::options::by_name")]
    kind: ImuKind,
    gyro_psd: f64,
    sigma: f64,
    /// ∫ω̂ dt and the time it spans since the last update.
    sum: Vec3,
    span: f64,
}

impl ZeroRate {
    /// Updates at `times` (s) on a record of `kind`, gyro white-noise PSD `gyro_psd`
    /// (rad²/s, ≥ 0) and motion allowance `sigma` (rad/s, ≥ 0; not both zero).
    pub fn new(times: Vec<f64>, kind: ImuKind, gyro_psd: f64, sigma: f64) -> Result<Self> {
        check_finite("zero_rate", &times, 1)?;
        for (field, x) in [("gyro_psd", gyro_psd), ("sigma", sigma)] {
            if !(x.is_finite() && x >= 0.0) {
                return Err(invalid(field, format!("must be finite and >= 0, got {x}")));
            }
        }
        if gyro_psd == 0.0 && sigma == 0.0 {
            return Err(invalid("sigma", "must be > 0 when the gyro has no white noise (the update would have R = 0)"));
        }
        Ok(ZeroRate { times, kind, gyro_psd, sigma, sum: Vec3::zeros(), span: 0.0 })
    }

    /// The same updates on a record of `kind` (a source checked before the INS that
    /// gives the kind is built).
    pub fn on_record(self, kind: ImuKind) -> Self {
        ZeroRate { kind, ..self }
    }

    fn model(&mut self, ctx: &AidingContext) -> Result<Option<Measurement>> {
        if self.span <= 0.0 {
            return Ok(None);
        }
        let rate = self.sum / self.span;
        let r = (self.gyro_psd / self.span + self.sigma * self.sigma) * DMatrix::identity(3, 3);
        (self.sum, self.span) = (Vec3::zeros(), 0.0);
        let loc = ctx.ell.local(ctx.nav.lla.x, ctx.nav.lla.z);
        let w_ie = loc.earth_rate();
        let c_bn = dcm_from_quat(&ctx.nav.q_nb).transpose();
        let z = rate - c_bn * w_ie;
        let mut h = DMatrix::<f64>::zeros(3, ctx.layout.size());
        h.view_mut((0, ctx.layout.range("attitude")?.start), (3, 3)).copy_from(&(c_bn * skew(&w_ie)));
        h.view_mut((0, ctx.layout.range("gyro_bias")?.start), (3, 3)).copy_from(&(-Mat3::identity()));
        let dlat = c_bn * Vec3::new(loc.sin, 0.0, loc.cos) * (ctx.ell.omega / loc.rm);
        h.view_mut((0, ctx.layout.range("position")?.start), (3, 1)).copy_from(&dlat);
        Ok(Some(Measurement { z: z.as_slice().to_vec(), h, r }))
    }
}

#[typetag::serde]
impl Aiding for ZeroRate {
    fn name(&self) -> &str {
        "zero_rate"
    }
    fn times(&self) -> &[f64] {
        &self.times
    }
    fn observe(&mut self, _t: f64, dt: f64, gyro: &Vec3, _accel: &Vec3, _nav: &NavState) {
        self.sum += match self.kind {
            ImuKind::Rates => gyro * dt,
            ImuKind::Increments => *gyro,
        };
        self.span += dt;
    }
    fn measure(&mut self, _j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        self.model(ctx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::aided::{run_aided, AidedConfig, AidedIns};
    use crate::filter::discretize::Discretization;
    use crate::filter::ins::{BiasModel, InsNoise};
    use crate::filter::kf::LoopMode;
    use crate::math::{dcm_from_euler, quat_from_euler};

    /// An error-free static record at (lat, 0, 100 m) with attitude `euler`, plus the
    /// constant sensor errors `ba`, `bg` (body), 100 Hz for `seconds`.
    fn record(lat: f64, euler: Vec3, ba: Vec3, bg: Vec3, seconds: f64) -> (Vec<f64>, Vec<Vec3>, Vec<Vec3>, Vec3) {
        let ell = crate::earth::WGS84;
        let lla = Vec3::new(lat, 0.0, 100.0);
        let loc = ell.local(lla.x, lla.z);
        let c_bn = dcm_from_euler(euler.x, euler.y, euler.z).transpose();
        let n = (seconds * 100.0) as usize;
        let t: Vec<f64> = (0..=n).map(|k| k as f64 * 0.01).collect();
        let f = c_bn * Vec3::new(0.0, 0.0, -loc.gravity) + ba;
        let w = c_bn * loc.earth_rate() + bg;
        (t.clone(), vec![w; t.len()], vec![f; t.len()], lla)
    }

    fn psi(est: &Quat, truth: &Mat3) -> Vec3 {
        let m = truth * dcm_from_quat(est).transpose();
        Vec3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)]) * 0.5
    }

    /// Error-free data: the attitude to rounding; constant biases: ψ as the closed form.
    #[test]
    fn coarse_matches_the_truth_and_the_closed_form_limit() {
        let ell = crate::earth::WGS84;
        let euler = Vec3::new(0.02, -0.03, 2.0);
        let truth = dcm_from_euler(euler.x, euler.y, euler.z);
        let model = ImuErrorModel::default();
        let (t, g, a, lla) = record(0.9, euler, Vec3::zeros(), Vec3::zeros(), 10.0);
        let c = coarse(&t, &g, &a, ImuKind::Rates, &lla, &ell, &model).unwrap();
        assert!(psi(&c.q_nb, &truth).norm() < 1e-12, "{:?}", psi(&c.q_nb, &truth));
        // small enough that the second-order terms (relative size ~ψ) stay below the 1e-3 tolerance
        let (ba, bg) = (Vec3::new(3e-5, -5e-5, 1e-4), Vec3::new(2e-8, 1e-8, -3e-8));
        let (t, g, a, lla) = record(0.9, euler, ba, bg, 10.0);
        let c = coarse(&t, &g, &a, ImuKind::Rates, &lla, &ell, &model).unwrap();
        let p = psi(&c.q_nb, &truth);
        let (ban, bgn) = (truth * ba, truth * bg);
        let gamma = ell.local(lla.x, lla.z).gravity;
        let want_n = ban.y / gamma;
        let want = Vec3::new(want_n, -ban.x / gamma, bgn.y / (ell.omega * lla.x.cos()) - want_n * lla.x.tan());
        assert!((p - want).norm() < 1e-3 * want.norm(), "{p:?} vs {want:?}");
    }

    #[test]
    fn bad_records_name_their_argument() {
        let ell = crate::earth::WGS84;
        let model = ImuErrorModel::default();
        let field = |r: Result<CoarseAlignment>| match r {
            Err(crate::error::NavError::InvalidInput { field, .. }) => field,
            other => panic!("expected InvalidInput, got {other:?}"),
        };
        let (t, g, a, lla) = record(0.9, Vec3::zeros(), Vec3::zeros(), Vec3::zeros(), 10.0);
        assert_eq!(field(coarse(&t[..50], &g[..50], &a[..50], ImuKind::Rates, &lla, &ell, &model)), "imu");
        assert_eq!(field(coarse(&t, &g, &a, ImuKind::Rates, &Vec3::new(1.56, 0.0, 0.0), &ell, &model)), "lla");
        let mut moving = a.clone();
        moving.iter_mut().skip(500).for_each(|f| f.x += 0.5);
        assert_eq!(field(coarse(&t, &g, &moving, ImuKind::Rates, &lla, &ell, &model)), "imu");
        let mut nan = a.clone();
        nan[7].y = f64::NAN;
        assert_eq!(field(coarse(&t, &g, &nan, ImuKind::Rates, &lla, &ell, &model)), "accel");
    }

    /// Fine alignment on error-free data with a 1 mrad heading error at the start: the
    /// ZUPT/ZARU filter pulls the heading in (gyrocompassing through the velocity drift).
    #[test]
    fn zero_motion_updates_pull_the_heading_in() {
        let ell = crate::earth::WGS84;
        let euler = Vec3::new(0.0, 0.0, 0.5);
        let (t, g, a, lla) = record(0.9, euler, Vec3::zeros(), Vec3::zeros(), 120.0);
        let start = quat_from_euler(0.0, 0.0, 0.5 + 1e-2);
        let noise = InsNoise { accel_psd: 1e-10, gyro_psd: 1e-14, accel_bias: BiasModel::RandomConstant, gyro_bias: BiasModel::RandomConstant };
        let cfg = AidedConfig { noise, predict_every: 10, method: Discretization::VanLoan, mode: LoopMode::Closed, sequential: false, gate: None };
        let layout = Layout::ins_with(&[]).unwrap();
        let ba = TriadBudget { white_psd: 1e-10, walk_psd: 0.0, bias_var: Vec3::repeat(1e-8), drift_var: 0.0 };
        let bg = TriadBudget { white_psd: 1e-14, walk_psd: 0.0, bias_var: Vec3::repeat(1e-16), drift_var: 0.0 };
        let gamma = ell.local(lla.x, lla.z).gravity;
        let p0 = fine_p0(&layout, &start, lla.x, gamma, ell.omega, &(Mat3::identity() * 1e-4), &ba, &bg, 1.0, 0.01).unwrap();
        let times: Vec<f64> = (1..=120).map(f64::from).collect();
        let zv: Box<dyn Aiding> = Box::new(ZeroVelocity::new(times.clone(), 1e-3).unwrap());
        let aid = crate::filter::sources::Sources::new(vec![zv, Box::new(ZeroRate::new(times, ImuKind::Rates, 1e-14, 0.0).unwrap())]).unwrap();
        let s0 = NavState { t: 0.0, lla, vel: Vec3::zeros(), q_nb: start };
        let ins = AidedIns::new(s0, ImuKind::Rates, ell, Vec3::zeros(), Vec3::zeros(), nalgebra::DVector::zeros(0), p0, cfg, aid).unwrap();
        let (out, _) = run_aided(ins, &t, &g, &a).unwrap();
        let last = out.nav.last().unwrap();
        let err = psi(&last.q_nb, &dcm_from_euler(euler.x, euler.y, euler.z));
        assert!(err.norm() < 1e-4, "{err:?}");
    }
}
