//! Strapdown mechanization in the local-level NED frame.
