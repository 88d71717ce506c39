//! Atom strapdown phase predictor (Tennstedt et al. 2023 §2, Eqs. 5–12) and its tangent-linear
//! Jacobians (default mode; the paper's Eqs. 27, 31–32 in paper mode).
//!
//! Per shot (pulses at t_s, t_s + T, t_s + 2T) and per interferometer channel the atom
//! position x in the sensor frame s obeys (docs/departures.md#specific-force-drives-the-atoms)
//!   ẍ = −f_s − 2ω×ẋ − ω×(ω×x) − ω̇×x + Γ_s x,   x(0) = 0, ẋ(0) = v0,
//! with (Eq. 7) f_s = C_sb (f_b + ω̇_b×l + ω_b×(ω_b×l)) − Γ_s C_sb l and (Eq. 8) ω = C_sb ω_b.
//! The gravity gradient is given once, as Γ_b0 in the body frame b at the shot's start, and
//! turns with the body during the shot: Γ_s(τ) = C_sb R(τ)ᵀ Γ_b0 R(τ) C_bs, R = C_b0b with
//! Ṙ = R[ω_b×] (docs/departures.md#gravity-gradient-frame).
//! The IMU inputs are interpolated between samples (cubic by default, or linear) and
//! bias-corrected with the current estimates; the ODE is integrated with RK4 on a grid made
//! of the IMU sample times and the pulse times (`substeps` RK4 steps per grid interval);
//! φ = k·D[x]. [`error_bound`] estimates the discretisation error from the samples
//! (docs/cai_predictor_accuracy.md).
//!
//! Breakdown (exact decomposition, docs/departures.md#per-term-breakdown): the solution of the linear ODE is
//! x = x_h + x_p, x_h = Φ(t) v0 (homogeneous part; Φ shared by all channels with the same
//! C_sb and l), x_p the forced part with zero initial state, so
//!   φ_rot = k·D[x_h],   φ_acc, φ_cen, φ_eul = −∫ w k·(…) dτ by
//!   Simpson's rule (exact for the piecewise-polynomial integrands),
//!   φ_mix = k·D[x_p] − φ_acc − φ_cen − φ_eul,   φ_gg = φ(Γ) − φ(Γ = 0),
//! and the six terms add up to the total by construction.

use crate::error::{check_finite, check_increasing, check_positive, invalid, Result};
use crate::math::{dcm_from_rotvec, skew, Mat3, Vec3};
use crate::options::Choice;

/// One interferometer channel: effective wave vector k (rad/m, in s), lever arm l from the
/// IMU to the release point (m, in b), C_sb (rotation b → s, may carry misalignment) and
/// the initial atom velocity v0 relative to s (m/s, in s).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Channel {
    pub k: Vec3,
    pub lever: Vec3,
    pub c_sb: Mat3,
    pub v0: Vec3,
}

/// Source of the angular acceleration ω̇_b used in the Euler terms
/// (docs/departures.md#euler-terms-and-angular-acceleration).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum OmegaDot {
    /// Euler terms omitted (ω̇ ≡ 0).
    Zero,
    /// Derivative of the gyro interpolant (for linear interpolation constant on each IMU
    /// interval; exactly consistent with an oracle fed the same interpolated rate).
    Pwl,
    /// Quadratic Savitzky–Golay derivative over 2m+1 samples:
    /// ω̇_k = Σ_{j=−m..m} j ω_{k+j} / (Δt Σ j²); m = 2 gives
    /// (−2ω_{k−2} − ω_{k−1} + ω_{k+1} + 2ω_{k+2}) / (10Δt). Windows are clamped at the
    /// record ends; Δt is the local mean spacing of the window.
    Savgol { half_width: usize },
    /// Given per-sample values (rad/s², body frame), e.g. from a simulator.
    Given(Vec<Vec3>),
}

/// The name of an ω̇ source (option `omega_dot`); the Savitzky–Golay half width and the
/// given samples travel as separate typed values (see [`OmegaDot::new`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OmegaDotKind {
    Zero,
    Pwl,
    Savgol,
    Given,
}

impl OmegaDotKind {
    /// The ω̇ source when none is named: the given samples when there are some, else the
    /// derivative of the gyro interpolant, whose lever-arm Euler term integrates by parts to
    /// the interpolated rate and so keeps the interpolation's order
    /// (docs/cai_predictor_accuracy.md#angular-acceleration).
    pub fn default_for(given: bool) -> Self {
        if given { OmegaDotKind::Given } else { OmegaDotKind::Pwl }
    }
}

impl Choice for OmegaDotKind {
    const PARAMETER: &'static str = "omega_dot";
    const CHOICES: &'static [(&'static str, Self)] =
        &[("zero", OmegaDotKind::Zero), ("pwl", OmegaDotKind::Pwl), ("savgol", OmegaDotKind::Savgol), ("given", OmegaDotKind::Given)];
}

/// Samples kept before a shot start for the interpolation stencils (cubic Hermite tangents
/// reach one sample further than the interval; the Savitzky–Golay window may need more).
pub const STENCIL_PAD: usize = 3;

/// Largest Savitzky–Golay half width accepted (a window of 2m + 1 samples).
pub const MAX_SAVGOL_HALF_WIDTH: usize = 1000;
/// Savitzky–Golay half width when none is given.
pub const DEFAULT_SAVGOL_HALF_WIDTH: usize = 2;
/// Largest number of RK4 steps per grid interval accepted.
pub const MAX_SUBSTEPS: usize = 1000;
/// RK4 steps per grid interval when none is given: the grid is the IMU sample times, so the
/// RK4 error is of higher order than the interpolation error (docs/cai_predictor_accuracy.md).
pub const DEFAULT_SUBSTEPS: usize = 1;

impl OmegaDot {
    /// The ω̇ source `kind` (None: [`OmegaDotKind::default_for`]) with its parameters: the
    /// half width m ≥ 1 of a Savitzky–Golay window, the per-sample values (rad/s², body
    /// frame) of `Given` (required by it and refused by the other kinds, which would ignore
    /// them).
    pub fn new(kind: Option<OmegaDotKind>, savgol_half_width: usize, given: Option<Vec<Vec3>>) -> Result<Self> {
        let kind = kind.unwrap_or_else(|| OmegaDotKind::default_for(given.is_some()));
        if kind == OmegaDotKind::Savgol && !(1..=MAX_SAVGOL_HALF_WIDTH).contains(&savgol_half_width) {
            return Err(invalid("savgol_half_width", format!("must be in [1, {MAX_SAVGOL_HALF_WIDTH}], got {savgol_half_width}")));
        }
        match (kind, given) {
            (OmegaDotKind::Given, Some(wd)) => Ok(OmegaDot::Given(wd)),
            (OmegaDotKind::Given, None) => Err(invalid("angular_acceleration", "required when omega_dot = 'given'")),
            (other, Some(_)) => Err(invalid("angular_acceleration", format!("given, but omega_dot = '{}' would ignore it", other.name()))),
            (OmegaDotKind::Zero, None) => Ok(OmegaDot::Zero),
            (OmegaDotKind::Pwl, None) => Ok(OmegaDot::Pwl),
            (OmegaDotKind::Savgol, None) => Ok(OmegaDot::Savgol { half_width: savgol_half_width }),
        }
    }

    /// The ω̇ source `kind` of a consumer without per-sample values (the CAI aiding):
    /// "given" is refused under `omega_dot`.
    pub fn without_samples(kind: OmegaDotKind, savgol_half_width: usize) -> Result<Self> {
        if kind == OmegaDotKind::Given {
            return Err(Self::given_without_samples());
        }
        Self::new(Some(kind), savgol_half_width, None)
    }

    /// The error of a "given" ω̇ where no per-sample values exist.
    pub(crate) fn given_without_samples() -> crate::error::NavError {
        invalid("omega_dot", "'given' needs per-sample values, which the aiding does not have; choose zero, pwl or savgol")
    }

    /// Samples needed before a shot start: the interpolation stencil, or a whole
    /// Savitzky–Golay window (2m + 1 samples) so that ω̇ near the shot start is centred.
    pub fn pad(&self) -> usize {
        match self {
            OmegaDot::Savgol { half_width } => STENCIL_PAD.max(2 * half_width + 1),
            _ => STENCIL_PAD,
        }
    }
}

/// Interpolation of the IMU samples between sample times.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Interpolation {
    /// Piecewise linear: integrated error ∝ h² (relative (hΩ)²/12 for a
    /// sinusoid of angular frequency Ω).
    Linear,
    /// Cubic Hermite with central-difference tangents (Catmull–Rom on non-uniform grids,
    /// one-sided at the record ends): integrated error ∝ h⁴ for smooth signals (the
    /// default).
    #[default]
    Cubic,
}

impl Interpolation {
    /// Order p of the integrated interpolation error (∝ h^p) and its coefficient c_p in
    /// |δφ| ≤ c_p h^p T² max|g⁽ᵖ⁾| (docs/cai_predictor_accuracy.md#interpolation-error):
    /// 1/12 for linear, 11/720 for cubic.
    fn error_order(self) -> (usize, f64) {
        match self {
            Interpolation::Linear => (2, 1.0 / 12.0),
            Interpolation::Cubic => (4, 11.0 / 720.0),
        }
    }
}

impl Choice for Interpolation {
    const PARAMETER: &'static str = "interpolation";
    const CHOICES: &'static [(&'static str, Self)] = &[("linear", Interpolation::Linear), ("cubic", Interpolation::Cubic)];
}

/// Channels from per-channel rows: k (rad/m), lever (m), C_sb (3 × 3 each), v0 (m/s), all
/// of the same count.
pub fn channels_from_rows(k: &[Vec3], lever: &[Vec3], c_sb: &[nalgebra::DMatrix<f64>], v0: &[Vec3]) -> Result<Vec<Channel>> {
    let n = k.len();
    if lever.len() != n || v0.len() != n || c_sb.len() != n {
        return Err(invalid("channels", format!("k, lever, v0 must be (C, 3) and c_sb (C, 3, 3) with the same C = {n}")));
    }
    if let Some(j) = c_sb.iter().position(|c| c.shape() != (3, 3)) {
        return Err(crate::error::invalid_at("c_sb", j, "expected a 3 × 3 rotation per channel"));
    }
    // each c_sb is 3 × 3 (checked above): its 9 column-major values
    Ok((k.iter().zip(lever).zip(c_sb).zip(v0))
        .map(|(((&k, &lever), c), &v0)| Channel { k, lever, c_sb: Mat3::from_iterator(c.iter().copied()), v0 })
        .collect())
}

/// Settings shared by all shots of a record.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PredictorConfig {
    /// Pulse separation T (s).
    pub t_sep: f64,
    /// RK4 steps per grid interval (≥ 1).
    pub substeps: usize,
    /// Gravity-gradient tensor Γ_b0 in the body frame b at each shot's start (1/s²), turned
    /// into each channel's frame by C_sb and with the body during the shot; None = no
    /// gradient.
    pub gradient: Option<Mat3>,
    /// Estimated accelerometer bias (m/s²) subtracted from the specific force.
    pub bias_a: Vec3,
    /// Estimated gyro bias (rad/s) subtracted from the angular rate.
    pub bias_g: Vec3,
    pub omega_dot: OmegaDot,
    #[serde(with = "crate::options::by_name")]
    pub interpolation: Interpolation,
}

/// The IMU record: time (s), specific force f_b (m/s²), angular rate ω_b (rad/s).
#[derive(Clone, Copy, Debug)]
pub struct Imu<'a> {
    pub t: &'a [f64],
    pub f: &'a [Vec3],
    pub w: &'a [Vec3],
}

/// Column order of [`predict`]'s output.
pub const TERM_NAMES: [&str; 7] = ["total", "acc", "rot", "cen", "eul", "mix", "gg"];
/// Column order of [`jacobian`]'s output: ∂φ/∂(b_a, b_g, l, γ), γ = small rotation with
/// C_sb = exp(−[γ×]) C_sb,0.
pub const JACOBIAN_PARAMS: [&str; 12] =
    ["ba_x", "ba_y", "ba_z", "bg_x", "bg_y", "bg_z", "l_x", "l_y", "l_z", "gamma_x", "gamma_y", "gamma_z"];

/// Body-frame inputs at one RK4 stage.
#[derive(Clone, Copy)]
struct BodyStage {
    tau: f64,
    f: Vec3,
    w: Vec3,
    wd: Vec3,
    /// Attitude R = C_b0b relative to the body at the shot start.
    att: Mat3,
}

/// Sensor-frame quantities of one channel at one stage.
#[derive(Clone, Copy)]
struct ChStage {
    tau: f64,
    /// ω_b (body frame), for the attitude tangent of the Jacobian.
    w_b: Vec3,
    w: Vec3,
    wd: Vec3,
    f_acc: Vec3,
    f_cen: Vec3,
    f_eul: Vec3,
    /// Γ_b = Rᵀ Γ_b0 R (body frame) and Γ_s = C_sb Γ_b C_bs at this stage; zero without a
    /// gradient.
    g_b: Mat3,
    g_s: Mat3,
    /// −C_sb Γ_b l (gravity gradient acting over the lever arm).
    f_gl: Vec3,
}

impl ChStage {
    fn new(b: &BodyStage, ch: &Channel, gradient: Option<&Mat3>) -> Self {
        let c = &ch.c_sb;
        let l = &ch.lever;
        let g_b = gradient.map_or(Mat3::zeros(), |g| b.att.transpose() * g * b.att);
        ChStage {
            tau: b.tau,
            w_b: b.w,
            w: c * b.w,
            wd: c * b.wd,
            f_acc: c * b.f,
            f_cen: c * b.w.cross(&b.w.cross(l)),
            f_eul: c * b.wd.cross(l),
            g_b,
            g_s: c * g_b * c.transpose(),
            f_gl: -(c * (g_b * l)),
        }
    }
    fn f_s(&self) -> Vec3 {
        self.f_acc + self.f_cen + self.f_eul
    }
}

/// (E5) right-hand side of the atom acceleration, with the stage's gradient when `gradient`.
#[inline]
fn atom_accel(s: &ChStage, x: &Vec3, v: &Vec3, force: &Vec3, gradient: bool) -> Vec3 {
    let mut a = -force - 2.0 * s.w.cross(v) - s.w.cross(&s.w.cross(x)) - s.wd.cross(x);
    if gradient {
        a += s.g_s * x;
    }
    a
}

/// One classical RK4 step of y' = rhs(stage, y) with stages at the start, middle, end.
#[inline]
// invariant: fixed-size arrays: from_fn and the loop give i < N, the length of y and every k.
#[allow(clippy::indexing_slicing, clippy::needless_range_loop)]
fn rk4<S, const N: usize>(y: &mut [Vec3; N], h: f64, s: [&S; 3], rhs: impl Fn(&S, &[Vec3; N]) -> [Vec3; N]) {
    let axpy = |y: &[Vec3; N], a: f64, k: &[Vec3; N]| -> [Vec3; N] { std::array::from_fn(|i| y[i] + a * k[i]) };
    let k1 = rhs(s[0], y);
    let k2 = rhs(s[1], &axpy(y, 0.5 * h, &k1));
    let k3 = rhs(s[1], &axpy(y, 0.5 * h, &k2));
    let k4 = rhs(s[2], &axpy(y, h, &k3));
    // an index loop over the const N unrolls; a five-way zip did not (12 % more
    // instructions in solve_geometry)
    for i in 0..N {
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// One integration interval of a shot: [a, b] (times relative to the shot start), inside
/// IMU interval `imu`; `pulse` is true when b is the middle pulse.
#[derive(Clone, Copy, Debug)]
struct Segment {
    a: f64,
    b: f64,
    imu: usize,
    pulse: bool,
}

/// Angular acceleration samples or per-interval values in the body frame.
enum Wd {
    Zero,
    Interpolant,
    PerSample(Vec<Vec3>),
}

/// Validated record, ready for shot integration.
struct Record<'a> {
    imu: Imu<'a>,
    wd: Wd,
    interpolation: Interpolation,
    bias_a: Vec3,
    bias_g: Vec3,
    t_sep: f64,
    substeps: usize,
    /// Grid segments of each shot.
    shots: Vec<(f64, Vec<Segment>)>,
}

impl Record<'_> {
    /// Value and time derivative of the interpolant of `v` at absolute time `t` in IMU
    /// interval i.
    // invariant: prepare clamps seg.imu (= i) to [0, n − 2] and makes every series n
    // long, so i, i + 1, a, b < n.
    #[allow(clippy::indexing_slicing)]
    fn interp(&self, v: &[Vec3], i: usize, t: f64) -> (Vec3, Vec3) {
        let ts = self.imu.t;
        let h = ts[i + 1] - ts[i];
        let s = ((t - ts[i]) / h).clamp(0.0, 1.0);
        match self.interpolation {
            Interpolation::Linear => (v[i] + s * (v[i + 1] - v[i]), (v[i + 1] - v[i]) / h),
            Interpolation::Cubic => {
                let n = ts.len();
                let tangent = |j: usize| {
                    let (a, b) = (j.saturating_sub(1), (j + 1).min(n - 1));
                    (v[b] - v[a]) / (ts[b] - ts[a])
                };
                let (m0, m1) = (tangent(i) * h, tangent(i + 1) * h);
                let (s2, s3) = (s * s, s * s * s);
                let val = (2.0 * s3 - 3.0 * s2 + 1.0) * v[i] + (s3 - 2.0 * s2 + s) * m0 + (3.0 * s2 - 2.0 * s3) * v[i + 1] + (s3 - s2) * m1;
                let der = ((6.0 * s2 - 6.0 * s) * v[i] + (3.0 * s2 - 4.0 * s + 1.0) * m0 + (6.0 * s - 6.0 * s2) * v[i + 1]
                    + (3.0 * s2 - 2.0 * s) * m1)
                    / h;
                (val, der)
            }
        }
    }

    fn body(&self, ts: f64, seg: &Segment, t: f64) -> BodyStage {
        let i = seg.imu;
        let abs_t = ts + t;
        let (f, _) = self.interp(self.imu.f, i, abs_t);
        let (w, w_rate) = self.interp(self.imu.w, i, abs_t);
        let wd = match &self.wd {
            Wd::Zero => Vec3::zeros(),
            Wd::Interpolant => w_rate,
            Wd::PerSample(v) => self.interp(v, i, abs_t).0,
        };
        BodyStage { tau: t, f: f - self.bias_a, w: w - self.bias_g, wd, att: Mat3::identity() }
    }

    /// The three RK4 stage inputs of each sub-step of each segment of a shot, with the
    /// body attitude R = C_b0b carried along: over a sub-step the rotation vector is
    /// α1 + α2 + ⅔ α1×α2 (trapezoid increments of ω_b on the two halves, two-sample coning
    /// correction), R(mid) = R(a) exp([α1×]).
    fn stages(&self, shot: usize) -> Vec<([BodyStage; 3], bool)> {
        let Some((ts, segs)) = self.shots.get(shot) else { return Vec::new() };
        let mut out = Vec::with_capacity(segs.len() * self.substeps);
        let mut att = Mat3::identity();
        for seg in segs {
            let h = (seg.b - seg.a) / self.substeps as f64;
            for j in 0..self.substeps {
                let a = seg.a + j as f64 * h;
                let b = if j + 1 == self.substeps { seg.b } else { a + h };
                let (mut s0, mut s1, mut s2) = (self.body(*ts, seg, a), self.body(*ts, seg, 0.5 * (a + b)), self.body(*ts, seg, b));
                let half = 0.25 * (b - a);
                let (a1, a2) = (half * (s0.w + s1.w), half * (s1.w + s2.w));
                s0.att = att;
                s1.att = att * dcm_from_rotvec(&a1);
                att *= dcm_from_rotvec(&(a1 + a2 + 2.0 / 3.0 * a1.cross(&a2)));
                s2.att = att;
                out.push(([s0, s1, s2], seg.pulse && j + 1 == self.substeps));
            }
        }
        out
    }

    /// Triangle weight w(τ) of (E4): τ on [0, T], 2T − τ on [T, 2T].
    fn weight(&self, tau: f64) -> f64 {
        if tau <= self.t_sep { tau } else { 2.0 * self.t_sep - tau }
    }
}

fn check_channels(channels: &[Channel]) -> Result<()> {
    if channels.is_empty() {
        return Err(invalid("channels", "at least one interferometer channel is required"));
    }
    for (j, ch) in channels.iter().enumerate() {
        for (name, v) in [("k", &ch.k), ("lever", &ch.lever), ("v0", &ch.v0)] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(invalid(&format!("channels[{j}].{name}"), "non-finite value"));
            }
        }
        if ch.k.norm() == 0.0 {
            return Err(invalid(&format!("channels[{j}].k"), "zero wave vector (k must be non-zero)"));
        }
        if ch.c_sb.iter().any(|x| !x.is_finite()) {
            return Err(invalid(&format!("channels[{j}].c_sb"), "non-finite value"));
        }
        crate::math::check_rotation(&format!("channels[{j}].c_sb"), 0, &ch.c_sb)?;
    }
    Ok(())
}

/// NaN/inf in an IMU series: name the field, the sample index and the shot that uses it.
fn check_series(field: &str, v: &[Vec3], t: &[f64], shots: &[f64], t_sep: f64) -> Result<()> {
    if let Some((i, (vi, &ti))) = v.iter().zip(t).enumerate().find(|(_, (x, _))| x.iter().any(|c| !c.is_finite())) {
        // the shot containing the sample, else one whose interpolation/derivative stencil may
        // reach it
        let shot = shots
            .iter()
            .position(|&s| ti >= s && ti <= s + 2.0 * t_sep)
            .or_else(|| shots.iter().position(|&s| ti >= s - t_sep && ti <= s + 3.0 * t_sep));
        let where_ = shot.map_or(String::from("outside every shot"), |s| format!("used by shot {s}"));
        return Err(invalid(field, format!("non-finite value {:?} at index {i} (t = {ti} s, {where_})", [vi.x, vi.y, vi.z])));
    }
    Ok(())
}

// invariant: n ≥ 2m + 1 (checked above), c ∈ [m, n − 1 − m] and j ≤ m, so c ± j and
// c ± m are in [0, n); w has n samples like t (checked by prepare).
#[allow(clippy::indexing_slicing)]
fn savgol(t: &[f64], w: &[Vec3], m: usize) -> Result<Vec<Vec3>> {
    if m == 0 {
        return Err(invalid("omega_dot", "Savitzky-Golay half width must be >= 1"));
    }
    let n = t.len();
    if m >= n / 2 + n % 2 {
        // n < 2m + 1, written so that no m overflows
        return Err(invalid("omega_dot", format!("Savitzky-Golay window of 2·{m} + 1 samples needs at least as many IMU samples, got {n}")));
    }
    let s2: f64 = (1..=m).map(|j| 2.0 * (j * j) as f64).sum();
    Ok((0..n)
        .map(|k| {
            let c = k.clamp(m, n - 1 - m);
            let dt = (t[c + m] - t[c - m]) / (2 * m) as f64;
            let num = (1..=m).fold(Vec3::zeros(), |acc, j| acc + j as f64 * (w[c + j] - w[c - j]));
            num / (s2 * dt)
        })
        .collect())
}

/// Validate everything and build the per-shot integration grids.
fn prepare<'a>(imu: Imu<'a>, shots: &[f64], channels: &[Channel], cfg: &PredictorConfig) -> Result<Record<'a>> {
    check_positive("T", cfg.t_sep)?;
    // the stage buffer holds substeps per grid interval: bounded before it is allocated
    crate::error::check_count("substeps", cfg.substeps, 1, MAX_SUBSTEPS)?;
    let n = imu.t.len();
    if n < 2 {
        return Err(invalid("t", format!("need at least 2 IMU samples, got {n}")));
    }
    if imu.f.len() != n || imu.w.len() != n {
        return Err(invalid("specific_force", format!("length {} / angular_rate length {} differ from t length {n}", imu.f.len(), imu.w.len())));
    }
    check_increasing("t", imu.t)?;
    check_finite("shots", shots, 1)?;
    check_channels(channels)?;
    for (name, v) in [("bias_a", &cfg.bias_a), ("bias_g", &cfg.bias_g)] {
        check_finite(name, v.as_slice(), 3)?;
    }
    if let Some(g) = &cfg.gradient {
        check_finite("gradient", g.as_slice(), 3)?;
    }
    let t_sep = cfg.t_sep;
    let &[t_first, .., t_last] = imu.t else {
        return Err(invalid("t", format!("need at least 2 IMU samples, got {n}")));
    };
    let eps = 1e-9 * t_sep;
    let mut prev: Option<f64> = None;
    for (s, &ts) in shots.iter().enumerate() {
        if ts < t_first - eps || ts + 2.0 * t_sep > t_last + eps {
            return Err(invalid(
                "shots",
                format!("shot {s}: pulse times [{ts}, {}] s outside the IMU record [{t_first}, {t_last}] s", ts + 2.0 * t_sep),
            ));
        }
        if let Some(p) = prev.filter(|&p| ts < p + 2.0 * t_sep - eps) {
            return Err(invalid("shots", format!("shot {s} starts at {ts} s, before shot {} ends at {} s (shots must not overlap)", s - 1, p + 2.0 * t_sep)));
        }
        prev = Some(ts);
    }
    check_series("specific_force", imu.f, imu.t, shots, t_sep)?;
    check_series("angular_rate", imu.w, imu.t, shots, t_sep)?;
    let wd = match &cfg.omega_dot {
        OmegaDot::Zero => Wd::Zero,
        OmegaDot::Pwl => Wd::Interpolant,
        OmegaDot::Savgol { half_width } => Wd::PerSample(savgol(imu.t, imu.w, *half_width)?),
        OmegaDot::Given(v) => {
            if v.len() != n {
                return Err(invalid("angular_acceleration", format!("length {} differs from t length {n}", v.len())));
            }
            check_series("angular_acceleration", v, imu.t, shots, t_sep)?;
            Wd::PerSample(v.clone())
        }
    };
    let shots = shots
        .iter()
        .map(|&ts| {
            let mut knots: Vec<(f64, bool)> = vec![(0.0, false), (t_sep, true), (2.0 * t_sep, false)];
            let i0 = imu.t.partition_point(|&x| x <= ts);
            for &ti in imu.t.get(i0..).unwrap_or_default() {
                let tau = ti - ts;
                if tau >= 2.0 * t_sep {
                    break;
                }
                if (tau - t_sep).abs() > eps && tau > eps && 2.0 * t_sep - tau > eps {
                    knots.push((tau, false));
                }
            }
            knots.sort_by(|a, b| a.0.total_cmp(&b.0));
            let segs = knots
                .windows(2)
                .filter_map(|w| {
                    let &[(a, _), (b, pulse)] = w else { return None };
                    let mid = ts + 0.5 * (a + b);
                    let imu_i = imu.t.partition_point(|&x| x <= mid).clamp(1, n - 1) - 1;
                    Some(Segment { a, b, imu: imu_i, pulse })
                })
                .collect();
            (ts, segs)
        })
        .collect();
    Ok(Record { imu, wd, interpolation: cfg.interpolation, bias_a: cfg.bias_a, bias_g: cfg.bias_g, t_sep, substeps: cfg.substeps, shots })
}

/// Per-shot solutions shared by all channels with the same (C_sb, l): the solution of the
/// linear ODE (E5) is x = Φ(t) v0 + x_p(t), so the transition block Φ (homogeneous
/// solutions for v0 = e_1, e_2, e_3) and the forced solution x_p serve every k and v0.
struct GeometrySolution {
    /// x(T) and x(2T) of [Φ e_1, Φ e_2, Φ e_3, x_p], Γ = 0.
    mid: [Vec3; 4],
    end: [Vec3; 4],
    /// The same with the gravity gradient (when given).
    mid_g: [Vec3; 4],
    end_g: [Vec3; 4],
    /// −∫ w f dτ of the acceleration, centrifugal and Euler forces (vectors; dot with k).
    acc: Vec3,
    cen: Vec3,
    eul: Vec3,
}

/// Right-hand side for [Φ e_1, Φ e_2, Φ e_3, x_p] and their velocities (8 vectors).
// invariant: fixed-size arrays of 8 vectors indexed by 2c, 2c + 1 with c < 4.
#[allow(clippy::indexing_slicing)]
fn block_rhs(s: &ChStage, y: &[Vec3; 8], force: &Vec3, gradient: bool) -> [Vec3; 8] {
    let zero = Vec3::zeros();
    let mut d = [zero; 8];
    for c in 0..4 {
        let f = if c == 3 { force } else { &zero };
        d[2 * c] = y[2 * c + 1];
        d[2 * c + 1] = atom_accel(s, &y[2 * c], &y[2 * c + 1], f, gradient);
    }
    d
}

fn solve_geometry(rec: &Record, stages: &[([BodyStage; 3], bool)], ch: &Channel, gradient: Option<&Mat3>) -> GeometrySolution {
    let zero = Vec3::zeros();
    let init = [zero, Vec3::x(), zero, Vec3::y(), zero, Vec3::z(), zero, zero];
    let (mut y, mut yg) = (init, init);
    let (mut mid, mut mid_g) = (init, init);
    let (mut acc, mut cen, mut eul) = (zero, zero, zero);
    for (st, pulse) in stages {
        let cs = st.each_ref().map(|b| ChStage::new(b, ch, gradient));
        let h = cs[2].tau - cs[0].tau;
        // Simpson's rule for (E12)–(E14), −∫ w f dτ (exact for the piecewise-polynomial
        // integrands of linear inputs).
        for (c, s) in cs.iter().zip([1.0, 4.0, 1.0]) {
            let wk = -h / 6.0 * s * rec.weight(c.tau);
            acc += wk * c.f_acc;
            cen += wk * c.f_cen;
            eul += wk * c.f_eul;
        }
        let refs = [&cs[0], &cs[1], &cs[2]];
        rk4(&mut y, h, refs, |s, y| block_rhs(s, y, &s.f_s(), false));
        if gradient.is_some() {
            rk4(&mut yg, h, refs, |s, y| block_rhs(s, y, &(s.f_s() + s.f_gl), true));
        }
        if *pulse {
            (mid, mid_g) = (y, yg);
        }
    }
    let pos = |y: &[Vec3; 8]| [y[0], y[2], y[4], y[6]];
    GeometrySolution { mid: pos(&mid), end: pos(&y), mid_g: pos(&mid_g), end_g: pos(&yg), acc, cen, eul }
}

/// Phase of one channel with its breakdown, in the order of [`TERM_NAMES`].
// invariant: fixed-size arrays of 4 vectors indexed by c < 4, Vec3 by c < 3.
#[allow(clippy::indexing_slicing)]
fn channel_phase(g: &GeometrySolution, ch: &Channel, gradient: bool) -> [f64; 7] {
    // φ = k·D[x] with x(0) = 0 (E4), x = Φ v0 + x_p.
    let d = |mid: &[Vec3; 4], end: &[Vec3; 4], c: usize| ch.k.dot(&(end[c] - 2.0 * mid[c]));
    let hom = |mid: &[Vec3; 4], end: &[Vec3; 4]| (0..3).map(|c| ch.v0[c] * d(mid, end, c)).sum::<f64>();
    let rot = hom(&g.mid, &g.end);
    let forced = d(&g.mid, &g.end, 3);
    let (acc, cen, eul) = (ch.k.dot(&g.acc), ch.k.dot(&g.cen), ch.k.dot(&g.eul));
    let no_grad = rot + forced;
    let (total, gg) = if gradient {
        let full = hom(&g.mid_g, &g.end_g) + d(&g.mid_g, &g.end_g, 3);
        (full, full - no_grad)
    } else {
        (no_grad, 0.0)
    };
    [total, acc, rot, cen, eul, forced - acc - cen - eul, gg]
}

/// Predicted phase (rad) of every shot and channel with its breakdown: row
/// `shot * channels.len() + channel`, columns [`TERM_NAMES`].
pub fn predict(imu: Imu, shots: &[f64], channels: &[Channel], cfg: &PredictorConfig) -> Result<Vec<[f64; 7]>> {
    let rec = prepare(imu, shots, channels, cfg)?;
    // channels with identical (C_sb, l) share one GeometrySolution
    let mut reps: Vec<&Channel> = Vec::new();
    let mut group = Vec::with_capacity(channels.len());
    for ch in channels {
        match reps.iter().position(|r| r.c_sb == ch.c_sb && r.lever == ch.lever) {
            Some(g) => group.push(g),
            None => {
                reps.push(ch);
                group.push(reps.len() - 1);
            }
        }
    }
    let grad = cfg.gradient.as_ref();
    let mut out = Vec::with_capacity(shots.len() * channels.len());
    for s in 0..shots.len() {
        let stages = rec.stages(s);
        let sols: Vec<GeometrySolution> = reps.iter().map(|r| solve_geometry(&rec, &stages, r, grad)).collect();
        // group[j] < reps.len() = sols.len() by construction
        for (ch, sol) in channels.iter().zip(&group).filter_map(|(ch, &g)| Some((ch, sols.get(g)?))) {
            out.push(channel_phase(sol, ch, grad.is_some()));
        }
    }
    check_rows(&out)?;
    Ok(out)
}

/// A-priori bound of the discretisation error of [`predict`] per row (shot × channel),
/// estimated from the samples around each shot (docs/cai_predictor_accuracy.md). Its parts
/// scale differently with the sample interval h: the interpolation error as h^p (p = 2
/// linear, 4 cubic), the Savitzky–Golay ω̇ error as h², the omitted Euler terms
/// (`OmegaDot::Zero`) not at all.
#[derive(Clone, Debug)]
pub struct ErrorBound {
    /// [∝ h^p, ∝ h², fixed] (rad) per row.
    parts: Vec<[f64; 3]>,
    order: i32,
    /// 1/h of the largest sample interval h around any shot (Hz).
    pub rate_hz: f64,
}

/// Margin between the tolerance and the bound at the advised rate: the sampled derivative
/// estimates change slightly with the rate (by ≈ (hν)²/6 for a sine of angular frequency ν).
const RATE_MARGIN: f64 = 1.05;

impl ErrorBound {
    /// The bound (rad) of each row; infinite where the record holds fewer samples around the
    /// shot than the estimate needs (p + 2).
    pub fn rad(&self) -> Vec<f64> {
        self.parts.iter().map(|p| p.iter().sum()).collect()
    }

    /// The largest bound (rad) at the sample intervals scaled by r.
    fn at(&self, r: f64) -> f64 {
        self.parts.iter().map(|&[a, b, c]| a * r.powi(self.order) + b * r * r + c).fold(0.0, f64::max)
    }

    /// The lowest IMU rate (Hz, rounded up to two significant digits) at which the bound is
    /// below `tolerance` (rad) by the margin 1.05, the record's rate if it already is; None
    /// when no rate reaches it (the Euler terms are omitted, or the bound is infinite).
    pub fn rate_needed(&self, tolerance: f64) -> Result<Option<f64>> {
        check_positive("tolerance_rad", tolerance)?;
        let target = tolerance / RATE_MARGIN;
        if self.at(0.0) >= target || !self.rate_hz.is_finite() {
            return Ok(None);
        }
        if self.at(1.0) <= target {
            return Ok(Some(self.rate_hz));
        }
        // at(r) increases with r; at(0) < target < at(1): bisection on r = h'/h
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if self.at(mid) <= target { lo = mid } else { hi = mid }
        }
        let rate = self.rate_hz / lo;
        let unit = 10f64.powf(rate.log10().floor() - 1.0);
        Ok(Some((rate / unit).ceil() * unit))
    }
}

/// Largest norm of p! times the p-th divided difference of `g` over the times `t` (an
/// estimate of max |g⁽ᵖ⁾|); None with fewer than p + 1 samples.
fn max_derivative(t: &[f64], g: &[Vec3], p: usize) -> Option<f64> {
    if g.len() <= p {
        return None;
    }
    let mut d = g.to_vec();
    for q in 1..=p {
        d = d.windows(2).zip(t.windows(q + 1)).map(|(v, s)| match (v, s) {
            ([a, b], [t0, .., t1]) => (b - a) / (t1 - t0),
            _ => Vec3::zeros(),
        }).collect();
    }
    let fact: f64 = (1..=p).map(|j| j as f64).product();
    Some(fact * d.iter().map(|v| v.norm()).fold(0.0, f64::max))
}

/// Central differences of ω (one-sided at the ends): the tangents of the cubic
/// interpolant, a sample of the derivative of the gyro interpolant.
fn central_differences(t: &[f64], w: &[Vec3]) -> Vec<Vec3> {
    let n = t.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n.saturating_sub(1)));
            match (t.get(a), t.get(b), w.get(a), w.get(b)) {
                (Some(ta), Some(tb), Some(wa), Some(wb)) if tb > ta => (wb - wa) / (tb - ta),
                _ => Vec3::zeros(),
            }
        })
        .collect()
}

/// A-priori bound of the discretisation error of [`predict`] with the same inputs
/// (docs/cai_predictor_accuracy.md#the-bound). Per shot, from the samples whose
/// interpolation stencils reach into it (interval h, the largest there), with
/// F = f_b + ω̇*×l + ω_b×(ω_b×l) (ω̇* the ω̇ series the predictor interpolates),
/// V = |v0| + 2T max|F|, X = 2T V, Ω = max|ω_b| and D_p(g) ≈ max|g⁽ᵖ⁾| from divided
/// differences:
///   interpolation   |k| T² c_p h^p [D_p(F) + 2V D_p(ω) + X (D_p(ω̇*) + 2Ω D_p(ω))],
///   Savitzky–Golay  |k| T² (|l| + X) h² D_3(ω) Σj⁴ / (6 Σj²),
///   ω̇ omitted       |k| T² (|l| + X) max|ω̇|,
/// c_2 = 1/12 (linear), c_4 = 11/720 (cubic).
// invariant: i0 ≤ i1 < n (clamped), so the window slices are in range.
#[allow(clippy::indexing_slicing)]
pub fn error_bound(imu: Imu, shots: &[f64], channels: &[Channel], cfg: &PredictorConfig) -> Result<ErrorBound> {
    let rec = prepare(imu, shots, channels, cfg)?;
    let (p, c_p) = cfg.interpolation.error_order();
    let n = imu.t.len();
    let t_sep = cfg.t_sep;
    let mut parts = Vec::with_capacity(shots.len() * channels.len());
    let mut h_max: f64 = 0.0;
    for &ts in shots {
        // the intervals holding the shot, one stencil sample either side, widened to p + 2
        // samples where the record allows
        let mut i0 = imu.t.partition_point(|&x| x <= ts).saturating_sub(2);
        let mut i1 = imu.t.partition_point(|&x| x < ts + 2.0 * t_sep).saturating_add(1).min(n - 1);
        while i1 - i0 < p + 1 && (i0 > 0 || i1 + 1 < n) {
            i0 = i0.saturating_sub(1);
            i1 = (i1 + 1).min(n - 1);
        }
        let t = &imu.t[i0..=i1];
        let h = t.windows(2).map(|w| match w { [a, b] => b - a, _ => 0.0 }).fold(0.0, f64::max);
        h_max = h_max.max(h);
        let w: Vec<Vec3> = imu.w[i0..=i1].iter().map(|w| w - rec.bias_g).collect();
        let f: Vec<Vec3> = imu.f[i0..=i1].iter().map(|f| f - rec.bias_a).collect();
        // central differences with the record's neighbours of the window (one-sided only at
        // the record's ends, as the interpolant's tangents)
        let (a, b) = (i0.saturating_sub(1), (i1 + 1).min(n - 1));
        let wide: Vec<Vec3> = imu.w[a..=b].iter().map(|w| w - rec.bias_g).collect();
        let wd_cd = central_differences(&imu.t[a..=b], &wide)[i0 - a..=i1 - a].to_vec();
        let (wd, savgol_part, omitted) = match (&rec.wd, &cfg.omega_dot) {
            (Wd::PerSample(v), OmegaDot::Savgol { half_width }) => {
                let m = *half_width as f64;
                // Σ_{j=1..m} j⁴ / Σ j² = (3m² + 3m − 1)/5
                let coef = (3.0 * m * m + 3.0 * m - 1.0) / 30.0;
                (v[i0..=i1].to_vec(), max_derivative(t, &w, 3).map(|d| coef * h * h * d), 0.0)
            }
            (Wd::PerSample(v), _) => (v[i0..=i1].to_vec(), Some(0.0), 0.0),
            (Wd::Interpolant, _) => (wd_cd, Some(0.0), 0.0),
            (Wd::Zero, _) => {
                let most = wd_cd.iter().map(|v| v.norm()).fold(0.0, f64::max);
                (vec![Vec3::zeros(); t.len()], Some(0.0), most)
            }
        };
        let omega = w.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let d_w = max_derivative(t, &w, p);
        let d_wd = max_derivative(t, &wd, p);
        for ch in channels {
            let l = &ch.lever;
            let force: Vec<Vec3> = f.iter().zip(&w).zip(&wd).map(|((f, w), wd)| f + wd.cross(l) + w.cross(&w.cross(l))).collect();
            let big_f = force.iter().map(|v| v.norm()).fold(0.0, f64::max);
            let speed = ch.v0.norm() + 2.0 * t_sep * big_f;
            let reach = 2.0 * t_sep * speed;
            let scale = ch.k.norm() * t_sep * t_sep;
            let row = match (max_derivative(t, &force, p), d_w, d_wd, savgol_part) {
                (Some(d_f), Some(d_w), Some(d_wd), Some(sg)) => [
                    scale * c_p * h.powi(p as i32) * (d_f + 2.0 * speed * d_w + reach * (d_wd + 2.0 * omega * d_w)),
                    scale * (l.norm() + reach) * sg,
                    scale * (l.norm() + reach) * omitted,
                ],
                _ => [f64::INFINITY, 0.0, 0.0],
            };
            parts.push(row);
        }
    }
    Ok(ErrorBound { parts, order: p as i32, rate_hz: 1.0 / h_max })
}

/// Finite inputs near the f64 range can overflow on the way: an error, not a NaN row.
fn check_rows<const W: usize>(rows: &[[f64; W]]) -> Result<()> {
    match rows.iter().position(|r| !r.iter().all(|v| v.is_finite())) {
        Some(i) => Err(crate::NavError::Numerical(format!("output row {i} (shot × channel) is not finite: the inputs overflow the floating-point range"))),
        None => Ok(()),
    }
}

/// Per-stage sensitivities of (ω_s, ω̇_s, forcing F, Γ_s) to the 12 Jacobian parameters
/// (the gyro bias also turns Γ through the attitude: see [`jacobian`]).
struct Tangent {
    dw: [Vec3; 12],
    dwd: [Vec3; 12],
    df: [Vec3; 12],
    dg: [Mat3; 12],
}

/// δΓ = −[θ×]Γ + Γ[θ×] of Γ seen from a frame turned by the small rotation θ.
fn turned(g: &Mat3, theta: &Vec3) -> Mat3 {
    let k = skew(theta);
    g * k - k * g
}

// invariant: fixed-size arrays of 12 vectors indexed by j, 3 + j, 6 + j, 9 + j with j < 3.
#[allow(clippy::indexing_slicing)]
fn tangent(b: &BodyStage, s: &ChStage, ch: &Channel, gradient: bool) -> Tangent {
    let c = &ch.c_sb;
    let l = &ch.lever;
    let zero = Vec3::zeros();
    let mut t = Tangent { dw: [zero; 12], dwd: [zero; 12], df: [zero; 12], dg: [Mat3::zeros(); 12] };
    let f_body_lever = s.f_s(); // C_sb (f_b + ω̇×l + ω×(ω×l))
    for j in 0..3 {
        let e = Vec3::ith(j, 1.0);
        // b_a: f_b → f_b − b_a.
        t.df[j] = -(c * e);
        // b_g: ω_b → ω_b − b_g (ω̇ derived from the gyro is bias-free).
        let dwb = -e;
        t.dw[3 + j] = c * dwb;
        t.df[3 + j] = c * (dwb.cross(&b.w.cross(l)) + b.w.cross(&dwb.cross(l)));
        // lever arm.
        t.df[6 + j] = c * (b.wd.cross(&e) + b.w.cross(&b.w.cross(&e))) - s.g_s * (c * e);
        // misalignment: δC_sb = −[e×] C_sb turns every sensor-frame vector and Γ_s.
        t.dw[9 + j] = -e.cross(&s.w);
        t.dwd[9 + j] = -e.cross(&s.wd);
        t.df[9 + j] = -e.cross(&(f_body_lever + s.f_gl));
        if gradient {
            t.dg[9 + j] = turned(&s.g_s, &e);
        }
    }
    t
}

/// Tangent-linear (forward-mode) derivative of the predicted phase with respect to
/// [`JACOBIAN_PARAMS`] (b_a, b_g, l, γ) at the configured estimates: row
/// `shot * channels.len() + channel`. Euler terms (ω̇) are removed from the linearisation
/// point unless `euler` (the paper's Eq. 31 item 8;
/// docs/departures.md#euler-terms-and-angular-acceleration); use [`jacobian_fd`] to check.
// invariant: fixed-size arrays: y holds 29 = 2 + 2·12 + 3 vectors indexed by 2 + 2p and
// 3 + 2p (p < 12), 26 + j (j < 3) or 2p (p < 13), mid 13, the stage arrays 3 (i < 3).
#[allow(clippy::indexing_slicing)]
pub fn jacobian(imu: Imu, shots: &[f64], channels: &[Channel], cfg: &PredictorConfig, euler: bool) -> Result<Vec<[f64; 12]>> {
    let cfg = jacobian_config(cfg, euler);
    let rec = prepare(imu, shots, channels, &cfg)?;
    let grad = cfg.gradient.as_ref();
    let with_grad = grad.is_some();
    let mut out = Vec::with_capacity(shots.len() * channels.len());
    for s in 0..shots.len() {
        let stages = rec.stages(s);
        for ch in channels {
            // y[0..2] = base (x, v); y[2+2p..4+2p] = tangent (δx, δv) of parameter p;
            // y[26 + j] = δθ, the attitude tangent R → R exp([δθ×]) of the gyro bias j,
            // δθ̇ = δω_b − ω_b × δθ with δω_b = −e_j: it turns Γ_b by δΓ_b = Γ_b[δθ×] − [δθ×]Γ_b.
            let mut y = [Vec3::zeros(); 29];
            y[1] = ch.v0;
            let mut mid = [Vec3::zeros(); 13];
            for (st, pulse) in &stages {
                let cs = [0, 1, 2].map(|i| ChStage::new(&st[i], ch, grad));
                let tg = [0, 1, 2].map(|i| tangent(&st[i], &cs[i], ch, with_grad));
                let h = cs[2].tau - cs[0].tau;
                let pairs = [(&cs[0], &tg[0]), (&cs[1], &tg[1]), (&cs[2], &tg[2])];
                rk4(&mut y, h, [&pairs[0], &pairs[1], &pairs[2]], |(s, tg), y| {
                    let (x, v) = (y[0], y[1]);
                    let force = s.f_s() + s.f_gl;
                    let mut d = [Vec3::zeros(); 29];
                    d[0] = v;
                    d[1] = atom_accel(s, &x, &v, &force, with_grad);
                    for p in 0..12 {
                        let (dx, dv) = (y[2 + 2 * p], y[3 + 2 * p]);
                        let (dw, dwd) = (tg.dw[p], tg.dwd[p]);
                        d[2 + 2 * p] = dv;
                        // δ of (E5): linear part on (δx, δv) plus the input perturbation.
                        d[3 + 2 * p] = atom_accel(s, &dx, &dv, &tg.df[p], with_grad)
                            - 2.0 * dw.cross(&v)
                            - dw.cross(&s.w.cross(&x))
                            - s.w.cross(&dw.cross(&x))
                            - dwd.cross(&x)
                            + tg.dg[p] * x;
                    }
                    if with_grad {
                        let c = &ch.c_sb;
                        for j in 0..3 {
                            let theta = y[26 + j];
                            d[26 + j] = -Vec3::ith(j, 1.0) - s.w_b.cross(&theta);
                            let dg_b = turned(&s.g_b, &theta);
                            // a = −(f_s + f_gl) + Γ_s x with f_gl = −C_sb Γ_b l, Γ_s = C_sb Γ_b C_bs
                            d[3 + 2 * (3 + j)] += c * (dg_b * (c.transpose() * x + ch.lever));
                        }
                    }
                    d
                });
                if *pulse {
                    for p in 0..13 {
                        mid[p] = y[2 * p];
                    }
                }
            }
            out.push(std::array::from_fn(|p| ch.k.dot(&(y[2 + 2 * p] - 2.0 * mid[1 + p]))));
        }
    }
    check_rows(&out)?;
    Ok(out)
}

fn jacobian_config(cfg: &PredictorConfig, euler: bool) -> PredictorConfig {
    let mut c = cfg.clone();
    if !euler {
        c.omega_dot = OmegaDot::Zero;
    }
    c
}

/// Central finite differences of the predicted total phase with respect to
/// [`JACOBIAN_PARAMS`], with steps `step_a` (m/s²), `step_g` (rad/s), `step_l` (m) and
/// `step_gamma` (rad); same linearisation point and Euler switch as [`jacobian`].
// invariant: p < 12 indexes the 12 columns of a row and p / 3 < 4 the 4 steps;
// plus, minus and out have one row per (shot, channel), r < out.len().
#[allow(clippy::indexing_slicing)]
pub fn jacobian_fd(
    imu: Imu,
    shots: &[f64],
    channels: &[Channel],
    cfg: &PredictorConfig,
    euler: bool,
    steps: [f64; 4],
) -> Result<Vec<[f64; 12]>> {
    for (name, s) in ["step_a", "step_g", "step_l", "step_gamma"].iter().zip(steps) {
        check_positive(name, s)?;
    }
    let base = jacobian_config(cfg, euler);
    let nch = channels.len();
    let mut out = vec![[0.0; 12]; shots.len() * nch];
    for p in 0..12 {
        let (group, axis) = (p / 3, p % 3);
        let h = steps[group];
        let phase = |sign: f64| -> Result<Vec<[f64; 7]>> {
            let d = Vec3::ith(axis, sign * h);
            let mut c = base.clone();
            let mut chs = channels.to_vec();
            match group {
                0 => c.bias_a += d,
                1 => c.bias_g += d,
                2 => chs.iter_mut().for_each(|ch| ch.lever += d),
                _ => chs.iter_mut().for_each(|ch| ch.c_sb = dcm_from_rotvec(&-d) * ch.c_sb),
            }
            predict(imu, shots, &chs, &c)
        };
        let (plus, minus) = (phase(1.0)?, phase(-1.0)?);
        for r in 0..out.len() {
            out[r][p] = (plus[r][0] - minus[r][0]) / (2.0 * h);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::dcm_from_euler;

    /// Analytic tangent-linear Jacobian vs central differences, with lever arm,
    /// misalignment, time-varying rate and gradient; Euler terms off and on.
    #[test]
    fn jacobian_matches_finite_differences() {
        let t: Vec<f64> = (0..=120).map(|i| i as f64 * 1e-3).collect();
        let f: Vec<Vec3> = t.iter().map(|&s| Vec3::new(0.3 + 0.2 * (9.0 * s).sin(), -0.2, -9.81 + 0.1 * s)).collect();
        let w: Vec<Vec3> = t.iter().map(|&s| Vec3::new(0.05 + 0.3 * s, -0.03, 0.2 * (5.0 * s).cos())).collect();
        let chs: Vec<Channel> = (0..3)
            .map(|j| Channel {
                k: Vec3::ith(j, 1.610576e7),
                lever: Vec3::new(0.3, -0.1, 0.2),
                c_sb: dcm_from_euler(0.01, -0.02, 0.03),
                v0: Vec3::ith((j + 1) % 3, 2.8),
            })
            .collect();
        // Earth's gradient, and 3000 × a tensor not symmetric about any body axis (turned by
        // the misalignment and, through the attitude, by the gyro bias)
        let strong = 3e-3 * Mat3::new(-1.2, 0.4, 0.3, 0.4, -1.9, 0.2, 0.3, 0.2, 3.1);
        for (euler, gradient) in [(false, Mat3::from_diagonal(&Vec3::new(-1.5e-6, -1.5e-6, 3.086e-6))), (true, Mat3::from_diagonal(&Vec3::new(-1.5e-6, -1.5e-6, 3.086e-6))), (false, strong), (true, strong)] {
            let cfg = PredictorConfig {
                t_sep: 0.025,
                substeps: 2,
                gradient: Some(gradient),
                bias_a: Vec3::new(1e-4, -2e-4, 3e-4),
                bias_g: Vec3::new(1e-5, 2e-5, -1e-5),
                omega_dot: OmegaDot::Savgol { half_width: 2 },
                interpolation: Interpolation::Cubic,
            };
            let imu = Imu { t: &t, f: &f, w: &w };
            let shots = [0.0103, 0.0607];
            let j = jacobian(imu, &shots, &chs, &cfg, euler).unwrap();
            let fd = jacobian_fd(imu, &shots, &chs, &cfg, euler, [1e-3, 1e-4, 1e-3, 1e-4]).unwrap();
            for (r, (a, b)) in j.iter().zip(&fd).enumerate() {
                let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                for p in 0..12 {
                    assert!((a[p] - b[p]).abs() < 1e-6 * a[p].abs().max(1e-6 * scale), "euler {euler}, row {r}, {}: {} vs {}", JACOBIAN_PARAMS[p], a[p], b[p]);
                }
            }
        }
    }
}
