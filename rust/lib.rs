//! atomnav: hybrid quantum–classical inertial navigation.
//!
//! One folder per idea (see README "Layout"). Everything here is plain Rust; the
//! Python bindings live in `py/` behind the `python` feature so `cargo test` and
//! `cargo bench` never link libpython.

pub mod astro;
pub mod cai;
pub mod earth;
pub mod error;
pub mod filter;
pub mod gnss;
pub mod imu;
pub mod math;
pub mod noise;
pub mod options;
pub mod state;
pub mod strapdown;
pub mod trajectory;
pub mod units;

#[cfg(test)]
mod proptests;

#[cfg(feature = "python")]
mod py;

pub use error::{NavError, Result};
