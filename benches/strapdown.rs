//! Criterion: strapdown mechanization throughput on 10 minutes of exact 100 Hz increments
//! of a sinusoidal motion (60 000 steps per iteration), for both IMU output kinds, step by
//! step into states and pipelined on two cores into a navigation table.

use atomnav::earth::WGS84;
use atomnav::imu::ideal::{ideal_increments, ideal_rates};
use atomnav::math::Vec3;
use atomnav::strapdown::{ImuKind, ImuSlices, NavState, NavTable, Samples3, Strapdown, Vertical, NAV_WIDTH};
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
    let (gf, af): (Vec<f64>, Vec<f64>) = (dth.iter().flat_map(|v| v.iter().copied()).collect(), dv.iter().flat_map(|v| v.iter().copied()).collect());
    let n = dth.len();
    let mut table = vec![0.0; NAV_WIDTH * n];
    g.bench_function("increments_100Hz_10min_pipelined_table", |b| {
        b.iter(|| {
            let mut sd = Strapdown::new(init, ImuKind::Increments, WGS84, Vertical::Free).unwrap();
            let imu = ImuSlices::new(&times[1..], Samples3::new("gyro", &gf, [n, 3], false).unwrap(), Samples3::new("accel", &af, [n, 3], false).unwrap(), None).unwrap();
            sd.run_pipelined(&imu, NavTable::new(&mut table, [NAV_WIDTH, n], 0).unwrap(), 0).1.unwrap();
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
