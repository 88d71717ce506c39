//! numpy ↔ nalgebra conversion with shape and finiteness checks, and NavError → PyErr.

use crate::error::{check_finite, invalid, NavError};
use crate::math::{quat, Quat, Vec3};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

impl From<NavError> for PyErr {
    fn from(e: NavError) -> PyErr {
        match e {
            NavError::InvalidInput { .. } => PyValueError::new_err(e.to_string()),
            NavError::Numerical(_) => super::NumericalError::new_err(e.to_string()),
        }
    }
}

/// The rows of an (N, W) float array, checked for shape and NaN/inf.
pub fn rows<const W: usize>(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<Vec<[f64; W]>, NavError> {
    let shape = a.shape();
    if shape[1] != W {
        return Err(invalid(field, format!("expected shape (N, {W}), got ({}, {})", shape[0], shape[1])));
    }
    let view = a.as_array();
    let mut out = Vec::with_capacity(shape[0]);
    match view.as_slice() {
        // C-contiguous: one pass over the flat buffer
        Some(flat) => {
            check_finite(field, flat, W)?;
            out.extend(flat.chunks_exact(W).map(|c| <[f64; W]>::try_from(c).expect("chunk of W")));
        }
        None => {
            for (i, row) in view.outer_iter().enumerate() {
                let mut r = [0.0; W];
                for (j, x) in row.iter().enumerate() {
                    if !x.is_finite() {
                        return Err(invalid(field, format!("non-finite value {x} at index {i} (column {j})")));
                    }
                    r[j] = *x;
                }
                out.push(r);
            }
        }
    }
    Ok(out)
}

pub fn vec3_rows(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<Vec<Vec3>, NavError> {
    Ok(rows::<3>(a, field)?.into_iter().map(Vec3::from).collect())
}

pub fn quat_rows(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<Vec<Quat>, NavError> {
    Ok(rows::<4>(a, field)?.into_iter().map(|r| quat(r[0], r[1], r[2], r[3])).collect())
}

/// A 1-D float array as a Vec, checked for NaN/inf.
pub fn vector(a: &PyReadonlyArray1<'_, f64>, field: &str) -> Result<Vec<f64>, NavError> {
    let v: Vec<f64> = a.as_array().iter().copied().collect();
    check_finite(field, &v, 1)?;
    Ok(v)
}

/// A length-3 vector argument.
pub fn vec3(a: &PyReadonlyArray1<'_, f64>, field: &str) -> Result<Vec3, NavError> {
    let v = vector(a, field)?;
    if v.len() != 3 {
        return Err(invalid(field, format!("expected 3 elements, got {}", v.len())));
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}

pub fn to_py_rows<'py, const W: usize>(py: Python<'py>, rows: &[[f64; W]]) -> Bound<'py, PyArray2<f64>> {
    rows_to_py(py, rows.len(), W, rows.iter().flat_map(|r| r.iter().copied()))
}

/// An (n, w) array from a row-major stream of values.
pub fn rows_to_py<'py>(py: Python<'py>, n: usize, w: usize, values: impl Iterator<Item = f64>) -> Bound<'py, PyArray2<f64>> {
    let mut flat = Vec::with_capacity(n * w);
    flat.extend(values);
    flat_to_py(py, n, w, flat)
}

/// An (n, w) array that takes ownership of a row-major buffer (no copy).
pub fn flat_to_py<'py>(py: Python<'py>, n: usize, w: usize, flat: Vec<f64>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((n, w), flat).expect("n·w values by construction").into_pyarray(py)
}

pub fn vec3_to_py<'py>(py: Python<'py>, v: &[Vec3]) -> Bound<'py, PyArray2<f64>> {
    let r: Vec<[f64; 3]> = v.iter().map(|x| [x.x, x.y, x.z]).collect();
    to_py_rows(py, &r)
}

pub fn quat_to_py<'py>(py: Python<'py>, q: &[Quat]) -> Bound<'py, PyArray2<f64>> {
    let r: Vec<[f64; 4]> = q.iter().map(|x| [x.w, x.i, x.j, x.k]).collect();
    to_py_rows(py, &r)
}

pub fn vec_to_py<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    v.into_pyarray(py)
}
