//! IMU: ideal measurement generation from a reference trajectory, and the sensor error
//! models / noise processes that turn ideal measurements into realistic ones.
pub mod ideal;
pub mod errors;
pub mod noise;
pub mod presets;


/// Kind of IMU output: instantaneous (or interval-average) rates — specific force m/s²,
/// angular rate rad/s — or increments over (t_{k−1}, t_k] — Δv m/s, Δθ rad.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuKind {
    Rates,
    Increments,
}

impl crate::options::Choice for ImuKind {
    const PARAMETER: &'static str = "kind";
    const CHOICES: &'static [(&'static str, Self)] = &[("rates", ImuKind::Rates), ("increments", ImuKind::Increments)];
}

impl ImuKind {
    /// Factor from an increment over Δt to the output sample: 1/Δt (rates) or 1.
    pub fn per_increment(self, dt: f64) -> f64 {
        match self {
            ImuKind::Rates => 1.0 / dt,
            ImuKind::Increments => 1.0,
        }
    }

    /// Factor from a rate to the output sample: 1 (rates) or Δt (increments).
    pub fn per_rate(self, dt: f64) -> f64 {
        match self {
            ImuKind::Rates => 1.0,
            ImuKind::Increments => dt,
        }
    }
}
