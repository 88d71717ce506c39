//! Allan variance and the ARIMA Kalman filters at 10⁶ samples (criterion).
//! Run: `cargo bench --bench noise`.

use atomnav::noise::allan::{self, DataType, Kind, TauSet};
use atomnav::noise::arma_filter::{kalman, ArimaStateSpace, NoiseForm, RMode, X0};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

const N: usize = 1_000_000;

fn series() -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(105);
    let white = Normal::new(0.6851, 0.1248).expect("valid normal");
    (0..N).map(|_| white.sample(&mut rng)).collect()
}

fn bench(c: &mut Criterion) {
    let y = series();
    let mut g = c.benchmark_group("noise");
    g.sample_size(10);
    g.throughput(Throughput::Elements(N as u64));
    for kind in [Kind::Allan, Kind::Modified, Kind::Hadamard] {
        g.bench_function(format!("{kind:?} variance, octave τ, 1e6 samples"), |b| {
            b.iter(|| allan::variance(&y, 52.0, DataType::Rate, kind, &TauSet::Octave).expect("valid input"))
        });
    }
    let model = ArimaStateSpace::from_arma(&[-0.018, 0.029], &[-0.99], 0.035, 1, NoiseForm::Paper).expect("valid model");
    for (name, mode) in [("fixed", RMode::Fixed), ("adaptive (differenced)", RMode::Differenced), ("Sage-Husa", RMode::SageHusa { b: 0.98, adapt_q: false, fading: false })] {
        g.bench_function(format!("Kalman {name}, 1e6 samples"), |b| {
            b.iter(|| kalman(&y, &model, 0.035, mode, X0::Zeros, 1.0, false).expect("valid input"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
