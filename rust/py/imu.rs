//! Bindings of imu::{errors, noise, presets}: the error-model parameters travel as one dict
//! per triad (keys of `TRIAD_KEYS`), the IMU stream as whole (N, 3) arrays.

use super::convert::{each_item, real, vec3_rows, vec3_to_py, Wrap};
use crate::error::invalid;
use crate::imu::errors::{FlickerSpec, GaussMarkovSpec, ImuErrorModel, ImuSimulator, TriadErrors};
use crate::imu::noise;
use crate::imu::ImuKind;
use crate::imu::presets::{preset, PRESET_NAMES};
use crate::math::{Mat3, Vec3};
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

const TRIAD_KEYS: [&str; 8] = ["bias", "bias_sigma", "scale", "misalignment", "white", "bias_rw", "gauss_markov", "flicker"];

fn floats(v: &Bound<'_, PyAny>, field: &str, len: usize) -> PyResult<Vec<f64>> {
    let x: Vec<f64> = v.extract()?;
    if x.len() != len {
        return Err(invalid(field, format!("expected {len} values, got {}", x.len())).into());
    }
    Ok(x)
}

// invariant: floats(v, field, n) returns exactly n values or an error.
#[allow(clippy::indexing_slicing)]
pub(super) fn triad_from_dict(d: &Bound<'_, PyDict>, name: &str) -> PyResult<TriadErrors> {
    let mut t = TriadErrors::default();
    each_item(d, name, |key, v| {
        let field = format!("{name}.{key}");
        match key {
            "bias" => t.bias = Vec3::from_vec(floats(&v, &field, 3)?),
            "scale" => t.scale = Vec3::from_vec(floats(&v, &field, 3)?),
            "misalignment" => t.misalignment = Mat3::from_row_slice(&floats(&v, &field, 9)?),
            "bias_sigma" => t.bias_sigma = v.extract()?,
            "white" => t.white = v.extract()?,
            "bias_rw" => t.bias_rw = v.extract()?,
            "gauss_markov" if v.is_none() => t.gauss_markov = None,
            "gauss_markov" => {
                let g = floats(&v, &field, 2)?;
                t.gauss_markov = Some(GaussMarkovSpec { sigma: g[0], tau: g[1] });
            }
            "flicker" if v.is_none() => t.flicker = None,
            "flicker" => {
                let f = floats(&v, &field, 3)?;
                t.flicker = Some(FlickerSpec { b: f[0], f_lo: f[1], f_hi: f[2] });
            }
            _ => return Err(invalid(&field, format!("unknown parameter; choose from {TRIAD_KEYS:?}")).into()),
        }
        Ok(())
    })?;
    Ok(t)
}

fn triad_to_dict<'py>(py: Python<'py>, t: &TriadErrors) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("bias", t.bias.as_slice().to_vec())?;
    d.set_item("bias_sigma", t.bias_sigma)?;
    d.set_item("scale", t.scale.as_slice().to_vec())?;
    d.set_item("misalignment", t.misalignment.transpose().as_slice().to_vec())?; // row-major
    d.set_item("white", t.white)?;
    d.set_item("bias_rw", t.bias_rw)?;
    d.set_item("gauss_markov", t.gauss_markov.map(|g| (g.sigma, g.tau)))?;
    d.set_item("flicker", t.flicker.map(|f| (f.b, f.f_lo, f.f_hi)))?;
    Ok(d)
}

/// Names of the built-in IMU grade presets.
#[pyfunction]
fn imu_preset_names() -> Vec<&'static str> {
    PRESET_NAMES.to_vec()
}

/// (accel dict, gyro dict) of a built-in preset.
#[pyfunction]
fn imu_preset<'py>(py: Python<'py>, preset: &str) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let m = self::preset(preset)?;
    Ok((triad_to_dict(py, &m.accel)?, triad_to_dict(py, &m.gyro)?))
}

/// Check a pair of triad dicts as the simulator would, without simulating.
#[pyfunction]
fn imu_validate_errors(accel: &Bound<'_, PyDict>, gyro: &Bound<'_, PyDict>) -> PyResult<()> {
    ImuErrorModel { accel: triad_from_dict(accel, "accel")?, gyro: triad_from_dict(gyro, "gyro")? }.validate()?;
    Ok(())
}

/// Seeded, stateful IMU corruption (imu::errors::ImuSimulator); successive `corrupt` calls
/// continue the same random streams.
#[pyclass(module = "atomnav._core")]
struct ImuErrorSimulator {
    sim: ImuSimulator,
}
// the state includes every random stream's position
super::pickle::picklable!(ImuErrorSimulator, sim, "ImuErrorSimulator");

#[pymethods]
impl ImuErrorSimulator {
    #[new]
    fn new(accel: &Bound<'_, PyDict>, gyro: &Bound<'_, PyDict>, #[pyo3(from_py_with = real)] dt: f64, kind: Wrap<ImuKind>, seed: &Bound<'_, PyAny>) -> PyResult<Self> {
        let model = ImuErrorModel { accel: triad_from_dict(accel, "accel")?, gyro: triad_from_dict(gyro, "gyro")? };
        Ok(Self { sim: ImuSimulator::new(&model, dt, kind.0, super::convert::seed(seed, "seed")?)? })
    }

    /// (accel measured, gyro measured, accel bias truth, gyro bias truth), each (N, 3).
    #[allow(clippy::type_complexity)]
    fn corrupt<'py>(
        &mut self,
        py: Python<'py>,
        accel: PyReadonlyArray2<'py, f64>,
        gyro: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let (f, w) = (vec3_rows(&accel, "accel")?, vec3_rows(&gyro, "gyro")?);
        let sim = &mut self.sim;
        let out = py.detach(|| sim.corrupt(&f, &w))?;
        Ok((vec3_to_py(py, &out.accel), vec3_to_py(py, &out.gyro), vec3_to_py(py, &out.accel_bias), vec3_to_py(py, &out.gyro_bias)))
    }
}

#[pyfunction]
fn imu_white_sigma(#[pyo3(from_py_with = real)] density: f64, #[pyo3(from_py_with = real)] dt: f64, kind: Wrap<ImuKind>) -> PyResult<f64> {
    Ok(noise::white_sigma(density, dt, kind.0)?)
}

#[pyfunction]
fn imu_white_density(#[pyo3(from_py_with = real)] sigma: f64, #[pyo3(from_py_with = real)] dt: f64, kind: Wrap<ImuKind>) -> PyResult<f64> {
    Ok(noise::white_density(sigma, dt, kind.0)?)
}

#[pyfunction]
fn imu_random_walk_step_sigma(#[pyo3(from_py_with = real)] density: f64, #[pyo3(from_py_with = real)] dt: f64) -> PyResult<f64> {
    Ok(noise::random_walk_step_sigma(density, dt)?)
}

#[pyfunction]
fn imu_random_walk_density(#[pyo3(from_py_with = real)] step_sigma: f64, #[pyo3(from_py_with = real)] dt: f64) -> PyResult<f64> {
    Ok(noise::random_walk_density(step_sigma, dt)?)
}

#[pyfunction]
fn imu_gauss_markov_driving_sigma(#[pyo3(from_py_with = real)] sigma: f64, #[pyo3(from_py_with = real)] tau: f64, #[pyo3(from_py_with = real)] dt: f64) -> PyResult<f64> {
    Ok(noise::gauss_markov_driving_sigma(sigma, tau, dt)?)
}

#[pyfunction]
fn imu_gauss_markov_sigma(#[pyo3(from_py_with = real)] driving_sigma: f64, #[pyo3(from_py_with = real)] tau: f64, #[pyo3(from_py_with = real)] dt: f64) -> PyResult<f64> {
    Ok(noise::gauss_markov_sigma(driving_sigma, tau, dt)?)
}

#[pyfunction]
fn imu_gauss_markov_low_freq_asd(#[pyo3(from_py_with = real)] sigma: f64, #[pyo3(from_py_with = real)] tau: f64) -> PyResult<f64> {
    Ok(noise::gauss_markov_low_freq_asd(sigma, tau)?)
}

#[pyfunction]
fn imu_flicker_psd(#[pyo3(from_py_with = real)] b: f64, #[pyo3(from_py_with = real)] f: f64) -> PyResult<f64> {
    Ok(noise::flicker_psd(b, f)?)
}

#[pyfunction]
fn imu_flicker_allan_floor(#[pyo3(from_py_with = real)] b: f64) -> PyResult<f64> {
    Ok(noise::flicker_allan_floor(b)?)
}

/// (σ, τ) of the Gauss–Markov poles the simulator sums into a flicker term (B, f_lo, f_hi).
#[pyfunction]
fn imu_flicker_poles(#[pyo3(from_py_with = real)] b: f64, #[pyo3(from_py_with = real)] f_lo: f64, #[pyo3(from_py_with = real)] f_hi: f64) -> PyResult<Vec<(f64, f64)>> {
    Ok(noise::Flicker::poles(b, f_lo, f_hi)?)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ImuErrorSimulator>()?;
    m.add_function(wrap_pyfunction!(imu_preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(imu_preset, m)?)?;
    m.add_function(wrap_pyfunction!(imu_validate_errors, m)?)?;
    m.add_function(wrap_pyfunction!(imu_white_sigma, m)?)?;
    m.add_function(wrap_pyfunction!(imu_white_density, m)?)?;
    m.add_function(wrap_pyfunction!(imu_random_walk_step_sigma, m)?)?;
    m.add_function(wrap_pyfunction!(imu_random_walk_density, m)?)?;
    m.add_function(wrap_pyfunction!(imu_gauss_markov_driving_sigma, m)?)?;
    m.add_function(wrap_pyfunction!(imu_gauss_markov_sigma, m)?)?;
    m.add_function(wrap_pyfunction!(imu_gauss_markov_low_freq_asd, m)?)?;
    m.add_function(wrap_pyfunction!(imu_flicker_psd, m)?)?;
    m.add_function(wrap_pyfunction!(imu_flicker_allan_floor, m)?)?;
    m.add_function(wrap_pyfunction!(imu_flicker_poles, m)?)?;
    Ok(())
}
