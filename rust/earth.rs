//! Earth models: WGS-84 and PZ-90.11 ellipsoids, normal gravity, radii of curvature,
//! Earth and transport rates, LLA ↔ ECEF ↔ NED (standard geodesy on the ellipsoid).
//!
//! Positions are (latitude rad, longitude rad, ellipsoidal height m).

use crate::error::{invalid, NavError, Result};
use crate::math::{Mat3, Vec3};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    pub name: &'static str,
    /// Semi-major axis a (m).
    pub a: f64,
    /// Flattening f.
    pub f: f64,
    /// Gravitational constant GM (m³/s²).
    pub gm: f64,
    /// Earth rotation rate Ω (rad/s).
    pub omega: f64,
    /// Normal gravity at the equator and at the pole (m/s²); equal to
    /// `gamma_equator_pole()` (the closed form), stored so gravity costs no `atan`.
    pub gamma_e: f64,
    pub gamma_p: f64,
}

/// WGS-84 (NIMA TR8350.2).
pub const WGS84: Ellipsoid = Ellipsoid {
    name: "WGS84",
    a: 6378137.0,
    f: 1.0 / 298.257223563,
    gm: 3.986004418e14,
    omega: 7.292115e-5,
    gamma_e: 9.7803253359,
    gamma_p: 9.8321849378,
};

/// Kinematic mode (docs/departures.md#kinematic-gravity-mode): WGS-84 geometry without Earth
/// rotation and with zero normal gravity, so a tilt error does not project gravity into
/// the velocity and the IMU senses the kinematic acceleration.
pub const KINEMATIC: Ellipsoid = Ellipsoid { name: "kinematic", omega: 0.0, gamma_e: 0.0, gamma_p: 0.0, ..WGS84 };

/// PZ-90.11 (GLONASS ICD 2016).
pub const PZ90_11: Ellipsoid = Ellipsoid {
    name: "PZ90.11",
    a: 6378136.0,
    f: 1.0 / 298.25784,
    gm: 3.986004418e14,
    omega: 7.292115e-5,
    // γ_e as published for PZ-90.11 (GLONASS ICD 2016); γ_p from the closed form (no published value)
    gamma_e: 9.7803284,
    gamma_p: 9.832188005043,
};

/// Ellipsoids by name: "WGS84" (default everywhere), "PZ90.11" (GLONASS), and
/// "kinematic" (WGS-84's shape with no rotation and no gravity, for purely kinematic tests).
impl crate::options::Choice for Ellipsoid {
    const PARAMETER: &'static str = "ellipsoid";
    const CHOICES: &'static [(&'static str, Self)] = &[("WGS84", WGS84), ("PZ90.11", PZ90_11), ("kinematic", KINEMATIC)];
}

impl Ellipsoid {
    /// First eccentricity squared e² = f(2 − f).
    pub fn e2(&self) -> f64 {
        self.f * (2.0 - self.f)
    }

    /// Semi-minor axis b (m).
    pub fn b(&self) -> f64 {
        self.a * (1.0 - self.f)
    }

    /// m = Ω²a²b/GM.
    pub fn m(&self) -> f64 {
        self.omega * self.omega * self.a * self.a * self.b() / self.gm
    }

    /// Normal gravity at the equator and pole (γ_e, γ_p) from the closed (Pizzetti/Clairaut)
    /// formulas of the level ellipsoid, Heiskanen & Moritz Eqs. 2-73 and 2-74.
    pub fn gamma_equator_pole(&self) -> (f64, f64) {
        let (a, b) = (self.a, self.b());
        let ep = (a * a - b * b).sqrt() / b; // second eccentricity e'
        let at = ep.atan();
        let q0 = 0.5 * ((1.0 + 3.0 / (ep * ep)) * at - 3.0 / ep);
        let q0p = 3.0 * (1.0 + 1.0 / (ep * ep)) * (1.0 - at / ep) - 1.0;
        let m = self.m();
        let ge = self.gm / (a * b) * (1.0 - m - m / 6.0 * ep * q0p / q0);
        let gp = self.gm / (a * a) * (1.0 + m / 3.0 * ep * q0p / q0);
        (ge, gp)
    }

    /// Somigliana's k = bγ_p/(aγ_e) − 1 (0 for the gravity-free kinematic model).
    fn somigliana_k(&self) -> f64 {
        if self.gamma_e == 0.0 {
            0.0
        } else {
            self.b() * self.gamma_p / (self.a * self.gamma_e) - 1.0
        }
    }

    /// Meridian (M) and prime-vertical (N) radii of curvature (m) at latitude `lat`.
    pub fn radii(&self, lat: f64) -> (f64, f64) {
        let e2 = self.e2();
        let s = lat.sin();
        let w2 = 1.0 - e2 * s * s;
        let w = w2.sqrt();
        (self.a * (1.0 - e2) / (w2 * w), self.a / w)
    }

    /// Normal gravity magnitude γ (m/s², positive down): Somigliana with the second-order
    /// height correction.
    pub fn gravity(&self, lat: f64, h: f64) -> f64 {
        let ge = self.gamma_e;
        let (a, f, m) = (self.a, self.f, self.m());
        let s2 = lat.sin().powi(2);
        let k = self.somigliana_k();
        let g0 = ge * (1.0 + k * s2) / (1.0 - self.e2() * s2).sqrt();
        g0 * (1.0 - 2.0 / a * (1.0 + f + m - 2.0 * f * s2) * h + 3.0 * h * h / (a * a))
    }

    /// ∂γ/∂φ at height h (m/s²/rad), by the analytic derivative of `gravity`.
    pub fn gravity_dlat(&self, lat: f64, h: f64) -> f64 {
        let ge = self.gamma_e;
        let (a, f, m, e2) = (self.a, self.f, self.m(), self.e2());
        let s2 = lat.sin().powi(2);
        let ds2 = (2.0 * lat).sin(); // d(sin²φ)/dφ
        let k = self.somigliana_k();
        let w = (1.0 - e2 * s2).sqrt();
        let g0 = ge * (1.0 + k * s2) / w;
        let dg0 = ge * (k * ds2 / w + (1.0 + k * s2) * 0.5 * e2 * ds2 / (w * w * w));
        let hc = 1.0 - 2.0 / a * (1.0 + f + m - 2.0 * f * s2) * h + 3.0 * h * h / (a * a);
        let dhc = 4.0 * f * h / a * ds2;
        dg0 * hc + g0 * dhc
    }

    /// Gravity vector in NED (m/s²): (0, 0, γ).
    pub fn gravity_ned(&self, lat: f64, h: f64) -> Vec3 {
        Vec3::new(0.0, 0.0, self.gravity(lat, h))
    }

    /// Earth rate in NED: ω_ie^n = Ω (cos φ, 0, −sin φ) (rad/s).
    pub fn earth_rate_ned(&self, lat: f64) -> Vec3 {
        Vec3::new(self.omega * lat.cos(), 0.0, -self.omega * lat.sin())
    }

    /// Transport rate ω_en^n = (v_E/R_P, −v_N/R_M, −v_E tan φ/R_P) (rad/s), R_M = M + h,
    /// R_P = N + h.
    pub fn transport_rate_ned(&self, lat: f64, h: f64, v_ned: &Vec3) -> Vec3 {
        let (m, n) = self.radii(lat);
        let (rm, rp) = (m + h, n + h);
        Vec3::new(v_ned.y / rp, -v_ned.x / rm, -v_ned.y * lat.tan() / rp)
    }

    /// Rates of (lat, lon, h) for a NED velocity: φ̇ = v_N/R_M, λ̇ = v_E/(R_P cos φ), ḣ = −v_D.
    pub fn lla_rate(&self, lat: f64, h: f64, v_ned: &Vec3) -> Vec3 {
        let (m, n) = self.radii(lat);
        Vec3::new(v_ned.x / (m + h), v_ned.y / ((n + h) * lat.cos()), -v_ned.z)
    }

    /// Schuler angular frequency ω_s = √(γ/R₀), R₀ = √(MN) (+h) (rad/s).
    pub fn schuler_frequency(&self, lat: f64, h: f64) -> f64 {
        let (m, n) = self.radii(lat);
        (self.gravity(lat, h) / ((m * n).sqrt() + h)).sqrt()
    }

    /// ECEF (m) of geodetic (lat, lon, h).
    pub fn lla_to_ecef(&self, lla: &Vec3) -> Vec3 {
        let (lat, lon, h) = (lla.x, lla.y, lla.z);
        let (_, n) = self.radii(lat);
        let (sl, cl) = lat.sin_cos();
        let (so, co) = lon.sin_cos();
        Vec3::new((n + h) * cl * co, (n + h) * cl * so, (n * (1.0 - self.e2()) + h) * sl)
    }

    /// Geodetic (lat, lon, h) of an ECEF point, iterated until |Δφ| < 1e-12 rad.
    pub fn ecef_to_lla(&self, r: &Vec3) -> Vec3 {
        let e2 = self.e2();
        let p = (r.x * r.x + r.y * r.y).sqrt();
        let lon = r.y.atan2(r.x);
        // height from whichever projection is better conditioned at this latitude
        let height = |lat: f64| {
            let (_, n) = self.radii(lat);
            let (s, c) = lat.sin_cos();
            if c.abs() > 0.5 { p / c - n } else { r.z / s - n * (1.0 - e2) }
        };
        let mut lat = r.z.atan2(p * (1.0 - e2));
        for _ in 0..20 {
            let (_, n) = self.radii(lat);
            let new = r.z.atan2(p * (1.0 - e2 * n / (n + height(lat))));
            let done = (new - lat).abs() < 1e-12;
            lat = new;
            if done {
                break;
            }
        }
        Vec3::new(lat, lon, height(lat))
    }
}

/// Earth quantities at one position (see `Ellipsoid::local`).
#[derive(Debug, Clone, Copy)]
pub struct Local {
    pub sin: f64,
    pub cos: f64,
    /// R_M = M + h and R_P = N + h (m).
    pub rm: f64,
    pub rp: f64,
    /// Normal gravity γ (m/s², down).
    pub gravity: f64,
    omega: f64,
    /// 1/R_M, 1/R_P and 1/(R_P cos φ), so the rates below need no division.
    inv_rm: f64,
    inv_rp: f64,
    inv_rp_cos: f64,
}

impl Local {
    /// ω_ie^n = Ω (cos φ, 0, −sin φ).
    #[inline]
    pub fn earth_rate(&self) -> Vec3 {
        Vec3::new(self.omega * self.cos, 0.0, -self.omega * self.sin)
    }
    /// ω_en^n = (v_E/R_P, −v_N/R_M, −v_E tan φ/R_P).
    #[inline]
    pub fn transport_rate(&self, v: &Vec3) -> Vec3 {
        Vec3::new(v.y * self.inv_rp, -v.x * self.inv_rm, -v.y * self.sin * self.inv_rp_cos)
    }
    /// (φ̇, λ̇, ḣ) = (v_N/R_M, v_E/(R_P cos φ), −v_D).
    #[inline]
    pub fn lla_rate(&self, v: &Vec3) -> Vec3 {
        Vec3::new(v.x * self.inv_rm, v.y * self.inv_rp_cos, -v.z)
    }
}

/// The position-independent constants of `Ellipsoid::local`, computed once (a
/// mechanization evaluates the Earth model at every step).
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct LocalModel {
    a: f64,
    e2: f64,
    /// a(1 − e²), for M = a(1 − e²)/W³.
    a_1me2: f64,
    omega: f64,
    gamma_e: f64,
    /// Somigliana's k.
    k: f64,
    /// Height correction 1 − (c₁ − c₂ sin²φ) h + c₃ h² with c₁ = 2(1 + f + m)/a,
    /// c₂ = 4f/a, c₃ = 3/a² (Somigliana with the second-order height correction).
    c1: f64,
    c2: f64,
    c3: f64,
}

impl LocalModel {
    /// Everything the mechanization needs at (lat rad, h m), with one sin/cos, one sqrt
    /// and one division (the divider is the scarce unit of a mechanization step). With
    /// W = √(1 − e² sin²φ): R_M = M + h = X/W³, X = a(1 − e²) + hW³, and R_P = N + h = Y/W,
    /// Y = a + hW; the one reciprocal r = 1/(X·Y·W·cos φ) gives 1/W = XY cos φ·r,
    /// 1/R_M = W⁴Y cos φ·r, 1/R_P = W²X cos φ·r and 1/(R_P cos φ) = W²X·r.
    pub fn at(&self, lat: f64, h: f64) -> Local {
        self.at_sin_cos(lat.sin_cos(), h)
    }

    /// `at` from (sin φ, cos φ), e.g. of an `AnchoredSinCos`.
    #[inline]
    pub fn at_sin_cos(&self, (sin, cos): (f64, f64), h: f64) -> Local {
        let s2 = sin * sin;
        let w2 = 1.0 - self.e2 * s2;
        let w = w2.sqrt();
        let (x, y) = (self.a_1me2 + h * w2 * w, self.a + h * w);
        let r = 1.0 / (x * y * w * cos);
        let w2xr = w2 * x * r;
        let inv_w = x * y * cos * r;
        let g0 = self.gamma_e * (1.0 + self.k * s2) * inv_w;
        let gravity = g0 * (1.0 - (self.c1 - self.c2 * s2) * h + self.c3 * h * h);
        let (rm, rp) = (x * inv_w * inv_w * inv_w, y * inv_w);
        Local { sin, cos, rm, rp, gravity, omega: self.omega, inv_rm: w2 * w2 * y * cos * r, inv_rp: w2xr * cos, inv_rp_cos: w2xr }
    }
}

/// sin φ and cos φ of a slowly moving latitude φ from an exact anchor φ_a by the
/// addition theorem, sin(φ_a + δ) = sin φ_a + (sin φ_a (cos δ − 1) + cos φ_a sin δ) and
/// likewise for cos, with cos δ − 1 = −δ²/2 + δ⁴/24 and sin δ = δ − δ³/6 + δ⁵/120. For
/// |δ| ≤ `REACH` = 1e-3 rad (6 km) the first omitted terms, δ⁶/720 and δ⁷/5040, are below
/// 1.4e-21, so the result is as exact as `f64::sin_cos` at about a sixth of its cost; a
/// latitude beyond the reach becomes the new anchor. A mechanization step moves the
/// latitude by ~1e-7 rad, so the anchor is renewed every few thousand steps.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct AnchoredSinCos {
    lat: f64,
    sin: f64,
    cos: f64,
}

impl AnchoredSinCos {
    pub const REACH: f64 = 1e-3;

    pub fn new(lat: f64) -> Self {
        let (sin, cos) = lat.sin_cos();
        Self { lat, sin, cos }
    }

    /// (sin φ, cos φ); NaN in, NaN out.
    #[inline]
    pub fn sin_cos(&mut self, lat: f64) -> (f64, f64) {
        let d = lat - self.lat;
        if !(d.abs() <= Self::REACH) {
            *self = Self::new(lat);
            return (self.sin, self.cos);
        }
        let d2 = d * d;
        let cos_d_m1 = -d2 * (0.5 - d2 * (1.0 / 24.0));
        let sin_d = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0)));
        (self.sin + (self.sin * cos_d_m1 + self.cos * sin_d), self.cos + (self.cos * cos_d_m1 - self.sin * sin_d))
    }
}

/// C_n^e: columns are the N, E, D axes in ECEF.
pub fn dcm_ned_to_ecef(lat: f64, lon: f64) -> Mat3 {
    let (sl, cl) = lat.sin_cos();
    let (so, co) = lon.sin_cos();
    Mat3::new(-sl * co, -so, -cl * co, -sl * so, co, -cl * so, cl, 0.0, -sl)
}

/// Heights (m) of a navigation state the Earth model is used for: from the deepest ocean
/// trench (−11 km, rounded to −10 km) to low Earth orbit. Below, normal gravity and the
/// radii lose their meaning (at −7e6 m the Schuler period is NaN); above, a navigation
/// frame on the ellipsoid is no longer what an orbit needs.
pub const HEIGHT_RANGE: (f64, f64) = (-1e4, 1e6);

/// `h` (m) inside [`HEIGHT_RANGE`]; else `InvalidInput` naming `field`.
pub fn check_height(field: &str, h: f64) -> Result<()> {
    let (lo, hi) = HEIGHT_RANGE;
    match (lo..=hi).contains(&h) {
        true => Ok(()),
        false => Err(invalid(field, format!("height {h} m is outside [{lo}, {hi}] m"))),
    }
}

/// Check a latitude (rad) is within [−π/2, π/2] and finite.
pub fn check_latitude(field: &str, lat: f64, index: usize) -> Result<()> {
    if lat.is_finite() && lat.abs() <= std::f64::consts::FRAC_PI_2 {
        Ok(())
    } else {
        Err(invalid(field, format!("latitude {lat} rad at index {index} is outside [-pi/2, pi/2]")))
    }
}

/// [`check_latitude`] of row `index` of an array (the error carries the row).
fn check_latitude_row(field: &str, lat: f64, index: usize) -> Result<()> {
    check_latitude(field, lat, index).map_err(|e| match e {
        NavError::InvalidInput { field, reason, .. } => NavError::InvalidInput { field, reason, index: Some(index) },
        other => other,
    })
}

/// [`check_latitude`] for every row of (lat, lon, h) positions (names the first bad row).
pub fn check_latitudes(field: &str, lla: &[Vec3]) -> Result<()> {
    lla.iter().enumerate().try_for_each(|(i, p)| check_latitude_row(field, p.x, i))
}

/// [`check_height`] of row `index` of an array (the error carries the row).
fn check_height_row(field: &str, h: f64, index: usize) -> Result<()> {
    check_height(field, h).map_err(|e| match e {
        NavError::InvalidInput { field, reason, .. } => NavError::InvalidInput { field, reason: format!("{reason} at index {index}"), index: Some(index) },
        other => other,
    })
}

impl Ellipsoid {
    /// [`Ellipsoid::ecef_to_lla`] of each row; a position whose geodetic coordinates are
    /// undefined (the Earth's centre, where the iteration divides N − N) is an
    /// `InvalidInput` naming `field` and the row instead of a NaN row.
    pub fn ecef_to_lla_rows(&self, field: &str, r: &[Vec3]) -> Result<Vec<Vec3>> {
        r.iter()
            .enumerate()
            .map(|(i, r)| {
                let lla = self.ecef_to_lla(r);
                match lla.iter().all(|x| x.is_finite()) {
                    true => Ok(lla),
                    false => Err(crate::error::invalid_at(field, i, format!("position {:?} m at index {i} is at the Earth's centre: latitude and height are undefined", [r.x, r.y, r.z]))),
                }
            })
            .collect()
    }

    /// Per row of (lat, lon, h): [M, N, γ, ∂γ/∂φ, ω_s] (m, m, m/s², m/s²/rad, rad/s). A
    /// latitude outside [−π/2, π/2] names `field`, a height outside [`HEIGHT_RANGE`]
    /// (where γ and ω_s lose their meaning: at h = −7e6 m γ is 66.9 m/s² and ω_s NaN)
    /// names `h_field`, each with the first bad row.
    pub fn parameters_rows(&self, field: &str, h_field: &str, lla: &[Vec3]) -> Result<Vec<[f64; 5]>> {
        lla.iter()
            .enumerate()
            .map(|(i, p)| {
                check_latitude_row(field, p.x, i)?;
                check_height_row(h_field, p.z, i)?;
                let (m, n) = self.radii(p.x);
                Ok([m, n, self.gravity(p.x, p.z), self.gravity_dlat(p.x, p.z), self.schuler_frequency(p.x, p.z)])
            })
            .collect()
    }

    /// Per row of (lat, lon, h, v_N, v_E, v_D): [ω_ie^n (3), ω_en^n (3)] in rad/s; a
    /// latitude outside [−π/2, π/2] or a height outside [`HEIGHT_RANGE`] (the transport
    /// rate divides by the radius plus h) names `field` and the row.
    pub fn nav_rates_rows(&self, field: &str, rows: &[[f64; 6]]) -> Result<Vec<[f64; 6]>> {
        rows.iter()
            .enumerate()
            .map(|(i, r)| {
                check_latitude_row(field, r[0], i)?;
                check_height_row(field, r[2], i)?;
                let wie = self.earth_rate_ned(r[0]);
                let wen = self.transport_rate_ned(r[0], r[2], &Vec3::new(r[3], r[4], r[5]));
                Ok([wie.x, wie.y, wie.z, wen.x, wen.y, wen.z])
            })
            .collect()
    }

    /// The defining and derived constants by name (a, f, gm, omega, e2, b, gamma_e, gamma_p).
    pub fn constants(&self) -> [(&'static str, f64); 8] {
        [("a", self.a), ("f", self.f), ("gm", self.gm), ("omega", self.omega), ("e2", self.e2()), ("b", self.b()), ("gamma_e", self.gamma_e), ("gamma_p", self.gamma_p)]
    }

    /// Everything the mechanization needs at one position (see `LocalModel::at`).
    pub fn local(&self, lat: f64, h: f64) -> Local {
        self.local_model().at(lat, h)
    }

    /// The constants of `local`, to compute once where it is evaluated at every step.
    pub fn local_model(&self) -> LocalModel {
        let (a, f) = (self.a, self.f);
        LocalModel {
            a,
            e2: self.e2(),
            a_1me2: a * (1.0 - self.e2()),
            omega: self.omega,
            gamma_e: self.gamma_e,
            k: self.somigliana_k(),
            c1: 2.0 / a * (1.0 + f + self.m()),
            c2: 4.0 * f / a,
            c3: 3.0 / (a * a),
        }
    }

    /// NED coordinates (m) of ECEF point `r` relative to the geodetic origin `origin_lla`.
    pub fn ecef_to_ned(&self, r: &Vec3, origin_lla: &Vec3) -> Vec3 {
        let c = dcm_ned_to_ecef(origin_lla.x, origin_lla.y);
        c.transpose() * (r - self.lla_to_ecef(origin_lla))
    }

    /// ECEF point of NED coordinates `ned` (m) relative to `origin_lla`.
    pub fn ned_to_ecef(&self, ned: &Vec3, origin_lla: &Vec3) -> Vec3 {
        self.lla_to_ecef(origin_lla) + dcm_ned_to_ecef(origin_lla.x, origin_lla.y) * ned
    }
}

/// A seven-parameter Helmert transformation r_WGS = T + (1 + s)·Rot·r_PZ with the
/// coordinate-frame rotation Rot = [[1, r_z, −r_y], [−r_z, 1, r_x], [r_y, −r_x, 1]]
/// (docs/departures.md#datum). Rotations in rad, scale dimensionless.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Helmert {
    pub translation: Vec3,
    pub rotation: Vec3,
    pub scale: f64,
}

/// The datum transformation of GLONASS positions into WGS-84: `identity` (default: PZ-90.11
/// ≈ WGS-84 to a few cm) or `pz90_02_to_wgs84` (T = (−0.36, +0.08, +0.18) m, for pre-2014
/// GLONASS ephemerides).
impl crate::options::Choice for Helmert {
    const PARAMETER: &'static str = "datum";
    const CHOICES: &'static [(&'static str, Self)] = &[
        ("identity", Helmert::IDENTITY),
        ("pz90_02_to_wgs84", Helmert { translation: Vec3::new(-0.36, 0.08, 0.18), rotation: Vec3::new(0.0, 0.0, 0.0), scale: 0.0 }),
    ];
}

impl Helmert {
    /// No transformation.
    pub const IDENTITY: Helmert = Helmert { translation: Vec3::new(0.0, 0.0, 0.0), rotation: Vec3::new(0.0, 0.0, 0.0), scale: 0.0 };

    fn rot(&self) -> Mat3 {
        let r = self.rotation;
        Mat3::new(1.0, r.z, -r.y, -r.z, 1.0, r.x, r.y, -r.x, 1.0)
    }

    /// PZ-90 → WGS-84 position (m).
    pub fn forward(&self, r: &Vec3) -> Vec3 {
        self.translation + self.rot() * r * (1.0 + self.scale)
    }

    /// PZ-90 → WGS-84 velocity (m/s): the translation drops out.
    pub fn forward_velocity(&self, v: &Vec3) -> Vec3 {
        self.rot() * v * (1.0 + self.scale)
    }

    /// WGS-84 → PZ-90 position (m), the exact inverse of `forward`.
    // invariant: Rot = I + S with S skew-symmetric has det = 1 + |w|² ≥ 1, never 0.
    #[allow(clippy::expect_used)]
    pub fn inverse(&self, r: &Vec3) -> Vec3 {
        self.rot().try_inverse().expect("Rot is I + small skew, always invertible") * (r - self.translation) / (1.0 + self.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The anchored sin/cos equals libm's within 2 ulp anywhere in its reach, renews its
    /// anchor beyond it, and passes NaN through; the one-division `LocalModel::at` equals
    /// the textbook radii and gravity.
    #[test]
    fn anchored_sin_cos_and_local_model_match_direct_formulas() {
        for lat0 in [-1.5707963267948966, -1.2, -0.3, 0.0, 0.4, 0.97, 1.5, 1.5707963267948966] {
            let mut a = AnchoredSinCos::new(lat0);
            for d in [0.0, 1e-9, -3e-7, 2.5e-4, -7e-4, 1e-3, -1e-3, 0.02, -0.5] {
                let lat = lat0 + d;
                let (s, c) = a.sin_cos(lat);
                let (s0, c0) = lat.sin_cos();
                assert!((s - s0).abs() <= 2.0 * f64::EPSILON && (c - c0).abs() <= 2.0 * f64::EPSILON, "lat {lat}: ({s}, {c}) vs ({s0}, {c0})");
            }
        }
        assert!(AnchoredSinCos::new(0.3).sin_cos(f64::NAN).0.is_nan());
        let model = WGS84.local_model();
        for (lat, h) in [(0.0, 0.0), (0.97, 200.0), (-1.3, 8000.0), (1.57, -50.0)] {
            let loc = model.at(lat, h);
            let (m, n) = WGS84.radii(lat);
            let rel = |a: f64, b: f64| ((a - b) / b).abs();
            assert!(rel(loc.rm, m + h) < 1e-15 && rel(loc.rp, n + h) < 1e-15, "radii at {lat}");
            assert!(rel(loc.gravity, WGS84.gravity(lat, h)) < 1e-14, "gravity at {lat}");
            let v = Vec3::new(100.0, -40.0, 3.0);
            let want = WGS84.transport_rate_ned(lat, h, &v);
            assert!((loc.transport_rate(&v) - want).norm() < 1e-14 * want.norm(), "transport rate at {lat}");
            let want = WGS84.lla_rate(lat, h, &v);
            assert!((loc.lla_rate(&v) - want).norm() < 1e-14 * want.norm(), "lla rate at {lat}");
        }
    }

    /// Kinematic mode: no gravity, no gradient, no Earth rate; WGS-84 geometry.
    #[test]
    fn kinematic_model_has_no_gravity_and_no_rotation() {
        let k = <Ellipsoid as crate::options::Choice>::parse("kinematic").unwrap();
        for (lat, h) in [(0.0, 0.0), (0.9, 300.0), (-1.2, -50.0)] {
            assert_eq!(k.gravity(lat, h), 0.0);
            assert_eq!(k.gravity_dlat(lat, h), 0.0);
            assert_eq!(k.local(lat, h).gravity, 0.0);
            assert_eq!(k.earth_rate_ned(lat), Vec3::zeros());
            assert_eq!(k.radii(lat), WGS84.radii(lat));
        }
    }

    #[test]
    fn wgs84_normal_gravity_matches_published_constants() {
        // NIMA TR8350.2 Table 3.4: γ_e = 9.7803253359, γ_p = 9.8321849378 m/s².
        let (ge, gp) = WGS84.gamma_equator_pole();
        assert!((ge - 9.7803253359).abs() < 1e-9, "{ge}");
        assert!((gp - 9.8321849378).abs() < 1e-9, "{gp}");
        assert!((WGS84.gravity(0.0, 0.0) - ge).abs() < 1e-9);
        // the stored PZ-90.11 values agree with its closed form
        let (pe, pp) = PZ90_11.gamma_equator_pole();
        assert!((pe - PZ90_11.gamma_e).abs() < 1e-7 && (pp - PZ90_11.gamma_p).abs() < 1e-11, "{pe} {pp}");
        assert!((WGS84.gravity(std::f64::consts::FRAC_PI_2, 0.0) - gp).abs() < 1e-9);
    }

    #[test]
    fn lla_ecef_round_trip() {
        for &(lat, lon, h) in &[(0.97, 0.656, 200.0), (-1.5, -3.0, 9000.0), (0.0, 0.0, -50.0), (1.5707963, 1.0, 10.0)] {
            let lla = Vec3::new(lat, lon, h);
            let back = WGS84.ecef_to_lla(&WGS84.lla_to_ecef(&lla));
            assert!((back.x - lat).abs() < 1e-12 && (back.y - lon).abs() < 1e-12 && (back.z - h).abs() < 1e-6, "{back:?}");
        }
    }

    #[test]
    fn local_matches_the_separate_functions() {
        let (lat, h, v) = (0.9, 250.0, Vec3::new(30.0, -12.0, 1.0));
        let l = WGS84.local(lat, h);
        let (m, n) = WGS84.radii(lat);
        assert!((l.gravity - WGS84.gravity(lat, h)).abs() < 1e-13);
        assert!((l.rm - m - h).abs() < 1e-8 && (l.rp - n - h).abs() < 1e-8);
        assert!((l.earth_rate() - WGS84.earth_rate_ned(lat)).norm() < 1e-20);
        assert!((l.transport_rate(&v) - WGS84.transport_rate_ned(lat, h, &v)).norm() < 1e-18);
        assert!((l.lla_rate(&v) - WGS84.lla_rate(lat, h, &v)).norm() < 1e-18);
    }

    #[test]
    fn gravity_derivative_matches_finite_difference() {
        let (lat, h, d) = (0.7, 300.0, 1e-6);
        let fd = (WGS84.gravity(lat + d, h) - WGS84.gravity(lat - d, h)) / (2.0 * d);
        assert!((WGS84.gravity_dlat(lat, h) - fd).abs() < 1e-8);
    }
    #[test]
    fn helmert_round_trip_and_pz90_02_offset() {
        let h = Helmert { translation: Vec3::new(-0.36, 0.08, 0.18), rotation: Vec3::new(1e-8, -2e-8, 3e-9), scale: 2e-9 };
        let r = Vec3::new(2.1e7, -1.3e7, 9.0e6);
        assert!((h.inverse(&h.forward(&r)) - r).norm() < 1e-7);
        let p = <Helmert as crate::options::Choice>::parse("pz90_02_to_wgs84").unwrap();
        assert!(((p.forward(&r) - r) - Vec3::new(-0.36, 0.08, 0.18)).norm() < 1e-9);
        assert_eq!(<Helmert as crate::options::Choice>::parse("identity").unwrap().forward(&r), r);
        assert!(<Helmert as crate::options::Choice>::parse("itrf").is_err());
    }

    #[test]
    fn centre_of_the_earth_is_rejected_not_nan() {
        let r = [WGS84.lla_to_ecef(&Vec3::new(0.5, 0.2, 100.0)), Vec3::zeros()];
        match WGS84.ecef_to_lla_rows("ecef", &r) {
            Err(crate::error::NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("ecef", Some(1))),
            other => panic!("{other:?}"),
        }
        let lla = WGS84.ecef_to_lla_rows("ecef", &r[..1]).unwrap();
        assert!((lla[0] - Vec3::new(0.5, 0.2, 100.0)).abs().max() < 1e-8);
        assert!(WGS84.nav_rates_rows("lla_vel", &[[0.1, 0.0, 0.0, 1.0, 2.0, 3.0], [2.0, 0.0, 0.0, 0.0, 0.0, 0.0]]).is_err());
    }
}
