//! Bindings of strapdown/: a streaming mechanization object and attitude integration.

use super::convert::{count, flat_to_py, quat_rows, quat_to_py, real, real_opt, register_choices, vec3, vec3_rows, vector, Wrap};
use crate::earth::Ellipsoid;
use crate::error::{invalid, NavError};
use crate::math::{quat, Vec3};
use crate::options::Choice;
use crate::strapdown::{integrate_attitude, nav_columns, ImuKind, ImuSlices, NavState, NavTable, Samples3, Strapdown as Core, Vertical, NAV_COLUMNS, NAV_WIDTH, PIPELINE_BLOCK};
use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::borrow::Cow;

/// Streaming strapdown INS (NED). Feed chunks with `run`; state carries over.
#[pyclass(module = "atomnav._core")]
pub struct Strapdown {
    inner: Core,
}
// the state includes the coning/sculling history and the rate priming
super::pickle::picklable!(Strapdown, inner, "Strapdown");

/// Navigation states as a (14, N) array — one row per column of
/// `atomnav.trajectory.COLUMNS` (time, lat, lon, h, v_N, v_E, v_D, q_nb (4), roll, pitch,
/// yaw) — so that pandas can wrap its transpose without copying.
pub(crate) fn states_to_columns<'py>(py: Python<'py>, s: &[NavState]) -> Bound<'py, PyArray2<f64>> {
    flat_to_py(py, NAV_WIDTH, s.len(), nav_columns(s))
}

/// A 1-D array's values, read in place when contiguous (copied otherwise).
fn values(a: ArrayView1<'_, f64>) -> Cow<'_, [f64]> {
    a.to_slice().map_or_else(|| Cow::Owned(a.to_vec()), Cow::Borrowed)
}

/// An (N, W) array's memory, read in place when C- or Fortran-contiguous (copied to C order
/// otherwise), and whether it is column-major.
fn memory(a: ArrayView2<'_, f64>) -> (Cow<'_, [f64]>, bool) {
    match (a.to_slice(), a.reversed_axes().to_slice()) {
        (Some(c), _) => (Cow::Borrowed(c), false),
        (None, Some(f)) => (Cow::Borrowed(f), true),
        (None, None) => (Cow::Owned(a.iter().copied().collect()), false),
    }
}

/// The optional `first_index` argument (0 when not given), checked before any use.
fn first_row(first_index: Option<&Bound<'_, PyAny>>) -> PyResult<usize> {
    first_index.map_or(Ok(0), |f| count(f, "first_index", 0, isize::MAX.unsigned_abs()))
}

fn shape2(a: &ArrayView2<'_, f64>) -> [usize; 2] {
    [a.nrows(), a.ncols()]
}

impl Strapdown {
    /// The shared body of `run` and `run_into`: the chunk read in place and integrated
    /// into rows `row0`… of `out`, a C-contiguous (14, M) table. Bad input is an `Err`
    /// (nothing integrated); a divergence is the error beside the number of rows written
    /// before it.
    #[allow(clippy::too_many_arguments)]
    // invariant: a 2-D array's shape has 2 entries.
    #[allow(clippy::indexing_slicing)]
    fn run_chunk<'py>(
        &mut self,
        py: Python<'py>,
        time: &PyReadonlyArray1<'py, f64>,
        gyro: &PyReadonlyArray2<'py, f64>,
        accel: &PyReadonlyArray2<'py, f64>,
        h_ref: Option<&PyReadonlyArray1<'py, f64>>,
        first_index: usize,
        out: &Bound<'py, PyArray2<f64>>,
        row0: usize,
    ) -> PyResult<(usize, Result<(), NavError>)> {
        let (g, a) = (gyro.as_array(), accel.as_array());
        let (t, (gm, g_cols), (am, a_cols)) = (values(time.as_array()), memory(g), memory(a));
        let h = h_ref.map(|h| values(h.as_array()));
        let imu = ImuSlices::new(&t, Samples3::new("gyro", &gm, shape2(&g), g_cols)?, Samples3::new("accel", &am, shape2(&a), a_cols)?, h.as_deref())?;
        let shape = [out.shape()[0], out.shape()[1]];
        let mut guard = out.try_readwrite().map_err(|e| invalid("out", format!("not writable: {e}")))?;
        let buf = guard.as_slice_mut().map_err(|_| invalid("out", "must be a C-contiguous float64 array"))?;
        let table = NavTable::new(buf, shape, row0)?;
        let inner = &mut self.inner;
        match py.detach(|| inner.run_pipelined(&imu, table, first_index)) {
            (_, Err(e @ NavError::InvalidInput { .. })) => Err(e.into()),
            other => Ok(other),
        }
    }
}

/// The core's state from the constructor's arguments.
fn nav_state(t0: f64, lla: &PyReadonlyArray1<'_, f64>, vel_ned: &PyReadonlyArray1<'_, f64>, q_nb: &PyReadonlyArray1<'_, f64>) -> PyResult<NavState> {
    let q = vector(q_nb, "q_nb")?;
    let [w, x, y, z] = <[f64; 4]>::try_from(q.as_slice()).map_err(|_| invalid("q_nb", format!("expected 4 elements, got {}", q.len())))?;
    Ok(NavState { t: t0, lla: vec3(lla, "lla")?, vel: vec3(vel_ned, "vel_ned")?, q_nb: quat(w, x, y, z) })
}

/// A `NumericalError` of a divergence carrying `rows`, the number of the chunk's rows
/// computed before it.
fn diverged(py: Python<'_>, e: NavError, rows: usize) -> PyResult<PyErr> {
    let err: PyErr = e.into();
    err.value(py).setattr("rows", rows)?;
    Ok(err)
}

#[pymethods]
impl Strapdown {
    /// t0 (s), lla (lat rad, lon rad, h m), vel_ned (m/s), q_nb (scalar first); kind
    /// "rates" or "increments"; vertical "free" or "damped" (baro loop with damping ratio
    /// `zeta` and natural frequency `omega` rad/s, the core's defaults when None).
    #[new]
    #[pyo3(signature = (t0, lla, vel_ned, q_nb, *, kind=Wrap(ImuKind::Increments), ellipsoid=Wrap(crate::earth::WGS84), vertical=Wrap(Vertical::Free), zeta=None, omega=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        #[pyo3(from_py_with = real)] t0: f64,
        lla: PyReadonlyArray1<'_, f64>,
        vel_ned: PyReadonlyArray1<'_, f64>,
        q_nb: PyReadonlyArray1<'_, f64>,
        kind: Wrap<ImuKind>,
        ellipsoid: Wrap<Ellipsoid>,
        vertical: Wrap<Vertical>,
        #[pyo3(from_py_with = real_opt)] zeta: Option<f64>,
        #[pyo3(from_py_with = real_opt)] omega: Option<f64>,
    ) -> PyResult<Self> {
        let init = nav_state(t0, &lla, &vel_ned, &q_nb)?;
        Ok(Strapdown { inner: Core::new(init, kind.0, ellipsoid.0, vertical.0.tuned(zeta, omega))? })
    }

    /// The IMU kind's name ("rates" or "increments").
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.kind().name()
    }

    /// Restart from the state (t0, lla, vel_ned, q_nb) as a new object with the same
    /// options would; the state is checked (unit q_nb within 1e-6, latitude, height).
    fn reset(&mut self, #[pyo3(from_py_with = real)] t0: f64, lla: PyReadonlyArray1<'_, f64>, vel_ned: PyReadonlyArray1<'_, f64>, q_nb: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        let state = nav_state(t0, &lla, &vel_ned, &q_nb)?;
        Ok(self.inner.reset(state)?)
    }

    /// Integrate one chunk; returns the state after each sample as a (14, N) column table.
    /// `first_index` is the chunk's first row in the whole record, for error messages.
    /// The inputs are read in place when contiguous; the table is allocated by numpy. On
    /// divergence the exception carries `rows` (rows computed before it) and `table`
    /// (this table, valid in its first `rows` columns).
    #[pyo3(signature = (time, gyro, accel, h_ref=None, first_index=None))]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        time: PyReadonlyArray1<'py, f64>,
        gyro: PyReadonlyArray2<'py, f64>,
        accel: PyReadonlyArray2<'py, f64>,
        h_ref: Option<PyReadonlyArray1<'py, f64>>,
        first_index: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let first_index = first_row(first_index.as_ref())?;
        // numpy's allocator advises huge pages for large arrays: a few page faults instead
        // of one per 4 KiB of the 112 bytes/row table
        let table = PyArray2::<f64>::zeros(py, [NAV_WIDTH, time.len()], false);
        match self.run_chunk(py, &time, &gyro, &accel, h_ref.as_ref(), first_index, &table, 0)? {
            (_, Ok(())) => Ok(table),
            (rows, Err(e)) => {
                let err = diverged(py, e, rows)?;
                err.value(py).setattr("table", &table)?;
                Err(err)
            }
        }
    }

    /// `run` into rows `first_index`… of `out`, a C-contiguous (14, M) table of the
    /// whole record, so that a record integrated in chunks is never copied. On divergence
    /// the exception's `rows` is the number of this chunk's rows written before it.
    #[pyo3(signature = (time, gyro, accel, out, h_ref=None, first_index=None))]
    #[allow(clippy::too_many_arguments)]
    fn run_into<'py>(
        &mut self,
        py: Python<'py>,
        time: PyReadonlyArray1<'py, f64>,
        gyro: PyReadonlyArray2<'py, f64>,
        accel: PyReadonlyArray2<'py, f64>,
        out: Bound<'py, PyArray2<f64>>,
        h_ref: Option<PyReadonlyArray1<'py, f64>>,
        first_index: Option<Bound<'py, PyAny>>,
    ) -> PyResult<()> {
        let first_index = first_row(first_index.as_ref())?;
        match self.run_chunk(py, &time, &gyro, &accel, h_ref.as_ref(), first_index, &out, first_index)? {
            (_, Ok(())) => Ok(()),
            (rows, Err(e)) => Err(diverged(py, e, rows)?),
        }
    }

    /// Current state as a (14, 1) column table.
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        states_to_columns(py, &[self.inner.state])
    }
}

/// Body attitude from gyro increments with the multi-interval coning correction
/// (no navigation-frame rotation); `dtheta_prev`: up to two earlier increments, oldest first.
#[pyfunction]
#[pyo3(signature = (q0, dtheta, dtheta_prev=None))]
// invariant: q0 has exactly one row (checked before any other use).
#[allow(clippy::indexing_slicing)]
fn integrate_attitude_increments<'py>(
    py: Python<'py>,
    q0: PyReadonlyArray2<'py, f64>,
    dtheta: PyReadonlyArray2<'py, f64>,
    dtheta_prev: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q0 = quat_rows(&q0, "q0")?;
    if q0.len() != 1 || q0[0].norm() == 0.0 {
        return Err(invalid("q0", "expected one non-zero quaternion").into());
    }
    let d: Vec<Vec3> = vec3_rows(&dtheta, "dtheta")?;
    let prev = match dtheta_prev {
        Some(p) => vec3_rows(&p, "dtheta_prev")?,
        None => Vec::new(),
    };
    let q = py.detach(|| integrate_attitude(&q0[0], &d, &prev));
    Ok(quat_to_py(py, &q))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Strapdown>()?;
    m.add_function(wrap_pyfunction!(integrate_attitude_increments, m)?)?;
    register_choices::<Vertical>(m, "Vertical")?;
    m.add("NAV_COLUMNS", NAV_COLUMNS.to_vec())?;
    m.add("STRAPDOWN_BLOCK", PIPELINE_BLOCK)?;
    Ok(())
}
