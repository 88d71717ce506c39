//! Nominal GPS (6 planes × 4) and GLONASS (3 planes × 8) constellations with broadcast
//! products and satellite clocks (circular orbits). GPS truth orbits are
//! Keplerian (e = 0), so the 2-hourly broadcast sets are exact; GLONASS truth is the J₂
//! integration of Eq. 10 sampled every 30 min into broadcast state vectors (a_ls = 0), so
//! the broadcast propagation reproduces it. No broadcast (SISRE) error is simulated.

use super::ephemeris::Ephemerides;
use super::glonass_orbit::{propagate, GloEphemeris, J2_GLO, MU_GLO, OMEGA_GLO};
use super::gps_orbit::{GpsEphemeris, MU_GPS};
use super::TimeScales;
use crate::earth::Helmert;
use crate::error::{invalid, Result};
use crate::math::Vec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::f64::consts::PI;

/// GLONASS FDMA channels of slots 1…24; antipodal slots share k (GLONASS ICD).
pub const GLONASS_CHANNELS: [i8; 24] = [1, -4, 5, 6, 1, -4, 5, 6, -2, -7, 0, -1, -2, -7, 0, -1, 4, -3, 3, 2, 4, -3, 3, 2];
const GPS_PERIOD: f64 = 43082.0;
const GLO_PERIOD: f64 = 40544.0;
/// Broadcast intervals (s): GPS 2 h, GLONASS 30 min.
const GPS_EVERY: f64 = 7200.0;
const GLO_EVERY: f64 = 1800.0;

#[derive(Debug, Clone, Copy)]
pub struct ConstellationConfig {
    pub gps: bool,
    pub glonass: bool,
    /// GPS-time span (s) the broadcast products must cover.
    pub t_start: f64,
    pub t_end: f64,
    /// True GPS–GLONASS offset τ_GPS (s) used to reference GLONASS sets to GLONASS time.
    pub tau_gps: f64,
    pub time: TimeScales,
    /// Satellite clocks b + d·t with b ~ U(±0.5 ms), d ~ N(0, 1e-11²); false → ideal clocks.
    pub clocks: bool,
    pub seed: u64,
}

/// Semi-major axis of a circular orbit with period T: a = (μ(T/2π)²)^{1/3}.
pub fn semi_major_axis(mu: f64, period: f64) -> f64 {
    (mu * (period / (2.0 * PI)).powi(2)).cbrt()
}

fn grid(start: f64, end: f64, every: f64) -> Vec<f64> {
    let (k0, k1) = ((start / every).floor() as i64 - 1, (end / every).ceil() as i64 + 1);
    (k0..=k1).map(|k| k as f64 * every).collect()
}

/// Broadcast ephemerides of the nominal constellations over [t_start, t_end].
pub fn nominal(cfg: &ConstellationConfig) -> Result<Ephemerides> {
    if !(cfg.t_start.is_finite() && cfg.t_end.is_finite() && cfg.t_end >= cfg.t_start) {
        return Err(invalid("t_end", format!("span [{}, {}] must be finite and ordered", cfg.t_start, cfg.t_end)));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let mut clock = || if cfg.clocks { (rng.random_range(-5e-4..5e-4), 1e-11 * rng.sample::<f64, _>(StandardNormal)) } else { (0.0, 0.0) };
    let mut gps = Vec::new();
    if cfg.gps {
        let a = semi_major_axis(MU_GPS, GPS_PERIOD);
        let n = (MU_GPS / a.powi(3)).sqrt();
        let toes = grid(cfg.t_start, cfg.t_end, GPS_EVERY);
        for j in 0..6 {
            for s in 0..4 {
                let u0 = (90.0 * s as f64 + 15.0 * j as f64).to_radians();
                let (b, d) = clock();
                for &toe in &toes {
                    gps.push(GpsEphemeris {
                        prn: (4 * j + s + 1) as u8,
                        toe,
                        toc: toe,
                        sqrt_a: a.sqrt(),
                        m0: u0 + n * toe,
                        omega0: (60.0 * j as f64).to_radians(),
                        i0: 55f64.to_radians(),
                        af0: b + d * toe,
                        af1: d,
                        ..GpsEphemeris::default()
                    });
                }
            }
        }
    }
    let mut glo = Vec::new();
    if cfg.glonass {
        let a = semi_major_axis(MU_GLO, GLO_PERIOD);
        let vc = (MU_GLO / a).sqrt();
        let inc = 64.8f64.to_radians();
        let nodes = grid(cfg.time.glonass_time(cfg.t_start, cfg.tau_gps), cfg.time.glonass_time(cfg.t_end, cfg.tau_gps), GLO_EVERY);
        for j in 0..3 {
            for s in 0..8 {
                let slot = 8 * j + s + 1;
                let (b, d) = clock();
                // circular inertial state at GLONASS time 0 (inertial ≡ ECEF axes then), in ECEF
                let u = (45.0 * s as f64 + 15.0 * j as f64).to_radians();
                let om = (120.0 * j as f64).to_radians();
                let (su, cu, so, co, si, ci) = (u.sin(), u.cos(), om.sin(), om.cos(), inc.sin(), inc.cos());
                let r = Vec3::new(co * cu - so * su * ci, so * cu + co * su * ci, su * si) * a;
                let vi = Vec3::new(-co * su - so * cu * ci, -so * su + co * cu * ci, cu * si) * vc;
                let v = vi - Vec3::new(0.0, 0.0, OMEGA_GLO).cross(&r);
                let (mut tc, mut rc, mut vcur) = (0.0, r, v);
                for &tb in &nodes {
                    let (rn, vn) = propagate(rc, vcur, &Vec3::zeros(), tb - tc, 30.0, J2_GLO);
                    (tc, rc, vcur) = (tb, rn, vn);
                    glo.push(GloEphemeris {
                        slot: slot as u8,
                        channel: GLONASS_CHANNELS.get(8 * j + s).copied().unwrap_or_default(),
                        tb,
                        pos: rn,
                        vel: vn,
                        acc: Vec3::zeros(),
                        tau_n: -(b + d * tb),
                        gamma_n: d,
                    });
                }
            }
        }
    }
    Ephemerides::new(gps, glo, cfg.time, Helmert::IDENTITY)
}
