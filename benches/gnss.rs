//! Criterion: tightly coupled GNSS/INS over 60 s of a stationary 100 Hz IMU record with
//! 1 Hz first-difference code and rate measurements (nominal GPS + GLONASS), and one
//! single-point position solution.

use atomnav::earth::WGS84;
use atomnav::filter::aided::{run_aided, AidedConfig, AidedIns};
use atomnav::filter::discretize::Discretization;
use atomnav::filter::ins::{BiasModel, InsNoise};
use atomnav::filter::kf::LoopMode;
use atomnav::gnss::constellation::{nominal, ConstellationConfig};
use atomnav::gnss::observation::{simulate, Atmosphere, SimConfig, Visibility};
use atomnav::gnss::spp::{solve_position, SppConfig};
use atomnav::gnss::tight::{Formulation, TightAiding, TightConfig};
use atomnav::gnss::TimeScales;
use atomnav::imu::ImuKind;
use atomnav::math::{quat, Vec3};
use atomnav::strapdown::NavState;
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{DMatrix, DVector};

fn bench(c: &mut Criterion) {
    let lla = Vec3::new(55.75f64.to_radians(), 37.6f64.to_radians(), 200.0);
    let cfg = ConstellationConfig { gps: true, glonass: true, t_start: 0.0, t_end: 120.0, tau_gps: -340e-9, time: TimeScales::default(), clocks: true, seed: 1 };
    let eph = nominal(&cfg).unwrap();
    let atm = Atmosphere { iono: Some(Default::default()), tropo: true };
    let sim = SimConfig { sigma_code_gps: 3.0, sigma_code_glo: 3.0, sigma_rate: 0.05, tau_gps: -340e-9, clock_bias: 1e-4, clock_drift: 1e-9, atm, seed: 2 };
    let vis = Visibility { mask: 10f64.to_radians(), ..Default::default() };
    let tg: Vec<f64> = (1..=60).map(|k| k as f64).collect();
    let obs = simulate(&eph, &tg, &vec![lla; 60], &vec![Vec3::zeros(); 60], &sim, &vis).unwrap();
    let epochs: Vec<(f64, Vec<_>)> = tg.iter().zip(&obs).map(|(&t, o)| (t, o.iter().map(|x| x.0).collect())).collect();
    let loc = WGS84.local(lla.x, lla.z);
    let t: Vec<f64> = (0..=6000).map(|k| k as f64 * 0.01).collect();
    let gyro = vec![loc.earth_rate(); t.len()];
    let accel = vec![Vec3::new(0.0, 0.0, -loc.gravity); t.len()];
    let tight = TightConfig {
        formulation: Formulation::FirstDifference, lever_arm: Vec3::new(0.5, 0.0, -1.0), sigma_code_gps: 3.0, sigma_code_glo: 3.0,
        sigma_rate: 0.05, use_rate: true, atm, elevation_mask: 10f64.to_radians(), tau_psd: 1e-4, clock_h0: 2e-19, clock_hm2: 2e-20, kind: ImuKind::Rates,
    };
    let noise = InsNoise { accel_psd: 1e-8, gyro_psd: 1e-14, accel_bias: BiasModel::RandomConstant, gyro_bias: BiasModel::RandomConstant };
    let acfg = AidedConfig { noise, predict_every: 100, method: Discretization::VanLoan, mode: LoopMode::Closed, sequential: true, gate: Some(10.83) };
    let mut p0 = vec![100.0, 100.0, 100.0, 0.01, 0.01, 0.01, 1e-8, 1e-8, 1e-6, 1e-8, 1e-8, 1e-8, 1e-12, 1e-12, 1e-12];
    p0.push(9e4);
    let p0 = DMatrix::from_diagonal(&DVector::from_vec(p0));
    let s0 = NavState { t: 0.0, lla, vel: Vec3::zeros(), q_nb: quat(1.0, 0.0, 0.0, 0.0) };
    let mut g = c.benchmark_group("gnss");
    g.sample_size(10);
    g.bench_function("tight_fd_60s_100hz", |b| {
        b.iter(|| {
            let aiding = TightAiding::new(eph.clone(), epochs.clone(), tight).unwrap();
            let ins = AidedIns::new(s0, ImuKind::Rates, WGS84, Vec3::zeros(), Vec3::zeros(), DVector::zeros(1), p0.clone(), acfg, aiding).unwrap();
            run_aided(ins, &t, &gyro, &accel).unwrap().0.nav.len()
        })
    });
    // the defaults of GnssOptions: 10° mask, fault detection on
    let spp = SppConfig { use_tau: true, atm, sigma_gps: 3.0, sigma_glo: 3.0, elevation_weight: false, elevation_mask: 10f64.to_radians(), fault_detection: true, ionosphere_free: false };
    g.bench_function("spp_one_epoch", |b| b.iter(|| solve_position(&eph, 1.0, &epochs[0].1, &spp, None).unwrap().pos));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
