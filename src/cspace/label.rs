//! Labelling every two-robot sample with the exact box test, in parallel (thesis 3.2.3,
//! 3.2.7; SPEC §6).
//!
//! The product structure is used twice: each robot's boxes are built once per sample (IK,
//! boxes, placement, inflation, axis-aligned bounds), never once per pair; and for one sample
//! of A, the samples of B whose robot AABB cannot reach A's along x are skipped wholesale (B's
//! samples are sorted by their AABB's lower x, so the candidates form one slice found by
//! binary search). The candidates then go through the AABB test in y and z, a per-box AABB
//! test and finally the separating axis test.
//!
//! The labellings share the kernel [`label_pairs`]:
//! - [`label_space`]: every box enlarged by one global `margin` (the thesis's blown-up model
//!   [`label_space_thesis`] with `margin = r / sqrt(2)`, or the exact labelling of the
//!   centres with 0);
//! - [`crate::cspace::certify::label_space_certified`]: every box swept by its own
//!   displacement set, so that a free label holds for the whole 6-D cell.
//!
//! # Numerics
//! Every pre-test errs toward overlap (slack [`AABB_SLACK`]); only the separating axis test
//! (itself conservative) can turn a candidate free.

use crate::cell::{Cell, Placement};
use crate::cspace::guarantee::thesis_margin;
use crate::cspace::sampler::{SampleGrid, Workspace};
use crate::cspace::swept_sat::{swept_apart, SweptFrame, TableSweep};
use crate::cspace::{Label, LabelledSpace, PairLabels};
use crate::geometry::sat::separating_axis;
use crate::geometry::sweep::{swept_aabb_half, Sweep};
use crate::geometry::Obb;
use crate::math::{max_or_nan, min_or_nan, Mat3, Real, Vec3};
use crate::robot::MAX_BOXES;
use crate::robot::{ModelOptions, RobotModel};
use core::sync::atomic::{AtomicU64, Ordering};
use rayon::prelude::*;

/// Whether a labelling reports its progress. The library prints nothing: a controller or a
/// test builds silently, and the CLI turns the reports into a progress bar.
#[derive(Clone, Copy, Debug, Default)]
pub enum Progress {
    /// No reports.
    #[default]
    Silent,
    /// `report(rows_done, rows)` after each row of A of a labelling pass, from the labelling's
    /// worker threads (so it may see the counts out of order); `rows_done == rows` once per pass.
    Rows(fn(u64, u64)),
}

/// Which of robot A's samples (the rows of the label array) a labelling labels: every
/// `step`-th from `first`. [`Rows::ALL`] is every row; a table built in shards
/// ([`crate::table::shard`]) gives shard `i` of `n` the rows `i, i + n, i + 2 n, ...`, so that
/// each shard gets rows from all over the grid and the shards do about equal work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rows {
    /// The first row labelled.
    pub first: usize,
    /// The distance between two labelled rows (at least 1).
    pub step: usize,
}

impl Rows {
    /// Every row.
    pub const ALL: Rows = Rows { first: 0, step: 1 };

    /// How many of `na` rows are labelled.
    pub fn count(self, na: usize) -> usize {
        na.saturating_sub(self.first).div_ceil(self.step.max(1))
    }

    /// The row (A's sample index) of the `j`-th labelled row.
    #[inline]
    pub fn row(self, j: usize) -> usize {
        self.first + j * self.step.max(1)
    }

    /// Which labelled row A's sample `ia` is (`j` with `row(j) == ia`), when it is one.
    #[inline]
    pub fn index_of(self, ia: usize) -> Option<usize> {
        let step = self.step.max(1);
        (ia >= self.first && (ia - self.first) % step == 0).then(|| (ia - self.first) / step)
    }
}

/// Slack (mm) of every axis-aligned pre-test: boxes closer than this go on to the exact test.
pub const AABB_SLACK: Real = 1e-6;

/// What one entry (a sample, or a sub-cell of one) of [`SampleBoxes`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// Boxes at the centre are built (enlarged as asked).
    Boxes,
    /// The centre is unreachable (exact and thesis-style labelling) or no TCP of the cell is
    /// ([`Inflation::Unreachable`], certified labelling): the pairs are labelled
    /// [`Label::Unreachable`].
    Unreachable,
    /// No TCP of the entry's cube is reachable: nothing there can collide (sub-cells only).
    Vacuous,
    /// Nothing could be proved (no displacement bound): every pair is a collision.
    Unknown,
}

/// How to enlarge the boxes of one entry when building [`SampleBoxes`] (a short-lived value,
/// one per entry while building: its size does not matter).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Inflation {
    /// Box `j` swept by the displacement set `.0[j]` (MCS; on top of the model's margin).
    Swept([Sweep; MAX_BOXES]),
    /// See [`Slot::Vacuous`].
    Vacuous,
    /// Proved: no TCP of the cell is reachable (a [`Slot::Unreachable`] sample).
    Unreachable,
    /// See [`Slot::Unknown`] (whether or not the centre is reachable).
    Unknown,
}

/// The axis-aligned bounds of one swept box. [`SampleBoxes`] keeps them in an array of
/// their own, apart from the rest of the boxes: the bounds of a box pair are the first thing
/// its test reads, and a pair they set apart reads no other byte of its two boxes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweptBounds {
    /// Lower corner.
    pub lo: [Real; 3],
    /// Upper corner.
    pub hi: [Real; 3],
}

impl SweptBounds {
    /// The bounds of box `b` swept by `sweep`.
    pub fn new(b: &Obb, sweep: &Sweep) -> SweptBounds {
        let h = swept_aabb_half(b, sweep);
        let (lo, hi) = (b.center - h, b.center + h);
        SweptBounds { lo: [lo.x, lo.y, lo.z], hi: [hi.x, hi.y, hi.z] }
    }
}

/// One box of a [`SampleBoxes`] entry with what the box test reads after the bounds
/// ([`SweptBounds`]), side by side (one stretch of memory per box: the tests read boxes of
/// many entries in turn), in the order the tests read it: what every axis of the swept test
/// reads (the centre and the frame), then the sweep, whose supports only some axes need. The
/// box's axes and half-extents are kept once, in the frame ([`SweptBox::obb`] gives the box
/// back, the same numbers), and the sweep without the segment a table's sweep never has
/// ([`TableSweep`]): 313 bytes, aligned to a 64-byte cache line, so that a box takes five
/// lines and no more.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct SweptBox {
    /// Centre of the box at the entry's centre.
    pub center: Vec3,
    /// Its axes, half-extents and the sweep's supports on its axes
    /// ([`crate::cspace::swept_sat`]).
    pub frame: SweptFrame,
    /// Its displacement set in the WCS ([`Sweep::ZERO`] for the exact boxes).
    pub sweep: TableSweep,
    /// Whether the sweep is [`Sweep::is_zero`] (an exact box: the separating axis test).
    pub exact: bool,
}

impl SweptBox {
    /// Box `b` swept by `sweep`.
    ///
    /// # Panics
    /// When `sweep` has a segment: the tables' sweeps have none, and the swept test, which
    /// leaves it out, would not cover it.
    pub fn new(b: Obb, sweep: Sweep) -> SweptBox {
        let table = TableSweep::of(&sweep).expect("a table's sweep has no segment");
        SweptBox {
            center: b.center,
            frame: SweptFrame::new(&b, &table),
            sweep: table,
            exact: sweep.is_zero(),
        }
    }

    /// The box at the entry's centre: the centre, and the frame's axes (as columns) and
    /// half-extents, copied back unchanged (so the box given to [`SweptBox::new`]).
    #[inline]
    pub fn obb(&self) -> Obb {
        let (u, h) = (&self.frame.u, &self.frame.h);
        Obb {
            center: self.center,
            axes: Mat3::from_fn(|r, k| u[k][r]),
            half: Vec3::new(h[0], h[1], h[2]),
        }
    }
}

/// One robot's boxes at a list of centres (sample centres, or sub-cell centres), in the WCS,
/// with their axis-aligned bounds: built once, shared by every pair.
#[derive(Clone, Debug)]
pub struct SampleBoxes {
    /// Boxes per entry.
    pub per_entry: usize,
    /// Box `j` of entry `s` at `s * per_entry + j` (meaningful when `slot[s]` is `Boxes`).
    pub boxes: Vec<SweptBox>,
    /// The bounds of `boxes[i]` at `bounds[i]`.
    pub bounds: Vec<SweptBounds>,
    /// Per entry: the AABB of all its boxes, lower corner.
    pub lo: Vec<[Real; 3]>,
    /// Per entry: upper corner.
    pub hi: Vec<[Real; 3]>,
    /// Per entry: what it holds.
    pub slot: Vec<Slot>,
}

/// One entry of [`SampleBoxes`] made whole: its slot, each box with its bounds, and the
/// entry's bounds (`lo`, `hi`).
type EntryBoxes = (Slot, Vec<(SweptBox, SweptBounds)>, [Real; 3], [Real; 3]);

impl SampleBoxes {
    /// The boxes of `model` placed by `placement` with the TCP at each of `centres` (MCS),
    /// enlarged as `inflate(s)` says; an unreachable centre gives [`Slot::Unreachable`].
    pub fn new<F>(
        model: &RobotModel,
        placement: &Placement,
        centres: &[Vec3],
        inflate: F,
    ) -> SampleBoxes
    where
        F: Fn(usize) -> Inflation + Sync,
    {
        let nb = model.box_count();
        let empty = Obb::new(Vec3::zeros(), Mat3::identity(), Vec3::zeros());
        // Each entry whole (boxes, their bounds, the entry's bounds and slot) in parallel; only
        // the copies into the flat arrays below are serial.
        let per: Vec<EntryBoxes> = centres
            .par_iter()
            .enumerate()
            .map(|(s, c)| {
                let (mut slot, boxes) = match (inflate(s), model.boxes(c)) {
                    (Inflation::Vacuous, _) => (Slot::Vacuous, vec![]),
                    (Inflation::Unreachable, _) => (Slot::Unreachable, vec![]),
                    (Inflation::Unknown, _) => (Slot::Unknown, vec![]),
                    (_, Err(_)) => (Slot::Unreachable, vec![]),
                    (Inflation::Swept(sweeps), Ok(boxes)) => {
                        let rot = placement.rotation();
                        let b = boxes.as_slice().iter().zip(sweeps);
                        (
                            Slot::Boxes,
                            b.map(|(b, s)| (placement.obb_to_wcs(b), s.rotated(&rot))).collect(),
                        )
                    }
                };
                let (mut lo, mut hi) = ([Real::INFINITY; 3], [Real::NEG_INFINITY; 3]);
                let swept = (0..nb)
                    .map(|j| {
                        let (b, sweep) = boxes.get(j).copied().unwrap_or((empty, Sweep::ZERO));
                        let bounds = SweptBounds::new(&b, &sweep);
                        for a in 0..3 {
                            lo[a] = min_or_nan(lo[a], bounds.lo[a]);
                            hi[a] = max_or_nan(hi[a], bounds.hi[a]);
                        }
                        (SweptBox::new(b, sweep), bounds)
                    })
                    .collect();
                // A non-finite box or sweep proves nothing: every pair of the entry is a collision.
                if slot == Slot::Boxes && !lo.iter().chain(&hi).all(|v| v.is_finite()) {
                    slot = Slot::Unknown;
                }
                (slot, swept, lo, hi)
            })
            .collect();
        let n = centres.len();
        let mut out = SampleBoxes {
            per_entry: nb,
            boxes: Vec::with_capacity(n * nb),
            bounds: Vec::with_capacity(n * nb),
            lo: Vec::with_capacity(n),
            hi: Vec::with_capacity(n),
            slot: Vec::with_capacity(n),
        };
        for (slot, swept, lo, hi) in per {
            for (b, bounds) in swept {
                out.boxes.push(b);
                out.bounds.push(bounds);
            }
            out.lo.push(lo);
            out.hi.push(hi);
            out.slot.push(slot);
        }
        out
    }

    /// The entries `entries` (indices into `self`), in that order.
    pub fn subset(&self, entries: &[u32]) -> SampleBoxes {
        let n = self.per_entry;
        let per_box = |e: &u32| *e as usize * n..(*e as usize + 1) * n;
        let entry = |v: &[_]| entries.iter().map(|&e| v[e as usize]).collect::<Vec<_>>();
        SampleBoxes {
            per_entry: n,
            boxes: entries.iter().flat_map(per_box).map(|i| self.boxes[i]).collect(),
            bounds: entries.iter().flat_map(per_box).map(|i| self.bounds[i]).collect(),
            lo: entry(&self.lo),
            hi: entry(&self.hi),
            slot: entries.iter().map(|&e| self.slot[e as usize]).collect(),
        }
    }

    /// Entry count.
    pub fn len(&self) -> usize {
        self.slot.len()
    }
}

/// Whether the closed boxes `[alo, ahi]` and `[blo, bhi]` are apart by more than the slack.
#[inline]
pub(crate) fn aabbs_apart(
    alo: &[Real; 3],
    ahi: &[Real; 3],
    blo: &[Real; 3],
    bhi: &[Real; 3],
) -> bool {
    (0..3).any(|k| blo[k] > ahi[k] + AABB_SLACK || alo[k] > bhi[k] + AABB_SLACK)
}

/// Whether two swept boxes' bounds are apart by more than the slack.
#[inline]
pub(crate) fn bounds_apart(a: &SweptBounds, b: &SweptBounds) -> bool {
    aabbs_apart(&a.lo, &a.hi, &b.lo, &b.hi)
}

/// Whether the AABBs of A's entry `ia` and B's entry `ib` (all their boxes) are apart.
#[inline]
pub(crate) fn entries_apart(a: &SampleBoxes, ia: usize, b: &SampleBoxes, ib: usize) -> bool {
    aabbs_apart(&a.lo[ia], &a.hi[ia], &b.lo[ib], &b.hi[ib])
}

/// Whether box `i` of A (index into `a.boxes`) and box `j` of B may intersect: not proved
/// apart by their AABBs, nor by the separating axis test (exact boxes) or its swept form
/// ([`crate::cspace::swept_sat::swept_apart`], the 15 axes of
/// [`crate::geometry::swept_boxes_apart`] written in A's frame).
#[inline]
pub(crate) fn boxes_may_touch(a: &SampleBoxes, i: usize, b: &SampleBoxes, j: usize) -> bool {
    if bounds_apart(&a.bounds[i], &b.bounds[j]) {
        return false;
    }
    let (x, y) = (&a.boxes[i], &b.boxes[j]);
    if x.exact && y.exact {
        separating_axis(&x.obb(), &y.obb()).is_none()
    } else {
        !swept_apart(&x.center, &x.frame, &x.sweep, &y.center, &y.frame, &y.sweep)
    }
}

/// Whether some box of A's entry `ia` intersects some box of B's entry `ib` (both `Boxes`).
#[inline]
pub fn entries_collide(a: &SampleBoxes, ia: usize, b: &SampleBoxes, ib: usize) -> bool {
    if entries_apart(a, ia, b, ib) {
        return false;
    }
    let (na, nb) = (a.per_entry, b.per_entry);
    for i in ia * na..(ia + 1) * na {
        for j in ib * nb..(ib + 1) * nb {
            if boxes_may_touch(a, i, b, j) {
                return true;
            }
        }
    }
    false
}

/// The box pairs among `mask` (bit `8 i + j`: box `i` of A, box `j` of B) that A's entry
/// `ia` and B's entry `ib` (both `Boxes`) do not prove disjoint; 0 when all are disjoint.
pub fn collision_mask(a: &SampleBoxes, ia: usize, b: &SampleBoxes, ib: usize, mask: u64) -> u64 {
    if mask == 0 || aabbs_apart(&a.lo[ia], &a.hi[ia], &b.lo[ib], &b.hi[ib]) {
        return 0;
    }
    let (na, nb) = (a.per_entry, b.per_entry);
    let mut out = 0;
    let mut rest = mask;
    while rest != 0 {
        let bit = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        let (i, j) = (ia * na + bit / 8, ib * nb + bit % 8);
        if boxes_may_touch(a, i, b, j) {
            out |= 1 << bit;
        }
    }
    out
}

/// Every box pair of models with `na` and `nb` boxes, as a [`collision_mask`] mask.
pub fn all_box_pairs(na: usize, nb: usize) -> u64 {
    (0..na).flat_map(|i| (0..nb).map(move |j| 1u64 << (8 * i + j))).fold(0, |m, b| m | b)
}

/// The label of every pair `(ia, ib)` of the rows `rows` of A, at `j * b.len() + ib` for
/// `ia = rows.row(j)` (at `ia * b.len() + ib` with [`Rows::ALL`]): `Unreachable` when either
/// centre is unreachable, `Collision` when either is `Unknown` or some pair of boxes
/// intersects and `second_look(ia, ib)` (called only then) confirms it, else `Free`.
/// Rows are labelled in parallel, each reported to `progress`.
pub fn label_pairs<F>(
    a: &SampleBoxes,
    b: &SampleBoxes,
    second_look: F,
    rows: Rows,
    progress: Progress,
) -> PairLabels
where
    F: Fn(usize, usize) -> bool + Sync,
{
    label_rows_except(&RowLabeller::new(b), a, second_look, rows, progress, |_| false, |_, _| {})
}

/// As [`label_pairs`] with B's side made once (`labeller`), leaving the rows of A that `skip`
/// names as `Collision` without testing them (the caller fills them), and every other row
/// finished by `then(ia, row)` before it is stored.
pub(crate) fn label_rows_except<F>(
    labeller: &RowLabeller,
    a: &SampleBoxes,
    second_look: F,
    rows: Rows,
    progress: Progress,
    skip: impl Fn(usize) -> bool + Sync,
    then: impl Fn(usize, &mut [Label]) + Sync,
) -> PairLabels
where
    F: Fn(usize, usize) -> bool + Sync,
{
    let nb = labeller.base.len();
    let rows_done = AtomicU64::new(0);
    let labelled = rows.count(a.len());
    PairLabels::from_rows(labelled, nb, |j, row| {
        let ia = rows.row(j);
        if !skip(ia) {
            labeller.row(a, ia, &second_look, row);
            then(ia, row);
        }
        if let Progress::Rows(report) = progress {
            report(rows_done.fetch_add(1, Ordering::Relaxed) + 1, labelled as u64);
        }
    })
}

/// What labelling one row of A against every entry of B needs from B alone: each entry's
/// label when nothing of A meets it, and B's entries with boxes sorted by the lower x of
/// their AABB (stored in that order, so that a row's candidates are read in memory order).
pub(crate) struct RowLabeller {
    base: Vec<Label>,
    order: Vec<u32>,
    keys: Vec<Real>,
    widest: Real,
    sorted: SampleBoxes,
}

impl RowLabeller {
    /// B's side of the labelling.
    pub(crate) fn new(b: &SampleBoxes) -> RowLabeller {
        let base: Vec<Label> = b
            .slot
            .iter()
            .map(|s| match s {
                Slot::Boxes | Slot::Vacuous => Label::Free,
                Slot::Unreachable => Label::Unreachable,
                Slot::Unknown => Label::Collision,
            })
            .collect();
        let mut order: Vec<u32> =
            (0..b.len() as u32).filter(|&i| b.slot[i as usize] == Slot::Boxes).collect();
        order.sort_by(|&i, &j| b.lo[i as usize][0].total_cmp(&b.lo[j as usize][0]));
        let keys: Vec<Real> = order.iter().map(|&i| b.lo[i as usize][0]).collect();
        let widest =
            order.iter().map(|&i| b.hi[i as usize][0] - b.lo[i as usize][0]).fold(0.0, Real::max);
        let sorted = b.subset(&order);
        RowLabeller { base, order, keys, widest, sorted }
    }

    /// The labels of A's entry `ia` with every entry of B, into `row` ([`label_pairs`]).
    pub(crate) fn row<F>(&self, a: &SampleBoxes, ia: usize, second_look: &F, row: &mut [Label])
    where
        F: Fn(usize, usize) -> bool,
    {
        let base = &self.base;
        match a.slot[ia] {
            Slot::Unreachable => row.fill(Label::Unreachable),
            Slot::Vacuous => row
                .iter_mut()
                .zip(base)
                .for_each(|(l, &bl)| *l = if bl == Label::Unreachable { bl } else { Label::Free }),
            Slot::Unknown => row.iter_mut().zip(base).for_each(|(l, &bl)| {
                *l = if bl == Label::Unreachable { bl } else { Label::Collision }
            }),
            Slot::Boxes => {
                row.copy_from_slice(base);
                let (lo, hi) = (a.lo[ia][0], a.hi[ia][0]);
                let first = self.keys.partition_point(|&x| x < lo - self.widest - AABB_SLACK);
                let last = self.keys.partition_point(|&x| x <= hi + AABB_SLACK).max(first);
                for (k, &ib) in self.order.iter().enumerate().take(last).skip(first) {
                    let ib = ib as usize;
                    if entries_collide(a, ia, &self.sorted, k) && second_look(ia, ib) {
                        row[ib] = Label::Collision;
                    }
                }
            }
        }
    }
}

/// Robot `i` of a two-robot cell with `margin` added to its model's margin.
pub(crate) fn robot_with_margin(cell: &Cell, i: usize, margin: Real) -> (RobotModel, Placement) {
    let r = &cell.robots[i];
    let options = ModelOptions { margin: r.model.options.margin + margin, ..r.model.options };
    (RobotModel { options, ..r.model }, r.placement)
}

pub(crate) fn two_robot_grids(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
) -> Result<(SampleGrid, SampleGrid), String> {
    if cell.robots.len() != 2 {
        return Err(format!(
            "cell '{}' has {} robots; tables are built for two-robot cells (split the cell into pairs)",
            cell.name,
            cell.robots.len()
        ));
    }
    Ok((
        SampleGrid::new(ws, k, &cell.robots[0].model.delta)?,
        SampleGrid::new(ws, k, &cell.robots[1].model.delta)?,
    ))
}

/// Labels every sample pair of the two-robot `cell` (robots 0 and 1) at `k` cells per axis,
/// with `margin` added to every half-extent of both robots (on top of their own margins).
///
/// # Errors
/// When the cell does not have exactly two robots, `margin` is not finite and >= 0, or the
/// grid cannot be built ([`SampleGrid::new`]).
pub fn label_space(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    margin: Real,
    progress: Progress,
) -> Result<LabelledSpace, String> {
    label_space_rows(cell, k, ws, margin, Rows::ALL, progress)
}

/// As [`label_space`] for the rows `rows` of A only: `labels` holds them as
/// [`label_pairs`] returns them (all of them, in the usual order, with [`Rows::ALL`]).
///
/// # Errors
/// As [`label_space`].
pub(crate) fn label_space_rows(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    margin: Real,
    rows: Rows,
    progress: Progress,
) -> Result<LabelledSpace, String> {
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(format!("labelling margin = {margin} must be finite and >= 0 (mm)"));
    }
    let (grid_a, grid_b) = two_robot_grids(cell, k, ws)?;
    let (ma, pa) = robot_with_margin(cell, 0, margin);
    let (mb, pb) = robot_with_margin(cell, 1, margin);
    let a = SampleBoxes::new(&ma, &pa, &centres(&grid_a), |_| {
        Inflation::Swept([Sweep::ZERO; MAX_BOXES])
    });
    let b = SampleBoxes::new(&mb, &pb, &centres(&grid_b), |_| {
        Inflation::Swept([Sweep::ZERO; MAX_BOXES])
    });
    let labels = label_pairs(&a, &b, |_, _| true, rows, progress);
    Ok(LabelledSpace { grid_a, grid_b, labels, margin })
}

/// The thesis's labelling (3.2.7): every half-extent enlarged by `r / sqrt(2)`. Not a proof
/// (see [`crate::cspace::guarantee`]); kept for comparison.
///
/// # Errors
/// As [`label_space`].
pub fn label_space_thesis(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    progress: Progress,
) -> Result<LabelledSpace, String> {
    label_space_thesis_rows(cell, k, ws, Rows::ALL, progress)
}

/// As [`label_space_thesis`] for the rows `rows` of A only (see [`label_space_rows`]).
///
/// # Errors
/// As [`label_space`].
pub(crate) fn label_space_thesis_rows(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    rows: Rows,
    progress: Progress,
) -> Result<LabelledSpace, String> {
    let (g, _) = two_robot_grids(cell, k, ws)?;
    label_space_rows(cell, k, ws, thesis_margin(g.r), rows, progress)
}

/// The centres of every sample of `grid`, in sample order.
pub fn centres(grid: &SampleGrid) -> Vec<Vec3> {
    (0..grid.cells.len()).map(|s| grid.sample_center(s)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sweep::tests::{any_box, any_sweep};
    use proptest::prelude::*;

    /// `index_of` inverts `row` on the rows labelled and names no other of the `na` rows: checked
    /// against the list of rows written out, for shards 0..n of n = 1..6 (and a step of 0, read as
    /// 1).
    #[test]
    fn rows_index_of_finds_exactly_the_labelled_rows() {
        let na = 50;
        for n in 0..6 {
            for first in 0..=n {
                let rows = Rows { first, step: n };
                let listed: Vec<usize> = (0..rows.count(na)).map(|j| rows.row(j)).collect();
                for ia in 0..na {
                    assert_eq!(
                        rows.index_of(ia),
                        listed.iter().position(|&r| r == ia),
                        "{rows:?} row {ia}"
                    );
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// A swept box keeps its box's axes and half-extents only in its frame: the box it gives
        /// back is the one it was made from, to the bit, so the plain separating axis test and
        /// the cores read the numbers they were given.
        #[test]
        fn swept_box_gives_back_its_box(b in any_box(), s in any_sweep()) {
            let back = SweptBox::new(b, s).obb();
            let bits = |o: &Obb| {
                o.center.iter().chain(o.axes.iter()).chain(o.half.iter()).map(|x| x.to_bits()).collect::<Vec<_>>()
            };
            prop_assert_eq!(bits(&back), bits(&b));
        }

        /// The bounds kept apart from the boxes are each box's own: those of the box and sweep
        /// it gives back, to the bit, at the same index, in a robot's boxes and in any subset
        /// of its entries; so the test that reads them first answers as it did with the
        /// bounds inside the box. An index out of step or a bound of another box fails it.
        #[test]
        fn bounds_apart_from_the_boxes_are_each_boxs_own(
                tcps in prop::collection::vec((-120.0..120.0f64, -120.0..120.0f64, -500.0..-300.0f64), 1..6),
                sweeps in prop::collection::vec(any_sweep(), MAX_BOXES),
                exact in any::<bool>(), pick in prop::collection::vec(0..6u32, 0..8)) {
            let cell = crate::cell::reference::reference_cell("T3").unwrap();
            let robot = &cell.robots[1];
            let centres: Vec<Vec3> = tcps.iter().map(|&(x, y, z)| Vec3::new(x, y, z)).collect();
            let sweeps: [Sweep; MAX_BOXES] = core::array::from_fn(|j| if exact { Sweep::ZERO } else { sweeps[j] });
            let all = SampleBoxes::new(&robot.model, &robot.placement, &centres, |_| Inflation::Swept(sweeps));
            let entries: Vec<u32> = pick.iter().map(|&e| e % centres.len() as u32).collect();
            let some = all.subset(&entries);
            for boxes in [&all, &some] {
                prop_assert_eq!(boxes.bounds.len(), boxes.boxes.len());
                for (bounds, b) in boxes.bounds.iter().zip(&boxes.boxes) {
                    let own = SweptBounds::new(&b.obb(), &b.sweep.sweep());
                    let bits = |x: &SweptBounds| x.lo.iter().chain(&x.hi).map(|v| v.to_bits()).collect::<Vec<_>>();
                    prop_assert_eq!(bits(bounds), bits(&own));
                }
            }
            let n = all.per_entry;
            for (k, &e) in entries.iter().enumerate() {
                for j in 0..n {
                    prop_assert_eq!(some.boxes[k * n + j], all.boxes[e as usize * n + j]);
                }
            }
        }
    }

    /// A swept box fills five cache lines and starts on one: the swept test reads five lines
    /// per box, not six or seven.
    #[test]
    fn a_swept_box_is_five_aligned_cache_lines() {
        assert_eq!(size_of::<SweptBox>(), 5 * 64);
        assert_eq!(align_of::<SweptBox>(), 64);
    }
}
