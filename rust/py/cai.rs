//! Bindings of cai: predictor, Jacobians, oracle and analytic motions, closed forms,
//! sensitivity function, fringe tracking and ML noise identification.

use super::convert::{Wrap, rows, to_py_rows, vec3, vec3_rows, vec3_to_py, vec_to_py, vector};
use super::imu::triad_from_dict;
use super::trajectory::Motion;
use super::filter::{AidedSetup, PyAidedIns};
use crate::cai::aiding::{CaiAiding, CaiConfig, CaiData, ForceMode};
use crate::cai::in_shot;
use nalgebra::DVector;
use crate::cai::hybrid::{HybridRun, HybridScenario, PhaseSource};
use crate::earth::Ellipsoid;
use crate::filter::aided::AidedConfig;
use crate::filter::discretize::Discretization;
use crate::filter::ins::{BiasModel, InsNoise};
use crate::filter::kf::LoopMode;
use crate::imu::errors::ImuErrorModel;
use crate::imu::ImuKind;
use crate::cai::closed_form::{phase_constant, phase_seed000, phase_series};
use crate::cai::noise_id::{fringe_track, ml_windows, FringeEkf, Method, MlConfig};
use crate::cai::oracle::{imu_from_motion, oracle_phase, BodyMotion, Gravity, SineMotion, Signal, YawDrive};
use crate::cai::predictor::{jacobian, jacobian_fd, predict, Channel, Imu, Interpolation, OmegaDot, PredictorConfig, JACOBIAN_PARAMS, TERM_NAMES};
use crate::cai::sensitivity::{convolution_phase, ideal_transfer, Pulses};
use crate::error::invalid;
use crate::math::{Mat3, Vec3};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Arr1<'py> = Bound<'py, PyArray1<f64>>;
type Arr2<'py> = Bound<'py, PyArray2<f64>>;

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

/// Interferometer channels, validated once; shared by the predictor and the oracle.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiChannels(Vec<Channel>);

#[pymethods]
impl CaiChannels {
    /// Channels from k (C, 3), lever (C, 3), c_sb (C, 3, 3), v0 (C, 3).
    #[new]
    fn new(k: PyReadonlyArray2<'_, f64>, lever: PyReadonlyArray2<'_, f64>, c_sb: PyReadonlyArray3<'_, f64>, v0: PyReadonlyArray2<'_, f64>) -> PyResult<Self> {
        let (k, l, v) = (vec3_rows(&k, "k")?, vec3_rows(&lever, "lever")?, vec3_rows(&v0, "v0")?);
        let s = c_sb.shape();
        if s[0] != k.len() || s[1] != 3 || s[2] != 3 || l.len() != k.len() || v.len() != k.len() {
            return Err(invalid("channels", format!("k, lever, v0 must be (C, 3) and c_sb (C, 3, 3) with the same C = {}", k.len())).into());
        }
        let c = c_sb.as_array();
        Ok(CaiChannels((0..k.len()).map(|j| Channel { k: k[j], lever: l[j], c_sb: Mat3::from_fn(|r, q| c[[j, r, q]]), v0: v[j] }).collect()))
    }
}

/// Predictor inputs, validated once at construction; `predict` and `jacobian` run on them.
#[pyclass(module = "atomnav._core", frozen)]
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

#[pymethods]
impl CaiSetup {
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        t: PyReadonlyArray1<'_, f64>,
        f: PyReadonlyArray2<'_, f64>,
        w: PyReadonlyArray2<'_, f64>,
        shots: PyReadonlyArray1<'_, f64>,
        channels: &CaiChannels,
        t_sep: f64,
        omega_dot: &str,
        wdot: Option<PyReadonlyArray2<'_, f64>>,
        savgol_half_width: usize,
        interpolation: &str,
        substeps: usize,
        gradient: Option<PyReadonlyArray2<'_, f64>>,
        bias_a: PyReadonlyArray1<'_, f64>,
        bias_g: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Self> {
        // NaN in the IMU stream is reported by the predictor with the shot that uses it, so the
        // IMU arrays are read without the finiteness check here.
        let raw3 = |a: &PyReadonlyArray2<'_, f64>, field: &str| -> PyResult<Vec<Vec3>> {
            let s = a.shape();
            if s[1] != 3 {
                return Err(invalid(field, format!("expected shape (N, 3), got ({}, {})", s[0], s[1])).into());
            }
            Ok(a.as_array().outer_iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect())
        };
        let omega_dot = match omega_dot {
            "zero" => OmegaDot::Zero,
            "pwl" => OmegaDot::Pwl,
            "savgol" => OmegaDot::Savgol { half_width: savgol_half_width },
            "given" => match &wdot {
                Some(a) => OmegaDot::Given(raw3(a, "angular_acceleration")?),
                None => return Err(invalid("angular_acceleration", "required when omega_dot = 'given'").into()),
            },
            other => return Err(invalid("omega_dot", format!("unknown option {other:?}; choose zero, pwl, savgol, given")).into()),
        };
        let interpolation = match interpolation {
            "linear" => Interpolation::Linear,
            "cubic" => Interpolation::Cubic,
            other => return Err(invalid("interpolation", format!("unknown option {other:?}; choose linear, cubic")).into()),
        };
        Ok(CaiSetup {
            t: t.as_array().iter().copied().collect(),
            f: raw3(&f, "specific_force")?,
            w: raw3(&w, "angular_rate")?,
            shots: shots.as_array().iter().copied().collect(),
            channels: channels.0.clone(),
            cfg: PredictorConfig {
                t_sep,
                substeps,
                gradient: gradient_tensor(gradient)?,
                bias_a: vec3(&bias_a, "bias_a")?,
                bias_g: vec3(&bias_g, "bias_g")?,
                omega_dot,
                interpolation,
            },
        })
    }

    /// Predicted phases: (shots · channels, 7) array, columns total, acc, rot, cen, eul, mix, gg.
    fn predict<'py>(&self, py: Python<'py>) -> PyResult<Arr2<'py>> {
        let out = py.detach(|| predict(self.imu(), &self.shots, &self.channels, &self.cfg))?;
        Ok(to_py_rows(py, &out))
    }

    /// ∂φ/∂(b_a, b_g, l, γ): (shots · channels, 12); `fd_steps` given → central differences.
    fn jacobian<'py>(&self, py: Python<'py>, euler: bool, fd_steps: Option<PyReadonlyArray1<'py, f64>>) -> PyResult<Arr2<'py>> {
        let steps = match fd_steps {
            None => None,
            Some(s) => {
                let v = vector(&s, "fd_steps")?;
                if v.len() != 4 {
                    return Err(invalid("fd_steps", format!("expected 4 steps (b_a, b_g, l, gamma), got {}", v.len())).into());
                }
                Some([v[0], v[1], v[2], v[3]])
            }
        };
        let out = py.detach(|| match steps {
            None => jacobian(self.imu(), &self.shots, &self.channels, &self.cfg, euler),
            Some(s) => jacobian_fd(self.imu(), &self.shots, &self.channels, &self.cfg, euler, s),
        })?;
        Ok(to_py_rows(py, &out))
    }
}

fn signal(poly: &[f64], sines: &[[f64; 4]], axis: usize) -> Signal {
    Signal {
        poly: [poly[0], poly[1], poly[2]],
        sines: sines.iter().filter(|r| r[0] as usize == axis).map(|r| (r[1], r[2], r[3])).collect(),
    }
}

/// Uniform gravity g0 (m/s², inertial) and an optional gradient (3, 3) 1/s² about the IMU
/// position at t_ref (s), validated once.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiGravity(Gravity);

#[pymethods]
impl CaiGravity {
    #[new]
    fn new(g0: PyReadonlyArray1<'_, f64>, gradient: Option<PyReadonlyArray2<'_, f64>>, t_ref: f64) -> PyResult<Self> {
        Ok(CaiGravity(Gravity { g0: vec3(&g0, "gravity")?, gradient: gradient_tensor(gradient)?, t_ref }))
    }
}

/// An analytic body motion, validated once; its ideal IMU (`imu`) and the inertial-oracle
/// phases (`oracle`) under a gravity model.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiMotion(Box<dyn BodyMotion + Send + Sync>);

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
        if pp.len() != 3 || ap.len() != 3 {
            return Err(invalid("position_poly", "position_poly and attitude_poly must be (3, 3)").into());
        }
        for (name, s) in [("position_sines", &ps), ("attitude_sines", &as_)] {
            if let Some(i) = s.iter().position(|r| !(r[0] == 0.0 || r[0] == 1.0 || r[0] == 2.0)) {
                return Err(invalid(name, format!("axis column must be 0, 1 or 2 (row {i})")).into());
            }
        }
        let motion = SineMotion { position: [0, 1, 2].map(|a| signal(&pp[a], &ps, a)), euler: [0, 1, 2].map(|a| signal(&ap[a], &as_, a)) };
        Ok(CaiMotion(Box::new(motion)))
    }

    /// Forward speed (m/s), yaw-rate amplitude (rad/s), period (s) of the yaw rate sine.
    #[staticmethod]
    fn yaw_drive(speed: f64, yaw_rate_amplitude: f64, period: f64) -> PyResult<Self> {
        crate::error::check_positive("period", period)?;
        Ok(CaiMotion(Box::new(YawDrive { speed, yaw_rate_amplitude, period })))
    }

    /// Ideal IMU (f_b, ω_b, ω̇_b) at times t.
    fn imu<'py>(&self, py: Python<'py>, t: PyReadonlyArray1<'py, f64>, gravity: &CaiGravity) -> PyResult<(Arr2<'py>, Arr2<'py>, Arr2<'py>)> {
        let t = vector(&t, "t")?;
        let (f, w, wd) = py.detach(|| imu_from_motion(self.0.as_ref(), &t, &gravity.0))?;
        Ok((vec3_to_py(py, &f), vec3_to_py(py, &w), vec3_to_py(py, &wd)))
    }

    /// Oracle phases (shots · channels).
    fn oracle<'py>(&self, py: Python<'py>, shots: PyReadonlyArray1<'py, f64>, t_sep: f64, channels: &CaiChannels, gravity: &CaiGravity) -> PyResult<Arr1<'py>> {
        let shots = vector(&shots, "shots")?;
        let out = py.detach(|| oracle_phase(self.0.as_ref(), &shots, t_sep, &channels.0, &gravity.0))?;
        Ok(vec_to_py(py, out))
    }
}

/// Closed forms per channel row: kind "exact" (E10), "series" (E11), "seed000" (P-52).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn cai_phase_closed_form<'py>(
    py: Python<'py>,
    kind: &str,
    k: PyReadonlyArray2<'py, f64>,
    v0: PyReadonlyArray2<'py, f64>,
    w: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    wd: PyReadonlyArray1<'py, f64>,
    gradient: Option<PyReadonlyArray2<'py, f64>>,
    t: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (k, v0) = (vec3_rows(&k, "k")?, vec3_rows(&v0, "v0")?);
    if k.len() != v0.len() {
        return Err(invalid("v0", format!("expected {} rows like k, got {}", k.len(), v0.len())).into());
    }
    let (w, f, wd, g) = (vec3(&w, "angular_rate")?, vec3(&f, "specific_force")?, vec3(&wd, "angular_acceleration")?, gradient_tensor(gradient)?.unwrap_or_else(Mat3::zeros));
    crate::error::check_positive("T", t)?;
    let out: Vec<f64> = match kind {
        "exact" => k.iter().zip(&v0).map(|(k, v)| phase_constant(k, &w, &f, v, t)).collect(),
        "series" => k.iter().zip(&v0).map(|(k, v)| phase_series(k, &w, &wd, &f, v, &g, t)).collect(),
        "seed000" => k.iter().zip(&v0).map(|(k, v)| phase_seed000(k, &w, &f, v, t)).collect(),
        other => return Err(invalid("kind", format!("unknown closed form {other:?}; choose exact, series, seed000")).into()),
    };
    Ok(vec_to_py(py, out))
}

/// Sensitivity g(t) and response f(t) at times t (pulse centred at 0).
#[pyfunction]
fn cai_sensitivity<'py>(py: Python<'py>, t: PyReadonlyArray1<'py, f64>, t_dark: f64, tau: f64) -> PyResult<(Arr1<'py>, Arr1<'py>)> {
    let p = Pulses::new(t_dark, tau)?;
    let t = vector(&t, "t")?;
    Ok((vec_to_py(py, t.iter().map(|&x| p.g(x)).collect()), vec_to_py(py, t.iter().map(|&x| p.f(x)).collect())))
}

/// Convolution phases (E20) of shots centred at `centres`.
#[pyfunction]
fn cai_convolution_phase<'py>(
    py: Python<'py>,
    t_dark: f64,
    tau: f64,
    k: f64,
    t: PyReadonlyArray1<'py, f64>,
    a: PyReadonlyArray1<'py, f64>,
    centres: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let p = Pulses::new(t_dark, tau)?;
    let (t, centres) = (vector(&t, "t")?, vector(&centres, "centres")?);
    let a: Vec<f64> = a.as_array().iter().copied().collect();
    let out = py.detach(|| convolution_phase(&p, k, &t, &a, &centres))?;
    Ok(vec_to_py(py, out))
}

/// Closed-form area ∫f and the ideal transfer 4 sin²(ωT/2)/ω² at angular frequencies.
#[pyfunction]
fn cai_response_area(t_dark: f64, tau: f64) -> PyResult<f64> {
    Ok(Pulses::new(t_dark, tau)?.area())
}

#[pyfunction]
fn cai_ideal_transfer<'py>(py: Python<'py>, t_sep: f64, omega: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
    crate::error::check_positive("T", t_sep)?;
    Ok(vec_to_py(py, vector(&omega, "omega")?.iter().map(|&w| ideal_transfer(t_sep, w)).collect()))
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
    r: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (z, s, q) = (vec3(&zeta0, "zeta0")?, vec3(&sigma0, "sigma0")?, vec3(&q, "q")?);
    let cfg = FringeEkf { zeta0: [z.x, z.y, z.z], sigma0: [s.x, s.y, s.z], q: [q.x, q.y, q.z], r };
    let (p, psi) = (p.as_array().to_vec(), psi.as_array().to_vec());
    let out = py.detach(|| fringe_track(&p, &psi, &cfg))?;
    Ok(to_py_rows(py, &out))
}

/// ML noise identification over batches / a sliding window; a dict of arrays.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn cai_ml_identify<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    phi: PyReadonlyArray1<'py, f64>,
    amp: PyReadonlyArray1<'py, f64>,
    method: &str,
    free: [bool; 3],
    theta0: PyReadonlyArray1<'py, f64>,
    max_iter: usize,
    tol: f64,
    batch: usize,
    sliding: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let method = match method {
        "gradient" => Method::Gradient,
        "newton" => Method::Newton,
        other => return Err(invalid("method", format!("unknown option {other:?}; choose gradient, newton")).into()),
    };
    let th = vec3(&theta0, "theta0")?;
    let cfg = MlConfig { method, free, theta0: [th.x, th.y, th.z], max_iter, tol };
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
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // column names of CaiSetup.predict / CaiSetup.jacobian (single source of truth)
    m.add("CAI_TERMS", TERM_NAMES.to_vec())?;
    m.add("CAI_JACOBIAN_PARAMS", JACOBIAN_PARAMS.to_vec())?;
    m.add_class::<CaiChannels>()?;
    m.add_class::<CaiSetup>()?;
    m.add_class::<CaiGravity>()?;
    m.add_class::<CaiMotion>()?;
    m.add_class::<CaiHybrid>()?;
    m.add_function(wrap_pyfunction!(cai_aided_ins, m)?)?;
    m.add_function(wrap_pyfunction!(cai_in_shot_noise, m)?)?;
    m.add_class::<CaiSensor>()?;
    m.add_function(wrap_pyfunction!(cai_phase_closed_form, m)?)?;
    m.add_function(wrap_pyfunction!(cai_sensitivity, m)?)?;
    m.add_function(wrap_pyfunction!(cai_convolution_phase, m)?)?;
    m.add_function(wrap_pyfunction!(cai_response_area, m)?)?;
    m.add_function(wrap_pyfunction!(cai_ideal_transfer, m)?)?;
    m.add_function(wrap_pyfunction!(cai_fringe_track, m)?)?;
    m.add_function(wrap_pyfunction!(cai_ml_identify, m)?)?;
    Ok(())
}

/// The triad of an IMU error model from its two dicts (as `atomnav.imu.ImuErrors._to_core`).
fn error_model(accel: &Bound<'_, PyDict>, gyro: &Bound<'_, PyDict>, name: &str) -> PyResult<ImuErrorModel> {
    let m = ImuErrorModel { accel: triad_from_dict(accel, &format!("{name}.accel"))?, gyro: triad_from_dict(gyro, &format!("{name}.gyro"))? };
    m.validate()?;
    Ok(m)
}

fn omega_dot_mode(name: &str, half_width: usize) -> PyResult<OmegaDot> {
    match name {
        "zero" => Ok(OmegaDot::Zero),
        "pwl" => Ok(OmegaDot::Pwl),
        "savgol" => Ok(OmegaDot::Savgol { half_width }),
        other => Err(invalid("omega_dot", format!("unknown option {other:?}; choose zero, pwl, savgol")).into()),
    }
}

fn interpolation_mode(name: &str) -> PyResult<Interpolation> {
    match name {
        "linear" => Ok(Interpolation::Linear),
        "cubic" => Ok(Interpolation::Cubic),
        other => Err(invalid("interpolation", format!("unknown option {other:?}; choose linear, cubic")).into()),
    }
}

/// The CAI sensor as the aiding sees it (channels, T, readout, R inflation, predictor and
/// Jacobian options, extra states, force mode), checked once; built by
/// `atomnav.cai.hybrid.CaiSensor._native()` and taken, with their shots, by the Monte Carlo
/// (`CaiHybrid`), `cai_aided_ins` and `cai_in_shot_noise`.
#[pyclass(name = "CaiSensor", module = "atomnav._core", frozen)]
pub struct CaiSensor(CaiConfig);

#[pymethods]
impl CaiSensor {
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (channels, t_sep, readout, inflation, omega_dot, savgol_half_width, interpolation, substeps, jacobian_euler,
        misalignment, lever_arm, force))]
    fn new(
        channels: &CaiChannels,
        t_sep: f64,
        readout: (f64, f64, f64),
        inflation: Option<(f64, f64)>,
        omega_dot: &str,
        savgol_half_width: usize,
        interpolation: &str,
        substeps: usize,
        jacobian_euler: bool,
        misalignment: Option<f64>,
        lever_arm: Option<f64>,
        force: Option<(f64, f64)>,
    ) -> PyResult<Self> {
        let cfg = CaiConfig {
            channels: channels.0.clone(),
            t_sep,
            shots: Vec::new(),
            offset: readout.0,
            contrast: readout.1,
            sigma_p: readout.2,
            inflation,
            omega_dot: omega_dot_mode(omega_dot, savgol_half_width)?,
            interpolation: interpolation_mode(interpolation)?,
            substeps,
            jacobian_euler,
            misalignment,
            lever_arm,
            force: force.map_or(ForceMode::Bias, |(tau, sigma)| ForceMode::Direct { tau, sigma }),
            kind: ImuKind::Rates,
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

/// In-shot IMU noise of one shot of `sensor` on a regular record of spacing `dt` (s)
/// (samples from the interpolation / ω̇ window before the shot to its end, as the aiding
/// holds them), white PSDs q_a (m²/s³), q_g (rad²/s): the phase covariance Σ (channels ×
/// channels, rad²) and, for each 15-state model f[k] (steps, 15, 15) held over a filter
/// step of one shot, E[w δφ̂ᵀ] (steps, 15, channels) (see cai/in_shot.rs).
#[pyfunction]
fn cai_in_shot_noise<'py>(py: Python<'py>, sensor: &CaiSensor, dt: f64, q_a: f64, q_g: f64, f: PyReadonlyArray3<'py, f64>) -> PyResult<(Arr2<'py>, Bound<'py, numpy::PyArray3<f64>>)> {
    crate::error::check_positive("dt", dt)?;
    for (name, q) in [("q_a", q_a), ("q_g", q_g)] {
        if !(q.is_finite() && q >= 0.0) {
            return Err(invalid(name, format!("must be finite and >= 0, got {q}")).into());
        }
    }
    let cfg = &sensor.0;
    let pad = match cfg.omega_dot { OmegaDot::Savgol { half_width } => 3.max(2 * half_width + 1), _ => 3 };
    let n = (2.0 * cfg.t_sep / dt + 1e-9).floor() as usize + pad + 1;
    let t: Vec<f64> = (0..n).map(|i| (i as f64 - pad as f64) * dt).collect();
    let fs = super::filter::mats(&f, "f")?;
    let m = cfg.channels.len();
    let (sigma, cross) = py.detach(|| -> crate::Result<_> {
        let pcfg = PredictorConfig { t_sep: cfg.t_sep, substeps: cfg.substeps, gradient: None, bias_a: Vec3::zeros(), bias_g: Vec3::zeros(), omega_dot: cfg.omega_dot.clone(), interpolation: cfg.interpolation };
        let sens = in_shot::sensitivity(&t, 0.0, &cfg.channels, &pcfg)?;
        let sigma = in_shot::covariance(&t, &sens, q_a, q_g, m);
        let cross: Vec<_> = fs.iter().map(|fk| in_shot::cross_covariance(fk, &t, 0.0, cfg.t_sep, &sens, q_a, q_g)).collect::<crate::Result<_>>()?;
        Ok((sigma, cross))
    })?;
    let flat: Vec<f64> = cross.iter().flat_map(|c| (0..15).flat_map(move |i| (0..m).map(move |j| c[(i, j)]))).collect();
    Ok((super::convert::mat_to_py(py, &sigma), numpy::PyArray1::from_vec(py, flat).reshape([cross.len(), 15, m])?))
}

/// A CAI-aided INS scenario (truth, IMU errors, CAI, filter), built once; `monte_carlo`
/// runs seeded runs in parallel with the GIL released.
#[pyclass(module = "atomnav._core", frozen)]
struct CaiHybrid(HybridScenario);

#[pymethods]
impl CaiHybrid {
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (motion, ellipsoid, rate_hz, truth_rate_hz, imu_accel, imu_gyro, reference, sensor, shots,
        noise, predict_every, p0, aiding, draw_initial))]
    fn new(
        py: Python<'_>,
        motion: &Motion,
        ellipsoid: Wrap<Ellipsoid>,
        rate_hz: f64,
        truth_rate_hz: Option<f64>,
        imu_accel: &Bound<'_, PyDict>,
        imu_gyro: &Bound<'_, PyDict>,
        reference: Option<(Bound<'_, PyDict>, Bound<'_, PyDict>)>,
        sensor: &CaiSensor,
        shots: PyReadonlyArray1<'_, f64>,
        noise: (f64, f64, f64, f64),
        predict_every: usize,
        p0: PyReadonlyArray2<'_, f64>,
        aiding: bool,
        draw_initial: bool,
    ) -> PyResult<Self> {
        let ell = ellipsoid.0;
        let cai = sensor.with_shots(&shots)?;
        let imu_model = error_model(imu_accel, imu_gyro, "imu")?;
        let reference = reference.map(|(a, g)| error_model(&a, &g, "reference")).transpose()?;
        let p0 = super::convert::mat(&p0, "p0")?;
        let m = &motion.inner;
        let scenario = py.detach(|| -> crate::Result<HybridScenario> {
            let (t, truth, f, w) = HybridScenario::imu_truth(m, &ell, rate_hz)?;
            let phase = match (reference, truth_rate_hz) {
                (Some(model), _) => PhaseSource::Reference(model),
                (None, Some(r)) if r == rate_hz => PhaseSource::Ideal(HybridScenario::ideal_phases(m, &ell, &t, &truth, &f, &w, &cai)?),
                (None, Some(r)) => {
                    let (tt, tr, tf, tw) = HybridScenario::imu_truth(m, &ell, r)?;
                    PhaseSource::Ideal(HybridScenario::ideal_phases(m, &ell, &tt, &tr, &tf, &tw, &cai)?)
                }
                (None, None) => return Err(invalid("truth_rate_hz", "required without a reference IMU")),
            };
            let rw = |psd: f64| BiasModel::RandomWalk { psd };
            let filter = AidedConfig {
                noise: InsNoise { accel_psd: noise.0, gyro_psd: noise.1, accel_bias: rw(noise.2), gyro_bias: rw(noise.3) },
                predict_every,
                method: Discretization::VanLoan,
                mode: LoopMode::Closed,
                sequential: false,
                gate: None,
            };
            Ok(HybridScenario { ell, t, truth, f, w, imu_model, cai, phase, filter, p0, aiding, draw_initial })
        })?;
        Ok(CaiHybrid(scenario))
    }

    /// Runs `runs` under `seed`: dict of arrays, each (runs, epochs, ...) except
    /// `phase_error` (runs, shots, channels), `accel_error` (runs, samples, 3), `time`
    /// (epochs) and `imu_time` (samples).
    fn monte_carlo<'py>(&self, py: Python<'py>, seed: u64, runs: Vec<u64>) -> PyResult<Bound<'py, PyDict>> {
        let res = py.detach(|| self.0.monte_carlo(seed, &runs))?;
        let d = PyDict::new(py);
        let nr = res.len();
        let ne = res.first().map_or(0, |r| r.time.len());
        if res.iter().any(|r| r.time.len() != ne) {
            return Err(crate::NavError::Numerical("runs produced different numbers of epochs".into()).into());
        }
        let cube = |w: usize, get: &dyn Fn(&HybridRun) -> Vec<f64>| -> PyResult<Bound<'py, numpy::PyArray3<f64>>> {
            let flat: Vec<f64> = res.iter().flat_map(get).collect();
            Ok(numpy::PyArray1::from_vec(py, flat).reshape([nr, ne, w])?)
        };
        d.set_item("time", vec_to_py(py, res.first().map_or_else(Vec::new, |r| r.time.clone())))?;
        d.set_item("hybrid", cube(9, &|r| r.hybrid.iter().flatten().copied().collect())?)?;
        d.set_item("free", cube(9, &|r| r.free.iter().flatten().copied().collect())?)?;
        d.set_item("bias", cube(6, &|r| r.bias.iter().flatten().copied().collect())?)?;
        d.set_item("bias_true", cube(6, &|r| r.bias_true.iter().flatten().copied().collect())?)?;
        let ns = self.0.t.len();
        let flat: Vec<f64> = res.iter().flat_map(|r| r.accel_error.iter().flatten().copied()).collect();
        d.set_item("accel_error", numpy::PyArray1::from_vec(py, flat).reshape([nr, ns, 3])?)?;
        d.set_item("imu_time", vec_to_py(py, self.0.t.clone()))?;
        let n = if ne > 0 { res[0].sigma.len() / ne } else { 0 };
        d.set_item("sigma", cube(n, &|r| r.sigma.clone())?)?;
        if res.iter().all(|r| r.nees.len() == ne) {
            d.set_item("nees", cube(1, &|r| r.nees.clone())?)?;
        }
        let nch = self.0.cai.channels.len();
        let nshots = res.first().map_or(0, |r| r.phase_error.len() / nch);
        let flat: Vec<f64> = res.iter().flat_map(|r| r.phase_error.iter().copied()).collect();
        d.set_item("phase_error", numpy::PyArray1::from_vec(py, flat).reshape([nr, nshots, nch])?)?;
        Ok(d)
    }

    /// Shot start times (s).
    #[getter]
    fn shots<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_to_py(py, self.0.cai.shots.clone())
    }

    /// Ideal specific force (N, 3) m/s² and angular rate (N, 3) rad/s at the IMU times, and the times.
    fn ideal_imu<'py>(&self, py: Python<'py>) -> (Arr1<'py>, Arr2<'py>, Arr2<'py>) {
        (vec_to_py(py, self.0.t.clone()), vec3_to_py(py, &self.0.f), vec3_to_py(py, &self.0.w))
    }
}

/// CAI-aided INS on the generic engine (`atomnav.filter.AidedIns`): the shots' data are
/// either emulated (`phase` true phases + `noise` population noise, shots × channels, the
/// laser phase steered inside the loop) or recorded (`population` + `laser_phase`).
#[pyfunction]
#[pyo3(signature = (ins, extra0, sensor, shots, data_kind, data_a, data_b))]
#[allow(clippy::too_many_arguments)]
fn cai_aided_ins(
    ins: PyRef<'_, AidedSetup>,
    extra0: PyReadonlyArray1<'_, f64>,
    sensor: &CaiSensor,
    shots: PyReadonlyArray1<'_, f64>,
    data_kind: &str,
    data_a: PyReadonlyArray2<'_, f64>,
    data_b: PyReadonlyArray2<'_, f64>,
) -> PyResult<PyAidedIns> {
    let mut cfg = sensor.with_shots(&shots)?;
    cfg.kind = ins.kind;
    // (shots, channels) tables, read row-major; the aiding checks their sizes
    let flat = |a: &PyReadonlyArray2<'_, f64>| a.as_array().iter().copied().collect::<Vec<f64>>();
    let (a, b) = (flat(&data_a), flat(&data_b));
    let data = match data_kind {
        "emulated" => CaiData::Emulated { phase: a, noise: b },
        "recorded" => CaiData::Recorded { population: a, laser_phase: b },
        other => return Err(invalid("data", format!("unknown kind {other:?}; choose emulated, recorded")).into()),
    };
    let (sa, sb) = (data_a.shape()[1], data_b.shape()[1]);
    for (name, w) in [(if data_kind == "emulated" { "phase" } else { "population" }, sa), (if data_kind == "emulated" { "noise" } else { "laser_phase" }, sb)] {
        if w != cfg.channels.len() {
            return Err(invalid(name, format!("has {w} interferometers per shot, but the configuration has {}", cfg.channels.len())).into());
        }
    }
    let aiding = CaiAiding::new(cfg, data)?;
    PyAidedIns::from_aiding(&ins, DVector::from_vec(vector(&extra0, "extra0")?), Box::new(aiding))
}
