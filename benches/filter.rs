//! Criterion: the 15-state Kalman predict step (P ← ΦPΦᵀ + Q_d), the 21-state DARE, and
//! the register-kernel / nalgebra path against the faer path at n = 21, 60, 150 for each
//! dense step that dispatches on the state size: the DARE doubling (riccati.rs), the
//! filter's covariance predict (kf.rs, also the covariance analysis `sigmas`), the
//! true-error analysis (analysis.rs) and the RTS smoother (kf.rs). The crossovers stated
//! next to each dispatch come from these numbers.

use atomnav::filter::analysis::Scenario;
use atomnav::filter::dense::Algebra;
use atomnav::filter::discretize::Discretization;
use atomnav::filter::kf::{rts_using, Kf, LoopMode, StoredStep};
use atomnav::filter::riccati::{dare, dare_using};
use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
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

const SIZES: [usize; 3] = [21, 60, 150];
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

/// Each dispatched step on both algebras at n = 21, 60, 150.
fn crossover(c: &mut Criterion) {
    let mut g = c.benchmark_group("crossover");
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    for n in SIZES {
        let (phi, q, h, r) = system(n, n / 4);
        for (name, algebra) in ALGEBRAS {
            g.bench_function(BenchmarkId::new(format!("dare/{name}"), n), |b| b.iter(|| dare_using(&phi, &q, &h, &r, algebra).unwrap()));
            // each timed step starts from the same P, so repeated steps cannot grow it unbounded
            let kf = Kf::new(DMatrix::identity(n, n), LoopMode::Open).unwrap().with_algebra(algebra);
            g.bench_function(BenchmarkId::new(format!("predict/{name}"), n), |b| {
                b.iter_batched_ref(|| kf.clone(), |k| k.predict(&phi, &q).unwrap(), BatchSize::SmallInput)
            });
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

criterion_group!(benches, bench, crossover);
criterion_main!(benches);
