//! Bindings of strapdown.rs: a streaming mechanization object and attitude integration.

use super::convert::{flat_to_py, quat_rows, quat_to_py, vec3, vec3_rows, vec3_rows_unchecked, vector};
use crate::earth::Ellipsoid;
use crate::error::{invalid, NavError};
use crate::math::{euler_from_quat, quat, Vec3};
use crate::strapdown::{integrate_attitude, ImuKind, NavState, Strapdown as Core, Vertical};
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

/// Streaming strapdown INS (NED). Feed chunks with `run`; state carries over.
#[pyclass(module = "atomnav._core")]
pub struct Strapdown {
    inner: Core,
}

/// Navigation states as a (14, N) array — one row per column of
/// `atomnav.trajectory.COLUMNS` (time, lat, lon, h, v_N, v_E, v_D, q_nb (4), roll, pitch,
/// yaw) — so that pandas can wrap its transpose without copying.
pub(crate) fn states_to_columns<'py>(py: Python<'py>, s: &[NavState]) -> Bound<'py, PyArray2<f64>> {
    let mut buf = vec![0.0; COLUMNS * s.len()];
    write_columns(&mut buf, s.len(), 0, s);
    flat_to_py(py, COLUMNS, s.len(), buf)
}

/// Number of columns of the navigation table.
const COLUMNS: usize = 14;

/// Write states as rows `first`… of an (14, n) column-major table `buf`.
fn write_columns(buf: &mut [f64], n: usize, first: usize, s: &[NavState]) {
    for (i, x) in s.iter().enumerate() {
        let e = euler_from_quat(&x.q_nb);
        let q = &x.q_nb;
        let row = [x.t, x.lla.x, x.lla.y, x.lla.z, x.vel.x, x.vel.y, x.vel.z, q.w, q.i, q.j, q.k, e.x, e.y, e.z];
        for (c, v) in row.into_iter().enumerate() {
            buf[c * n + first + i] = v;
        }
    }
}

/// Samples integrated per block of the pipelined run: small enough that the states of
/// two blocks stay in cache, large enough to amortise the thread hand-over.
const PIPELINE_BLOCK: usize = 4096;

/// Integrate a validated chunk while a second core turns the previous block's states into
/// the column table (the Euler angles' three atan2 per row cost about as much as the
/// mechanization step). Returns the table of the rows computed and, on divergence, the error.
fn run_pipelined(core: &mut Core, t: &[f64], g: &[Vec3], a: &[Vec3], h: Option<&[f64]>, first_index: usize) -> (Vec<f64>, usize, Result<(), NavError>) {
    let n = t.len();
    let mut buf = vec![0.0; COLUMNS * n];
    let (mut done, mut current) = (Vec::with_capacity(PIPELINE_BLOCK), Vec::with_capacity(PIPELINE_BLOCK));
    let mut written = 0;
    let mut result = Ok(());
    for start in (0..n).step_by(PIPELINE_BLOCK) {
        let end = (start + PIPELINE_BLOCK).min(n);
        current.clear();
        let (step, ()) = rayon::join(
            || core.run_validated(&t[start..end], &g[start..end], &a[start..end], h.map(|h| &h[start..end]), first_index + start, &mut current),
            || write_columns(&mut buf, n, written, &done),
        );
        written += done.len();
        std::mem::swap(&mut done, &mut current);
        if step.is_err() {
            result = step;
            break;
        }
    }
    write_columns(&mut buf, n, written, &done);
    written += done.len();
    (buf, written, result)
}

/// The first `rows` rows of an (14, n) column-major table, as a (14, rows) array.
fn table_rows<'py>(py: Python<'py>, buf: Vec<f64>, n: usize, rows: usize) -> Bound<'py, PyArray2<f64>> {
    if rows == n {
        return flat_to_py(py, COLUMNS, n, buf);
    }
    let cut: Vec<f64> = buf.chunks_exact(n).flat_map(|col| col[..rows].iter().copied()).collect();
    flat_to_py(py, COLUMNS, rows, cut)
}

#[pymethods]
impl Strapdown {
    /// t0 (s), lla (lat rad, lon rad, h m), vel_ned (m/s), q_nb (scalar first); kind
    /// "rates" or "increments"; vertical "free" or "damped" (baro loop with damping ratio
    /// `zeta` and natural frequency `omega` rad/s).
    #[new]
    #[pyo3(signature = (t0, lla, vel_ned, q_nb, kind, ellipsoid="WGS84", vertical="free", zeta=0.707, omega=0.01))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        t0: f64,
        lla: PyReadonlyArray1<'_, f64>,
        vel_ned: PyReadonlyArray1<'_, f64>,
        q_nb: PyReadonlyArray1<'_, f64>,
        kind: &str,
        ellipsoid: &str,
        vertical: &str,
        zeta: f64,
        omega: f64,
    ) -> PyResult<Self> {
        let q = vector(&q_nb, "q_nb")?;
        if q.len() != 4 {
            return Err(invalid("q_nb", format!("expected 4 elements, got {}", q.len())).into());
        }
        let vertical = match vertical {
            "free" => Vertical::Free,
            "damped" => Vertical::Damped { zeta, omega },
            other => return Err(invalid("vertical", format!("unknown option '{other}' (known: 'free', 'damped')")).into()),
        };
        let init = NavState { t: t0, lla: vec3(&lla, "lla")?, vel: vec3(&vel_ned, "vel_ned")?, q_nb: quat(q[0], q[1], q[2], q[3]) };
        Ok(Strapdown { inner: Core::new(init, ImuKind::parse(kind)?, Ellipsoid::by_name(ellipsoid)?, vertical)? })
    }

    /// Integrate one chunk; returns the state after each sample as a (14, N) column table.
    /// `first_index` is the chunk's first row in the whole record, for error messages.
    #[pyo3(signature = (time, gyro, accel, h_ref=None, first_index=0))]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        time: PyReadonlyArray1<'py, f64>,
        gyro: PyReadonlyArray2<'py, f64>,
        accel: PyReadonlyArray2<'py, f64>,
        h_ref: Option<PyReadonlyArray1<'py, f64>>,
        first_index: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let t: Vec<f64> = time.as_array().iter().copied().collect();
        // finiteness is checked by `validate`, with indices in the whole record
        let g = vec3_rows_unchecked(&gyro, "gyro")?;
        let a = vec3_rows_unchecked(&accel, "accel")?;
        let h: Option<Vec<f64>> = h_ref.map(|h| h.as_array().iter().copied().collect());
        let inner = &mut self.inner;
        inner.validate(&t, &g, &a, h.as_deref(), first_index)?;
        let (buf, rows, result) = py.detach(|| run_pipelined(inner, &t, &g, &a, h.as_deref(), first_index));
        let table = table_rows(py, buf, t.len(), rows);
        match result {
            Ok(()) => Ok(table),
            Err(e) => {
                // keep what was computed: the exception carries the rows before the failure
                let err: PyErr = e.into();
                err.value(py).setattr("partial", table)?;
                Err(err)
            }
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
    Ok(())
}
