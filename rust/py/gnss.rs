//! Bindings of gnss/: broadcast ephemerides, the constellation simulator, observation
//! simulation and single-point positioning, over numpy arrays.

use super::convert::{Wrap, rows, rows_to_py, vec3_rows, vector};
use crate::earth::Helmert;
use crate::error::invalid;
use crate::gnss::atmosphere::Klobuchar;
use crate::gnss::constellation::{nominal, ConstellationConfig};
use crate::gnss::ephemeris::Ephemerides;
use crate::gnss::geometry::geometry;
use crate::gnss::glonass_orbit::{propagate, GloEphemeris};
use crate::gnss::gps_orbit::GpsEphemeris;
use crate::gnss::observation::{group_epochs, receiver_ecef, simulate, Atmosphere, Observation, SimConfig, Visibility};
use crate::gnss::spp::{solve_position, solve_velocity, SppConfig};
use crate::gnss::tight::{Formulation, TightAiding, TightConfig};
use super::filter::PyAidedIns;
use crate::gnss::{check_channel, SatId, System, TimeScales};
use crate::math::Vec3;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Broadcast ephemerides of GPS (rows of 22: prn, toe, sqrt_a, e, m0, delta_n, omega0, i0,
/// omega, omega_dot, idot, cuc, cus, crc, crs, cic, cis, toc, af0, af1, af2, tgd) and
/// GLONASS (rows of 14: slot, channel, tb, x, y, z, vx, vy, vz, ax, ay, az, tau_n, gamma_n).
#[pyclass(module = "atomnav._core", name = "GnssEphemerides", frozen)]
pub struct PyEphemerides {
    pub(crate) inner: Ephemerides,
}

fn gps_row(r: &[f64; 22]) -> GpsEphemeris {
    GpsEphemeris {
        prn: r[0] as u8, toe: r[1], sqrt_a: r[2], e: r[3], m0: r[4], delta_n: r[5], omega0: r[6], i0: r[7], omega: r[8],
        omega_dot: r[9], idot: r[10], cuc: r[11], cus: r[12], crc: r[13], crs: r[14], cic: r[15], cis: r[16], toc: r[17],
        af0: r[18], af1: r[19], af2: r[20], tgd: r[21],
    }
}

/// Satellite names "G05"/"R12" → ids.
pub(crate) fn parse_sats(names: &[String], field: &str) -> PyResult<Vec<SatId>> {
    names
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let c = s.chars().next().unwrap_or('?');
            let n: i64 = s.get(1..).and_then(|x| x.trim().parse().ok()).ok_or_else(|| invalid(field, format!("malformed satellite '{s}' at index {i}")))?;
            Ok(SatId::parse(c, n, field, i)?)
        })
        .collect()
}

/// Flat observation table → observations (channel checked, rate NaN allowed).
pub(crate) fn parse_obs(sats: &[String], channel: &PyReadonlyArray1<'_, i64>, code: &PyReadonlyArray1<'_, f64>, rate: &PyReadonlyArray1<'_, f64>) -> PyResult<Vec<Observation>> {
    let ids = parse_sats(sats, "sat")?;
    let (ch, code, rate) = (channel.as_array(), code.as_array(), rate.as_array());
    if ch.len() != ids.len() || code.len() != ids.len() || rate.len() != ids.len() {
        return Err(invalid("sat", format!("{} satellites, {} channels, {} codes, {} rates", ids.len(), ch.len(), code.len(), rate.len())).into());
    }
    ids.iter()
        .enumerate()
        .map(|(i, &sat)| {
            let channel = if sat.system == System::Glonass { check_channel("channel", ch[i], i)? } else { 0 };
            Ok(Observation { sat, channel, code: code[i], rate: rate[i] })
        })
        .collect()
}

#[pymethods]
impl PyEphemerides {
    #[new]
    #[pyo3(signature = (gps, glonass, n_leap=18.0, datum=Wrap(Helmert::IDENTITY)))]
    fn new(gps: PyReadonlyArray2<'_, f64>, glonass: PyReadonlyArray2<'_, f64>, n_leap: f64, datum: Wrap<Helmert>) -> PyResult<Self> {
        let g = rows::<22>(&gps, "gps")?.iter().map(gps_row).collect();
        let mut r = Vec::new();
        for (i, x) in rows::<14>(&glonass, "glonass")?.iter().enumerate() {
            r.push(GloEphemeris {
                slot: x[0] as u8,
                channel: check_channel("glonass", x[1] as i64, i)?,
                tb: x[2],
                pos: Vec3::new(x[3], x[4], x[5]),
                vel: Vec3::new(x[6], x[7], x[8]),
                acc: Vec3::new(x[9], x[10], x[11]),
                tau_n: x[12],
                gamma_n: x[13],
            });
        }
        Ok(PyEphemerides { inner: Ephemerides::new(g, r, TimeScales { n_leap }, datum.0)? })
    }

    /// The nominal constellations over GPS times [t_start, t_end] (spec §2.5).
    #[staticmethod]
    #[pyo3(signature = (t_start, t_end, gps=true, glonass=true, tau_gps=0.0, n_leap=18.0, clocks=true, seed=0))]
    #[allow(clippy::too_many_arguments)]
    fn nominal(t_start: f64, t_end: f64, gps: bool, glonass: bool, tau_gps: f64, n_leap: f64, clocks: bool, seed: u64) -> PyResult<Self> {
        let cfg = ConstellationConfig { gps, glonass, t_start, t_end, tau_gps, time: TimeScales { n_leap }, clocks, seed };
        Ok(PyEphemerides { inner: nominal(&cfg)? })
    }

    /// The GPS sets as (N, 22) rows in the constructor's column order.
    fn gps_table<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let r: Vec<[f64; 22]> = self
            .inner
            .gps_sets()
            .map(|e| [e.prn as f64, e.toe, e.sqrt_a, e.e, e.m0, e.delta_n, e.omega0, e.i0, e.omega, e.omega_dot, e.idot, e.cuc, e.cus, e.crc, e.crs, e.cic, e.cis, e.toc, e.af0, e.af1, e.af2, e.tgd])
            .collect();
        super::convert::to_py_rows(py, &r)
    }

    /// The GLONASS sets as (M, 14) rows in the constructor's column order.
    fn glonass_table<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let r: Vec<[f64; 14]> = self
            .inner
            .glonass_sets()
            .map(|e| [e.slot as f64, e.channel as f64, e.tb, e.pos.x, e.pos.y, e.pos.z, e.vel.x, e.vel.y, e.vel.z, e.acc.x, e.acc.y, e.acc.z, e.tau_n, e.gamma_n])
            .collect();
        super::convert::to_py_rows(py, &r)
    }

    fn satellites(&self) -> Vec<String> {
        self.inner.satellites().iter().map(|s| s.name()).collect()
    }

    fn channel(&self, sat: String) -> PyResult<i64> {
        Ok(self.inner.channel(parse_sats(&[sat], "sat")?[0])? as i64)
    }

    /// (N, 8) rows [x, y, z, vx, vy, vz (WGS-84 ECEF), clock s, clock rate] of `sat` at GPS
    /// times `t` (GLONASS evaluated at t − ΔT_leap − tau_gps).
    #[pyo3(signature = (sat, t, tau_gps=0.0))]
    fn state<'py>(&self, py: Python<'py>, sat: String, t: PyReadonlyArray1<'py, f64>, tau_gps: f64) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let id = parse_sats(&[sat], "sat")?[0];
        let t = vector(&t, "t")?;
        let mut out = Vec::with_capacity(8 * t.len());
        for &tk in &t {
            let s = self.inner.state(id, tk, tau_gps)?;
            out.extend([s.pos.x, s.pos.y, s.pos.z, s.vel.x, s.vel.y, s.vel.z, s.clock, s.clock_rate]);
        }
        Ok(rows_to_py(py, t.len(), 8, out.into_iter()))
    }

    /// (N, 2) rows [elevation, azimuth] (rad) of `sat` seen from `lla` at GPS times `t`.
    fn look_angles<'py>(&self, py: Python<'py>, sat: String, t: PyReadonlyArray1<'py, f64>, lla: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let id = parse_sats(&[sat], "sat")?[0];
        let t = vector(&t, "t")?;
        let p = super::convert::vec3(&lla, "lla")?;
        let (r, _) = receiver_ecef(&p, &Vec3::zeros());
        let mut out = Vec::new();
        for &tk in &t {
            let g = geometry(&self.inner, id, tk, &r, &Vec3::zeros(), p.x, p.y, 0.0)?;
            out.extend([g.elevation, g.azimuth]);
        }
        Ok(rows_to_py(py, t.len(), 2, out.into_iter()))
    }
}

/// GLONASS RK4 propagation of (pos, vel) with constant acceleration `acc` over `dt` s
/// (Eq. 10), step ≤ `step` s, J₂ = `j2`; returns [x, y, z, vx, vy, vz].
#[pyfunction]
fn glonass_propagate<'py>(py: Python<'py>, pos: PyReadonlyArray1<'py, f64>, vel: PyReadonlyArray1<'py, f64>, acc: PyReadonlyArray1<'py, f64>, dt: f64, step: f64, j2: f64) -> PyResult<Bound<'py, PyArray1<f64>>> {
    crate::error::check_positive("step", step)?;
    let (p, v) = propagate(super::convert::vec3(&pos, "pos")?, super::convert::vec3(&vel, "vel")?, &super::convert::vec3(&acc, "acc")?, dt, step, j2);
    Ok(PyArray1::from_vec(py, vec![p.x, p.y, p.z, v.x, v.y, v.z]))
}

fn atmosphere(iono: bool, tropo: bool) -> Atmosphere {
    Atmosphere { iono: if iono { Some(Klobuchar::default()) } else { None }, tropo }
}

/// Simulated observation table: dict of sat (list of str), channel, time_s, code_m, rate_mps,
/// elevation_rad (truth).
#[pyfunction]
#[pyo3(signature = (eph, t, lla, vel_ned, sigma_code_gps, sigma_code_glo, sigma_rate, tau_gps, clock_bias, clock_drift, iono, tropo, mask, only, outages, sat_outages, seed))]
#[allow(clippy::too_many_arguments)]
fn gnss_simulate<'py>(
    py: Python<'py>, eph: &PyEphemerides, t: PyReadonlyArray1<'py, f64>, lla: PyReadonlyArray2<'py, f64>, vel_ned: PyReadonlyArray2<'py, f64>,
    sigma_code_gps: f64, sigma_code_glo: f64, sigma_rate: f64, tau_gps: f64, clock_bias: f64, clock_drift: f64, iono: bool, tropo: bool,
    mask: f64, only: Option<Vec<String>>, outages: PyReadonlyArray2<'py, f64>, sat_outages: Vec<(String, f64, f64)>, seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let t = vector(&t, "t")?;
    crate::error::check_increasing("t", &t)?;
    let (lla, vel) = (vec3_rows(&lla, "lla")?, vec3_rows(&vel_ned, "vel_ned")?);
    let names: Vec<String> = sat_outages.iter().map(|x| x.0.clone()).collect();
    let ids = parse_sats(&names, "sat_outages")?;
    let vis = Visibility {
        mask,
        only: only.map(|o| parse_sats(&o, "only")).transpose()?,
        outages: rows::<2>(&outages, "outages")?.iter().map(|r| (r[0], r[1])).collect(),
        sat_outages: ids.into_iter().zip(&sat_outages).map(|(s, x)| (s, x.1, x.2)).collect(),
    };
    let cfg = SimConfig { sigma_code_gps, sigma_code_glo, sigma_rate, tau_gps, clock_bias, clock_drift, atm: atmosphere(iono, tropo), seed };
    let e = &eph.inner;
    let epochs = py.detach(|| simulate(e, &t, &lla, &vel, &cfg, &vis))?;
    let (mut sat, mut ch, mut tt, mut code, mut rate, mut el) = (vec![], vec![], vec![], vec![], vec![], vec![]);
    for (k, ep) in epochs.iter().enumerate() {
        for (o, e) in ep {
            el.push(*e);
            sat.push(o.sat.name());
            ch.push(o.channel as i64);
            tt.push(t[k]);
            code.push(o.code);
            rate.push(o.rate);
        }
    }
    let d = PyDict::new(py);
    d.set_item("sat", sat)?;
    d.set_item("channel", PyArray1::from_vec(py, ch))?;
    d.set_item("time_s", PyArray1::from_vec(py, tt))?;
    d.set_item("code_m", PyArray1::from_vec(py, code))?;
    d.set_item("rate_mps", PyArray1::from_vec(py, rate))?;
    d.set_item("elevation_rad", PyArray1::from_vec(py, el))?;
    Ok(d)
}

/// Epoch-by-epoch single-point positioning; one row per epoch: [t, x, y, z, lat, lon, h,
/// clock_m, tau_s, sigma_tau_s, residual_metric_m, n_sats, n_unknowns, gdop, pdop, hdop,
/// vdop, tdop, vx, vy, vz, drift_mps] (τ columns NaN when not estimated, velocity NaN
/// without Doppler).
#[pyfunction]
#[pyo3(signature = (eph, time, sat, channel, code, rate, use_tau, iono, tropo, sigma_gps, sigma_glo, sigma_rate, elevation_weight))]
#[allow(clippy::too_many_arguments)]
fn gnss_spp<'py>(
    py: Python<'py>, eph: &PyEphemerides, time: PyReadonlyArray1<'py, f64>, sat: Vec<String>, channel: PyReadonlyArray1<'py, i64>,
    code: PyReadonlyArray1<'py, f64>, rate: PyReadonlyArray1<'py, f64>, use_tau: bool, iono: bool, tropo: bool, sigma_gps: f64,
    sigma_glo: f64, sigma_rate: f64, elevation_weight: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let obs = parse_obs(&sat, &channel, &code, &rate)?;
    let epochs = group_epochs(time.as_array().as_slice().ok_or_else(|| invalid("time", "must be contiguous"))?, &obs)?;
    let cfg = SppConfig { use_tau, atm: atmosphere(iono, tropo), sigma_gps, sigma_glo, elevation_weight };
    let e = &eph.inner;
    let out = py.detach(|| -> crate::Result<Vec<f64>> {
        let mut out = Vec::with_capacity(22 * epochs.len());
        let mut x0 = None;
        for (t, ob) in &epochs {
            let s = solve_position(e, *t, ob, &cfg, x0)?;
            x0 = Some(s.pos);
            let (v, d) = if ob.iter().filter(|o| o.rate.is_finite()).count() >= 4 {
                let (v, d, _) = solve_velocity(e, *t, ob, &s.pos, sigma_rate)?;
                (v, d)
            } else {
                (Vec3::repeat(f64::NAN), f64::NAN)
            };
            let (tau, st) = s.tau.map_or((f64::NAN, f64::NAN), |x| (x, s.cov[(4, 4)].sqrt()));
            out.extend([
                *t, s.pos.x, s.pos.y, s.pos.z, s.lla.x, s.lla.y, s.lla.z, s.clock_m, tau, st, s.residual_metric, ob.len() as f64,
                s.n_unknowns as f64, s.dop.gdop, s.dop.pdop, s.dop.hdop, s.dop.vdop, s.dop.tdop, v.x, v.y, v.z, d,
            ]);
        }
        Ok(out)
    })?;
    Ok(rows_to_py(py, out.len() / 22, 22, out.into_iter()))
}

/// Tightly coupled GNSS/INS on the aided-INS engine (see `gnss/tight.rs`). Observation
/// table as for `gnss_spp`; `extra0` initial (c·τ_GPS m[, c·δt_r m, c·δṫ_r m/s]); `p0` for
/// the whole layout (15 INS states, then the extra blocks).
#[pyfunction]
#[pyo3(signature = (eph, time, sat, channel, code, rate, formulation, lever_arm, sigma_code_gps, sigma_code_glo, sigma_rate, use_rate, iono, tropo, tau_psd, clock_h0, clock_hm2, ins, extra0))]
#[allow(clippy::too_many_arguments)]
fn gnss_tight_ins<'py>(
    eph: &PyEphemerides, time: PyReadonlyArray1<'py, f64>, sat: Vec<String>, channel: PyReadonlyArray1<'py, i64>,
    code: PyReadonlyArray1<'py, f64>, rate: PyReadonlyArray1<'py, f64>, formulation: &str, lever_arm: PyReadonlyArray1<'py, f64>,
    sigma_code_gps: f64, sigma_code_glo: f64, sigma_rate: f64, use_rate: bool, iono: bool, tropo: bool, tau_psd: f64, clock_h0: f64,
    clock_hm2: f64, ins: PyRef<'py, super::filter::AidedSetup>, extra0: PyReadonlyArray1<'py, f64>,
) -> PyResult<PyAidedIns> {
    let obs = parse_obs(&sat, &channel, &code, &rate)?;
    let epochs = group_epochs(time.as_array().as_slice().ok_or_else(|| invalid("time", "must be contiguous"))?, &obs)?;
    for (field, x) in [("tau_psd", tau_psd), ("clock_h0", clock_h0), ("clock_hm2", clock_hm2)] {
        if !(x.is_finite() && x >= 0.0) {
            return Err(invalid(field, format!("must be finite and >= 0, got {x}")).into());
        }
    }
    let cfg = TightConfig {
        formulation: Formulation::by_name(formulation)?,
        lever_arm: super::convert::vec3(&lever_arm, "lever_arm")?,
        sigma_code_gps,
        sigma_code_glo,
        sigma_rate,
        use_rate,
        atm: atmosphere(iono, tropo),
        tau_psd,
        clock_h0,
        clock_hm2,
        kind: ins.kind,
    };
    let aiding = TightAiding::new(eph.inner.clone(), epochs, cfg)?;
    PyAidedIns::from_aiding(&ins, nalgebra::DVector::from_vec(vector(&extra0, "extra0")?), Box::new(aiding))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(gnss_tight_ins, m)?)?;
    m.add_class::<PyEphemerides>()?;
    m.add_function(wrap_pyfunction!(glonass_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(gnss_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(gnss_spp, m)?)?;
    Ok(())
}
