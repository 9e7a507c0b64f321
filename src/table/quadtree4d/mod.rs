//! The linear 4-D quadtree: location codes over four dimensions, each pointing to a shared
//! 2-D bit slice of the two ignored ones, slices grouped by similarity (thesis 3.2.6,
//! Algorithms 8 and 9, Observation 3.2.3; SPEC §6).
//!
//! # Conventions
//! `SliceAxes::YY` ignores `(iy, iy')` (the quadtree runs over `(ix, iz, ix', iz')`),
//! `SliceAxes::ZZ` ignores `(iz, iz')` (over `(ix, iy, ix', iy')`). Slice bit
//! `(a - a0) * k + b` holds `(a, b)` = A's and B's ignored index; `a0 = k/2` for symmetric
//! yy' slices, which then hold only A's upper half (`k/2` rows), else 0 (`k` rows).
//!
//! # Grouping (Algorithm 8)
//! Ranges are visited in the thesis's order `x, x', z, z'` (`x, x', y, y'` for zz' slices).
//! A range's slice `S` joins the first group whose representative `R` satisfies
//! `|S \ R| < G_add` and `|R \ S| < G_sub` (the thesis's strict `<`), or matches exactly
//! (both 0): with `t = 0` strict `<` would match nothing, and the thesis says `t = 0` groups
//! exact matches. `R` becomes `R ∪ S` and `G_add -= |S \ R|`; `G_sub` stays `t`. Don't-care
//! bits of `S` (unreachable or unsampled) are 0 in `S` and not counted in `|R \ S|`, so
//! `t = 0` still answers every free and collision sample exactly.
//!
//! At `t = 0` a slice joins only a representative that agrees with it on every care bit
//! (`R ∩ C = S`, with `S ⊆ C`), so `R ∪ S = R`: representatives never change once made.
//! `ExactGroups` uses that to find the first such group without scanning the groups one by
//! one; the groups, and so the table, are those of the scan.
//!
//! This file holds the table and its query (what the controller loads); the builder is in
//! `build.rs`, Algorithm 8's grouping in `grouping.rs` and, for the report tool only
//! (`eval` feature), the tables of sub-cell labels in `sub_cells.rs`.

use super::code::{encode, MAX_LEVELS};
use super::error::{corrupt, TableError};
use super::space::fold;
use alloc::{format, vec::Vec};

#[cfg(feature = "std")]
mod build;
#[cfg(feature = "std")]
mod grouping;
#[cfg(feature = "eval")]
mod sub_cells;

#[cfg(feature = "eval")]
pub use sub_cells::{subdivided_slices, SliceBound};

/// Which two dimensions a slice holds (the two the quadtree ignores).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SliceAxes {
    /// `(iy, iy')` slices.
    YY,
    /// `(iz, iz')` slices.
    ZZ,
}

impl SliceAxes {
    /// (the quadtree's second dimension per robot, the ignored dimension per robot).
    fn dims(self) -> (usize, usize) {
        match self {
            SliceAxes::YY => (2, 1),
            SliceAxes::ZZ => (1, 2),
        }
    }
}

/// Sorted 4-D codes, each with the index of its slice (see the module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LinearQuadtree4d {
    levels: u32,
    symmetric: bool,
    axes: SliceAxes,
    t: u32,
    codes: Vec<u64>,
    slice_of: Vec<u32>,
    slices: Vec<u64>,
}

/// Slice shape for these parameters: (first row `a0`, words per slice).
fn shape(levels: u32, symmetric: bool, axes: SliceAxes) -> (u32, usize) {
    let k = 1u32 << levels;
    let a0 = if symmetric && axes == SliceAxes::YY { k / 2 } else { 0 };
    (a0, (((k - a0) * k) as usize).div_ceil(64))
}

impl LinearQuadtree4d {
    /// A table from stored parts, validated so that [`query`](Self::query) is exact and safe.
    ///
    /// # Errors
    /// [`TableError::Corrupt`] naming the first bad field: levels, a code out of range or
    /// out of order, a slice index `>=` the slice count, a slice array of the wrong length.
    pub fn from_parts(
        levels: u32,
        symmetric: bool,
        axes: SliceAxes,
        t: u32,
        codes: Vec<u64>,
        slice_of: Vec<u32>,
        slices: Vec<u64>,
    ) -> Result<LinearQuadtree4d, TableError> {
        if levels == 0 || levels > MAX_LEVELS {
            return Err(corrupt(format!("levels = {levels} must be in 1..={MAX_LEVELS}")));
        }
        if let Some(i) = codes.iter().position(|&c| c >> (4 * levels) != 0) {
            return Err(corrupt(format!(
                "codes[{i}] = {:#x} has bits above {levels} 4-bit levels",
                codes[i]
            )));
        }
        if let Some(i) = codes.windows(2).position(|w| w[0] >= w[1]) {
            return Err(corrupt(format!(
                "codes[{}] is not greater than codes[{i}]: codes are not sorted",
                i + 1
            )));
        }
        let (_, wps) = shape(levels, symmetric, axes);
        if slices.len() % wps != 0 {
            return Err(corrupt(format!(
                "slices has {} words, not a multiple of {wps} per slice",
                slices.len()
            )));
        }
        let count = slices.len() / wps;
        if slice_of.len() != codes.len() {
            return Err(corrupt(format!(
                "slice_of has {} entries for {} codes",
                slice_of.len(),
                codes.len()
            )));
        }
        if let Some(i) = slice_of.iter().position(|&s| s as usize >= count) {
            return Err(corrupt(format!(
                "slice_of[{i}] = {} is not below the slice count {count}",
                slice_of[i]
            )));
        }
        Ok(LinearQuadtree4d { levels, symmetric, axes, t, codes, slice_of, slices })
    }

    /// Whether the 6-D cell is stored as collision (thesis Algorithm 9); an index `>= k`
    /// answers `true`. Never allocates.
    #[inline]
    pub fn query(&self, cell: [u16; 6]) -> bool {
        let k = 1u32 << self.levels;
        let Some(c) = fold(cell, k, self.symmetric) else {
            return true;
        };
        let (second, ignored) = self.axes.dims();
        let Ok(i) = self.codes.binary_search(&encode([c[0], c[second], c[3], c[3 + second]], 4))
        else {
            return false;
        };
        let (a0, wps) = shape(self.levels, self.symmetric, self.axes);
        let bit = ((u32::from(c[ignored]) - a0) * k + u32::from(c[3 + ignored])) as usize;
        let Some(&s) = self.slice_of.get(i) else { return true };
        self.slices.get(s as usize * wps + bit / 64).is_none_or(|w| (w >> (bit % 64)) & 1 != 0)
    }

    /// Quadtree levels (`k = 2^levels`).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// Whether only A's upper half is stored.
    pub fn symmetric(&self) -> bool {
        self.symmetric
    }

    /// The ignored dimensions.
    pub fn axes(&self) -> SliceAxes {
        self.axes
    }

    /// The similarity threshold it was built with.
    pub fn threshold(&self) -> u32 {
        self.t
    }

    /// The stored parts: codes, slice index per code, slice words.
    pub fn parts(&self) -> (&[u64], &[u32], &[u64]) {
        (&self.codes, &self.slice_of, &self.slices)
    }

    /// Number of distinct slices (groups).
    pub fn slice_count(&self) -> usize {
        self.slices.len() / shape(self.levels, self.symmetric, self.axes).1
    }

    /// Bytes this table occupies in memory (struct plus its arrays).
    pub fn memory_bytes(&self) -> usize {
        core::mem::size_of::<Self>()
            + 8 * self.codes.len()
            + 4 * self.slice_of.len()
            + 8 * self.slices.len()
    }

    /// The thesis's figure, `8 m + s b^2 / 8 + 8 b + 76` (Observation 3.2.3), for slices of
    /// `b x b` squares (`b` = sampled coordinates along an ignored axis, 29 for the thesis's
    /// yy' slices at k = 32).
    pub fn thesis_bytes(&self, b: usize) -> usize {
        8 * self.codes.len() + self.slice_count() * b * b / 8 + 8 * b + 76
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_parts_rejects_bad_slice_indices() {
        let (_, wps) = shape(2, false, SliceAxes::YY);
        let ok = LinearQuadtree4d::from_parts(
            2,
            false,
            SliceAxes::YY,
            0,
            vec![3],
            vec![0],
            vec![0; wps],
        );
        assert!(ok.is_ok());
        let bad = LinearQuadtree4d::from_parts(
            2,
            false,
            SliceAxes::YY,
            0,
            vec![3],
            vec![1],
            vec![0; wps],
        );
        assert!(bad.is_err(), "slice index out of range");
        let bad = LinearQuadtree4d::from_parts(
            2,
            false,
            SliceAxes::YY,
            0,
            vec![3, 3],
            vec![0, 0],
            vec![0; wps],
        );
        assert!(bad.is_err(), "duplicate code");
    }
}
