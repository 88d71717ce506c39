//! Bindings of cai: predictor, Jacobians, oracle and analytic motions, closed forms,
//! sensitivity function, readout, fringe tracking, ML noise identification, the CAI
//! sensor, the aided INS and the Monte-Carlo scenarios. Conversion only: every check and
//! loop is in `crate::cai`.

use super::convert::{count, counts, flags, quat_rows, real, real_opt, register_choices, rows, seed as seed_arg, to_py_rows, vec3, vec3_rows, vec3_to_py, vec_to_py, vector, Wrap};
use super::filter::mats;
use super::sources::AidingSource;
use super::imu::triad_from_dict;
use super::trajectory::Motion;
use crate::cai::aiding::{shot_times, CaiAiding, CaiConfig, CaiData, DataKind, ForceKind, ForceMode, IncompleteShots};
use crate::cai::closed_form::{closed_form_phases, ClosedForm};
use crate::cai::hybrid::{GravityModel, HybridConfig, HybridScenario, PhaseSourceKind};
use crate::cai::noise_id::{fringe_track, ml_windows, FringeEkf, Method, MlConfig, MAX_ML_ITER};
use crate::cai::oracle::{imu_from_motion, oracle_phase, AnalyticMotion, Gravity, SineMotion, YawDrive};
use crate::cai::predictor::{
    channels_from_rows, error_bound, jacobian, jacobian_fd, predict, Channel, Imu, Interpolation, OmegaDot, OmegaDotKind, PredictorConfig,
    DEFAULT_SAVGOL_HALF_WIDTH, DEFAULT_SUBSTEPS, JACOBIAN_PARAMS, MAX_SAVGOL_HALF_WIDTH, MAX_SUBSTEPS, TERM_NAMES,
};
use crate::cai::readout::{populations, steer_all};
use crate::cai::sensitivity::{convolution_phase, ideal_transfers, sensitivity_samples, Pulses};
use crate::error::invalid;
use crate::filter::sources::Source;
use crate::imu::errors::ImuErrorModel;
use crate::imu::ImuKind;
use crate::math::{Mat3, Vec3};
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Arr1<'py> = Bound<'py, PyArray1<f64>>;
type Arr2<'py> = Bound<'py, PyArray2<f64>>;
type Arr3<'py> = Bound<'py, PyArray3<f64>>;

// invariant: r has 3 rows of 3 (checked above), i, j < 3.
#[allow(clippy::indexing_slicing)]
fn mat3(a: &PyReadonlyArray2<'_, f64>, field: &str) -> PyResult<Mat3> {
    let r = rows::<3>(a, field)?;
    if r.len() != 3 {
        return Err(invalid(field, format!("expected shape (3, 3), got ({}, 3)", r.len())).into());
    }
    Ok(Mat3::from_fn(|i, j| r[i][j]))
}

/// Optional gravity-gradient tensor (3, 3) 1/s².
fn gradient_tensor(g: Option<PyReadonlyArray2<'_, f64>>) -> PyResult<Option<Mat3>> {
    g.map(|g| mat3(&g, "gradient")).transpose()
}

/// A flat row-major table as an array of `shape`.
fn cube<'py>(py: Python<'py>, flat: Vec<f64>, shape: [usize; 3]) -> PyResult<Arr3<'py>> {
    Ok(PyArray1::from_vec(py, flat).reshape(shape)?)
}

/// Interferometer channels, validated once; shared by the predictor and the oracle.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiChannels(Vec<Channel>);
super::pickle::picklable!(CaiChannels, 0, "CaiChannels");

#[pymethods]
impl CaiChannels {
    /// Channels from k (C, 3), lever (C, 3), c_sb (C, 3, 3), v0 (C, 3).
    #[new]
    fn new(k: PyReadonlyArray2<'_, f64>, lever: PyReadonlyArray2<'_, f64>, c_sb: PyReadonlyArray3<'_, f64>, v0: PyReadonlyArray2<'_, f64>) -> PyResult<Self> {
        let (k, l, v) = (vec3_rows(&k, "k")?, vec3_rows(&lever, "lever")?, vec3_rows(&v0, "v0")?);
        Ok(CaiChannels(channels_from_rows(&k, &l, &mats(&c_sb, "c_sb")?, &v)?))
    }
}

/// An IMU array (N, 3) read without the finiteness check: NaN in the IMU stream is
/// reported by the predictor with the shot that uses it.
// invariant: a 2-D array's shape has 2 entries; rows have 3 columns (checked above).
#[allow(clippy::indexing_slicing)]
fn raw3(a: &PyReadonlyArray2<'_, f64>, field: &str) -> PyResult<Vec<Vec3>> {
    let s = a.shape();
    if s[1] != 3 {
        return Err(invalid(field, format!("expected shape (N, 3), got ({}, {})", s[0], s[1])).into());
    }
    Ok(a.as_array().outer_iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect())
}

/// Predictor inputs, validated once at construction; `predict` and `jacobian` run on them.
#[pyclass(module = "atomnav._core", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
struct CaiSetup {
    t: Vec<f64>,
    f: Vec<Vec3>,
    w: Vec<Vec3>,
    shots: Vec<f64>,
    channels: Vec<Channel>,
    cfg: PredictorConfig,
}

impl CaiSetup {
    fn imu(&self) -> Imu<'_> {
        Imu { t: &self.t, f: &self.f, w: &self.w }
    }
}
super::pickle::picklable!(CaiSetup, self, "CaiSetup");

#[pymethods]
impl CaiSetup {
    #[new]
    #[allow(clippy::too_many_arguments, non_snake_case)]
    /// `omega_dot`, `savgol_half_width`, `interpolation`, `substeps` None: the core's defaults.
    #[pyo3(signature = (t, specific_force, angular_rate, shots, channels, T, *, omega_dot, angular_acceleration, savgol_half_width, interpolation, substeps,
        gradient, bias_a, bias_g))]
    fn new(
        t: PyReadonlyArray1<'_, f64>,
        specific_force: PyReadonlyArray2<'_, f64>,
        angular_rate: PyReadonlyArray2<'_, f64>,
        shots: PyReadonlyArray1<'_, f64>,
        channels: &CaiChannels,
        #[pyo3(from_py_with = real)] T: f64,
        omega_dot: Option<Wrap<OmegaDotKind>>,
        angular_acceleration: Option<PyReadonlyArray2<'_, f64>>,
        savgol_half_width: Option<&Bound<'_, PyAny>>,
        interpolation: Option<Wrap<Interpolation>>,
        substeps: Option<&Bound<'_, PyAny>>,
        gradient: Option<PyReadonlyArray2<'_, f64>>,
        bias_a: PyReadonlyArray1<'_, f64>,
        bias_g: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Self> {
        let given = angular_acceleration.map(|a| raw3(&a, "angular_acceleration")).transpose()?;
        let half_width = savgol_half_width.map_or(Ok(DEFAULT_SAVGOL_HALF_WIDTH), |m| count(m, "savgol_half_width", 0, MAX_SAVGOL_HALF_WIDTH))?;
        let omega_dot = OmegaDot::new(omega_dot.map(|o| o.0), half_width, given)?;
        Ok(CaiSetup {
            t: t.as_array().iter().copied().collect(),
            f: raw3(&specific_force, "specific_force")?,
            w: raw3(&angular_rate, "angular_rate")?,
            shots: shots.as_array().iter().copied().collect(),
            channels: channels.0.clone(),
            cfg: PredictorConfig {
                t_sep: T,
                substeps: substeps.map_or(Ok(DEFAULT_SUBSTEPS), |s| count(s, "substeps", 1, MAX_SUBSTEPS))?,
                gradient: gradient_tensor(gradient)?,
                bias_a: vec3(&bias_a, "bias_a")?,
                bias_g: vec3(&bias_g, "bias_g")?,
                omega_dot,
                interpolation: interpolation.map(|i| i.0).unwrap_or_default(),
            },
        })
    }

    /// Predicted phases: (shots · channels, 7) array, columns `CAI_TERMS`.
    fn predict<'py>(&self, py: Python<'py>) -> PyResult<Arr2<'py>> {
        let out = py.detach(|| predict(self.imu(), &self.shots, &self.channels, &self.cfg))?;
        Ok(to_py_rows(py, &out))
    }

    /// Error bound (rad) per shot · channel, the IMU rate (Hz) at which it falls below
    /// `tolerance_rad` (None: no rate does) and the record's rate (Hz).
    fn error_bound<'py>(&self, py: Python<'py>, #[pyo3(from_py_with = real)] tolerance_rad: f64) -> PyResult<(Arr1<'py>, Option<f64>, f64)> {
        let (bound, needed) = py.detach(|| -> crate::error::Result<_> {
            let b = error_bound(self.imu(), &self.shots, &self.channels, &self.cfg)?;
            let needed = b.rate_needed(tolerance_rad)?;
            Ok((b, needed))
        })?;
        Ok((vec_to_py(py, bound.rad()), needed, bound.rate_hz))
    }

    /// ∂φ/∂(b_a, b_g, l, γ): (shots · channels, 12); `fd_steps` (b_a, b_g, l, γ) given →
    /// central differences.
    #[pyo3(signature = (euler, fd_steps=None))]
    fn jacobian<'py>(&self, py: Python<'py>, euler: bool, fd_steps: Option<(f64, f64, f64, f64)>) -> PyResult<Arr2<'py>> {
        let out = py.detach(|| match fd_steps {
            None => jacobian(self.imu(), &self.shots, &self.channels, &self.cfg, euler),
            Some(s) => jacobian_fd(self.imu(), &self.shots, &self.channels, &self.cfg, euler, [s.0, s.1, s.2, s.3]),
        })?;
        Ok(to_py_rows(py, &out))
    }
}

/// Uniform gravity g0 (m/s², inertial) and an optional gradient (3, 3) 1/s² about the IMU
/// position at t_ref (s), validated once.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiGravity(Gravity);
super::pickle::picklable!(CaiGravity, 0, "CaiGravity");

#[pymethods]
impl CaiGravity {
    #[new]
    fn new(g0: PyReadonlyArray1<'_, f64>, gradient: Option<PyReadonlyArray2<'_, f64>>, #[pyo3(from_py_with = real)] t_ref: f64) -> PyResult<Self> {
        Ok(CaiGravity(Gravity { g0: vec3(&g0, "g0")?, gradient: gradient_tensor(gradient)?, t_ref }))
    }
}

/// An analytic body motion, validated once; its ideal IMU (`imu`) and the inertial-oracle
/// phases (`oracle`) under a gravity model.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiMotion(AnalyticMotion);
super::pickle::picklable!(CaiMotion, 0, "CaiMotion");

#[pymethods]
impl CaiMotion {
    /// Position / Euler-angle polynomials (3, 3) and sine rows [axis, amplitude, frequency Hz,
    /// phase rad].
    #[staticmethod]
    fn sine(
        position_poly: PyReadonlyArray2<'_, f64>,
        position_sines: PyReadonlyArray2<'_, f64>,
        attitude_poly: PyReadonlyArray2<'_, f64>,
        attitude_sines: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<Self> {
        let (pp, ps) = (rows::<3>(&position_poly, "position_poly")?, rows::<4>(&position_sines, "position_sines")?);
        let (ap, as_) = (rows::<3>(&attitude_poly, "attitude_poly")?, rows::<4>(&attitude_sines, "attitude_sines")?);
        Ok(CaiMotion(AnalyticMotion::Sine(Box::new(SineMotion::from_rows(&pp, &ps, &ap, &as_)?))))
    }

    /// Forward speed (m/s), yaw-rate amplitude (rad/s), period (s) of the yaw rate sine.
    #[staticmethod]
    fn yaw_drive(#[pyo3(from_py_with = real)] speed: f64, #[pyo3(from_py_with = real)] yaw_rate_amplitude: f64, #[pyo3(from_py_with = real)] period: f64) -> PyResult<Self> {
        Ok(CaiMotion(AnalyticMotion::YawDrive(YawDrive::new(speed, yaw_rate_amplitude, period)?)))
    }

    /// Ideal IMU (f_b, ω_b, ω̇_b) at times t.
    fn imu<'py>(&self, py: Python<'py>, t: PyReadonlyArray1<'py, f64>, gravity: &CaiGravity) -> PyResult<(Arr2<'py>, Arr2<'py>, Arr2<'py>)> {
        let t = vector(&t, "t")?;
        let (f, w, wd) = py.detach(|| imu_from_motion(&self.0, &t, &gravity.0))?;
        Ok((vec3_to_py(py, &f), vec3_to_py(py, &w), vec3_to_py(py, &wd)))
    }

    /// Oracle phases (shots · channels).
    #[allow(non_snake_case)]
    fn oracle<'py>(&self, py: Python<'py>, shots: PyReadonlyArray1<'py, f64>, #[pyo3(from_py_with = real)] T: f64, channels: &CaiChannels, gravity: &CaiGravity) -> PyResult<Arr1<'py>> {
        let shots = vector(&shots, "shots")?;
        let out = py.detach(|| oracle_phase(&self.0, &shots, T, &channels.0, &gravity.0))?;
        Ok(vec_to_py(py, out))
    }
}

/// Closed forms per channel row: kind "exact" (constant-input solution), "series" (its fourth-order
/// series in T), "seed000" (Tennstedt et al. 2021 Eq. 52).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn cai_phase_closed_form<'py>(
    py: Python<'py>,
    kind: Wrap<ClosedForm>,
    k: PyReadonlyArray2<'py, f64>,
    v0: PyReadonlyArray2<'py, f64>,
    w: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    wd: PyReadonlyArray1<'py, f64>,
    gradient: Option<PyReadonlyArray2<'py, f64>>,
    #[pyo3(from_py_with = real)] t: f64,
) -> PyResult<Arr1<'py>> {
    let (k, v0) = (vec3_rows(&k, "k")?, vec3_rows(&v0, "v0")?);
    let (w, f, wd, g) = (vec3(&w, "angular_rate")?, vec3(&f, "specific_force")?, vec3(&wd, "angular_acceleration")?, gradient_tensor(gradient)?.unwrap_or_else(Mat3::zeros));
    Ok(vec_to_py(py, closed_form_phases(kind.0, &k, &v0, (&w, &f, &wd), &g, t)?))
}

/// Sensitivity g(t) and response f(t) at times t (pulse centred at 0).
#[pyfunction]
fn cai_sensitivity<'py>(py: Python<'py>, t: PyReadonlyArray1<'py, f64>, #[pyo3(from_py_with = real)] t_dark: f64, #[pyo3(from_py_with = real)] tau: f64) -> PyResult<(Arr1<'py>, Arr1<'py>)> {
    let (g, f) = sensitivity_samples(&Pulses::new(t_dark, tau)?, &vector(&t, "t")?)?;
    Ok((vec_to_py(py, g), vec_to_py(py, f)))
}

/// Convolution phases (Tennstedt et al. 2023 Eq. 14) of shots centred at `centres`.
#[pyfunction]
fn cai_convolution_phase<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = real)] t_dark: f64,
    #[pyo3(from_py_with = real)] tau: f64,
    #[pyo3(from_py_with = real)] k: f64,
    t: PyReadonlyArray1<'py, f64>,
    a: PyReadonlyArray1<'py, f64>,
    centres: PyReadonlyArray1<'py, f64>,
) -> PyResult<Arr1<'py>> {
    let p = Pulses::new(t_dark, tau)?;
    let (t, centres) = (vector(&t, "t")?, vector(&centres, "centres")?);
    let a: Vec<f64> = a.as_array().iter().copied().collect();
    let out = py.detach(|| convolution_phase(&p, k, &t, &a, &centres))?;
    Ok(vec_to_py(py, out))
}

/// Closed-form area ∫f of the response function.
#[pyfunction]
fn cai_response_area(#[pyo3(from_py_with = real)] t_dark: f64, #[pyo3(from_py_with = real)] tau: f64) -> PyResult<f64> {
    Ok(Pulses::new(t_dark, tau)?.area())
}

/// The ideal transfer 4 sin²(ωT/2)/ω² at angular frequencies ω (rad/s).
#[pyfunction]
#[allow(non_snake_case)]
fn cai_ideal_transfer<'py>(py: Python<'py>, #[pyo3(from_py_with = real)] T: f64, omega: PyReadonlyArray1<'py, f64>) -> PyResult<Arr1<'py>> {
    Ok(vec_to_py(py, ideal_transfers(T, &vector(&omega, "omega")?)?))
}

/// Populations o − (C/2) cos(φ) of total phases φ (rad) with contrasts C (same length).
#[pyfunction]
fn cai_readout<'py>(py: Python<'py>, #[pyo3(from_py_with = real)] offset: f64, contrast: PyReadonlyArray1<'py, f64>, phase: PyReadonlyArray1<'py, f64>) -> PyResult<Arr1<'py>> {
    let (c, p) = (contrast.as_array().to_vec(), phase.as_array().to_vec());
    Ok(vec_to_py(py, populations(offset, &c, &p)?))
}

/// Laser phases (π/2 − φ̂) mod 2π putting predicted phases φ̂ (rad) at mid-fringe.
#[pyfunction]
fn cai_steer_mid_fringe<'py>(py: Python<'py>, phi_hat: PyReadonlyArray1<'py, f64>) -> PyResult<Arr1<'py>> {
    Ok(vec_to_py(py, steer_all(&phi_hat.as_array().to_vec())?))
}

/// Shot start times (s) from t0, one per `period` (≥ 2T), the last ending by t_end.
#[pyfunction]
#[allow(non_snake_case)]
fn cai_shot_times<'py>(py: Python<'py>, #[pyo3(from_py_with = real)] t0: f64, #[pyo3(from_py_with = real)] t_end: f64, #[pyo3(from_py_with = real)] T: f64, #[pyo3(from_py_with = real)] shot_period: f64) -> PyResult<Arr1<'py>> {
    Ok(vec_to_py(py, shot_times(t0, t_end, T, shot_period)?))
}

/// The Earth model (`Ellipsoid` name) of a scenario gravity ("kinematic", "earth").
#[pyfunction]
fn cai_gravity_ellipsoid(gravity: Wrap<GravityModel>) -> &'static str {
    gravity.0.ellipsoid().name
}

/// Fringe-tracking EKF: ζ = [p0, φ, A] after every readout, (N, 3).
#[pyfunction]
fn cai_fringe_track<'py>(
    py: Python<'py>,
    p: PyReadonlyArray1<'py, f64>,
    psi: PyReadonlyArray1<'py, f64>,
    zeta0: PyReadonlyArray1<'py, f64>,
    sigma0: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray1<'py, f64>,
    #[pyo3(from_py_with = real)] r: f64,
) -> PyResult<Arr2<'py>> {
    let (z, s, q) = (vec3(&zeta0, "zeta0")?, vec3(&sigma0, "sigma0")?, vec3(&q, "q")?);
    let cfg = FringeEkf { zeta0: [z.x, z.y, z.z], sigma0: [s.x, s.y, s.z], q: [q.x, q.y, q.z], r };
    let (p, psi) = (p.as_array().to_vec(), psi.as_array().to_vec());
    let out = py.detach(|| fringe_track(&p, &psi, &cfg))?;
    Ok(to_py_rows(py, &out))
}

/// ML noise identification over batches / a sliding window; a dict of arrays.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (x, phi, amp, *, method, free, theta0, max_iter, tol, batch, sliding))]
fn cai_ml_identify<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    phi: PyReadonlyArray1<'py, f64>,
    amp: PyReadonlyArray1<'py, f64>,
    method: Wrap<Method>,
    free: &Bound<'py, PyAny>,
    theta0: PyReadonlyArray1<'py, f64>,
    max_iter: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = real)] tol: f64,
    batch: &Bound<'py, PyAny>,
    sliding: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let th = vec3(&theta0, "theta0")?;
    let cfg = MlConfig { method: method.0, free: flags(free, "free")?, theta0: [th.x, th.y, th.z], max_iter: count(max_iter, "max_iter", 0, MAX_ML_ITER)?, tol };
    let batch = count(batch, "batch", 0, usize::MAX)?;
    let (x, phi, amp) = (x.as_array().to_vec(), phi.as_array().to_vec(), amp.as_array().to_vec());
    let res = py.detach(|| ml_windows(&x, &phi, &amp, &cfg, batch, sliding))?;
    let d = PyDict::new(py);
    d.set_item("theta", to_py_rows(py, &res.iter().map(|r| r.theta).collect::<Vec<_>>()))?;
    d.set_item("iterations", res.iter().map(|r| r.iterations).collect::<Vec<_>>())?;
    d.set_item("converged", res.iter().map(|r| r.converged).collect::<Vec<_>>())?;
    d.set_item("log_likelihood", vec_to_py(py, res.iter().map(|r| r.log_likelihood).collect()))?;
    d.set_item("a", vec_to_py(py, res.iter().map(|r| r.a).collect()))?;
    d.set_item("b", vec_to_py(py, res.iter().map(|r| r.b).collect()))?;
    d.set_item("hessian_eigenvalues", to_py_rows(py, &res.iter().map(|r| r.hessian_eigenvalues).collect::<Vec<_>>()))?;
    d.set_item("se_theta", to_py_rows(py, &res.iter().map(|r| r.se_theta).collect::<Vec<_>>()))?;
    d.set_item("se_a", vec_to_py(py, res.iter().map(|r| r.se_a).collect()))?;
    d.set_item("se_b", vec_to_py(py, res.iter().map(|r| r.se_b).collect()))?;
    Ok(d)
}

/// The triad of an IMU error model from its two dicts (as `atomnav.imu.ImuErrors._to_core`).
fn error_model(accel: &Bound<'_, PyDict>, gyro: &Bound<'_, PyDict>, name: &str) -> PyResult<ImuErrorModel> {
    let m = ImuErrorModel { accel: triad_from_dict(accel, &format!("{name}.accel"))?, gyro: triad_from_dict(gyro, &format!("{name}.gyro"))? };
    m.validate()?;
    Ok(m)
}

/// The CAI sensor as the aiding sees it (channels, T, readout, R inflation, predictor and
/// Jacobian options, extra states, force mode), checked once; built by
/// `atomnav.cai.CaiSensor._native()` and taken, with their shots, by the Monte Carlo
/// (`CaiHybrid`), `cai_source` and `cai_in_shot_noise`.
#[pyclass(name = "CaiSensor", module = "atomnav._core", frozen)]
pub struct CaiSensor(CaiConfig);
super::pickle::picklable!(CaiSensor, 0, "CaiSensor");

#[pymethods]
impl CaiSensor {
    #[new]
    #[allow(clippy::too_many_arguments, non_snake_case)]
    #[pyo3(signature = (channels, T, *, offset, contrast, sigma_p, inflation, omega_dot, savgol_half_width, interpolation, substeps,
        jacobian_euler, misalignment, lever_arm, force, force_tau, force_sigma))]
    fn new(
        channels: &CaiChannels,
        #[pyo3(from_py_with = real)] T: f64,
        #[pyo3(from_py_with = real)] offset: f64,
        #[pyo3(from_py_with = real)] contrast: f64,
        #[pyo3(from_py_with = real)] sigma_p: f64,
        inflation: Option<(f64, f64)>,
        omega_dot: Option<Wrap<OmegaDotKind>>,
        savgol_half_width: &Bound<'_, PyAny>,
        interpolation: Option<Wrap<Interpolation>>,
        substeps: &Bound<'_, PyAny>,
        jacobian_euler: bool,
        #[pyo3(from_py_with = real_opt)] misalignment: Option<f64>,
        #[pyo3(from_py_with = real_opt)] lever_arm: Option<f64>,
        force: Wrap<ForceKind>,
        #[pyo3(from_py_with = real_opt)] force_tau: Option<f64>,
        #[pyo3(from_py_with = real_opt)] force_sigma: Option<f64>,
    ) -> PyResult<Self> {
        let cfg = CaiConfig {
            channels: channels.0.clone(),
            t_sep: T,
            shots: Vec::new(),
            offset,
            contrast,
            sigma_p,
            inflation,
            // None: the predictor's defaults (predict_phase's)
            omega_dot: OmegaDot::without_samples(
                omega_dot.map_or(OmegaDotKind::default_for(false), |w| w.0),
                count(savgol_half_width, "savgol_half_width", 0, MAX_SAVGOL_HALF_WIDTH)?,
            )?,
            interpolation: interpolation.map_or_else(Interpolation::default, |w| w.0),
            substeps: count(substeps, "substeps", 1, MAX_SUBSTEPS)?,
            jacobian_euler,
            misalignment,
            lever_arm,
            force: ForceMode::new(force.0, force_tau, force_sigma)?,
            kind: ImuKind::Rates,
            incomplete: IncompleteShots::Skip,
        };
        cfg.check()?;
        Ok(CaiSensor(cfg))
    }
}

impl CaiSensor {
    fn with_shots(&self, shots: &PyReadonlyArray1<'_, f64>) -> PyResult<CaiConfig> {
        Ok(CaiConfig { shots: vector(shots, "shots")?, ..self.0.clone() })
    }
}

/// In-shot IMU noise of one shot of `sensor` on a regular record of spacing `dt` (s),
/// white PSDs q_a (m²/s³), q_g (rad²/s): the phase covariance Σ (channels × channels,
/// rad²) and, for each 15-state model f[k] (steps, 15, 15) held over a filter step of one
/// shot, E[w δφ̂ᵀ] (steps, 15, channels) (`CaiConfig::in_shot_noise`).
#[pyfunction]
// invariant: a 3-D array's shape has 3 entries.
#[allow(clippy::indexing_slicing)]
fn cai_in_shot_noise<'py>(py: Python<'py>, sensor: &CaiSensor, #[pyo3(from_py_with = real)] dt: f64, #[pyo3(from_py_with = real)] q_a: f64, #[pyo3(from_py_with = real)] q_g: f64, f: PyReadonlyArray3<'py, f64>) -> PyResult<(Arr2<'py>, Arr3<'py>)> {
    let fs = mats(&f, "f")?;
    let (sigma, cross) = py.detach(|| sensor.0.in_shot_noise(dt, q_a, q_g, &fs))?;
    let (n, m) = (f.shape()[1], sigma.nrows());
    let flat: Vec<f64> = cross.iter().flat_map(|c| c.transpose().as_slice().to_vec()).collect();
    Ok((super::convert::mat_to_py(py, &sigma), cube(py, flat, [cross.len(), n, m])?))
}

/// One incomplete shot for Python: (index, start s, samples lacking before, after, message).
type IncompleteShot = (usize, f64, usize, usize, String);

/// The shots of `sensor` at `shots` (s) that the record `time` (s) cannot complete: (index,
/// start s, samples lacking before the record start, after its end, message)
/// (`CaiConfig::incomplete_shots`).
#[pyfunction]
fn cai_incomplete_shots(sensor: &CaiSensor, shots: PyReadonlyArray1<'_, f64>, time: PyReadonlyArray1<'_, f64>) -> PyResult<Vec<IncompleteShot>> {
    let found = sensor.with_shots(&shots)?.incomplete_shots(&vector(&time, "time")?)?;
    Ok(found.into_iter().map(|(j, ts, g, text)| (j, ts, g.before, g.after, text)).collect())
}

/// The truth of a scenario: a motion model, or a sampled trajectory (time s, lla, NED
/// velocity m/s, q_nb).
#[derive(FromPyObject)]
enum Truth<'py> {
    Motion(PyRef<'py, Motion>),
    Table(PyReadonlyArray1<'py, f64>, PyReadonlyArray2<'py, f64>, PyReadonlyArray2<'py, f64>, PyReadonlyArray2<'py, f64>),
}

/// A CAI-aided INS scenario (truth, IMU errors, CAI, filter), built once by the core
/// (`HybridScenario::new`); `monte_carlo` runs seeded runs in parallel with the GIL released.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiHybrid(HybridScenario);
// the built truth and models, so a copy skips the build and runs the same Monte Carlo
super::pickle::picklable!(CaiHybrid, 0, "CaiHybrid");

#[pymethods]
impl CaiHybrid {
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (truth, sensor, shots, imu_accel, imu_gyro, reference, p0, *, gravity, rate_hz, truth_rate_hz, phase_source,
        accel_psd, gyro_psd, accel_bias_psd, gyro_bias_psd, predict_every, aiding, draw_initial))]
    fn new(
        py: Python<'_>,
        truth: Truth<'_>,
        sensor: &CaiSensor,
        shots: PyReadonlyArray1<'_, f64>,
        imu_accel: &Bound<'_, PyDict>,
        imu_gyro: &Bound<'_, PyDict>,
        reference: Option<(Bound<'_, PyDict>, Bound<'_, PyDict>)>,
        p0: PyReadonlyArray2<'_, f64>,
        gravity: Wrap<GravityModel>,
        #[pyo3(from_py_with = real)] rate_hz: f64,
        #[pyo3(from_py_with = real_opt)] truth_rate_hz: Option<f64>,
        phase_source: Wrap<PhaseSourceKind>,
        #[pyo3(from_py_with = real)] accel_psd: f64,
        #[pyo3(from_py_with = real)] gyro_psd: f64,
        #[pyo3(from_py_with = real)] accel_bias_psd: f64,
        #[pyo3(from_py_with = real)] gyro_bias_psd: f64,
        predict_every: &Bound<'_, PyAny>,
        aiding: bool,
        draw_initial: bool,
    ) -> PyResult<Self> {
        let cfg = HybridConfig {
            gravity: gravity.0,
            rate_hz,
            truth_rate_hz,
            phase_source: phase_source.0,
            accel_psd,
            gyro_psd,
            accel_bias_psd,
            gyro_bias_psd,
            predict_every: count(predict_every, "predict_every", 1, crate::cai::hybrid::MAX_SAMPLES)?,
            aiding,
            draw_initial,
        };
        let cai = sensor.with_shots(&shots)?;
        let imu_model = error_model(imu_accel, imu_gyro, "imu")?;
        let reference = reference.map(|(a, g)| error_model(&a, &g, "reference")).transpose()?;
        let p0 = super::convert::mat(&p0, "p0")?;
        let scenario = match truth {
            Truth::Motion(motion) => {
                let m = &motion.inner;
                py.detach(|| HybridScenario::new(m, &cfg, imu_model, reference, cai, p0))?
            }
            Truth::Table(t, lla, vel, q) => {
                let (t, lla, vel, q) = (vector(&t, "trajectory")?, vec3_rows(&lla, "trajectory")?, vec3_rows(&vel, "trajectory")?, quat_rows(&q, "trajectory")?);
                py.detach(|| HybridScenario::from_table(t, &lla, &vel, &q, &cfg, imu_model, reference, cai, p0))?
            }
        };
        Ok(CaiHybrid(scenario))
    }

    /// The truth at the IMU times: position (N, 3) (lat rad, lon rad, h m), NED velocity
    /// (N, 3) m/s and q_nb (N, 4).
    fn truth<'py>(&self, py: Python<'py>) -> (Arr2<'py>, Arr2<'py>, Arr2<'py>) {
        let tr = &self.0.truth;
        let lla: Vec<Vec3> = tr.iter().map(|s| s.lla).collect();
        let vel: Vec<Vec3> = tr.iter().map(|s| s.vel).collect();
        let q: Vec<crate::math::Quat> = tr.iter().map(|s| s.q_nb).collect();
        (vec3_to_py(py, &lla), vec3_to_py(py, &vel), super::convert::quat_to_py(py, &q))
    }

    /// Runs `runs` under `seed`: dict of arrays, each (runs, epochs, ...) except
    /// `phase_error` (runs, shots, channels), `accel_error` (runs, samples, 3), `time`
    /// (epochs) and `imu_time` (samples).
    fn monte_carlo<'py>(&self, py: Python<'py>, seed: &Bound<'py, PyAny>, runs: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        let seed = seed_arg(seed, "seed")?;
        let runs: Vec<u64> = counts(runs, "runs", 0, usize::MAX)?.into_iter().map(|r| r as u64).collect();
        let r = py.detach(|| self.0.monte_carlo_tables(seed, &runs))?;
        let (nr, ne) = (r.runs, r.epochs);
        let d = PyDict::new(py);
        d.set_item("time", vec_to_py(py, r.time))?;
        d.set_item("imu_time", vec_to_py(py, r.imu_time))?;
        d.set_item("hybrid", cube(py, r.hybrid, [nr, ne, 9])?)?;
        d.set_item("free", cube(py, r.free, [nr, ne, 9])?)?;
        d.set_item("bias", cube(py, r.bias, [nr, ne, 6])?)?;
        d.set_item("bias_true", cube(py, r.bias_true, [nr, ne, 6])?)?;
        d.set_item("accel_error", cube(py, r.accel_error, [nr, self.0.t.len(), 3])?)?;
        d.set_item("sigma", cube(py, r.sigma, [nr, ne, r.states])?)?;
        d.set_item("nees", cube(py, r.nees, [nr, ne, 1])?)?;
        d.set_item("phase_error", cube(py, r.phase_error, [nr, r.shots, r.channels])?)?;
        Ok(d)
    }

    /// Shot start times (s).
    #[getter]
    fn shots<'py>(&self, py: Python<'py>) -> Arr1<'py> {
        vec_to_py(py, self.0.cai.shots.clone())
    }

    /// Ideal specific force (N, 3) m/s² and angular rate (N, 3) rad/s at the IMU times, and the times.
    fn ideal_imu<'py>(&self, py: Python<'py>) -> (Arr1<'py>, Arr2<'py>, Arr2<'py>) {
        (vec_to_py(py, self.0.t.clone()), vec3_to_py(py, &self.0.f), vec3_to_py(py, &self.0.w))
    }
}

/// The sensor `sensor` at `shots` (s) with the shots' data, `incomplete_shots` as chosen:
/// either emulated (`data_a` true phases, `data_b` population noise, shots × channels, the
/// laser phase steered inside the loop) or recorded (`data_a` populations, `data_b` laser
/// phases). The tables are read row-major; the aiding checks their sizes.
// invariant: a 2-D array's shape has 2 entries.
#[allow(clippy::indexing_slicing)]
fn cai_parts(
    sensor: &CaiSensor,
    shots: &PyReadonlyArray1<'_, f64>,
    data_kind: DataKind,
    data_a: &PyReadonlyArray2<'_, f64>,
    data_b: &PyReadonlyArray2<'_, f64>,
    incomplete_shots: IncompleteShots,
) -> PyResult<(CaiConfig, CaiData)> {
    let cfg = CaiConfig { incomplete: incomplete_shots, ..sensor.with_shots(shots)? };
    let flat = |a: &PyReadonlyArray2<'_, f64>| a.as_array().iter().copied().collect::<Vec<f64>>();
    let widths = (data_a.shape()[1], data_b.shape()[1]);
    let data = CaiData::new(data_kind, flat(data_a), flat(data_b), widths, cfg.channels.len())?;
    Ok((cfg, data))
}

/// CAI shots as one measurement source of an aided INS (`aided_ins_from_sources`):
/// sensor, shots and data as for `cai_parts`, `extra0` the initial values of the sensor's
/// extra states and `extra_var` their initial variances (None: the setup's P₀ covers the
/// whole layout). Checked now; the sensor is made when the INS is built (it needs the IMU
/// kind of the setup).
#[pyfunction]
#[pyo3(signature = (extra0, extra_var, sensor, shots, data_kind, data_a, data_b, incomplete_shots))]
#[allow(clippy::too_many_arguments)]
fn cai_source(
    extra0: PyReadonlyArray1<'_, f64>,
    extra_var: Option<PyReadonlyArray1<'_, f64>>,
    sensor: &CaiSensor,
    shots: PyReadonlyArray1<'_, f64>,
    data_kind: Wrap<DataKind>,
    data_a: PyReadonlyArray2<'_, f64>,
    data_b: PyReadonlyArray2<'_, f64>,
    incomplete_shots: Wrap<IncompleteShots>,
) -> PyResult<AidingSource> {
    let (cfg, data) = cai_parts(sensor, &shots, data_kind.0, &data_a, &data_b, incomplete_shots.0)?;
    CaiAiding::new(cfg.clone(), data.clone())?;
    let extra0 = vector(&extra0, "extra0")?;
    let p0 = extra_var.map(|v| vector(&v, "sigma0_extra")).transpose()?.map(|v| DMatrix::from_diagonal(&DVector::from_vec(v)));
    Ok(AidingSource::deferred(
        "cai".to_string(),
        Box::new(move |setup| {
            let aiding = CaiAiding::new(CaiConfig { kind: setup.kind, ..cfg }, data)?;
            Ok(Source { aiding: Box::new(aiding), extra0, p0 })
        }),
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // column names of CaiSetup.predict / CaiSetup.jacobian (single source of truth)
    m.add("CAI_TERMS", TERM_NAMES.to_vec())?;
    m.add("CAI_JACOBIAN_PARAMS", JACOBIAN_PARAMS.to_vec())?;
    // IMU samples the predictor holds before a shot start (cubic / "pwl" stencils)
    m.add("CAI_STENCIL_PAD", crate::cai::predictor::STENCIL_PAD)?;
    register_choices::<OmegaDotKind>(m, "OmegaDot")?;
    register_choices::<Interpolation>(m, "Interpolation")?;
    register_choices::<ClosedForm>(m, "ClosedForm")?;
    register_choices::<Method>(m, "MlMethod")?;
    register_choices::<DataKind>(m, "CaiData")?;
    register_choices::<ForceKind>(m, "ForceMode")?;
    register_choices::<GravityModel>(m, "Gravity")?;
    register_choices::<PhaseSourceKind>(m, "PhaseSource")?;
    register_choices::<IncompleteShots>(m, "IncompleteShots")?;
    m.add_class::<CaiChannels>()?;
    m.add_class::<CaiSetup>()?;
    m.add_class::<CaiGravity>()?;
    m.add_class::<CaiMotion>()?;
    m.add_class::<CaiHybrid>()?;
    m.add_class::<CaiSensor>()?;
    m.add_function(wrap_pyfunction!(cai_source, m)?)?;
    m.add_function(wrap_pyfunction!(cai_in_shot_noise, m)?)?;
    m.add_function(wrap_pyfunction!(cai_incomplete_shots, m)?)?;
    m.add_function(wrap_pyfunction!(cai_phase_closed_form, m)?)?;
    m.add_function(wrap_pyfunction!(cai_sensitivity, m)?)?;
    m.add_function(wrap_pyfunction!(cai_convolution_phase, m)?)?;
    m.add_function(wrap_pyfunction!(cai_response_area, m)?)?;
    m.add_function(wrap_pyfunction!(cai_ideal_transfer, m)?)?;
    m.add_function(wrap_pyfunction!(cai_readout, m)?)?;
    m.add_function(wrap_pyfunction!(cai_steer_mid_fringe, m)?)?;
    m.add_function(wrap_pyfunction!(cai_shot_times, m)?)?;
    m.add_function(wrap_pyfunction!(cai_gravity_ellipsoid, m)?)?;
    m.add_function(wrap_pyfunction!(cai_fringe_track, m)?)?;
    m.add_function(wrap_pyfunction!(cai_ml_identify, m)?)?;
    Ok(())
}
