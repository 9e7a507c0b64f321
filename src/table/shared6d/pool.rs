//! The query layout of the shared 6-D quadtree: one array of `u64` words that a query descends
//! with about one cache line per node step (its targets: median under 50 ns, maximum within 10x).
//!
//! # Layout
//! ```text
//! [top table][records of depth 0][depth 1]...[depth depths-1][leaves]
//! ```
//! - *Top table*: the first `top_depths` inner depths ([`TOP_DEPTHS`], or 1 for a 2-level
//!   grid) resolved at once: one slot per combination of their child indices
//!   (`64^top_depths` slots; half when symmetric, since a folded query always has A's top `y`
//!   bit set). A slot is 0 (free), 1 (collision), or `2 + r` for the node at word
//!   `region[top_depths] + r`.
//! - *Record* of an inner node: `nonuniform`, `collision`, then one slot per non-uniform child
//!   (`popcount` order), packed into the following words and padded to a word. A slot holds
//!   the child's word offset from the start of the next depth's region (inner depths) or its
//!   leaf index. Records sit depth by depth in the order of [`SharedParts`] (the order in
//!   which a depth-first descent first reaches them, as `build` numbers them), so that the
//!   leaves of one node lie side by side; the records of the depths under the top table are
//!   kept for [`Pool::arrays`] but never read by a query.
//! - *Leaf*: one word, bit `i` for child cell `i`.
//!
//! The slots of each depth are `u16` when every offset into the next region fits, else
//! `u32`, four or two to a word, lowest bits first (so a table is as narrow as its stored
//! child indices were, at the leaves, which hold most slots). One node step reads the
//! record's masks and then one slot of the same record, 16 to 272 bytes on: the same cache
//! line for a small rank, its neighbour otherwise. Reading the stored arrays directly (masks,
//! bases and child indices apart) took three lines per step and, at k = 32, nine dependent
//! reads instead of six.
//!
//! [`SharedParts`]: super::SharedParts

use super::child_index;
use crate::table::code::MAX_LEVELS;
use alloc::{vec, vec::Vec};

/// Per-depth arrays hold at most this many entries (inner depths, plus one).
const DEPTH_SLOTS: usize = MAX_LEVELS as usize + 1;

/// Inner depths the top table resolves (fewer when the grid has fewer). Two: 2,048 or 4,096
/// slots (4 or 8 KiB with 16-bit slots), one dependent read for the two nodes every query
/// starts with; one would save that much memory and cost one more read (on T1 at k = 32 the
/// flushed median rose from 160 to 270 ns).
const TOP_DEPTHS: u32 = 2;

/// The query layout (see the module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Pool {
    /// Top table, records, leaves.
    words: Vec<u64>,
    /// Bit `d`: the slots of depth `d`'s records (and of the top table, for
    /// `d = top_depths - 1`) are 32-bit, else 16-bit.
    wide: u32,
    /// Inner depths resolved by the top table.
    top_depths: u32,
    /// Inner depths (`levels + sub_levels - 1`).
    depths: u32,
    symmetric: bool,
    /// Word where the records of each inner depth start, then the leaves, then the end.
    region: [u32; DEPTH_SLOTS + 1],
    /// First node of each inner depth, then the inner node count (as [`SharedParts`] has it).
    ///
    /// [`SharedParts`]: super::SharedParts
    depth_start: [u32; DEPTH_SLOTS],
}

/// The canonical arrays: masks, bases, depth starts, child indices, leaves.
pub(super) type Arrays = (Vec<[u64; 2]>, Vec<u32>, Vec<u32>, Vec<u32>, Vec<u64>);

/// Slot `i` of the slots packed from word `word` on, `BITS` bits each.
#[inline(always)]
fn slot<const BITS: u32>(words: &[u64], word: usize, i: usize) -> usize {
    let per = (64 / BITS) as usize;
    (words[word + i / per] >> (BITS as usize * (i % per)) & ((1u64 << BITS) - 1)) as usize
}

/// Slot `i` from word `word` on, 32-bit when `wide`, else 16-bit.
#[inline(always)]
fn slot_of(words: &[u64], wide: bool, word: usize, i: usize) -> usize {
    if wide {
        slot::<32>(words, word, i)
    } else {
        slot::<16>(words, word, i)
    }
}

/// Packs `values` into words appended to `out`, `bits` each, lowest first.
fn pack(out: &mut Vec<u64>, values: impl IntoIterator<Item = u64>, bits: u32) {
    let per = 64 / bits;
    for (i, v) in values.into_iter().enumerate() {
        if i as u32 % per == 0 {
            out.push(0);
        }
        *out.last_mut().expect("pushed") |= v << (bits * (i as u32 % per));
    }
}

/// Words of a record with `n` child slots of `bits` bits.
fn record_words(n: usize, bits: u32) -> usize {
    2 + n.div_ceil((64 / bits) as usize)
}

/// Top-table slots: `64^top_depths`, half when symmetric.
fn top_slots(top_depths: u32, symmetric: bool) -> usize {
    (64usize << (6 * (top_depths - 1))) >> usize::from(symmetric)
}

impl Pool {
    /// The layout of validated canonical arrays (see [`super::SharedQuadtree6d::from_parts`]).
    pub(super) fn new(fine: u32, symmetric: bool, a: &Arrays) -> Pool {
        Self::layout(fine, symmetric, a, false)
    }

    /// As [`new`](Self::new) with every slot 32-bit.
    #[cfg(test)]
    fn all_wide(fine: u32, symmetric: bool, a: &Arrays) -> Pool {
        Self::layout(fine, symmetric, a, true)
    }

    fn layout(fine: u32, symmetric: bool, a: &Arrays, all_wide: bool) -> Pool {
        let (masks, bases, depth_start, children, leaves) = a;
        let depths = fine - 1;
        let top_depths = depths.min(TOP_DEPTHS);
        // Slot widths, deepest first: a depth's slots are offsets into the next region,
        // whose size depends on that depth's own width.
        let (mut wide, mut next_len) = (0u32, leaves.len());
        let mut rel = vec![0u32; masks.len()];
        let mut region_len = [0usize; DEPTH_SLOTS];
        for d in (0..depths as usize).rev() {
            let top_entry = usize::from(d + 1 == top_depths as usize) * 2;
            let bits = if !all_wide && next_len + top_entry <= 1 << 16 { 16 } else { 32 };
            wide |= u32::from(bits == 32) << d;
            let mut len = 0usize;
            for node in depth_start[d] as usize..depth_start[d + 1] as usize {
                rel[node] = u32::try_from(len).expect("a table of at most 2^32 words");
                len += record_words(masks[node][0].count_ones() as usize, bits);
            }
            region_len[d] = len;
            next_len = len;
        }
        let bits_of = |d: usize| if wide >> d & 1 == 1 { 32 } else { 16 };
        let top_bits = bits_of(top_depths as usize - 1);
        let mut region = [0u32; DEPTH_SLOTS + 1];
        region[0] = top_slots(top_depths, symmetric).div_ceil((64 / top_bits) as usize) as u32;
        for d in 0..depths as usize {
            region[d + 1] = region[d] + region_len[d] as u32;
        }
        region[depths as usize + 1] = region[depths as usize] + leaves.len() as u32;
        // The slot value of child `id` of a node of depth `d`.
        let target = |d: usize, id: u32| -> u64 {
            if d + 1 < depths as usize {
                u64::from(rel[(depth_start[d + 1] + id) as usize])
            } else {
                u64::from(id)
            }
        };
        let mut words = Vec::with_capacity(region[depths as usize + 1] as usize);
        pack(
            &mut words,
            top_entries(symmetric, top_depths, a, |d, id| 2 + target(d, id)),
            top_bits,
        );
        for d in 0..depths as usize {
            for node in depth_start[d] as usize..depth_start[d + 1] as usize {
                let [nonuniform, collision] = masks[node];
                words.extend([nonuniform, collision]);
                let ids = &children[bases[node] as usize..][..nonuniform.count_ones() as usize];
                pack(&mut words, ids.iter().map(|&id| target(d, id)), bits_of(d));
            }
        }
        words.extend_from_slice(leaves);
        debug_assert_eq!(words.len(), region[depths as usize + 1] as usize);
        let mut starts = [0u32; DEPTH_SLOTS];
        starts[..depth_start.len()].copy_from_slice(depth_start);
        Pool { words, wide, top_depths, depths, symmetric, region, depth_start: starts }
    }

    /// Whether the slots of depth `d`'s records are 32-bit.
    #[inline(always)]
    fn is_wide(&self, d: u32) -> bool {
        self.wide >> d & 1 == 1
    }

    /// The canonical arrays back (as the file stores them).
    pub(super) fn arrays(&self) -> Arrays {
        let depths = self.depths as usize;
        let (mut masks, mut bases, mut raw) = (vec![], vec![], vec![]);
        // Per depth, the record offsets within its region, ascending.
        let mut offsets: Vec<Vec<u32>> = vec![vec![]; depths];
        for (d, offsets) in offsets.iter_mut().enumerate() {
            let (wide, mut w) = (self.is_wide(d as u32), self.region[d] as usize);
            for _ in self.depth_start[d]..self.depth_start[d + 1] {
                let [nonuniform, collision] = [self.words[w], self.words[w + 1]];
                offsets.push((w - self.region[d] as usize) as u32);
                masks.push([nonuniform, collision]);
                bases.push(raw.len() as u32);
                let n = nonuniform.count_ones() as usize;
                raw.extend((0..n).map(|i| slot_of(&self.words, wide, w + 2, i) as u32));
                w += record_words(n, if wide { 32 } else { 16 });
            }
        }
        // Slots of inner children are record offsets: back to indices within the depth.
        let raw_len = raw.len();
        let (mut children, count) = (raw, raw_len);
        let base = |node: u32| bases.get(node as usize).map_or(count, |&b| b as usize);
        for d in 0..depths.saturating_sub(1) {
            let range = base(self.depth_start[d])..base(self.depth_start[d + 1]);
            for c in &mut children[range] {
                *c = offsets[d + 1].binary_search(c).expect("a record start") as u32;
            }
        }
        let leaves = self.words[self.region[depths] as usize..].to_vec();
        (masks, bases, self.depth_start[..=depths].to_vec(), children, leaves)
    }

    /// The top-table slot of the folded cell `c`.
    #[inline(always)]
    fn top_index(&self, c: &[u16; 6], fine: u32) -> usize {
        let full =
            (0..self.top_depths).fold(0, |i, d| i << 6 | child_index(c, fine - 1 - d) as usize);
        squeeze(full, self.top_depths, self.symmetric)
    }

    /// Whether the folded cell `c` (indices below `2^fine`) is stored as collision.
    #[inline(always)]
    pub(super) fn query(&self, c: &[u16; 6], fine: u32) -> bool {
        let w = &self.words;
        let entry = slot_of(w, self.is_wide(self.top_depths - 1), 0, self.top_index(c, fine));
        if entry < 2 {
            return entry == 1;
        }
        let mut node = self.region[self.top_depths as usize] as usize + entry - 2;
        for d in self.top_depths..self.depths {
            let bit = 1u64 << child_index(c, fine - 1 - d);
            let (nonuniform, collision) = (w[node], w[node + 1]);
            if nonuniform & bit == 0 {
                return collision & bit != 0;
            }
            let rank = (nonuniform & (bit - 1)).count_ones() as usize;
            node =
                self.region[d as usize + 1] as usize + slot_of(w, self.is_wide(d), node + 2, rank);
        }
        w[node] >> child_index(c, 0) & 1 == 1
    }

    /// The whole stored word of the folded cell `c` (indices below `2^fine`, the last bit of
    /// each ignored): a leaf's 64 bits, or all ones / all zeros for a uniform collision / free
    /// block. The same reads as [`query`](Self::query); a clearance table's lookup.
    #[inline(always)]
    pub(super) fn query_word(&self, c: &[u16; 6], fine: u32) -> u64 {
        let uniform = |collision: bool| if collision { u64::MAX } else { 0 };
        let w = &self.words;
        let entry = slot_of(w, self.is_wide(self.top_depths - 1), 0, self.top_index(c, fine));
        if entry < 2 {
            return uniform(entry == 1);
        }
        let mut node = self.region[self.top_depths as usize] as usize + entry - 2;
        for d in self.top_depths..self.depths {
            let bit = 1u64 << child_index(c, fine - 1 - d);
            let (nonuniform, collision) = (w[node], w[node + 1]);
            if nonuniform & bit == 0 {
                return uniform(collision & bit != 0);
            }
            let rank = (nonuniform & (bit - 1)).count_ones() as usize;
            node =
                self.region[d as usize + 1] as usize + slot_of(w, self.is_wide(d), node + 2, rank);
        }
        w[node]
    }

    /// [`query`](Self::query) and its reads as `(address, bytes, step)`.
    #[cfg(any(test, feature = "eval"))]
    pub(super) fn query_reads(&self, c: &[u16; 6], fine: u32) -> (bool, Vec<(usize, usize, u32)>) {
        let w = &self.words;
        let at = |i: usize| w.as_ptr() as usize + 8 * i;
        let slot_addr = |wide: bool, word: usize, i: usize| {
            let (bytes, per) = if wide { (4, 2) } else { (2, 4) };
            (at(word + i / per) + bytes * (i % per), bytes)
        };
        let (top, top_wide) = (self.top_index(c, fine), self.is_wide(self.top_depths - 1));
        let (addr, bytes) = slot_addr(top_wide, 0, top);
        let mut reads = vec![(addr, bytes, 0)];
        let entry = slot_of(w, top_wide, 0, top);
        if entry < 2 {
            return (entry == 1, reads);
        }
        let mut node = self.region[self.top_depths as usize] as usize + entry - 2;
        let mut step = 1;
        for d in self.top_depths..self.depths {
            let bit = 1u64 << child_index(c, fine - 1 - d);
            let (nonuniform, collision) = (w[node], w[node + 1]);
            reads.push((at(node), 16, step));
            if nonuniform & bit == 0 {
                return (collision & bit != 0, reads);
            }
            let rank = (nonuniform & (bit - 1)).count_ones() as usize;
            let (addr, bytes) = slot_addr(self.is_wide(d), node + 2, rank);
            reads.push((addr, bytes, step + 1));
            node =
                self.region[d as usize + 1] as usize + slot_of(w, self.is_wide(d), node + 2, rank);
            step += 2;
        }
        reads.push((at(node), 8, step));
        (w[node] >> child_index(c, 0) & 1 == 1, reads)
    }

    /// Inner nodes per depth, then the leaf count.
    pub(super) fn nodes_per_depth(&self) -> Vec<usize> {
        let d = self.depths as usize;
        let mut v: Vec<usize> =
            self.depth_start[..=d].windows(2).map(|w| (w[1] - w[0]) as usize).collect();
        v.push((self.region[d + 1] - self.region[d]) as usize);
        v
    }

    /// The words a query reads.
    pub(super) fn words(&self) -> &[u64] {
        &self.words
    }

    /// Bits per slot, per inner depth (16 or 32).
    pub(super) fn slot_bits(&self) -> Vec<u32> {
        (0..self.depths).map(|d| if self.is_wide(d) { 32 } else { 16 }).collect()
    }
}

/// The top-table slot of the full index `full` (child indices of the top depths, 6 bits
/// each, depth 0 highest): without A's `y` bit of depth 0 when symmetric (always 1 there).
#[inline(always)]
fn squeeze(full: usize, top_depths: u32, symmetric: bool) -> usize {
    if !symmetric {
        return full;
    }
    let b = 6 * (top_depths as usize - 1) + 4;
    (full >> (b + 1)) << b | (full & ((1 << b) - 1))
}

/// The top table's slot values in slot order: 0 free, 1 collision, or `node(d, id)` for the
/// non-uniform child `id` that a node of depth `d = top_depths - 1` reaches.
fn top_entries(
    symmetric: bool,
    top_depths: u32,
    a: &Arrays,
    node: impl Fn(usize, u32) -> u64,
) -> Vec<u64> {
    let (masks, bases, depth_start, children, _) = a;
    let full_slots = 1usize << (6 * top_depths);
    let ay_bit = 6 * (top_depths as usize - 1) + 4;
    let mut out = vec![0u64; top_slots(top_depths, symmetric)];
    for full in 0..full_slots {
        if symmetric && full >> ay_bit & 1 == 0 {
            continue;
        }
        let mut n = 0usize;
        let mut value = 0;
        for d in 0..top_depths as usize {
            let i = full >> (6 * (top_depths as usize - 1 - d)) & 63;
            let bit = 1u64 << i;
            let [nonuniform, collision] = masks[n];
            if nonuniform & bit == 0 {
                value = u64::from(collision & bit != 0);
                break;
            }
            let id = children[bases[n] as usize + (nonuniform & (bit - 1)).count_ones() as usize];
            if d + 1 == top_depths as usize {
                value = node(d, id);
            } else {
                n = (depth_start[d + 1] + id) as usize;
            }
        }
        out[squeeze(full, top_depths, symmetric)] = value;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cspace::Symmetry;
    use crate::table::space::fold;
    use crate::table::synthetic::{space, Pattern};
    use crate::table::SharedQuadtree6d;

    /// The descent over the canonical arrays (the layout before this one), the reference.
    fn canonical_query(a: &Arrays, fine: u32, symmetric: bool, cell: [u16; 6]) -> bool {
        let (masks, bases, depth_start, children, leaves) = a;
        let Some(c) = fold(cell, 1 << fine, symmetric) else { return true };
        let (mut node, depths) = (0usize, fine - 1);
        for d in 0..depths {
            let bit = 1u64 << child_index(&c, fine - 1 - d);
            let [nonuniform, collision] = masks[node];
            if nonuniform & bit == 0 {
                return collision & bit != 0;
            }
            let child = children
                [bases[node] as usize + (nonuniform & (bit - 1)).count_ones() as usize]
                as usize;
            node =
                if d + 1 < depths { depth_start[d as usize + 1] as usize + child } else { child };
        }
        leaves[node] >> child_index(&c, 0) & 1 == 1
    }

    fn cells(levels: u32, n: usize) -> impl Iterator<Item = [u16; 6]> {
        let k = 1u64 << levels;
        let mut rng = crate::test_rng::TestRng(0x9e37_79b9_7f4a_7c15u64 ^ u64::from(levels));
        let all = k.pow(6) as usize <= n;
        (0..n.min(k.pow(6) as usize)).map(move |i| {
            let v = if all { i as u64 } else { rng.next_u64() };
            core::array::from_fn(|j| (v >> (levels as usize * j) & (k - 1)) as u16)
        })
    }

    /// Every cell (all of them up to k = 8, else a seeded million) is answered as the
    /// canonical arrays answer it, with 16- and 32-bit slots, and the arrays read back equal.
    #[test]
    fn answers_every_cell_as_the_canonical_arrays() {
        for (pattern, levels, symmetric) in [
            (Pattern::Blobs, 2, false),
            (Pattern::Blobs, 3, true),
            (Pattern::Noise { p: 0.3, seed: 1 }, 3, false),
            (Pattern::AsymmetricNoise { p: 0.1, seed: 2 }, 4, true),
            (Pattern::Blobs, 5, true),
            (Pattern::AllCollision, 3, true),
            (Pattern::AllFree, 4, false),
        ] {
            let t =
                SharedQuadtree6d::build(&space(levels, pattern), Symmetry::from_flag(symmetric))
                    .unwrap();
            let p = t.parts();
            let a = (p.masks, p.bases, p.depth_start, p.children.to_u32(), p.leaves);
            for wide in [None, Some(u32::MAX)] {
                let bits = if wide.is_some() { 32 } else { 16 };
                let pool = match wide {
                    None => Pool::new(levels, symmetric, &a),
                    Some(_) => Pool::all_wide(levels, symmetric, &a),
                };
                assert_eq!(pool.arrays(), a, "{pattern:?} {levels} {bits}: arrays read back");
                for cell in cells(levels, 1 << 20) {
                    let c = fold(cell, 1 << levels, symmetric).unwrap();
                    let want = canonical_query(&a, levels, symmetric, cell);
                    assert_eq!(
                        pool.query(&c, levels),
                        want,
                        "{pattern:?} {levels} {bits}: {cell:?}"
                    );
                    assert_eq!(pool.query_reads(&c, levels).0, want);
                }
            }
        }
    }

    #[test]
    fn symmetric_top_table_drops_the_a_y_bit_of_depth_0() {
        // Depth-0 index bits: ax ay az bx by bz; with two top depths A's y is bit 10.
        assert_eq!(squeeze(0b111111_000000, 2, true), 0b11111_000000);
        assert_eq!(squeeze(0b101111_101010, 2, true), 0b11111_101010);
        assert_eq!(squeeze(0b010000, 1, true), 0);
        assert_eq!(squeeze(0b110000, 1, true), 0b10000);
        assert_eq!(squeeze(1234, 2, false), 1234);
    }

    #[test]
    fn slots_pack_lowest_first() {
        let mut w = vec![];
        pack(&mut w, [1, 2, 3, 4, 5], 16);
        assert_eq!(w, vec![0x0004_0003_0002_0001, 5]);
        assert_eq!((0..5).map(|i| slot::<16>(&w, 0, i)).collect::<Vec<_>>(), [1, 2, 3, 4, 5]);
        let mut w = vec![];
        pack(&mut w, [7, u64::from(u32::MAX), 9], 32);
        assert_eq!(
            (0..3).map(|i| slot::<32>(&w, 0, i)).collect::<Vec<_>>(),
            [7, u32::MAX as usize, 9]
        );
    }
}
