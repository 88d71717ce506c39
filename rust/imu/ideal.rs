//! Error-free IMU output of a motion model: specific force and angular rate in body
//! axes, including Earth rate, transport rate and gravity, as instantaneous rates or as
//! exact increments over each sample interval.
//!
//! f^n = v̇^n − g^n + (2ω_ie + ω_en) × v^n, f^b = C_bn f^n (the NED mechanization solved for f);
//! ω_ib^b = ω_nb^b + C_bn (ω_ie^n + ω_en^n).

use crate::earth::Ellipsoid;
use crate::math::Vec3;
use crate::trajectory::{Kinematics, Motion, TruthState};

/// Specific force (m/s²) and angular rate ω_ib^b (rad/s) at time t and position lla.
pub fn body_measurements(motion: &Motion, ell: &Ellipsoid, t: f64, lla: &Vec3) -> (Vec3, Vec3) {
    body_from_kinematics(ell, &motion.kinematics(t), lla)
}

/// Specific force (m/s²) and angular rate ω_ib^b (rad/s) of the kinematics `k` at position lla.
pub fn body_from_kinematics(ell: &Ellipsoid, k: &Kinematics, lla: &Vec3) -> (Vec3, Vec3) {
    let w_ie = ell.earth_rate_ned(lla.x);
    let w_en = ell.transport_rate_ned(lla.x, lla.z, &k.vel);
    let f_n = k.acc - ell.gravity_ned(lla.x, lla.z) + (2.0 * w_ie + w_en).cross(&k.vel);
    let c_bn = k.c_nb.transpose();
    (c_bn * f_n, k.w_nb_b + c_bn * (w_ie + w_en))
}

/// Rates at the truth samples: (specific force, angular rate, angular acceleration).
/// Angular acceleration ω̇_ib^b is a 4-point central difference (step 1e-4 s) of the exact
/// rate with the position frozen at the sample; the frozen position changes ω_ib by
/// < 1e-10 rad/s² for vehicle speeds.
pub fn ideal_rates(motion: &Motion, ell: &Ellipsoid, truth: &[TruthState]) -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec3>) {
    const H: f64 = 1e-4;
    let mut f = Vec::with_capacity(truth.len());
    let mut w = Vec::with_capacity(truth.len());
    let mut wd = Vec::with_capacity(truth.len());
    for s in truth {
        let (fb, wb) = body_measurements(motion, ell, s.t, &s.lla);
        let rate = |dt: f64| body_measurements(motion, ell, s.t + dt, &s.lla).1;
        let d = (8.0 * (rate(H) - rate(-H)) - (rate(2.0 * H) - rate(-2.0 * H))) / (12.0 * H);
        f.push(fb);
        w.push(wb);
        wd.push(d);
    }
    (f, w, wd)
}

/// 5-point Gauss–Legendre nodes and weights on [0, 1].
const GL_NODES: [f64; 5] = [
    0.5 - 0.5 * 0.906_179_845_938_664,
    0.5 - 0.5 * 0.538_469_310_105_683_1,
    0.5,
    0.5 + 0.5 * 0.538_469_310_105_683_1,
    0.5 + 0.5 * 0.906_179_845_938_664,
];
const GL_WEIGHTS: [f64; 5] = [
    0.5 * 0.236_926_885_056_189_1,
    0.5 * 0.478_628_670_499_366_5,
    0.5 * 0.568_888_888_888_888_9,
    0.5 * 0.478_628_670_499_366_5,
    0.5 * 0.236_926_885_056_189_1,
];

/// Exact increments (Δv = ∫f^b dt in m/s, Δθ = ∫ω_ib^b dt in rad) over each interval
/// (t_{k−1}, t_k] of consecutive truth samples: N − 1 rows. Each interval is cut into
/// pieces of at most 0.01 s (one piece for a motion at rest, whose integrand is
/// constant), each integrated by 5-point Gauss–Legendre (exact for polynomials of
/// degree 9). Position enters only through gravity and the Earth and
/// transport rates, so at the nodes it is interpolated linearly between the samples
/// (≤ 1e-6 m for vehicle motion, i.e. < 1e-11 m/s² of gravity).
pub fn ideal_increments(motion: &Motion, ell: &Ellipsoid, truth: &[TruthState]) -> (Vec<Vec3>, Vec<Vec3>) {
    let max_piece = if motion.is_at_rest() { f64::INFINITY } else { 0.01 };
    let mut dv = Vec::with_capacity(truth.len().saturating_sub(1));
    let mut dth = Vec::with_capacity(truth.len().saturating_sub(1));
    for pair in truth.windows(2) {
        let [a, b] = pair else { continue };
        let span = b.t - a.t;
        let pieces = (span / max_piece).ceil().max(1.0) as usize;
        let h = span / pieces as f64;
        let (mut sv, mut sth) = (Vec3::zeros(), Vec3::zeros());
        for p in 0..pieces {
            let t0 = a.t + p as f64 * h;
            for (x, wgt) in GL_NODES.iter().zip(GL_WEIGHTS) {
                let t = t0 + x * h;
                let lla = a.lla + (b.lla - a.lla) * ((t - a.t) / span);
                let (f, w) = body_measurements(motion, ell, t, &lla);
                sv += wgt * h * f;
                sth += wgt * h * w;
            }
        }
        dv.push(sv);
        dth.push(sth);
    }
    (dv, dth)
}
