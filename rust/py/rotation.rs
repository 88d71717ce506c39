//! Bindings of math::rotation, vectorised over rows.

use super::convert::{quat_rows, quat_to_py, to_py_rows, vec3_rows, vec3_to_py};
use crate::math::*;
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;

fn dcm_rows(a: &PyReadonlyArray3<'_, f64>) -> PyResult<Vec<Mat3>> {
    let s = a.shape();
    if s[1] != 3 || s[2] != 3 {
        return Err(crate::error::invalid("dcm", format!("expected shape (N, 3, 3), got ({}, {}, {})", s[0], s[1], s[2])).into());
    }
    let v = a.as_array();
    let mut out = Vec::with_capacity(s[0]);
    for i in 0..s[0] {
        let m = Mat3::from_fn(|r, c| v[[i, r, c]]);
        if m.iter().any(|x| !x.is_finite()) {
            return Err(crate::error::invalid("dcm", format!("non-finite value at index {i}")).into());
        }
        out.push(m);
    }
    Ok(out)
}

fn dcm_to_py<'py>(py: Python<'py>, m: &[Mat3]) -> Bound<'py, PyArray3<f64>> {
    let mut a = Array3::<f64>::zeros((m.len(), 3, 3));
    for (i, c) in m.iter().enumerate() {
        for r in 0..3 {
            for k in 0..3 {
                a[[i, r, k]] = c[(r, k)];
            }
        }
    }
    a.into_pyarray(py)
}

#[pyfunction]
fn quat_from_euler_rows<'py>(py: Python<'py>, euler: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let e = vec3_rows(&euler, "euler")?;
    Ok(quat_to_py(py, &e.iter().map(|v| quat_from_euler(v.x, v.y, v.z)).collect::<Vec<_>>()))
}

#[pyfunction]
fn euler_from_quat_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = quat_rows(&q, "q")?;
    Ok(vec3_to_py(py, &q.iter().map(|q| euler_from_quat(&quat_normalize(q))).collect::<Vec<_>>()))
}

#[pyfunction]
fn dcm_from_quat_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let q = quat_rows(&q, "q")?;
    Ok(dcm_to_py(py, &q.iter().map(|q| dcm_from_quat(&quat_normalize(q))).collect::<Vec<_>>()))
}

#[pyfunction]
fn quat_from_dcm_rows<'py>(py: Python<'py>, dcm: PyReadonlyArray3<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = dcm_rows(&dcm)?;
    Ok(quat_to_py(py, &m.iter().map(quat_from_dcm).collect::<Vec<_>>()))
}

#[pyfunction]
fn quat_from_rotvec_rows<'py>(py: Python<'py>, rv: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let v = vec3_rows(&rv, "rotvec")?;
    Ok(quat_to_py(py, &v.iter().map(quat_from_rotvec).collect::<Vec<_>>()))
}

#[pyfunction]
fn rotvec_from_quat_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = quat_rows(&q, "q")?;
    Ok(vec3_to_py(py, &q.iter().map(|q| rotvec_from_quat(&quat_normalize(q))).collect::<Vec<_>>()))
}

#[pyfunction]
fn quat_mul_rows<'py>(py: Python<'py>, a: PyReadonlyArray2<'py, f64>, b: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, b) = (quat_rows(&a, "a")?, quat_rows(&b, "b")?);
    if a.len() != b.len() {
        return Err(crate::error::invalid("b", format!("expected {} rows like a, got {}", a.len(), b.len())).into());
    }
    Ok(quat_to_py(py, &a.iter().zip(&b).map(|(x, y)| quat_mul(x, y)).collect::<Vec<_>>()))
}

#[pyfunction]
fn quat_normalize_rows<'py>(py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q = quat_rows(&q, "q")?;
    if let Some(i) = q.iter().position(|x| x.norm() == 0.0) {
        return Err(crate::error::invalid("q", format!("zero quaternion at index {i}")).into());
    }
    Ok(quat_to_py(py, &q.iter().map(quat_normalize).collect::<Vec<_>>()))
}

#[pyfunction]
fn skew_rows<'py>(py: Python<'py>, v: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let v = vec3_rows(&v, "v")?;
    Ok(dcm_to_py(py, &v.iter().map(skew).collect::<Vec<_>>()))
}

/// Attitude difference angle (rad) per row between two quaternion series.
#[pyfunction]
fn quat_angle_rows<'py>(py: Python<'py>, a: PyReadonlyArray2<'py, f64>, b: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, b) = (quat_rows(&a, "a")?, quat_rows(&b, "b")?);
    if a.len() != b.len() {
        return Err(crate::error::invalid("b", format!("expected {} rows like a, got {}", a.len(), b.len())).into());
    }
    let r: Vec<[f64; 1]> = a.iter().zip(&b).map(|(x, y)| [quat_angle_between(&quat_normalize(x), &quat_normalize(y))]).collect();
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
    Ok(())
}
