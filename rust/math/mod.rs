//! Small fixed-size algebra: rotations in every representation the papers use.
pub mod rotation;
pub use rotation::*;
