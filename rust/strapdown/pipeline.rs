//! A chunk of IMU samples integrated on two cores into a navigation table.
//!
//! The integrating thread runs only the navigation half of each step
//! ([`Strapdown::run_body`]); a second thread prepares the next block of rows (copy out of
//! the caller's buffers, input checks, rates to increments, coning and sculling:
//! [`BodyFront`]) and turns the finished block into table rows (the Euler angles' three
//! atan2 per row cost about half a mechanization step). Blocks and state buffers are
//! recycled between the threads, so after the first blocks nothing is allocated.

use super::{check_lengths, BodyFront, BodyStep, NavState, SampleCheck, Strapdown};
use crate::error::{invalid, NavError, Result};
use crate::math::{euler_from_quat, Vec3};
use std::ops::Range;
use std::sync::mpsc;

/// Column names of the navigation table, in order: time, position (lat, lon, h), NED
/// velocity, q_nb (scalar first), Euler angles (roll, pitch, yaw).
pub const NAV_COLUMNS: [&str; 14] = [
    "time_s", "lat_rad", "lon_rad", "h_m", "vn_mps", "ve_mps", "vd_mps", "qw", "qx", "qy", "qz", "roll_rad", "pitch_rad", "yaw_rad",
];

/// Number of columns of the navigation table.
pub const NAV_WIDTH: usize = NAV_COLUMNS.len();

/// Rows per block of the pipelined run: small enough that a block's IMU rows and states
/// stay in cache, large enough to amortise the hand-over between the threads.
pub const PIPELINE_BLOCK: usize = 4096;

/// (N, 3) samples read in place from a row-major buffer (x, y, z of row k at 3k…3k+2) or a
/// column-major one (the N x values, then the N y values, then the N z values).
#[derive(Debug, Clone, Copy)]
pub struct Samples3<'a> {
    data: &'a [f64],
    rows: usize,
    column_major: bool,
}

impl<'a> Samples3<'a> {
    /// `data` holding an array of `shape` (which must be (N, 3)) in the given order; `field`
    /// names the argument in errors.
    pub fn new(field: &str, data: &'a [f64], shape: [usize; 2], column_major: bool) -> Result<Self> {
        let [rows, width] = shape;
        if width != 3 {
            return Err(invalid(field, format!("expected shape (N, 3), got ({rows}, {width})")));
        }
        if rows.checked_mul(3) != Some(data.len()) {
            return Err(invalid(field, format!("{} values do not fill shape ({rows}, 3)", data.len())));
        }
        Ok(Self { data, rows, column_major })
    }

    /// Number of samples.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Append rows `r` (within `0..rows`) to `out`.
    // invariant: callers pass rows r within 0..rows, and new checked data to hold
    // 3·rows values, so every range below lies inside data.
    #[allow(clippy::indexing_slicing)]
    fn extend(&self, r: Range<usize>, out: &mut Vec<Vec3>) {
        if self.column_major {
            let n = self.rows;
            let (x, y, z) = (&self.data[r.clone()], &self.data[n + r.start..n + r.end], &self.data[2 * n + r.start..2 * n + r.end]);
            out.extend(x.iter().zip(y).zip(z).map(|((&x, &y), &z)| Vec3::new(x, y, z)));
        } else {
            out.extend(self.data[3 * r.start..3 * r.end].chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        }
    }
}

/// One chunk of an IMU record read in place: time stamps, gyro and accelerometer samples
/// (rates or increments), and the reference altitude of a damped vertical channel.
#[derive(Debug, Clone, Copy)]
pub struct ImuSlices<'a> {
    t: &'a [f64],
    gyro: Samples3<'a>,
    accel: Samples3<'a>,
    h_ref: Option<&'a [f64]>,
}

impl<'a> ImuSlices<'a> {
    /// The chunk, with one gyro, accel and (when given) reference altitude per time stamp.
    pub fn new(t: &'a [f64], gyro: Samples3<'a>, accel: Samples3<'a>, h_ref: Option<&'a [f64]>) -> Result<Self> {
        check_lengths(t.len(), gyro.rows, accel.rows, h_ref.map(<[f64]>::len))?;
        Ok(Self { t, gyro, accel, h_ref })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

/// Where a run writes its states: rows `row0`… of a navigation table stored column by
/// column, [`NAV_WIDTH`] columns of `stride` values each (column c is
/// `buf[c·stride..(c+1)·stride]`, so a numpy (14, stride) array's transpose is the table).
#[derive(Debug)]
pub struct NavTable<'a> {
    buf: &'a mut [f64],
    stride: usize,
    row0: usize,
}

impl<'a> NavTable<'a> {
    /// `buf` holding a row-major array of `shape` ([`NAV_WIDTH`], rows of the table),
    /// written from row `row0` on.
    pub fn new(buf: &'a mut [f64], shape: [usize; 2], row0: usize) -> Result<Self> {
        if shape[0] != NAV_WIDTH || shape[0].checked_mul(shape[1]) != Some(buf.len()) {
            return Err(invalid("out", format!("expected a ({NAV_WIDTH}, N) table, got {shape:?}")));
        }
        Ok(Self { buf, stride: shape[1], row0 })
    }

    /// Check that rows `row0`… hold `n` more rows.
    fn check_room(&self, n: usize) -> Result<()> {
        match self.row0.checked_add(n) {
            Some(end) if end <= self.stride => Ok(()),
            _ => Err(invalid("out", format!("expected a ({NAV_WIDTH}, >= {}) table, got {:?}", self.row0.saturating_add(n), [NAV_WIDTH, self.stride]))),
        }
    }

    /// The states as rows `row0 + first`….
    fn write(&mut self, first: usize, states: &[NavState]) {
        write_columns(self.buf, self.stride, self.row0 + first, states);
    }
}

/// States as a navigation table of `states.len()` rows, stored column by column (see
/// [`NavTable`]).
pub fn nav_columns(states: &[NavState]) -> Vec<f64> {
    let mut buf = vec![0.0; NAV_WIDTH * states.len()];
    write_columns(&mut buf, states.len(), 0, states);
    buf
}

/// Write states as rows `first`… of a column-by-column table with columns of `n` values.
// invariant: buf holds NAV_WIDTH columns of n values and first + i < n (NavTable's
// check_room, or n = s.len() with first = 0); c < NAV_WIDTH = row.len().
#[allow(clippy::indexing_slicing)]
fn write_columns(buf: &mut [f64], n: usize, first: usize, s: &[NavState]) {
    for (i, x) in s.iter().enumerate() {
        let e = euler_from_quat(&x.q_nb);
        let q = &x.q_nb;
        let row = [x.t, x.lla.x, x.lla.y, x.lla.z, x.vel.x, x.vel.y, x.vel.z, q.w, q.i, q.j, q.k, e.x, e.y, e.z];
        for (c, v) in row.into_iter().enumerate() {
            buf[c * n + first + i] = v;
        }
    }
}

/// One block of IMU rows, in buffers reused from block to block (no allocation, no page
/// faults after the first blocks).
#[derive(Default)]
struct Block {
    t: Vec<f64>,
    gyro: Vec<Vec3>,
    accel: Vec<Vec3>,
    h_ref: Vec<f64>,
    has_h_ref: bool,
}

impl Block {
    // invariant: callers pass rows within the record, whose t, gyro, accel and h_ref
    // hold one entry per row (validated before the blocks are cut).
    #[allow(clippy::indexing_slicing)]
    fn fill(&mut self, imu: &ImuSlices<'_>, rows: Range<usize>) {
        self.t.clear();
        self.t.extend_from_slice(&imu.t[rows.clone()]);
        self.gyro.clear();
        imu.gyro.extend(rows.clone(), &mut self.gyro);
        self.accel.clear();
        imu.accel.extend(rows.clone(), &mut self.accel);
        self.h_ref.clear();
        self.has_h_ref = imu.h_ref.is_some();
        if let Some(h) = imu.h_ref {
            self.h_ref.extend_from_slice(&h[rows]);
        }
    }

    fn h_ref(&self) -> Option<&[f64]> {
        self.has_h_ref.then_some(&self.h_ref[..])
    }
}

/// The IMU-only work on a block, ready for the navigation half: checked rows, their body
/// steps (`BodyFront::push`), the reference altitudes.
#[derive(Default)]
struct Prepared {
    start: usize,
    block: Block,
    body: Vec<BodyStep>,
}

/// What is done to a chunk off the integrating thread: checking and the body half of each
/// step one block ahead. `check` and `front` continue from the state the chunk starts at.
struct Helper<'a, 'v> {
    imu: &'a ImuSlices<'v>,
    first_index: usize,
    check: SampleCheck,
    front: BodyFront,
}

impl Helper<'_, '_> {
    /// Block `j` copied out of the chunk, checked, and its body steps computed.
    fn prepare(&mut self, j: usize, mut into: Prepared) -> Result<Prepared> {
        let (start, n) = (j * PIPELINE_BLOCK, self.imu.len());
        into.start = start;
        into.block.fill(self.imu, start..(start + PIPELINE_BLOCK).min(n));
        let b = &into.block;
        self.check.check(&b.t, &b.gyro, &b.accel, b.h_ref(), self.first_index + start)?;
        self.front.push_block(&b.t, &b.gyro, &b.accel, &mut into.body);
        Ok(into)
    }
}

type Finished = (Vec<NavState>, Prepared);

impl Strapdown {
    /// Check and integrate a chunk into `out` on two cores (see the module documentation);
    /// `first_index` is the chunk's first row in the whole record, the row errors name.
    ///
    /// Returns the number of rows computed and the outcome. Bad input (a row found bad in
    /// any block) restores the state the chunk started from, so it integrates nothing; a
    /// divergence keeps the rows before it in `out` and leaves the state where it failed.
    /// The result equals [`Strapdown::step`] over the rows bit for bit.
    pub fn run_pipelined(&mut self, imu: &ImuSlices<'_>, mut out: NavTable<'_>, first_index: usize) -> (usize, Result<()>) {
        if let Err(e) = out.check_room(imu.len()) {
            return (0, Err(e));
        }
        let (n, initial) = (imu.len(), self.clone());
        let blocks = n.div_ceil(PIPELINE_BLOCK).max(1);
        let mut helper = Helper { imu, first_index, check: self.sample_check(), front: self.front.clone() };
        let (to_core, prepared) = mpsc::channel::<Result<Prepared>>();
        let (to_writer, finished) = mpsc::channel::<Finished>();
        // the navigation half; `to_writer` is moved in, so the writer's loop ends when it returns
        let integrate = |core: &mut Strapdown, to_writer: mpsc::Sender<Finished>, spare: &mpsc::Receiver<Vec<NavState>>| {
            for p in prepared.iter() {
                let p = match p {
                    Ok(p) => p,
                    Err(e) => return (0, Err(e)),
                };
                let mut states = spare.try_recv().unwrap_or_else(|_| Vec::with_capacity(PIPELINE_BLOCK));
                states.clear();
                let step = core.run_body(&p.block.t, &p.body, p.block.h_ref(), first_index + p.start, &mut states);
                let rows = p.start + states.len();
                let _ = to_writer.send((states, p)); // the helper stops early on bad input
                if step.is_err() {
                    return (rows, step);
                }
            }
            (n, Ok(()))
        };
        let (rows, result, front) = if n <= PIPELINE_BLOCK {
            // one block: not worth a thread
            let _ = to_core.send(helper.prepare(0, Prepared::default()));
            drop(to_core);
            let (_, spare) = mpsc::channel();
            let (rows, result) = integrate(self, to_writer, &spare);
            for (states, p) in finished.try_iter() {
                out.write(p.start, &states);
            }
            (rows, result, Some(helper.front))
        } else {
            let (recycle, spare) = mpsc::channel::<Vec<NavState>>();
            std::thread::scope(|s| {
                let writer = s.spawn(move || {
                    let mut reuse = Prepared::default();
                    for j in 0..=blocks {
                        // block j while the core integrates block j − 1, whose rows come next
                        if j < blocks {
                            let p = helper.prepare(j, std::mem::take(&mut reuse));
                            let bad = p.is_err();
                            if to_core.send(p).is_err() || bad {
                                break; // the core has stopped, or bad input: stop preparing
                            }
                        }
                        if j > 0 {
                            let Ok((states, p)) = finished.recv() else { break };
                            out.write(p.start, &states);
                            reuse = p;
                            let _ = recycle.send(states);
                        }
                    }
                    drop(to_core);
                    // after an early stop: the rows the core still sends
                    for (states, p) in finished.iter() {
                        out.write(p.start, &states);
                    }
                    helper.front
                });
                let (rows, result) = integrate(self, to_writer, &spare);
                (rows, result, writer.join().ok())
            })
        };
        match (result, front) {
            (Ok(()), Some(front)) => {
                self.front = front;
                (rows, Ok(()))
            }
            (Err(e @ NavError::InvalidInput { .. }), _) => {
                *self = initial;
                (rows, Err(e))
            }
            (Err(e), Some(_)) => (rows, Err(e)), // diverged: the state is where it failed
            (_, None) => {
                *self = initial;
                (0, Err(NavError::Numerical("the pipeline's second thread failed; the state is left where the chunk started".into())))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::WGS84;
    use crate::math::quat;
    use crate::strapdown::{ImuKind, Vertical};

    /// A deterministic IMU record of `n` rows of the given kind (a tumbling, accelerating
    /// vehicle at 100 Hz), flattened row-major, with its time stamps.
    fn record(kind: ImuKind, n: usize) -> (Vec<f64>, Vec<Vec3>, Vec<Vec3>) {
        let dt = 0.01;
        let first = if kind == ImuKind::Rates { 0.0 } else { dt };
        let t: Vec<f64> = (0..n).map(|k| first + k as f64 * dt).collect();
        let gyro = t.iter().map(|&t| Vec3::new(0.3 * (1.1 * t).sin(), 0.2 * (0.7 * t).cos(), 0.1 * (2.3 * t).sin())).collect::<Vec<_>>();
        let accel = t.iter().map(|&t| Vec3::new(0.5 * (0.9 * t).sin(), 0.4 * (1.3 * t).cos(), -9.8 + 0.1 * (3.1 * t).sin())).collect::<Vec<_>>();
        let scale = if kind == ImuKind::Increments { dt } else { 1.0 };
        (t, gyro.iter().map(|g| g * scale).collect(), accel.iter().map(|a| a * scale).collect())
    }

    fn start(kind: ImuKind) -> Strapdown {
        let init = NavState { t: 0.0, lla: Vec3::new(0.9, 0.3, 120.0), vel: Vec3::new(10.0, -3.0, 0.5), q_nb: crate::math::quat_normalize(&quat(0.9, 0.1, -0.2, 0.3)) };
        Strapdown::new(init, kind, WGS84, Vertical::Free).unwrap()
    }

    fn flat(v: &[Vec3], column_major: bool) -> Vec<f64> {
        if column_major {
            (0..3).flat_map(|c| v.iter().map(move |x| x[c])).collect()
        } else {
            v.iter().flat_map(|x| x.iter().copied()).collect()
        }
    }

    /// Run `rows` of the record through `run_pipelined` into `table` (rows `row0`…).
    fn pipelined(sd: &mut Strapdown, rec: &(Vec<f64>, Vec<Vec3>, Vec<Vec3>), rows: Range<usize>, table: &mut [f64], row0: usize, column_major: bool) -> (usize, Result<()>) {
        let (g, a) = (flat(&rec.1[rows.clone()], column_major), flat(&rec.2[rows.clone()], column_major));
        let n = rows.len();
        let imu = ImuSlices::new(
            &rec.0[rows.clone()],
            Samples3::new("gyro", &g, [n, 3], column_major).unwrap(),
            Samples3::new("accel", &a, [n, 3], column_major).unwrap(),
            None,
        )
        .unwrap();
        let stride = table.len() / NAV_WIDTH;
        sd.run_pipelined(&imu, NavTable::new(table, [NAV_WIDTH, stride], row0).unwrap(), rows.start)
    }

    /// The reference: `step` sample by sample.
    fn stepped(kind: ImuKind, rec: &(Vec<f64>, Vec<Vec3>, Vec<Vec3>)) -> Vec<NavState> {
        let mut sd = start(kind);
        (0..rec.0.len())
            .map(|k| {
                sd.step(rec.0[k], &rec.1[k], &rec.2[k], None);
                sd.state
            })
            .collect()
    }

    fn same_bits(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn pipelined_equals_step_bit_for_bit() {
        for kind in [ImuKind::Rates, ImuKind::Increments] {
            for n in [1, PIPELINE_BLOCK - 1, PIPELINE_BLOCK, PIPELINE_BLOCK + 1, 2 * PIPELINE_BLOCK + 17] {
                let rec = record(kind, n);
                let want = nav_columns(&stepped(kind, &rec));
                for column_major in [false, true] {
                    let mut sd = start(kind);
                    let mut table = vec![f64::NAN; NAV_WIDTH * n];
                    assert_eq!(pipelined(&mut sd, &rec, 0..n, &mut table, 0, column_major), (n, Ok(())));
                    assert!(same_bits(&table, &want), "{kind:?}, n = {n}, column-major {column_major}");
                }
            }
        }
    }

    #[test]
    fn chunks_across_blocks_equal_one_run() {
        // chunks that do not line up with the blocks carry the coning/sculling history and
        // the rate priming over; each chunk writes its own rows of the record's table
        for kind in [ImuKind::Rates, ImuKind::Increments] {
            let n = 3 * PIPELINE_BLOCK + 5;
            let rec = record(kind, n);
            let want = nav_columns(&stepped(kind, &rec));
            let mut sd = start(kind);
            let mut table = vec![f64::NAN; NAV_WIDTH * n];
            let cuts = [0, 7, PIPELINE_BLOCK + 3, 2 * PIPELINE_BLOCK + 4099, n];
            for w in cuts.windows(2) {
                assert_eq!(pipelined(&mut sd, &rec, w[0]..w[1], &mut table, w[0], false), (w[1] - w[0], Ok(())));
            }
            assert!(same_bits(&table, &want), "{kind:?}");
        }
    }

    #[test]
    fn bad_row_in_a_later_block_names_its_record_row_and_changes_nothing() {
        let kind = ImuKind::Increments;
        let n = 3 * PIPELINE_BLOCK;
        let good = record(kind, n);
        let mut bad = good.clone();
        let k = 2 * PIPELINE_BLOCK + 11;
        bad.2[k].y = f64::NAN;
        let mut sd = start(kind);
        // the chunk is rows 100… of the record: the error names the record's row
        pipelined(&mut sd, &good, 0..100, &mut vec![0.0; NAV_WIDTH * 100], 0, false).1.unwrap();
        let before = sd.state;
        let mut table = vec![0.0; NAV_WIDTH * n];
        let (_, result) = pipelined(&mut sd, &bad, 100..n, &mut table, 0, false);
        match result {
            Err(NavError::InvalidInput { field, index, reason }) => {
                assert_eq!((field.as_str(), index), ("accel", Some(k)), "{reason}");
                assert!(reason.contains(&format!("index {k}")), "{reason}");
            }
            other => panic!("expected bad input, got {other:?}"),
        }
        assert_eq!(sd.state, before);
        // the stream continues as if the bad chunk had never been given
        let mut again = vec![0.0; NAV_WIDTH * n];
        assert_eq!(pipelined(&mut sd, &good, 100..n, &mut again, 100, false), (n - 100, Ok(())));
        let want = nav_columns(&stepped(kind, &good));
        let col = |t: &[f64], c: usize| t[c * n + 100..(c + 1) * n].to_vec();
        assert!((0..NAV_WIDTH).all(|c| same_bits(&col(&again, c), &col(&want, c))));
    }

    #[test]
    fn divergence_keeps_its_rows() {
        // an accelerometer stream growing tenfold every 8 samples from row 5000 (finite, so
        // the input checks pass) overflows the solution some hundred rows later
        let kind = ImuKind::Increments;
        let n = 3 * PIPELINE_BLOCK;
        let mut rec = record(kind, n);
        for (k, a) in rec.2.iter_mut().enumerate().skip(5000) {
            a.x += 10f64.powf(((k - 5000) as f64 / 8.0).min(300.0));
        }
        let states = stepped(kind, &rec);
        let bad = states.iter().position(|s| !(s.lla.sum() + s.vel.sum() + s.q_nb.coords.sum()).is_finite() || s.lla.x.abs() > std::f64::consts::FRAC_PI_2).unwrap();
        assert!(bad > PIPELINE_BLOCK + 1000 && bad < n - 100, "{bad}");
        let mut sd = start(kind);
        let mut table = vec![f64::NAN; NAV_WIDTH * n];
        let (rows, result) = pipelined(&mut sd, &rec, 0..n, &mut table, 0, false);
        assert_eq!(rows, bad);
        match result {
            Err(NavError::Numerical(msg)) => assert!(msg.contains(&format!("sample {bad} ")), "{msg}"),
            other => panic!("expected a divergence, got {other:?}"),
        }
        let want = nav_columns(&states[..bad]);
        let col = |t: &[f64], stride: usize, c: usize| t[c * stride..c * stride + bad].to_vec();
        assert!((0..NAV_WIDTH).all(|c| same_bits(&col(&table, n, c), &col(&want, bad, c))));
        assert_eq!(sd.state.t, rec.0[bad], "the state is the diverged step's");
    }

    #[test]
    fn rejects_a_short_or_narrow_table_and_bad_shapes() {
        let rec = record(ImuKind::Increments, 50);
        let mut sd = start(ImuKind::Increments);
        let mut small = vec![0.0; NAV_WIDTH * 40];
        let (rows, r) = pipelined(&mut sd, &rec, 0..50, &mut small, 0, false);
        assert_eq!(rows, 0);
        assert!(r.unwrap_err().to_string().starts_with("out: expected a (14, >= 50) table, got [14, 40]"));
        assert!(NavTable::new(&mut [0.0; 26], [13, 2], 0).is_err());
        assert!(Samples3::new("gyro", &[0.0; 8], [2, 4], false).unwrap_err().to_string().contains("gyro: expected shape (N, 3), got (2, 4)"));
        assert!(Samples3::new("gyro", &[0.0; 5], [2, 3], false).is_err());
        let g = Samples3::new("gyro", &[0.0; 6], [2, 3], false).unwrap();
        assert!(ImuSlices::new(&[1.0], g, g, None).is_err());
    }
}
