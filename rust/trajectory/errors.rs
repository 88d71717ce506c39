//! Navigation errors of a solution against a reference (the truth of a trajectory): NED
//! position (m), NED velocity (m/s) and the attitude error ψ (rad, navigation frame) with
//! C_nb(est) = (I − [ψ×]) C_nb(ref) (Titterton & Weston 2004, §12.3.1: the "phi-angle"
//! error), i.e. ψ = −rotvec(q_est ⊗ q_ref*).

use crate::earth::{check_latitude, Ellipsoid};
use crate::error::{check_finite, invalid, Result};
use crate::math::{quat_mul, rotvec_from_quat, Quat, Vec3};

/// Column names of [`nav_error`]'s nine values.
pub const ERROR_COLUMNS: [&str; 9] =
    ["dpos_n_m", "dpos_e_m", "dpos_d_m", "dvel_n_mps", "dvel_e_mps", "dvel_d_mps", "psi_n_rad", "psi_e_rad", "psi_d_rad"];

/// Errors estimate − reference of one epoch: geodetic positions (lat rad, lon rad, h m),
/// NED velocities (m/s) and attitudes q_nb; the position difference is expressed in the
/// reference's NED frame.
pub fn nav_error(ell: &Ellipsoid, est: (&Vec3, &Vec3, &Quat), reference: (&Vec3, &Vec3, &Quat)) -> [f64; 9] {
    let dpos = ell.ecef_to_ned(&ell.lla_to_ecef(est.0), reference.0);
    let dv = est.1 - reference.1;
    let psi = -rotvec_from_quat(&quat_mul(est.2, &reference.2.conjugate()));
    [dpos.x, dpos.y, dpos.z, dv.x, dv.y, dv.z, psi.x, psi.y, psi.z]
}

/// A series of navigation states: geodetic position, NED velocity, attitude q_nb.
#[derive(Clone, Copy, Debug)]
pub struct NavSeries<'a> {
    pub lla: &'a [Vec3],
    pub vel: &'a [Vec3],
    pub q_nb: &'a [Quat],
}

impl NavSeries<'_> {
    fn check(&self, name: &str, n: usize) -> Result<()> {
        if self.lla.len() != n || self.vel.len() != n || self.q_nb.len() != n {
            return Err(invalid(name, format!("positions, velocities and attitudes must have {n} rows, got {}, {}, {}", self.lla.len(), self.vel.len(), self.q_nb.len())));
        }
        for (i, p) in self.lla.iter().enumerate() {
            check_latitude(name, p.x, i)?;
            check_finite(name, &[p.y, p.z], i)?;
        }
        Ok(())
    }
}

/// [`nav_error`] of every row of `est` against the same row of `reference`.
pub fn nav_errors(ell: &Ellipsoid, est: NavSeries<'_>, reference: NavSeries<'_>) -> Result<Vec<[f64; 9]>> {
    est.check("nav", est.lla.len())?;
    reference.check("reference", est.lla.len())?;
    let e = est.lla.iter().zip(est.vel).zip(est.q_nb);
    let r = reference.lla.iter().zip(reference.vel).zip(reference.q_nb);
    Ok(e.zip(r).map(|(((p, v), q), ((rp, rv), rq))| nav_error(ell, (p, v, q), (rp, rv, rq))).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::WGS84;
    use crate::math::{quat, quat_from_rotvec};

    /// A displacement of 10 m north, 5 m east, 2 m up, a velocity offset and a small
    /// rotation ψ applied to the reference come back as exactly those errors.
    #[test]
    fn recovers_known_offsets() {
        let r_lla = Vec3::new(0.9, 0.17, 120.0);
        let (rm, rn) = WGS84.radii(r_lla.x);
        // first-order geodetic offsets of (10, 5, −2) m NED
        let e_lla = r_lla + Vec3::new(10.0 / (rm + r_lla.z), 5.0 / ((rn + r_lla.z) * r_lla.x.cos()), 2.0);
        let q_ref = quat(0.9, 0.1, -0.3, 0.2).normalize();
        let psi = Vec3::new(1e-4, -2e-4, 3e-4);
        // C_est = (I − [ψ×]) C_ref ⇔ q_est = q(−ψ) ⊗ q_ref
        let q_est = quat_mul(&quat_from_rotvec(&-psi), &q_ref);
        let (v_ref, v_est) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.5, 1.0, 3.25));
        let e = nav_error(&WGS84, (&e_lla, &v_est, &q_est), (&r_lla, &v_ref, &q_ref));
        for (got, want) in e[..3].iter().zip([10.0, 5.0, -2.0]) {
            assert!((got - want).abs() < 1e-4, "{e:?}");
        }
        assert_eq!(&e[3..6], &[0.5, -1.0, 0.25]);
        for (got, want) in e[6..].iter().zip(psi.iter()) {
            assert!((got - want).abs() < 1e-12, "{e:?}");
        }
    }

    #[test]
    fn series_are_checked() {
        let p = [Vec3::new(0.5, 0.1, 0.0)];
        let v = [Vec3::zeros()];
        let q = [quat(1.0, 0.0, 0.0, 0.0)];
        let ok = NavSeries { lla: &p, vel: &v, q_nb: &q };
        assert_eq!(nav_errors(&WGS84, ok, ok).unwrap(), vec![[0.0; 9]]);
        let short = NavSeries { lla: &p, vel: &[], q_nb: &q };
        assert!(nav_errors(&WGS84, ok, short).unwrap_err().to_string().starts_with("reference:"));
        let bad = [Vec3::new(2.0, 0.1, 0.0)];
        assert!(nav_errors(&WGS84, NavSeries { lla: &bad, ..ok }, ok).unwrap_err().to_string().starts_with("nav:"));
    }
}
