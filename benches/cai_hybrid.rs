//! CAI-aided INS throughput: one 35 s car run of Tennstedt et al. 2023 (200 Hz IMU, kinematic mode, one
//! shot per 50 ms with 6 channels, 15 states) through the generic engine with `CaiAiding`.

use atomnav::cai::aiding::{shot_times, CaiAiding, CaiConfig, CaiData};
use atomnav::cai::predictor::{predict, Channel, Imu, Interpolation, OmegaDot, PredictorConfig};
use atomnav::earth::KINEMATIC;
use atomnav::filter::aided::{run_aided, AidedConfig, AidedIns};
use atomnav::filter::discretize::Discretization;
use atomnav::filter::ins::{BiasModel, InsNoise};
use atomnav::filter::kf::LoopMode;
use atomnav::imu::ideal::ideal_rates;
use atomnav::imu::ImuKind;
use atomnav::math::{Mat3, Vec3};
use atomnav::strapdown::NavState;
use atomnav::trajectory::generators::car;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{DMatrix, DVector};

fn bench(c: &mut Criterion) {
    let motion = car(Vec3::new(0.914, 0.17, 60.0), 0.0, true);
    let t: Vec<f64> = (0..=7000).map(|i| i as f64 * 0.005).collect();
    let truth = motion.truth(&KINEMATIC, &t).unwrap();
    let (f, w, _) = ideal_rates(&motion, &KINEMATIC, &truth);
    let channels: Vec<Channel> =
        (0..6).map(|c| Channel { k: Vec3::ith(c / 2, 1.610576e7), lever: Vec3::zeros(), c_sb: Mat3::identity(), v0: Vec3::ith((c / 2 + 1) % 3, if c % 2 == 0 { 2.8 } else { -2.8 }) }).collect();
    let shots = shot_times(0.0, 35.0, 0.025, 0.05).unwrap();
    let pcfg = PredictorConfig { t_sep: 0.025, substeps: 1, gradient: None, bias_a: Vec3::zeros(), bias_g: Vec3::zeros(), omega_dot: OmegaDot::Pwl, interpolation: Interpolation::Cubic };
    let phase: Vec<f64> = predict(Imu { t: &t, f: &f, w: &w }, &shots, &channels, &pcfg).unwrap().iter().map(|r| r[0]).collect();
    let noise = vec![0.0; phase.len()];
    let cfg = CaiConfig {
        inflation: Some((1.25e-11, 1.0576e-12)),
        interpolation: Interpolation::Cubic,
        ..CaiConfig::ideal(channels, 0.025, shots, 1e-3f64.sqrt())
    };
    let filter = AidedConfig {
        noise: InsNoise { accel_psd: 1.25e-11, gyro_psd: 1.0576e-12, accel_bias: BiasModel::RandomWalk { psd: 9e-10 }, gyro_bias: BiasModel::RandomWalk { psd: 4e-14 } },
        predict_every: 10,
        method: Discretization::VanLoan,
        mode: LoopMode::Closed,
        sequential: false,
        gate: None,
    };
    let sig = [1e-6, 1e-6, 1e-7, 2e-5, 1e-6];
    let p0 = DMatrix::from_diagonal(&DVector::from_fn(15, |i, _| sig[i / 3] * sig[i / 3]));
    let initial = NavState { t: 0.0, lla: truth[0].lla, vel: truth[0].vel, q_nb: truth[0].q_nb };
    let mut g = c.benchmark_group("cai_hybrid");
    g.sample_size(10);
    g.throughput(Throughput::Elements(t.len() as u64));
    g.bench_function("car_35s_200Hz_6ch_15states", |b| {
        b.iter(|| {
            let aiding = CaiAiding::new(cfg.clone(), CaiData::Emulated { phase: phase.clone(), noise: noise.clone() }).unwrap();
            let ins = AidedIns::new(initial, ImuKind::Rates, KINEMATIC, Vec3::zeros(), Vec3::zeros(), DVector::zeros(0), p0.clone(), filter, aiding).unwrap();
            run_aided(ins, &t, &w, &f).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
