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

//!
//! This file holds the table and its query; the builder is in `build.rs` and the query's
//! layout in `pool.rs`.

#[cfg(feature = "std")]
mod build;
mod pool;

#[cfg(feature = "std")]
pub(crate) use build::SubCellBlocks;

use super::code::MAX_LEVELS;
use super::error::{corrupt, TableError};
use super::space::fold;
#[cfg(any(test, feature = "eval"))]
use alloc::vec;
use alloc::{format, vec::Vec};

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

impl SharedQuadtree6d {
    /// The table of valid arrays, laid out for the query.
    fn assemble(
        levels: u32,
        sub_levels: u32,
        symmetric: bool,
        arrays: pool::Arrays,
    ) -> SharedQuadtree6d {
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
            return Err(corrupt(format!(
                "depth_start has {} entries, expected {}",
                depth_start.len(),
                depths + 1
            )));
        }
        if depth_start[0] != 0 || depth_start[1] != 1 {
            return Err(corrupt("depth 0 must hold exactly the root"));
        }
        if depth_start.windows(2).any(|w| w[0] > w[1])
            || depth_start[depths] as usize != masks.len()
        {
            return Err(corrupt("depth_start is not increasing up to the node count"));
        }
        if bases.len() != masks.len() {
            return Err(corrupt(format!("{} bases for {} nodes", bases.len(), masks.len())));
        }
        // The running count of non-uniform children: each node's base (the query layout
        // keeps no bases, and the parts read back from it must be the bytes loaded).
        let mut count = 0usize;
        for d in 0..depths {
            let next = if d + 1 < depths {
                depth_start[d + 2] - depth_start[d + 1]
            } else {
                leaves.len() as u32
            };
            for node in depth_start[d] as usize..depth_start[d + 1] as usize {
                let [nonuniform, collision] = masks[node];
                if nonuniform & collision != 0 {
                    return Err(corrupt(format!(
                        "node {node}: a child is both uniform collision and a node"
                    )));
                }
                let (base, n) = (bases[node] as usize, nonuniform.count_ones() as usize);
                if base != count {
                    return Err(corrupt(format!(
                        "node {node}: children start at {base}, not at {count} (the non-uniform children before it)"
                    )));
                }
                count += n;
                let Some(ids) = children.get(base..base + n) else {
                    return Err(corrupt(format!(
                        "node {node}: children {base}..{} outside the pool",
                        base + n
                    )));
                };
                if let Some(id) = ids.iter().find(|&&id| id >= next) {
                    return Err(corrupt(format!(
                        "node {node}: child index {id} >= {next} nodes of depth {}",
                        d + 1
                    )));
                }
            }
        }
        if children.len() != count {
            return Err(corrupt(format!(
                "{} child indices for {count} non-uniform children",
                children.len()
            )));
        }
        Ok(Self::assemble(
            levels,
            sub_levels,
            symmetric,
            (masks, bases, depth_start, children, leaves),
        ))
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

    /// The stored word of the grid cell `cell` (indices at `2^levels`, every sub-cell of it
    /// alike: a table whose sub-cell bits are not places but a per-cell value, as a clearance
    /// table's are): a leaf, or `u64::MAX` / 0 for a uniform collision / free block, and
    /// `u64::MAX` for an index beyond. The reads of [`query`](Self::query).
    #[inline]
    pub(crate) fn query_word(&self, cell: [u16; 6]) -> u64 {
        let fine = self.levels + self.sub_levels;
        match fold(cell, 1 << self.levels, self.symmetric) {
            Some(c) => self.pool.query_word(&c.map(|v| v << self.sub_levels), fine),
            None => u64::MAX,
        }
    }

    /// The answer of [`query`](Self::query) and every table read it makes, in order, as
    /// `(address, bytes, step)`: reads of one step depend only on earlier steps, so a query
    /// waits for at most one memory access per step. For the report tool, which counts cache
    /// lines and dependent loads per query; allocates, not the per-tick path.
    #[cfg(any(test, feature = "eval"))]
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
        SharedParts {
            masks,
            bases,
            depth_start,
            children: ChildIndices::from_u32(children),
            leaves,
        }
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
    use crate::cspace::{Label, LabelledSpace, SubCells, Symmetry};
    use crate::table::space::SpaceView;
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
            let shared = SharedQuadtree6d::build(&space, Symmetry::from_flag(symmetric)).unwrap();
            let d6 = LinearQuadtree6d::build(&space, Symmetry::from_flag(symmetric)).unwrap();
            let view = SpaceView::new(&space, symmetric).unwrap();
            let (ga, gb) = (&space.grid_a, &space.grid_b);
            for (ia, ca) in ga.cells.iter().enumerate().filter(|&(ia, _)| view.stored(ia)) {
                for (ib, cb) in gb.cells.iter().enumerate() {
                    let cell = [ca[0], ca[1], ca[2], cb[0], cb[1], cb[2]];
                    assert_eq!(
                        shared.query_reads(cell).0,
                        shared.query(cell),
                        "{seed}: {cell:?} traced"
                    );
                    match view.label(ia, ib) {
                        Label::Free => {
                            assert!(!shared.query(cell) && !d6.query(cell), "{seed}: {cell:?} free")
                        }
                        Label::Collision => assert!(
                            shared.query(cell) && d6.query(cell),
                            "{seed}: {cell:?} collision"
                        ),
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
        let mut rng = crate::test_rng::TestRng(seed.max(1));
        let mut next = || rng.next_u64();
        for (pair, l) in space.labels.iter().enumerate() {
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

    /// The synthetic spaces the subdivided tables are tested on: pattern, levels, symmetric.
    const SUBDIVIDED_SPACES: [(Pattern, u32, bool); 3] = [
        (Pattern::Blobs, 3, false),
        (Pattern::Blobs, 4, true),
        (Pattern::Noise { p: 0.2, seed: 9 }, 3, true),
    ];

    /// With sub-cells, every sub-cell that is free or collision in its pair is answered
    /// exactly at the fine indices, and, for a symmetric table, so is its mirror sub-cell (both
    /// robots' `y` reflected at `2 k`): a pair's sub-cells are its own, never merged with its
    /// mirror pair's, whose sub-cells a symmetric labelling does not find.
    #[test]
    fn subdivided_table_answers_every_sub_cell() {
        for (pattern, levels, symmetric) in SUBDIVIDED_SPACES {
            let space = space(levels, pattern);
            let sub = random_sub_cells(&space, u64::from(levels));
            let t =
                SharedQuadtree6d::build_subdivided(&space, &sub, Symmetry::from_flag(symmetric))
                    .unwrap();
            assert_eq!(t.sub_levels(), 1);
            let view = SpaceView::new(&space, symmetric).unwrap();
            let nb = space.grid_b.cells.len();
            let masks = |ia: usize, ib: usize| match view.own_label(ia, ib) {
                Label::Free => (u64::MAX, 0),
                Label::Unreachable => (0, 0),
                Label::Collision => sub.get((ia * nb + ib) as u64).unwrap(),
            };
            let (mut checked, mut free, mut hit) = (0, 0, 0);
            for (ia, ca) in space.grid_a.cells.iter().enumerate().filter(|&(ia, _)| view.stored(ia))
            {
                for (ib, cb) in space.grid_b.cells.iter().enumerate() {
                    let (care, coll) = masks(ia, ib);
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
                        assert_eq!(
                            t.query(fine),
                            want,
                            "{pattern:?}: pair ({ia}, {ib}) sub-cell {c}"
                        );
                        if symmetric {
                            let top = (2 << levels) - 1;
                            let mirror =
                                [fine[0], top - fine[1], fine[2], fine[3], top - fine[4], fine[5]];
                            assert_eq!(
                                t.query(mirror),
                                want,
                                "{pattern:?}: mirror of pair ({ia}, {ib}) sub-cell {c}"
                            );
                        }
                        checked += 1;
                        free += usize::from(!want);
                        hit += usize::from(want);
                    }
                }
            }
            assert!(
                free > 0 && hit > 0,
                "{pattern:?}: {checked} checked, {free} free, {hit} collision"
            );
            // The file round trip keeps the sub-level.
            assert_eq!(round_trip(&t), t);
        }
    }

    /// The sub-cells of a pair labelled collision, as a streamed build asks for them.
    struct Served<'a>(&'a SubCells);

    impl SubCellBlocks for Served<'_> {
        fn masks(&mut self, pairs: &[u64], _nb: usize) -> Vec<(u64, u64)> {
            pairs.iter().map(|&p| self.0.get(p).unwrap()).collect()
        }
    }

    /// A build whose sub-cells come block by block from a second thread, at every block
    /// depth, gives the table of the build that holds them all: the blocks come in the order
    /// the tree enters them, and the order of the leaves first stored (which decides the
    /// don't-care bits) is kept.
    #[test]
    fn streamed_blocks_give_the_table_of_all_sub_cells() {
        for (pattern, levels, symmetric) in SUBDIVIDED_SPACES {
            let space = space(levels, pattern);
            let sub = random_sub_cells(&space, u64::from(levels));
            let symmetry = Symmetry::from_flag(symmetric);
            let whole = SharedQuadtree6d::build_subdivided(&space, &sub, symmetry).unwrap();
            for depth in 0..=levels {
                let (t, _) =
                    SharedQuadtree6d::build_streamed(&space, &mut Served(&sub), depth, symmetry)
                        .unwrap();
                assert!(t == whole, "{pattern:?}, blocks at depth {depth}");
            }
        }
    }

    #[test]
    fn out_of_range_cells_are_collisions() {
        let space = space(3, Pattern::Blobs);
        let t = SharedQuadtree6d::build(&space, Symmetry::Whole).unwrap();
        assert!(t.query([8, 0, 0, 0, 0, 0]));
        assert!(t.query([0, 0, 0, 0, 0, u16::MAX]));
    }

    #[test]
    fn malformed_parts_are_rejected() {
        let space = space(3, Pattern::Noise { p: 0.2, seed: 4 });
        let t = SharedQuadtree6d::build(&space, Symmetry::Whole).unwrap();
        let p = t.parts();
        let (m, b, ds, c, l) = (
            p.masks.to_vec(),
            p.bases.to_vec(),
            p.depth_start.to_vec(),
            p.children.to_u32(),
            p.leaves.to_vec(),
        );
        let ok = |m: Vec<[u64; 2]>, b: Vec<u32>, ds: Vec<u32>, c: Vec<u32>, l: Vec<u64>| {
            SharedQuadtree6d::from_parts(3, 0, false, m, b, ds, c, l).is_ok()
        };
        assert!(ok(m.clone(), b.clone(), ds.clone(), c.clone(), l.clone()));
        assert!(
            !ok(m.clone(), b.clone(), ds.clone(), c.clone(), vec![]),
            "children point past the leaves"
        );
        assert!(!ok(m.clone(), b.clone(), ds.clone(), vec![], l.clone()), "empty pool");
        assert!(
            !ok(m.clone(), b.clone(), vec![0, 1], c.clone(), l.clone()),
            "depth_start too short"
        );
        let mut both = m.clone();
        both[0][1] |= both[0][0];
        assert!(!ok(both, b.clone(), ds.clone(), c.clone(), l.clone()), "overlapping masks");
        let mut far = b.clone();
        far[0] = u32::MAX;
        assert!(!ok(m.clone(), far, ds.clone(), c.clone(), l.clone()), "base past the pool");
        let mut shifted = b.clone();
        *shifted.last_mut().unwrap() -= 1;
        assert!(
            !ok(m.clone(), shifted, ds.clone(), c.clone(), l.clone()),
            "bases not the running counts"
        );
        let mut longer = c.clone();
        longer.push(0);
        assert!(!ok(m, b, ds, longer, l), "an unused child index");
    }
}
