//! A continuous-time motion model and its sampled truth.
//!
//! Horizontal motion is `speed(t)` along `course(t)` plus an NED displacement (for
//! sinusoidal motion and vibration); attitude is a product of elementary rotations
//! C_nb = Π exp(θᵢ(t)[aᵢ×]) (z-y-x Euler angles are three of them). Every profile has
//! exact derivatives, so velocity, acceleration and body rate are exact; position is
//! the RK4 integral of the velocity in (lat, lon, h).

use super::profile::{Eval, Profile};
use crate::earth::Ellipsoid;
use crate::error::{check_increasing, invalid, Result};
use crate::math::{dcm_from_quat, quat_from_axis_angle, quat_from_dcm, Mat3, Quat, Vec3};

/// One elementary rotation of the attitude chain: angle θ(t) about a fixed unit axis.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AxisRotation {
    pub axis: Vec3,
    pub angle: Profile,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Motion {
    pub name: String,
    /// Geodetic start position (lat rad, lon rad, h m).
    pub origin: Vec3,
    /// Length of the motion (s); samples beyond it are rejected.
    pub duration: f64,
    /// Ground speed along the course (m/s).
    pub speed: Profile,
    /// Course angle from north (rad).
    pub course: Profile,
    /// Additional NED displacement (m): sinusoidal motion, vibration.
    pub displacement: [Profile; 3],
    /// C_nb = R(a₁,θ₁) R(a₂,θ₂) … (left to right).
    pub attitude: Vec<AxisRotation>,
}

/// Exact kinematics at one instant (position excluded: it is integrated).
#[derive(Debug, Clone, Copy)]
pub struct Kinematics {
    /// NED velocity (m/s).
    pub vel: Vec3,
    /// Time derivative of the NED velocity components (m/s²).
    pub acc: Vec3,
    pub c_nb: Mat3,
    /// Body rate relative to the navigation frame, in body axes (rad/s).
    pub w_nb_b: Vec3,
}

impl Motion {
    /// Stationary motion at `origin` with constant (roll, pitch, yaw).
    pub fn stationary(name: &str, origin: Vec3, duration: f64, euler: Vec3) -> Motion {
        Motion {
            name: name.to_string(),
            origin,
            duration,
            speed: Profile::zero(),
            course: Profile::zero(),
            displacement: [Profile::zero(), Profile::zero(), Profile::zero()],
            attitude: euler_chain(Profile::constant(euler.x), Profile::constant(euler.y), Profile::constant(euler.z)),
        }
    }

    pub fn kinematics(&self, t: f64) -> Kinematics {
        let (s, c) = (self.speed.eval(t), self.course.eval(t));
        let (sc, cc) = c.v.sin_cos();
        let d: [Eval; 3] = self.displacement.each_ref().map(|p| p.eval(t));
        let vel = Vec3::new(s.v * cc + d[0].d1, s.v * sc + d[1].d1, d[2].d1);
        let acc = Vec3::new(
            s.d1 * cc - s.v * c.d1 * sc + d[0].d2,
            s.d1 * sc + s.v * c.d1 * cc + d[1].d2,
            d[2].d2,
        );
        // C = R₁…R_n; ω_nb^b = Σ θ̇ᵢ (R_{i+1}…R_n)ᵀ aᵢ, accumulated from the right.
        let mut c_nb = Mat3::identity();
        let mut w = Vec3::zeros();
        for rot in self.attitude.iter().rev() {
            let e = rot.angle.eval(t);
            w += e.d1 * (c_nb.transpose() * rot.axis);
            c_nb = dcm_from_quat(&quat_from_axis_angle(&rot.axis, e.v)) * c_nb;
        }
        Kinematics { vel, acc, c_nb, w_nb_b: w }
    }

    /// True when the vehicle neither moves nor turns relative to the Earth: zero speed,
    /// constant displacement and constant attitude. Its position, specific force and body
    /// rate are then constant, so integrals over time need no subdivision.
    pub fn is_at_rest(&self) -> bool {
        self.speed.constant_value() == Some(0.0)
            && self.displacement.iter().all(|d| d.constant_value().is_some())
            && self.attitude.iter().all(|r| r.angle.constant_value().is_some())
    }

    /// (lat, lon, h) at `t1` from (lat, lon, h) at `t0` by RK4 on
    /// φ̇ = v_N/R_M, λ̇ = v_E/(R_P cos φ), ḣ = −v_D, with steps of at most `max_step`
    /// (exactly `lla` for a motion at rest).
    pub fn propagate_lla(&self, ell: &Ellipsoid, lla: Vec3, t0: f64, t1: f64, max_step: f64) -> Vec3 {
        if self.is_at_rest() {
            return lla;
        }
        let n = ((t1 - t0).abs() / max_step).ceil().max(1.0) as usize;
        let h = (t1 - t0) / n as f64;
        let rate = |p: &Vec3, t: f64| ell.lla_rate(p.x, p.z, &self.kinematics(t).vel);
        let mut p = lla;
        for i in 0..n {
            let t = t0 + i as f64 * h;
            let k1 = rate(&p, t);
            let k2 = rate(&(p + 0.5 * h * k1), t + 0.5 * h);
            let k3 = rate(&(p + 0.5 * h * k2), t + 0.5 * h);
            let k4 = rate(&(p + h * k3), t + h);
            p += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        p
    }

    /// Check that `times` are increasing and inside [0, duration].
    pub fn check_times(&self, times: &[f64]) -> Result<()> {
        check_increasing("times", times)?;
        if let Some((i, t)) = times.iter().enumerate().find(|(_, &t)| t < 0.0 || t > self.duration + 1e-9) {
            return Err(invalid("times", format!("time {t} at index {i} is outside the motion '{}' span [0, {}] s", self.name, self.duration)));
        }
        Ok(())
    }

    /// Truth at the given times (increasing, within [0, duration]).
    pub fn truth(&self, ell: &Ellipsoid, times: &[f64]) -> Result<Vec<TruthState>> {
        self.check_times(times)?;
        let mut out = Vec::with_capacity(times.len());
        let (mut lla, mut t_prev) = (self.origin, 0.0);
        for &t in times {
            lla = self.propagate_lla(ell, lla, t_prev, t, MAX_RK4_STEP);
            t_prev = t;
            let k = self.kinematics(t);
            out.push(TruthState { t, lla, vel: k.vel, acc: k.acc, q_nb: quat_from_dcm(&k.c_nb), w_nb_b: k.w_nb_b });
        }
        Ok(out)
    }
}

/// RK4 step bound for the position integral (s): its error is far below 1e-9 m per hour
/// for the generators' motions.
pub const MAX_RK4_STEP: f64 = 0.01;

/// C_nb = Rz(yaw) Ry(pitch) Rx(roll) as an attitude chain.
pub fn euler_chain(roll: Profile, pitch: Profile, yaw: Profile) -> Vec<AxisRotation> {
    vec![
        AxisRotation { axis: Vec3::z(), angle: yaw },
        AxisRotation { axis: Vec3::y(), angle: pitch },
        AxisRotation { axis: Vec3::x(), angle: roll },
    ]
}

#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct TruthState {
    pub t: f64,
    pub lla: Vec3,
    pub vel: Vec3,
    pub acc: Vec3,
    pub q_nb: Quat,
    pub w_nb_b: Vec3,
}
