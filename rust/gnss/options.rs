//! One set of GNSS processing options for positioning, simulation and tight coupling (the
//! role of RTKLIB's `prcopt_t`; Takasu 2013, RTKLIB manual §E.4): measurement noise,
//! atmosphere corrections, single-point options, and the tightly coupled filter's
//! formulation, lever arm and clock models. Checked once by [`GnssOptions::check`].

use super::ephemeris::Ephemerides;
use super::observation::{Atmosphere, SimConfig};
use super::spp::{ionosphere_free_gain, SppConfig};
use super::tight::{Formulation, TightConfig};
use super::{glonass_l1_hz, glonass_l2_hz, C_LIGHT, GPS_L1_HZ, GPS_L2_HZ};
use crate::error::{invalid, Result};
use crate::imu::ImuKind;
use crate::math::Vec3;
use std::f64::consts::FRAC_PI_2;

#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GnssOptions {
    /// Code σ (m) of GPS and GLONASS, pseudorange-rate σ (m/s).
    pub sigma_code_gps: f64,
    pub sigma_code_glo: f64,
    pub sigma_rate: f64,
    /// Klobuchar ionosphere and Saastamoinen troposphere (simulation and correction).
    pub iono: bool,
    pub tropo: bool,
    /// Single-point positioning: estimate τ_GPS; σ/sin E weights.
    pub use_tau: bool,
    pub elevation_weight: bool,
    /// Single-point positioning: elevation mask (rad), residual χ² test with exclusion.
    pub elevation_mask: f64,
    pub fault_detection: bool,
    /// Single-point positioning with the ionosphere-free code combination (the second
    /// frequency's code needed; no Klobuchar then).
    pub ionosphere_free: bool,
    /// Tight coupling: measurement formulation, IMU → antenna lever arm (body, m), use the
    /// pseudorange rates.
    #[serde(with = "crate::options::by_name")]
    pub formulation: Formulation,
    pub lever_arm: Vec3,
    pub use_rate: bool,
    /// τ_GPS initial value and σ (s), random-walk PSD (s²/s).
    pub tau0: f64,
    pub sigma_tau0: f64,
    pub tau_psd: f64,
    /// Receiver clock states (c·δt_r m, c·δṫ_r m/s): initial values and σ; oscillator
    /// h₀ (s) and h₋₂ (1/s) (Brown & Hwang 2012, §9.3).
    pub clock0: [f64; 2],
    pub sigma_clock0: [f64; 2],
    pub clock_h0: f64,
    pub clock_hm2: f64,
}

impl Default for GnssOptions {
    /// Code 3 m, rate 0.05 m/s, both atmosphere models, τ_GPS estimated, first
    /// differences; τ_GPS 0 ± 1 µs with PSD (0.1 ns)²/h (Demidov 2009, Eq. 42); a TCXO
    /// (h₀ = 2·10⁻¹⁹ s, h₋₂ = 2·10⁻²⁰ /s; Brown & Hwang 2012, Table 9.1) starting at
    /// 0 ± (300 km, 300 m/s).
    fn default() -> Self {
        GnssOptions {
            sigma_code_gps: 3.0,
            sigma_code_glo: 3.0,
            sigma_rate: 0.05,
            iono: true,
            tropo: true,
            use_tau: true,
            elevation_weight: false,
            elevation_mask: 10f64.to_radians(),
            fault_detection: true,
            ionosphere_free: false,
            formulation: Formulation::FirstDifference,
            lever_arm: Vec3::zeros(),
            use_rate: true,
            tau0: 0.0,
            sigma_tau0: 1e-6,
            tau_psd: 0.1e-9 * 0.1e-9 / 3600.0,
            clock0: [0.0, 0.0],
            sigma_clock0: [3e5, 300.0],
            clock_h0: 2e-19,
            clock_hm2: 2e-20,
        }
    }
}

impl GnssOptions {
    /// σ's finite and > 0, PSDs and oscillator coefficients finite and ≥ 0, initial values
    /// and the lever arm finite.
    pub fn check(&self) -> Result<()> {
        let positive = [("sigma_code", self.sigma_code_gps), ("sigma_code_glonass", self.sigma_code_glo), ("sigma_rate", self.sigma_rate), ("sigma_tau0", self.sigma_tau0)];
        for (field, x) in positive.into_iter().chain([("sigma_clock0", self.sigma_clock0[0]), ("sigma_clock0", self.sigma_clock0[1])]) {
            crate::error::check_positive(field, x)?;
        }
        for (field, x) in [("tau_psd", self.tau_psd), ("clock_h0", self.clock_h0), ("clock_hm2", self.clock_hm2)] {
            if !(x.is_finite() && x >= 0.0) {
                return Err(invalid(field, format!("must be finite and >= 0, got {x}")));
            }
        }
        if !(self.elevation_mask.is_finite() && (-FRAC_PI_2..FRAC_PI_2).contains(&self.elevation_mask)) {
            return Err(invalid("elevation_mask", format!("must be an elevation in [-π/2, π/2) rad, got {}", self.elevation_mask)));
        }
        crate::error::check_finite("lever_arm", self.lever_arm.as_slice(), 1)?;
        crate::error::check_finite("tau0", &[self.tau0], 1)?;
        crate::error::check_finite("clock0", &self.clock0, 1)
    }

    /// The corrections applied: the navigation message's Klobuchar ionosphere of `eph`
    /// when `iono`, Saastamoinen when `tropo`.
    pub fn atmosphere(&self, eph: &Ephemerides) -> Atmosphere {
        Atmosphere { iono: self.iono.then_some(eph.ionosphere), tropo: self.tropo }
    }

    pub fn spp(&self, eph: &Ephemerides) -> SppConfig {
        SppConfig {
            use_tau: self.use_tau,
            atm: Atmosphere { iono: self.iono.then_some(eph.ionosphere).filter(|_| !self.ionosphere_free), tropo: self.tropo },
            sigma_gps: self.sigma_code_gps * if self.ionosphere_free { ionosphere_free_gain(GPS_L1_HZ, GPS_L2_HZ) } else { 1.0 },
            sigma_glo: self.sigma_code_glo * if self.ionosphere_free { ionosphere_free_gain(glonass_l1_hz(0), glonass_l2_hz(0)) } else { 1.0 },
            elevation_weight: self.elevation_weight,
            elevation_mask: self.elevation_mask,
            fault_detection: self.fault_detection,
            ionosphere_free: self.ionosphere_free,
        }
    }

    /// The simulator's noise and atmosphere with the true τ_GPS (s), receiver clock
    /// δt_r(t) = `clock_bias` + `clock_drift`·(t − t₀) from the record's first epoch t₀
    /// (s, s/s) and the noise seed.
    pub fn simulation(&self, eph: &Ephemerides, tau_gps: f64, clock_bias: f64, clock_drift: f64, seed: u64) -> Result<SimConfig> {
        for (field, x) in [("tau_gps", tau_gps), ("clock_bias", clock_bias), ("clock_drift", clock_drift)] {
            crate::error::check_finite(field, &[x], 1)?;
        }
        let (sigma_code_gps, sigma_code_glo, sigma_rate) = (self.sigma_code_gps, self.sigma_code_glo, self.sigma_rate);
        Ok(SimConfig { sigma_code_gps, sigma_code_glo, sigma_rate, tau_gps, clock_bias, clock_drift, atm: self.atmosphere(eph), seed })
    }

    /// The tight aiding's configuration for an IMU record of `kind`; the c·τ_GPS PSD in m²/s.
    pub fn tight(&self, eph: &Ephemerides, kind: ImuKind) -> TightConfig {
        TightConfig {
            formulation: self.formulation,
            lever_arm: self.lever_arm,
            sigma_code_gps: self.sigma_code_gps,
            sigma_code_glo: self.sigma_code_glo,
            sigma_rate: self.sigma_rate,
            use_rate: self.use_rate,
            atm: self.atmosphere(eph),
            elevation_mask: self.elevation_mask,
            tau_psd: C_LIGHT * C_LIGHT * self.tau_psd,
            clock_h0: self.clock_h0,
            clock_hm2: self.clock_hm2,
            kind,
        }
    }

    /// Initial estimate and variance of the tight aiding's extra blocks, in layout order
    /// (`c_tau_gps` m, then `clock` (m, m/s) with [`Formulation::ClockStates`]).
    pub fn tight_initial(&self) -> (Vec<f64>, Vec<f64>) {
        let mut x = vec![C_LIGHT * self.tau0];
        let mut var = vec![(C_LIGHT * self.sigma_tau0).powi(2)];
        if self.formulation == Formulation::ClockStates {
            x.extend(self.clock0);
            var.extend(self.sigma_clock0.map(|s| s * s));
        }
        (x, var)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_pass_and_bad_values_name_their_option() {
        GnssOptions::default().check().unwrap();
        let bad = [
            GnssOptions { sigma_code_gps: 0.0, ..Default::default() },
            GnssOptions { sigma_clock0: [1.0, -1.0], ..Default::default() },
            GnssOptions { tau_psd: -1.0, ..Default::default() },
            GnssOptions { lever_arm: Vec3::new(0.0, f64::NAN, 0.0), ..Default::default() },
        ];
        let fields: Vec<String> = bad.iter().map(|o| o.check().unwrap_err().to_string()).collect();
        for (e, f) in fields.iter().zip(["sigma_code:", "sigma_clock0:", "tau_psd:", "lever_arm:"]) {
            assert!(e.starts_with(f), "{e}");
        }
    }

    /// c·τ in metres: 1 µs is 299.792458 m; the clock states follow with their σ².
    #[test]
    fn tight_initial_blocks_in_metres() {
        let o = GnssOptions { tau0: 1e-6, formulation: Formulation::ClockStates, clock0: [5.0, -0.5], sigma_clock0: [10.0, 2.0], ..Default::default() };
        let (x, var) = o.tight_initial();
        assert_eq!(x, vec![299.792458, 5.0, -0.5]);
        assert!((var[0] - 299.792458f64.powi(2)).abs() < 1e-9 && var[1..] == [100.0, 4.0]);
        assert_eq!(GnssOptions::default().tight_initial().0.len(), 1);
    }
}
