//! CAI-aided INS scenarios and their Monte Carlo (Tennstedt et al. 2023, §5; Tennstedt et al. 2021, §5): a truth
//! trajectory with its ideal IMU, an IMU error model, a CAI (channels, shots, readout
//! noise) and the aided-INS engine with [`CaiAiding`]; every run also integrates the same
//! IMU record without aiding (the IMU-only baseline). Runs are independent and seeded
//! (ChaCha20, stream = run index), so any subset reproduces anywhere; they run in
//! parallel with rayon.

use super::aiding::{CaiAiding, CaiConfig, CaiData};
use super::predictor::{predict, Imu, Interpolation, OmegaDot, PredictorConfig};
use crate::earth::{Ellipsoid, KINEMATIC, WGS84};
use crate::error::{check_count, check_positive, invalid, invalid_at, Result};
use crate::filter::aided::{AidedConfig, AidedIns, AidedOutput, Aiding};
use crate::filter::discretize::Discretization;
use crate::filter::ins::{BiasModel, InsNoise};
use crate::filter::kf::LoopMode;
use crate::filter::layout::ins_size;
use crate::imu::errors::{ImuErrorModel, ImuSimulator};
use crate::imu::ideal::{body_from_kinematics, ideal_rates};
use crate::imu::ImuKind;
use crate::filter::initial_error::draw_start;
use crate::math::{dcm_from_quat, quat_mul, rotation_quats, rotvec_from_quat, Quat, Vec3};
use crate::options::Choice;
use crate::strapdown::{NavState, Strapdown, Vertical};
use crate::trajectory::{Kinematics, Motion, TruthState};
use nalgebra::{DMatrix, DVector};
use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// Gravity of a scenario (option `gravity`): "kinematic" (no gravity, no Earth rate:
/// Tennstedt et al. 2023's kinematic mode) or "earth" (WGS84 normal gravity and rotation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GravityModel {
    Kinematic,
    Earth,
}

impl Choice for GravityModel {
    const PARAMETER: &'static str = "gravity";
    const CHOICES: &'static [(&'static str, Self)] = &[("kinematic", GravityModel::Kinematic), ("earth", GravityModel::Earth)];
}

impl GravityModel {
    /// The Earth model the truth, the IMU and the filter use under this gravity.
    pub fn ellipsoid(self) -> Ellipsoid {
        match self {
            GravityModel::Kinematic => KINEMATIC,
            GravityModel::Earth => WGS84,
        }
    }
}

/// The name of a phase source (option `phase_source`), see [`PhaseSource`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PhaseSourceKind {
    Ideal,
    Reference,
}

impl Choice for PhaseSourceKind {
    const PARAMETER: &'static str = "phase_source";
    const CHOICES: &'static [(&'static str, Self)] = &[("ideal", PhaseSourceKind::Ideal), ("reference", PhaseSourceKind::Reference)];
}

/// Largest number of IMU samples of a scenario (checked before the truth is allocated).
pub const MAX_SAMPLES: usize = 100_000_000;

/// The scenario settings besides motion, IMU models, CAI and P0, checked once by
/// [`HybridScenario::new`].
#[derive(Clone, Debug)]
pub struct HybridConfig {
    pub gravity: GravityModel,
    /// Navigation IMU rate (Hz).
    pub rate_hz: f64,
    /// Rate (Hz) of the truth the ideal CAI phases are computed from ([`PhaseSourceKind::Ideal`]).
    pub truth_rate_hz: Option<f64>,
    pub phase_source: PhaseSourceKind,
    /// Filter noise: white PSDs (accel m²/s³, gyro rad²/s), bias random-walk PSDs (m²/s⁵, rad²/s³).
    pub accel_psd: f64,
    pub gyro_psd: f64,
    pub accel_bias_psd: f64,
    pub gyro_bias_psd: f64,
    /// Prediction interval in IMU steps.
    pub predict_every: usize,
    /// With CAI updates (false: the "no hidden aiding" check).
    pub aiding: bool,
    /// Draw the initial navigation error from P0 (see [`HybridScenario::draw_initial`]).
    pub draw_initial: bool,
}

impl HybridConfig {
    /// The filter of every CAI scenario: Van Loan discretisation, closed loop, one stacked
    /// update per shot, bias random walks (Tennstedt et al. 2023, §2.8).
    pub fn filter(&self) -> AidedConfig {
        let rw = |psd: f64| BiasModel::RandomWalk { psd };
        AidedConfig {
            noise: InsNoise { accel_psd: self.accel_psd, gyro_psd: self.gyro_psd, accel_bias: rw(self.accel_bias_psd), gyro_bias: rw(self.gyro_bias_psd) },
            predict_every: self.predict_every,
            method: Discretization::VanLoan,
            mode: LoopMode::Closed,
            sequential: false,
            gate: None,
        }
    }
}

/// How the instrument's true phase is produced.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum PhaseSource {
    /// A perfect CAI on the true motion: the predictor applied to the ideal IMU sampled
    /// `oversample` times faster than the navigation IMU, with the exact ω̇ and cubic
    /// interpolation (truth integrated at 2 kHz); one set of phases
    /// serves every run.
    Ideal(Vec<f64>),
    /// A CAI emulated from a better reference IMU (Tennstedt et al. 2021, Eq. 38, hexapod): per run, the
    /// predictor applied to the ideal IMU corrupted with this model (Savitzky–Golay ω̇);
    /// the estimated biases are then relative to the reference IMU's.
    Reference(ImuErrorModel),
}

/// Everything a run needs; built once, shared by all runs.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct HybridScenario {
    #[serde(with = "crate::options::by_name")]
    pub ell: Ellipsoid,
    /// IMU sample times (s) and the truth at each.
    pub t: Vec<f64>,
    pub truth: Vec<TruthState>,
    /// Ideal specific force (m/s²) and angular rate (rad/s) at `t`.
    pub f: Vec<Vec3>,
    pub w: Vec<Vec3>,
    pub imu_model: ImuErrorModel,
    pub cai: CaiConfig,
    pub phase: PhaseSource,
    pub filter: AidedConfig,
    pub p0: DMatrix<f64>,
    /// Without CAI updates (no shots): the "no hidden aiding" check.
    pub aiding: bool,
    /// Draw the initial navigation error (position, velocity, attitude) from the diagonal
    /// of P0 (a consistent start for NEES); false = start at the truth.
    pub draw_initial: bool,
}

/// Navigation errors estimate − truth (`trajectory::nav_error`).
fn nav_error(ell: &Ellipsoid, est: &NavState, truth: &TruthState) -> [f64; 9] {
    crate::trajectory::nav_error(ell, (&est.lla, &est.vel, &est.q_nb), (&truth.lla, &truth.vel, &truth.q_nb))
}

/// One run, per output epoch (the engine's prediction epochs).
#[derive(Clone, Debug, Default)]
pub struct HybridRun {
    pub time: Vec<f64>,
    /// Errors (9 per epoch, [`nav_error`]) of the hybrid solution and of the IMU-only one.
    pub hybrid: Vec<[f64; 9]>,
    pub free: Vec<[f64; 9]>,
    /// Bias estimates (accel m/s², gyro rad/s) and the truth they estimate.
    pub bias: Vec<[f64; 6]>,
    pub bias_true: Vec<[f64; 6]>,
    /// Accelerometer error (measured − ideal, m/s²) of every IMU sample.
    pub accel_error: Vec<[f64; 3]>,
    /// σ of every filter state (epochs × n, row-major), n = state size.
    pub sigma: Vec<f64>,
    /// NEES (δx̂ − δx)ᵀ P⁻¹ (δx̂ − δx) of the 15 INS states per epoch.
    pub nees: Vec<f64>,
    /// Per shot and channel: true − predicted phase (rad).
    pub phase_error: Vec<f64>,
}

fn state_at(s: &TruthState) -> NavState {
    NavState { t: s.t, lla: s.lla, vel: s.vel, q_nb: s.q_nb }
}

impl HybridScenario {
    /// The scenario of `motion` under `cfg`: truth and ideal IMU at `cfg.rate_hz`, the true
    /// phases of the chosen source (ideal phases from a truth at `cfg.truth_rate_hz`, which
    /// may equal the IMU rate, or a reference IMU `reference`), the filter of
    /// [`HybridConfig::filter`]; `cai` carries the shots.
    pub fn new(motion: &Motion, cfg: &HybridConfig, imu_model: ImuErrorModel, reference: Option<ImuErrorModel>, cai: CaiConfig, p0: nalgebra::DMatrix<f64>) -> Result<Self> {
        let ell = cfg.gravity.ellipsoid();
        let reference = Self::check(cfg, &imu_model, reference, &cai, &p0)?;
        let (t, truth, f, w) = Self::imu_truth(motion, &ell, cfg.rate_hz)?;
        let phase = match (reference, cfg.truth_rate_hz) {
            (Some(model), _) => PhaseSource::Reference(model),
            (None, Some(r)) if r == cfg.rate_hz => PhaseSource::Ideal(Self::ideal_phases(motion, &ell, &t, &truth, &f, &w, &cai)?),
            (None, Some(r)) => {
                let (tt, tr, tf, tw) = Self::imu_truth(motion, &ell, r)?;
                PhaseSource::Ideal(Self::ideal_phases(motion, &ell, &tt, &tr, &tf, &tw, &cai)?)
            }
            (None, None) => return Err(invalid("truth_rate_hz", "required when phase_source = 'ideal'")),
        };
        Ok(HybridScenario { ell, t, truth, f, w, imu_model, cai, phase, filter: cfg.filter(), p0, aiding: cfg.aiding, draw_initial: cfg.draw_initial })
    }

    /// The scenario of a sampled trajectory (user data): sample times `t` (s, evenly spaced
    /// at `cfg.rate_hz`), positions (lat rad, lon rad, h m), NED velocities (m/s) and
    /// attitudes `q_nb`. The ideal IMU at the samples comes from the trajectory by finite
    /// differences ([`table_imu`]); the truth is the strapdown integral of that ideal IMU
    /// from the first sample, so an error-free IMU navigates exactly on it (it departs from
    /// the table by the differences' error); a perfect CAI's phases are the sensor's own
    /// predictor applied to the ideal IMU ("ideal"; there is no truth between the samples,
    /// so `truth_rate_hz` must be None or the table's rate) or a reference IMU's.
    #[allow(clippy::too_many_arguments)]
    pub fn from_table(
        t: Vec<f64>,
        lla: &[Vec3],
        vel: &[Vec3],
        q_nb: &[Quat],
        cfg: &HybridConfig,
        imu_model: ImuErrorModel,
        reference: Option<ImuErrorModel>,
        cai: CaiConfig,
        p0: DMatrix<f64>,
    ) -> Result<Self> {
        let ell = cfg.gravity.ellipsoid();
        let reference = Self::check(cfg, &imu_model, reference, &cai, &p0)?;
        check_count("trajectory", t.len(), 3, MAX_SAMPLES)?;
        let q_nb = rotation_quats("trajectory", q_nb)?;
        let (f, w, acc, w_nb) = table_imu(&ell, &t, lla, vel, &q_nb, cfg.rate_hz)?;
        if let Some(r) = cfg.truth_rate_hz.filter(|&r| reference.is_none() && r != cfg.rate_hz) {
            return Err(invalid("truth_rate_hz", format!("{r} Hz, but a sampled trajectory has no truth between its samples: give None (or its rate {} Hz)", cfg.rate_hz)));
        }
        let start = NavState { t: t.first().copied().unwrap_or(0.0), lla: lla.first().copied().unwrap_or_default(), vel: vel.first().copied().unwrap_or_default(), q_nb: q_nb.first().copied().unwrap_or_else(Quat::identity) };
        let mut nav = Vec::with_capacity(t.len());
        Strapdown::new(start, ImuKind::Rates, ell, Vertical::Free)?.run(&t, &w, &f, None, &mut nav)?;
        let truth = nav.iter().zip(acc.iter().zip(&w_nb)).map(|(s, (&acc, &w_nb_b))| TruthState { t: s.t, lla: s.lla, vel: s.vel, acc, q_nb: s.q_nb, w_nb_b }).collect();
        let phase = match reference {
            Some(model) => PhaseSource::Reference(model),
            None => PhaseSource::Ideal(predict(Imu { t: &t, f: &f, w: &w }, &cai.shots, &cai.channels, &cai.predictor())?.iter().map(|r| r[0]).collect()),
        };
        Ok(HybridScenario { ell, t, truth, f, w, imu_model, cai, phase, filter: cfg.filter(), p0, aiding: cfg.aiding, draw_initial: cfg.draw_initial })
    }

    /// The checks every scenario shares: the CAI, the IMU models, the filter settings, the
    /// phase source against the reference model (returned when the source is "reference")
    /// and the size of P0.
    fn check(cfg: &HybridConfig, imu_model: &ImuErrorModel, reference: Option<ImuErrorModel>, cai: &CaiConfig, p0: &DMatrix<f64>) -> Result<Option<ImuErrorModel>> {
        cai.check()?;
        imu_model.validate()?;
        check_count("predict_every", cfg.predict_every, 1, MAX_SAMPLES)?;
        for (name, q) in [("accel_psd", cfg.accel_psd), ("gyro_psd", cfg.gyro_psd), ("accel_bias_psd", cfg.accel_bias_psd), ("gyro_bias_psd", cfg.gyro_bias_psd)] {
            if !(q.is_finite() && q >= 0.0) {
                return Err(invalid(name, format!("must be finite and >= 0, got {q}")));
            }
        }
        let reference = match (cfg.phase_source, reference) {
            (PhaseSourceKind::Reference, Some(model)) => {
                model.validate()?;
                Some(model)
            }
            (PhaseSourceKind::Reference, None) => return Err(invalid("reference", "required when phase_source = 'reference'")),
            (PhaseSourceKind::Ideal, Some(_)) => return Err(invalid("reference", "given, but phase_source = 'ideal' would ignore it")),
            (PhaseSourceKind::Ideal, None) => None,
        };
        let n = ins_size() + cai_extra_states(cai);
        if p0.nrows() != n || p0.ncols() != n {
            return Err(invalid("p0", format!("expected {n} × {n} ({} INS states and the CAI's extra states), got {} × {}", ins_size(), p0.nrows(), p0.ncols())));
        }
        Ok(reference)
    }

    /// Truth and ideal IMU of `motion` at `rate_hz` over its duration.
    pub fn imu_truth(motion: &Motion, ell: &Ellipsoid, rate_hz: f64) -> Result<(Vec<f64>, Vec<TruthState>, Vec<Vec3>, Vec<Vec3>)> {
        check_positive("rate_hz", rate_hz)?;
        let n = check_count("rate_hz", ((motion.duration * rate_hz + 1e-9).floor() as usize).saturating_add(1), 2, MAX_SAMPLES)?;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / rate_hz).collect();
        let truth = motion.truth(ell, &t)?;
        let (f, w, _) = ideal_rates(motion, ell, &truth);
        Ok((t, truth, f, w))
    }

    /// True phases of a perfect CAI (see [`PhaseSource::Ideal`]) from the ideal IMU at the
    /// truth samples `t`, `truth`, `f`, `w` of `motion` (ω̇ exact).
    pub fn ideal_phases(motion: &Motion, ell: &Ellipsoid, t: &[f64], truth: &[TruthState], f: &[Vec3], w: &[Vec3], cai: &CaiConfig) -> Result<Vec<f64>> {
        let (_, _, wd) = ideal_rates(motion, ell, truth);
        let cfg = PredictorConfig { substeps: 1, omega_dot: OmegaDot::Given(wd), interpolation: Interpolation::Cubic, ..cai.predictor() };
        Ok(predict(Imu { t, f, w }, &cai.shots, &cai.channels, &cfg)?.iter().map(|r| r[0]).collect())
    }

    /// Run `run` of the Monte Carlo seeded by `master_seed`.
    // invariant: new makes t ≥ 2 samples (imu_truth) with truth, f, w one per sample; the
    // simulated IMU series, its biases and free_nav have one entry per sample too, k < t.len()
    // is checked before use, lo < hi ≤ t.len(), and nees holds one entry per output epoch e.
    #[allow(clippy::indexing_slicing)]
    pub fn run(&self, master_seed: u64, run: u64) -> Result<HybridRun> {
        let mut rng = ChaCha20Rng::seed_from_u64(master_seed);
        rng.set_stream(run);
        let dt = self.t[1] - self.t[0];
        let imu = ImuSimulator::new(&self.imu_model, dt, ImuKind::Rates, rng.next_u64())?.corrupt(&self.f, &self.w)?;
        let (phase, reference_bias) = match &self.phase {
            PhaseSource::Ideal(p) => (p.clone(), None),
            PhaseSource::Reference(model) => {
                let r = ImuSimulator::new(model, dt, ImuKind::Rates, rng.next_u64())?.corrupt(&self.f, &self.w)?;
                let p = predict(Imu { t: &self.t, f: &r.accel, w: &r.gyro }, &self.cai.shots, &self.cai.channels, &self.cai.predictor())?;
                (p.iter().map(|r| r[0]).collect(), Some((r.accel_bias, r.gyro_bias)))
            }
        };
        let noise: Vec<f64> = (0..phase.len()).map(|_| { let u: f64 = StandardNormal.sample(&mut rng); self.cai.sigma_p * u }).collect();
        let mut cfg = self.cai.clone();
        let data = if self.aiding {
            CaiData::Emulated { phase, noise }
        } else {
            cfg.shots.clear();
            CaiData::Emulated { phase: Vec::new(), noise: Vec::new() }
        };
        let aiding = CaiAiding::new(cfg, data)?;
        let n_extra: usize = aiding.extra_blocks().iter().map(|b| b.1).sum();
        let mut initial = state_at(&self.truth[0]);
        if self.draw_initial {
            // δx = estimate − truth ~ N(0, P0 navigation block)
            initial = draw_start(&self.ell, &initial, &self.p0, &mut rng)?;
        }
        let mut ins = AidedIns::new(initial, ImuKind::Rates, self.ell, Vec3::zeros(), Vec3::zeros(), DVector::zeros(n_extra), self.p0.clone(), self.filter, aiding)?;
        let (t0, t1) = (self.t[0], self.t[self.t.len() - 1]);
        if let Some((i, tm)) = ins.aiding().times().iter().enumerate().find(|(_, &tm)| !(tm >= t0 && tm <= t1)) {
            return Err(invalid("shots", format!("shot {i} ends at {tm} s, outside the IMU record [{t0}, {t1}] s")));
        }
        // chunks of one prediction interval, so that P is read at every output epoch (NEES)
        let mut out = AidedOutput::default();
        let mut nees = Vec::new();
        let step = self.filter.predict_every;
        let mut lo = 0;
        while lo < self.t.len() {
            let hi = (lo + step).min(self.t.len());
            let before = out.time.len();
            ins.process(&self.t[lo..hi], &imu.gyro[lo..hi], &imu.accel[lo..hi], &mut out)?;
            if hi == self.t.len() {
                ins.finish(&mut out)?;
            }
            for e in before..out.time.len() {
                nees.push((e, ins.covariance().view((0, 0), (15, 15)).into_owned()));
            }
            lo = hi;
        }
        let mut free_nav = Vec::with_capacity(self.t.len());
        Strapdown::new(initial, ImuKind::Rates, self.ell, Vertical::Free)?.run(&self.t, &imu.gyro, &imu.accel, None, &mut free_nav)?;
        let mut res = HybridRun { sigma: out.sigma, phase_error: ins.aiding().log.phase_error.clone(), ..Default::default() };
        res.accel_error = imu.accel.iter().zip(&self.f).map(|(m, f)| [m.x - f.x, m.y - f.y, m.z - f.z]).collect();
        for (e, &te) in out.time.iter().enumerate() {
            let k = ((te - t0) / dt).round() as usize;
            if k >= self.t.len() || (self.t[k] - te).abs() > 1e-9 {
                return Err(invalid("time", format!("output epoch {te} s is not an IMU sample time")));
            }
            let tr = &self.truth[k];
            res.time.push(te);
            let err = nav_error(&self.ell, &out.nav[e], tr);
            res.hybrid.push(err);
            res.free.push(nav_error(&self.ell, &free_nav[k], tr));
            let (ba, bg) = (out.accel_bias[e], out.gyro_bias[e]);
            res.bias.push([ba.x, ba.y, ba.z, bg.x, bg.y, bg.z]);
            let (mut ta, mut tg) = (imu.accel_bias[k], imu.gyro_bias[k]);
            if let Some((ra, rg)) = &reference_bias {
                ta -= ra[k];
                tg -= rg[k];
            }
            res.bias_true.push([ta.x, ta.y, ta.z, tg.x, tg.y, tg.z]);
            // NEES of the 15 INS states: δx = (navigation errors, b̂ − b)
            let dx = DVector::from_iterator(15, err.iter().copied().chain((0..3).map(|i| ba[i] - ta[i])).chain((0..3).map(|i| bg[i] - tg[i])));
            let p = &nees[e].1;
            res.nees.push(p.clone().cholesky().map_or(f64::NAN, |c| dx.dot(&c.solve(&dx))));
        }
        Ok(res)
    }

    /// Runs `runs` of the Monte Carlo in parallel (rayon), in the order given.
    pub fn monte_carlo(&self, master_seed: u64, runs: &[u64]) -> Result<Vec<HybridRun>> {
        runs.par_iter().map(|&r| self.run(master_seed, r)).collect()
    }

    /// [`monte_carlo`](Self::monte_carlo) as row-major tables, run by run.
    pub fn monte_carlo_tables(&self, master_seed: u64, runs: &[u64]) -> Result<McTables> {
        let res = self.monte_carlo(master_seed, runs)?;
        let epochs = res.first().map_or(0, |r| r.time.len());
        if res.iter().any(|r| r.time.len() != epochs) {
            return Err(crate::NavError::Numerical("runs produced different numbers of epochs".into()));
        }
        let channels = self.cai.channels.len();
        let flat = |get: &dyn Fn(&HybridRun) -> Vec<f64>| res.iter().flat_map(get).collect::<Vec<f64>>();
        Ok(McTables {
            runs: res.len(),
            epochs,
            states: res.first().and_then(|r| r.sigma.len().checked_div(epochs)).unwrap_or(0),
            shots: res.first().and_then(|r| r.phase_error.len().checked_div(channels)).unwrap_or(0),
            channels,
            time: res.first().map_or_else(Vec::new, |r| r.time.clone()),
            imu_time: self.t.clone(),
            hybrid: flat(&|r| r.hybrid.iter().flatten().copied().collect()),
            free: flat(&|r| r.free.iter().flatten().copied().collect()),
            bias: flat(&|r| r.bias.iter().flatten().copied().collect()),
            bias_true: flat(&|r| r.bias_true.iter().flatten().copied().collect()),
            accel_error: flat(&|r| r.accel_error.iter().flatten().copied().collect()),
            sigma: flat(&|r| r.sigma.clone()),
            nees: flat(&|r| r.nees.clone()),
            phase_error: flat(&|r| r.phase_error.clone()),
        })
    }
}

/// The ideal IMU of a table: specific force, angular rate ω_ib^b, NED acceleration, ω_nb^b.
pub type TableImu = (Vec<Vec3>, Vec<Vec3>, Vec<Vec3>, Vec<Vec3>);

/// Ideal IMU of a sampled trajectory: specific force f^b (m/s²) and angular rate ω_ib^b
/// (rad/s) at each sample (the NED mechanization solved for them, [`body_from_kinematics`]),
/// with the NED acceleration and ω_nb^b they come from. Both are second-order finite
/// differences at the samples (central inside, one-sided three-point at the ends): of the
/// velocity, and of the body-frame rotation vectors log(q_k⁻¹ ⊗ q_j) to the neighbours. The
/// samples must be evenly spaced at `rate_hz` (the simulated IMU has one rate).
// invariant: every series has n ≥ 3 entries (checked by the caller and here), and the
// stencils use k − 1, k + 1 only inside (0 < k < n − 1) and 0..2, n − 3..n − 1 at the ends.
#[allow(clippy::indexing_slicing)]
pub fn table_imu(ell: &Ellipsoid, t: &[f64], lla: &[Vec3], vel: &[Vec3], q_nb: &[Quat], rate_hz: f64) -> Result<TableImu> {
    let n = t.len();
    if n < 3 || lla.len() != n || vel.len() != n || q_nb.len() != n {
        return Err(invalid("trajectory", format!("needs at least 3 samples with a position, velocity and attitude each, got {n} times, {} / {} / {}", lla.len(), vel.len(), q_nb.len())));
    }
    check_positive("rate_hz", rate_hz)?;
    let dt = 1.0 / rate_hz;
    let even = |k: usize| (t[k] - t[k - 1] - dt).abs() <= 1e-6 * dt; // false for NaN
    if let Some(k) = (1..n).find(|&k| !even(k)) {
        return Err(invalid_at("trajectory", k, format!("time step {} s before sample {k} is not 1/rate_hz = {dt} s: the simulated IMU samples at one rate", t[k] - t[k - 1])));
    }
    for (name, v) in [("trajectory", lla), ("trajectory", vel)] {
        if let Some(k) = v.iter().position(|x| !x.iter().all(|c| c.is_finite())) {
            return Err(invalid_at(name, k, "non-finite position or velocity"));
        }
    }
    // d(k, j): the change from sample k to sample j, in sample k's frame
    let derivative = |d: &dyn Fn(usize, usize) -> Vec3| -> Vec<Vec3> {
        (0..n)
            .map(|k| match k {
                0 => (4.0 * d(0, 1) - d(0, 2)) / (2.0 * dt),
                k if k == n - 1 => -(4.0 * d(k, k - 1) - d(k, k - 2)) / (2.0 * dt),
                k => (d(k, k + 1) - d(k, k - 1)) / (2.0 * dt),
            })
            .collect()
    };
    let acc = derivative(&|k, j| vel[j] - vel[k]);
    let w_nb = derivative(&|k, j| rotvec_from_quat(&quat_mul(&q_nb[k].conjugate(), &q_nb[j])));
    let (f, w) = (0..n)
        .map(|k| body_from_kinematics(ell, &Kinematics { vel: vel[k], acc: acc[k], c_nb: dcm_from_quat(&q_nb[k]), w_nb_b: w_nb[k] }, &lla[k]))
        .unzip();
    Ok((f, w, acc, w_nb))
}

/// Number of extra filter states the CAI adds (misalignment, lever arm, force blocks).
fn cai_extra_states(cai: &CaiConfig) -> usize {
    3 * (usize::from(cai.misalignment.is_some()) + usize::from(cai.lever_arm.is_some()) + usize::from(cai.force != super::aiding::ForceMode::Bias))
}

/// Monte-Carlo results as row-major tables: `hybrid`, `free` (runs × epochs × 9),
/// `bias`, `bias_true` (runs × epochs × 6), `sigma` (runs × epochs × states), `nees`
/// (runs × epochs), `accel_error` (runs × IMU samples × 3), `phase_error` (runs × shots ×
/// channels), `time` (epochs) and `imu_time` (IMU samples).
#[derive(Clone, Debug, Default)]
pub struct McTables {
    pub runs: usize,
    pub epochs: usize,
    pub states: usize,
    pub shots: usize,
    pub channels: usize,
    pub time: Vec<f64>,
    pub imu_time: Vec<f64>,
    pub hybrid: Vec<f64>,
    pub free: Vec<f64>,
    pub bias: Vec<f64>,
    pub bias_true: Vec<f64>,
    pub accel_error: Vec<f64>,
    pub sigma: Vec<f64>,
    pub nees: Vec<f64>,
    pub phase_error: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cai::predictor::Channel;
    use crate::math::Mat3;

    fn cai(shots: Vec<f64>) -> CaiConfig {
        let channels = vec![Channel { k: Vec3::new(1.6e7, 0.0, 0.0), lever: Vec3::zeros(), c_sb: Mat3::identity(), v0: Vec3::new(0.0, 2.8, 0.0) }];
        CaiConfig::ideal(channels, 0.025, shots, 0.03)
    }

    fn config(phase_source: PhaseSourceKind, truth_rate_hz: Option<f64>) -> HybridConfig {
        HybridConfig {
            gravity: GravityModel::Kinematic,
            rate_hz: 200.0,
            truth_rate_hz,
            phase_source,
            accel_psd: 1e-11,
            gyro_psd: 1e-12,
            accel_bias_psd: 1e-10,
            gyro_bias_psd: 1e-14,
            predict_every: 10,
            aiding: true,
            draw_initial: false,
        }
    }

    /// At rest in kinematic mode an ideal CAI reads zero phase (no force, no rotation), the
    /// filter is the closed-loop Van Loan one, and a missing source or a wrong P0 is refused
    /// by name.
    #[test]
    fn scenario_assembly_and_its_checks() {
        let motion = Motion::stationary("rest", Vec3::new(0.9, 0.17, 60.0), 1.0, Vec3::zeros());
        let p0 = DMatrix::identity(15, 15) * 1e-12;
        let s = HybridScenario::new(&motion, &config(PhaseSourceKind::Ideal, Some(400.0)), ImuErrorModel::default(), None, cai(vec![0.1, 0.2]), p0.clone()).unwrap();
        assert_eq!(s.t.len(), 201);
        assert_eq!((s.filter.method, s.filter.mode), (Discretization::VanLoan, LoopMode::Closed));
        match &s.phase {
            PhaseSource::Ideal(p) => assert!(p.len() == 2 && p.iter().all(|x| x.abs() < 1e-9), "{p:?}"),
            other => panic!("{other:?}"),
        }
        let err = |cfg: HybridConfig, reference: Option<ImuErrorModel>, p0: DMatrix<f64>| {
            HybridScenario::new(&motion, &cfg, ImuErrorModel::default(), reference, cai(vec![0.1]), p0).err().unwrap().to_string()
        };
        assert!(err(config(PhaseSourceKind::Ideal, None), None, p0.clone()).starts_with("truth_rate_hz:"));
        assert!(err(config(PhaseSourceKind::Reference, None), None, p0.clone()).starts_with("reference:"));
        assert!(err(config(PhaseSourceKind::Ideal, Some(400.0)), Some(ImuErrorModel::default()), p0.clone()).starts_with("reference:"));
        assert!(err(config(PhaseSourceKind::Ideal, Some(400.0)), None, DMatrix::identity(9, 9)).starts_with("p0:"));
        let mut bad = config(PhaseSourceKind::Ideal, Some(400.0));
        bad.gyro_psd = -1.0;
        assert!(err(bad, None, p0).starts_with("gyro_psd:"));
    }

    /// The ideal IMU of a sampled slalom (200 Hz, Earth gravity) against the motion's exact
    /// rates: second-order differences err by h²/6 × the third derivative (≈ 1e-6 m/s²,
    /// 1e-6 rad/s here); an uneven step is refused with its row; the table's scenario
    /// truth starts at the table's first sample and stays within millimetres of it.
    #[test]
    fn table_imu_matches_the_exact_rates() {
        let motion = crate::trajectory::generators::slalom(Vec3::new(0.9, 0.17, 60.0), 5.0, 2.0, 10.0, 20.0).unwrap();
        let t: Vec<f64> = (0..=4000).map(|i| i as f64 / 200.0).collect();
        let truth = motion.truth(&WGS84, &t).unwrap();
        let (f_exact, w_exact, _) = ideal_rates(&motion, &WGS84, &truth);
        let (lla, vel, q): (Vec<Vec3>, Vec<Vec3>, Vec<Quat>) = (truth.iter().map(|s| s.lla).collect(), truth.iter().map(|s| s.vel).collect(), truth.iter().map(|s| s.q_nb).collect());
        let (f, w, _, _) = table_imu(&WGS84, &t, &lla, &vel, &q, 200.0).unwrap();
        let worst = |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).map(|(x, y)| (x - y).norm()).fold(0.0, f64::max);
        assert!(worst(&f, &f_exact) < 2e-5, "{}", worst(&f, &f_exact));
        assert!(worst(&w, &w_exact) < 2e-5, "{}", worst(&w, &w_exact));
        let inner = |a: &[Vec3], b: &[Vec3]| worst(&a[1..a.len() - 1], &b[1..b.len() - 1]);
        assert!(inner(&f, &f_exact) < 2e-6 && inner(&w, &w_exact) < 2e-6, "{} {}", inner(&f, &f_exact), inner(&w, &w_exact));
        let mut uneven = t.clone();
        uneven[7] += 1e-4;
        let e = table_imu(&WGS84, &uneven, &lla, &vel, &q, 200.0).unwrap_err();
        assert!(matches!(&e, crate::NavError::InvalidInput { index: Some(7), .. }), "{e}");
        let mut cfg = config(PhaseSourceKind::Ideal, None);
        cfg.gravity = GravityModel::Earth;
        let s = HybridScenario::from_table(t.clone(), &lla, &vel, &q, &cfg, ImuErrorModel::default(), None, cai(vec![0.1, 0.2]), DMatrix::identity(15, 15)).unwrap();
        assert_eq!(s.truth.len(), t.len());
        let last = s.truth.len() - 1;
        let err = nav_error(&WGS84, &state_at(&s.truth[last]), &truth[last]);
        assert!(err[..3].iter().all(|e| e.abs() < 1e-2), "{err:?}");
        cfg.truth_rate_hz = Some(2000.0);
        let e = HybridScenario::from_table(t, &lla, &vel, &q, &cfg, ImuErrorModel::default(), None, cai(vec![0.1]), DMatrix::identity(15, 15)).err().unwrap();
        assert!(e.to_string().starts_with("truth_rate_hz:"), "{e}");
    }

    #[test]
    fn gravity_by_name() {
        assert_eq!(GravityModel::parse("earth").unwrap().ellipsoid(), WGS84);
        assert_eq!(GravityModel::parse("kinematic").unwrap().ellipsoid(), KINEMATIC);
        assert!(GravityModel::parse("moon").unwrap_err().to_string().starts_with("gravity: unknown option"));
        assert!(PhaseSourceKind::parse("oracle").unwrap_err().to_string().starts_with("phase_source:"));
    }
}
