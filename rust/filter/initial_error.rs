//! The initial navigation error of a filter run drawn from its P₀, so that the estimation
//! error starts with the covariance the filter assumes (the condition under which the
//! NEES is χ²-distributed; Bar-Shalom, Li & Kirubarajan 2001, §5.4.2).
//!
//! δx = estimate − true over the navigation blocks of the layout (NED position m, NED
//! velocity m/s, ψ rad with Ĉ_b^n = (I − [ψ×])C_b^n), δx = L u with L Lᵀ the navigation
//! block of P₀ (Cholesky) and u standard normal. The same function serves the Rust
//! Monte Carlo (`cai/hybrid.rs`) and the Python scenarios (`atomnav.gnss.scenarios`), which
//! pass their own standard normals.

use super::layout::Layout;
use crate::earth::Ellipsoid;
use crate::error::{invalid, Result};
use crate::math::{quat_from_rotvec, quat_normalize, Vec3};
use crate::strapdown::NavState;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_distr::StandardNormal;

/// The navigation blocks, in the order of δx.
pub const NAV_BLOCKS: [&str; 3] = ["position", "velocity", "attitude"];

/// Number of navigation error states (the length of δx).
pub fn nav_size() -> usize {
    NAV_BLOCKS.iter().filter_map(|b| super::layout::standard_size(b)).sum()
}

/// State indices of the navigation blocks in the INS layout, in δx order.
fn nav_indices() -> Result<Vec<usize>> {
    let l = Layout::ins15();
    let mut idx = Vec::with_capacity(nav_size());
    for b in NAV_BLOCKS {
        idx.extend(l.range(b)?);
    }
    Ok(idx)
}

/// X ⊕ δx: the state whose error relative to `s` is (δr NED m, δv m/s, ψ rad), i.e. the
/// estimate when `s` is the truth (small-difference position; q̂ = q(−ψ) ⊗ q, normalised).
pub fn add_nav_error(ell: &Ellipsoid, s: &NavState, dr: &Vec3, dv: &Vec3, psi: &Vec3) -> NavState {
    let loc = ell.local(s.lla.x, s.lla.z);
    let lla = s.lla + Vec3::new(dr.x / loc.rm, dr.y / (loc.rp * loc.cos), -dr.z);
    let q_nb = quat_normalize(&(quat_from_rotvec(&(-psi)) * s.q_nb));
    NavState { t: s.t, lla, vel: s.vel + dv, q_nb }
}

/// δx = L u for the navigation block of `p0` (n × n over a layout starting with the
/// INS blocks) and standard normals `u` (one per navigation state).
// invariant: idx holds the m navigation indices of the layout, all < m ≤ rows of
// the square p0 (checked above); i, j < m.
#[allow(clippy::indexing_slicing)]
pub fn initial_error(p0: &DMatrix<f64>, u: &[f64]) -> Result<Vec<f64>> {
    let idx = nav_indices()?;
    let m = idx.len();
    if p0.nrows() != p0.ncols() || p0.nrows() < m {
        return Err(invalid("p0", format!("expected a square matrix of at least {m} x {m} (the navigation blocks), got {}x{}", p0.nrows(), p0.ncols())));
    }
    if u.len() != m {
        return Err(invalid("normals", format!("expected {m} standard normals, got {}", u.len())));
    }
    crate::error::check_finite("normals", u, 1)?;
    let block = DMatrix::from_fn(m, m, |i, j| p0[(idx[i], idx[j])]);
    crate::error::check_finite("p0", block.as_slice(), m)?;
    let l = block
        .cholesky()
        .ok_or_else(|| invalid("p0", "the navigation block (position, velocity, attitude) must be positive definite"))?
        .l();
    Ok((l * DVector::from_column_slice(u)).as_slice().to_vec())
}

/// The estimate at the start: `truth` ⊕ δx with δx = L u ([`initial_error`]).
pub fn perturbed_start(ell: &Ellipsoid, truth: &NavState, p0: &DMatrix<f64>, u: &[f64]) -> Result<NavState> {
    let d = initial_error(p0, u)?;
    let v = |k: usize| match d.get(k..k + 3) {
        Some(&[a, b, c]) => Ok(Vec3::new(a, b, c)),
        _ => Err(invalid("p0", format!("the navigation blocks need 9 states, got {}", d.len()))),
    };
    Ok(add_nav_error(ell, truth, &v(0)?, &v(3)?, &v(6)?))
}

/// [`perturbed_start`] with the standard normals drawn from `rng` (one per navigation
/// state, in δx order).
pub fn draw_start<R: Rng>(ell: &Ellipsoid, truth: &NavState, p0: &DMatrix<f64>, rng: &mut R) -> Result<NavState> {
    let u: Vec<f64> = (0..nav_size()).map(|_| rng.sample(StandardNormal)).collect();
    perturbed_start(ell, truth, p0, &u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::WGS84;
    use rand::SeedableRng;
    use rand_chacha::ChaCha20Rng;

    fn p0() -> DMatrix<f64> {
        // a full (correlated) navigation block and bias states
        let g = DMatrix::from_fn(15, 15, |i, j| (((i * 7 + j * 3) % 11) as f64 - 5.0) * 0.1 + if i == j { 2.0 } else { 0.0 });
        let mut p = &g * g.transpose();
        for i in 0..15 {
            let s = [5.0, 5.0, 5.0, 0.1, 0.1, 0.1, 1e-3, 1e-3, 1e-2, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0][i];
            p.row_mut(i).scale_mut(s);
            p.column_mut(i).scale_mut(s);
        }
        p
    }

    /// The sample covariance of many draws of δx (recovered from the perturbed state by
    /// the inverse small-error relations) matches the navigation block of P₀ (χ²-sized
    /// tolerance: 20 000 draws give a relative standard error ≈ √(2/N) = 1 %).
    #[test]
    fn sample_covariance_of_draws_matches_p0() {
        let p = p0();
        let truth = NavState { t: 0.0, lla: Vec3::new(0.9, 0.3, 200.0), vel: Vec3::new(10.0, -5.0, 0.2), q_nb: crate::math::quat(1.0, 0.0, 0.0, 0.0) };
        let loc = WGS84.local(truth.lla.x, truth.lla.z);
        let mut rng = ChaCha20Rng::seed_from_u64(11);
        let n = 20_000;
        let mut cov = DMatrix::<f64>::zeros(9, 9);
        for _ in 0..n {
            let s = draw_start(&WGS84, &truth, &p, &mut rng).unwrap();
            let dl = s.lla - truth.lla;
            // ψ from q̂ q* = q(−ψ) (small angle: vector part ≈ −ψ/2)
            let dq = s.q_nb * truth.q_nb.conjugate();
            let psi = -2.0 * Vec3::new(dq.i, dq.j, dq.k) * dq.w.signum();
            let d = [dl.x * loc.rm, dl.y * loc.rp * loc.cos, -dl.z, s.vel.x - truth.vel.x, s.vel.y - truth.vel.y, s.vel.z - truth.vel.z, psi.x, psi.y, psi.z];
            let d = DVector::from_column_slice(&d);
            cov += &d * d.transpose();
        }
        cov /= n as f64;
        for i in 0..9 {
            for j in 0..9 {
                let scale = (p[(i, i)] * p[(j, j)]).sqrt();
                assert!((cov[(i, j)] - p[(i, j)]).abs() < 0.05 * scale, "({i}, {j}): {} vs {}", cov[(i, j)], p[(i, j)]);
            }
        }
    }

    /// With a diagonal P₀ the draw is σ_i u_i exactly (the Cholesky factor is the σ's).
    #[test]
    fn diagonal_p0_scales_each_normal_by_its_sigma() {
        let sig = [3.0, 4.0, 5.0, 0.1, 0.2, 0.3, 1e-4, 2e-4, 3e-3];
        let mut d = vec![1.0; 15];
        d[..9].iter_mut().zip(sig).for_each(|(x, s)| *x = s * s);
        let p = DMatrix::from_diagonal(&DVector::from_vec(d));
        let u = [0.5, -1.0, 2.0, 1.5, -0.25, 0.75, -2.0, 1.0, 0.1];
        let e = initial_error(&p, &u).unwrap();
        for i in 0..9 {
            assert_eq!(e[i], sig[i] * u[i]);
        }
    }

    #[test]
    fn bad_p0_or_normals_are_rejected() {
        let u = [0.0; 9];
        let e = initial_error(&DMatrix::identity(5, 5), &u).unwrap_err().to_string();
        assert!(e.starts_with("p0:") && e.contains("9 x 9"), "{e}");
        let mut p = DMatrix::identity(15, 15);
        p[(4, 4)] = -1.0;
        assert!(initial_error(&p, &u).unwrap_err().to_string().contains("positive definite"));
        assert!(initial_error(&DMatrix::identity(15, 15), &u[..8]).unwrap_err().to_string().starts_with("normals:"));
    }
}
