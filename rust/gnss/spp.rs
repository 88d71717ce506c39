//! Single-point positioning (standard mode, Demidov 2009 Ch. 2): Gauss–Newton least
//! squares for (position, c·δt_r, τ_GPS) with the exact H rows of our own prediction, the
//! thesis's residual metric, DOP, and the Doppler velocity solution.

use super::ephemeris::Ephemerides;
use super::geometry::{geometry, Geometry};
use super::observation::{check_unique, Atmosphere, Observation};
use super::{System, C_LIGHT};
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
}

/// DOP values of the geometry (unweighted, local NED).
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
    /// Post-fit residuals (m) per observation, in input order.
    pub residuals: Vec<f64>,
    pub n_unknowns: usize,
    pub dop: Dop,
    pub iterations: usize,
}

/// Code corrected for the satellite clock and the atmosphere: P + c·δt^s − I − T (m).
fn corrected_code(o: &Observation, g: &Geometry, atm: &Atmosphere, lla: &Vec3, t: f64) -> f64 {
    o.code + C_LIGHT * g.sat.clock - atm.delay(o.sat, o.channel, lla, g, t)
}

/// Position solution at GPS time t from the code observations of one epoch; `x0` is the
/// initial ECEF guess (the Earth's centre when None).
// invariant: x has n ∈ {4, 5} unknowns (5 exactly when with_tau), h is m × n, z and
// w have m = obs.len() rows, i < m; cov is n × n.
#[allow(clippy::indexing_slicing)]
pub fn solve_position(eph: &Ephemerides, t: f64, obs: &[Observation], cfg: &SppConfig, x0: Option<Vec3>) -> Result<SppSolution> {
    check_unique("obs", obs)?;
    let has_glo = obs.iter().any(|o| o.sat.system == System::Glonass);
    let with_tau = cfg.use_tau && has_glo;
    let n = if with_tau { 5 } else { 4 };
    if obs.len() < n {
        let what = if with_tau { "position, clock and τ_GPS" } else { "position and clock" };
        return Err(invalid("obs", format!("{} satellites at t = {t} s; the solver needs at least {n} ({what})", obs.len())));
    }
    for (i, o) in obs.iter().enumerate() {
        if !o.code.is_finite() {
            return Err(invalid("obs", format!("non-finite pseudorange at index {i}")));
        }
        if o.sat.system == System::Glonass && eph.channel(o.sat)? != o.channel {
            return Err(invalid("obs", format!("{} at index {i}: channel {} but the ephemeris says {}", o.sat.name(), o.channel, eph.channel(o.sat)?)));
        }
    }
    let m = obs.len();
    // state (x, y, z, c·δt_r, c·τ_GPS): τ carried in metres for conditioning
    let mut x = DVector::<f64>::zeros(n);
    if let Some(p) = x0 {
        x.rows_mut(0, 3).copy_from(&p);
    }
    let mut h = DMatrix::<f64>::zeros(m, n);
    let mut z = DVector::<f64>::zeros(m);
    let mut w = DVector::<f64>::zeros(m);
    let mut iterations = 0;
    let mut geo = Vec::with_capacity(m);
    loop {
        iterations += 1;
        let r = Vec3::new(x[0], x[1], x[2]);
        let lla = if r.norm() > 1e6 { WGS84.ecef_to_lla(&r) } else { Vec3::new(0.0, 0.0, -WGS84.a) };
        let tau = if with_tau { x[4] / C_LIGHT } else { 0.0 };
        geo.clear();
        for (i, o) in obs.iter().enumerate() {
            let g = geometry(eph, o.sat, t, &r, &Vec3::zeros(), lla.x, lla.y, tau)?;
            let glo = o.sat.system == System::Glonass;
            let pred = g.range + x[3] + if glo && with_tau { x[4] } else { 0.0 };
            z[i] = corrected_code(o, &g, &cfg.atm, &lla, t) - pred;
            let row = -g.los * g.kappa;
            h[(i, 0)] = row.x;
            h[(i, 1)] = row.y;
            h[(i, 2)] = row.z;
            h[(i, 3)] = 1.0;
            if with_tau {
                // ∂P̂/∂(cτ) = 1 − κ uᵀv_s/c on GLONASS rows (the satellite epoch moves by −τ)
                h[(i, 4)] = if glo { 1.0 - g.kappa * g.los.dot(&g.sat.vel) / C_LIGHT } else { 0.0 };
            }
            let s = if glo { cfg.sigma_glo } else { cfg.sigma_gps };
            let s = if cfg.elevation_weight && r.norm() > 1e6 { s / g.elevation.sin().max(0.05) } else { s };
            w[i] = 1.0 / (s * s);
            geo.push(g);
        }
        let hw = DMatrix::from_fn(n, m, |a, b| h[(b, a)] * w[b]);
        let nmat = &hw * &h;
        let chol = nmat.clone().cholesky().ok_or_else(|| NavError::Numerical(format!("singular normal matrix at t = {t} s (degenerate geometry)")))?;
        let dx = chol.solve(&(&hw * &z));
        x += &dx;
        let done = dx.rows(0, 3).norm() < 1e-4;
        if done || iterations >= 30 {
            if !done {
                return Err(NavError::Numerical(format!("position solution did not converge at t = {t} s")));
            }
            // final residuals at the converged x: z − H·dx
            let res = &z - &h * &dx;
            let mut cov = chol.inverse();
            if with_tau {
                for j in 0..5 {
                    cov[(4, j)] /= C_LIGHT;
                    cov[(j, 4)] /= C_LIGHT;
                }
            }
            let pos = Vec3::new(x[0], x[1], x[2]);
            let lla = WGS84.ecef_to_lla(&pos);
            let dop = dop(&h, &lla, n)?;
            let metric = if m > n { res.iter().map(|v| v.abs()).sum::<f64>() / (m - n) as f64 } else { f64::NAN };
            return Ok(SppSolution {
                pos,
                lla,
                clock_m: x[3],
                tau: if with_tau { Some(x[4] / C_LIGHT) } else { None },
                cov,
                residual_metric: metric,
                residuals: res.iter().copied().collect(),
                n_unknowns: n,
                dop,
                iterations,
            });
        }
    }
}

/// Columns of a [`solve_epochs`] row: time, ECEF and geodetic antenna position, c·δt_r,
/// τ_GPS and its σ (s; NaN when not estimated), the residual metric, satellites and
/// unknowns, DOP values, Doppler velocity (ECEF m/s) and c·δṫ_r (m/s; NaN with fewer than
/// four rates).
pub const SPP_COLUMNS: [&str; 22] = [
    "time_s", "x_m", "y_m", "z_m", "lat_rad", "lon_rad", "h_m", "clock_m", "tau_gps_s", "sigma_tau_gps_s", "residual_metric_m", "n_sats",
    "n_unknowns", "gdop", "pdop", "hdop", "vdop", "tdop", "vx_mps", "vy_mps", "vz_mps", "clock_drift_mps",
];

/// Single-point positioning epoch by epoch: each position solution starts from the
/// previous epoch's (the first from the Earth's centre); the Doppler velocity
/// ([`solve_velocity`], rate σ `sigma_rate` m/s) when at least four rates are finite.
/// One row per epoch, columns [`SPP_COLUMNS`].
// invariant: tau is Some only for the 5-unknown solution, whose cov is 5 × 5.
#[allow(clippy::indexing_slicing)]
pub fn solve_epochs(eph: &Ephemerides, epochs: &[(f64, Vec<Observation>)], cfg: &SppConfig, sigma_rate: f64) -> Result<Vec<[f64; 22]>> {
    crate::error::check_positive("sigma_rate", sigma_rate)?;
    let mut x0 = None;
    epochs
        .iter()
        .map(|(t, ob)| {
            let s = solve_position(eph, *t, ob, cfg, x0)?;
            x0 = Some(s.pos);
            let (v, d) = if ob.iter().filter(|o| o.rate.is_finite()).count() >= 4 {
                let (v, d, _) = solve_velocity(eph, *t, ob, &s.pos, sigma_rate)?;
                (v, d)
            } else {
                (Vec3::repeat(f64::NAN), f64::NAN)
            };
            let (tau, st) = s.tau.map_or((f64::NAN, f64::NAN), |x| (x, s.cov[(4, 4)].sqrt()));
            Ok([
                *t, s.pos.x, s.pos.y, s.pos.z, s.lla.x, s.lla.y, s.lla.z, s.clock_m, tau, st, s.residual_metric, ob.len() as f64,
                s.n_unknowns as f64, s.dop.gdop, s.dop.pdop, s.dop.hdop, s.dop.vdop, s.dop.tdop, v.x, v.y, v.z, d,
            ])
        })
        .collect()
}

/// DOP from the design matrix rotated into local NED (position columns).
// invariant: h has n ≥ 4 columns (the solver's unknowns: position, clock[, τ]), so q
// is n × n with n ≥ 4 and i < rows of h, j < 3.
#[allow(clippy::indexing_slicing)]
fn dop(h: &DMatrix<f64>, lla: &Vec3, n: usize) -> Result<Dop> {
    let cne = dcm_ned_to_ecef(lla.x, lla.y);
    let mut g = h.clone();
    for i in 0..h.nrows() {
        let v = cne.transpose() * Vec3::new(h[(i, 0)], h[(i, 1)], h[(i, 2)]);
        for j in 0..3 {
            g[(i, j)] = v[j];
        }
    }
    let q = (g.transpose() * &g).try_inverse().ok_or_else(|| NavError::Numerical("singular DOP matrix".into()))?;
    let tr: f64 = (0..n).map(|i| q[(i, i)]).sum();
    Ok(Dop {
        gdop: tr.sqrt(),
        pdop: (q[(0, 0)] + q[(1, 1)] + q[(2, 2)]).sqrt(),
        hdop: (q[(0, 0)] + q[(1, 1)]).sqrt(),
        vdop: q[(2, 2)].sqrt(),
        tdop: q[(3, 3)].sqrt(),
    })
}

/// Doppler velocity (Eq. 24): least squares for (v ECEF m/s, c·δṫ_r m/s) at the known
/// antenna position `pos`, with rows (−κu_iᵀ, 1); returns (velocity, clock drift, covariance).
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
        let cfg = SppConfig { use_tau: true, atm: sim.atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false };
        let s = solve_position(&eph, 600.0, &obs, &cfg, None).unwrap();
        let truth = WGS84.lla_to_ecef(&lla);
        assert!((s.pos - truth).norm() < 1e-4, "{}", (s.pos - truth).norm());
        assert!((s.clock_m - C_LIGHT * (2e-4 + 1e-8 * 600.0)).abs() < 1e-4);
        assert!((s.tau.unwrap() + 340e-9).abs() < 1e-13);
        assert!(s.residual_metric < 1e-4);
        let (v, drift, _) = solve_velocity(&eph, 600.0, &obs, &truth, 0.05).unwrap();
        let vt = dcm_ned_to_ecef(lla.x, lla.y) * Vec3::new(3.0, -2.0, 0.5);
        assert!((v - vt).norm() < 1e-6 && (drift - C_LIGHT * 1e-8).abs() < 1e-6, "{} {}", (v - vt).norm(), drift);
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
        let cfg = SppConfig { use_tau: true, atm: sim.atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false };
        let gps: Vec<Observation> = obs.iter().filter(|o| o.sat.system == System::Gps).copied().collect();
        let mut few_rates = obs.clone();
        few_rates.iter_mut().skip(3).for_each(|o| o.rate = f64::NAN);
        let rows = solve_epochs(&eph, &[(600.0, obs.clone()), (600.0, gps.clone()), (600.0, few_rates)], &cfg, 0.05).unwrap();
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
        let cfg = SppConfig { use_tau: true, atm: sim.atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false };
        let e = solve_position(&eph, 600.0, &obs[..3], &cfg, None).unwrap_err().to_string();
        assert!(e.contains("3 satellites") && e.contains("at least 4"), "{e}");
        let mut dup = obs.clone();
        dup.push(obs[1]);
        let e = solve_position(&eph, 600.0, &dup, &cfg, None).unwrap_err().to_string();
        assert!(e.contains("duplicated satellite") && e.contains(&format!("index {}", obs.len())), "{e}");
        let e = solve_position(&eph, 30000.0, &obs, &cfg, None).unwrap_err().to_string();
        assert!(e.contains("does not overlap the ephemerides") && e.contains("validity"), "{e}");
    }
}
