//! The shared 6-D quadtree: the 6-D quadtree of the labels with identical subtrees stored
//! once (a directed acyclic graph), queried by a descent of at most `levels` nodes (issue 4;
//! beyond the thesis: its chapter 4 and 3.2.3 suggest exploiting repetition and hashing
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
//! At most `levels - 1` inner nodes and one leaf are read, each one `[u64; 2]` mask pair plus
//! one base and one child index: no search, no loop whose length depends on the data, no
//! allocation. Child indices are `u16` when every index fits, else `u32`.

use super::code::MAX_LEVELS;
use super::error::{bad_input, corrupt, TableError};
use super::space::{fold, SpaceView};
use crate::cspace::{Label, LabelledSpace};
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

    /// Entry `i` (the caller keeps `i` in bounds).
    #[inline]
    fn get(&self, i: usize) -> usize {
        match self {
            ChildIndices::Narrow(v) => usize::from(v[i]),
            ChildIndices::Wide(v) => v[i] as usize,
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

    fn bytes_per_entry(&self) -> usize {
        match self {
            ChildIndices::Narrow(_) => 2,
            ChildIndices::Wide(_) => 4,
        }
    }
}

/// The arrays of a [`SharedQuadtree6d`] (see its fields).
#[derive(Clone, Copy, Debug)]
pub struct SharedParts<'a> {
    /// Inner nodes, depth by depth: `[nonuniform, collision]`.
    pub masks: &'a [[u64; 2]],
    /// Per inner node: where its non-uniform children start in `children`.
    pub bases: &'a [u32],
    /// First node of each depth, then the node count.
    pub depth_start: &'a [u32],
    /// Child indices.
    pub children: &'a ChildIndices,
    /// Leaves.
    pub leaves: &'a [u64],
}

/// The shared 6-D quadtree (see the module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SharedQuadtree6d {
    levels: u32,
    symmetric: bool,
    /// Inner nodes, depth by depth (the root is node 0): `[nonuniform, collision]`.
    masks: Vec<[u64; 2]>,
    /// Per inner node: where its non-uniform children start in `children`.
    bases: Vec<u32>,
    /// Index of the first node of each depth `0..levels-1` in `masks`, then `masks.len()`.
    depth_start: Vec<u32>,
    /// Per non-uniform child: the index of the child node within its depth (inner nodes) or
    /// in `leaves` (children of depth `levels - 2`).
    children: ChildIndices,
    /// Leaves: bit `i` is child cell `i`.
    leaves: Vec<u64>,
}

/// The 6-bit child index of `c` at bit `shift` of every coordinate.
#[inline]
fn child_index(c: &[u16; 6], shift: u32) -> u32 {
    c.iter().fold(0, |i, &v| i << 1 | (u32::from(v) >> shift & 1))
}

/// An inner node while building: non-uniform mask, collision mask, child ids.
type InnerNode = (u64, u64, Vec<u32>);

/// A child while building: don't care, uniform, or a stored node of the next depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Part {
    DontCare,
    Free,
    Collision,
    Node(u32),
}

/// Hash-consing builder over a [`SpaceView`].
struct Builder<'a> {
    view: SpaceView<'a>,
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

const NONE: u32 = u32::MAX;

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

impl Builder<'_> {
    /// The part for the 6-D block at depth `d` whose per-robot block coordinates are `a`, `b`
    /// (in units of the block side).
    fn build(&mut self, d: u32, a: [usize; 3], b: [usize; 3]) -> Part {
        let n = 1usize << d;
        let at = |c: [usize; 3]| (c[0] * n + c[1]) * n + c[2];
        if !self.occ_a[d as usize][at(a)] || !self.occ_b[d as usize][at(b)] {
            return Part::DontCare;
        }
        let levels = self.view.levels;
        if d == levels - 1 {
            return self.leaf(a, b);
        }
        let mut kids = [Part::DontCare; 64];
        for (i, kid) in kids.iter_mut().enumerate() {
            let bit = |j: usize| (i >> (5 - j)) & 1;
            let ca = [2 * a[0] + bit(0), 2 * a[1] + bit(1), 2 * a[2] + bit(2)];
            let cb = [2 * b[0] + bit(3), 2 * b[1] + bit(4), 2 * b[2] + bit(5)];
            *kid = self.build(d + 1, ca, cb);
        }
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
        let depth = d as usize;
        if let Some(&id) = self.inner[depth].get(&key) {
            return Part::Node(id);
        }
        let id = self.inner_nodes[depth].len() as u32;
        self.inner_nodes[depth].push(key.clone());
        self.inner[depth].insert(key, id);
        Part::Node(id)
    }

    /// The 2x2x2 x 2x2x2 block of cells at per-robot leaf-block coordinates `a`, `b`.
    fn leaf(&mut self, a: [usize; 3], b: [usize; 3]) -> Part {
        let k = self.k;
        let (mut care, mut value) = (0u64, 0u64);
        for i in 0..64usize {
            let bit = |j: usize| (i >> (5 - j)) & 1;
            let ca = [2 * a[0] + bit(0), 2 * a[1] + bit(1), 2 * a[2] + bit(2)];
            let cb = [2 * b[0] + bit(3), 2 * b[1] + bit(4), 2 * b[2] + bit(5)];
            let ia = self.dense_a[(ca[0] * k + ca[1]) * k + ca[2]];
            let ib = self.dense_b[(cb[0] * k + cb[1]) * k + cb[2]];
            if ia == NONE || ib == NONE {
                continue;
            }
            match self.view.label(ia as usize, ib as usize) {
                Label::Free => care |= 1 << i,
                Label::Collision => {
                    care |= 1 << i;
                    value |= 1 << i;
                }
                Label::Unreachable => {}
            }
        }
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

impl SharedQuadtree6d {
    /// Builds the table of `space` (see the module doc); with `symmetric`, only A's upper
    /// half `iy >= k/2` is stored, as the other variants do.
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ or are not `2^levels` with
    /// `2 <= levels <= MAX_LEVELS`, or the label count is wrong.
    pub fn build(space: &LabelledSpace, symmetric: bool) -> Result<SharedQuadtree6d, TableError> {
        let view = SpaceView::new(space, symmetric)?;
        let levels = view.levels;
        if levels < 2 {
            return Err(bad_input(format!("the shared 6-D quadtree needs k >= 4, got k = {}", view.k)));
        }
        let k = view.k as usize;
        let dense_a = dense_map(&space.grid_a.cells, k, |ia| view.stored(ia));
        let dense_b = dense_map(&space.grid_b.cells, k, |_| true);
        let (occ_a, occ_b) = (occupancy(&dense_a, k, levels), occupancy(&dense_b, k, levels));
        let inner_depths = levels as usize - 1;
        let mut b = Builder {
            view,
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
        let t = SharedQuadtree6d {
            levels,
            symmetric,
            masks,
            bases,
            depth_start,
            children: ChildIndices::from_u32(children),
            leaves: b.leaves,
        };
        Ok(t)
    }

    /// A table from stored parts, validated so that [`query`](Self::query) never reads out of
    /// bounds: `depth_start` has `levels` increasing entries from 0 with one root, masks are
    /// disjoint, every node's children lie in the pool, and every child index names a node of
    /// the next depth (or a leaf).
    ///
    /// # Errors
    /// [`TableError::Corrupt`] naming the first bad field.
    pub fn from_parts(
        levels: u32,
        symmetric: bool,
        masks: Vec<[u64; 2]>,
        bases: Vec<u32>,
        depth_start: Vec<u32>,
        children: Vec<u32>,
        leaves: Vec<u64>,
    ) -> Result<SharedQuadtree6d, TableError> {
        if !(2..=MAX_LEVELS).contains(&levels) {
            return Err(corrupt(format!("levels = {levels} must be in 2..={MAX_LEVELS} for the shared 6-D quadtree")));
        }
        let depths = levels as usize - 1;
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
        for d in 0..depths {
            let next = if d + 1 < depths { depth_start[d + 2] - depth_start[d + 1] } else { leaves.len() as u32 };
            for node in depth_start[d] as usize..depth_start[d + 1] as usize {
                let [nonuniform, collision] = masks[node];
                if nonuniform & collision != 0 {
                    return Err(corrupt(format!("node {node}: a child is both uniform collision and a node")));
                }
                let (base, n) = (bases[node] as usize, nonuniform.count_ones() as usize);
                let Some(ids) = children.get(base..base + n) else {
                    return Err(corrupt(format!("node {node}: children {base}..{} outside the pool", base + n)));
                };
                if let Some(id) = ids.iter().find(|&&id| id >= next) {
                    return Err(corrupt(format!("node {node}: child index {id} >= {next} nodes of depth {}", d + 1)));
                }
            }
        }
        let children = ChildIndices::from_u32(children);
        Ok(SharedQuadtree6d { levels, symmetric, masks, bases, depth_start, children, leaves })
    }

    /// Whether the 6-D cell is stored as collision (`true` for an index `>= k`). Reads at most
    /// `levels - 1` nodes and one leaf; never allocates, never panics on a validated table.
    #[inline]
    pub fn query(&self, cell: [u16; 6]) -> bool {
        let Some(c) = fold(cell, 1 << self.levels, self.symmetric) else {
            return true;
        };
        let mut node = 0usize;
        let depths = self.levels - 1;
        for d in 0..depths {
            let bit = 1u64 << child_index(&c, self.levels - 1 - d);
            let [nonuniform, collision] = self.masks[node];
            if nonuniform & bit == 0 {
                return collision & bit != 0;
            }
            let rank = (nonuniform & (bit - 1)).count_ones() as usize;
            let child = self.children.get(self.bases[node] as usize + rank);
            node = if d + 1 < depths { self.depth_start[d as usize + 1] as usize + child } else { child };
        }
        self.leaves[node] >> child_index(&c, 0) & 1 == 1
    }

    /// Quadtree levels (`k = 2^levels`).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// Whether only A's upper half is stored.
    pub fn symmetric(&self) -> bool {
        self.symmetric
    }

    /// The stored arrays (as [`from_parts`](Self::from_parts) takes them).
    pub fn parts(&self) -> SharedParts<'_> {
        SharedParts {
            masks: &self.masks,
            bases: &self.bases,
            depth_start: &self.depth_start,
            children: &self.children,
            leaves: &self.leaves,
        }
    }

    /// Inner nodes per depth, then the leaf count.
    pub fn nodes_per_depth(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self.depth_start.windows(2).map(|w| (w[1] - w[0]) as usize).collect();
        v.push(self.leaves.len());
        v
    }

    /// Bytes this table occupies in memory (struct plus its arrays).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + 16 * self.masks.len()
            + 4 * (self.bases.len() + self.depth_start.len())
            + self.children.bytes_per_entry() * self.children.len()
            + 8 * self.leaves.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::synthetic::{space, Pattern};
    use crate::table::LinearQuadtree6d;

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
                    match view.label(ia, ib) {
                        Label::Free => assert!(!shared.query(cell) && !d6.query(cell), "{seed}: {cell:?} free"),
                        Label::Collision => assert!(shared.query(cell) && d6.query(cell), "{seed}: {cell:?} collision"),
                        Label::Unreachable => {}
                    }
                }
            }
            let p = shared.parts();
            let again = SharedQuadtree6d::from_parts(
                levels,
                symmetric,
                p.masks.to_vec(),
                p.bases.to_vec(),
                p.depth_start.to_vec(),
                p.children.to_u32(),
                p.leaves.to_vec(),
            )
            .unwrap();
            assert_eq!(again, shared);
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
            SharedQuadtree6d::from_parts(3, false, m, b, ds, c, l).is_ok()
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
        assert!(!ok(m, far, ds, c, l), "base past the pool");
    }
}
