//! Vehicle and pedestrian constraints: automatic still detection for zero-velocity and
//! zero-angular-rate updates ([`StillDetector`], [`ZeroRateWhileStill`]), and the
//! non-holonomic constraint of a wheeled vehicle ([`NonHolonomic`]).
//!
//! Still detection (Groves 2013, ch. 15; the windowed test of Skog et al. 2010, IEEE
//! Trans. Biomed. Eng. 57(11)): a sample passes when | |f| − g | < `accel_threshold` and
//! |ω| < `gyro_threshold`; a sample is still when it lies in a window of `window`
//! consecutive passing samples, i.e. in a run of at least `window` passing samples (the
//! rule of the loosely coupled filter after Groves 2013 published in rtklibexplorer's
//! GNSS_IMU, 2025).

use super::aided::{Aiding, AidingContext, Measurement};
use super::alignment::ZeroRate;
use super::sources::Mounting;
use crate::error::{check_count, check_increasing, check_positive, invalid, invalid_at, Result};
use crate::imu::ImuKind;
use crate::math::{dcm_from_quat, skew, Vec3};
use crate::strapdown::NavState;
use nalgebra::DMatrix;

/// The still test: window (samples), thresholds on | |f| − g | (m/s²) and |ω| (rad/s),
/// and the gravity g (m/s²) of the site.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StillDetector {
    pub window: usize,
    pub accel_threshold: f64,
    pub gyro_threshold: f64,
    pub gravity: f64,
}

/// The still samples of a record and their runs (first and last sample index, inclusive,
/// of each run of still samples, in time order).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Still {
    pub still: Vec<bool>,
    pub runs: Vec<[usize; 2]>,
}

impl StillDetector {
    /// A detector: `window` ≥ 1 samples, thresholds and gravity finite and > 0 (errors
    /// name the argument).
    pub fn new(window: usize, accel_threshold: f64, gyro_threshold: f64, gravity: f64) -> Result<Self> {
        check_count("window", window, 1, usize::MAX)?;
        check_positive("accel_threshold", accel_threshold)?;
        check_positive("gyro_threshold", gyro_threshold)?;
        check_positive("gravity", gravity)?;
        Ok(StillDetector { window, accel_threshold, gyro_threshold, gravity })
    }

    /// Whether a sample of specific force `f` (m/s²) and angular rate `w` (rad/s) passes.
    fn passes(&self, w: &Vec3, f: &Vec3) -> bool {
        (f.norm() - self.gravity).abs() < self.accel_threshold && w.norm() < self.gyro_threshold
    }

    /// The still samples of the record: time (N,) s, strictly increasing; gyro and accel
    /// (N rows) of `kind`. Increments are turned into rates over their interval
    /// (t_{k−1}, t_k]; the first row's interval is taken as t_1 − t_0. Errors name `time`,
    /// `gyro` or `accel` and the row, or `window` when it is longer than the record.
    pub fn detect(&self, t: &[f64], gyro: &[Vec3], accel: &[Vec3], kind: ImuKind) -> Result<Still> {
        check_increasing("time", t)?;
        let n = t.len();
        if n < 2 {
            return Err(invalid("time", format!("need >= 2 samples, got {n}")));
        }
        for (field, rows) in [("gyro", gyro), ("accel", accel)] {
            if rows.len() != n {
                return Err(invalid(field, format!("time has {n} samples but {field} {}", rows.len())));
            }
            if let Some(i) = rows.iter().position(|r| !r.iter().all(|x| x.is_finite())) {
                return Err(invalid_at(field, i, format!("non-finite value at index {i}")));
            }
        }
        if self.window > n {
            return Err(invalid("window", format!("{} samples is longer than the record ({n} samples)", self.window)));
        }
        let first = match t {
            [a, b, ..] => b - a,
            _ => 1.0,
        };
        let dts = std::iter::once(first).chain(t.windows(2).map(|w| match w {
            [a, b] => b - a,
            _ => first,
        }));
        let pass = gyro.iter().zip(accel).zip(dts).map(|((g, a), dt)| match kind {
            ImuKind::Rates => self.passes(g, a),
            ImuKind::Increments => self.passes(&(g / dt), &(a / dt)),
        });
        let mut out = Still { still: vec![false; n], runs: Vec::new() };
        let mut start = 0;
        // a failing sample after the last one closes the last run
        for (k, p) in pass.chain(std::iter::once(false)).enumerate() {
            if p {
                continue;
            }
            if k - start >= self.window {
                if let Some(s) = out.still.get_mut(start..k) {
                    s.fill(true);
                }
                out.runs.push([start, k - 1]);
            }
            start = k + 1;
        }
        Ok(out)
    }
}

/// Zero-angular-rate updates ([`ZeroRate`]) that average the gyro only over still time:
/// a sample's interval (t − dt, t] enters the mean only when it lies inside one of the
/// still `intervals` [start, end] (s), so the first update of a still period does not
/// average the motion before it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ZeroRateWhileStill {
    rate: ZeroRate,
    intervals: Vec<[f64; 2]>,
}

impl ZeroRateWhileStill {
    /// `rate` averaging over `intervals` (finite, start ≤ end, in time order without
    /// overlap; an error names `intervals` and the row).
    pub fn new(rate: ZeroRate, intervals: Vec<[f64; 2]>) -> Result<Self> {
        let mut prev_end = f64::NEG_INFINITY;
        for (i, &[a, b]) in intervals.iter().enumerate() {
            if !(a.is_finite() && b.is_finite() && a <= b && a > prev_end) {
                return Err(invalid_at("intervals", i, format!("interval {i} [{a}, {b}] s is not finite, reversed, or not after the previous one")));
            }
            prev_end = b;
        }
        Ok(ZeroRateWhileStill { rate, intervals })
    }

    /// The same updates on a record of `kind` (see [`ZeroRate::on_record`]).
    pub fn on_record(self, kind: ImuKind) -> Self {
        ZeroRateWhileStill { rate: self.rate.on_record(kind), ..self }
    }

    /// Whether (t0, t1] lies inside a still interval.
    fn inside(&self, t0: f64, t1: f64) -> bool {
        let i = self.intervals.partition_point(|iv| iv[1] < t1);
        self.intervals.get(i).is_some_and(|iv| iv[0] <= t0 && t1 <= iv[1])
    }
}

#[typetag::serde]
impl Aiding for ZeroRateWhileStill {
    fn name(&self) -> &str {
        self.rate.name()
    }
    fn times(&self) -> &[f64] {
        self.rate.times()
    }
    fn check_times(&self) -> Result<()> {
        self.rate.check_times()
    }
    fn observe(&mut self, t: f64, dt: f64, gyro: &Vec3, accel: &Vec3, nav: &NavState) {
        if self.inside(t - dt, t) {
            self.rate.observe(t, dt, gyro, accel, nav);
        }
    }
    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        self.rate.measure(j, ctx)
    }
}

/// Non-holonomic constraint of a wheeled vehicle (Groves 2013, ch. 15; Dissanayake et al.
/// 2001, IEEE Trans. Robot. Autom. 17(5)):
/// the point at the lever arm l^b (m, body frame, from the IMU; e.g. the middle of the
/// rear axle) moves neither sideways nor vertically in the body frame.
///
/// Model (δx = estimate − true, Ĉ_b^n = (I − [ψ×])C_b^n, so Ĉ_n^b = C_n^b(I + [ψ×])): the
/// NED velocity of the point u = v + Ĉ(ω̂_ib × l) − ω_ie × Ĉl ([`Mounting::velocity`]),
/// and z = [Ĉ_n^b û]_{y,z} − 0 (predicted − measured). To first order
/// z = [C_n^b δu − C_n^b [u×] ψ]_{y,z}, so H is rows y, z of Ĉ_n^b on the velocity
/// block, Ĉ_n^b(∂(u − v)/∂ψ − [û×]) on the attitude block and Ĉ_n^b ∂(u − v)/∂δb_g on
/// the gyro-bias block; R = σ²I₂. An update is skipped while the speed |v̂| is below
/// `min_speed` (m/s).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct NonHolonomic {
    times: Vec<f64>,
    sigma: f64,
    lever_arm: Vec3,
    min_speed: f64,
}

impl NonHolonomic {
    /// Updates at `times` (s, finite and strictly increasing) with noise σ `sigma` of
    /// both rows (m/s, positive), at `lever_arm` (m, finite), at speeds of `min_speed`
    /// and above (m/s, finite, not negative). Errors name `time`, `sigma`, `lever_arm` or
    /// `min_speed`.
    pub fn new(times: Vec<f64>, sigma: f64, lever_arm: Vec3, min_speed: f64) -> Result<Self> {
        check_increasing("time", &times)?;
        check_positive("sigma", sigma)?;
        Mounting::new(lever_arm, 0.0)?;
        if !(min_speed.is_finite() && min_speed >= 0.0) {
            return Err(invalid("min_speed", format!("must be finite and >= 0, got {min_speed}")));
        }
        Ok(NonHolonomic { times, sigma, lever_arm, min_speed })
    }

    fn model(&self, ctx: &AidingContext) -> Result<Option<Measurement>> {
        if ctx.nav.vel.norm() < self.min_speed {
            return Ok(None);
        }
        let c_bn = dcm_from_quat(&ctx.nav.q_nb).transpose();
        let mounting = Mounting { lever_arm: self.lever_arm, time_offset: 0.0 };
        let (dv, dv_psi, dv_bg) = mounting.velocity(ctx.ell, ctx.nav, &ctx.gyro_rate);
        let u = ctx.nav.vel + dv;
        let body = c_bn * u;
        let (h_v, h_psi, h_bg) = (c_bn, c_bn * (dv_psi - skew(&u)), c_bn * dv_bg);
        let mut h = DMatrix::<f64>::zeros(2, ctx.layout.size());
        for (block, m) in [("velocity", &h_v), ("attitude", &h_psi), ("gyro_bias", &h_bg)] {
            h.view_mut((0, ctx.layout.range(block)?.start), (2, 3)).copy_from(&m.fixed_rows::<2>(1));
        }
        let r = DMatrix::identity(2, 2) * (self.sigma * self.sigma);
        Ok(Some(Measurement { z: vec![body.y, body.z], h, r }))
    }
}

#[typetag::serde]
impl Aiding for NonHolonomic {
    fn name(&self) -> &str {
        "non_holonomic"
    }
    fn times(&self) -> &[f64] {
        &self.times
    }
    fn measure(&mut self, _j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        self.model(ctx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NavError;
    use crate::filter::layout::Layout;
    use nalgebra::DVector;

    fn field(e: NavError) -> (String, Option<usize>) {
        match e {
            NavError::InvalidInput { field, index, .. } => (field, index),
            other => (format!("{other}"), None),
        }
    }

    /// A record at rest with one 0.3 s shake: the still runs end before it and start after
    /// it; runs shorter than the window are not still; increments give the same answer.
    #[test]
    fn still_runs_around_a_shake() {
        let g = 9.81;
        let t: Vec<f64> = (0..300).map(|k| k as f64 * 0.01).collect();
        let shake = |k: usize| (100..130).contains(&k) || k == 250;
        let accel: Vec<Vec3> = (0..300).map(|k| Vec3::new(if shake(k) { 3.0 } else { 0.0 }, 0.0, -g)).collect();
        let gyro = vec![Vec3::new(1e-5, 0.0, 0.0); 300];
        let det = StillDetector::new(50, 0.25, 0.25_f64.to_radians(), g).unwrap();
        let s = det.detect(&t, &gyro, &accel, ImuKind::Rates).unwrap();
        // 130..250 holds 120 passing samples, 251..300 holds 49 (< 50): not still
        assert_eq!(s.runs, vec![[0, 99], [130, 249]]);
        assert_eq!(s.still.iter().filter(|&&x| x).count(), 100 + 120);
        let dg: Vec<Vec3> = gyro.iter().map(|w| w * 0.01).collect();
        let da: Vec<Vec3> = accel.iter().map(|a| a * 0.01).collect();
        assert_eq!(det.detect(&t, &dg, &da, ImuKind::Increments).unwrap(), s);
        // a wrong gravity (the record in g) finds nothing
        let det_g = StillDetector::new(50, 0.25, 0.25_f64.to_radians(), 1.0).unwrap();
        assert!(det_g.detect(&t, &gyro, &accel, ImuKind::Rates).unwrap().runs.is_empty());
    }

    #[test]
    fn bad_detector_input_is_named() {
        assert_eq!(field(StillDetector::new(0, 0.25, 0.01, 9.8).unwrap_err()).0, "window");
        assert_eq!(field(StillDetector::new(5, 0.0, 0.01, 9.8).unwrap_err()).0, "accel_threshold");
        assert_eq!(field(StillDetector::new(5, 0.2, f64::NAN, 9.8).unwrap_err()).0, "gyro_threshold");
        assert_eq!(field(StillDetector::new(5, 0.2, 0.01, -1.0).unwrap_err()).0, "gravity");
        let det = StillDetector::new(5, 0.25, 0.01, 9.8).unwrap();
        let t = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5];
        let ok = vec![Vec3::zeros(); 6];
        let mut bad = ok.clone();
        bad[3].y = f64::NAN;
        assert_eq!(field(det.detect(&t, &bad, &ok, ImuKind::Rates).unwrap_err()), ("gyro".into(), Some(3)));
        assert_eq!(field(det.detect(&t, &ok, &bad, ImuKind::Rates).unwrap_err()), ("accel".into(), Some(3)));
        assert_eq!(field(det.detect(&[0.0, 0.1, 0.1, 0.3, 0.4, 0.5], &ok, &ok, ImuKind::Rates).unwrap_err()), ("time".into(), Some(2)));
        assert_eq!(field(det.detect(&t, &ok[..5], &ok, ImuKind::Rates).unwrap_err()).0, "gyro");
        let long = StillDetector::new(7, 0.25, 0.01, 9.8).unwrap();
        assert_eq!(field(long.detect(&t, &ok, &ok, ImuKind::Rates).unwrap_err()).0, "window");
        assert_eq!(field(NonHolonomic::new(vec![0.0], 0.1, Vec3::new(0.0, f64::NAN, 0.0), 0.0).unwrap_err()).0, "lever_arm");
        assert_eq!(field(NonHolonomic::new(vec![0.0], 0.0, Vec3::zeros(), 0.0).unwrap_err()).0, "sigma");
        assert_eq!(field(NonHolonomic::new(vec![0.0], 0.1, Vec3::zeros(), -1.0).unwrap_err()).0, "min_speed");
        assert_eq!(field(NonHolonomic::new(vec![1.0, 0.5], 0.1, Vec3::zeros(), 0.0).unwrap_err()), ("time".into(), Some(1)));
    }

    /// z at the estimate whose error against a moving, turning truth is δx (position,
    /// velocity, ψ, accel and gyro bias: ω̂ = ω − δb_g), and H at the truth: H equals the
    /// central finite difference of z, column by column.
    #[test]
    fn jacobian_matches_finite_differences() {
        let ell = crate::earth::WGS84;
        let truth = NavState { t: 1.0, lla: Vec3::new(0.8, 0.2, 100.0), vel: Vec3::new(12.0, -3.0, 0.5), q_nb: crate::math::quat_from_euler(0.1, -0.3, 2.0) };
        let omega = Vec3::new(0.2, -0.35, 0.5);
        let mut nhc = NonHolonomic::new(vec![1.0], 0.1, Vec3::new(-1.2, 0.3, 0.4), 0.0).unwrap();
        let layout = Layout::ins_with(&[]).unwrap();
        let n = layout.size();
        let (x, extra) = (DVector::zeros(n), DVector::zeros(0));
        let mut model = |dx: &DVector<f64>| {
            let at = |i: usize| Vec3::new(dx[i], dx[i + 1], dx[i + 2]);
            let nav = crate::filter::initial_error::add_nav_error(&ell, &truth, &at(0), &at(3), &at(6));
            let ctx = AidingContext { t: 1.0, nav: &nav, accel_bias: at(9), gyro_bias: at(12), gyro_rate: omega - at(12), x: &x, extra: &extra, layout: &layout, ell: &ell };
            nhc.measure(0, &ctx).unwrap().unwrap()
        };
        let h = model(&DVector::zeros(n)).h;
        let mut fd = DMatrix::zeros(2, n);
        for i in 0..n {
            let step = if i < 3 { 1e-2 } else { 1e-5 };
            let mut dx = DVector::zeros(n);
            dx[i] = step;
            let (zp, zm) = (model(&dx).z, model(&-dx).z);
            for r in 0..2 {
                fd[(r, i)] = (zp[r] - zm[r]) / (2.0 * step);
            }
        }
        let worst = (&h - &fd).abs().max();
        // the attitude columns carry |v| ~ 12 m/s, the gyro-bias ones |l| ~ 1 m
        assert!(h.columns(6, 3).abs().max() > 1.0 && h.columns(12, 3).abs().max() > 0.1, "H = {h:.6}");
        assert!(worst < 1e-6, "|H − finite difference| = {worst:e}\nH = {h:.6}\nFD = {fd:.6}");
    }

    /// Below `min_speed` the update is skipped; the gated ZARU averages still samples only.
    #[test]
    fn min_speed_skips_and_zaru_averages_still_time_only() {
        let ell = crate::earth::WGS84;
        let layout = Layout::ins_with(&[]).unwrap();
        let (x, extra) = (DVector::zeros(15), DVector::zeros(0));
        let slow = NavState { t: 1.0, lla: Vec3::new(0.8, 0.2, 100.0), vel: Vec3::new(0.5, 0.0, 0.0), q_nb: crate::math::quat_from_euler(0.0, 0.0, 0.0) };
        let ctx = AidingContext { t: 1.0, nav: &slow, accel_bias: Vec3::zeros(), gyro_bias: Vec3::zeros(), gyro_rate: Vec3::zeros(), x: &x, extra: &extra, layout: &layout, ell: &ell };
        let mut nhc = NonHolonomic::new(vec![1.0], 0.1, Vec3::zeros(), 1.0).unwrap();
        assert!(nhc.measure(0, &ctx).unwrap().is_none());
        let rate = ZeroRate::new(vec![1.0, 2.0], ImuKind::Rates, 1e-12, 0.0).unwrap();
        let mut gated = ZeroRateWhileStill::new(rate, vec![[1.5, 2.0]]).unwrap();
        // 1 rad/s of motion before the still period, 1e-3 rad/s inside it
        for k in 1..=200 {
            let t = k as f64 * 0.01;
            let w = if t <= 1.5 { Vec3::new(1.0, 0.0, 0.0) } else { Vec3::new(1e-3, 0.0, 0.0) };
            gated.observe(t, 0.01, &w, &Vec3::zeros(), &slow);
            if k == 100 {
                // nothing still yet: the update is skipped
                assert!(gated.measure(0, &ctx).unwrap().is_none());
            }
        }
        let z = gated.measure(1, &ctx).unwrap().unwrap().z;
        let earth = dcm_from_quat(&slow.q_nb).transpose() * ell.local(0.8, 100.0).earth_rate();
        assert!((z[0] + earth.x - 1e-3).abs() < 1e-12, "{z:?}");
        assert_eq!(field(ZeroRateWhileStill::new(ZeroRate::new(vec![1.0], ImuKind::Rates, 1e-12, 0.0).unwrap(), vec![[0.0, 1.0], [0.5, 2.0]]).unwrap_err()), ("intervals".into(), Some(1)));
    }
}
