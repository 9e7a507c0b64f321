//! The builder of the shared 6-D quadtree (module doc of `shared6d`): the 6-D quadtree of
//! the labels built depth first, every subtree hash-consed so that equal subtrees are stored
//! once, and, for a subdivided table, one more level from the sub-cell labels: held whole, or
//! fetched block by block (a block: the subtree of a node at a chosen depth) so that a build
//! within bounded memory holds two blocks' sub-cells at a time: the one the tree is in, and
//! the next, which a second thread finds meanwhile. The tree's own work (reading every stored
//! pair's label, hash-consing) is serial, because the order in which leaves are first stored
//! decides which leaf a don't-care cell matches; running it beside the sub-cells of the blocks
//! ahead keeps both cores busy.

use super::SharedQuadtree6d;
use crate::cspace::symmetry::Symmetry;
use crate::cspace::{Label, LabelledSpace, SubCells};
use crate::table::code::MAX_LEVELS;
use crate::table::error::{bad_input, TableError};
use crate::table::space::SpaceView;
use alloc::format;
use std::collections::HashMap;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::time::{Duration, Instant};

/// An inner node while building: non-uniform mask, collision mask, child ids.
pub(super) type InnerNode = (u64, u64, Vec<u32>);

/// A child while building: don't care, uniform, or a stored node of the next depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Part {
    DontCare,
    Free,
    Collision,
    Node(u32),
}

/// What the extra level below the grid cells holds, when there is one.
#[derive(Clone, Copy)]
pub(crate) enum Fine<'a> {
    /// Sub-cells of the pairs labelled collision (a subdivided table).
    SubCells(&'a SubCells),
    /// Per pair, a word that is one value for the whole grid cell (a clearance table's
    /// levels, `crate::table::clearance`), not 64 places: its mirror pair's word merges in
    /// unpermuted.
    Words(&'a (dyn Fn(usize) -> u64 + Sync)),
    /// Sub-cells found block by block ([`SubCellBlocks`]), two blocks held at a time.
    Streamed,
}

/// Where a subdivided build streamed by blocks finds the sub-cells: the masks of a block's
/// pairs, asked (on a thread of their own) one block ahead of the tree, so that only two
/// blocks' sub-cells are alive.
pub(crate) trait SubCellBlocks {
    /// `(care, collision)` of each pair of `pairs` (numbered `ia * nb + ib`, each labelled
    /// collision), in order.
    fn masks(&mut self, pairs: &[u64], nb: usize) -> Vec<(u64, u64)>;
}

/// A block: A's and B's block coordinates at the blocks' depth.
type BlockAt = ([usize; 3], [usize; 3]);

/// The streamed sub-cells, as the tree sees them: the blocks' depth, the sub-cells of the
/// block it is in, and where the next block's come from (found ahead, in the order the tree
/// enters the blocks, [`find_blocks`]).
struct Stream {
    depth: u32,
    block: SubCells,
    next: Receiver<(BlockAt, SubCells)>,
    /// Time spent waiting for a block's sub-cells.
    waited: Duration,
    /// Whether a block came that was not the one entered (then the build fails).
    out_of_order: bool,
}

/// Hash-consing builder over a [`SpaceView`].
pub(super) struct Builder<'a> {
    view: &'a SpaceView<'a>,
    /// The level below the grid cells, if any.
    sub: Option<Fine<'a>>,
    k: usize,
    /// Dense `k^3` maps from cell to sample index (`u32::MAX`: none, or not stored).
    dense_a: &'a [u32],
    dense_b: &'a [u32],
    /// Per depth: which blocks hold a (stored) sample ([`occupancy`]).
    occ_a: &'a [Vec<bool>],
    occ_b: &'a [Vec<bool>],
    /// Per inner depth: node -> id within the depth, and the nodes in id order.
    inner: Vec<HashMap<InnerNode, u32>>,
    inner_nodes: Vec<Vec<InnerNode>>,
    leaf_ids: HashMap<u64, u32>,
    leaves: Vec<u64>,
    /// With [`Fine::Streamed`]: where the blocks' sub-cells come from.
    stream: Option<Stream>,
}

pub(super) const NONE: u32 = u32::MAX;

pub(super) fn dense_map(cells: &[[u16; 3]], k: usize, keep: impl Fn(usize) -> bool) -> Vec<u32> {
    let mut dense = vec![NONE; k * k * k];
    for (i, c) in cells.iter().enumerate() {
        if keep(i) {
            dense[(usize::from(c[0]) * k + usize::from(c[1])) * k + usize::from(c[2])] = i as u32;
        }
    }
    dense
}

/// `occ[d][block]`: whether the block of side `2^(levels - d)` holds a sample, `d` in `0..=levels`.
pub(super) fn occupancy(dense: &[u32], k: usize, levels: u32) -> Vec<Vec<bool>> {
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

/// Child `i` of the block at per-robot block coordinates `a`, `b`: its coordinates one depth
/// down (module doc of `shared6d`, "Structure").
fn kid(i: usize, a: [usize; 3], b: [usize; 3]) -> BlockAt {
    let bit = |j: usize| (i >> (5 - j)) & 1;
    let a = [2 * a[0] + bit(0), 2 * a[1] + bit(1), 2 * a[2] + bit(2)];
    (a, [2 * b[0] + bit(3), 2 * b[1] + bit(4), 2 * b[2] + bit(5)])
}

/// Whether the block at depth `d` holds a (stored) sample of each robot: the tree enters it.
fn occupied(occ_a: &[Vec<bool>], occ_b: &[Vec<bool>], d: u32, (a, b): BlockAt) -> bool {
    let n = 1usize << d;
    let at = |c: [usize; 3]| (c[0] * n + c[1]) * n + c[2];
    occ_a[d as usize][at(a)] && occ_b[d as usize][at(b)]
}

/// The blocks at `depth` in the order [`Builder::build`] enters them (depth first, child
/// order): the blocks whose sub-cells it fetches.
fn blocks_in_order(occ_a: &[Vec<bool>], occ_b: &[Vec<bool>], depth: u32) -> Vec<BlockAt> {
    fn visit(
        occ: (&[Vec<bool>], &[Vec<bool>]),
        d: u32,
        at: BlockAt,
        depth: u32,
        out: &mut Vec<BlockAt>,
    ) {
        if !occupied(occ.0, occ.1, d, at) {
            return;
        }
        if d == depth {
            out.push(at);
            return;
        }
        for i in 0..64 {
            visit(occ, d + 1, kid(i, at.0, at.1), depth, out);
        }
    }
    let mut out = Vec::new();
    visit((occ_a, occ_b), 0, ([0; 3], [0; 3]), depth, &mut out);
    out
}

/// The pairs of a block labelled collision (by their own label), numbered `ia * nb + ib`, in
/// order: the pairs whose sub-cells [`Builder::subdivided_cell`] looks up inside the block
/// (under symmetry too: a pair's sub-cells are its own, not merged with its mirror pair's).
fn block_pairs(
    view: &SpaceView,
    dense: (&[u32], &[u32]),
    k: usize,
    depth: u32,
    (a, b): BlockAt,
) -> Vec<u64> {
    let side = k >> depth;
    let in_a = block_samples(dense.0, k, side, a);
    let in_b = block_samples(dense.1, k, side, b);
    let nb = view.space.grid_b.cells.len();
    let mut pairs = Vec::new();
    for &ia in &in_a {
        for &ib in &in_b {
            if view.own_label(ia, ib) == Label::Collision {
                pairs.push((ia * nb + ib) as u64);
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// Finds the sub-cells of the blocks of `order` with `source` and hands each on in that order,
/// until every block is sent or the tree stops taking them.
fn find_blocks(
    view: &SpaceView,
    dense: (&[u32], &[u32]),
    k: usize,
    depth: u32,
    order: &[BlockAt],
    source: &mut (dyn SubCellBlocks + Send),
    to_tree: SyncSender<(BlockAt, SubCells)>,
) {
    let nb = view.space.grid_b.cells.len();
    for &at in order {
        let pairs = block_pairs(view, dense, k, depth, at);
        let (care, collision) = source.masks(&pairs, nb).into_iter().unzip();
        if to_tree.send((at, SubCells { pairs, care, collision })).is_err() {
            return;
        }
    }
}

impl Builder<'_> {
    /// The part for the 6-D block at depth `d` whose per-robot block coordinates are `a`, `b`
    /// (in units of the block side).
    fn build(&mut self, d: u32, a: [usize; 3], b: [usize; 3]) -> Part {
        if !occupied(self.occ_a, self.occ_b, d, (a, b)) {
            return Part::DontCare;
        }
        let streamed_block = self.stream.as_ref().is_some_and(|s| s.depth == d);
        if streamed_block {
            self.fetch_block((a, b));
        }
        let last = d == self.view.levels - 1;
        let mut kids = [Part::DontCare; 64];
        for (i, kid_part) in kids.iter_mut().enumerate() {
            let (ca, cb) = kid(i, a, b);
            *kid_part = match (last, self.sub) {
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
        if streamed_block {
            if let Some(s) = self.stream.as_mut() {
                s.block = SubCells::default();
            }
        }
        self.node(d as usize, &kids)
    }

    /// Takes the sub-cells of the block entered (`at`) from the stream ([`find_blocks`] sends
    /// them in the order the tree enters the blocks).
    fn fetch_block(&mut self, at: BlockAt) {
        let Some(s) = self.stream.as_mut() else { return };
        let start = Instant::now();
        match s.next.recv() {
            Ok((sent, block)) if sent == at => s.block = block,
            _ => s.out_of_order = true,
        }
        s.waited += start.elapsed();
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

    /// The part of one cell pair cut into its 64 sub-cells ([`SubCells`]). Under symmetry the
    /// sub-cells are the stored pair's own: a labelling finds them for the stored half only,
    /// its proofs holding for the mirror pair by the cell's symmetry (`crate::cspace::certify`,
    /// module doc, "Symmetric cells"). A clearance table's words ([`Fine::Words`]) merge with
    /// the mirror pair's, unpermuted.
    fn subdivided_cell(&mut self, ca: [usize; 3], cb: [usize; 3]) -> Part {
        let (part, Some((ia, ib))) = self.cell(ca, cb) else { return Part::DontCare };
        if part != Part::Collision {
            return part;
        }
        let (mut care, mut value) = self.sub_masks(ia, ib);
        if let (Some(Fine::Words(_)), Some((ma, mb))) = (self.sub, self.view.mirror_pair(ia, ib)) {
            let (c, v) = self.sub_masks(ma, mb);
            (care, value) = (care | c, value | v);
        }
        self.leaf(care, value)
    }

    /// `(care, collision)` of the sub-cells of one pair, by its own label.
    fn sub_masks(&self, ia: usize, ib: usize) -> (u64, u64) {
        match self.view.own_label(ia, ib) {
            Label::Free => (u64::MAX, 0),
            Label::Unreachable => (0, 0),
            Label::Collision => {
                let pair = ia * self.view.space.grid_b.cells.len() + ib;
                match self.sub {
                    Some(Fine::SubCells(s)) => s.get(pair as u64).unwrap_or((u64::MAX, u64::MAX)),
                    Some(Fine::Words(word)) => (u64::MAX, word(pair)),
                    Some(Fine::Streamed) => match &self.stream {
                        Some(s) => s.block.get(pair as u64).unwrap_or((u64::MAX, u64::MAX)),
                        None => (u64::MAX, u64::MAX),
                    },
                    None => (u64::MAX, u64::MAX),
                }
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

/// The samples (dense map `dense` of side `k`) in the block of side `side` at block
/// coordinates `c`, in the grid's order.
fn block_samples(dense: &[u32], k: usize, side: usize, c: [usize; 3]) -> Vec<usize> {
    let mut out = Vec::new();
    for x in c[0] * side..(c[0] + 1) * side {
        for y in c[1] * side..(c[1] + 1) * side {
            let row = (x * k + y) * k;
            let line = &dense[row + c[2] * side..row + (c[2] + 1) * side];
            out.extend(line.iter().filter(|&&i| i != NONE).map(|&i| i as usize));
        }
    }
    out
}

impl SharedQuadtree6d {
    /// Builds the table of `space` (see the module doc); with [`Symmetry::MirrorY`], only A's upper
    /// half `iy >= k/2` is stored, as the other variants do.
    ///
    /// # Errors
    /// [`TableError::BadInput`] when the grids differ or are not `2^levels` with
    /// `2 <= levels <= MAX_LEVELS`, or the label count is wrong.
    pub fn build(
        space: &LabelledSpace,
        symmetry: Symmetry,
    ) -> Result<SharedQuadtree6d, TableError> {
        Self::build_with(space, None, symmetry.is_mirrored(), None).map(|(table, _)| table)
    }

    /// As [`build`](Self::build) with every pair labelled collision cut into the sub-cells of
    /// `sub` ([`crate::cspace::label_space_subdivided`]): one more level, queried with cell
    /// indices at `2 k` per axis.
    ///
    /// # Errors
    /// As [`build`](Self::build).
    pub fn build_subdivided(
        space: &LabelledSpace,
        sub: &SubCells,
        symmetry: Symmetry,
    ) -> Result<SharedQuadtree6d, TableError> {
        Self::build_with(space, Some(Fine::SubCells(sub)), symmetry.is_mirrored(), None)
            .map(|(table, _)| table)
    }

    /// As [`build`](Self::build) with one more level whose leaves hold, per pair labelled
    /// collision, the word `word(pair)` (pairs numbered `ia * nb + ib`) for the whole grid
    /// cell; a pair labelled free holds 0. Symmetric tables OR a pair's word with its mirror
    /// pair's. Read back with [`query_word`](Self::query_word).
    ///
    /// # Errors
    /// As [`build`](Self::build).
    pub(crate) fn build_words(
        space: &LabelledSpace,
        word: &(dyn Fn(usize) -> u64 + Sync),
        symmetry: Symmetry,
    ) -> Result<SharedQuadtree6d, TableError> {
        Self::build_with(space, Some(Fine::Words(word)), symmetry.is_mirrored(), None)
            .map(|(table, _)| table)
    }

    /// As [`build_subdivided`](Self::build_subdivided) with the sub-cells fetched from `source`
    /// block by block: a block is the subtree of a node at depth `block_depth` (clamped to
    /// the grid cells' parents), one box of A's cells by one of B's, so that only two blocks'
    /// sub-cells are held at a time (the tree's, and the next, found meanwhile on a second
    /// thread). The same table, for every `block_depth`. Also returns the time the tree waited
    /// for sub-cells.
    ///
    /// # Errors
    /// As [`build`](Self::build).
    pub(crate) fn build_streamed(
        space: &LabelledSpace,
        source: &mut (dyn SubCellBlocks + Send),
        block_depth: u32,
        symmetry: Symmetry,
    ) -> Result<(SharedQuadtree6d, Duration), TableError> {
        Self::build_with(
            space,
            Some(Fine::Streamed),
            symmetry.is_mirrored(),
            Some((source, block_depth)),
        )
    }

    fn build_with(
        space: &LabelledSpace,
        sub: Option<Fine<'_>>,
        symmetric: bool,
        source: Option<(&mut (dyn SubCellBlocks + Send), u32)>,
    ) -> Result<(SharedQuadtree6d, Duration), TableError> {
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
        let builder = |stream| Builder {
            view: &view,
            sub,
            k,
            dense_a: &dense_a,
            dense_b: &dense_b,
            occ_a: &occ_a,
            occ_b: &occ_b,
            inner: vec![HashMap::new(); inner_depths],
            inner_nodes: vec![Vec::new(); inner_depths],
            leaf_ids: HashMap::new(),
            leaves: Vec::new(),
            stream,
        };
        let (root, b, waited) = match source {
            None => {
                let mut b = builder(None);
                (b.build(0, [0; 3], [0; 3]), b, Duration::ZERO)
            }
            Some((source, depth)) => {
                let depth = depth.min(levels - 1);
                let order = blocks_in_order(&occ_a, &occ_b, depth);
                let (to_tree, next) = sync_channel(0);
                let (view, dense) = (&view, (&dense_a[..], &dense_b[..]));
                std::thread::scope(|scope| {
                    scope
                        .spawn(move || find_blocks(view, dense, k, depth, &order, source, to_tree));
                    let block = SubCells::default();
                    let stream =
                        Stream { depth, block, next, waited: Duration::ZERO, out_of_order: false };
                    let mut b = builder(Some(stream));
                    let root = b.build(0, [0; 3], [0; 3]);
                    // Dropping the receiver stops the finder should it have blocks left.
                    match b.stream.take() {
                        Some(s) if !s.out_of_order => Ok((root, b, s.waited)),
                        _ => Err(bad_input("a block's sub-cells came out of the tree's order")),
                    }
                })?
            }
        };
        let table = Self::from_nodes(levels, sub_levels, symmetric, root, b.inner_nodes, b.leaves);
        Ok((table, waited))
    }

    /// The table of the hash-consed `inner_nodes` (per depth) and `leaves` under `root`.
    fn from_nodes(
        levels: u32,
        sub_levels: u32,
        symmetric: bool,
        root: Part,
        mut inner_nodes: Vec<Vec<InnerNode>>,
        leaves: Vec<u64>,
    ) -> SharedQuadtree6d {
        let (mut masks, mut bases, mut depth_start, mut children) =
            (vec![], vec![], vec![], vec![]);
        match root {
            // A uniform root is stored as one node with every child uniform.
            Part::Node(_) => {}
            Part::Collision => inner_nodes[0].push((0, u64::MAX, vec![])),
            Part::Free | Part::DontCare => inner_nodes[0].push((0, 0, vec![])),
        }
        // Depth 0 now holds exactly the root.
        for nodes in &inner_nodes {
            depth_start.push(masks.len() as u32);
            for (nonuniform, collision, ids) in nodes {
                masks.push([*nonuniform, *collision]);
                bases.push(children.len() as u32);
                children.extend_from_slice(ids);
            }
        }
        depth_start.push(masks.len() as u32);
        Self::assemble(levels, sub_levels, symmetric, (masks, bases, depth_start, children, leaves))
    }
}
