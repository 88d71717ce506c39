//! The broadcast ephemerides of both systems: selection of the set nearest in time, the
//! validity check, and satellite state in WGS-84 (GLONASS through the datum transformation
//! of docs/departures.md#datum).

use super::atmosphere::Klobuchar;
use super::glonass_orbit::{GloEphemeris, DEFAULT_STEP};
use super::gps_orbit::GpsEphemeris;
use super::{SatId, System, TimeScales};
use crate::earth::Helmert;
use crate::error::{invalid, Result};
use crate::math::Vec3;
use std::collections::BTreeMap;

/// GPS ephemeris validity ±2 h about t_oe (4-h fit interval, IS-GPS-200 20.3.4.4; RTKLIB MAXDTOE).
pub const MAX_AGE_GPS: f64 = 7200.0;
/// GLONASS ephemeris validity ±30 min about t_b (RTKLIB MAXDTOE_GLO); sets come every 30 min.
pub const MAX_AGE_GLO: f64 = 1800.0;

/// Satellite position (m) and velocity (m/s) in WGS-84 ECEF at the transmit epoch, clock
/// offset (s) and rate (s/s) relative to its own system time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatState {
    pub pos: Vec3,
    pub vel: Vec3,
    pub clock: f64,
    pub clock_rate: f64,
}

#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Ephemerides {
    gps: BTreeMap<u8, Vec<GpsEphemeris>>,
    glo: BTreeMap<u8, Vec<GloEphemeris>>,
    pub time: TimeScales,
    pub datum: Helmert,
    pub glo_step: f64,
    /// The broadcast ionosphere of the navigation message (GPS Klobuchar α, β).
    #[serde(default)]
    pub ionosphere: Klobuchar,
}

impl Ephemerides {
    /// Validate, group by satellite and sort by reference time; a repeated (satellite,
    /// reference time) or a GLONASS slot broadcast on two channels is rejected.
    pub fn new(gps: Vec<GpsEphemeris>, glo: Vec<GloEphemeris>, time: TimeScales, datum: Helmert) -> Result<Ephemerides> {
        let mut g: BTreeMap<u8, Vec<GpsEphemeris>> = BTreeMap::new();
        for (i, e) in gps.into_iter().enumerate() {
            e.validate(i)?;
            SatId::parse('G', e.prn as i64, "gps_ephemeris", i)?;
            let v = g.entry(e.prn).or_default();
            if v.iter().any(|x| x.toe == e.toe) {
                return Err(invalid("gps_ephemeris", format!("duplicated set G{:02} toe {} at index {i}", e.prn, e.toe)));
            }
            v.push(e);
        }
        let mut r: BTreeMap<u8, Vec<GloEphemeris>> = BTreeMap::new();
        for (i, e) in glo.into_iter().enumerate() {
            e.validate(i)?;
            SatId::parse('R', e.slot as i64, "glonass_ephemeris", i)?;
            let v = r.entry(e.slot).or_default();
            if v.iter().any(|x| x.tb == e.tb) {
                return Err(invalid("glonass_ephemeris", format!("duplicated set R{:02} tb {} at index {i}", e.slot, e.tb)));
            }
            if let Some(x) = v.first() {
                if x.channel != e.channel {
                    return Err(invalid("glonass_ephemeris", format!("R{:02} at index {i} on channel {} but earlier on {}", e.slot, e.channel, x.channel)));
                }
            }
            v.push(e);
        }
        g.values_mut().for_each(|v| v.sort_by(|a, b| a.toe.total_cmp(&b.toe)));
        r.values_mut().for_each(|v| v.sort_by(|a, b| a.tb.total_cmp(&b.tb)));
        Ok(Ephemerides { gps: g, glo: r, time, datum, glo_step: DEFAULT_STEP, ionosphere: Klobuchar::default() })
    }

    /// The same sets with the navigation message's Klobuchar coefficients (finite).
    pub fn with_ionosphere(self, ionosphere: Klobuchar) -> Result<Ephemerides> {
        crate::error::check_finite("ionosphere", &ionosphere.alpha, 1)?;
        crate::error::check_finite("ionosphere", &ionosphere.beta, 1)?;
        Ok(Ephemerides { ionosphere, ..self })
    }

    /// Every GPS set, by satellite then reference time.
    pub fn gps_sets(&self) -> impl Iterator<Item = &GpsEphemeris> {
        self.gps.values().flatten()
    }

    /// Every GLONASS set, by slot then reference time.
    pub fn glonass_sets(&self) -> impl Iterator<Item = &GloEphemeris> {
        self.glo.values().flatten()
    }

    /// All satellites with at least one set, GPS first.
    pub fn satellites(&self) -> Vec<SatId> {
        self.gps.keys().map(|&p| SatId::gps(p)).chain(self.glo.keys().map(|&s| SatId::glonass(s))).collect()
    }

    /// FDMA channel of a GLONASS slot (0 for GPS).
    pub fn channel(&self, sat: SatId) -> Result<i8> {
        match sat.system {
            System::Gps => Ok(0),
            System::Glonass => self.glo.get(&sat.prn).and_then(|v| v.first()).map(|e| e.channel).ok_or_else(|| invalid("sat", format!("no GLONASS ephemeris for {}", sat.name()))),
        }
    }

    fn nearest<T>(v: &[T], key: impl Fn(&T) -> f64, t: f64) -> Option<&T> {
        v.iter().min_by(|a, b| (key(a) - t).abs().total_cmp(&(key(b) - t).abs()))
    }

    fn stale(sat: SatId, t: f64, age: f64, max: f64) -> crate::error::NavError {
        invalid("t", format!("{} at t = {t} s: nearest set is {age:.0} s away (validity ±{max} s): the time does not overlap the ephemerides", sat.name()))
    }

    /// Rows [x, y, z, vx, vy, vz (WGS-84 ECEF m, m/s), clock s, clock rate s/s] of `sat`
    /// at each GPS time of `t` ([`Ephemerides::state`]).
    pub fn state_rows(&self, sat: SatId, t: &[f64], tau_gps: f64) -> Result<Vec<[f64; 8]>> {
        crate::error::check_finite("t", t, 1)?;
        t.iter()
            .map(|&tk| {
                let s = self.state(sat, tk, tau_gps)?;
                Ok([s.pos.x, s.pos.y, s.pos.z, s.vel.x, s.vel.y, s.vel.z, s.clock, s.clock_rate])
            })
            .collect()
    }

    /// Group delay T_GD (s) of the GPS set used at GPS time t (IS-GPS-200 20.3.3.3.3.2),
    /// which the L1 clock of [`Ephemerides::state`] includes; 0 for GLONASS.
    pub fn group_delay(&self, sat: SatId, t: f64) -> Result<f64> {
        match sat.system {
            System::Gps => {
                let v = self.gps.get(&sat.prn).ok_or_else(|| invalid("sat", format!("no GPS ephemeris for {}", sat.name())))?;
                Ok(Self::nearest(v, |e| e.toe, t).map_or(0.0, |e| e.tgd))
            }
            System::Glonass => Ok(0.0),
        }
    }

    /// State of `sat` at GPS time t. GLONASS sets are evaluated at GLONASS time
    /// t − ΔT_leap − τ_GPS (Eq. 7) with the caller's τ_GPS estimate `tau_gps` (s).
    pub fn state(&self, sat: SatId, t: f64, tau_gps: f64) -> Result<SatState> {
        match sat.system {
            System::Gps => {
                let v = self.gps.get(&sat.prn).ok_or_else(|| invalid("sat", format!("no GPS ephemeris for {}", sat.name())))?;
                let e = Self::nearest(v, |e| e.toe, t).ok_or_else(|| invalid("sat", format!("no GPS ephemeris for {}", sat.name())))?;
                let age = (t - e.toe).abs();
                if age > MAX_AGE_GPS {
                    return Err(Self::stale(sat, t, age, MAX_AGE_GPS));
                }
                let (pos, vel) = e.state(t);
                let (clock, clock_rate) = e.clock(t);
                Ok(SatState { pos, vel, clock, clock_rate })
            }
            System::Glonass => {
                let v = self.glo.get(&sat.prn).ok_or_else(|| invalid("sat", format!("no GLONASS ephemeris for {}", sat.name())))?;
                let tg = self.time.glonass_time(t, tau_gps);
                let e = Self::nearest(v, |e| e.tb, tg).ok_or_else(|| invalid("sat", format!("no GLONASS ephemeris for {}", sat.name())))?;
                let age = (tg - e.tb).abs();
                if age > MAX_AGE_GLO {
                    return Err(Self::stale(sat, t, age, MAX_AGE_GLO));
                }
                let (p, vv) = e.state(tg, self.glo_step);
                let (clock, clock_rate) = e.clock(tg);
                Ok(SatState { pos: self.datum.forward(&p), vel: self.datum.forward_velocity(&vv), clock, clock_rate })
            }
        }
    }
}
