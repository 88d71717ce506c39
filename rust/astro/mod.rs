//! Astro-inertial calibration of the star-camera (virtual camera VF) to IMU (MF) mount from
//! attitude increments (Vasilyuk et al. 2024).
//!
//! Internally everything is in the paper's conventions: ENU navigation frame,
//! right-forward-up body axes, right-multiplicative body-frame small errors
//! S = S̆ (I + [θ×]). `S_X2^X1` maps X1 coordinates into X2. Conversion to the project's
//! NED/FRD frames happens in `scenario.rs` (the only place that touches `trajectory`).

pub mod calibration;
pub mod increments;
pub mod scenario;
pub mod stars;

use crate::math::{half_open, Mat3, Vec3};

/// vee(M) = ½(M32 − M23, M13 − M31, M21 − M12).
pub fn vee(m: &Mat3) -> Vec3 {
    0.5 * Vec3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
}

/// The paper's Euler matrix C(ψ, ϑ, γ) = R_ψ(ψ) R_ϑ(ϑ) R_γ(γ) with R_ψ = R_z(−ψ),
/// R_ϑ = R_x(ϑ), R_γ = R_y(γ).
pub fn euler_dcm(b: &Vec3) -> Mat3 {
    let (sp, cp) = b.x.sin_cos();
    let (st, ct) = b.y.sin_cos();
    let (sg, cg) = b.z.sin_cos();
    let rpsi = Mat3::new(cp, sp, 0.0, -sp, cp, 0.0, 0.0, 0.0, 1.0);
    let rth = Mat3::new(1.0, 0.0, 0.0, 0.0, ct, -st, 0.0, st, ct);
    let rg = Mat3::new(cg, 0.0, sg, 0.0, 1.0, 0.0, -sg, 0.0, cg);
    rpsi * rth * rg
}

/// Canonical angles of C: ϑ = asin(C32) ∈ [−π/2, π/2], ψ = atan2(C12, C22) and
/// γ = atan2(−C31, C33), both in (−π, π]. Singular at |ϑ| = 90°.
pub fn euler_from_dcm(c: &Mat3) -> Vec3 {
    let th = c[(2, 1)].clamp(-1.0, 1.0).asin();
    let psi = half_open(c[(0, 1)].atan2(c[(1, 1)]));
    let g = half_open((-c[(2, 0)]).atan2(c[(2, 2)]));
    Vec3::new(psi, th, g)
}

/// D1(β): θ^clb = D1 δβ with C(β + δβ) ≈ C(β)(I + [θ^clb×]) (Vasilyuk et al. 2024, Eq. 8).
pub fn d1(b: &Vec3) -> Mat3 {
    let (st, ct) = b.y.sin_cos();
    let (sg, cg) = b.z.sin_cos();
    Mat3::new(sg * ct, cg, 0.0, -st, 0.0, 1.0, -cg * ct, sg, 0.0)
}

/// D2(β) = C(β) D1(β).
pub fn d2(b: &Vec3) -> Mat3 {
    let (sp, cp) = b.x.sin_cos();
    let (st, ct) = b.y.sin_cos();
    Mat3::new(0.0, cp, ct * sp, 0.0, -sp, ct * cp, -1.0, 0.0, st)
}

/// Rotation angle of a rotation matrix by atan2: accurate for small angles.
pub fn rotation_angle(s: &Mat3) -> f64 {
    (2.0 * vee(s).norm()).atan2(s.trace() - 1.0)
}

/// Nearest rotation matrix U diag(1, 1, det U det V) Vᵀ of B = U Σ Vᵀ (the solution of Wahba's problem).
// invariant: svd(true, true) always computes u and v_t.
#[allow(clippy::expect_used)]
pub fn nearest_rotation(b: &Mat3) -> Mat3 {
    let svd = b.svd(true, true);
    let (u, vt) = (svd.u.expect("u requested"), svd.v_t.expect("v_t requested"));
    let d = (u.determinant() * vt.determinant()).signum();
    u * Mat3::from_diagonal(&Vec3::new(1.0, 1.0, d)) * vt
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::dcm_from_rotvec;

    #[test]
    fn d1_matches_finite_differences_and_d2_is_c_d1() {
        // Cᵀ ∂C/∂β_i = [d_i×]; central differences h = 1e-6.
        let h = 1e-6;
        for k in 0..200 {
            let x = k as f64;
            let b = Vec3::new((x * 0.731).sin() * 3.0, (x * 0.377).cos() * 1.4, (x * 1.13).sin() * 3.0);
            let c = euler_dcm(&b);
            for i in 0..3 {
                let mut e = Vec3::zeros();
                e[i] = h;
                let dc = (euler_dcm(&(b + e)) - euler_dcm(&(b - e))) / (2.0 * h);
                let fd = vee(&(c.transpose() * dc));
                assert!((fd - d1(&b).column(i)).norm() < 1e-9, "D1 column {i} at {b:?}");
            }
            assert!((c * d1(&b) - d2(&b)).abs().max() < 1e-15);
            // D2: C(β + δβ) ≈ (I + [D2 δβ×]) C(β), by central differences
            for i in 0..3 {
                let mut e = Vec3::zeros();
                e[i] = h;
                let dc = (euler_dcm(&(b + e)) - euler_dcm(&(b - e))) / (2.0 * h);
                assert!((vee(&(dc * c.transpose())) - d2(&b).column(i)).norm() < 1e-9, "D2 column {i}");
            }
        }
    }

    #[test]
    fn euler_round_trip_and_geometry() {
        let b = Vec3::new(0.3, 0.2, -0.7);
        let c = euler_dcm(&b);
        assert!((euler_from_dcm(&c) - b).norm() < 1e-14);
        // C ŷ = (sψ cϑ, cψ cϑ, sϑ): heading clockwise from North, pitch nose-up.
        let y = c * Vec3::y();
        assert!((y - Vec3::new(b.x.sin() * b.y.cos(), b.x.cos() * b.y.cos(), b.y.sin())).norm() < 1e-15);
        // every angle in (−π, π]: a small negative heading stays negative, −π (a signed zero) is π
        let small = Vec3::new(-0.1f64.to_radians(), 0.2, -0.3);
        assert!((euler_from_dcm(&euler_dcm(&small)) - small).norm() < 1e-14);
        let flip = Mat3::new(-1.0, -0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
        assert_eq!(euler_from_dcm(&flip).x, std::f64::consts::PI);
        let roll = Mat3::new(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0);
        assert_eq!(euler_from_dcm(&roll).z, std::f64::consts::PI);
        let phi = Vec3::new(0.01, -0.02, 0.005);
        assert!((rotation_angle(&dcm_from_rotvec(&phi)) - phi.norm()).abs() < 1e-17);
    }
}
