//! Measurement sources for one aided INS: NED velocity fixes, and [`Sources`], several
//! aiding sensors (position and velocity fixes, zero-velocity updates, CAI shots, GNSS)
//! acting as one. The composite merges the sensors' measurement times (equal times keep
//! the order of the sensors), hands each measurement to its sensor with the sensor's own
//! index, and lays out the sensors' extra state blocks one after another, in sensor
//! order; every sensor finds its blocks by name, so it works unchanged inside the
//! composite.

use super::aided::{Aiding, AidingContext, InsSetup, Measurement};
use super::layout::{ins_size, Layout};
use super::matrix::check_covariance;
use crate::earth::Ellipsoid;
use crate::error::{check_increasing, invalid, invalid_at, NavError, Result};
use crate::math::{dcm_from_quat, skew, Mat3, Vec3};
use crate::strapdown::NavState;
use nalgebra::{DMatrix, DVector};

/// A table of 3-vector fixes (position, velocity) checked: times finite and strictly
/// increasing, as many values and covariances as times, each covariance 3 × 3, and every
/// row as [`check_fix_rows`] checks it. `names` are the caller's arguments (times, values,
/// covariances): errors name them and the first offending row. Returns the covariances.
pub fn fix_table(names: [&str; 3], what: &str, t: &[f64], values: &[Vec3], cov: &[DMatrix<f64>]) -> Result<Vec<Mat3>> {
    let [time, v, c] = names;
    check_increasing(time, t)?;
    if values.len() != t.len() {
        return Err(invalid(v, format!("{time} has {} entries but {v} {}", t.len(), values.len())));
    }
    if cov.len() != t.len() {
        return Err(invalid(c, format!("{time} has {} entries but {c} {}", t.len(), cov.len())));
    }
    if let Some((i, m)) = cov.iter().enumerate().find(|(_, m)| m.nrows() != 3 || m.ncols() != 3) {
        return Err(invalid_at(c, i, format!("expected (M, 3, 3), entry {i} is {}x{}", m.nrows(), m.ncols())));
    }
    // each is 3 × 3 (checked above): its 9 column-major values
    let cov: Vec<Mat3> = cov.iter().map(|m| Mat3::from_iterator(m.iter().copied())).collect();
    check_fix_rows([v, c], what, values.iter().zip(&cov))?;
    Ok(cov)
}

/// The checks of every row of a table of 3-vector fixes: a finite value (a `what`) and a
/// symmetric positive-definite covariance. `names` (values, covariances) are named in the
/// errors, with the row.
pub fn check_fix_rows<'a>(names: [&str; 2], what: &str, rows: impl IntoIterator<Item = (&'a Vec3, &'a Mat3)>) -> Result<()> {
    let [v, c] = names;
    for (i, (value, m)) in rows.into_iter().enumerate() {
        if !value.iter().all(|x| x.is_finite()) {
            return Err(invalid_at(v, i, format!("non-finite {what} at index {i}")));
        }
        check_covariance(c, &DMatrix::from_column_slice(3, 3, m.as_slice()), Some(3), true).map_err(|e| at_row(e, i))?;
    }
    Ok(())
}

/// An invalid-input error about entry `i` of an array: its row set, named in the reason.
fn at_row(e: NavError, i: usize) -> NavError {
    match e {
        NavError::InvalidInput { field, reason, .. } => NavError::InvalidInput { field, reason: format!("entry {i}: {reason}"), index: Some(i) },
        other => other,
    }
}

/// Where and when a source measures relative to the IMU (docs/mounting.md): the lever
/// arm l^b (m, body frame) from the IMU to the point the source measures (antenna, the
/// point at rest), and the time offset (s) of its stamps: a measurement stamped t was
/// made at t + `time_offset` in the IMU clock. The default (no lever arm, no offset)
/// leaves a source's model as it was.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mounting {
    pub lever_arm: Vec3,
    pub time_offset: f64,
}

impl Mounting {
    /// A finite lever arm and time offset (an error names `lever_arm` or `time_offset`).
    pub fn new(lever_arm: Vec3, time_offset: f64) -> Result<Mounting> {
        crate::error::check_finite("lever_arm", lever_arm.as_slice(), 1)?;
        crate::error::check_finite("time_offset", &[time_offset], 1)?;
        Ok(Mounting { lever_arm, time_offset })
    }

    /// Stamps `t` in the IMU clock: t + time_offset.
    pub fn imu_times(&self, t: &[f64]) -> Vec<f64> {
        t.iter().map(|&s| s + self.time_offset).collect()
    }

    /// The point's NED offset from the IMU and its attitude column: Ĉ_b^n l and ∂(Ĉ_b^n l)/∂ψ
    /// = [(Ĉ_b^n l)×] (from Ĉ = (I − [ψ×])C: Ĉl = Cl + (Ĉl) × ψ to first order).
    pub fn position(&self, nav: &NavState) -> (Vec3, Mat3) {
        let lever_n = dcm_from_quat(&nav.q_nb) * self.lever_arm;
        (lever_n, skew(&lever_n))
    }

    /// The point's NED velocity relative to the IMU, v_point − v = Ĉ(ω̂_eb × l) =
    /// Ĉ(ω̂_ib × l) − ω_ie × Ĉl (Groves 2013, ch. 14), with `omega` = ω̂_ib^b the
    /// bias-compensated angular rate (rad/s); and its columns on ψ,
    /// [(Ĉ(ω̂ × l))×] − [ω_ie×][(Ĉl)×], and on the gyro bias δb_g (ω̂ = ω − δb_g),
    /// Ĉ[l×].
    pub fn velocity(&self, ell: &Ellipsoid, nav: &NavState, omega: &Vec3) -> (Vec3, Mat3, Mat3) {
        let cnb = dcm_from_quat(&nav.q_nb);
        let w_ie = ell.earth_rate_ned(nav.lla.x);
        let lever_n = cnb * self.lever_arm;
        let turn = cnb * omega.cross(&self.lever_arm);
        let dv = turn - w_ie.cross(&lever_n);
        (dv, skew(&turn) - skew(&w_ie) * skew(&lever_n), cnb * skew(&self.lever_arm))
    }

    /// The lever-arm terms of a position model: `z` += Ĉ_b^n l, and the ψ columns in `h`
    /// (3 rows); nothing without a lever arm.
    pub fn add_position_terms(&self, ctx: &AidingContext, z: &mut Vec3, h: &mut DMatrix<f64>) -> Result<()> {
        if self.lever_arm == Vec3::zeros() {
            return Ok(());
        }
        let (lever_n, h_psi) = self.position(ctx.nav);
        *z += lever_n;
        h.view_mut((0, ctx.layout.range("attitude")?.start), (3, 3)).copy_from(&h_psi);
        Ok(())
    }

    /// The lever-arm terms of a velocity model: `z` += v_point − v, and the ψ and gyro-bias
    /// columns in `h` (3 rows); nothing without a lever arm.
    pub fn add_velocity_terms(&self, ctx: &AidingContext, z: &mut Vec3, h: &mut DMatrix<f64>) -> Result<()> {
        if self.lever_arm == Vec3::zeros() {
            return Ok(());
        }
        let (dv, h_psi, h_bg) = self.velocity(ctx.ell, ctx.nav, &ctx.gyro_rate);
        *z += dv;
        h.view_mut((0, ctx.layout.range("attitude")?.start), (3, 3)).copy_from(&h_psi);
        h.view_mut((0, ctx.layout.range("gyro_bias")?.start), (3, 3)).copy_from(&h_bg);
        Ok(())
    }
}

/// A velocity fix: time (s), NED velocity (m/s) and its covariance (m²/s²).
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct VelocityFix {
    pub t: f64,
    pub vel_ned: Vec3,
    pub cov: Mat3,
}

/// NED velocity fixes as an aiding sensor: z = v̂_point − v_fix, H = [0 I 0 ...] on the
/// velocity block (δv = estimate − true) plus, with a lever arm, the ψ and gyro-bias
/// columns of [`Mounting::velocity`]; R the fix's covariance.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct VelocityFixes {
    times: Vec<f64>,
    fixes: Vec<VelocityFix>,
    #[serde(default)]
    mounting: Mounting,
}

impl VelocityFixes {
    /// Fixes from columns: times (s), NED velocities (m/s) and their covariances (3 × 3,
    /// m²/s²), checked by [`fix_table`]; `names` are the caller's arguments.
    pub fn table(names: [&str; 3], t: &[f64], vel: &[Vec3], cov: &[DMatrix<f64>]) -> Result<Self> {
        let cov = fix_table(names, "velocity", t, vel, cov)?;
        let fixes = t.iter().zip(vel).zip(cov).map(|((&t, &vel_ned), cov)| VelocityFix { t, vel_ned, cov }).collect();
        Ok(VelocityFixes { times: t.to_vec(), fixes, mounting: Mounting::default() })
    }

    /// These fixes measured at the lever arm and time offset of `mounting`.
    pub fn with_mounting(mut self, mounting: Mounting) -> Self {
        self.times = mounting.imu_times(&self.fixes.iter().map(|f| f.t).collect::<Vec<_>>());
        self.mounting = mounting;
        self
    }
}

#[typetag::serde]
impl Aiding for VelocityFixes {
    fn name(&self) -> &str {
        "velocity_fixes"
    }
    fn times(&self) -> &[f64] {
        &self.times
    }
    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        let fx = self.fixes.get(j).ok_or_else(|| invalid("velocity_fixes", format!("no fix {j} (of {})", self.fixes.len())))?;
        let mut z = ctx.nav.vel - fx.vel_ned;
        let mut h = DMatrix::<f64>::zeros(3, ctx.layout.size());
        h.view_mut((0, ctx.layout.range("velocity")?.start), (3, 3)).fill_with_identity();
        self.mounting.add_velocity_terms(ctx, &mut z, &mut h)?;
        Ok(Some(Measurement { z: z.as_slice().to_vec(), h, r: DMatrix::from_column_slice(3, 3, fx.cov.as_slice()) }))
    }
}

/// Several aiding sensors as one (see the module documentation).
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Sources {
    sources: Vec<Box<dyn Aiding>>,
    /// Every sensor's measurement times, merged in time order (ties in sensor order).
    times: Vec<f64>,
    /// Per merged measurement: its sensor and the sensor's own index of it.
    order: Vec<(usize, usize)>,
}

impl Sources {
    /// The composite of `sources`: each sensor's times finite and strictly increasing
    /// (errors name the sensor), no state block name asked for by two sensors.
    pub fn new(sources: Vec<Box<dyn Aiding>>) -> Result<Self> {
        let mut owner: Vec<(String, usize)> = Vec::new();
        for (i, s) in sources.iter().enumerate() {
            s.check_times()?;
            for (block, _) in s.extra_blocks() {
                if let Some((_, k)) = owner.iter().find(|(b, _)| *b == block) {
                    let other = sources.get(*k).map_or("", |o| o.name());
                    return Err(invalid_at("sources", i, format!("source {i} ({}) and source {k} ({other}) both have a state block {block:?}", s.name())));
                }
                owner.push((block, i));
            }
        }
        let mut merged: Vec<(f64, usize, usize)> = sources.iter().enumerate().flat_map(|(i, s)| s.times().iter().enumerate().map(move |(j, &t)| (t, i, j))).collect();
        // a stable sort: equal times stay in sensor order
        merged.sort_by(|a, b| a.0.total_cmp(&b.0));
        let times = merged.iter().map(|m| m.0).collect();
        let order = merged.iter().map(|m| (m.1, m.2)).collect();
        Ok(Sources { sources, times, order })
    }

    /// The sensors, in the order given.
    pub fn sources(&self) -> &[Box<dyn Aiding>] {
        &self.sources
    }

    /// The sensor of each merged measurement (index into [`Self::sources`]).
    pub fn source_of(&self) -> impl Iterator<Item = usize> + '_ {
        self.order.iter().map(|o| o.0)
    }
}

#[typetag::serde]
impl Aiding for Sources {
    fn name(&self) -> &str {
        "sources"
    }
    fn source_name(&self, j: usize) -> &str {
        match self.order.get(j).and_then(|&(i, local)| Some((self.sources.get(i)?, local))) {
            Some((s, local)) => s.source_name(local),
            None => self.name(),
        }
    }
    fn extra_blocks(&self) -> Vec<(String, usize)> {
        self.sources.iter().flat_map(|s| s.extra_blocks()).collect()
    }
    fn times(&self) -> &[f64] {
        &self.times
    }
    /// Each sensor's times were checked by [`Sources::new`]; the merge is sorted.
    fn check_times(&self) -> Result<()> {
        Ok(())
    }
    fn observe(&mut self, t: f64, dt: f64, gyro: &Vec3, accel: &Vec3, nav: &NavState) {
        for s in &mut self.sources {
            s.observe(t, dt, gyro, accel, nav);
        }
    }
    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        let (i, local) = *self.order.get(j).ok_or_else(|| invalid("sources", format!("no measurement {j} (of {})", self.order.len())))?;
        let source = self.sources.get_mut(i).ok_or_else(|| invalid("sources", format!("no source {i}")))?;
        source.measure(local, ctx)
    }
    fn extra_dynamics(&self, layout: &Layout, f: &mut DMatrix<f64>, qc: &mut DMatrix<f64>) {
        for s in &self.sources {
            s.extra_dynamics(layout, f, qc);
        }
    }
    fn propagate_extra(&self, layout: &Layout, dt: f64, extra: &mut [f64]) {
        for s in &self.sources {
            s.propagate_extra(layout, dt, extra);
        }
    }
}

/// One sensor of a composite with the initial estimate of its extra blocks (all of them,
/// in its block order) and, when it has extra blocks, their initial covariance.
pub struct Source {
    pub aiding: Box<dyn Aiding>,
    pub extra0: Vec<f64>,
    pub p0: Option<DMatrix<f64>>,
}

impl Source {
    /// A sensor without extra state blocks.
    pub fn plain(aiding: Box<dyn Aiding>) -> Source {
        Source { aiding, extra0: Vec::new(), p0: None }
    }
}

/// What the aided INS of `setup` fed by every sensor of `parts` is built from
/// ([`AidedIns::from_setup`]): the composite, the initial estimate of the extra blocks and
/// P₀ over the whole layout. P₀ is `setup.p0` when it covers the whole layout (then it
/// replaces the sensors' own initial covariances), otherwise `setup.p0` over the 15 INS
/// states and, block-diagonally after it, each sensor's initial covariance of its extra
/// blocks.
pub fn combine(setup: &InsSetup, parts: Vec<Source>) -> Result<(Sources, DVector<f64>, DMatrix<f64>)> {
    let m = ins_size();
    let sizes: Vec<usize> = parts.iter().map(|p| p.aiding.extra_blocks().iter().map(|b| b.1).sum()).collect();
    let n = m + sizes.iter().sum::<usize>();
    let whole = setup.p0.nrows() == n && setup.p0.ncols() == n;
    let mut p0 = setup.p0.clone();
    if !whole {
        p0 = setup.p0_with_extra(&vec![0.0; n - m])?;
    }
    let mut extra0 = Vec::with_capacity(n - m);
    let mut at = m;
    for (i, (part, &k)) in parts.iter().zip(&sizes).enumerate() {
        let name = part.aiding.name();
        if part.extra0.len() != k {
            return Err(invalid_at("sources", i, format!("source {i} ({name}) has {k} extra states but {} initial values", part.extra0.len())));
        }
        crate::error::check_finite("sources", &part.extra0, 1).map_err(|_| invalid_at("sources", i, format!("source {i} ({name}): non-finite initial value of its extra states")))?;
        extra0.extend_from_slice(&part.extra0);
        if !whole && k > 0 {
            let p = part.p0.as_ref().ok_or_else(|| invalid_at("sources", i, format!("source {i} ({name}) has {k} extra states but no initial covariance: give it one, or p0 over the whole layout ({n} x {n}) in the setup")))?;
            if p.nrows() != k || p.ncols() != k {
                return Err(invalid_at("sources", i, format!("source {i} ({name}): initial covariance {}x{}, expected {k}x{k}", p.nrows(), p.ncols())));
            }
            p0.view_mut((at, at), (k, k)).copy_from(p);
        }
        at += k;
    }
    let sources = Sources::new(parts.into_iter().map(|p| p.aiding).collect())?;
    Ok((sources, DVector::from_vec(extra0), p0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::aided::{run_aided, AidedConfig, AidedIns, AidedOutput, PositionAiding, PositionFix};
    use crate::filter::discretize::Discretization;
    use crate::filter::ins::{BiasModel, InsNoise};
    use crate::filter::kf::LoopMode;
    use crate::imu::ImuKind;

    /// A stationary 10 s record at 100 Hz with an accelerometer bias, and a setup whose
    /// initial position is 3 m off.
    fn record(mode: LoopMode) -> (InsSetup, Vec3, Vec<f64>, Vec<Vec3>, Vec<Vec3>) {
        let ell = crate::earth::WGS84;
        let lla = Vec3::new(0.8, 0.2, 100.0);
        let loc = ell.local(lla.x, lla.z);
        let t: Vec<f64> = (0..=1000).map(|k| k as f64 * 0.01).collect();
        let gyro = vec![loc.earth_rate(); t.len()];
        let accel = vec![Vec3::new(1e-3, -2e-3, -loc.gravity); t.len()];
        let noise = InsNoise { accel_psd: 1e-8, gyro_psd: 1e-14, accel_bias: BiasModel::RandomConstant, gyro_bias: BiasModel::RandomConstant };
        let cfg = AidedConfig { noise, predict_every: 10, method: Discretization::VanLoan, mode, sequential: false, gate: None };
        let diag = [9.0, 9.0, 9.0, 0.01, 0.01, 0.01, 1e-6, 1e-6, 1e-6, 1e-4, 1e-4, 1e-4, 1e-10, 1e-10, 1e-10];
        let p0 = DMatrix::from_diagonal(&DVector::from_vec(diag.to_vec()));
        let start = NavState { t: 0.0, lla: lla + Vec3::new(3.0 / loc.rm, 0.0, 0.0), vel: Vec3::zeros(), q_nb: crate::math::quat(1.0, 0.0, 0.0, 0.0) };
        let setup = InsSetup::new(start, ImuKind::Rates, ell, Vec3::zeros(), Vec3::zeros(), p0, cfg, None).unwrap();
        (setup, lla, t, gyro, accel)
    }

    fn fixes(lla: Vec3, times: impl Iterator<Item = f64>) -> PositionAiding {
        let cov = Mat3::identity() * 0.25;
        PositionAiding::new(times.map(|t| PositionFix { t, lla, cov_ned: cov }).collect()).unwrap()
    }

    fn velocity(times: impl Iterator<Item = f64>) -> VelocityFixes {
        let t: Vec<f64> = times.collect();
        VelocityFixes::table(["time", "vel_ned", "cov"], &t, &vec![Vec3::zeros(); t.len()], &vec![DMatrix::identity(3, 3) * 1e-4; t.len()]).unwrap()
    }

    fn run(setup: &InsSetup, parts: Vec<Source>, t: &[f64], g: &[Vec3], a: &[Vec3]) -> AidedOutput {
        let (sources, extra0, p0) = combine(setup, parts).unwrap();
        let ins = AidedIns::from_setup(setup, extra0, Some(p0), Box::new(sources) as Box<dyn Aiding>).unwrap();
        run_aided(ins, t, g, a).unwrap().0
    }

    fn assert_same(want: &AidedOutput, got: &AidedOutput) {
        assert_eq!(want.time, got.time);
        assert_eq!(want.nav, got.nav);
        assert_eq!(want.accel_bias, got.accel_bias);
        assert_eq!(want.sigma, got.sigma);
        assert_eq!(want.meas_time, got.meas_time);
        assert_eq!(want.innovation, got.innovation);
        assert_eq!(want.nis, got.nis);
    }

    /// A composite of one sensor gives the sensor's own output, to the last bit.
    #[test]
    fn composite_of_one_is_the_source_alone() {
        for mode in [LoopMode::Closed, LoopMode::Open] {
            let (setup, lla, t, g, a) = record(mode);
            let alone = AidedIns::from_setup(&setup, DVector::zeros(0), None, fixes(lla, (1..10).map(f64::from))).unwrap();
            let (want, _) = run_aided(alone, &t, &g, &a).unwrap();
            let got = run(&setup, vec![Source::plain(Box::new(fixes(lla, (1..10).map(f64::from))))], &t, &g, &a);
            assert_eq!(want.meas_time.len(), 9);
            assert_same(&want, &got);
        }
    }

    /// Fixes at odd seconds and fixes at even seconds as two sources equal one source of
    /// all the fixes: at distinct epochs the engine applies them one after another either way.
    #[test]
    fn odd_and_even_fixes_equal_all_fixes() {
        for mode in [LoopMode::Closed, LoopMode::Open] {
            let (setup, lla, t, g, a) = record(mode);
            let all = run(&setup, vec![Source::plain(Box::new(fixes(lla, (1..10).map(f64::from))))], &t, &g, &a);
            let odd = Source::plain(Box::new(fixes(lla, (1..10).step_by(2).map(f64::from))));
            let even = Source::plain(Box::new(fixes(lla, (2..10).step_by(2).map(f64::from))));
            let split = run(&setup, vec![even, odd], &t, &g, &a);
            assert_eq!(split.meas_time, (1..10).map(f64::from).collect::<Vec<_>>());
            assert_same(&all, &split);
        }
    }

    /// Equal times from two sensors are applied at the same epoch in sensor order, and
    /// the velocity fixes pull the velocity estimate towards zero.
    #[test]
    fn equal_times_keep_sensor_order() {
        let (setup, lla, t, g, a) = record(LoopMode::Closed);
        let pos = Source::plain(Box::new(fixes(lla, (1..10).map(f64::from))));
        let vel = Source::plain(Box::new(velocity((1..10).map(f64::from))));
        let sources = Sources::new(vec![pos.aiding, vel.aiding]).unwrap();
        assert_eq!(sources.source_of().collect::<Vec<_>>(), [0, 1].repeat(9));
        let both = run(&setup, vec![Source::plain(Box::new(fixes(lla, (1..10).map(f64::from)))), Source::plain(Box::new(velocity((1..10).map(f64::from))))], &t, &g, &a);
        let pos_only = run(&setup, vec![Source::plain(Box::new(fixes(lla, (1..10).map(f64::from))))], &t, &g, &a);
        let speed = |o: &AidedOutput| o.nav.last().map_or(f64::NAN, |s| s.vel.norm());
        assert_eq!(both.meas_time.len(), 18);
        assert!(speed(&both) < speed(&pos_only), "{} vs {}", speed(&both), speed(&pos_only));
    }

    /// Each applied measurement names its sensor: fixes every second and velocity fixes
    /// every other second, merged in time order (ties in sensor order); a sensor's skipped
    /// measurements leave no entry; a sensor alone names itself.
    #[test]
    fn each_measurement_names_its_source() {
        #[derive(serde::Serialize, serde::Deserialize)]
        struct Skips(Vec<f64>);
        #[typetag::serde]
        impl Aiding for Skips {
            fn name(&self) -> &str {
                "skips"
            }
            fn times(&self) -> &[f64] {
                &self.0
            }
            fn measure(&mut self, _j: usize, _ctx: &AidingContext) -> Result<Option<Measurement>> {
                Ok(None)
            }
        }
        let (setup, lla, t, g, a) = record(LoopMode::Closed);
        let parts = vec![
            Source::plain(Box::new(Skips(vec![0.5, 2.0, 9.5]))),
            Source::plain(Box::new(fixes(lla, (1..10).map(f64::from)))),
            Source::plain(Box::new(velocity((2..10).step_by(2).map(f64::from)))),
        ];
        let out = run(&setup, parts, &t, &g, &a);
        let want: Vec<&str> = (1..10).flat_map(|s| if s % 2 == 0 { vec!["position_fixes", "velocity_fixes"] } else { vec!["position_fixes"] }).collect();
        assert_eq!(out.meas_source, want);
        assert_eq!(out.meas_time.len(), want.len());
        let alone = run(&setup, vec![Source::plain(Box::new(velocity([3.0, 4.0].into_iter())))], &t, &g, &a);
        assert_eq!(alone.meas_source, ["velocity_fixes"; 2]);
    }

    /// Two sensors with the same state block name: an error naming `sources` and the second.
    #[test]
    fn duplicate_block_names_are_refused() {
        #[derive(serde::Serialize, serde::Deserialize)]
        struct Clock;
        #[typetag::serde]
        impl Aiding for Clock {
            fn extra_blocks(&self) -> Vec<(String, usize)> {
                vec![("clock".to_string(), 2)]
            }
            fn times(&self) -> &[f64] {
                &[]
            }
            fn measure(&mut self, _j: usize, _ctx: &AidingContext) -> Result<Option<Measurement>> {
                Ok(None)
            }
        }
        match Sources::new(vec![Box::new(Clock), Box::new(Clock)]) {
            Err(NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("sources", Some(1))),
            other => panic!("expected an invalid sources, got {:?}", other.map(|s| s.times.len())),
        }
    }

    /// Central finite difference of `z(δx)` (3 rows) over the 15 INS error states, step
    /// `h` (1 cm for the position states: a smaller step in latitude drowns in rounding).
    fn finite_difference(mut z: impl FnMut(&DVector<f64>) -> Vec3, h: f64) -> DMatrix<f64> {
        let n = ins_size();
        let mut jac = DMatrix::zeros(3, n);
        for i in 0..n {
            let h = if i < 3 { 1e-2 } else { h };
            let mut dx = DVector::zeros(n);
            dx[i] = h;
            jac.set_column(i, &((z(&dx) - z(&-dx)) / (2.0 * h)));
        }
        jac
    }

    /// The lever-arm models' z at the estimate whose error against a moving, turning
    /// truth is δx (position, velocity, ψ and gyro bias: ω̂ = ω − δb_g), and their H at
    /// the truth: H equals the finite difference of z, column by column.
    #[test]
    fn lever_arm_jacobians_match_finite_differences() {
        let ell = crate::earth::WGS84;
        let truth = NavState { t: 1.0, lla: Vec3::new(0.8, 0.2, 100.0), vel: Vec3::new(12.0, -3.0, 0.5), q_nb: crate::math::quat_from_euler(0.1, -0.3, 2.0) };
        let omega = Vec3::new(0.2, -0.35, 0.5);
        let mounting = Mounting::new(Vec3::new(0.4, -0.3, -0.65), 0.0).unwrap();
        let layout = Layout::ins_with(&[]).unwrap();
        let (x, extra) = (DVector::zeros(layout.size()), DVector::zeros(0));
        let fix_cov = vec![DMatrix::identity(3, 3); 1];
        let position = PositionAiding::new(vec![PositionFix { t: 1.0, lla: truth.lla, cov_ned: Mat3::identity() }]).unwrap().with_mounting(mounting);
        let velocity = VelocityFixes::table(["time", "vel_ned", "cov"], &[1.0], &[Vec3::new(1.0, 2.0, 3.0)], &fix_cov).unwrap().with_mounting(mounting);
        let mut sensors: [Box<dyn Aiding>; 2] = [Box::new(position), Box::new(velocity)];
        for sensor in &mut sensors {
            let mut model = |dx: &DVector<f64>| {
                let at = |i: usize| Vec3::new(dx[i], dx[i + 1], dx[i + 2]);
                let nav = crate::filter::initial_error::add_nav_error(&ell, &truth, &at(0), &at(3), &at(6));
                let ctx = AidingContext { t: 1.0, nav: &nav, accel_bias: at(9), gyro_bias: at(12), gyro_rate: omega - at(12), x: &x, extra: &extra, layout: &layout, ell: &ell };
                sensor.measure(0, &ctx).unwrap().unwrap()
            };
            let h = model(&DVector::zeros(15)).h;
            let z = |dx: &DVector<f64>| Vec3::from_column_slice(&model(dx).z);
            let fd = finite_difference(z, 1e-5);
            let worst = (&h - &fd).abs().max();
            // the lever-arm columns are ~0.1–1: a wrong sign or a missing term errs by that
            assert!(h.columns(6, 3).abs().max() > 0.1, "{}: no attitude column", sensor.name());
            assert!(worst < 1e-6, "{}: |H − finite difference| = {worst:e}\nH = {h:.6}\nFD = {fd:.6}", sensor.name());
        }
    }

    /// A stamp plus the time offset is the measurement time in the IMU clock; a NaN lever
    /// arm or offset is an error naming it.
    #[test]
    fn time_offset_shifts_and_bad_mountings_are_named() {
        let (_, lla, _, _, _) = record(LoopMode::Closed);
        let shifted = fixes(lla, [1.0, 2.0].into_iter()).with_mounting(Mounting::new(Vec3::zeros(), 0.125).unwrap());
        assert_eq!(shifted.times(), [1.125, 2.125]);
        for (lever, offset, name) in [(Vec3::new(0.0, f64::NAN, 0.0), 0.0, "lever_arm"), (Vec3::zeros(), f64::INFINITY, "time_offset")] {
            match Mounting::new(lever, offset) {
                Err(NavError::InvalidInput { field, .. }) => assert_eq!(field, name),
                other => panic!("expected an invalid {name}, got {other:?}"),
            }
        }
    }

    /// A mount that is no rotation (a reflection, a scaled matrix) is an error naming
    /// `mount`; a rotation is kept, and the identity leaves the samples untouched.
    #[test]
    fn mount_must_be_a_rotation() {
        let (setup, _, _, _, _) = record(LoopMode::Closed);
        for bad in [Mat3::from_diagonal(&Vec3::new(1.0, 1.0, -1.0)), Mat3::identity() * 1.01] {
            match setup.clone().with_mount(bad) {
                Err(NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("mount", None)),
                other => panic!("expected an invalid mount, got {:?}", other.map(|s| s.mount)),
            }
        }
        let turned = crate::math::dcm_from_euler(std::f64::consts::PI, 0.0, -std::f64::consts::FRAC_PI_2);
        assert_eq!(setup.with_mount(turned).unwrap().mount, turned);
    }

    /// A sensor's own times must increase: the error names the sensor.
    #[test]
    fn each_sensor_keeps_its_time_check() {
        let (_, lla, _, _, _) = record(LoopMode::Closed);
        let bad = fixes(lla, [1.0, 1.0].into_iter());
        match Sources::new(vec![Box::new(bad)]) {
            Err(NavError::InvalidInput { field, .. }) => assert_eq!(field, "position_fixes"),
            other => panic!("expected an invalid position_fixes, got {:?}", other.map(|s| s.times.len())),
        }
    }
}
