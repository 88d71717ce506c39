//! Named IMU grade presets: error models of typical instrument classes, each value with its
//! source. All values are converted to SI densities here (noise.rs conventions); the
//! comments quote them in the units of the source. Python (`atomnav.imu`) reads them
//! through `preset` and lets users register their own named sets.

use super::errors::{FlickerSpec, GaussMarkovSpec, ImuErrorModel, TriadErrors};
use super::noise::{gauss_markov_sigma, white_density};
use super::ImuKind;
use crate::error::{invalid, Result};
use crate::math::Vec3;
use crate::units::{DEG_PER_HOUR, DEG_PER_SQRT_HOUR, HOUR, MICRO_G, MICRO_G_PER_SQRT_HZ, MILLI_G};

/// Names of the built-in presets, in a stable order.
pub const PRESET_NAMES: [&str; 8] =
    ["navigation", "tactical", "mems", "electrostatic_space", "electrostatic_space_drift", "precise", "medium", "coarse"];

fn triad(bias_sigma: f64, white: f64, bias_rw: f64) -> TriadErrors {
    TriadErrors { bias_sigma, white, bias_rw, ..TriadErrors::default() }
}

/// Navigation-grade RLG IMU of Tennstedt et al. 2023 (units read as in
/// docs/departures.md#noise-units): white noise σ_d = 5e-5 m/s² and
/// 1.4544e-5 rad/s per sample at 200 Hz (→ VRW 3.5355e-6 m/s/√s = 0.36 µg/√Hz, ARW
/// 1.0284e-6 rad/√s = 0.0035 °/√h); bias random-walk PSD q_ra = 9e-10 m²/s⁵, q_rg = 4e-14
/// rad²/s³ (K = 3e-5 m/s²/√s, 2e-7 rad/s/√s). Turn-on bias σ from the filter initialisation
/// P0 of docs/departures.md#scenario-values: 2e-5 m/s², 1e-6 rad/s.
fn navigation() -> Result<ImuErrorModel> {
    let dt = 1.0 / 200.0;
    Ok(ImuErrorModel {
        accel: triad(2e-5, white_density(5e-5, dt, ImuKind::Rates)?, 9e-10f64.sqrt()),
        gyro: triad(1e-6, white_density(1.4544e-5, dt, ImuKind::Rates)?, 4e-14f64.sqrt()),
    })
}

/// Tactical grade: typical class values, not one datasheet. Turn-on biases 1 °/h and 1 mg
/// are the lower ends of the tactical class in El-Sheimy & Youssef 2020, "Inertial sensors
/// technologies for navigation applications", Satellite Navigation 1:2, Table 1 (gyro
/// drift 1–10 °/h, accelerometer bias 1–5 mg). ARW 0.1 °/√h, VRW 100 µg/√Hz and bias
/// instabilities 0.3 °/h and 50 µg (flicker, band 1e-4…0.1 Hz) are typical class values
/// of tactical FOG/MEMS IMUs.
fn tactical() -> ImuErrorModel {
    let band = |b| Some(FlickerSpec { b, f_lo: 1e-4, f_hi: 0.1 });
    ImuErrorModel {
        accel: TriadErrors { flicker: band(50.0 * MICRO_G), ..triad(MILLI_G, 100.0 * MICRO_G_PER_SQRT_HZ, 0.0) },
        gyro: TriadErrors { flicker: band(0.3 * DEG_PER_HOUR), ..triad(DEG_PER_HOUR, 0.1 * DEG_PER_SQRT_HOUR, 0.0) },
    }
}

/// Tactical MEMS of the hexapod scenario of Tennstedt et al. 2021 (placeholders,
/// docs/departures.md#hexapod-scenario): accel white ASD 5e-5 m/s²/√Hz, gyro ARW 1.5e-5 rad/√s,
/// biases (2e-3, −1.5e-3, 1e-3) m/s² and (5e-5, −4e-5, 3e-5) rad/s, bias random-walk PSD
/// 1e-12 m²/s⁵ and 1e-16 rad²/s³ (K = 1e-6 m/s²/√s and 1e-8 rad/s/√s).
fn mems() -> ImuErrorModel {
    ImuErrorModel {
        accel: TriadErrors { bias: Vec3::new(2e-3, -1.5e-3, 1e-3), ..triad(0.0, 5e-5, 1e-12f64.sqrt()) },
        gyro: TriadErrors { bias: Vec3::new(5e-5, -4e-5, 3e-5), ..triad(0.0, 1.5e-5, 1e-16f64.sqrt()) },
    }
}

/// Electrostatic space accelerometer of Tennstedt et al. 2021, Sec. 5.2
/// (docs/departures.md#satellite-scenario): white ASD 1e-10 m/s²/√Hz (σ 1e-10 m/s²
/// per sample at 1 Hz) plus a Gauss–Markov process with τ = 10 s driven by σ_gm = 2e-12 m/s²
/// per 1-s sample, i.e. stationary σ = 2e-12/√(1 − e^{−0.2}) = 4.6975e-12 m/s². `drift`
/// adds the bias random walk q_rw = 1e-21 m²/s⁵. The paper models accelerometer
/// axes only, so the gyro triad is error-free.
fn electrostatic_space(drift: bool) -> Result<ImuErrorModel> {
    let gm = GaussMarkovSpec { sigma: gauss_markov_sigma(2e-12, 10.0, 1.0)?, tau: 10.0 };
    let rw = if drift { 1e-21f64.sqrt() } else { 0.0 };
    Ok(ImuErrorModel { accel: TriadErrors { gauss_markov: Some(gm), ..triad(0.0, 1e-10, rw) }, gyro: TriadErrors::default() })
}

/// Demidov (2009) INS accuracy classes (docs/departures.md#accuracy-classes): gyro drift
/// and accelerometer bias as random turn-on constants of that σ, ARW, VRW; bias process
/// "constant plus random walk of 1 % of the bias per √h": K = 0.01·σ_b/√(3600 s).
fn demidov(gyro_drift: f64, accel_bias: f64, arw: f64, vrw: f64) -> ImuErrorModel {
    let k = 0.01 / HOUR.sqrt();
    ImuErrorModel { accel: triad(accel_bias, vrw, k * accel_bias), gyro: triad(gyro_drift, arw, k * gyro_drift) }
}

/// The built-in preset `name`; an unknown name is InvalidInput listing the known ones.
pub fn preset(name: &str) -> Result<ImuErrorModel> {
    match name {
        "navigation" => navigation(),
        "tactical" => Ok(tactical()),
        "mems" => Ok(mems()),
        "electrostatic_space" => electrostatic_space(false),
        "electrostatic_space_drift" => electrostatic_space(true),
        // precise: 0.05 °/h, 20 µg, ARW 0.003 °/√h, VRW 10 µg/√Hz
        "precise" => Ok(demidov(0.05 * DEG_PER_HOUR, 20.0 * MICRO_G, 0.003 * DEG_PER_SQRT_HOUR, 10.0 * MICRO_G_PER_SQRT_HZ)),
        // medium: 1 °/h, 200 µg, 0.05 °/√h, 50 µg/√Hz
        "medium" => Ok(demidov(DEG_PER_HOUR, 200.0 * MICRO_G, 0.05 * DEG_PER_SQRT_HOUR, 50.0 * MICRO_G_PER_SQRT_HZ)),
        // coarse (MEMS): 30 °/h, 3 mg, 0.5 °/√h, 200 µg/√Hz
        "coarse" => Ok(demidov(30.0 * DEG_PER_HOUR, 3.0 * MILLI_G, 0.5 * DEG_PER_SQRT_HOUR, 200.0 * MICRO_G_PER_SQRT_HZ)),
        _ => Err(invalid("preset", format!("unknown preset {name:?}; choose one of {PRESET_NAMES:?}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::imu::noise::{gauss_markov_driving_sigma, white_sigma};

    #[test]
    fn every_name_resolves_to_a_valid_model() {
        for name in PRESET_NAMES {
            preset(name).unwrap().validate().unwrap();
        }
        let e = preset("strategic").unwrap_err().to_string();
        assert!(e.starts_with("preset:") && e.contains("navigation") && e.contains("coarse"), "{e}");
    }

    #[test]
    fn presets_reproduce_their_source_numbers() {
        // Tennstedt et al. 2023: per-sample σ at 200 Hz and ARW 0.00354 °/√h
        let n = preset("navigation").unwrap();
        assert!((white_sigma(n.accel.white, 1.0 / 200.0, ImuKind::Rates).unwrap() / 5e-5 - 1.0).abs() < 1e-12);
        assert!((n.gyro.white / DEG_PER_SQRT_HOUR / 0.00354 - 1.0).abs() < 2e-3);
        // Tennstedt et al. 2021 satellite: driving σ 2e-12 per 1-s sample
        let g = preset("electrostatic_space").unwrap().accel.gauss_markov.unwrap();
        assert!((gauss_markov_driving_sigma(g.sigma, g.tau, 1.0).unwrap() / 2e-12 - 1.0).abs() < 1e-12);
        // Demidov medium: 1 °/h = 4.8481e-6 rad/s, RW 1 % per √h
        let m = preset("medium").unwrap();
        assert!((m.gyro.bias_sigma / 4.84813681e-6 - 1.0).abs() < 1e-8);
        assert!((m.gyro.bias_rw * 60.0 / m.gyro.bias_sigma - 0.01).abs() < 1e-15);
    }
}
