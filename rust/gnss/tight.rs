//! Tightly coupled GNSS aiding of the generic aided-INS engine (Demidov 2009 Ch. 3).
//! Default: between-satellite first differences of code and pseudorange rate
//! against the highest GPS satellite (no receiver-clock states; the correlated FD noise
//! R = σ₀²11ᵀ + diag(σᵢ²) is decorrelated by the engine in sequential mode) with c·τ_GPS
//! as an extra state. Option: undifferenced rows with the receiver clock states (c·δt_r,
//! c·δṫ_r). Lever arm l^b from the IMU to the antenna.
//!
//! Signs: z = predicted − measured; δx = estimate − true. The H rows have no IMU-bias
//! columns, so a raw-bias sign convention (opposite to the engine's
//! δb = b̂ − b, see filter/ins.rs) never enters here.

use super::ephemeris::Ephemerides;
use super::geometry::geometry;
use super::observation::{Atmosphere, Observation};
use super::{SatId, System, C_LIGHT};
use crate::earth::dcm_ned_to_ecef;
use crate::error::{invalid, Result};
use crate::filter::aided::{Aiding, AidingContext, Measurement};
use crate::filter::layout::Layout;
use crate::imu::ImuKind;
use crate::math::{dcm_from_quat, skew, Mat3, Vec3};
use crate::strapdown::NavState;
use nalgebra::{DMatrix, RowDVector};

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Formulation {
    /// Between-satellite first differences (no clock states).
    FirstDifference,
    /// Undifferenced rows with the receiver clock bias and drift states (m, m/s).
    ClockStates,
}

impl crate::options::Choice for Formulation {
    const PARAMETER: &'static str = "formulation";
    const CHOICES: &'static [(&'static str, Self)] = &[("first_difference", Formulation::FirstDifference), ("clock_states", Formulation::ClockStates)];
}

#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct TightConfig {
    #[serde(with = "crate::options::by_name")]
    pub formulation: Formulation,
    /// IMU → antenna lever arm in the body frame (m).
    pub lever_arm: Vec3,
    pub sigma_code_gps: f64,
    pub sigma_code_glo: f64,
    pub sigma_rate: f64,
    pub use_rate: bool,
    pub atm: Atmosphere,
    /// Satellites below this elevation (rad) are not used.
    #[serde(default)]
    pub elevation_mask: f64,
    /// c·τ_GPS random-walk PSD (m²/s); default (0.1 ns)²/h.
    pub tau_psd: f64,
    /// Receiver oscillator h₀ (s) and h₋₂ (1/s) of Eq. 41 (TCXO 2e-19, 2e-20).
    pub clock_h0: f64,
    pub clock_hm2: f64,
    /// IMU record kind: the gyro sample gives the body rate for the lever-arm velocity.
    #[serde(with = "crate::options::by_name")]
    pub kind: ImuKind,
}

#[derive(serde::Serialize, serde::Deserialize)]
pub struct TightAiding {
    eph: Ephemerides,
    times: Vec<f64>,
    epochs: Vec<Vec<Observation>>,
    cfg: TightConfig,
    reference: Option<SatId>,
    /// Last compensated body rate (rad/s).
    omega_b: Vec3,
}

/// One satellite's undifferenced innovation and rows for code and rate.
struct Row {
    sat: SatId,
    elevation: f64,
    z_code: f64,
    h_code: RowDVector<f64>,
    s_code: f64,
    z_rate: f64,
    h_rate: RowDVector<f64>,
}

impl TightAiding {
    /// `epochs`: (GPS time, observations) with strictly increasing time. A barometric
    /// altimeter damps the INS's vertical channel in the engine
    /// (`AidedIns::with_damped_vertical`, docs/departures.md#baro-damped-vertical-channel), not through rows here.
    pub fn new(eph: Ephemerides, epochs: Vec<(f64, Vec<Observation>)>, cfg: TightConfig) -> Result<TightAiding> {
        for (field, s) in [("sigma_code_gps", cfg.sigma_code_gps), ("sigma_code_glo", cfg.sigma_code_glo), ("sigma_rate", cfg.sigma_rate)] {
            crate::error::check_positive(field, s)?;
        }
        for (i, (_, obs)) in epochs.iter().enumerate() {
            for o in obs {
                // a GLONASS slot the ephemerides lack is left out at its epochs
                if let (System::Glonass, Ok(k)) = (o.sat.system, eph.channel(o.sat)) {
                    if k != o.channel {
                        return Err(invalid("obs", format!("epoch {i}: {} on channel {} but the ephemeris says {k}", o.sat.name(), o.channel)));
                    }
                }
            }
        }
        let (times, epochs) = epochs.into_iter().unzip();
        Ok(TightAiding { eph, times, epochs, cfg, reference: None, omega_b: Vec3::zeros() })
    }

    /// The FD reference satellite at the last measurement (None before the first).
    pub fn reference(&self) -> Option<SatId> {
        self.reference
    }

    // invariant: ip, iv, ipsi and the extra-block starts are ranges of ctx.layout, whose
    // size n is the length of h_code and h_rate (clock: 2 states, so i + 1 < n); k < 3.
    #[allow(clippy::indexing_slicing)]
    fn rows(&mut self, j: usize, ctx: &AidingContext) -> Result<Vec<Row>> {
        let (Some(&t), Some(epoch)) = (self.times.get(j), self.epochs.get(j)) else {
            return Err(invalid("gnss", format!("no epoch {j} (of {})", self.times.len())));
        };
        let nav = ctx.nav;
        let n = ctx.layout.size();
        let cne = dcm_ned_to_ecef(nav.lla.x, nav.lla.y);
        let cnb = dcm_from_quat(&nav.q_nb);
        let lever_n = cnb * self.cfg.lever_arm;
        // antenna: r̂_a = r̂ + Ĉl^b, v̂_a = v̂ + Ĉ(ω × l^b) (Eq. 37)
        let r_a = ctx.ell.lla_to_ecef(&nav.lla) + cne * lever_n;
        let v_a = cne * (nav.vel + cnb * self.omega_b.cross(&self.cfg.lever_arm));
        let lla_a = ctx.ell.ecef_to_lla(&r_a);
        let (ip, iv, ipsi) = (ctx.layout.range("position")?.start, ctx.layout.range("velocity")?.start, ctx.layout.range("attitude")?.start);
        // (state index, nominal value, nominal value of the next component) of an extra block
        let extra = |name: &str| {
            let (r, e) = (ctx.layout.get(name)?, ctx.layout.extra_index(name)?);
            Some((r.start, *ctx.extra.get(e)?, ctx.extra.get(e + 1).copied().unwrap_or(0.0)))
        };
        let tau = extra("c_tau_gps");
        let clock = extra("clock");
        let lever_skew = skew(&lever_n);
        // v̂^e = C_n^e(r̂)v̂ⁿ: a position error δr turns the computed frame by δθ = A_ev·δr
        // (C(r̂) = C(r)(I + [δθ×])), so δv^e = C(δv − [vⁿ×]A_ev δr); the Doppler rows carry
        // this term besides g_i (|v||δr|/R: 0.016 m/s at 100 m/s and 1 km, open loop).
        let loc = ctx.ell.local(nav.lla.x, nav.lla.z);
        let a_ev = Mat3::new(0.0, 1.0 / loc.rp, 0.0, -1.0 / loc.rm, 0.0, 0.0, 0.0, -loc.sin / (loc.cos * loc.rp), 0.0);
        let frame_term = skew(&(cne.transpose() * v_a)) * a_ev;
        // the signal arrives at the stamp less the receiver clock, when the clock is a state
        let tau_s = tau.map_or(0.0, |x| x.1 / C_LIGHT);
        let t_rx = t - clock.map_or(0.0, |c| c.1 / C_LIGHT);
        let mut rows = Vec::new();
        // a satellite without a set valid then is left out, as in single-point positioning;
        // an epoch where no satellite has one is outside the ephemerides: that error
        let (mut covered, mut uncovered) = (0, None);
        for o in epoch.iter().filter(|o| o.code.is_finite()) {
            let glo = o.sat.system == System::Glonass;
            let g = match geometry(&self.eph, o.sat, t_rx, &r_a, &v_a, lla_a.x, lla_a.y, tau_s) {
                Ok(g) => g,
                Err(e) => {
                    uncovered.get_or_insert(e);
                    continue;
                }
            };
            covered += 1;
            if g.elevation <= 0.0 || g.elevation < self.cfg.elevation_mask {
                continue;
            }
            let u_n = cne.transpose() * g.los * g.kappa;
            let mut pred = g.range;
            let mut h_code = RowDVector::zeros(n);
            let mut h_rate = RowDVector::zeros(n);
            for k in 0..3 {
                h_code[ip + k] = -u_n[k];
            }
            let hp = -u_n.transpose() * lever_skew;
            for k in 0..3 {
                h_code[ipsi + k] = hp[k];
            }
            // g_iᵀ = −(v_s − v̂)ᵀ(I − uuᵀ)C_n^e/ρ̂ (required in open loop)
            let dv = g.sat.vel - v_a;
            let gi = -(dv - g.los * g.los.dot(&dv)).transpose() * cne / g.range;
            let gf = gi + u_n.transpose() * frame_term;
            // the lever arm moves the antenna by [(Ĉl)×]ψ, which turns the line of sight
            let gpsi = gi * lever_skew;
            for k in 0..3 {
                h_rate[ip + k] = gf[k];
                h_rate[iv + k] = -u_n[k];
                h_rate[ipsi + k] = gpsi[k];
            }
            let mut pred_rate = g.rate;
            if let Some((i, ct, _)) = tau {
                if glo {
                    pred += ct;
                    h_code[i] = 1.0 - g.kappa * g.los.dot(&g.sat.vel) / C_LIGHT;
                }
            }
            if let Some((i, cb, drift)) = clock {
                pred += cb;
                pred_rate += drift;
                h_code[i] = 1.0;
                h_rate[i + 1] = 1.0;
            }
            let measured = o.code + C_LIGHT * g.sat.clock - self.cfg.atm.delay(o.sat, o.channel, &lla_a, &g, t_rx);
            let measured_rate = o.rate + C_LIGHT * g.sat.clock_rate;
            rows.push(Row {
                sat: o.sat,
                elevation: g.elevation,
                z_code: pred - measured,
                h_code,
                s_code: if glo { self.cfg.sigma_code_glo } else { self.cfg.sigma_code_gps },
                z_rate: if self.cfg.use_rate && o.rate.is_finite() { pred_rate - measured_rate } else { f64::NAN },
                h_rate,
            });
        }
        match uncovered {
            Some(e) if covered == 0 => Err(e),
            _ => Ok(rows),
        }
    }

    /// Keep the reference while it is seen; otherwise the highest GPS satellite (the
    /// highest GLONASS one when no GPS satellite is seen). Returns its index in `rows`.
    fn pick_reference(&mut self, rows: &[Row]) -> Option<usize> {
        if let Some(i) = self.reference.and_then(|r| rows.iter().position(|x| x.sat == r)) {
            return Some(i);
        }
        let best = |sys: System| {
            rows.iter().enumerate().filter(|(_, r)| r.sat.system == sys).max_by(|a, b| a.1.elevation.total_cmp(&b.1.elevation)).map(|(i, _)| i)
        };
        let i = best(System::Gps).or_else(|| best(System::Glonass))?;
        self.reference = rows.get(i).map(|r| r.sat);
        Some(i)
    }
}

/// Stack (z, H, R) of a set of rows; FD against row `r0` when given, with
/// R = σ₀²11ᵀ + diag(σᵢ²) (Eq. 39).
// invariant: h and s have one entry per z (built from the same rows), i, k < z.len(),
// and a, b < m = rows and columns of hm and r.
#[allow(clippy::indexing_slicing)]
fn stack(z: &[f64], h: &[&RowDVector<f64>], s: &[f64], r0: Option<usize>, n: usize) -> (Vec<f64>, DMatrix<f64>, DMatrix<f64>) {
    let idx: Vec<usize> = (0..z.len()).filter(|&i| Some(i) != r0).collect();
    let m = idx.len();
    let mut hm = DMatrix::zeros(m, n);
    let mut r = DMatrix::zeros(m, m);
    let mut zz = Vec::with_capacity(m);
    for (a, &i) in idx.iter().enumerate() {
        match r0 {
            Some(k) => {
                zz.push(z[i] - z[k]);
                hm.set_row(a, &(h[i] - h[k]));
                for b in 0..m {
                    r[(a, b)] = s[k] * s[k];
                }
            }
            None => {
                zz.push(z[i]);
                hm.set_row(a, h[i]);
            }
        }
        r[(a, a)] += s[i] * s[i];
    }
    (zz, hm, r)
}

#[typetag::serde]
impl Aiding for TightAiding {
    fn name(&self) -> &str {
        "gnss"
    }

    fn extra_blocks(&self) -> Vec<(String, usize)> {
        let mut b = vec![("c_tau_gps".to_string(), 1)];
        if self.cfg.formulation == Formulation::ClockStates {
            b.push(("clock".to_string(), 2));
        }
        b
    }

    fn times(&self) -> &[f64] {
        &self.times
    }

    fn observe(&mut self, _t: f64, dt: f64, gyro: &Vec3, _accel: &Vec3, _nav: &NavState) {
        self.omega_b = match self.cfg.kind {
            ImuKind::Rates => *gyro,
            ImuKind::Increments if dt > 0.0 => gyro / dt,
            ImuKind::Increments => self.omega_b,
        };
    }

    fn measure(&mut self, j: usize, ctx: &AidingContext) -> Result<Option<Measurement>> {
        let rows = self.rows(j, ctx)?;
        let fd = self.cfg.formulation == Formulation::FirstDifference;
        let n = ctx.layout.size();
        if rows.is_empty() || (fd && rows.len() < 2) {
            return Ok(None);
        }
        let r0 = match fd {
            true => match self.pick_reference(&rows) {
                Some(i) => Some(i),
                None => return Ok(None),
            },
            false => None,
        };
        let zc: Vec<f64> = rows.iter().map(|r| r.z_code).collect();
        let hc: Vec<&RowDVector<f64>> = rows.iter().map(|r| &r.h_code).collect();
        let sc: Vec<f64> = rows.iter().map(|r| r.s_code).collect();
        let (mut z, mut h, mut r) = stack(&zc, &hc, &sc, r0, n);
        // rate rows: only satellites with a rate, differenced against the same reference
        let with_rate: Vec<(usize, &Row)> = rows.iter().enumerate().filter(|(_, r)| r.z_rate.is_finite()).collect();
        let rate_ref = r0.and_then(|k| with_rate.iter().position(|&(i, _)| i == k));
        if with_rate.len() > usize::from(fd) && (!fd || rate_ref.is_some()) {
            let zr: Vec<f64> = with_rate.iter().map(|(_, r)| r.z_rate).collect();
            let hr: Vec<&RowDVector<f64>> = with_rate.iter().map(|(_, r)| &r.h_rate).collect();
            let sr = vec![self.cfg.sigma_rate; with_rate.len()];
            let (z2, h2, r2) = stack(&zr, &hr, &sr, rate_ref, n);
            let (m1, m2) = (z.len(), z2.len());
            z.extend(z2);
            h = h.resize_vertically(m1 + m2, 0.0);
            h.rows_mut(m1, m2).copy_from(&h2);
            r = r.resize(m1 + m2, m1 + m2, 0.0);
            r.view_mut((m1, m1), (m2, m2)).copy_from(&r2);
        }
        Ok(Some(Measurement { z, h, r }))
    }

    // invariant: f and qc are n × n for this layout, whose c_tau_gps (1 state) and clock
    // (2 states) ranges lie inside n.
    #[allow(clippy::indexing_slicing)]
    fn extra_dynamics(&self, layout: &Layout, f: &mut DMatrix<f64>, qc: &mut DMatrix<f64>) {
        if let Some(r) = layout.get("c_tau_gps") {
            qc[(r.start, r.start)] = self.cfg.tau_psd;
        }
        if let Some(r) = layout.get("clock") {
            // ẋ_c = [[0, 1], [0, 0]]x_c + w, Q_c = c²·diag(h₀/2, 2π²h₋₂) (Eq. 41)
            let i = r.start;
            f[(i, i + 1)] = 1.0;
            qc[(i, i)] = C_LIGHT * C_LIGHT * self.cfg.clock_h0 / 2.0;
            qc[(i + 1, i + 1)] = C_LIGHT * C_LIGHT * 2.0 * std::f64::consts::PI.powi(2) * self.cfg.clock_hm2;
        }
    }

    fn propagate_extra(&self, layout: &Layout, dt: f64, extra: &mut [f64]) {
        // nominal clock bias follows the drift (the F block above): c·δt_r += c·δṫ_r·Δt
        if let Some(&mut [ref mut bias, drift, ..]) = layout.extra_index("clock").and_then(|i| extra.get_mut(i..)) {
            *bias += drift * dt;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::constellation::{nominal, ConstellationConfig};
    use super::super::observation::{simulate, SimConfig, Visibility};
    use super::super::TimeScales;
    use super::*;
    use crate::earth::WGS84;
    use crate::math::{quat_from_euler, quat_from_rotvec};
    use nalgebra::DVector;

    /// H rows (code and rate, clock-state form) = finite differences of the innovation
    /// with respect to position (NED m), velocity and ψ of the INS solution.
    #[test]
    fn h_rows_match_finite_differences_of_the_prediction() {
        let lla = Vec3::new(0.97, 0.66, 300.0);
        let vel = Vec3::new(80.0, -60.0, 2.0);
        let cfg = ConstellationConfig { gps: true, glonass: true, t_start: 0.0, t_end: 600.0, tau_gps: 0.0, time: TimeScales::default(), clocks: true, seed: 4 };
        let eph = nominal(&cfg).unwrap();
        let atm = Atmosphere { iono: None, tropo: false };
        let sim = SimConfig { sigma_code_gps: 0.0, sigma_code_glo: 0.0, sigma_rate: 0.0, tau_gps: 0.0, clock_bias: 0.0, clock_drift: 0.0, atm, seed: 1 };
        let obs: Vec<Observation> = simulate(&eph, &[100.0], &[lla], &[vel], &sim, &Visibility::default()).unwrap().remove(0).into_iter().map(|x| x.0).collect();
        let tc = TightConfig {
            formulation: Formulation::ClockStates, lever_arm: Vec3::new(1.0, -0.5, -2.0), sigma_code_gps: 3.0, sigma_code_glo: 3.0, sigma_rate: 0.05,
            use_rate: true, atm, elevation_mask: 0.0, tau_psd: 0.0, clock_h0: 0.0, clock_hm2: 0.0, kind: ImuKind::Rates,
        };
        let mut aiding = TightAiding::new(eph, vec![(100.0, obs)], tc).unwrap();
        let layout = Layout::ins_with(&aiding.extra_blocks()).unwrap();
        let (x, extra) = (DVector::zeros(layout.size()), DVector::zeros(3));
        let q = quat_from_euler(0.1, -0.05, 1.2);
        let z_of = |a: &mut TightAiding, nav: &NavState| {
            let ctx = AidingContext { t: 100.0, nav, accel_bias: Vec3::zeros(), gyro_bias: Vec3::zeros(), gyro_rate: Vec3::zeros(), x: &x, extra: &extra, layout: &layout, ell: &WGS84 };
            a.measure(0, &ctx).unwrap().unwrap()
        };
        let nav0 = NavState { t: 100.0, lla, vel, q_nb: q };
        let m0 = z_of(&mut aiding, &nav0);
        let loc = WGS84.local(lla.x, lla.z);
        for k in 0..9 {
            let d = [10.0, 10.0, 10.0, 0.1, 0.1, 0.1, 1e-3, 1e-3, 1e-3][k];
            let shifted = |s: f64| {
                let mut e = Vec3::zeros();
                e[k % 3] = s * d;
                match k / 3 {
                    0 => NavState { lla: lla + Vec3::new(e.x / loc.rm, e.y / (loc.rp * loc.cos), -e.z), ..nav0 },
                    1 => NavState { vel: vel + e, ..nav0 },
                    // Ĉ = (I − [ψ×])C ⇒ q̂ = q(−ψ) ⊗ q
                    _ => NavState { q_nb: quat_from_rotvec(&(-e)) * q, ..nav0 },
                }
            };
            let (zp, zm) = (z_of(&mut aiding, &shifted(1.0)).z, z_of(&mut aiding, &shifted(-1.0)).z);
            for (i, (p, m)) in zp.iter().zip(&zm).enumerate() {
                let fd = (p - m) / (2.0 * d);
                // code rows: z is a difference of ~2e7 m numbers (ulp 3.7e-9 m) over a 2d step
                let tol = if i < m0.z.len() / 2 { 1e-5 } else { 1e-7 };
                assert!((fd - m0.h[(i, k)]).abs() < tol, "row {i} state {k}: fd {fd} vs H {}", m0.h[(i, k)]);
            }
        }
    }
}
