//! CAI aiding of the generic aided INS (`filter::aided`): the measurement of one shot is
//! the raw population readout of every interferometer channel, stacked into one vector
//! (Tennstedt et al. 2021, §2.3; Tennstedt et al. 2023, §2.2: 3 axes × A/B = 6
//! rows). The predicted readout comes from the atom-strapdown predictor (`predictor.rs`)
//! driven by the bias-compensated IMU stream the engine hands to `observe`.
//!
//! Per shot j with pulses at t_s, t_s + T, t_s + 2T (measurement at t_s + 2T):
//! - φ̂_j = predictor(compensated IMU over the shot)     (Tennstedt et al. 2023 Eqs. 5–8)
//! - laser phase steered by the filter's own best prediction:
//!   φ0_j = π/2 − (φ̂_j − J_j δx̂) mod 2π  (δx̂ = 0 in closed loop)   (Tennstedt et al. 2023 Eq. 24)
//! - instrument: p_j = o − (C/2) cos(φ_j + φ0_j) + n_j  (emulated from the true phase, or
//!   recorded together with the laser phase it used)   (docs/departures.md#one-readout-model)
//! - z_j = h_j − p_j with h_j = o − (C/2) cos(φ̂_j + φ0_j), no linearisation  (Tennstedt et al. 2021 Eq. 9)
//! - H_j = (C/2) sin(φ̂_j + φ0_j) J_j, J_j = ∂φ̂_j/∂(δb_a, δb_g, δl, δγ) from the
//!   tangent-linear predictor                          (Tennstedt et al. 2021 Eq. 10)
//! - R = σ_p² I + (C/2)² sin² · Σ_shot (in-shot IMU white noise, full 6 × 6 with the A/B
//!   correlation, Tennstedt et al. 2021, §2.4): Σ = Σ_i s_i Q_i s_iᵀ from the predictor's sensitivity s_i to
//!   each IMU sample (`in_shot.rs`; it includes the atom and lever-arm Euler terms that the
//!   closed form (E38) (2T³/3)[q_a K Kᵀ + 4 q_g V Vᵀ] leaves out)
//!
//! Signs: the compensated force is f̃ − b̂ = f − δb (δb = b̂ − b), so φ̂ − φ = J δx with J
//! the predictor's derivative with respect to the subtracted bias; the extra blocks follow
//! the same convention (δl = l̂ − l, δγ = γ̂ − γ, C_sb = exp(−[γ×]) C_sb,0).

use super::in_shot;
use super::predictor::{jacobian, predict, Channel, Imu, Interpolation, OmegaDot, PredictorConfig, MAX_SUBSTEPS};
use super::readout::{population, slope, steer_mid_fringe};
use crate::error::{check_finite, check_positive, invalid, invalid_at, Result};
use crate::filter::aided::{Aiding, AidingContext, Measurement};
use crate::filter::layout::Layout;
use crate::imu::ImuKind;
use crate::math::{dcm_from_quat, dcm_from_rotvec, Mat3, Vec3};
use crate::options::Choice;
use crate::strapdown::NavState;
use nalgebra::{DMatrix, DVector};

/// Names of the optional extra state blocks (after the 15 INS states).
pub const MISALIGNMENT_BLOCK: &str = "cai_misalignment";
pub const LEVER_BLOCK: &str = "cai_lever_arm";
pub const FORCE_BLOCK: &str = "cai_force";

/// Where the populations come from.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum CaiData {
    /// Emulated instrument: the true phase (rad) and the population noise of every shot and
    /// channel (row-major, shots × channels); the population is formed inside the loop with
    /// the laser phase the filter steers, p = o − (C/2) cos(φ + φ0) + n.
    Emulated { phase: Vec<f64>, noise: Vec<f64> },
    /// Recorded populations and the laser phases (rad) the instrument applied (shots × channels).
    Recorded { population: Vec<f64>, laser_phase: Vec<f64> },
}

/// The kind of the shots' data (option `data_kind`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DataKind {
    Emulated,
    Recorded,
}

impl Choice for DataKind {
    const PARAMETER: &'static str = "data_kind";
    const CHOICES: &'static [(&'static str, Self)] = &[("emulated", DataKind::Emulated), ("recorded", DataKind::Recorded)];
}

impl DataKind {
    /// Parameter names of the two (shots × channels) tables of this kind.
    pub fn tables(self) -> (&'static str, &'static str) {
        match self {
            DataKind::Emulated => ("phase", "noise"),
            DataKind::Recorded => ("population", "laser_phase"),
        }
    }
}

impl CaiData {
    /// The data of `kind` from its two row-major tables `a`, `b` of `width_a`, `width_b`
    /// columns, checked against the `channels` interferometers of the configuration (the
    /// number of shots is checked by [`CaiAiding::new`]).
    pub fn new(kind: DataKind, a: Vec<f64>, b: Vec<f64>, (width_a, width_b): (usize, usize), channels: usize) -> Result<Self> {
        let (na, nb) = kind.tables();
        if let Some((name, w)) = [(na, width_a), (nb, width_b)].into_iter().find(|&(_, w)| w != channels) {
            return Err(invalid(name, format!("has {w} interferometers per shot, but the configuration has {channels}")));
        }
        Ok(match kind {
            DataKind::Emulated => CaiData::Emulated { phase: a, noise: b },
            DataKind::Recorded => CaiData::Recorded { population: a, laser_phase: b },
        })
    }
}

/// The name of a force mode (option `force`); option a carries its Gauss–Markov parameters
/// separately (see [`ForceMode::new`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ForceKind {
    Bias,
    Direct,
}

impl Choice for ForceKind {
    const PARAMETER: &'static str = "force";
    const CHOICES: &'static [(&'static str, Self)] = &[("bias", ForceKind::Bias), ("direct", ForceKind::Direct)];
}

/// How the CAI corrects the IMU (Tennstedt et al. 2021, Eq. 11).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ForceMode {
    /// Option b (default): the readout observes the accelerometer (and gyro) bias states.
    Bias,
    /// Option a: the readout corrects the specific force of the shot directly. The force
    /// error is an extra Gauss–Markov block (correlation time `tau` s, σ `sigma` m/s²)
    /// entering the velocity like a bias (δv̇ = −Ĉ_b^n δf); the accelerometer-bias columns
    /// of H are zero, so nothing is fed back into the bias estimate.
    Direct { tau: f64, sigma: f64 },
}

impl ForceMode {
    /// The force mode `kind`; "direct" needs the correlation time `tau` (s) and σ `sigma`
    /// (m/s²) of the force error, "bias" refuses them (it would ignore them).
    pub fn new(kind: ForceKind, tau: Option<f64>, sigma: Option<f64>) -> Result<Self> {
        match (kind, tau, sigma) {
            (ForceKind::Bias, None, None) => Ok(ForceMode::Bias),
            (ForceKind::Bias, _, _) => Err(invalid("force", "force_tau and force_sigma are given, but force = 'bias' would ignore them; choose force = 'direct'")),
            (ForceKind::Direct, Some(tau), Some(sigma)) => {
                check_positive("force_tau", tau)?;
                check_positive("force_sigma", sigma)?;
                Ok(ForceMode::Direct { tau, sigma })
            }
            (ForceKind::Direct, _, _) => Err(invalid("force", "force = 'direct' needs force_tau (s) and force_sigma (m/s²)")),
        }
    }
}

/// What to do with a shot the IMU record cannot complete (option `incomplete_shots`): its
/// interferometer window (pulses at t_s … t_s + 2T, the interpolation stencil and a whole
/// Savitzky–Golay window) needs IMU samples before the record start or after its end.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum IncompleteShots {
    /// Leave the shot out (no update; NaN in the shot log).
    #[default]
    Skip,
    /// Refuse the record: an invalid-input error naming `shots` and the shot's index.
    Error,
}

impl Choice for IncompleteShots {
    const PARAMETER: &'static str = "incomplete_shots";
    const CHOICES: &'static [(&'static str, Self)] = &[("skip", IncompleteShots::Skip), ("error", IncompleteShots::Error)];
}

/// IMU samples a shot lacks: `before` the record start and `after` its end (both 0 for a
/// shot the record completes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ShotGap {
    pub before: usize,
    pub after: usize,
}

impl ShotGap {
    pub fn is_complete(&self) -> bool {
        self.before == 0 && self.after == 0
    }

    /// Why shot `j` starting at `ts` (s) cannot be predicted, for messages.
    pub fn describe(&self, j: usize, ts: f64) -> String {
        let mut parts = Vec::new();
        if self.before > 0 {
            parts.push(format!("{} IMU sample(s) before the record start", self.before));
        }
        if self.after > 0 {
            parts.push(format!("{} IMU sample(s) after the record end", self.after));
        }
        format!("shot {j} (start {ts} s) needs {}", parts.join(" and "))
    }
}

/// Configuration of the CAI aiding.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CaiConfig {
    /// Interferometer channels (nominal lever arm and C_sb).
    pub channels: Vec<Channel>,
    /// Pulse separation T (s).
    pub t_sep: f64,
    /// Shot start (first pulse) times (s), strictly increasing, non-overlapping.
    pub shots: Vec<f64>,
    /// Readout offset o and contrast C.
    pub offset: f64,
    pub contrast: f64,
    /// Population noise σ_p per channel.
    pub sigma_p: f64,
    /// White-noise PSDs (q_a m²/s³, q_g rad²/s) of the IMU for the in-shot R inflation
    /// (Tennstedt et al. 2021, §2.4); None = no inflation.
    pub inflation: Option<(f64, f64)>,
    pub omega_dot: OmegaDot,
    #[serde(with = "crate::options::by_name")]
    pub interpolation: Interpolation,
    pub substeps: usize,
    /// Keep the Euler terms in the Jacobian (Tennstedt et al. 2023, Eq. 31; default false).
    pub jacobian_euler: bool,
    /// Estimate the CAI misalignment γ (3 states, random walk of this PSD rad²/s).
    pub misalignment: Option<f64>,
    /// Estimate the lever-arm correction l (3 states, random walk of this PSD m²/s).
    pub lever_arm: Option<f64>,
    pub force: ForceMode,
    /// Kind of the IMU record the engine runs on (increments become interval-mean rates).
    #[serde(with = "crate::options::by_name")]
    pub kind: ImuKind,
    /// A shot the record cannot complete: skipped (default) or an error.
    #[serde(default)]
    pub incomplete: IncompleteShots,
}

/// Per shot and channel, what the instrument and the filter saw.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ShotLog {
    /// Shots left out because the record cannot complete them: (index, start s, gap).
    #[serde(default)]
    pub skipped: Vec<(usize, f64, ShotGap)>,
    /// Predicted phase at the filter's best estimate (rad).
    pub predicted: Vec<f64>,
    /// True minus predicted phase (rad); NaN for recorded data.
    pub phase_error: Vec<f64>,
    /// Laser phase φ0 (rad) and population p.
    pub laser_phase: Vec<f64>,
    pub population: Vec<f64>,
}

/// The CAI as an `Aiding` of the engine.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct CaiAiding {
    cfg: CaiConfig,
    data: CaiData,
    /// Measurement epochs t_s + 2T.
    times: Vec<f64>,
    /// Compensated IMU samples (t, f m/s², ω rad/s) kept for the current shot.
    buf_t: Vec<f64>,
    buf_f: Vec<Vec3>,
    buf_w: Vec<Vec3>,
    /// Ĉ_b^n of the latest solution (for the force block's velocity coupling).
    c_nb: Mat3,
    /// In-shot noise covariance Σ with the sample offsets (t_i − t_s) it was computed for.
    noise_cache: Option<(Vec<f64>, DMatrix<f64>)>,
    pub log: ShotLog,
}

/// Largest number of shots a schedule may hold (checked before allocating it).
pub const MAX_SHOTS: usize = 100_000_000;

/// Shot start times t0, t0 + period, ... with the last shot ending (t_s + 2T) no later
/// than `t_end`; `period` (s) between shot starts is at least 2T (2T = no dead time).
pub fn shot_times(t0: f64, t_end: f64, t_sep: f64, period: f64) -> Result<Vec<f64>> {
    check_positive("T", t_sep)?;
    if !(period.is_finite() && period >= 2.0 * t_sep) {
        return Err(invalid("shot_period", format!("must be >= 2T = {} s (shots must not overlap), got {period}", 2.0 * t_sep)));
    }
    check_finite("t0", &[t0], 1)?;
    check_finite("t_end", &[t_end], 1)?;
    let n = ((t_end - t0 - 2.0 * t_sep) / period + 1e-9).floor().max(-1.0) + 1.0;
    let n = crate::error::check_count("t_end", n as usize, 0, MAX_SHOTS)?;
    Ok((0..n).map(|i| t0 + i as f64 * period).collect())
}

impl CaiConfig {
    /// An ideal interferometer: readout offset ½ and contrast 1, piecewise-linear Ω̇,
    /// the predictor's default (cubic) IMU interpolation, one substep, no R inflation, no extra states (γ, l), the
    /// force term as an accelerometer bias, rate samples. Change fields with struct update
    /// syntax (`CaiConfig { contrast: 0.9, ..CaiConfig::ideal(…) }`).
    pub fn ideal(channels: Vec<Channel>, t_sep: f64, shots: Vec<f64>, sigma_p: f64) -> Self {
        CaiConfig {
            channels,
            t_sep,
            shots,
            offset: 0.5,
            contrast: 1.0,
            sigma_p,
            inflation: None,
            omega_dot: OmegaDot::Pwl,
            interpolation: Interpolation::default(),
            substeps: 1,
            jacobian_euler: false,
            misalignment: None,
            lever_arm: None,
            force: ForceMode::Bias,
            kind: ImuKind::Rates,
            incomplete: IncompleteShots::Skip,
        }
    }

    /// Checks everything but the shots (which [`CaiAiding::new`] checks against the data).
    pub fn check(&self) -> Result<()> {
        check_positive("T", self.t_sep)?;
        if self.channels.is_empty() {
            return Err(invalid("channels", "at least one interferometer channel is required"));
        }
        if !(1..=MAX_SUBSTEPS).contains(&self.substeps) {
            return Err(invalid("substeps", format!("must be in [1, {MAX_SUBSTEPS}], got {}", self.substeps)));
        }
        if let OmegaDot::Given(_) = self.omega_dot {
            return Err(OmegaDot::given_without_samples());
        }
        check_positive("sigma_p", self.sigma_p)?;
        check_positive("contrast", self.contrast)?;
        check_finite("offset", &[self.offset], 1)?;
        if let Some((qa, qg)) = self.inflation {
            for (name, q) in [("inflation q_accel", qa), ("inflation q_gyro", qg)] {
                if !(q.is_finite() && q >= 0.0) {
                    return Err(invalid(name, format!("must be finite and >= 0, got {q}")));
                }
            }
        }
        for (name, q) in [("misalignment psd", self.misalignment), ("lever_arm psd", self.lever_arm)] {
            if let Some(q) = q {
                if !(q.is_finite() && q >= 0.0) {
                    return Err(invalid(name, format!("must be finite and >= 0, got {q}")));
                }
            }
        }
        if let ForceMode::Direct { tau, sigma } = self.force {
            check_positive("force tau", tau)?;
            check_positive("force sigma", sigma)?;
        }
        // the predictor validates the channels on its first call; do it now instead
        let probe_t = [0.0, 2.0 * self.t_sep];
        let z = [Vec3::zeros(); 2];
        let probe = PredictorConfig { omega_dot: OmegaDot::Zero, ..self.predictor() };
        predict(Imu { t: &probe_t, f: &z, w: &z }, &[0.0], &self.channels, &probe)?;
        Ok(())
    }

    /// The predictor of this CAI at the nominal point (no gravity gradient, zero bias
    /// estimates: the aiding hands it the bias-compensated stream).
    pub fn predictor(&self) -> PredictorConfig {
        PredictorConfig {
            t_sep: self.t_sep,
            substeps: self.substeps,
            gradient: None,
            bias_a: Vec3::zeros(),
            bias_g: Vec3::zeros(),
            omega_dot: self.omega_dot.clone(),
            interpolation: self.interpolation,
        }
    }

    /// The IMU samples the shot starting at `ts` (s) lacks in the record `t` (s, increasing,
    /// at least 2 samples): before its start when the shot starts before the first sample
    /// (counted at the record's mean spacing) or when fewer samples than a Savitzky–Golay
    /// window (2m + 1) lie between the record start and the shot's end, where a shot in
    /// mid-record has the window's samples before it; after its end when the last pulse
    /// t_s + 2T comes after the last sample.
    pub fn missing_samples(&self, t: &[f64], ts: f64) -> Result<ShotGap> {
        let (&[first, .., last], n) = (t, t.len()) else {
            return Err(invalid("time", format!("need at least 2 IMU samples to place a shot, got {}", t.len())));
        };
        let dt = (last - first) / (n - 1) as f64;
        let eps = 1e-9 * self.t_sep;
        let end = ts + 2.0 * self.t_sep;
        let count = |gap: f64| if gap > eps && dt > 0.0 { (gap / dt - 1e-6).ceil().max(1.0) as usize } else { 0 };
        let (before, after) = (count(first - ts), count(end - last));
        let window = match self.omega_dot {
            OmegaDot::Savgol { half_width } => 2 * half_width + 1,
            _ => 0,
        };
        // the samples a shot's prediction sees: the pad before its start, then through the
        // first sample at or after its end (as the aiding buffers them)
        let start = t.partition_point(|&x| x < ts - eps);
        let stop = t.partition_point(|&x| x < end - eps).saturating_add(1).min(n);
        let seen = stop.saturating_sub(start) + start.min(self.omega_dot.pad());
        let short = window.saturating_sub(seen + before + after);
        Ok(ShotGap { before: before + short, after })
    }

    /// The shots the record `t` (s, increasing) cannot complete: index, start (s), the
    /// samples it lacks ([`missing_samples`](Self::missing_samples)) and why, in words.
    pub fn incomplete_shots(&self, t: &[f64]) -> Result<Vec<(usize, f64, ShotGap, String)>> {
        crate::error::check_increasing("time", t)?;
        let gaps = self.shots.iter().map(|&ts| self.missing_samples(t, ts)).collect::<Result<Vec<_>>>()?;
        Ok(gaps.into_iter().zip(&self.shots).enumerate().filter(|(_, (g, _))| !g.is_complete()).map(|(j, (g, &ts))| (j, ts, g, g.describe(j, ts))).collect())
    }

    /// In-shot IMU noise of one shot on a regular record of spacing `dt` (s), samples from
    /// the interpolation / ω̇ window before the shot to the first sample at or after its end
    /// (as the aiding holds them), white PSDs `q_a` (m²/s³), `q_g` (rad²/s): the phase
    /// covariance Σ (channels × channels, rad²) and, for each 15-state model `f` held over
    /// a filter step of one shot, E[w δφ̂ᵀ] (15 × channels) (see `in_shot.rs`).
    pub fn in_shot_noise(&self, dt: f64, q_a: f64, q_g: f64, f: &[DMatrix<f64>]) -> Result<(DMatrix<f64>, Vec<DMatrix<f64>>)> {
        check_positive("dt", dt)?;
        for (name, q) in [("q_a", q_a), ("q_g", q_g)] {
            if !(q.is_finite() && q >= 0.0) {
                return Err(invalid(name, format!("must be finite and >= 0, got {q}")));
            }
        }
        let pad = self.omega_dot.pad();
        // enough intervals to cover the last pulse at 2T, also when dt does not divide 2T
        let intervals = (2.0 * self.t_sep / dt - 1e-9).ceil().max(1.0);
        let n = crate::error::check_count("dt", (intervals as usize).saturating_add(pad + 1), 2, MAX_SHOT_SAMPLES)?;
        let t: Vec<f64> = (0..n).map(|i| (i as f64 - pad as f64) * dt).collect();
        let sens = in_shot::sensitivity(&t, 0.0, &self.channels, &self.predictor())?;
        let sigma = in_shot::covariance(&t, &sens, q_a, q_g, self.channels.len());
        let cross = f.iter().map(|fk| in_shot::cross_covariance(fk, &t, 0.0, self.t_sep, &sens, q_a, q_g)).collect::<Result<_>>()?;
        Ok((sigma, cross))
    }
}

/// Largest number of IMU samples in one shot accepted by [`CaiConfig::in_shot_noise`].
pub const MAX_SHOT_SAMPLES: usize = 1_000_000;

impl CaiAiding {
    pub fn new(cfg: CaiConfig, data: CaiData) -> Result<Self> {
        cfg.check()?;
        check_finite("shots", &cfg.shots, 1)?;
        for (i, pair) in cfg.shots.windows(2).enumerate() {
            let &[prev, cur] = pair else { continue };
            let end = prev + 2.0 * cfg.t_sep;
            if cur < end - 1e-9 * cfg.t_sep {
                return Err(invalid("shots", format!("shot {} starts at {cur} s, before shot {i} ends at {end} s (shots must not overlap)", i + 1)));
            }
        }
        let expected = cfg.shots.len() * cfg.channels.len();
        let (a, b, na, nb) = match &data {
            CaiData::Emulated { phase, noise } => (phase, noise, "phase", "noise"),
            CaiData::Recorded { population, laser_phase } => (population, laser_phase, "population", "laser_phase"),
        };
        for (v, name) in [(a, na), (b, nb)] {
            if v.len() != expected {
                return Err(invalid(
                    name,
                    format!(
                        "expected {} shots × {} interferometers = {expected} values, got {} ({} per shot would be {})",
                        cfg.shots.len(),
                        cfg.channels.len(),
                        v.len(),
                        name,
                        v.len() as f64 / cfg.shots.len().max(1) as f64
                    ),
                ));
            }
            check_finite(name, v, cfg.channels.len())?;
        }
        // last pulse t_s + 2T, less a rounding margin so that a shot ending on an IMU sample
        // is applied at that sample (0.05·i + 0.05 may exceed the grid value by 1 ulp)
        let times = cfg.shots.iter().map(|s| s + 2.0 * cfg.t_sep - 1e-9 * cfg.t_sep).collect();
        Ok(CaiAiding { cfg, data, times, buf_t: Vec::new(), buf_f: Vec::new(), buf_w: Vec::new(), c_nb: Mat3::identity(), noise_cache: None, log: ShotLog::default() })
    }

    pub fn config(&self) -> &CaiConfig {
        &self.cfg
    }

    /// Channels with the current lever-arm and misalignment estimates applied.
    fn current_channels(&self, layout: &Layout, extra: &DVector<f64>) -> Vec<Channel> {
        let get = |name: &str| layout.extra_index(name).and_then(|i| extra.as_slice().get(i..i + 3)).map(Vec3::from_column_slice);
        let dl = get(LEVER_BLOCK).unwrap_or_else(Vec3::zeros);
        let rot = get(MISALIGNMENT_BLOCK).map_or_else(Mat3::identity, |g| dcm_from_rotvec(&-g));
        self.cfg.channels.iter().map(|c| Channel { lever: c.lever + dl, c_sb: rot * c.c_sb, ..c.clone() }).collect()
    }

    /// Phase Jacobian rows (channels × n) w.r.t. the full error state.
    // invariant: the layout's blocks lie inside its n columns (3 states each), c < 3 so
    // c, 3 + c, 6 + c, 9 + c < 12 index the Jacobian rows, r < rows.len().
    #[allow(clippy::indexing_slicing)]
    fn phase_jacobian(&self, rows: &[[f64; 12]], layout: &Layout) -> Result<DMatrix<f64>> {
        let n = layout.size();
        let mut j = DMatrix::<f64>::zeros(rows.len(), n);
        let ba = layout.range("accel_bias")?.start;
        let bg = layout.range("gyro_bias")?.start;
        for (r, row) in rows.iter().enumerate() {
            for c in 0..3 {
                match self.cfg.force {
                    ForceMode::Bias => j[(r, ba + c)] = row[c],
                    ForceMode::Direct { .. } => j[(r, layout.range(FORCE_BLOCK)?.start + c)] = row[c],
                }
                j[(r, bg + c)] = row[3 + c];
                if let Some(l) = layout.get(LEVER_BLOCK) {
                    j[(r, l.start + c)] = row[6 + c];
                }
                if let Some(g) = layout.get(MISALIGNMENT_BLOCK) {
                    j[(r, g.start + c)] = row[9 + c];
                }
            }
        }
        Ok(j)
    }

    /// In-shot IMU-noise phase covariance Σ (rad²) of the shot starting at `ts`
    /// (Tennstedt et al. 2021, §2.4, `in_shot.rs`): from the predictor's sensitivity to every buffered sample, for the
    /// nominal channels (the small lever-arm / misalignment corrections do not change it).
    /// The sensitivities depend only on the sample times relative to the shot start, so Σ
    /// is cached and recomputed only when that pattern changes (first shots, irregular data).
    fn in_shot_covariance(&mut self, ts: f64) -> Result<DMatrix<f64>> {
        let m = self.cfg.channels.len();
        let Some((qa, qg)) = self.cfg.inflation else { return Ok(DMatrix::zeros(m, m)) };
        let offsets: Vec<f64> = self.buf_t.iter().map(|t| t - ts).collect();
        let tol = 1e-9 * self.cfg.t_sep;
        if let Some((key, sigma)) = &self.noise_cache {
            if key.len() == offsets.len() && key.iter().zip(&offsets).all(|(a, b)| (a - b).abs() <= tol) {
                return Ok(sigma.clone());
            }
        }
        let sens = in_shot::sensitivity(&self.buf_t, ts, &self.cfg.channels, &self.cfg.predictor())?;
        let sigma = in_shot::covariance(&self.buf_t, &sens, qa, qg, m);
        self.noise_cache = Some((offsets, sigma.clone()));
        Ok(sigma)
    }

    /// Drop the samples no later shot needs.
    fn prune(&mut self, next_shot: Option<f64>) {
        let keep_from = match next_shot {
            // the same rounding margin as the shot times, so that a sample on the next shot's
            // start is never dropped and the kept window (and the noise cache key) is the same
            // for every shot
            Some(ts) => self.buf_t.partition_point(|&t| t < ts - 1e-9 * self.cfg.t_sep).saturating_sub(self.cfg.omega_dot.pad()),
            None => self.buf_t.len(),
        };
        self.buf_t.drain(..keep_from);
        self.buf_f.drain(..keep_from);
        self.buf_w.drain(..keep_from);
    }

    /// The measurement of shot j given the filter's state (the engine's `measure`).
    // invariant: j < shots.len() (read above) and new checks every data series to hold
    // shots × m values, so idx = j·m + ch is in range; predict and jacobian return one row per
    // channel, so ch < m indexes best and phi_nom.
    #[allow(clippy::indexing_slicing)]
    fn shot_measurement(&mut self, j: usize, x: &DVector<f64>, extra: &DVector<f64>, layout: &Layout) -> Result<Option<Measurement>> {
        let ts = *self.cfg.shots.get(j).ok_or_else(|| invalid("shots", format!("no shot {j} (of {})", self.cfg.shots.len())))?;
        // mid-record the buffer holds the whole window before the shot, so a gap means the
        // record started too late for it
        let gap = self.cfg.missing_samples(&self.buf_t, ts)?;
        if !gap.is_complete() {
            return match self.cfg.incomplete {
                IncompleteShots::Error => Err(invalid_at("shots", j, gap.describe(j, ts))),
                IncompleteShots::Skip => {
                    self.skip_shot(j, ts, gap);
                    Ok(None)
                }
            };
        }
        let channels = self.current_channels(layout, extra);
        let imu = Imu { t: &self.buf_t, f: &self.buf_f, w: &self.buf_w };
        let pcfg = self.cfg.predictor();
        let phi_nom: Vec<f64> = predict(imu, &[ts], &channels, &pcfg)?.iter().map(|r| r[0]).collect();
        let jac = self.phase_jacobian(&jacobian(imu, &[ts], &channels, &pcfg, self.cfg.jacobian_euler)?, layout)?;
        let best = DVector::from_vec(phi_nom.clone()) - &jac * x;
        let m = channels.len();
        let (o, c) = (self.cfg.offset, self.cfg.contrast);
        let mut z = Vec::with_capacity(m);
        let mut gain = Vec::with_capacity(m);
        for ch in 0..m {
            let idx = j * m + ch;
            let (phi0, p, err) = match &self.data {
                CaiData::Emulated { phase, noise } => {
                    let phi0 = steer_mid_fringe(best[ch]);
                    (phi0, population(o, c, phase[idx] + phi0) + noise[idx], phase[idx] - best[ch])
                }
                CaiData::Recorded { population, laser_phase } => (laser_phase[idx], population[idx], f64::NAN),
            };
            let arg = phi_nom[ch] + phi0;
            z.push(population(o, c, arg) - p);
            gain.push(slope(c, arg));
            self.log.predicted.push(best[ch]);
            self.log.phase_error.push(err);
            self.log.laser_phase.push(phi0);
            self.log.population.push(p);
        }
        let g = DMatrix::from_diagonal(&DVector::from_vec(gain));
        let h = &g * jac;
        let r = DMatrix::identity(m, m) * self.cfg.sigma_p.powi(2) + &g * self.in_shot_covariance(ts)? * &g;
        self.prune(self.cfg.shots.get(j + 1).copied());
        Ok(Some(Measurement { z, h, r }))
    }

    /// Leave shot `j` out: logged as skipped, NaN for each channel in the shot log.
    fn skip_shot(&mut self, j: usize, ts: f64, gap: ShotGap) {
        self.log.skipped.push((j, ts, gap));
        let m = self.cfg.channels.len();
        for v in [&mut self.log.predicted, &mut self.log.phase_error, &mut self.log.laser_phase, &mut self.log.population] {
            v.extend(std::iter::repeat_n(f64::NAN, m));
        }
        self.prune(self.cfg.shots.get(j + 1).copied());
    }
}

#[typetag::serde]
impl Aiding for CaiAiding {
    fn name(&self) -> &str {
        "cai"
    }

    fn extra_blocks(&self) -> Vec<(String, usize)> {
        let mut b = Vec::new();
        if self.cfg.misalignment.is_some() {
            b.push((MISALIGNMENT_BLOCK.to_string(), 3));
        }
        if self.cfg.lever_arm.is_some() {
            b.push((LEVER_BLOCK.to_string(), 3));
        }
        if let ForceMode::Direct { .. } = self.cfg.force {
            b.push((FORCE_BLOCK.to_string(), 3));
        }
        b
    }

    fn times(&self) -> &[f64] {
        &self.times
    }

    fn observe(&mut self, t: f64, dt: f64, gyro: &Vec3, accel: &Vec3, nav: &NavState) {
        self.c_nb = dcm_from_quat(&nav.q_nb);
        // the engine passes samples of the record's kind; increments become interval rates
        // stamped at the interval midpoint
        let (t, f, w) = match self.cfg.kind {
            ImuKind::Increments if dt > 0.0 => (t - 0.5 * dt, accel / dt, gyro / dt),
            _ => (t, *accel, *gyro),
        };
        if self.buf_t.last().is_some_and(|&l| t <= l) {
            return;
        }
        self.buf_t.push(t);
        self.buf_f.push(f);
        self.buf_w.push(w);
    }

    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        self.shot_measurement(j, ctx.x, ctx.extra, ctx.layout)
    }

    // invariant: f and qc are n × n for this layout, whose blocks (and the velocity
    // block) lie inside n; a, b < 3 index the 3-state blocks and the 3 × 3 C_nb.
    #[allow(clippy::indexing_slicing)]
    fn extra_dynamics(&self, layout: &Layout, f: &mut DMatrix<f64>, qc: &mut DMatrix<f64>) {
        for (name, psd) in [(MISALIGNMENT_BLOCK, self.cfg.misalignment), (LEVER_BLOCK, self.cfg.lever_arm)] {
            if let (Some(r), Some(q)) = (layout.get(name), psd) {
                for i in r {
                    qc[(i, i)] = q;
                }
            }
        }
        if let (ForceMode::Direct { tau, sigma }, Some(r)) = (self.cfg.force, layout.get(FORCE_BLOCK)) {
            let iv = layout.get("velocity").map_or(3, |v| v.start);
            for a in 0..3 {
                f[(r.start + a, r.start + a)] = -1.0 / tau;
                qc[(r.start + a, r.start + a)] = 2.0 * sigma * sigma / tau;
                // δv̇ = −Ĉ_b^n δf, like the accelerometer bias (ins.rs F_vba)
                for b in 0..3 {
                    f[(iv + b, r.start + a)] = -self.c_nb[(b, a)];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cai::closed_form::phase_constant;
    use crate::math::{dcm_from_euler, quat};

    const K: f64 = 1.610576e7;

    /// Six-channel geometry of Tennstedt et al. 2023 (cyclic ±v0), lever arm and C_sb as given.
    fn cyclic(lever: Vec3, c_sb: Mat3) -> Vec<Channel> {
        (0..6).map(|c| Channel { k: Vec3::ith(c / 2, K), lever, c_sb, v0: Vec3::ith((c / 2 + 1) % 3, if c % 2 == 0 { 2.8 } else { -2.8 }) }).collect()
    }

    fn config(channels: Vec<Channel>, shots: Vec<f64>) -> CaiConfig {
        CaiConfig {
            contrast: 0.9,
            omega_dot: OmegaDot::Zero,
            // the closed forms of the in-shot noise below are those of linear interpolation
            // (hat-function sample weights)
            interpolation: Interpolation::Linear,
            substeps: 2,
            misalignment: Some(1e-12),
            lever_arm: Some(1e-12),
            ..CaiConfig::ideal(channels, 0.025, shots, 1e-3f64.sqrt())
        }
    }

    fn layout(a: &CaiAiding) -> Layout {
        let mut spec: Vec<(String, Option<usize>)> = crate::filter::layout::INS15.iter().map(|s| (s.to_string(), None)).collect();
        spec.extend(a.extra_blocks().into_iter().map(|(n, s)| (n, Some(s))));
        Layout::new(&spec).unwrap()
    }

    fn nav() -> NavState {
        NavState { t: 0.0, lla: Vec3::new(0.9, 0.2, 50.0), vel: Vec3::zeros(), q_nb: quat(1.0, 0.0, 0.0, 0.0) }
    }

    /// Feed a 200 Hz stream (f, ω at t), shifted by the bias perturbation −(δb_a, δb_g).
    fn feed(a: &mut CaiAiding, f: &dyn Fn(f64) -> Vec3, w: &dyn Fn(f64) -> Vec3, dba: Vec3, dbg: Vec3) {
        for i in 0..=12 {
            let t = i as f64 * 0.005;
            a.observe(t, 0.005, &(w(t) - dbg), &(f(t) - dba), &nav());
        }
    }

    /// H (readout Jacobian, bias and extra columns) equals central differences of the
    /// predicted readout h(x̂) = o − (C/2)cos(φ̂(x̂) + φ0) at fixed recorded φ0 and p.
    #[test]
    fn h_matches_finite_differences_of_the_readout() {
        let c_sb = dcm_from_euler(0.01, -0.02, 0.03);
        let chs = cyclic(Vec3::new(0.05, -0.02, 0.1), c_sb);
        let f = |t: f64| Vec3::new(0.3 + 0.5 * (7.0 * t).sin(), -0.2 + t, 0.1);
        let w = |t: f64| Vec3::new(0.05 + 0.3 * t, -0.03, 0.2 * (5.0 * t).cos());
        let shots = vec![0.005];
        // laser phases away from mid-fringe so that sin(φ̂ + φ0) ≠ 1 is exercised
        let data = CaiData::Recorded { population: vec![0.4; 6], laser_phase: vec![0.3, 1.1, -0.7, 2.0, 0.4, -1.3] };
        let base = CaiAiding::new(config(chs, shots), data).unwrap();
        let lay = layout(&base);
        let n = lay.size();
        let z_at = |dx: &DVector<f64>| -> (Vec<f64>, DMatrix<f64>) {
            let mut a = CaiAiding::new(base.cfg.clone(), base.data.clone()).unwrap();
            let (ba, bg) = (lay.range("accel_bias").unwrap().start, lay.range("gyro_bias").unwrap().start);
            feed(&mut a, &f, &w, Vec3::new(dx[ba], dx[ba + 1], dx[ba + 2]), Vec3::new(dx[bg], dx[bg + 1], dx[bg + 2]));
            let extra = DVector::from_iterator(n - 15, dx.iter().skip(15).copied());
            let m = a.shot_measurement(0, &DVector::zeros(n), &extra, &lay).unwrap().unwrap();
            (m.z, m.h)
        };
        let (_, h) = z_at(&DVector::zeros(n));
        // accel bias, gyro bias, misalignment, lever arm (layout order); small enough that the
        // readout curvature (Δφ²/6) stays below the tolerance
        let steps = [1e-6, 1e-7, 1e-7, 1e-5];
        for col in 9..n {
            let step = steps[(col - 9) / 3];
            let mut dx = DVector::zeros(n);
            dx[col] = step;
            let (zp, _) = z_at(&dx);
            dx[col] = -step;
            let (zm, _) = z_at(&dx);
            for r in 0..6 {
                let fd = (zp[r] - zm[r]) / (2.0 * step);
                let scale = h.row(r).abs().max() * steps[(col - 9) / 3];
                assert!((fd - h[(r, col)]).abs() * steps[(col - 9) / 3] < 1e-4 * scale.max(1e-12), "row {r} col {col}: fd {fd} vs H {}", h[(r, col)]);
            }
        }
        // navigation columns are zero: the phase does not depend on position, velocity, attitude
        assert!(h.columns(0, 9).iter().all(|x| *x == 0.0));
    }

    /// Constant inputs: the innovation of a steered emulated shot is exactly
    /// z = (C/2) sin(φ̂ − φ) − n with φ̂ from the closed form (E10) (no linearisation), and
    /// H = (C/2) J at mid-fringe.
    #[test]
    fn steered_innovation_is_nonlinear_closed_form() {
        let chs = cyclic(Vec3::zeros(), Mat3::identity());
        let (f0, w0) = (Vec3::new(0.4, -0.3, 0.2), Vec3::new(0.02, -0.05, 0.1));
        let truth = [0.3, -2.5, 1.0, 4.0, -0.2, 0.0]; // true − predicted up to ±4 rad
        let phat: Vec<f64> = chs.iter().map(|c| phase_constant(&c.k, &w0, &f0, &c.v0, 0.025)).collect();
        let phase: Vec<f64> = phat.iter().zip(truth).map(|(p, d)| p + d).collect();
        let noise = vec![1e-3, -2e-3, 0.0, 5e-3, 0.0, -1e-3];
        let mut cfg = config(chs, vec![0.005]);
        cfg.omega_dot = OmegaDot::Zero;
        let mut a = CaiAiding::new(cfg, CaiData::Emulated { phase, noise: noise.clone() }).unwrap();
        let lay = layout(&a);
        feed(&mut a, &|_| f0, &|_| w0, Vec3::zeros(), Vec3::zeros());
        let m = a.shot_measurement(0, &DVector::zeros(lay.size()), &DVector::zeros(lay.size() - 15), &lay).unwrap().unwrap();
        for c in 0..6 {
            let expect = 0.45 * (-truth[c]).sin() - noise[c];
            assert!((m.z[c] - expect).abs() < 1e-7, "channel {c}: {} vs {expect}", m.z[c]);
            assert!((a.log.phase_error[c] - truth[c]).abs() < 2e-7);
            assert!((a.log.predicted[c] - phat[c]).abs() < 2e-7);
        }
        // accelerometer-bias column of channel x: (C/2) T² k (constant-input closed form)
        let ba = lay.range("accel_bias").unwrap().start;
        let expect = 0.45 * 0.025f64.powi(2) * K;
        assert!((m.h[(0, ba)] / expect - 1.0).abs() < 0.05, "{} vs {expect}", m.h[(0, ba)]);
    }

    /// R inflation (Tennstedt et al. 2021, §2.4) at mid-fringe reproduces the in-shot phase noise
    /// (0.1838 rad accelerometer, 0.2994 rad gyro at T = 25 ms, the
    /// closed form of a continuous record without Euler terms, as here with ω̇ = 0) and
    /// the A/B correlation (common accelerometer, opposite Coriolis part), sampled at 200 Hz:
    /// with linear interpolation the sample weights are c_i = ∫ w ℓ_i dt (ℓ_i the hat
    /// functions): Δt·w(t_i) inside, Δt(T − Δt/3) at the apex, Δt²/6 at the ends, so
    /// Σ c_i²/Δt = Δt³[2(1 + 4 + 9 + 16) + (5 − 1/3)² + 1/18] = 81.833 Δt³ against
    /// ∫ w² = 2T³/3 = 83.333 Δt³ (T = 5Δt): a factor 0.98200 on both parts.
    #[test]
    fn inflated_r_matches_in_shot_noise_values() {
        let mut cfg = config(cyclic(Vec3::zeros(), Mat3::identity()), vec![0.005]);
        cfg.inflation = Some((1.25e-11, 1.0576e-12));
        cfg.contrast = 1.0;
        let mut a = CaiAiding::new(cfg, CaiData::Emulated { phase: vec![0.0; 6], noise: vec![0.0; 6] }).unwrap();
        let lay = layout(&a);
        feed(&mut a, &|_| Vec3::zeros(), &|_| Vec3::zeros(), Vec3::zeros(), Vec3::zeros());
        let m = a.shot_measurement(0, &DVector::zeros(lay.size()), &DVector::zeros(lay.size() - 15), &lay).unwrap().unwrap();
        let (sa, sg) = (0.1838f64, 0.2994f64);
        let sampled = (2.0 * 30.0 + (5.0f64 - 1.0 / 3.0).powi(2) + 1.0 / 18.0) / (2.0 * 125.0 / 3.0);
        let diag = 1e-3 + 0.25 * sampled * (sa * sa + sg * sg);
        let cross = 0.25 * sampled * (sa * sa - sg * sg);
        assert!((m.r[(0, 0)] / diag - 1.0).abs() < 1e-3, "{} vs {diag}", m.r[(0, 0)]);
        assert!((m.r[(0, 1)] / cross - 1.0).abs() < 2e-3, "{} vs {cross}", m.r[(0, 1)]);
        assert!(m.r[(0, 2)].abs() < 1e-12);
    }

    #[test]
    fn bad_input_is_rejected_with_the_field() {
        let chs = cyclic(Vec3::zeros(), Mat3::identity());
        let ok = CaiData::Emulated { phase: vec![0.0; 12], noise: vec![0.0; 12] };
        let e = CaiAiding::new(config(chs.clone(), vec![0.0, 0.04]), ok.clone()).err().unwrap().to_string();
        assert!(e.starts_with("shots:") && e.contains("shot 1") && e.contains("overlap"), "{e}");
        let e = CaiAiding::new(config(chs[..5].to_vec(), vec![0.0, 0.05]), ok).err().unwrap().to_string();
        assert!(e.starts_with("phase:") && e.contains("5 interferometers"), "{e}");
    }

    /// A shot starting one sample before the record: skipped (logged, NaN phase error, no
    /// update) by default, an error naming the shot and the sample it needs otherwise.
    #[test]
    fn shot_before_the_record_is_skipped_or_refused() {
        let chs = cyclic(Vec3::zeros(), Mat3::identity());
        for incomplete in [IncompleteShots::Skip, IncompleteShots::Error] {
            let cfg = CaiConfig { incomplete, ..config(chs.clone(), vec![0.0]) };
            let mut a = CaiAiding::new(cfg, CaiData::Emulated { phase: vec![0.0; 6], noise: vec![0.0; 6] }).unwrap();
            let lay = layout(&a);
            for i in 1..=12 {
                a.observe(i as f64 * 0.005, 0.005, &Vec3::zeros(), &Vec3::zeros(), &nav());
            }
            let r = a.shot_measurement(0, &DVector::zeros(lay.size()), &DVector::zeros(lay.size() - 15), &lay);
            match incomplete {
                IncompleteShots::Skip => {
                    assert!(r.unwrap().is_none());
                    assert_eq!(a.log.skipped, vec![(0, 0.0, ShotGap { before: 1, after: 0 })]);
                    assert!(a.log.phase_error.len() == 6 && a.log.phase_error.iter().all(|x| x.is_nan()));
                }
                IncompleteShots::Error => {
                    let e = r.err().unwrap();
                    assert!(matches!(&e, crate::NavError::InvalidInput { index: Some(0), .. }), "{e}");
                    let e = e.to_string();
                    assert!(e.starts_with("shots:") && e.contains("shot 0") && e.contains("1 IMU sample(s) before the record start"), "{e}");
                }
            }
        }
    }

    /// Samples a shot lacks, against counts by hand on a 200 Hz record from 0 to 1 s with
    /// T = 25 ms: none inside; before the start at the spacing; the Savitzky–Golay window's
    /// shortfall at the start (m = 8: 17 samples, 11 in the shot); after the end.
    #[test]
    fn missing_samples_counted_by_hand() {
        let t: Vec<f64> = (0..=200).map(|i| i as f64 * 0.005).collect();
        let cfg = config(cyclic(Vec3::zeros(), Mat3::identity()), vec![]);
        let gap = |cfg: &CaiConfig, ts: f64| cfg.missing_samples(&t, ts).unwrap();
        assert_eq!(gap(&cfg, 0.0), ShotGap::default());
        assert_eq!(gap(&cfg, 0.5), ShotGap::default());
        assert_eq!(gap(&cfg, -0.012), ShotGap { before: 3, after: 0 });
        assert_eq!(gap(&cfg, 0.96), ShotGap { before: 0, after: 2 });
        let sg = CaiConfig { omega_dot: OmegaDot::Savgol { half_width: 8 }, ..cfg.clone() };
        assert_eq!(gap(&sg, 0.0), ShotGap { before: 6, after: 0 });
        assert_eq!(gap(&sg, 0.01), ShotGap { before: 4, after: 0 });
        assert_eq!(gap(&sg, 0.5), ShotGap::default());
        assert!(cfg.missing_samples(&t[..1], 0.0).unwrap_err().to_string().starts_with("time:"));
    }

    #[test]
    fn shot_times_respect_rate_and_dead_time() {
        let s = shot_times(0.0, 1.0, 0.025, 0.1).unwrap();
        assert_eq!(s.len(), 10);
        assert!((s[9] - 0.9).abs() < 1e-12);
        // no dead time: 0, 0.05, ..., 0.95 (the last ends at 1.0)
        assert_eq!(shot_times(0.0, 1.0, 0.025, 0.05).unwrap().len(), 20);
        assert!(shot_times(0.0, 0.04, 0.025, 0.05).unwrap().is_empty());
        let e = shot_times(0.0, 1.0, 0.025, 0.04).unwrap_err().to_string();
        assert!(e.starts_with("shot_period: must be >= 2T"), "{e}");
        assert!(shot_times(0.0, 1e300, 0.025, 0.05).is_err());
    }

    /// One predictor configuration: the aiding's is the sensor's (T, substeps, ω̇,
    /// interpolation) at zero biases without gradient.
    #[test]
    fn predictor_config_is_the_sensors() {
        let mut cfg = config(cyclic(Vec3::zeros(), Mat3::identity()), vec![]);
        cfg.omega_dot = OmegaDot::Savgol { half_width: 4 };
        cfg.interpolation = Interpolation::Cubic;
        let p = cfg.predictor();
        assert_eq!((p.t_sep, p.substeps, p.interpolation), (0.025, 2, Interpolation::Cubic));
        assert_eq!(p.omega_dot, OmegaDot::Savgol { half_width: 4 });
        assert!(p.gradient.is_none() && p.bias_a == Vec3::zeros() && p.bias_g == Vec3::zeros());
        // the in-shot grid keeps the whole Savitzky–Golay window (2m + 1 = 9 samples) before the shot
        assert_eq!(p.omega_dot.pad(), 9);
        assert_eq!(OmegaDot::Pwl.pad(), 3);
    }

    /// The in-shot covariance on the sampled grid equals the aiding's R inflation of the
    /// same shot (`inflated_r_matches_in_shot_noise_values`: both from `in_shot.rs` on the
    /// 200 Hz grid), and bad PSDs or sample intervals are refused by name.
    #[test]
    fn in_shot_noise_checks_and_matches_the_sampled_closed_form() {
        let cfg = config(cyclic(Vec3::zeros(), Mat3::identity()), vec![]);
        let (sa, sg) = (0.1838f64, 0.2994f64);
        let sampled = (2.0 * 30.0 + (5.0f64 - 1.0 / 3.0).powi(2) + 1.0 / 18.0) / (2.0 * 125.0 / 3.0);
        let (sigma, cross) = cfg.in_shot_noise(0.005, 1.25e-11, 1.0576e-12, &[]).unwrap();
        assert!(cross.is_empty());
        assert!((sigma[(0, 0)] / (sampled * (sa * sa + sg * sg)) - 1.0).abs() < 1e-3, "{}", sigma[(0, 0)]);
        // a spacing that does not divide 2T, or exceeds it, still covers the whole shot
        for dt in [0.007, 1.0] {
            let (sigma, _) = cfg.in_shot_noise(dt, 1.25e-11, 1.0576e-12, &[]).unwrap();
            assert!(sigma[(0, 0)].is_finite() && sigma[(0, 0)] > 0.0, "dt = {dt}: {}", sigma[(0, 0)]);
        }
        for (dt, qa, qg, field) in [(0.0, 1.0, 1.0, "dt"), (0.005, -1.0, 1.0, "q_a"), (0.005, 1.0, f64::NAN, "q_g"), (1e-12, 1.0, 1.0, "dt")] {
            let e = cfg.in_shot_noise(dt, qa, qg, &[]).unwrap_err().to_string();
            assert!(e.starts_with(&format!("{field}:")), "{e}");
        }
    }

    #[test]
    fn options_by_name() {
        assert_eq!(ForceMode::new(ForceKind::Bias, None, None).unwrap(), ForceMode::Bias);
        assert_eq!(ForceMode::new(ForceKind::Direct, Some(0.05), Some(1e-4)).unwrap(), ForceMode::Direct { tau: 0.05, sigma: 1e-4 });
        assert!(ForceMode::new(ForceKind::Direct, Some(0.05), None).unwrap_err().to_string().starts_with("force:"));
        assert!(ForceMode::new(ForceKind::Direct, Some(-1.0), Some(1.0)).unwrap_err().to_string().starts_with("force_tau:"));
        assert!(ForceMode::new(ForceKind::Bias, Some(1.0), None).is_err());
        let e = CaiData::new(DataKind::Recorded, vec![], vec![], (6, 5), 6).unwrap_err().to_string();
        assert!(e.starts_with("laser_phase: has 5 interferometers"), "{e}");
        assert!(matches!(CaiData::new(DataKind::Emulated, vec![], vec![], (6, 6), 6), Ok(CaiData::Emulated { .. })));
        assert_eq!(DataKind::parse("recorded"), Ok(DataKind::Recorded));
        assert!(ForceKind::parse("both").unwrap_err().to_string().starts_with("force: unknown option"));
    }
}
