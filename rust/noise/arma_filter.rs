//! ARIMA(p,d,q) state-space form and the scalar-measurement Kalman filters of Niu et al. 2025:
//! fixed R, the measurement-noise-adaptive R of Eq. 17 (both readings of y_k), and
//! Sage–Husa (standard form, not from the paper; docs/departures.md#sage-husa-filter). Batch and streaming.
//!
//! Sign convention (Niu et al. 2025 Eqs. 6–8, as statsmodels): d_k = Σφ_i d_{k−i} + a_k + Σβ_j a_{k−j},
//! d = (1−L)^D ω. Measurement H = [1 0 … 0]: the filter observes ω_k directly.

use crate::error::{check_finite, check_positive, invalid, NavError, Result};
use crate::options::Choice;
use nalgebra::{DMatrix, SMatrix, SVector};

/// How the ARMA innovations enter the state (docs/departures.md#arma-noise-form).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseForm {
    /// Niu et al. 2025 Eq. 16: X = [ω_k … ω_{k−n+1}], B first row [1, β₁ … β_q, 0 …], Q = σ²I_n.
    /// Treats a_{k−j} in W_k as fresh noise (doubles the process noise for β₁ ≈ −1).
    Paper,
    /// X = [ω_k … ω_{k−r+1}, a_k … a_{k−q+1}], G = e₀ + e_r, scalar Q = σ² (exact).
    Exact,
}

impl Choice for NoiseForm {
    const PARAMETER: &'static str = "noise_form";
    const CHOICES: &'static [(&'static str, Self)] = &[("paper", NoiseForm::Paper), ("exact", NoiseForm::Exact)];
}

/// X_k = Φ X_{k−1} + B W_{k−1}, Y_k = H X_k + V_k (Niu et al. 2025 Eq. 14).
#[derive(Debug, Clone, PartialEq)]
pub struct ArimaStateSpace {
    /// Transition matrix Φ (n×n), companion form of the AR polynomial on ω.
    pub phi: DMatrix<f64>,
    /// Noise gain B (n×n for the paper form, n×1 for the exact form).
    pub b: DMatrix<f64>,
    /// Noise covariance Q (σ²I_n, or 1×1 σ²).
    pub q: DMatrix<f64>,
    /// Process noise covariance B Q Bᵀ (n×n).
    pub qd: DMatrix<f64>,
    /// Innovation variance σ_a².
    pub sigma2: f64,
}

/// Coefficients c of ω_k = Σ c_i ω_{k−i} + …: (1 − Σφ_i Lⁱ)(1 − L)^d = 1 − Σ c_i Lⁱ.
/// For (2,1): [1+φ₁, φ₂−φ₁, −φ₂] (Niu et al. 2025 Eq. 12).
// invariant: next has poly.len() + 1 entries, so i + 1 ≤ poly.len() is in range.
#[allow(clippy::indexing_slicing)]
pub fn integrated_ar(ar: &[f64], d: usize) -> Vec<f64> {
    // Polynomial in L with constant term first.
    let mut poly: Vec<f64> = std::iter::once(1.0).chain(ar.iter().map(|a| -a)).collect();
    for _ in 0..d {
        let mut next = vec![0.0; poly.len() + 1];
        for (i, c) in poly.iter().enumerate() {
            next[i] += c;
            next[i + 1] -= c;
        }
        poly = next;
    }
    poly.iter().skip(1).map(|c| -c).collect()
}

impl ArimaStateSpace {
    /// ARIMA(p,d,q) with AR coefficients `ar` (φ), MA coefficients `ma` (β) and
    /// innovation variance `sigma2`, in the paper's or the exact noise form.
    // invariant: n ≥ c.len() = r, n ≥ q + 1 (paper) or n = max(r, 1) + q (exact), cols = n
    // or 1: every index below is inside the n × n Φ and n × cols B.
    #[allow(clippy::indexing_slicing)]
    pub fn from_arma(ar: &[f64], ma: &[f64], sigma2: f64, d: usize, form: NoiseForm) -> Result<ArimaStateSpace> {
        check_finite("ar", ar, 1)?;
        check_finite("ma", ma, 1)?;
        check_positive("sigma2", sigma2)?;
        let c = integrated_ar(ar, d);
        let (r, q) = (c.len(), ma.len());
        let (n, cols) = match form {
            NoiseForm::Paper => (r.max(q + 1), r.max(q + 1)),
            NoiseForm::Exact => (r.max(1) + q, 1),
        };
        let mut phi = DMatrix::zeros(n, n);
        for (i, ci) in c.iter().enumerate() {
            phi[(0, i)] = *ci;
        }
        let mut b = DMatrix::zeros(n, cols);
        let qm;
        match form {
            NoiseForm::Paper => {
                for i in 1..n {
                    phi[(i, i - 1)] = 1.0;
                }
                b[(0, 0)] = 1.0;
                for (j, bj) in ma.iter().enumerate() {
                    b[(0, j + 1)] = *bj;
                }
                qm = DMatrix::identity(n, n) * sigma2;
            }
            NoiseForm::Exact => {
                let r1 = r.max(1);
                for i in 1..r1 {
                    phi[(i, i - 1)] = 1.0;
                }
                for (j, bj) in ma.iter().enumerate() {
                    phi[(0, r1 + j)] = *bj;
                }
                for i in r1 + 1..n {
                    phi[(i, i - 1)] = 1.0;
                }
                b[(0, 0)] = 1.0;
                if q > 0 {
                    b[(r1, 0)] = 1.0;
                }
                qm = DMatrix::from_element(1, 1, sigma2);
            }
        }
        let qd = &b * &qm * b.transpose();
        if !phi.iter().all(|x| x.is_finite()) {
            return Err(crate::error::invalid("ar", format!("the integrated AR polynomial (d = {d}) has coefficients beyond the range of floats")));
        }
        if !qd.iter().all(|x| x.is_finite()) {
            return Err(crate::error::invalid("ma", format!("the process noise B Q Bᵀ (σ² = {sigma2}) has entries beyond the range of floats")));
        }
        Ok(ArimaStateSpace { phi, b, q: qm, qd, sigma2 })
    }

    pub fn dim(&self) -> usize {
        self.phi.nrows()
    }
}

/// How R_k is chosen (Niu et al. 2025 Eqs. 15, 17; docs/departures.md#reading-of-eq-17).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum RMode {
    /// R_k ≡ R₀.
    Fixed,
    /// Eq. 17 with y = ω: running AVAR(τ₀) of the measurements, from k = 2.
    Literal,
    /// Eq. 17 with y = d (the differenced series, the paper's y elsewhere), from k = 3.
    Differenced,
    /// Sage–Husa with forgetting factor b; optional Q adaptation and strong-tracking fading.
    SageHusa { b: f64, adapt_q: bool, fading: bool },
}

/// The name of an [`RMode`] (`adaptive="differenced"`); Sage–Husa's numbers travel beside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Adaptive {
    Fixed,
    Literal,
    Differenced,
    SageHusa,
}

impl Choice for Adaptive {
    const PARAMETER: &'static str = "adaptive";
    const CHOICES: &'static [(&'static str, Self)] = &[
        ("fixed", Adaptive::Fixed),
        ("literal", Adaptive::Literal),
        ("differenced", Adaptive::Differenced),
        ("sage_husa", Adaptive::SageHusa),
    ];
}

impl RMode {
    /// The mode named `adaptive`; `b`, `adapt_q` and `fading` are used by Sage–Husa only.
    pub fn new(adaptive: Adaptive, b: f64, adapt_q: bool, fading: bool) -> Result<RMode> {
        match adaptive {
            Adaptive::Fixed => Ok(RMode::Fixed),
            Adaptive::Literal => Ok(RMode::Literal),
            Adaptive::Differenced => Ok(RMode::Differenced),
            Adaptive::SageHusa => {
                if !(b > 0.0 && b < 1.0) {
                    return Err(invalid("b", format!("forgetting factor must be in (0, 1), got {b}")));
                }
                Ok(RMode::SageHusa { b, adapt_q, fading })
            }
        }
    }
}

/// Running Eq. 17: R̂(k) = (1 − 1/c) R̂(k−1) + (y_k − y_{k−1})²/(2c), c = number of
/// differences so far; equals Σ(y_i − y_{i−1})²/(2c).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct RunningAllanR {
    prev: Option<f64>,
    count: usize,
    r: f64,
}

impl RunningAllanR {
    /// Feed y_k; the estimate once at least one difference exists.
    pub fn update(&mut self, y: f64) -> Option<f64> {
        let prev = self.prev.replace(y)?;
        self.count += 1;
        let c = self.count as f64;
        let dy = y - prev;
        // Niu et al. 2025, Eq. 17 (recursive form)
        self.r = (1.0 - 1.0 / c) * self.r + dy * dy / (2.0 * c);
        Some(self.r)
    }
}

/// Initial state (docs/departures.md#initial-values).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum X0 {
    Zeros,
    /// All ω-slots start at the first measurement (removes the start-up transient).
    First,
}

impl Choice for X0 {
    const PARAMETER: &'static str = "x0";
    const CHOICES: &'static [(&'static str, Self)] = &[("zeros", X0::Zeros), ("first", X0::First)];
}

/// Everything that defines an ARMA Kalman filter run (model, measurement-noise mode,
/// initial state), frozen: the binding builds it once, Python mirrors it as
/// `atomnav.noise.filters.ArmaFilterConfig` (to/from dict and JSON).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ArmaFilterConfig {
    /// AR coefficients φ of the differenced series.
    pub ar: Vec<f64>,
    /// MA coefficients β.
    pub ma: Vec<f64>,
    /// Innovation variance σ_a².
    pub sigma2: f64,
    /// Differencing order.
    pub d: usize,
    #[serde(with = "crate::options::by_name")]
    pub noise_form: NoiseForm,
    /// Initial (and fixed) measurement variance; σ_a² when None.
    pub r0: Option<f64>,
    #[serde(with = "crate::options::by_name")]
    pub adaptive: Adaptive,
    /// Sage–Husa forgetting factor, Q adaptation and fading.
    pub b: f64,
    pub adapt_q: bool,
    pub fading: bool,
    #[serde(with = "crate::options::by_name")]
    pub x0: X0,
    /// P₀ = p0·I.
    pub p0: f64,
}

impl ArmaFilterConfig {
    /// The filter this configuration describes (checks every field).
    pub fn build(&self, record: bool) -> Result<Kalman> {
        let model = ArimaStateSpace::from_arma(&self.ar, &self.ma, self.sigma2, self.d, self.noise_form)?;
        if model.dim() > MAX_DIM {
            let (p, q, d) = (self.ar.len(), self.ma.len(), self.d);
            return Err(invalid("ar", format!("ARIMA({p},{d},{q}) needs {} filter states, more than the supported {MAX_DIM}", model.dim())));
        }
        let mode = RMode::new(self.adaptive, self.b, self.adapt_q, self.fading)?;
        Kalman::new(&model, self.r0.unwrap_or(self.sigma2), mode, self.x0, self.p0, record)
    }

    /// Batch filter of a whole series; also returns the state dimension.
    pub fn filter(&self, omega: &[f64], record: bool) -> Result<(FilterOutput, usize)> {
        if omega.is_empty() {
            return Err(invalid("omega", "empty series"));
        }
        let mut f = self.build(record)?;
        let mut out = FilterOutput::default();
        f.update(omega, &mut out)?;
        Ok((out, f.dim()))
    }
}

/// Filter output; the R and gain histories only when requested.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FilterOutput {
    /// ω̂_k = H X̂_k.
    pub xhat: Vec<f64>,
    /// R_k used at each step.
    pub r: Vec<f64>,
    /// K_k, row-major N×n.
    pub gain: Vec<f64>,
    /// Posterior variance of ω̂_k, the (0, 0) entry of P_k.
    pub var: Vec<f64>,
}

/// Largest state dimension the filter supports (ARMA orders p, q ≤ 3 need at most 7).
pub const MAX_DIM: usize = 8;

const FADING_RHO: f64 = 0.95;

/// Measurement-variance bookkeeping shared by every state dimension.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct RState {
    mode: RMode,
    r: f64,
    r_floor: f64,
    k: usize,
    allan: RunningAllanR,
    last: Option<f64>,
    /// Sage–Husa: b^k, and the fading-factor innovation power V_k.
    bk: f64,
    v: f64,
}

impl RState {
    /// Eq. 17 readings: R_k from the running Allan variance including sample k.
    fn eq17(&mut self, z: f64) {
        let y = match self.mode {
            RMode::Literal => Some(z),
            RMode::Differenced => self.last.map(|prev| z - prev),
            _ => None,
        };
        self.last = Some(z);
        if let Some(r) = y.and_then(|y| self.allan.update(y)) {
            self.r = r;
        }
    }

    /// Sage–Husa weight d_k = (1−b)/(1−b^k).
    fn sage_husa_weight(&self, b: f64) -> f64 {
        (1.0 - b) / (1.0 - self.bk)
    }
}

/// Serde for `[T; N]` of any const N (serde itself covers N ≤ 32 of concrete sizes only).
mod const_array {
    use serde::{de::Error, Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer, T: Serialize, const N: usize>(a: &[T; N], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(a)
    }

    pub fn deserialize<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(d: D) -> Result<[T; N], D::Error> {
        let v = Vec::<T>::deserialize(d)?;
        let n = v.len();
        v.try_into().map_err(|_| D::Error::invalid_length(n, &"the filter's state dimension"))
    }
}

/// The filter at a fixed state dimension N (fixed-size algebra, no allocation per step).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Core<const N: usize> {
    /// Φ = e₀cᵀ + shifts: first row c, row i ≥ 1 copies row i−1 where `shift[i]`.
    c: SVector<f64, N>,
    #[serde(with = "const_array")]
    shift: [bool; N],
    qd: SMatrix<f64, N, N>,
    x: SVector<f64, N>,
    p: SMatrix<f64, N, N>,
    gain: SVector<f64, N>,
    first: bool,
}

// invariant: AnyCore::new builds Core<N> only for N = model.dim() with Φ and Q_d
// checked N × N (check_companion); every i, j below is < N, and i − 1 is taken for i > 0.
#[allow(clippy::indexing_slicing)]
impl<const N: usize> Core<N> {
    fn new(model: &ArimaStateSpace, p0: f64, first: bool) -> Core<N> {
        Core {
            c: SVector::from_fn(|j, _| model.phi[(0, j)]),
            shift: std::array::from_fn(|i| i > 0 && model.phi[(i, i - 1)] == 1.0),
            qd: SMatrix::from_fn(|i, j| model.qd[(i, j)]),
            x: SVector::zeros(),
            p: SMatrix::identity() * p0,
            gain: SVector::zeros(),
            first,
        }
    }

    /// Filter a chunk (the per-step loop is monomorphised for N).
    fn run(&mut self, z: &[f64], rs: &mut RState, out: &mut FilterOutput, record: bool) -> Result<()> {
        for &zk in z {
            out.xhat.push(self.step(zk, rs)?);
            if record {
                out.r.push(rs.r);
                out.gain.extend_from_slice(self.gain.as_slice());
                out.var.push(self.p[(0, 0)]);
            }
        }
        Ok(())
    }

    /// One step of Niu et al. 2025 Eq. 15 with R_k chosen by `rs`.
    #[inline(always)]
    fn step(&mut self, z: f64, rs: &mut RState) -> Result<f64> {
        rs.k += 1;
        if rs.k == 1 && self.first {
            self.x.fill(z);
        }
        // Predict: X⁻ = Φ X̂, F = Φ P Φᵀ.
        let xp = SVector::from_fn(|i, _| if i == 0 { self.c.dot(&self.x) } else if self.shift[i] { self.x[i - 1] } else { 0.0 });
        // Φ P Φᵀ from the structure Φ = e₀cᵀ + shifts and symmetric P, with u = P c:
        // (0,0) = cᵀu, (i,0) = (0,i) = u_{i−1}, (i,j) = P_{i−1,j−1} on shifted rows.
        let u = self.p * self.c;
        let sh = |i: usize| self.shift[i];
        let fpf = SMatrix::<f64, N, N>::from_fn(|i, j| match (i, j) {
            (0, 0) => self.c.dot(&u),
            (0, j) => if sh(j) { u[j - 1] } else { 0.0 },
            (i, 0) => if sh(i) { u[i - 1] } else { 0.0 },
            (i, j) => if sh(i) && sh(j) { self.p[(i - 1, j - 1)] } else { 0.0 },
        });
        let eps = z - xp[0];
        let r_prev = rs.r;
        rs.eq17(z);
        let mut lambda = 1.0;
        if let RMode::SageHusa { b, fading, .. } = rs.mode {
            if fading {
                // Strong-tracking fading factor.
                rs.v = if rs.k == 1 { eps * eps } else { (FADING_RHO * rs.v + eps * eps) / (1.0 + FADING_RHO) };
                if fpf[(0, 0)] > 0.0 {
                    lambda = ((rs.v - self.qd[(0, 0)] - r_prev) / fpf[(0, 0)]).max(1.0);
                }
            }
            let pm00 = lambda * fpf[(0, 0)] + self.qd[(0, 0)];
            rs.bk *= b;
            let dk = rs.sage_husa_weight(b);
            // Sage–Husa: R̂_k = (1−d_k) R̂_{k−1} + d_k (ε² − H P⁻ Hᵀ); drop the subtraction if ≤ 0.
            let r = (1.0 - dk) * r_prev + dk * (eps * eps - pm00);
            rs.r = if r > 0.0 { r } else { (1.0 - dk) * r_prev + dk * eps * eps };
        }
        // R floor (docs/departures.md#r-floor).
        rs.r = rs.r.max(rs.r_floor);
        let pm = fpf * lambda + self.qd;
        let s = pm[(0, 0)] + rs.r;
        if !(s > 0.0 && s.is_finite()) {
            return Err(NavError::Numerical(format!("innovation variance {s} at step {}", rs.k)));
        }
        self.gain = pm.column(0) / s;
        self.x = xp + self.gain * eps;
        // P = (I − K H) P⁻, symmetrised (Niu et al. 2025 Eq. 15).
        let p = pm - self.gain * pm.row(0);
        self.p = (p + p.transpose()) * 0.5;
        if let RMode::SageHusa { b, adapt_q: true, .. } = rs.mode {
            // Sage–Husa Q: Q_k = (1−d_k) Q_{k−1} + d_k (K ε² Kᵀ + P_k − Φ P_{k−1} Φᵀ), kept
            // only if its diagonal stays non-negative (the standard form can lose
            // positive semi-definiteness, e.g. right after P₀).
            let dk = rs.sage_husa_weight(b);
            let q = self.qd * (1.0 - dk) + (self.gain * self.gain.transpose() * (eps * eps) + self.p - fpf) * dk;
            if q.diagonal().iter().all(|&d| d >= 0.0) {
                self.qd = q;
            }
        }
        if !self.x[0].is_finite() {
            return Err(NavError::Numerical(format!("state diverged at step {}", rs.k)));
        }
        Ok(self.x[0])
    }
}

/// The filter relies on Φ having the form built by [`ArimaStateSpace::from_arma`]: a
/// dense first row and, below it, rows that are zero or copy the previous state.
/// Φ and Q_d are checked square of one size here, which the fixed-size cores rely on.
// invariant: i < nrows, j < ncols.
#[allow(clippy::indexing_slicing)]
fn check_companion(phi: &DMatrix<f64>, qd: &DMatrix<f64>) -> Result<()> {
    let n = phi.nrows();
    if phi.ncols() != n || qd.shape() != (n, n) {
        return Err(invalid("model", format!("Φ ({}x{}) and Q_d ({}x{}) must be square of one size", n, phi.ncols(), qd.nrows(), qd.ncols())));
    }
    for i in 1..phi.nrows() {
        for j in 0..phi.ncols() {
            let v = phi[(i, j)];
            if v != 0.0 && !(j + 1 == i && v == 1.0) {
                return Err(invalid("model", format!("Φ row {i} is not a shift row (entry {v} at column {j})")));
            }
        }
    }
    Ok(())
}

macro_rules! cores {
    ($($v:ident = $n:literal),*) => {
        #[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
        #[allow(clippy::large_enum_variant)] // one per filter; boxing would add an indirection per step
        enum AnyCore { $($v(Core<$n>)),* }

        impl AnyCore {
            fn new(model: &ArimaStateSpace, p0: f64, first: bool) -> Result<AnyCore> {
                check_companion(&model.phi, &model.qd)?;
                match model.dim() {
                    $($n => Ok(AnyCore::$v(Core::new(model, p0, first))),)*
                    n => Err(invalid("model", format!("state dimension {n} exceeds the supported maximum {MAX_DIM}"))),
                }
            }

            fn dim(&self) -> usize {
                match self { $(AnyCore::$v(_) => $n,)* }
            }

            fn run(&mut self, z: &[f64], rs: &mut RState, out: &mut FilterOutput, record: bool) -> Result<()> {
                match self { $(AnyCore::$v(c) => c.run(z, rs, out, record),)* }
            }
        }
    };
}

cores!(D1 = 1, D2 = 2, D3 = 3, D4 = 4, D5 = 5, D6 = 6, D7 = 7, D8 = 8);

/// Stateful Kalman filter on an ARIMA state-space model (Niu et al. 2025 Eq. 15); feed chunks
/// with [`Kalman::update`] for streaming, or use [`kalman`] for a whole series.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Kalman {
    core: AnyCore,
    rs: RState,
    record: bool,
}

impl Kalman {
    /// `r0`: initial (and fixed) measurement variance; `p0`: P₀ = p0·I.
    pub fn new(model: &ArimaStateSpace, r0: f64, mode: RMode, x0: X0, p0: f64, record: bool) -> Result<Kalman> {
        check_positive("r0", r0)?;
        check_positive("p0", p0)?;
        let rs = RState { mode, r: r0, r_floor: 1e-12 * model.sigma2, k: 0, allan: RunningAllanR::default(), last: None, bk: 1.0, v: 0.0 };
        Ok(Kalman { core: AnyCore::new(model, p0, x0 == X0::First)?, rs, record })
    }

    /// State dimension n (the width of a gain row).
    pub fn dim(&self) -> usize {
        self.core.dim()
    }

    /// Filter the next chunk of measurements, appending to `out`.
    pub fn update(&mut self, z: &[f64], out: &mut FilterOutput) -> Result<()> {
        check_finite("omega", z, 1)?;
        out.xhat.reserve(z.len());
        self.core.run(z, &mut self.rs, out, self.record)
    }
}

/// Batch filter of a whole series.
pub fn kalman(omega: &[f64], model: &ArimaStateSpace, r0: f64, mode: RMode, x0: X0, p0: f64, record: bool) -> Result<FilterOutput> {
    if omega.is_empty() {
        return Err(invalid("omega", "empty series"));
    }
    let mut f = Kalman::new(model, r0, mode, x0, p0, record)?;
    let mut out = FilterOutput::default();
    f.update(omega, &mut out)?;
    Ok(out)
}

/// Steady state of the fixed filter for measurement variance r: (K∞, P⁻∞, P⁺∞), by
/// iterating the Riccati recursion to convergence.
// invariant: Φ and Q_d are n × n with n = dim ≥ 1 (from_arma), so (0, 0) is in range.
#[allow(clippy::indexing_slicing)]
pub fn steady_state(model: &ArimaStateSpace, r: f64) -> Result<(Vec<f64>, DMatrix<f64>, DMatrix<f64>)> {
    check_positive("r", r)?;
    let phi = &model.phi;
    let mut pm = phi * phi.transpose() + &model.qd;
    for _ in 0..1_000_000 {
        let s = pm[(0, 0)] + r;
        let k = pm.column(0) / s;
        let pp = &pm - &k * pm.row(0);
        let next = phi * &pp * phi.transpose() + &model.qd;
        let diff = (&next - &pm).abs().max();
        if !diff.is_finite() {
            return Err(NavError::Numerical("steady_state: the Riccati iteration diverged (model not detectable?)".into()));
        }
        pm = next;
        if diff <= 1e-15 * pm.abs().max() {
            let s = pm[(0, 0)] + r;
            let k = pm.column(0) / s;
            let pp = &pm - &k * pm.row(0);
            if !k.iter().chain(pm.iter()).chain(pp.iter()).all(|v| v.is_finite()) {
                return Err(NavError::Numerical("steady_state: the Riccati solution overflows the floating-point range".into()));
            }
            return Ok((k.iter().copied().collect(), pm, pp));
        }
    }
    Err(NavError::Numerical("steady_state: Riccati iteration did not converge (model not detectable?)".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> ArimaStateSpace {
        ArimaStateSpace::from_arma(&[-0.018, 0.029], &[-0.99], 0.035, 1, NoiseForm::Paper).unwrap()
    }

    #[test]
    fn eq12_coefficients_and_noise() {
        let m = paper();
        let row: Vec<f64> = (0..3).map(|j| m.phi[(0, j)]).collect();
        for (a, e) in row.iter().zip([0.982, 0.047, -0.029]) {
            assert!((a - e).abs() < 1e-12);
        }
        assert!((m.qd[(0, 0)] - 0.0693035).abs() < 1e-12);
        assert_eq!(m.qd.iter().filter(|v| **v != 0.0).count(), 1);
    }

    #[test]
    fn a_filter_too_large_names_ar() {
        let config = ArmaFilterConfig { ar: vec![0.0; 48], ma: vec![100.0], sigma2: 20.6, d: 1, noise_form: NoiseForm::Paper, r0: Some(77.0),
                                        adaptive: Adaptive::Fixed, b: 0.98, adapt_q: false, fading: false, x0: X0::Zeros, p0: 1.0 };
        match config.build(false).err() {
            Some(crate::error::NavError::InvalidInput { field, .. }) => assert_eq!(field, "ar"),
            other => panic!("expected InvalidInput, got {other:?}"),
        }
        assert!(ArmaFilterConfig { ar: vec![-0.018, 0.029], ma: vec![-0.99], ..config }.build(false).is_ok());
    }

    #[test]
    fn a_model_beyond_floats_names_its_coefficients() {
        let field = |r: Result<ArimaStateSpace>| match r {
            Err(crate::error::NavError::InvalidInput { field, .. }) => field,
            other => panic!("expected InvalidInput, got {other:?}"),
        };
        assert_eq!(field(ArimaStateSpace::from_arma(&[0.0; 8], &[1e308], 0.001, 1, NoiseForm::Paper)), "ma");
        assert_eq!(field(ArimaStateSpace::from_arma(&[1e308, 1e308], &[], 1.0, 3, NoiseForm::Exact)), "ar");
    }

    #[test]
    fn steady_state_gain_matches_spec() {
        let (k, pm, pp) = steady_state(&paper(), 0.035).unwrap();
        for (a, e) in k.iter().zip([0.729723, 0.195707, 0.058209]) {
            assert!((a - e).abs() < 1e-6, "{k:?}");
        }
        assert!((pm[(0, 0)] - 0.094497).abs() < 1e-6 && (pp[(0, 0)] - 0.025540).abs() < 1e-6);
    }

    #[test]
    fn eq17_recursion_oracle() {
        // by hand: y = [1, 3, 2, 5, 4].
        let mut r = RunningAllanR::default();
        let got: Vec<Option<f64>> = [1.0, 3.0, 2.0, 5.0, 4.0].iter().map(|&y| r.update(y)).collect();
        let want = [None, Some(2.0), Some(1.25), Some(7.0 / 3.0), Some(1.875)];
        for (g, w) in got.iter().zip(want) {
            match (g, w) {
                (None, None) => {}
                (Some(g), Some(w)) => assert!((g - w).abs() < 1e-14),
                _ => panic!("{got:?}"),
            }
        }
    }

    #[test]
    fn exact_form_layout() {
        let m = ArimaStateSpace::from_arma(&[-0.018, 0.029], &[-0.99], 0.035, 1, NoiseForm::Exact).unwrap();
        assert_eq!(m.dim(), 4);
        assert_eq!(m.phi[(0, 3)], -0.99);
        assert_eq!((m.b[(0, 0)], m.b[(3, 0)]), (1.0, 1.0));
        assert_eq!(m.phi.row(3).iter().filter(|v| **v != 0.0).count(), 0);
    }

    #[test]
    fn streaming_equals_batch() {
        let m = paper();
        let w: Vec<f64> = (0..500).map(|k| 0.7 + 0.1 * ((k * 7919 % 101) as f64 / 50.0 - 1.0)).collect();
        for mode in [RMode::Fixed, RMode::Differenced, RMode::SageHusa { b: 0.98, adapt_q: true, fading: true }] {
            let batch = kalman(&w, &m, 0.035, mode, X0::Zeros, 1.0, true).unwrap();
            let mut f = Kalman::new(&m, 0.035, mode, X0::Zeros, 1.0, true).unwrap();
            let mut out = FilterOutput::default();
            for c in w.chunks(33) {
                f.update(c, &mut out).unwrap();
            }
            assert_eq!(batch, out);
        }
    }

    #[test]
    fn config_builds_the_named_filter() {
        let w: Vec<f64> = (0..300).map(|k| 0.7 + 0.1 * ((k * 7919 % 101) as f64 / 50.0 - 1.0)).collect();
        let cfg = ArmaFilterConfig {
            ar: vec![-0.018, 0.029],
            ma: vec![-0.99],
            sigma2: 0.035,
            d: 1,
            noise_form: NoiseForm::parse("paper").unwrap(),
            r0: None,
            adaptive: Adaptive::parse("sage_husa").unwrap(),
            b: 0.98,
            adapt_q: true,
            fading: false,
            x0: X0::parse("first").unwrap(),
            p0: 1.0,
        };
        let (out, n) = cfg.filter(&w, true).unwrap();
        let mode = RMode::SageHusa { b: 0.98, adapt_q: true, fading: false };
        assert_eq!(out, kalman(&w, &paper(), 0.035, mode, X0::First, 1.0, true).unwrap());
        assert_eq!(n, 3);
        let bad = ArmaFilterConfig { b: 1.0, ..cfg.clone() };
        assert!(matches!(bad.build(false), Err(NavError::InvalidInput { ref field, .. }) if field == "b"));
        assert!(matches!(cfg.filter(&[], false), Err(NavError::InvalidInput { ref field, .. }) if field == "omega"));
        for (e, p) in [(Adaptive::parse("eq17").unwrap_err(), "adaptive"), (X0::parse("last").unwrap_err(), "x0"), (NoiseForm::parse("x").unwrap_err(), "noise_form")] {
            assert!(matches!(e, NavError::InvalidInput { ref field, .. } if field == p), "{e}");
        }
    }
}
