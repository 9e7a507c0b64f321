//! Algorithm 8's grouping of the 4-D quadtree's slices (thesis 3.2.6; the rule is in the
//! parent module's doc): the first-fit scan for `t > 0` and [`ExactGroups`], the same groups
//! found without scanning, for `t = 0`.

use super::{shape, LinearQuadtree4d, SliceAxes};
use crate::table::code::encode;
use std::collections::HashMap;

/// `Some(|S \ R|)` when `S` (collision bits, care mask) may join a group with representative
/// `R` and budgets `g_add`, `g_sub` (see the module doc).
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
///   `64 j + i` has bit `p`; blocks come in chunks of `chunk_blocks` blocks, stored bit by bit (a
///   chunk's words of one slice bit are adjacent). A query ANDs, chunk by chunk, the words of
///   `S`'s bits and the complements of the words of `C \ S`'s bits into one word per block,
///   and stops a chunk when none of its groups is left: the first chunk with a group left
///   holds, at its lowest, the first group that fits.
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
    /// Blocks of 64 groups per chunk of `sliced` (at most [`MAX_CHUNK_BLOCKS`]).
    chunk_blocks: usize,
}

/// The tile sides of [`ExactGroups`], tried in this order.
const TILE_SIDES: [usize; 2] = [8, 4];

/// Blocks of 64 groups per chunk of [`ExactGroups`]'s bit-sliced representatives (2 in the
/// unit tests, whose few hundred groups then span chunks).
/// Blocks of 64 groups per chunk of [`ExactGroups`]'s bit-sliced representatives in the
/// builder (any value gives the same groups; 64 keeps a chunk's words of one slice bit in
/// one 512-byte run).
const CHUNK_BLOCKS: usize = 64;

/// The most blocks a chunk may have (the size of the scan's per-chunk array).
const MAX_CHUNK_BLOCKS: usize = 64;

/// Positions of the set bits of `words` (bit `p % 64` of word `p / 64`), increasing.
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

impl ExactGroups {
    /// Groups of slices of `rows` rows of `cols` bits (`wps` words), the bit-sliced
    /// representatives in chunks of `chunk_blocks` blocks (the builder: [`CHUNK_BLOCKS`]).
    fn new(wps: usize, rows: usize, cols: usize, chunk_blocks: usize) -> ExactGroups {
        assert!((1..=MAX_CHUNK_BLOCKS).contains(&chunk_blocks), "chunk_blocks = {chunk_blocks}");
        ExactGroups {
            wps,
            rows,
            cols,
            reps: Vec::new(),
            by_tile: HashMap::new(),
            sliced: Vec::new(),
            chunk_blocks,
        }
    }

    fn count(&self) -> usize {
        self.reps.len() / self.wps
    }

    /// The tiles of side `side` of `words`, each as (index, bits: row `r` of the tile at bit
    /// `side * r`), and the bits of a tile with all of them set.
    fn tiles<'w>(
        &self,
        words: &'w [u64],
        side: usize,
    ) -> (impl Iterator<Item = (u32, u64)> + 'w, u64) {
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
        let blocks = self.chunk_blocks;
        let per_chunk = 64 * blocks;
        let mut left_all = [0u64; MAX_CHUNK_BLOCKS];
        let left = &mut left_all[..blocks];
        for (c, words) in self.sliced.chunks_exact(64 * self.wps * blocks).enumerate() {
            // Groups `..n` of this chunk exist.
            let n = (self.count() - per_chunk * c).min(per_chunk);
            for (j, l) in left.iter_mut().enumerate() {
                let m = n.saturating_sub(64 * j).min(64);
                *l = if m == 64 { !0 } else { (1u64 << m) - 1 };
            }
            for &(p, flip) in &probe {
                let mut any = 0;
                for (l, &w) in left.iter_mut().zip(&words[p as usize * blocks..][..blocks]) {
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
        debug_assert!(
            s.iter().zip(care).all(|(&s, &c)| s & !c == 0),
            "a collision bit outside the care mask"
        );
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
        let blocks = self.chunk_blocks;
        let (per_chunk, chunk_words) = (64 * blocks, 64 * self.wps * blocks);
        if g % per_chunk == 0 {
            self.sliced.resize(self.sliced.len() + chunk_words, 0);
        }
        let chunk = &mut self.sliced[g / per_chunk * chunk_words..];
        for p in set_bits(s.iter().copied()) {
            chunk[p as usize * blocks + g % per_chunk / 64] |= 1 << (g % 64);
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

/// Algorithm 8's grouping, fed the ranges' slices in the thesis's order (x, x', then the
/// second dimension of each).
pub(super) struct Grouping {
    tree: LinearQuadtree4d,
    wps: usize,
    g_add: Vec<u32>,
    exact: Option<ExactGroups>,
    nodes: Vec<(u64, u32)>,
}

impl Grouping {
    pub(super) fn new(levels: u32, symmetric: bool, axes: SliceAxes, t: u32) -> Grouping {
        let (a0, wps) = shape(levels, symmetric, axes);
        let tree = LinearQuadtree4d {
            levels,
            symmetric,
            axes,
            t,
            codes: vec![],
            slice_of: vec![],
            slices: vec![],
        };
        let k = 1usize << levels;
        let exact = (t == 0).then(|| ExactGroups::new(wps, k - a0 as usize, k, CHUNK_BLOCKS));
        Grouping { tree, wps, g_add: Vec::new(), exact, nodes: Vec::new() }
    }

    /// Range `[x, second, x', second']` with slice `s` (collision bits) and `care`.
    pub(super) fn add(&mut self, range: [u16; 4], s: &[u64], care: &[u64]) {
        let group = match self.exact.as_mut() {
            Some(exact) => exact.group(s, care),
            None => self.tree.group(s, care, &mut self.g_add, self.wps),
        };
        self.nodes.push((encode(range, 4), group));
    }

    pub(super) fn finish(mut self) -> LinearQuadtree4d {
        if let Some(exact) = self.exact {
            self.tree.slices = exact.reps;
        }
        self.nodes.sort_unstable_by_key(|n| n.0);
        (self.tree.codes, self.tree.slice_of) = self.nodes.into_iter().unzip();
        self.tree
    }
}

impl LinearQuadtree4d {
    /// The group `s` joins (its representative updated), or a new one (Algorithm 8 l. 7-19).
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
        assert_eq!(
            try_join(&[0b0011], &[0b1011], &rep, 2, 1),
            Some(0),
            "a don't-care bit is not counted"
        );
    }

    /// Slices made from a few patterns, each seen through one of a few care masks (some with
    /// a flipped bit), 16 x 16 bits: both searches of [`ExactGroups`] find the scan's group.
    /// Chunks of 2 blocks, so that the few hundred groups span several chunks.
    #[test]
    fn exact_groups_are_those_of_the_first_fit_scan() {
        let mut rng = crate::test_rng::TestRng(0x9e37_79b9_7f4a_7c15);
        let mut next = || {
            rng.unit();
            rng.0
        };
        let wps = 4;
        let patterns: Vec<Vec<u64>> =
            (0..200).map(|_| (0..wps).map(|_| next()).collect()).collect();
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
        let (mut g_add, mut exact, mut joined) = (Vec::new(), ExactGroups::new(wps, 16, 16, 2), 0);
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
                    assert_eq!(
                        groups.iter().copied().find(|&g| exact.fits(g, &s, &care)),
                        old,
                        "slice {i}"
                    );
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
}
