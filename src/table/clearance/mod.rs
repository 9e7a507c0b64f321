//! Certified clearance tables: per 6-D grid cell, a lower bound on the two robots'
//! clearance taken from a ladder of levels fixed at build time (SPEC §6, §8).
//!
//! A level `L` is stored for a grid cell only when every configuration of the cell is proved
//! to have clearance `>= L`: the whole-cell box sweeps of the certified labels with `L` mm
//! added to robot A's sweeps are proved apart (`crate::cspace::certify`, the `extra` of the
//! protective verdict's proof). A cell that may collide, or that no level can be proved for,
//! has *no level*: the cells the boolean certified labels call COLLISION have none, and
//! [`ClearanceTable::query`] answers exactly as the boolean `shared` table of the same labels.
//!
//! # Storage
//! Two shared 6-D quadtrees ([`SharedQuadtree6d`]), as the file holds them:
//! - the *exact* tree: the boolean table of the certified labels, at `k` (free: level 0 or
//!   more proved; collision: no level);
//! - the *level* tree, at `k >> shift`: per coarse cell (a block of `2^shift` grid cells per
//!   axis and robot) the smallest level proved for any free grid cell pair in it, as a
//!   *thermometer word* below the coarse grid: `m` of the `n` levels proved gives bits
//!   `m..64` set (`u64::MAX << m`), all `n` gives 0. Collision pairs are "don't care" there
//!   (the exact tree answers them), a block of top-level cells is a uniform free child, and
//!   the words in between are at most `n - 1` distinct leaves, stored once. The mirror merge
//!   of a symmetric table ORs a pair's word with its mirror's: the smaller level wins.
//!
//! # Lookup: one descent and one read
//! The level tree is the stored form. A table, built or loaded, expands it once into a
//! *level grid* when the grid fits the size budget (below): one 4-bit count per coarse cell
//! of the whole `(k >> shift)^6` grid (no symmetry fold: the mirror half holds what the level
//! tree's folded lookup answers there), 16 counts to a `u64`. A lookup is then the exact
//! tree's descent (the boolean `shared` table's reads) and one read of the level grid at an
//! address computed from the cell indices alone, so the two reads do not wait for each
//! other: a fixed number of memory reads, one dependent chain. A table whose grid does not
//! fit (at k = 16 the `k / 2` grid is 128 KiB against an exact tree of 19-37 KB) keeps the
//! two descents: the exact tree's and the level tree's, side by side.
//!
//! Why the grid answers what the level tree answers: its count at a coarse cell is
//! `trailing_zeros` of the level tree's word there, read by the level tree's own lookup
//! (`query_word`, folding as it folds), so for every grid cell the lookup gives the count
//! the two-descent lookup of the same trees gives, except that a count of 16 (a ladder of
//! [`MAX_RUNGS`] levels, all proved) is kept as 15: 4 bits, and a lower level is always safe.
//!
//! Storing a lower level than proved is always safe, so the builder takes the finest `shift`
//! whose two trees are at most [`SIZE_BUDGET`] times the exact tree's bytes, both in memory
//! and in the file (against the `shared` table's file of the same labels); the
//! grid is added when the table with it stays within that budget (the same rule on load, so
//! a file gives the same lookup wherever it is loaded).

#[cfg(feature = "std")]
mod coarse;

use super::error::{corrupt, TableError};
use super::shared6d::{SharedParts, SharedQuadtree6d};
use alloc::{format, vec, vec::Vec};

/// Most levels a ladder holds.
pub const MAX_RUNGS: usize = 16;

/// The levels of a clearance table (mm): finite, at least 0, strictly increasing, 1 to
/// [`MAX_RUNGS`] of them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ladder {
    len: u8,
    mm: [f64; MAX_RUNGS],
}

// Every value is finite (checked in `Ladder::new`), so equality is reflexive.
impl Eq for Ladder {}

impl Ladder {
    /// The default ladder: 0, 5, 10, 20, 40, 80, 160 mm.
    pub const DEFAULT_MM: [f64; 7] = [0.0, 5.0, 10.0, 20.0, 40.0, 80.0, 160.0];

    /// A ladder of `mm`.
    ///
    /// # Errors
    /// [`TableError::BadInput`] naming the fault: no level, more than [`MAX_RUNGS`], a value
    /// not finite or below 0, or not strictly increasing.
    pub fn new(mm: &[f64]) -> Result<Ladder, TableError> {
        let bad = |what: alloc::string::String| TableError::BadInput { what };
        if mm.is_empty() || mm.len() > MAX_RUNGS {
            return Err(bad(format!(
                "a clearance ladder has 1 to {MAX_RUNGS} levels, got {}",
                mm.len()
            )));
        }
        if let Some(v) = mm.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(bad(format!("clearance level {v} mm must be finite and >= 0")));
        }
        if let Some(w) = mm.windows(2).find(|w| w[0] >= w[1]) {
            return Err(bad(format!(
                "clearance levels must increase: {} mm then {} mm",
                w[0], w[1]
            )));
        }
        let mut out = [0.0; MAX_RUNGS];
        out[..mm.len()].copy_from_slice(mm);
        Ok(Ladder { len: mm.len() as u8, mm: out })
    }

    /// The default ladder ([`Ladder::DEFAULT_MM`]).
    pub fn default_ladder() -> Ladder {
        Ladder::new(&Ladder::DEFAULT_MM).expect("the default ladder is valid")
    }

    /// The levels (mm), lowest first.
    pub fn mm(&self) -> &[f64] {
        &self.mm[..usize::from(self.len)]
    }

    /// How many levels.
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// Whether there is no level (never, for a ladder from [`Ladder::new`]).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// The thermometer word of a cell with `count` of `n` levels proved (module doc).
pub(crate) fn word_of(count: usize, n: usize) -> u64 {
    if count >= n {
        0
    } else {
        u64::MAX << count
    }
}

/// How many of `n` levels a stored word proves.
#[inline]
fn count_of(word: u64, n: usize) -> usize {
    (word.trailing_zeros() as usize).min(n)
}

/// The builder's size limit: the level tree takes the finest coarsening that keeps the whole
/// table at most this many times the exact (boolean) tree's bytes, or the coarsest.
pub const SIZE_BUDGET: usize = 3;

/// The level grid (module doc): one 4-bit count per coarse cell, 16 to a word, the cell
/// `(c0 .. c5)` (coarse indices of `bits` bits each) at index `c0 << 5 bits | .. | c5`.
#[derive(Clone, Debug, PartialEq, Eq)]
struct LevelGrid {
    /// Bits per coarse index (`levels - shift`).
    bits: u32,
    words: Vec<u64>,
}

impl LevelGrid {
    /// The grid of `level_tree` (coarse grid of `2^bits` per axis), `n` ladder levels.
    fn of(level_tree: &SharedQuadtree6d, bits: u32, n: usize) -> LevelGrid {
        let cells = 1usize << (6 * bits);
        let mut words = vec![0u64; cells.div_ceil(16)];
        let mask = (1usize << bits) - 1;
        for i in 0..cells {
            let c: [u16; 6] =
                core::array::from_fn(|j| (i >> (bits as usize * (5 - j)) & mask) as u16);
            let count = count_of(level_tree.query_word(c), n).min(15) as u64;
            words[i / 16] |= count << (4 * (i % 16));
        }
        LevelGrid { bits, words }
    }

    /// Bytes of the grid's counts for a coarse grid of `2^bits` cells per axis (`None`
    /// beyond the address space).
    fn bytes_for(bits: u32) -> Option<usize> {
        let cells = 1usize.checked_shl(6 * bits).filter(|_| 6 * bits < usize::BITS - 1)?;
        Some(cells.div_ceil(16) * 8)
    }

    /// The count of the grid cell `cell` (indices at `k = 2^(bits + shift)`; an index beyond
    /// reads some cell of the grid, never out of bounds: the exact tree answers such a cell
    /// as collision, so the count is not used).
    #[inline(always)]
    fn count(&self, cell: [u16; 6], shift: u32) -> usize {
        let mask = (1usize << self.bits) - 1;
        let i = cell.iter().fold(0usize, |i, &v| i << self.bits | (usize::from(v) >> shift & mask));
        // `i < 2^(6 bits)`, and `words` holds `2^(6 bits) / 16` words (rounded up).
        (self.words[i / 16] >> (4 * (i % 16)) & 15) as usize
    }
}

/// The stored arrays of one tree, as [`SharedQuadtree6d::from_parts`] takes them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TreeParts {
    /// `[nonuniform, collision]` per inner node.
    pub masks: Vec<[u64; 2]>,
    /// Per inner node, where its children start.
    pub bases: Vec<u32>,
    /// First node of each inner depth, then the node count.
    pub depth_start: Vec<u32>,
    /// Child indices.
    pub children: Vec<u32>,
    /// Leaves.
    pub leaves: Vec<u64>,
}

impl TreeParts {
    fn of(t: &SharedQuadtree6d) -> TreeParts {
        let p: SharedParts = t.parts();
        let children = p.children.to_u32();
        TreeParts {
            masks: p.masks,
            bases: p.bases,
            depth_start: p.depth_start,
            children,
            leaves: p.leaves,
        }
    }

    fn tree(
        self,
        levels: u32,
        sub_levels: u32,
        symmetric: bool,
    ) -> Result<SharedQuadtree6d, TableError> {
        let TreeParts { masks, bases, depth_start, children, leaves } = self;
        SharedQuadtree6d::from_parts(
            levels,
            sub_levels,
            symmetric,
            masks,
            bases,
            depth_start,
            children,
            leaves,
        )
    }

    /// The child indices as the file packs them (`format.rs`, variant 8): each inner depth's
    /// in [`child_width`] of what they point into, little-endian. A level tree's children
    /// mostly point at its few leaves, one byte each instead of four.
    pub(crate) fn packed_children(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut children = self.children.iter();
        // A valid tree's depth runs hold exactly its child indices.
        for (count, targets) in
            depth_runs(&self.masks, &self.depth_start, self.leaves.len()).into_iter().flatten()
        {
            let width = child_width(targets);
            for _ in 0..count {
                let c = children.next().copied().unwrap_or(0);
                out.extend_from_slice(&c.to_le_bytes()[..width]);
            }
        }
        out
    }

    /// The inverse of [`packed_children`](Self::packed_children) for a tree whose masks,
    /// depth starts and leaf count are read: the indices taken from the front of `bytes`.
    ///
    /// # Errors
    /// [`TableError::Corrupt`] when the depth starts do not cover the nodes in order, or
    /// `bytes` is too short.
    pub(crate) fn unpack_children(
        masks: &[[u64; 2]],
        depth_start: &[u32],
        leaves: usize,
        bytes: &mut &[u8],
        what: &str,
    ) -> Result<Vec<u32>, TableError> {
        let runs = depth_runs(masks, depth_start, leaves).ok_or_else(|| {
            corrupt(format!(
                "{what}: depth starts {depth_start:?} do not cover its {} nodes",
                masks.len()
            ))
        })?;
        let mut out = Vec::new();
        for (count, targets) in runs {
            let width = child_width(targets);
            let n = count.checked_mul(width).filter(|&n| n <= bytes.len()).ok_or_else(|| {
                let left = bytes.len();
                corrupt(format!("{what}: {count} child indices of {width} bytes, the section has {left} bytes left"))
            })?;
            let (run, rest) = bytes.split_at(n);
            out.extend(
                run.chunks_exact(width)
                    .map(|c| c.iter().rev().fold(0u32, |v, &b| v << 8 | u32::from(b))),
            );
            *bytes = rest;
        }
        Ok(out)
    }
}

/// Bytes of a packed child index that points into `targets` entries: 1 up to 256, 2 up to
/// 65,536, else 4.
pub(crate) fn child_width(targets: usize) -> usize {
    match targets {
        0..=0x100 => 1,
        0x101..=0x1_0000 => 2,
        _ => 4,
    }
}

/// Per inner depth: how many child indices its nodes hold (their non-uniform children) and
/// how many entries those point into (the next depth's nodes; the leaves, for the last inner
/// depth). `None` when `depth_start` is not `0`, non-decreasing, ending at the node count.
fn depth_runs(
    masks: &[[u64; 2]],
    depth_start: &[u32],
    leaves: usize,
) -> Option<Vec<(usize, usize)>> {
    let starts: Vec<usize> = depth_start.iter().map(|&d| d as usize).collect();
    let ordered = starts.windows(2).all(|w| w[0] <= w[1]);
    if starts.len() < 2 || starts[0] != 0 || !ordered || starts[starts.len() - 1] != masks.len() {
        return None;
    }
    let depths = starts.len() - 1;
    let runs = (0..depths).map(|d| {
        let count =
            masks[starts[d]..starts[d + 1]].iter().map(|m| m[0].count_ones() as usize).sum();
        let targets = if d + 1 < depths { starts[d + 2] - starts[d + 1] } else { leaves };
        (count, targets)
    });
    Some(runs.collect())
}

/// Bytes a `shared` table file holds for `tree` (`format::to_bytes`): two words per inner
/// node's masks, a word per leaf, four bytes per depth start, base and child index.
fn stored_bytes(tree: &SharedQuadtree6d) -> usize {
    let p = tree.parts();
    16 * p.masks.len()
        + 8 * p.leaves.len()
        + 4 * (p.depth_start.len() + p.bases.len() + p.children.len())
}

/// As [`stored_bytes`], the child indices packed as a clearance table file holds them.
fn packed_bytes(tree: &SharedQuadtree6d) -> usize {
    let p = TreeParts::of(tree);
    16 * p.masks.len()
        + 8 * p.leaves.len()
        + 4 * (p.depth_start.len() + p.bases.len())
        + p.packed_children().len()
}

/// A clearance table (module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ClearanceTable {
    exact: SharedQuadtree6d,
    level_tree: SharedQuadtree6d,
    /// The level tree expanded for the lookup, when it fits the size budget (module doc).
    grid: Option<LevelGrid>,
    /// 1 when the ladder starts at 0 mm (a free cell has level 0 proved), else 0.
    floor: usize,
    shift: u32,
    ladder: Ladder,
}

impl ClearanceTable {
    /// The table of `space`'s certified labels and `counts` (per pair `ia * nb + ib`, how
    /// many levels of `ladder` are proved; 0 for pairs not labelled free).
    ///
    /// # Errors
    /// [`TableError::BadInput`] when `counts` and the labels disagree in length, or as
    /// [`SharedQuadtree6d::build`].
    #[cfg(feature = "std")]
    pub fn build(
        space: &crate::cspace::LabelledSpace,
        counts: &[u8],
        ladder: Ladder,
        symmetry: crate::cspace::Symmetry,
    ) -> Result<ClearanceTable, TableError> {
        if counts.len() != space.labels.len() {
            return Err(TableError::BadInput {
                what: format!(
                    "{} clearance counts for {} labelled pairs",
                    counts.len(),
                    space.labels.len()
                ),
            });
        }
        let exact = SharedQuadtree6d::build(space, symmetry)?;
        let levels = exact.levels();
        let mut best = None;
        for shift in 0..=levels.saturating_sub(2) {
            let t = Self::build_at(space, counts, ladder, symmetry, exact.clone(), shift)?;
            let fits = t.memory_bytes() <= SIZE_BUDGET * exact.memory_bytes()
                && t.stored_bytes() <= SIZE_BUDGET * stored_bytes(&exact);
            best = Some(t);
            if fits {
                break;
            }
        }
        best.ok_or_else(|| TableError::BadInput {
            what: format!("k = {} is too small for a clearance table", 1u32 << levels),
        })
    }

    /// As [`build`](Self::build) with the level tree coarsened by `shift` and `exact` the
    /// boolean tree of `space`.
    #[cfg(feature = "std")]
    fn build_at(
        space: &crate::cspace::LabelledSpace,
        counts: &[u8],
        ladder: Ladder,
        symmetry: crate::cspace::Symmetry,
        exact: SharedQuadtree6d,
        shift: u32,
    ) -> Result<ClearanceTable, TableError> {
        let n = ladder.len();
        let (coarse, coarse_counts) = coarse::coarsen(space, counts, shift, n as u8);
        let word = |pair: usize| word_of(usize::from(coarse_counts[pair]), n);
        let level_tree = SharedQuadtree6d::build_words(&coarse, &word, symmetry)?;
        Ok(Self::assemble(exact, level_tree, shift, ladder))
    }

    /// The table of two validated trees, with its level grid when the table with it is at
    /// most [`SIZE_BUDGET`] times the exact tree in memory.
    fn assemble(
        exact: SharedQuadtree6d,
        level_tree: SharedQuadtree6d,
        shift: u32,
        ladder: Ladder,
    ) -> ClearanceTable {
        let floor = usize::from(ladder.mm[0] == 0.0);
        let mut t = ClearanceTable { exact, level_tree, grid: None, floor, shift, ladder };
        let bits = t.levels() - shift;
        let budget = SIZE_BUDGET.saturating_mul(t.exact.memory_bytes());
        if LevelGrid::bytes_for(bits).is_some_and(|g| t.memory_bytes().saturating_add(g) <= budget)
        {
            t.grid = Some(LevelGrid::of(&t.level_tree, bits, t.ladder.len()));
        }
        t
    }

    /// The table with its level grid whatever its size, or without (tests compare both
    /// lookups).
    #[cfg(test)]
    fn with_grid(mut self, grid: bool) -> ClearanceTable {
        let bits = self.levels() - self.shift;
        self.grid = grid.then(|| LevelGrid::of(&self.level_tree, bits, self.ladder.len()));
        self
    }

    /// A table from stored parts: both trees as [`SharedQuadtree6d::from_parts`] validates
    /// them (the level tree with one level of words below its coarse grid), and every leaf of
    /// the level tree a thermometer word of a level strictly between none and the top.
    ///
    /// # Errors
    /// [`TableError::Corrupt`] naming the first bad field.
    pub fn from_parts(
        levels: u32,
        symmetric: bool,
        ladder_mm: &[f64],
        shift: u32,
        exact: TreeParts,
        level_tree: TreeParts,
    ) -> Result<ClearanceTable, TableError> {
        let ladder =
            Ladder::new(ladder_mm).map_err(|e| corrupt(format!("clearance ladder: {e}")))?;
        let n = ladder.len();
        if levels < 2 || shift > levels - 2 {
            return Err(corrupt(format!(
                "clearance level tree shift = {shift} with levels = {levels}: need levels - shift >= 2"
            )));
        }
        let bad_leaf =
            |&w: &u64| !(1..n).contains(&count_of(w, n)) || word_of(count_of(w, n), n) != w;
        if let Some((i, w)) = level_tree.leaves.iter().enumerate().find(|(_, w)| bad_leaf(w)) {
            return Err(corrupt(format!(
                "clearance leaf {i} = {w:#018x} is not the word of a level below the top"
            )));
        }
        let exact = exact.tree(levels, 0, symmetric)?;
        let level_tree = level_tree.tree(levels - shift, 1, symmetric)?;
        Ok(Self::assemble(exact, level_tree, shift, ladder))
    }

    /// How many levels are proved for the 6-D grid cell `cell` (indices at `k`; 0 for an
    /// index beyond): the exact tree's descent and one read of the level grid, independent
    /// of each other (without a grid, the level tree's descent). Never allocates, never
    /// panics on a validated table.
    #[inline]
    pub fn level_count(&self, cell: [u16; 6]) -> usize {
        let count = match &self.grid {
            Some(grid) => grid.count(cell, self.shift),
            None => count_of(
                self.level_tree.query_word(cell.map(|v| v >> self.shift)),
                self.ladder.len(),
            ),
        };
        let collision = self.exact.query(cell);
        // A free cell has level 0 proved when the ladder starts at 0 mm.
        if collision {
            0
        } else {
            count.max(self.floor)
        }
    }

    /// The certified lower bound on the clearance over the grid cell `cell` (mm), or `None`
    /// when no level is proved (the cell may collide).
    #[inline]
    pub fn bound_mm(&self, cell: [u16; 6]) -> Option<f64> {
        self.level_count(cell).checked_sub(1).map(|i| self.ladder.mm[i])
    }

    /// Whether the grid cell is stored as collision (the exact tree's answer: the boolean
    /// certified table's).
    #[inline]
    pub fn query(&self, cell: [u16; 6]) -> bool {
        self.exact.query(cell)
    }

    /// The ladder.
    pub fn ladder(&self) -> &Ladder {
        &self.ladder
    }

    /// The level tree's coarsening: `2^shift` grid cells per axis and robot share a level.
    pub fn shift(&self) -> u32 {
        self.shift
    }

    /// Quadtree levels of the grid (`k = 2^levels`).
    pub fn levels(&self) -> u32 {
        self.exact.levels()
    }

    /// Whether only A's upper half is stored.
    pub fn symmetric(&self) -> bool {
        self.exact.symmetric()
    }

    /// The exact (boolean) tree.
    pub fn exact_tree(&self) -> &SharedQuadtree6d {
        &self.exact
    }

    /// The level tree.
    pub fn level_tree(&self) -> &SharedQuadtree6d {
        &self.level_tree
    }

    /// The stored arrays of both trees, exact then level (as
    /// [`from_parts`](Self::from_parts) takes them).
    pub fn parts(&self) -> (TreeParts, TreeParts) {
        (TreeParts::of(&self.exact), TreeParts::of(&self.level_tree))
    }

    /// Whether the lookup reads the level grid (one descent and one read) rather than the
    /// level tree (two descents).
    pub fn has_level_grid(&self) -> bool {
        self.grid.is_some()
    }

    /// The address and byte length of the second array a lookup reads (the first is the exact
    /// tree's [`SharedQuadtree6d::memory_region`]): the level grid, else the level tree's,
    /// for benchmarks that flush it from the caches.
    pub fn level_region(&self) -> (usize, usize) {
        match &self.grid {
            Some(g) => (g.words.as_ptr() as usize, core::mem::size_of_val(g.words.as_slice())),
            None => self.level_tree.memory_region(),
        }
    }

    /// Bytes this table occupies in memory: both trees (the level tree is kept to write the
    /// file) and the level grid.
    pub fn memory_bytes(&self) -> usize {
        core::mem::size_of::<Self>() - 2 * core::mem::size_of::<SharedQuadtree6d>()
            + self.exact.memory_bytes()
            + self.level_tree.memory_bytes()
            + self.grid.as_ref().map_or(0, |g| core::mem::size_of_val(g.words.as_slice()))
    }

    /// Bytes the file holds for this table: both trees and the ladder words ahead of them
    /// (`format::to_bytes`), without the header every table file has.
    pub fn stored_bytes(&self) -> usize {
        8 * (self.ladder.len() + 5) + packed_bytes(&self.exact) + packed_bytes(&self.level_tree)
    }

    /// Grid cells per number of proved levels (index 0: no level), over every `k^6` grid
    /// cell (a "don't care" cell counts as what is stored there). Queries every cell: for
    /// reports at small `k`; allocates.
    pub fn cells_per_level(&self) -> Vec<u64> {
        let k = 1u32 << self.levels();
        let mut out = vec![0u64; self.ladder.len() + 1];
        let mut c = [0u16; 6];
        for i in 0..(u64::from(k)).pow(6) {
            for (j, v) in c.iter_mut().enumerate() {
                *v = (i >> (self.levels() as usize * j) & u64::from(k - 1)) as u16;
            }
            out[self.level_count(c)] += 1;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cspace::{Label, Symmetry};
    use crate::table::synthetic::{space, Pattern};
    use crate::table::SharedQuadtree6d;

    #[test]
    fn ladders_are_checked() {
        assert!(Ladder::new(&Ladder::DEFAULT_MM).is_ok());
        assert!(Ladder::new(&[]).is_err());
        assert!(Ladder::new(&[0.0, 5.0, 5.0]).is_err());
        assert!(Ladder::new(&[-1.0]).is_err());
        assert!(Ladder::new(&[f64::NAN]).is_err());
        assert!(Ladder::new(&[0.0; MAX_RUNGS + 1]).is_err());
        assert_eq!(Ladder::new(&[1.0, 2.5]).unwrap().mm(), &[1.0, 2.5]);
    }

    #[test]
    fn words_give_their_counts_back() {
        for n in 1..=MAX_RUNGS {
            for m in 0..=n {
                assert_eq!(count_of(word_of(m, n), n), m, "n {n} m {m}");
            }
            // The OR of two words is the word of the smaller count (the mirror merge).
            for (a, b) in [(0, n), (1, n), (n / 2, n - 1)] {
                assert_eq!(word_of(a, n) | word_of(b, n), word_of(a.min(b), n));
            }
        }
    }

    /// Seeded counts: 0 on pairs not free, on free ones 1 to `n` from a hash of the pair.
    fn counts_for(space: &crate::cspace::LabelledSpace, n: usize) -> Vec<u8> {
        let hash = |i: usize| ((i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 58) as usize;
        let count =
            |(i, l): (usize, Label)| if l == Label::Free { (1 + hash(i) % n) as u8 } else { 0 };
        space.labels.iter().enumerate().map(count).collect()
    }

    /// Every sampled pair: no level exactly where the boolean shared table says collision;
    /// otherwise a level proved for the pair (and its mirror), the smaller of the two at
    /// `shift = 0`; the parts round trip.
    #[test]
    fn answers_every_pair_with_a_stored_level_it_has() {
        let ladder = Ladder::default_ladder();
        for (pattern, levels, symmetric) in [
            (Pattern::Blobs, 2, false),
            (Pattern::Noise { p: 0.3, seed: 1 }, 3, false),
            (Pattern::Blobs, 4, true),
            (Pattern::AsymmetricNoise { p: 0.2, seed: 5 }, 3, true),
        ] {
            let s = space(levels, pattern);
            let counts = counts_for(&s, ladder.len());
            let symmetry = Symmetry::from_flag(symmetric);
            let boolean = SharedQuadtree6d::build(&s, symmetry).unwrap();
            let view = crate::table::space::SpaceView::new(&s, symmetric).unwrap();
            let nb = s.grid_b.cells.len();
            for shift in 0..=levels - 2 {
                let t =
                    ClearanceTable::build_at(&s, &counts, ladder, symmetry, boolean.clone(), shift)
                        .unwrap();
                let (gridded, treed) = (t.clone().with_grid(true), t.clone().with_grid(false));
                assert!(gridded.has_level_grid() && !treed.has_level_grid());
                let mut seen = vec![0usize; ladder.len() + 1];
                for (ia, ca) in s.grid_a.cells.iter().enumerate() {
                    for (ib, cb) in s.grid_b.cells.iter().enumerate() {
                        if s.labels[ia * nb + ib] == Label::Unreachable {
                            continue;
                        }
                        let cell = [ca[0], ca[1], ca[2], cb[0], cb[1], cb[2]];
                        let mut own = usize::from(counts[ia * nb + ib]);
                        if let Some((ma, mb)) = view.mirror_pair(ia, ib) {
                            if s.labels[ma * nb + mb] != Label::Unreachable {
                                own = own.min(usize::from(counts[ma * nb + mb]));
                            }
                        }
                        let got = t.level_count(cell);
                        // The two-descent lookup, spelled out: the reference of both layouts.
                        let word = t.level_tree().query_word(cell.map(|v| v >> shift));
                        let by_tree = if boolean.query(cell) {
                            0
                        } else {
                            count_of(word, ladder.len()).max(1)
                        };
                        assert_eq!(
                            gridded.level_count(cell),
                            by_tree,
                            "{pattern:?} {shift} {cell:?}: grid"
                        );
                        assert_eq!(
                            treed.level_count(cell),
                            by_tree,
                            "{pattern:?} {shift} {cell:?}: tree"
                        );
                        assert_eq!(got, by_tree, "{pattern:?} {shift} {cell:?}");
                        assert_eq!(got == 0, boolean.query(cell), "{pattern:?} {shift} {cell:?}");
                        assert!(got <= own, "{pattern:?} {shift} {cell:?}: {got} > {own}");
                        if shift == 0 {
                            assert_eq!(got, own, "{pattern:?} {cell:?}");
                        }
                        assert_eq!(t.bound_mm(cell), got.checked_sub(1).map(|i| ladder.mm()[i]));
                        seen[got] += 1;
                    }
                }
                // Coarse level trees may hold only the smallest level; the finest holds them all.
                let distinct = seen.iter().filter(|&&c| c > 0).count();
                assert!(
                    distinct >= if shift == 0 { 3 } else { 2 },
                    "{pattern:?} {shift}: levels seen {seen:?}"
                );
                let (e, l) = t.parts();
                let back = ClearanceTable::from_parts(levels, symmetric, ladder.mm(), shift, e, l)
                    .unwrap();
                assert_eq!(back, t);
                let k6 = (1u64 << levels).pow(6);
                assert_eq!(t.cells_per_level().iter().sum::<u64>(), k6);
            }
        }
    }

    /// The builder takes the finest shift whose table fits the size budget in memory and in
    /// the file; `stored_bytes` is what the file holds beyond its header and checksum.
    #[test]
    fn builds_take_the_finest_shift_that_fits_memory_and_file() {
        use crate::table::format::{to_bytes, Certification, Header};
        use crate::table::Table;
        let ladder = Ladder::default_ladder();
        // The file less its 192-byte header (no cell parameters) and 8-byte checksum.
        let sections = |t: Table, s: &crate::cspace::LabelledSpace| {
            let header = Header::for_space(
                s,
                0,
                crate::cspace::Workspace::THESIS,
                Certification::SweptBound,
            );
            to_bytes(&t, &header).len() - 192 - 8
        };
        for (pattern, levels, symmetric) in [
            (Pattern::Blobs, 4, true),
            (Pattern::Noise { p: 0.3, seed: 1 }, 4, false),
            (Pattern::Blobs, 3, false),
        ] {
            let s = space(levels, pattern);
            let counts = counts_for(&s, ladder.len());
            let symmetry = Symmetry::from_flag(symmetric);
            let exact = SharedQuadtree6d::build(&s, symmetry).unwrap();
            let fits = |t: &ClearanceTable| {
                t.memory_bytes() <= SIZE_BUDGET * exact.memory_bytes()
                    && t.stored_bytes() <= SIZE_BUDGET * stored_bytes(&exact)
            };
            let t = ClearanceTable::build(&s, &counts, ladder, symmetry).unwrap();
            assert_eq!(
                sections(Table::Clearance(alloc::boxed::Box::new(t.clone())), &s),
                t.stored_bytes()
            );
            assert_eq!(sections(Table::Shared(exact.clone()), &s), stored_bytes(&exact));
            assert!(
                fits(&t) || t.shift() == levels - 2,
                "{pattern:?}: shift {} does not fit",
                t.shift()
            );
            for finer in 0..t.shift() {
                let f =
                    ClearanceTable::build_at(&s, &counts, ladder, symmetry, exact.clone(), finer)
                        .unwrap();
                assert!(!fits(&f), "{pattern:?}: shift {finer} fits, finer than {}", t.shift());
            }
        }
    }

    #[test]
    fn leaves_that_are_not_level_words_are_refused() {
        let s = space(3, Pattern::Noise { p: 0.3, seed: 1 });
        let ladder = Ladder::default_ladder();
        let counts = counts_for(&s, ladder.len());
        let exact = SharedQuadtree6d::build(&s, Symmetry::Whole).unwrap();
        let t = ClearanceTable::build_at(&s, &counts, ladder, Symmetry::Whole, exact, 0).unwrap();
        let (e, l) = t.parts();
        assert!(!l.leaves.is_empty());
        for bad in [0u64, 0b1010, u64::MAX] {
            let mut l = l.clone();
            l.leaves[0] = bad;
            let r = ClearanceTable::from_parts(3, false, ladder.mm(), 0, e.clone(), l);
            assert!(matches!(r, Err(TableError::Corrupt { .. })), "{bad:#x}");
        }
        let r = ClearanceTable::from_parts(3, false, &[5.0, 1.0], 0, e.clone(), l.clone());
        assert!(matches!(r, Err(TableError::Corrupt { .. })));
        let r = ClearanceTable::from_parts(3, false, ladder.mm(), 2, e, l);
        assert!(matches!(r, Err(TableError::Corrupt { .. })), "shift beyond levels - 2");
    }
}
