//! Atom strapdown predictor throughput: IMU samples per second (6 channels, T = 25 ms,
//! back-to-back shots, 1 kHz IMU), with and without the tangent-linear Jacobian.

use atomnav::cai::predictor::{jacobian, predict, Channel, Imu, Interpolation, OmegaDot, PredictorConfig};
use atomnav::math::{Mat3, Vec3};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;

/// (t, specific force, angular rate, shot starts, channels)
type Setup = (Vec<f64>, Vec<Vec3>, Vec<Vec3>, Vec<f64>, Vec<Channel>);

fn setup(n: usize) -> Setup {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
    let f = t.iter().map(|&s| Vec3::new(0.3 * (4.3 * s).sin(), 0.1 * (9.7 * s).cos(), -9.81)).collect();
    let w = t.iter().map(|&s| Vec3::new(0.01 * (1.3 * s).sin(), 0.02, 0.05 * (0.1 * s).cos())).collect();
    let shots = (0..((n - 2) / 50)).map(|i| i as f64 * 0.05).collect();
    let mut ch = Vec::new();
    for j in 0..3 {
        for s in [1.0, -1.0] {
            ch.push(Channel { k: Vec3::ith(j, 1.610576e7), lever: Vec3::new(0.0, 0.0, 0.1), c_sb: Mat3::identity(), v0: Vec3::ith((j + 1) % 3, 2.8 * s) });
        }
    }
    (t, f, w, shots, ch)
}

fn bench(c: &mut Criterion) {
    let n = 10_001;
    let (t, f, w, shots, ch) = setup(n);
    let imu = Imu { t: &t, f: &f, w: &w };
    let cfg = PredictorConfig {
        t_sep: 0.025,
        substeps: 1,
        gradient: None,
        bias_a: Vec3::zeros(),
        bias_g: Vec3::zeros(),
        omega_dot: OmegaDot::Savgol { half_width: 2 },
        interpolation: Interpolation::Linear,
    };
    let mut g = c.benchmark_group("cai");
    g.sample_size(10);
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("predict_6ch_10s_1kHz", |b| b.iter(|| predict(black_box(imu), &shots, &ch, &cfg).unwrap()));
    g.bench_function("jacobian_6ch_10s_1kHz", |b| b.iter(|| jacobian(black_box(imu), &shots, &ch, &cfg, false).unwrap()));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
