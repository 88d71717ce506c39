//! CAI-aided INS scenarios and their Monte Carlo (seed 003 §5, seed 000 §5): a truth
//! trajectory with its ideal IMU, an IMU error model, a CAI (channels, shots, readout
//! noise) and the aided-INS engine with [`CaiAiding`]; every run also integrates the same
//! IMU record without aiding (the IMU-only baseline). Runs are independent and seeded
//! (ChaCha20, stream = run index), so any subset reproduces anywhere; they run in
//! parallel with rayon.

use super::aiding::{CaiAiding, CaiConfig, CaiData};
use super::predictor::{predict, Imu, Interpolation, OmegaDot, PredictorConfig};
use crate::earth::Ellipsoid;
use crate::error::{invalid, Result};
use crate::filter::aided::{AidedConfig, AidedIns, AidedOutput, Aiding};
use crate::imu::errors::{ImuErrorModel, ImuSimulator};
use crate::imu::ideal::ideal_rates;
use crate::imu::ImuKind;
use crate::filter::initial_error::draw_start;
use crate::math::{quat_mul, rotvec_from_quat, Quat, Vec3};
use crate::strapdown::{NavState, Strapdown, Vertical};
use crate::trajectory::{Motion, TruthState};
use nalgebra::{DMatrix, DVector};
use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// How the instrument's true phase is produced.
#[derive(Clone, Debug)]
pub enum PhaseSource {
    /// A perfect CAI on the true motion: the predictor applied to the ideal IMU sampled
    /// `oversample` times faster than the navigation IMU, with the exact ω̇ and cubic
    /// interpolation (atom-strapdown §2.8: "truth integrated at 2 kHz"); one set of phases
    /// serves every run.
    Ideal(Vec<f64>),
    /// A CAI emulated from a better reference IMU (seed 000 (E38), hexapod): per run, the
    /// predictor applied to the ideal IMU corrupted with this model (Savitzky–Golay ω̇);
    /// the estimated biases are then relative to the reference IMU's.
    Reference(ImuErrorModel),
}

/// Everything a run needs; built once, shared by all runs.
pub struct HybridScenario {
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

/// Navigation errors estimate − truth: NED position (m), NED velocity (m/s), ψ (rad) with
/// C_nb(est) = (I − [ψ×]) C_nb(true), i.e. ψ = −rotvec(q_est ⊗ q_true*).
pub fn nav_error(ell: &Ellipsoid, est: &NavState, truth: &TruthState) -> [f64; 9] {
    let dpos = ell.ecef_to_ned(&ell.lla_to_ecef(&est.lla), &truth.lla);
    let dv = est.vel - truth.vel;
    let qt: Quat = truth.q_nb.conjugate();
    let psi = -rotvec_from_quat(&quat_mul(&est.q_nb, &qt));
    [dpos.x, dpos.y, dpos.z, dv.x, dv.y, dv.z, psi.x, psi.y, psi.z]
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
    /// Truth and ideal IMU of `motion` at `rate_hz` over its duration.
    pub fn imu_truth(motion: &Motion, ell: &Ellipsoid, rate_hz: f64) -> Result<(Vec<f64>, Vec<TruthState>, Vec<Vec3>, Vec<Vec3>)> {
        crate::error::check_positive("rate_hz", rate_hz)?;
        let n = (motion.duration * rate_hz + 1e-9).floor() as usize + 1;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / rate_hz).collect();
        let truth = motion.truth(ell, &t)?;
        let (f, w, _) = ideal_rates(motion, ell, &truth);
        Ok((t, truth, f, w))
    }

    /// True phases of a perfect CAI (see [`PhaseSource::Ideal`]) from the ideal IMU at the
    /// truth samples `t`, `truth`, `f`, `w` of `motion` (ω̇ exact).
    pub fn ideal_phases(motion: &Motion, ell: &Ellipsoid, t: &[f64], truth: &[TruthState], f: &[Vec3], w: &[Vec3], cai: &CaiConfig) -> Result<Vec<f64>> {
        let (_, _, wd) = ideal_rates(motion, ell, truth);
        let cfg = PredictorConfig {
            t_sep: cai.t_sep,
            substeps: 1,
            gradient: None,
            bias_a: Vec3::zeros(),
            bias_g: Vec3::zeros(),
            omega_dot: OmegaDot::Given(wd),
            interpolation: Interpolation::Cubic,
        };
        Ok(predict(Imu { t, f, w }, &cai.shots, &cai.channels, &cfg)?.iter().map(|r| r[0]).collect())
    }

    /// Run `run` of the Monte Carlo seeded by `master_seed`.
    pub fn run(&self, master_seed: u64, run: u64) -> Result<HybridRun> {
        let mut rng = ChaCha20Rng::seed_from_u64(master_seed);
        rng.set_stream(run);
        let dt = self.t[1] - self.t[0];
        let imu = ImuSimulator::new(&self.imu_model, dt, ImuKind::Rates, rng.next_u64())?.corrupt(&self.f, &self.w)?;
        let (phase, reference_bias) = match &self.phase {
            PhaseSource::Ideal(p) => (p.clone(), None),
            PhaseSource::Reference(model) => {
                let r = ImuSimulator::new(model, dt, ImuKind::Rates, rng.next_u64())?.corrupt(&self.f, &self.w)?;
                let cfg = PredictorConfig {
                    t_sep: self.cai.t_sep,
                    substeps: self.cai.substeps,
                    gradient: None,
                    bias_a: Vec3::zeros(),
                    bias_g: Vec3::zeros(),
                    omega_dot: self.cai.omega_dot.clone(),
                    interpolation: self.cai.interpolation,
                };
                let p = predict(Imu { t: &self.t, f: &r.accel, w: &r.gyro }, &self.cai.shots, &self.cai.channels, &cfg)?;
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
}
