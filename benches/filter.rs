//! Criterion: 15-state Kalman predict step (P ← ΦPΦᵀ + Q_d) and 21-state DARE.

use atomnav::filter::kf::{Kf, LoopMode};
use atomnav::filter::riccati::dare;
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DMatrix;

/// Deterministic test matrices (no RNG dependency in the bench): a stable Φ, PD Q, R.
fn system(n: usize, m: usize) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let phi = DMatrix::from_fn(n, n, |i, j| if i == j { 0.95 } else { 0.02 * (((i * 7 + j * 3) % 11) as f64 - 5.0) / 5.0 });
    let g = DMatrix::from_fn(n, n, |i, j| (((i * 5 + j * 13) % 17) as f64 - 8.0) / 8.0);
    let q = &g * g.transpose() / n as f64 + DMatrix::identity(n, n) * 1e-3;
    let h = DMatrix::from_fn(m, n, |i, j| (((i * 3 + j * 11) % 7) as f64 - 3.0) / 3.0);
    (phi, q, h, DMatrix::identity(m, m))
}

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

criterion_group!(benches, bench);
criterion_main!(benches);
