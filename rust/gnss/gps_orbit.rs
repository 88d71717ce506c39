//! GPS satellite position, velocity and clock from broadcast Keplerian elements
//! (IS-GPS-200, Table 20-IV and the clock correction of 20.3.3.3.3.1).

use crate::error::{invalid, Result};
use crate::math::Vec3;

/// μ of the GPS ICD (m³/s²).
pub const MU_GPS: f64 = 3.986005e14;
/// Ω̇_e of the GPS ICD (rad/s).
pub const OMEGA_E_DOT: f64 = 7.2921151467e-5;
/// Relativistic clock constant F = −2√μ/c² (s/√m).
pub const F_REL: f64 = -4.442807633e-10;
const HALF_WEEK: f64 = 302_400.0;

/// One broadcast ephemeris and clock set (angles in rad, times in GPS seconds).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct GpsEphemeris {
    pub prn: u8,
    pub toe: f64,
    pub sqrt_a: f64,
    pub e: f64,
    pub m0: f64,
    pub delta_n: f64,
    pub omega0: f64,
    pub i0: f64,
    /// Argument of perigee ω.
    pub omega: f64,
    pub omega_dot: f64,
    pub idot: f64,
    pub cuc: f64,
    pub cus: f64,
    pub crc: f64,
    pub crs: f64,
    pub cic: f64,
    pub cis: f64,
    pub toc: f64,
    pub af0: f64,
    pub af1: f64,
    pub af2: f64,
    pub tgd: f64,
}

impl GpsEphemeris {
    /// Width of [`GpsEphemeris::to_row`]: prn, toe, sqrt_a, e, m0, delta_n, omega0, i0,
    /// omega, omega_dot, idot, cuc, cus, crc, crs, cic, cis, toc, af0, af1, af2, tgd.
    pub const ROW: usize = 22;

    /// From a row in the order of [`GpsEphemeris::ROW`] (the PRN is checked by
    /// `Ephemerides::new`).
    pub fn from_row(r: &[f64; 22]) -> GpsEphemeris {
        GpsEphemeris {
            prn: r[0] as u8, toe: r[1], sqrt_a: r[2], e: r[3], m0: r[4], delta_n: r[5], omega0: r[6], i0: r[7], omega: r[8],
            omega_dot: r[9], idot: r[10], cuc: r[11], cus: r[12], crc: r[13], crs: r[14], cic: r[15], cis: r[16], toc: r[17],
            af0: r[18], af1: r[19], af2: r[20], tgd: r[21],
        }
    }

    /// The set as a row in the order of [`GpsEphemeris::ROW`].
    pub fn to_row(&self) -> [f64; 22] {
        let e = self;
        [e.prn as f64, e.toe, e.sqrt_a, e.e, e.m0, e.delta_n, e.omega0, e.i0, e.omega, e.omega_dot, e.idot, e.cuc, e.cus, e.crc, e.crs, e.cic, e.cis, e.toc, e.af0, e.af1, e.af2, e.tgd]
    }
}

/// t − t_ref wrapped to ±302400 s (week crossover, IS-GPS-200 20.3.3.4.3).
fn wrap_half_week(dt: f64) -> f64 {
    if dt > HALF_WEEK {
        dt - 2.0 * HALF_WEEK
    } else if dt < -HALF_WEEK {
        dt + 2.0 * HALF_WEEK
    } else {
        dt
    }
}

impl GpsEphemeris {
    /// Reject non-physical elements (index = position in the caller's list).
    pub fn validate(&self, index: usize) -> Result<()> {
        let vals = [self.toe, self.sqrt_a, self.e, self.m0, self.delta_n, self.omega0, self.i0, self.omega, self.omega_dot,
            self.idot, self.cuc, self.cus, self.crc, self.crs, self.cic, self.cis, self.toc, self.af0, self.af1, self.af2, self.tgd];
        if vals.iter().any(|x| !x.is_finite()) {
            return Err(invalid("gps_ephemeris", format!("non-finite element at index {index}")));
        }
        if !(0.0..1.0).contains(&self.e) {
            return Err(invalid("gps_ephemeris", format!("eccentricity {} at index {index} outside [0, 1)", self.e)));
        }
        if self.sqrt_a <= 0.0 {
            return Err(invalid("gps_ephemeris", format!("sqrt_a {} at index {index} must be > 0", self.sqrt_a)));
        }
        Ok(())
    }

    /// Eccentric anomaly E and its rate at time t (Newton until |ΔE| < 1e-13, Eq. 8).
    fn anomaly(&self, t: f64) -> (f64, f64, f64) {
        let a = self.sqrt_a * self.sqrt_a;
        let n = (MU_GPS / (a * a * a)).sqrt() + self.delta_n;
        let tk = wrap_half_week(t - self.toe);
        let m = self.m0 + n * tk;
        let mut ek = m;
        for _ in 0..50 {
            let d = (ek - self.e * ek.sin() - m) / (1.0 - self.e * ek.cos());
            ek -= d;
            if d.abs() < 1e-13 {
                break;
            }
        }
        let edot = n / (1.0 - self.e * ek.cos());
        (ek, edot, tk)
    }

    /// ECEF position (m) and velocity (m/s) at GPS time t (s) by IS-GPS-200 Table 20-IV and
    /// its analytic time derivative (Ė = n/(1 − e cos E)).
    pub fn state(&self, t: f64) -> (Vec3, Vec3) {
        let (ek, edot, tk) = self.anomaly(t);
        let a = self.sqrt_a * self.sqrt_a;
        let (se, ce) = ek.sin_cos();
        let q = (1.0 - self.e * self.e).sqrt();
        let nu = (q * se).atan2(ce - self.e);
        let nudot = edot * q / (1.0 - self.e * ce);
        let phi = nu + self.omega;
        let (s2, c2) = (2.0 * phi).sin_cos();
        let u = phi + self.cus * s2 + self.cuc * c2;
        let r = a * (1.0 - self.e * ce) + self.crs * s2 + self.crc * c2;
        let i = self.i0 + self.cis * s2 + self.cic * c2 + self.idot * tk;
        let udot = nudot * (1.0 + 2.0 * (self.cus * c2 - self.cuc * s2));
        let rdot = a * self.e * se * edot + 2.0 * nudot * (self.crs * c2 - self.crc * s2);
        let idot = self.idot + 2.0 * nudot * (self.cis * c2 - self.cic * s2);
        let (su, cu) = u.sin_cos();
        let (xp, yp) = (r * cu, r * su);
        let (xpd, ypd) = (rdot * cu - r * udot * su, rdot * su + r * udot * cu);
        let om_rate = self.omega_dot - OMEGA_E_DOT;
        let om = self.omega0 + om_rate * tk - OMEGA_E_DOT * self.toe;
        let (so, co) = om.sin_cos();
        let (si, ci) = i.sin_cos();
        let pos = Vec3::new(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si);
        let vel = Vec3::new(
            xpd * co - ypd * ci * so + yp * si * idot * so - om_rate * pos.y,
            xpd * so + ypd * ci * co - yp * si * idot * co + om_rate * pos.x,
            ypd * si + yp * ci * idot,
        );
        (pos, vel)
    }

    /// Satellite clock offset (s) and rate (s/s) at GPS time t, with the relativistic term
    /// F·e·√A·sin E and −T_GD (Eq. 9).
    pub fn clock(&self, t: f64) -> (f64, f64) {
        let (ek, edot, _) = self.anomaly(t);
        let dt = wrap_half_week(t - self.toc);
        let rel = F_REL * self.e * self.sqrt_a;
        (
            self.af0 + self.af1 * dt + self.af2 * dt * dt + rel * ek.sin() - self.tgd,
            self.af1 + 2.0 * self.af2 * dt + rel * ek.cos() * edot,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn sample() -> GpsEphemeris {
        // a realistic broadcast set (values of the kind in a RINEX 2 NAV file)
        GpsEphemeris {
            prn: 5, toe: 352800.0, sqrt_a: 5153.65531, e: 0.0103, m0: 1.2, delta_n: 4.6e-9, omega0: -2.1, i0: 0.96,
            omega: 0.65, omega_dot: -8.1e-9, idot: 3.2e-10, cuc: 2.1e-6, cus: 8.4e-6, crc: 210.0, crs: 45.0, cic: 1.2e-7,
            cis: -9.0e-8, toc: 352800.0, af0: 1.5e-4, af1: 2.0e-12, af2: 0.0, tgd: -1.1e-8,
        }
    }

    #[test]
    fn velocity_matches_central_difference() {
        let e = sample();
        for dt in [-7000.0, -100.0, 0.0, 3000.0] {
            let t = e.toe + dt;
            let (_, v) = e.state(t);
            let h = 0.01;
            let fd = (e.state(t + h).0 - e.state(t - h).0) / (2.0 * h);
            assert!((v - fd).norm() < 1e-3, "{}", (v - fd).norm());
            let (_, cd) = e.clock(t);
            let cfd = (e.clock(t + h).0 - e.clock(t - h).0) / (2.0 * h);
            assert!((cd - cfd).abs() < 1e-15);
        }
    }

    #[test]
    fn orbit_radius_is_that_of_the_semi_major_axis() {
        let e = sample();
        let (p, _) = e.state(e.toe);
        let a = e.sqrt_a * e.sqrt_a;
        assert!(p.norm() > a * (1.0 - e.e) - 1000.0 && p.norm() < a * (1.0 + e.e) + 1000.0);
    }
}
