//! Bindings of gnss/rinex.rs: the RINEX observation and navigation readers, converted to
//! numpy arrays and dicts (atomnav.gnss.rinex builds the tables).

use super::convert::to_py_rows;
use crate::gnss::rinex::{
    read_navigation, read_observations, CODE_L1, CODE_L2, DOPPLER_L1, GLONASS_RECORD_FIELDS, GPS_RECORD_FIELDS, NONE, SNR_L1,
};
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

fn column<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyArray1<T>> {
    v.into_pyarray(py)
}

/// An observation file (gnss/rinex.rs `read_observations`): a dict of the header facts,
/// per-row arrays (`time_s` calendar GPS s since 1980-01-06, `sat`, values and the index of
/// the observable used in its preference list, −1 when missing), `set_aside` and counts.
#[pyfunction]
fn gnss_read_rinex_obs<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let f = py.detach(|| read_observations(&path))?;
    let d = PyDict::new(py);
    let h = &f.header;
    let header = PyDict::new(py);
    header.set_item("version", h.version)?;
    header.set_item("marker", &h.marker)?;
    header.set_item("receiver", &h.receiver)?;
    header.set_item("time_system", &h.time_system)?;
    header.set_item("interval_s", h.interval_s)?;
    header.set_item("approx_position_m", h.approx_position_m.to_vec())?;
    header.set_item("antenna_delta_hen_m", h.antenna_delta_hen_m.to_vec())?;
    header.set_item("glonass_channels", h.glonass_channels.iter().map(|(s, k)| (*s, *k)).collect::<std::collections::BTreeMap<_, _>>())?;
    header.set_item("leap_seconds", h.leap_seconds)?;
    d.set_item("header", header)?;
    let r = &f.rows;
    let kind = |x: u8| if x == NONE { -1i8 } else { x as i8 };
    d.set_item("time_s", column(py, r.iter().map(|x| x.time_s).collect()))?;
    d.set_item("sat", r.iter().map(|x| x.sat.name()).collect::<Vec<_>>())?;
    d.set_item("code_m", column(py, r.iter().map(|x| x.code_m).collect()))?;
    d.set_item("code_type", column(py, r.iter().map(|x| kind(x.code_type)).collect()))?;
    d.set_item("code2_m", column(py, r.iter().map(|x| x.code2_m).collect()))?;
    d.set_item("code2_type", column(py, r.iter().map(|x| kind(x.code2_type)).collect()))?;
    d.set_item("doppler_hz", column(py, r.iter().map(|x| x.doppler_hz).collect()))?;
    d.set_item("doppler_type", column(py, r.iter().map(|x| kind(x.doppler_type)).collect()))?;
    d.set_item("snr_dbhz", column(py, r.iter().map(|x| x.snr_dbhz).collect()))?;
    d.set_item("set_aside", f.set_aside.iter().map(|(c, n)| (c.to_string(), *n)).collect::<std::collections::BTreeMap<_, _>>())?;
    d.set_item("n_epochs", f.n_epochs)?;
    d.set_item("n_events", f.n_events)?;
    d.set_item("header_lines", f.header_lines)?;
    Ok(d)
}

/// A navigation file (gnss/rinex.rs `read_navigation`): `gps` rows of
/// `RINEX_GPS_RECORD_FIELDS`, `glonass` rows of `RINEX_GLONASS_RECORD_FIELDS`, `klobuchar`
/// (8 or None), `leap_seconds`, `time_corrections` [(system, a0, a1, week, sow)],
/// `set_aside`, `version`.
#[pyfunction]
fn gnss_read_rinex_nav<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let f = py.detach(|| read_navigation(&path))?;
    let d = PyDict::new(py);
    d.set_item("version", f.version)?;
    d.set_item("leap_seconds", f.leap_seconds)?;
    d.set_item("klobuchar", f.klobuchar.map(|k| k.to_vec()))?;
    d.set_item(
        "time_corrections",
        f.time_corrections.iter().map(|c| (c.system.clone(), c.a0, c.a1, c.week, c.seconds_of_week)).collect::<Vec<_>>(),
    )?;
    d.set_item("gps", to_py_rows(py, &f.gps))?;
    d.set_item("glonass", to_py_rows(py, &f.glonass))?;
    d.set_item("set_aside", f.set_aside.iter().map(|(c, n)| (c.to_string(), *n)).collect::<std::collections::BTreeMap<_, _>>())?;
    Ok(d)
}

fn preference(list: &[(char, &[&str]); 2]) -> std::collections::BTreeMap<String, Vec<String>> {
    list.iter().map(|(s, codes)| (s.to_string(), codes.iter().map(|c| c.to_string()).collect())).collect()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(gnss_read_rinex_obs, m)?)?;
    m.add_function(wrap_pyfunction!(gnss_read_rinex_nav, m)?)?;
    m.add("RINEX_CODE_L1", preference(&CODE_L1))?;
    m.add("RINEX_CODE_L2", preference(&CODE_L2))?;
    m.add("RINEX_DOPPLER_L1", preference(&DOPPLER_L1))?;
    m.add("RINEX_SNR_L1", preference(&SNR_L1))?;
    m.add("RINEX_GPS_RECORD_FIELDS", GPS_RECORD_FIELDS.to_vec())?;
    m.add("RINEX_GLONASS_RECORD_FIELDS", GLONASS_RECORD_FIELDS.to_vec())?;
    Ok(())
}
