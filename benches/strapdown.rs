//! Criterion: strapdown mechanization throughput on 10 minutes of exact 100 Hz increments
//! of a sinusoidal motion (60 000 steps per iteration), for both IMU output kinds.

use atomnav::earth::WGS84;
use atomnav::imu::ideal::{ideal_increments, ideal_rates};
use atomnav::math::Vec3;
use atomnav::strapdown::{ImuKind, NavState, Strapdown, Vertical};
use atomnav::trajectory::generators::sinusoidal;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

fn bench(c: &mut Criterion) {
    let m = sinusoidal(Vec3::new(0.97, 0.65, 200.0), 600.0, Vec3::new(20.0, 15.0, 2.0), Vec3::new(60.0, 45.0, 30.0), Vec3::new(0.1, 0.08, 0.3), Vec3::new(20.0, 25.0, 40.0), 0.5).unwrap();
    let times: Vec<f64> = (0..=60_000).map(|k| k as f64 * 0.01).collect();
    let truth = m.truth(&WGS84, &times).unwrap();
    let init = NavState { t: 0.0, lla: truth[0].lla, vel: truth[0].vel, q_nb: truth[0].q_nb };
    let (dv, dth) = ideal_increments(&m, &WGS84, &truth);
    let (f, w, _) = ideal_rates(&m, &WGS84, &truth);
    let mut g = c.benchmark_group("strapdown");
    g.sample_size(20).throughput(Throughput::Elements(dth.len() as u64));
    let mut out = Vec::with_capacity(times.len());
    g.bench_function("increments_100Hz_10min", |b| {
        b.iter(|| {
            let mut sd = Strapdown::new(init, ImuKind::Increments, WGS84, Vertical::Free).unwrap();
            out.clear();
            sd.run(&times[1..], &dth, &dv, None, &mut out).unwrap();
        })
    });
    g.bench_function("rates_100Hz_10min", |b| {
        b.iter(|| {
            let mut sd = Strapdown::new(init, ImuKind::Rates, WGS84, Vertical::Free).unwrap();
            out.clear();
            sd.run(&times, &w, &f, None, &mut out).unwrap();
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
