//! The linear 6-D quadtree: sorted, condensed location codes of the collision samples,
//! queried by a modified binary search (thesis 3.2.4, Algorithms 2-5, Observation 3.2.1;
//! SPEC §6).
//!
//! # Condensation
//! Thesis Algorithm 3 merges a run of 64 codes from child index 0 to 63, which also merges
//! parents whose children are only partly present; here a node is condensed only when its
//! whole subtree may be reported as collision. Unreachable pairs and unsampled cells are
//! "don't care" (SPEC §6), so a node may be stored as one condensed code exactly when it holds
//! no free sample; each collision leaf is stored as its shallowest free-less ancestor. That is
//! Algorithm 3 run to the end with every don't-care leaf counted as present, and never covers
//! a free sample. A condensed node keeps its prefix and has the bare mark (index 0, bit 6 set)
//! in every level below it, as Algorithm 2's seventh bit.
//!
//! # Query
//! The first stored code `>= L` is the only one that can cover leaf `L` (a condensed node sorts
//! after every leaf of its subtree, and stored nodes are disjoint), so one lower-bound search
//! and one [`covers6`] test replace Algorithm 5's low/high checks.

use super::code::{code6, covers6, valid6, MAX_LEVELS};
#[cfg(feature = "std")]
use super::code::{condensed6, encode};
#[cfg(feature = "std")]
use super::error::bad_input;
use super::error::{corrupt, TableError};
use super::space::fold;
#[cfg(feature = "std")]
use super::space::SpaceView;
#[cfg(feature = "std")]
use crate::cspace::symmetry::Symmetry;
#[cfg(feature = "std")]
use crate::cspace::{Label, LabelledSpace};
use alloc::{format, vec::Vec};

/// Sorted stored codes of the collision samples (see the module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LinearQuadtree6d {
    levels: u32,
    symmetric: bool,
    codes: Vec<u64>,
}

/// Most levels the 6-D builder takes: its free map has `64^(levels-1)` bits (128 MiB at 6).
#[cfg(feature = "std")]
pub const MAX_BUILD_LEVELS_6D: u32 = 6;

/// One bit per node of depth `d`, for `d` in `0..levels`: whether it holds a free sample.
#[cfg(feature = "std")]
fn free_maps(
    view: &SpaceView,
    plain_a: &[u64],
    plain_b: &[u64],
    leaves: &mut Vec<u64>,
) -> Vec<Vec<u64>> {
    let h = view.levels as usize;
    let mut maps: Vec<Vec<u64>> =
        (0..h).map(|d| vec![0u64; (1usize << (6 * d)).div_ceil(64)]).collect();
    let deepest = &mut maps[h - 1];
    for (ia, &ca) in plain_a.iter().enumerate() {
        if !view.stored(ia) {
            continue;
        }
        for (ib, &cb) in plain_b.iter().enumerate() {
            let leaf = ca | cb;
            match view.label(ia, ib) {
                Label::Free => deepest[(leaf >> 12) as usize] |= 1 << ((leaf >> 6) & 63),
                Label::Collision => leaves.push(leaf),
                Label::Unreachable => {}
            }
        }
    }
    for d in (1..h).rev() {
        let (upper, lower) = maps.split_at_mut(d);
        for (p, &w) in lower[0].iter().enumerate() {
            if w != 0 {
                upper[d - 1][p / 64] |= 1 << (p % 64);
            }
        }
    }
    maps
}

impl LinearQuadtree6d {
    /// Builds the table of `space` (thesis Algorithm 4 with the condensation of the module
    /// doc); with [`Symmetry::MirrorY`], only A's upper half `iy >= k/2` is stored (see
    /// `space.rs`).
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ or are not `2^levels` with
    /// `levels <= MAX_BUILD_LEVELS_6D`, or the label count is wrong.
    #[cfg(feature = "std")]
    pub fn build(
        space: &LabelledSpace,
        symmetry: Symmetry,
    ) -> Result<LinearQuadtree6d, TableError> {
        let symmetric = symmetry.is_mirrored();
        let view = SpaceView::new(space, symmetric)?;
        if view.levels > MAX_BUILD_LEVELS_6D {
            return Err(bad_input(format!(
                "6-D builder takes levels <= {MAX_BUILD_LEVELS_6D}, got {}",
                view.levels
            )));
        }
        let h = view.levels;
        let plain_a: Vec<u64> =
            space.grid_a.cells.iter().map(|c| encode([c[0], c[1], c[2], 0, 0, 0], 6)).collect();
        let plain_b: Vec<u64> =
            space.grid_b.cells.iter().map(|c| encode([0, 0, 0, c[0], c[1], c[2]], 6)).collect();
        let mut leaves = Vec::new();
        let maps = free_maps(&view, &plain_a, &plain_b, &mut leaves);
        leaves.sort_unstable();
        let mut codes: Vec<u64> = Vec::new();
        for &leaf in &leaves {
            let depth = (0..h)
                .find(|&d| {
                    let node = leaf >> (6 * (h - d));
                    maps[d as usize][(node / 64) as usize] & (1 << (node % 64)) == 0
                })
                .unwrap_or(h);
            let code = condensed6(leaf, h - depth, h);
            if codes.last() != Some(&code) {
                codes.push(code);
            }
        }
        Ok(LinearQuadtree6d { levels: h, symmetric, codes })
    }

    /// A table from stored parts, validated so that [`query`](Self::query) is exact and safe.
    ///
    /// # Errors
    /// [`TableError::Corrupt`] naming the first bad field: levels out of range, a malformed
    /// code, codes not strictly increasing, or a code inside a condensed node's subtree.
    pub fn from_parts(
        levels: u32,
        symmetric: bool,
        codes: Vec<u64>,
    ) -> Result<LinearQuadtree6d, TableError> {
        if levels == 0 || levels > MAX_LEVELS {
            return Err(corrupt(format!("levels = {levels} must be in 1..={MAX_LEVELS}")));
        }
        if let Some(i) = codes.iter().position(|&c| !valid6(c, levels)) {
            return Err(corrupt(format!(
                "codes[{i}] = {:#x} is not a 6-D code of {levels} levels",
                codes[i]
            )));
        }
        for (i, w) in codes.windows(2).enumerate() {
            if w[0] >= w[1] {
                return Err(corrupt(format!(
                    "codes[{}] is not greater than codes[{i}]: codes are not sorted",
                    i + 1
                )));
            }
            if covers6(w[1], w[0]) {
                return Err(corrupt(format!(
                    "codes[{i}] lies inside the condensed node codes[{}]",
                    i + 1
                )));
            }
        }
        Ok(LinearQuadtree6d { levels, symmetric, codes })
    }

    /// Whether the 6-D cell `(ix, iy, iz, ix', iy', iz')` is stored as collision; an index
    /// `>= k` answers `true` (fail closed). Never allocates.
    #[inline]
    pub fn query(&self, cell: [u16; 6]) -> bool {
        let Some(c) = fold(cell, 1 << self.levels, self.symmetric) else {
            return true;
        };
        let leaf = code6(c);
        let i = self.codes.partition_point(|&s| s < leaf);
        self.codes.get(i).is_some_and(|&s| covers6(s, leaf))
    }

    /// Quadtree levels (`k = 2^levels`).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// Whether only A's upper half is stored.
    pub fn symmetric(&self) -> bool {
        self.symmetric
    }

    /// The stored codes, sorted.
    pub fn codes(&self) -> &[u64] {
        &self.codes
    }

    /// How many stored codes are condensed nodes.
    pub fn condensed(&self) -> usize {
        self.codes.iter().filter(|&&c| c & super::code::MARK != 0).count()
    }

    /// Bytes this table occupies in memory (struct plus its array).
    pub fn memory_bytes(&self) -> usize {
        core::mem::size_of::<Self>() + 8 * self.codes.len()
    }

    /// The thesis's figure for the same code count, `8 m + 64` (Observation 3.2.1).
    pub fn thesis_bytes(&self) -> usize {
        8 * self.codes.len() + 64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cspace::Symmetry;
    use crate::table::synthetic::{space, Pattern};

    #[test]
    fn all_collision_condenses_to_the_root() {
        let s = space(3, Pattern::AllCollision);
        let t = LinearQuadtree6d::build(&s, Symmetry::Whole).unwrap();
        assert_eq!(t.codes().len(), 1, "no free sample: one root node");
        assert!(t.query([0; 6]) && t.query([7; 6]));
        let f = LinearQuadtree6d::build(&space(3, Pattern::AllFree), Symmetry::Whole).unwrap();
        assert!(f.codes().is_empty());
        assert!(!f.query([3, 3, 3, 3, 3, 3]));
    }

    #[test]
    fn condensation_never_covers_a_free_sample() {
        for (pattern, must_condense) in
            [(Pattern::Noise { p: 0.3, seed: 5 }, false), (Pattern::Blobs, true)]
        {
            let s = space(3, pattern);
            let t = LinearQuadtree6d::build(&s, Symmetry::Whole).unwrap();
            let nb = s.grid_b.cells.len();
            let mut collisions = 0;
            for (ia, a) in s.grid_a.cells.iter().enumerate() {
                for (ib, b) in s.grid_b.cells.iter().enumerate() {
                    let got = t.query([a[0], a[1], a[2], b[0], b[1], b[2]]);
                    match s.labels[ia * nb + ib] {
                        Label::Free => {
                            assert!(!got, "free sample {a:?} {b:?} reported as collision")
                        }
                        Label::Collision => {
                            collisions += 1;
                            assert!(got, "collision sample {a:?} {b:?} lost");
                        }
                        Label::Unreachable => {}
                    }
                }
            }
            if must_condense {
                assert!(
                    t.condensed() > 0 && t.codes().len() < collisions,
                    "{} codes for {collisions}",
                    t.codes().len()
                );
            }
            assert!(LinearQuadtree6d::from_parts(3, false, t.codes().to_vec()).is_ok());
        }
    }

    #[test]
    fn out_of_range_index_fails_closed() {
        let t = LinearQuadtree6d::build(&space(2, Pattern::AllFree), Symmetry::Whole).unwrap();
        assert!(t.query([4, 0, 0, 0, 0, 0]));
        assert!(t.query([0, 0, 0, 0, 0, u16::MAX]));
    }

    #[test]
    fn from_parts_rejects_nested_and_unsorted_codes() {
        let root = condensed6(0, 2, 2);
        let leaf = code6([1, 0, 0, 0, 0, 0]);
        assert!(
            LinearQuadtree6d::from_parts(2, false, vec![leaf, root]).is_err(),
            "leaf inside the root"
        );
        assert!(LinearQuadtree6d::from_parts(2, false, vec![leaf, leaf]).is_err(), "duplicate");
        assert!(LinearQuadtree6d::from_parts(9, false, vec![]).is_err(), "levels");
        assert!(LinearQuadtree6d::from_parts(2, false, vec![leaf]).is_ok());
    }
}
