//! Bindings of earth.rs, vectorised over rows; every function takes an ellipsoid name.

use super::convert::{mat_to_py, real, rows, set_floats, to_py_rows, vec3, vec3_rows, vec3_to_py, Wrap};
use crate::earth::{check_latitude, check_latitudes, dcm_ned_to_ecef, Ellipsoid};
use crate::math::Vec3;
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

fn lla_rows(a: &PyReadonlyArray2<'_, f64>, field: &str) -> PyResult<Vec<Vec3>> {
    let v = vec3_rows(a, field)?;
    check_latitudes(field, &v)?;
    Ok(v)
}

fn origin(a: &PyReadonlyArray1<'_, f64>) -> PyResult<Vec3> {
    let o = vec3(a, "origin_lla")?;
    check_latitude("origin_lla", o.x, 0)?;
    Ok(o)
}

#[pyfunction]
#[pyo3(signature = (lla, ellipsoid=Wrap(crate::earth::WGS84)))]
fn lla_to_ecef_rows<'py>(py: Python<'py>, lla: PyReadonlyArray2<'py, f64>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = ellipsoid.0;
    let p = lla_rows(&lla, "lla")?;
    Ok(vec3_to_py(py, &p.iter().map(|x| e.lla_to_ecef(x)).collect::<Vec<_>>()))
}

#[pyfunction]
#[pyo3(signature = (ecef, ellipsoid=Wrap(crate::earth::WGS84)))]
fn ecef_to_lla_rows<'py>(py: Python<'py>, ecef: PyReadonlyArray2<'py, f64>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = vec3_rows(&ecef, "ecef")?;
    Ok(vec3_to_py(py, &ellipsoid.0.ecef_to_lla_rows("ecef", &r)?))
}

#[pyfunction]
#[pyo3(signature = (ecef, origin_lla, ellipsoid=Wrap(crate::earth::WGS84)))]
fn ecef_to_ned_rows<'py>(py: Python<'py>, ecef: PyReadonlyArray2<'py, f64>, origin_lla: PyReadonlyArray1<'py, f64>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (e, o) = (ellipsoid.0, origin(&origin_lla)?);
    let r = vec3_rows(&ecef, "ecef")?;
    Ok(vec3_to_py(py, &r.iter().map(|x| e.ecef_to_ned(x, &o)).collect::<Vec<_>>()))
}

#[pyfunction]
#[pyo3(signature = (ned, origin_lla, ellipsoid=Wrap(crate::earth::WGS84)))]
fn ned_to_ecef_rows<'py>(py: Python<'py>, ned: PyReadonlyArray2<'py, f64>, origin_lla: PyReadonlyArray1<'py, f64>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (e, o) = (ellipsoid.0, origin(&origin_lla)?);
    let r = vec3_rows(&ned, "ned")?;
    Ok(vec3_to_py(py, &r.iter().map(|x| e.ned_to_ecef(x, &o)).collect::<Vec<_>>()))
}

/// Per row of (lat, lon, h): [M, N, gravity γ, ∂γ/∂φ, Schuler ω_s]; a height outside the
/// model's range names `h_field` (the caller's height argument).
#[pyfunction]
#[pyo3(signature = (lla, ellipsoid=Wrap(crate::earth::WGS84), h_field="lla"))]
fn earth_params_rows<'py>(py: Python<'py>, lla: PyReadonlyArray2<'py, f64>, ellipsoid: Wrap<Ellipsoid>, h_field: &str) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let p = vec3_rows(&lla, "lla")?;
    Ok(to_py_rows(py, &ellipsoid.0.parameters_rows("lla", h_field, &p)?))
}

/// Per row of (lat, lon, h, v_N, v_E, v_D): [ω_ie^n (3), ω_en^n (3)] in rad/s.
#[pyfunction]
#[pyo3(signature = (lla_vel, ellipsoid=Wrap(crate::earth::WGS84)))]
fn nav_rates_rows<'py>(py: Python<'py>, lla_vel: PyReadonlyArray2<'py, f64>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let p = rows::<6>(&lla_vel, "lla_vel")?;
    Ok(to_py_rows(py, &ellipsoid.0.nav_rates_rows("lla_vel", &p)?))
}

/// The core's latitude check of (lat, lon, h) rows: an `InputError` naming `field` and the
/// first row whose latitude is not finite within [−π/2, π/2].
#[pyfunction]
fn check_latitudes_rows(lla: PyReadonlyArray2<'_, f64>, field: &str) -> PyResult<()> {
    lla_rows(&lla, field)?;
    Ok(())
}

/// C_n^e for one (lat, lon) as a (3, 3) array.
#[pyfunction]
fn dcm_ned_to_ecef_py<'py>(py: Python<'py>, #[pyo3(from_py_with = real)] lat: f64, #[pyo3(from_py_with = real)] lon: f64) -> PyResult<Bound<'py, PyArray2<f64>>> {
    check_latitude("lat", lat, 0)?;
    Ok(mat_to_py(py, &dcm_ned_to_ecef(lat, lon)))
}

/// Ellipsoid constants as a dict (a, f, gm, omega, e2, b, gamma_e, gamma_p).
#[pyfunction]
fn ellipsoid_constants(py: Python<'_>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Py<PyAny>> {
    let d = pyo3::types::PyDict::new(py);
    set_floats(&d, &ellipsoid.0.constants())?;
    d.set_item("name", ellipsoid.0.name)?;
    Ok(d.into_any().unbind())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(lla_to_ecef_rows, m)?)?;
    m.add_function(wrap_pyfunction!(ecef_to_lla_rows, m)?)?;
    m.add_function(wrap_pyfunction!(ecef_to_ned_rows, m)?)?;
    m.add_function(wrap_pyfunction!(ned_to_ecef_rows, m)?)?;
    m.add_function(wrap_pyfunction!(earth_params_rows, m)?)?;
    m.add_function(wrap_pyfunction!(nav_rates_rows, m)?)?;
    m.add_function(wrap_pyfunction!(dcm_ned_to_ecef_py, m)?)?;
    m.add_function(wrap_pyfunction!(check_latitudes_rows, m)?)?;
    m.add_function(wrap_pyfunction!(ellipsoid_constants, m)?)?;
    m.add("HEIGHT_RANGE", crate::earth::HEIGHT_RANGE)?;
    Ok(())
}
