//! The shared 6-D quadtree: the 6-D quadtree of the labels with identical subtrees stored
//! once (a directed acyclic graph), queried by a descent of at most `levels` nodes (beyond
//! the thesis: its chapter 4 and 3.2.3 suggest exploiting repetition and hashing
//! similar slices; this hashes whole subtrees).
//!
//! # Structure
//! A node at depth `d` covers a block of `2^(levels - d)` cells per axis of the 6-D grid and
//! has 64 children, child `i` holding bit `5 - j` of `i` for dimension `j`
//! (`bx << 5 | by << 4 | bz << 3 | bx' << 2 | by' << 1 | bz'`, the order of
//! [`super::code`]). A child is *uniform* (all free or all collision: one bit in the node's
//! `collision` mask) or a node of depth `d + 1`, named by its index in the `children` pool at
//! `base + rank`, where `rank` counts the node's non-uniform children before it
//! (`popcount(nonuniform & (bit - 1))`). Nodes of depth `levels - 1` are *leaves*: one `u64`,
//! bit `i` for child cell `i`. Equal subtrees are one node (hash-consing while building),
//! which is where the size goes: a T1 table at k = 32 has ~2,400 inner nodes and ~9,000
//! distinct leaves for ~1.1 million stored collision samples.
//!
//! # Don't care
//! Unreachable pairs, unsampled cells and, with symmetry, A's lower half are "don't care"
//! (SPEC §6): a block with no free sample is stored as collision and one with no collision
//! sample as free; in a mixed leaf, don't-care bits are set to 0 or to 1, whichever matches a
//! leaf already stored (else 0). Every free and collision sample is answered exactly.
//!
//! # Query
//! The arrays above are what the file stores ([`SharedParts`]); a query reads them laid out
//! again in one array (`shared6d/pool.rs`): a top table resolves the first two depths in one
//! read, then each further node step reads one record (masks and child slots together, most
//! often one cache line), then one leaf. At k = 32 a query makes at most 6 dependent reads on
//! at most 8 cache lines (the arrays read directly: 9 reads on up to 14 lines). No search, no
//! loop whose length depends on the data, no allocation.

mod pool;

use super::code::MAX_LEVELS;
#[cfg(feature = "std")]
use super::error::bad_input;
use super::error::{corrupt, TableError};
use super::space::fold;
#[cfg(feature = "std")]
use super::space::SpaceView;
#[cfg(feature = "std")]
use crate::cspace::{Label, LabelledSpace, SubCells};
use alloc::{format, vec, vec::Vec};
#[cfg(feature = "std")]
use std::collections::HashMap;

/// Child indices of the pool, as narrow as the table allows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ChildIndices {
    /// Every index fits in 16 bits.
    Narrow(Vec<u16>),
    /// Some index does not.
    Wide(Vec<u32>),
}

impl ChildIndices {
    fn from_u32(v: Vec<u32>) -> ChildIndices {
        if v.iter().all(|&x| x <= u32::from(u16::MAX)) {
            ChildIndices::Narrow(v.into_iter().map(|x| x as u16).collect())
        } else {
            ChildIndices::Wide(v)
        }
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        match self {
            ChildIndices::Narrow(v) => v.len(),
            ChildIndices::Wide(v) => v.len(),
        }
    }

    /// Whether there are no entries.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The entries, widened.
    pub fn to_u32(&self) -> Vec<u32> {
        match self {
            ChildIndices::Narrow(v) => v.iter().map(|&x| u32::from(x)).collect(),
            ChildIndices::Wide(v) => v.clone(),
        }
    }
}

/// The arrays of a [`SharedQuadtree6d`] as the file stores them (read back from the query
/// layout, so `bases` are the running sums of the non-uniform children).
#[derive(Clone, Debug)]
pub struct SharedParts {
    /// Inner nodes, depth by depth (the root is node 0): `[nonuniform, collision]`.
    pub masks: Vec<[u64; 2]>,
    /// Per inner node: where its non-uniform children start in `children`.
    pub bases: Vec<u32>,
    /// Index of the first node of each depth `0..levels-1` in `masks`, then `masks.len()`.
    pub depth_start: Vec<u32>,
    /// Per non-uniform child: the index of the child node within its depth (inner nodes) or
    /// in `leaves` (children of depth `levels - 2`).
    pub children: ChildIndices,
    /// Leaves: bit `i` is child cell `i`.
    pub leaves: Vec<u64>,
}

/// The shared 6-D quadtree (see the module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SharedQuadtree6d {
    /// Levels of the sampled grid (`k = 2^levels`).
    levels: u32,
    /// Extra levels of sub-cells (0, or 1 for [`SharedQuadtree6d::build_subdivided`]).
    sub_levels: u32,
    symmetric: bool,
    /// The nodes, laid out for the query ([`pool`]).
    pool: pool::Pool,
}

/// The 6-bit child index of `c` at bit `shift` of every coordinate.
#[inline]
fn child_index(c: &[u16; 6], shift: u32) -> u32 {
    c.iter().fold(0, |i, &v| i << 1 | (u32::from(v) >> shift & 1))
}

/// An inner node while building: non-uniform mask, collision mask, child ids.
#[cfg(feature = "std")]
type InnerNode = (u64, u64, Vec<u32>);

/// A child while building: don't care, uniform, or a stored node of the next depth.
#[cfg(feature = "std")]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Part {
    DontCare,
    Free,
    Collision,
    Node(u32),
}

/// Hash-consing builder over a [`SpaceView`].
#[cfg(feature = "std")]
struct Builder<'a> {
    view: SpaceView<'a>,
    /// Sub-cells of the pairs labelled collision, when subdividing.
    sub: Option<&'a SubCells>,
    k: usize,
    /// Dense `k^3` maps from cell to sample index (`u32::MAX`: none, or not stored).
    dense_a: Vec<u32>,
    dense_b: Vec<u32>,
    /// Per depth: which blocks hold a (stored) sample ([`occupancy`]).
    occ_a: Vec<Vec<bool>>,
    occ_b: Vec<Vec<bool>>,
    /// Per inner depth: node -> id within the depth, and the nodes in id order.
    inner: Vec<HashMap<InnerNode, u32>>,
    inner_nodes: Vec<Vec<InnerNode>>,
    leaf_ids: HashMap<u64, u32>,
    leaves: Vec<u64>,
}

#[cfg(feature = "std")]
const NONE: u32 = u32::MAX;

#[cfg(feature = "std")]
fn dense_map(cells: &[[u16; 3]], k: usize, keep: impl Fn(usize) -> bool) -> Vec<u32> {
    let mut dense = vec![NONE; k * k * k];
    for (i, c) in cells.iter().enumerate() {
        if keep(i) {
            dense[(usize::from(c[0]) * k + usize::from(c[1])) * k + usize::from(c[2])] = i as u32;
        }
    }
    dense
}

/// `occ[d][block]`: whether the block of side `2^(levels - d)` holds a sample, `d` in `0..=levels`.
#[cfg(feature = "std")]
fn occupancy(dense: &[u32], k: usize, levels: u32) -> Vec<Vec<bool>> {
    (0..=levels)
        .map(|d| {
            let n = 1usize << d;
            let side = k / n;
            let mut occ = vec![false; n * n * n];
            for x in 0..k {
                for y in 0..k {
                    for z in 0..k {
                        if dense[(x * k + y) * k + z] != NONE {
                            occ[((x / side) * n + y / side) * n + z / side] = true;
                        }
                    }
                }
            }
            occ
        })
        .collect()
}

#[cfg(feature = "std")]
impl Builder<'_> {
    /// The part for the 6-D block at depth `d` whose per-robot block coordinates are `a`, `b`
    /// (in units of the block side).
    fn build(&mut self, d: u32, a: [usize; 3], b: [usize; 3]) -> Part {
        let n = 1usize << d;
        let at = |c: [usize; 3]| (c[0] * n + c[1]) * n + c[2];
        if !self.occ_a[d as usize][at(a)] || !self.occ_b[d as usize][at(b)] {
            return Part::DontCare;
        }
        let last = d == self.view.levels - 1;
        let mut kids = [Part::DontCare; 64];
        for (i, kid) in kids.iter_mut().enumerate() {
            let bit = |j: usize| (i >> (5 - j)) & 1;
            let ca = [2 * a[0] + bit(0), 2 * a[1] + bit(1), 2 * a[2] + bit(2)];
            let cb = [2 * b[0] + bit(3), 2 * b[1] + bit(4), 2 * b[2] + bit(5)];
            *kid = match (last, self.sub) {
                (false, _) => self.build(d + 1, ca, cb),
                (true, None) => self.cell(ca, cb).0,
                (true, Some(_)) => self.subdivided_cell(ca, cb),
            };
        }
        if last && self.sub.is_none() {
            // The children are cells: this block is a leaf.
            let (mut care, mut value) = (0u64, 0u64);
            for (i, p) in kids.iter().enumerate() {
                match p {
                    Part::Free => care |= 1 << i,
                    Part::Collision => (care, value) = (care | 1 << i, value | 1 << i),
                    Part::DontCare | Part::Node(_) => {}
                }
            }
            return self.leaf(care, value);
        }
        self.node(d as usize, &kids)
    }

    /// The part of one cell pair without sub-cells, and its sample pair when both are sampled.
    fn cell(&self, ca: [usize; 3], cb: [usize; 3]) -> (Part, Option<(usize, usize)>) {
        let k = self.k;
        let ia = self.dense_a[(ca[0] * k + ca[1]) * k + ca[2]];
        let ib = self.dense_b[(cb[0] * k + cb[1]) * k + cb[2]];
        if ia == NONE || ib == NONE {
            return (Part::DontCare, None);
        }
        let (ia, ib) = (ia as usize, ib as usize);
        let part = match self.view.label(ia, ib) {
            Label::Free => Part::Free,
            Label::Collision => Part::Collision,
            Label::Unreachable => Part::DontCare,
        };
        (part, Some((ia, ib)))
    }

    /// The part of one cell pair cut into its 64 sub-cells ([`SubCells`]), merged with its
    /// mirror pair under symmetry as [`SpaceView::label`] merges labels (collision wins).
    fn subdivided_cell(&mut self, ca: [usize; 3], cb: [usize; 3]) -> Part {
        let (part, Some((ia, ib))) = self.cell(ca, cb) else { return Part::DontCare };
        if part != Part::Collision {
            return part;
        }
        let (mut care, mut value) = self.sub_masks(ia, ib);
        if let Some((ma, mb)) = self.view.mirror_pair(ia, ib) {
            let (c, v) = self.sub_masks(ma, mb);
            (care, value) = (care | mirror_sub_cells(c), value | mirror_sub_cells(v));
        }
        self.leaf(care, value)
    }

    /// `(care, collision)` of the sub-cells of one pair, by its own label.
    fn sub_masks(&self, ia: usize, ib: usize) -> (u64, u64) {
        match self.view.own_label(ia, ib) {
            Label::Free => (u64::MAX, 0),
            Label::Unreachable => (0, 0),
            Label::Collision => {
                let pair = (ia * self.view.space.grid_b.cells.len() + ib) as u64;
                self.sub.and_then(|s| s.get(pair)).unwrap_or((u64::MAX, u64::MAX))
            }
        }
    }

    /// An inner node of depth `d` with these children (hash-consed), or the uniform part.
    fn node(&mut self, d: usize, kids: &[Part; 64]) -> Part {
        let has = |p: Part| kids.contains(&p);
        let nodes = kids.iter().any(|p| matches!(p, Part::Node(_)));
        match (has(Part::Free), has(Part::Collision), nodes) {
            (false, false, false) => return Part::DontCare,
            (true, false, false) => return Part::Free,
            (false, true, false) => return Part::Collision,
            _ => {}
        }
        let (mut nonuniform, mut collision, mut ids) = (0u64, 0u64, Vec::new());
        for (i, p) in kids.iter().enumerate() {
            match *p {
                Part::Node(id) => {
                    nonuniform |= 1 << i;
                    ids.push(id);
                }
                Part::Collision => collision |= 1 << i,
                Part::Free | Part::DontCare => {}
            }
        }
        let key = (nonuniform, collision, ids);
        if let Some(&id) = self.inner[d].get(&key) {
            return Part::Node(id);
        }
        let id = self.inner_nodes[d].len() as u32;
        self.inner_nodes[d].push(key.clone());
        self.inner[d].insert(key, id);
        Part::Node(id)
    }

    /// A leaf of 64 cells, `care` the cells that are not "don't care" and `value` the
    /// collisions among them (hash-consed; see the module doc for the don't-care choice).
    fn leaf(&mut self, care: u64, value: u64) -> Part {
        let value = value & care;
        if care == 0 {
            return Part::DontCare;
        }
        if value == 0 {
            return Part::Free;
        }
        if value == care {
            return Part::Collision;
        }
        for candidate in [value, value | !care] {
            if let Some(&id) = self.leaf_ids.get(&candidate) {
                return Part::Node(id);
            }
        }
        let id = self.leaves.len() as u32;
        self.leaves.push(value);
        self.leaf_ids.insert(value, id);
        Part::Node(id)
    }
}

/// A sub-cell mask of a pair mapped to its mirror pair's (`y -> -y` flips the y octant bit of
/// both robots: child index bits 4 and 1).
#[cfg(feature = "std")]
fn mirror_sub_cells(mask: u64) -> u64 {
    (0..64).filter(|&c| mask >> c & 1 == 1).fold(0, |m, c| m | 1 << (c ^ 0b01_0010))
}

impl SharedQuadtree6d {
    /// Builds the table of `space` (see the module doc); with `symmetric`, only A's upper
    /// half `iy >= k/2` is stored, as the other variants do.
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ or are not `2^levels` with
    /// `2 <= levels <= MAX_LEVELS`, or the label count is wrong.
    #[cfg(feature = "std")]
    pub fn build(space: &LabelledSpace, symmetric: bool) -> Result<SharedQuadtree6d, TableError> {
        Self::build_with(space, None, symmetric)
    }

    /// As [`build`](Self::build) with every pair labelled collision cut into the sub-cells of
    /// `sub` ([`crate::cspace::label_space_subdivided`]): one more level, queried with cell
    /// indices at `2 k` per axis.
    ///
    /// # Errors
    /// As [`build`](Self::build).
    #[cfg(feature = "std")]
    pub fn build_subdivided(
        space: &LabelledSpace,
        sub: &SubCells,
        symmetric: bool,
    ) -> Result<SharedQuadtree6d, TableError> {
        Self::build_with(space, Some(sub), symmetric)
    }

    #[cfg(feature = "std")]
    fn build_with(
        space: &LabelledSpace,
        sub: Option<&SubCells>,
        symmetric: bool,
    ) -> Result<SharedQuadtree6d, TableError> {
        let view = SpaceView::new(space, symmetric)?;
        let levels = view.levels;
        let sub_levels = u32::from(sub.is_some());
        if levels < 2 || levels + sub_levels > MAX_LEVELS {
            return Err(bad_input(format!(
                "the shared 6-D quadtree needs 4 <= k <= 2^{MAX_LEVELS}, got k = {}",
                view.k
            )));
        }
        let k = view.k as usize;
        let dense_a = dense_map(&space.grid_a.cells, k, |ia| view.stored(ia));
        let dense_b = dense_map(&space.grid_b.cells, k, |_| true);
        let (occ_a, occ_b) = (occupancy(&dense_a, k, levels), occupancy(&dense_b, k, levels));
        let inner_depths = (levels + sub_levels) as usize - 1;
        let mut b = Builder {
            view,
            sub,
            k,
            dense_a,
            dense_b,
            occ_a,
            occ_b,
            inner: vec![HashMap::new(); inner_depths],
            inner_nodes: vec![Vec::new(); inner_depths],
            leaf_ids: HashMap::new(),
            leaves: Vec::new(),
        };
        let root = b.build(0, [0; 3], [0; 3]);
        let (mut masks, mut bases, mut depth_start, mut children) = (vec![], vec![], vec![], vec![]);
        match root {
            // A uniform root is stored as one node with every child uniform.
            Part::Node(_) => {}
            Part::Collision => b.inner_nodes[0].push((0, u64::MAX, vec![])),
            Part::Free | Part::DontCare => b.inner_nodes[0].push((0, 0, vec![])),
        }
        // Depth 0 now holds exactly the root.
        for nodes in &b.inner_nodes {
            depth_start.push(masks.len() as u32);
            for (nonuniform, collision, ids) in nodes {
                masks.push([*nonuniform, *collision]);
                bases.push(children.len() as u32);
                children.extend_from_slice(ids);
            }
        }
        depth_start.push(masks.len() as u32);
        Ok(Self::assemble(levels, sub_levels, symmetric, (masks, bases, depth_start, children, b.leaves)))
    }

    /// The table of valid arrays, laid out for the query.
    fn assemble(levels: u32, sub_levels: u32, symmetric: bool, arrays: pool::Arrays) -> SharedQuadtree6d {
        let pool = pool::Pool::new(levels + sub_levels, symmetric, &arrays);
        SharedQuadtree6d { levels, sub_levels, symmetric, pool }
    }

    /// A table from stored parts, validated so that [`query`](Self::query) never reads out of
    /// bounds: `depth_start` has `levels` increasing entries from 0 with one root, masks are
    /// disjoint, every node's children lie in the pool right after the previous node's (bases
    /// are the running counts, as `build` writes them and [`parts`](Self::parts) gives them
    /// back), and every child index names a node of the next depth (or a leaf).
    ///
    /// # Errors
    /// [`TableError::Corrupt`] naming the first bad field.
    #[allow(clippy::too_many_arguments)] // one per stored array, as the file holds them
    pub fn from_parts(
        levels: u32,
        sub_levels: u32,
        symmetric: bool,
        masks: Vec<[u64; 2]>,
        bases: Vec<u32>,
        depth_start: Vec<u32>,
        children: Vec<u32>,
        leaves: Vec<u64>,
    ) -> Result<SharedQuadtree6d, TableError> {
        if levels < 2 || sub_levels > 1 || levels + sub_levels > MAX_LEVELS {
            return Err(corrupt(format!(
                "levels = {levels}, sub-levels = {sub_levels}: need levels >= 2, sub-levels 0 or 1, at most {MAX_LEVELS} in all"
            )));
        }
        let depths = (levels + sub_levels) as usize - 1;
        if depth_start.len() != depths + 1 {
            return Err(corrupt(format!("depth_start has {} entries, expected {}", depth_start.len(), depths + 1)));
        }
        if depth_start[0] != 0 || depth_start[1] != 1 {
            return Err(corrupt("depth 0 must hold exactly the root"));
        }
        if depth_start.windows(2).any(|w| w[0] > w[1]) || depth_start[depths] as usize != masks.len() {
            return Err(corrupt("depth_start is not increasing up to the node count"));
        }
        if bases.len() != masks.len() {
            return Err(corrupt(format!("{} bases for {} nodes", bases.len(), masks.len())));
        }
        // The running count of non-uniform children: each node's base (the query layout
        // keeps no bases, and the parts read back from it must be the bytes loaded).
        let mut count = 0usize;
        for d in 0..depths {
            let next = if d + 1 < depths { depth_start[d + 2] - depth_start[d + 1] } else { leaves.len() as u32 };
            for node in depth_start[d] as usize..depth_start[d + 1] as usize {
                let [nonuniform, collision] = masks[node];
                if nonuniform & collision != 0 {
                    return Err(corrupt(format!("node {node}: a child is both uniform collision and a node")));
                }
                let (base, n) = (bases[node] as usize, nonuniform.count_ones() as usize);
                if base != count {
                    return Err(corrupt(format!(
                        "node {node}: children start at {base}, not at {count} (the non-uniform children before it)"
                    )));
                }
                count += n;
                let Some(ids) = children.get(base..base + n) else {
                    return Err(corrupt(format!("node {node}: children {base}..{} outside the pool", base + n)));
                };
                if let Some(id) = ids.iter().find(|&&id| id >= next) {
                    return Err(corrupt(format!("node {node}: child index {id} >= {next} nodes of depth {}", d + 1)));
                }
            }
        }
        if children.len() != count {
            return Err(corrupt(format!("{} child indices for {count} non-uniform children", children.len())));
        }
        Ok(Self::assemble(levels, sub_levels, symmetric, (masks, bases, depth_start, children, leaves)))
    }

    /// Whether the 6-D cell is stored as collision, its indices at `2^(levels + sub_levels)`
    /// per axis (`true` for an index beyond). Reads one top-table slot, then per node step one
    /// record, then one leaf: at most `2 (levels + sub_levels) - 4` dependent reads (one for a
    /// 2-level grid); never allocates, never panics on a validated table.
    #[inline]
    pub fn query(&self, cell: [u16; 6]) -> bool {
        let fine = self.levels + self.sub_levels;
        match fold(cell, 1 << fine, self.symmetric) {
            Some(c) => self.pool.query(&c, fine),
            None => true,
        }
    }

    /// The answer of [`query`](Self::query) and every table read it makes, in order, as
    /// `(address, bytes, step)`: reads of one step depend only on earlier steps, so a query
    /// waits for at most one memory access per step. For benchmarks that count cache lines
    /// and dependent loads per query; allocates, not the per-tick path.
    pub fn query_reads(&self, cell: [u16; 6]) -> (bool, Vec<(usize, usize, u32)>) {
        let fine = self.levels + self.sub_levels;
        match fold(cell, 1 << fine, self.symmetric) {
            Some(c) => self.pool.query_reads(&c, fine),
            None => (true, vec![]),
        }
    }

    /// Quadtree levels (`k = 2^levels`).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// Extra levels of sub-cells: [`query`](Self::query) takes cell indices at
    /// `2^(levels + sub_levels)` per axis.
    pub fn sub_levels(&self) -> u32 {
        self.sub_levels
    }

    /// Whether only A's upper half is stored.
    pub fn symmetric(&self) -> bool {
        self.symmetric
    }

    /// The stored arrays (as [`from_parts`](Self::from_parts) takes them and the file holds
    /// them), read back from the query layout; allocates.
    pub fn parts(&self) -> SharedParts {
        let (masks, bases, depth_start, children, leaves) = self.pool.arrays();
        SharedParts { masks, bases, depth_start, children: ChildIndices::from_u32(children), leaves }
    }

    /// Inner nodes per depth, then the leaf count.
    pub fn nodes_per_depth(&self) -> Vec<usize> {
        self.pool.nodes_per_depth()
    }

    /// Bits per child slot of the query layout, per inner depth: 16, or 32 where an offset
    /// into the next depth does not fit.
    pub fn slot_bits(&self) -> Vec<u32> {
        self.pool.slot_bits()
    }

    /// The address and byte length of the one array a query reads (for benchmarks that flush
    /// it from the caches).
    pub fn memory_region(&self) -> (usize, usize) {
        let w = self.pool.words();
        (w.as_ptr() as usize, core::mem::size_of_val(w))
    }

    /// Bytes this table occupies in memory (struct plus its array).
    pub fn memory_bytes(&self) -> usize {
        core::mem::size_of::<Self>() + core::mem::size_of_val(self.pool.words())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::synthetic::{space, Pattern};
    use crate::table::LinearQuadtree6d;

    /// The table rebuilt from its own parts (as a file load does).
    fn round_trip(t: &SharedQuadtree6d) -> SharedQuadtree6d {
        let p = t.parts();
        let (masks, bases, starts, leaves) =
            (p.masks.to_vec(), p.bases.to_vec(), p.depth_start.to_vec(), p.leaves.to_vec());
        SharedQuadtree6d::from_parts(
            t.levels,
            t.sub_levels,
            t.symmetric,
            masks,
            bases,
            starts,
            p.children.to_u32(),
            leaves,
        )
        .unwrap()
    }

    /// Every free and collision sample is answered exactly, as the 6-D linear quadtree does.
    #[test]
    fn answers_every_sample_as_the_labels_and_the_6d_table() {
        let cases = [
            (Pattern::Blobs, 2, false),
            (Pattern::Blobs, 4, true),
            (Pattern::Blobs, 5, true),
            (Pattern::Noise { p: 0.3, seed: 1 }, 3, true),
            (Pattern::AsymmetricNoise { p: 0.1, seed: 2 }, 4, false),
            (Pattern::AsymmetricNoise { p: 0.1, seed: 3 }, 3, true),
            (Pattern::AllFree, 3, true),
            (Pattern::AllCollision, 3, false),
        ];
        for (seed, (pattern, levels, symmetric)) in cases.into_iter().enumerate() {
            let space = space(levels, pattern);
            let shared = SharedQuadtree6d::build(&space, symmetric).unwrap();
            let d6 = LinearQuadtree6d::build(&space, symmetric).unwrap();
            let view = SpaceView::new(&space, symmetric).unwrap();
            let (ga, gb) = (&space.grid_a, &space.grid_b);
            for (ia, ca) in ga.cells.iter().enumerate().filter(|&(ia, _)| view.stored(ia)) {
                for (ib, cb) in gb.cells.iter().enumerate() {
                    let cell = [ca[0], ca[1], ca[2], cb[0], cb[1], cb[2]];
                    assert_eq!(shared.query_reads(cell).0, shared.query(cell), "{seed}: {cell:?} traced");
                    match view.label(ia, ib) {
                        Label::Free => assert!(!shared.query(cell) && !d6.query(cell), "{seed}: {cell:?} free"),
                        Label::Collision => assert!(shared.query(cell) && d6.query(cell), "{seed}: {cell:?} collision"),
                        Label::Unreachable => {}
                    }
                }
            }
            assert_eq!(round_trip(&shared), shared);
        }
    }

    /// Sub-cells of every collision pair from a seeded hash (some "don't care").
    fn random_sub_cells(space: &LabelledSpace, seed: u64) -> SubCells {
        let mut out = SubCells::default();
        let mut x = seed;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            x ^ x >> 29
        };
        for (pair, &l) in space.labels.iter().enumerate() {
            if l == Label::Collision {
                let care = next() | next();
                out.pairs.push(pair as u64);
                out.care.push(care);
                out.collision.push(match pair % 3 {
                    0 => care,
                    1 => next() & care,
                    _ => next() & next() & care,
                });
            }
        }
        out
    }

    /// With sub-cells, every sub-cell that is free or collision in its pair and in its mirror
    /// pair's merge is answered exactly at the fine indices, and coarse free cells stay free.
    #[test]
    fn subdivided_table_answers_every_sub_cell() {
        for (pattern, levels, symmetric) in
            [(Pattern::Blobs, 3, false), (Pattern::Blobs, 4, true), (Pattern::Noise { p: 0.2, seed: 9 }, 3, true)]
        {
            let space = space(levels, pattern);
            let sub = random_sub_cells(&space, u64::from(levels));
            let t = SharedQuadtree6d::build_subdivided(&space, &sub, symmetric).unwrap();
            assert_eq!(t.sub_levels(), 1);
            let view = SpaceView::new(&space, symmetric).unwrap();
            let nb = space.grid_b.cells.len();
            let masks = |ia: usize, ib: usize| match view.own_label(ia, ib) {
                Label::Free => (u64::MAX, 0),
                Label::Unreachable => (0, 0),
                Label::Collision => sub.get((ia * nb + ib) as u64).unwrap(),
            };
            let (mut checked, mut free, mut hit) = (0, 0, 0);
            for (ia, ca) in space.grid_a.cells.iter().enumerate().filter(|&(ia, _)| view.stored(ia)) {
                for (ib, cb) in space.grid_b.cells.iter().enumerate() {
                    let (mut care, mut coll) = masks(ia, ib);
                    if let Some((ma, mb)) = view.mirror_pair(ia, ib) {
                        let (c, v) = masks(ma, mb);
                        (care, coll) = (care | mirror_sub_cells(c), coll | mirror_sub_cells(v));
                    }
                    for c in 0..64u32 {
                        if care >> c & 1 == 0 {
                            continue;
                        }
                        let bit = |j: u32| (c >> (5 - j) & 1) as u16;
                        let fine = [
                            2 * ca[0] + bit(0),
                            2 * ca[1] + bit(1),
                            2 * ca[2] + bit(2),
                            2 * cb[0] + bit(3),
                            2 * cb[1] + bit(4),
                            2 * cb[2] + bit(5),
                        ];
                        let want = coll >> c & 1 == 1;
                        assert_eq!(t.query(fine), want, "{pattern:?}: pair ({ia}, {ib}) sub-cell {c}");
                        checked += 1;
                        free += usize::from(!want);
                        hit += usize::from(want);
                    }
                }
            }
            assert!(free > 0 && hit > 0, "{pattern:?}: {checked} checked, {free} free, {hit} collision");
            // The file round trip keeps the sub-level.
            assert_eq!(round_trip(&t), t);
        }
    }

    #[test]
    fn mirror_of_sub_cells_flips_both_y_octant_bits() {
        use crate::cspace::certify::sub_cell_index;
        for i in 0..8 {
            for j in 0..8 {
                let m = mirror_sub_cells(1 << sub_cell_index(i, j));
                assert_eq!(m, 1 << sub_cell_index(i ^ 2, j ^ 2));
            }
        }
    }

    #[test]
    fn out_of_range_cells_are_collisions() {
        let space = space(3, Pattern::Blobs);
        let t = SharedQuadtree6d::build(&space, false).unwrap();
        assert!(t.query([8, 0, 0, 0, 0, 0]));
        assert!(t.query([0, 0, 0, 0, 0, u16::MAX]));
    }

    #[test]
    fn malformed_parts_are_rejected() {
        let space = space(3, Pattern::Noise { p: 0.2, seed: 4 });
        let t = SharedQuadtree6d::build(&space, false).unwrap();
        let p = t.parts();
        let (m, b, ds, c, l) =
            (p.masks.to_vec(), p.bases.to_vec(), p.depth_start.to_vec(), p.children.to_u32(), p.leaves.to_vec());
        let ok = |m: Vec<[u64; 2]>, b: Vec<u32>, ds: Vec<u32>, c: Vec<u32>, l: Vec<u64>| {
            SharedQuadtree6d::from_parts(3, 0, false, m, b, ds, c, l).is_ok()
        };
        assert!(ok(m.clone(), b.clone(), ds.clone(), c.clone(), l.clone()));
        assert!(!ok(m.clone(), b.clone(), ds.clone(), c.clone(), vec![]), "children point past the leaves");
        assert!(!ok(m.clone(), b.clone(), ds.clone(), vec![], l.clone()), "empty pool");
        assert!(!ok(m.clone(), b.clone(), vec![0, 1], c.clone(), l.clone()), "depth_start too short");
        let mut both = m.clone();
        both[0][1] |= both[0][0];
        assert!(!ok(both, b.clone(), ds.clone(), c.clone(), l.clone()), "overlapping masks");
        let mut far = b.clone();
        far[0] = u32::MAX;
        assert!(!ok(m.clone(), far, ds.clone(), c.clone(), l.clone()), "base past the pool");
        let mut shifted = b.clone();
        *shifted.last_mut().unwrap() -= 1;
        assert!(!ok(m.clone(), shifted, ds.clone(), c.clone(), l.clone()), "bases not the running counts");
        let mut longer = c.clone();
        longer.push(0);
        assert!(!ok(m, b, ds, longer, l), "an unused child index");
    }
}
