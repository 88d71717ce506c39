//! Bindings of strapdown.rs: a streaming mechanization object and attitude integration.

use super::convert::{flat_to_py, quat_rows, quat_to_py, vec3, vec3_rows, vector};
use crate::earth::Ellipsoid;
use crate::error::{invalid, NavError};
use crate::math::{euler_from_quat, quat, Vec3};
use crate::strapdown::{integrate_attitude, ImuKind, NavState, Strapdown as Core, Vertical};
use numpy::ndarray::{s, ArrayView1, ArrayView2};
use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use std::sync::mpsc;
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

/// Write states as rows `first`… of an (14, n) row-major table `buf` (column c of the
/// navigation table is buf[c·n..(c+1)·n]).
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

/// Rows per block of the pipelined run: small enough that a block's IMU rows and states
/// stay in cache, large enough to amortise the hand-over to the writer thread.
const PIPELINE_BLOCK: usize = 4096;

/// The IMU chunk as numpy views, read in place (any strides, e.g. columns of one (N, 7)
/// table); `Block::fill` copies one block of rows into reusable buffers.
struct ImuView<'a> {
    time: ArrayView1<'a, f64>,
    gyro: ArrayView2<'a, f64>,
    accel: ArrayView2<'a, f64>,
    h_ref: Option<ArrayView1<'a, f64>>,
}

impl ImuView<'_> {
    fn len(&self) -> usize {
        self.time.len()
    }
}

/// One block of IMU rows, in buffers reused from block to block (no allocation, no page
/// faults after the first block).
#[derive(Default)]
struct Block {
    t: Vec<f64>,
    gyro: Vec<Vec3>,
    accel: Vec<Vec3>,
    h_ref: Vec<f64>,
    has_h_ref: bool,
}

impl Block {
    fn fill(&mut self, imu: &ImuView<'_>, rows: std::ops::Range<usize>) {
        let row = |a: &ArrayView2<'_, f64>, k: usize| Vec3::new(a[[k, 0]], a[[k, 1]], a[[k, 2]]);
        self.t.clear();
        self.t.extend(rows.clone().map(|k| imu.time[k]));
        self.gyro.clear();
        self.gyro.extend(rows.clone().map(|k| row(&imu.gyro, k)));
        self.accel.clear();
        self.accel.extend(rows.clone().map(|k| row(&imu.accel, k)));
        self.h_ref.clear();
        self.has_h_ref = imu.h_ref.is_some();
        if let Some(h) = &imu.h_ref {
            self.h_ref.extend(rows.map(|k| h[k]));
        }
    }

    fn h_ref(&self) -> Option<&[f64]> {
        self.has_h_ref.then_some(&self.h_ref[..])
    }
}

/// Check a whole chunk block by block (nothing is integrated when any row is bad).
fn validate(core: &Core, imu: &ImuView<'_>, first_index: usize) -> Result<(), NavError> {
    let (n, mut blk) = (imu.len(), Block::default());
    if imu.gyro.nrows() != n || imu.accel.nrows() != n {
        return Err(invalid("imu", format!("time has {n} samples but gyro {} and accel {}", imu.gyro.nrows(), imu.accel.nrows())));
    }
    if let Some(h) = imu.h_ref.as_ref().filter(|h| h.len() != n) {
        return Err(invalid("h_ref", format!("expected {n} samples, got {}", h.len())));
    }
    let mut after = None;
    for start in (0..n.max(1)).step_by(PIPELINE_BLOCK) {
        blk.fill(imu, start..(start + PIPELINE_BLOCK).min(n));
        core.validate_block(&blk.t, &blk.gyro, &blk.accel, blk.h_ref(), first_index + start, after)?;
        after = blk.t.last().copied().or(after);
    }
    Ok(())
}

/// Integrate a validated chunk on this thread while a second thread turns each finished
/// block of states into rows of the (14, n) table `table` (the Euler angles' three atan2
/// per row cost about half a mechanization step). Returns the number of rows computed
/// and, on divergence, the error; the rows before it are in `table`.
fn run_pipelined(core: &mut Core, imu: &ImuView<'_>, table: &mut [f64], first_index: usize) -> (usize, Result<(), NavError>) {
    let n = imu.len();
    let (to_writer, blocks) = mpsc::channel::<(usize, Vec<NavState>)>();
    let (recycle, free) = mpsc::channel::<Vec<NavState>>();
    // the sender is moved in, so it is dropped when the producer returns (ending the writer)
    let mut produce = |to_writer: mpsc::Sender<(usize, Vec<NavState>)>| {
        let mut blk = Block::default();
        for start in (0..n).step_by(PIPELINE_BLOCK) {
            blk.fill(imu, start..(start + PIPELINE_BLOCK).min(n));
            let mut states = free.try_recv().unwrap_or_else(|_| Vec::with_capacity(PIPELINE_BLOCK));
            states.clear();
            let step = core.run_validated(&blk.t, &blk.gyro, &blk.accel, blk.h_ref(), first_index + start, &mut states);
            let rows = start + states.len();
            to_writer.send((start, states)).expect("the writer thread outlives the producer");
            if step.is_err() {
                return (rows, step);
            }
        }
        (n, Ok(()))
    };
    if n <= PIPELINE_BLOCK {
        // one block: not worth a thread
        let out = produce(to_writer);
        for (first, states) in blocks.try_iter() {
            write_columns(table, n, first, &states);
        }
        return out;
    }
    std::thread::scope(|s| {
        s.spawn(move || {
            for (first, states) in blocks {
                write_columns(table, n, first, &states);
                let _ = recycle.send(states); // the producer may have finished already
            }
        });
        produce(to_writer)
    })
}

/// The first `rows` columns of a (14, n) table, as a (14, rows) array.
fn table_rows<'py>(py: Python<'py>, table: &Bound<'py, PyArray2<f64>>, rows: usize) -> Bound<'py, PyArray2<f64>> {
    let full = table.readonly();
    let cut: Vec<f64> = full.as_array().rows().into_iter().flat_map(|col| col.slice(s![..rows]).to_vec()).collect();
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
    /// The inputs are read in place (any strides); the table is allocated by numpy.
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
        for (name, a) in [("gyro", &gyro), ("accel", &accel)] {
            if a.shape()[1] != 3 {
                return Err(invalid(name, format!("expected shape (N, 3), got ({}, {})", a.shape()[0], a.shape()[1])).into());
            }
        }
        let imu = ImuView { time: time.as_array(), gyro: gyro.as_array(), accel: accel.as_array(), h_ref: h_ref.as_ref().map(|h| h.as_array()) };
        let n = imu.len();
        let inner = &mut self.inner;
        // values checked here, once, with indices in the whole record
        py.detach(|| validate(inner, &imu, first_index))?;
        // numpy's allocator advises huge pages for large arrays: a few page faults instead
        // of one per 4 KiB of the 112 bytes/row table
        let table = PyArray2::<f64>::zeros(py, [COLUMNS, n], false);
        let rows = {
            let mut guard = table.readwrite();
            let buf = guard.as_slice_mut().expect("a new C-contiguous array");
            let (rows, result) = py.detach(|| run_pipelined(inner, &imu, buf, first_index));
            if let Err(e) = result {
                drop(guard);
                // keep what was computed: the exception carries the rows before the failure
                let err: PyErr = e.into();
                err.value(py).setattr("partial", table_rows(py, &table, rows))?;
                return Err(err);
            }
            rows
        };
        debug_assert_eq!(rows, n);
        Ok(table)
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
