//! GLONASS satellite orbit and clock from a broadcast state vector: RK4 integration of the
//! PZ-90 equations of motion with J₂ and the luni-solar acceleration (GLONASS ICD 2008,
//! Appendix A.3.1.2).

use crate::error::{invalid, Result};
use crate::math::Vec3;

/// GLONASS ICD constants (PZ-90.11): μ (m³/s²), a_e (m), J₂, Ω (rad/s).
pub const MU_GLO: f64 = 3.986004418e14;
pub const AE_GLO: f64 = 6_378_136.0;
pub const J2_GLO: f64 = 1_082_625.75e-9;
pub const OMEGA_GLO: f64 = 7.292115e-5;
/// Default RK4 step (s); steps up to 60 s are accurate enough.
pub const DEFAULT_STEP: f64 = 30.0;

/// One broadcast GLONASS ephemeris: state at t_b (GLONASS time, s) in PZ-90, clock terms.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GloEphemeris {
    pub slot: u8,
    /// FDMA channel k ∈ [−7, 6].
    pub channel: i8,
    pub tb: f64,
    pub pos: Vec3,
    pub vel: Vec3,
    /// Luni-solar acceleration (m/s²), constant over the interval.
    pub acc: Vec3,
    /// τ_n (s): GLONASS time − satellite time at t_b.
    pub tau_n: f64,
    /// γ_n: relative frequency offset.
    pub gamma_n: f64,
}

impl GloEphemeris {
    /// From a row: slot, channel, tb, x, y, z, vx, vy, vz, ax, ay, az, tau_n, gamma_n;
    /// the channel is checked (row `index` named on error).
    pub fn from_row(x: &[f64; 14], index: usize) -> Result<GloEphemeris> {
        Ok(GloEphemeris {
            slot: x[0] as u8,
            channel: super::check_channel("glonass", x[1] as i64, index)?,
            tb: x[2],
            pos: Vec3::new(x[3], x[4], x[5]),
            vel: Vec3::new(x[6], x[7], x[8]),
            acc: Vec3::new(x[9], x[10], x[11]),
            tau_n: x[12],
            gamma_n: x[13],
        })
    }

    /// The set as a row in the order of [`GloEphemeris::from_row`].
    pub fn to_row(&self) -> [f64; 14] {
        let e = self;
        [e.slot as f64, e.channel as f64, e.tb, e.pos.x, e.pos.y, e.pos.z, e.vel.x, e.vel.y, e.vel.z, e.acc.x, e.acc.y, e.acc.z, e.tau_n, e.gamma_n]
    }
}

/// Right-hand side of Eq. 10 (J₂, centrifugal and Coriolis terms in the rotating frame).
pub fn acceleration(pos: &Vec3, vel: &Vec3, acc_ls: &Vec3, j2: f64) -> Vec3 {
    let r = pos.norm();
    let mu_bar = MU_GLO / (r * r);
    let (xb, yb, zb) = (pos.x / r, pos.y / r, pos.z / r);
    let rho2 = (AE_GLO / r).powi(2);
    let w2 = OMEGA_GLO * OMEGA_GLO;
    let k = 1.5 * j2 * mu_bar * rho2;
    Vec3::new(
        -mu_bar * xb - k * xb * (1.0 - 5.0 * zb * zb) + w2 * pos.x + 2.0 * OMEGA_GLO * vel.y + acc_ls.x,
        -mu_bar * yb - k * yb * (1.0 - 5.0 * zb * zb) + w2 * pos.y - 2.0 * OMEGA_GLO * vel.x + acc_ls.y,
        -mu_bar * zb - k * zb * (3.0 - 5.0 * zb * zb) + acc_ls.z,
    )
}

/// Least orbit radius (m) of a satellite state: the Earth's equatorial radius a_e of
/// PZ-90.11 (GLONASS ICD 2008). A state below it is inside the Earth, where the
/// equations of motion, a point mass with J₂, do not hold (at r = 0 they give NaN).
pub const MIN_RADIUS: f64 = AE_GLO;

/// [`propagate`] with the step checked (finite, > 0), the inputs finite, and the orbit
/// outside the Earth: a position below [`MIN_RADIUS`] names `pos`; an orbit that descends
/// below it at an RK4 step point, or leaves the floating-point range, names `vel`.
pub fn propagate_checked(pos: Vec3, vel: Vec3, acc_ls: &Vec3, dt: f64, max_step: f64, j2: f64) -> Result<(Vec3, Vec3)> {
    crate::error::check_positive("step", max_step)?;
    for (field, v) in [("pos", &pos), ("vel", &vel), ("acc", acc_ls)] {
        crate::error::check_finite(field, v.as_slice(), 1)?;
    }
    for (field, x) in [("dt", dt), ("j2", j2)] {
        crate::error::check_finite(field, &[x], 1)?;
    }
    let steps = (dt.abs() / max_step).ceil();
    if !(steps <= MAX_RK4_STEPS as f64) {
        return Err(invalid("step", format!("|dt| / step = {steps} RK4 steps, at most {MAX_RK4_STEPS}")));
    }
    let r0 = pos.norm();
    if r0 < MIN_RADIUS {
        return Err(invalid("pos", format!("radius {r0} m is inside the Earth (below a_e = {MIN_RADIUS} m): not a satellite state")));
    }
    let ((r, v), lowest) = propagate_lowest(pos, vel, acc_ls, dt, max_step, j2);
    // a NaN step point carries on to the end: the first check catches it
    if !r.iter().chain(v.iter()).all(|x| x.is_finite()) {
        return Err(invalid("vel", "the orbit of pos and vel leaves the floating-point range within dt"));
    }
    if lowest < MIN_RADIUS {
        return Err(invalid("vel", format!("the orbit of pos and vel descends inside the Earth within dt (radius {lowest} m, below a_e = {MIN_RADIUS} m)")));
    }
    Ok((r, v))
}

/// Most RK4 steps of one checked propagation (a broadcast set is valid for ±15 min, 30 steps
/// of 30 s; 10⁷ steps take about a second).
pub const MAX_RK4_STEPS: usize = 10_000_000;

/// Classical RK4 of (r, v) over `dt` seconds in equal steps no longer than `max_step`.
pub fn propagate(pos: Vec3, vel: Vec3, acc_ls: &Vec3, dt: f64, max_step: f64, j2: f64) -> (Vec3, Vec3) {
    propagate_lowest(pos, vel, acc_ls, dt, max_step, j2).0
}

/// [`propagate`] and the least radius |r| (m) of its step points after the first.
fn propagate_lowest(pos: Vec3, vel: Vec3, acc_ls: &Vec3, dt: f64, max_step: f64, j2: f64) -> ((Vec3, Vec3), f64) {
    let n = ((dt.abs() / max_step).ceil() as usize).max(1);
    let h = dt / n as f64;
    let (mut r, mut v) = (pos, vel);
    let mut lowest = f64::INFINITY;
    for _ in 0..n {
        let k1r = v;
        let k1v = acceleration(&r, &v, acc_ls, j2);
        let k2r = v + k1v * (0.5 * h);
        let k2v = acceleration(&(r + k1r * (0.5 * h)), &k2r, acc_ls, j2);
        let k3r = v + k2v * (0.5 * h);
        let k3v = acceleration(&(r + k2r * (0.5 * h)), &k3r, acc_ls, j2);
        let k4r = v + k3v * h;
        let k4v = acceleration(&(r + k3r * h), &k4r, acc_ls, j2);
        r += (k1r + k2r * 2.0 + k3r * 2.0 + k4r) * (h / 6.0);
        v += (k1v + k2v * 2.0 + k3v * 2.0 + k4v) * (h / 6.0);
        lowest = lowest.min(r.norm());
    }
    ((r, v), lowest)
}

impl GloEphemeris {
    pub fn validate(&self, index: usize) -> Result<()> {
        super::check_channel("glonass_ephemeris", self.channel as i64, index)?;
        let vals = [self.tb, self.tau_n, self.gamma_n];
        if vals.iter().any(|x| !x.is_finite()) || [self.pos, self.vel, self.acc].iter().any(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(invalid("glonass_ephemeris", format!("non-finite value at index {index}")));
        }
        let r = self.pos.norm();
        if !(1.0e7..1.0e8).contains(&r) {
            return Err(invalid("glonass_ephemeris", format!("orbit radius {r} m at index {index} is not a GNSS orbit")));
        }
        Ok(())
    }

    /// PZ-90 position and velocity at GLONASS time t by RK4 from t_b (step `max_step` s).
    pub fn state(&self, t: f64, max_step: f64) -> (Vec3, Vec3) {
        propagate(self.pos, self.vel, &self.acc, t - self.tb, max_step, J2_GLO)
    }

    /// Clock offset δt^s = −τ_n + γ_n (t − t_b) (s) and its rate (Eq. 11).
    pub fn clock(&self, t: f64) -> (f64, f64) {
        (-self.tau_n + self.gamma_n * (t - self.tb), self.gamma_n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_count_is_checked_before_the_loop() {
        let (r, v) = circular(0.3);
        for (dt, step) in [(1.0, 5e-324), (1e308, 1.0), (1e9, 1e-3)] {
            match propagate_checked(r, v, &Vec3::zeros(), dt, step, J2_GLO) {
                Err(crate::error::NavError::InvalidInput { field, .. }) => assert_eq!(field, "step"),
                other => panic!("dt {dt}, step {step}: expected InvalidInput on step, got {other:?}"),
            }
        }
        assert!(propagate_checked(r, v, &Vec3::zeros(), 900.0, 30.0, J2_GLO).is_ok());
    }

    /// A state inside the Earth names pos; one that falls into it names vel.
    #[test]
    fn states_inside_the_earth_are_rejected() {
        let field = |p: Vec3, v: Vec3, dt: f64| match propagate_checked(p, v, &Vec3::zeros(), dt, 30.0, J2_GLO) {
            Err(crate::error::NavError::InvalidInput { field, .. }) => field,
            other => format!("{other:?}"),
        };
        assert_eq!(field(Vec3::zeros(), Vec3::zeros(), 100.0), "pos");
        assert_eq!(field(Vec3::new(6.0e6, 0.0, 0.0), Vec3::zeros(), 100.0), "pos");
        // dropped from 7000 km at rest: below a_e after about 15 min
        assert_eq!(field(Vec3::new(7.0e6, 0.0, 0.0), Vec3::zeros(), 3600.0), "vel");
        assert!(propagate_checked(Vec3::new(7.0e6, 0.0, 0.0), Vec3::zeros(), &Vec3::zeros(), 60.0, 30.0, J2_GLO).is_ok());
    }

    fn circular(u: f64) -> (Vec3, Vec3) {
        // a = 25508 km, i = 64.8°, node at 0: inertial circular state expressed in ECEF at t = 0
        let a = 25_508_000.0f64;
        let vc = (MU_GLO / a).sqrt();
        let i = 64.8f64.to_radians();
        let r = Vec3::new(a * u.cos(), a * u.sin() * i.cos(), a * u.sin() * i.sin());
        let vi = Vec3::new(-vc * u.sin(), vc * u.cos() * i.cos(), vc * u.cos() * i.sin());
        let w = Vec3::new(0.0, 0.0, OMEGA_GLO);
        (r, vi - w.cross(&r))
    }

    #[test]
    fn rk4_30s_agrees_with_fine_step_over_15_min_and_j2_matters() {
        // acceptance: < 1 mm vs a tight integration; 15–50 m if J₂ is dropped
        for u in [0.0f64, 45.0, 90.0] {
            let (r, v) = circular(u.to_radians());
            for dt in [900.0, -900.0] {
                let (ref_r, _) = propagate(r, v, &Vec3::zeros(), dt, 0.5, J2_GLO);
                let (r30, _) = propagate(r, v, &Vec3::zeros(), dt, 30.0, J2_GLO);
                let (rno, _) = propagate(r, v, &Vec3::zeros(), dt, 0.5, 0.0);
                assert!((r30 - ref_r).norm() < 1e-3, "{}", (r30 - ref_r).norm());
                let dj2 = (rno - ref_r).norm();
                assert!((15.0..50.0).contains(&dj2), "J2 effect {dj2}");
            }
        }
    }
}
