//! numpy ↔ nalgebra conversion with shape and finiteness checks, options by name
//! (`Wrap<T>`), checked integer arguments, and NavError → PyErr.

use crate::error::{check_finite, invalid, invalid_at, NavError};
use crate::math::{quat, Quat, Vec3};
use crate::options::Choice;
use nalgebra::{DMatrix, Dim, Matrix, RawStorage};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyTypeError};
use pyo3::prelude::*;
use pyo3::pybacked::PyBackedStr;
use pyo3::types::{PyBool, PyBytes, PyDict, PyInt, PyString};

impl From<NavError> for PyErr {
    fn from(e: NavError) -> PyErr {
        match &e {
            NavError::InvalidInput { field, index, .. } => {
                let err = super::InputError::new_err(e.to_string());
                Python::attach(|py| {
                    let value = err.value(py);
                    // setting attributes on a fresh exception instance cannot fail
                    let _ = value.setattr("parameter", field.as_str());
                    let _ = value.setattr("index", *index);
                });
                err
            }
            NavError::OutOfMemory { .. } => PyMemoryError::new_err(e.to_string()),
            NavError::Numerical(_) => super::NumericalError::new_err(e.to_string()),
        }
    }
}

/// An option given by name from Python, parsed once by the core's [`Choice`] list
/// (polars' `Wrap<T>` pattern). A non-`str` is a `TypeError` (pyo3 prefixes the argument
/// name); an unknown name an `InputError` naming `T::PARAMETER` and the accepted names.
pub struct Wrap<T>(pub T);

impl<'a, 'py, T: Choice> FromPyObject<'a, 'py> for Wrap<T> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let name: PyBackedStr = obj
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("expected a str, one of {}", T::names().join(", "))))?;
        Ok(Wrap(T::parse(&name)?))
    }
}

/// A scalar float argument (`#[pyo3(from_py_with = real)]`): a Python or numpy number.
/// Text is never read as a number: a `str`, `bytes`, or a numpy string scalar or array
/// (whose `float()` would parse the text, or raise `ValueError`) is a `TypeError` (pyo3
/// prefixes the argument name), as is any other non-number.
pub fn real(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    let text_dtype = obj
        .getattr(pyo3::intern!(obj.py(), "dtype"))
        .and_then(|d| d.getattr(pyo3::intern!(obj.py(), "kind")))
        .and_then(|k| k.extract::<PyBackedStr>())
        .is_ok_and(|k| matches!(&*k, "U" | "S" | "O" | "V" | "M" | "m"));
    if text_dtype || obj.is_instance_of::<PyString>() || obj.is_instance_of::<PyBytes>() {
        return Err(PyTypeError::new_err(format!("expected a number, got {}", type_name(obj))));
    }
    obj.extract()
}

/// [`real`] for an optional argument: `None` is `None`.
pub fn real_opt(obj: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    if obj.is_none() {
        Ok(None)
    } else {
        real(obj).map(Some)
    }
}

/// Publish the accepted names of option `T` in `_core.OPTIONS`, keyed by `key` (the
/// option's type name), so Python reads the one list instead of keeping its own.
pub fn register_choices<T: Choice>(m: &Bound<'_, PyModule>, key: &str) -> PyResult<()> {
    m.getattr("OPTIONS")?.cast_into::<PyDict>()?.set_item(key, T::names())
}

/// An integer argument (count, size, index) checked against [min, max] before anything is
/// sized from it: a non-integer is a `TypeError` naming `field`, an integer out of range
/// (including one too large for 64 bits) an `InputError` naming `field`.
pub fn count(obj: &Bound<'_, PyAny>, field: &str, min: usize, max: usize) -> PyResult<usize> {
    if !obj.is_instance_of::<PyInt>() || obj.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!("{field}: expected an int, got {}", type_name(obj))));
    }
    let n: i128 = match obj.extract::<i64>() {
        Ok(n) => n.into(),
        Err(_) => i128::MAX,
    };
    match usize::try_from(n) {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ => Err(invalid(field, format!("must be an integer in [{min}, {max}], got {obj}")).into()),
    }
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type().name().map_or_else(|_| "object".to_string(), |n| n.to_string())
}

/// A 2-D float array as a DMatrix, checked for NaN/inf (names the first bad row).
// invariant: a 2-D array's shape has 2 entries and (i, j) < shape.
#[allow(clippy::indexing_slicing)]
pub fn mat(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<DMatrix<f64>, NavError> {
    let s = a.shape();
    let v = a.as_array();
    if let Some(((i, j), x)) = v.indexed_iter().find(|(_, x)| !x.is_finite()) {
        return Err(invalid_at(field, i, format!("non-finite value {x} at index ({i}, {j})")));
    }
    Ok(DMatrix::from_fn(s[0], s[1], |i, j| v[(i, j)]))
}

/// Any nalgebra matrix as a 2-D numpy array (row-major copy).
pub fn mat_to_py<'py, R: Dim, C: Dim, S: RawStorage<f64, R, C>>(py: Python<'py>, m: &Matrix<f64, R, C, S>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}

/// The rows of an (N, W) float array, checked for shape and NaN/inf.
// invariant: a 2-D array's shape has 2 entries; rows have W columns (checked
// above), so every chunk converts to [f64; W] and j < W.
#[allow(clippy::indexing_slicing, clippy::expect_used)]
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
                        return Err(invalid_at(field, i, format!("non-finite value {x} at index {i} (column {j})")));
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

/// A (3, 3) array as a matrix; another shape names `field`.
pub fn mat3(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<crate::math::Mat3, NavError> {
    let r = rows::<3>(a, field)?;
    match r.as_slice() {
        [x, y, z] => Ok(crate::math::Mat3::new(x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2])),
        _ => Err(crate::error::invalid(field, format!("expected (3, 3), got ({}, 3)", r.len()))),
    }
}

/// A length-3 vector argument.
// invariant: v has 3 elements (checked above).
#[allow(clippy::indexing_slicing)]
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
// invariant: callers pass n·w values (rows_to_py streams n rows of w).
#[allow(clippy::expect_used)]
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

/// A sequence of counts (averaging factors, sizes), each checked like [`count`]: an
/// element out of [min, max] (including -1 or 2**64) is an `InputError` naming `field`
/// and its index; a non-integer a `TypeError`.
pub fn counts(obj: &Bound<'_, PyAny>, field: &str, min: usize, max: usize) -> PyResult<Vec<usize>> {
    let items: Vec<Bound<'_, PyAny>> =
        obj.extract().map_err(|_| PyTypeError::new_err(format!("{field}: expected a sequence of ints, got {}", type_name(obj))))?;
    items
        .iter()
        .enumerate()
        .map(|(i, x)| {
            index_count(x, field, min, max).map_err(|e| match e.is_instance_of::<PyTypeError>(x.py()) {
                true => e,
                false => invalid_at(field, i, format!("element {i} must be an integer in [{min}, {max}], got {x}")).into(),
            })
        })
        .collect()
}

/// [`count`] of any integer-like object (`int`, numpy integers: whatever has
/// `__index__`, but not `bool`), over the whole range of `usize`.
pub fn index_count(obj: &Bound<'_, PyAny>, field: &str, min: usize, max: usize) -> PyResult<usize> {
    let index = match obj.is_instance_of::<PyBool>() {
        true => None,
        false => obj.call_method0("__index__").ok(),
    };
    let Some(index) = index else {
        return count(obj, field, min, max); // the TypeError naming `field`
    };
    match index.extract::<u64>().ok().and_then(|n| usize::try_from(n).ok()) {
        Some(n) if (min..=max).contains(&n) => Ok(n),
        _ => Err(invalid(field, format!("must be an integer in [{min}, {max}], got {obj}")).into()),
    }
}

/// `N` flags (a sequence of bools): another type is a `TypeError` naming `field`, another
/// length an `InputError` naming it (not pyo3's own `ValueError`).
pub fn flags<const N: usize>(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[bool; N]> {
    let items: Vec<bool> = obj
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{field}: expected a sequence of {N} bools, got {}", type_name(obj))))?;
    let n = items.len();
    items.try_into().map_err(|_| invalid(field, format!("expected {N} flags, got {n}")).into())
}

/// A random seed: any integer in [0, 2⁶⁴ − 1]; others are an `InputError` naming `field`
/// (not an `OverflowError`), a non-integer a `TypeError`.
pub fn seed(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<u64> {
    if !obj.is_instance_of::<PyInt>() || obj.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!("{field}: expected an int, got {}", type_name(obj))));
    }
    obj.extract::<u64>().map_err(|_| invalid(field, format!("must be an integer in [0, 2**64), got {obj}")).into())
}

/// Named numbers (constants, fitted parameters) into a dict.
pub fn set_floats(d: &Bound<'_, PyDict>, items: &[(&str, f64)]) -> PyResult<()> {
    items.iter().try_for_each(|(k, v)| d.set_item(*k, *v))
}

/// Call `f(key, value)` for every item of a dict with `str` keys (a non-str key is a
/// `TypeError` naming `field`).
pub fn each_item<'py>(d: &Bound<'py, PyDict>, field: &str, mut f: impl FnMut(&str, Bound<'py, PyAny>) -> PyResult<()>) -> PyResult<()> {
    for (k, v) in d.iter() {
        let key: PyBackedStr = k.extract().map_err(|_| PyTypeError::new_err(format!("{field}: keys must be str, got {}", type_name(&k))))?;
        f(&key, v)?;
    }
    Ok(())
}

/// The (R, C) blocks of an (N, R, C) array, checked for shape and NaN/inf (naming the
/// first bad block).
// invariant: a 3-D array's shape has 3 entries, (s[1], s[2]) = (R, C) checked
// above, so [i, r, c] < shape.
#[allow(clippy::indexing_slicing)]
pub fn mats<const R: usize, const C: usize>(a: &numpy::PyReadonlyArray3<'_, f64>, field: &str) -> Result<Vec<nalgebra::SMatrix<f64, R, C>>, NavError> {
    let s = a.shape();
    if s[1] != R || s[2] != C {
        return Err(invalid(field, format!("expected shape (N, {R}, {C}), got ({}, {}, {})", s[0], s[1], s[2])));
    }
    let v = a.as_array();
    (0..s[0])
        .map(|i| {
            let m = nalgebra::SMatrix::<f64, R, C>::from_fn(|r, c| v[[i, r, c]]);
            match m.iter().find(|x| !x.is_finite()) {
                None => Ok(m),
                Some(x) => Err(invalid_at(field, i, format!("non-finite value {x} at index {i}"))),
            }
        })
        .collect()
}

/// A stack of (R, C) matrices as an (N, R, C) array.
// invariant: i < m.len() and (r, c) < (R, C) by the shape given to from_shape_fn.
#[allow(clippy::indexing_slicing)]
pub fn mats_to_py<'py, const R: usize, const C: usize>(py: Python<'py>, m: &[nalgebra::SMatrix<f64, R, C>]) -> Bound<'py, numpy::PyArray3<f64>> {
    numpy::ndarray::Array3::from_shape_fn((m.len(), R, C), |(i, r, c)| m[i][(r, c)]).into_pyarray(py)
}
