//! Code and pseudorange-rate observations: the standard measurement model
//! (receiver clock bias and drift, satellite clock, τ_GPS on GLONASS, ionosphere,
//! troposphere, noise), its inverse correction used by positioning and the filter, and
//! the simulator with per-satellite visibility control.

use super::atmosphere::{saastamoinen, Klobuchar};
use super::ephemeris::Ephemerides;
use super::geometry::{geometry, Geometry};
use super::{glonass_l1_hz, SatId, System, C_LIGHT, GPS_L1_HZ};
use crate::earth::{dcm_ned_to_ecef, WGS84};
use crate::error::{invalid, Result};
use crate::math::Vec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::collections::HashSet;

/// One satellite's measurements at one epoch. GLONASS code has c·ΔT_leap removed (Eq. 15).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Observation {
    pub sat: SatId,
    /// FDMA channel (GLONASS), 0 for GPS.
    pub channel: i8,
    /// Pseudorange (m).
    pub code: f64,
    /// Second-frequency pseudorange (m; GPS L2, GLONASS L2 of the same channel), for the
    /// ionosphere-free combination; NaN when absent.
    pub code2: f64,
    /// Pseudorange rate (m/s) = −λ·Doppler; NaN when absent.
    pub rate: f64,
}

/// The atmosphere models applied (both in simulation and in correction).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Atmosphere {
    pub iono: Option<Klobuchar>,
    pub tropo: bool,
}

impl Atmosphere {
    /// Ionosphere + troposphere delay (m) of one signal; 0 below the horizon.
    pub fn delay(&self, sat: SatId, channel: i8, lla: &Vec3, g: &Geometry, t: f64) -> f64 {
        if g.elevation <= 0.0 {
            return 0.0;
        }
        let freq = if sat.system == System::Gps { GPS_L1_HZ } else { glonass_l1_hz(channel) };
        let i = self.iono.map_or(0.0, |k| k.delay_at(lla.x, lla.y, g.elevation, g.azimuth, t, freq));
        let tr = if self.tropo { saastamoinen(lla.x, lla.z, g.elevation) } else { 0.0 };
        i + tr
    }
}

/// Reject duplicated satellites in one epoch, naming the first repeated index.
pub fn check_unique(field: &str, obs: &[Observation]) -> Result<()> {
    let mut seen = HashSet::new();
    for (i, o) in obs.iter().enumerate() {
        if !seen.insert(o.sat) {
            return Err(invalid(field, format!("duplicated satellite {} at index {i}", o.sat.name())));
        }
    }
    Ok(())
}

/// Visibility control: elevation mask, an optional fixed satellite subset, outage windows
/// of all satellites and of single satellites (GPS-time intervals [start, end)).
#[derive(Debug, Clone, Default)]
pub struct Visibility {
    pub mask: f64,
    pub only: Option<Vec<SatId>>,
    pub outages: Vec<(f64, f64)>,
    pub sat_outages: Vec<(SatId, f64, f64)>,
}

impl Visibility {
    pub fn visible(&self, sat: SatId, t: f64, elevation: f64) -> bool {
        elevation >= self.mask
            && self.only.as_ref().is_none_or(|v| v.contains(&sat))
            && !self.outages.iter().any(|&(a, b)| t >= a && t < b)
            && !self.sat_outages.iter().any(|&(s, a, b)| s == sat && t >= a && t < b)
    }
}

#[derive(Debug, Clone, Copy)]
pub struct SimConfig {
    pub sigma_code_gps: f64,
    pub sigma_code_glo: f64,
    pub sigma_rate: f64,
    /// True τ_GPS (s) added as c·τ to GLONASS code.
    pub tau_gps: f64,
    /// Receiver clock δt_r(t) = bias + drift·(t − t₀) (s, s/s), t₀ the first epoch of the
    /// simulated record: the bias is the clock offset at the start, whatever the time of week.
    pub clock_bias: f64,
    pub clock_drift: f64,
    pub atm: Atmosphere,
    pub seed: u64,
}

/// Receiver ECEF position and velocity of a geodetic position and NED velocity (WGS-84).
pub fn receiver_ecef(lla: &Vec3, vel_ned: &Vec3) -> (Vec3, Vec3) {
    (WGS84.lla_to_ecef(lla), dcm_ned_to_ecef(lla.x, lla.y) * vel_ned)
}

/// Observations stamped `t` by the receiver's clock (the signals arrive at GPS time
/// t − δt_r) of a receiver at `lla` moving with `vel_ned`, each with its true elevation
/// (rad). The receiver clock is δt_r(t) = `clock_bias` + `clock_drift`·(t − t₀) from the
/// first epoch t₀ of `t`. Satellites are those with ephemerides, in the order of
/// `Ephemerides::satellites`.
// invariant: lla and vel_ned have one row per epoch of t (checked above), k < t.len().
#[allow(clippy::indexing_slicing)]
pub fn simulate(eph: &Ephemerides, t: &[f64], lla: &[Vec3], vel_ned: &[Vec3], cfg: &SimConfig, vis: &Visibility) -> Result<Vec<Vec<(Observation, f64)>>> {
    if lla.len() != t.len() || vel_ned.len() != t.len() {
        return Err(invalid("lla", format!("{} positions and {} velocities for {} epochs", lla.len(), vel_ned.len(), t.len())));
    }
    crate::earth::check_latitudes("lla", lla)?;
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let sats = eph.satellites();
    let mut out = Vec::with_capacity(t.len());
    let t0 = t.first().copied().unwrap_or(0.0);
    for k in 0..t.len() {
        let (r, v) = receiver_ecef(&lla[k], &vel_ned[k]);
        let (dtr, dtr_dot) = (cfg.clock_bias + cfg.clock_drift * (t[k] - t0), cfg.clock_drift);
        // a receiver stamps by its own clock: the signal arrives at GPS time t − δt_r
        let t_rx = t[k] - dtr;
        let mut epoch = Vec::new();
        for &sat in &sats {
            let g = geometry(eph, sat, t_rx, &r, &v, lla[k].x, lla[k].y, cfg.tau_gps)?;
            // draw the noise for every satellite so the streams do not depend on visibility
            let (n1, n2): (f64, f64) = (rng.sample(StandardNormal), rng.sample(StandardNormal));
            if !vis.visible(sat, t[k], g.elevation) {
                continue;
            }
            let channel = eph.channel(sat)?;
            let (tau, sigma) = match sat.system {
                System::Gps => (0.0, cfg.sigma_code_gps),
                System::Glonass => (cfg.tau_gps, cfg.sigma_code_glo),
            };
            let code = g.range + C_LIGHT * (dtr - g.sat.clock + tau) + cfg.atm.delay(sat, channel, &lla[k], &g, t_rx) + sigma * n1;
            let rate = g.rate + C_LIGHT * (dtr_dot - g.sat.clock_rate) + cfg.sigma_rate * n2;
            epoch.push((Observation { sat, channel, code, code2: f64::NAN, rate }, g.elevation));
        }
        out.push(epoch);
    }
    Ok(out)
}

/// Observations from the columns of a flat table (satellite names, GLONASS channels,
/// code m, rate m/s); the channels of GLONASS rows are checked (GPS rows get 0).
pub fn observations(sat: &[String], channel: &[i64], code: &[f64], code2: Option<&[f64]>, rate: &[f64]) -> Result<Vec<Observation>> {
    let ids = SatId::from_names(sat, "sat")?;
    if channel.len() != ids.len() || code.len() != ids.len() || rate.len() != ids.len() || code2.is_some_and(|c| c.len() != ids.len()) {
        return Err(invalid("sat", format!("{} satellites, {} channels, {} codes, {} second codes, {} rates", ids.len(), channel.len(), code.len(), code2.map_or(ids.len(), <[f64]>::len), rate.len())));
    }
    (ids.iter().zip(channel).zip(code).zip(rate).enumerate())
        .map(|(i, (((&sat, &ch), &code), &rate))| {
            let channel = if sat.system == System::Glonass { super::check_channel("channel", ch, i)? } else { 0 };
            let code2 = code2.and_then(|c| c.get(i).copied()).unwrap_or(f64::NAN);
            Ok(Observation { sat, channel, code, code2, rate })
        })
        .collect()
}

/// Simulated observations as a flat table, one row per satellite and epoch.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObservationTable {
    pub sat: Vec<String>,
    pub channel: Vec<i64>,
    pub time: Vec<f64>,
    pub code: Vec<f64>,
    pub rate: Vec<f64>,
    /// True elevation (rad).
    pub elevation: Vec<f64>,
}

/// [`simulate`] flattened into an [`ObservationTable`] (epochs in time order, satellites
/// in the order of `Ephemerides::satellites`).
pub fn simulate_table(eph: &Ephemerides, t: &[f64], lla: &[Vec3], vel_ned: &[Vec3], cfg: &SimConfig, vis: &Visibility) -> Result<ObservationTable> {
    crate::error::check_increasing("t", t)?;
    let epochs = simulate(eph, t, lla, vel_ned, cfg, vis)?;
    let mut out = ObservationTable::default();
    for (ep, &tk) in epochs.iter().zip(t) {
        for (o, e) in ep {
            out.sat.push(o.sat.name());
            out.channel.push(o.channel as i64);
            out.time.push(tk);
            out.code.push(o.code);
            out.rate.push(o.rate);
            out.elevation.push(*e);
        }
    }
    Ok(out)
}

/// Group a flat observation table (one row per satellite and epoch, time non-decreasing)
/// into epochs; rejects decreasing or non-finite time, infinite code or rate and
/// duplicated satellites. A NaN code or rate is a missing observable (not tracked), kept
/// for the solvers to leave out and report.
pub fn group_epochs(time: &[f64], obs: &[Observation]) -> Result<Vec<(f64, Vec<Observation>)>> {
    if time.len() != obs.len() {
        return Err(invalid("time", format!("{} time stamps for {} observations", time.len(), obs.len())));
    }
    let mut out: Vec<(f64, Vec<Observation>)> = Vec::new();
    for (i, (&t, o)) in time.iter().zip(obs).enumerate() {
        if !t.is_finite() || o.code.is_infinite() || o.rate.is_infinite() {
            return Err(invalid("obs", format!("non-finite time or infinite pseudorange or rate at index {i}")));
        }
        match out.last_mut() {
            Some((t0, v)) if *t0 == t => {
                if v.iter().any(|x| x.sat == o.sat) {
                    return Err(invalid("obs", format!("duplicated satellite {} at index {i}", o.sat.name())));
                }
                v.push(*o);
            }
            Some((t0, _)) if *t0 > t => {
                return Err(invalid("time", format!("observation time decreasing at index {i} ({t} after {t0})")));
            }
            _ => out.push((t, vec![*o])),
        }
    }
    Ok(out)
}
