//! RINEX observation and navigation files through the `rinex` crate (rtk-rs, MPL-2.0):
//! RINEX 2.11, 3.0x and 4.0x, Hatanaka-compressed or gzip. The crate parses; this module
//! only picks, per GPS and GLONASS satellite and epoch, the code, second-frequency code,
//! Doppler and SNR by a fixed preference order, gathers the broadcast records atomnav
//! positions with, and turns the crate's recoverable decoding failures into errors that
//! name the file and line (docs/departures.md#rinex-reading).
//!
//! Time: seconds since the GPS epoch 1980-01-06 00:00:00, counted on the calendar of the
//! file's own time scale (GPS time for observations and GPS records, UTC for GLONASS
//! records), so no leap-second table is applied here.

use super::SatId;
use crate::error::{invalid, NavError, Result};
use rinex::navigation::{IonosphereModel, NavFrameType, NavMessageType};
use rinex::observation::EpochFlag;
use rinex::prelude::{Constellation, Epoch, Rinex};
use rinex::record::{ParsingDiagnostic, ParsingDiagnosticKind};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Code observables on the first frequency, per system, in order of preference: the civil
/// L1 code, then P(Y), then other tracking modes; RINEX 2 names (C1, P1) beside RINEX 3 ones.
pub const CODE_L1: [(char, &[&str]); 2] =
    [('G', &["C1C", "C1", "C1W", "P1", "C1X", "C1P", "C1L", "C1S"]), ('R', &["C1C", "C1", "C1P", "P1"])];
/// Code observables on the second frequency (for the ionosphere-free combination).
pub const CODE_L2: [(char, &[&str]); 2] =
    [('G', &["C2W", "P2", "C2L", "C2S", "C2X", "C2D", "C2"]), ('R', &["C2P", "P2", "C2C", "C2"])];
/// Doppler observables on the first frequency.
pub const DOPPLER_L1: [(char, &[&str]); 2] =
    [('G', &["D1C", "D1", "D1W", "D1X", "D1P", "D1L", "D1S"]), ('R', &["D1C", "D1", "D1P"])];
/// Carrier-to-noise density on the first frequency (dB-Hz).
pub const SNR_L1: [(char, &[&str]); 2] =
    [('G', &["S1C", "S1", "S1W", "S1X", "S1P", "S1L"]), ('R', &["S1C", "S1", "S1P"])];

/// No observable of a preference list present.
pub const NONE: u8 = u8::MAX;

const GPS_EPOCH_DAYS: i64 = 3657; // 1970-01-01 → 1980-01-06

/// Days from 1970-01-01 of a Gregorian date (Howard Hinnant's `days_from_civil`).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Calendar seconds since 1980-01-06 00:00:00 of an epoch, in its own time scale.
pub fn calendar_seconds(t: Epoch) -> f64 {
    let (y, mo, d, h, mi, s, ns) = t.to_gregorian(t.time_scale);
    let days = days_from_civil(y as i64, mo as i64, d as i64) - GPS_EPOCH_DAYS;
    (days * 86_400 + h as i64 * 3600 + mi as i64 * 60 + s as i64) as f64 + ns as f64 * 1e-9
}

/// A file opened as the crate reads it: gzip by its magic bytes, not by its name.
fn open(path: &Path) -> Result<Box<dyn BufRead>> {
    let name = path.display();
    let mut file = File::open(path).map_err(|e| invalid("path", format!("{name}: {e}")))?;
    let mut magic = [0u8; 2];
    let n = file.read(&mut magic).map_err(|e| invalid("path", format!("{name}: {e}")))?;
    let file = File::open(path).map_err(|e| invalid("path", format!("{name}: {e}")))?;
    if n == 2 && magic == [0x1f, 0x8b] {
        Ok(Box::new(BufReader::new(flate2::read::MultiGzDecoder::new(file))))
    } else {
        Ok(Box::new(BufReader::new(file)))
    }
}

/// What atomnav takes from the header text itself: the number of header lines (through END
/// OF HEADER), to turn the crate's body lines into file lines, and the ANTENNA: DELTA H/E/N
/// line, which the crate 0.24 drops when it precedes ANT # / TYPE (WTZR's files).
struct HeaderText {
    lines: usize,
    antenna_delta_hen_m: Option<[f64; 3]>,
}

/// Read the header text; refuses a file whose first line is not a RINEX VERSION / TYPE, or
/// whose version atomnav does not read.
fn header_text(path: &Path) -> Result<HeaderText> {
    let name = path.display();
    let mut antenna_delta_hen_m = None;
    for (k, line) in open(path)?.lines().enumerate() {
        let line = line.map_err(|e| invalid("path", format!("{name}, line {}: {e}", k + 1)))?;
        if k == 0 && !(line.contains("RINEX VERSION / TYPE") || line.contains("CRINEX VERS   / TYPE")) {
            return Err(invalid("path", format!("{name}, line 1: not a RINEX file (no RINEX VERSION / TYPE label)")));
        }
        if line.contains("RINEX VERSION / TYPE") {
            let field = line.get(..9).unwrap_or("").trim();
            if !field.parse::<f64>().is_ok_and(|v| (2.0..5.0).contains(&v)) {
                return Err(invalid("path", format!(
                    "{name}, line {}, field RINEX VERSION: version '{field}' is not one atomnav reads (2.xx, 3.xx, 4.xx)", k + 1)));
            }
        }
        if line.get(60..).is_some_and(|l| l.starts_with("ANTENNA: DELTA H/E/N")) {
            let f = |a: usize| line.get(a..a + 14).and_then(|x| x.trim().parse::<f64>().ok());
            if let (Some(h), Some(e), Some(n)) = (f(0), f(14), f(28)) {
                antenna_delta_hen_m = Some([h, e, n]);
            }
        }
        if line.contains("END OF HEADER") {
            return Ok(HeaderText { lines: k + 1, antenna_delta_hen_m });
        }
    }
    Err(invalid("path", format!("{name}: no END OF HEADER line (truncated header)")))
}

/// Parse with the crate (and count the header lines); a record it could not decode is an
/// error naming the file line.
fn parse(path: &Path) -> Result<(Rinex, HeaderText)> {
    let name = path.display();
    let text = header_text(path)?;
    let header = text.lines;
    // the crate may panic on input it did not foresee: never across the Python boundary
    let parsed = std::panic::catch_unwind(|| -> Result<(Rinex, Vec<ParsingDiagnostic>)> {
        let mut reader = BufReader::new(open(path)?);
        Rinex::parse_with_diagnostics(&mut reader).map_err(|e| invalid("path", format!("{name}: {e}")))
    })
    .map_err(|_| invalid("path", format!("{name}: the RINEX reader failed on this file")))??;
    let (rinex, diagnostics) = parsed;
    for d in diagnostics {
        let failure = match &d.kind {
            ParsingDiagnosticKind::NavigationFailure(e) | ParsingDiagnosticKind::ObservationFailure(e) => e,
            _ => continue,
        };
        let crx = if rinex.header.obs.as_ref().is_some_and(|o| o.crinex.is_some()) { " (Hatanaka-compressed)" } else { "" };
        return Err(invalid("path", format!("{name}{crx}, line {}: record not decoded: {failure}", header + d.record_line)));
    }
    Ok((rinex, text))
}

/// RINEX 3/4 epoch records ('>' lines) must increase in time and hold as many lines as
/// their satellite count: the crate keys epochs by time (it would sort a file out of order)
/// and keeps what a record cut short holds. Hatanaka files are checked by the expansion.
fn check_epoch_records(path: &Path, header: usize) -> Result<()> {
    let name = path.display();
    let mut last: Option<(f64, usize)> = None;
    // the open record: its line, its declared line count, the lines seen
    let mut open_record: Option<(usize, usize, usize)> = None;
    let short = |(line, declared, seen): (usize, usize, usize)| -> Result<()> {
        if seen < declared {
            return Err(invalid("path", format!(
                "{name}, line {line}, field number of satellites: the epoch record declares {declared} lines but holds {seen} (truncated record)")));
        }
        Ok(())
    };
    for (k, line) in open(path)?.lines().enumerate().skip(header) {
        let line = line.map_err(|e| invalid("path", format!("{name}, line {}: {e}", k + 1)))?;
        if !line.starts_with('>') {
            if let Some(r) = open_record.as_mut() {
                r.2 += 1;
            }
            continue;
        }
        if let Some(r) = open_record.take() {
            short(r)?;
        }
        let declared = line.get(32..35).and_then(|x| x.trim().parse::<usize>().ok()).unwrap_or(0);
        open_record = Some((k + 1, declared, 0));
        let Some(t) = epoch_of_line(&line) else { continue };
        if let Some((prev, prev_line)) = last {
            if t <= prev {
                let what = if t == prev { "repeats" } else { "precedes" };
                return Err(invalid("path", format!(
                    "{name}, line {}, field EPOCH: epoch {} {what} the epoch of line {prev_line}; epochs must increase",
                    k + 1, line.get(2..29).unwrap_or("").trim())));
            }
        }
        last = Some((t, k + 1));
    }
    match open_record {
        Some(r) => short(r),
        None => Ok(()),
    }
}

/// Calendar seconds of a RINEX 3/4 epoch line "> yyyy mm dd hh mm ss.sssssss".
fn epoch_of_line(line: &str) -> Option<f64> {
    let f = |a: usize, b: usize| line.get(a..b).and_then(|s| s.trim().parse::<f64>().ok());
    let (y, mo, d, h, mi, s) = (f(2, 6)?, f(7, 9)?, f(10, 12)?, f(13, 15)?, f(16, 18)?, f(18, 29)?);
    let days = days_from_civil(y as i64, mo as i64, d as i64) - GPS_EPOCH_DAYS;
    Some(days as f64 * 86_400.0 + h * 3600.0 + mi * 60.0 + s)
}

fn letter(c: Constellation) -> Option<char> {
    match c {
        Constellation::GPS => Some('G'),
        Constellation::Glonass => Some('R'),
        Constellation::Galileo => Some('E'),
        Constellation::BeiDou => Some('C'),
        Constellation::QZSS => Some('J'),
        Constellation::IRNSS => Some('I'),
        c if c.is_sbas() => Some('S'),
        _ => None,
    }
}

fn rank(list: &[(char, &[&str]); 2], system: char, code: &str) -> u8 {
    list.iter()
        .find(|(s, _)| *s == system)
        .and_then(|(_, codes)| codes.iter().position(|c| *c == code))
        .map_or(NONE, |k| k as u8)
}

/// The header facts of an observation file.
#[derive(Debug, Clone, Default)]
pub struct ObservationHeader {
    pub version: f64,
    pub marker: String,
    pub receiver: String,
    pub time_system: String,
    pub interval_s: f64,
    pub approx_position_m: [f64; 3],
    pub antenna_delta_hen_m: [f64; 3],
    pub glonass_channels: Vec<(u8, i8)>,
    pub leap_seconds: Option<f64>,
}

/// The observables chosen for one satellite at one epoch (`NONE` type: missing, value NaN).
#[derive(Debug, Clone, Copy)]
pub struct ObservationRow {
    pub time_s: f64,
    pub sat: SatId,
    pub code_m: f64,
    pub code_type: u8,
    pub code2_m: f64,
    pub code2_type: u8,
    pub doppler_hz: f64,
    pub doppler_type: u8,
    pub snr_dbhz: f64,
}

/// An observation file as atomnav uses it.
#[derive(Debug, Clone, Default)]
pub struct ObservationFile {
    pub header: ObservationHeader,
    pub rows: Vec<ObservationRow>,
    /// Satellite-epochs of the systems not positioned (E, C, J, I, S), per letter.
    pub set_aside: BTreeMap<char, usize>,
    /// Epochs read (flags 0 and 1), and event records skipped (flags 2–6).
    pub n_epochs: usize,
    pub n_events: usize,
    /// Lines of the header, through END OF HEADER.
    pub header_lines: usize,
}

fn set(value: f64, rank: u8, slot: &mut f64, slot_rank: &mut u8) {
    if rank < *slot_rank && value.is_finite() && value != 0.0 {
        *slot = value;
        *slot_rank = rank;
    }
}

/// Read an observation file: per GPS/GLONASS satellite and epoch, the first present code,
/// second-frequency code, Doppler and SNR of [`CODE_L1`], [`CODE_L2`], [`DOPPLER_L1`] and
/// [`SNR_L1`] (a blank, NaN or 0.0 field is missing).
pub fn read_observations(path: &Path) -> Result<ObservationFile> {
    let (rinex, text) = parse(path)?;
    let header_lines = text.lines;
    let name = path.display();
    let h = &rinex.header;
    let Some(record) = rinex.record.as_obs() else {
        return Err(invalid("path", format!("{name}: not an observation file ({:?})", h.rinex_type)));
    };
    if rinex.header.obs.as_ref().is_none_or(|o| o.crinex.is_none()) && h.version.major >= 3 {
        check_epoch_records(path, header_lines)?;
    }
    let time_system = h.obs.as_ref().and_then(|o| o.timeof_first_obs).map_or("GPS".to_string(), |t| t.time_scale.to_string());
    let header = ObservationHeader {
        version: h.version.major as f64 + h.version.minor as f64 / 100.0,
        marker: h.geodetic_marker.as_ref().map_or(String::new(), |m| m.name.clone()),
        receiver: h.rcvr.as_ref().map_or(String::new(), |r| format!("{} {}", r.model, r.firmware).trim().to_string()),
        time_system,
        interval_s: h.sampling_interval.map_or(f64::NAN, |d| d.to_seconds()),
        approx_position_m: h.rx_position.map_or([f64::NAN; 3], |(x, y, z)| [x, y, z]),
        antenna_delta_hen_m: text.antenna_delta_hen_m.unwrap_or([f64::NAN; 3]),
        glonass_channels: {
            let mut v: Vec<(u8, i8)> = h.glo_channels.iter().map(|(sv, k)| (sv.prn, *k)).collect();
            v.sort_unstable();
            v
        },
        leap_seconds: h.leap.map(|l| l.leap as f64),
    };
    let mut out = ObservationFile { header, header_lines, ..Default::default() };
    let mut epoch_rows: Vec<ObservationRow> = Vec::with_capacity(64);
    let mut other: Vec<rinex::prelude::SV> = Vec::with_capacity(64);
    for (key, obs) in record.iter() {
        if !matches!(key.flag, EpochFlag::Ok | EpochFlag::PowerFailure) {
            out.n_events += 1;
            continue;
        }
        out.n_epochs += 1;
        let t = calendar_seconds(key.epoch);
        epoch_rows.clear();
        other.clear();
        for s in &obs.signals {
            let Some(system) = letter(s.sv.constellation) else { continue };
            if system != 'G' && system != 'R' {
                if s.value.is_finite() && s.value != 0.0 && !other.contains(&s.sv) {
                    other.push(s.sv);
                }
                continue;
            }
            let sat = if system == 'G' { SatId::gps(s.sv.prn) } else { SatId::glonass(s.sv.prn) };
            let k = match epoch_rows.iter().position(|r| r.sat == sat) {
                Some(k) => k,
                None => {
                    epoch_rows.push(ObservationRow {
                        time_s: t, sat, code_m: f64::NAN, code_type: NONE, code2_m: f64::NAN, code2_type: NONE,
                        doppler_hz: f64::NAN, doppler_type: NONE, snr_dbhz: f64::NAN,
                    });
                    epoch_rows.len() - 1
                }
            };
            let Some(row) = epoch_rows.get_mut(k) else { continue };
            let code = s.observable.to_string();
            let mut snr_rank = NONE;
            set(s.value, rank(&CODE_L1, system, &code), &mut row.code_m, &mut row.code_type);
            set(s.value, rank(&CODE_L2, system, &code), &mut row.code2_m, &mut row.code2_type);
            set(s.value, rank(&DOPPLER_L1, system, &code), &mut row.doppler_hz, &mut row.doppler_type);
            set(s.value, rank(&SNR_L1, system, &code), &mut row.snr_dbhz, &mut snr_rank);
        }
        for sv in &other {
            if let Some(c) = letter(sv.constellation) {
                *out.set_aside.entry(c).or_default() += 1;
            }
        }
        epoch_rows.sort_by_key(|r| r.sat);
        out.rows.extend(epoch_rows.iter().filter(|r| r.code_type != NONE || r.doppler_type != NONE));
    }
    Ok(out)
}

/// Width of a GPS record row ([`GPS_RECORD_FIELDS`]).
pub const GPS_RECORD_WIDTH: usize = 24;
/// The GPS LNAV record fields, in row order (times in calendar seconds since 1980-01-06, GPS time).
pub const GPS_RECORD_FIELDS: [&str; GPS_RECORD_WIDTH] = [
    "prn", "toc", "week", "toe_sow", "sqrt_a", "e", "m0", "delta_n", "omega0", "i0", "omega", "omega_dot", "idot", "cuc",
    "cus", "crc", "crs", "cic", "cis", "af0", "af1", "af2", "tgd", "health",
];
const GPS_ORBIT_KEYS: [&str; 15] =
    ["sqrta", "e", "m0", "deltaN", "omega0", "i0", "omega", "omegaDot", "idot", "cuc", "cus", "crc", "crs", "cic", "cis"];
/// Width of a GLONASS record row ([`GLONASS_RECORD_FIELDS`]).
pub const GLONASS_RECORD_WIDTH: usize = 15;
/// The GLONASS FDMA record fields (`toc`: calendar seconds since 1980-01-06 in UTC; km in
/// the file, m here; `minus_tau_n` as written, −τ_n).
pub const GLONASS_RECORD_FIELDS: [&str; GLONASS_RECORD_WIDTH] = [
    "slot", "channel", "toc_utc", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az", "minus_tau_n", "gamma_n", "health",
];
const GLONASS_ORBIT_KEYS: [&str; 9] = ["satPosX", "satPosY", "satPosZ", "velX", "velY", "velZ", "accelX", "accelY", "accelZ"];

/// A time-system correction of a navigation file (GPUT, GLUT, GLGP, ...): a0 (s), a1 (s/s)
/// at the reference GPS week and second of week.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeCorrection {
    pub system: String,
    pub a0: f64,
    pub a1: f64,
    pub week: u32,
    pub seconds_of_week: f64,
}

/// The GPS and GLONASS broadcast records of a navigation file.
#[derive(Debug, Clone, Default)]
pub struct NavigationFile {
    pub version: f64,
    pub leap_seconds: Option<f64>,
    /// GPS Klobuchar α₀..α₃, β₀..β₃ (header ION ALPHA/BETA, GPSA/GPSB, or RINEX 4 ION LNAV).
    pub klobuchar: Option<[f64; 8]>,
    pub time_corrections: Vec<TimeCorrection>,
    pub gps: Vec<[f64; GPS_RECORD_WIDTH]>,
    pub glonass: Vec<[f64; GLONASS_RECORD_WIDTH]>,
    /// Records of the systems not positioned, and GPS CNAV/CNV2, per letter.
    pub set_aside: BTreeMap<char, usize>,
}

fn klobuchar(model: &IonosphereModel) -> Option<[f64; 8]> {
    match model {
        IonosphereModel::Klobuchar(k) => {
            let (a, b) = (k.alpha, k.beta);
            Some([a.0, a.1, a.2, a.3, b.0, b.1, b.2, b.3])
        }
        _ => None,
    }
}

/// Read a navigation file's GPS LNAV and GLONASS FDMA records (others set aside and counted).
pub fn read_navigation(path: &Path) -> Result<NavigationFile> {
    let (rinex, text) = parse(path)?;
    let header_lines = text.lines;
    let name = path.display();
    let h = &rinex.header;
    let Some(record) = rinex.record.as_nav() else {
        return Err(invalid("path", format!("{name}: not a navigation file ({:?})", h.rinex_type)));
    };
    let mut out = NavigationFile {
        version: h.version.major as f64 + h.version.minor as f64 / 100.0,
        leap_seconds: h.leap.map(|l| l.leap as f64),
        klobuchar: h.ionod_corrections.get(&Constellation::GPS).and_then(klobuchar),
        time_corrections: h.nav.as_ref().map_or(Vec::new(), |n| n.time_offsets.iter().map(correction).collect()),
        ..Default::default()
    };
    let missing = |key: &rinex::navigation::NavKey, field: &str| -> NavError {
        let line = record_line(path, header_lines, key).map_or(String::new(), |l| format!(", line {l}"));
        invalid("path", format!("{name}{line}, field {field}: the record of {} lacks it (truncated record)", key.sv))
    };
    for (key, frame) in record.iter() {
        match key.frmtype {
            NavFrameType::IonosphereModel if key.sv.constellation == Constellation::GPS => {
                if out.klobuchar.is_none() {
                    out.klobuchar = frame.as_ionosphere_model().and_then(klobuchar);
                }
                continue;
            }
            NavFrameType::SystemTimeOffset => {
                if let Some(o) = frame.as_system_time() {
                    out.time_corrections.push(correction(o));
                }
                continue;
            }
            NavFrameType::Ephemeris => {}
            _ => continue,
        }
        let Some(e) = frame.as_ephemeris() else { continue };
        let orbit = |k: &str| e.get_orbit_f64(k).ok_or_else(|| missing(key, k));
        match (key.sv.constellation, key.msgtype) {
            (Constellation::GPS, NavMessageType::LNAV) => {
                let mut row = [0.0; GPS_RECORD_WIDTH];
                row[0] = key.sv.prn as f64;
                row[1] = calendar_seconds(key.epoch);
                row[2] = orbit("week")?;
                row[3] = orbit("toe")?;
                for (slot, k) in row[4..19].iter_mut().zip(GPS_ORBIT_KEYS) {
                    *slot = orbit(k)?;
                }
                row[19..22].copy_from_slice(&[e.clock_bias, e.clock_drift, e.clock_drift_rate]);
                row[22] = orbit("tgd")?;
                row[23] = e.get_orbit_f64("health").unwrap_or(0.0);
                out.gps.push(row);
            }
            (Constellation::Glonass, NavMessageType::LNAV | NavMessageType::FDMA) => {
                let mut row = [0.0; GLONASS_RECORD_WIDTH];
                row[0] = key.sv.prn as f64;
                row[1] = orbit("channel")?;
                row[2] = calendar_seconds(key.epoch);
                for (slot, k) in row[3..12].iter_mut().zip(GLONASS_ORBIT_KEYS) {
                    *slot = orbit(k)? * 1e3;
                }
                row[12..14].copy_from_slice(&[e.clock_bias, e.clock_drift]);
                row[14] = e.get_orbit_f64("health").unwrap_or(0.0);
                out.glonass.push(row);
            }
            (c, _) => {
                if let Some(l) = letter(c) {
                    *out.set_aside.entry(l).or_default() += 1;
                }
            }
        }
    }
    Ok(out)
}

/// The file line where a navigation record starts (only to name it in an error): RINEX 3/4
/// "G01 2020 06 25 14 00 00", RINEX 2 " 1 20  6 25 14  0".
fn record_line(path: &Path, header: usize, key: &rinex::navigation::NavKey) -> Option<usize> {
    let (y, mo, d, h, mi, s, _) = key.epoch.to_gregorian(key.epoch.time_scale);
    let l = letter(key.sv.constellation)?;
    let v3 = format!("{l}{:02} {y:04} {mo:02} {d:02} {h:02} {mi:02} {s:02}", key.sv.prn);
    let v2 = format!("{:2} {:02} {mo:2} {d:2} {h:2} {mi:2}", key.sv.prn, y % 100);
    let lines = open(path).ok()?.lines().enumerate().skip(header);
    lines.map_while(|(k, line)| line.ok().map(|line| (k, line))).find(|(_, line)| line.starts_with(&v3) || line.starts_with(&v2)).map(|(k, _)| k + 1)
}

fn correction(o: &rinex::navigation::TimeOffset) -> TimeCorrection {
    TimeCorrection {
        system: o.time_system.clone().unwrap_or_else(|| format!("{}{}", o.lhs, o.rhs)),
        a0: o.polynomial.0,
        a1: o.polynomial.1,
        week: o.t_ref.0,
        seconds_of_week: (o.t_ref.1 / 1_000_000_000) as f64 + (o.t_ref.1 % 1_000_000_000) as f64 * 1e-9,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calendar_seconds_of_known_dates() {
        // GPS week 2111 starts 2020-06-21 (ESBC day 177 is Thursday 2020-06-25)
        assert_eq!(days_from_civil(1980, 1, 6), GPS_EPOCH_DAYS);
        assert_eq!((days_from_civil(2020, 6, 21) - GPS_EPOCH_DAYS) * 86_400, 2111 * 604_800);
        assert_eq!(epoch_of_line("> 2020 06 25 12 00 30.0000000  0 38"), Some((2111.0 * 7.0 + 4.0) * 86_400.0 + 43_230.0));
    }
}
