//! Inertial oracle (docs/departures.md#full-phase-predictor): the atom flies
//! ballistically in the inertial frame i (uniform gravity g and optional constant gradient
//! Γ_i), released at the sensor origin with the sensor's velocity plus C_is v0; its
//! position is transformed into the moving, rotating sensor frame at the pulse times,
//! x(t) = C_si(t) (r_a(t) − r_s(t)), r_s = r_b + C_ib l, and φ = k·D[x].
//! Body motions are analytic with exact derivatives, so the oracle also generates the
//! IMU stream (specific force, angular rate, angular acceleration) the predictor is fed.

use crate::cai::predictor::Channel;
use crate::error::{check_finite, check_positive, invalid, Result};
use crate::math::{dcm_from_euler, Mat3, Vec3};
use nalgebra::SymmetricEigen;
use std::f64::consts::PI;

/// Rigid-body motion of the IMU in the inertial frame with exact derivatives.
pub trait BodyMotion {
    /// C_ib (body → inertial), ω_b (rad/s) and ω̇_b (rad/s²) at t.
    fn attitude(&self, t: f64) -> (Mat3, Vec3, Vec3);
    /// Inertial velocity (m/s) of the IMU.
    fn velocity(&self, t: f64) -> Vec3;
    /// Inertial acceleration (m/s²) of the IMU.
    fn acceleration(&self, t: f64) -> Vec3;
    /// r_b(t1) − r_b(t0) (m), computed without cancellation.
    fn displacement(&self, t0: f64, t1: f64) -> Vec3;
}

/// One scalar signal c0 + c1 t + c2 t² + Σ A sin(2π f t + φ).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Signal {
    pub poly: [f64; 3],
    /// (amplitude, frequency Hz, phase rad)
    pub sines: Vec<(f64, f64, f64)>,
}

impl Signal {
    /// Value and first two derivatives.
    fn eval(&self, t: f64) -> [f64; 3] {
        let [c0, c1, c2] = self.poly;
        let mut r = [c0 + c1 * t + c2 * t * t, c1 + 2.0 * c2 * t, 2.0 * c2];
        for &(a, f, ph) in &self.sines {
            let om = 2.0 * PI * f;
            let (s, c) = (om * t + ph).sin_cos();
            r[0] += a * s;
            r[1] += a * om * c;
            r[2] -= a * om * om * s;
        }
        r
    }
    /// s(t1) − s(t0): sin a1 − sin a0 = 2 cos((a1 + a0)/2) sin((a1 − a0)/2).
    fn difference(&self, t0: f64, t1: f64) -> f64 {
        let [_, c1, c2] = self.poly;
        let dt = t1 - t0;
        let mut d = c1 * dt + c2 * dt * (t1 + t0);
        for &(a, f, ph) in &self.sines {
            let om = 2.0 * PI * f;
            d += 2.0 * a * (0.5 * om * (t1 + t0) + ph).cos() * (0.5 * om * dt).sin();
        }
        d
    }
}

/// Position per inertial axis and attitude as z-y-x Euler angles (roll, pitch, yaw), each
/// a [`Signal`]: C_ib = Rz(yaw) Ry(pitch) Rx(roll).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SineMotion {
    pub position: [Signal; 3],
    pub euler: [Signal; 3],
}

impl BodyMotion for SineMotion {
    fn attitude(&self, t: f64) -> (Mat3, Vec3, Vec3) {
        let [r, p, y] = self.euler.each_ref().map(|s| s.eval(t));
        let (sr, cr) = r[0].sin_cos();
        let (sp, cp) = p[0].sin_cos();
        // ω_b = E(roll, pitch) · (ṙ, ṗ, ẏ) for the z-y-x sequence.
        let w = Vec3::new(r[1] - sp * y[1], cr * p[1] + sr * cp * y[1], -sr * p[1] + cr * cp * y[1]);
        // ω̇_b = E · (r̈, p̈, ÿ) + Ė · (ṙ, ṗ, ẏ).
        let wd = Vec3::new(
            r[2] - cp * p[1] * y[1] - sp * y[2],
            -sr * r[1] * p[1] + cr * p[2] + cr * r[1] * cp * y[1] - sr * sp * p[1] * y[1] + sr * cp * y[2],
            -cr * r[1] * p[1] - sr * p[2] - sr * r[1] * cp * y[1] - cr * sp * p[1] * y[1] + cr * cp * y[2],
        );
        (dcm_from_euler(r[0], p[0], y[0]), w, wd)
    }
    fn velocity(&self, t: f64) -> Vec3 {
        Vec3::from(self.position.each_ref().map(|s| s.eval(t)[1]))
    }
    fn acceleration(&self, t: f64) -> Vec3 {
        Vec3::from(self.position.each_ref().map(|s| s.eval(t)[2]))
    }
    fn displacement(&self, t0: f64, t1: f64) -> Vec3 {
        Vec3::from(self.position.each_ref().map(|s| s.difference(t0, t1)))
    }
}

impl SineMotion {
    /// The motion of position / Euler-angle polynomial rows (3 rows c0, c1, c2, one per
    /// axis) and sine rows [axis, amplitude, frequency Hz, phase rad], axis 0, 1 or 2.
    pub fn from_rows(position_poly: &[[f64; 3]], position_sines: &[[f64; 4]], attitude_poly: &[[f64; 3]], attitude_sines: &[[f64; 4]]) -> Result<Self> {
        for (name, p) in [("position_poly", position_poly), ("attitude_poly", attitude_poly)] {
            if p.len() != 3 {
                return Err(invalid(name, format!("expected shape (3, 3), got ({}, 3)", p.len())));
            }
        }
        for (name, s) in [("position_sines", position_sines), ("attitude_sines", attitude_sines)] {
            if let Some(i) = s.iter().position(|r| !(r[0] == 0.0 || r[0] == 1.0 || r[0] == 2.0)) {
                return Err(crate::error::invalid_at(name, i, "axis column must be 0, 1 or 2"));
            }
        }
        let signal = |poly: &[f64; 3], sines: &[[f64; 4]], axis: usize| Signal {
            poly: *poly,
            sines: sines.iter().filter(|r| r[0] as usize == axis).map(|r| (r[1], r[2], r[3])).collect(),
        };
        let (&[p0, p1, p2], &[e0, e1, e2]) = (position_poly, attitude_poly) else {
            return Err(invalid("position_poly", "expected shape (3, 3)"));
        };
        Ok(SineMotion {
            position: [(p0, 0), (p1, 1), (p2, 2)].map(|(c, a)| signal(&c, position_sines, a)),
            euler: [(e0, 0), (e1, 1), (e2, 2)].map(|(c, a)| signal(&c, attitude_sines, a)),
        })
    }
}

impl YawDrive {
    /// Forward speed (m/s), yaw-rate amplitude (rad/s) and period (s, > 0) of the yaw rate.
    pub fn new(speed: f64, yaw_rate_amplitude: f64, period: f64) -> Result<Self> {
        crate::error::check_finite("speed", &[speed], 1)?;
        crate::error::check_finite("yaw_rate_amplitude", &[yaw_rate_amplitude], 1)?;
        crate::error::check_positive("period", period)?;
        Ok(YawDrive { speed, yaw_rate_amplitude, period })
    }
}

/// Drive of Tennstedt et al. 2023, Fig. 7: constant forward speed V along the
/// body x axis, level, yaw rate ω_z = A sin(2πt/P), yaw ψ = A P/(2π)(1 − cos(2πt/P)).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct YawDrive {
    pub speed: f64,
    pub yaw_rate_amplitude: f64,
    pub period: f64,
}

impl YawDrive {
    fn yaw(&self, t: f64) -> [f64; 3] {
        let om = 2.0 * PI / self.period;
        let a = self.yaw_rate_amplitude;
        [a / om * (1.0 - (om * t).cos()), a * (om * t).sin(), a * om * (om * t).cos()]
    }
}

/// 16-point Gauss–Legendre nodes and weights on [−1, 1] (positive half).
const GL16: [(f64, f64); 8] = [
    (0.0950125098376374, 0.1894506104550685),
    (0.2816035507792589, 0.1826034150449236),
    (0.4580167776572274, 0.1691565193950025),
    (0.6178762444026438, 0.1495959888165767),
    (0.755404408355003, 0.1246289712555339),
    (0.8656312023878318, 0.0951585116824928),
    (0.9445750230732326, 0.0622535239386479),
    (0.9894009349916499, 0.0271524594117541),
];

impl BodyMotion for YawDrive {
    fn attitude(&self, t: f64) -> (Mat3, Vec3, Vec3) {
        let [psi, rate, acc] = self.yaw(t);
        (dcm_from_euler(0.0, 0.0, psi), Vec3::new(0.0, 0.0, rate), Vec3::new(0.0, 0.0, acc))
    }
    fn velocity(&self, t: f64) -> Vec3 {
        let psi = self.yaw(t)[0];
        self.speed * Vec3::new(psi.cos(), psi.sin(), 0.0)
    }
    fn acceleration(&self, t: f64) -> Vec3 {
        let [psi, rate, _] = self.yaw(t);
        self.speed * rate * Vec3::new(-psi.sin(), psi.cos(), 0.0)
    }
    /// ∫ V (cos ψ, sin ψ, 0) dt by 16-point Gauss–Legendre on pieces of at most P/20
    /// (ψ is an entire function; the rule is exact to rounding on such pieces).
    fn displacement(&self, t0: f64, t1: f64) -> Vec3 {
        let n = (((t1 - t0).abs() / (self.period / 20.0)).ceil() as usize).max(1);
        let h = (t1 - t0) / n as f64;
        let mut d = Vec3::zeros();
        for j in 0..n {
            let c = t0 + (j as f64 + 0.5) * h;
            for &(x, wgt) in &GL16 {
                for s in [-1.0, 1.0] {
                    d += 0.5 * h * wgt * self.velocity(c + s * 0.5 * h * x);
                }
            }
        }
        d
    }
}

/// One of the analytic motions above, as a value that can be saved (pickle of
/// `atomnav.cai` motions). The set is closed: a new motion needs its exact derivatives
/// here anyway, and adds a variant.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum AnalyticMotion {
    Sine(Box<SineMotion>),
    YawDrive(YawDrive),
}

impl AnalyticMotion {
    fn motion(&self) -> &dyn BodyMotion {
        match self {
            AnalyticMotion::Sine(m) => m.as_ref(),
            AnalyticMotion::YawDrive(m) => m,
        }
    }
}

impl BodyMotion for AnalyticMotion {
    fn attitude(&self, t: f64) -> (Mat3, Vec3, Vec3) {
        self.motion().attitude(t)
    }
    fn velocity(&self, t: f64) -> Vec3 {
        self.motion().velocity(t)
    }
    fn acceleration(&self, t: f64) -> Vec3 {
        self.motion().acceleration(t)
    }
    fn displacement(&self, t0: f64, t1: f64) -> Vec3 {
        self.motion().displacement(t0, t1)
    }
}

/// Gravity field g(r) = g0 + Γ (r − r_ref), r_ref = IMU position at `t_ref`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Gravity {
    pub g0: Vec3,
    pub gradient: Option<Mat3>,
    pub t_ref: f64,
}

impl Gravity {
    fn check(&self) -> Result<()> {
        check_finite("gravity", self.g0.as_slice(), 3)?;
        if let Some(g) = &self.gradient {
            check_finite("gradient", g.as_slice(), 3)?;
            if (g - g.transpose()).abs().max() > 1e-12 * g.abs().max() {
                return Err(invalid("gradient", "gravity-gradient tensor must be symmetric"));
            }
        }
        Ok(())
    }
    fn at(&self, m: &dyn BodyMotion, t: f64, offset: &Vec3) -> Vec3 {
        match &self.gradient {
            None => self.g0,
            Some(g) => self.g0 + g * (m.displacement(self.t_ref, t) + offset),
        }
    }
}

/// Ideal IMU output at the times `t`: specific force f_b = C_bi (r̈_b − g(r_b)), ω_b, ω̇_b.
pub fn imu_from_motion(m: &dyn BodyMotion, t: &[f64], gravity: &Gravity) -> Result<(Vec<Vec3>, Vec<Vec3>, Vec<Vec3>)> {
    check_finite("t", t, 1)?;
    gravity.check()?;
    let mut f = Vec::with_capacity(t.len());
    let mut w = Vec::with_capacity(t.len());
    let mut wd = Vec::with_capacity(t.len());
    for &ti in t {
        let (c_ib, om, omd) = m.attitude(ti);
        f.push(c_ib.transpose() * (m.acceleration(ti) - gravity.at(m, ti, &Vec3::zeros())));
        w.push(om);
        wd.push(omd);
    }
    Ok((f, w, wd))
}

/// Functions C(τ) = cosh(√λ τ), S(τ) = sinh(√λ τ)/√λ, K(τ) = (C − 1)/λ of ü = λu + c,
/// valid for either sign of λ (power series for |λ|τ² ≤ 1, closed form beyond).
fn mode_functions(lam: f64, tau: f64) -> [f64; 3] {
    let z = lam * tau * tau;
    if z.abs() <= 1.0 {
        let (mut c, mut s, mut k) = (0.0, 0.0, 0.0);
        let mut p = 1.0; // z^n / (2n)!
        for n in 0..25u32 {
            let fn1 = (2 * n + 1) as f64;
            c += p;
            s += p / fn1;
            k += p / (fn1 * (fn1 + 1.0));
            p *= z / ((2 * n + 1) as f64 * (2 * n + 2) as f64);
        }
        [c, s * tau, k * tau * tau]
    } else if lam > 0.0 {
        let r = lam.sqrt();
        [(r * tau).cosh(), (r * tau).sinh() / r, ((r * tau).cosh() - 1.0) / lam]
    } else {
        let r = (-lam).sqrt();
        [(r * tau).cos(), (r * tau).sin() / r, ((r * tau).cos() - 1.0) / lam]
    }
}

/// Atom displacement r_a(t_s + τ) − r_a(t_s) for release position offset u0 = r_a(t_s) −
/// r_ref, velocity u1, in g(r) = g0 + Γ (r − r_ref): exact mode-wise solution.
// invariant: fixed-size: from_fn gives i < 3 for the 3-vectors and 3 eigenvalues.
#[allow(clippy::indexing_slicing)]
fn atom_displacement(gravity: &Gravity, u0: &Vec3, u1: &Vec3, tau: f64) -> Vec3 {
    match &gravity.gradient {
        None => u1 * tau + 0.5 * gravity.g0 * tau * tau,
        Some(g) => {
            let eig = SymmetricEigen::new(*g);
            let q = eig.eigenvectors;
            let (a0, a1, c) = (q.transpose() * u0, q.transpose() * u1, q.transpose() * gravity.g0);
            let d = Vec3::from_fn(|i, _| {
                let [_, s, k] = mode_functions(eig.eigenvalues[i], tau);
                // u(τ) − u0 = (C − 1)u0 + S u1 + K c = K (λ u0 + c) + S u1.
                k * (eig.eigenvalues[i] * a0[i] + c[i]) + s * a1[i]
            });
            q * d
        }
    }
}

/// Exact phase (rad) of every shot (start times `shots`, pulses at 0, T, 2T) and channel:
/// row `shot * channels.len() + channel`.
pub fn oracle_phase(m: &dyn BodyMotion, shots: &[f64], t_sep: f64, channels: &[Channel], gravity: &Gravity) -> Result<Vec<f64>> {
    check_positive("T", t_sep)?;
    check_finite("shots", shots, 1)?;
    gravity.check()?;
    let mut out = Vec::with_capacity(shots.len() * channels.len());
    for &ts in shots {
        let (c_ib0, w0, _) = m.attitude(ts);
        for (j, ch) in channels.iter().enumerate() {
            if ch.k.norm() == 0.0 {
                return Err(invalid(&format!("channels[{j}].k"), "zero wave vector (k must be non-zero)"));
            }
            let c_is0 = c_ib0 * ch.c_sb.transpose();
            let lever_i0 = c_ib0 * ch.lever;
            // ṙ_s = ṙ_b + C_ib (ω_b × l); atom released with ṙ_s + C_is v0.
            let u1 = m.velocity(ts) + c_ib0 * w0.cross(&ch.lever) + c_is0 * ch.v0;
            let u0 = m.displacement(gravity.t_ref, ts) + lever_i0;
            // x(τ) = C_si (r_a − r_s), both taken relative to r_s(t_s).
            let x = |tau: f64| -> Vec3 {
                let t = ts + tau;
                let (c_ib, _, _) = m.attitude(t);
                let rs = m.displacement(ts, t) + c_ib * ch.lever - lever_i0;
                let ra = atom_displacement(gravity, &u0, &u1, tau);
                ch.c_sb * (c_ib.transpose() * (ra - rs))
            };
            out.push(ch.k.dot(&(x(2.0 * t_sep) - 2.0 * x(t_sep))));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cai::closed_form::phase_constant;
    use crate::cai::predictor::{predict, Imu, Interpolation, OmegaDot, PredictorConfig};
    use crate::math::dcm_from_euler;

    const K: f64 = 1.610576e7;

    fn channels(lever: Vec3, c_sb: Mat3) -> Vec<Channel> {
        // Cyclic geometry (docs/departures.md#ensemble-geometry): k along e_j, v0 = ±2.8 m/s along e_{j+1}.
        let mut out = Vec::new();
        for j in 0..3 {
            for s in [1.0, -1.0] {
                out.push(Channel { k: Vec3::ith(j, K), lever, c_sb, v0: Vec3::ith((j + 1) % 3, 2.8 * s) });
            }
        }
        out
    }

    fn cfg(t_sep: f64, omega_dot: OmegaDot, interpolation: Interpolation) -> PredictorConfig {
        PredictorConfig { t_sep, substeps: 1, gradient: None, bias_a: Vec3::zeros(), bias_g: Vec3::zeros(), omega_dot, interpolation }
    }

    /// Body with 0.05 rad/s yaw, roll/pitch wobble, forward motion and vibration.
    fn motion() -> SineMotion {
        let sig = |poly: [f64; 3], sines: Vec<(f64, f64, f64)>| Signal { poly, sines };
        SineMotion {
            position: [
                sig([0.0, 1.0, 0.1], vec![(2e-5, 9.7, 0.3)]),
                sig([0.0, 0.2, 0.0], vec![(1e-5, 4.3, 1.0)]),
                sig([0.0, 0.0, 0.0], vec![(1.5e-5, 6.1, -0.4)]),
            ],
            euler: [
                sig([0.01, 0.0, 0.0], vec![(2e-3, 1.3, 0.0)]),
                sig([-0.02, 0.0, 0.0], vec![(1e-3, 2.1, 0.5)]),
                sig([0.3, 0.05, 0.0], vec![(5e-4, 3.7, 0.2)]),
            ],
        }
    }

    fn max_error(rate: f64, interp: Interpolation) -> f64 {
        let m = motion();
        let t: Vec<f64> = (0..=(1.0 * rate) as usize).map(|i| i as f64 / rate).collect();
        let grav = Gravity { g0: Vec3::new(0.0, 0.0, 9.81), gradient: None, t_ref: 0.0 };
        let (f, w, wd) = imu_from_motion(&m, &t, &grav).unwrap();
        let chs = channels(Vec3::new(0.3, -0.1, 0.2), dcm_from_euler(0.01, -0.02, 0.03));
        let shots: Vec<f64> = (0..8).map(|i| 0.1 + 0.1 * i as f64 + 0.0003).collect();
        let p = predict(Imu { t: &t, f: &f, w: &w }, &shots, &chs, &cfg(0.025, OmegaDot::Given(wd), interp)).unwrap();
        let o = oracle_phase(&m, &shots, 0.025, &chs, &grav).unwrap();
        p.iter().zip(&o).map(|(a, b)| (a[0] - b).abs()).fold(0.0, f64::max)
    }

    /// Acceptance: 0.05 rad/s rotation, 0.3 m lever arm, vibration, T = 25 ms, 1 kHz,
    /// shots not aligned with the samples: |predictor − oracle| < 1e-3 rad.
    #[test]
    fn predictor_matches_oracle() {
        let e_cubic = max_error(1000.0, Interpolation::Cubic);
        assert!(e_cubic < 1e-3, "cubic, 1 kHz: {e_cubic}");
        let e_lin = max_error(1000.0, Interpolation::Linear);
        let e_lin4 = max_error(4000.0, Interpolation::Linear);
        // Linear interpolation error ∝ h².
        assert!(e_lin4 < e_lin / 10.0, "linear: {e_lin} (1 kHz) vs {e_lin4} (4 kHz)");
    }

    /// Constant specific force and rate: predictor = closed form (E10) within 1e-9 rad.
    #[test]
    fn constant_inputs_match_closed_form() {
        let f0 = Vec3::new(0.3, -0.2, -9.81);
        let w0 = Vec3::new(0.05, -0.03, 0.2);
        let t: Vec<f64> = (0..=200).map(|i| i as f64 * 1e-3).collect();
        let f = vec![f0; t.len()];
        let w = vec![w0; t.len()];
        let chs = channels(Vec3::zeros(), Mat3::identity());
        let p = predict(Imu { t: &t, f: &f, w: &w }, &[0.0104, 0.0705], &chs, &cfg(0.025, OmegaDot::Pwl, Interpolation::Linear)).unwrap();
        for (i, ch) in chs.iter().cycle().take(p.len()).enumerate() {
            let want = phase_constant(&ch.k, &w0, &f0, &ch.v0, 0.025);
            assert!((p[i][0] - want).abs() < 1e-9, "row {i}: {} vs {want}", p[i][0]);
            let sum: f64 = p[i][1..].iter().sum();
            assert!((sum - p[i][0]).abs() < 1e-9 * want.abs().max(1.0));
        }
    }

    /// Euler-angle rates: Ċ_ib = C_ib [ω_b×], and ω̇_b by central differences.
    #[test]
    fn sine_motion_rates() {
        let m = motion();
        let (t, h) = (0.37, 1e-5);
        let (c, w, wd) = m.attitude(t);
        let (cp, wp, _) = m.attitude(t + h);
        let (cm, wm, _) = m.attitude(t - h);
        let cdot = (cp - cm) / (2.0 * h);
        assert!((cdot - c * crate::math::skew(&w)).abs().max() < 1e-9);
        assert!(((wp - wm) / (2.0 * h) - wd).norm() < 1e-8);
    }
}
