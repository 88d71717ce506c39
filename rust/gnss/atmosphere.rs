//! Standard atmosphere delays: Klobuchar ionosphere (IS-GPS-200 20.3.3.5.2.5) and
//! Saastamoinen troposphere (Saastamoinen 1972).

use super::{C_LIGHT, GPS_L1_HZ};
use std::f64::consts::PI;

/// Broadcast Klobuchar coefficients α (s/semicircleⁿ) and β (s/semicircleⁿ).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Klobuchar {
    pub alpha: [f64; 4],
    pub beta: [f64; 4],
}

impl Default for Klobuchar {
    /// A typical broadcast set (the GPS navigation message of 2009-01-01, as in RINEX ION ALPHA/BETA).
    fn default() -> Self {
        Klobuchar { alpha: [1.118e-8, 7.451e-9, -5.961e-8, -1.192e-7], beta: [1.167e5, -2.294e5, -1.311e5, 1.049e6] }
    }
}

impl Klobuchar {
    /// From the eight broadcast coefficients α₀..α₃, β₀..β₃ in RINEX order (ION ALPHA,
    /// ION BETA; GPSA, GPSB).
    pub fn from_coefficients(c: [f64; 8]) -> Klobuchar {
        let [a0, a1, a2, a3, b0, b1, b2, b3] = c;
        Klobuchar { alpha: [a0, a1, a2, a3], beta: [b0, b1, b2, b3] }
    }

    /// The eight coefficients α₀..α₃, β₀..β₃.
    pub fn coefficients(&self) -> [f64; 8] {
        let ([a0, a1, a2, a3], [b0, b1, b2, b3]) = (self.alpha, self.beta);
        [a0, a1, a2, a3, b0, b1, b2, b3]
    }

    /// L1 ionospheric group delay (m) for receiver (lat, lon) rad, elevation and azimuth rad,
    /// GPS time t (s). GLONASS channel frequencies scale it by (f_L1/f_k)².
    pub fn delay(&self, lat: f64, lon: f64, elev: f64, azim: f64, t: f64) -> f64 {
        let e = elev / PI; // semicircles
        let psi = 0.0137 / (e + 0.11) - 0.022;
        let phi_i = (lat / PI + psi * azim.cos()).clamp(-0.416, 0.416);
        let lam_i = lon / PI + psi * azim.sin() / (phi_i * PI).cos();
        let phi_m = phi_i + 0.064 * ((lam_i - 1.617) * PI).cos();
        let tt = (43200.0 * lam_i + t).rem_euclid(86400.0);
        let f = 1.0 + 16.0 * (0.53 - e).powi(3);
        let poly = |c: &[f64; 4]| c[0] + phi_m * (c[1] + phi_m * (c[2] + phi_m * c[3]));
        let amp = poly(&self.alpha).max(0.0);
        let per = poly(&self.beta).max(72000.0);
        let x = 2.0 * PI * (tt - 50400.0) / per;
        let d = if x.abs() < 1.57 { 5e-9 + amp * (1.0 - x * x / 2.0 + x.powi(4) / 24.0) } else { 5e-9 };
        C_LIGHT * f * d
    }

    /// Delay (m) on carrier `freq_hz`: I·(f_L1/f)².
    pub fn delay_at(&self, lat: f64, lon: f64, elev: f64, azim: f64, t: f64, freq_hz: f64) -> f64 {
        self.delay(lat, lon, elev, azim, t) * (GPS_L1_HZ / freq_hz).powi(2)
    }
}

/// Saastamoinen tropospheric delay (m) with the standard atmosphere (relative humidity 0.7)
/// at geodetic latitude `lat` rad, height h m, elevation rad; 0 below the horizon or for
/// h outside [−100 m, 10 km].
pub fn saastamoinen(lat: f64, h: f64, elev: f64) -> f64 {
    if elev <= 0.0 || !(-100.0..=1.0e4).contains(&h) {
        return 0.0;
    }
    let p = 1013.25 * (1.0 - 2.2557e-5 * h).powf(5.2568);
    let tk = 288.15 - 0.0065 * h;
    let ew = 6.108 * 0.7 * ((17.15 * tk - 4684.0) / (tk - 38.45)).exp();
    let z = PI / 2.0 - elev;
    (0.0022768 * p / (1.0 - 0.00266 * (2.0 * lat).cos() - 0.00028 * h / 1e3) + 0.002277 * (1255.0 / tk + 0.05) * ew) / z.cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saastamoinen_zenith_delay_is_about_2_4_m_at_sea_level() {
        // standard zenith hydrostatic + wet delay at sea level ≈ 2.3–2.6 m
        let z = saastamoinen(0.97, 0.0, PI / 2.0);
        assert!((2.3..2.6).contains(&z), "{z}");
        assert!((saastamoinen(0.97, 0.0, 10f64.to_radians()) / z - 1.0 / 10f64.to_radians().sin()).abs() < 1e-9);
        assert_eq!(saastamoinen(0.97, 0.0, -0.1), 0.0);
    }

    #[test]
    fn klobuchar_night_floor_and_day_peak() {
        let k = Klobuchar::default();
        // night (local 02:00): 5 ns · obliquity; zenith obliquity F = 1 + 16·0.03³
        let night = k.delay(0.0, 0.0, PI / 2.0, 0.0, 2.0 * 3600.0);
        assert!((night - C_LIGHT * 5e-9 * (1.0 + 16.0 * 0.03f64.powi(3))).abs() < 1e-9, "{night}");
        let day = k.delay(0.0, 0.0, PI / 2.0, 0.0, 14.0 * 3600.0);
        assert!(day > night);
    }
}
