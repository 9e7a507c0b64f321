//! Levels 2 and 3 of the certified labelling (module doc of `certify`): octant pairs proved
//! free with the octants' own sweeps, sub-octant pairs for what level 2 leaves open, and the
//! sub-cell labels ([`SubCells`]) of the pairs that stay collisions.

use super::sweeps::{inflation, octant_centre, octant_sweeps};
use super::{sub_cell_index, SubCells};
use crate::cell::RobotSpec;
use crate::cspace::label::{
    aabbs_apart, all_box_pairs, bounds_apart, boxes_may_touch, collision_mask, entries_apart,
    Inflation, Rows, SampleBoxes, Slot, SweptBounds, SweptBox,
};
use crate::cspace::sampler::SampleGrid;
use crate::cspace::{Label, PairLabels};
use crate::geometry::sat::separating_axis;
use crate::geometry::sweep::{boxes_overlap_deeply, core};
use crate::geometry::Obb;
use crate::math::{max_or_nan, min_or_nan, Real, Vec3};
use crate::robot::motion_bound::reference_point;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

/// Rows of A whose sub-cells are found together ([`sub_cells`]; a cache blocking, any value
/// gives the same answers).
const SUB_CELL_ROWS: usize = 16;

/// One robot's boxes at both levels with their cores ([`core`](fn@core): what every
/// configuration of the (sub)cell covers; `None` for a box without one or an entry without
/// boxes).
pub(super) struct Levels<'a> {
    pub(super) whole: &'a SampleBoxes,
    pub(super) octs: &'a SampleBoxes,
    pub(super) whole_cores: Vec<Option<Obb>>,
    pub(super) oct_cores: Vec<Option<Obb>>,
    /// Per sample: its octants that hold its reference TCP
    /// ([`octants_holding`](super::sweeps::octants_holding)). `None` turns off
    /// [`held_by_references`], to test it against the levels without it.
    pub(super) ref_octants: Option<Vec<u8>>,
    /// Level 3, for the sub-cells only.
    pub(super) subs: Option<SubOctants<'a>>,
}

impl<'a> Levels<'a> {
    pub(super) fn new(whole: &'a SampleBoxes, octs: &'a SampleBoxes) -> Self {
        Levels {
            whole,
            octs,
            whole_cores: cores(whole),
            oct_cores: cores(octs),
            ref_octants: None,
            subs: None,
        }
    }

    /// As [`Levels::new`], with the octants holding each sample's reference TCP.
    pub(super) fn with_references(
        whole: &'a SampleBoxes,
        octs: &'a SampleBoxes,
        ref_octants: Vec<u8>,
    ) -> Self {
        Levels { ref_octants: Some(ref_octants), ..Levels::new(whole, octs) }
    }
}

/// Level 3 (sub-cells only, module doc): each octant cut into its 8 sub-octants (half-side
/// `r/8`), their boxes and sweeps made when an octant first needs them.
pub(super) struct SubOctants<'a> {
    robot: &'a RobotSpec,
    grid: &'a SampleGrid,
    /// Per octant entry `8 s + i`: its sub-octants, entry `u` offset by `+/- r/8` along x,
    /// y, z for bits 0, 1, 2 of `u`.
    boxes: Vec<OnceLock<SampleBoxes>>,
    /// How many of `boxes` are made.
    made: AtomicUsize,
}

impl<'a> SubOctants<'a> {
    pub(super) fn new(robot: &'a RobotSpec, grid: &'a SampleGrid) -> Self {
        let boxes = (0..8 * grid.cells.len()).map(|_| OnceLock::new()).collect();
        SubOctants { robot, grid, boxes, made: AtomicUsize::new(0) }
    }

    /// Bytes of the sub-octant boxes made so far (their boxes and per-entry arrays).
    pub(super) fn cached_bytes(&self) -> usize {
        self.made.load(Ordering::Relaxed) * sub_octant_bytes(self.robot.model.box_count())
    }

    /// Drops the sub-octant boxes made so far.
    pub(super) fn clear(&mut self) {
        if *self.made.get_mut() > 0 {
            self.boxes.iter_mut().for_each(|b| drop(b.take()));
            *self.made.get_mut() = 0;
        }
    }

    /// The sub-octants of octant entry `e`.
    fn of(&self, e: usize) -> &SampleBoxes {
        self.boxes[e].get_or_init(|| {
            self.made.fetch_add(1, Ordering::Relaxed);
            let (model, r) = (&self.robot.model, self.grid.r);
            let octant = octant_centre(&self.grid.sample_center(e / 8), e % 8, 0.25 * r);
            let h = 0.125 * r;
            let cs: Vec<Vec3> = (0..8).map(|u| octant_centre(&octant, u, h)).collect();
            let refs: Vec<Vec3> =
                cs.iter().map(|c| reference_point(&model.delta, c, h).unwrap_or(*c)).collect();
            let inflate = |u: usize| {
                octant_sweeps(model, &cs[u], h, &refs[u]).map_or(Inflation::Vacuous, inflation)
            };
            SampleBoxes::new(model, &self.robot.placement, &refs, inflate)
        })
    }
}

/// Bytes of one octant's 8 sub-octants with `boxes` boxes each ([`SubOctants::of`]): the
/// boxes and their bounds, the per-entry bounds and slots, and the vectors' headers.
pub(crate) fn sub_octant_bytes(boxes: usize) -> usize {
    let per_box = size_of::<SweptBox>() + size_of::<SweptBounds>();
    8 * (boxes * per_box + 2 * size_of::<[Real; 3]>() + size_of::<Slot>())
        + 5 * size_of::<Vec<u8>>()
}

/// Whether level 3 proves octant pair (A's entry `sa`, B's entry `sb`) free: for each pair
/// of their sub-octants, each box pair of `open` (those the octant pair's tests left open) is
/// proved disjoint by (A sub-octant, B sub-octant), (A sub-octant, B octant) or (A octant,
/// B sub-octant). Never when a box pair's octant cores meet (a certain collision). The
/// sub-octant pair `hint` (`8 u + v`) is tried first; it is set to the one that fails.
pub(super) fn sub_octants_prove_free(
    a: &Levels,
    b: &Levels,
    sa: usize,
    sb: usize,
    first: usize,
    open: impl FnOnce() -> u64,
    hint: &mut usize,
) -> bool {
    let (Some(sub_a), Some(sub_b)) = (&a.subs, &b.subs) else { return false };
    let (a1, b1, na, nb) = (a.octs, b.octs, a.octs.per_entry, b.octs.per_entry);
    let (x, y) = (sub_a.of(sa), sub_b.of(sb));
    let usable = |slot: Slot| slot == Slot::Boxes || slot == Slot::Vacuous;
    if !x.slot[..8].iter().chain(&y.slot[..8]).all(|&s| usable(s)) {
        return false;
    }
    let fine = |u: usize, v: usize, open: u64| {
        if open == 0 || entries_apart(x, u, y, v) {
            0
        } else {
            collision_mask(x, u, y, v, open)
        }
    };
    // Each test's answers on each box pair, kept from the first time it is asked: the rows
    // (sub-octant `u` against B's octant), the columns (A's octant against sub-octant `v`)
    // and the hinted sub-octant pair, which the hinted exit and the full loop both ask.
    let (mut rows, mut columns, mut hinted_pair) =
        ([Known::default(); 8], [Known::default(); 8], Known::default());
    let row = |known: &mut Known, u: usize, mask: u64| {
        known.open(mask, |m| collision_mask(x, u, b1, sb, m))
    };
    let column = |known: &mut Known, v: usize, mask: u64| {
        known.open(mask, |m| collision_mask(a1, sa, y, v, m))
    };
    // The pair that failed last first, on box pair `first`, finest test first: a collision
    // usually fails there.
    let (u0, v0) = (*hint / 8, *hint % 8);
    let mut stays = |open: u64| {
        let left = hinted_pair.open(open, |m| fine(u0, v0, m));
        left != 0 && row(&mut rows[u0], u0, left) & column(&mut columns[v0], v0, left) != 0
    };
    let hinted = x.slot[u0] == Slot::Boxes && y.slot[v0] == Slot::Boxes;
    if hinted && (meet_at_references(x, u0, y, v0, first) || stays(1 << first)) {
        return false;
    }
    let open = open();
    if cores_meet(&a.oct_cores, sa, na, &b.oct_cores, sb, nb, open)
        || hinted && stays(open & !(1 << first))
    {
        return false;
    }
    // Then each sub-octant against the other octant, and the finest test for what is left. A
    // column is tested only on the box pairs that some row left open, each once: only those
    // enter `row & column`.
    for u in (0..8).filter(|&u| x.slot[u] == Slot::Boxes) {
        let left = row(&mut rows[u], u, open);
        if left == 0 {
            continue;
        }
        for v in (0..8).filter(|&v| y.slot[v] == Slot::Boxes) {
            let both = left & column(&mut columns[v], v, left);
            let met = if (u, v) == (u0, v0) {
                hinted_pair.open(both, |m| fine(u, v, m))
            } else {
                fine(u, v, both)
            };
            if met != 0 {
                *hint = 8 * u + v;
                return false;
            }
        }
    }
    true
}

/// The answers of one test over the box pairs asked so far: bit `p` of `tested` says whether
/// box pair `p` (as [`collision_mask`]) was tested, of `open` whether it stayed open. A test
/// answers each box pair alone (its two boxes decide it), so asking only the untested ones
/// and keeping the answers gives what testing the whole mask again would.
#[derive(Clone, Copy, Default)]
pub(super) struct Known {
    tested: u64,
    open: u64,
}

impl Known {
    /// The box pairs of `mask` left open; `test(m)` gives those of `m` left open, and is asked
    /// only about the box pairs not tested before.
    pub(super) fn open(&mut self, mask: u64, test: impl FnOnce(u64) -> u64) -> u64 {
        let new = mask & !self.tested;
        if new != 0 {
            self.open |= test(new) & new;
            self.tested |= new;
        }
        self.open & mask
    }
}

/// Whether box pair `bit` (as [`collision_mask`]) of A's entry `ea` of `x` and B's entry `eb`
/// of `y` (both [`Slot::Boxes`]) meets at the entries' reference TCPs: the boxes without their
/// sweeps, by the plain separating axis test. A cheap answer "may touch" for every test whose
/// sweeps cover both reference configurations:
///
/// - an entry's reference TCP is reachable (a `Boxes` entry's boxes are built there) and lies
///   in the entry's closed cube ([`reference_point`]), so every sweep made over a cube that
///   holds it (the entry's own, or a coarser level's whose cube contains the entry's) holds the
///   zero displacement or the displacement of that configuration: the swept box holds the
///   box at the reference;
/// - the plain test finds no axis only when every axis shows a gap of at most its touch
///   tolerance (1e-9 mm, rounding far below it), so the two boxes at the references are that
///   close or closer on all 15 axes; the swept test calls an axis separating only for a gap
///   above [`crate::geometry::sweep::SWEEP_GAP`] = 1e-6 mm between two sets that contain
///   them, so it finds none either;
/// - so neither (sub-octant, sub-octant), (sub-octant, octant), (octant, sub-octant) nor
///   (octant, octant) tests of those cubes prove the box pair disjoint: a sub-cell that holds
///   both references is a collision whatever level 3 tries, and so is an octant pair whose
///   sub-octant pair holding them is tried.
///
/// It only skips tests whose answers it predicts; a "not free" is never a wrong answer.
pub(super) fn meet_at_references(
    x: &SampleBoxes,
    ea: usize,
    y: &SampleBoxes,
    eb: usize,
    bit: usize,
) -> bool {
    let (i, j) = (ea * x.per_entry + bit / 8, eb * y.per_entry + bit % 8);
    !bounds_apart(&x.bounds[i], &y.bounds[j]) && meet(&x.boxes[i], &y.boxes[j])
}

/// Whether two boxes at their entries' reference TCPs ([`SweptBox::obb`]) meet: the plain
/// separating axis test finds no axis (the premise of [`meet_at_references`]). Asked only of
/// boxes whose swept bounds are not apart ([`bounds_apart`]); boxes whose swept bounds are
/// apart (by the slack, 1e-6 mm, along a world axis) do not meet: each swept box holds its
/// box, so such boxes are apart by more than 1e-6 mm, and boxes on which the plain test finds
/// no axis are within its touch tolerance (1e-9 mm) on each of their 15 axes, so a few times
/// that apart at most: the answer is the plain test's, found without it.
fn meet(a: &SweptBox, b: &SweptBox) -> bool {
    separating_axis(&a.obb(), &b.obb()).is_none()
}

/// The octant pairs of `(ia, ib)` (bits as [`sub_cell_index`]) that level 2 and level 3 leave
/// collisions because the boxes meet at the whole cells' reference TCPs: those of A's octants
/// holding A's reference (`a.ref_octants`) with B's octants holding B's; 0 when the boxes do
/// not meet there or a cell has no boxes.
///
/// A box pair meeting at both references is open after every test whose cubes hold the two
/// references ([`meet_at_references`], first two points): the whole cells' test, each of
/// those octants' with the other cell ([`sub_cell_masks`]' rows and columns) and the octant
/// pair's own, so level 2 leaves such an octant pair a collision on it. At level 3 the
/// octant's sub-octants cover its cube, so a sub-octant of each holds the reference (a point
/// counted in an octant lies within `HOLD_SLACK` of its cube, so within as much of one of its
/// sub-octants' cubes, inside what their sweeps cover:
/// [`octants_holding`](super::sweeps::octants_holding)), and the three tests of that sub-octant
/// pair keep the box pair open too; a sub-octant with no reachable TCP cannot hold a reachable
/// reference. The cell centres, when reachable (the usual reference), are held by all 8
/// octants: the 64 octant pairs are decided by a few plain tests.
///
/// Like [`meet_at_references`], it only skips tests whose answers it predicts; a test checks
/// that the sub-cells are those found without it.
pub(super) fn held_by_references(a: &Levels, b: &Levels, ia: usize, ib: usize) -> u64 {
    let (a0, b0) = (a.whole, b.whole);
    let (Some(in_a), Some(in_b)) = (&a.ref_octants, &b.ref_octants) else { return 0 };
    let (in_a, in_b) = (in_a[ia], in_b[ib]);
    if in_a == 0 || in_b == 0 || a0.slot[ia] != Slot::Boxes || b0.slot[ib] != Slot::Boxes {
        return 0;
    }
    let (na, nb) = (a0.per_entry, b0.per_entry);
    let mut pairs = all_box_pairs(na, nb);
    let met = loop {
        if pairs == 0 {
            break false;
        }
        let p = pairs.trailing_zeros() as usize;
        pairs &= pairs - 1;
        if meet_at_references(a0, ia, b0, ib, p) {
            break true;
        }
    };
    if !met {
        return 0;
    }
    let column =
        (0..8).filter(|&j| in_b >> j & 1 == 1).fold(0u64, |m, j| m | 1 << sub_cell_index(0, j));
    (0..8).filter(|&i| in_a >> i & 1 == 1).fold(0, |m, i| m | column << sub_cell_index(i, 0))
}

/// Per box of `boxes`: its core under its sweep, when its entry has boxes and the core exists.
pub(super) fn cores(boxes: &SampleBoxes) -> Vec<Option<Obb>> {
    let n = boxes.per_entry;
    (0..boxes.boxes.len())
        .into_par_iter()
        .map(|i| {
            let b = &boxes.boxes[i];
            (boxes.slot[i / n] == Slot::Boxes).then(|| core(&b.obb(), &b.sweep.sweep())).flatten()
        })
        .collect()
}

/// Whether some box pair among `mask` (as [`collision_mask`]) of A's entry `ia` and B's entry
/// `ib` certainly intersects: their cores overlap deeply ([`boxes_overlap_deeply`]), so the
/// boxes meet for every configuration of the two (sub)cells.
pub(super) fn cores_meet(
    a: &[Option<Obb>],
    ia: usize,
    na: usize,
    b: &[Option<Obb>],
    ib: usize,
    nb: usize,
    mask: u64,
) -> bool {
    let mut rest = mask;
    while rest != 0 {
        let bit = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        if let (Some(x), Some(y)) = (&a[ia * na + bit / 8], &b[ib * nb + bit % 8]) {
            if boxes_overlap_deeply(x, y) {
                return true;
            }
        }
    }
    false
}

/// The sub-cell labels of every pair labelled collision whose A sample `stored` keeps (see
/// [`SubCells`]); `labels` holds the rows `selection` of A as
/// [`crate::cspace::label::label_pairs`] returns them, the pairs come out numbered
/// `ia * nb + ib` all the same.
///
/// Rows of A are taken [`SUB_CELL_ROWS`] at a time, column by column, so that B's boxes of a
/// column are used by every row of the block while they are in the cache.
pub(super) fn sub_cells(
    a: &Levels,
    b: &Levels,
    labels: &PairLabels,
    selection: Rows,
    stored: impl Fn(usize) -> bool + Sync,
) -> SubCells {
    let nb = b.whole.len();
    if nb == 0 {
        return SubCells::default();
    }
    let labelled = labels.len() / nb;
    let rows: Vec<Vec<(u64, u64, u64)>> = (0..labelled.div_ceil(SUB_CELL_ROWS))
        .into_par_iter()
        .map(|block| {
            let mut out = vec![];
            let first = block * SUB_CELL_ROWS;
            for ib in 0..nb {
                for j in first..labelled.min(first + SUB_CELL_ROWS) {
                    let ia = selection.row(j);
                    if labels[j * nb + ib] == Label::Collision && stored(ia) {
                        let (care, collision) = sub_cell_masks(a, b, ia, ib, false);
                        out.push(((ia * nb + ib) as u64, care, collision));
                    }
                }
            }
            out.sort_unstable_by_key(|&(pair, _, _)| pair);
            out
        })
        .collect();
    // Each block's rows are freed as they are copied, and the copies never reallocate: the
    // peak stays near one copy of the sub-cells (at k = 64 on T2, gigabytes).
    let n = rows.iter().map(Vec::len).sum();
    let mut out = SubCells {
        pairs: Vec::with_capacity(n),
        care: Vec::with_capacity(n),
        collision: Vec::with_capacity(n),
    };
    for (pair, care, collision) in rows.into_iter().flatten() {
        out.pairs.push(pair);
        out.care.push(care);
        out.collision.push(collision);
    }
    out
}

/// The sub-cells of `(ia, ib)` that hold reachable TCPs of both robots: neither octant is
/// [`Slot::Vacuous`].
pub(super) fn care_mask(a1: &SampleBoxes, ia: usize, b1: &SampleBoxes, ib: usize) -> u64 {
    // `sub_cell_index(i, j) = 8 sub_cell_index(i, 0) + sub_cell_index(0, j)`: B's occupied
    // octants as one byte, shifted to each occupied octant of A's byte.
    let column = (0..8)
        .filter(|&j| b1.slot[8 * ib + j] != Slot::Vacuous)
        .fold(0u64, |m, j| m | 1 << sub_cell_index(0, j));
    (0..8)
        .filter(|&i| a1.slot[8 * ia + i] != Slot::Vacuous)
        .fold(0, |m, i| m | column << sub_cell_index(i, 0))
}

/// `(care, collision)` over the 64 octant pairs of `(ia, ib)`, as `octant_pairs` gives
/// them, faster (every change only skips tests whose answers are implied, or reorders tests
/// whose answers are combined by "and"/"or"):
/// - an octant pair is a collision as soon as a box pair certainly intersects for every
///   configuration of a (sub)cell pair that holds it ([`cores_meet`]): of the whole cells
///   (then every octant pair is), of A's octant and B's cell (its row), of A's cell and B's
///   octant (its column). Such an octant pair is never proved free by `octant_pairs`: its
///   octants are [`Slot::Boxes`] only with reachable reference TCPs, a configuration of the
///   pair that collides, and its tests are sound; other octants it calls collisions anyway.
/// - an octant pair is a collision without its tests when a box pair meets at the whole
///   cells' reference TCPs and its octants hold them ([`held_by_references`]).
/// - a box pair of an octant pair is proved disjoint when one of the tests (A octant, B
///   cell), (A cell, B octant), (A octant, B octant) proves it (after the whole cells left it
///   open); an octant pair is free when all its box pairs are. The octant-cell tests are
///   shared by the 8 pairs of a row or column and run only when first needed; the box pairs
///   are tried from the one that last stopped an octant pair, and an octant pair stops at
///   its first box pair that no test proves.
///
/// With `first_only`, stops at the first octant pair not proved free.
pub(super) fn sub_cell_masks(
    a: &Levels,
    b: &Levels,
    ia: usize,
    ib: usize,
    first_only: bool,
) -> (u64, u64) {
    let (a0, a1, b0, b1) = (a.whole, a.octs, b.whole, b.octs);
    let (na, nb) = (a0.per_entry, b0.per_entry);
    let care = care_mask(a1, ia, b1, ib);
    let (whole_a, whole_b) = (a0.slot[ia] == Slot::Boxes, b0.slot[ib] == Slot::Boxes);
    let all = all_box_pairs(na, nb);
    // Octant pairs left collisions by the boxes at the cells' references (the labelling found
    // them meeting there and skipped level 2).
    let held = if first_only { 0 } else { held_by_references(a, b, ia, ib) };
    if care & !held == 0 {
        return (care, care);
    }
    // A box pair whose cores meet is never proved disjoint: no need to look for it among
    // those the whole cells leave open.
    if whole_a && whole_b && cores_meet(&a.whole_cores, ia, na, &b.whole_cores, ib, nb, all) {
        return (care, care);
    }
    let open0 = if whole_a && whole_b { collision_mask(a0, ia, b0, ib, all) } else { all };
    let boxes = |s: &SampleBoxes, e: usize| s.slot[e] == Slot::Boxes;
    let row_meets: [bool; 8] = std::array::from_fn(|i| {
        let sa = 8 * ia + i;
        whole_b && boxes(a1, sa) && cores_meet(&a.oct_cores, sa, na, &b.whole_cores, ib, nb, open0)
    });
    let column_meets: [bool; 8] = std::array::from_fn(|j| {
        let sb = 8 * ib + j;
        whole_a && boxes(b1, sb) && cores_meet(&a.whole_cores, ia, na, &b.oct_cores, sb, nb, open0)
    });
    // Whether box pair `bit` may touch between A's entry `ea` of `x` and B's entry `eb` of `y`.
    let touch = |x: &SampleBoxes, ea: usize, y: &SampleBoxes, eb: usize, bit: usize| {
        boxes_may_touch(x, ea * na + bit / 8, y, eb * nb + bit % 8)
    };
    let (mut rows, mut columns) = (Memo::default(), Memo::default());
    let mut hint = open0.trailing_zeros() as usize;
    let mut hint3 = 0;
    let mut collision = 0u64;
    for (i, &row_meet) in row_meets.iter().enumerate() {
        for (j, &column_meet) in column_meets.iter().enumerate() {
            let bit = 1u64 << sub_cell_index(i, j);
            if care & bit == 0 {
                continue;
            }
            let (sa, sb) = (8 * ia + i, 8 * ib + j);
            let decided =
                !boxes(a1, sa) || !boxes(b1, sb) || row_meet || column_meet || held & bit != 0;
            // Whether box pair `p` stays open: no test of the octant pair proves it.
            let mut open = |p: usize| {
                rows.open(i, p, || !whole_b || touch(a1, sa, b0, ib, p))
                    && columns.open(j, p, || !whole_a || touch(a0, ia, b1, sb, p))
                    && touch(a1, sa, b1, sb, p)
            };
            // The box pairs found closed before the stopper: `left` below does not test them again.
            let mut closed = 0u64;
            let stopper = if decided {
                None
            } else if entries_apart(a1, sa, b1, sb) {
                Some(None)
            } else {
                Some(hint_first(open0, hint).find(|&p| {
                    let o = open(p);
                    if !o {
                        closed |= 1 << p;
                    }
                    o
                }))
            };
            match stopper {
                Some(None) => continue,
                Some(Some(p)) => {
                    hint = p;
                    // Both octants' references lie in the sub-cell: their boxes meeting decides
                    // it (`meet_at_references`), level 3 could not prove it free.
                    if !first_only && !meet_at_references(a1, sa, b1, sb, p) {
                        // The box pairs the octant pair leaves open: the stopper `p`, and those
                        // the search above did not reach, each tested once (every test is a
                        // function of its boxes, so the answers are those of testing all again).
                        let left = || {
                            let rest =
                                hint_first(open0 & !closed & !(1 << p), p).filter(|&q| open(q));
                            rest.fold(1u64 << p, |m, q| m | 1 << q)
                        };
                        if sub_octants_prove_free(a, b, sa, sb, p, left, &mut hint3) {
                            continue;
                        }
                    }
                }
                None => {}
            }
            collision |= bit;
            if first_only {
                return (care, collision);
            }
        }
    }
    (care, collision)
}

/// The answers of one kind of coarse test (an octant against the other robot's whole cell),
/// found when first asked: per octant `o`, bit `p` of `known[o]` says whether box pair `p` was
/// tested, of `open[o]` whether it stayed open.
#[derive(Default)]
pub(super) struct Memo {
    known: [u64; 8],
    open: [u64; 8],
}

impl Memo {
    /// Whether box pair `p` of octant `o` stays open; `test` finds it the first time.
    fn open(&mut self, o: usize, p: usize, test: impl FnOnce() -> bool) -> bool {
        let bit = 1u64 << p;
        if self.known[o] & bit == 0 {
            self.known[o] |= bit;
            if test() {
                self.open[o] |= bit;
            }
        }
        self.open[o] & bit != 0
    }
}

/// The set bits of `mask` (box pair indices), `hint` first when set, then the others upward.
pub(super) fn hint_first(mask: u64, hint: usize) -> impl Iterator<Item = usize> {
    let first = (hint < 64 && mask >> hint & 1 == 1).then_some(hint);
    let mut rest = first.map_or(mask, |h| mask & !(1u64 << h));
    first.into_iter().chain(std::iter::from_fn(move || {
        let p = rest.trailing_zeros() as usize;
        rest &= rest.wrapping_sub(1);
        (p < 64).then_some(p)
    }))
}

/// `(care, collision)` over the 64 octant pairs of `(ia, ib)`: an octant pair is free when
/// every box pair is proved disjoint by one of the tests (A cell, B cell), (A octant,
/// B cell), (A cell, B octant) or (A octant, B octant), each valid for all of it. Only the
/// box pairs a coarser test left open go on to a finer one. With `first_only`, stops at the
/// first octant pair not proved free. The plain form of [`sub_cell_masks`], kept to test it.
#[cfg(test)]
pub(super) fn octant_pairs(
    a0: &SampleBoxes,
    a1: &SampleBoxes,
    b0: &SampleBoxes,
    b1: &SampleBoxes,
    ia: usize,
    ib: usize,
    first_only: bool,
) -> (u64, u64) {
    let (whole_a, whole_b) = (a0.slot[ia] == Slot::Boxes, b0.slot[ib] == Slot::Boxes);
    let all = all_box_pairs(a0.per_entry, b0.per_entry);
    let open0 = if whole_a && whole_b { collision_mask(a0, ia, b0, ib, all) } else { all };
    let (mut care, mut collision) = (0u64, 0u64);
    for i in 0..8 {
        let sa = 8 * ia + i;
        let a_slot = a1.slot[sa];
        if a_slot == Slot::Vacuous {
            continue;
        }
        let open_a = if a_slot == Slot::Boxes && whole_b {
            collision_mask(a1, sa, b0, ib, open0)
        } else {
            open0
        };
        for j in 0..8 {
            let sb = 8 * ib + j;
            let b_slot = b1.slot[sb];
            if b_slot == Slot::Vacuous {
                continue;
            }
            let bit = 1u64 << sub_cell_index(i, j);
            care |= bit;
            let proved = a_slot == Slot::Boxes && b_slot == Slot::Boxes && {
                let open = if whole_a { collision_mask(a0, ia, b1, sb, open_a) } else { open_a };
                open == 0
                    || entries_apart(a1, sa, b1, sb)
                    || collision_mask(a1, sa, b1, sb, open) == 0
            };
            if !proved {
                collision |= bit;
                if first_only {
                    return (care, collision);
                }
            }
        }
    }
    (care, collision)
}

/// Level 3 of octant pair (A's entry `sa`, B's entry `sb`) as the module doc of `certify`
/// states it, to test [`sub_octants_prove_free`]: free when no box pair of `open` has its
/// octant cores meet, every sub-octant is [`Slot::Boxes`] or [`Slot::Vacuous`], and for
/// every pair of sub-octants with boxes each box pair of `open` is proved disjoint by
/// (A sub-octant, B sub-octant), (A sub-octant, B octant) or (A octant, B sub-octant).
#[cfg(test)]
pub(super) fn sub_octants_prove_free_plainly(
    a: &Levels,
    b: &Levels,
    sa: usize,
    sb: usize,
    open: u64,
) -> bool {
    let (Some(sub_a), Some(sub_b)) = (&a.subs, &b.subs) else { return false };
    let (a1, b1, na, nb) = (a.octs, b.octs, a.octs.per_entry, b.octs.per_entry);
    let (x, y) = (sub_a.of(sa), sub_b.of(sb));
    let usable = |slot: Slot| slot == Slot::Boxes || slot == Slot::Vacuous;
    if !x.slot[..8].iter().chain(&y.slot[..8]).all(|&s| usable(s))
        || cores_meet(&a.oct_cores, sa, na, &b.oct_cores, sb, nb, open)
    {
        return false;
    }
    let boxes = |s: &SampleBoxes, e: usize| s.slot[e] == Slot::Boxes;
    (0..8).filter(|&u| boxes(x, u)).all(|u| {
        (0..8).filter(|&v| boxes(y, v)).all(|v| {
            let left = collision_mask(x, u, b1, sb, open) & collision_mask(a1, sa, y, v, open);
            collision_mask(x, u, y, v, left) == 0
        })
    })
}

/// Level 2 for a pair whose whole-cell test failed or could not run (a sample without a
/// whole-cell bound, [`Slot::Unknown`]: its centre is unreachable but its cell is not):
/// every octant pair proved free ([`sub_cell_masks`], stopping at the first that is not).
pub(super) fn octants_prove_free(a: &Levels, b: &Levels, ia: usize, ib: usize) -> bool {
    sub_cell_masks(a, b, ia, ib, true).1 == 0
}

/// What level 2 needs once for the pairs that [`label_pairs`](crate::cspace::label::label_pairs)
/// made collisions because a sample has no whole-cell bound ([`Slot::Unknown`]), each retried
/// octant by octant ([`UnknownCells::refine_row`]): B's samples without a whole-cell bound
/// and both robots' octant covers.
pub(super) struct UnknownCells {
    unknown_b: Vec<usize>,
    cover_a: Vec<Option<([Real; 3], [Real; 3])>>,
    cover_b: Vec<Option<([Real; 3], [Real; 3])>>,
}

impl UnknownCells {
    pub(super) fn new(a: &Levels, b: &Levels) -> UnknownCells {
        let b0 = b.whole;
        let unknown_b = (0..b0.len()).filter(|&ib| b0.slot[ib] == Slot::Unknown).collect();
        UnknownCells { unknown_b, cover_a: octant_covers(a.octs), cover_b: octant_covers(b.octs) }
    }

    /// Level 2 for those pairs of the row of A's sample `ia`.
    pub(super) fn refine_row(&self, a: &Levels, b: &Levels, ia: usize, row: &mut [Label]) {
        let (a0, b0) = (a.whole, b.whole);
        let mut retry = |ib: usize| {
            if row[ib] == Label::Collision
                && b0.slot[ib] != Slot::Unreachable
                && (cover_apart(&self.cover_a[ia], &self.cover_b[ib])
                    || octants_prove_free(a, b, ia, ib))
            {
                row[ib] = Label::Free;
            }
        };
        match a0.slot[ia] {
            Slot::Unknown => (0..b0.len()).for_each(&mut retry),
            Slot::Boxes => self.unknown_b.iter().for_each(|&ib| retry(ib)),
            Slot::Unreachable | Slot::Vacuous => {}
        }
    }
}

/// Per sample: the AABB of its 8 octants' boxes (empty when every octant is vacuous), or
/// `None` when an octant has no bound (nothing can be proved from it).
pub(super) fn octant_covers(octs: &SampleBoxes) -> Vec<Option<([Real; 3], [Real; 3])>> {
    (0..octs.len() / 8)
        .map(|s| {
            let (mut lo, mut hi) = ([Real::INFINITY; 3], [Real::NEG_INFINITY; 3]);
            for e in s * 8..s * 8 + 8 {
                match octs.slot[e] {
                    Slot::Vacuous => continue,
                    Slot::Boxes => {}
                    Slot::Unreachable | Slot::Unknown => return None,
                }
                for a in 0..3 {
                    lo[a] = min_or_nan(lo[a], octs.lo[e][a]);
                    hi[a] = max_or_nan(hi[a], octs.hi[e][a]);
                }
            }
            Some((lo, hi))
        })
        .collect()
}

/// Whether two octant covers are apart (AABBs disjoint by more than the slack).
pub(super) fn cover_apart(
    a: &Option<([Real; 3], [Real; 3])>,
    b: &Option<([Real; 3], [Real; 3])>,
) -> bool {
    match (a, b) {
        (Some((alo, ahi)), Some((blo, bhi))) => aabbs_apart(alo, ahi, blo, bhi),
        _ => false,
    }
}
