//! Criterion: the 15-state Kalman predict step (P ← ΦPΦᵀ + Q_d), the 21-state DARE, and
//! the register-kernel / nalgebra path against the faer path at n = 9 … 150 (21, 60 and
//! 150 among them) for each dense step that dispatches on the state size: the DARE
//! doubling (riccati.rs), the filter's covariance predict (kf.rs, also the covariance
//! analysis `sigmas`), the true-error analysis (analysis.rs) and the RTS smoother (kf.rs).
//! The crossovers stated next to each dispatch come from these numbers.
//!
//! The crossover group is timed in CPU time of the benchmarking thread, not wall time:
//! what is compared is the two algebras' work, and CPU time does not count the time the
//! thread waits for a core on a shared machine, which would otherwise decide a close call.

use atomnav::filter::analysis::Scenario;
use atomnav::filter::dense::Algebra;
use atomnav::filter::discretize::Discretization;
use atomnav::filter::kf::{rts_using, Kf, LoopMode, StoredStep};
use atomnav::filter::riccati::{dare, dare_using};
use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::DMatrix;
use std::time::Duration;

/// Deterministic test matrices (no RNG dependency in the bench): a stable Φ, PD Q, R.
fn system(n: usize, m: usize) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let phi = DMatrix::from_fn(n, n, |i, j| if i == j { 0.95 } else { 0.02 * (((i * 7 + j * 3) % 11) as f64 - 5.0) / 5.0 });
    let g = DMatrix::from_fn(n, n, |i, j| (((i * 5 + j * 13) % 17) as f64 - 8.0) / 8.0);
    let q = &g * g.transpose() / n as f64 + DMatrix::identity(n, n) * 1e-3;
    let h = DMatrix::from_fn(m, n, |i, j| (((i * 3 + j * 11) % 7) as f64 - 3.0) / 3.0);
    (phi, q, h, DMatrix::identity(m, m))
}

const SIZES: [usize; 9] = [9, 12, 15, 21, 30, 45, 52, 60, 150];
const ALGEBRAS: [(&str, Algebra); 2] = [("kernels", Algebra::Kernels), ("faer", Algebra::Faer)];

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("filter");
    let (phi, q, _, _) = system(15, 3);
    let mut kf = Kf::new(DMatrix::identity(15, 15), LoopMode::Open).unwrap();
    g.bench_function("predict_15_state", |b| {
        // Φ is stable, so P stays bounded over any number of iterations.
        b.iter(|| kf.predict(&phi, &q).unwrap())
    });
    let (phi, q, h, r) = system(21, 6);
    g.bench_function("dare_21_state", |b| b.iter(|| dare(&phi, &q, &h, &r).unwrap()));
    g.finish();
}

/// CPU time consumed by the calling thread (`CLOCK_THREAD_CPUTIME_ID`), reported like
/// wall time.
struct ThreadCpuTime;

static WALL: WallTime = WallTime;

fn thread_cpu_time() -> Duration {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid timespec for the call to write into.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

impl Measurement for ThreadCpuTime {
    type Intermediate = Duration;
    type Value = Duration;
    fn start(&self) -> Duration {
        thread_cpu_time()
    }
    fn end(&self, start: Duration) -> Duration {
        thread_cpu_time().saturating_sub(start)
    }
    fn add(&self, a: &Duration, b: &Duration) -> Duration {
        *a + *b
    }
    fn zero(&self) -> Duration {
        Duration::ZERO
    }
    fn to_f64(&self, v: &Duration) -> f64 {
        v.as_nanos() as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        WALL.formatter()
    }
}

/// Each dispatched step on both algebras at every size of `SIZES`.
fn crossover(c: &mut Criterion<ThreadCpuTime>) {
    let mut g = c.benchmark_group("crossover");
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    for n in SIZES {
        let (phi, q, h, r) = system(n, n / 4);
        for (name, algebra) in ALGEBRAS {
            g.bench_function(BenchmarkId::new(format!("dare/{name}"), n), |b| b.iter(|| dare_using(&phi, &q, &h, &r, algebra).unwrap()));
            // Steady state, as in a filter run: Φ scaled to a row-sum norm of 0.95 keeps P
            // bounded over any number of repeated steps, and the buffers stay warm.
            let phi_contracting = &phi * (0.95 / phi.row_iter().map(|r| r.abs().sum()).fold(0.0, f64::max));
            let mut kf = Kf::new(DMatrix::identity(n, n), LoopMode::Open).unwrap().with_algebra(algebra);
            g.bench_function(BenchmarkId::new(format!("predict/{name}"), n), |b| b.iter(|| kf.predict(&phi_contracting, &q).unwrap()));
        }
        // true-error analysis over 10 steps with a measurement at every epoch
        let steps = 10;
        let f = vec![(&phi - DMatrix::identity(n, n)) * 0.1; steps];
        let qc = vec![q.clone(); steps];
        let scn = Scenario::new(&f, &qc, &vec![0.1; steps], DMatrix::identity(n, n), h.clone(), r.clone(), vec![true; steps + 1], Discretization::FirstOrder, false).unwrap();
        let cross = vec![DMatrix::zeros(n, h.nrows()); steps];
        // RTS over 100 stored steps of a filter run (30 at n = 150)
        let mut kf = Kf::new(DMatrix::identity(n, n), LoopMode::Open).unwrap();
        let stored: Vec<StoredStep> = (0..if n < 150 { 100 } else { 30 })
            .map(|k| {
                let (x_prior, p_prior) = (kf.x.clone(), kf.p.clone());
                kf.update(&vec![0.1 * k as f64; h.nrows()], &h, &r, false, None).unwrap();
                let s = StoredStep { phi: phi.clone(), x_prior, p_prior, x_post: kf.x.clone(), p_post: kf.p.clone() };
                kf.predict(&phi, &q).unwrap();
                s
            })
            .collect();
        for (name, algebra) in ALGEBRAS {
            g.bench_function(BenchmarkId::new(format!("true_sigmas/{name}"), n), |b| b.iter(|| scn.true_sigmas_using(&r, &cross, algebra).unwrap()));
            g.bench_function(BenchmarkId::new(format!("rts/{name}"), n), |b| b.iter(|| rts_using(&stored, algebra).unwrap()));
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_group! {
    name = crossovers;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = crossover
}
criterion_main!(benches, crossovers);
