//! Reference trajectories: continuous-time motion models (`motion`), their smooth
//! building blocks (`profile`), and the named scenarios of the papers (`generators`).
pub mod errors;
pub mod generators;
pub mod motion;
pub mod profile;

pub use errors::{nav_error, nav_errors, NavSeries, ERROR_COLUMNS};
pub use motion::{euler_chain, AxisRotation, Kinematics, Motion, TruthState};
pub use profile::{Eval, Profile, StepShape, Term};
