//! The sensor error model of an accelerometer triad and a gyro triad, and the seeded,
//! streamable simulator that corrupts an ideal IMU stream with it.
//!
//! Model per triad (project convention: measured = true + error):
//!   ỹ = (I + diag(s) + M) y + b + b_rw(t) + m_gm(t) + m_fl(t) + w
//! with y the true specific force f (m/s²) or angular rate ω (rad/s), s the scale-factor
//! errors, M the off-diagonal misalignment (zero diagonal), b the constant bias (a fixed
//! value plus an optional random turn-on bias drawn once per run), and the noise processes of
//! noise.rs. For increment output (Δv in m/s, Δθ in rad over Δt) every error term is its
//! integral over the sample interval: b contributes b·Δt, white noise has σ = N·√Δt, and
//! the coloured terms are integrated exactly (noise.rs). A rate sample is the increment
//! divided by Δt, so both kinds share one code path and increment = rate·Δt exactly.
//!
//! Randomness: one master seed (u64). Each (triad, term) pair has its own ChaCha12 stream:
//! key = the 8 little-endian bytes of the seed followed by 24 zero bytes, stream id =
//! 8·triad + term, triad 0 = accelerometer, 1 = gyro; term 0 = turn-on bias, 1 = white,
//! 2 = bias random walk, 3 = Gauss–Markov, 4 = flicker. A stream first draws the initial
//! (stationary) states of its term, axis x, y, z, then goes sample by sample, axis x, y, z. So the accelerometer and gyro are independent, and
//! switching one term on or off leaves the realisations of the others unchanged. Chunks
//! continue the streams, so any chunking gives the numbers of one batch call.

use super::noise::{Flicker, GaussMarkov, Increment, RandomWalk, White};
use super::ImuKind;
use crate::error::{check_positive, invalid, Result};
use crate::math::{Mat3, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha12Rng;
use rand_distr::StandardNormal;

/// First-order Gauss–Markov term: stationary σ (m/s² or rad/s) and correlation time τ (s).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GaussMarkovSpec {
    pub sigma: f64,
    pub tau: f64,
}

/// Flicker term: bias instability B (m/s² or rad/s, IEEE 952) valid in [f_lo, f_hi] Hz.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FlickerSpec {
    pub b: f64,
    pub f_lo: f64,
    pub f_hi: f64,
}

/// Errors of one sensor triad. Units: accelerometer m/s², gyro rad/s (rates), densities
/// as in noise.rs (continuous, two-sided).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TriadErrors {
    /// Fixed constant bias per axis.
    pub bias: Vec3,
    /// σ per axis of a random constant turn-on bias, drawn once per simulator.
    pub bias_sigma: f64,
    /// Scale-factor errors per axis (dimensionless, 1e-6 = 1 ppm).
    pub scale: Vec3,
    /// Misalignment / cross-coupling matrix; diagonal must be zero (that is `scale`).
    pub misalignment: Mat3,
    /// White-noise density N: VRW (m/s/√s) or ARW (rad/√s).
    pub white: f64,
    /// Bias random-walk density K: m/s²/√s or rad/s/√s.
    pub bias_rw: f64,
    pub gauss_markov: Option<GaussMarkovSpec>,
    pub flicker: Option<FlickerSpec>,
}

impl Default for TriadErrors {
    fn default() -> Self {
        Self {
            bias: Vec3::zeros(),
            bias_sigma: 0.0,
            scale: Vec3::zeros(),
            misalignment: Mat3::zeros(),
            white: 0.0,
            bias_rw: 0.0,
            gauss_markov: None,
            flicker: None,
        }
    }
}

fn check_nonneg(field: String, x: f64) -> Result<()> {
    if x.is_finite() && x >= 0.0 {
        Ok(())
    } else {
        Err(invalid(&field, format!("must be finite and >= 0, got {x}")))
    }
}

fn check_vec_finite(field: String, v: &Vec3) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(invalid(&field, format!("non-finite value {} at index {i}", v[i]))),
    }
}

impl TriadErrors {
    /// Reject invalid parameters; `name` ("accel" or "gyro") prefixes the field.
    pub fn validate(&self, name: &str) -> Result<()> {
        check_vec_finite(format!("{name}.bias"), &self.bias)?;
        check_nonneg(format!("{name}.bias_sigma"), self.bias_sigma)?;
        check_vec_finite(format!("{name}.scale"), &self.scale)?;
        if let Some(i) = self.misalignment.iter().position(|x| !x.is_finite()) {
            let (r, c) = (i % 3, i / 3); // nalgebra is column-major
            return Err(invalid(&format!("{name}.misalignment"), format!("non-finite value at index ({r}, {c})")));
        }
        if let Some((i, d)) = self.misalignment.diagonal().iter().enumerate().find(|(_, &d)| d != 0.0) {
            return Err(invalid(&format!("{name}.misalignment"), format!("diagonal must be zero (scale-factor errors go in `scale`), got {d} at index ({i}, {i})")));
        }
        check_nonneg(format!("{name}.white"), self.white)?;
        check_nonneg(format!("{name}.bias_rw"), self.bias_rw)?;
        if let Some(g) = self.gauss_markov {
            check_nonneg(format!("{name}.gauss_markov.sigma"), g.sigma)?;
            check_positive(&format!("{name}.gauss_markov.tau"), g.tau)?;
        }
        if let Some(f) = self.flicker {
            check_nonneg(format!("{name}.flicker.b"), f.b)?;
            check_positive(&format!("{name}.flicker.f_lo"), f.f_lo)?;
            check_positive(&format!("{name}.flicker.f_hi"), f.f_hi)?;
            if f.f_hi <= f.f_lo {
                return Err(invalid(&format!("{name}.flicker.f_hi"), format!("must exceed f_lo = {}, got {}", f.f_lo, f.f_hi)));
            }
        }
        Ok(())
    }

    /// I + diag(s) + M.
    pub fn sensor_matrix(&self) -> Mat3 {
        Mat3::identity() + Mat3::from_diagonal(&self.scale) + self.misalignment
    }
}

/// The full IMU error model: accelerometer and gyro triads.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ImuErrorModel {
    pub accel: TriadErrors,
    pub gyro: TriadErrors,
}

impl ImuErrorModel {
    pub fn validate(&self) -> Result<()> {
        self.accel.validate("accel")?;
        self.gyro.validate("gyro")
    }
}

/// One noise term on three axes with its own random stream.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Term<P> {
    rng: ChaCha12Rng,
    axes: [P; 3],
}

impl<P: Increment> Term<P> {
    fn step(&mut self) -> Vec3 {
        let rng = &mut self.rng;
        let [x, y, z] = &mut self.axes;
        Vec3::new(x.step(rng), y.step(rng), z.step(rng))
    }
}

fn stream(seed: u64, triad: u64, term: u64) -> ChaCha12Rng {
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    let mut rng = ChaCha12Rng::from_seed(key);
    rng.set_stream(8 * triad + term);
    rng
}

/// Stateful simulator of one triad.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct TriadSim {
    sensor: Mat3,
    /// Constant bias including the turn-on draw (rate units).
    bias: Vec3,
    white: Option<Term<White>>,
    rw: Option<Term<RandomWalk>>,
    gm: Option<Term<GaussMarkov>>,
    flicker: Option<Term<Flicker>>,
}

impl TriadSim {
    fn new(e: &TriadErrors, dt: f64, seed: u64, triad: u64) -> Self {
        let mut init = stream(seed, triad, 0);
        let turn_on = Vec3::from_fn(|_, _| e.bias_sigma * init.sample::<f64, _>(StandardNormal));
        let white = (e.white > 0.0).then(|| Term { rng: stream(seed, triad, 1), axes: [0; 3].map(|_| White::new(e.white, dt)) });
        let rw = (e.bias_rw > 0.0).then(|| Term { rng: stream(seed, triad, 2), axes: [0; 3].map(|_| RandomWalk::new(e.bias_rw, dt)) });
        let gm = e.gauss_markov.filter(|g| g.sigma > 0.0).map(|g| {
            let mut rng = stream(seed, triad, 3);
            let axes = [0; 3].map(|_| GaussMarkov::new(g.sigma, g.tau, dt, &mut rng));
            Term { rng, axes }
        });
        let flicker = e.flicker.filter(|f| f.b > 0.0).map(|f| {
            let mut rng = stream(seed, triad, 4);
            let axes = [0; 3].map(|_| Flicker::new(f.b, f.f_lo, f.f_hi, dt, &mut rng));
            Term { rng, axes }
        });
        Self { sensor: e.sensor_matrix(), bias: e.bias + turn_on, white, rw, gm, flicker }
    }

    /// Corrupt one sample. Returns (measured sample, bias truth as interval-average rate).
    fn sample(&mut self, y: &Vec3, dt: f64, kind: ImuKind) -> (Vec3, Vec3) {
        let mut coloured = Vec3::zeros(); // ∫ over the interval of b_rw + m_gm + m_fl
        if let Some(t) = &mut self.rw {
            coloured += t.step();
        }
        if let Some(t) = &mut self.gm {
            coloured += t.step();
        }
        if let Some(t) = &mut self.flicker {
            coloured += t.step();
        }
        let white = self.white.as_mut().map_or_else(Vec3::zeros, |t| t.step());
        let measured = self.sensor * y + self.bias * kind.per_rate(dt) + (coloured + white) * kind.per_increment(dt);
        (measured, self.bias + coloured / dt)
    }
}

/// Output of [`ImuSimulator::corrupt`]: measured samples of the requested kind and the true
/// time-varying bias per sample (constant + turn-on + random walk + Gauss–Markov + flicker,
/// averaged over the sample interval, always in rate units m/s² and rad/s; white noise and
/// scale/misalignment excluded).
#[derive(Debug, Clone, PartialEq)]
pub struct CorruptedImu {
    pub accel: Vec<Vec3>,
    pub gyro: Vec<Vec3>,
    pub accel_bias: Vec<Vec3>,
    pub gyro_bias: Vec<Vec3>,
}

/// Seeded, stateful IMU corruption: feed the ideal stream in one call or in chunks.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ImuSimulator {
    dt: f64,
    #[serde(with = "crate::options::by_name")]
    kind: ImuKind,
    accel: TriadSim,
    gyro: TriadSim,
}

fn first_non_finite(v: &[Vec3]) -> Option<(usize, usize, f64)> {
    v.iter().enumerate().find_map(|(i, r)| r.iter().enumerate().find(|(_, x)| !x.is_finite()).map(|(c, &x)| (i, c, x)))
}

impl ImuSimulator {
    /// `dt` is the sampling interval (s); every flicker band must lie below Nyquist 1/(2Δt).
    pub fn new(model: &ImuErrorModel, dt: f64, kind: ImuKind, seed: u64) -> Result<Self> {
        check_positive("dt", dt)?;
        model.validate()?;
        for (name, e) in [("accel", &model.accel), ("gyro", &model.gyro)] {
            if let Some(f) = e.flicker {
                if f.f_hi > 0.5 / dt {
                    return Err(invalid(&format!("{name}.flicker.f_hi"), format!("must not exceed the Nyquist frequency {} Hz, got {}", 0.5 / dt, f.f_hi)));
                }
            }
        }
        Ok(Self { dt, kind, accel: TriadSim::new(&model.accel, dt, seed, 0), gyro: TriadSim::new(&model.gyro, dt, seed, 1) })
    }

    pub fn dt(&self) -> f64 {
        self.dt
    }

    pub fn kind(&self) -> ImuKind {
        self.kind
    }

    /// Corrupt the next chunk of the ideal stream: true specific force (or Δv) and angular
    /// rate (or Δθ) per sample, of the kind given at construction. On invalid input nothing
    /// is consumed and the simulator state is unchanged.
    pub fn corrupt(&mut self, accel: &[Vec3], gyro: &[Vec3]) -> Result<CorruptedImu> {
        if gyro.len() != accel.len() {
            return Err(invalid("gyro", format!("expected {} rows like accel, got {}", accel.len(), gyro.len())));
        }
        for (name, v) in [("accel", accel), ("gyro", gyro)] {
            if let Some((i, c, x)) = first_non_finite(v) {
                return Err(invalid(name, format!("non-finite value {x} at index {i} (column {c})")));
            }
        }
        let n = accel.len();
        let mut out = CorruptedImu { accel: Vec::with_capacity(n), gyro: Vec::with_capacity(n), accel_bias: Vec::with_capacity(n), gyro_bias: Vec::with_capacity(n) };
        for (f, w) in accel.iter().zip(gyro) {
            let (fm, fb) = self.accel.sample(f, self.dt, self.kind);
            let (wm, wb) = self.gyro.sample(w, self.dt, self.kind);
            out.accel.push(fm);
            out.accel_bias.push(fb);
            out.gyro.push(wm);
            out.gyro_bias.push(wb);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noisy() -> ImuErrorModel {
        let t = TriadErrors {
            bias: Vec3::new(1e-3, -2e-3, 3e-3),
            bias_sigma: 1e-3,
            scale: Vec3::new(1e-4, -2e-4, 3e-4),
            misalignment: Mat3::new(0.0, 1e-3, -2e-3, 3e-3, 0.0, 4e-4, -5e-4, 6e-4, 0.0),
            white: 1e-3,
            bias_rw: 1e-4,
            gauss_markov: Some(GaussMarkovSpec { sigma: 1e-3, tau: 2.0 }),
            flicker: Some(FlickerSpec { b: 1e-4, f_lo: 1e-3, f_hi: 1.0 }),
        };
        ImuErrorModel { accel: t.clone(), gyro: t }
    }

    fn stream_of(n: usize) -> (Vec<Vec3>, Vec<Vec3>) {
        let f = (0..n).map(|k| Vec3::new((k as f64 * 0.1).sin(), 0.2, -9.8)).collect();
        let w = (0..n).map(|k| Vec3::new(0.01, (k as f64 * 0.05).cos() * 0.1, 0.3)).collect();
        (f, w)
    }

    #[test]
    fn chunked_equals_batch() {
        let (f, w) = stream_of(1000);
        let mut a = ImuSimulator::new(&noisy(), 0.01, ImuKind::Rates, 42).unwrap();
        let batch = a.corrupt(&f, &w).unwrap();
        let mut b = ImuSimulator::new(&noisy(), 0.01, ImuKind::Rates, 42).unwrap();
        let mut cat = CorruptedImu { accel: vec![], gyro: vec![], accel_bias: vec![], gyro_bias: vec![] };
        for (lo, hi) in [(0, 1), (1, 1), (1, 377), (377, 1000)] {
            let c = b.corrupt(&f[lo..hi], &w[lo..hi]).unwrap();
            cat.accel.extend(c.accel);
            cat.gyro.extend(c.gyro);
            cat.accel_bias.extend(c.accel_bias);
            cat.gyro_bias.extend(c.gyro_bias);
        }
        assert_eq!(batch, cat);
    }

    #[test]
    fn increment_is_rate_times_dt_for_the_same_seed() {
        let dt = 0.02;
        let (f, w) = stream_of(200);
        let (fi, wi): (Vec<Vec3>, Vec<Vec3>) = (f.iter().map(|x| x * dt).collect(), w.iter().map(|x| x * dt).collect());
        let r = ImuSimulator::new(&noisy(), dt, ImuKind::Rates, 3).unwrap().corrupt(&f, &w).unwrap();
        let i = ImuSimulator::new(&noisy(), dt, ImuKind::Increments, 3).unwrap().corrupt(&fi, &wi).unwrap();
        for k in 0..200 {
            assert!((i.accel[k] - r.accel[k] * dt).norm() < 1e-14 * r.accel[k].norm() * dt + 1e-18);
            assert!((i.gyro[k] - r.gyro[k] * dt).norm() < 1e-14);
            assert_eq!(i.accel_bias[k], r.accel_bias[k]);
        }
    }

    #[test]
    fn deterministic_errors_are_exact() {
        let mut m = noisy();
        for t in [&mut m.accel, &mut m.gyro] {
            t.bias_sigma = 0.0;
            t.white = 0.0;
            t.bias_rw = 0.0;
            t.gauss_markov = None;
            t.flicker = None;
        }
        let (f, w) = stream_of(10);
        let out = ImuSimulator::new(&m, 0.01, ImuKind::Rates, 0).unwrap().corrupt(&f, &w).unwrap();
        let s = m.accel.sensor_matrix();
        for ((meas, truth), bias) in out.accel.iter().zip(&f).zip(&out.gyro_bias) {
            assert!((meas - (s * truth + m.accel.bias)).norm() < 1e-15 * 10.0);
            assert_eq!(*bias, m.gyro.bias);
        }
    }

    #[test]
    fn bad_input_is_rejected_without_consuming_state() {
        let (mut f, w) = stream_of(5);
        let mut a = ImuSimulator::new(&noisy(), 0.01, ImuKind::Rates, 1).unwrap();
        f[3].y = f64::NAN;
        let e = a.corrupt(&f, &w).unwrap_err().to_string();
        assert!(e.starts_with("accel:") && e.contains("index 3"), "{e}");
        let e = a.corrupt(&f[..2], &w).unwrap_err().to_string();
        assert!(e.starts_with("gyro:"), "{e}");
        f[3].y = 0.0;
        let fresh = ImuSimulator::new(&noisy(), 0.01, ImuKind::Rates, 1).unwrap().corrupt(&f, &w).unwrap();
        assert_eq!(a.corrupt(&f, &w).unwrap(), fresh);

        let mut m = noisy();
        m.gyro.gauss_markov = Some(GaussMarkovSpec { sigma: 1.0, tau: -1.0 });
        let e = ImuSimulator::new(&m, 0.01, ImuKind::Rates, 1).unwrap_err().to_string();
        assert!(e.starts_with("gyro.gauss_markov.tau:"), "{e}");
        let e = ImuSimulator::new(&noisy(), 0.0, ImuKind::Rates, 1).unwrap_err().to_string();
        assert!(e.starts_with("dt:"), "{e}");
        let e = ImuSimulator::new(&noisy(), 1.0, ImuKind::Rates, 1).unwrap_err().to_string();
        assert!(e.starts_with("accel.flicker.f_hi:"), "{e}");
        let mut m = noisy();
        m.accel.misalignment[(1, 1)] = 1e-3;
        let e = m.validate().unwrap_err().to_string();
        assert!(e.contains("accel.misalignment") && e.contains("(1, 1)"), "{e}");
    }
}
