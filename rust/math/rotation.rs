//! Rotations: quaternion ↔ DCM ↔ Euler (roll, pitch, heading) ↔ rotation vector.
//!
//! Conventions (README "Conventions"): Hamilton quaternions, scalar first, unit norm.
//! `q_nb` rotates body-frame vectors into the navigation frame: v_n = C(q_nb) v_b.
//! Euler angles are the aerospace z-y-x sequence: C_nb = Rz(yaw) Ry(pitch) Rx(roll).
//! Composition: C(q_a ⊗ q_b) = C(q_a) C(q_b).

use crate::error::{invalid_at, Result};
use nalgebra::{Matrix3, Quaternion, Vector3};

pub type Vec3 = Vector3<f64>;
pub type Mat3 = Matrix3<f64>;
/// Unit quaternion, Hamilton, stored by nalgebra as (w; i, j, k).
pub type Quat = Quaternion<f64>;

/// Skew-symmetric matrix [v×] with [v×] u = v × u.
pub fn skew(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Quaternion from scalar-first components [w, x, y, z].
pub fn quat(w: f64, x: f64, y: f64, z: f64) -> Quat {
    Quaternion::new(w, x, y, z)
}

/// Scalar-first array of a quaternion.
pub fn quat_to_array(q: &Quat) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

pub fn quat_normalize(q: &Quat) -> Quat {
    let n = q.norm();
    q / n
}

/// Rows `q` that stand for rotations, scaled to unit norm. A row whose norm is zero or not
/// finite names no rotation: `InvalidInput` naming `field` and that row (never a NaN row).
pub fn unit_quats(field: &str, q: &[Quat]) -> Result<Vec<Quat>> {
    q.iter()
        .enumerate()
        .map(|(i, q)| {
            let n = q.norm();
            let u = q / n;
            match n.is_finite() && n > 0.0 && u.coords.iter().all(|x| x.is_finite()) {
                true => Ok(u),
                false => Err(invalid_at(field, i, format!("quaternion {:?} at index {i} has norm {}, not a rotation", quat_to_array(q), q.norm()))),
            }
        })
        .collect()
}

/// How far a rotation given by the user may be from an exact one: |‖q‖ − 1| for a
/// quaternion, max |RᵀR − I| for a matrix. A quaternion or matrix stored in single
/// precision or printed with seven significant digits is within it; one typed by hand
/// with a wrong sign or a swapped element is not.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// Quaternion rows `q` given as rotations: each must have unit norm within
/// [`ROTATION_TOLERANCE`] (`[1, .1, .1, .1]`, norm 1.015, is no rotation, not one to be
/// silently rescaled); returned scaled to exactly unit norm. `InvalidInput` naming `field`
/// and the first row that is not.
pub fn rotation_quats(field: &str, q: &[Quat]) -> Result<Vec<Quat>> {
    q.iter().enumerate().map(|(i, q)| rotation_quat(field, i, q)).collect()
}

/// [`rotation_quats`] of one quaternion, row `index` of `field`.
pub fn rotation_quat(field: &str, index: usize, q: &Quat) -> Result<Quat> {
    let n = q.norm();
    match (n - 1.0).abs() <= ROTATION_TOLERANCE {
        true => Ok(q / n),
        false => Err(invalid_at(
            field,
            index,
            format!("quaternion {:?} at index {index} has norm {n}, not a rotation (unit norm within {ROTATION_TOLERANCE})", quat_to_array(q)),
        )),
    }
}

/// Matrix `r`, row `index` of `field`, given as a rotation: orthonormal (max |RᵀR − I| ≤
/// [`ROTATION_TOLERANCE`]) with det R = +1 (a reflection such as diag(1, 1, −1) is not a
/// rotation). `InvalidInput` naming `field` and `index` otherwise.
pub fn check_rotation(field: &str, index: usize, r: &Mat3) -> Result<()> {
    let orth = (r.transpose() * r - Mat3::identity()).abs().max();
    let det = r.determinant();
    if !orth.is_finite() || orth > ROTATION_TOLERANCE || det <= 0.0 {
        return Err(invalid_at(
            field,
            index,
            format!("not a rotation matrix at index {index} (max |RᵀR − I| = {orth:.3e}, tolerance {ROTATION_TOLERANCE}; det = {det:.6})"),
        ));
    }
    Ok(())
}

/// [`check_rotation`] of every matrix of a series (names the first that is not a rotation).
pub fn check_rotations(field: &str, r: &[Mat3]) -> Result<()> {
    r.iter().enumerate().try_for_each(|(i, m)| check_rotation(field, i, m))
}

/// Quaternions of rotation vectors `phi` (rows named `field`). A row whose angle |φ|² is
/// not a finite float (|φ| above about 1.3e154 rad) has no defined rotation: `InvalidInput`
/// naming `field` and that row (never a NaN row).
pub fn quats_from_rotvecs(field: &str, phi: &[Vec3]) -> Result<Vec<Quat>> {
    phi.iter()
        .enumerate()
        .map(|(i, p)| match p.norm_squared().is_finite() {
            true => Ok(quat_from_rotvec(p)),
            false => Err(invalid_at(field, i, format!("rotation vector {:?} at index {i} has an angle beyond the range of floats", [p.x, p.y, p.z]))),
        })
        .collect()
}

/// Hamilton product a ⊗ b.
pub fn quat_mul(a: &Quat, b: &Quat) -> Quat {
    a * b
}

/// Quaternion of the rotation vector φ (exponential map): [cos(|φ|/2), sin(|φ|/2) φ/|φ|].
/// Below |φ| = 1e-2 (every strapdown step) the Taylor series through θ⁶ replaces sin/cos:
/// the first omitted terms, θ⁸/10321920 and θ⁸/185794560, are < 1e-23 there, so the
/// series is exact to rounding and tiny rotations keep full relative accuracy.
#[inline]
pub fn quat_from_rotvec(phi: &Vec3) -> Quat {
    let th2 = phi.norm_squared();
    let (c, s_over_th) = if th2 < 1e-4 {
        // cos(θ/2) = 1 − θ²/8 + θ⁴/384 − θ⁶/46080; sin(θ/2)/θ = ½ − θ²/48 + θ⁴/3840 − θ⁶/645120
        // (the divisors as multipliers: this runs twice per strapdown step)
        let (c8, c48, c80, c120, c168) = (1.0 / 8.0, 1.0 / 48.0, 1.0 / 80.0, 1.0 / 120.0, 1.0 / 168.0);
        (1.0 - th2 * c8 * (1.0 - th2 * c48 * (1.0 - th2 * c120)), 0.5 - th2 * c48 * (1.0 - th2 * c80 * (1.0 - th2 * c168)))
    } else {
        let th = th2.sqrt();
        ((0.5 * th).cos(), (0.5 * th).sin() / th)
    };
    Quaternion::new(c, s_over_th * phi.x, s_over_th * phi.y, s_over_th * phi.z)
}

/// Quaternion of a rotation by `angle` (rad) about the unit vector `axis`. Unlike
/// [`quat_from_rotvec`] of `axis·angle`, whose θ² overflows beyond 1.3e154 rad, it holds
/// for every finite angle.
#[inline]
pub fn quat_from_axis_angle(axis: &Vec3, angle: f64) -> Quat {
    let (s, c) = (0.5 * angle).sin_cos();
    Quaternion::new(c, s * axis.x, s * axis.y, s * axis.z)
}

/// Rotation vector of a unit quaternion (logarithmic map), angle in [0, π].
pub fn rotvec_from_quat(q: &Quat) -> Vec3 {
    // q and −q are the same rotation: take the representative with w ≥ 0.
    let (w, v) = if q.w < 0.0 { (-q.w, -q.imag()) } else { (q.w, q.imag()) };
    let s = v.norm();
    if s < 1e-8 {
        // θ = 2 atan2(s, w); θ/s = 2/w (1 − s²/(3w²) + ...)
        v * (2.0 / w) * (1.0 - s * s / (3.0 * w * w))
    } else {
        v * (2.0 * s.atan2(w) / s)
    }
}

/// Direction cosine matrix C(q): v_n = C v_b for q = q_nb.
pub fn dcm_from_quat(q: &Quat) -> Mat3 {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    Mat3::new(
        w * w + x * x - y * y - z * z,
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        w * w - x * x + y * y - z * z,
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        w * w - x * x - y * y + z * z,
    )
}

/// Quaternion of a rotation matrix (Shepperd's method: largest diagonal pivot), w ≥ 0.
pub fn quat_from_dcm(c: &Mat3) -> Quat {
    let tr = c.trace();
    let diag = [c[(0, 0)], c[(1, 1)], c[(2, 2)]];
    let q = if tr >= diag[0] && tr >= diag[1] && tr >= diag[2] {
        let w = 0.5 * (1.0 + tr).sqrt();
        let f = 0.25 / w;
        quat(w, (c[(2, 1)] - c[(1, 2)]) * f, (c[(0, 2)] - c[(2, 0)]) * f, (c[(1, 0)] - c[(0, 1)]) * f)
    } else if diag[0] >= diag[1] && diag[0] >= diag[2] {
        let x = 0.5 * (1.0 + 2.0 * diag[0] - tr).sqrt();
        let f = 0.25 / x;
        quat((c[(2, 1)] - c[(1, 2)]) * f, x, (c[(0, 1)] + c[(1, 0)]) * f, (c[(0, 2)] + c[(2, 0)]) * f)
    } else if diag[1] >= diag[2] {
        let y = 0.5 * (1.0 + 2.0 * diag[1] - tr).sqrt();
        let f = 0.25 / y;
        quat((c[(0, 2)] - c[(2, 0)]) * f, (c[(0, 1)] + c[(1, 0)]) * f, y, (c[(1, 2)] + c[(2, 1)]) * f)
    } else {
        let z = 0.5 * (1.0 + 2.0 * diag[2] - tr).sqrt();
        let f = 0.25 / z;
        quat((c[(1, 0)] - c[(0, 1)]) * f, (c[(0, 2)] + c[(2, 0)]) * f, (c[(1, 2)] + c[(2, 1)]) * f, z)
    };
    if q.w < 0.0 { -q } else { q }
}

/// C_nb = Rz(yaw) Ry(pitch) Rx(roll), angles in rad.
pub fn dcm_from_euler(roll: f64, pitch: f64, yaw: f64) -> Mat3 {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    Mat3::new(
        cy * cp,
        cy * sp * sr - sy * cr,
        cy * sp * cr + sy * sr,
        sy * cp,
        sy * sp * sr + cy * cr,
        sy * sp * cr - cy * sr,
        -sp,
        cp * sr,
        cp * cr,
    )
}

/// An atan2 angle, in [−π, π], moved to (−π, π]: −π (from a negative or signed-zero
/// sine) becomes π; every other value is returned unchanged, bit for bit.
pub fn half_open(a: f64) -> f64 {
    if a <= -std::f64::consts::PI {
        std::f64::consts::PI
    } else {
        a
    }
}

/// Any angle wrapped to (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    half_open((a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI)
}

/// (roll, pitch, yaw) of C_nb; roll and yaw in (−π, π], pitch in [−π/2, π/2].
pub fn euler_from_dcm(c: &Mat3) -> Vec3 {
    let roll = half_open(c[(2, 1)].atan2(c[(2, 2)]));
    // asin loses accuracy near ±π/2; atan2 with the row norm keeps it.
    let pitch = (-c[(2, 0)]).atan2((c[(2, 1)] * c[(2, 1)] + c[(2, 2)] * c[(2, 2)]).sqrt());
    let yaw = half_open(c[(1, 0)].atan2(c[(0, 0)]));
    Vec3::new(roll, pitch, yaw)
}

pub fn quat_from_euler(roll: f64, pitch: f64, yaw: f64) -> Quat {
    let (sr, cr) = (0.5 * roll).sin_cos();
    let (sp, cp) = (0.5 * pitch).sin_cos();
    let (sy, cy) = (0.5 * yaw).sin_cos();
    let q = quat(
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    );
    if q.w < 0.0 { -q } else { q }
}

/// (roll, pitch, yaw) of q_nb from the DCM elements that `euler_from_dcm` uses,
/// written in quaternion components.
pub fn euler_from_quat(q: &Quat) -> Vec3 {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    let (c20, c21, c22) = (2.0 * (x * z - w * y), 2.0 * (y * z + w * x), w * w - x * x - y * y + z * z);
    let (c10, c00) = (2.0 * (x * y + w * z), w * w + x * x - y * y - z * z);
    // musl's atan2 (the libm crate): within 1 ulp of glibc's at two thirds of its cost,
    // which matters where a table of states gets its Euler columns
    Vec3::new(half_open(libm::atan2(c21, c22)), libm::atan2(-c20, (c21 * c21 + c22 * c22).sqrt()), half_open(libm::atan2(c10, c00)))
}

/// DCM of a rotation vector: exp([φ×]) (Rodrigues).
pub fn dcm_from_rotvec(phi: &Vec3) -> Mat3 {
    dcm_from_quat(&quat_from_rotvec(phi))
}

pub fn rotvec_from_dcm(c: &Mat3) -> Vec3 {
    rotvec_from_quat(&quat_from_dcm(c))
}

/// Rotate a vector: C(q) v, without forming the matrix.
#[inline]
pub fn quat_rotate(q: &Quat, v: &Vec3) -> Vec3 {
    let u = q.imag();
    let t = 2.0 * u.cross(v);
    v + q.w * t + u.cross(&t)
}

/// Angle (rad) of the rotation that takes `b` into `a`: |log(a ⊗ b*)|.
pub fn quat_angle_between(a: &Quat, b: &Quat) -> f64 {
    rotvec_from_quat(&(a * b.conjugate())).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_dcm_quat_round_trip() {
        for &(r, p, y) in &[(0.1, -0.4, 2.9), (-3.0, 1.2, -1.0), (0.0, 0.0, 0.0), (1e-9, -1e-9, 3.14159)] {
            let c = dcm_from_euler(r, p, y);
            let q = quat_from_euler(r, p, y);
            assert!((dcm_from_quat(&q) - c).abs().max() < 1e-14);
            assert!((quat_from_dcm(&c) - q).coords.abs().max() < 1e-14);
            let e = euler_from_quat(&q);
            assert!((e - Vec3::new(r, p, y)).abs().max() < 1e-12, "{e:?}");
        }
    }

    #[test]
    fn rotvec_matches_rodrigues() {
        let phi = Vec3::new(0.3, -1.1, 0.7);
        let th = phi.norm();
        let k = skew(&(phi / th));
        let rodrigues = Mat3::identity() + th.sin() * k + (1.0 - th.cos()) * k * k;
        assert!((dcm_from_rotvec(&phi) - rodrigues).abs().max() < 1e-15);
        assert!((rotvec_from_dcm(&rodrigues) - phi).abs().max() < 1e-14);
        let tiny = Vec3::new(1e-9, 2e-10, -3e-9);
        assert!((rotvec_from_quat(&quat_from_rotvec(&tiny)) - tiny).norm() < 1e-24);
    }

    #[test]
    fn composition_and_rotation() {
        let a = quat_from_euler(0.2, 0.1, -0.5);
        let b = quat_from_euler(-0.3, 0.4, 1.5);
        let v = Vec3::new(1.0, -2.0, 0.5);
        assert!((dcm_from_quat(&quat_mul(&a, &b)) - dcm_from_quat(&a) * dcm_from_quat(&b)).abs().max() < 1e-15);
        assert!((quat_rotate(&a, &v) - dcm_from_quat(&a) * v).norm() < 1e-15);
    }

    #[test]
    fn unit_quats_rejects_what_names_no_rotation() {
        let good = [quat(2.0, 0.0, 0.0, 0.0), quat(0.0, 0.0, 3.0, 4.0)];
        let u = unit_quats("q", &good).unwrap();
        assert_eq!(quat_to_array(&u[1]), [0.0, 0.0, 0.6, 0.8]);
        for bad in [quat(0.0, 0.0, 0.0, 0.0), quat(1e300, 1e300, 0.0, 0.0), quat(f64::NAN, 1.0, 0.0, 0.0)] {
            match unit_quats("q", &[good[0], bad]) {
                Err(crate::error::NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("q", Some(1))),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn axis_angle_matches_the_rotation_vector_and_holds_for_every_finite_angle() {
        for (axis, angle) in [(Vec3::z(), 1e-7), (Vec3::x(), -0.3), (Vec3::new(0.6, 0.0, 0.8), 2.9)] {
            let (a, b) = (quat_from_axis_angle(&axis, angle), quat_from_rotvec(&(axis * angle)));
            assert!((a.coords - b.coords).amax() < 4.0 * f64::EPSILON, "{a:?} {b:?}"); // a few ulp: two roundings differ
        }
        // θ² overflows for a rotation vector; half the angle's cos/sin do not
        let q = quat_from_axis_angle(&Vec3::z(), 1e308);
        let (s, c) = (5e307f64).sin_cos();
        assert_eq!((q.w, q.i, q.j, q.k), (c, 0.0, 0.0, s));
        assert!(quat_from_rotvec(&(Vec3::z() * 1e308)).w.is_nan());
    }

    #[test]
    fn a_reflection_or_a_non_orthonormal_matrix_is_no_rotation() {
        let r = dcm_from_euler(0.3, -0.2, 1.1);
        assert!(check_rotations("dcm", &[Mat3::identity(), r]).is_ok());
        // within the tolerance: a rotation perturbed by 1e-7 (single precision storage)
        assert!(check_rotation("dcm", 0, &(r + Mat3::from_element(1e-7))).is_ok());
        for bad in [Mat3::from_diagonal(&Vec3::new(1.0, 1.0, -1.0)), Mat3::from_element(1.0), r * 1.01, Mat3::from_element(f64::NAN)] {
            match check_rotations("dcm", &[r, bad]) {
                Err(crate::error::NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("dcm", Some(1))),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn a_quaternion_off_unit_norm_is_no_rotation() {
        let ok = quat(1.0 + 0.5e-6, 0.0, 0.0, 0.0);
        assert_eq!(quat_to_array(&rotation_quats("q_nb", &[ok]).unwrap()[0]), [1.0, 0.0, 0.0, 0.0]);
        for bad in [quat(1.0, 0.1, 0.1, 0.1), quat(0.0, 0.0, 0.0, 0.0), quat(f64::NAN, 0.0, 0.0, 0.0), quat(2.0, 0.0, 0.0, 0.0)] {
            match rotation_quats("q_nb", &[ok, bad]) {
                Err(crate::error::NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("q_nb", Some(1))),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn quats_from_rotvecs_rejects_an_angle_beyond_floats() {
        let half_pi = Vec3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let q = quats_from_rotvecs("rotvec", &[half_pi]).unwrap();
        let h = std::f64::consts::FRAC_1_SQRT_2; // a quarter turn about z: [cos π/4, 0, 0, sin π/4]
        assert!((q[0].w - h).abs() < 1e-15 && (q[0].k - h).abs() < 1e-15);
        match quats_from_rotvecs("rotvec", &[half_pi, Vec3::new(1e-3, 1e308, -1e308)]) {
            Err(crate::error::NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("rotvec", Some(1))),
            other => panic!("{other:?}"),
        }
    }
}
