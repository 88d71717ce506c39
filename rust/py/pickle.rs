//! Pickle and deepcopy of the core objects: `__reduce__` returns `_from_state` and the
//! object's saved state (`crate::state`: whole, every f64 bit for bit), so a copy continues
//! exactly like the original. A class whose one field holds a serde-serialisable core value
//! becomes picklable with `picklable!(Class, field, "PythonName")`.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use serde::{de::DeserializeOwned, Serialize};

/// `(type(obj)._from_state, (bytes,))`: what `__reduce__` returns for `obj`, whose core
/// state is `state`, saved under the class's name.
pub fn reduce<'py, T: Serialize>(obj: &Bound<'py, PyAny>, state: &T) -> PyResult<Bound<'py, PyTuple>> {
    let py = obj.py();
    let class = obj.get_type();
    let bytes = crate::state::save(&class.qualname()?.to_string(), state)?;
    let restore = class.getattr("_from_state")?;
    PyTuple::new(py, [restore, PyTuple::new(py, [PyBytes::new(py, &bytes)])?.into_any()])
}

/// The state saved by [`reduce`] for class `class`.
pub fn restore<T: DeserializeOwned>(class: &str, bytes: &[u8]) -> PyResult<T> {
    Ok(crate::state::load(class, bytes)?)
}

/// `__reduce__` and `_from_state` for pyclass `$class`, whose field `$field` (a name, or 0
/// for a tuple struct) is the whole state; `$name` is the class name Python sees. With
/// `locked`, the field is a `Mutex` taken by `shared::lock` (the state is read whole,
/// never half way through another thread's call). With `self` in place of the field, the
/// (frozen) pyclass derives serde itself: a binding object of several checked fields.
macro_rules! picklable {
    ($class:ident, self, $name:literal) => {
        #[pyo3::pymethods]
        impl $class {
            /// Pickle and deepcopy: the whole state, so a copy behaves bit for bit like
            /// this object.
            fn __reduce__<'py>(slf: &pyo3::Bound<'py, Self>) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyTuple>> {
                $crate::py::pickle::reduce(slf.as_any(), slf.get())
            }

            /// The object saved by `__reduce__`.
            #[staticmethod]
            fn _from_state(state: &[u8]) -> pyo3::PyResult<Self> {
                $crate::py::pickle::restore($name, state)
            }
        }
    };
    ($class:ident, $field:tt, $name:literal, locked) => {
        #[pyo3::pymethods]
        impl $class {
            /// Pickle and deepcopy: the whole state, so a copy continues bit for bit like
            /// this object.
            fn __reduce__<'py>(slf: &pyo3::Bound<'py, Self>) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyTuple>> {
                let this = slf.borrow();
                let state = $crate::py::shared::lock(slf.py(), &this.$field);
                $crate::py::pickle::reduce(slf.as_any(), &*state)
            }

            /// The object saved by `__reduce__`.
            #[staticmethod]
            fn _from_state(state: &[u8]) -> pyo3::PyResult<Self> {
                Ok($class { $field: std::sync::Mutex::new($crate::py::pickle::restore($name, state)?) })
            }
        }
    };
    ($class:ident, $field:tt, $name:literal) => {
        #[pyo3::pymethods]
        impl $class {
            /// Pickle and deepcopy: the whole state, so a copy continues bit for bit like
            /// this object.
            fn __reduce__<'py>(slf: &pyo3::Bound<'py, Self>) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyTuple>> {
                $crate::py::pickle::reduce(slf.as_any(), &slf.borrow().$field)
            }

            /// The object saved by `__reduce__`.
            #[staticmethod]
            fn _from_state(state: &[u8]) -> pyo3::PyResult<Self> {
                Ok($class { $field: $crate::py::pickle::restore($name, state)? })
            }
        }
    };
}
pub(crate) use picklable;
