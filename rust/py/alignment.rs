//! Bindings of filter/alignment.rs: the coarse alignment of a static record, the initial
//! covariance of a fine alignment, and the zero-velocity / zero-angular-rate updates as
//! measurement sources (`AidingSource`) of an aided INS.

use super::convert::{mat3, mat_to_py, real, vec3, vec3_rows, vector, Wrap};
use super::imu::triad_from_dict;
use super::sources::AidingSource;
use crate::earth::Ellipsoid;
use crate::filter::alignment::{coarse, euler_sigma, fine_start, level, CoarseAlignment, ZeroRate, ZeroVelocity};
use crate::filter::sources::Source;
use crate::imu::errors::ImuErrorModel;
use crate::imu::ImuKind;
use crate::math::quat;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Coarse alignment of a static record: time (N,) s, gyro and accel (N, 3) of `kind`, the
/// site `lla` (3,) and the sensor error model as the two triad dicts of `atomnav.imu`;
/// with `gyrocompass` False, levelling alone (the heading undetermined). Returns a dict
/// of the core's `CoarseAlignment` fields (arrays, floats).
#[pyfunction]
#[pyo3(signature = (time, gyro, accel, kind, lla, accel_errors, gyro_errors, *, ellipsoid=Wrap(crate::earth::WGS84), gyrocompass=true))]
#[allow(clippy::too_many_arguments)]
fn coarse_alignment<'py>(
    py: Python<'py>,
    time: numpy::PyReadonlyArray1<'py, f64>,
    gyro: numpy::PyReadonlyArray2<'py, f64>,
    accel: numpy::PyReadonlyArray2<'py, f64>,
    kind: Wrap<ImuKind>,
    lla: numpy::PyReadonlyArray1<'py, f64>,
    accel_errors: &Bound<'py, PyDict>,
    gyro_errors: &Bound<'py, PyDict>,
    ellipsoid: Wrap<Ellipsoid>,
    gyrocompass: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let model = errors_model(accel_errors, gyro_errors)?;
    let (t, g, a, lla) = (vector(&time, "time")?, vec3_rows(&gyro, "gyro")?, vec3_rows(&accel, "accel")?, vec3(&lla, "lla")?);
    let align = if gyrocompass { coarse } else { level };
    let c = py.detach(|| align(&t, &g, &a, kind.0, &lla, &ellipsoid.0, &model))?;
    coarse_dict(py, &c)
}

fn errors_model(accel_errors: &Bound<'_, PyDict>, gyro_errors: &Bound<'_, PyDict>) -> PyResult<ImuErrorModel> {
    Ok(ImuErrorModel { accel: triad_from_dict(accel_errors, "accel")?, gyro: triad_from_dict(gyro_errors, "gyro")? })
}

fn coarse_dict<'py>(py: Python<'py>, c: &CoarseAlignment) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t0", c.t0)?;
    d.set_item("t1", c.t1)?;
    d.set_item("samples", c.samples)?;
    d.set_item("q_nb", vec![c.q_nb.w, c.q_nb.i, c.q_nb.j, c.q_nb.k])?;
    d.set_item("euler", c.euler.as_slice().to_vec())?;
    d.set_item("euler_sigma", c.euler_sigma.as_slice().to_vec())?;
    d.set_item("mean_f", c.mean_f.as_slice().to_vec())?;
    d.set_item("mean_w", c.mean_w.as_slice().to_vec())?;
    d.set_item("gravity", c.gravity)?;
    d.set_item("earth_rate_h", c.earth_rate_h)?;
    d.set_item("psi_cov", mat_to_py(py, &c.psi_cov))?;
    d.set_item("psi_cov_noise", mat_to_py(py, &c.psi_cov_noise))?;
    d.set_item("spread", c.spread)?;
    d.set_item("gyro_bias", c.gyro_bias.as_slice().to_vec())?;
    d.set_item("gyro_bias_cov", mat_to_py(py, &c.gyro_bias_cov))?;
    Ok(d)
}

/// The initial covariance (15, 15) of a fine alignment from a coarse one (`q_nb` (4,);
/// keyword-only: `psi_cov_noise` (3, 3), static means `mean_f`, `mean_w`, `gravity`) at `lla` over a
/// record of `horizon` s, with the error model's triad dicts, position σ `pos_sigma` (m)
/// and velocity σ `vel_sigma` (m/s); and the filter's noise model: (accel white PSD,
/// accel bias random-walk PSD, gyro white PSD, gyro bias random-walk PSD).
#[pyfunction]
#[pyo3(signature = (lla, q_nb, *, psi_cov_noise, mean_f, mean_w, gravity, horizon, accel_errors, gyro_errors, pos_sigma, vel_sigma, ellipsoid=Wrap(crate::earth::WGS84)))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn fine_alignment_p0<'py>(
    py: Python<'py>,
    lla: numpy::PyReadonlyArray1<'py, f64>,
    q_nb: numpy::PyReadonlyArray1<'py, f64>,
    psi_cov_noise: numpy::PyReadonlyArray2<'py, f64>,
    mean_f: numpy::PyReadonlyArray1<'py, f64>,
    mean_w: numpy::PyReadonlyArray1<'py, f64>,
    #[pyo3(from_py_with = real)] gravity: f64,
    #[pyo3(from_py_with = real)] horizon: f64,
    accel_errors: &Bound<'py, PyDict>,
    gyro_errors: &Bound<'py, PyDict>,
    #[pyo3(from_py_with = real)] pos_sigma: f64,
    #[pyo3(from_py_with = real)] vel_sigma: f64,
    ellipsoid: Wrap<Ellipsoid>,
) -> PyResult<(Bound<'py, numpy::PyArray2<f64>>, (f64, f64, f64, f64))> {
    let model = errors_model(accel_errors, gyro_errors)?;
    let (lla, q) = (vec3(&lla, "lla")?, vector(&q_nb, "q_nb")?);
    let [w, x, y, z] = <[f64; 4]>::try_from(q).map_err(|q| crate::error::invalid("q_nb", format!("expected 4 values, got {}", q.len())))?;
    let (noise, mean_f, mean_w) = (mat3(&psi_cov_noise, "psi_cov_noise")?, vec3(&mean_f, "mean_f")?, vec3(&mean_w, "mean_w")?);
    let (p0, [aw, ar, gw, gr]) = fine_start(&lla, &quat(w, x, y, z), &noise, &mean_f, &mean_w, gravity, horizon, &model, pos_sigma, vel_sigma, &ellipsoid.0)?;
    Ok((mat_to_py(py, &p0), (aw, ar, gw, gr)))
}

/// σ of (roll, pitch, yaw) (3,) rad from the Euler angles `euler` (3,) rad and the
/// covariance `psi_cov` (3, 3) rad² of the attitude error ψ (NED).
#[pyfunction]
fn alignment_euler_sigma<'py>(py: Python<'py>, euler: numpy::PyReadonlyArray1<'py, f64>, psi_cov: numpy::PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
    let s = euler_sigma(&vec3(&euler, "euler")?, &mat3(&psi_cov, "psi_cov")?);
    Ok(numpy::IntoPyArray::into_pyarray(s.as_slice().to_vec(), py))
}

/// Zero-velocity updates at `time` (M,) s with velocity noise σ `sigma` (m/s) of the
/// point at the lever arm (m; None: the IMU), stamps offset by `time_offset` (s).
#[pyfunction]
#[pyo3(signature = (time, sigma, *, lever_arm=None, time_offset=0.0))]
fn zero_velocity(time: numpy::PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] sigma: f64, lever_arm: Option<&Bound<'_, PyAny>>, #[pyo3(from_py_with = real)] time_offset: f64) -> PyResult<AidingSource> {
    let mounting = super::sources::mounting(lever_arm, time_offset)?;
    Ok(AidingSource::new(Box::new(ZeroVelocity::new(vector(&time, "time")?, sigma)?.with_mounting(mounting))))
}

/// Zero-angular-rate updates at `time` (M,) s: gyro white-noise PSD `gyro_psd` (rad²/s)
/// and a motion allowance σ `sigma` (rad/s); the IMU kind is the INS's.
#[pyfunction]
fn zero_rate(time: numpy::PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] gyro_psd: f64, #[pyo3(from_py_with = real)] sigma: f64) -> PyResult<AidingSource> {
    // checked now; the IMU kind is the setup's, when the INS is built
    let rate = ZeroRate::new(vector(&time, "time")?, ImuKind::Rates, gyro_psd, sigma)?;
    Ok(AidingSource::deferred("zero_rate".to_string(), Box::new(move |setup| Ok(Source::plain(Box::new(rate.on_record(setup.kind)))))))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(coarse_alignment, m)?)?;
    m.add_function(wrap_pyfunction!(fine_alignment_p0, m)?)?;
    m.add_function(wrap_pyfunction!(alignment_euler_sigma, m)?)?;
    m.add_function(wrap_pyfunction!(zero_velocity, m)?)?;
    m.add_function(wrap_pyfunction!(zero_rate, m)?)?;
    Ok(())
}
