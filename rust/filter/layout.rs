//! Error-state layout from named blocks; indices are derived, never hand-typed.

use crate::error::{invalid, Result};
use std::ops::Range;

/// The standard blocks and their sizes (navigation errors and IMU error blocks), in the
/// order the documentation lists them; misalignment blocks carry the off-diagonal
/// small-angle terms (xy, xz, yx, yz, zx, zy). Python reads this table
/// (`_core.STATE_BLOCKS`).
pub const STANDARD_BLOCKS: [(&str, usize); 9] = [
    ("position", 3),
    ("velocity", 3),
    ("attitude", 3),
    ("accel_bias", 3),
    ("gyro_bias", 3),
    ("accel_scale", 3),
    ("gyro_scale", 3),
    ("accel_misalignment", 6),
    ("gyro_misalignment", 6),
];

/// Size of a standard block, or None for an extra block (lever arm, clock, ...).
pub fn standard_size(name: &str) -> Option<usize> {
    STANDARD_BLOCKS.iter().find(|(b, _)| *b == name).map(|(_, k)| *k)
}

/// The 15-state INS layout (Groves 2013, §14.2.1; block order as in the project:
/// accelerometer bias before gyro bias). Aided-INS layouts are these blocks followed by
/// the aiding sensor's extra blocks.
pub const INS15: [&str; 5] = ["position", "velocity", "attitude", "accel_bias", "gyro_bias"];

/// Number of states of [`INS15`]: the index of the first extra block of an aided-INS layout.
pub fn ins_size() -> usize {
    INS15.iter().filter_map(|b| standard_size(b)).sum()
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Layout {
    blocks: Vec<(String, Range<usize>)>,
}

/// Most states of a layout (its covariance, 10⁴ × 10⁴ floats, is 800 MB).
pub const MAX_STATES: usize = 10_000;

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
                        format!(
                            "unknown block name {name:?} at index {i}: a non-standard block needs a size (standard: {})",
                            STANDARD_BLOCKS.map(|b| b.0).join(", ")
                        ),
                    ))
                }
            };
            if len > MAX_STATES - n {
                return Err(invalid("blocks", format!("more than {MAX_STATES} states (block {name:?} at index {i} has size {len})")));
            }
            blocks.push((name.clone(), n..n + len));
            n += len;
        }
        Ok(Layout { blocks })
    }

    /// The 15-state INS layout.
    // invariant: INS15 has fixed, distinct, non-empty blocks and no extra block is
    // given, the only inputs on which ins_with fails.
    #[allow(clippy::expect_used)]
    pub fn ins15() -> Layout {
        Layout::ins_with(&[]).expect("standard blocks")
    }

    /// [`INS15`] followed by the extra blocks (name, size) of an aiding sensor.
    pub fn ins_with(extra: &[(String, usize)]) -> Result<Layout> {
        let mut spec: Vec<(String, Option<usize>)> = INS15.iter().map(|s| (s.to_string(), None)).collect();
        spec.extend(extra.iter().map(|(b, k)| (b.clone(), Some(*k))));
        Layout::new(&spec)
    }

    /// Index of block `name` within the extra blocks of an aided-INS layout (its start
    /// minus [`ins_size`]), or None when the layout has no such extra block.
    pub fn extra_index(&self, name: &str) -> Option<usize> {
        self.get(name).and_then(|r| r.start.checked_sub(ins_size()))
    }

    /// Total state size.
    pub fn size(&self) -> usize {
        self.blocks.last().map_or(0, |(_, r)| r.end)
    }

    /// Index range of a block. A missing block is a fault of the layout the caller built,
    /// so the error names `blocks` and lists the blocks the layout has.
    pub fn range(&self, name: &str) -> Result<Range<usize>> {
        self.get(name).ok_or_else(|| {
            let known: Vec<&str> = self.blocks.iter().map(|(b, _)| b.as_str()).collect();
            invalid("blocks", format!("the layout has no block {name:?} (it has: {})", known.join(", ")))
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

    #[test]
    fn oversized_blocks_are_rejected_not_wrapped() {
        for spec in [vec![("clock".to_string(), Some(usize::MAX))], vec![("a".into(), Some(MAX_STATES)), ("b".into(), Some(1))]] {
            match Layout::new(&spec) {
                Err(crate::error::NavError::InvalidInput { field, .. }) => assert_eq!(field, "blocks"),
                other => panic!("expected InvalidInput on blocks, got {other:?}"),
            }
        }
        assert_eq!(Layout::new(&[("a".into(), Some(MAX_STATES))]).unwrap().size(), MAX_STATES);
    }

    #[test]
    fn ins_layout_and_extra_blocks() {
        // Groves 2013 §14.2.1: 3 position, 3 velocity, 3 attitude, 3 + 3 bias states
        assert_eq!(ins_size(), 15);
        assert_eq!(Layout::ins15().size(), ins_size());
        let l = Layout::ins_with(&[("c_tau_gps".into(), 1), ("clock".into(), 2)]).unwrap();
        assert_eq!(l.range("clock").unwrap(), 16..18);
        assert_eq!(l.extra_index("clock"), Some(1));
        assert_eq!(l.extra_index("c_tau_gps"), Some(0));
        assert_eq!(l.extra_index("position"), None);
        assert_eq!(l.extra_index("lever_arm"), None);
    }
}
