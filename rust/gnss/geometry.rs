//! Receiver–satellite geometry: light-time iteration, Earth rotation during the signal
//! flight (Sagnac), range and its exact rate, elevation and azimuth.

use super::ephemeris::{Ephemerides, SatState};
use super::{SatId, C_LIGHT, OMEGA_E_GPS};
use crate::earth::dcm_ned_to_ecef;
use crate::error::Result;
use crate::math::{Mat3, Vec3};

/// Geometry of one satellite seen from one receiver state.
#[derive(Debug, Clone, Copy)]
pub struct Geometry {
    /// |R₃(Ωτ) r_s(t − τ) − r| (m), the Sagnac-corrected geometric range.
    pub range: f64,
    /// Its exact time derivative (m/s).
    pub rate: f64,
    /// κ = 1/(1 − uᵀ(ΩR₃′r_s − R₃v_s)/c): ∂range/∂r = −κu, and a shift δ of the satellite
    /// epoch changes the range by κ·uᵀv_s·δ (light-time feedback, |κ − 1| < 1e-5).
    pub kappa: f64,
    /// Unit line of sight receiver → satellite (ECEF).
    pub los: Vec3,
    /// Satellite at the transmit epoch, rotated into the ECEF frame of the receive epoch
    /// (position, velocity) and its clock (s, s/s).
    pub sat: SatState,
    pub elevation: f64,
    pub azimuth: f64,
}

/// R₃(θ) = [[cθ, sθ, 0], [−sθ, cθ, 0], [0, 0, 1]] and dR₃/dθ.
fn r3(theta: f64) -> (Mat3, Mat3) {
    let (s, c) = theta.sin_cos();
    (Mat3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0), Mat3::new(-s, c, 0.0, -c, -s, 0.0, 0.0, 0.0, 0.0))
}

/// Range geometry at GPS receive time t for a receiver at ECEF r (m) moving with v (m/s),
/// receiver geodetic latitude/longitude `lat`, `lon` (rad) for elevation and azimuth.
/// Light time iterated t_tx = t − ρ/c until |Δρ| < 1e-9 m (Eq. 13). The rate is the exact
/// derivative of the range model: ρ̇ = uᵀ(R₃v_s − v)/(1 − uᵀ(ΩR₃′r_s − R₃v_s)/c).
#[allow(clippy::too_many_arguments)]
/// Rows [elevation, azimuth] (rad) of `sat` seen from the geodetic position `lla` (WGS-84,
/// at rest) at each GPS time of `t`.
pub fn look_angles(eph: &Ephemerides, sat: SatId, t: &[f64], lla: &Vec3) -> Result<Vec<[f64; 2]>> {
    crate::earth::check_latitude("lla", lla.x, 0)?;
    crate::error::check_finite("t", t, 1)?;
    let (r, _) = super::observation::receiver_ecef(lla, &Vec3::zeros());
    t.iter()
        .map(|&tk| {
            let g = geometry(eph, sat, tk, &r, &Vec3::zeros(), lla.x, lla.y, 0.0)?;
            Ok([g.elevation, g.azimuth])
        })
        .collect()
}

pub fn geometry(eph: &Ephemerides, sat: SatId, t: f64, r: &Vec3, v: &Vec3, lat: f64, lon: f64, tau_gps: f64) -> Result<Geometry> {
    let mut rho = 0.0;
    let mut st = eph.state(sat, t, tau_gps)?;
    let mut rs = st.pos;
    for _ in 0..10 {
        let tau = rho / C_LIGHT;
        st = eph.state(sat, t - tau, tau_gps)?;
        rs = r3(OMEGA_E_GPS * tau).0 * st.pos;
        let new = (rs - r).norm();
        let done = (new - rho).abs() < 1e-9;
        rho = new;
        if done {
            break;
        }
    }
    let (rot, drot) = r3(OMEGA_E_GPS * rho / C_LIGHT);
    let u = (rs - r) / rho;
    let vs = rot * st.vel;
    let a = u.dot(&(vs - v));
    let b = u.dot(&(drot * st.pos * OMEGA_E_GPS - vs));
    let kappa = 1.0 / (1.0 - b / C_LIGHT);
    let un = dcm_ned_to_ecef(lat, lon).transpose() * u;
    Ok(Geometry {
        range: rho,
        rate: a * kappa,
        kappa,
        los: u,
        sat: SatState { pos: rs, vel: vs, clock: st.clock, clock_rate: st.clock_rate },
        elevation: (-un.z).asin(),
        azimuth: un.y.atan2(un.x),
    })
}
