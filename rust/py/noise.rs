//! Bindings of noise/: Allan family (batch, streaming, EDF, five-term fit), NNLS, ARIMA
//! state space and the Kalman filters (batch, streaming, steady state).

use super::convert::{mat_to_py, vec_to_py, vector};
use crate::error::invalid;
use crate::noise::allan::{self, AllanResult, AllanStream, DataType, Kind, NoiseType, TauSet};
use crate::noise::arma_filter::{self, ArimaStateSpace, FilterOutput, Kalman, NoiseForm, RMode, X0};
use crate::noise::nnls::nnls;
use nalgebra::{DMatrix, DVector};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Arr<'py> = Bound<'py, PyArray1<f64>>;

fn tau_set(set: &str, m: Option<Vec<usize>>) -> PyResult<TauSet> {
    Ok(match (set, m) {
        (_, Some(m)) => TauSet::List(m),
        ("octave", None) => TauSet::Octave,
        ("decade", None) => TauSet::Decade,
        ("all", None) => TauSet::All,
        (other, None) => return Err(invalid("m", format!("unknown τ set {other:?}; choose octave, decade, all or give a list")).into()),
    })
}

fn result_to_py<'py>(py: Python<'py>, r: AllanResult) -> (Bound<'py, PyArray1<usize>>, Arr<'py>, Arr<'py>, Bound<'py, PyArray1<usize>>) {
    (r.m.into_pyarray(py), r.tau.into_pyarray(py), r.var.into_pyarray(py), r.n.into_pyarray(py))
}

/// Allan-family variance: returns (m, tau_s, var, n_terms).
#[pyfunction]
#[pyo3(signature = (data, tau0, data_type="rate", kind="allan", set="octave", m=None))]
#[allow(clippy::type_complexity)]
fn allan_var<'py>(
    py: Python<'py>,
    data: PyReadonlyArray1<'py, f64>,
    tau0: f64,
    data_type: &str,
    kind: &str,
    set: &str,
    m: Option<Vec<usize>>,
) -> PyResult<(Bound<'py, PyArray1<usize>>, Arr<'py>, Arr<'py>, Bound<'py, PyArray1<usize>>)> {
    let (dt, k, ts) = (DataType::by_name(data_type)?, Kind::by_name(kind)?, tau_set(set, m)?);
    let x = data.as_slice().map_err(|_| invalid("data", "array must be C-contiguous"))?;
    let r = py.detach(|| allan::variance(x, tau0, dt, k, &ts))?;
    Ok(result_to_py(py, r))
}

/// Equivalent degrees of freedom per averaging factor (`np` phase points).
#[pyfunction]
fn allan_edf<'py>(py: Python<'py>, kind: &str, noise: &str, np: usize, m: Vec<usize>) -> PyResult<Arr<'py>> {
    let (k, nt) = (Kind::by_name(kind)?, NoiseType::by_name(noise)?);
    let e: Vec<f64> = m
        .iter()
        .map(|&mj| if k == Kind::Allan { allan::edf_overlapping_allan(nt, np, mj) } else { allan::edf_non_overlapping(k, np, mj) })
        .collect();
    Ok(vec_to_py(py, e))
}

/// Five-term fit; returns a dict of coefficients and derived parameters.
#[pyfunction]
#[pyo3(signature = (m, tau, var, n_samples, terms, tau_min, tau_max))]
#[allow(clippy::too_many_arguments)]
fn allan_fit<'py>(
    py: Python<'py>,
    m: Vec<usize>,
    tau: PyReadonlyArray1<'py, f64>,
    var: PyReadonlyArray1<'py, f64>,
    n_samples: usize,
    terms: [bool; 5],
    tau_min: f64,
    tau_max: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (tau, var) = (vector(&tau, "tau")?, vector(&var, "var")?);
    if tau.len() != m.len() || var.len() != m.len() {
        return Err(invalid("var", format!("m, tau and var must have equal lengths ({}, {}, {})", m.len(), tau.len(), var.len())).into());
    }
    let n = vec![0; m.len()];
    let f = allan::fit(&AllanResult { m, tau, var, n }, n_samples, terms, tau_min, tau_max)?;
    let d = PyDict::new(py);
    d.set_item("coeffs", f.coeffs.to_vec())?;
    for (k, v) in [("quantization", f.quantization), ("arw", f.arw), ("bias_instability", f.bias_instability), ("rrw", f.rrw), ("ramp", f.ramp)] {
        d.set_item(k, v)?;
    }
    d.set_item("points", f.points)?;
    Ok(d)
}

/// Lawson–Hanson non-negative least squares (for parity checks against scipy).
#[pyfunction]
fn nnls_solve<'py>(py: Python<'py>, a: PyReadonlyArray2<'py, f64>, b: PyReadonlyArray1<'py, f64>) -> PyResult<Arr<'py>> {
    let av = a.as_array();
    let am = DMatrix::from_fn(av.nrows(), av.ncols(), |i, j| av[(i, j)]);
    let bv = DVector::from_vec(vector(&b, "b")?);
    if bv.len() != am.nrows() {
        return Err(invalid("b", format!("length {} does not match the {} rows of a", bv.len(), am.nrows())).into());
    }
    Ok(vec_to_py(py, nnls(&am, &bv)?.iter().copied().collect()))
}

/// Streaming Allan, modified Allan and Hadamard variance at fixed averaging factors.
#[pyclass(name = "AllanStream", module = "atomnav._core")]
struct PyAllanStream(AllanStream);

#[pymethods]
impl PyAllanStream {
    #[new]
    #[pyo3(signature = (m, tau0, data_type="rate"))]
    fn new(m: Vec<usize>, tau0: f64, data_type: &str) -> PyResult<Self> {
        Ok(PyAllanStream(AllanStream::new(&m, tau0, DataType::by_name(data_type)?)?))
    }

    fn update(&mut self, py: Python<'_>, chunk: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        let c: Vec<f64> = chunk.as_array().iter().copied().collect();
        let s = &mut self.0;
        Ok(py.detach(|| s.update(&c))?)
    }

    #[allow(clippy::type_complexity)]
    fn result<'py>(&self, py: Python<'py>, kind: &str) -> PyResult<(Bound<'py, PyArray1<usize>>, Arr<'py>, Arr<'py>, Bound<'py, PyArray1<usize>>)> {
        Ok(result_to_py(py, self.0.result(Kind::by_name(kind)?)))
    }
}

fn model(ar: Vec<f64>, ma: Vec<f64>, sigma2: f64, d: usize, noise_form: &str) -> PyResult<ArimaStateSpace> {
    Ok(ArimaStateSpace::from_arma(&ar, &ma, sigma2, d, NoiseForm::by_name(noise_form)?)?)
}

/// Φ, B, Q and BQBᵀ of an ARIMA(p,d,q) state-space model.
#[pyfunction]
#[pyo3(signature = (ar, ma, sigma2, d=1, noise_form="paper"))]
fn arima_state_space<'py>(py: Python<'py>, ar: Vec<f64>, ma: Vec<f64>, sigma2: f64, d: usize, noise_form: &str) -> PyResult<Bound<'py, PyDict>> {
    let s = model(ar, ma, sigma2, d, noise_form)?;
    let out = PyDict::new(py);
    out.set_item("phi", mat_to_py(py, &s.phi))?;
    out.set_item("b", mat_to_py(py, &s.b))?;
    out.set_item("q", mat_to_py(py, &s.q))?;
    out.set_item("qd", mat_to_py(py, &s.qd))?;
    Ok(out)
}

struct FilterConfig {
    model: ArimaStateSpace,
    r0: f64,
    mode: RMode,
    x0: X0,
    p0: f64,
}

#[allow(clippy::too_many_arguments)]
fn filter_config(ar: Vec<f64>, ma: Vec<f64>, sigma2: f64, d: usize, noise_form: &str, r0: f64, mode: &str, b: f64, adapt_q: bool, fading: bool, x0: &str, p0: f64) -> PyResult<FilterConfig> {
    let x0 = match x0 {
        "zeros" => X0::Zeros,
        "first" => X0::First,
        other => return Err(invalid("x0", format!("unknown {other:?}; choose zeros or first")).into()),
    };
    Ok(FilterConfig { model: model(ar, ma, sigma2, d, noise_form)?, r0, mode: RMode::by_name(mode, b, adapt_q, fading)?, x0, p0 })
}

#[allow(clippy::type_complexity)]
fn output_to_py<'py>(py: Python<'py>, out: FilterOutput, n: usize) -> PyResult<(Arr<'py>, Arr<'py>, Bound<'py, PyArray2<f64>>)> {
    let rows = out.gain.len() / n;
    let gain = Array2::from_shape_vec((rows, n), out.gain).map_err(|e| invalid("gain", e.to_string()))?;
    Ok((out.xhat.into_pyarray(py), out.r.into_pyarray(py), gain.into_pyarray(py)))
}

/// Batch Kalman filter; returns (ω̂, R history, gain history (N, n)); histories are empty
/// unless `record`.
#[pyfunction]
#[pyo3(signature = (omega, ar, ma, sigma2, d=1, noise_form="paper", r0=None, mode="differenced", b=0.98, adapt_q=false, fading=false, x0="zeros", p0=1.0, record=true))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn kalman_filter<'py>(
    py: Python<'py>,
    omega: PyReadonlyArray1<'py, f64>,
    ar: Vec<f64>,
    ma: Vec<f64>,
    sigma2: f64,
    d: usize,
    noise_form: &str,
    r0: Option<f64>,
    mode: &str,
    b: f64,
    adapt_q: bool,
    fading: bool,
    x0: &str,
    p0: f64,
    record: bool,
) -> PyResult<(Arr<'py>, Arr<'py>, Bound<'py, PyArray2<f64>>)> {
    let c = filter_config(ar, ma, sigma2, d, noise_form, r0.unwrap_or(sigma2), mode, b, adapt_q, fading, x0, p0)?;
    let w = omega.as_slice().map_err(|_| invalid("omega", "array must be C-contiguous"))?;
    let out = py.detach(|| arma_filter::kalman(w, &c.model, c.r0, c.mode, c.x0, c.p0, record))?;
    output_to_py(py, out, c.model.dim())
}

/// Streaming Kalman filter: feed chunks, get the filtered chunk back.
#[pyclass(name = "KalmanStream", module = "atomnav._core")]
struct PyKalmanStream {
    filter: Kalman,
    n: usize,
}

#[pymethods]
impl PyKalmanStream {
    #[new]
    #[pyo3(signature = (ar, ma, sigma2, d=1, noise_form="paper", r0=None, mode="differenced", b=0.98, adapt_q=false, fading=false, x0="zeros", p0=1.0, record=true))]
    #[allow(clippy::too_many_arguments)]
    fn new(ar: Vec<f64>, ma: Vec<f64>, sigma2: f64, d: usize, noise_form: &str, r0: Option<f64>, mode: &str, b: f64, adapt_q: bool, fading: bool, x0: &str, p0: f64, record: bool) -> PyResult<Self> {
        let c = filter_config(ar, ma, sigma2, d, noise_form, r0.unwrap_or(sigma2), mode, b, adapt_q, fading, x0, p0)?;
        Ok(PyKalmanStream { filter: Kalman::new(&c.model, c.r0, c.mode, c.x0, c.p0, record)?, n: c.model.dim() })
    }

    #[allow(clippy::type_complexity)]
    fn update<'py>(&mut self, py: Python<'py>, chunk: PyReadonlyArray1<'py, f64>) -> PyResult<(Arr<'py>, Arr<'py>, Bound<'py, PyArray2<f64>>)> {
        let c: Vec<f64> = chunk.as_array().iter().copied().collect();
        let f = &mut self.filter;
        let mut out = FilterOutput::default();
        py.detach(|| f.update(&c, &mut out))?;
        output_to_py(py, out, self.n)
    }
}

/// Steady-state gain K∞, P⁻∞ and P⁺∞ of the fixed filter for measurement variance r.
#[pyfunction]
#[pyo3(signature = (ar, ma, sigma2, r, d=1, noise_form="paper"))]
#[allow(clippy::type_complexity)]
fn steady_state_gain<'py>(py: Python<'py>, ar: Vec<f64>, ma: Vec<f64>, sigma2: f64, r: f64, d: usize, noise_form: &str) -> PyResult<(Arr<'py>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    let s = model(ar, ma, sigma2, d, noise_form)?;
    let (k, pm, pp) = arma_filter::steady_state(&s, r)?;
    Ok((vec_to_py(py, k), mat_to_py(py, &pm), mat_to_py(py, &pp)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(allan_var, m)?)?;
    m.add_function(wrap_pyfunction!(allan_edf, m)?)?;
    m.add_function(wrap_pyfunction!(allan_fit, m)?)?;
    m.add_function(wrap_pyfunction!(nnls_solve, m)?)?;
    m.add_function(wrap_pyfunction!(arima_state_space, m)?)?;
    m.add_function(wrap_pyfunction!(kalman_filter, m)?)?;
    m.add_function(wrap_pyfunction!(steady_state_gain, m)?)?;
    m.add_class::<PyAllanStream>()?;
    m.add_class::<PyKalmanStream>()?;
    Ok(())
}
