//! Bindings of math::rotation, vectorised over rows.

use super::convert::{mats, mats_to_py, quat_rows, quat_to_py, to_py_rows, vec3_rows, vec3_to_py};
use crate::math::*;
use numpy::{PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;

/// Quaternion rows given as rotations (unit norm within the core's tolerance), scaled to
/// exactly unit norm; any other row is an `InputError`.
fn rotation_rows(q: &PyReadonlyArray2<'_, f64>, field: &str) -> PyResult<Vec<Quat>> {
    Ok(rotation_quats(field, &quat_rows(q, field)?)?)
}

#[pyfunction]
fn quat_from_euler_rows<'py>(py: Python<'py>, euler: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = vec3_rows(&euler, "euler")?;
    Ok(quat_to_py(py, &e.iter().map(|v| quat_from_euler(v.x, v.y, v.z)).collect::<Vec<_>>()))
}

#[pyfunction]
fn euler_from_quat_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(vec3_to_py(py, &rotation_rows(&q, "q")?.iter().map(euler_from_quat).collect::<Vec<_>>()))
}

#[pyfunction]
fn dcm_from_quat_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray3<f64>>> {
    Ok(mats_to_py(py, &rotation_rows(&q, "q")?.iter().map(dcm_from_quat).collect::<Vec<_>>()))
}

#[pyfunction]
fn quat_from_dcm_rows<'py>(py: Python<'py>, dcm: PyReadonlyArray3<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = mats::<3, 3>(&dcm, "dcm")?;
    check_rotations("dcm", &m)?;
    Ok(quat_to_py(py, &m.iter().map(quat_from_dcm).collect::<Vec<_>>()))
}

#[pyfunction]
fn quat_from_rotvec_rows<'py>(py: Python<'py>, rotvec: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(quat_to_py(py, &quats_from_rotvecs("rotvec", &vec3_rows(&rotvec, "rotvec")?)?))
}

#[pyfunction]
fn rotvec_from_quat_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(vec3_to_py(py, &rotation_rows(&q, "q")?.iter().map(rotvec_from_quat).collect::<Vec<_>>()))
}

/// Two quaternion series of equal length named `na`, `nb` (`nb` is named when they differ).
fn pair(a: &PyReadonlyArray2<'_, f64>, b: &PyReadonlyArray2<'_, f64>, na: &str, nb: &str) -> PyResult<(Vec<Quat>, Vec<Quat>)> {
    let (a, b) = (quat_rows(a, na)?, quat_rows(b, nb)?);
    if a.len() != b.len() {
        return Err(crate::error::invalid(nb, format!("expected {} rows like {na}, got {}", a.len(), b.len())).into());
    }
    Ok((a, b))
}

#[pyfunction]
fn quat_mul_rows<'py>(py: Python<'py>, a: PyReadonlyArray2<'py, f64>, b: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, b) = pair(&a, &b, "a", "b")?;
    Ok(quat_to_py(py, &a.iter().zip(&b).map(|(x, y)| quat_mul(x, y)).collect::<Vec<_>>()))
}

#[pyfunction]
fn quat_normalize_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    Ok(quat_to_py(py, &unit_quats("q", &quat_rows(&q, "q")?)?))
}

#[pyfunction]
fn skew_rows<'py>(py: Python<'py>, v: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let v = vec3_rows(&v, "v")?;
    Ok(mats_to_py(py, &v.iter().map(skew).collect::<Vec<_>>()))
}

/// Attitude difference angle (rad) per row between two quaternion series.
#[pyfunction]
fn quat_angle_rows<'py>(py: Python<'py>, q_a: PyReadonlyArray2<'py, f64>, q_b: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, b) = pair(&q_a, &q_b, "q_a", "q_b")?;
    let (a, b) = (rotation_quats("q_a", &a)?, rotation_quats("q_b", &b)?);
    let r: Vec<[f64; 1]> = a.iter().zip(&b).map(|(x, y)| [quat_angle_between(x, y)]).collect();
    Ok(to_py_rows(py, &r))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(quat_from_euler_rows, m)?)?;
    m.add_function(wrap_pyfunction!(euler_from_quat_rows, m)?)?;
    m.add_function(wrap_pyfunction!(dcm_from_quat_rows, m)?)?;
    m.add_function(wrap_pyfunction!(quat_from_dcm_rows, m)?)?;
    m.add_function(wrap_pyfunction!(quat_from_rotvec_rows, m)?)?;
    m.add_function(wrap_pyfunction!(rotvec_from_quat_rows, m)?)?;
    m.add_function(wrap_pyfunction!(quat_mul_rows, m)?)?;
    m.add_function(wrap_pyfunction!(quat_normalize_rows, m)?)?;
    m.add_function(wrap_pyfunction!(skew_rows, m)?)?;
    m.add_function(wrap_pyfunction!(quat_angle_rows, m)?)?;
    m.add("ROTATION_TOLERANCE", ROTATION_TOLERANCE)?;
    Ok(())
}
