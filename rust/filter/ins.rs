//! 15-state INS error model (spec gnss-ins-tight §2.9 Eq. 28, free vertical channel) in the
//! project conventions: δr = NED position error (m), δv (m/s), ψ with
//! Ĉ_b^n = (I − [ψ×])C_b^n, δb = b̂ − b for both biases (estimate − true), so the bias
//! columns are F_vba = −Ĉ_b^n and F_ψbg = +Ĉ_b^n (spec cai-ekf E31; the GNSS spec carries
//! the uncompensated sensor bias, hence its opposite signs).

use super::layout::Layout;
use crate::earth::Ellipsoid;
use crate::error::{invalid, Result};
use crate::math::{dcm_from_quat, skew, Mat3, Vec3};
use crate::strapdown::NavState;
use nalgebra::DMatrix;

/// A bias process per axis (spec gnss-ins-tight Eq. 28 "F_bb"; atom-strapdown E23).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BiasModel {
    /// ḃ = 0.
    RandomConstant,
    /// ḃ = w, E[w²] = psd (units²/s).
    RandomWalk { psd: f64 },
    /// ḃ = −b/τ + w, steady-state σ: PSD 2σ²/τ.
    GaussMarkov { tau: f64, sigma: f64 },
}

impl BiasModel {
    /// Parse ("random_constant" | "random_walk" | "gauss_markov", p1, p2): random walk takes
    /// its PSD as p1; Gauss–Markov τ (s) as p1 and σ as p2.
    pub fn from_parts(field: &str, kind: &str, p1: f64, p2: f64) -> Result<Self> {
        let pos = |name: &str, x: f64| {
            if x.is_finite() && x >= 0.0 {
                Ok(x)
            } else {
                Err(invalid(field, format!("{name} must be finite and >= 0, got {x}")))
            }
        };
        match kind {
            "random_constant" => Ok(Self::RandomConstant),
            "random_walk" => Ok(Self::RandomWalk { psd: pos("psd", p1)? }),
            "gauss_markov" => {
                crate::error::check_positive(&format!("{field} tau"), p1)?;
                Ok(Self::GaussMarkov { tau: p1, sigma: pos("sigma", p2)? })
            }
            _ => Err(invalid(field, format!("unknown bias model {kind:?} (random_constant, random_walk, gauss_markov)"))),
        }
    }

    /// (F diagonal entry, white-noise PSD) per axis.
    pub fn dynamics(&self) -> (f64, f64) {
        match *self {
            Self::RandomConstant => (0.0, 0.0),
            Self::RandomWalk { psd } => (0.0, psd),
            Self::GaussMarkov { tau, sigma } => (-1.0 / tau, 2.0 * sigma * sigma / tau),
        }
    }
}

/// Noise of the 15-state model: white accelerometer/gyro noise PSD (VRW² in (m/s²)²/Hz,
/// ARW² in rad²/s) and the two bias processes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InsNoise {
    pub accel_psd: f64,
    pub gyro_psd: f64,
    pub accel_bias: BiasModel,
    pub gyro_bias: BiasModel,
}

fn put(f: &mut DMatrix<f64>, r: usize, c: usize, m: &Mat3) {
    f.view_mut((r, c), (3, 3)).copy_from(m);
}

/// Continuous F and Q_c = G Q Gᵀ of the INS blocks of `layout` (which must contain
/// position, velocity, attitude; accel_bias and gyro_bias when present are coupled;
/// other blocks get zero rows) at the navigation solution `nav` with compensated
/// specific force `f_b` (m/s², body) — spec gnss-ins-tight Eq. 28.
pub fn error_dynamics(layout: &Layout, ell: &Ellipsoid, nav: &NavState, f_b: &Vec3, noise: &InsNoise) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let (ir, iv, ip) = (layout.range("position")?.start, layout.range("velocity")?.start, layout.range("attitude")?.start);
    let n = layout.size();
    let mut f = DMatrix::<f64>::zeros(n, n);
    let mut qc = DMatrix::<f64>::zeros(n, n);
    let (lat, h) = (nav.lla.x, nav.lla.z);
    let loc = ell.local(lat, h);
    let (rm, rp, s, c) = (loc.rm, loc.rp, loc.sin, loc.cos);
    let t = s / c;
    let om = ell.omega;
    let v = nav.vel;
    let cnb = dcm_from_quat(&nav.q_nb);
    let fn_ = cnb * f_b;
    let w_ie = loc.earth_rate();
    let w_en = loc.transport_rate(&v);
    let a_ie = Mat3::new(-om * s / rm, 0.0, 0.0, 0.0, 0.0, 0.0, -om * c / rm, 0.0, 0.0);
    let a_er = Mat3::new(0.0, 0.0, v.y / (rp * rp), 0.0, 0.0, -v.x / (rm * rm), -v.y / (rm * rp * c * c), 0.0, -v.y * t / (rp * rp));
    let a_ev = Mat3::new(0.0, 1.0 / rp, 0.0, -1.0 / rm, 0.0, 0.0, 0.0, -t / rp, 0.0);
    let f_rr = Mat3::new(-v.z / rm, 0.0, v.x / rm, v.y * t / rp, -(v.x * t + v.z) / rp, v.y / rp, 0.0, 0.0, 0.0);
    // Gravity gradient from this Earth model: δγ = γ_φ δr_N/R_M − γ_h δr_D (the spec's
    // 2γ/R₀ approximates −γ_h; the central difference is exact for the quadratic in h).
    let g_h = (ell.gravity(lat, h + 1.0) - ell.gravity(lat, h - 1.0)) / 2.0;
    let mut f_vr = skew(&v) * (2.0 * a_ie + a_er);
    f_vr[(2, 0)] += ell.gravity_dlat(lat, h) / rm;
    f_vr[(2, 2)] -= g_h;
    let f_vv = -skew(&(2.0 * w_ie + w_en)) + skew(&v) * a_ev;
    put(&mut f, ir, ir, &f_rr);
    put(&mut f, ir, iv, &Mat3::identity());
    put(&mut f, iv, ir, &f_vr);
    put(&mut f, iv, iv, &f_vv);
    put(&mut f, iv, ip, &skew(&fn_));
    put(&mut f, ip, ir, &(a_ie + a_er));
    put(&mut f, ip, iv, &a_ev);
    put(&mut f, ip, ip, &(-skew(&(w_ie + w_en))));
    // White sensor noise: Ĉ q I Ĉᵀ = q I.
    put(&mut qc, iv, iv, &(Mat3::identity() * noise.accel_psd));
    put(&mut qc, ip, ip, &(Mat3::identity() * noise.gyro_psd));
    for (name, row, sign, model) in [("accel_bias", iv, -1.0, noise.accel_bias), ("gyro_bias", ip, 1.0, noise.gyro_bias)] {
        if let Some(b) = layout.get(name) {
            put(&mut f, row, b.start, &(cnb * sign));
            let (fb, q) = model.dynamics();
            put(&mut f, b.start, b.start, &(Mat3::identity() * fb));
            put(&mut qc, b.start, b.start, &(Mat3::identity() * q));
        }
    }
    Ok((f, qc))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::dcm_from_euler;
    use nalgebra::DVector;

    /// Continuous mechanization (spec gnss-ins-tight Eq. 26, free vertical) with the sensor
    /// bias errors: returns (llȧ, v̇, Ċ) for the state (lla, v, C) and sensed f, ω (body).
    fn rates(ell: &Ellipsoid, lla: &Vec3, v: &Vec3, c: &Mat3, f: &Vec3, w: &Vec3) -> (Vec3, Vec3, Mat3) {
        let loc = ell.local(lla.x, lla.z);
        let (w_ie, w_en) = (loc.earth_rate(), loc.transport_rate(v));
        let vdot = c * f - (2.0 * w_ie + w_en).cross(v) + Vec3::new(0.0, 0.0, ell.gravity(lla.x, lla.z));
        let cdot = c * skew(w) - skew(&(w_ie + w_en)) * c;
        (loc.lla_rate(v), vdot, cdot)
    }

    /// Relative mismatch per block (position, velocity, attitude) between F·δx, with F the
    /// Jacobian at the true state, and the derivative of the error between a perturbed and
    /// the true trajectory (both from the mechanization): central difference in time, and
    /// symmetric in the perturbation ((D(δx) − D(−δx))/2) so that second-order terms
    /// cancel and only the linearisation is tested.
    fn mismatch(dr: Vec3, dv: Vec3, psi: Vec3, dba: Vec3, dbg: Vec3) -> [f64; 3] {
        let ell = Ellipsoid::by_name("WGS84").unwrap();
        let layout = Layout::ins15();
        let lla = Vec3::new(0.9, 0.3, 300.0);
        let v = Vec3::new(60.0, -25.0, 1.5);
        let c = dcm_from_euler(0.1, -0.05, 2.0);
        let (f_b, w_b) = (Vec3::new(0.8, -0.3, -9.7), Vec3::new(0.01, -0.02, 0.03));
        let loc = ell.local(lla.x, lla.z);
        let nav = NavState { t: 0.0, lla, vel: v, q_nb: crate::math::quat_from_dcm(&c) };
        let noise = InsNoise { accel_psd: 0.0, gyro_psd: 0.0, accel_bias: BiasModel::RandomConstant, gyro_bias: BiasModel::RandomConstant };
        let (f, _) = error_dynamics(&layout, &ell, &nav, &f_b, &noise).unwrap();
        let x = DVector::from_iterator(15, dr.iter().chain(dv.iter()).chain(psi.iter()).chain(dba.iter()).chain(dbg.iter()).copied());
        let fx = &f * &x;
        // Time derivative of the error for perturbation sign s (central difference in time).
        let deriv = |s: f64| -> DVector<f64> {
            let lla_e = lla + Vec3::new(s * dr.x / loc.rm, s * dr.y / (loc.rp * loc.cos), -s * dr.z);
            let c_e = (Mat3::identity() - skew(&(s * psi))) * c;
            // δb = b̂ − b: the estimate's compensated sensor outputs differ by −δb.
            let (f_e, w_e, v_e) = (f_b - s * dba, w_b - s * dbg, v + s * dv);
            let err = |eps: f64| -> DVector<f64> {
                let (a, b, cc) = rates(&ell, &lla, &v, &c, &f_b, &w_b);
                let (ae, be, ce) = rates(&ell, &lla_e, &v_e, &c_e, &f_e, &w_e);
                let (l1, v1, c1) = (lla + a * eps, v + b * eps, c + cc * eps);
                let (l2, v2, c2) = (lla_e + ae * eps, v_e + be * eps, c_e + ce * eps);
                let lc = ell.local(l1.x, l1.z);
                let r = Vec3::new((l2.x - l1.x) * lc.rm, (l2.y - l1.y) * lc.rp * lc.cos, -(l2.z - l1.z));
                // I − [ψ×] = Ĉ Cᵀ: ψ = vee of the skew part of C Ĉᵀ.
                let m = c1 * c2.transpose();
                let p = Vec3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)]) * 0.5;
                DVector::from_iterator(9, r.iter().chain((v2 - v1).iter()).chain(p.iter()).copied())
            };
            let eps = 1e-2;
            (err(eps) - err(-eps)) / (2.0 * eps)
        };
        let d = (deriv(1.0) - deriv(-1.0)) / 2.0;
        [0, 3, 6].map(|blk| (fx.rows(blk, 3) - d.rows(blk, 3)).norm() / d.rows(blk, 3).norm())
    }

    /// spec gnss-ins-tight §2.9 acceptance: δr = 5 m, δv = 0.05 m/s, ψ = 1e-4 rad, ≤ 1e-4.
    #[test]
    fn f_matches_central_differences_of_mechanization() {
        let z = Vec3::zeros();
        let rel = mismatch(Vec3::new(5.0, -5.0, 5.0), Vec3::new(0.05, 0.05, -0.05), Vec3::new(1e-4, -1e-4, 1e-4), z, z);
        assert!(rel.iter().all(|r| *r < 1e-4), "{rel:?}");
    }

    /// Bias columns alone (nav errors zero): F_vba = −Ĉ, F_ψbg = +Ĉ for δb = b̂ − b.
    #[test]
    fn f_bias_columns_match_central_differences() {
        let z = Vec3::zeros();
        let rel = mismatch(z, z, z, Vec3::new(1e-3, -2e-3, 1e-3), Vec3::new(1e-6, 2e-6, -1e-6));
        // position rows see no bias in one step (δṙ = δv = 0): only velocity and attitude.
        assert!(rel[1] < 1e-6 && rel[2] < 1e-6, "{rel:?}");
    }
}
