//! GNSS for tight GPS + GLONASS / INS integration (Demidov 2009):
//! broadcast orbits and clocks, a nominal-constellation simulator, code and Doppler
//! observables with the system-time offset τ_GPS, atmosphere models, single-point
//! positioning, and the tightly coupled aiding of the generic aided-INS engine.
//!
//! Time: every epoch argument named `t` is GPS system time in seconds (one continuous scale,
//! t = 0 at the start of a GPS week); GLONASS ephemerides are referenced to GLONASS time,
//! T_GPS − T_GLO = ΔT_leap + τ_GPS (docs/departures.md#system-time-offset).

pub mod atmosphere;
pub mod constellation;
pub mod ephemeris;
pub mod geometry;
pub mod glonass_orbit;
pub mod gps_orbit;
pub mod observation;
pub mod options;
pub mod rinex;
pub mod spp;
pub mod tight;

use crate::error::{invalid, Result};

/// Speed of light (m/s), IS-GPS-200 and GLONASS ICD.
pub const C_LIGHT: f64 = 299_792_458.0;
/// GPS L1 carrier (Hz).
pub const GPS_L1_HZ: f64 = 1575.42e6;
/// GPS L2 carrier (Hz).
pub const GPS_L2_HZ: f64 = 1227.60e6;
/// Earth rotation rate of the GPS ICD (rad/s), used for the Sagnac rotation of both systems.
pub const OMEGA_E_GPS: f64 = 7.2921151467e-5;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum System {
    Gps,
    Glonass,
}

/// A satellite: system and PRN (GPS) or orbital slot (GLONASS), 1-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub struct SatId {
    pub system: System,
    pub prn: u8,
}

impl SatId {
    pub fn gps(prn: u8) -> SatId {
        SatId { system: System::Gps, prn }
    }
    pub fn glonass(slot: u8) -> SatId {
        SatId { system: System::Glonass, prn: slot }
    }
    /// From the RINEX letter ('G' or 'R') and number.
    pub fn parse(system: char, prn: i64, field: &str, index: usize) -> Result<SatId> {
        let sys = match system {
            'G' => System::Gps,
            'R' => System::Glonass,
            c => return Err(invalid(field, format!("unknown satellite system '{c}' at index {index} (known: G, R)"))),
        };
        if !(1..=63).contains(&prn) {
            return Err(invalid(field, format!("satellite number {prn} at index {index} outside 1..63")));
        }
        Ok(SatId { system: sys, prn: prn as u8 })
    }
    /// From a RINEX-style name "G05", "R12" (entry `index` of `field` named on error).
    pub fn from_name(name: &str, field: &str, index: usize) -> Result<SatId> {
        let mut chars = name.chars();
        let system = chars.next().unwrap_or('?');
        let prn: i64 = chars.as_str().trim().parse().map_err(|_| invalid(field, format!("malformed satellite '{name}' at index {index}")))?;
        SatId::parse(system, prn, field, index)
    }

    /// Satellites from their names ([`SatId::from_name`]).
    pub fn from_names(names: &[String], field: &str) -> Result<Vec<SatId>> {
        names.iter().enumerate().map(|(i, s)| SatId::from_name(s, field, i)).collect()
    }

    /// RINEX-style name "G05", "R12".
    pub fn name(&self) -> String {
        let c = if self.system == System::Gps { 'G' } else { 'R' };
        format!("{c}{:02}", self.prn)
    }
}

/// GLONASS FDMA channel k ∈ [−7, 6] (GLONASS ICD).
pub fn check_channel(field: &str, k: i64, index: usize) -> Result<i8> {
    if (-7..=6).contains(&k) {
        Ok(k as i8)
    } else {
        Err(invalid(field, format!("unknown GLONASS frequency channel {k} at index {index} (valid: -7..6)")))
    }
}

/// GLONASS L1 carrier of channel k (Hz): 1602 + 0.5625k MHz (GLONASS ICD).
pub fn glonass_l1_hz(k: i8) -> f64 {
    (1602.0 + 0.5625 * k as f64) * 1e6
}

/// GLONASS L2 carrier of channel k (Hz): 1246 + 0.4375k MHz (GLONASS ICD).
pub fn glonass_l2_hz(k: i8) -> f64 {
    (1246.0 + 0.4375 * k as f64) * 1e6
}

/// L1 wavelength (m) of a satellite; GLONASS per channel (FDMA: mandatory).
pub fn l1_wavelength(sat: SatId, channel: i8) -> f64 {
    match sat.system {
        System::Gps => C_LIGHT / GPS_L1_HZ,
        System::Glonass => C_LIGHT / glonass_l1_hz(channel),
    }
}

/// Time-scale relation T_GPS − T_GLO = ΔT_leap + τ_GPS with ΔT_leap = n_leap − 10800 s
/// (n_leap = 15 s in 2009, 18 s since 2017; docs/departures.md#system-time-offset).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimeScales {
    pub n_leap: f64,
}

impl Default for TimeScales {
    fn default() -> Self {
        TimeScales { n_leap: 18.0 }
    }
}

impl TimeScales {
    /// ΔT_leap = n_leap − 10800 s (−10782 s since 2017).
    pub fn delta_t_leap(&self) -> f64 {
        self.n_leap - 10800.0
    }
    /// GLONASS time of GPS time t for a given τ_GPS (s).
    pub fn glonass_time(&self, t_gps: f64, tau_gps: f64) -> f64 {
        t_gps - self.delta_t_leap() - tau_gps
    }
}
