//! Bindings of trajectory/ (motion models and generators) and imu::ideal.

use super::convert::{quat_rows, quat_to_py, real, to_py_rows, vec3, vec3_rows, vec3_to_py, vec_to_py, vector, Wrap};
use crate::earth::{check_latitude, Ellipsoid};
use crate::imu::ideal::{ideal_increments, ideal_rates};
use crate::imu::ImuKind;
use crate::math::Vec3;
use crate::trajectory::{generators, nav_errors as core_nav_errors, Motion as CoreMotion, NavSeries, ERROR_COLUMNS};
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A continuous-time motion model (exact velocity, acceleration, attitude and body rate).
#[pyclass(module = "atomnav._core", frozen)]
pub struct Motion {
    pub inner: CoreMotion,
}
super::pickle::picklable!(Motion, inner, "Motion");

/// The `origin` argument (lat rad, lon rad, h m) of every motion constructor, checked.
fn checked_origin(o: &PyReadonlyArray1<'_, f64>) -> PyResult<Vec3> {
    let v = vec3(o, "origin")?;
    check_latitude("origin", v.x, 0)?;
    Ok(v)
}

fn wrap(m: CoreMotion) -> Motion {
    Motion { inner: m }
}

#[pymethods]
impl Motion {
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    #[getter]
    fn duration(&self) -> f64 {
        self.inner.duration
    }
    #[getter]
    fn origin_lla(&self) -> (f64, f64, f64) {
        (self.inner.origin.x, self.inner.origin.y, self.inner.origin.z)
    }

    #[staticmethod]
    fn stationary(origin: PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] duration: f64, euler: PyReadonlyArray1<'_, f64>) -> PyResult<Motion> {
        crate::error::check_positive("duration", duration)?;
        Ok(wrap(CoreMotion::stationary("stationary", checked_origin(&origin)?, duration, vec3(&euler, "euler")?)))
    }

    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    fn sinusoidal(
        origin: PyReadonlyArray1<'_, f64>,
        #[pyo3(from_py_with = real)] duration: f64,
        amp_ned: PyReadonlyArray1<'_, f64>,
        period_ned: PyReadonlyArray1<'_, f64>,
        amp_euler: PyReadonlyArray1<'_, f64>,
        period_euler: PyReadonlyArray1<'_, f64>,
        #[pyo3(from_py_with = real)] heading: f64,
    ) -> PyResult<Motion> {
        crate::error::check_positive("duration", duration)?;
        Ok(wrap(generators::sinusoidal(
            checked_origin(&origin)?,
            duration,
            vec3(&amp_ned, "amp_ned")?,
            vec3(&period_ned, "period_ned")?,
            vec3(&amp_euler, "amp_euler")?,
            vec3(&period_euler, "period_euler")?,
            heading,
        )?))
    }

    #[staticmethod]
    fn hexapod(origin: PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] max_tilt: f64, #[pyo3(from_py_with = real)] pitch_delay: f64, #[pyo3(from_py_with = real)] heading: f64) -> PyResult<Motion> {
        Ok(wrap(generators::hexapod(checked_origin(&origin)?, max_tilt, pitch_delay, heading)?))
    }

    #[staticmethod]
    fn drive_with_yaw(origin: PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] speed: f64, #[pyo3(from_py_with = real)] yaw_rate_amp: f64, #[pyo3(from_py_with = real)] period: f64, #[pyo3(from_py_with = real)] duration: f64, #[pyo3(from_py_with = real)] heading: f64) -> PyResult<Motion> {
        crate::error::check_positive("duration", duration)?;
        Ok(wrap(generators::drive_with_yaw(checked_origin(&origin)?, speed, yaw_rate_amp, period, duration, heading)?))
    }

    #[staticmethod]
    fn slalom(origin: PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] speed: f64, #[pyo3(from_py_with = real)] amp: f64, #[pyo3(from_py_with = real)] period: f64, #[pyo3(from_py_with = real)] duration: f64) -> PyResult<Motion> {
        crate::error::check_positive("duration", duration)?;
        Ok(wrap(generators::slalom(checked_origin(&origin)?, speed, amp, period, duration)?))
    }

    #[staticmethod]
    #[pyo3(signature = (origin, *, heading, speed, ramp, cruise, stop, cycles, squat, vibration))]
    #[allow(clippy::too_many_arguments)]
    fn stop_and_go(
        origin: PyReadonlyArray1<'_, f64>,
        #[pyo3(from_py_with = real)] heading: f64,
        #[pyo3(from_py_with = real)] speed: f64,
        #[pyo3(from_py_with = real)] ramp: f64,
        #[pyo3(from_py_with = real)] cruise: f64,
        #[pyo3(from_py_with = real)] stop: f64,
        cycles: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = real)] squat: f64,
        #[pyo3(from_py_with = real)] vibration: f64,
    ) -> PyResult<Motion> {
        let cycles = super::convert::count(cycles, "cycles", 1, 10_000)?;
        Ok(wrap(generators::stop_and_go(checked_origin(&origin)?, heading, speed, ramp, cruise, stop, cycles, squat, vibration)?))
    }

    #[staticmethod]
    fn car(origin: PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] heading: f64, vibration: bool) -> PyResult<Motion> {
        Ok(wrap(generators::car(checked_origin(&origin)?, heading, vibration)))
    }

    #[staticmethod]
    fn rotary_stand(
        origin: PyReadonlyArray1<'_, f64>,
        states: PyReadonlyArray2<'_, f64>,
        move_starts: PyReadonlyArray1<'_, f64>,
        #[pyo3(from_py_with = real)] move_duration: f64,
        #[pyo3(from_py_with = real)] duration: f64,
    ) -> PyResult<Motion> {
        let st: Vec<(f64, f64)> = super::convert::rows::<2>(&states, "states")?.into_iter().map(|r| (r[0], r[1])).collect();
        let ms = vector(&move_starts, "move_starts")?;
        Ok(wrap(generators::rotary_stand(checked_origin(&origin)?, &st, &ms, move_duration, duration)?))
    }

    #[staticmethod]
    fn vasilyuk2024_stand(origin: PyReadonlyArray1<'_, f64>) -> PyResult<Motion> {
        Ok(wrap(generators::vasilyuk2024_stand(checked_origin(&origin)?)?))
    }

    /// Truth at `times` (s, increasing, within [0, duration]): dict of arrays
    /// time, lla (N,3), vel_ned (N,3), acc_ned (N,3), q_nb (N,4), w_nb_b (N,3).
    #[pyo3(signature = (times, ellipsoid=Wrap(crate::earth::WGS84)))]
    fn truth<'py>(&self, py: Python<'py>, times: PyReadonlyArray1<'py, f64>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Bound<'py, PyDict>> {
        let ell = ellipsoid.0;
        let t = vector(&times, "times")?;
        let truth = py.detach(|| self.inner.truth(&ell, &t))?;
        let d = PyDict::new(py);
        d.set_item("time", vec_to_py(py, t))?;
        d.set_item("lla", vec3_to_py(py, &truth.iter().map(|s| s.lla).collect::<Vec<_>>()))?;
        d.set_item("vel_ned", vec3_to_py(py, &truth.iter().map(|s| s.vel).collect::<Vec<_>>()))?;
        d.set_item("acc_ned", vec3_to_py(py, &truth.iter().map(|s| s.acc).collect::<Vec<_>>()))?;
        d.set_item("q_nb", quat_to_py(py, &truth.iter().map(|s| s.q_nb).collect::<Vec<_>>()))?;
        d.set_item("w_nb_b", vec3_to_py(py, &truth.iter().map(|s| s.w_nb_b).collect::<Vec<_>>()))?;
        Ok(d)
    }

    /// Error-free IMU output at `times`. kind "rates": gyro (rad/s), accel (m/s²) and
    /// angular acceleration (rad/s²) at each time; kind "increments": dtheta (rad), dv (m/s)
    /// over each interval (t_{k−1}, t_k], N − 1 rows.
    #[pyo3(signature = (times, kind, ellipsoid=Wrap(crate::earth::WGS84)))]
    fn ideal_imu<'py>(&self, py: Python<'py>, times: PyReadonlyArray1<'py, f64>, kind: Wrap<ImuKind>, ellipsoid: Wrap<Ellipsoid>) -> PyResult<Bound<'py, PyDict>> {
        let ell = ellipsoid.0;
        let kind = kind.0;
        let t = vector(&times, "times")?;
        let d = PyDict::new(py);
        match kind {
            crate::strapdown::ImuKind::Rates => {
                let (f, w, wd) = py.detach(|| self.inner.truth(&ell, &t).map(|tr| ideal_rates(&self.inner, &ell, &tr)))?;
                d.set_item("gyro", vec3_to_py(py, &w))?;
                d.set_item("accel", vec3_to_py(py, &f))?;
                d.set_item("angular_acceleration", vec3_to_py(py, &wd))?;
            }
            crate::strapdown::ImuKind::Increments => {
                let (dv, dth) = py.detach(|| self.inner.truth(&ell, &t).map(|tr| ideal_increments(&self.inner, &ell, &tr)))?;
                d.set_item("gyro", vec3_to_py(py, &dth))?;
                d.set_item("accel", vec3_to_py(py, &dv))?;
            }
        }
        Ok(d)
    }
}

/// Navigation errors (N, 9) of a solution against a reference, row by row: positions
/// (N, 3) lat rad, lon rad, h m, NED velocities (N, 3) m/s, attitudes q_nb (N, 4);
/// columns `NAV_ERROR_COLUMNS` (see trajectory/errors.rs).
#[pyfunction]
#[pyo3(signature = (lla, vel, q_nb, ref_lla, ref_vel, ref_q_nb, *, ellipsoid=Wrap(crate::earth::WGS84)))]
#[allow(clippy::too_many_arguments)]
fn nav_errors<'py>(
    py: Python<'py>,
    lla: PyReadonlyArray2<'py, f64>,
    vel: PyReadonlyArray2<'py, f64>,
    q_nb: PyReadonlyArray2<'py, f64>,
    ref_lla: PyReadonlyArray2<'py, f64>,
    ref_vel: PyReadonlyArray2<'py, f64>,
    ref_q_nb: PyReadonlyArray2<'py, f64>,
    ellipsoid: Wrap<Ellipsoid>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (lla, vel, q) = (vec3_rows(&lla, "nav")?, vec3_rows(&vel, "nav")?, quat_rows(&q_nb, "nav")?);
    let (rl, rv, rq) = (vec3_rows(&ref_lla, "reference")?, vec3_rows(&ref_vel, "reference")?, quat_rows(&ref_q_nb, "reference")?);
    let est = NavSeries { lla: &lla, vel: &vel, q_nb: &q };
    let reference = NavSeries { lla: &rl, vel: &rv, q_nb: &rq };
    let out = py.detach(|| core_nav_errors(&ellipsoid.0, est, reference))?;
    Ok(to_py_rows(py, &out))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("NAV_ERROR_COLUMNS", ERROR_COLUMNS.to_vec())?;
    m.add_function(wrap_pyfunction!(nav_errors, m)?)?;
    m.add_class::<Motion>()
}
