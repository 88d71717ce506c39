//! Astro-inertial calibration on the 73-epoch `vasilyuk2024_like` scenario (Vasilyuk et al. 2024):
//! gyro increments over 302k samples (E3–E7), star attitudes (E9–E12), and Gauss–Newton
//! with the sandwich covariance (E17–E18), each per iteration.

use atomnav::astro::calibration::{calibrate, DiffForm, Options};
use atomnav::astro::increments::{integrate_increments, GyroErrorMode, ImuRecord, TaylorVariant};
use atomnav::astro::scenario::{run, vasilyuk2024_like};
use atomnav::astro::stars::star_attitudes;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn astro(c: &mut Criterion) {
    let scn = vasilyuk2024_like(3, GyroErrorMode::Paper).unwrap();
    let r = run(&scn, 0, &Options::default(), DiffForm::Full).unwrap();
    let rec = ImuRecord { t_start: scn.t_start, period: scn.period, rho: &scn.rho_true };
    let mut g = c.benchmark_group("astro_vasilyuk2024");
    g.sample_size(10);
    g.bench_function("gyro_increments_73_epochs", |b| {
        b.iter(|| black_box(integrate_increments(&rec, &scn.epochs, &scn.gyro, TaylorVariant::Corrected).unwrap()))
    });
    g.bench_function("star_attitudes_73_epochs", |b| {
        b.iter(|| black_box(star_attitudes(&r.observations, scn.epochs.len(), &scn.cameras, scn.sigma_s, Some((&scn.up_gcrs, scn.n_refr)), None).unwrap()))
    });
    g.bench_function("gauss_newton_and_covariance", |b| b.iter(|| black_box(calibrate(&r.ds_imu, &r.ds_avu, &Options::default()).unwrap())));
    g.finish();
}

criterion_group!(benches, astro);
criterion_main!(benches);
