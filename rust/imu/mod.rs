//! IMU: ideal measurement generation from a reference trajectory, and the sensor error
//! models / noise processes that turn ideal measurements into realistic ones.
pub mod ideal;
pub mod errors;
pub mod noise;
pub mod presets;
