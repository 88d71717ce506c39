//! One error type for the whole crate. Bad input is `InvalidInput` (mapped to Python
//! `ValueError`), numerical failure is `Numerical` (mapped to `atomnav.NumericalError`).

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum NavError {
    /// Input that can never give a meaningful result: names the field and, for series,
    /// the first offending index.
    #[error("{field}: {reason}")]
    InvalidInput { field: String, reason: String, index: Option<usize> },
    /// An allocation sized by input that this machine cannot hold (mapped to `MemoryError`).
    #[error("{field}: cannot allocate {bytes} bytes")]
    OutOfMemory { field: String, bytes: u128 },
    /// A computation that failed on valid input (loss of positive definiteness, divergence).
    #[error("numerical failure: {0}")]
    Numerical(String),
}

pub type Result<T> = std::result::Result<T, NavError>;

/// Shorthand used by every validator: `invalid("gyro", "NaN at index 12")`.
pub fn invalid(field: &str, reason: impl Into<String>) -> NavError {
    NavError::InvalidInput { field: field.to_string(), reason: reason.into(), index: None }
}

/// Like [`invalid`], for array input: `index` is the first offending row, which Python
/// sees as `InputError.index`.
pub fn invalid_at(field: &str, index: usize, reason: impl Into<String>) -> NavError {
    NavError::InvalidInput { field: field.to_string(), reason: reason.into(), index: Some(index) }
}

/// A count or size taken from input, checked against its meaningful range before anything
/// is allocated from it.
pub fn check_count(field: &str, n: usize, min: usize, max: usize) -> Result<usize> {
    if (min..=max).contains(&n) {
        Ok(n)
    } else {
        Err(invalid(field, format!("must be in [{min}, {max}], got {n}")))
    }
}

/// A vector of `n` elements whose size comes from input: `OutOfMemory` (Python's
/// `MemoryError`, naming the size) instead of an abort when the machine cannot hold it.
pub fn try_vec<T: Clone>(field: &str, n: usize, value: T) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| NavError::OutOfMemory {
        field: field.to_string(),
        bytes: n as u128 * std::mem::size_of::<T>() as u128,
    })?;
    v.resize(n, value);
    Ok(v)
}

/// Reject NaN/inf values in a flat slice of `width`-wide rows, naming the first bad row.
pub fn check_finite(field: &str, data: &[f64], width: usize) -> Result<()> {
    match data.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        None => Ok(()),
        Some((i, v)) if width <= 1 => Err(invalid_at(field, i, format!("non-finite value {v} at index {i}"))),
        Some((i, v)) => Err(invalid_at(field, i / width, format!("non-finite value {v} at index {} (column {})", i / width, i % width))),
    }
}

/// Time stamps must be finite and strictly increasing.
pub fn check_increasing(field: &str, t: &[f64]) -> Result<()> {
    check_finite(field, t, 1)?;
    for (k, w) in t.windows(2).enumerate() {
        if let [prev, cur] = *w {
            if cur <= prev {
                let what = if cur == prev { "duplicated" } else { "decreasing" };
                let k = k + 1;
                return Err(invalid_at(field, k, format!("time not strictly increasing: {what} stamp {cur} at index {k} (previous {prev})")));
            }
        }
    }
    Ok(())
}

/// A strictly positive, finite scalar parameter (sampling interval, period, ...).
pub fn check_positive(field: &str, x: f64) -> Result<()> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, format!("must be finite and > 0, got {x}")))
    }
}
