//! Bindings of filter/sources.rs: measurement sources for one aided INS. A sensor's
//! constructor (`position_fixes`, `velocity_fixes`, and those of other modules) returns an
//! `AidingSource`; `aided_ins_from_sources` builds one `AidedIns` from a list of them.

use super::convert::{real, vec3_rows, vector};
use super::filter::{floats, mats, AidedSetup, PyAidedIns};
use crate::error::{invalid_at, Result};
use crate::filter::aided::{Aiding, InsSetup, PositionAiding, PositionFix};
use crate::filter::sources::{combine, Mounting, Source, VelocityFixes};
use numpy::{PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use std::sync::Mutex;

/// What makes a source's sensor once the INS it feeds is known (a sensor may need the
/// IMU kind of the setup).
pub(crate) type Build = Box<dyn FnOnce(&InsSetup) -> Result<Source> + Send>;

/// One measurement source for an aided INS (position fixes, velocity fixes, ...), made by
/// its constructor function. It is consumed when an INS is built from it.
#[pyclass(name = "AidingSource", module = "atomnav._core", frozen)]
pub struct AidingSource {
    name: String,
    build: Mutex<Option<Build>>,
}

impl AidingSource {
    /// A source of `aiding`, which has no extra state blocks.
    pub(crate) fn new(aiding: Box<dyn Aiding>) -> Self {
        Self::deferred(aiding.name().to_string(), Box::new(move |_| Ok(Source::plain(aiding))))
    }

    /// A source whose sensor is made by `build` from the setup of the INS it feeds.
    pub(crate) fn deferred(name: String, build: Build) -> Self {
        AidingSource { name, build: Mutex::new(Some(build)) }
    }
}

#[pymethods]
impl AidingSource {
    /// The sensor's name (e.g. "position_fixes").
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Whether an INS was built from this source already.
    #[getter]
    fn consumed(&self, py: Python<'_>) -> bool {
        super::shared::lock(py, &self.build).is_none()
    }
}

/// The lever arm (3 values, m, body frame; None: none) and time offset (s) of a source.
pub(crate) fn mounting(lever_arm: Option<&Bound<'_, PyAny>>, time_offset: f64) -> PyResult<Mounting> {
    let lever_arm = lever_arm.map(|l| floats::<3>(l, "lever_arm")).transpose()?.unwrap_or_default();
    Ok(Mounting::new(lever_arm.into(), time_offset)?)
}

/// Position fixes: times (M,) s, (lat, lon, h) (M, 3) rad, rad, m and NED covariances
/// (M, 3, 3) m², measured at the lever arm (m) and time offset (s) of the source.
#[pyfunction]
#[pyo3(signature = (time, lla, cov, *, lever_arm=None, time_offset=0.0))]
fn position_fixes(time: PyReadonlyArray1<'_, f64>, lla: PyReadonlyArray2<'_, f64>, cov: PyReadonlyArray3<'_, f64>, lever_arm: Option<&Bound<'_, PyAny>>, #[pyo3(from_py_with = real)] time_offset: f64) -> PyResult<AidingSource> {
    let (t, lla, cov) = (vector(&time, "time")?, vec3_rows(&lla, "lla")?, mats(&cov, "cov")?);
    let fixes = PositionFix::table(["time", "lla", "cov"], &t, &lla, &cov)?;
    let mounting = mounting(lever_arm, time_offset)?;
    Ok(AidingSource::new(Box::new(PositionAiding::new(fixes)?.with_mounting(mounting))))
}

/// NED velocity fixes: times (M,) s, velocities (M, 3) m/s and covariances (M, 3, 3)
/// m²/s², measured at the lever arm (m) and time offset (s) of the source.
#[pyfunction]
#[pyo3(signature = (time, vel_ned, cov, *, lever_arm=None, time_offset=0.0))]
fn velocity_fixes(time: PyReadonlyArray1<'_, f64>, vel_ned: PyReadonlyArray2<'_, f64>, cov: PyReadonlyArray3<'_, f64>, lever_arm: Option<&Bound<'_, PyAny>>, #[pyo3(from_py_with = real)] time_offset: f64) -> PyResult<AidingSource> {
    let (t, vel, cov) = (vector(&time, "time")?, vec3_rows(&vel_ned, "vel_ned")?, mats(&cov, "cov")?);
    let mounting = mounting(lever_arm, time_offset)?;
    Ok(AidingSource::new(Box::new(VelocityFixes::table(["time", "vel_ned", "cov"], &t, &vel, &cov)?.with_mounting(mounting))))
}

/// The aided INS of `setup` fed by every source of `sources` (a list of `AidingSource`,
/// each consumed). A source used before, or given twice, is an `InputError` naming
/// `sources` and its place in the list; then no source is consumed.
#[pyfunction]
fn aided_ins_from_sources(py: Python<'_>, setup: PyRef<'_, AidedSetup>, sources: Vec<Bound<'_, AidingSource>>) -> PyResult<PyAidedIns> {
    let slot = |s: &Bound<'_, AidingSource>| super::shared::lock(py, &s.get().build).take();
    let taken: Vec<Option<Build>> = sources.iter().map(slot).collect();
    if let Some(i) = taken.iter().position(Option::is_none) {
        // give back what was taken: a failed call consumes nothing
        sources.iter().zip(taken).filter_map(|(s, b)| Some((s, b?))).for_each(|(s, b)| *super::shared::lock(py, &s.get().build) = Some(b));
        let name = sources.get(i).map_or_else(String::new, |s| s.get().name.clone());
        return Err(invalid_at("sources", i, format!("source {i} ({name}) was used to build an INS already, or is given twice: make it again")).into());
    }
    let parts = taken.into_iter().flatten().map(|b| b(&setup.setup)).collect::<Result<Vec<Source>>>()?;
    let (sources, extra0, p0) = combine(&setup.setup, parts)?;
    PyAidedIns::from_aiding(&setup, extra0, Some(p0), Box::new(sources))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<AidingSource>()?;
    m.add_function(wrap_pyfunction!(position_fixes, m)?)?;
    m.add_function(wrap_pyfunction!(velocity_fixes, m)?)?;
    m.add_function(wrap_pyfunction!(aided_ins_from_sources, m)?)?;
    Ok(())
}
