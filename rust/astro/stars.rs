//! Star-camera front end (Vasilyuk et al. 2024 §2.1): a deterministic synthetic
//! catalog, a camera simulator, refraction, bundle merging into the virtual camera VF,
//! Wahba/SVD attitudes with their covariance, and the astro increments.

use super::{d1, euler_from_dcm, nearest_rotation};
use crate::math::{check_rotation, check_rotations};
use crate::error::{invalid, invalid_at, Result};
use crate::math::{Mat3, Vec3};
use rand::Rng;
use rand_distr::StandardNormal;

/// Refraction passes after the uncorrected first solution (docs/departures.md#refraction iterates once; a third
/// pass takes the noise-free attitude error from ~1e-11 to the rounding level).
const REFRACTION_PASSES: usize = 3;

/// Largest accepted |‖s‖ − 1| of an input direction vector.
pub const UNIT_TOLERANCE: f64 = 1e-9;

/// xoshiro256** seeded through SplitMix64: the same catalog on every platform.
pub struct Xoshiro256 {
    s: [u64; 4],
}

impl Xoshiro256 {
    pub fn new(seed: u64) -> Self {
        let mut x = seed;
        let mut next = || {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        Self { s: [next(), next(), next(), next()] }
    }

    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let out = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        out
    }

    /// Uniform in (0, 1): ((x >> 11) + 0.5)·2⁻⁵³.
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) * (1.0 / 9_007_199_254_740_992.0)
    }
}

/// Star catalog: GCRS unit vectors (aberration already applied), magnitudes, identifiers.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Catalog {
    pub dirs: Vec<Vec3>,
    pub mags: Vec<f64>,
    pub ids: Vec<u64>,
}

impl Catalog {
    /// A user catalog, checked for unit directions and finite magnitudes.
    pub fn new(dirs: Vec<Vec3>, mags: Vec<f64>, ids: Vec<u64>) -> Result<Self> {
        if mags.len() != dirs.len() || ids.len() != dirs.len() {
            return Err(invalid("catalog", format!("{} directions but {} magnitudes and {} ids", dirs.len(), mags.len(), ids.len())));
        }
        check_unit("catalog_directions", &dirs)?;
        crate::error::check_finite("magnitudes", &mags, 1)?;
        Ok(Self { dirs, mags, ids })
    }

    /// Uniform synthetic sky: N = round(10^(0.985 + 0.455 m_lim)),
    /// z = 2u₁ − 1, λ = 2πu₂, m = m_lim + log10(u₃)/0.455.
    pub fn synthetic(m_lim: f64, seed: u64) -> Result<Self> {
        if !(m_lim.is_finite() && (0.0..=12.0).contains(&m_lim)) {
            return Err(invalid("m_lim", format!("must be within [0, 12], got {m_lim}")));
        }
        let n = 10f64.powf(0.985 + 0.455 * m_lim).round() as usize;
        let mut rng = Xoshiro256::new(seed);
        let mut dirs = Vec::with_capacity(n);
        let mut mags = Vec::with_capacity(n);
        for _ in 0..n {
            let z = 2.0 * rng.uniform() - 1.0;
            let lam = 2.0 * std::f64::consts::PI * rng.uniform();
            let r = (1.0 - z * z).sqrt();
            dirs.push(Vec3::new(r * lam.cos(), r * lam.sin(), z));
            mags.push(m_lim + rng.uniform().log10() / 0.455);
        }
        Ok(Self { dirs, mags, ids: (0..n as u64).collect() })
    }
}

pub fn check_unit(field: &str, v: &[Vec3]) -> Result<()> {
    // one norm per vector; a NaN norm fails too: `is_nan() ||` keeps it out of the accepted set
    let off_unit = |s: &Vec3| {
        let e = (s.norm() - 1.0).abs();
        e.is_nan() || e > UNIT_TOLERANCE
    };
    match v.iter().enumerate().find(|(_, s)| off_unit(s)) {
        None => Ok(()),
        Some((i, vi)) => Err(invalid_at(field, i, format!("not a unit vector at index {i} (norm {})", vi.norm()))),
    }
}

/// Largest observer speed of the first-order aberration formula: above 1e-3 c the
/// neglected second-order term exceeds ~1e-6 rad (0.2″).
pub const ABERRATION_MAX_SPEED: f64 = 1e-3 * crate::gnss::C_LIGHT;

/// [`aberration`] of unit directions `s` (N) for one velocity or one per direction,
/// checked: unit directions, 1 or N velocities, each below [`ABERRATION_MAX_SPEED`].
pub fn aberration_rows(s: &[Vec3], v: &[Vec3]) -> Result<Vec<Vec3>> {
    if v.len() != s.len() && v.len() != 1 {
        return Err(invalid("velocity", format!("expected 1 or {} rows like directions, got {}", s.len(), v.len())));
    }
    check_unit("directions", s)?;
    if let Some((i, vi)) = v.iter().enumerate().find(|(_, v)| v.norm() >= ABERRATION_MAX_SPEED) {
        return Err(invalid_at("velocity", i, format!("|v| = {} m/s at index {i}: the first-order formula needs |v| < 1e-3 c", vi.norm())));
    }
    let vel = |i: usize| if v.len() == 1 { v.first() } else { v.get(i) };
    s.iter()
        .enumerate()
        .map(|(i, s)| vel(i).map(|v| aberration(s, v)).ok_or_else(|| invalid_at("velocity", i, format!("no velocity for direction {i}"))))
        .collect()
}

fn check_cameras(cameras: &[Camera]) -> Result<()> {
    cameras.iter().enumerate().try_for_each(|(i, c)| check_rotation("cameras", i, &c.c_vf_cf))
}

fn check_refractive_index(n: f64) -> Result<()> {
    match n.is_finite() && n >= 1.0 {
        true => Ok(()),
        false => Err(invalid("n_refr", format!("refractive index must be finite and ≥ 1, got {n}"))),
    }
}

/// [`refraction_apply`] (`apply`) or [`refraction_correct`] of each direction `s` about
/// the vertical `u` of the same row, with refractive index `n` ≥ 1.
pub fn refraction_rows(s: &[Vec3], u: &[Vec3], n: f64, apply: bool) -> Result<Vec<Vec3>> {
    if s.len() != u.len() {
        return Err(invalid("up", format!("expected {} rows like directions, got {}", s.len(), u.len())));
    }
    check_refractive_index(n)?;
    let f = if apply { refraction_apply } else { refraction_correct };
    Ok(s.iter().zip(u).map(|(s, u)| f(s, u, n)).collect())
}

/// Lowest height (m) at which [`refractive_index`] is evaluated: below the deepest land
/// depressions the standard-atmosphere model has no meaning.
pub const REFRACTION_MIN_HEIGHT: f64 = -1.0e4;

/// n(H) = 1 + 2.7783e-4 (1 − 2.25577e-5 H)^4.25588 for a height H (m) of at least
/// [`REFRACTION_MIN_HEIGHT`]. Above H = 1/2.25577e-5 ≈ 44.3 km the model's air density
/// reaches zero and n = 1 (vacuum).
pub fn refractive_index(height: f64) -> Result<f64> {
    if !(height.is_finite() && height >= REFRACTION_MIN_HEIGHT) {
        return Err(invalid("height", format!("must be finite and ≥ {REFRACTION_MIN_HEIGHT} m, got {height}")));
    }
    Ok(1.0 + 2.7783e-4 * (1.0 - 2.25577e-5 * height).max(0.0).powf(4.25588))
}

/// Remove refraction: s^rfc = n(I − uuᵀ)s + u√(1 − n²(1 − (uᵀs)²)).
pub fn refraction_correct(s: &Vec3, u: &Vec3, n: f64) -> Vec3 {
    let c = u.dot(s);
    (s - u * c) * n + u * (1.0 - n * n * (1.0 - c * c)).max(0.0).sqrt()
}

/// Apply refraction (inverse of E10): s = (1/n)(I − uuᵀ)s^rfc + u√(1 − (1 − (uᵀs^rfc)²)/n²).
pub fn refraction_apply(s: &Vec3, u: &Vec3, n: f64) -> Vec3 {
    let c = u.dot(s);
    (s - u * c) / n + u * (1.0 - (1.0 - c * c) / (n * n)).sqrt()
}

/// First-order (classical) stellar aberration: the apparent direction of a star of geometric
/// unit direction `s` seen by an observer moving with velocity `v` (m/s, same frame),
/// s' = normalize(s + v/c) = s + (v/c − (s·v/c) s) + O((v/c)²) (Explanatory
/// Supplement to the Astronomical Almanac, 1992, Eq. 3.252-1 to first order). The
/// exact (relativistic) form differs by O((v/c)²): ≈ 1e-8 rad for Earth's 30 km/s orbit.
pub fn aberration(s: &Vec3, v: &Vec3) -> Vec3 {
    (s + v / crate::gnss::C_LIGHT).normalize()
}

/// A rigid camera of the set: C_VF^CFⁱ (maps camera into VF) and the covariance P_aⁱ of
/// its Euler angles αⁱ (rad², zero for camera 1 which defines VF).
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub c_vf_cf: Mat3,
    pub p_alpha: Mat3,
}

/// Star observations of all epochs, one row per star: epoch index, camera index, measured
/// direction in the camera frame, catalog direction in GCRS.
#[derive(Debug, Clone, Default)]
pub struct Observations {
    pub epoch: Vec<usize>,
    pub camera: Vec<usize>,
    pub s_cf: Vec<Vec3>,
    pub g: Vec<Vec3>,
}

/// Wahba/SVD with unit weights: S_GCRS^VF = U diag(1, 1, det U det V) Vᵀ of B = Σ g sᵀ (E11).
pub fn wahba(g: &[Vec3], s: &[Vec3]) -> Mat3 {
    nearest_rotation(&g.iter().zip(s).map(|(g, s)| g * s.transpose()).sum())
}

/// Star attitudes S_GCRS^VF of every epoch with the covariance P_n^avu of θ_n^avu (VF, rad²).
pub struct StarAttitudes {
    pub s: Vec<Mat3>,
    pub p: Vec<Mat3>,
    pub stars: Vec<usize>,
}

/// `n` finite, symmetric, positive semi-definite 3×3 covariances, e.g. a user-supplied
/// P_n^avu of every epoch (E12 "users may instead supply P_n^avu directly").
pub fn check_covariances(field: &str, p: &[Mat3], n: usize) -> Result<()> {
    if p.len() != n {
        return Err(invalid(field, format!("expected {n} covariances, got {}", p.len())));
    }
    for (e, m) in p.iter().enumerate() {
        crate::filter::matrix::check_covariance(field, &nalgebra::DMatrix::from_column_slice(3, 3, m.as_slice()), Some(3), false)
            .map_err(|err| match err {
                crate::error::NavError::InvalidInput { reason, .. } => crate::error::invalid_at(field, e, format!("{reason} at index {e}")),
                other => other,
            })?;
    }
    Ok(())
}

/// Merge the cameras into VF (E9), remove refraction about the local vertical from a
/// first-pass attitude (E10, D13), solve Wahba (E11) and form P^avu (E12, project default:
/// σ_s²K_n + K_n(Σᵢ Cᵢ Aᵢ D1(αⁱ) P_aⁱ D1(αⁱ)ᵀ Aᵢ Cᵢᵀ)K_n, K_n = (Σ(I − ssᵀ))⁻¹), or take
/// the user's `p_avu` (one per epoch, rad², VF) in its place (E12, D11).
/// `up_gcrs` (one per epoch) and `n_refr` enable refraction; `None` skips it.
// invariant: every obs array has m entries, obs.camera < cameras.len() and obs.epoch <
// n_epochs (checked above), so r < m, e < n_epochs = rows.len() = up.len() = p.len(),
// k < idx.len() = s.len() and the camera indices are in range.
#[allow(clippy::indexing_slicing)]
pub fn star_attitudes(
    obs: &Observations,
    n_epochs: usize,
    cameras: &[Camera],
    sigma_s: f64,
    refraction: Option<(&[Vec3], f64)>,
    p_avu: Option<&[Mat3]>,
) -> Result<StarAttitudes> {
    let m = obs.s_cf.len();
    if let Some(p) = p_avu {
        check_covariances("p_avu", p, n_epochs)?;
    }
    check_cameras(cameras)?;
    if obs.epoch.len() != m || obs.camera.len() != m || obs.g.len() != m {
        return Err(invalid("observations", "epoch, camera, star and catalog arrays differ in length"));
    }
    check_unit("star_directions", &obs.s_cf)?;
    check_unit("catalog_directions", &obs.g)?;
    if !(sigma_s.is_finite() && sigma_s >= 0.0) {
        return Err(invalid("sigma_s", format!("must be finite and ≥ 0, got {sigma_s}")));
    }
    if let Some((i, c)) = obs.camera.iter().enumerate().find(|(_, &c)| c >= cameras.len()) {
        return Err(invalid("camera", format!("camera index {c} at index {i} but {} cameras", cameras.len())));
    }
    if let Some((i, e)) = obs.epoch.iter().enumerate().find(|(_, &e)| e >= n_epochs) {
        return Err(invalid("epoch", format!("epoch index {e} at index {i} but {n_epochs} epochs")));
    }
    if let Some((up, n)) = refraction {
        check_refractive_index(n)?;
        if up.len() != n_epochs {
            return Err(invalid("up_gcrs", format!("expected {n_epochs} rows, got {}", up.len())));
        }
        check_unit("up_gcrs", up)?;
    }
    // Every epoch needs three stars, checked before anything is sized by n_epochs: m
    // observations cannot give m/3 + 1 epochs three stars each, so the first short epoch is
    // among the first m/3 + 1 and the count vector is bounded by m, however large n_epochs is.
    let mut stars_at = vec![0usize; n_epochs.min(m / 3 + 1)];
    for &e in &obs.epoch {
        if let Some(k) = stars_at.get_mut(e) {
            *k += 1;
        }
    }
    if let Some((e, &k)) = stars_at.iter().enumerate().find(|(_, &k)| k < 3) {
        return Err(invalid("star_directions", format!("epoch at index {e} has {k} stars, need at least 3")));
    }
    let mut rows: Vec<Vec<usize>> = vec![Vec::new(); n_epochs];
    for (r, &e) in obs.epoch.iter().enumerate() {
        rows[e].push(r);
    }
    let d1s: Vec<Mat3> = cameras.iter().map(|c| d1(&euler_from_dcm(&c.c_vf_cf))).collect();
    let mut out = StarAttitudes { s: Vec::with_capacity(n_epochs), p: Vec::with_capacity(n_epochs), stars: Vec::with_capacity(n_epochs) };
    for (e, idx) in rows.iter().enumerate() {
        let g: Vec<Vec3> = idx.iter().map(|&r| obs.g[r]).collect();
        let raw: Vec<Vec3> = idx.iter().map(|&r| cameras[obs.camera[r]].c_vf_cf * obs.s_cf[r]).collect();
        let mut s = raw.clone();
        let mut att = wahba(&g, &s);
        if let Some((up, n)) = refraction {
            // D13: the vertical in VF from the uncorrected solution, then iterated: each pass
            // shrinks the vertical error by a factor ~(n − 1).
            for _ in 0..REFRACTION_PASSES {
                let u = att.transpose() * up[e];
                s = raw.iter().map(|v| refraction_correct(v, &u, n)).collect();
                att = wahba(&g, &s);
            }
        }
        let mut info = Mat3::zeros();
        let mut a_cam = vec![Mat3::zeros(); cameras.len()];
        for (k, &r) in idx.iter().enumerate() {
            let p = Mat3::identity() - s[k] * s[k].transpose();
            info += p;
            let sc = cameras[obs.camera[r]].c_vf_cf.transpose() * s[k];
            a_cam[obs.camera[r]] += Mat3::identity() - sc * sc.transpose();
        }
        let k_n = info.try_inverse().ok_or_else(|| invalid("star_directions", format!("epoch at index {e}: stars are collinear")))?;
        let att_terms: Mat3 = cameras
            .iter()
            .zip(&a_cam)
            .zip(&d1s)
            .map(|((c, a), d)| {
                let t = c.c_vf_cf * a * d;
                t * c.p_alpha * t.transpose()
            })
            .sum();
        out.s.push(att);
        out.p.push(match p_avu {
            Some(p) => p[e],
            None => k_n * sigma_s * sigma_s + k_n * att_terms * k_n,
        });
        out.stars.push(idx.len());
    }
    Ok(out)
}

/// ΔS_n^avu = S_{n−1}ᵀ S_n and E_n^avu = P_n + ΔS_nᵀ P_{n−1} ΔS_n.
pub fn astro_increments(s: &[Mat3], p: &[Mat3]) -> (Vec<Mat3>, Vec<Mat3>) {
    (s.windows(2).zip(p.windows(2)))
        .filter_map(|pair| {
            let ([s0, s1], [p0, p1]) = pair else { return None };
            let ds = s0.transpose() * s1;
            Some((ds, p1 + ds.transpose() * p0 * ds))
        })
        .unzip()
}

/// Camera simulator: for every epoch (true S_GCRS^VF, local up in GCRS) and camera, the
/// catalog stars brighter than `m_lim`, above the horizon and within `fov_half` (rad) of
/// the boresight +z_CF after refraction (index `n_refr`), with isotropic tangent noise
/// σ_s (rad). Deterministic for a given `rng` state.
#[allow(clippy::too_many_arguments)]
pub fn simulate_observations<R: Rng>(
    catalog: &Catalog,
    s_gcrs_vf: &[Mat3],
    up_gcrs: &[Vec3],
    cameras: &[Camera],
    fov_half: f64,
    m_lim: f64,
    sigma_s: f64,
    n_refr: f64,
    rng: &mut R,
) -> Result<Observations> {
    check_rotations("s_gcrs_vf", s_gcrs_vf)?;
    if up_gcrs.len() != s_gcrs_vf.len() {
        return Err(invalid("up_gcrs", format!("expected {} rows, got {}", s_gcrs_vf.len(), up_gcrs.len())));
    }
    check_cameras(cameras)?;
    for (name, v) in [("fov_half", fov_half), ("sigma_s", sigma_s)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(name, format!("must be finite and ≥ 0, got {v}")));
        }
    }
    check_refractive_index(n_refr)?;
    let cos_fov = fov_half.cos();
    let mut obs = Observations::default();
    for (e, (s, up)) in s_gcrs_vf.iter().zip(up_gcrs).enumerate() {
        let u = s.transpose() * up;
        for (ci, cam) in cameras.iter().enumerate() {
            for (g, &mag) in catalog.dirs.iter().zip(&catalog.mags) {
                if mag > m_lim {
                    continue;
                }
                let true_vf = s.transpose() * g;
                if true_vf.dot(&u) <= 0.0 {
                    continue;
                }
                let app = cam.c_vf_cf.transpose() * refraction_apply(&true_vf, &u, n_refr);
                if app.z < cos_fov {
                    continue;
                }
                let e1 = app.cross(&if app.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() }).normalize();
                let e2 = app.cross(&e1);
                let (n1, n2): (f64, f64) = (rng.sample(StandardNormal), rng.sample(StandardNormal));
                obs.epoch.push(e);
                obs.camera.push(ci);
                obs.s_cf.push((app + (e1 * n1 + e2 * n2) * sigma_s).normalize());
                obs.g.push(*g);
            }
        }
    }
    Ok(obs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::ARCSEC;

    #[test]
    fn refraction_matches_snell_closed_form() {
        // Oracle: Snell's law z_obs = asin(sin z / n) for the plane-parallel atmosphere.
        // (a reference table printed 32.61″, 56.49″, 97.88″; the exact Snell values for
        // n − 1 = 2.7385e-4 are 32.602″, 56.463″, 97.769″ — the printed ones are not.)
        let n = refractive_index(150.0).unwrap();
        assert!(((n - 1.0) / 2.7385e-4 - 1.0).abs() < 1e-4);
        let u = Vec3::z();
        for zdeg in [30.0f64, 45.0, 60.0, 85.0] {
            let z = zdeg.to_radians();
            let truth = Vec3::new(z.sin(), 0.0, z.cos());
            let app = refraction_apply(&truth, &u, n);
            let dz = truth.cross(&app).norm().atan2(truth.dot(&app));
            let snell = z - (z.sin() / n).asin();
            assert!((dz - snell).abs() / ARCSEC < 1e-3, "{zdeg}°: {}″ vs {}″", dz / ARCSEC, snell / ARCSEC);
            assert!((refraction_correct(&app, &u, n) - truth).norm() < 1e-15);
        }
    }

    #[test]
    fn aberration_matches_the_exact_relativistic_formula_to_second_order() {
        // Oracle: the exact aberration angle of special relativity between the geometric
        // direction and v: cos θ' = (cos θ + β)/(1 + β cos θ) (Einstein 1905 §7), θ' toward v.
        let c = crate::gnss::C_LIGHT;
        let v = Vec3::new(0.0, 29_780.0, 0.0);
        let beta = v.norm() / c;
        for deg in [10.0f64, 45.0, 90.0, 135.0, 170.0] {
            let th = deg.to_radians();
            let s = Vec3::new(th.sin(), th.cos(), 0.0);
            let app = aberration(&s, &v);
            let th_app = app.dot(&v.normalize()).clamp(-1.0, 1.0).acos();
            let exact = ((th.cos() + beta) / (1.0 + beta * th.cos())).acos();
            assert!((th_app - exact).abs() < beta * beta, "{deg}°: {:e} rad", th_app - exact);
            assert!(((th - th_app) - beta * th.sin()).abs() < beta * beta, "first-order shift β sin θ at {deg}°");
            assert!(app.dot(&s.cross(&v.normalize())).abs() < 1e-15 && (app.norm() - 1.0).abs() < 1e-15, "in the plane of s and v");
        }
    }

    #[test]
    fn synthetic_catalog_size_and_determinism() {
        let c = Catalog::synthetic(5.6, 7).unwrap();
        assert_eq!(c.dirs.len(), 3412);
        assert!(c.mags.iter().all(|&m| m <= 5.6));
        assert_eq!(c.dirs[17], Catalog::synthetic(5.6, 7).unwrap().dirs[17]);
        assert!((c.dirs.iter().sum::<Vec3>() / c.dirs.len() as f64).norm() < 0.05);
    }

    #[test]
    fn huge_epoch_count_is_an_error_not_an_allocation() {
        let g = [Vec3::x(), Vec3::y(), Vec3::z()];
        let obs = Observations { epoch: vec![0, 0, 0], camera: vec![0; 3], s_cf: g.to_vec(), g: g.to_vec() };
        let cams = [Camera { c_vf_cf: Mat3::identity(), p_alpha: Mat3::zeros() }];
        assert_eq!(star_attitudes(&obs, 1, &cams, 1e-5, None, None).unwrap().s.len(), 1);
        match star_attitudes(&obs, usize::MAX, &cams, 1e-5, None, None) {
            Err(crate::error::NavError::InvalidInput { field, reason, .. }) => {
                assert_eq!(field, "star_directions");
                assert!(reason.starts_with("epoch at index 1 has 0 stars"), "{reason}");
            }
            Err(e) => panic!("{e}"),
            Ok(_) => panic!("usize::MAX epochs accepted"),
        }
    }

    #[test]
    fn row_checks_name_the_row() {
        let s = [Vec3::x(), Vec3::y()];
        let slow = Vec3::new(0.0, 0.0, 3.0e4);
        let got = aberration_rows(&s, &[slow]).unwrap();
        assert_eq!(got, vec![aberration(&s[0], &slow), aberration(&s[1], &slow)]);
        let fast = Vec3::new(0.0, 0.0, 1.0001e-3 * crate::gnss::C_LIGHT);
        match aberration_rows(&s, &[slow, fast]) {
            Err(crate::error::NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("velocity", Some(1))),
            other => panic!("{other:?}"),
        }
        assert!(refraction_rows(&s, &s, 0.99, true).is_err());
        assert_eq!(refraction_rows(&s, &[Vec3::z(), Vec3::z()], 1.0003, true).unwrap()[0], refraction_apply(&s[0], &Vec3::z(), 1.0003));
    }
}
