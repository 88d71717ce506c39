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
use crate::error::{check_increasing, invalid, invalid_at, NavError, Result};
use crate::math::{Mat3, Vec3};
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

/// A velocity fix: time (s), NED velocity (m/s) and its covariance (m²/s²).
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct VelocityFix {
    pub t: f64,
    pub vel_ned: Vec3,
    pub cov: Mat3,
}

/// NED velocity fixes as an aiding sensor: z = v̂ − v_fix, H = [0 I 0 ...] on the velocity
/// block (δv = estimate − true), R the fix's covariance.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct VelocityFixes {
    times: Vec<f64>,
    fixes: Vec<VelocityFix>,
}

impl VelocityFixes {
    /// Fixes from columns: times (s), NED velocities (m/s) and their covariances (3 × 3,
    /// m²/s²), checked by [`fix_table`]; `names` are the caller's arguments.
    pub fn table(names: [&str; 3], t: &[f64], vel: &[Vec3], cov: &[DMatrix<f64>]) -> Result<Self> {
        let cov = fix_table(names, "velocity", t, vel, cov)?;
        let fixes = t.iter().zip(vel).zip(cov).map(|((&t, &vel_ned), cov)| VelocityFix { t, vel_ned, cov }).collect();
        Ok(VelocityFixes { times: t.to_vec(), fixes })
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
        let z = ctx.nav.vel - fx.vel_ned;
        let mut h = DMatrix::<f64>::zeros(3, ctx.layout.size());
        h.view_mut((0, ctx.layout.range("velocity")?.start), (3, 3)).fill_with_identity();
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
