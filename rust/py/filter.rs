//! Bindings of filter/: state layouts, the INS error model and the aided INS (the linear
//! Kalman machinery is bound in kalman.rs).

use super::convert::{count, index_count, mat, quat_rows, real, real_opt, register_choices, vec3_rows, vector, Wrap};
use crate::earth::Ellipsoid;
use crate::error::{check_finite, invalid, invalid_at, NavError};
use pyo3::exceptions::PyTypeError;
use crate::filter::aided::{AidedConfig, AidedIns, AidedOutput, Aiding, DampedVertical, ForwardPass, InsSetup, NOMINAL_WIDTH};
use crate::strapdown::Vertical;
use crate::filter::discretize::Discretization;
use crate::filter::initial_error::perturbed_start;
use crate::filter::ins::{error_dynamics_along, BaroModel, BiasKind, BiasModel, InsNoise};
use crate::filter::kf::{stored_steps, LoopMode, StoredStep};
use super::kalman::{rows_mat, vecs_to_py};
use crate::filter::layout::{Layout, INS15, STANDARD_BLOCKS};
use crate::imu::ImuKind;
use crate::strapdown::NavState;
use nalgebra::{DMatrix, DVector};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;

// invariant: callers pass n × n matrices (the core's state size), k < ms.len().
#[allow(clippy::indexing_slicing)]
pub(crate) fn stack_to_py<'py>(py: Python<'py>, ms: &[DMatrix<f64>], n: usize) -> Bound<'py, PyArray3<f64>> {
    Array3::from_shape_fn((ms.len(), n, n), |(k, i, j)| ms[k][(i, j)]).into_pyarray(py)
}

/// A stack (N, r, c) as N matrices, checked for NaN/inf.
// invariant: a 3-D array's shape has 3 entries and (k, i, j) < shape.
#[allow(clippy::indexing_slicing)]
pub(crate) fn mats(a: &PyReadonlyArray3<'_, f64>, field: &str) -> Result<Vec<DMatrix<f64>>, NavError> {
    let s = a.shape();
    let v = a.as_array();
    // a C-contiguous stack (what the Python side passes) is read row by row: long stacks
    // (a covariance analysis over hours of 1 s steps) convert at memory speed
    let (flat, size) = (a.as_slice().ok(), s[1] * s[2]);
    if flat.is_none_or(|x| !x.iter().all(|x| x.is_finite())) {
        if let Some(((k, i, j), x)) = v.indexed_iter().find(|(_, x)| !x.is_finite()) {
            return Err(invalid_at(field, k, format!("non-finite value {x} at index ({k}, {i}, {j})")));
        }
    }
    Ok(match flat {
        Some(flat) if size > 0 => flat.chunks_exact(size).map(|m| DMatrix::from_row_slice(s[1], s[2], m)).collect(),
        _ => (0..s[0]).map(|k| DMatrix::from_fn(s[1], s[2], |i, j| v[(k, i, j)])).collect(),
    })
}

/// A fixed number of floats (a position, velocity, quaternion, bias) from any sequence: a
/// non-sequence is a `TypeError`, a wrong length or a NaN/inf an `InputError` naming `field`.
pub(super) fn floats<const N: usize>(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[f64; N]> {
    let v: Vec<f64> = obj.extract().map_err(|_| PyTypeError::new_err(format!("{field}: expected a sequence of {N} numbers")))?;
    let a: [f64; N] = v.try_into().map_err(|v: Vec<f64>| invalid(field, format!("expected {N} values, got {}", v.len())))?;
    check_finite(field, &a, 1)?;
    Ok(a)
}

/// A layout from [(name, size or None)]; a size that is no integer in [0, 2⁶⁴) is an
/// `InputError` naming `blocks` (not an `OverflowError`).
fn blocks_of(blocks: Vec<(String, Option<Bound<'_, PyAny>>)>) -> PyResult<Layout> {
    let spec = blocks
        .into_iter()
        .map(|(name, size)| Ok((name, size.map(|s| index_count(&s, "blocks", 0, usize::MAX)).transpose()?)))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(Layout::new(&spec)?)
}

/// (name, start, stop) of every block of a layout given as [(name, size or None)].
#[pyfunction]
fn layout_ranges(blocks: Vec<(String, Option<Bound<'_, PyAny>>)>) -> PyResult<Vec<(String, usize, usize)>> {
    let l = blocks_of(blocks)?;
    Ok(l.blocks().iter().map(|(n, r)| (n.clone(), r.start, r.end)).collect())
}

/// Continuous INS error model (Demidov 2009, Eq. 28) along a trajectory:
/// (F, Q_c) stacks of shape (N, n, n) for the layout `blocks`.
#[pyfunction]
#[pyo3(signature = (blocks, lla, vel_ned, q_nb, f_b, *, accel_psd, gyro_psd, accel_bias, gyro_bias, ellipsoid=Wrap(crate::earth::WGS84)))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn ins_error_dynamics<'py>(
    py: Python<'py>,
    blocks: Vec<(String, Option<Bound<'py, PyAny>>)>,
    lla: PyReadonlyArray2<'py, f64>,
    vel_ned: PyReadonlyArray2<'py, f64>,
    q_nb: PyReadonlyArray2<'py, f64>,
    f_b: PyReadonlyArray2<'py, f64>,
    #[pyo3(from_py_with = real)] accel_psd: f64,
    #[pyo3(from_py_with = real)] gyro_psd: f64,
    accel_bias: (String, f64, f64),
    gyro_bias: (String, f64, f64),
    ellipsoid: Wrap<Ellipsoid>,
) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<f64>>)> {
    let layout = blocks_of(blocks)?;
    let ell = ellipsoid.0;
    let (lla, vel, q, fb) = (vec3_rows(&lla, "lla")?, vec3_rows(&vel_ned, "vel_ned")?, quat_rows(&q_nb, "q_nb")?, vec3_rows(&f_b, "f_b")?);
    let noise = ins_noise(accel_psd, gyro_psd, &accel_bias, &gyro_bias)?;
    let out = py.detach(|| error_dynamics_along(&layout, &ell, &lla, &vel, &q, &fb, &noise))?;
    let m = layout.size();
    let f: Vec<_> = out.iter().map(|x| x.0.clone()).collect();
    let qc: Vec<_> = out.iter().map(|x| x.1.clone()).collect();
    Ok((stack_to_py(py, &f, m), stack_to_py(py, &qc, m)))
}

/// The aided INS (filter/aided.rs) with any aiding sensor, fed chunk by chunk. Built by
/// `aided_ins_from_sources`. `process` and `finish` return
/// (nav (14, E) column table, accel_bias (E, 3), gyro_bias (E, 3), extra (E, n_extra),
/// sigma (E, n), covariance (E, n, n) or None, meas_time (M,), meas_rows (M,), innovation (ΣM rows,), nis (M,),
/// rejected (M,), source (list of M sensor names), forward) for the epochs and
/// measurements of that call; `forward` is the stored forward pass of those epochs (empty
/// unless `store_forward_pass` was called):
/// (phi (E, n, n), qd (E, n, n), x_prior (E, n), p_prior (E, n, n), x_post (E, n),
/// p_post (E, n, n), nominal (E, 17 + n_extra)).
#[pyclass(name = "AidedIns", module = "atomnav._core")]
pub struct PyAidedIns {
    inner: std::sync::Mutex<AidedIns<Box<dyn Aiding>>>,
}
// the whole run (strapdown, filter, pending measurements and the sensor by its registered
// name), so a copy taken between chunks continues bit for bit
super::pickle::picklable!(PyAidedIns, inner, "AidedIns", locked);

type OutputTuple<'py> = Bound<'py, pyo3::types::PyTuple>;

/// The INS part every aided-INS factory shares (initial state, IMU kind, Earth model,
/// initial bias estimates, P₀, noise and filter options, vertical channel; the core's
/// `InsSetup`), checked once; each sensor's factory takes it as `ins` and adds its own
/// measurement model. Keyword-only.
#[pyclass(name = "AidedSetup", module = "atomnav._core", frozen)]
pub struct AidedSetup {
    pub(crate) setup: InsSetup,
}
super::pickle::picklable!(AidedSetup, setup, "AidedSetup");

#[pymethods]
impl AidedSetup {
    /// `vertical` "free" (default) or "damped" with the baro loop's ζ, ω_v (rad/s) and the
    /// reference-altitude error model: white-noise PSD `baro_psd` (m²·s) and optionally a
    /// bias state `baro_bias` = (model, p1, p2) as for the IMU biases with initial σ
    /// `baro_bias_sigma0` (m). `mount` the IMU mount C_imu^b (3, 3) (None: identity).
    #[new]
    #[pyo3(signature = (*, t0, lla0, vel0, q0, kind, p0, accel_psd, gyro_psd, accel_bias, gyro_bias, ba0, bg0, predict_every, method, mode, sequential=false, gate=None, ellipsoid=Wrap(crate::earth::WGS84), vertical=Wrap(Vertical::Free), zeta=None, omega=None, baro_psd=0.0, baro_bias=None, baro_bias_sigma0=None, mount=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        #[pyo3(from_py_with = real)] t0: f64,
        lla0: &Bound<'_, PyAny>,
        vel0: &Bound<'_, PyAny>,
        q0: &Bound<'_, PyAny>,
        kind: Wrap<ImuKind>,
        p0: PyReadonlyArray2<'_, f64>,
        #[pyo3(from_py_with = real)] accel_psd: f64,
        #[pyo3(from_py_with = real)] gyro_psd: f64,
        accel_bias: (String, f64, f64),
        gyro_bias: (String, f64, f64),
        ba0: &Bound<'_, PyAny>,
        bg0: &Bound<'_, PyAny>,
        predict_every: &Bound<'_, PyAny>,
        method: &str,
        mode: &str,
        sequential: bool,
        #[pyo3(from_py_with = real_opt)] gate: Option<f64>,
        ellipsoid: Wrap<Ellipsoid>,
        vertical: Wrap<Vertical>,
        #[pyo3(from_py_with = real_opt)] zeta: Option<f64>,
        #[pyo3(from_py_with = real_opt)] omega: Option<f64>,
        #[pyo3(from_py_with = real)] baro_psd: f64,
        baro_bias: Option<(String, f64, f64)>,
        #[pyo3(from_py_with = real_opt)] baro_bias_sigma0: Option<f64>,
        mount: Option<PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<Self> {
        let (lla0, vel0, q0) = (floats::<3>(lla0, "lla0")?, floats::<3>(vel0, "vel0")?, floats::<4>(q0, "q0")?);
        let (ba0, bg0) = (floats::<3>(ba0, "ba0")?, floats::<3>(bg0, "bg0")?);
        let predict_every = count(predict_every, "predict_every", 1, usize::MAX)?;
        let initial = NavState { t: t0, lla: lla0.into(), vel: vel0.into(), q_nb: crate::math::quat(q0[0], q0[1], q0[2], q0[3]) };
        let noise = ins_noise(accel_psd, gyro_psd, &accel_bias, &gyro_bias)?;
        let cfg = AidedConfig { noise, predict_every, method: <Discretization as crate::options::Choice>::parse(method)?, mode: <LoopMode as crate::options::Choice>::parse(mode)?, sequential, gate };
        let bias = match (baro_bias, baro_bias_sigma0) {
            (Some((kind, p1, p2)), Some(s0)) => Some((BiasModel::from_parts("baro_bias", &kind, p1, p2)?, s0)),
            (None, None) => None,
            (Some(_), None) => return Err(invalid("baro_bias_sigma0", "required with baro_bias (initial σ of the bias state, m)").into()),
            (None, Some(_)) => return Err(invalid("baro_bias_sigma0", "given without baro_bias").into()),
        };
        let damped = match vertical.0.tuned(zeta, omega) {
            Vertical::Free => None,
            Vertical::Damped { zeta, omega } => Some(DampedVertical { zeta, omega, baro: BaroModel { noise_psd: baro_psd, bias } }),
        };
        let mut setup = InsSetup::new(initial, kind.0, ellipsoid.0, ba0.into(), bg0.into(), mat(&p0, "p0")?, cfg, damped)?;
        if let Some(m) = mount.map(|m| mat(&m, "mount")).transpose()? {
            if m.shape() != (3, 3) {
                return Err(invalid("mount", format!("expected shape (3, 3), got {:?}", m.shape())).into());
            }
            setup = setup.with_mount(crate::math::Mat3::from_iterator(m.iter().copied()))?;
        }
        Ok(AidedSetup { setup })
    }
}

impl PyAidedIns {
    /// The aided INS of `ins` with the sensor's model, the initial estimate of its extra
    /// blocks and, when the sensor assembles it, P₀ over the whole layout.
    pub(crate) fn from_aiding(ins: &AidedSetup, extra0: DVector<f64>, p0: Option<DMatrix<f64>>, aiding: Box<dyn Aiding>) -> PyResult<Self> {
        let engine = AidedIns::from_setup(&ins.setup, extra0, p0, aiding)?;
        Ok(PyAidedIns { inner: std::sync::Mutex::new(engine) })
    }

    fn output<'py>(py: Python<'py>, o: AidedOutput, n: usize, n_extra: usize) -> PyResult<OutputTuple<'py>> {
        use super::convert::{flat_to_py, vec3_to_py};
        let ne = o.time.len();
        let items: Vec<Bound<'py, PyAny>> = vec![
            super::strapdown::states_to_columns(py, &o.nav).into_any(),
            vec3_to_py(py, &o.accel_bias).into_any(),
            vec3_to_py(py, &o.gyro_bias).into_any(),
            flat_to_py(py, ne, n_extra, o.extra).into_any(),
            flat_to_py(py, ne, n, o.sigma).into_any(),
            Self::covariance_stack(py, o.covariance, ne, n)?,
            o.meas_time.into_pyarray(py).into_any(),
            o.meas_rows.into_pyarray(py).into_any(),
            o.innovation.into_pyarray(py).into_any(),
            o.nis.into_pyarray(py).into_any(),
            o.rejected.into_pyarray(py).into_any(),
            pyo3::types::PyList::new(py, o.meas_source)?.into_any(),
            Self::forward(py, o.forward, n, n_extra)?.into_any(),
        ];
        pyo3::types::PyTuple::new(py, items)
    }

    /// The per-epoch covariances (E, n, n) from their row-major blocks, or None when
    /// they were not asked for.
    fn covariance_stack<'py>(py: Python<'py>, flat: Vec<f64>, epochs: usize, n: usize) -> PyResult<Bound<'py, PyAny>> {
        if flat.is_empty() {
            return Ok(py.None().into_bound(py));
        }
        let blocks = Array3::from_shape_vec((epochs, n, n), flat).map_err(|e| NavError::Numerical(format!("covariance output: {e}")))?;
        Ok(blocks.into_pyarray(py).into_any())
    }

    fn forward<'py>(py: Python<'py>, f: ForwardPass, n: usize, n_extra: usize) -> PyResult<OutputTuple<'py>> {
        use super::convert::rows_to_py;
        let e = f.steps.len();
        let pick = |m: fn(&StoredStep) -> &DMatrix<f64>| f.steps.iter().map(m).cloned().collect::<Vec<_>>();
        let items: Vec<Bound<'py, PyAny>> = vec![
            stack_to_py(py, &pick(|s| &s.phi), n).into_any(),
            stack_to_py(py, &f.qd, n).into_any(),
            rows_to_py(py, e, n, f.steps.iter().flat_map(|s| s.x_prior.iter().copied())).into_any(),
            stack_to_py(py, &pick(|s| &s.p_prior), n).into_any(),
            rows_to_py(py, e, n, f.steps.iter().flat_map(|s| s.x_post.iter().copied())).into_any(),
            stack_to_py(py, &pick(|s| &s.p_post), n).into_any(),
            rows_to_py(py, e, NOMINAL_WIDTH + n_extra, f.nominal.iter().flat_map(|r| r.iter().copied())).into_any(),
        ];
        pyo3::types::PyTuple::new(py, items)
    }

    /// Run `f` on the engine with the GIL released. When it stops on an error, the epochs
    /// computed before it are not lost: the raised exception carries them as `partial`.
    fn call<'py>(&self, py: Python<'py>, f: impl FnOnce(&mut AidedIns<Box<dyn Aiding>>, &mut AidedOutput) -> crate::error::Result<()> + Send) -> PyResult<OutputTuple<'py>> {
        let mut guard = super::shared::lock(py, &self.inner);
        let (n, n_extra) = (guard.layout().size(), guard.n_extra());
        let mut out = AidedOutput::default();
        let ins: &mut AidedIns<Box<dyn Aiding>> = &mut guard;
        let res = py.detach(|| f(ins, &mut out));
        drop(guard);
        let table = Self::output(py, out, n, n_extra)?;
        match res {
            Ok(()) => Ok(table),
            Err(e) => {
                let err = PyErr::from(e);
                err.value(py).setattr("partial", table)?;
                Err(err)
            }
        }
    }
}

#[pymethods]
impl PyAidedIns {
    /// Feed one chunk: time (N,) s, gyro and accel (N, 3) as rates or increments, the
    /// reference altitude h_ref (N,) m of a damped vertical channel. The engine checks the
    /// samples and names their index in the whole streamed record.
    #[pyo3(signature = (t, gyro, accel, h_ref=None))]
    fn process<'py>(
        &self,
        py: Python<'py>,
        t: PyReadonlyArray1<'py, f64>,
        gyro: PyReadonlyArray2<'py, f64>,
        accel: PyReadonlyArray2<'py, f64>,
        h_ref: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<OutputTuple<'py>> {
        let (tt, g, a) = (t.as_array().to_vec(), unchecked_vec3_rows(&gyro, "gyro")?, unchecked_vec3_rows(&accel, "accel")?);
        let h = h_ref.map(|h| h.as_array().to_vec());
        self.call(py, move |ins, out| ins.process_ref(&tt, &g, &a, h.as_deref(), out))
    }

    /// End of the record: one last epoch at the last sample.
    fn finish<'py>(&self, py: Python<'py>) -> PyResult<OutputTuple<'py>> {
        self.call(py, |ins, out| ins.finish(out))
    }

    /// Output the full error-state covariance of every epoch (the sixth item of what
    /// `process` and `finish` return) from now on, or stop.
    fn output_covariance(&self, py: Python<'_>, on: bool) {
        super::shared::lock(py, &self.inner).output_covariance(on);
    }

    /// Store the forward pass of every epoch from the first sample on (the last item of
    /// what `process` and `finish` return), for `smooth_chunk`.
    fn store_forward_pass(&self, py: Python<'_>) -> PyResult<()> {
        Ok(super::shared::lock(py, &self.inner).store_forward_pass()?)
    }

    /// The RTS smoother over one chunk of the stored forward pass (filter/aided.rs,
    /// `AidedIns::smooth_chunk`): the chunk's phi, x_prior, p_prior, x_post, p_post and
    /// nominal as stored; `after` None for the last chunk of the record, else the step that
    /// follows the chunk (phi, x_prior, p_prior, x_post, p_post) and its smoothed (x_s, p_s);
    /// `first` the epoch index of the chunk's first step. Returns (the output tuple of the
    /// smoothed epochs, x_s (E, n), p_s (E, n, n)).
    #[pyo3(signature = (phi, x_prior, p_prior, x_post, p_post, nominal, after, first))]
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn smooth_chunk<'py>(
        &self,
        py: Python<'py>,
        phi: PyReadonlyArray3<'py, f64>,
        x_prior: PyReadonlyArray2<'py, f64>,
        p_prior: PyReadonlyArray3<'py, f64>,
        x_post: PyReadonlyArray2<'py, f64>,
        p_post: PyReadonlyArray3<'py, f64>,
        nominal: PyReadonlyArray2<'py, f64>,
        after: Option<(PyReadonlyArray2<'py, f64>, PyReadonlyArray1<'py, f64>, PyReadonlyArray2<'py, f64>, PyReadonlyArray1<'py, f64>, PyReadonlyArray2<'py, f64>, PyReadonlyArray1<'py, f64>, PyReadonlyArray2<'py, f64>)>,
        first: &Bound<'py, PyAny>,
    ) -> PyResult<(OutputTuple<'py>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray3<f64>>)> {
        let steps = stored_steps(mats(&phi, "phi")?, rows_mat(&x_prior, "x_prior")?, mats(&p_prior, "p_prior")?, rows_mat(&x_post, "x_post")?, mats(&p_post, "p_post")?)?;
        let chunk = ForwardPass { steps, qd: vec![], nominal: rows_mat(&nominal, "nominal")? };
        let after = match after {
            Some((phi, xp, pp, xq, pq, xs, ps)) => {
                let dv = |a: &PyReadonlyArray1<'py, f64>, f: &str| vector(a, f).map(DVector::from_vec);
                let step = StoredStep { phi: mat(&phi, "after")?, x_prior: dv(&xp, "after")?, p_prior: mat(&pp, "after")?, x_post: dv(&xq, "after")?, p_post: mat(&pq, "after")? };
                Some((step, dv(&xs, "after")?, mat(&ps, "after")?))
            }
            None => None,
        };
        let first = index_count(first, "first", 0, usize::MAX)?;
        let mut guard = super::shared::lock(py, &self.inner);
        let (n, n_extra) = (guard.layout().size(), guard.n_extra());
        // &mut: the engine is Send, not Sync (its sensor is a Box<dyn Aiding + Send>)
        let engine: &mut AidedIns<Box<dyn Aiding>> = &mut guard;
        let sm = py.detach(move || engine.smooth_chunk(&chunk, after.as_ref().map(|(s, x, p)| (s, x.clone(), p.clone())), first))?;
        drop(guard);
        Ok((Self::output(py, sm.out, n, n_extra)?, vecs_to_py(py, &sm.x, n), stack_to_py(py, &sm.p, n)))
    }

    /// Labels of the state components, e.g. "velocity[2]".
    #[getter]
    fn labels(&self, py: Python<'_>) -> Vec<String> {
        super::shared::lock(py, &self.inner).layout().labels()
    }

    /// Measurement times (s) of the sensor.
    #[getter]
    fn measurement_times(&self, py: Python<'_>) -> Vec<f64> {
        super::shared::lock(py, &self.inner).aiding().times().to_vec()
    }

    /// Number of measurements not applied yet.
    #[getter]
    fn pending(&self, py: Python<'_>) -> usize {
        super::shared::lock(py, &self.inner).pending()
    }

    /// The current error-state covariance P (n, n) in the order of `labels` (after the
    /// last epoch processed), e.g. for the NEES against a known truth.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let p = super::shared::lock(py, &self.inner).covariance().clone();
        super::convert::mat_to_py(py, &p)
    }
}

/// The rows of an (N, 3) array, shape-checked only: the aided engine checks finiteness
/// itself and names the sample's index in the whole record, not in the chunk.
// invariant: rows have 3 columns (checked above).
#[allow(clippy::indexing_slicing)]
fn unchecked_vec3_rows(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<Vec<crate::math::Vec3>, NavError> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(invalid(field, format!("expected shape (N, 3), got ({}, {})", v.nrows(), v.ncols())));
    }
    Ok(v.outer_iter().map(|r| crate::math::Vec3::new(r[0], r[1], r[2])).collect())
}

/// INS noise model from the Python arguments (bias models as (kind, p1, p2)).
pub(crate) fn ins_noise(accel_psd: f64, gyro_psd: f64, accel_bias: &(String, f64, f64), gyro_bias: &(String, f64, f64)) -> PyResult<InsNoise> {
    let ba = BiasModel::from_parts("accel_bias", &accel_bias.0, accel_bias.1, accel_bias.2)?;
    let bg = BiasModel::from_parts("gyro_bias", &gyro_bias.0, gyro_bias.1, gyro_bias.2)?;
    Ok(InsNoise::new(accel_psd, gyro_psd, ba, bg)?)
}

/// The estimate at the start of a run whose truth is (`lla` rad/rad/m, `vel_ned` m/s,
/// `q_nb`): the truth ⊕ δx with δx = L u drawn from the navigation block of `p0` and the
/// standard normals `normals` (9,) (filter/initial_error.rs). Returns (lla, vel_ned, q_nb).
#[pyfunction]
#[pyo3(signature = (lla, vel_ned, q_nb, p0, normals, ellipsoid=Wrap(crate::earth::WGS84)))]
#[allow(clippy::type_complexity)]
fn initial_error<'py>(
    py: Python<'py>, lla: &Bound<'py, PyAny>, vel_ned: &Bound<'py, PyAny>, q_nb: &Bound<'py, PyAny>, p0: PyReadonlyArray2<'py, f64>, normals: PyReadonlyArray1<'py, f64>, ellipsoid: Wrap<Ellipsoid>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let (lla, vel_ned, q_nb) = (floats::<3>(lla, "lla")?, floats::<3>(vel_ned, "vel_ned")?, floats::<4>(q_nb, "q_nb")?);
    let truth = NavState { t: 0.0, lla: lla.into(), vel: vel_ned.into(), q_nb: crate::math::quat(q_nb[0], q_nb[1], q_nb[2], q_nb[3]) };
    let s = perturbed_start(&ellipsoid.0, &truth, &mat(&p0, "p0")?, &vector(&normals, "normals")?)?;
    let q = [s.q_nb.w, s.q_nb.i, s.q_nb.j, s.q_nb.k];
    Ok((s.lla.as_slice().to_vec().into_pyarray(py), s.vel.as_slice().to_vec().into_pyarray(py), q.to_vec().into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(layout_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(ins_error_dynamics, m)?)?;
    m.add_function(wrap_pyfunction!(initial_error, m)?)?;
    m.add("STATE_BLOCKS", STANDARD_BLOCKS.to_vec())?;
    m.add("INS15", INS15.to_vec())?;
    register_choices::<BiasKind>(m, "BiasKind")?;
    m.add_class::<PyAidedIns>()?;
    m.add_class::<AidedSetup>()?;
    Ok(())
}
