//! One error type for the whole crate. Bad input is `InvalidInput` (mapped to Python
//! `ValueError`), numerical failure is `Numerical` (mapped to `atomnav.NumericalError`).

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum NavError {
    /// Input that can never give a meaningful result: names the field and, for series,
    /// the first offending index.
    #[error("{field}: {reason}")]
    InvalidInput { field: String, reason: String },
    /// A computation that failed on valid input (loss of positive definiteness, divergence).
    #[error("numerical failure: {0}")]
    Numerical(String),
}

pub type Result<T> = std::result::Result<T, NavError>;

/// Shorthand used by every validator: `invalid("gyro", "NaN at index 12")`.
pub fn invalid(field: &str, reason: impl Into<String>) -> NavError {
    NavError::InvalidInput { field: field.to_string(), reason: reason.into() }
}

/// Reject NaN/inf values in a flat slice of `width`-wide rows, naming the first bad row.
pub fn check_finite(field: &str, data: &[f64], width: usize) -> Result<()> {
    match data.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) if width == 1 => Err(invalid(field, format!("non-finite value {} at index {i}", data[i]))),
        Some(i) => Err(invalid(
            field,
            format!("non-finite value {} at index {} (column {})", data[i], i / width, i % width),
        )),
    }
}

/// Time stamps must be finite and strictly increasing.
pub fn check_increasing(field: &str, t: &[f64]) -> Result<()> {
    check_finite(field, t, 1)?;
    for k in 1..t.len() {
        if t[k] <= t[k - 1] {
            let what = if t[k] == t[k - 1] { "duplicated" } else { "decreasing" };
            return Err(invalid(
                field,
                format!("time not strictly increasing: {what} stamp {} at index {k} (previous {})", t[k], t[k - 1]),
            ));
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
