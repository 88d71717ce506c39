//! Strapdown mechanization in the local-level NED frame: quaternion attitude with coning correction, velocity with rotation and sculling
//! corrections, Coriolis, Earth and transport rate, normal gravity, optional baro-damped
//! vertical channel. Second order in the step: gravity, Coriolis and the navigation-frame
//! rotation are taken at the interval midpoint (predictor–corrector), and the specific
//! force is rotated by [I − ½[ζ×]] for the navigation-frame rotation ζ over the step
//! (Savage, Strapdown Analytics §7.2). The midpoint is extrapolated from the previous
//! step (position) and from this step's specific force plus the previous step's
//! gravity–Coriolis term (velocity), so each step evaluates the Earth model once.
//!
//! One `Strapdown` object serves batch use (one call over a whole record) and streaming
//! (successive chunks): it keeps the previous sample for coning/sculling. `pipeline.rs`
//! integrates a chunk on two cores into a navigation table.

mod pipeline;

use serde::{Deserialize, Serialize};
use crate::earth::{check_height, check_latitude, AnchoredSinCos, Ellipsoid, LocalModel};
use crate::error::{invalid, invalid_at, Result};
pub use crate::imu::ImuKind;
use crate::math::{quat_from_rotvec, quat_normalize, quat_rotate, rotation_quat, Quat, Vec3};
use crate::options::Choice;
pub use pipeline::{nav_columns, ImuSlices, NavTable, Samples3, NAV_COLUMNS, NAV_WIDTH, PIPELINE_BLOCK};

/// Navigation solution at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NavState {
    pub t: f64,
    /// (lat rad, lon rad, h m).
    pub lla: Vec3,
    /// NED velocity (m/s).
    pub vel: Vec3,
    /// Attitude q_nb (Hamilton, scalar first).
    pub q_nb: Quat,
}

/// Vertical channel: free (unstable, e-folding ≈ √(R/2g) ≈ 9.5 min) or damped by a
/// reference altitude h_b (barometer): the second-order baro loop with gains
/// K_v1 = 2ζω_v, K_v2 = ω_v² + 2γ/R₀, whose 2γ/R₀ cancels the free channel's instability.
/// Chosen by name ("free", "damped"); "damped" has the loop's default damping ratio and
/// natural frequency until [`Vertical::tuned`] sets them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Vertical {
    Free,
    Damped { zeta: f64, omega: f64 },
}

impl Vertical {
    /// Default damping ratio ζ of the baro loop (critical damping's 1/√2).
    pub const DEFAULT_ZETA: f64 = 0.707;
    /// Default natural frequency ω_v of the baro loop (rad/s; a period of about 10 min).
    pub const DEFAULT_OMEGA: f64 = 0.01;

    /// This channel with the baro loop's damping ratio `zeta` and natural frequency
    /// `omega` (rad/s) where given; a free channel stays free. `Strapdown::new` checks them.
    pub fn tuned(self, zeta: Option<f64>, omega: Option<f64>) -> Vertical {
        match self {
            Vertical::Free => Vertical::Free,
            Vertical::Damped { zeta: z, omega: w } => Vertical::Damped { zeta: zeta.unwrap_or(z), omega: omega.unwrap_or(w) },
        }
    }
}

impl NavState {
    /// The checks every state a user starts from passes, the same for a new object and a
    /// restart: finite time `t0`, velocity `vel_ned` and position `lla` with the latitude
    /// within ±90° and the height in [`crate::earth::HEIGHT_RANGE`], and a rotation `q_nb` (unit norm
    /// within [`crate::math::ROTATION_TOLERANCE`]). Returns `q_nb` scaled to exactly unit norm. Errors
    /// name the argument (`t0`, `lla`, `vel_ned`, `q_nb`).
    pub fn check(&self) -> Result<Quat> {
        if !self.t.is_finite() {
            return Err(invalid("t0", format!("must be finite, got {}", self.t)));
        }
        for (field, v) in [("lla", &self.lla), ("vel_ned", &self.vel)] {
            if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                return Err(invalid(field, format!("non-finite value {x}")));
            }
        }
        check_latitude("lla", self.lla.x, 0)?;
        check_height("lla", self.lla.z)?;
        rotation_quat("q_nb", 0, &self.q_nb)
    }
}

impl Choice for Vertical {
    const PARAMETER: &'static str = "vertical";
    const CHOICES: &'static [(&'static str, Self)] =
        &[("free", Vertical::Free), ("damped", Vertical::Damped { zeta: Vertical::DEFAULT_ZETA, omega: Vertical::DEFAULT_OMEGA })];

    /// The name of either channel, whatever the damped loop's gains.
    fn name(self) -> &'static str {
        match self {
            Vertical::Free => "free",
            Vertical::Damped { .. } => "damped",
        }
    }
}


#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Strapdown {
    #[serde(with = "crate::options::by_name")]
    pub ell: Ellipsoid,
    pub vertical: Vertical,
    pub state: NavState,
    /// `ell`'s constants of the Earth model evaluated at every step.
    earth: LocalModel,
    /// sin/cos of the midpoint latitude, from an exact anchor (a sixth of libm's cost).
    lat_sin_cos: AnchoredSinCos,
    /// The IMU-only half of each step (rates to increments, coning, sculling).
    pub(crate) front: BodyFront,
    /// Previous step: (Δlla, Δt, g − (2ω_ie + ω_en)×v at its midpoint), for the midpoint
    /// extrapolation.
    last_step: Option<(Vec3, f64, Vec3)>,
}

impl Strapdown {
    /// A strapdown INS from `initial`, checked by [`NavState::check`] (errors name the
    /// constructor's arguments `t0`, `lla`, `vel_ned`, `q_nb`) and with the baro loop's
    /// gains checked (`zeta`, `omega`).
    pub fn new(initial: NavState, kind: ImuKind, ell: Ellipsoid, vertical: Vertical) -> Result<Strapdown> {
        let q_nb = initial.check()?;
        if let Vertical::Damped { zeta, omega } = vertical {
            if !(zeta.is_finite() && zeta > 0.0) {
                return Err(invalid("zeta", format!("the baro loop's damping ratio must be finite and > 0, got {zeta}")));
            }
            if !(omega.is_finite() && omega > 0.0) {
                return Err(invalid("omega", format!("the baro loop's natural frequency must be finite and > 0 rad/s, got {omega}")));
            }
        }
        let state = NavState { q_nb, ..initial };
        Ok(Strapdown { ell, vertical, state, earth: ell.local_model(), lat_sin_cos: AnchoredSinCos::new(state.lla.x), front: BodyFront::new(kind), last_step: None })
    }

    /// Restart from `state` as a new object with this one's IMU kind, ellipsoid and
    /// vertical channel would (no coning/sculling history, rate priming anew), with the
    /// constructor's checks. On error nothing changes.
    pub fn reset(&mut self, state: NavState) -> Result<()> {
        *self = Strapdown::new(state, self.kind(), self.ell, self.vertical)?;
        Ok(())
    }

    /// Rates or increments.
    pub fn kind(&self) -> ImuKind {
        self.front.kind
    }

    /// Run over a chunk. `t[k]` is the sample time (rates) or the end of the interval
    /// (increments); `gyro`, `accel` are rates (rad/s, m/s²) or increments (rad, m/s);
    /// `h_ref` is the reference altitude (m) per sample, required with a damped vertical
    /// channel. Appends the state after each sample to `out`. With rates, a first sample
    /// at the initial time only primes the integrator (its output is the initial state).
    /// On divergence `out` keeps every state computed before it.
    pub fn run(&mut self, t: &[f64], gyro: &[Vec3], accel: &[Vec3], h_ref: Option<&[f64]>, out: &mut Vec<NavState>) -> Result<()> {
        self.validate(t, gyro, accel, h_ref, 0)?;
        let mut body = Vec::new();
        self.front.push_block(t, gyro, accel, &mut body);
        self.run_body(t, &body, h_ref, 0, out)
    }

    /// The navigation half of `run` on checked samples (rows `first_index`… of the record,
    /// the index divergence errors report): `body[k]` is `BodyFront::push` of sample k by a
    /// front that has seen the same samples as this one's (a pipelined run computes it on
    /// another core; the caller then sets `front` to that front).
    pub(crate) fn run_body(&mut self, t: &[f64], body: &[BodyStep], h_ref: Option<&[f64]>, first_index: usize, out: &mut Vec<NavState>) -> Result<()> {
        out.reserve(t.len());
        let mut h_ref = h_ref.map(|h| h.iter());
        for (k, (b, &tk)) in body.iter().zip(t).enumerate() {
            let hk = h_ref.as_mut().and_then(|h| h.next().copied());
            if let Some(b) = b {
                self.integrate(tk, b, hk);
            }
            self.check_diverged(first_index + k)?;
            out.push(self.state);
        }
        Ok(())
    }

    /// Numerical error if the solution after sample `k` is non-finite or off the globe.
    pub(crate) fn check_diverged(&self, k: usize) -> Result<()> {
        let s = &self.state;
        // a sum is finite iff every term is (NaN and ±inf propagate)
        let finite = (s.lla.sum() + s.vel.sum() + s.q_nb.coords.sum()).is_finite();
        if !finite || s.lla.x.abs() > std::f64::consts::FRAC_PI_2 {
            return Err(crate::error::NavError::Numerical(format!(
                "navigation solution diverged at sample {k} (t = {} s): latitude {} rad, velocity {:?}",
                s.t, s.lla.x, s.vel
            )));
        }
        Ok(())
    }

    /// Checks of a chunk before it is run (shapes, time order from the current state,
    /// finite samples, reference altitude). Messages give indices counted from
    /// `first_index` (the chunk's position in the whole record).
    pub(crate) fn validate(&self, t: &[f64], gyro: &[Vec3], accel: &[Vec3], h_ref: Option<&[f64]>, first_index: usize) -> Result<()> {
        self.sample_check().check(t, gyro, accel, h_ref, first_index)
    }

    /// The checks `validate` applies to samples that follow the current state.
    pub(crate) fn sample_check(&self) -> SampleCheck {
        SampleCheck { kind: self.kind(), damped: matches!(self.vertical, Vertical::Damped { .. }), prev_t: self.state.t, primed: self.front.primed() }
    }

    /// One mechanization step to time `t` with one IMU sample (rates or increments).
    #[inline]
    pub fn step(&mut self, t: f64, gyro: &Vec3, accel: &Vec3, h_ref: Option<f64>) {
        if let Some(b) = self.front.push(t, gyro, accel) {
            self.integrate(t, &b, h_ref);
        }
    }

    /// Attitude, velocity and position over one interval (t_{k−1}, t], given the body
    /// step of `BodyFront::push`.
    #[inline(always)]
    fn integrate(&mut self, t: f64, &(q_phi, dv_body): &(Quat, Vec3), h_ref: Option<f64>) {
        let s0 = self.state;
        let dt = t - s0.t;
        let model = &self.earth;
        let dv_sf_b = quat_rotate(&s0.q_nb, &dv_body); // C_nb(k−1) Δv
        // midpoint: position extrapolated from the previous step; velocity from this step's
        // specific force and the previous gravity–Coriolis term (at t₀ on the first step)
        let (lla_mid, gc_prev) = match self.last_step {
            Some((dlla, dt_prev, gc)) => (s0.lla + dlla * (0.5 * dt / dt_prev), gc),
            None => {
                let e = model.at(s0.lla.x, s0.lla.z);
                (s0.lla, Vec3::new(0.0, 0.0, e.gravity) - (2.0 * e.earth_rate() + e.transport_rate(&s0.vel)).cross(&s0.vel))
            }
        };
        let v_mid = s0.vel + 0.5 * (dv_sf_b + gc_prev * dt);
        let earth = model.at_sin_cos(self.lat_sin_cos.sin_cos(lla_mid.x), lla_mid.z);
        // Baro loop: ḣ gets −K_v1(h − h_b), v̇_D gets +K_v2(h − h_b), with
        // K_v1 = 2ζω_v, K_v2 = ω_v² + 2γ/R₀ (R₀ = √(R_M R_P)).
        let (k1, k2, dh0) = match (self.vertical, h_ref) {
            (Vertical::Damped { zeta, omega }, Some(hb)) => {
                (2.0 * zeta * omega, omega * omega + 2.0 * earth.gravity / (earth.rm * earth.rp).sqrt(), s0.lla.z - hb)
            }
            _ => (0.0, 0.0, 0.0),
        };
        let w_ie = earth.earth_rate();
        let w_en = earth.transport_rate(&v_mid);
        let zeta = (w_ie + w_en) * dt; // navigation-frame rotation over the step
        let dv_sf = dv_sf_b - 0.5 * zeta.cross(&dv_sf_b);
        let gc = Vec3::new(0.0, 0.0, earth.gravity) - (2.0 * w_ie + w_en).cross(&v_mid);
        let mut vel = s0.vel + dv_sf + gc * dt;
        vel.z += k2 * dh0 * dt;
        let mut lla = s0.lla + earth.lla_rate(&(0.5 * (s0.vel + vel))) * dt;
        lla.z -= k1 * dh0 * dt;
        self.last_step = Some((lla - s0.lla, dt, gc));
        // C_nb(k) = C_{n(k−1)}^{n(k)} C_nb(k−1) C_{b(k)}^{b(k−1)}
        let q = quat_from_rotvec(&(-zeta)) * s0.q_nb * q_phi;
        // renormalise by one Newton step for 1/|q|: |q|² = 1 + ε with ε at rounding level
        // after a product of unit quaternions, so (3 − |q|²)/2 leaves O(ε²) — no sqrt, no divide
        self.state = NavState { t, lla, vel, q_nb: q * (1.5 - 0.5 * q.norm_squared()) };
    }
}

/// One sample's body-frame step: q(φ) of the rotation vector φ (coning included) and the
/// velocity increment Δv_b (rotation and sculling included), both referred to the body
/// frame at t_{k−1}; None for the rate sample that only primes the integrator.
pub type BodyStep = Option<(Quat, Vec3)>;

/// The IMU-only half of a mechanization step: rates turned into increments, then coning
/// and sculling over the last intervals. It depends on the IMU record alone, so a
/// pipelined run computes it for the next block on another core while the navigation
/// half integrates this one.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BodyFront {
    #[serde(with = "crate::options::by_name")]
    kind: ImuKind,
    /// Increments (Δθ, Δv) of up to the two previous intervals (most recent last), for
    /// the multi-interval coning and sculling terms.
    prev_increments: History<(Vec3, Vec3)>,
    /// Up to the last two rate samples (t, ω, f), to turn rates into increments.
    rate_history: History<(f64, Vec3, Vec3)>,
}

impl BodyFront {
    pub fn new(kind: ImuKind) -> Self {
        Self { kind, prev_increments: History::default(), rate_history: History::default() }
    }

    /// False until the first rate sample (which only primes the integrator) has been seen.
    pub fn primed(&self) -> bool {
        self.kind == ImuKind::Increments || !self.rate_history.as_slice().is_empty()
    }

    /// The body step of one sample at time `t` (rates or increments).
    #[inline(always)]
    pub fn push(&mut self, t: f64, gyro: &Vec3, accel: &Vec3) -> BodyStep {
        let (dth, dv) = match self.kind {
            ImuKind::Increments => (*gyro, *accel),
            ImuKind::Rates => {
                let inc = rates_to_increment(self.rate_history.as_slice(), t, gyro, accel);
                self.rate_history.push((t, *gyro, *accel));
                inc? // None: the first rate sample at the initial time, nothing to integrate yet
            }
        };
        let (phi, dv_body) = coning_sculling(self.prev_increments.as_slice(), &dth, &dv);
        self.prev_increments.push((dth, dv));
        Some((quat_from_rotvec(&phi), dv_body))
    }

    /// `push` of each sample of a block, into `out` (cleared first).
    pub fn push_block(&mut self, t: &[f64], gyro: &[Vec3], accel: &[Vec3], out: &mut Vec<BodyStep>) {
        out.clear();
        out.extend(t.iter().zip(gyro).zip(accel).map(|((&t, g), a)| self.push(t, g, a)));
    }
}

/// The input checks of samples following time `prev_t`: shapes, strictly increasing finite
/// time (a first rate sample, when not yet `primed`, must be at `prev_t`, the initial
/// time), finite samples, a finite reference altitude per sample when `damped`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SampleCheck {
    pub kind: ImuKind,
    pub damped: bool,
    pub prev_t: f64,
    pub primed: bool,
}

impl SampleCheck {
    /// Check one chunk (messages give indices counted from `first_index`), then move past it.
    pub fn check(&mut self, t: &[f64], gyro: &[Vec3], accel: &[Vec3], h_ref: Option<&[f64]>, first_index: usize) -> Result<()> {
        check_lengths(t.len(), gyro.len(), accel.len(), h_ref.map(<[f64]>::len))?;
        let t0 = self.prev_t;
        for (k, &tk) in t.iter().enumerate() {
            if !tk.is_finite() {
                return Err(invalid_at("time", first_index + k, format!("non-finite time {tk} at index {}", first_index + k)));
            }
            // With rates the very first sample may coincide with the initial time.
            let first_rate_sample = self.kind == ImuKind::Rates && !self.primed && k == 0;
            if first_rate_sample && tk != t0 {
                return Err(invalid_at("time", first_index, format!("the first rate sample must be at the initial time {t0} s, got {tk} at index {first_index}")));
            }
            if !first_rate_sample && tk <= self.prev_t {
                let what = if tk == self.prev_t { "duplicated" } else { "decreasing" };
                return Err(invalid_at("time", first_index + k, format!("time not strictly increasing: {what} stamp {tk} at index {}", first_index + k)));
            }
            self.prev_t = tk;
        }
        for (name, data) in [("gyro", gyro), ("accel", accel)] {
            if let Some((k, v)) = data.iter().enumerate().find(|(_, v)| !v.iter().all(|x| x.is_finite())) {
                return Err(invalid_at(name, first_index + k, format!("non-finite value at index {}: {:?}", first_index + k, v.as_slice())));
            }
        }
        match h_ref {
            None if self.damped => return Err(invalid("h_ref", "a damped vertical channel needs a reference altitude per sample")),
            Some(h) => {
                if let Some(k) = h.iter().position(|x| !x.is_finite()) {
                    return Err(invalid_at("h_ref", first_index + k, format!("non-finite value at index {}", first_index + k)));
                }
            }
            None => {}
        }
        self.primed |= !t.is_empty();
        Ok(())
    }
}

/// A chunk's gyro, accel and reference-altitude (when given) lengths equal its `n` time
/// stamps.
pub(crate) fn check_lengths(n: usize, gyro: usize, accel: usize, h_ref: Option<usize>) -> Result<()> {
    if gyro != n || accel != n {
        return Err(invalid("imu", format!("time has {n} samples but gyro {gyro} and accel {accel}")));
    }
    match h_ref {
        Some(h) if h != n => Err(invalid("h_ref", format!("expected {n} samples, got {h}"))),
        _ => Ok(()),
    }
}

/// Increments (∫ω dt, ∫f dt) over (t_{k−1}, t_k] from rate samples: the integral of the
/// quadratic through the last three samples (trapezoid while only two exist). For uniform
/// steps the weights are h/12·(−1, 8, 5); the local error is O(h⁴ y‴) instead of the
/// trapezoid's O(h³ y″), which keeps a 10-minute run at the 10⁻³ m level.
fn rates_to_increment(history: &[(f64, Vec3, Vec3)], t: f64, w: &Vec3, f: &Vec3) -> Option<(Vec3, Vec3)> {
    match history {
        [] => None,
        [(t1, w1, f1)] => {
            let h = t - t1;
            Some((0.5 * h * (w1 + w), 0.5 * h * (f1 + f)))
        }
        [(t0, w0, f0), (t1, w1, f1)] => {
            // Lagrange weights on nodes (−h₁, 0, h) integrated over [0, h]
            let (h1, h) = (t1 - t0, t - t1);
            let a = -h * h * h / (6.0 * h1 * (h1 + h));
            let b = h * h / (6.0 * h1) + 0.5 * h;
            let c = (h * h / 3.0 + 0.5 * h1 * h) / (h + h1);
            Some((a * w0 + b * w1 + c * w, a * f0 + b * f1 + c * f))
        }
        _ => unreachable!("the rate history holds at most two samples"),
    }
}

/// The last two entries of a stream (oldest first), kept without allocation.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
struct History<T: Copy + Default> {
    items: [T; 2],
    len: usize,
}

// invariant: len ≤ 2 = items.len(): push drops the oldest item before len reaches 2.
#[allow(clippy::indexing_slicing)]
impl<T: Copy + Default> History<T> {
    fn push(&mut self, item: T) {
        if self.len == 2 {
            self.items[0] = self.items[1];
            self.len = 1;
        }
        self.items[self.len] = item;
        self.len += 1;
    }
    fn as_slice(&self) -> &[T] {
        &self.items[..self.len]
    }
}

/// Coning and sculling from this and the previous increments (most recent last).
///
/// Coning: φ = Δθ_k + (c₁Δθ_{k−1} + c₂Δθ_{k−2}) × Δθ_k. With two previous intervals
/// c = (7/60, −1/60): matching the exact per-interval coning term ½ sin²β (λ − sin λ)
/// (λ = ΩΔt) through λ⁵ leaves a drift O(sin²β Ω λ⁶); for linearly varying rates the sum
/// c₁ + 2c₂ = 1/12 keeps it exact to third order. With one previous interval c₁ = 1/12,
/// whose drift sin²β Ω λ⁴/60 is 5e-10 rad/s for a 1°, 1 Hz cone at 100 Hz. The first
/// interval of a record has no coning term.
///
/// Velocity: Δv_b = Δv + ½Δθ×Δv + ⅙Δθ×(Δθ×Δv) + (Δθ_{k−1}×Δv + Δv_{k−1}×Δθ)/12. The ⅙
/// term is the second-order rotation of the specific force within the step; it is
/// rectified (always opposes f's component across the rotation axis), so leaving it
/// out biases the vertical channel by ≈ ⅙|Δθ|²g/Δt (1.5e-7 m/s² for 0.03 rad/s at 100 Hz).
#[inline(always)]
fn coning_sculling(prev: &[(Vec3, Vec3)], dth: &Vec3, dv: &Vec3) -> (Vec3, Vec3) {
    // constant divisors as multipliers (a division is ~4× a multiplication's throughput)
    const SIXTH: f64 = 1.0 / 6.0;
    const TWELFTH: f64 = 1.0 / 12.0;
    let rot = 0.5 * dth.cross(dv) + SIXTH * dth.cross(&dth.cross(dv));
    match prev {
        [] => (*dth, dv + rot),
        [.., (pth, pv)] => {
            let coning = match prev {
                [(ppth, _), _] => (7.0 / 60.0 * pth - 1.0 / 60.0 * ppth).cross(dth),
                _ => TWELFTH * pth.cross(dth),
            };
            (dth + coning, dv + rot + TWELFTH * (pth.cross(dv) + pv.cross(dth)))
        }
    }
}

/// Integrate body attitude only (no navigation-frame rotation) from increments with the
/// coning correction of `coning_sculling`: q_k = q_{k−1} ⊗ q(φ_k). `dtheta_prev` holds
/// the increments of up to two intervals before the first one, oldest first, when known
/// (a running INS has them); without them the first steps have a lower-order coning
/// term (a one-time error of about |Δθ₀ × Δθ₁|/12 on the first step).
pub fn integrate_attitude(q0: &Quat, dtheta: &[Vec3], dtheta_prev: &[Vec3]) -> Vec<Quat> {
    let mut q = quat_normalize(q0);
    let mut prev = History::default();
    for d in dtheta_prev.iter().rev().take(2).rev() {
        prev.push((*d, Vec3::zeros()));
    }
    dtheta
        .iter()
        .map(|d| {
            let (phi, _) = coning_sculling(prev.as_slice(), d, &Vec3::zeros());
            prev.push((*d, Vec3::zeros()));
            q = quat_normalize(&(q * quat_from_rotvec(&phi)));
            q
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::WGS84;
    use crate::imu::ideal::{ideal_increments, ideal_rates};
    use crate::math::quat_angle_between;
    use crate::trajectory::generators::sinusoidal;

    /// Free-vertical round trip: exact IMU of a sinusoidal motion integrated back.
    fn round_trip(kind: ImuKind, seconds: f64) -> (f64, f64) {
        let origin = Vec3::new(0.6, 0.2, 150.0);
        let m = sinusoidal(origin, seconds, Vec3::new(20.0, 15.0, 2.0), Vec3::new(60.0, 45.0, 30.0), Vec3::new(0.1, 0.08, 0.3), Vec3::new(20.0, 25.0, 40.0), 0.5).unwrap();
        let n = (seconds * 100.0) as usize + 1;
        let times: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
        let truth = m.truth(&WGS84, &times).unwrap();
        let init = NavState { t: 0.0, lla: truth[0].lla, vel: truth[0].vel, q_nb: truth[0].q_nb };
        let mut sd = Strapdown::new(init, kind, WGS84, Vertical::Free).unwrap();
        let out = match kind {
            ImuKind::Rates => {
                let (f, w, _) = ideal_rates(&m, &WGS84, &truth);
                let mut out = Vec::new();
                sd.run(&times, &w, &f, None, &mut out).unwrap();
                out
            }
            ImuKind::Increments => {
                let (dv, dth) = ideal_increments(&m, &WGS84, &truth);
                let mut out = Vec::new();
                sd.run(&times[1..], &dth, &dv, None, &mut out).unwrap();
                out
            }
        };
        let last = out.last().unwrap();
        let tl = truth.last().unwrap();
        let dpos = WGS84.lla_to_ecef(&last.lla) - WGS84.lla_to_ecef(&tl.lla);
        (dpos.norm(), quat_angle_between(&last.q_nb, &tl.q_nb))
    }

    #[test]
    fn reset_equals_a_new_object_bit_for_bit() {
        for kind in [ImuKind::Rates, ImuKind::Increments] {
            let (t, g, a) = (0..300).fold((vec![], vec![], vec![]), |(mut t, mut g, mut a), k| {
                let tk = if kind == ImuKind::Rates { k } else { k + 1 } as f64 * 0.01;
                t.push(tk);
                g.push(Vec3::new(0.1 * tk.sin(), 0.05, -0.02 * tk));
                a.push(Vec3::new(0.3, -0.1 * tk.cos(), -9.81));
                (t, g, a)
            });
            let vertical = Vertical::Damped { zeta: 0.5, omega: 0.02 };
            let h = vec![130.0; t.len()];
            let run = |sd: &mut Strapdown, from: usize| {
                let (t, g, a, h) = (&t[from..], &g[from..], &a[from..], &h[from..]);
                let mut out = Vec::new();
                sd.run(t, g, a, Some(h), &mut out).unwrap();
                out
            };
            let first = NavState { t: 0.0, lla: Vec3::new(-0.4, 2.0, 120.0), vel: Vec3::new(1.0, 2.0, 0.1), q_nb: crate::math::quat(0.5, 0.5, -0.5, 0.5) };
            let mut used = Strapdown::new(first, kind, WGS84, vertical).unwrap();
            let before = run(&mut used, 0);
            // restart from the state after row 99 (with rates, row 99 then primes anew)
            let mid = before[99];
            used.reset(mid).unwrap();
            let mut fresh = Strapdown::new(mid, kind, WGS84, vertical).unwrap();
            let from = if kind == ImuKind::Rates { 99 } else { 100 };
            assert_eq!(run(&mut used, from), run(&mut fresh, from), "{kind:?}");
        }
    }

    #[test]
    fn new_and_reset_reject_the_same_states_naming_the_argument_and_keep_the_old_one() {
        let good = NavState { t: 0.0, lla: Vec3::new(0.4, 0.1, 10.0), vel: Vec3::zeros(), q_nb: crate::math::quat(1.0, 0.0, 0.0, 0.0) };
        let mut sd = Strapdown::new(good, ImuKind::Increments, WGS84, Vertical::Free).unwrap();
        let nudged = |f: &dyn Fn(&mut NavState)| {
            let mut s = good;
            f(&mut s);
            s
        };
        for (bad, field, why) in [
            (nudged(&|s| s.q_nb = crate::math::quat(1.0, 0.1, 0.1, 0.1)), "q_nb", "norm"),
            (nudged(&|s| s.q_nb = crate::math::quat(1.0 + 2e-6, 0.0, 0.0, 0.0)), "q_nb", "norm"),
            (nudged(&|s| s.lla.x = 1.5708), "lla", "latitude"),
            (nudged(&|s| s.lla.z = -1.1e4), "lla", "height"),
            (nudged(&|s| s.lla.z = 2e7), "lla", "height"),
            (nudged(&|s| s.vel.y = f64::NAN), "vel_ned", "non-finite"),
            (nudged(&|s| s.t = f64::INFINITY), "t0", "finite"),
        ] {
            for e in [Strapdown::new(bad, ImuKind::Increments, WGS84, Vertical::Free).unwrap_err(), sd.reset(bad).unwrap_err()] {
                assert!(matches!(&e, crate::error::NavError::InvalidInput { field: f, .. } if f == field), "{e}");
                assert!(e.to_string().contains(why), "{e}");
            }
            assert_eq!(sd.state, good);
        }
        // within the tolerance: accepted, normalised like a new object's
        let near = nudged(&|s| s.q_nb = crate::math::quat(1.0 + 5e-7, 0.0, 0.0, 0.0));
        sd.reset(near).unwrap();
        assert_eq!(sd.state.q_nb, Strapdown::new(near, ImuKind::Increments, WGS84, Vertical::Free).unwrap().state.q_nb);
        let damped = |zeta, omega| Strapdown::new(good, ImuKind::Increments, WGS84, Vertical::Damped { zeta, omega }).unwrap_err();
        assert!(matches!(damped(-1.0, 0.01), crate::error::NavError::InvalidInput { field, .. } if field == "zeta"));
        assert!(matches!(damped(0.7, 0.0), crate::error::NavError::InvalidInput { field, .. } if field == "omega"));
    }

    #[test]
    fn vertical_by_name() {
        assert_eq!(Vertical::parse("free"), Ok(Vertical::Free));
        assert_eq!(Vertical::parse("damped"), Ok(Vertical::Damped { zeta: 0.707, omega: 0.01 }));
        assert_eq!(Vertical::parse("damped").unwrap().tuned(Some(0.5), None), Vertical::Damped { zeta: 0.5, omega: 0.01 });
        assert_eq!(Vertical::Free.tuned(Some(0.5), Some(0.1)), Vertical::Free);
        assert_eq!(Vertical::Damped { zeta: 0.3, omega: 0.2 }.name(), "damped");
        assert!(Vertical::parse("baro").unwrap_err().to_string().starts_with("vertical: unknown option \"baro\""));
    }

    #[test]
    fn round_trip_short_is_exact_to_mm() {
        for kind in [ImuKind::Rates, ImuKind::Increments] {
            let (dp, da) = round_trip(kind, 60.0);
            assert!(dp < 1e-4 && da < 1e-9, "{kind:?}: {dp} m, {da} rad");
        }
    }
}
