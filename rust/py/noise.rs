//! Bindings of noise/: Allan family (batch, streaming, EDF, five-term fit), time
//! variance and time interval error, NNLS, ARIMA
//! state space and the Kalman filters (batch, streaming, steady state).

use super::convert::{counts, flags, flat_to_py, index_count, mat, mat_to_py, real, real_opt, register_choices, set_floats, vec_to_py, vector, Wrap};
use crate::error::invalid;
use crate::noise::allan::{self, AllanResult, AllanStream, DataType, Kind, NoiseType, TauGrid, TauSet};
use crate::noise::arma_filter::{self, Adaptive, ArimaStateSpace, ArmaFilterConfig, FilterOutput, Kalman, NoiseForm, X0, MAX_DIM};
use crate::noise::nnls::nnls;
use crate::noise::time_error;
use nalgebra::DVector;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Arr<'py> = Bound<'py, PyArray1<f64>>;
type AllanArrays<'py> = (Bound<'py, PyArray1<usize>>, Arr<'py>, Arr<'py>, Bound<'py, PyArray1<usize>>, usize);

fn result_to_py<'py>(py: Python<'py>, r: AllanResult) -> AllanArrays<'py> {
    (r.m.into_pyarray(py), r.tau.into_pyarray(py), r.var.into_pyarray(py), r.n.into_pyarray(py), r.missing)
}

/// Allan-family variance at the named τ grid `set`, or at the factors `m` when given:
/// returns (m, tau_s, var, n_terms, missing samples).
#[pyfunction]
#[pyo3(signature = (data, tau0, data_type=Wrap(DataType::Rate), kind=Wrap(Kind::Allan), set=Wrap(TauGrid::Octave), m=None))]
fn allan_var<'py>(
    py: Python<'py>,
    data: PyReadonlyArray1<'py, f64>,
    #[pyo3(from_py_with = real)] tau0: f64,
    data_type: Wrap<DataType>,
    kind: Wrap<Kind>,
    set: Wrap<TauGrid>,
    m: Option<Bound<'py, PyAny>>,
) -> PyResult<AllanArrays<'py>> {
    let ts = tau_set(set, m)?;
    let x = data.as_slice().map_err(|_| invalid("data", "array must be C-contiguous"))?;
    let r = py.detach(|| allan::variance(x, tau0, data_type.0, kind.0, &ts))?;
    Ok(result_to_py(py, r))
}

/// The τ set of a binding: the factors `m` when given, else the named grid `set`.
fn tau_set(set: Wrap<TauGrid>, m: Option<Bound<'_, PyAny>>) -> PyResult<TauSet> {
    Ok(match m {
        Some(m) => TauSet::List(counts(&m, "m", 1, usize::MAX)?),
        None => set.0.into(),
    })
}

/// Time variance τ²/3 · MVAR at the named τ grid `set`, or at the factors `m`:
/// returns (m, tau_s, var, n_terms, missing samples).
#[pyfunction]
#[pyo3(signature = (data, tau0, data_type=Wrap(DataType::Phase), set=Wrap(TauGrid::Octave), m=None))]
fn time_var<'py>(py: Python<'py>, data: PyReadonlyArray1<'py, f64>, #[pyo3(from_py_with = real)] tau0: f64, data_type: Wrap<DataType>, set: Wrap<TauGrid>, m: Option<Bound<'py, PyAny>>) -> PyResult<AllanArrays<'py>> {
    let ts = tau_set(set, m)?;
    let x = data.as_slice().map_err(|_| invalid("data", "array must be C-contiguous"))?;
    let r = py.detach(|| allan::time_variance(x, tau0, data_type.0, &ts))?;
    Ok(result_to_py(py, r))
}

/// MTIE and TIE rms of phase data at the named τ grid `set`, or at the factors `m`:
/// returns (m, tau_s, mtie, tie_rms, n_windows).
#[pyfunction]
#[pyo3(signature = (data, tau0, set=Wrap(TauGrid::Octave), m=None))]
#[allow(clippy::type_complexity)]
fn time_interval_error<'py>(py: Python<'py>, data: PyReadonlyArray1<'py, f64>, #[pyo3(from_py_with = real)] tau0: f64, set: Wrap<TauGrid>, m: Option<Bound<'py, PyAny>>) -> PyResult<(Bound<'py, PyArray1<usize>>, Arr<'py>, Arr<'py>, Arr<'py>, Bound<'py, PyArray1<usize>>)> {
    let ts = tau_set(set, m)?;
    let x = data.as_slice().map_err(|_| invalid("data", "array must be C-contiguous"))?;
    let r = py.detach(|| time_error::time_interval_error(x, tau0, &ts))?;
    Ok((r.m.into_pyarray(py), r.tau.into_pyarray(py), r.mtie.into_pyarray(py), r.tie_rms.into_pyarray(py), r.n.into_pyarray(py)))
}

/// Equivalent degrees of freedom per averaging factor (`np` phase points).
#[pyfunction]
fn allan_edf<'py>(py: Python<'py>, kind: Wrap<Kind>, noise: Wrap<NoiseType>, np: &Bound<'py, PyAny>, m: &Bound<'py, PyAny>) -> PyResult<Arr<'py>> {
    let np = index_count(np, "np", 2, usize::MAX)?;
    Ok(vec_to_py(py, allan::edf(kind.0, noise.0, np, &counts(m, "m", 1, usize::MAX)?)?))
}

/// Five-term fit; returns a dict of coefficients and derived parameters.
#[pyfunction]
#[pyo3(signature = (m, tau, var, n_samples, terms, tau_min, tau_max))]
#[allow(clippy::too_many_arguments)]
fn allan_fit<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyAny>,
    tau: PyReadonlyArray1<'py, f64>,
    var: PyReadonlyArray1<'py, f64>,
    n_samples: &Bound<'py, PyAny>,
    terms: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = real)] tau_min: f64,
    #[pyo3(from_py_with = real)] tau_max: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let m = counts(m, "m", 1, usize::MAX)?;
    let n = vec![0; m.len()];
    let res = AllanResult { m, tau: vector(&tau, "tau")?, var: vector(&var, "var")?, n, missing: 0 };
    let f = allan::fit(&res, index_count(n_samples, "n_samples", 1, usize::MAX)?, flags(terms, "terms")?, tau_min, tau_max)?;
    let d = PyDict::new(py);
    d.set_item("coeffs", f.coeffs.to_vec())?;
    set_floats(&d, &f.parameters())?;
    d.set_item("points", f.points)?;
    Ok(d)
}

/// Lawson–Hanson non-negative least squares (for parity checks against scipy).
#[pyfunction]
fn nnls_solve<'py>(py: Python<'py>, a: PyReadonlyArray2<'py, f64>, b: PyReadonlyArray1<'py, f64>) -> PyResult<Arr<'py>> {
    let am = mat(&a, "a")?;
    let bv = DVector::from_vec(vector(&b, "b")?);
    if bv.len() != am.nrows() {
        return Err(invalid("b", format!("length {} does not match the {} rows of a", bv.len(), am.nrows())).into());
    }
    Ok(vec_to_py(py, nnls(&am, &bv)?.iter().copied().collect()))
}

/// Streaming Allan, modified Allan and Hadamard variance at fixed averaging factors.
#[pyclass(name = "AllanStream", module = "atomnav._core")]
struct PyAllanStream(AllanStream);
super::pickle::picklable!(PyAllanStream, 0, "AllanStream");

#[pymethods]
impl PyAllanStream {
    #[new]
    #[pyo3(signature = (m, tau0, data_type=Wrap(DataType::Rate)))]
    fn new(m: &Bound<'_, PyAny>, #[pyo3(from_py_with = real)] tau0: f64, data_type: Wrap<DataType>) -> PyResult<Self> {
        Ok(PyAllanStream(AllanStream::new(&counts(m, "m", 1, usize::MAX)?, tau0, data_type.0)?))
    }

    fn update(&mut self, py: Python<'_>, chunk: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        let c: Vec<f64> = chunk.as_array().iter().copied().collect();
        let s = &mut self.0;
        Ok(py.detach(|| s.update(&c))?)
    }

    fn result<'py>(&self, py: Python<'py>, kind: Wrap<Kind>) -> PyResult<AllanArrays<'py>> {
        Ok(result_to_py(py, self.0.result(kind.0)?))
    }
}

/// The differencing order (1 when not given), at most the filter's largest state.
fn order(d: Option<Bound<'_, PyAny>>) -> PyResult<usize> {
    Ok(d.map(|d| index_count(&d, "d", 0, MAX_DIM)).transpose()?.unwrap_or(1))
}

/// Φ, B, Q and BQBᵀ of an ARIMA(p,d,q) state-space model.
#[pyfunction]
#[pyo3(signature = (ar, ma, sigma2, d=None, noise_form=Wrap(NoiseForm::Paper)))]
fn arima_state_space<'py>(py: Python<'py>, ar: Vec<f64>, ma: Vec<f64>, #[pyo3(from_py_with = real)] sigma2: f64, d: Option<Bound<'py, PyAny>>, noise_form: Wrap<NoiseForm>) -> PyResult<Bound<'py, PyDict>> {
    let s = ArimaStateSpace::from_arma(&ar, &ma, sigma2, order(d)?, noise_form.0)?;
    let out = PyDict::new(py);
    out.set_item("phi", mat_to_py(py, &s.phi))?;
    out.set_item("b", mat_to_py(py, &s.b))?;
    out.set_item("q", mat_to_py(py, &s.q))?;
    out.set_item("qd", mat_to_py(py, &s.qd))?;
    Ok(out)
}

/// The frozen configuration of an ARMA Kalman filter (`noise::arma_filter::ArmaFilterConfig`),
/// checked when built; Python's `atomnav.noise.filters.ArmaFilterConfig` mirrors it.
#[pyclass(name = "ArmaFilterConfig", module = "atomnav._core", frozen)]
struct PyArmaFilterConfig(ArmaFilterConfig);
super::pickle::picklable!(PyArmaFilterConfig, 0, "ArmaFilterConfig");

#[pymethods]
impl PyArmaFilterConfig {
    #[new]
    #[pyo3(signature = (*, ar, ma, sigma2, d=None, noise_form=Wrap(NoiseForm::Paper), r0=None, adaptive=Wrap(Adaptive::Fixed), b=0.98, adapt_q=false, fading=false, x0=Wrap(X0::Zeros), p0=1.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        ar: Vec<f64>,
        ma: Vec<f64>,
        #[pyo3(from_py_with = real)] sigma2: f64,
        d: Option<Bound<'_, PyAny>>,
        noise_form: Wrap<NoiseForm>,
        #[pyo3(from_py_with = real_opt)] r0: Option<f64>,
        adaptive: Wrap<Adaptive>,
        #[pyo3(from_py_with = real)] b: f64,
        adapt_q: bool,
        fading: bool,
        x0: Wrap<X0>,
        #[pyo3(from_py_with = real)] p0: f64,
    ) -> PyResult<Self> {
        let d = order(d)?;
        let c = ArmaFilterConfig { ar, ma, sigma2, d, noise_form: noise_form.0, r0, adaptive: adaptive.0, b, adapt_q, fading, x0: x0.0, p0 };
        c.build(false)?;
        Ok(Self(c))
    }
}

type FilterArrays<'py> = (Arr<'py>, Arr<'py>, Bound<'py, PyArray2<f64>>, Arr<'py>);

fn output_to_py<'py>(py: Python<'py>, out: FilterOutput, n: usize) -> FilterArrays<'py> {
    let rows = out.gain.len() / n;
    (out.xhat.into_pyarray(py), out.r.into_pyarray(py), flat_to_py(py, rows, n, out.gain), out.var.into_pyarray(py))
}

/// Batch Kalman filter; returns (ω̂, R history, gain history (N, n), posterior variance of
/// ω̂); histories are empty unless `record`.
#[pyfunction]
#[pyo3(signature = (omega, config, *, record=true))]
fn kalman_filter<'py>(py: Python<'py>, omega: PyReadonlyArray1<'py, f64>, config: PyRef<'py, PyArmaFilterConfig>, record: bool) -> PyResult<FilterArrays<'py>> {
    let w = omega.as_slice().map_err(|_| invalid("omega", "array must be C-contiguous"))?;
    let c = &config.0;
    let (out, n) = py.detach(|| c.filter(w, record))?;
    Ok(output_to_py(py, out, n))
}

/// Streaming Kalman filter: feed chunks, get the filtered chunk back.
#[pyclass(name = "KalmanStream", module = "atomnav._core")]
struct PyKalmanStream(Kalman);
super::pickle::picklable!(PyKalmanStream, 0, "KalmanStream");

#[pymethods]
impl PyKalmanStream {
    #[new]
    #[pyo3(signature = (config, *, record=true))]
    fn new(config: PyRef<'_, PyArmaFilterConfig>, record: bool) -> PyResult<Self> {
        Ok(PyKalmanStream(config.0.build(record)?))
    }

    fn update<'py>(&mut self, py: Python<'py>, chunk: PyReadonlyArray1<'py, f64>) -> PyResult<FilterArrays<'py>> {
        let c: Vec<f64> = chunk.as_array().iter().copied().collect();
        let f = &mut self.0;
        let mut out = FilterOutput::default();
        py.detach(|| f.update(&c, &mut out))?;
        Ok(output_to_py(py, out, self.0.dim()))
    }
}

/// Steady-state gain K∞, P⁻∞ and P⁺∞ of the fixed filter for measurement variance r.
#[pyfunction]
#[pyo3(signature = (ar, ma, sigma2, r, d=None, noise_form=Wrap(NoiseForm::Paper)))]
#[allow(clippy::type_complexity)]
fn steady_state_gain<'py>(py: Python<'py>, ar: Vec<f64>, ma: Vec<f64>, #[pyo3(from_py_with = real)] sigma2: f64, #[pyo3(from_py_with = real)] r: f64, d: Option<Bound<'py, PyAny>>, noise_form: Wrap<NoiseForm>) -> PyResult<(Arr<'py>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    let s = ArimaStateSpace::from_arma(&ar, &ma, sigma2, order(d)?, noise_form.0)?;
    let (k, pm, pp) = arma_filter::steady_state(&s, r)?;
    Ok((vec_to_py(py, k), mat_to_py(py, &pm), mat_to_py(py, &pp)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    register_choices::<Kind>(m, "AllanKind")?;
    register_choices::<DataType>(m, "DataType")?;
    register_choices::<NoiseType>(m, "NoiseType")?;
    register_choices::<TauGrid>(m, "TauGrid")?;
    register_choices::<NoiseForm>(m, "NoiseForm")?;
    register_choices::<Adaptive>(m, "Adaptive")?;
    register_choices::<X0>(m, "X0")?;
    m.add_function(wrap_pyfunction!(allan_var, m)?)?;
    m.add_function(wrap_pyfunction!(allan_edf, m)?)?;
    m.add_function(wrap_pyfunction!(time_var, m)?)?;
    m.add_function(wrap_pyfunction!(time_interval_error, m)?)?;
    m.add_function(wrap_pyfunction!(allan_fit, m)?)?;
    m.add_function(wrap_pyfunction!(nnls_solve, m)?)?;
    m.add_function(wrap_pyfunction!(arima_state_space, m)?)?;
    m.add_function(wrap_pyfunction!(kalman_filter, m)?)?;
    m.add_function(wrap_pyfunction!(steady_state_gain, m)?)?;
    m.add_class::<PyAllanStream>()?;
    m.add_class::<PyArmaFilterConfig>()?;
    m.add_class::<PyKalmanStream>()?;
    Ok(())
}
