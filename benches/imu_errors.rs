//! IMU error simulation throughput: 100 000 samples (100 s at 1 kHz) per iteration, for a
//! white + random-walk preset (navigation) and one with flicker noise (tactical).

use atomnav::imu::errors::ImuSimulator;
use atomnav::imu::ImuKind;
use atomnav::imu::presets::preset;
use atomnav::math::Vec3;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn corrupt(c: &mut Criterion) {
    let n = 100_000;
    let f = vec![Vec3::new(0.1, -0.2, -9.8); n];
    let w = vec![Vec3::new(1e-3, 2e-3, 0.1); n];
    let mut g = c.benchmark_group("imu_corrupt_100k");
    g.sample_size(10);
    for name in ["navigation", "tactical"] {
        let model = preset(name).unwrap();
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut sim = ImuSimulator::new(&model, 1e-3, ImuKind::Rates, 1).unwrap();
                black_box(sim.corrupt(&f, &w).unwrap())
            })
        });
    }
    g.finish();
}

criterion_group!(benches, corrupt);
criterion_main!(benches);
