//! The single home of unit conversion factors. Everything inside atomnav is SI
//! (m, s, rad, m/s², rad/s); these constants convert from the units the field quotes.

use std::f64::consts::PI;

/// Standard gravity used for µg and mg (m/s²).
pub const G0: f64 = 9.80665;
pub const DEG: f64 = PI / 180.0;
pub const ARCSEC: f64 = DEG / 3600.0;
pub const ARCMIN: f64 = DEG / 60.0;
pub const HOUR: f64 = 3600.0;
/// °/h → rad/s.
pub const DEG_PER_HOUR: f64 = DEG / HOUR;
/// °/√h → rad/√s (angle random walk).
pub const DEG_PER_SQRT_HOUR: f64 = DEG / 60.0;
/// µg → m/s².
pub const MICRO_G: f64 = 1e-6 * G0;
/// mg → m/s².
pub const MILLI_G: f64 = 1e-3 * G0;
/// µg/√Hz → m/s²/√Hz = m/s/√s (velocity random walk).
pub const MICRO_G_PER_SQRT_HZ: f64 = 1e-6 * G0;
/// m/s/√h → m/s/√s.
pub const MPS_PER_SQRT_HOUR: f64 = 1.0 / 60.0;
/// parts per million → dimensionless.
pub const PPM: f64 = 1e-6;

/// Every factor above by name (read by `atomnav.units`, so Python has no second copy).
pub const UNITS: [(&str, f64); 12] = [
    ("G0", G0),
    ("DEG", DEG),
    ("ARCSEC", ARCSEC),
    ("ARCMIN", ARCMIN),
    ("HOUR", HOUR),
    ("DEG_PER_HOUR", DEG_PER_HOUR),
    ("DEG_PER_SQRT_HOUR", DEG_PER_SQRT_HOUR),
    ("MICRO_G", MICRO_G),
    ("MILLI_G", MILLI_G),
    ("MICRO_G_PER_SQRT_HZ", MICRO_G_PER_SQRT_HZ),
    ("MPS_PER_SQRT_HOUR", MPS_PER_SQRT_HOUR),
    ("PPM", PPM),
];
