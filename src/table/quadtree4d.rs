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

use super::code::{encode, MAX_LEVELS};
use super::error::{corrupt, TableError};
use super::space::fold;
#[cfg(feature = "std")]
use super::space::{check_grids, merge, reflections, SpaceView, NONE};
#[cfg(feature = "std")]
use crate::cspace::{Label, LabelledSpace, SubdividedLabels};
use alloc::{format, vec::Vec};
#[cfg(feature = "std")]
use rayon::prelude::*;
#[cfg(feature = "std")]
use std::collections::{BTreeMap, HashMap};

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

/// `Some(|S \ R|)` when `S` (collision bits, care mask) may join a group with representative
/// `R` and budgets `g_add`, `g_sub` (see the module doc).
#[cfg(feature = "std")]
fn try_join(s: &[u64], care: &[u64], rep: &[u64], g_add: u32, g_sub: u32) -> Option<u32> {
    let (mut add, mut sub) = (0u32, 0u32);
    for ((&s, &c), &r) in s.iter().zip(care).zip(rep) {
        add += (s & !r).count_ones();
        sub += (r & !s & c).count_ones();
        if (add > 0 && add >= g_add) || (sub > 0 && sub >= g_sub) {
            return None;
        }
    }
    Some(add)
}

/// Algorithm 8's first fit at `t = 0`. The representatives are fixed once made (see the module
/// doc), so the first group that `S` (care mask `C`) may join is the first `R` with
/// `R ∩ C = S`, found in one of two ways, with the same answer:
/// - *By tile.* On every square tile of the slice that `C` covers whole, such an `R` has
///   `S`'s bits. Every group's *mixed* tiles (some bits set, not all) are indexed by (side,
///   tile, bits), groups in increasing order, for 8 x 8 and 4 x 4 tiles. A slice with a mixed
///   tile that `C` covers whole checks only the groups of its rarest such tile's entry (8 x 8
///   tiles first), and makes a new group at once where one such tile has no entry.
/// - *Bit-sliced*, for any other slice: the representatives also stored transposed, 64 groups
///   to a block, so that bit `i` of block `j`'s word for slice bit `p` is set when group
///   `64 j + i` has bit `p`; blocks come in chunks of [`CHUNK_BLOCKS`], stored bit by bit (a
///   chunk's words of one slice bit are adjacent). A query ANDs, chunk by chunk, the words of
///   `S`'s bits and the complements of the words of `C \ S`'s bits into one word per block,
///   and stops a chunk when none of its groups is left: the first chunk with a group left
///   holds, at its lowest, the first group that fits.
#[cfg(feature = "std")]
struct ExactGroups {
    wps: usize,
    rows: usize,
    /// Bits per slice row.
    cols: usize,
    /// The representatives, `wps` words each.
    reps: Vec<u64>,
    /// (side, tile, its bits) of the representatives' mixed tiles -> groups, increasing.
    by_tile: HashMap<(u8, u32, u64), Vec<u32>>,
    /// The representatives, bit-sliced (see the type's doc).
    sliced: Vec<u64>,
}

/// The tile sides of [`ExactGroups`], tried in this order.
#[cfg(feature = "std")]
const TILE_SIDES: [usize; 2] = [8, 4];

/// Blocks of 64 groups per chunk of [`ExactGroups`]'s bit-sliced representatives (2 in the
/// unit tests, whose few hundred groups then span chunks).
#[cfg(feature = "std")]
const CHUNK_BLOCKS: usize = if cfg!(test) { 2 } else { 64 };

/// Positions of the set bits of `words` (bit `p % 64` of word `p / 64`), increasing.
#[cfg(feature = "std")]
fn set_bits(words: impl Iterator<Item = u64>) -> Vec<u32> {
    let mut out = Vec::new();
    for (i, mut w) in words.enumerate() {
        while w != 0 {
            out.push(64 * i as u32 + w.trailing_zeros());
            w &= w - 1;
        }
    }
    out
}

#[cfg(feature = "std")]
impl ExactGroups {
    /// Groups of slices of `rows` rows of `cols` bits (`wps` words).
    fn new(wps: usize, rows: usize, cols: usize) -> ExactGroups {
        ExactGroups { wps, rows, cols, reps: Vec::new(), by_tile: HashMap::new(), sliced: Vec::new() }
    }

    fn count(&self) -> usize {
        self.reps.len() / self.wps
    }

    /// The tiles of side `side` of `words`, each as (index, bits: row `r` of the tile at bit
    /// `side * r`), and the bits of a tile with all of them set.
    fn tiles<'w>(&self, words: &'w [u64], side: usize) -> (impl Iterator<Item = (u32, u64)> + 'w, u64) {
        let (cols, across) = (self.cols, self.cols / side);
        let mask = (1u64 << side) - 1;
        let tiles = (0..(self.rows / side) * across).map(move |t| {
            let (row, col) = (side * (t / across), side * (t % across));
            let bits = (0..side).fold(0, |out, r| {
                let bit = (row + r) * cols + col;
                out | (words[bit / 64] >> (bit % 64) & mask) << (side * r)
            });
            (t as u32, bits)
        });
        (tiles, u64::MAX >> (64 - side * side))
    }

    /// Over the mixed tiles of `s` that `care` covers whole, of the first side with one:
    /// `None` when there is none, `Some(None)` when one has no entry (no group fits), else
    /// the shortest entry.
    fn rarest_tile(&self, s: &[u64], care: &[u64]) -> Option<Option<&[u32]>> {
        for side in TILE_SIDES {
            let (tiles, full) = self.tiles(s, side);
            let (cares, _) = self.tiles(care, side);
            let mut best: Option<&[u32]> = None;
            for ((t, v), (_, c)) in tiles.zip(cares) {
                if v == 0 || v == full || c != full {
                    continue;
                }
                let Some(groups) = self.by_tile.get(&(side as u8, t, v)) else { return Some(None) };
                if best.is_none_or(|b| groups.len() < b.len()) {
                    best = Some(groups);
                }
            }
            if best.is_some() {
                return Some(best);
            }
        }
        None
    }

    /// Whether group `g`'s representative `R` has `R ∩ C = S`.
    fn fits(&self, g: u32, s: &[u64], care: &[u64]) -> bool {
        let rep = &self.reps[g as usize * self.wps..][..self.wps];
        rep.iter().zip(care).zip(s).all(|((&r, &c), &s)| r & c == s)
    }

    /// The first group that fits, bit-sliced (see the type's doc).
    fn scan(&self, s: &[u64], care: &[u64]) -> Option<u32> {
        let ones = set_bits(s.iter().copied());
        let zeros = set_bits(care.iter().zip(s).map(|(&c, &s)| c & !s));
        // The bits to test, alternately from `S` and from `C \ S` while both last, each with
        // the word to XOR a block's word with (all ones for a bit that must be clear).
        let mut probe = Vec::with_capacity(ones.len() + zeros.len());
        for i in 0..ones.len().max(zeros.len()) {
            probe.extend(ones.get(i).map(|&p| (p, 0u64)));
            probe.extend(zeros.get(i).map(|&p| (p, !0u64)));
        }
        let per_chunk = 64 * CHUNK_BLOCKS;
        let mut left = [0u64; CHUNK_BLOCKS];
        for (c, words) in self.sliced.chunks_exact(64 * self.wps * CHUNK_BLOCKS).enumerate() {
            // Groups `..n` of this chunk exist.
            let n = (self.count() - per_chunk * c).min(per_chunk);
            for (j, l) in left.iter_mut().enumerate() {
                let m = n.saturating_sub(64 * j).min(64);
                *l = if m == 64 { !0 } else { (1u64 << m) - 1 };
            }
            for &(p, flip) in &probe {
                let mut any = 0;
                for (l, &w) in left.iter_mut().zip(&words[p as usize * CHUNK_BLOCKS..][..CHUNK_BLOCKS]) {
                    *l &= w ^ flip;
                    any |= *l;
                }
                if any == 0 {
                    break;
                }
            }
            if let Some(j) = left.iter().position(|&l| l != 0) {
                return Some((per_chunk * c + 64 * j) as u32 + left[j].trailing_zeros());
            }
        }
        None
    }

    /// The first group whose representative `R` has `R ∩ C = S`, or a new group made of `S`.
    fn group(&mut self, s: &[u64], care: &[u64]) -> u32 {
        debug_assert!(s.iter().zip(care).all(|(&s, &c)| s & !c == 0), "a collision bit outside the care mask");
        let found = match self.rarest_tile(s, care) {
            Some(None) => None,
            Some(Some(groups)) => groups.iter().copied().find(|&g| self.fits(g, s, care)),
            None => self.scan(s, care),
        };
        found.unwrap_or_else(|| self.push(s))
    }

    /// A new group made of `s`.
    fn push(&mut self, s: &[u64]) -> u32 {
        let g = self.count();
        let (per_chunk, chunk_words) = (64 * CHUNK_BLOCKS, 64 * self.wps * CHUNK_BLOCKS);
        if g % per_chunk == 0 {
            self.sliced.resize(self.sliced.len() + chunk_words, 0);
        }
        let chunk = &mut self.sliced[g / per_chunk * chunk_words..];
        for p in set_bits(s.iter().copied()) {
            chunk[p as usize * CHUNK_BLOCKS + g % per_chunk / 64] |= 1 << (g % 64);
        }
        self.reps.extend_from_slice(s);
        for side in TILE_SIDES {
            let (tiles, full) = self.tiles(s, side);
            for (t, v) in tiles.filter(|&(_, v)| v != 0 && v != full) {
                self.by_tile.entry((side as u8, t, v)).or_default().push(g as u32);
            }
        }
        g as u32
    }
}

/// Samples of one robot grouped by its two quadtree coordinates `(ix, second)`.
#[cfg(feature = "std")]
fn ranges(cells: &[[u16; 3]], keep: impl Fn(usize) -> bool, second: usize) -> BTreeMap<(u16, u16), Vec<usize>> {
    let mut m: BTreeMap<(u16, u16), Vec<usize>> = BTreeMap::new();
    for (i, c) in cells.iter().enumerate().filter(|(i, _)| keep(*i)) {
        m.entry((c[0], c[second])).or_default().push(i);
    }
    m
}

/// Algorithm 8's grouping, fed the ranges' slices in the thesis's order (x, x', then the
/// second dimension of each).
#[cfg(feature = "std")]
struct Grouping {
    tree: LinearQuadtree4d,
    wps: usize,
    g_add: Vec<u32>,
    exact: Option<ExactGroups>,
    nodes: Vec<(u64, u32)>,
}

#[cfg(feature = "std")]
impl Grouping {
    fn new(levels: u32, symmetric: bool, axes: SliceAxes, t: u32) -> Grouping {
        let (a0, wps) = shape(levels, symmetric, axes);
        let tree = LinearQuadtree4d { levels, symmetric, axes, t, codes: vec![], slice_of: vec![], slices: vec![] };
        let k = 1usize << levels;
        let exact = (t == 0).then(|| ExactGroups::new(wps, k - a0 as usize, k));
        Grouping { tree, wps, g_add: Vec::new(), exact, nodes: Vec::new() }
    }

    /// Range `[x, second, x', second']` with slice `s` (collision bits) and `care`.
    fn add(&mut self, range: [u16; 4], s: &[u64], care: &[u64]) {
        let group = match self.exact.as_mut() {
            Some(exact) => exact.group(s, care),
            None => self.tree.group(s, care, &mut self.g_add, self.wps),
        };
        self.nodes.push((encode(range, 4), group));
    }

    fn finish(mut self) -> LinearQuadtree4d {
        if let Some(exact) = self.exact {
            self.tree.slices = exact.reps;
        }
        self.nodes.sort_unstable_by_key(|n| n.0);
        (self.tree.codes, self.tree.slice_of) = self.nodes.into_iter().unzip();
        self.tree
    }
}

/// Puts `label` at slice bit `bit`; whether it is a collision.
#[cfg(feature = "std")]
fn put(s: &mut [u64], care: &mut [u64], bit: usize, label: Label) -> bool {
    if label != Label::Unreachable {
        care[bit / 64] |= 1 << (bit % 64);
    }
    let collision = label == Label::Collision;
    if collision {
        s[bit / 64] |= 1 << (bit % 64);
    }
    collision
}

impl LinearQuadtree4d {
    /// Builds the table of `space` with threshold `t` (thesis Algorithm 8); with
    /// `symmetric`, only A's upper half `iy >= k/2` is stored.
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ or the label count is wrong.
    #[cfg(feature = "std")]
    pub fn build(
        space: &LabelledSpace,
        symmetric: bool,
        axes: SliceAxes,
        t: u32,
    ) -> Result<LinearQuadtree4d, TableError> {
        let view = SpaceView::new(space, symmetric)?;
        let (k, levels) = (view.k, view.levels);
        let (second, ignored) = axes.dims();
        let (a0, wps) = shape(levels, symmetric, axes);
        let (ca, cb) = (&space.grid_a.cells, &space.grid_b.cells);
        let ra = ranges(ca, |i| view.stored(i), second);
        let rb = ranges(cb, |_| true, second);
        let mut grouping = Grouping::new(levels, symmetric, axes, t);
        let (mut s, mut care) = (vec![0u64; wps], vec![0u64; wps]);
        // Thesis order x, x', z, z': the A and B maps are sorted by (ix, second).
        let xs_a: Vec<u16> = ra.keys().map(|k| k.0).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        let xs_b: Vec<u16> = rb.keys().map(|k| k.0).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        for &xa in &xs_a {
            for &xb in &xs_b {
                for ((_, za), ias) in ra.range((xa, 0)..=(xa, u16::MAX)) {
                    for ((_, zb), ibs) in rb.range((xb, 0)..=(xb, u16::MAX)) {
                        s.fill(0);
                        care.fill(0);
                        let mut any = false;
                        for &ia in ias {
                            let row = (u32::from(ca[ia][ignored]) - a0) * k;
                            for &ib in ibs {
                                let bit = (row + u32::from(cb[ib][ignored])) as usize;
                                any |= put(&mut s, &mut care, bit, view.label(ia, ib));
                            }
                        }
                        if any {
                            grouping.add([xa, *za, xb, *zb], &s, &care);
                        }
                    }
                }
            }
        }
        Ok(grouping.finish())
    }

    /// The table [`build`](Self::build) makes from [`SubdividedLabels::to_dense`]
    /// (the same table, tested), without those dense labels ([`subdivided_slices`]).
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ.
    #[cfg(feature = "std")]
    pub fn build_subdivided(
        labels: &SubdividedLabels,
        symmetric: bool,
        axes: SliceAxes,
        t: u32,
    ) -> Result<LinearQuadtree4d, TableError> {
        let mut grouping = Grouping::new(labels.grid_a.levels, symmetric, axes, t);
        subdivided_slices(labels, symmetric, axes, |range, s, care| grouping.add(range, s, care))?;
        Ok(grouping.finish())
    }

    /// The group `s` joins (its representative updated), or a new one (Algorithm 8 l. 7-19).
    #[cfg(feature = "std")]
    fn group(&mut self, s: &[u64], care: &[u64], g_add: &mut Vec<u32>, wps: usize) -> u32 {
        for (g, rep) in self.slices.chunks_exact_mut(wps).enumerate() {
            if let Some(add) = try_join(s, care, rep, g_add[g], self.t) {
                rep.iter_mut().zip(s).for_each(|(r, &s)| *r |= s);
                g_add[g] -= add;
                return g as u32;
            }
        }
        self.slices.extend_from_slice(s);
        g_add.push(self.t);
        (g_add.len() - 1) as u32
    }

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
            return Err(corrupt(format!("codes[{i}] = {:#x} has bits above {levels} 4-bit levels", codes[i])));
        }
        if let Some(i) = codes.windows(2).position(|w| w[0] >= w[1]) {
            return Err(corrupt(format!("codes[{}] is not greater than codes[{i}]: codes are not sorted", i + 1)));
        }
        let (_, wps) = shape(levels, symmetric, axes);
        if slices.len() % wps != 0 {
            return Err(corrupt(format!("slices has {} words, not a multiple of {wps} per slice", slices.len())));
        }
        let count = slices.len() / wps;
        if slice_of.len() != codes.len() {
            return Err(corrupt(format!("slice_of has {} entries for {} codes", slice_of.len(), codes.len())));
        }
        if let Some(i) = slice_of.iter().position(|&s| s as usize >= count) {
            return Err(corrupt(format!("slice_of[{i}] = {} is not below the slice count {count}", slice_of[i])));
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
        let Ok(i) = self.codes.binary_search(&encode([c[0], c[second], c[3], c[3 + second]], 4)) else {
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
        core::mem::size_of::<Self>() + 8 * self.codes.len() + 4 * self.slice_of.len() + 8 * self.slices.len()
    }

    /// The thesis's figure, `8 m + s b^2 / 8 + 8 b + 76` (Observation 3.2.3), for slices of
    /// `b x b` squares (`b` = sampled coordinates along an ignored axis, 29 for the thesis's
    /// yy' slices at k = 32).
    pub fn thesis_bytes(&self, b: usize) -> usize {
        8 * self.codes.len() + self.slice_count() * b * b / 8 + 8 * b + 76
    }
}

/// The slices of the table of the sub-cell labels at `2k` ([`SubdividedLabels`]), each with
/// its range and care mask, in the thesis's order, as [`LinearQuadtree4d::build`] makes them
/// from the dense labels: only the ranges inside a coarse range that holds a collision,
/// itself or by its mirror, can hold one, so only they are visited, their pairs' labels read
/// from `labels` and their slices made in parallel, a block of ranges at a time.
///
/// # Errors
/// [`TableError::BadInput`] when the grids differ.
#[cfg(feature = "std")]
pub fn subdivided_slices(
    labels: &SubdividedLabels,
    symmetric: bool,
    axes: SliceAxes,
    mut visit: impl FnMut([u16; 4], &[u64], &[u64]),
) -> Result<(), TableError> {
    let (ga, gb) = (&labels.grid_a, &labels.grid_b);
    check_grids(ga, gb)?;
    let (k, levels) = (ga.k, ga.levels);
    let (second, ignored) = axes.dims();
    let (a0, wps) = shape(levels, symmetric, axes);
    let ra = ranges(&ga.cells, |i| !symmetric || u32::from(ga.cells[i][1]) >= k / 2, second);
    let rb = ranges(&gb.cells, |_| true, second);
    let (refl_a, refl_b) = if symmetric { (reflections(ga), reflections(gb)) } else { (vec![], vec![]) };
    let coarse = labels.coarse();
    let (ca0, cb0, k0) = (&coarse.grid_a.cells, &coarse.grid_b.cells, coarse.grid_a.k as u16);
    let nb0 = cb0.len().max(1);
    let mut coarse_ranges: Vec<[u16; 4]> = coarse
        .labels
        .par_chunks(nb0)
        .enumerate()
        .flat_map_iter(|(pa, row)| {
            let (a, mut out) = (ca0[pa], Vec::new());
            for (pb, _) in row.iter().enumerate().filter(|(_, &l)| l == Label::Collision) {
                let b = cb0[pb];
                out.push([a[0], a[second], b[0], b[second]]);
                if symmetric && second == 1 {
                    out.push([a[0], k0 - 1 - a[1], b[0], k0 - 1 - b[1]]);
                }
            }
            out.sort_unstable();
            out.dedup();
            out
        })
        .collect();
    coarse_ranges.par_sort_unstable();
    coarse_ranges.dedup();
    let mut fine: Vec<[u16; 4]> = coarse_ranges
        .iter()
        .flat_map(|c| (0..16u16).map(move |o| core::array::from_fn(|d| 2 * c[d] + (o >> d & 1))))
        .filter(|f: &[u16; 4]| ra.contains_key(&(f[0], f[1])) && rb.contains_key(&(f[2], f[3])))
        .collect();
    // The thesis order (x, x', then the second dimension of each).
    fine.par_sort_unstable_by_key(|f| (f[0], f[2], f[1], f[3]));
    let slice = |f: &[u16; 4]| -> Option<(Vec<u64>, Vec<u64>)> {
        let (ias, ibs) = (&ra[&(f[0], f[1])], &rb[&(f[2], f[3])]);
        let own_b: Vec<u32> = ibs.iter().map(|&ib| ib as u32).collect();
        let mirror_b: Vec<u32> = if symmetric { ibs.iter().map(|&ib| refl_b[ib]).collect() } else { vec![] };
        let (mut own, mut mirror) = (vec![Label::Unreachable; ibs.len()], vec![Label::Unreachable; ibs.len()]);
        let (mut s, mut care, mut any) = (vec![0u64; wps], vec![0u64; wps], false);
        for &ia in ias {
            labels.row(Some(ia), &own_b, &mut own);
            if symmetric {
                let m = refl_a[ia];
                labels.row((m != NONE).then_some(m as usize), &mirror_b, &mut mirror);
            }
            let row = (u32::from(ga.cells[ia][ignored]) - a0) * k;
            for (n, &ib) in ibs.iter().enumerate() {
                let bit = (row + u32::from(gb.cells[ib][ignored])) as usize;
                // A missing mirror reads "don't care", which `merge` leaves as `own`.
                any |= put(&mut s, &mut care, bit, merge(own[n], mirror[n]));
            }
        }
        any.then_some((s, care))
    };
    for block in fine.chunks(4096) {
        let slices: Vec<_> = block.par_iter().map(slice).collect();
        for (f, s) in block.iter().zip(slices) {
            if let Some((s, care)) = s {
                visit(*f, &s, &care);
            }
        }
    }
    Ok(())
}

/// A lower bound on the size of every 4-D table of a stream of slices at `t = 0`, for when
/// the grouping itself would take hours (`6D-shared/sub`'s baseline at `k = 64`: millions of
/// slices of 8,192 bits).
///
/// At `t = 0` every slice of a group agrees with its representative on the slice's care bits
/// (module doc), so two slices of one group agree on every bit both care for. So for any
/// window `W` of slice bits, slices that care for all of `W` and differ on it are in
/// different groups: the number of their distinct patterns on `W` is at most the number of
/// groups. The bound is the largest such number over square windows of sides from a
/// sixteenth to all of the slice's rows (4 to 64), each side's windows overlapping by half
/// (patterns are counted by a 64-bit hash: a collision only lowers the count).
#[cfg(feature = "std")]
pub struct SliceBound {
    k: usize,
    wps: usize,
    /// `(first row, first column, side)` of each window, with the hashes of its patterns.
    windows: Vec<((usize, usize, usize), std::collections::HashSet<u64>)>,
    /// Slices seen (each is one code of the table).
    pub codes: usize,
}

#[cfg(feature = "std")]
impl SliceBound {
    /// For the slices of a table with these parameters.
    pub fn new(levels: u32, symmetric: bool, axes: SliceAxes) -> SliceBound {
        let (a0, wps) = shape(levels, symmetric, axes);
        let k = 1usize << levels;
        let rows = k - a0 as usize;
        let mut windows = Vec::new();
        for side in [rows / 16, rows / 8, rows / 4, rows / 2, rows].into_iter().filter(|w| (4..=64).contains(w)) {
            for r0 in (0..=rows - side).step_by(side / 2) {
                for c0 in (0..=k - side).step_by(side / 2) {
                    windows.push(((r0, c0, side), Default::default()));
                }
            }
        }
        SliceBound { k, wps, windows, codes: 0 }
    }

    /// One slice: its collision bits `s` and care mask `care`.
    pub fn add(&mut self, s: &[u64], care: &[u64]) {
        self.codes += 1;
        let k = self.k;
        for ((r0, c0, side), seen) in &mut self.windows {
            let full = if *side == 64 { !0 } else { (1u64 << *side) - 1 };
            let rows = *r0..*r0 + *side;
            if rows.clone().all(|r| window_bits(care, r * k + *c0, *side) == full) {
                let h = rows.fold(0u64, |h, r| {
                    (h.rotate_left(5) ^ window_bits(s, r * k + *c0, *side)).wrapping_mul(0x517c_c1b7_2722_0a95)
                });
                seen.insert(h);
            }
        }
    }

    /// At least this many groups: `(groups, (first row, first column, side) of its window)`.
    pub fn groups_at_least(&self) -> (usize, (usize, usize, usize)) {
        self.windows.iter().map(|(w, seen)| (seen.len(), *w)).max().unwrap_or((0, (0, 0, 0)))
    }

    /// At least this many bytes in memory ([`LinearQuadtree4d::memory_bytes`]): the codes
    /// and slice indices, and the groups' slices.
    pub fn bytes_at_least(&self) -> usize {
        core::mem::size_of::<LinearQuadtree4d>() + 12 * self.codes + 8 * self.wps * self.groups_at_least().0
    }
}

/// Bits `start .. start + len` of `words` (`len <= 64`), the first in bit 0.
#[cfg(feature = "std")]
fn window_bits(words: &[u64], start: usize, len: usize) -> u64 {
    let (w, o) = (start / 64, start % 64);
    let mut v = words[w] >> o;
    if o > 0 && o + len > 64 {
        v |= words[w + 1] << (64 - o);
    }
    if len == 64 {
        v
    } else {
        v & ((1u64 << len) - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn join_rule_follows_algorithm_8() {
        let rep = [0b0111u64];
        let all = [!0u64];
        assert_eq!(try_join(&[0b0111], &all, &rep, 0, 0), Some(0), "exact match joins at t = 0");
        assert_eq!(try_join(&[0b1111], &all, &rep, 0, 0), None, "one bit more: no match at t = 0");
        assert_eq!(try_join(&[0b1111], &all, &rep, 1, 1), None, "|add| = 1 is not < 1");
        assert_eq!(try_join(&[0b1111], &all, &rep, 2, 2), Some(1));
        assert_eq!(try_join(&[0b0011], &all, &rep, 2, 1), None, "|sub| = 1 is not < 1");
        assert_eq!(try_join(&[0b0011], &[0b1011], &rep, 2, 1), Some(0), "a don't-care bit is not counted");
    }

    /// Slices made from a few patterns, each seen through one of a few care masks (some with
    /// a flipped bit), 16 x 16 bits: both searches of [`ExactGroups`] find the scan's group.
    #[test]
    fn exact_groups_are_those_of_the_first_fit_scan() {
        let mut rng = crate::geometry::TestRng(0x9e37_79b9_7f4a_7c15);
        let mut next = || {
            rng.unit();
            rng.0
        };
        let wps = 4;
        let patterns: Vec<Vec<u64>> = (0..200).map(|_| (0..wps).map(|_| next()).collect()).collect();
        let mut chain = vec![vec![!0u64; wps]];
        for _ in 0..3 {
            let wider = chain.last().unwrap().clone();
            chain.push(wider.iter().map(|&m| m & (next() | next())).collect());
        }
        let mut scan = LinearQuadtree4d {
            levels: 1,
            symmetric: false,
            axes: SliceAxes::YY,
            t: 0,
            codes: vec![],
            slice_of: vec![],
            slices: vec![],
        };
        let (mut g_add, mut exact, mut joined) = (Vec::new(), ExactGroups::new(wps, 16, 16), 0);
        let (mut by_tile, mut no_entry) = (0, 0);
        for i in 0..5000 {
            let pattern = &patterns[(next() % 200) as usize];
            // One of four nested masks per half (two tiles): a slice joins a group made through
            // a wider one.
            let (m0, m1) = ((next() % 4) as usize, (next() % 4) as usize);
            let care: Vec<u64> = (0..wps).map(|w| chain[if w < 2 { m0 } else { m1 }][w]).collect();
            let mut s: Vec<u64> = pattern.iter().zip(&care).map(|(p, c)| p & c).collect();
            if i % 7 == 0 {
                let bit = next() % (64 * wps as u64);
                s[bit as usize / 64] ^= 1 << (bit % 64);
                s[bit as usize / 64] &= care[bit as usize / 64];
            }
            let before = scan.slices.len() / wps;
            let want = scan.group(&s, &care, &mut g_add, wps);
            let old = ((want as usize) < before).then_some(want);
            joined += usize::from(old.is_some());
            match exact.rarest_tile(&s, &care) {
                Some(Some(groups)) => {
                    by_tile += 1;
                    assert_eq!(groups.iter().copied().find(|&g| exact.fits(g, &s, &care)), old, "slice {i}");
                }
                Some(None) => {
                    no_entry += 1;
                    assert_eq!(old, None, "slice {i}: no entry, but group {old:?} fits");
                }
                None => {}
            }
            assert_eq!(exact.scan(&s, &care), old, "slice {i}: bit-sliced");
            assert_eq!(exact.group(&s, &care), want, "slice {i}");
        }
        let groups = exact.count();
        assert!(groups > 128 && joined > 2000, "{groups} groups, {joined} joins");
        assert!(by_tile > 500 && no_entry > 50, "{by_tile} by tile, {no_entry} with no entry");
    }

    /// The builder without dense labels makes the table the dense builder makes from the
    /// sub-cell labels: the same ranges, slices and groups (so the same order), on T1 and T2
    /// (symmetric) and T3 (not), for both slice axes, exact and lossy; and [`SliceBound`]
    /// stays below it.
    #[test]
    fn subdivided_build_is_the_dense_build_of_the_sub_cell_labels() {
        use crate::cell::reference::reference_cell;
        use crate::cspace::symmetry::reflection_y;
        use crate::cspace::{label_space_subdivided, SubdividedLabels, Workspace};
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let mut certified = label_space_subdivided(&cell, 16, &Workspace::THESIS, false).unwrap();
            // Every fifth pair's sub-cells all collisions: labels no longer mirror-symmetric,
            // so the symmetric tables must merge each pair with its mirror as the dense one does.
            let sub = certified.sub.as_mut().unwrap();
            sub.collision.iter_mut().zip(&sub.care).step_by(5).for_each(|(c, &care)| *c = care);
            let sparse = SubdividedLabels::new(&cell, &Workspace::THESIS, &certified).unwrap();
            let dense = sparse.to_dense();
            let symmetric = reflection_y(&cell);
            for axes in [SliceAxes::YY, SliceAxes::ZZ] {
                for t in [0, 40] {
                    let want = LinearQuadtree4d::build(&dense, symmetric, axes, t).unwrap();
                    let got = LinearQuadtree4d::build_subdivided(&sparse, symmetric, axes, t).unwrap();
                    assert!(want.codes.len() > 100 && want.slice_count() > 10, "{name} {axes:?} t={t}: too small");
                    assert!(got == want, "{name} {axes:?} t={t}: the tables differ");
                    if t == 0 {
                        // The lower bound is not above the table it bounds, and not trivial.
                        let mut bound = SliceBound::new(sparse.grid_a.levels, symmetric, axes);
                        subdivided_slices(&sparse, symmetric, axes, |_, s, care| bound.add(s, care)).unwrap();
                        let (groups, _) = bound.groups_at_least();
                        assert_eq!(bound.codes, got.codes.len(), "{name} {axes:?}");
                        assert!(groups > 10 && groups <= got.slice_count(), "{name} {axes:?}: {groups} groups");
                        assert!(bound.bytes_at_least() <= got.memory_bytes(), "{name} {axes:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn from_parts_rejects_bad_slice_indices() {
        let (_, wps) = shape(2, false, SliceAxes::YY);
        let ok = LinearQuadtree4d::from_parts(2, false, SliceAxes::YY, 0, vec![3], vec![0], vec![0; wps]);
        assert!(ok.is_ok());
        let bad = LinearQuadtree4d::from_parts(2, false, SliceAxes::YY, 0, vec![3], vec![1], vec![0; wps]);
        assert!(bad.is_err(), "slice index out of range");
        let bad = LinearQuadtree4d::from_parts(2, false, SliceAxes::YY, 0, vec![3, 3], vec![0, 0], vec![0; wps]);
        assert!(bad.is_err(), "duplicate code");
    }
}
