//! Bindings of gnss/: broadcast ephemerides, the constellation simulator, observation
//! simulation, single-point positioning and the tightly coupled aided INS, over numpy
//! arrays, with one options object ([`PyGnssOptions`]) for all of them.

use super::convert::{real, real_opt, register_choices, rows, seed as seed_arg, to_py_rows, vec3, vec3_rows, vector, Wrap};
use super::filter::floats;
use crate::earth::Helmert;
use crate::error::invalid;
use crate::gnss::atmosphere::Klobuchar;
use crate::gnss::constellation::{nominal, ConstellationConfig};
use crate::gnss::ephemeris::Ephemerides;
use crate::gnss::geometry::look_angles;
use crate::gnss::glonass_orbit::{propagate_checked, GloEphemeris};
use crate::gnss::gps_orbit::GpsEphemeris;
use crate::gnss::observation::{group_epochs, observations, simulate_table, Observation, Visibility};
use crate::gnss::options::GnssOptions;
use crate::gnss::spp::{solve_epochs, Exclusion, SPP_COLUMNS, SPP_COVARIANCE_STATES, SPP_SATELLITE_COLUMNS};
use crate::gnss::tight::{Formulation, TightAiding};
use crate::gnss::{SatId, TimeScales};
use crate::math::Vec3;
use super::sources::AidingSource;
use crate::filter::sources::Source;
use nalgebra::{DMatrix, DVector};
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
super::pickle::picklable!(PyEphemerides, inner, "GnssEphemerides");

fn sat_id(name: &str) -> PyResult<SatId> {
    Ok(SatId::from_name(name, "sat", 0)?)
}

#[pymethods]
impl PyEphemerides {
    #[new]
    #[pyo3(signature = (gps, glonass, n_leap=18.0, datum=Wrap(Helmert::IDENTITY), *, ionosphere=None))]
    fn new(
        gps: PyReadonlyArray2<'_, f64>, glonass: PyReadonlyArray2<'_, f64>, #[pyo3(from_py_with = real)] n_leap: f64, datum: Wrap<Helmert>, ionosphere: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let g = rows::<22>(&gps, "gps")?.iter().map(GpsEphemeris::from_row).collect();
        let r = rows::<14>(&glonass, "glonass")?.iter().enumerate().map(|(i, x)| GloEphemeris::from_row(x, i)).collect::<crate::Result<Vec<_>>>()?;
        let eph = Ephemerides::new(g, r, TimeScales { n_leap }, datum.0)?;
        let inner = match ionosphere {
            Some(k) => eph.with_ionosphere(Klobuchar::from_coefficients(floats::<8>(k, "ionosphere")?))?,
            None => eph,
        };
        Ok(PyEphemerides { inner })
    }

    /// The navigation message's Klobuchar coefficients (α₀..α₃, β₀..β₃).
    #[getter]
    fn ionosphere(&self) -> [f64; 8] {
        self.inner.ionosphere.coefficients()
    }

    /// The nominal constellations over GPS times [t_start, t_end].
    #[staticmethod]
    #[pyo3(signature = (t_start, t_end, gps=true, glonass=true, tau_gps=0.0, n_leap=18.0, clocks=true, seed=None))]
    #[allow(clippy::too_many_arguments)]
    fn nominal(#[pyo3(from_py_with = real)] t_start: f64, #[pyo3(from_py_with = real)] t_end: f64, gps: bool, glonass: bool, #[pyo3(from_py_with = real)] tau_gps: f64, #[pyo3(from_py_with = real)] n_leap: f64, clocks: bool, seed: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let seed = seed.map(|s| seed_arg(s, "seed")).transpose()?.unwrap_or_default();
        let cfg = ConstellationConfig { gps, glonass, t_start, t_end, tau_gps, time: TimeScales { n_leap }, clocks, seed };
        Ok(PyEphemerides { inner: nominal(&cfg)? })
    }

    /// The GPS sets as (N, 22) rows in the constructor's column order.
    fn gps_table<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let r: Vec<[f64; 22]> = self.inner.gps_sets().map(GpsEphemeris::to_row).collect();
        to_py_rows(py, &r)
    }

    /// The GLONASS sets as (M, 14) rows in the constructor's column order.
    fn glonass_table<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let r: Vec<[f64; 14]> = self.inner.glonass_sets().map(GloEphemeris::to_row).collect();
        to_py_rows(py, &r)
    }

    fn satellites(&self) -> Vec<String> {
        self.inner.satellites().iter().map(|s| s.name()).collect()
    }

    fn channel(&self, sat: String) -> PyResult<i64> {
        Ok(self.inner.channel(sat_id(&sat)?)? as i64)
    }

    /// (N, 8) rows [x, y, z, vx, vy, vz (WGS-84 ECEF), clock s, clock rate] of `sat` at GPS
    /// times `t` (GLONASS evaluated at t − ΔT_leap − tau_gps).
    #[pyo3(signature = (sat, t, tau_gps=0.0))]
    fn state<'py>(&self, py: Python<'py>, sat: String, t: PyReadonlyArray1<'py, f64>, #[pyo3(from_py_with = real)] tau_gps: f64) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(to_py_rows(py, &self.inner.state_rows(sat_id(&sat)?, &vector(&t, "t")?, tau_gps)?))
    }

    /// (N, 2) rows [elevation, azimuth] (rad) of `sat` seen from `lla` at GPS times `t`.
    fn look_angles<'py>(&self, py: Python<'py>, sat: String, t: PyReadonlyArray1<'py, f64>, lla: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(to_py_rows(py, &look_angles(&self.inner, sat_id(&sat)?, &vector(&t, "t")?, &vec3(&lla, "lla")?)?))
    }
}

/// GLONASS RK4 propagation of (pos, vel) with constant acceleration `acc` over `dt` s
/// (GLONASS ICD 2008, A.3.1.2), step ≤ `step` s, J₂ = `j2`; returns [x, y, z, vx, vy, vz].
#[pyfunction]
fn glonass_propagate<'py>(py: Python<'py>, pos: PyReadonlyArray1<'py, f64>, vel: PyReadonlyArray1<'py, f64>, acc: PyReadonlyArray1<'py, f64>, #[pyo3(from_py_with = real)] dt: f64, #[pyo3(from_py_with = real)] step: f64, #[pyo3(from_py_with = real)] j2: f64) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (p, v) = propagate_checked(vec3(&pos, "pos")?, vec3(&vel, "vel")?, &vec3(&acc, "acc")?, dt, step, j2)?;
    Ok(PyArray1::from_vec(py, vec![p.x, p.y, p.z, v.x, v.y, v.z]))
}

/// GNSS processing options (gnss/options.rs), checked once; every GNSS function takes
/// one. Keyword-only; `sigma_code_glonass` None = `sigma_code`.
#[pyclass(module = "atomnav._core", name = "GnssOptions", frozen)]
pub struct PyGnssOptions {
    inner: GnssOptions,
}
super::pickle::picklable!(PyGnssOptions, inner, "GnssOptions");

#[pymethods]
impl PyGnssOptions {
    #[new]
    #[pyo3(signature = (*, sigma_code, sigma_code_glonass, sigma_rate, iono, tropo, use_tau, elevation_weight, elevation_mask, fault_detection, ionosphere_free, formulation, lever_arm, use_rate, tau0, sigma_tau0, tau_psd, clock0, sigma_clock0, clock_h0, clock_hm2))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        #[pyo3(from_py_with = real)] sigma_code: f64, #[pyo3(from_py_with = real_opt)] sigma_code_glonass: Option<f64>, #[pyo3(from_py_with = real)] sigma_rate: f64, iono: bool, tropo: bool, use_tau: bool, elevation_weight: bool,
        #[pyo3(from_py_with = real)] elevation_mask: f64, fault_detection: bool, ionosphere_free: bool, formulation: Wrap<Formulation>, lever_arm: &Bound<'_, PyAny>, use_rate: bool, #[pyo3(from_py_with = real)] tau0: f64, #[pyo3(from_py_with = real)] sigma_tau0: f64, #[pyo3(from_py_with = real)] tau_psd: f64,
        clock0: &Bound<'_, PyAny>, sigma_clock0: &Bound<'_, PyAny>, #[pyo3(from_py_with = real)] clock_h0: f64, #[pyo3(from_py_with = real)] clock_hm2: f64,
    ) -> PyResult<Self> {
        let (lever_arm, clock0) = (floats::<3>(lever_arm, "lever_arm")?, floats::<2>(clock0, "clock0")?);
        let sigma_clock0 = floats::<2>(sigma_clock0, "sigma_clock0")?;
        let inner = GnssOptions {
            sigma_code_gps: sigma_code,
            sigma_code_glo: sigma_code_glonass.unwrap_or(sigma_code),
            sigma_rate,
            iono,
            tropo,
            use_tau,
            elevation_weight,
            elevation_mask,
            fault_detection,
            ionosphere_free,
            formulation: formulation.0,
            lever_arm: Vec3::from(lever_arm),
            use_rate,
            tau0,
            sigma_tau0,
            tau_psd,
            clock0,
            sigma_clock0,
            clock_h0,
            clock_hm2,
        };
        inner.check()?;
        Ok(PyGnssOptions { inner })
    }
}

/// Simulated observation table: dict of sat (list of str), channel, time_s, code_m, rate_mps,
/// elevation_rad (truth). Truth: τ_GPS `tau_gps` (s), receiver clock
/// `clock_bias` + `clock_drift`·(t − t[0]) (s); visibility: elevation `mask` (rad), `only` a
/// satellite subset, `outages` (K, 2) GPS-time windows, `sat_outages` [(sat, start, end)].
#[pyfunction]
#[pyo3(signature = (eph, t, lla, vel_ned, options, *, tau_gps=0.0, clock_bias=0.0, clock_drift=0.0, mask=0.0, only=None, outages=None, sat_outages=Vec::new(), seed=None))]
#[allow(clippy::too_many_arguments)]
fn gnss_simulate<'py>(
    py: Python<'py>, eph: &PyEphemerides, t: PyReadonlyArray1<'py, f64>, lla: PyReadonlyArray2<'py, f64>, vel_ned: PyReadonlyArray2<'py, f64>,
    options: &PyGnssOptions, #[pyo3(from_py_with = real)] tau_gps: f64, #[pyo3(from_py_with = real)] clock_bias: f64, #[pyo3(from_py_with = real)] clock_drift: f64, #[pyo3(from_py_with = real)] mask: f64, only: Option<Vec<String>>,
    outages: Option<PyReadonlyArray2<'py, f64>>, sat_outages: Vec<(String, f64, f64)>, seed: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let seed = seed.map(|s| seed_arg(s, "seed")).transpose()?.unwrap_or_default();
    let t = vector(&t, "t")?;
    let (lla, vel) = (vec3_rows(&lla, "lla")?, vec3_rows(&vel_ned, "vel_ned")?);
    let names: Vec<String> = sat_outages.iter().map(|x| x.0.clone()).collect();
    let ids = SatId::from_names(&names, "sat_outages")?;
    let vis = Visibility {
        mask,
        only: only.map(|o| SatId::from_names(&o, "only")).transpose()?,
        outages: outages.map(|o| rows::<2>(&o, "outages")).transpose()?.unwrap_or_default().iter().map(|r| (r[0], r[1])).collect(),
        sat_outages: ids.into_iter().zip(&sat_outages).map(|(s, x)| (s, x.1, x.2)).collect(),
    };
    let cfg = options.inner.simulation(&eph.inner, tau_gps, clock_bias, clock_drift, seed)?;
    let e = &eph.inner;
    let tab = py.detach(|| simulate_table(e, &t, &lla, &vel, &cfg, &vis))?;
    let d = PyDict::new(py);
    d.set_item("sat", tab.sat)?;
    d.set_item("channel", PyArray1::from_vec(py, tab.channel))?;
    d.set_item("time_s", PyArray1::from_vec(py, tab.time))?;
    d.set_item("code_m", PyArray1::from_vec(py, tab.code))?;
    d.set_item("rate_mps", PyArray1::from_vec(py, tab.rate))?;
    d.set_item("elevation_rad", PyArray1::from_vec(py, tab.elevation))?;
    Ok(d)
}

/// The flat observation table (time, sat, channel, code, rate; rate NaN when absent)
/// grouped into epochs.
fn epochs(
    time: &PyReadonlyArray1<'_, f64>, sat: &[String], channel: &PyReadonlyArray1<'_, i64>, code: &PyReadonlyArray1<'_, f64>, code2: Option<&PyReadonlyArray1<'_, f64>>,
    rate: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Vec<(f64, Vec<Observation>)>> {
    let code2 = code2.map(|c| c.as_array().to_vec());
    let obs = observations(sat, &channel.as_array().to_vec(), &code.as_array().to_vec(), code2.as_deref(), &rate.as_array().to_vec())?;
    Ok(group_epochs(time.as_array().as_slice().ok_or_else(|| invalid("time", "must be contiguous"))?, &obs)?)
}

/// Epoch-by-epoch single-point positioning (gnss/spp.rs `solve_epochs`): the epoch rows
/// (columns `SPP_COLUMNS`), the satellite rows (`SPP_SATELLITE_COLUMNS`), their
/// satellite names, and the epochs' covariances of `SPP_COVARIANCE_STATES` as rows of 25
/// (5 × 5 row-major). `code2`: the second-frequency codes for `ionosphere_free` (NaN where absent).
#[pyfunction]
#[pyo3(signature = (eph, time, sat, channel, code, rate, options, *, code2=None))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn gnss_spp<'py>(
    py: Python<'py>, eph: &PyEphemerides, time: PyReadonlyArray1<'py, f64>, sat: Vec<String>, channel: PyReadonlyArray1<'py, i64>,
    code: PyReadonlyArray1<'py, f64>, rate: PyReadonlyArray1<'py, f64>, options: &PyGnssOptions, code2: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Vec<String>, Bound<'py, PyArray2<f64>>)> {
    let ep = epochs(&time, &sat, &channel, &code, code2.as_ref(), &rate)?;
    let (e, o) = (&eph.inner, &options.inner);
    let out = py.detach(|| solve_epochs(e, &ep, &o.spp(e), o.sigma_rate))?;
    Ok((to_py_rows(py, &out.epochs), to_py_rows(py, &out.satellites), out.satellite_names, to_py_rows(py, &out.covariance)))
}

/// Tightly coupled GNSS as one measurement source of an aided INS
/// (`aided_ins_from_sources`): observation table as for `gnss_spp`, options as for the tightly coupled model (`gnss/tight.rs`); the
/// initial values and σ of its extra states come from `options`. The sensor is made when
/// the INS is built (it needs the IMU kind of the setup).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn gnss_source<'py>(
    eph: &PyEphemerides, time: PyReadonlyArray1<'py, f64>, sat: Vec<String>, channel: PyReadonlyArray1<'py, i64>, code: PyReadonlyArray1<'py, f64>,
    rate: PyReadonlyArray1<'py, f64>, options: &PyGnssOptions,
) -> PyResult<AidingSource> {
    let ep = epochs(&time, &sat, &channel, &code, None, &rate)?;
    let (e, o) = (eph.inner.clone(), options.inner);
    Ok(AidingSource::deferred(
        "gnss".to_string(),
        Box::new(move |setup| {
            let (x0, var) = o.tight_initial();
            let config = o.tight(&e, setup.kind);
            let aiding = TightAiding::new(e, ep, config)?;
            Ok(Source { aiding: Box::new(aiding), extra0: x0, p0: Some(DMatrix::from_diagonal(&DVector::from_vec(var))) })
        }),
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(gnss_source, m)?)?;
    m.add_class::<PyEphemerides>()?;
    m.add_class::<PyGnssOptions>()?;
    m.add_function(wrap_pyfunction!(glonass_propagate, m)?)?;
    m.add_function(wrap_pyfunction!(gnss_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(gnss_spp, m)?)?;
    m.add("SPP_COLUMNS", SPP_COLUMNS.to_vec())?;
    m.add("SPP_SATELLITE_COLUMNS", SPP_SATELLITE_COLUMNS.to_vec())?;
    m.add("SPP_COVARIANCE_STATES", SPP_COVARIANCE_STATES.to_vec())?;
    m.add("SPP_EXCLUSIONS", Exclusion::ALL.iter().map(|e| e.name()).collect::<Vec<_>>())?;
    register_choices::<Formulation>(m, "Formulation")
}
