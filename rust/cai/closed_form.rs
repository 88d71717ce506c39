//! Constant-input closed forms of the CAI phase: the exact solution of the atom motion in the
//! rotating sensor frame, its fourth-order series in T, and Tennstedt et al. 2021 Eq. 52.

use crate::error::{check_positive, invalid, Result};
use crate::math::{skew, Mat3, Vec3};
use crate::options::Choice;

/// Which closed form (option `kind`): "exact", "series" or "seed000" (Tennstedt et al. 2021 Eq. 52).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClosedForm {
    Exact,
    Series,
    Seed000,
}

impl Choice for ClosedForm {
    const PARAMETER: &'static str = "kind";
    const CHOICES: &'static [(&'static str, Self)] = &[("exact", ClosedForm::Exact), ("series", ClosedForm::Series), ("seed000", ClosedForm::Seed000)];
}

/// The closed form `kind` per channel (rows of `k` rad/m and `v0` m/s) for constant rate
/// `w` (rad/s), specific force `f` (m/s²), angular acceleration `wd` (rad/s², series only)
/// and gradient (1/s², series only); `t` is T, or the total time T0 for "seed000" (s).
pub fn closed_form_phases(kind: ClosedForm, k: &[Vec3], v0: &[Vec3], (w, f, wd): (&Vec3, &Vec3, &Vec3), gradient: &Mat3, t: f64) -> Result<Vec<f64>> {
    if k.len() != v0.len() {
        return Err(invalid("v0", format!("expected {} rows like k, got {}", k.len(), v0.len())));
    }
    check_positive("T", t)?;
    let one = |(k, v): (&Vec3, &Vec3)| match kind {
        ClosedForm::Exact => phase_constant(k, w, f, v, t),
        ClosedForm::Series => phase_series(k, w, wd, f, v, gradient, t),
        ClosedForm::Seed000 => phase_seed000(k, w, f, v, t),
    };
    Ok(k.iter().zip(v0).map(one).collect())
}

/// Σ_m sign^m c_m x^{2m} for a coefficient generator, summed until negligible. Used for
/// the even power series of the rotation kernels below at small Ωt (no cancellation).
fn even_series(x2: f64, coef: impl Fn(u32) -> f64) -> f64 {
    let mut s = 0.0;
    let mut p = 1.0;
    for m in 0..30 {
        let term = coef(m) * p;
        s += term;
        if term.abs() < 1e-18 * s.abs() {
            break;
        }
        p *= -x2;
    }
    s
}

fn factorial(n: u32) -> f64 {
    (1..=n).map(f64::from).product()
}

/// Kernels of the exact form for W = [ω×], |ω| = Ω, x = Ωt:
/// R(−t) = I − a W + b W², M(t) = t²/2 I − c W + d W² with
/// a = sin x/Ω, b = (1 − cos x)/Ω², c = (sin x − x cos x)/Ω³,
/// d = (t²/2 − (cos x + x sin x − 1)/Ω²)/Ω².
fn kernels(omega: f64, t: f64) -> [f64; 4] {
    let x = omega * t;
    if x < 1.0 {
        let x2 = x * x;
        // Series (derived from the Taylor series of sin and cos).
        let a = t * even_series(x2, |m| 1.0 / factorial(2 * m + 1));
        let b = t * t * even_series(x2, |m| 1.0 / factorial(2 * m + 2));
        let c = t.powi(3) * even_series(x2, |m| (2 * m + 2) as f64 / factorial(2 * m + 3));
        let d = t.powi(4) * even_series(x2, |m| (2 * m + 3) as f64 / factorial(2 * m + 4));
        [a, b, c, d]
    } else {
        let (s, co) = x.sin_cos();
        let o2 = omega * omega;
        [s / omega, (1.0 - co) / o2, (s - x * co) / (o2 * omega), (0.5 * t * t - (co + x * s - 1.0) / o2) / o2]
    }
}

/// Atom position x(t) in s for constant ω_s, f_s:
/// x(t) = R(−t) v0 t − M(t) f_s (no gradient, ω̇ = 0).
pub fn position_constant(w: &Vec3, f: &Vec3, v0: &Vec3, t: f64) -> Vec3 {
    let wm = skew(w);
    let w2 = wm * wm;
    let [a, b, c, d] = kernels(w.norm(), t);
    let r = Mat3::identity() - a * wm + b * w2;
    let m = 0.5 * t * t * Mat3::identity() - c * wm + d * w2;
    r * v0 * t - m * f
}

/// Exact phase k·D[x] for constant specific force f_s and rate ω_s in s (E10).
pub fn phase_constant(k: &Vec3, w: &Vec3, f: &Vec3, v0: &Vec3, t_sep: f64) -> f64 {
    k.dot(&(position_constant(w, f, v0, 2.0 * t_sep) - 2.0 * position_constant(w, f, v0, t_sep)))
}

/// Series to fourth order in T, with optional gradient Γ and angular acceleration:
/// φ = −T²k·f − 2T²k·(ω×v0) + 2T³k·(ω×f) + 3T³k·(ω×(ω×v0)) − 3T³k·(ω̇×v0)
///     − 7/4 T⁴k·(ω×(ω×f)) − 7/3 T⁴k·(ω×(ω×(ω×v0))) + T³k·Γv0 − 7/12 T⁴k·Γf.
pub fn phase_series(k: &Vec3, w: &Vec3, wd: &Vec3, f: &Vec3, v0: &Vec3, gradient: &Mat3, t: f64) -> f64 {
    let (t2, t3, t4) = (t * t, t.powi(3), t.powi(4));
    -t2 * k.dot(f) - 2.0 * t2 * k.dot(&w.cross(v0)) + 2.0 * t3 * k.dot(&w.cross(f)) + 3.0 * t3 * k.dot(&w.cross(&w.cross(v0)))
        - 3.0 * t3 * k.dot(&wd.cross(v0))
        - 1.75 * t4 * k.dot(&w.cross(&w.cross(f)))
        - 7.0 / 3.0 * t4 * k.dot(&w.cross(&w.cross(&w.cross(v0))))
        + t3 * k.dot(&(gradient * v0))
        - 7.0 / 12.0 * t4 * k.dot(&(gradient * f))
}

/// Tennstedt et al. 2021 Eq. 52 in the paper's own convention: φ = k·(¼ f − ½ ω×v̄) T0², with
/// T0 the total interrogation time and v̄ the paper's (negated) atom velocity.
pub fn phase_seed000(k: &Vec3, w: &Vec3, f: &Vec3, vbar: &Vec3, t_total: f64) -> f64 {
    k.dot(&(0.25 * f - 0.5 * w.cross(vbar))) * t_total * t_total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// "Oracle vs closed form" reference numbers of an independent computation.
    #[test]
    fn spec_reference_phases() {
        // k = 4π/780.241 nm unrounded (the reference numbers use it).
        let k0 = 4.0 * std::f64::consts::PI / 780.241e-9;
        let f = Vec3::new(0.3, -0.2, -9.81);
        let w = Vec3::new(0.05, -0.03, 0.2);
        let v0 = Vec3::new(0.0, 2.8, 0.0);
        let want = [8420.1364, 2199.7094, 95916.3943];
        for (j, want) in want.iter().enumerate() {
            let k = Vec3::ith(j, k0);
            let phi = phase_constant(&k, &w, &f, &v0, 0.025);
            assert!((phi - want).abs() < 1e-3, "axis {j}: {phi}");
            let ser = phase_series(&k, &w, &Vec3::zeros(), &f, &v0, &Mat3::zeros(), 0.025);
            assert!((ser - phi).abs() < 5e-3, "series axis {j}: {ser} vs {phi}");
        }
    }

    /// The batch form is the per-channel closed form, by name, with its checks.
    #[test]
    fn batch_by_name() {
        let (k, v0) = ([Vec3::new(1e7, 0.0, 0.0), Vec3::new(0.0, 1e7, 0.0)], [Vec3::new(0.0, 2.8, 0.0), Vec3::new(0.0, 0.0, 2.8)]);
        let (w, f, wd) = (Vec3::new(0.01, 0.02, 0.03), Vec3::new(0.1, 0.2, -9.8), Vec3::zeros());
        let got = closed_form_phases(ClosedForm::parse("seed000").unwrap(), &k, &v0, (&w, &f, &wd), &Mat3::zeros(), 0.05).unwrap();
        assert_eq!(got[1], phase_seed000(&k[1], &w, &f, &v0[1], 0.05));
        assert!(closed_form_phases(ClosedForm::Exact, &k, &v0[..1], (&w, &f, &wd), &Mat3::zeros(), 0.05).unwrap_err().to_string().starts_with("v0:"));
        assert!(closed_form_phases(ClosedForm::Exact, &k, &v0, (&w, &f, &wd), &Mat3::zeros(), 0.0).unwrap_err().to_string().starts_with("T:"));
        assert!(ClosedForm::parse("taylor").unwrap_err().to_string().starts_with("kind: unknown option"));
    }

    /// Series and exact kernels agree across the switch at Ωt = 1.
    #[test]
    fn kernel_branches_continuous() {
        let lo = kernels(1.0 - 1e-12, 1.0);
        let hi = kernels(1.0 + 1e-12, 1.0);
        for i in 0..4 {
            assert!((lo[i] - hi[i]).abs() < 1e-11 * hi[i].abs(), "{i}: {lo:?} {hi:?}");
        }
    }
}
