//! Pickle and deepcopy of the stateful core objects: the object's whole state as bytes
//! (postcard, every f64 bit for bit), so a copy continues exactly like the original. A
//! class whose one field holds a serde-serialisable core value becomes picklable with
//! `picklable!(Class, field, "PythonName")`, which adds `__reduce__` (built by [`reduce`])
//! and a static `_from_state` (by [`restore`]).

use crate::error::invalid;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use serde::{de::DeserializeOwned, Serialize};

/// Format version of the state bytes: a pickle from another version is an `InputError`
/// rather than a misread state.
const VERSION: u32 = 1;

/// `(type(obj)._from_state, (bytes,))`: what `__reduce__` returns for `obj`, whose core
/// state is `state`, tagged with the class name and the format version.
pub fn reduce<'py, T: Serialize>(obj: &Bound<'py, PyAny>, state: &T) -> PyResult<Bound<'py, PyTuple>> {
    let py = obj.py();
    let class = obj.get_type();
    let tag = class.qualname()?.to_string();
    let bytes = postcard::to_stdvec(&(VERSION, tag.as_str(), state)).map_err(|e| invalid("state", format!("cannot be saved: {e}")))?;
    let restore = class.getattr("_from_state")?;
    PyTuple::new(py, [restore, PyTuple::new(py, [PyBytes::new(py, &bytes)])?.into_any()])
}

/// The state saved by [`reduce`] for class `class`; bytes of another class or version, or
/// not a state at all, are an `InputError` naming `state`.
pub fn restore<T: DeserializeOwned>(class: &str, bytes: &[u8]) -> PyResult<T> {
    let not_a_state = |e: postcard::Error| invalid("state", format!("not a saved {class} state ({e})"));
    // the tuple (version, tag, state) is the concatenation of its parts: read the header first
    let ((version, tag), rest): ((u32, String), &[u8]) = postcard::take_from_bytes(bytes).map_err(not_a_state)?;
    if version != VERSION || tag != class {
        return Err(invalid("state", format!("a saved {tag} state of format {version}, expected {class} of format {VERSION}")).into());
    }
    Ok(postcard::from_bytes(rest).map_err(not_a_state)?)
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
