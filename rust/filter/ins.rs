//! 15-state INS error model (NED, free vertical channel; docs/departures.md#error-states-in-metres) in the
//! project conventions: δr = NED position error (m), δv (m/s), ψ with
//! Ĉ_b^n = (I − [ψ×])C_b^n, δb = b̂ − b for both biases (estimate − true), so the bias
//! columns are F_vba = −Ĉ_b^n and F_ψbg = +Ĉ_b^n (docs/departures.md#sign-of-the-sensor-errors;
//! a model written for the uncompensated sensor bias has the opposite signs).

use super::layout::Layout;
use crate::earth::Ellipsoid;
use crate::error::{invalid, Result};
use crate::math::{dcm_from_quat, skew, Mat3, Vec3};
use crate::options::Choice;
use crate::strapdown::NavState;
use nalgebra::DMatrix;

/// A bias process per axis (the F_bb block: random constant, random walk or Gauss–Markov).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum BiasModel {
    /// ḃ = 0.
    RandomConstant,
    /// ḃ = w, E[w²] = psd (units²/s).
    RandomWalk { psd: f64 },
    /// ḃ = −b/τ + w, steady-state σ: PSD 2σ²/τ.
    GaussMarkov { tau: f64, sigma: f64 },
}

/// The name of a bias process (the kind of [`BiasModel`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BiasKind {
    RandomConstant,
    RandomWalk,
    GaussMarkov,
}

impl Choice for BiasKind {
    const PARAMETER: &'static str = "kind";
    const CHOICES: &'static [(&'static str, Self)] =
        &[("random_constant", BiasKind::RandomConstant), ("random_walk", BiasKind::RandomWalk), ("gauss_markov", BiasKind::GaussMarkov)];
}

impl BiasModel {
    /// Parse ("random_constant" | "random_walk" | "gauss_markov", p1, p2): random walk takes
    /// its PSD as p1; Gauss–Markov τ (s) as p1 and σ as p2. Errors name `field` (the
    /// argument that carries the model, e.g. "accel_bias").
    pub fn from_parts(field: &str, kind: &str, p1: f64, p2: f64) -> Result<Self> {
        let pos = |name: &str, x: f64| {
            if x.is_finite() && x >= 0.0 {
                Ok(x)
            } else {
                Err(invalid(field, format!("{name} must be finite and >= 0, got {x}")))
            }
        };
        let kind = BiasKind::CHOICES.iter().find(|(n, _)| *n == kind).map(|(_, k)| *k).ok_or_else(|| {
            invalid(field, format!("unknown bias model {kind:?}; choose one of {}", BiasKind::names().join(", ")))
        })?;
        match kind {
            BiasKind::RandomConstant => Ok(Self::RandomConstant),
            BiasKind::RandomWalk => Ok(Self::RandomWalk { psd: pos("psd", p1)? }),
            BiasKind::GaussMarkov => {
                crate::error::check_positive(&format!("{field} tau"), p1)?;
                Ok(Self::GaussMarkov { tau: p1, sigma: pos("sigma", p2)? })
            }
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
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InsNoise {
    pub accel_psd: f64,
    pub gyro_psd: f64,
    pub accel_bias: BiasModel,
    pub gyro_bias: BiasModel,
}

impl InsNoise {
    /// The noise model, checked ([`InsNoise::check`]).
    pub fn new(accel_psd: f64, gyro_psd: f64, accel_bias: BiasModel, gyro_bias: BiasModel) -> Result<InsNoise> {
        let n = InsNoise { accel_psd, gyro_psd, accel_bias, gyro_bias };
        n.check()?;
        Ok(n)
    }

    /// White-noise PSDs finite and ≥ 0.
    pub fn check(&self) -> Result<()> {
        for (field, x) in [("accel_psd", self.accel_psd), ("gyro_psd", self.gyro_psd)] {
            if !(x.is_finite() && x >= 0.0) {
                return Err(invalid(field, format!("must be finite and >= 0, got {x}")));
            }
        }
        Ok(())
    }
}

fn put(f: &mut DMatrix<f64>, r: usize, c: usize, m: &Mat3) {
    f.view_mut((r, c), (3, 3)).copy_from(m);
}

/// Continuous F and Q_c = G Q Gᵀ of the INS blocks of `layout` (which must contain
/// position, velocity, attitude; accel_bias and gyro_bias when present are coupled;
/// other blocks get zero rows) at the navigation solution `nav` with compensated
/// specific force `f_b` (m/s², body).
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
    // Gravity gradient from this Earth model: δγ = γ_φ δr_N/R_M − γ_h δr_D (the usual
    // 2γ/R₀ approximates −γ_h; the central difference is exact for the quadratic in h).
    let g_h = (ell.gravity(lat, h + 1.0) - ell.gravity(lat, h - 1.0)) / 2.0;
    let mut f_vr = skew(&v) * (2.0 * a_ie + a_er);
    f_vr.m31 += ell.gravity_dlat(lat, h) / rm;
    f_vr.m33 -= g_h;
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

/// [`error_dynamics`] at every sample of a trajectory (geodetic position, NED velocity,
/// attitude, compensated specific force; equal lengths, latitude inside ±90°).
pub fn error_dynamics_along(layout: &Layout, ell: &Ellipsoid, lla: &[Vec3], vel: &[Vec3], q_nb: &[crate::math::Quat], f_b: &[Vec3], noise: &InsNoise) -> Result<Vec<(DMatrix<f64>, DMatrix<f64>)>> {
    noise.check()?;
    let n = lla.len();
    if let Some((name, len)) = [("vel_ned", vel.len()), ("q_nb", q_nb.len()), ("f_b", f_b.len())].into_iter().find(|x| x.1 != n) {
        return Err(invalid(name, format!("expected {n} rows like lla, got {len}")));
    }
    (lla.iter().zip(vel).zip(q_nb).zip(f_b).enumerate())
        .map(|(k, (((&lla, &vel), &q_nb), f))| {
            crate::earth::check_latitude("lla", lla.x, k)?;
            let nav = NavState { t: 0.0, lla, vel, q_nb };
            error_dynamics(layout, ell, &nav, f, noise)
        })
        .collect()
}

/// Gains of the baro loop (as in `strapdown.rs`; docs/departures.md#baro-damped-vertical-channel):
/// K_v1 = 2ζω_v, K_v2 = ω_v² + 2γ/R₀ with R₀ = √(R_M R_P) at (lat, h).
pub fn baro_gains(ell: &Ellipsoid, lat: f64, h: f64, zeta: f64, omega: f64) -> (f64, f64) {
    let e = ell.local(lat, h);
    (2.0 * zeta * omega, omega * omega + 2.0 * e.gravity / (e.rm * e.rp).sqrt())
}

/// Error model of the reference (barometric) altitude h_b that damps the vertical
/// channel: h_b − h = b + n, with n white (two-sided PSD `noise_psd`, m²·s = m²/Hz; for
/// independent samples of σ every Δt, or σ held over Δt, PSD = σ²Δt as long as Δt is
/// short against the loop's 1/ω_v) and, when `bias` is given, a bias b carried as the
/// one-component state `baro_bias` (m; δb = b̂ − b, the engine compensates h_b − b̂) with
/// its process and initial σ (m). Without `bias` the filter assumes b = 0.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BaroModel {
    pub noise_psd: f64,
    pub bias: Option<(BiasModel, f64)>,
}

impl BaroModel {
    /// White-noise PSD finite and ≥ 0, initial σ of the bias state > 0.
    pub fn check(&self) -> Result<()> {
        if !(self.noise_psd.is_finite() && self.noise_psd >= 0.0) {
            return Err(invalid("baro_psd", format!("must be finite and >= 0, got {}", self.noise_psd)));
        }
        if let Some((_, sigma0)) = self.bias {
            crate::error::check_positive("baro_bias_sigma0", sigma0)?;
        }
        Ok(())
    }
}

/// Add the baro-loop terms of a damped vertical channel to F and Q_c
/// (F_rr[D,D] = −K_v1, F_vr[D,D] gets −K_v2; baro noise n_b enters as −K_v1·n_b into
/// δṙ_D and −K_v2·n_b into δv̇_D). The altitude error seen by the loop is
/// δh_b = (h_b − b̂) − h = −δb + n, so the `baro_bias` column (when the layout has it) is
/// +K_v1 on δṙ_D and +K_v2 on δv̇_D. Derivation (δr_D = −δh): the INS integrates
/// ḣ = −v_D − K_v1(ĥ − h_b), v̇_D += K_v2(ĥ − h_b), the truth ḣ = −v_D, so
/// δṙ_D = δv_D − K_v1(δr_D + δh_b) and δv̇_D gets −K_v2(δr_D + δh_b).
pub fn baro_loop_dynamics(layout: &Layout, ell: &Ellipsoid, nav: &NavState, zeta: f64, omega: f64, baro: &BaroModel, f: &mut DMatrix<f64>, qc: &mut DMatrix<f64>) -> Result<()> {
    let (ir, iv) = (layout.range("position")?.start + 2, layout.range("velocity")?.start + 2);
    let (k1, k2) = baro_gains(ell, nav.lla.x, nav.lla.z, zeta, omega);
    f[(ir, ir)] -= k1;
    f[(iv, ir)] -= k2;
    // G = (−K_v1, −K_v2)ᵀ on (δr_D, δv_D): Q_c += G q Gᵀ
    let q = baro.noise_psd;
    qc[(ir, ir)] += k1 * k1 * q;
    qc[(ir, iv)] += k1 * k2 * q;
    qc[(iv, ir)] += k1 * k2 * q;
    qc[(iv, iv)] += k2 * k2 * q;
    if let (Some(b), Some((model, _))) = (layout.get("baro_bias"), baro.bias) {
        let j = b.start;
        f[(ir, j)] = k1;
        f[(iv, j)] = k2;
        let (fb, qb) = model.dynamics();
        f[(j, j)] = fb;
        qc[(j, j)] = qb;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::layout::INS15 as INS15_SPEC;
    use crate::math::dcm_from_euler;
    use nalgebra::DVector;

    /// Continuous NED mechanization with the sensor bias errors:
    /// returns (llȧ, v̇, Ċ) for the state (lla, v, C) and sensed f, ω (body); `baro` =
    /// (ζ, ω_v, h_b) damps the vertical channel.
    fn rates(ell: &Ellipsoid, lla: &Vec3, v: &Vec3, c: &Mat3, f: &Vec3, w: &Vec3, baro: Option<(f64, f64, f64)>) -> (Vec3, Vec3, Mat3) {
        let loc = ell.local(lla.x, lla.z);
        let (w_ie, w_en) = (loc.earth_rate(), loc.transport_rate(v));
        let mut vdot = c * f - (2.0 * w_ie + w_en).cross(v) + Vec3::new(0.0, 0.0, ell.gravity(lla.x, lla.z));
        let cdot = c * skew(w) - skew(&(w_ie + w_en)) * c;
        let mut lladot = loc.lla_rate(v);
        if let Some((zeta, omega, hb)) = baro {
            let (k1, k2) = baro_gains(ell, lla.x, lla.z, zeta, omega);
            lladot.z -= k1 * (lla.z - hb);
            vdot.z += k2 * (lla.z - hb);
        }
        (lladot, vdot, cdot)
    }

    /// Relative mismatch per block (position, velocity, attitude) between F·δx, with F the
    /// Jacobian at the true state, and the derivative of the error between a perturbed and
    /// the true trajectory (both from the mechanization): central difference in time, and
    /// symmetric in the perturbation ((D(δx) − D(−δx))/2) so that second-order terms
    /// cancel and only the linearisation is tested. `damped` = (ζ, ω_v, δb_baro): both
    /// run the baro loop on the true altitude, the estimate's compensated by −δb_baro.
    fn mismatch(dr: Vec3, dv: Vec3, psi: Vec3, dba: Vec3, dbg: Vec3, damped: Option<(f64, f64, f64)>) -> [f64; 3] {
        let ell = crate::earth::WGS84;
        let mut spec: Vec<(String, Option<usize>)> = INS15_SPEC.iter().map(|s| (s.to_string(), None)).collect();
        if damped.is_some() {
            spec.push(("baro_bias".to_string(), Some(1)));
        }
        let layout = Layout::new(&spec).unwrap();
        let lla = Vec3::new(0.9, 0.3, 300.0);
        let v = Vec3::new(60.0, -25.0, 1.5);
        let c = dcm_from_euler(0.1, -0.05, 2.0);
        let (f_b, w_b) = (Vec3::new(0.8, -0.3, -9.7), Vec3::new(0.01, -0.02, 0.03));
        let loc = ell.local(lla.x, lla.z);
        let nav = NavState { t: 0.0, lla, vel: v, q_nb: crate::math::quat_from_dcm(&c) };
        let noise = InsNoise { accel_psd: 0.0, gyro_psd: 0.0, accel_bias: BiasModel::RandomConstant, gyro_bias: BiasModel::RandomConstant };
        let (mut f, mut qc) = error_dynamics(&layout, &ell, &nav, &f_b, &noise).unwrap();
        let mut xs: Vec<f64> = dr.iter().chain(dv.iter()).chain(psi.iter()).chain(dba.iter()).chain(dbg.iter()).copied().collect();
        if let Some((zeta, omega, dbb)) = damped {
            let baro = BaroModel { noise_psd: 0.0, bias: Some((BiasModel::RandomConstant, 1.0)) };
            baro_loop_dynamics(&layout, &ell, &nav, zeta, omega, &baro, &mut f, &mut qc).unwrap();
            xs.push(dbb);
        }
        let fx = &f * DVector::from_vec(xs);
        // Time derivative of the error for perturbation sign s (central difference in time).
        let deriv = |s: f64| -> DVector<f64> {
            let lla_e = lla + Vec3::new(s * dr.x / loc.rm, s * dr.y / (loc.rp * loc.cos), -s * dr.z);
            let c_e = (Mat3::identity() - skew(&(s * psi))) * c;
            // δb = b̂ − b: the estimate's compensated sensor outputs differ by −δb.
            let (f_e, w_e, v_e) = (f_b - s * dba, w_b - s * dbg, v + s * dv);
            let (baro_t, baro_e) = match damped {
                Some((zeta, omega, dbb)) => (Some((zeta, omega, lla.z)), Some((zeta, omega, lla.z - s * dbb))),
                None => (None, None),
            };
            let err = |eps: f64| -> DVector<f64> {
                let (a, b, cc) = rates(&ell, &lla, &v, &c, &f_b, &w_b, baro_t);
                let (ae, be, ce) = rates(&ell, &lla_e, &v_e, &c_e, &f_e, &w_e, baro_e);
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

    /// Acceptance: δr = 5 m, δv = 0.05 m/s, ψ = 1e-4 rad, ≤ 1e-4.
    #[test]
    fn f_matches_central_differences_of_mechanization() {
        let z = Vec3::zeros();
        let rel = mismatch(Vec3::new(5.0, -5.0, 5.0), Vec3::new(0.05, 0.05, -0.05), Vec3::new(1e-4, -1e-4, 1e-4), z, z, None);
        assert!(rel.iter().all(|r| *r < 1e-4), "{rel:?}");
    }

    /// Bias columns alone (nav errors zero): F_vba = −Ĉ, F_ψbg = +Ĉ for δb = b̂ − b.
    #[test]
    fn f_bias_columns_match_central_differences() {
        let z = Vec3::zeros();
        let rel = mismatch(z, z, z, Vec3::new(1e-3, -2e-3, 1e-3), Vec3::new(1e-6, 2e-6, -1e-6), None);
        // position rows see no bias in one step (δṙ = δv = 0): only velocity and attitude.
        assert!(rel[1] < 1e-6 && rel[2] < 1e-6, "{rel:?}");
    }

    /// Damped vertical channel (docs/departures.md#baro-damped-vertical-channel): F with the
    /// baro-loop terms matches the
    /// mechanization with the loop, at the acceptance perturbation plus a 3 m baro
    /// bias error; the vertical position and velocity rows are where the loop acts.
    #[test]
    fn f_with_baro_loop_matches_central_differences_of_damped_mechanization() {
        let z = Vec3::zeros();
        let rel = mismatch(Vec3::new(5.0, -5.0, 5.0), Vec3::new(0.05, 0.05, -0.05), Vec3::new(1e-4, -1e-4, 1e-4), z, z, Some((0.707, 0.01, 3.0)));
        assert!(rel.iter().all(|r| *r < 1e-4), "{rel:?}");
        // the baro bias column alone: only δṙ_D and δv̇_D respond
        let rel = mismatch(z, z, z, z, z, Some((0.707, 0.01, 3.0)));
        assert!(rel[0] < 1e-6 && rel[1] < 1e-6, "{rel:?}");
    }
}
