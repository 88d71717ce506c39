//! Bindings of astro/: gyro increments, star attitudes, mount calibration, scenario runs.

use super::convert::{index_count, mat_to_py, mats, mats_to_py, quat_to_py, real, register_choices, seed, vec3_rows, vec3_to_py, vector, Wrap};
use crate::astro::calibration::{self, Calibration, CovarianceForm, DiffForm, IncrementErrors, Init, Observability, Options, ResidualForm, Solver, Start, Verdict};
use crate::astro::increments::{self, GyroErrorMode, GyroErrorModel, ImuRecord, Mat39, TaylorVariant};
use crate::astro::scenario::{self, Run, Scenario};
use crate::astro::stars::{self, Camera, Catalog, Observations};
use crate::astro::{d1, d2, euler_dcm, euler_from_dcm};
use crate::math::check_rotations;
use crate::error::{invalid, NavError};
use crate::math::{Mat3, Vec3};
use crate::options::Choice;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::borrow::Cow;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

type Arr3<'py> = Bound<'py, PyArray3<f64>>;

/// A series of rotation matrices (N, 3, 3), each checked to be a rotation.
fn rotations(a: &PyReadonlyArray3<'_, f64>, field: &str) -> Result<Vec<Mat3>, NavError> {
    let m = mats::<3, 3>(a, field)?;
    check_rotations(field, &m)?;
    Ok(m)
}

fn vec_to_py<'py>(py: Python<'py>, v: &Vec3) -> Bound<'py, PyArray1<f64>> {
    vec![v.x, v.y, v.z].into_pyarray(py)
}

// invariant: r has 3 rows of 3 (checked above), i, j < 3.
#[allow(clippy::indexing_slicing)]
fn mat3_arg(a: &PyReadonlyArray2<'_, f64>, field: &str) -> Result<Mat3, NavError> {
    let r = super::convert::rows::<3>(a, field)?;
    if r.len() != 3 {
        return Err(invalid(field, format!("expected shape (3, 3), got ({}, 3)", r.len())));
    }
    Ok(Mat3::from_fn(|i, j| r[i][j]))
}

fn gyro_model(sigmas: (f64, f64, f64, f64), mode: GyroErrorMode) -> Result<GyroErrorModel, NavError> {
    let m = GyroErrorModel { sigma_phi: sigmas.0, sigma_k: sigmas.1, sigma_w: sigmas.2, sigma_b: sigmas.3, mode };
    m.validate()?;
    Ok(m)
}

#[pyfunction]
fn astro_euler_dcm<'py>(py: Python<'py>, beta: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let b = vec3_rows(&beta, "beta")?;
    Ok(mats_to_py(py, &b.iter().map(euler_dcm).collect::<Vec<_>>()))
}

#[pyfunction]
fn astro_euler_from_dcm<'py>(py: Python<'py>, c: PyReadonlyArray3<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let c = rotations(&c, "c")?;
    Ok(vec3_to_py(py, &c.iter().map(euler_from_dcm).collect::<Vec<_>>()))
}

#[pyfunction]
fn astro_d1_d2<'py>(py: Python<'py>, beta: PyReadonlyArray2<'py, f64>) -> PyResult<(Arr3<'py>, Arr3<'py>)> {
    let b = vec3_rows(&beta, "beta")?;
    Ok((mats_to_py(py, &b.iter().map(d1).collect::<Vec<_>>()), mats_to_py(py, &b.iter().map(d2).collect::<Vec<_>>())))
}

/// An (N, 3) array read in place when C-contiguous (copied otherwise). NaN/inf are left to
/// the core's validation pass, which names the first bad row: no second pass here.
// invariant: a 2-D array's shape has 2 entries; rows have 3 columns (checked above).
#[allow(clippy::indexing_slicing)]
fn rows3<'a>(a: &'a PyReadonlyArray2<'_, f64>, field: &str) -> Result<Cow<'a, [[f64; 3]]>, NavError> {
    let s = a.shape();
    if s[1] != 3 {
        return Err(invalid(field, format!("expected shape (N, 3), got ({}, {})", s[0], s[1])));
    }
    Ok(match a.as_slice() {
        Ok(flat) => Cow::Borrowed(flat.as_chunks::<3>().0),
        Err(_) => Cow::Owned(a.as_array().outer_iter().map(|r| [r[0], r[1], r[2]]).collect()),
    })
}

/// The gyro increments, camera epochs and gyro error model shared by the increment calls.
fn gyro_record<'a>(
    rho: &'a PyReadonlyArray2<'_, f64>,
    epochs: &PyReadonlyArray1<'_, f64>,
    sigmas: (f64, f64, f64, f64),
    mode: GyroErrorMode,
) -> PyResult<(Cow<'a, [[f64; 3]]>, Vec<f64>, GyroErrorModel)> {
    Ok((rows3(rho, "gyro_increments")?, vector(epochs, "epochs")?, gyro_model(sigmas, mode)?))
}

type IncrementArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray3<f64>>, Option<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<f64>>)>);

#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn astro_increments<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = real)] t_start: f64,
    #[pyo3(from_py_with = real)] period: f64,
    rho: PyReadonlyArray2<'py, f64>,
    epochs: PyReadonlyArray1<'py, f64>,
    sigmas: (f64, f64, f64, f64),
    mode: Wrap<GyroErrorMode>,
    taylor_variant: Wrap<TaylorVariant>,
) -> PyResult<IncrementArrays<'py>> {
    let (rho, epochs, model) = gyro_record(&rho, &epochs, sigmas, mode.0)?;
    let variant = taylor_variant.0;
    let inc = py.detach(|| increments::integrate_increments(&ImuRecord { t_start, period, rho: &rho[..] }, &epochs, &model, variant))?;
    let q: Vec<_> = inc.iter().map(|i| i.q).collect();
    let cov: Vec<Mat3> = inc.iter().map(|i| i.cov).collect();
    let sens = (model.mode == GyroErrorMode::Consistent).then(|| {
        let (jm, jb): (Vec<_>, Vec<Mat3>) = inc.iter().filter_map(|i| i.sensitivities).unzip();
        (mats_to_py(py, &jm), mats_to_py(py, &jb))
    });
    Ok((quat_to_py(py, &q), mats_to_py(py, &cov), sens))
}

#[pyfunction]
fn astro_dead_reckoning_cov<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = real)] t_start: f64,
    #[pyo3(from_py_with = real)] period: f64,
    rho: PyReadonlyArray2<'py, f64>,
    epochs: PyReadonlyArray1<'py, f64>,
    sigmas: (f64, f64, f64, f64),
    mode: Wrap<GyroErrorMode>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (rho, epochs, model) = gyro_record(&rho, &epochs, sigmas, mode.0)?;
    let p = py.detach(|| increments::dead_reckoning_cov(&ImuRecord { t_start, period, rho: &rho[..] }, &epochs, &model))?;
    Ok(mats_to_py(py, &p))
}

fn observability_dict<'py>(py: Python<'py>, o: &Observability) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("axes_vf", vec3_to_py(py, &o.axes_vf))?;
    d.set_item("angles", o.angles.clone().into_pyarray(py))?;
    d.set_item("cluster", o.cluster.clone().into_pyarray(py))?;
    d.set_item("n_clusters", o.n_clusters)?;
    d.set_item("eigenvalues", vec_to_py(py, &o.eigenvalues))?;
    d.set_item("eigenvectors", mat_to_py(py, &o.eigenvectors))?;
    d.set_item("kappa", o.kappa)?;
    d.set_item("weak_axis_vf", vec_to_py(py, &o.weak_axis_vf()))?;
    d.set_item("verdict", o.verdict.name())?;
    Ok(d)
}

fn calibration_dict<'py>(py: Python<'py>, c: &Calibration) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("c", mat_to_py(py, &c.c))?;
    d.set_item("beta", vec_to_py(py, &c.beta))?;
    d.set_item("iterations", c.iterations)?;
    d.set_item("residuals", vec3_to_py(py, &c.residuals))?;
    d.set_item("relative_misfit", c.relative_misfit)?;
    d.set_item("p_s", mat_to_py(py, &c.p_s))?;
    d.set_item("p_theta", mat_to_py(py, &c.p_theta))?;
    d.set_item("p_beta", mat_to_py(py, &c.p_beta))?;
    d.set_item("p_clb", mat_to_py(py, &c.p_clb))?;
    d.set_item("covariance", c.covariance.name())?;
    d.set_item("singular_values", vec_to_py(py, &c.singular_values))?;
    d.set_item("condition_number", c.condition_number)?;
    d.set_item("weak_axis_mf", vec_to_py(py, &c.weak_axis_mf))?;
    d.set_item("sigma_weak", c.sigma_weak)?;
    d.set_item("observability", observability_dict(py, &c.observability)?)?;
    Ok(d)
}

/// The consistent gyro mode's sensitivities `j_m` (M, 3, 9), `j_b` (M, 3, 3) with the budget
/// `sigmas` (all or none), for the constant-error terms of the model covariance.
fn constant_errors(j_m: Option<PyReadonlyArray3<'_, f64>>, j_b: Option<PyReadonlyArray3<'_, f64>>, sigmas: Option<(f64, f64, f64, f64)>) -> PyResult<Option<(Vec<(Mat39, Mat3)>, GyroErrorModel)>> {
    match (j_m, j_b, sigmas) {
        (None, None, None) => Ok(None),
        (Some(jm), Some(jb), Some(sg)) => {
            let pairs = calibration::sensitivity_pairs(mats::<3, 9>(&jm, "j_m")?, mats::<3, 3>(&jb, "j_b")?)?;
            Ok(Some((pairs, gyro_model(sg, GyroErrorMode::Consistent)?)))
        }
        _ => Err(invalid("j_m", "give j_m, j_b and sigmas together (consistent gyro mode) or none of them").into()),
    }
}

#[pyfunction]
#[pyo3(signature = (ds_imu, ds_avu, *, init=Wrap(Start::Axes), c0=None, solver=Wrap(Solver::So3), max_iter=None, tol=1e-9, residual_form=Wrap(ResidualForm::Full),
                    covariance=None, e_imu=None, p_avu=None, j_m=None, j_b=None, sigmas=None))]
#[allow(clippy::too_many_arguments)]
fn astro_calibrate<'py>(
    py: Python<'py>,
    ds_imu: PyReadonlyArray3<'py, f64>,
    ds_avu: PyReadonlyArray3<'py, f64>,
    init: Wrap<Start>,
    c0: Option<PyReadonlyArray2<'py, f64>>,
    solver: Wrap<Solver>,
    max_iter: Option<Bound<'py, PyAny>>,
    #[pyo3(from_py_with = real)] tol: f64,
    residual_form: Wrap<ResidualForm>,
    covariance: Option<Wrap<CovarianceForm>>,
    e_imu: Option<PyReadonlyArray3<'py, f64>>,
    p_avu: Option<PyReadonlyArray3<'py, f64>>,
    j_m: Option<PyReadonlyArray3<'py, f64>>,
    j_b: Option<PyReadonlyArray3<'py, f64>>,
    sigmas: Option<(f64, f64, f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, b) = (mats::<3, 3>(&ds_imu, "ds_imu")?, mats::<3, 3>(&ds_avu, "ds_avu")?);
    let c0 = c0.map(|c| mat3_arg(&c, "c0")).transpose()?;
    let max_iter = max_iter.map(|n| index_count(&n, "max_iter", 1, usize::MAX)).transpose()?.unwrap_or(Options::default().max_iter);
    let opt = Options { covariance: covariance.map(|c| c.0), ..Options::new(Init::new(init.0, c0)?, solver.0, max_iter, tol, residual_form.0)? };
    let e = e_imu.map(|e| mats::<3, 3>(&e, "e_imu")).transpose()?;
    let p = p_avu.map(|p| mats::<3, 3>(&p, "p_avu")).transpose()?;
    let sens = constant_errors(j_m, j_b, sigmas)?;
    let constant = sens.as_ref().map(|(s, m)| calibration::ConstantGyroErrors { sensitivities: s, p_m: m.p_m(), sigma_b: m.sigma_b });
    let errors = IncrementErrors::given(e.as_deref(), p.as_deref(), constant.as_ref())?;
    let cal = py.detach(|| calibration::calibrate_with(&a, &b, &opt, errors.as_ref()))?;
    calibration_dict(py, &cal)
}

#[pyfunction]
fn astro_observability<'py>(py: Python<'py>, ds_avu: PyReadonlyArray3<'py, f64>) -> PyResult<Bound<'py, PyDict>> {
    let b = rotations(&ds_avu, "ds_avu")?;
    observability_dict(py, &calibration::observability(&b))
}

fn cameras_arg(c: &PyReadonlyArray3<'_, f64>, p: &PyReadonlyArray3<'_, f64>) -> Result<Vec<Camera>, NavError> {
    let (c, p) = (mats::<3, 3>(c, "cameras")?, mats::<3, 3>(p, "p_alpha")?);
    if c.len() != p.len() {
        return Err(invalid("p_alpha", format!("expected {} covariances (one per camera), got {}", c.len(), p.len())));
    }
    Ok(c.into_iter().zip(p).map(|(c_vf_cf, p_alpha)| Camera { c_vf_cf, p_alpha }).collect())
}

fn indices(a: &PyReadonlyArray1<'_, i64>, field: &str) -> Result<Vec<usize>, NavError> {
    a.as_array()
        .iter()
        .enumerate()
        .map(|(i, &x)| usize::try_from(x).map_err(|_| invalid(field, format!("negative index {x} at index {i}"))))
        .collect()
}

#[pyfunction]
#[pyo3(signature = (epoch, camera, s_cf, g, n_epochs, *, cameras, p_alpha, sigma_s, up_gcrs=None, n_refr=1.0, p_avu=None))]
#[allow(clippy::too_many_arguments)]
fn astro_star_attitudes<'py>(
    py: Python<'py>,
    epoch: PyReadonlyArray1<'py, i64>,
    camera: PyReadonlyArray1<'py, i64>,
    s_cf: PyReadonlyArray2<'py, f64>,
    g: PyReadonlyArray2<'py, f64>,
    n_epochs: &Bound<'py, PyAny>,
    cameras: PyReadonlyArray3<'py, f64>,
    p_alpha: PyReadonlyArray3<'py, f64>,
    #[pyo3(from_py_with = real)] sigma_s: f64,
    up_gcrs: Option<PyReadonlyArray2<'py, f64>>,
    #[pyo3(from_py_with = real)] n_refr: f64,
    p_avu: Option<PyReadonlyArray3<'py, f64>>,
) -> PyResult<(Arr3<'py>, Arr3<'py>, Bound<'py, PyArray1<i64>>)> {
    let obs = Observations { epoch: indices(&epoch, "epoch")?, camera: indices(&camera, "camera")?, s_cf: vec3_rows(&s_cf, "star_directions")?, g: vec3_rows(&g, "catalog_directions")? };
    let n_epochs = index_count(n_epochs, "n_epochs", 1, usize::MAX)?;
    let cams = cameras_arg(&cameras, &p_alpha)?;
    let up = up_gcrs.map(|u| vec3_rows(&u, "up_gcrs")).transpose()?;
    let p_avu = p_avu.map(|p| mats::<3, 3>(&p, "p_avu")).transpose()?;
    let att = py.detach(|| stars::star_attitudes(&obs, n_epochs, &cams, sigma_s, up.as_deref().map(|u| (u, n_refr)), p_avu.as_deref()))?;
    let counts: Vec<i64> = att.stars.iter().map(|&k| k as i64).collect();
    Ok((mats_to_py(py, &att.s), mats_to_py(py, &att.p), counts.into_pyarray(py)))
}

#[pyfunction]
fn astro_astro_increments<'py>(py: Python<'py>, s_vf: PyReadonlyArray3<'py, f64>, p_avu: PyReadonlyArray3<'py, f64>) -> PyResult<(Arr3<'py>, Arr3<'py>)> {
    let (s, p) = (mats::<3, 3>(&s_vf, "s_vf")?, mats::<3, 3>(&p_avu, "p_avu")?);
    if s.len() != p.len() {
        return Err(invalid("p_avu", format!("expected {} covariances, got {}", s.len(), p.len())).into());
    }
    check_rotations("s_vf", &s)?;
    let (ds, e) = stars::astro_increments(&s, &p);
    Ok((mats_to_py(py, &ds), mats_to_py(py, &e)))
}

/// P_β^model and P_β^sys (rad²) at the mount `c` from the interval and epoch
/// covariances; with the consistent gyro mode's sensitivities `j_m` (M, 3, 9), `j_b`
/// (M, 3, 3) and the budget `sigmas` the constant-error cross terms are included.
#[pyfunction]
#[pyo3(signature = (c, ds_imu, ds_avu, e_imu, p_avu, j_m=None, j_b=None, sigmas=None))]
#[allow(clippy::too_many_arguments)]
fn astro_model_covariance<'py>(
    py: Python<'py>,
    c: PyReadonlyArray2<'py, f64>,
    ds_imu: PyReadonlyArray3<'py, f64>,
    ds_avu: PyReadonlyArray3<'py, f64>,
    e_imu: PyReadonlyArray3<'py, f64>,
    p_avu: PyReadonlyArray3<'py, f64>,
    j_m: Option<PyReadonlyArray3<'py, f64>>,
    j_b: Option<PyReadonlyArray3<'py, f64>>,
    sigmas: Option<(f64, f64, f64, f64)>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    let c = mat3_arg(&c, "c")?;
    crate::math::check_rotation("c", 0, &c)?;
    let (a, b) = (mats::<3, 3>(&ds_imu, "ds_imu")?, mats::<3, 3>(&ds_avu, "ds_avu")?);
    calibration::check_increments(&a, &b)?;
    let (e, p) = (mats::<3, 3>(&e_imu, "e_imu")?, mats::<3, 3>(&p_avu, "p_avu")?);
    stars::check_covariances("e_imu", &e, a.len())?;
    stars::check_covariances("p_avu", &p, a.len() + 1)?;
    let sens = constant_errors(j_m, j_b, sigmas)?;
    let constant = sens.as_ref().map(|(s, m)| calibration::ConstantGyroErrors { sensitivities: s, p_m: m.p_m(), sigma_b: m.sigma_b });
    let (pm, ps) = calibration::model_covariance(&c, &a, &b, &e, &p, constant.as_ref())?;
    Ok((mat_to_py(py, &pm), mat_to_py(py, &ps)))
}

#[pyfunction]
fn astro_aberration<'py>(py: Python<'py>, directions: PyReadonlyArray2<'py, f64>, velocity: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (s, v) = (vec3_rows(&directions, "directions")?, vec3_rows(&velocity, "velocity")?);
    Ok(vec3_to_py(py, &stars::aberration_rows(&s, &v)?))
}

type CatalogArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u64>>);

#[pyfunction]
fn astro_synthetic_catalog<'py>(py: Python<'py>, #[pyo3(from_py_with = real)] m_lim: f64, seed: &Bound<'py, PyAny>) -> PyResult<CatalogArrays<'py>> {
    let c = Catalog::synthetic(m_lim, super::convert::seed(seed, "seed")?)?;
    Ok((vec3_to_py(py, &c.dirs), c.mags.into_pyarray(py), c.ids.into_pyarray(py)))
}

#[pyfunction]
fn astro_refraction<'py>(py: Python<'py>, s: PyReadonlyArray2<'py, f64>, u: PyReadonlyArray2<'py, f64>, #[pyo3(from_py_with = real)] n_refr: f64, apply: bool) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (s, u) = (vec3_rows(&s, "directions")?, vec3_rows(&u, "up")?);
    Ok(vec3_to_py(py, &stars::refraction_rows(&s, &u, n_refr, apply)?))
}

#[pyfunction]
fn astro_refractive_index(#[pyo3(from_py_with = real)] height: f64) -> PyResult<f64> {
    Ok(stars::refractive_index(height)?)
}

#[pyfunction]
#[pyo3(signature = (catalog_dirs, catalog_mags, s_gcrs_vf, up_gcrs, cameras, *, fov_half, m_lim, sigma_s, n_refr, seed))]
#[allow(clippy::too_many_arguments)]
fn astro_simulate_observations<'py>(
    py: Python<'py>,
    catalog_dirs: PyReadonlyArray2<'py, f64>,
    catalog_mags: PyReadonlyArray1<'py, f64>,
    s_gcrs_vf: PyReadonlyArray3<'py, f64>,
    up_gcrs: PyReadonlyArray2<'py, f64>,
    cameras: PyReadonlyArray3<'py, f64>,
    #[pyo3(from_py_with = real)] fov_half: f64,
    #[pyo3(from_py_with = real)] m_lim: f64,
    #[pyo3(from_py_with = real)] sigma_s: f64,
    #[pyo3(from_py_with = real)] n_refr: f64,
    seed: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let dirs = vec3_rows(&catalog_dirs, "catalog_directions")?;
    let mags = vector(&catalog_mags, "magnitudes")?;
    let ids = (0..dirs.len() as u64).collect();
    let cat = Catalog::new(dirs, mags, ids)?;
    let s = mats::<3, 3>(&s_gcrs_vf, "s_gcrs_vf")?;
    let up = vec3_rows(&up_gcrs, "up_gcrs")?;
    let cams: Vec<Camera> = mats::<3, 3>(&cameras, "cameras")?.into_iter().map(|c| Camera { c_vf_cf: c, p_alpha: Mat3::zeros() }).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(super::convert::seed(seed, "seed")?);
    let obs = py.detach(|| stars::simulate_observations(&cat, &s, &up, &cams, fov_half, m_lim, sigma_s, n_refr, &mut rng))?;
    observations_dict(py, &obs)
}

fn observations_dict<'py>(py: Python<'py>, o: &Observations) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("epoch", o.epoch.iter().map(|&x| x as i64).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("camera", o.camera.iter().map(|&x| x as i64).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("s_cf", vec3_to_py(py, &o.s_cf))?;
    d.set_item("g", vec3_to_py(py, &o.g))?;
    Ok(d)
}

/// The paper's gyro budget (σ_φ, σ_k, σ_w, σ_b) in SI units.
#[pyfunction]
fn astro_vasilyuk2024_gyro_budget() -> (f64, f64, f64, f64) {
    let m = GyroErrorModel::vasilyuk2024(GyroErrorMode::Paper);
    (m.sigma_phi, m.sigma_k, m.sigma_w, m.sigma_b)
}

/// Scenario wrapper kept alive across calls (its truth takes ~1 s to build).
#[pyclass(module = "atomnav._core", name = "AstroScenario")]
pub struct PyScenario {
    inner: Scenario,
}
// the whole truth (catalog, cameras, rotations), so a copy skips the ~1 s build
super::pickle::picklable!(PyScenario, inner, "AstroScenario");

fn scenario_dict<'py>(py: Python<'py>, s: &Scenario) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("epochs", s.epochs.clone().into_pyarray(py))?;
    d.set_item("t_start", s.t_start)?;
    d.set_item("period", s.period)?;
    d.set_item("rho_true", vec3_to_py(py, &s.rho_true))?;
    d.set_item("s_gcrs_vf", mats_to_py(py, &s.s_gcrs_vf))?;
    d.set_item("up_gcrs", vec3_to_py(py, &s.up_gcrs))?;
    d.set_item("c_true", mat_to_py(py, &s.c_true))?;
    d.set_item("cameras", mats_to_py(py, &s.cameras.iter().map(|c| c.c_vf_cf).collect::<Vec<_>>()))?;
    d.set_item("catalog_dirs", vec3_to_py(py, &s.catalog.dirs))?;
    d.set_item("catalog_mags", s.catalog.mags.clone().into_pyarray(py))?;
    d.set_item("fov_half", s.fov_half)?;
    d.set_item("m_lim", s.m_lim)?;
    d.set_item("sigma_s", s.sigma_s)?;
    d.set_item("n_refr", s.n_refr)?;
    Ok(d)
}

fn run_dict<'py>(py: Python<'py>, r: &Run) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("observations", observations_dict(py, &r.observations)?)?;
    d.set_item("stars_per_epoch", r.stars_per_epoch.iter().map(|&x| x as i64).collect::<Vec<_>>().into_pyarray(py))?;
    d.set_item("s_vf", mats_to_py(py, &r.s_vf))?;
    d.set_item("p_avu", mats_to_py(py, &r.p_avu))?;
    d.set_item("ds_imu", mats_to_py(py, &r.ds_imu))?;
    d.set_item("e_imu", mats_to_py(py, &r.e_imu))?;
    d.set_item("ds_avu", mats_to_py(py, &r.ds_avu))?;
    d.set_item("e_avu", mats_to_py(py, &r.e_avu))?;
    d.set_item("calibration", calibration_dict(py, &r.calibration)?)?;
    d.set_item("p_beta_model", mat_to_py(py, &r.p_beta_model))?;
    d.set_item("p_beta_sys", mat_to_py(py, &r.p_beta_sys))?;
    d.set_item("beta_error", vec_to_py(py, &r.beta_error))?;
    d.set_item("theta_error", vec_to_py(py, &r.theta_error))?;
    d.set_item("theta_diff", vec3_to_py(py, &r.theta_diff))?;
    d.set_item("p_diff", mats_to_py(py, &r.p_diff))?;
    Ok(d)
}

#[pymethods]
impl PyScenario {
    /// `vasilyuk2024_like` (after Vasilyuk et al. 2024) with catalog seed and gyro truth "paper" | "consistent".
    #[new]
    #[pyo3(signature = (catalog_seed=None, gyro_error_model=Wrap(GyroErrorMode::Paper)))]
    fn new(py: Python<'_>, catalog_seed: Option<Bound<'_, PyAny>>, gyro_error_model: Wrap<GyroErrorMode>) -> PyResult<Self> {
        let catalog_seed = catalog_seed.map(|s| seed(&s, "catalog_seed")).transpose()?.unwrap_or(scenario::CATALOG_SEED);
        Ok(Self { inner: py.detach(|| scenario::vasilyuk2024_like(catalog_seed, gyro_error_model.0))? })
    }

    fn truth<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        scenario_dict(py, &self.inner)
    }

    #[pyo3(signature = (seed, init=Wrap(Start::Axes), p_diff=Wrap(DiffForm::Full)))]
    fn run<'py>(&self, py: Python<'py>, seed: &Bound<'py, PyAny>, init: Wrap<Start>, p_diff: Wrap<DiffForm>) -> PyResult<Bound<'py, PyDict>> {
        let seed = super::convert::seed(seed, "seed")?;
        let opt = Options { init: Init::named(init.0)?, ..Options::default() };
        let r = py.detach(|| scenario::run(&self.inner, seed, &opt, p_diff.0))?;
        run_dict(py, &r)
    }

    /// Per run: β̂ − β̆ (rad), √diag P_β and √diag P_β^model (rad), fraction of θ^diff components within ±3σ,
    /// mean χ² of θ^diff, Gauss–Newton iterations.
    #[pyo3(signature = (runs, seed0=None, p_diff=Wrap(DiffForm::Full)))]
    fn monte_carlo<'py>(&self, py: Python<'py>, runs: &Bound<'py, PyAny>, seed0: Option<Bound<'py, PyAny>>, p_diff: Wrap<DiffForm>) -> PyResult<Bound<'py, PyDict>> {
        let runs = index_count(runs, "runs", 1, usize::MAX)?;
        let seed0 = seed0.map(|s| seed(&s, "seed0")).transpose()?.unwrap_or(0);
        let s = py.detach(|| scenario::monte_carlo(&self.inner, runs, seed0, &Options::default(), p_diff.0))?;
        let d = PyDict::new(py);
        d.set_item("beta_error", vec3_to_py(py, &s.iter().map(|r| r.beta_error).collect::<Vec<_>>()))?;
        d.set_item("sigma_beta", vec3_to_py(py, &s.iter().map(|r| r.sigma_beta).collect::<Vec<_>>()))?;
        d.set_item("sigma_beta_model", vec3_to_py(py, &s.iter().map(|r| r.sigma_beta_model).collect::<Vec<_>>()))?;
        d.set_item("inside_3sigma", s.iter().map(|r| r.inside_3sigma).collect::<Vec<_>>().into_pyarray(py))?;
        d.set_item("chi2_diff", s.iter().map(|r| r.chi2_diff).collect::<Vec<_>>().into_pyarray(py))?;
        d.set_item("iterations", s.iter().map(|r| r.iterations as i64).collect::<Vec<_>>().into_pyarray(py))?;
        Ok(d)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    register_choices::<Start>(m, "CalibrationInit")?;
    register_choices::<Solver>(m, "CalibrationSolver")?;
    register_choices::<ResidualForm>(m, "ResidualForm")?;
    register_choices::<CovarianceForm>(m, "MountCovariance")?;
    register_choices::<DiffForm>(m, "DiffForm")?;
    register_choices::<GyroErrorMode>(m, "GyroErrorMode")?;
    register_choices::<TaylorVariant>(m, "TaylorVariant")?;
    register_choices::<Verdict>(m, "Verdict")?;
    m.add_class::<PyScenario>()?;
    m.add_function(wrap_pyfunction!(astro_euler_dcm, m)?)?;
    m.add_function(wrap_pyfunction!(astro_euler_from_dcm, m)?)?;
    m.add_function(wrap_pyfunction!(astro_d1_d2, m)?)?;
    m.add_function(wrap_pyfunction!(astro_increments, m)?)?;
    m.add_function(wrap_pyfunction!(astro_dead_reckoning_cov, m)?)?;
    m.add_function(wrap_pyfunction!(astro_calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(astro_observability, m)?)?;
    m.add_function(wrap_pyfunction!(astro_star_attitudes, m)?)?;
    m.add_function(wrap_pyfunction!(astro_astro_increments, m)?)?;
    m.add_function(wrap_pyfunction!(astro_synthetic_catalog, m)?)?;
    m.add_function(wrap_pyfunction!(astro_refraction, m)?)?;
    m.add_function(wrap_pyfunction!(astro_aberration, m)?)?;
    m.add_function(wrap_pyfunction!(astro_model_covariance, m)?)?;
    m.add_function(wrap_pyfunction!(astro_refractive_index, m)?)?;
    m.add_function(wrap_pyfunction!(astro_simulate_observations, m)?)?;
    m.add_function(wrap_pyfunction!(astro_vasilyuk2024_gyro_budget, m)?)?;
    Ok(())
}
