//! Bindings of strapdown.rs: a streaming mechanization object and attitude integration.

use super::convert::{Wrap, flat_to_py, quat_rows, quat_to_py, vec3, vec3_rows, vector};
use crate::earth::Ellipsoid;
use crate::error::{invalid, NavError};
use crate::math::{euler_from_quat, quat, Vec3};
use crate::strapdown::{check_lengths, integrate_attitude, BodyFront, BodyStep, ImuKind, NavState, SampleCheck, Strapdown as Core, Vertical};
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

/// Where a run writes its rows: columns `row0`… of a (14, stride) row-major table (the
/// chunk's own table, or the whole record's).
struct TableOut<'a> {
    buf: &'a mut [f64],
    stride: usize,
    row0: usize,
}

impl TableOut<'_> {
    /// The states of the chunk's rows `first`….
    fn write(&mut self, first: usize, states: &[NavState]) {
        write_columns(self.buf, self.stride, self.row0 + first, states);
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
/// faults after the first blocks).
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

/// The IMU-only work on a block, ready for the navigation half: checked rows, their body
/// steps (`BodyFront::push`), the reference altitudes.
#[derive(Default)]
struct Prepared {
    start: usize,
    block: Block,
    body: Vec<BodyStep>,
}

/// What is done to a chunk off the integrating thread: checking and the body half of each
/// step one block ahead, turning finished states into table rows behind. `check` and
/// `front` continue from the state the chunk starts at.
struct Helper<'a, 'v> {
    imu: &'a ImuView<'v>,
    first_index: usize,
    check: SampleCheck,
    front: BodyFront,
}

impl Helper<'_, '_> {
    /// Block `j` copied out of the numpy views, checked, and its body steps computed.
    fn prepare(&mut self, j: usize, mut into: Prepared) -> Result<Prepared, NavError> {
        let (start, n) = (j * PIPELINE_BLOCK, self.imu.len());
        into.start = start;
        into.block.fill(self.imu, start..(start + PIPELINE_BLOCK).min(n));
        let b = &into.block;
        self.check.check(&b.t, &b.gyro, &b.accel, b.h_ref(), self.first_index + start)?;
        self.front.push_block(&b.t, &b.gyro, &b.accel, &mut into.body);
        Ok(into)
    }
}

/// Check and integrate a chunk in blocks: this thread runs the navigation half of every
/// step; a second thread prepares the next block (copy, checks, coning and sculling) and
/// turns the finished one into rows of `out` (the Euler angles' three atan2 per row cost
/// about half a mechanization step). A bad row restores the state the
/// chunk started from, so bad input integrates nothing. Returns the number of rows
/// computed and the error, if any; on divergence the rows before it are in `out`.
fn run_pipelined(core: &mut Core, imu: &ImuView<'_>, mut out: TableOut<'_>, first_index: usize) -> (usize, Result<(), NavError>) {
    let (n, initial) = (imu.len(), core.clone());
    let blocks = n.div_ceil(PIPELINE_BLOCK).max(1);
    let mut helper = Helper { imu, first_index, check: core.sample_check(), front: core.front.clone() };
    let (to_core, prepared) = mpsc::channel::<Result<Prepared, NavError>>();
    let (to_writer, finished) = mpsc::channel::<(Vec<NavState>, Prepared)>();
    // the navigation half; `to_writer` is moved in, so the writer's loop ends when it returns
    let integrate = |core: &mut Core, to_writer: mpsc::Sender<(Vec<NavState>, Prepared)>, spare: &mpsc::Receiver<Vec<NavState>>| {
        for p in prepared.iter() {
            let p = match p {
                Ok(p) => p,
                Err(e) => return (0, Err(e)),
            };
            let mut states = spare.try_recv().unwrap_or_else(|_| Vec::with_capacity(PIPELINE_BLOCK));
            states.clear();
            let step = core.run_body(&p.block.t, &p.body, p.block.h_ref(), first_index + p.start, &mut states);
            let rows = p.start + states.len();
            let _ = to_writer.send((states, p)); // the helper stops early on bad input
            if step.is_err() {
                return (rows, step);
            }
        }
        (n, Ok(()))
    };
    let (rows, result, front) = if n <= PIPELINE_BLOCK {
        // one block: not worth a thread
        let _ = to_core.send(helper.prepare(0, Prepared::default()));
        drop(to_core);
        let (_, spare) = mpsc::channel();
        let (rows, result) = integrate(core, to_writer, &spare);
        for (states, p) in finished.try_iter() {
            out.write(p.start, &states);
        }
        (rows, result, helper.front)
    } else {
        let (recycle, spare) = mpsc::channel::<Vec<NavState>>();
        std::thread::scope(|s| {
            let writer = s.spawn(move || {
                let mut reuse = Prepared::default();
                for j in 0..=blocks {
                    // block j while the core integrates block j − 1, whose rows come next
                    if j < blocks {
                        let p = helper.prepare(j, std::mem::take(&mut reuse));
                        let bad = p.is_err();
                        if to_core.send(p).is_err() || bad {
                            break; // the core has stopped, or bad input: stop preparing
                        }
                    }
                    if j > 0 {
                        let Ok((states, p)) = finished.recv() else { break };
                        out.write(p.start, &states);
                        reuse = p;
                        let _ = recycle.send(states);
                    }
                }
                drop(to_core);
                // after an early stop: the rows the core still sends
                for (states, p) in finished.iter() {
                    out.write(p.start, &states);
                }
                helper.front
            });
            let (rows, result) = integrate(core, to_writer, &spare);
            (rows, result, writer.join().expect("the pipeline's writer thread does not panic"))
        })
    };
    match result {
        Ok(()) => core.front = front,
        Err(NavError::InvalidInput { .. }) => *core = initial,
        Err(_) => {} // diverged: the state is where it failed
    }
    (rows, result)
}

impl Strapdown {
    /// The shared body of `run` and `run_into`: the chunk's shapes checked, its values
    /// checked and integrated into columns `row0`… of `out`. Bad input is an `Err` (nothing
    /// integrated); a divergence is the error beside the number of rows written before it.
    #[allow(clippy::too_many_arguments)]
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
        for (name, a) in [("gyro", gyro), ("accel", accel)] {
            if a.shape()[1] != 3 {
                return Err(invalid(name, format!("expected shape (N, 3), got ({}, {})", a.shape()[0], a.shape()[1])).into());
            }
        }
        let imu = ImuView { time: time.as_array(), gyro: gyro.as_array(), accel: accel.as_array(), h_ref: h_ref.map(|h| h.as_array()) };
        check_lengths(imu.len(), imu.gyro.nrows(), imu.accel.nrows(), imu.h_ref.as_ref().map(|h| h.len()))?;
        let mut guard = out.try_readwrite().map_err(|e| invalid("out", format!("not writable: {e}")))?;
        let stride = out.shape()[1];
        let buf = guard.as_slice_mut().map_err(|_| invalid("out", "must be a C-contiguous float64 array"))?;
        let inner = &mut self.inner;
        let (rows, result) = py.detach(|| run_pipelined(inner, &imu, TableOut { buf, stride, row0 }, first_index));
        match result {
            Err(e @ NavError::InvalidInput { .. }) => Err(e.into()),
            other => Ok((rows, other)),
        }
    }
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
    #[pyo3(signature = (t0, lla, vel_ned, q_nb, kind, ellipsoid=Wrap(crate::earth::WGS84), vertical="free", zeta=0.707, omega=0.01))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        t0: f64,
        lla: PyReadonlyArray1<'_, f64>,
        vel_ned: PyReadonlyArray1<'_, f64>,
        q_nb: PyReadonlyArray1<'_, f64>,
        kind: Wrap<ImuKind>,
        ellipsoid: Wrap<Ellipsoid>,
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
        Ok(Strapdown { inner: Core::new(init, kind.0, ellipsoid.0, vertical)? })
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
        // numpy's allocator advises huge pages for large arrays: a few page faults instead
        // of one per 4 KiB of the 112 bytes/row table
        let table = PyArray2::<f64>::zeros(py, [COLUMNS, time.len()], false);
        match self.run_chunk(py, &time, &gyro, &accel, h_ref.as_ref(), first_index, &table, 0)? {
            (_, Ok(())) => Ok(table),
            (rows, Err(e)) => {
                // keep what was computed: the exception carries the rows before the failure
                let err: PyErr = e.into();
                err.value(py).setattr("partial", table_rows(py, &table, rows))?;
                Err(err)
            }
        }
    }

    /// `run` into columns `first_index`… of `out`, a C-contiguous (14, M) table of the
    /// whole record, so that a record integrated in chunks is never copied. On divergence
    /// the exception's `rows` is the number of this chunk's rows written before it.
    #[pyo3(signature = (time, gyro, accel, out, h_ref=None, first_index=0))]
    #[allow(clippy::too_many_arguments)]
    fn run_into<'py>(
        &mut self,
        py: Python<'py>,
        time: PyReadonlyArray1<'py, f64>,
        gyro: PyReadonlyArray2<'py, f64>,
        accel: PyReadonlyArray2<'py, f64>,
        out: Bound<'py, PyArray2<f64>>,
        h_ref: Option<PyReadonlyArray1<'py, f64>>,
        first_index: usize,
    ) -> PyResult<()> {
        let (n, shape) = (time.len(), out.shape().to_vec());
        if shape[0] != COLUMNS || shape[1] < first_index + n {
            return Err(invalid("out", format!("expected a ({COLUMNS}, >= {}) table, got {shape:?}", first_index + n)).into());
        }
        match self.run_chunk(py, &time, &gyro, &accel, h_ref.as_ref(), first_index, &out, first_index)? {
            (_, Ok(())) => Ok(()),
            (rows, Err(e)) => {
                let err: PyErr = e.into();
                err.value(py).setattr("rows", rows)?;
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
