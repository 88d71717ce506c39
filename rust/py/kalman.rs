//! Bindings of the linear Kalman machinery of filter/: DARE and Riccati recursion,
//! discretisation, the streaming Kalman filter, the RTS smoother and the covariance
//! analysis / Monte Carlo of a linearised scenario.

use super::convert::{count, counts, mat, mat_to_py, real, real_opt, register_choices, seed, vector, Wrap};
use super::filter::{mats, stack_to_py};
use crate::error::NavError;
use crate::filter::analysis::Scenario as CoreScenario;
use crate::filter::discretize::{discretize_checked, Discretization};
use crate::filter::kf::{rts as core_rts, stored_steps, Kf, LoopMode, UpdateForm};
use crate::filter::riccati;
use nalgebra::{DMatrix, DVector};
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use std::sync::Mutex;
use super::shared::lock;

/// Filter-form DARE (a-priori P⁻, a-posteriori P⁺, gain K, doubling iterations).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn dare<'py>(
    py: Python<'py>,
    phi: PyReadonlyArray2<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    h: PyReadonlyArray2<'py, f64>,
    r: PyReadonlyArray2<'py, f64>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, usize)> {
    let (phi, q, h, r) = (mat(&phi, "phi")?, mat(&q, "q")?, mat(&h, "h")?, mat(&r, "r")?);
    let s = py.detach(|| riccati::dare(&phi, &q, &h, &r))?;
    Ok((mat_to_py(py, &s.p_prior), mat_to_py(py, &s.p_post), mat_to_py(py, &s.gain), s.iterations))
}

/// Scalar closed forms for Φ = 1 (Tennstedt et al. 2021, Eqs. 32–35): (P⁻, P⁺).
#[pyfunction]
fn riccati_scalar(#[pyo3(from_py_with = real)] q: f64, #[pyo3(from_py_with = real)] r: f64, #[pyo3(from_py_with = real)] h: f64) -> PyResult<(f64, f64)> {
    Ok(riccati::scalar(q, r, h)?)
}

/// A row-major buffer of `rows` × `cols` values as a 2-D array (no copy).
fn flat_2d<'py>(py: Python<'py>, v: Vec<f64>, rows: usize, cols: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    PyArray1::from_vec(py, v).reshape([rows, cols])
}

/// Kalman covariance recursion from P⁻₀: (steps, n, n) a-priori and a-posteriori stacks.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn kalman_recursion<'py>(
    py: Python<'py>,
    phi: PyReadonlyArray2<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    h: PyReadonlyArray2<'py, f64>,
    r: PyReadonlyArray2<'py, f64>,
    p0: PyReadonlyArray2<'py, f64>,
    steps: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<f64>>)> {
    let steps = count(steps, "steps", 1, riccati::MAX_RECURSION_STEPS)?;
    let (phi, q, h, r, p0) = (mat(&phi, "phi")?, mat(&q, "q")?, mat(&h, "h")?, mat(&r, "r")?, mat(&p0, "p0")?);
    let rec = py.detach(|| riccati::recursion(&phi, &q, &h, &r, &p0, steps))?;
    let shape = [steps, rec.n, rec.n];
    Ok((PyArray1::from_vec(py, rec.prior).reshape(shape)?, PyArray1::from_vec(py, rec.post).reshape(shape)?))
}

pub(crate) fn rows_mat(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<Vec<DVector<f64>>, NavError> {
    let m = mat(a, field)?;
    Ok((0..m.nrows()).map(|k| m.row(k).transpose()).collect())
}

// invariant: callers pass vectors of n entries, k < v.len().
#[allow(clippy::indexing_slicing)]
pub(crate) fn vecs_to_py<'py>(py: Python<'py>, v: &[DVector<f64>], n: usize) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((v.len(), n), |(k, i)| v[k][i]).into_pyarray(py)
}

/// Van Loan (or first-order) discretisation: (Φ, Q_d).
#[pyfunction]
#[pyo3(signature = (f, qc, dt, method=Wrap(Discretization::VanLoan)))]
#[allow(clippy::type_complexity)]
fn discretize_model<'py>(
    py: Python<'py>,
    f: PyReadonlyArray2<'py, f64>,
    qc: PyReadonlyArray2<'py, f64>,
    #[pyo3(from_py_with = real)] dt: f64,
    method: Wrap<Discretization>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    let (f, qc) = (mat(&f, "f")?, mat(&qc, "qc")?);
    let (phi, qd) = discretize_checked(&f, &qc, dt, method.0)?;
    Ok((mat_to_py(py, &phi), mat_to_py(py, &qd)))
}

/// A 2-D float array as a DMatrix without the finiteness check of `mat`: the rows of a
/// missing measurement component may hold NaN, and `Kf::update` checks the others.
fn with_missing(a: &PyReadonlyArray2<'_, f64>) -> DMatrix<f64> {
    let (rows, cols) = a.as_array().dim();
    DMatrix::from_row_iterator(rows, cols, a.as_array().iter().copied())
}

/// Error-state Kalman filter (closed or open loop), streaming one call per step. Shared
/// between threads through a mutex (a per-step call from a Python loop: a Python-side
/// lock would cost 7 % of it).
#[pyclass(module = "atomnav._core", frozen)]
pub struct KalmanFilter {
    inner: Mutex<Kf>,
}
super::pickle::picklable!(KalmanFilter, inner, "KalmanFilter", locked);

#[pymethods]
impl KalmanFilter {
    #[new]
    #[pyo3(signature = (p0, *, x0=None, mode=Wrap(LoopMode::Closed), covariance_update=Wrap(UpdateForm::Joseph)))]
    fn new(p0: PyReadonlyArray2<'_, f64>, x0: Option<PyReadonlyArray1<'_, f64>>, mode: Wrap<LoopMode>, covariance_update: Wrap<UpdateForm>) -> PyResult<Self> {
        let mut kf = Kf::new(mat(&p0, "p0")?, mode.0)?.with_update_form(covariance_update.0);
        if let Some(x0) = x0 {
            kf = kf.with_state(&vector(&x0, "x0")?)?;
        }
        Ok(KalmanFilter { inner: Mutex::new(kf) })
    }

    fn predict(&self, py: Python<'_>, phi: PyReadonlyArray2<'_, f64>, qd: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let (phi, qd) = (mat(&phi, "phi")?, mat(&qd, "qd")?);
        Ok(lock(py, &self.inner).predict_many(&phi, &qd, 1)?)
    }

    /// `steps` predictions with the same (Φ, Q_d) in one call (the multirate / benchmark path).
    fn predict_many(&self, py: Python<'_>, phi: PyReadonlyArray2<'_, f64>, qd: PyReadonlyArray2<'_, f64>, steps: &Bound<'_, PyAny>) -> PyResult<()> {
        let steps = count(steps, "steps", 0, riccati::MAX_RECURSION_STEPS)?;
        let (phi, qd) = (mat(&phi, "phi")?, mat(&qd, "qd")?);
        let mut guard = lock(py, &self.inner);
        let kf: &mut Kf = &mut guard;
        Ok(py.detach(|| kf.predict_many(&phi, &qd, steps))?)
    }

    /// Returns (innovation, nis, rejected rows, skipped rows). NaN in z marks a missing
    /// component; the core checks z, H and R (the rows of a missing one are not read).
    #[pyo3(signature = (z, h, r, sequential=false, gate=None))]
    #[allow(clippy::type_complexity)]
    fn update<'py>(
        &self,
        py: Python<'py>,
        z: PyReadonlyArray1<'py, f64>,
        h: PyReadonlyArray2<'py, f64>,
        r: PyReadonlyArray2<'py, f64>,
        sequential: bool,
        #[pyo3(from_py_with = real_opt)] gate: Option<f64>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Vec<usize>, Vec<usize>)> {
        let z: Vec<f64> = z.as_array().iter().copied().collect();
        let rep = lock(py, &self.inner).update(&z, &with_missing(&h), &with_missing(&r), sequential, gate)?;
        Ok((rep.innovation.into_pyarray(py), rep.nis.into_pyarray(py), rep.rejected, rep.skipped))
    }

    /// Closed loop: returns δx̂ and resets it to 0; open loop: returns δx̂.
    fn take_correction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        lock(py, &self.inner).take_correction().as_slice().to_vec().into_pyarray(py)
    }

    #[getter]
    fn x<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        lock(py, &self.inner).x.as_slice().to_vec().into_pyarray(py)
    }

    #[getter]
    fn p<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        mat_to_py(py, &lock(py, &self.inner).p)
    }

    #[getter]
    fn epoch(&self, py: Python<'_>) -> usize {
        lock(py, &self.inner).epoch
    }
}

/// RTS smoother over stored steps: (x_smoothed (N, n), P_smoothed (N, n, n)).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn rts<'py>(
    py: Python<'py>,
    phi: PyReadonlyArray3<'py, f64>,
    x_prior: PyReadonlyArray2<'py, f64>,
    p_prior: PyReadonlyArray3<'py, f64>,
    x_post: PyReadonlyArray2<'py, f64>,
    p_post: PyReadonlyArray3<'py, f64>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray3<f64>>)> {
    let (phi, pp, ps) = (mats(&phi, "phi")?, mats(&p_prior, "p_prior")?, mats(&p_post, "p_post")?);
    let (xp, xs) = (rows_mat(&x_prior, "x_prior")?, rows_mat(&x_post, "x_post")?);
    let n = ps.first().map_or(0, |m| m.nrows());
    let steps = stored_steps(phi, xp, pp, xs, ps)?;
    let out = py.detach(|| core_rts(&steps))?;
    let xs: Vec<DVector<f64>> = out.iter().map(|o| o.0.clone()).collect();
    let ps: Vec<DMatrix<f64>> = out.into_iter().map(|o| o.1).collect();
    Ok((vecs_to_py(py, &xs, n), stack_to_py(py, &ps, n)))
}

/// Linearised scenario: covariance analysis and Monte Carlo (see filter/analysis.rs).
#[pyclass(module = "atomnav._core")]
pub struct Scenario {
    inner: CoreScenario,
}
super::pickle::picklable!(Scenario, inner, "Scenario");

#[pymethods]
impl Scenario {
    #[new]
    #[pyo3(signature = (f, qc, dt, p0, h, r, measure, *, method=Wrap(Discretization::VanLoan), sequential=false))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        f: PyReadonlyArray3<'_, f64>,
        qc: PyReadonlyArray3<'_, f64>,
        dt: PyReadonlyArray1<'_, f64>,
        p0: PyReadonlyArray2<'_, f64>,
        h: PyReadonlyArray2<'_, f64>,
        r: PyReadonlyArray2<'_, f64>,
        measure: Vec<bool>,
        method: Wrap<Discretization>,
        sequential: bool,
    ) -> PyResult<Self> {
        let method = method.0;
        let (f, qc, dt) = (mats(&f, "f")?, mats(&qc, "qc")?, vector(&dt, "dt")?);
        let (p0, h, r) = (mat(&p0, "p0")?, mat(&h, "h")?, mat(&r, "r")?);
        let inner = py.detach(|| CoreScenario::new(&f, &qc, &dt, p0, h, r, measure, method, sequential))?;
        Ok(Scenario { inner })
    }

    /// σ of every state after each epoch: (epochs, n).
    fn sigmas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let s = py.detach(|| self.inner.sigmas())?;
        flat_2d(py, s, self.inner.epochs(), self.inner.size())
    }

    /// σ of the true error of the filter as built when the measurement noise has
    /// covariance `r_true` and cross-covariance `cross` (steps, n, m) with the process noise
    /// of the step before each epoch (see filter/analysis.rs): (epochs, n).
    fn true_sigmas<'py>(&self, py: Python<'py>, r_true: PyReadonlyArray2<'py, f64>, cross: PyReadonlyArray3<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (r_true, cross) = (mat(&r_true, "r_true")?, mats(&cross, "cross")?);
        let s = py.detach(|| self.inner.true_sigmas(&r_true, &cross))?;
        flat_2d(py, s, self.inner.epochs(), self.inner.size())
    }

    /// Runs `runs` (indices under `master_seed`) on all local cores:
    /// (error (R, E, n), sigma (R, E, n), nees (R, E), nis (R, E)).
    #[allow(clippy::type_complexity)]
    // invariant: each run of Scenario::monte_carlo holds epochs × size errors and
    // sigmas and one NEES and NIS per epoch; a < nr = res.len().
    #[allow(clippy::indexing_slicing)]
    fn monte_carlo<'py>(
        &self,
        py: Python<'py>,
        master_seed: &Bound<'py, PyAny>,
        runs: &Bound<'py, PyAny>,
        mode: Wrap<LoopMode>,
    ) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let (mode, master_seed) = (mode.0, seed(master_seed, "master_seed")?);
        let runs: Vec<u64> = counts(runs, "runs", 0, usize::MAX)?.into_iter().map(|r| r as u64).collect();
        let res = py.detach(|| self.inner.monte_carlo(master_seed, &runs, mode))?;
        let (nr, ne, n) = (res.len(), self.inner.epochs(), self.inner.size());
        let cube = |sel: fn(&crate::filter::analysis::RunResult) -> &Vec<f64>| {
            Array3::from_shape_fn((nr, ne, n), |(a, b, c)| sel(&res[a])[b * n + c])
        };
        let err = cube(|r| &r.error).into_pyarray(py);
        let sig = cube(|r| &r.sigma).into_pyarray(py);
        let nees = Array2::from_shape_fn((nr, ne), |(a, b)| res[a].nees[b]).into_pyarray(py);
        let nis = Array2::from_shape_fn((nr, ne), |(a, b)| res[a].nis[b]).into_pyarray(py);
        Ok((err, sig, nees, nis))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(dare, m)?)?;
    m.add_function(wrap_pyfunction!(riccati_scalar, m)?)?;
    m.add_function(wrap_pyfunction!(kalman_recursion, m)?)?;
    m.add_function(wrap_pyfunction!(discretize_model, m)?)?;
    m.add_function(wrap_pyfunction!(rts, m)?)?;
    m.add_class::<KalmanFilter>()?;
    m.add_class::<Scenario>()?;
    register_choices::<LoopMode>(m, "LoopMode")?;
    register_choices::<UpdateForm>(m, "UpdateForm")?;
    register_choices::<Discretization>(m, "Discretization")?;
    Ok(())
}
