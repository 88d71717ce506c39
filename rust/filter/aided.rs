//! Position-aided strapdown INS with the 15-state error-state filter (batch over a whole
//! IMU record): the strapdown of `strapdown.rs` runs on bias-compensated IMU output, the
//! filter predicts every `predict_every` IMU steps with F from the current solution
//! (spec gnss-ins-tight Eq. 28, `ins::error_dynamics`), position fixes update it, and in
//! closed loop the estimate is fed back (X ← X ⊖ δx̂, b̂ ← b̂ − δb̂, δx̂ ← 0); in open loop
//! the INS runs free and the output is X ⊖ δx̂ (spec gnss-ins-tight §2.11).

use super::discretize::{discretize, Discretization};
use super::ins::{error_dynamics, InsNoise};
use super::kf::{Kf, LoopMode};
use super::layout::Layout;
use crate::earth::Ellipsoid;
use crate::error::{invalid, Result};
use crate::imu::ImuKind;
use crate::math::{quat_from_rotvec, quat_normalize, Mat3, Vec3};
use crate::strapdown::{NavState, Strapdown, Vertical};
use nalgebra::{DMatrix, DVector};

/// A position fix: time (s), (lat rad, lon rad, h m) and its NED covariance (m²).
#[derive(Debug, Clone, Copy)]
pub struct PositionFix {
    pub t: f64,
    pub lla: Vec3,
    pub cov_ned: Mat3,
}

#[derive(Debug, Clone, Copy)]
pub struct AidedConfig {
    pub noise: InsNoise,
    pub predict_every: usize,
    pub method: Discretization,
    pub mode: LoopMode,
    pub sequential: bool,
    pub gate: Option<f64>,
}

/// Output at every prediction epoch, and per fix the innovation statistics.
#[derive(Debug, Clone, Default)]
pub struct AidedOutput {
    pub nav: Vec<NavState>,
    pub accel_bias: Vec<Vec3>,
    pub gyro_bias: Vec<Vec3>,
    /// σ of the 15 states, row-major (epochs × 15).
    pub sigma: Vec<f64>,
    pub fix_nis: Vec<f64>,
    pub fix_rejected: Vec<bool>,
}

/// NED position difference (m) of `a` relative to `b` (small-difference form).
fn ned_diff(ell: &Ellipsoid, a: &Vec3, b: &Vec3) -> Vec3 {
    let loc = ell.local(b.x, b.z);
    Vec3::new((a.x - b.x) * loc.rm, (a.y - b.y) * loc.rp * loc.cos, -(a.z - b.z))
}

/// X ⊖ δx for the navigation blocks: position (NED m), velocity, ψ (Ĉ = (I − [ψ×])C ⇒
/// C = (I + [ψ×])Ĉ ≈ exp([ψ×])Ĉ).
fn remove_error(ell: &Ellipsoid, s: &NavState, dx: &DVector<f64>) -> NavState {
    let loc = ell.local(s.lla.x, s.lla.z);
    let lla = s.lla - Vec3::new(dx[0] / loc.rm, dx[1] / (loc.rp * loc.cos), -dx[2]);
    let vel = s.vel - Vec3::new(dx[3], dx[4], dx[5]);
    let q_nb = quat_normalize(&(quat_from_rotvec(&Vec3::new(dx[6], dx[7], dx[8])) * s.q_nb));
    NavState { t: s.t, lla, vel, q_nb }
}

/// Run the aided INS over the record. `t`, `gyro`, `accel` as for `Strapdown::run`
/// (free vertical channel); `p0` 15 × 15; biases start at `ba0`, `bg0`.
#[allow(clippy::too_many_arguments)]
pub fn run_position_aided(
    initial: NavState,
    kind: ImuKind,
    ell: Ellipsoid,
    t: &[f64],
    gyro: &[Vec3],
    accel: &[Vec3],
    ba0: Vec3,
    bg0: Vec3,
    p0: DMatrix<f64>,
    fixes: &[PositionFix],
    cfg: &AidedConfig,
) -> Result<AidedOutput> {
    let n = t.len();
    if n < 2 || gyro.len() != n || accel.len() != n {
        return Err(invalid("imu", format!("need >= 2 samples with equal lengths, got time {n}, gyro {}, accel {}", gyro.len(), accel.len())));
    }
    crate::error::check_increasing("time", t)?;
    if cfg.predict_every == 0 {
        return Err(invalid("predict_every", "must be >= 1"));
    }
    for (i, f) in fixes.iter().enumerate() {
        if !(f.t >= t[0] && f.t <= t[n - 1]) {
            return Err(invalid("fixes", format!("time {} s at index {i} is outside the IMU span [{}, {}] s", f.t, t[0], t[n - 1])));
        }
        if i > 0 && f.t <= fixes[i - 1].t {
            return Err(invalid("fixes", format!("time not strictly increasing at index {i}")));
        }
        if !f.lla.iter().all(|x| x.is_finite()) {
            return Err(invalid("fixes", format!("non-finite position at index {i}")));
        }
        super::matrix::check_covariance(&format!("fixes[{i}] covariance"), &DMatrix::from_fn(3, 3, |a, b| f.cov_ned[(a, b)]), Some(3), true)?;
    }
    let layout = Layout::ins15();
    let mut kf = Kf::new(p0, cfg.mode)?;
    if kf.size() != 15 {
        return Err(invalid("p0", format!("expected 15x15, got {0}x{0}", kf.size())));
    }
    let mut sd = Strapdown::new(initial, kind, ell, Vertical::Free)?;
    let (mut ba, mut bg) = (ba0, bg0);
    let mut h = DMatrix::<f64>::zeros(3, 15);
    h.view_mut((0, 0), (3, 3)).fill_with_identity();
    let mut out = AidedOutput::default();
    let mut next_fix = 0;
    let mut t_last_predict = initial.t;
    let mut steps_since = 0;
    let record = |out: &mut AidedOutput, sd: &Strapdown, kf: &Kf, ba: &Vec3, bg: &Vec3| {
        let (nav, dba, dbg) = match cfg.mode {
            LoopMode::Closed => (sd.state, Vec3::zeros(), Vec3::zeros()),
            LoopMode::Open => (remove_error(&ell, &sd.state, &kf.x), Vec3::new(kf.x[9], kf.x[10], kf.x[11]), Vec3::new(kf.x[12], kf.x[13], kf.x[14])),
        };
        out.nav.push(nav);
        out.accel_bias.push(ba - dba);
        out.gyro_bias.push(bg - dbg);
        out.sigma.extend((0..15).map(|i| kf.p[(i, i)].sqrt()));
    };
    for k in 0..n {
        let dt = if k > 0 { t[k] - t[k - 1] } else { t[0] - initial.t };
        let (g, a) = match kind {
            ImuKind::Rates => (gyro[k] - bg, accel[k] - ba),
            ImuKind::Increments => (gyro[k] - bg * dt, accel[k] - ba * dt),
        };
        sd.step(t[k], &g, &a, None);
        let s = sd.state;
        if !s.lla.iter().chain(s.vel.iter()).all(|x| x.is_finite()) {
            return Err(crate::error::NavError::Numerical(format!("navigation solution diverged at sample {k} (t = {} s)", t[k])));
        }
        steps_since += 1;
        let fix_due = next_fix < fixes.len() && fixes[next_fix].t <= t[k];
        if (steps_since >= cfg.predict_every || fix_due || k == n - 1) && t[k] > t_last_predict {
            let f_b = match kind {
                ImuKind::Rates => a,
                ImuKind::Increments => a / dt,
            };
            let (f, qc) = error_dynamics(&layout, &ell, &sd.state, &f_b, &cfg.noise)?;
            let (phi, qd) = discretize(&f, &qc, t[k] - t_last_predict, cfg.method);
            kf.predict_unchecked(&phi, &qd)?;
            t_last_predict = t[k];
            steps_since = 0;
            // Fixes are applied at the first IMU epoch at or after their time.
            while next_fix < fixes.len() && fixes[next_fix].t <= t[k] {
                let fx = &fixes[next_fix];
                let z = ned_diff(&ell, &sd.state.lla, &fx.lla);
                let r = DMatrix::from_fn(3, 3, |i, j| fx.cov_ned[(i, j)]);
                let rep = kf.update(z.as_slice(), &h, &r, cfg.sequential, cfg.gate)?;
                out.fix_nis.push(rep.nis.iter().sum());
                out.fix_rejected.push(!rep.rejected.is_empty());
                next_fix += 1;
            }
            if cfg.mode == LoopMode::Closed {
                let dx = kf.take_correction();
                sd.state = remove_error(&ell, &sd.state, &dx);
                ba -= Vec3::new(dx[9], dx[10], dx[11]);
                bg -= Vec3::new(dx[12], dx[13], dx[14]);
            }
            record(&mut out, &sd, &kf, &ba, &bg);
        }
    }
    Ok(out)
}
