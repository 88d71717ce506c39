//! pyo3 bindings only: numpy in/out, error mapping, GIL release. No algorithms here.

use pyo3::prelude::*;

mod alignment;
mod astro;
mod cai;
mod constraints;
mod convert;
mod earth;
mod filter;
mod gnss;
mod imu;
mod kalman;
mod noise;
mod pickle;
mod rinex;
mod shared;
mod sources;
mod rotation;
mod strapdown;
mod trajectory;

pyo3::create_exception!(
    _core,
    InputError,
    pyo3::exceptions::PyValueError,
    "An invalid argument. `parameter` names it; for array input `index` is the first offending row (None otherwise)."
);

pyo3::create_exception!(
    _core,
    NumericalError,
    pyo3::exceptions::PyArithmeticError,
    "A computation failed on valid input (covariance lost positive definiteness, divergence)."
);

/// The unit factors of `units.rs` as a dict, so Python has no second copy of them.
#[pyfunction]
fn unit_constants(py: Python<'_>) -> PyResult<Py<PyAny>> {
    use crate::units::UNITS;
    let d = pyo3::types::PyDict::new(py);
    convert::set_floats(&d, &UNITS)?;
    Ok(d.into_any().unbind())
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let input_error = m.py().get_type::<InputError>();
    input_error.setattr("parameter", m.py().None())?;
    input_error.setattr("index", m.py().None())?;
    m.add("InputError", input_error)?;
    m.add("NumericalError", m.py().get_type::<NumericalError>())?;
    m.add("OPTIONS", pyo3::types::PyDict::new(m.py()))?;
    convert::register_choices::<crate::earth::Ellipsoid>(m, "Ellipsoid")?;
    convert::register_choices::<crate::earth::Helmert>(m, "Helmert")?;
    convert::register_choices::<crate::imu::ImuKind>(m, "ImuKind")?;
    m.add_function(wrap_pyfunction!(unit_constants, m)?)?;
    rotation::register(m)?;
    astro::register(m)?;
    earth::register(m)?;
    imu::register(m)?;
    trajectory::register(m)?;
    strapdown::register(m)?;
    cai::register(m)?;
    noise::register(m)?;
    filter::register(m)?;
    kalman::register(m)?;
    gnss::register(m)?;
    rinex::register(m)?;
    sources::register(m)?;
    alignment::register(m)?;
    constraints::register(m)?;
    Ok(())
}
