//! The aided strapdown INS: one engine for every aiding sensor (position fixes, CAI, GNSS,
//! star camera). The strapdown of `strapdown.rs` runs on bias-compensated IMU output; the
//! error-state filter predicts every `predict_every` IMU steps and at each measurement
//! epoch with F from the current solution (the 15-state NED error model,
//! `ins::error_dynamics`, plus the sensor's extra blocks); an [`Aiding`] model supplies
//! z = predicted − measured, H and R. In closed loop the estimate is fed back
//! (X ← X ⊖ δx̂, b̂ ← b̂ − δb̂, extra ← extra − δx̂_extra, δx̂ ← 0); in open loop the INS
//! runs free and the output is X ⊖ δx̂ (the estimation and feedback variants of Demidov 2009).
//!
//! [`AidedIns::process`] takes the IMU record chunk by chunk (streaming); feeding the
//! whole record in one call, or in any chunks followed by [`AidedIns::finish`], gives the
//! same result. Error messages about samples name their index in the whole record.
//!
//! The vertical channel is free by default; [`AidedIns::with_damped_vertical`] damps it
//! with a reference (barometric) altitude per IMU sample (docs/departures.md#baro-damped-vertical-channel), and
//! the filter's F then carries the baro loop (`ins::baro_loop_dynamics`) and, optionally,
//! a `baro_bias` state appended after the aiding's extra blocks.

use super::discretize::{discretize, Discretization};
use super::ins::{baro_loop_dynamics, error_dynamics, BaroModel, InsNoise};
use super::initial_error::add_nav_error;
use super::kf::{rts_chunk, Kf, LoopMode, StoredStep};
use super::layout::{ins_size, Layout};
use super::sources::Mounting;
use crate::earth::Ellipsoid;
use crate::error::{invalid, NavError, Result};
use crate::imu::ImuKind;
use crate::math::{Mat3, Vec3};
use crate::strapdown::{NavState, Strapdown, Vertical};
use nalgebra::{DMatrix, DVector};

/// What an aiding sensor reports at one epoch.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// z = predicted − measured (m rows; δx = estimate − true).
    pub z: Vec<f64>,
    /// H (m × n) with respect to the whole layout's δx.
    pub h: DMatrix<f64>,
    /// Measurement-noise covariance (m × m); sequential mode decorrelates it.
    pub r: DMatrix<f64>,
}

/// What the engine knows when it asks for a measurement.
pub struct AidingContext<'a> {
    /// IMU epoch at which the measurement is applied (first epoch ≥ its time), s.
    pub t: f64,
    /// Current strapdown solution (open loop: the free, uncorrected INS).
    pub nav: &'a NavState,
    /// Bias estimates currently removed from the IMU output (m/s², rad/s).
    pub accel_bias: Vec3,
    pub gyro_bias: Vec3,
    /// Bias-compensated angular rate ω̂_ib^b of the last IMU sample (rad/s, body frame).
    pub gyro_rate: Vec3,
    /// δx̂ (all zeros in closed loop).
    pub x: &'a DVector<f64>,
    /// Estimate of the extra blocks currently in use (layout order after the 15 INS states).
    pub extra: &'a DVector<f64>,
    pub layout: &'a Layout,
    pub ell: &'a Ellipsoid,
}

/// An aiding sensor's measurement model.
///
/// Each implementation is saved and restored by its type name (`#[typetag::serde]` on
/// the `impl`, with serde derives on the sensor), so an aided INS pickles whole, its
/// sensor included.
#[typetag::serde]
pub trait Aiding: Send {
    /// The sensor's name: the field of error messages about its measurements and the
    /// `source` of each of them in [`AidedOutput`] (e.g. "position_fixes").
    fn name(&self) -> &str {
        "measurements"
    }
    /// Name of the sensor that made measurement `j`: [`Self::name`], or for a composite
    /// the name of its sensor of that measurement.
    fn source_name(&self, _j: usize) -> &str {
        self.name()
    }
    /// Extra state blocks after the 15 INS states: (name, size).
    fn extra_blocks(&self) -> Vec<(String, usize)> {
        Vec::new()
    }
    /// Measurement times (s), strictly increasing.
    fn times(&self) -> &[f64];
    /// Check [`Self::times`] when the engine is built: finite and strictly increasing
    /// (a composite of several sources allows equal times from different sources).
    fn check_times(&self) -> Result<()> {
        check_times(self.name(), self.times())
    }
    /// After every strapdown step: the bias-compensated IMU sample (rates or increments as
    /// the record), its interval `dt` (s; 0 for a rate sample at the initial time, which
    /// only primes the integrator) and the new navigation solution.
    fn observe(&mut self, _t: f64, _dt: f64, _gyro: &Vec3, _accel: &Vec3, _nav: &NavState) {}
    /// Measurement `j` at `ctx.t`; `Ok(None)` skips it.
    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>>;
    /// Continuous F and Q_c rows/columns of the extra blocks (INS blocks already filled).
    fn extra_dynamics(&self, _layout: &Layout, _f: &mut DMatrix<f64>, _qc: &mut DMatrix<f64>) {}
    /// Propagate the nominal values of the extra blocks over `dt` s to the next prediction
    /// epoch, consistently with `extra_dynamics` (e.g. clock bias += drift·dt); `extra`
    /// holds every extra block in layout order after the 15 INS states. Default: constant.
    fn propagate_extra(&self, _layout: &Layout, _dt: f64, _extra: &mut [f64]) {}
}

impl Aiding for Box<dyn Aiding> {
    fn name(&self) -> &str {
        (**self).name()
    }
    fn source_name(&self, j: usize) -> &str {
        (**self).source_name(j)
    }
    fn extra_blocks(&self) -> Vec<(String, usize)> {
        (**self).extra_blocks()
    }
    fn times(&self) -> &[f64] {
        (**self).times()
    }
    fn check_times(&self) -> Result<()> {
        (**self).check_times()
    }
    fn observe(&mut self, t: f64, dt: f64, gyro: &Vec3, accel: &Vec3, nav: &NavState) {
        (**self).observe(t, dt, gyro, accel, nav)
    }
    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        (**self).measure(j, ctx)
    }
    fn extra_dynamics(&self, layout: &Layout, f: &mut DMatrix<f64>, qc: &mut DMatrix<f64>) {
        (**self).extra_dynamics(layout, f, qc)
    }
    fn propagate_extra(&self, layout: &Layout, dt: f64, extra: &mut [f64]) {
        (**self).propagate_extra(layout, dt, extra)
    }
    // what #[typetag::serde] adds to an impl: the boxed sensor is saved under its own name
    fn typetag_name(&self) -> &'static str {
        (**self).typetag_name()
    }
    fn typetag_deserialize(&self) {}
}

#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AidedConfig {
    pub noise: InsNoise,
    pub predict_every: usize,
    #[serde(with = "crate::options::by_name")]
    pub method: Discretization,
    #[serde(with = "crate::options::by_name")]
    pub mode: LoopMode,
    pub sequential: bool,
    pub gate: Option<f64>,
}

/// Output per prediction epoch and per applied measurement (appended by `process`).
#[derive(Debug, Clone, Default)]
pub struct AidedOutput {
    pub time: Vec<f64>,
    /// Navigation estimate (open loop: X ⊖ δx̂).
    pub nav: Vec<NavState>,
    pub accel_bias: Vec<Vec3>,
    pub gyro_bias: Vec<Vec3>,
    /// Estimate of the extra blocks, epochs × n_extra.
    pub extra: Vec<f64>,
    /// σ of every state, epochs × n.
    pub sigma: Vec<f64>,
    /// The error-state covariance P of every epoch, epochs × n² (row-major n × n blocks,
    /// the layout numpy takes as is; empty unless [`AidedIns::output_covariance`] is on).
    pub covariance: Vec<f64>,
    /// Per measurement: its time, number of rows, innovations (concatenated), NIS (summed
    /// over rows), the number of rows the χ² gate rejected and the name of the sensor that
    /// made it ([`Aiding::source_name`]).
    pub meas_time: Vec<f64>,
    pub meas_rows: Vec<usize>,
    pub innovation: Vec<f64>,
    pub nis: Vec<f64>,
    pub rejected: Vec<usize>,
    pub meas_source: Vec<String>,
    /// The forward pass of these epochs, stored for the smoother (empty unless
    /// [`AidedIns::store_forward_pass`] was called).
    pub forward: ForwardPass,
}

/// The forward pass of an aided-INS run stored for the Rauch–Tung–Striebel smoother, per
/// prediction epoch: the filter step (Φ from the previous epoch, prior and posterior
/// error-state mean and covariance; the posterior before a closed loop's feedback), Q_d of
/// the step, and the nominal solution after the epoch (the corrected solution in closed
/// loop, the free INS in open loop) as a row of [`NOMINAL_WIDTH`] + n_extra values: t (s),
/// lat, lon (rad), h (m), v_NED (m/s), q_nb (4), accel bias (m/s²), gyro bias (rad/s), then
/// the extra blocks. 8 (4n² + 2n + 17 + n_extra) bytes per epoch for n states.
#[derive(Debug, Clone, Default)]
pub struct ForwardPass {
    pub steps: Vec<StoredStep>,
    pub qd: Vec<DMatrix<f64>>,
    pub nominal: Vec<DVector<f64>>,
}

/// Values of a nominal row before the extra blocks (t, lla, v_NED, q_nb, accel and gyro
/// bias).
pub const NOMINAL_WIDTH: usize = 17;

/// The nominal row of a solution (layout of [`ForwardPass::nominal`]).
fn nominal_row(nav: &NavState, ba: &Vec3, bg: &Vec3, extra: &DVector<f64>) -> DVector<f64> {
    let q = &nav.q_nb;
    let head = [nav.t, nav.lla.x, nav.lla.y, nav.lla.z, nav.vel.x, nav.vel.y, nav.vel.z, q.w, q.i, q.j, q.k, ba.x, ba.y, ba.z, bg.x, bg.y, bg.z];
    DVector::from_iterator(NOMINAL_WIDTH + extra.len(), head.into_iter().chain(extra.iter().copied()))
}

/// A nominal row back as (solution, accel bias, gyro bias, extra blocks); `None` when
/// the row is shorter than [`NOMINAL_WIDTH`].
fn from_nominal_row(row: &DVector<f64>) -> Option<(NavState, Vec3, Vec3, DVector<f64>)> {
    let (&[t, lat, lon, h, vn, ve, vd, qw, qx, qy, qz, ba_x, ba_y, ba_z, bg_x, bg_y, bg_z], extra) = row.as_slice().split_first_chunk::<NOMINAL_WIDTH>()?;
    let nav = NavState { t, lla: Vec3::new(lat, lon, h), vel: Vec3::new(vn, ve, vd), q_nb: crate::math::quat(qw, qx, qy, qz) };
    Some((nav, Vec3::new(ba_x, ba_y, ba_z), Vec3::new(bg_x, bg_y, bg_z), DVector::from_column_slice(extra)))
}

/// The smoothed solution of one chunk of a stored forward pass
/// ([`AidedIns::smooth_chunk`]).
#[derive(Debug, Clone, Default)]
pub struct SmoothedChunk {
    /// Smoothed navigation solution, IMU bias and extra-block estimates and σ of every
    /// state, per epoch (the measurement fields are empty: a smoothed NIS does not exist).
    pub out: AidedOutput,
    /// Smoothed error state x^s and covariance P^s per epoch, relative to the nominal
    /// before the epoch's feedback (the prior nominal in closed loop, the free INS in
    /// open loop): the carry into the chunk before this one.
    pub x: Vec<DVector<f64>>,
    pub p: Vec<DMatrix<f64>>,
}

/// NED position difference (m) of `a` relative to `b` (small-difference form).
pub fn ned_diff(ell: &Ellipsoid, a: &Vec3, b: &Vec3) -> Vec3 {
    let loc = ell.local(b.x, b.z);
    Vec3::new((a.x - b.x) * loc.rm, (a.y - b.y) * loc.rp * loc.cos, -(a.z - b.z))
}

/// Start index of every INS block in the layout, and the number of INS states (the
/// index of the first extra block); read once from the layout.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct InsIndex {
    position: usize,
    velocity: usize,
    attitude: usize,
    accel_bias: usize,
    gyro_bias: usize,
    n: usize,
}

impl InsIndex {
    fn of(layout: &Layout) -> Result<InsIndex> {
        Ok(InsIndex {
            position: layout.range("position")?.start,
            velocity: layout.range("velocity")?.start,
            attitude: layout.range("attitude")?.start,
            accel_bias: layout.range("accel_bias")?.start,
            gyro_bias: layout.range("gyro_bias")?.start,
            n: ins_size(),
        })
    }

    /// X ⊖ δx for the navigation blocks: position (NED m), velocity, ψ (Ĉ = (I − [ψ×])C ⇒
    /// C = (I + [ψ×])Ĉ ≈ exp([ψ×])Ĉ).
    fn remove_error(&self, ell: &Ellipsoid, s: &NavState, dx: &DVector<f64>) -> NavState {
        add_nav_error(ell, s, &-block(dx, self.position), &-block(dx, self.velocity), &-block(dx, self.attitude))
    }
}

fn block(x: &DVector<f64>, start: usize) -> Vec3 {
    Vec3::new(x[start], x[start + 1], x[start + 2])
}

/// The baro loop of a damped vertical channel: damping ratio ζ, natural frequency ω_v
/// (rad/s) and the error model of the reference altitude.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DampedVertical {
    pub zeta: f64,
    pub omega: f64,
    pub baro: BaroModel,
}

/// The INS part every aided-INS run shares (initial state, IMU kind, Earth model, initial
/// bias estimates, P₀, noise and filter options, vertical channel), checked once by
/// [`InsSetup::new`]; a sensor adds its measurement model ([`AidedIns::from_setup`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InsSetup {
    pub initial: NavState,
    #[serde(with = "crate::options::by_name")]
    pub kind: ImuKind,
    #[serde(with = "crate::options::by_name")]
    pub ell: Ellipsoid,
    pub accel_bias0: Vec3,
    pub gyro_bias0: Vec3,
    /// P₀ over the whole layout (INS blocks, then the sensor's extra blocks), or over the
    /// INS blocks only when the sensor supplies its own initial covariance.
    pub p0: DMatrix<f64>,
    pub cfg: AidedConfig,
    pub damped: Option<DampedVertical>,
    /// The IMU mount C_imu^b (v_b = C v_imu; docs/mounting.md), applied to every IMU
    /// sample before the strapdown; identity by default.
    #[serde(default = "Mat3::identity")]
    pub mount: Mat3,
}

impl InsSetup {
    /// Check everything that does not depend on the aiding sensor: the initial state as a
    /// strapdown INS checks it ([`NavState::check`]; kept with q_nb scaled to exactly unit
    /// norm), finite bias estimates, P₀
    /// symmetric positive definite, `predict_every` ≥ 1, the noise model, the baro loop.
    #[allow(clippy::too_many_arguments)]
    pub fn new(initial: NavState, kind: ImuKind, ell: Ellipsoid, accel_bias0: Vec3, gyro_bias0: Vec3, p0: DMatrix<f64>, cfg: AidedConfig, damped: Option<DampedVertical>) -> Result<InsSetup> {
        let vertical = damped.map_or(Vertical::Free, |d| Vertical::Damped { zeta: d.zeta, omega: d.omega });
        let initial = Strapdown::new(initial, kind, ell, vertical)?.state;
        for (field, v) in [("ba0", &accel_bias0), ("bg0", &gyro_bias0)] {
            crate::error::check_finite(field, v.as_slice(), 1)?;
        }
        super::matrix::check_covariance("p0", &p0, None, true)?;
        check_config(&cfg)?;
        if let Some(d) = damped {
            d.baro.check()?;
        }
        Ok(InsSetup { initial, kind, ell, accel_bias0, gyro_bias0, p0, cfg, damped, mount: Mat3::identity() })
    }

    /// This setup with the IMU mounted by `mount` = C_imu^b (checked by [`check_mount`]).
    pub fn with_mount(mut self, mount: Mat3) -> Result<InsSetup> {
        check_mount(&mount)?;
        self.mount = mount;
        Ok(self)
    }

    /// P₀ of the whole layout: this P₀ over the INS blocks and `extra_var` on the
    /// diagonal of the extra blocks (a sensor that supplies its own initial covariance;
    /// then this P₀ must be the INS block).
    // invariant: p is resized to n = m + extra_var.len(), so m + i < n.
    #[allow(clippy::indexing_slicing)]
    pub fn p0_with_extra(&self, extra_var: &[f64]) -> Result<DMatrix<f64>> {
        let m = ins_size();
        if self.p0.nrows() != m {
            return Err(invalid("p0", format!("expected the {m} x {m} INS block, got {}x{}", self.p0.nrows(), self.p0.ncols())));
        }
        let n = m + extra_var.len();
        let mut p = self.p0.clone().resize(n, n, 0.0);
        for (i, v) in extra_var.iter().enumerate() {
            p[(m + i, m + i)] = *v;
        }
        Ok(p)
    }
}

/// An IMU mount C_imu^b must be a rotation (orthonormal within the tolerance of
/// [`crate::math::check_rotation`], det = +1): otherwise an error naming `mount`.
pub fn check_mount(mount: &Mat3) -> Result<()> {
    crate::math::check_rotation("mount", 0, mount).map_err(|e| match e {
        NavError::InvalidInput { field, reason, .. } => NavError::InvalidInput { field, reason: reason.replace(" at index 0", ""), index: None },
        other => other,
    })
}

/// The checks of the filter options that need no layout.
fn check_config(cfg: &AidedConfig) -> Result<()> {
    if cfg.predict_every == 0 {
        return Err(invalid("predict_every", "must be >= 1"));
    }
    cfg.noise.check()?;
    if let Some(g) = cfg.gate {
        crate::error::check_positive("gate", g)?;
    }
    Ok(())
}

/// The whole run state derives serde (pickle of `atomnav.filter.AidedIns` mid-record).
#[derive(serde::Serialize, serde::Deserialize)]
pub struct AidedIns<A: Aiding> {
    sd: Strapdown,
    kf: Kf,
    layout: Layout,
    #[serde(with = "crate::options::by_name")]
    ell: Ellipsoid,
    cfg: AidedConfig,
    aiding: A,
    accel_bias: Vec3,
    gyro_bias: Vec3,
    extra: DVector<f64>,
    next_meas: usize,
    t_last_predict: f64,
    /// Time and compensated specific force (m/s²) of the last sample, for F.
    last_sample: Option<(f64, Vec3)>,
    /// Compensated angular rate (rad/s) of the last sample, for the sensors' models.
    #[serde(default)]
    last_rate: Vec3,
    /// The IMU mount C_imu^b applied to every sample (None: the identity, not applied).
    #[serde(default)]
    mount: Option<Mat3>,
    steps_since: usize,
    /// Samples processed so far (errors name the sample of the whole record).
    samples: usize,
    /// Error model of the reference altitude (used with a damped vertical channel).
    baro: BaroModel,
    /// Where the INS blocks sit in the layout.
    ix: InsIndex,
    /// Store the forward pass for the smoother ([`AidedOutput::forward`]).
    store: bool,
    /// Output the full covariance of every epoch ([`AidedOutput::covariance`]).
    #[serde(default)]
    covariance_out: bool,
}

impl<A: Aiding> AidedIns<A> {
    /// `p0`: n × n for the whole layout (15 INS states then the aiding's extra blocks);
    /// `extra0`: initial estimate of the extra blocks.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        initial: NavState,
        kind: ImuKind,
        ell: Ellipsoid,
        accel_bias0: Vec3,
        gyro_bias0: Vec3,
        extra0: DVector<f64>,
        p0: DMatrix<f64>,
        cfg: AidedConfig,
        aiding: A,
    ) -> Result<Self> {
        check_config(&cfg)?;
        let layout = Layout::ins_with(&aiding.extra_blocks())?;
        let ix = InsIndex::of(&layout)?;
        let n = layout.size();
        if p0.nrows() != n || p0.ncols() != n {
            return Err(invalid("p0", format!("expected {n}x{n}, got {}x{}", p0.nrows(), p0.ncols())));
        }
        if extra0.len() != n - ix.n {
            return Err(invalid("extra0", format!("expected {} values for the extra blocks, got {}", n - ix.n, extra0.len())));
        }
        crate::error::check_finite("extra0", extra0.as_slice(), 1)?;
        for (field, v) in [("accel_bias0", &accel_bias0), ("gyro_bias0", &gyro_bias0)] {
            crate::error::check_finite(field, v.as_slice(), 1)?;
        }
        aiding.check_times()?;
        let kf = Kf::new(p0, cfg.mode)?;
        let sd = Strapdown::new(initial, kind, ell, Vertical::Free)?;
        Ok(AidedIns {
            sd,
            kf,
            layout,
            ell,
            cfg,
            aiding,
            accel_bias: accel_bias0,
            gyro_bias: gyro_bias0,
            extra: extra0,
            next_meas: 0,
            t_last_predict: initial.t,
            last_sample: None,
            last_rate: Vec3::zeros(),
            mount: None,
            steps_since: 0,
            samples: 0,
            baro: BaroModel { noise_psd: 0.0, bias: None },
            ix,
            store: false,
            covariance_out: false,
        })
    }

    /// The engine of `setup` with the sensor's model, the initial estimate of its extra
    /// blocks and `p0` over the whole layout (`setup.p0` when None).
    pub fn from_setup(setup: &InsSetup, extra0: DVector<f64>, p0: Option<DMatrix<f64>>, aiding: A) -> Result<Self> {
        let p0 = p0.unwrap_or_else(|| setup.p0.clone());
        let engine = AidedIns::new(setup.initial, setup.kind, setup.ell, setup.accel_bias0, setup.gyro_bias0, extra0, p0, setup.cfg, aiding)?.with_mount(setup.mount)?;
        match setup.damped {
            Some(d) => engine.with_damped_vertical(d.zeta, d.omega, d.baro),
            None => Ok(engine),
        }
    }

    /// Damp the vertical channel with a reference altitude h_b per IMU sample (then
    /// required by [`Self::process_ref`]): damping ratio ζ, natural frequency ω_v (rad/s)
    /// of the baro loop and the error model of h_b. With `baro.bias` a
    /// one-component `baro_bias` block (m, initial estimate 0 ± the given σ) is appended
    /// to the layout, after the aiding's blocks; the engine compensates h_b − b̂. Only
    /// before the first sample.
    pub fn with_damped_vertical(mut self, zeta: f64, omega: f64, baro: BaroModel) -> Result<Self> {
        if self.samples > 0 {
            return Err(invalid("vertical", "must be set before the first sample"));
        }
        self.sd = Strapdown::new(self.sd.state, self.sd.kind(), self.ell, Vertical::Damped { zeta, omega })?;
        baro.check()?;
        if let Some((_, sigma0)) = baro.bias {
            let mut spec: Vec<(String, Option<usize>)> = self.layout.blocks().iter().map(|(b, r)| (b.clone(), Some(r.len()))).collect();
            spec.push(("baro_bias".to_string(), Some(1)));
            self.layout = Layout::new(&spec)?;
            let n = self.layout.size();
            let mut p0 = self.kf.p.clone().resize(n, n, 0.0);
            // the last entry of the column-major n × n P₀: (n − 1, n − 1), the new block
            if let Some(v) = p0.as_mut_slice().last_mut() {
                *v = sigma0 * sigma0;
            }
            self.kf = Kf::new(p0, self.cfg.mode)?;
            self.extra = self.extra.clone().push(0.0);
        }
        self.baro = baro;
        Ok(self)
    }

    /// Mount the IMU by `mount` = C_imu^b: every sample is turned to the body frame
    /// (v_b = C v_imu) before the bias compensation and the strapdown, so the bias
    /// estimates are body-frame biases. Only before the first sample.
    pub fn with_mount(mut self, mount: Mat3) -> Result<Self> {
        if self.samples > 0 {
            return Err(invalid("mount", "must be set before the first sample"));
        }
        check_mount(&mount)?;
        self.mount = (mount != Mat3::identity()).then_some(mount);
        Ok(self)
    }

    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Number of states in the extra blocks (the sensor's, then `baro_bias`).
    pub fn n_extra(&self) -> usize {
        self.extra.len()
    }

    pub fn aiding(&self) -> &A {
        &self.aiding
    }

    /// Current error-state covariance P (n × n), e.g. for NEES.
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.kf.p
    }

    /// Output the full error-state covariance of every epoch from now on
    /// ([`AidedOutput::covariance`], 8n² bytes per epoch), or stop.
    pub fn output_covariance(&mut self, on: bool) {
        self.covariance_out = on;
    }

    /// Measurements not applied yet (their time is after the last processed sample).
    pub fn pending(&self) -> usize {
        self.aiding.times().len() - self.next_meas
    }

    /// Store the forward pass of every epoch from now on in [`AidedOutput::forward`], for
    /// the smoother ([`Self::smooth_chunk`]). Only before the first sample (a fixed-interval
    /// smoother needs the whole record).
    pub fn store_forward_pass(&mut self) -> Result<()> {
        if self.samples > 0 {
            return Err(invalid("smooth", "the forward pass must be stored from the first sample: request smoothing before processing the record"));
        }
        self.store = true;
        Ok(())
    }

    /// The Rauch–Tung–Striebel smoother (Rauch, Tung & Striebel 1965) over one chunk of
    /// the stored forward pass ([`ForwardPass`]); a record is smoothed chunk by chunk from
    /// its end, `after` carrying the step that follows the chunk and its smoothed moments
    /// (`x`, `p` of the first epoch of the next chunk's [`SmoothedChunk`]); `first` is the
    /// epoch index of the chunk's first step in the record (named by errors). The
    /// backward pass is [`rts_chunk`], on the filter's error states.
    ///
    /// Which nominal the smoothed error refers to. Let X̄⁻ₖ be the solution at epoch k
    /// before its update (the prior nominal) and δxₖ = X̄⁻ₖ ⊖ X_true its error.
    ///
    /// Open loop: the nominal is the free INS, X̄⁻ₖ₊₁ = f(X̄⁻ₖ), δxₖ₊₁ = Φₖ₊₁δxₖ + wₖ; the
    /// filter's x⁻, x⁺ are the prior and posterior means of δxₖ and the smoother is the
    /// textbook one: x^s_k = x⁺ₖ + Cₖ(x^s_{k+1} − x⁻ₖ₊₁), Cₖ = P⁺ₖΦᵀₖ₊₁(P⁻ₖ₊₁)⁻¹, and the
    /// smoothed solution is X̄⁻ₖ ⊖ x^s_k.
    ///
    /// Closed loop: after the update the estimate δx̂ₖ = x⁺ₖ is fed back, the corrected
    /// nominal X̄⁺ₖ = X̄⁻ₖ ⊖ δx̂ₖ has the error δxₖ − δx̂ₖ, and the next prior nominal is its
    /// propagation, X̄⁻ₖ₊₁ = f(X̄⁺ₖ), so δxₖ₊₁ = Φₖ₊₁(δxₖ − δx̂ₖ) + wₖ: the same linear-Gaussian
    /// model as open loop with the known input −Φₖ₊₁δx̂ₖ, whose prior mean is x⁻ₖ₊₁ =
    /// Φₖ₊₁x⁺ₖ − Φₖ₊₁δx̂ₖ = 0, as the filter has it after the reset. A known input leaves the
    /// RTS recursion unchanged in the stored x⁻ (= 0) and x⁺ (= δx̂ₖ): x^s_k = δx̂ₖ + Cₖx^s_{k+1}
    /// is the smoothed δxₖ relative to the prior nominal, and relative to the corrected
    /// nominal (the filter's output, stored) the smoothed error is x^s_k − δx̂ₖ = Cₖx^s_{k+1};
    /// the smoothed solution is X̄⁺ₖ ⊖ Cₖx^s_{k+1}, and at the last epoch X̄⁺ₖ itself. The
    /// covariances are those of open loop (a known input does not change them).
    ///
    /// Biases and extra blocks follow the same rule with their (additive) nominal values.
    pub fn smooth_chunk(&self, chunk: &ForwardPass, after: Option<(&StoredStep, DVector<f64>, DMatrix<f64>)>, first: usize) -> Result<SmoothedChunk> {
        let (n, n_extra) = (self.layout.size(), self.extra.len());
        let epochs = chunk.steps.len();
        if chunk.nominal.len() != epochs {
            return Err(invalid("nominal", format!("expected {epochs} rows like phi, got {}", chunk.nominal.len())));
        }
        if let Some(m) = chunk.steps.first().map(|s| s.p_post.nrows()).filter(|&m| m != n) {
            return Err(invalid("p_post", format!("expected the {n} states of the filter, got {m}")));
        }
        let smoothed = rts_chunk(&chunk.steps, after, first)?;
        let mut sm = SmoothedChunk::default();
        for (k, ((step, row), (x, p))) in chunk.steps.iter().zip(&chunk.nominal).zip(smoothed).enumerate() {
            let (nav, ba, bg, extra) = from_nominal_row(row)
                .filter(|r| r.3.len() == n_extra)
                .ok_or_else(|| crate::error::invalid_at("nominal", first + k, format!("row {} has {} values, expected {}", first + k, row.len(), NOMINAL_WIDTH + n_extra)))?;
            let dx = match self.cfg.mode {
                LoopMode::Closed => &x - &step.x_post,
                LoopMode::Open => x.clone(),
            };
            let ix = self.ix;
            let out = &mut sm.out;
            out.time.push(nav.t);
            out.nav.push(ix.remove_error(&self.ell, &nav, &dx));
            out.accel_bias.push(ba - block(&dx, ix.accel_bias));
            out.gyro_bias.push(bg - block(&dx, ix.gyro_bias));
            out.extra.extend((extra - dx.rows(ix.n, n - ix.n)).iter());
            out.sigma.extend(p.diagonal().iter().map(|d| d.sqrt()));
            sm.x.push(x);
            sm.p.push(p);
        }
        Ok(sm)
    }

    /// Feed one chunk of the IMU record (`t`, `gyro`, `accel` as for `Strapdown::run`);
    /// appends to `out`. On error `out` keeps every epoch computed before it.
    pub fn process(&mut self, t: &[f64], gyro: &[Vec3], accel: &[Vec3], out: &mut AidedOutput) -> Result<()> {
        self.process_ref(t, gyro, accel, None, out)
    }

    /// [`Self::process`] with the reference altitude `h_ref` (m) per sample, required with
    /// a damped vertical channel and refused with a free one.
    // invariant: gyro and accel have n = t.len() entries (checked above), h_ref n
    // entries (validate), n ≥ 1 here, and baro_bias is a layout index of the extra blocks
    // (< extra.len()); k < n.
    #[allow(clippy::indexing_slicing)]
    pub fn process_ref(&mut self, t: &[f64], gyro: &[Vec3], accel: &[Vec3], h_ref: Option<&[f64]>, out: &mut AidedOutput) -> Result<()> {
        let n = t.len();
        if gyro.len() != n || accel.len() != n {
            return Err(invalid("imu", format!("time has {n} samples but gyro {} and accel {}", gyro.len(), accel.len())));
        }
        if self.sd.vertical == Vertical::Free && h_ref.is_some() {
            return Err(invalid("h_ref", "given, but the vertical channel is free (a reference altitude needs vertical=\"damped\")"));
        }
        if n == 0 {
            return Ok(());
        }
        self.sd.validate(t, gyro, accel, h_ref, self.samples)?;
        let baro_bias = self.layout.extra_index("baro_bias");
        // A measurement before the first sample of the record can never be applied.
        if self.last_sample.is_none() {
            if let Some(&tm) = self.aiding.times().first().filter(|&&tm| tm < t[0]) {
                return Err(invalid(self.aiding.name(), format!("time {tm} s at index 0 is before the IMU record start {} s", t[0])));
            }
        }
        for k in 0..n {
            let dt = t[k] - self.sd.state.t;
            let (gyro_b, accel_b) = match self.mount {
                Some(m) => (m * gyro[k], m * accel[k]),
                None => (gyro[k], accel[k]),
            };
            let (g, a) = match self.sd.kind() {
                ImuKind::Rates => (gyro_b - self.gyro_bias, accel_b - self.accel_bias),
                ImuKind::Increments => (gyro_b - self.gyro_bias * dt, accel_b - self.accel_bias * dt),
            };
            // reference altitude compensated by the baro bias estimate
            let hb = h_ref.map(|h| h[k] - baro_bias.map_or(0.0, |i| self.extra[i]));
            self.sd.step(t[k], &g, &a, hb);
            self.sd.check_diverged(self.samples)?;
            self.samples += 1;
            self.aiding.observe(t[k], dt, &g, &a, &self.sd.state);
            let (f_b, w_b) = match self.sd.kind() {
                ImuKind::Rates => (a, g),
                ImuKind::Increments => (a / dt, g / dt),
            };
            self.last_sample = Some((t[k], f_b));
            self.last_rate = w_b;
            // A rate sample at the initial time only primes the integrator: not a step.
            if dt > 0.0 {
                self.steps_since += 1;
            }
            let due = self.next_meas < self.aiding.times().len() && self.aiding.times()[self.next_meas] <= t[k];
            if self.steps_since >= self.cfg.predict_every || due {
                self.epoch(out)?;
            }
        }
        Ok(())
    }

    /// End of the record: predict to the last sample if steps are left since the last
    /// epoch (so the output ends at the last sample).
    pub fn finish(&mut self, out: &mut AidedOutput) -> Result<()> {
        if self.steps_since > 0 {
            self.epoch(out)?;
        }
        Ok(())
    }

    /// Predict to the last sample, apply the measurements due, feed back, record.
    fn epoch(&mut self, out: &mut AidedOutput) -> Result<()> {
        // an epoch follows a sample; without one there is nothing to predict to
        let Some((tk, f_b)) = self.last_sample else { return Ok(()) };
        self.steps_since = 0;
        if tk <= self.t_last_predict {
            return Ok(());
        }
        let (mut f, mut qc) = error_dynamics(&self.layout, &self.ell, &self.sd.state, &f_b, &self.cfg.noise)?;
        if let Vertical::Damped { zeta, omega } = self.sd.vertical {
            baro_loop_dynamics(&self.layout, &self.ell, &self.sd.state, zeta, omega, &self.baro, &mut f, &mut qc)?;
        }
        self.aiding.extra_dynamics(&self.layout, &mut f, &mut qc);
        let dt = tk - self.t_last_predict;
        let (phi, qd) = discretize(&f, &qc, dt, self.cfg.method);
        self.kf.predict_unchecked(&phi, &qd)?;
        let prior = self.store.then(|| (self.kf.x.clone(), self.kf.p.clone()));
        self.t_last_predict = tk;
        // nominal values of the extra blocks follow their dynamics too (δx = nominal − true)
        self.aiding.propagate_extra(&self.layout, dt, self.extra.as_mut_slice());
        if let (Some(i), Some((model, _))) = (self.layout.extra_index("baro_bias"), self.baro.bias) {
            if let Some(e) = self.extra.get_mut(i) {
                *e *= (model.dynamics().0 * dt).exp();
            }
        }
        while let Some(&tm) = self.aiding.times().get(self.next_meas).filter(|&&tm| tm <= tk) {
            let j = self.next_meas;
            self.next_meas += 1;
            let ctx = AidingContext {
                t: tk,
                nav: &self.sd.state,
                accel_bias: self.accel_bias,
                gyro_bias: self.gyro_bias,
                gyro_rate: self.last_rate,
                x: &self.kf.x,
                extra: &self.extra,
                layout: &self.layout,
                ell: &self.ell,
            };
            let Some(m) = self.aiding.measure(j, &ctx)? else { continue };
            let rep = self.kf.update(&m.z, &m.h, &m.r, self.cfg.sequential, self.cfg.gate).map_err(|e| at_measurement(e, self.aiding.name(), j))?;
            out.meas_time.push(tm);
            out.meas_rows.push(m.z.len());
            out.innovation.extend_from_slice(&rep.innovation);
            out.nis.push(rep.nis.iter().sum());
            out.rejected.push(rep.rejected.len());
            out.meas_source.push(self.aiding.source_name(j).to_string());
        }
        let post = self.store.then(|| (self.kf.x.clone(), self.kf.p.clone()));
        if self.cfg.mode == LoopMode::Closed {
            let dx = self.kf.take_correction();
            let ix = self.ix;
            self.sd.state = ix.remove_error(&self.ell, &self.sd.state, &dx);
            self.accel_bias -= block(&dx, ix.accel_bias);
            self.gyro_bias -= block(&dx, ix.gyro_bias);
            self.extra -= dx.rows(ix.n, dx.len() - ix.n);
        }
        if let (Some((x_prior, p_prior)), Some((x_post, p_post))) = (prior, post) {
            out.forward.steps.push(StoredStep { phi, x_prior, p_prior, x_post, p_post });
            out.forward.qd.push(qd);
            out.forward.nominal.push(nominal_row(&self.sd.state, &self.accel_bias, &self.gyro_bias, &self.extra));
        }
        self.record(out);
        Ok(())
    }

    fn record(&self, out: &mut AidedOutput) {
        let (x, ix) = (&self.kf.x, self.ix);
        let (nav, ba, bg, extra) = match self.cfg.mode {
            LoopMode::Closed => (self.sd.state, self.accel_bias, self.gyro_bias, self.extra.clone()),
            LoopMode::Open => (
                ix.remove_error(&self.ell, &self.sd.state, x),
                self.accel_bias - block(x, ix.accel_bias),
                self.gyro_bias - block(x, ix.gyro_bias),
                &self.extra - x.rows(ix.n, x.len() - ix.n),
            ),
        };
        out.time.push(nav.t);
        out.nav.push(nav);
        out.accel_bias.push(ba);
        out.gyro_bias.push(bg);
        out.extra.extend(extra.iter());
        out.sigma.extend(self.kf.p.diagonal().iter().map(|d| d.sqrt()));
        if self.covariance_out {
            for row in self.kf.p.row_iter() {
                out.covariance.extend(row.iter());
            }
        }
    }
}

/// Measurement times of sensor `name`: finite and strictly increasing.
pub fn check_times(name: &str, times: &[f64]) -> Result<()> {
    let mut prev = None;
    for (i, &tm) in times.iter().enumerate() {
        if !tm.is_finite() {
            return Err(invalid(name, format!("non-finite time {tm} at index {i}")));
        }
        if prev.is_some_and(|p| tm <= p) {
            return Err(invalid(name, format!("time not strictly increasing at index {i}")));
        }
        prev = Some(tm);
    }
    Ok(())
}

/// Name the measurement in an invalid-input error of the update (NaN z, bad R, ...).
fn at_measurement(e: NavError, name: &str, j: usize) -> NavError {
    match e {
        NavError::InvalidInput { field, reason, .. } => {
            NavError::InvalidInput { field: format!("{name}[{j}] {field}"), reason, index: Some(j) }
        }
        other => other,
    }
}

/// Run over a whole record: every measurement must lie inside the IMU span.
pub fn run_aided<A: Aiding>(mut ins: AidedIns<A>, t: &[f64], gyro: &[Vec3], accel: &[Vec3]) -> Result<(AidedOutput, AidedIns<A>)> {
    let &[t0, .., t1] = t else {
        return Err(invalid("imu", format!("need >= 2 samples, got {}", t.len())));
    };
    if let Some((i, tm)) = ins.aiding.times().iter().enumerate().find(|(_, &tm)| !(tm >= t0 && tm <= t1)) {
        return Err(invalid(ins.aiding.name(), format!("time {tm} s at index {i} is outside the IMU span [{t0}, {t1}] s")));
    }
    let mut out = AidedOutput::default();
    ins.process(t, gyro, accel, &mut out)?;
    ins.finish(&mut out)?;
    Ok((out, ins))
}

/// A position fix: time (s), (lat rad, lon rad, h m) and its NED covariance (m²).
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct PositionFix {
    pub t: f64,
    pub lla: Vec3,
    pub cov_ned: Mat3,
}

/// Position fixes as an aiding sensor: z = NED(INS + Ĉ_b^n l − fix) for the lever arm l
/// of its [`Mounting`], H = [I 0 [(Ĉ_b^n l)×] 0 ...].
#[derive(serde::Serialize, serde::Deserialize)]
pub struct PositionAiding {
    times: Vec<f64>,
    fixes: Vec<PositionFix>,
    #[serde(default)]
    mounting: Mounting,
}

impl PositionFix {
    /// Fixes from columns: times (s), (lat, lon, h) and NED covariances (3 × 3, m²);
    /// `names` are the caller's arguments (times, positions, covariances), errors name
    /// them: a latitude outside ±π/2 names the positions and its row.
    pub fn table(names: [&str; 3], t: &[f64], lla: &[Vec3], cov: &[DMatrix<f64>]) -> Result<Vec<PositionFix>> {
        let cov = super::sources::fix_table(names, "position", t, lla, cov)?;
        // a latitude beyond ±π/2 (one in degrees) would pull the filter off the Earth
        let [_, positions, _] = names;
        crate::earth::check_latitudes(positions, lla)?;
        Ok(t.iter().zip(lla).zip(cov).map(|((&t, &lla), cov_ned)| PositionFix { t, lla, cov_ned }).collect())
    }
}

impl PositionAiding {
    pub fn new(fixes: Vec<PositionFix>) -> Result<Self> {
        super::sources::check_fix_rows(["fixes", "fixes"], "position", fixes.iter().map(|f| (&f.lla, &f.cov_ned)))?;
        Ok(PositionAiding { times: fixes.iter().map(|f| f.t).collect(), fixes, mounting: Mounting::default() })
    }

    /// These fixes measured at the lever arm and time offset of `mounting`.
    pub fn with_mounting(mut self, mounting: Mounting) -> Self {
        self.times = mounting.imu_times(&self.fixes.iter().map(|f| f.t).collect::<Vec<_>>());
        self.mounting = mounting;
        self
    }
}

#[typetag::serde]
impl Aiding for PositionAiding {
    fn name(&self) -> &str {
        "position_fixes"
    }
    fn times(&self) -> &[f64] {
        &self.times
    }
    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        let fx = self.fixes.get(j).ok_or_else(|| invalid("position_fixes", format!("no fix {j} (of {})", self.fixes.len())))?;
        let mut z = ned_diff(ctx.ell, &ctx.nav.lla, &fx.lla);
        let mut h = DMatrix::<f64>::zeros(3, ctx.layout.size());
        h.view_mut((0, ctx.layout.range("position")?.start), (3, 3)).fill_with_identity();
        self.mounting.add_position_terms(ctx, &mut z, &mut h)?;
        Ok(Some(Measurement { z: z.as_slice().to_vec(), h, r: DMatrix::from_column_slice(3, 3, fx.cov_ned.as_slice()) }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::ins::BiasModel;

    fn config(mode: LoopMode) -> AidedConfig {
        let noise = InsNoise { accel_psd: 1e-8, gyro_psd: 1e-14, accel_bias: BiasModel::RandomConstant, gyro_bias: BiasModel::RandomConstant };
        AidedConfig { noise, predict_every: 7, method: Discretization::VanLoan, mode, sequential: false, gate: None }
    }

    /// A stationary record with an accelerometer bias, fixes every 0.5 s.
    fn record() -> (NavState, Vec<f64>, Vec<Vec3>, Vec<Vec3>, Vec<PositionFix>) {
        let ell = crate::earth::WGS84;
        let lla = Vec3::new(0.8, 0.2, 100.0);
        let loc = ell.local(lla.x, lla.z);
        let t: Vec<f64> = (0..=500).map(|k| k as f64 * 0.01).collect();
        let gyro = vec![loc.earth_rate(); t.len()];
        let accel = vec![Vec3::new(1e-3, 0.0, -loc.gravity); t.len()];
        let fixes = (1..10).map(|i| PositionFix { t: i as f64 * 0.5, lla, cov_ned: Mat3::identity() }).collect();
        (NavState { t: 0.0, lla, vel: Vec3::zeros(), q_nb: crate::math::quat(1.0, 0.0, 0.0, 0.0) }, t, gyro, accel, fixes)
    }

    fn engine(mode: LoopMode) -> AidedIns<PositionAiding> {
        engine_with(mode, |a| a)
    }

    /// The engine of `record` with its position aiding as `wrap` makes it (e.g. boxed).
    fn engine_with<A: Aiding>(mode: LoopMode, wrap: impl FnOnce(PositionAiding) -> A) -> AidedIns<A> {
        let (s0, _, _, _, fixes) = record();
        let p0 = DMatrix::from_diagonal(&DVector::from_vec([1.0, 1.0, 1.0, 0.01, 0.01, 0.01, 1e-6, 1e-6, 1e-6, 1e-4, 1e-4, 1e-4, 1e-10, 1e-10, 1e-10].to_vec()));
        let ell = crate::earth::WGS84;
        AidedIns::new(s0, ImuKind::Rates, ell, Vec3::zeros(), Vec3::zeros(), DVector::zeros(0), p0, config(mode), wrap(PositionAiding::new(fixes).unwrap())).unwrap()
    }

    /// Streaming in uneven chunks equals one batch call, to the last bit.
    #[test]
    fn chunks_equal_batch() {
        let (_, t, g, a, _) = record();
        for mode in [LoopMode::Closed, LoopMode::Open] {
            let (batch, _) = run_aided(engine(mode), &t, &g, &a).unwrap();
            let mut ins = engine(mode);
            let mut out = AidedOutput::default();
            for (lo, hi) in [(0, 3), (3, 140), (140, 141), (141, 501)] {
                ins.process(&t[lo..hi], &g[lo..hi], &a[lo..hi], &mut out).unwrap();
            }
            ins.finish(&mut out).unwrap();
            assert_same_output(&batch, &out, 9);
        }
    }

    /// An engine with a boxed sensor, saved mid-record and restored (the sensor by its
    /// registered name), continues bit for bit like the original.
    #[test]
    fn saved_engine_continues_bit_for_bit() {
        let (_, t, g, a, _) = record();
        let mut ins = engine_with(LoopMode::Closed, |a| Box::new(a) as Box<dyn Aiding>);
        let mut out = AidedOutput::default();
        ins.process(&t[..123], &g[..123], &a[..123], &mut out).unwrap();
        let bytes = crate::state::save("AidedIns", &ins).unwrap();
        let mut copy: AidedIns<Box<dyn Aiding>> = crate::state::load("AidedIns", &bytes).unwrap();
        let (mut want, mut got) = (AidedOutput::default(), AidedOutput::default());
        ins.process(&t[123..], &g[123..], &a[123..], &mut want).unwrap();
        copy.process(&t[123..], &g[123..], &a[123..], &mut got).unwrap();
        assert_same_output(&want, &got, 7);
    }

    /// Two runs' outputs equal to the last bit, with `measurements` measurements applied.
    fn assert_same_output(want: &AidedOutput, got: &AidedOutput, measurements: usize) {
        assert_eq!(want.nav, got.nav);
        assert_eq!(want.sigma, got.sigma);
        assert_eq!(want.nis, got.nis);
        assert_eq!(want.innovation, got.innovation);
        assert_eq!((want.meas_time.len(), got.meas_time.len()), (measurements, measurements));
    }

    /// The smoother over the stored forward pass: chunk by chunk from the end equals one
    /// chunk, its σ is at most the filter's, and closed and open loop (two linearisations
    /// of one problem, whose smoothed error states refer to different nominals) give the
    /// same smoothed solution to well within σ.
    #[test]
    fn smoother_chunks_and_loop_modes_agree() {
        let (_, t, g, a, _) = record();
        let mut smoothed = vec![];
        for mode in [LoopMode::Closed, LoopMode::Open] {
            let mut ins = engine(mode);
            ins.store_forward_pass().unwrap();
            let (out, ins) = run_aided(ins, &t, &g, &a).unwrap();
            let f = &out.forward;
            assert_eq!((f.steps.len(), f.nominal.len(), f.qd.len()), (out.time.len(), out.time.len(), out.time.len()));
            let whole = ins.smooth_chunk(f, None, 0).unwrap();
            let (e, size) = (f.steps.len(), 4);
            let mut parts: Vec<SmoothedChunk> = vec![];
            for lo in (0..e).step_by(size).rev() {
                let hi = (lo + size).min(e);
                let part = ForwardPass { steps: f.steps[lo..hi].to_vec(), qd: vec![], nominal: f.nominal[lo..hi].to_vec() };
                let after = parts.last().and_then(|p| Some((f.steps.get(hi)?, p.x[0].clone(), p.p[0].clone())));
                parts.push(ins.smooth_chunk(&part, after, lo).unwrap());
            }
            let nav: Vec<NavState> = parts.iter().rev().flat_map(|p| p.out.nav.clone()).collect();
            let sigma: Vec<f64> = parts.iter().rev().flat_map(|p| p.out.sigma.clone()).collect();
            assert_eq!((&nav, &sigma), (&whole.out.nav, &whole.out.sigma), "{mode:?}");
            assert!(whole.out.sigma.iter().zip(&out.sigma).all(|(s, f)| *s <= f * (1.0 + 1e-12)), "{mode:?}");
            smoothed.push(whole.out);
        }
        let (c, o) = (&smoothed[0], &smoothed[1]);
        for k in 0..c.time.len() {
            let dv = (c.nav[k].vel - o.nav[k].vel).norm();
            let dba = (c.accel_bias[k] - o.accel_bias[k]).norm();
            // σ of velocity and accel bias (states 3 and 9 of 15)
            let (sv, sba) = (c.sigma[k * 15 + 3], c.sigma[k * 15 + 9]);
            assert!(dv < 0.01 * sv && dba < 0.01 * sba, "epoch {k}: closed - open {dv} m/s (σ {sv}), {dba} m/s² (σ {sba})");
        }
    }

    /// A fix latitude in degrees (45.8 "rad") is an error naming `fix_lla` and its row.
    #[test]
    fn fix_latitude_beyond_half_pi_names_fix_lla_and_its_row() {
        let lla = [Vec3::new(0.8, 0.2, 100.0), Vec3::new(45.8, 0.2, 100.0)];
        let cov = vec![DMatrix::<f64>::identity(3, 3); 2];
        match PositionFix::table(["fix_t", "fix_lla", "fix_cov"], &[0.5, 1.0], &lla, &cov) {
            Err(NavError::InvalidInput { field, index, .. }) => assert_eq!((field.as_str(), index), ("fix_lla", Some(1))),
            other => panic!("expected an invalid fix_lla, got {:?}", other.map(|f| f.len())),
        }
    }

    #[test]
    fn chunk_time_must_keep_increasing() {
        let (_, t, g, a, _) = record();
        let mut ins = engine(LoopMode::Closed);
        let mut out = AidedOutput::default();
        ins.process(&t[..10], &g[..10], &a[..10], &mut out).unwrap();
        let err = ins.process(&t[5..10], &g[5..10], &a[5..10], &mut out).unwrap_err();
        // the index is the sample's place in the whole record (10 samples came before)
        assert!(err.to_string().contains("time not strictly increasing: decreasing stamp 0.05 at index 10"), "{err}");
    }

    /// No measurements, one extra block (bias, drift) with ḃ = drift: the nominal bias
    /// follows the drift through the `propagate_extra` hook, in both loop modes.
    #[derive(serde::Serialize, serde::Deserialize)]
    struct Drift;

    #[typetag::serde]
    impl Aiding for Drift {
        fn extra_blocks(&self) -> Vec<(String, usize)> {
            vec![("clk".to_string(), 2)]
        }
        fn times(&self) -> &[f64] {
            &[]
        }
        fn measure(&mut self, _j: usize, _ctx: &AidingContext) -> Result<Option<Measurement>> {
            Ok(None)
        }
        fn extra_dynamics(&self, layout: &Layout, f: &mut DMatrix<f64>, _qc: &mut DMatrix<f64>) {
            let i = layout.get("clk").unwrap().start;
            f[(i, i + 1)] = 1.0;
        }
        fn propagate_extra(&self, layout: &Layout, dt: f64, extra: &mut [f64]) {
            let i = layout.extra_index("clk").unwrap();
            extra[i] += extra[i + 1] * dt;
        }
    }

    #[test]
    fn nominal_extra_blocks_follow_their_dynamics() {
        let (s0, t, g, a, _) = record();
        let ell = crate::earth::WGS84;
        for mode in [LoopMode::Closed, LoopMode::Open] {
            let p0 = DMatrix::identity(17, 17) * 1e-4;
            let ins = AidedIns::new(s0, ImuKind::Rates, ell, Vec3::zeros(), Vec3::zeros(), DVector::from_vec(vec![1.0, 0.5]), p0, config(mode), Drift).unwrap();
            let (out, _) = run_aided(ins, &t, &g, &a).unwrap();
            let last = &out.extra[out.extra.len() - 2..];
            assert!((last[0] - (1.0 + 0.5 * 5.0)).abs() < 1e-12 && last[1] == 0.5, "{mode:?}: {last:?}");
        }
    }
}
