//! Single-point positioning (standard mode, Demidov 2009 Ch. 2): Gauss–Newton least
//! squares for (position, c·δt_r, τ_GPS) with the exact H rows of our own prediction, the
//! thesis's residual metric, DOP, and the Doppler velocity solution.

use super::ephemeris::Ephemerides;
use super::geometry::{geometry, Geometry};
use super::observation::{check_unique, Atmosphere, Observation};
use super::{glonass_l1_hz, glonass_l2_hz, SatId, System, C_LIGHT, GPS_L1_HZ, GPS_L2_HZ};
use crate::earth::{dcm_ned_to_ecef, WGS84};
use crate::error::{invalid, NavError, Result};
use crate::math::Vec3;
use nalgebra::{DMatrix, DVector};

#[derive(Debug, Clone, Copy)]
pub struct SppConfig {
    /// Estimate τ_GPS (dropped anyway when no GLONASS satellite is used).
    pub use_tau: bool,
    pub atm: Atmosphere,
    pub sigma_gps: f64,
    pub sigma_glo: f64,
    /// σ_i = σ/sin E_i instead of σ.
    pub elevation_weight: bool,
    /// Satellites below this elevation (rad) are left out once the position is known.
    pub elevation_mask: f64,
    /// Residual χ² test with exclusion of the faulty satellite (RAIM FDE).
    pub fault_detection: bool,
    /// Solve with the ionosphere-free code combination ([`ionosphere_free`]); `atm` then
    /// carries no ionosphere and the σ are those of the combination.
    pub ionosphere_free: bool,
}

/// Why a satellite of an epoch is not in its solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exclusion {
    /// No pseudorange (NaN: not tracked).
    NoCode,
    /// No broadcast set valid at the epoch.
    NoEphemeris,
    /// Below the elevation mask.
    Elevation,
    /// Excluded by the residual χ² test (RAIM FDE).
    Fault,
    /// The epoch has fewer usable satellites than unknowns: no solution.
    TooFew,
    /// No second-frequency code for the ionosphere-free combination.
    NoSecondCode,
}

impl Exclusion {
    /// Every reason, in code order (code k + 1 is `ALL[k]`; 0 means used).
    pub const ALL: [Exclusion; 6] =
        [Exclusion::NoCode, Exclusion::NoEphemeris, Exclusion::Elevation, Exclusion::Fault, Exclusion::TooFew, Exclusion::NoSecondCode];
    /// Its name in result tables.
    pub const fn name(self) -> &'static str {
        match self {
            Exclusion::NoCode => "no_code",
            Exclusion::NoEphemeris => "no_ephemeris",
            Exclusion::Elevation => "elevation",
            Exclusion::Fault => "fault",
            Exclusion::TooFew => "too_few_satellites",
            Exclusion::NoSecondCode => "no_second_code",
        }
    }
    /// Its code in result rows (1-based; 0 = used).
    pub fn code(self) -> f64 {
        Self::ALL.iter().position(|e| *e == self).map_or(0.0, |k| (k + 1) as f64)
    }
}

/// One satellite of an epoch: its look angles, post-fit residual and code σ at the
/// solution (NaN when the satellite has no ephemeris or code, or the epoch no solution),
/// and why it was left out, if it was.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatelliteUse {
    pub sat: SatId,
    pub elevation: f64,
    pub azimuth: f64,
    pub residual: f64,
    /// Code σ (m) the least squares gives (or would give) this satellite: weight 1/σ².
    pub sigma: f64,
    pub excluded: Option<Exclusion>,
}

/// Unweighted DOP values of the satellites used (Langley 1999, "Dilution of precision",
/// GPS World 10(5)): Q = (GᵀG)⁻¹ with rows (−u_ENU, 1[, 1 on GLONASS rows when τ_GPS is
/// estimated]); PDOP² = Q_EE + Q_NN + Q_UU, HDOP² = Q_EE + Q_NN, VDOP² = Q_UU, TDOP² = Q of
/// the receiver clock, GDOP² = PDOP² + TDOP² (the τ_GPS column widens them, its own
/// variance is not summed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dop {
    pub gdop: f64,
    pub pdop: f64,
    pub hdop: f64,
    pub vdop: f64,
    pub tdop: f64,
}

#[derive(Debug, Clone)]
pub struct SppSolution {
    /// ECEF (m) and geodetic (lat, lon, h) of the antenna.
    pub pos: Vec3,
    pub lla: Vec3,
    /// c·δt_r (m).
    pub clock_m: f64,
    /// τ_GPS (s) when estimated.
    pub tau: Option<f64>,
    /// Covariance of (x, y, z, c·δt_r[, τ_GPS]) in m² (τ rows/columns in s).
    pub cov: DMatrix<f64>,
    /// Residual metric m = Σ|z_i − h_iᵀx̂|/(N − n) (m), NaN when N = n (Eq. 23).
    pub residual_metric: f64,
    /// Weighted sum of squared post-fit residuals Σ r_i²/σ_i² of the used satellites.
    pub chi2: f64,
    /// Post-fit residuals (m) of the used observations, in input order.
    pub residuals: Vec<f64>,
    /// Every input observation, in input order: used or why not.
    pub satellites: Vec<SatelliteUse>,
    pub n_used: usize,
    pub n_unknowns: usize,
    pub dop: Dop,
    pub iterations: usize,
}

/// Code σ (m) of a satellite: the system's σ, divided by sin E (floored at 0.05) with
/// `elevation_weight` once the elevation is known.
fn code_sigma(cfg: &SppConfig, sat: SatId, elevation: Option<f64>) -> f64 {
    let s = if sat.system == System::Glonass { cfg.sigma_glo } else { cfg.sigma_gps };
    match elevation {
        Some(e) if cfg.elevation_weight => s / e.sin().max(0.05),
        _ => s,
    }
}

/// Code corrected for the satellite clock and the atmosphere: P + c·δt^s − I − T (m).
fn corrected_code(o: &Observation, g: &Geometry, atm: &Atmosphere, lla: &Vec3, t: f64) -> f64 {
    o.code + C_LIGHT * g.sat.clock - atm.delay(o.sat, o.channel, lla, g, t)
}

/// The carriers (Hz) of a satellite's first and second code: GPS L1/L2, GLONASS L1/L2 of
/// its FDMA channel.
fn carriers(sat: SatId, channel: i8) -> (f64, f64) {
    match sat.system {
        System::Gps => (GPS_L1_HZ, GPS_L2_HZ),
        System::Glonass => (glonass_l1_hz(channel), glonass_l2_hz(channel)),
    }
}

/// Noise gain of the ionosphere-free combination of two equally noisy codes on carriers
/// f₁, f₂: √(f₁⁴ + f₂⁴)/(f₁² − f₂²) (2.98 for GPS L1/L2, 2.96 for GLONASS, whose ratio is
/// 9/7 on every channel).
pub fn ionosphere_free_gain(f1: f64, f2: f64) -> f64 {
    (f1.powi(4) + f2.powi(4)).sqrt() / (f1 * f1 - f2 * f2)
}

/// The ionosphere-free code combination (f₁²P₁ − f₂²P₂)/(f₁² − f₂²), which removes the
/// first-order ionospheric delay (Groves 2013, Eq. 9.50), plus c·T_GD: the broadcast GPS
/// clock refers to this combination, while the L1 clock of the ephemerides includes −T_GD
/// (IS-GPS-200 20.3.3.3.3.2). NaN where either code is missing.
pub fn ionosphere_free(eph: &Ephemerides, t: f64, obs: &[Observation]) -> Vec<Observation> {
    obs.iter()
        .map(|o| {
            let (f1, f2) = carriers(o.sat, o.channel);
            let (a, b) = (f1 * f1, f2 * f2);
            let code = if o.code.is_finite() && o.code2.is_finite() {
                (a * o.code - b * o.code2) / (a - b) + C_LIGHT * eph.group_delay(o.sat, t).unwrap_or(0.0)
            } else {
                f64::NAN
            };
            Observation { code, ..*o }
        })
        .collect()
}

/// How long before its stamp a signal may have left the satellite (s): light time
/// (< 0.09 s for a receiver on the ground or in low orbit) plus a receiver clock offset.
const SIGNAL_SPAN: f64 = 0.2;

/// Measured less predicted code (m) of `o` with geometry `g` at the unknowns `x`
/// (position, c·δt_r[, c·τ_GPS on GLONASS rows when `with_tau`]).
// invariant: x has at least 4 entries, 5 when with_tau.
#[allow(clippy::indexing_slicing)]
fn code_residual(o: &Observation, g: &Geometry, atm: &Atmosphere, lla: &Vec3, t_rx: f64, x: &DVector<f64>, with_tau: bool) -> f64 {
    let tau = if with_tau && o.sat.system == System::Glonass { x[4] } else { 0.0 };
    corrected_code(o, g, atm, lla, t_rx) - (g.range + x[3] + tau)
}

/// Upper 0.1 % point of χ²(k): the tabulated values for k ≤ 10 (Abramowitz & Stegun 1964,
/// Table 26.8) and the Wilson–Hilferty cube beyond (Wilson & Hilferty 1931; within 0.6 %
/// for k > 10). RTKLIB's test uses the same level (Takasu 2013, `chisqr` in `pntpos.c`).
pub fn chi2_threshold(k: usize) -> f64 {
    const TABLE: [f64; 10] = [10.828, 13.816, 16.266, 18.467, 20.515, 22.458, 24.322, 26.124, 27.877, 29.588];
    match k {
        0 => f64::INFINITY,
        1..=10 => TABLE.get(k - 1).copied().unwrap_or(f64::INFINITY),
        _ => {
            let (k, z) = (k as f64, 3.090_232);
            let c = 2.0 / (9.0 * k);
            k * (1.0 - c + z * c.sqrt()).powi(3)
        }
    }
}

/// The outcome of [`least_squares`]: a converged fit, or too few usable satellites for
/// the unknowns (with those the mask removed).
enum Outcome {
    Fit(Fit),
    TooFew { used: usize, needed: usize, masked: Vec<usize> },
}

/// A converged least-squares fit of one set of satellites.
struct Fit {
    x: DVector<f64>,
    with_tau: bool,
    /// Indices (into the epoch's observations) used, and those the mask removed.
    used: Vec<usize>,
    masked: Vec<usize>,
    residuals: DVector<f64>,
    weights: DVector<f64>,
    normal_inverse: DMatrix<f64>,
    iterations: usize,
}

impl Fit {
    fn chi2(&self) -> f64 {
        self.residuals.iter().zip(self.weights.iter()).map(|(r, w)| r * r * w).sum()
    }
    fn redundancy(&self) -> usize {
        self.used.len().saturating_sub(self.x.len())
    }
}

/// Gauss–Newton least squares for (position, c·δt_r[, c·τ_GPS]) from the observations
/// `candidates` (indices into `obs`), starting at `x0`. Once the position is known
/// (|r| > 1000 km) satellites below the mask are dropped; the signal leaves each satellite
/// at the receive time t − c·δt_r/c of the current clock estimate.
// invariant: x has n ∈ {4, 5} unknowns (5 exactly when with_tau), h is m × n, z and
// w have m = used.len() rows, i < m; every index in candidates is < obs.len().
#[allow(clippy::indexing_slicing)]
fn least_squares(eph: &Ephemerides, t: f64, obs: &[Observation], candidates: &[usize], cfg: &SppConfig, x0: Option<Vec3>) -> Result<Outcome> {
    let mut x = DVector::<f64>::zeros(5);
    if let Some(p) = x0 {
        x.rows_mut(0, 3).copy_from(&p);
    }
    let mut previous: Option<Vec<usize>> = None;
    let mut iterations = 0;
    loop {
        iterations += 1;
        let r = Vec3::new(x[0], x[1], x[2]);
        let known = r.norm() > 1e6;
        let lla = if known { WGS84.ecef_to_lla(&r) } else { Vec3::new(0.0, 0.0, -WGS84.a) };
        let t_rx = t - x[3] / C_LIGHT;
        let tau = x[4] / C_LIGHT;
        // the mask is applied afresh at every iterate: early iterates can be far off
        let (mut used, mut masked, mut geo) = (Vec::new(), Vec::new(), Vec::new());
        for &i in candidates {
            let g = geometry(eph, obs[i].sat, t_rx, &r, &Vec3::zeros(), lla.x, lla.y, tau)?;
            if known && g.elevation < cfg.elevation_mask {
                masked.push(i);
            } else {
                used.push(i);
                geo.push(g);
            }
        }
        let with_tau = cfg.use_tau && used.iter().any(|&i| obs[i].sat.system == System::Glonass);
        let n = if with_tau { 5 } else { 4 };
        if used.len() < n {
            return Ok(Outcome::TooFew { used: used.len(), needed: n, masked });
        }
        let same_set = previous.as_ref() == Some(&used);
        let m = used.len();
        let mut h = DMatrix::<f64>::zeros(m, n);
        let mut z = DVector::<f64>::zeros(m);
        let mut w = DVector::<f64>::zeros(m);
        for (k, (&i, g)) in used.iter().zip(&geo).enumerate() {
            let o = &obs[i];
            let glo = o.sat.system == System::Glonass;
            z[k] = code_residual(o, g, &cfg.atm, &lla, t_rx, &x, with_tau);
            let row = -g.los * g.kappa;
            h[(k, 0)] = row.x;
            h[(k, 1)] = row.y;
            h[(k, 2)] = row.z;
            h[(k, 3)] = 1.0;
            if with_tau {
                // ∂P̂/∂(cτ) = 1 − κ uᵀv_s/c on GLONASS rows (the satellite epoch moves by −τ)
                h[(k, 4)] = if glo { 1.0 - g.kappa * g.los.dot(&g.sat.vel) / C_LIGHT } else { 0.0 };
            }
            let s = code_sigma(cfg, o.sat, known.then_some(g.elevation));
            w[k] = 1.0 / (s * s);
        }
        let hw = DMatrix::from_fn(n, m, |a, b| h[(b, a)] * w[b]);
        let chol = (&hw * &h).cholesky().ok_or_else(|| NavError::Numerical(format!("singular normal matrix at t = {t} s (degenerate geometry)")))?;
        let dx = chol.solve(&(&hw * &z));
        for j in 0..n {
            x[j] += dx[j];
        }
        if !with_tau {
            x[4] = 0.0;
        }
        if dx.rows(0, 3).norm() < 1e-4 && same_set {
            // final residuals at the converged x: z − H·dx
            let residuals = &z - &h * &dx;
            let normal_inverse = chol.inverse();
            return Ok(Outcome::Fit(Fit { x: x.rows(0, n).into_owned(), with_tau, used, masked, residuals, weights: w, normal_inverse, iterations }));
        }
        previous = Some(used);
        if iterations >= 30 {
            return Err(NavError::Numerical(format!("position solution did not converge at t = {t} s")));
        }
    }
}

/// Position solution at GPS time t from the code observations of one epoch; `x0` is the
/// initial ECEF guess (the Earth's centre when None). A satellite without code or without
/// a valid broadcast set, or below the mask, is left out and reported; with
/// `fault_detection`, while the weighted residuals fail the χ² test ([`chi2_threshold`])
/// and two or more observations are redundant, the satellite whose removal leaves the
/// smallest χ² per degree of freedom is excluded (the subset test of RTKLIB's
/// `raim_fde`, Takasu 2013). With fewer usable satellites than unknowns, the epoch has no
/// solution ([`Epoch::TooFew`]).
// invariant: fit.used/masked hold indices < obs.len() (= satellites.len()); the fit's x
// has n ∈ {4, 5} entries and its normal_inverse is n × n.
#[allow(clippy::indexing_slicing)]
fn solve_epoch(eph: &Ephemerides, t: f64, obs: &[Observation], cfg: &SppConfig, x0: Option<Vec3>) -> Result<Epoch> {
    check_unique("obs", obs)?;
    let mut satellites: Vec<SatelliteUse> =
        obs.iter().map(|o| SatelliteUse { sat: o.sat, elevation: f64::NAN, azimuth: f64::NAN, residual: f64::NAN, sigma: f64::NAN, excluded: None }).collect();
    let mut no_ephemeris = None;
    for (i, o) in obs.iter().enumerate() {
        if o.code.is_nan() {
            satellites[i].excluded = Some(Exclusion::NoCode);
            continue;
        }
        if !o.code.is_finite() {
            return Err(invalid("obs", format!("infinite pseudorange at index {i}")));
        }
        // valid over the whole signal path: the transmit time is up to ~0.1 s (light time
        // plus a receiver clock of up to tens of ms) before the stamp
        if let Err(e) = eph.state(o.sat, t, 0.0).and_then(|_| eph.state(o.sat, t - SIGNAL_SPAN, 0.0)) {
            no_ephemeris.get_or_insert(e);
            satellites[i].excluded = Some(Exclusion::NoEphemeris);
            continue;
        }
        if o.sat.system == System::Glonass && eph.channel(o.sat)? != o.channel {
            return Err(invalid("obs", format!("{} at index {i}: channel {} but the ephemeris says {}", o.sat.name(), o.channel, eph.channel(o.sat)?)));
        }
    }
    let combined;
    let obs = if cfg.ionosphere_free {
        for (i, o) in obs.iter().enumerate() {
            if satellites[i].excluded.is_none() && !o.code2.is_finite() {
                satellites[i].excluded = Some(Exclusion::NoSecondCode);
            }
        }
        combined = ionosphere_free(eph, t, obs);
        &combined[..]
    } else {
        obs
    };
    let candidates: Vec<usize> = (0..obs.len()).filter(|&i| satellites[i].excluded.is_none()).collect();
    if candidates.is_empty() {
        if let Some(e) = no_ephemeris {
            return Err(e); // no satellite is covered: the time is outside the ephemerides
        }
    }
    let mut fit = match least_squares(eph, t, obs, &candidates, cfg, x0)? {
        Outcome::Fit(f) => f,
        Outcome::TooFew { used, needed, masked } => {
            for u in satellites.iter_mut().filter(|u| u.excluded.is_none()) {
                u.excluded = Some(Exclusion::TooFew);
            }
            for i in masked {
                satellites[i].excluded = Some(Exclusion::Elevation);
            }
            return Ok(Epoch::TooFew { used, needed, satellites });
        }
    };
    let mut faults = Vec::new();
    while cfg.fault_detection && fit.redundancy() >= 2 && fit.chi2() > chi2_threshold(fit.redundancy()) {
        let start = Vec3::new(fit.x[0], fit.x[1], fit.x[2]);
        let best = fit
            .used
            .iter()
            .filter_map(|&k| {
                let rest: Vec<usize> = fit.used.iter().copied().filter(|&i| i != k).collect();
                match least_squares(eph, t, obs, &rest, cfg, Some(start)) {
                    Ok(Outcome::Fit(f)) => Some((k, f)),
                    _ => None,
                }
            })
            .min_by(|a, b| (a.1.chi2() / a.1.redundancy().max(1) as f64).total_cmp(&(b.1.chi2() / b.1.redundancy().max(1) as f64)));
        let Some((k, f)) = best else { break };
        faults.push(k);
        let masked = fit.masked.clone();
        fit = f;
        fit.masked.extend(masked);
    }
    for &i in &fit.masked {
        satellites[i].excluded = Some(Exclusion::Elevation);
    }
    for &i in &faults {
        satellites[i].excluded = Some(Exclusion::Fault);
    }
    let n = fit.x.len();
    let pos = Vec3::new(fit.x[0], fit.x[1], fit.x[2]);
    let lla = WGS84.ecef_to_lla(&pos);
    let tau = if fit.with_tau { fit.x[4] / C_LIGHT } else { 0.0 };
    let t_rx = t - fit.x[3] / C_LIGHT;
    // look angles, residuals and σ of every satellite with code and ephemeris at the
    // solution; the lines of sight of the used ones for the DOP
    let mut lines_of_sight = Vec::with_capacity(fit.used.len());
    for (i, o) in obs.iter().enumerate() {
        if matches!(satellites[i].excluded, Some(Exclusion::NoCode | Exclusion::NoEphemeris | Exclusion::NoSecondCode)) {
            continue;
        }
        let g = geometry(eph, o.sat, t_rx, &pos, &Vec3::zeros(), lla.x, lla.y, tau)?;
        satellites[i].residual = code_residual(o, &g, &cfg.atm, &lla, t_rx, &fit.x, fit.with_tau);
        satellites[i].sigma = code_sigma(cfg, o.sat, Some(g.elevation));
        satellites[i].elevation = g.elevation;
        satellites[i].azimuth = g.azimuth.rem_euclid(std::f64::consts::TAU);
        if fit.used.contains(&i) {
            lines_of_sight.push((g.los, o.sat.system == System::Glonass));
        }
    }
    let mut cov = fit.normal_inverse.clone();
    if fit.with_tau {
        for j in 0..5 {
            cov[(4, j)] /= C_LIGHT;
            cov[(j, 4)] /= C_LIGHT;
        }
    }
    let m = fit.used.len();
    let metric = if m > n { fit.residuals.iter().map(|v| v.abs()).sum::<f64>() / (m - n) as f64 } else { f64::NAN };
    let mut used_sorted = fit.used.clone();
    used_sorted.sort_unstable();
    let residuals = used_sorted.iter().map(|&i| satellites[i].residual).collect();
    Ok(Epoch::Solved(SppSolution {
        pos,
        lla,
        clock_m: fit.x[3],
        tau: fit.with_tau.then_some(tau),
        cov,
        residual_metric: metric,
        chi2: fit.chi2(),
        residuals,
        satellites,
        n_used: m,
        n_unknowns: n,
        dop: dop(&lines_of_sight, &lla, fit.with_tau)?,
        iterations: fit.iterations,
    }))
}

/// One epoch of [`solve_epoch`]: solved, or too few usable satellites (`used` of the
/// `needed` unknowns) with every satellite's reason.
enum Epoch {
    Solved(SppSolution),
    TooFew { used: usize, needed: usize, satellites: Vec<SatelliteUse> },
}

/// Position solution at GPS time t from the code observations of one epoch
/// ([`solve_epoch`]); too few usable satellites is an error naming `obs` with the count.
pub fn solve_position(eph: &Ephemerides, t: f64, obs: &[Observation], cfg: &SppConfig, x0: Option<Vec3>) -> Result<SppSolution> {
    match solve_epoch(eph, t, obs, cfg, x0)? {
        Epoch::Solved(s) => Ok(s),
        Epoch::TooFew { used, needed, .. } => {
            let what = if needed == 5 { "position, clock and τ_GPS" } else { "position and clock" };
            Err(invalid("obs", format!("{used} usable satellites at t = {t} s; the solver needs at least {needed} ({what})")))
        }
    }
}

/// Columns of a [`solve_epochs`] row: time, ECEF and geodetic antenna position, c·δt_r,
/// τ_GPS and its σ (s; NaN when not estimated), the residual metric, satellites used and
/// unknowns, unweighted DOP values ([`Dop`]), Doppler velocity (ECEF m/s) and c·δṫ_r (m/s;
/// NaN with fewer than four rates), satellites excluded, the weighted residual χ², and
/// the σ (m) of the position (ECEF and local east, north, up) and of c·δt_r from the
/// least-squares covariance (GᵀWG)⁻¹.
pub const SPP_COLUMNS: [&str; 31] = [
    "time_s", "x_m", "y_m", "z_m", "lat_rad", "lon_rad", "h_m", "clock_m", "tau_gps_s", "sigma_tau_gps_s", "residual_metric_m", "n_sats",
    "n_unknowns", "gdop", "pdop", "hdop", "vdop", "tdop", "vx_mps", "vy_mps", "vz_mps", "clock_drift_mps", "n_excluded", "chi2",
    "sigma_x_m", "sigma_y_m", "sigma_z_m", "sigma_e_m", "sigma_n_m", "sigma_u_m", "sigma_clock_m",
];

/// Columns of a per-satellite row of [`solve_epochs`]: time, elevation and azimuth (rad),
/// post-fit residual (m), the code σ of its weight (m), and the exclusion code (0 used,
/// k + 1 for [`Exclusion::ALL`]`[k]`).
pub const SPP_SATELLITE_COLUMNS: [&str; 6] = ["time_s", "elevation_rad", "azimuth_rad", "residual_m", "sigma_m", "excluded"];

/// The unknowns of an epoch's covariance ([`SppRows::covariance`]), in order:
/// ECEF position (m), c·δt_r (m), τ_GPS (s).
pub const SPP_COVARIANCE_STATES: [&str; 5] = ["x_m", "y_m", "z_m", "clock_m", "tau_gps_s"];

/// The rows of [`solve_epochs`]: one per solved epoch, and one per satellite of every
/// epoch with its name.
#[derive(Debug, Clone, Default)]
pub struct SppRows {
    pub epochs: Vec<[f64; 31]>,
    pub satellites: Vec<[f64; 6]>,
    pub satellite_names: Vec<String>,
    /// Per solved epoch, the 5 × 5 covariance of [`SPP_COVARIANCE_STATES`] (row-major;
    /// m², m·s, s²), with the τ_GPS row and column NaN when τ_GPS is not estimated.
    pub covariance: Vec<[f64; 25]>,
}

/// Single-point positioning epoch by epoch: each position solution starts from the
/// previous epoch's (the first from the Earth's centre); the Doppler velocity
/// ([`solve_velocity`], rate σ `sigma_rate` m/s) of the used satellites when at least
/// four of them have a rate. An epoch with fewer usable satellites than unknowns has no
/// row; its satellites are reported as [`Exclusion::TooFew`] (unless excluded earlier).
// invariant: tau is Some only for the 5-unknown solution, whose cov is 5 × 5; cov is at
// least 4 × 4 (position, clock).
#[allow(clippy::indexing_slicing)]
pub fn solve_epochs(eph: &Ephemerides, epochs: &[(f64, Vec<Observation>)], cfg: &SppConfig, sigma_rate: f64) -> Result<SppRows> {
    crate::error::check_positive("sigma_rate", sigma_rate)?;
    let mut x0 = None;
    let mut out = SppRows::default();
    for (t, ob) in epochs {
        let s = match solve_epoch(eph, *t, ob, cfg, x0)? {
            Epoch::Solved(s) => s,
            Epoch::TooFew { satellites, .. } => {
                for u in satellites {
                    out.satellites.push([*t, f64::NAN, f64::NAN, f64::NAN, f64::NAN, u.excluded.map_or(0.0, Exclusion::code)]);
                    out.satellite_names.push(u.sat.name());
                }
                continue;
            }
        };
        x0 = Some(s.pos);
        let used: Vec<Observation> = ob.iter().zip(&s.satellites).filter(|(_, u)| u.excluded.is_none()).map(|(o, _)| *o).collect();
        let (v, d) = if used.iter().filter(|o| o.rate.is_finite()).count() >= 4 {
            let (v, d, _) = solve_velocity(eph, *t - s.clock_m / C_LIGHT, &used, &s.pos, sigma_rate)?;
            (v, d)
        } else {
            (Vec3::repeat(f64::NAN), f64::NAN)
        };
        let (tau, st) = s.tau.map_or((f64::NAN, f64::NAN), |x| (x, s.cov[(4, 4)].sqrt()));
        let excluded = s.satellites.iter().filter(|u| u.excluded.is_some()).count();
        let mut cov = [f64::NAN; 25];
        for (k, c) in cov.iter_mut().enumerate() {
            let (a, b) = (k / 5, k % 5);
            if a < s.cov.nrows() && b < s.cov.ncols() {
                *c = s.cov[(a, b)];
            }
        }
        let cne = dcm_ned_to_ecef(s.lla.x, s.lla.y);
        let ned = cne.transpose() * s.cov.fixed_view::<3, 3>(0, 0) * cne;
        out.epochs.push([
            *t, s.pos.x, s.pos.y, s.pos.z, s.lla.x, s.lla.y, s.lla.z, s.clock_m, tau, st, s.residual_metric, s.n_used as f64,
            s.n_unknowns as f64, s.dop.gdop, s.dop.pdop, s.dop.hdop, s.dop.vdop, s.dop.tdop, v.x, v.y, v.z, d, excluded as f64, s.chi2,
            s.cov[(0, 0)].sqrt(), s.cov[(1, 1)].sqrt(), s.cov[(2, 2)].sqrt(), ned[(1, 1)].sqrt(), ned[(0, 0)].sqrt(), ned[(2, 2)].sqrt(),
            s.cov[(3, 3)].sqrt(),
        ]);
        out.covariance.push(cov);
        for u in &s.satellites {
            out.satellites.push([*t, u.elevation, u.azimuth, u.residual, u.sigma, u.excluded.map_or(0.0, Exclusion::code)]);
            out.satellite_names.push(u.sat.name());
        }
    }
    Ok(out)
}

/// [`Dop`] of the unit lines of sight (ECEF) of the used satellites at the solution
/// `lla`, each flagged GLONASS or not; the τ_GPS column is present when `with_tau`.
// invariant: q is n × n with n ≥ 4 (position, clock[, τ]); rows are k < los.len().
#[allow(clippy::indexing_slicing)]
fn dop(los: &[(Vec3, bool)], lla: &Vec3, with_tau: bool) -> Result<Dop> {
    let cne = dcm_ned_to_ecef(lla.x, lla.y).transpose();
    let n = if with_tau { 5 } else { 4 };
    let mut g = DMatrix::<f64>::zeros(los.len(), n);
    for (k, (u, glonass)) in los.iter().enumerate() {
        let ned = cne * u;
        g[(k, 0)] = -ned.y; // east
        g[(k, 1)] = -ned.x; // north
        g[(k, 2)] = ned.z; // up: −u_U = +u_D
        g[(k, 3)] = 1.0;
        if with_tau && *glonass {
            g[(k, 4)] = 1.0;
        }
    }
    let q = (g.transpose() * &g).try_inverse().ok_or_else(|| NavError::Numerical("singular DOP matrix".into()))?;
    let (h2, v2, t2) = (q[(0, 0)] + q[(1, 1)], q[(2, 2)], q[(3, 3)]);
    Ok(Dop { gdop: (h2 + v2 + t2).sqrt(), pdop: (h2 + v2).sqrt(), hdop: h2.sqrt(), vdop: v2.sqrt(), tdop: t2.sqrt() })
}

/// Doppler velocity (Eq. 24): least squares for (v ECEF m/s, c·δṫ_r m/s) at the known
/// antenna position `pos` and GPS receive time `t` (the stamp less the receiver clock),
/// with rows (−κu_iᵀ, 1); returns (velocity, clock drift, covariance).
// invariant: x has 4 unknowns, h and z one row per used observation (i < used.len()).
#[allow(clippy::indexing_slicing)]
pub fn solve_velocity(eph: &Ephemerides, t: f64, obs: &[Observation], pos: &Vec3, sigma: f64) -> Result<(Vec3, f64, DMatrix<f64>)> {
    check_unique("obs", obs)?;
    let used: Vec<&Observation> = obs.iter().filter(|o| o.rate.is_finite()).collect();
    if used.len() < 4 {
        return Err(invalid("obs", format!("{} Doppler measurements at t = {t} s; the velocity solver needs at least 4", used.len())));
    }
    let lla = WGS84.ecef_to_lla(pos);
    let mut v = Vec3::zeros();
    let mut x = DVector::<f64>::zeros(4);
    // linear in (v, drift) except for κ and the satellite-clock epoch: converges in 2–3 passes
    for _ in 0..6 {
        let mut h = DMatrix::<f64>::zeros(used.len(), 4);
        let mut z = DVector::<f64>::zeros(used.len());
        for (i, o) in used.iter().enumerate() {
            let g = geometry(eph, o.sat, t, pos, &v, lla.x, lla.y, 0.0)?;
            z[i] = o.rate + C_LIGHT * g.sat.clock_rate - (g.rate + x[3]);
            let row = -g.los * g.kappa;
            h.set_row(i, &nalgebra::RowDVector::from_row_slice(&[row.x, row.y, row.z, 1.0]));
        }
        let n = h.transpose() * &h;
        let ni = n.try_inverse().ok_or_else(|| NavError::Numerical(format!("singular velocity geometry at t = {t} s")))?;
        let dx = &ni * (h.transpose() * &z);
        x += &dx;
        v = Vec3::new(x[0], x[1], x[2]);
        if dx.norm() < 1e-7 {
            return Ok((v, x[3], ni * (sigma * sigma)));
        }
    }
    Err(NavError::Numerical(format!("velocity solution did not converge at t = {t} s")))
}

#[cfg(test)]
mod tests {
    use super::super::constellation::{nominal, ConstellationConfig};
    use super::super::observation::{simulate, SimConfig, Visibility};
    use super::super::gps_orbit::GpsEphemeris;
    use super::super::TimeScales;
    use super::*;

    fn setup(tau: f64, noise: f64) -> (Ephemerides, Vec3, Vec<Observation>, SimConfig) {
        let cfg = ConstellationConfig { gps: true, glonass: true, t_start: 0.0, t_end: 3600.0, tau_gps: tau, time: TimeScales::default(), clocks: true, seed: 3 };
        let eph = nominal(&cfg).unwrap();
        let lla = Vec3::new(55.75f64.to_radians(), 37.6f64.to_radians(), 200.0);
        let sim = SimConfig {
            sigma_code_gps: noise, sigma_code_glo: noise, sigma_rate: noise * 0.01, tau_gps: tau, clock_bias: 2e-4, clock_drift: 1e-8,
            atm: Atmosphere { iono: Some(Default::default()), tropo: true }, seed: 1,
        };
        let vis = Visibility { mask: 10f64.to_radians(), ..Default::default() };
        let obs = simulate(&eph, &[600.0], &[lla], &[Vec3::new(3.0, -2.0, 0.5)], &sim, &vis).unwrap().remove(0).into_iter().map(|x| x.0).collect();
        (eph, lla, obs, sim)
    }

    #[test]
    fn noiseless_solution_recovers_position_clock_tau_and_velocity() {
        let (eph, lla, obs, sim) = setup(-340e-9, 0.0);
        assert!(obs.iter().filter(|o| o.sat.system == System::Glonass).count() >= 2);
        let cfg = SppConfig { use_tau: true, atm: sim.atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false, elevation_mask: 0.0, fault_detection: false, ionosphere_free: false };
        let s = solve_position(&eph, 600.0, &obs, &cfg, None).unwrap();
        let truth = WGS84.lla_to_ecef(&lla);
        assert!((s.pos - truth).norm() < 1e-4, "{}", (s.pos - truth).norm());
        // the simulated clock is bias + drift·(t − t_start): the single epoch is the start
        assert!((s.clock_m - C_LIGHT * 2e-4).abs() < 1e-4);
        assert!((s.tau.unwrap() + 340e-9).abs() < 1e-13);
        assert!(s.residual_metric < 1e-4);
        let (v, drift, _) = solve_velocity(&eph, 600.0 - s.clock_m / C_LIGHT, &obs, &truth, 0.05).unwrap();
        let vt = dcm_ned_to_ecef(lla.x, lla.y) * Vec3::new(3.0, -2.0, 0.5);
        assert!((v - vt).norm() < 1e-6 && (drift - C_LIGHT * 1e-8).abs() < 1e-6, "{} {}", (v - vt).norm(), drift);
    }

    /// Dual-frequency codes made from the simulator's L1 codes with and without the
    /// ionosphere (the L1 delay I₁), with group delays T_GD of up to ±10 ns: the L2 code is
    /// P₁ + (γ − 1)(I₁ + c·T_GD), γ = (f₁/f₂)² (IS-GPS-200 20.3.3.3.3.2). The ionosphere-free
    /// solution without any ionosphere model recovers the position; L1 alone without the
    /// model does not.
    #[test]
    fn ionosphere_free_combination_removes_the_ionosphere_and_keeps_the_group_delay() {
        let (nominal_eph, lla, _, sim) = setup(-340e-9, 0.0);
        let gps = nominal_eph.gps_sets().map(|e| GpsEphemeris { tgd: 1e-8 * ((e.prn as f64) * 0.7).sin(), ..e.clone() }).collect();
        let eph = Ephemerides::new(gps, nominal_eph.glonass_sets().cloned().collect(), nominal_eph.time, nominal_eph.datum).unwrap();
        let vis = Visibility { mask: 10f64.to_radians(), ..Default::default() };
        let run = |atm: Atmosphere| -> Vec<Observation> {
            let sim = SimConfig { atm, ..sim };
            simulate(&eph, &[600.0], &[lla], &[Vec3::zeros()], &sim, &vis).unwrap().remove(0).into_iter().map(|x| x.0).collect()
        };
        let (with, without) = (run(sim.atm), run(Atmosphere { iono: None, tropo: true }));
        let dual: Vec<Observation> = with
            .iter()
            .zip(&without)
            .map(|(o, o0)| {
                let (f1, f2) = carriers(o.sat, o.channel);
                let gamma = (f1 / f2).powi(2);
                let code2 = o.code + (gamma - 1.0) * (o.code - o0.code + C_LIGHT * eph.group_delay(o.sat, 600.0).unwrap());
                Observation { code2, ..o.clone() }
            })
            .collect();
        assert!(dual.iter().any(|o| (o.code2 - o.code).abs() > 3.0));
        let no_model = Atmosphere { iono: None, tropo: true };
        let cfg = |ionosphere_free| SppConfig {
            use_tau: true, atm: no_model, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false, elevation_mask: 0.0, fault_detection: false, ionosphere_free,
        };
        let truth = WGS84.lla_to_ecef(&lla);
        let dual_error = (solve_position(&eph, 600.0, &dual, &cfg(true), None).unwrap().pos - truth).norm();
        let single_error = (solve_position(&eph, 600.0, &dual, &cfg(false), None).unwrap().pos - truth).norm();
        assert!(dual_error < 1e-4 && single_error > 1.0, "{dual_error} {single_error}");
        // the noise gain of the combination: ≈ 2.98 for GPS, 2.96 for GLONASS
        assert!((ionosphere_free_gain(GPS_L1_HZ, GPS_L2_HZ) - 2.978).abs() < 1e-3);
        assert!((ionosphere_free_gain(glonass_l1_hz(-7), glonass_l2_hz(-7)) - 94.6678_f64 / 32.0).abs() < 1e-4);
    }

    #[test]
    fn h_rows_match_finite_differences_of_the_prediction() {
        let (eph, lla, obs, _) = setup(-340e-9, 0.0);
        let r = WGS84.lla_to_ecef(&lla);
        for o in obs.iter().take(12) {
            let g = geometry(&eph, o.sat, 600.0, &r, &Vec3::zeros(), lla.x, lla.y, 1e-7).unwrap();
            for j in 0..3 {
                let mut d = Vec3::zeros();
                d[j] = 1.0;
                let p = geometry(&eph, o.sat, 600.0, &(r + d), &Vec3::zeros(), lla.x, lla.y, 1e-7).unwrap().range;
                let m = geometry(&eph, o.sat, 600.0, &(r - d), &Vec3::zeros(), lla.x, lla.y, 1e-7).unwrap().range;
                assert!(((p - m) / 2.0 + g.kappa * g.los[j]).abs() < 1e-8);
            }
            if o.sat.system == System::Glonass {
                let dt = 1e-6;
                let p = geometry(&eph, o.sat, 600.0, &r, &Vec3::zeros(), lla.x, lla.y, 1e-7 + dt).unwrap().range;
                let m = geometry(&eph, o.sat, 600.0, &r, &Vec3::zeros(), lla.x, lla.y, 1e-7 - dt).unwrap().range;
                let fd = (p - m) / (2.0 * dt);
                assert!((fd + g.kappa * g.los.dot(&g.sat.vel)).abs() < 1e-2 * g.sat.vel.norm().max(1.0), "{fd}");
            }
            // rate = time derivative of the range along the receiver motion
            let v = Vec3::new(30.0, -20.0, 5.0);
            let gv = geometry(&eph, o.sat, 600.0, &r, &v, lla.x, lla.y, 0.0).unwrap();
            let h = 0.5;
            let fp = geometry(&eph, o.sat, 600.0 + h, &(r + v * h), &v, lla.x, lla.y, 0.0).unwrap().range;
            let fm = geometry(&eph, o.sat, 600.0 - h, &(r - v * h), &v, lla.x, lla.y, 0.0).unwrap().range;
            assert!(((fp - fm) / (2.0 * h) - gv.rate).abs() < 1e-4, "{}", (fp - fm) / (2.0 * h) - gv.rate);
        }
    }

    /// Noiseless epochs: every row recovers the truth; τ columns NaN without GLONASS,
    /// velocity columns NaN when fewer than four rates are given.
    #[test]
    fn solve_epochs_rows_follow_the_rules() {
        let (eph, lla, obs, sim) = setup(-340e-9, 0.0);
        let cfg = SppConfig { use_tau: true, atm: sim.atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false, elevation_mask: 0.0, fault_detection: false, ionosphere_free: false };
        let gps: Vec<Observation> = obs.iter().filter(|o| o.sat.system == System::Gps).copied().collect();
        let mut few_rates = obs.clone();
        few_rates.iter_mut().skip(3).for_each(|o| o.rate = f64::NAN);
        let rows = solve_epochs(&eph, &[(600.0, obs.clone()), (600.0, gps.clone()), (600.0, few_rates)], &cfg, 0.05).unwrap().epochs;
        let truth = WGS84.lla_to_ecef(&lla);
        let col = |name: &str| SPP_COLUMNS.iter().position(|c| *c == name).unwrap();
        for r in &rows {
            assert!((Vec3::new(r[col("x_m")], r[col("y_m")], r[col("z_m")]) - truth).norm() < 1e-4);
        }
        assert!((rows[0][col("tau_gps_s")] + 340e-9).abs() < 1e-13 && rows[0][col("n_unknowns")] == 5.0);
        assert!(rows[1][col("tau_gps_s")].is_nan() && rows[1][col("n_unknowns")] == 4.0 && rows[1][col("n_sats")] == gps.len() as f64);
        assert!(rows[0][col("vx_mps")].is_finite() && rows[2][col("vx_mps")].is_nan() && rows[2][col("clock_drift_mps")].is_nan());
        assert!(solve_epochs(&eph, &[], &cfg, 0.0).unwrap_err().to_string().starts_with("sigma_rate:"));
    }

    #[test]
    fn bad_input_is_rejected_with_the_count() {
        let (eph, _, obs, sim) = setup(0.0, 0.0);
        let cfg = SppConfig { use_tau: true, atm: sim.atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false, elevation_mask: 0.0, fault_detection: false, ionosphere_free: false };
        let e = solve_position(&eph, 600.0, &obs[..3], &cfg, None).unwrap_err().to_string();
        assert!(e.contains("3 usable satellites") && e.contains("at least 4"), "{e}");
        let mut dup = obs.clone();
        dup.push(obs[1]);
        let e = solve_position(&eph, 600.0, &dup, &cfg, None).unwrap_err().to_string();
        assert!(e.contains("duplicated satellite") && e.contains(&format!("index {}", obs.len())), "{e}");
        let e = solve_position(&eph, 30000.0, &obs, &cfg, None).unwrap_err().to_string();
        assert!(e.contains("does not overlap the ephemerides") && e.contains("validity"), "{e}");
    }
    fn config(mask_deg: f64, fault_detection: bool) -> SppConfig {
        let atm = Atmosphere { iono: Some(Default::default()), tropo: true };
        SppConfig { use_tau: true, atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false, elevation_mask: mask_deg.to_radians(), fault_detection, ionosphere_free: false }
    }

    /// Satellites the simulator put below 10° (its true elevations) are the ones the mask
    /// leaves out; the rest give the truth.
    #[test]
    fn the_elevation_mask_leaves_out_exactly_the_low_satellites() {
        let cfg = ConstellationConfig { gps: true, glonass: true, t_start: 0.0, t_end: 3600.0, tau_gps: 0.0, time: TimeScales::default(), clocks: true, seed: 3 };
        let eph = nominal(&cfg).unwrap();
        let lla = Vec3::new(55.75f64.to_radians(), 37.6f64.to_radians(), 200.0);
        let sim = SimConfig { sigma_code_gps: 0.0, sigma_code_glo: 0.0, sigma_rate: 0.0, tau_gps: 0.0, clock_bias: 1e-3, clock_drift: 0.0, atm: config(0.0, false).atm, seed: 1 };
        let vis = Visibility { mask: 0.0, ..Default::default() };
        let epoch = simulate(&eph, &[600.0], &[lla], &[Vec3::zeros()], &sim, &vis).unwrap().remove(0);
        let low: Vec<SatId> = epoch.iter().filter(|(_, e)| *e < 10f64.to_radians()).map(|(o, _)| o.sat).collect();
        assert!(!low.is_empty());
        let obs: Vec<Observation> = epoch.iter().map(|x| x.0).collect();
        let s = solve_position(&eph, 600.0, &obs, &config(10.0, true), None).unwrap();
        let masked: Vec<SatId> = s.satellites.iter().filter(|u| u.excluded == Some(Exclusion::Elevation)).map(|u| u.sat).collect();
        assert_eq!(masked, low);
        assert_eq!(s.n_used, obs.len() - low.len());
        assert!((s.pos - WGS84.lla_to_ecef(&lla)).norm() < 1e-4, "{}", (s.pos - WGS84.lla_to_ecef(&lla)).norm());
    }

    /// A 100 m fault on one satellite fails the χ² test; the subset without it passes and
    /// gives the noiseless truth. Without fault detection the fault pulls the solution.
    #[test]
    fn fault_detection_excludes_a_100_m_pseudorange_fault() {
        let (eph, lla, mut obs, _) = setup(-340e-9, 0.0);
        let bad = obs.iter().position(|o| o.sat.system == System::Gps).unwrap();
        obs[bad].code += 100.0;
        let truth = WGS84.lla_to_ecef(&lla);
        let s = solve_position(&eph, 600.0, &obs, &config(0.0, true), None).unwrap();
        let faults: Vec<usize> = s.satellites.iter().enumerate().filter(|(_, u)| u.excluded == Some(Exclusion::Fault)).map(|(i, _)| i).collect();
        assert_eq!(faults, vec![bad]);
        assert!((s.pos - truth).norm() < 1e-4 && s.chi2 < 1e-6);
        assert!((s.satellites[bad].residual - 100.0).abs() < 1e-3, "{}", s.satellites[bad].residual);
        let plain = solve_position(&eph, 600.0, &obs, &config(0.0, false), None).unwrap();
        assert!((plain.pos - truth).norm() > 5.0 && plain.chi2 > chi2_threshold(plain.n_used - plain.n_unknowns));
    }

    /// A satellite the ephemerides do not have, and one without code, are reported and do
    /// not change the solution; an epoch left with three satellites has no row.
    #[test]
    fn missing_ephemeris_and_code_are_reported_not_fatal() {
        let (eph, lla, obs, _) = setup(-340e-9, 0.0);
        let truth = WGS84.lla_to_ecef(&lla);
        let unknown = (1..=32).map(SatId::gps).find(|s| !eph.satellites().contains(s)).unwrap();
        let mut more = obs.clone();
        more.push(Observation { sat: unknown, channel: 0, code: 2.2e7, code2: f64::NAN, rate: f64::NAN });
        more[0].code = f64::NAN;
        let s = solve_position(&eph, 600.0, &more, &config(0.0, true), None).unwrap();
        assert_eq!(s.satellites.last().unwrap().excluded, Some(Exclusion::NoEphemeris));
        assert_eq!(s.satellites[0].excluded, Some(Exclusion::NoCode));
        assert!((s.pos - truth).norm() < 1e-4 && s.n_used == obs.len() - 1);
        let gps: Vec<Observation> = obs.iter().filter(|o| o.sat.system == System::Gps).take(3).copied().collect();
        let rows = solve_epochs(&eph, &[(600.0, obs.clone()), (630.0, gps)], &config(0.0, true), 0.05).unwrap();
        assert_eq!(rows.epochs.len(), 1);
        let excluded = SPP_SATELLITE_COLUMNS.iter().position(|c| *c == "excluded").unwrap();
        let last: Vec<f64> = rows.satellites.iter().filter(|r| r[0] == 630.0).map(|r| r[excluded]).collect();
        assert_eq!(last, vec![Exclusion::TooFew.code(); 3]);
    }

    /// χ² upper 0.1 % points (tables: Abramowitz & Stegun 1964, Table 26.8).
    #[test]
    fn chi2_thresholds_match_the_table() {
        for (k, x) in [(1, 10.828), (2, 13.816), (3, 16.266), (5, 20.515), (10, 29.588), (20, 45.315), (30, 59.703)] {
            assert!((chi2_threshold(k) / x - 1.0).abs() < 6e-3, "{k}: {}", chi2_threshold(k));
        }
    }
}
