//! Bindings of filter/constraints.rs: still detection over an IMU record, zero-rate
//! updates averaged over still time, and the non-holonomic constraint as measurement
//! sources (`AidingSource`) of an aided INS.

use super::convert::{count, real, rows, vec3_rows, vector, Wrap};
use super::sources::{mounting, AidingSource};
use crate::filter::alignment::ZeroRate;
use crate::filter::constraints::{NonHolonomic, StillDetector, ZeroRateWhileStill};
use crate::filter::sources::Source;
use crate::imu::ImuKind;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

/// The still samples of the record time (N,) s, gyro and accel (N, 3) of `kind`: a bool
/// per sample and the runs of still samples as [first, last] sample indices.
#[pyfunction]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn detect_still<'py>(
    py: Python<'py>,
    time: PyReadonlyArray1<'py, f64>,
    gyro: PyReadonlyArray2<'py, f64>,
    accel: PyReadonlyArray2<'py, f64>,
    kind: Wrap<ImuKind>,
    window: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = real)] accel_threshold: f64,
    #[pyo3(from_py_with = real)] gyro_threshold: f64,
    #[pyo3(from_py_with = real)] gravity: f64,
) -> PyResult<(Bound<'py, PyArray1<bool>>, Vec<[usize; 2]>)> {
    let det = StillDetector::new(count(window, "window", 1, usize::MAX)?, accel_threshold, gyro_threshold, gravity)?;
    let (t, g, a) = (vector(&time, "time")?, vec3_rows(&gyro, "gyro")?, vec3_rows(&accel, "accel")?);
    let s = py.detach(|| det.detect(&t, &g, &a, kind.0))?;
    Ok((s.still.into_pyarray(py), s.runs))
}

/// Zero-angular-rate updates at `time` (M,) s (gyro white-noise PSD `gyro_psd` rad²/s,
/// motion allowance `sigma` rad/s) averaging the gyro over the still `intervals` (K, 2)
/// [start, end] s only; the IMU kind is the INS's.
#[pyfunction]
fn zero_rate_while_still(time: PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] gyro_psd: f64, #[pyo3(from_py_with = real)] sigma: f64, intervals: PyReadonlyArray2<'_, f64>) -> PyResult<AidingSource> {
    // checked now; the IMU kind is the setup's, when the INS is built
    let rate = ZeroRate::new(vector(&time, "time")?, ImuKind::Rates, gyro_psd, sigma)?;
    let still = ZeroRateWhileStill::new(rate, rows::<2>(&intervals, "intervals")?)?;
    Ok(AidingSource::deferred("zero_rate".to_string(), Box::new(move |setup| Ok(Source::plain(Box::new(still.on_record(setup.kind)))))))
}

/// The non-holonomic constraint at `time` (M,) s with noise σ `sigma` (m/s) at the lever
/// arm (3,) m from the IMU (None: the IMU), skipped below `min_speed` (m/s).
#[pyfunction]
#[pyo3(signature = (time, sigma, *, lever_arm=None, min_speed=0.0))]
fn non_holonomic(time: PyReadonlyArray1<'_, f64>, #[pyo3(from_py_with = real)] sigma: f64, lever_arm: Option<&Bound<'_, PyAny>>, #[pyo3(from_py_with = real)] min_speed: f64) -> PyResult<AidingSource> {
    let lever = mounting(lever_arm, 0.0)?.lever_arm;
    Ok(AidingSource::new(Box::new(NonHolonomic::new(vector(&time, "time")?, sigma, lever, min_speed)?)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(detect_still, m)?)?;
    m.add_function(wrap_pyfunction!(zero_rate_while_still, m)?)?;
    m.add_function(wrap_pyfunction!(non_holonomic, m)?)?;
    Ok(())
}
