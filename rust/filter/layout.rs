//! Error-state layout from named blocks; indices are derived, never hand-typed.

use crate::error::{invalid, Result};
use std::ops::Range;

/// Size of the standard blocks (navigation errors and IMU error blocks).
pub fn standard_size(name: &str) -> Option<usize> {
    match name {
        "position" | "velocity" | "attitude" | "accel_bias" | "gyro_bias" | "accel_scale" | "gyro_scale" => Some(3),
        // Off-diagonal small-angle misalignment terms: (xy, xz, yx, yz, zx, zy).
        "accel_misalignment" | "gyro_misalignment" => Some(6),
        _ => None,
    }
}

/// Names of the standard blocks, for error messages and documentation.
pub const STANDARD_BLOCKS: [&str; 9] = [
    "position", "velocity", "attitude", "accel_bias", "gyro_bias", "accel_scale", "gyro_scale", "accel_misalignment", "gyro_misalignment",
];

/// The 15-state layout of spec gnss-ins-tight §2.9 / atom-strapdown E22 (block order as in
/// the project: accelerometer bias before gyro bias).
pub const INS15: [&str; 5] = ["position", "velocity", "attitude", "accel_bias", "gyro_bias"];

#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    blocks: Vec<(String, Range<usize>)>,
}

impl Layout {
    /// Blocks in order; a standard block takes its standard size (`None`), an extra
    /// block (lever arm, clock, ...) must give its size.
    pub fn new(spec: &[(String, Option<usize>)]) -> Result<Layout> {
        if spec.is_empty() {
            return Err(invalid("blocks", "at least one block is required"));
        }
        let mut blocks: Vec<(String, Range<usize>)> = Vec::with_capacity(spec.len());
        let mut n = 0;
        for (i, (name, size)) in spec.iter().enumerate() {
            if blocks.iter().any(|(b, _)| b == name) {
                return Err(invalid("blocks", format!("duplicate block name {name:?} at index {i}")));
            }
            let len = match (standard_size(name), size) {
                (Some(s), None) => s,
                (Some(s), Some(k)) if *k == s => s,
                (Some(s), Some(k)) => return Err(invalid("blocks", format!("block {name:?} at index {i} has size {s}, got {k}"))),
                (None, Some(k)) if *k > 0 => *k,
                (None, Some(_)) => return Err(invalid("blocks", format!("block {name:?} at index {i}: size must be > 0"))),
                (None, None) => {
                    return Err(invalid(
                        "blocks",
                        format!("unknown block name {name:?} at index {i}: a non-standard block needs a size (standard: {})", STANDARD_BLOCKS.join(", ")),
                    ))
                }
            };
            blocks.push((name.clone(), n..n + len));
            n += len;
        }
        Ok(Layout { blocks })
    }

    /// The 15-state INS layout.
    pub fn ins15() -> Layout {
        Layout::new(&INS15.map(|s| (s.to_string(), None))).expect("standard blocks")
    }

    /// Total state size.
    pub fn size(&self) -> usize {
        self.blocks.last().map_or(0, |(_, r)| r.end)
    }

    /// Index range of a block; unknown names are rejected with the list of known ones.
    pub fn range(&self, name: &str) -> Result<Range<usize>> {
        self.get(name).ok_or_else(|| {
            let known: Vec<&str> = self.blocks.iter().map(|(b, _)| b.as_str()).collect();
            invalid("block", format!("unknown block name {name:?} (layout has: {})", known.join(", ")))
        })
    }

    /// Index range of a block, or None.
    pub fn get(&self, name: &str) -> Option<Range<usize>> {
        self.blocks.iter().find(|(b, _)| b == name).map(|(_, r)| r.clone())
    }

    /// (name, range) of every block in order.
    pub fn blocks(&self) -> &[(String, Range<usize>)] {
        &self.blocks
    }

    /// Name of every state component, e.g. "velocity[2]".
    pub fn labels(&self) -> Vec<String> {
        self.blocks.iter().flat_map(|(b, r)| (0..r.len()).map(move |i| format!("{b}[{i}]"))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_indices() {
        let l = Layout::new(&[("position".into(), None), ("attitude".into(), None), ("clock".into(), Some(2)), ("gyro_bias".into(), None)]).unwrap();
        assert_eq!(l.range("clock").unwrap(), 6..8);
        assert_eq!(l.range("gyro_bias").unwrap(), 8..11);
        assert_eq!(l.size(), 11);
        assert!(l.range("velocity").is_err());
        assert_eq!(Layout::ins15().range("gyro_bias").unwrap(), 12..15);
    }
}
