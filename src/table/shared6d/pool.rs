//! The query layout of the shared 6-D quadtree: one array of `u64` words that a query descends
//! with one cache line per node step, each node next to its first parent (issue 4: "median
//! under 50 ns, maximum within 10x").
//!
//! # Layout
//! ```text
//! [top table][root record, then every node once, in the order the descent first reaches it]
//! ```
//! - *Top table*: the first `top_depths` inner depths ([`TOP_DEPTHS`], or 1 for a 2-level
//!   grid) resolved at once: one slot per combination of their child indices
//!   (`64^top_depths` slots; half when symmetric, since a folded query always has A's top `y`
//!   bit set). A slot is 0 (free),
//!   1 (collision), or the word of the node it reaches (never 0 or 1: the top table comes
//!   first).
//! - *Record* of an inner node: `nonuniform`, `collision`, then one slot per non-uniform child
//!   (`popcount` order) holding the child's word, packed into the following words and padded
//!   to a word.
//! - *Leaf*: one word, bit `i` for child cell `i`.
//!
//! Nodes are placed depth first (a node, then the subtree of each child not placed yet, in
//! child order), so that a node that has one parent (all inner nodes but a few, three
//! quarters of the leaves at k = 32) lies right after its parent's record or its siblings:
//! the last node step and its leaf share a cache line or its neighbour and one page. The
//! records above the top table are kept (for [`Pool::arrays`]) but never read by a query.
//!
//! Slots are `u16` when every word index fits, else `u32`, four or two to a word, lowest bits
//! first. A query reads one top slot, then per node step the record's masks and one slot of
//! the same record, then one leaf. The old layout (masks, bases and child indices in three
//! arrays, nodes depth by depth) read three lines per step and nine dependent reads at k = 32.
//!
//! # Order
//! [`Pool::arrays`] gives the canonical arrays back by walking the layout, numbering the
//! nodes of each depth in the order the descent first reaches them: the order `build` gives
//! them, which [`check_order`] requires of stored parts.

use super::child_index;
use crate::table::code::MAX_LEVELS;
use alloc::{format, string::String, vec, vec::Vec};

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
    /// Top table, then the nodes.
    words: Vec<u64>,
    /// 16 or 32.
    slot_bits: u32,
    /// Inner depths resolved by the top table.
    top_depths: u32,
    /// Inner depths (`levels + sub_levels - 1`).
    depths: u32,
    symmetric: bool,
    /// Inner nodes per depth, then leaves.
    counts: [u32; DEPTH_SLOTS],
}

/// The canonical arrays: masks, bases, depth starts, child indices, leaves.
pub(super) type Arrays = (Vec<[u64; 2]>, Vec<u32>, Vec<u32>, Vec<u32>, Vec<u64>);

/// Slot `i` of the slots packed from word `word` on, `BITS` bits each.
#[inline(always)]
fn slot<const BITS: u32>(words: &[u64], word: usize, i: usize) -> usize {
    let per = (64 / BITS) as usize;
    (words[word + i / per] >> (BITS as usize * (i % per)) & ((1u64 << BITS) - 1)) as usize
}

/// Packs `values` into `out` from word 0 on, `bits` each, lowest first.
fn pack(out: &mut [u64], values: impl IntoIterator<Item = u64>, bits: u32) {
    let per = (64 / bits) as usize;
    for (i, v) in values.into_iter().enumerate() {
        out[i / per] |= v << (bits as usize * (i % per));
    }
}

/// Words of a record with `n` child slots.
fn record_words(n: usize, bits: u32) -> usize {
    2 + n.div_ceil((64 / bits) as usize)
}

/// A node of the canonical arrays: inner (depth, global index) or leaf (index).
#[derive(Clone, Copy)]
enum Node {
    Inner(usize, usize),
    Leaf(usize),
}

/// Visits the canonical arrays depth first from the root (a node, then each child not yet
/// visited, in child order), calling `first(node)` at each node's first visit.
fn depth_first(a: &Arrays, depths: usize, first: &mut impl FnMut(Node)) {
    let (masks, _, depth_start, _, leaves) = a;
    let mut seen_inner = vec![false; masks.len()];
    let mut seen_leaf = vec![false; leaves.len()];
    visit(a, depths, 0, 0, &mut seen_inner, &mut seen_leaf, first);
    debug_assert!(depth_start[0] == 0);
}

fn visit(
    a: &Arrays,
    depths: usize,
    d: usize,
    node: usize,
    seen_inner: &mut [bool],
    seen_leaf: &mut [bool],
    first: &mut impl FnMut(Node),
) {
    let (masks, bases, depth_start, children, _) = a;
    seen_inner[node] = true;
    first(Node::Inner(d, node));
    let n = masks[node][0].count_ones() as usize;
    for &id in &children[bases[node] as usize..][..n] {
        if d + 1 < depths {
            let child = (depth_start[d + 1] + id) as usize;
            if !seen_inner[child] {
                visit(a, depths, d + 1, child, seen_inner, seen_leaf, first);
            }
        } else if !seen_leaf[id as usize] {
            seen_leaf[id as usize] = true;
            first(Node::Leaf(id as usize));
        }
    }
}

/// Whether bounds-checked canonical arrays number the nodes of each depth in the order the
/// descent first reaches them, and reach them all (see the module doc).
///
/// # Errors
/// The first node out of order, or the first depth with a node never reached.
pub(super) fn check_order(a: &Arrays, depths: usize) -> Result<(), String> {
    let (_, _, depth_start, _, leaves) = a;
    // Next expected index per depth (global for inner depths), leaves last.
    let mut next: Vec<usize> = depth_start[..depths].iter().map(|&s| s as usize).collect();
    next.push(0);
    let mut bad = None;
    depth_first(a, depths, &mut |n| {
        let (d, i) = match n {
            Node::Inner(d, i) => (d, i),
            Node::Leaf(i) => (depths, i),
        };
        if bad.is_none() && i != next[d] {
            bad = Some(format!("depth {d}: node {i} is reached first where node {} is due", next[d]));
        }
        next[d] += 1;
    });
    if let Some(e) = bad {
        return Err(
            e + "; nodes must be numbered in the order the descent first reaches them (as `build` numbers them)"
        );
    }
    let ends = depth_start[1..=depths].iter().map(|&s| s as usize).chain([leaves.len()]);
    match next.iter().zip(ends).position(|(&n, end)| n != end) {
        Some(d) => Err(format!("depth {d}: some nodes are never reached from the root")),
        None => Ok(()),
    }
}

impl Pool {
    /// The layout of canonical arrays that passed [`check_order`] (see
    /// [`super::SharedQuadtree6d::from_parts`]).
    pub(super) fn new(fine: u32, symmetric: bool, a: &Arrays) -> Pool {
        Self::with_slots(fine, symmetric, a, 16)
            .unwrap_or_else(|| Self::with_slots(fine, symmetric, a, 32).expect("a table of at most 2^32 words"))
    }

    /// The layout with `bits`-bit slots, or `None` when a word index does not fit.
    fn with_slots(fine: u32, symmetric: bool, a: &Arrays, bits: u32) -> Option<Pool> {
        let (masks, bases, depth_start, children, leaves) = a;
        let depths = fine - 1;
        let top_depths = depths.min(TOP_DEPTHS);
        let top_slots = (64usize << (6 * (top_depths - 1))) >> usize::from(symmetric);
        let top_words = top_slots.div_ceil((64 / bits) as usize);
        // Where each node goes: depth first, right after the node placed before it.
        let (mut inner_at, mut leaf_at) = (vec![0usize; masks.len()], vec![0usize; leaves.len()]);
        let mut end = top_words;
        depth_first(a, depths as usize, &mut |n| match n {
            Node::Inner(_, i) => {
                inner_at[i] = end;
                end += record_words(masks[i][0].count_ones() as usize, bits);
            }
            Node::Leaf(i) => {
                leaf_at[i] = end;
                end += 1;
            }
        });
        if (end as u64) > 1u64 << bits {
            return None;
        }
        // The word of child `id` of a node of depth `d`.
        let target = |d: usize, id: u32| -> u64 {
            if d + 1 < depths as usize {
                inner_at[(depth_start[d + 1] + id) as usize] as u64
            } else {
                leaf_at[id as usize] as u64
            }
        };
        let mut words = vec![0u64; end];
        pack(&mut words, top_entries(symmetric, top_depths, a, target), bits);
        for d in 0..depths as usize {
            for node in depth_start[d] as usize..depth_start[d + 1] as usize {
                let [nonuniform, collision] = masks[node];
                let at = inner_at[node];
                words[at] = nonuniform;
                words[at + 1] = collision;
                let ids = &children[bases[node] as usize..][..nonuniform.count_ones() as usize];
                pack(&mut words[at + 2..], ids.iter().map(|&id| target(d, id)), bits);
            }
        }
        for (leaf, &at) in leaves.iter().zip(&leaf_at) {
            words[at] = *leaf;
        }
        let mut counts = [0u32; DEPTH_SLOTS];
        for d in 0..depths as usize {
            counts[d] = depth_start[d + 1] - depth_start[d];
        }
        counts[depths as usize] = leaves.len() as u32;
        Some(Pool { words, slot_bits: bits, top_depths, depths, symmetric, counts })
    }

    /// The canonical arrays back (as the file stores them): the layout walked depth first,
    /// each depth's nodes numbered in the order they are first reached.
    pub(super) fn arrays(&self) -> Arrays {
        let depths = self.depths as usize;
        let top_words = self.root();
        // Per depth (leaves last): the words of its nodes in number order; per word, its number.
        let mut order: Vec<Vec<usize>> = vec![vec![]; depths + 1];
        let mut number = vec![u32::MAX; self.words.len()];
        let mut stack = vec![(top_words, 0usize)];
        // Depth first with an explicit stack: children pushed in reverse to pop in order.
        while let Some((at, d)) = stack.pop() {
            if number[at] != u32::MAX {
                continue;
            }
            number[at] = order[d].len() as u32;
            order[d].push(at);
            if d < depths {
                let n = self.words[at].count_ones() as usize;
                for i in (0..n).rev() {
                    stack.push((self.slot_at(at + 2, i), d + 1));
                }
            }
        }
        let (mut masks, mut bases, mut children, mut depth_start) = (vec![], vec![], vec![], vec![]);
        for level in &order[..depths] {
            depth_start.push(masks.len() as u32);
            for &at in level {
                let nonuniform = self.words[at];
                masks.push([nonuniform, self.words[at + 1]]);
                bases.push(children.len() as u32);
                children.extend((0..nonuniform.count_ones() as usize).map(|i| number[self.slot_at(at + 2, i)]));
            }
        }
        depth_start.push(masks.len() as u32);
        let leaves = order[depths].iter().map(|&at| self.words[at]).collect();
        (masks, bases, depth_start, children, leaves)
    }

    /// The root record's word (right after the top table).
    fn root(&self) -> usize {
        let top_slots = (64usize << (6 * (self.top_depths - 1))) >> usize::from(self.symmetric);
        top_slots.div_ceil((64 / self.slot_bits) as usize)
    }

    /// Slot `i` from word `word` on, at this pool's slot width.
    fn slot_at(&self, word: usize, i: usize) -> usize {
        match self.slot_bits {
            16 => slot::<16>(&self.words, word, i),
            _ => slot::<32>(&self.words, word, i),
        }
    }

    /// The top-table slot of the folded cell `c`.
    #[inline(always)]
    fn top_index(&self, c: &[u16; 6], fine: u32) -> usize {
        let full = (0..self.top_depths).fold(0, |i, d| i << 6 | child_index(c, fine - 1 - d) as usize);
        squeeze(full, self.top_depths, self.symmetric)
    }

    /// Whether the folded cell `c` (indices below `2^fine`) is stored as collision.
    #[inline(always)]
    pub(super) fn query(&self, c: &[u16; 6], fine: u32) -> bool {
        match self.slot_bits {
            16 => self.descend::<16>(c, fine),
            _ => self.descend::<32>(c, fine),
        }
    }

    #[inline(always)]
    fn descend<const BITS: u32>(&self, c: &[u16; 6], fine: u32) -> bool {
        let w = &self.words;
        let mut node = slot::<BITS>(w, 0, self.top_index(c, fine));
        if node < 2 {
            return node == 1;
        }
        for d in self.top_depths..self.depths {
            let bit = 1u64 << child_index(c, fine - 1 - d);
            let (nonuniform, collision) = (w[node], w[node + 1]);
            if nonuniform & bit == 0 {
                return collision & bit != 0;
            }
            node = slot::<BITS>(w, node + 2, (nonuniform & (bit - 1)).count_ones() as usize);
        }
        w[node] >> child_index(c, 0) & 1 == 1
    }

    /// [`query`](Self::query) and its reads as `(address, bytes, step)`.
    pub(super) fn query_reads(&self, c: &[u16; 6], fine: u32) -> (bool, Vec<(usize, usize, u32)>) {
        let w = &self.words;
        let at = |i: usize| w.as_ptr() as usize + 8 * i;
        let bytes = (self.slot_bits / 8) as usize;
        let per = (64 / self.slot_bits) as usize;
        let slot_addr = |word: usize, i: usize| at(word + i / per) + bytes * (i % per);
        let top = self.top_index(c, fine);
        let mut reads = vec![(slot_addr(0, top), bytes, 0)];
        let mut node = self.slot_at(0, top);
        if node < 2 {
            return (node == 1, reads);
        }
        let mut step = 1;
        for d in self.top_depths..self.depths {
            let bit = 1u64 << child_index(c, fine - 1 - d);
            let (nonuniform, collision) = (w[node], w[node + 1]);
            reads.push((at(node), 16, step));
            if nonuniform & bit == 0 {
                return (collision & bit != 0, reads);
            }
            let rank = (nonuniform & (bit - 1)).count_ones() as usize;
            reads.push((slot_addr(node + 2, rank), bytes, step + 1));
            node = self.slot_at(node + 2, rank);
            step += 2;
        }
        reads.push((at(node), 8, step));
        (w[node] >> child_index(c, 0) & 1 == 1, reads)
    }

    /// Inner nodes per depth, then the leaf count.
    pub(super) fn nodes_per_depth(&self) -> Vec<usize> {
        self.counts[..=self.depths as usize].iter().map(|&n| n as usize).collect()
    }

    /// The words a query reads.
    pub(super) fn words(&self) -> &[u64] {
        &self.words
    }

    /// Bits per slot (16 or 32).
    pub(super) fn slot_bits(&self) -> u32 {
        self.slot_bits
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
fn top_entries(symmetric: bool, top_depths: u32, a: &Arrays, node: impl Fn(usize, u32) -> u64) -> Vec<u64> {
    let (masks, bases, depth_start, children, _) = a;
    let full_slots = 1usize << (6 * top_depths);
    let ay_bit = 6 * (top_depths as usize - 1) + 4;
    let mut out = vec![0u64; full_slots >> usize::from(symmetric)];
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
            let child = children[bases[node] as usize + (nonuniform & (bit - 1)).count_ones() as usize] as usize;
            node = if d + 1 < depths { depth_start[d as usize + 1] as usize + child } else { child };
        }
        leaves[node] >> child_index(&c, 0) & 1 == 1
    }

    fn cells(levels: u32, n: usize) -> impl Iterator<Item = [u16; 6]> {
        let k = 1u64 << levels;
        let mut x = 0x9e37_79b9_7f4a_7c15u64 ^ u64::from(levels);
        let all = k.pow(6) as usize <= n;
        (0..n.min(k.pow(6) as usize)).map(move |i| {
            let v = if all {
                i as u64
            } else {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                x >> 16
            };
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
            let t = SharedQuadtree6d::build(&space(levels, pattern), symmetric).unwrap();
            let p = t.parts();
            let a = (p.masks, p.bases, p.depth_start, p.children.to_u32(), p.leaves);
            for bits in [16, 32] {
                let pool = Pool::with_slots(levels, symmetric, &a, bits).unwrap();
                assert_eq!(pool.arrays(), a, "{pattern:?} {levels} {bits}: arrays read back");
                for cell in cells(levels, 1 << 20) {
                    let c = fold(cell, 1 << levels, symmetric).unwrap();
                    let want = canonical_query(&a, levels, symmetric, cell);
                    assert_eq!(pool.query(&c, levels), want, "{pattern:?} {levels} {bits}: {cell:?}");
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
        let mut w = vec![0; 2];
        pack(&mut w, [1, 2, 3, 4, 5], 16);
        assert_eq!(w, vec![0x0004_0003_0002_0001, 5]);
        assert_eq!((0..5).map(|i| slot::<16>(&w, 0, i)).collect::<Vec<_>>(), [1, 2, 3, 4, 5]);
        let mut w = vec![0; 2];
        pack(&mut w, [7, u64::from(u32::MAX), 9], 32);
        assert_eq!((0..3).map(|i| slot::<32>(&w, 0, i)).collect::<Vec<_>>(), [7, u32::MAX as usize, 9]);
    }
}
