//! Certified labelling: free labels that are proofs for whole 6-D grid cells (SPEC §6,
//! thesis 3.2.7).
//!
//! Each robot's boxes at a cell's reference TCP are swept by their displacement sets over the
//! cell ([`box_sweeps`], direction-aware, [`crate::cspace::guarantee`]); a box pair is proved
//! disjoint over a 6-D cell when the swept boxes are ([`crate::geometry::sweep`]). A pair of
//! samples `(ia, ib)` is free when it is proved free at one of two levels:
//! 1. every box pair is proved disjoint with the whole cells' sweeps; or, failing that,
//! 2. (refinement) each robot's cell is cut into its 8 octants, each with its own reference
//!    boxes and sweeps over the octant ([`cube_box_sweeps`], about half as large), and for
//!    every pair (octant i of A, octant j of B) each box pair is proved disjoint by one of
//!    the tests (A cell, B cell), (A octant i, B cell), (A cell, B octant j) or (A octant i,
//!    B octant j) (a box pair proved disjoint by a coarser test is disjoint for every
//!    configuration it covers). Octants that hold no reachable TCP are skipped. Pairs whose
//!    physical boxes collide at the reference TCPs skip this level.
//!
//! Either way every configuration of the 6-D cell is covered by a disjoint pair of swept
//! box sets, each of which contains the physical boxes for every TCP of its (sub)cell. Anything
//! not proved is a collision. [`label_space_subdivided`] keeps level 2's answer per octant pair
//! for the pairs that stay collisions ([`SubCells`]), with one more level for those:
//! 3. an octant pair that level 2 leaves a collision, unless some box pair's octant cores
//!    meet (a certain collision), is cut once more: each octant into its 8 sub-octants
//!    (half-side `r/8`; boxes and sweeps made when an octant first needs them), and it is
//!    free when, for every pair of sub-octants, each box pair that level 2 left open is
//!    proved disjoint by (A sub-octant, B sub-octant), (A sub-octant, B octant) or
//!    (A octant, B sub-octant). The sub-octants cover their octant, so the proof covers the
//!    whole sub-cell. These sweeps are not made mirror-symmetric: a symmetric cell's
//!    sub-cells are found for the half its table stores ("Symmetric cells" below).
//!
//! The sub-cells are found faster than by 64 runs of level 2 (`sub_cell_masks`, same
//! answers): an octant pair is a collision without its tests when a box pair certainly
//! intersects for every configuration of a (sub)cell pair holding it (the boxes' *cores*
//! overlap, [`crate::geometry::sweep`], "Certain intersection"); whole cells decide all 64
//! at once, an octant with the other robot's whole cell decides a row or column of 8.
//! Boxes that meet at two configurations decide the same way, with plain separating axis
//! tests instead of swept ones: every swept test whose cubes hold both configurations keeps
//! the box pair open. So a pair whose boxes meet at the whole cells' reference TCPs (cell
//! centres, each held by all 8 octants) has all its octant pairs collisions at levels 2 and 3
//! (`held_by_references`; which octants hold a reference is counted as the sweeps cover their
//! cubes, `sweeps::octants_holding`), as the octants' references meeting already decided
//! level 3 of an octant pair.
//!
//! A sample is labelled [`Label::Unreachable`](crate::cspace::Label) ("don't care") only
//! when no TCP of its whole cell is reachable ([`cube_unreachable`]); a cell whose centre is
//! unreachable but which holds reachable TCPs is measured from a reachable reference point,
//! or, without one, has no displacement bound and is a collision.
//!
//! Sweeps are made mirror-symmetric (every size the larger of an entry's and its mirror's,
//! arms 1 and 2 swapped), so that a symmetric cell gets symmetric labels (thesis 3.2.8).
//!
//! # Symmetric cells
//! A cell with the reflection `y -> -y` ([`crate::cspace::symmetry::reflection_y`]) has a
//! table that stores A's upper half `iy >= k/2` only, a query in the other half reading its
//! mirror. Its sub-cells (level 3, by far the largest cost of a build) are found for the
//! stored half only ([`stored_half`]): a sub-cell proved free is a proof for every
//! configuration of it, and the reflection maps those configurations onto the mirror
//! sub-cell's while it maps the two robots onto themselves, so no configuration of the
//! mirror sub-cell collides either (thesis Lemma 3.2.1); likewise a sub-cell proved to hold
//! no reachable TCP ("don't care") mirrors to one without any. The proof does not use the mirror
//! pair's own tests; finding them too would only make more sub-cells collisions where the
//! rounding of the mirror's boxes differs. For the same reason the whole-cell labels (levels
//! 1 and 2) of a lower-half sample are its mirror sample's with B's samples reflected
//! ([`MirrorRows`], when every B sample has its mirror): a shard whose rows' mirrors lie in
//! other shards labels those mirror rows itself, so that every shard, and a build in one
//! piece, gives each row the same labels. The reflection is exact up to the placement's
//! `alpha`, which [`reflection_y`](crate::cspace::symmetry::reflection_y) allows to differ from
//! 0 or pi by `1e-12` rad: that moves B's boxes by at most `1e-8` mm within 5 m of its base,
//! far inside the `1e-6` mm gap every separating axis of a proof keeps
//! ([`crate::geometry::sweep`], `SWEEP_GAP`).
//!
//! This file runs the labelling; `sweeps.rs` makes the displacement sets of cells and
//! octants, `refine.rs` holds levels 2 and 3 and the sub-cell labels, and, for the report
//! tool only (`eval` feature), `subdivided_labels.rs` spells the sub-cells out as labels at
//! `2 k`.
//!
//! [`box_sweeps`]: crate::cspace::guarantee::box_sweeps
//! [`cube_box_sweeps`]: crate::robot::motion_bound::cube_box_sweeps
//! [`cube_unreachable`]: crate::robot::motion_bound::cube_unreachable

pub(crate) mod clearance;
mod refine;
#[cfg(feature = "eval")]
mod subdivided_labels;
mod sweeps;

#[cfg(feature = "eval")]
pub use subdivided_labels::SubdividedLabels;

use crate::cell::{Cell, RobotSpec};
use crate::cspace::guarantee::CELL_SPLITS;
use crate::cspace::label::{
    entries_collide, label_pairs, label_rows_except, two_robot_grids, Inflation, Progress,
    RowLabeller, Rows, SampleBoxes,
};
use crate::cspace::sampler::{SampleGrid, Workspace};
use crate::cspace::symmetry::{in_stored_half, mirror_samples, reflection_y};
use crate::cspace::{Label, LabelledSpace, PairLabels};
use crate::geometry::Sweep;
use crate::math::{Real, Vec3};
use crate::robot::MAX_BOXES;
use refine::{octants_prove_free, sub_cell_masks, sub_cells, Levels, SubOctants, UnknownCells};
use sweeps::{cell_sweeps, inflation, octants, reference_octants, references, unreachable_cells};

/// Sub-boxes per axis when enclosing the motor angles over an octant (an octant is half as
/// wide as a cell, so this gives the same sub-box size as [`CELL_SPLITS`] on a cell).
pub const OCTANT_SPLITS: u32 = CELL_SPLITS / 2;

/// A labelling whose free labels are proofs for whole 6-D cells, with the bounds it used.
#[derive(Clone, Debug, PartialEq)]
pub struct CertifiedSpace {
    /// The labels; `space.margin` is the largest whole-cell enlargement used (each box got
    /// its own, never more than this).
    pub space: LabelledSpace,
    /// Per sample of A, per box: the radius of the whole-cell displacement set its box was
    /// swept by ([`Sweep::radius`]).
    pub bounds_a: Vec<[Real; MAX_BOXES]>,
    /// Per sample of B, per box.
    pub bounds_b: Vec<[Real; MAX_BOXES]>,
    /// Whether level 2 (octant refinement) was used.
    pub refined: bool,
    /// With [`label_space_subdivided`]: the sub-cell labels of every pair labelled collision.
    pub sub: Option<SubCells>,
    /// Seconds spent finding [`sub`](Self::sub) (0 without it), for the caller to report:
    /// the library prints nothing.
    pub sub_secs: f64,
}

/// Sub-cell labels of the pairs labelled collision: each such 6-D cell cut into its 64
/// sub-cells (A's octant `i` x B's octant `j`), each proved free or not with the octants'
/// own bounds and, failing that, the sub-octants' (levels 2 and 3 of the module doc;
/// adaptive resolution where the labels change).
///
/// Bit `c` of a mask is the sub-cell with child index `c = ax << 5 | ay << 4 | az << 3 |
/// bx << 2 | by << 1 | bz` (octant bits x, y, z of A then B; the order of
/// [`crate::table::code`]). A sub-cell outside `care` holds no reachable TCP of A or of B
/// ("don't care"); one in `collision` could not be proved free. For a cell with the
/// reflection `y -> -y`, only the pairs of A's stored half have sub-cells (module doc,
/// "Symmetric cells").
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct SubCells {
    /// Pair indices `ia * nb + ib`, increasing.
    pub pairs: Vec<u64>,
    /// Per pair: the sub-cells that hold reachable TCPs of both robots.
    pub care: Vec<u64>,
    /// Per pair: the sub-cells not proved free.
    pub collision: Vec<u64>,
}

impl SubCells {
    /// `(care, collision)` of pair `(ia, ib)`, or `None` when it was not subdivided.
    pub fn get(&self, pair: u64) -> Option<(u64, u64)> {
        self.pairs.binary_search(&pair).ok().map(|i| (self.care[i], self.collision[i]))
    }
}

/// For a cell with the reflection `y -> -y`, which of A's samples are in the half a table
/// stores (`iy >= k/2`): only their sub-cells are found (module doc, "Symmetric cells").
/// `None` for a cell without it: every sample's are.
pub(crate) fn stored_half(cell: &Cell, grid_a: &SampleGrid) -> Option<Vec<bool>> {
    reflection_y(cell).then(|| grid_a.cells.iter().map(|&c| in_stored_half(grid_a, c)).collect())
}

/// For a cell with the reflection `y -> -y` whose B samples all have their mirror sample:
/// the mirror of each B sample, and of each A sample outside the half a table stores (when
/// sampled). Those rows of A take their mirror rows' labels, B's samples reflected (module
/// doc, "Symmetric cells").
struct MirrorRows {
    /// Per A sample: its mirror when it lies outside the stored half, else `None`.
    a: Vec<Option<usize>>,
    /// Per B sample: its mirror.
    b: Vec<usize>,
}

impl MirrorRows {
    /// `None` for a cell without the reflection or a B sample without its mirror.
    fn of(cell: &Cell, grid_a: &SampleGrid, grid_b: &SampleGrid) -> Option<MirrorRows> {
        if !reflection_y(cell) {
            return None;
        }
        let b = mirror_samples(grid_b).into_iter().collect::<Option<Vec<_>>>()?;
        let a = grid_a
            .cells
            .iter()
            .zip(mirror_samples(grid_a))
            .map(|(&c, m)| m.filter(|_| !in_stored_half(grid_a, c)));
        Some(MirrorRows { a: a.collect(), b })
    }

    /// Writes each reflected row of `labels` (the rows `rows` of A, `nb` labels each) from its
    /// mirror row, read from `labels` when `rows` holds it and labelled by `row_of` otherwise
    /// (the rows of a shard): label `(ia, ib)` is that of `(a[ia], b[ib])`. Rows are written in
    /// parallel, the mirror rows read from a copy of the labels (a quarter byte per pair).
    fn fill(
        &self,
        labels: &mut PairLabels,
        rows: Rows,
        row_of: impl Fn(usize) -> Vec<Label> + Sync,
    ) {
        if self.b.is_empty() {
            return;
        }
        let sources = labels.clone();
        labels.rows_mut(|j, row| {
            let Some(m) = self.a[rows.row(j)] else { return };
            let source = match rows.index_of(m) {
                // A mirror row is in the stored half, so never reflected itself.
                Some(_) if self.a[m].is_some() => return,
                Some(jm) => sources.row(jm),
                // The mirror row is not among `rows` (a shard's): labelled here.
                None => row_of(m),
            };
            row.iter_mut().zip(&self.b).for_each(|(l, &mb)| *l = source[mb]);
        });
    }
}

/// The child index of A's octant `i` and B's octant `j` (octant bits x, y, z = 0, 1, 2).
pub fn sub_cell_index(i: usize, j: usize) -> u32 {
    let b = |o: usize, bit: usize| (o >> bit & 1) as u32;
    b(i, 0) << 5 | b(i, 1) << 4 | b(i, 2) << 3 | b(j, 0) << 2 | b(j, 1) << 1 | b(j, 2)
}

/// How far the certified labelling refines (the levels of the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refinement {
    /// Level 1 only: whole-cell bounds.
    WholeCells,
    /// Levels 1 and 2: octant pairs for what level 1 leaves open.
    Octants,
    /// Levels 1 to 3, keeping the sub-cell labels of the pairs that stay collisions
    /// ([`CertifiedSpace::sub`]).
    SubCells,
}

/// What the certified labelling does and shows.
#[derive(Clone, Copy, Debug)]
pub struct CertifyConfig {
    /// How far it refines.
    pub refinement: Refinement,
    /// Where the labelling reports its progress.
    pub progress: Progress,
}

/// Certified labels of every sample pair of the two-robot `cell` at `k` cells per axis, with
/// octant refinement (see the module doc).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_certified(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    progress: Progress,
) -> Result<CertifiedSpace, String> {
    label_space_certified_with(
        cell,
        k,
        ws,
        &CertifyConfig { refinement: Refinement::Octants, progress },
    )
}

/// As [`label_space_certified`], and every pair labelled collision is subdivided into its 64
/// sub-cells, each certified with the octants' bounds or the sub-octants' (levels 2 and 3,
/// [`CertifiedSpace::sub`]).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_subdivided(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    progress: Progress,
) -> Result<CertifiedSpace, String> {
    label_space_certified_with(
        cell,
        k,
        ws,
        &CertifyConfig { refinement: Refinement::SubCells, progress },
    )
}

/// Certified labels of every sample pair of the two-robot `cell` at `k` cells per axis,
/// refined as far as `config` says.
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_certified_with(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    config: &CertifyConfig,
) -> Result<CertifiedSpace, String> {
    certify_rows(cell, k, ws, config, Rows::ALL)
}

/// As [`label_space_certified_with`] for the rows `rows` of A only (one shard of a table
/// build): `space.labels` holds them as [`label_pairs`] returns them (row `j` of the
/// selection at `j * nb`), and the sub-cells' pairs keep their numbers `ia * nb + ib`. Each
/// robot's sweeps are made for its whole grid, so the labels are those of the whole build.
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub(crate) fn certify_rows(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    config: &CertifyConfig,
    rows: Rows,
) -> Result<CertifiedSpace, String> {
    certify_rows_then(cell, k, ws, config, rows, false, |c, _| c)
}

/// The sub-cells of one pair at a time, found when asked ([`certify_rows_then`] with
/// `defer_sub`): the same masks as [`CertifiedSpace::sub`] holds, so that a table build can
/// find them block by block and drop them (and the sub-octant boxes they needed) in between.
pub(crate) struct SubCellSource<'a> {
    a: Levels<'a>,
    b: Levels<'a>,
}

impl SubCellSource<'_> {
    /// `(care, collision)` of pair `(ia, ib)`, as [`SubCells::get`] gives it for a pair labelled
    /// collision.
    pub(crate) fn masks(&self, ia: usize, ib: usize) -> (u64, u64) {
        sub_cell_masks(&self.a, &self.b, ia, ib, false)
    }

    /// Bytes held by the sub-octant boxes made so far (both robots).
    pub(crate) fn cached_bytes(&self) -> usize {
        [&self.a.subs, &self.b.subs].into_iter().flatten().map(SubOctants::cached_bytes).sum()
    }

    /// Drops the sub-octant boxes made so far: they are made again when needed, with the same
    /// answers.
    pub(crate) fn clear_cache(&mut self) {
        for subs in [&mut self.a.subs, &mut self.b.subs].into_iter().flatten() {
            subs.clear();
        }
    }
}

/// As [`certify_rows`], handing the result to `then`; with `defer_sub` (and sub-cell
/// refinement) the sub-cells are not found here: `then` gets a [`SubCellSource`] instead,
/// alive while it runs (it borrows the robots' boxes of the labelling).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub(crate) fn certify_rows_then<R>(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    config: &CertifyConfig,
    rows: Rows,
    defer_sub: bool,
    then: impl FnOnce(CertifiedSpace, Option<&mut SubCellSource<'_>>) -> R,
) -> Result<R, String> {
    let refine = config.refinement != Refinement::WholeCells;
    let subdivide = config.refinement == Refinement::SubCells;
    let progress = config.progress;
    let (grid_a, grid_b) = two_robot_grids(cell, k, ws)?;
    let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
    let (sweeps_a, sweeps_b) = (cell_sweeps(&ra.model, &grid_a), cell_sweeps(&rb.model, &grid_b));
    let (empty_a, empty_b) =
        (unreachable_cells(&ra.model, &grid_a), unreachable_cells(&rb.model, &grid_b));
    let (refs_a, refs_b) = (references(&ra.model, &grid_a), references(&rb.model, &grid_b));
    let a0 = whole_cell_boxes(ra, &refs_a, &sweeps_a, &empty_a);
    let b0 = whole_cell_boxes(rb, &refs_b, &sweeps_b, &empty_b);
    let radii =
        |ss: &[[Sweep; MAX_BOXES]]| ss.iter().map(|s| s.map(|w| w.radius())).collect::<Vec<_>>();
    let (bounds_a, bounds_b) = (radii(&sweeps_a), radii(&sweeps_b));
    let used = |bs: &[[Real; MAX_BOXES]]| {
        bs.iter().flatten().copied().filter(|v| v.is_finite()).fold(0.0, Real::max)
    };
    let margin = used(&bounds_a).max(used(&bounds_b));
    let certified = |labels, sub, sub_secs: f64, grid_a, grid_b| {
        let space = LabelledSpace { grid_a, grid_b, labels, margin };
        let sub_secs = if subdivide { sub_secs } else { 0.0 };
        CertifiedSpace { space, bounds_a, bounds_b, refined: refine, sub, sub_secs }
    };
    if !refine {
        let labels = label_pairs(&a0, &b0, |_, _| true, rows, progress);
        return Ok(then(certified(labels, None, 0.0, grid_a, grid_b), None));
    }
    let (a1, b1) = (octant_boxes(ra, &grid_a), octant_boxes(rb, &grid_b));
    // The physical boxes at the reference points: a pair that collides there is a
    // collision without refinement.
    let none = |_| Inflation::Swept([Sweep::ZERO; MAX_BOXES]);
    let (xa, xb) = (
        SampleBoxes::new(&ra.model, &ra.placement, &refs_a, none),
        SampleBoxes::new(&rb.model, &rb.placement, &refs_b, none),
    );
    let (mut la, mut lb) = (
        Levels::with_references(&a0, &a1, reference_octants(&grid_a, &refs_a)),
        Levels::with_references(&b0, &b1, reference_octants(&grid_b, &refs_b)),
    );
    if subdivide {
        (la.subs, lb.subs) =
            (Some(SubOctants::new(ra, &grid_a)), Some(SubOctants::new(rb, &grid_b)));
    }
    let collides =
        |ia, ib| entries_collide(&xa, ia, &xb, ib) || !octants_prove_free(&la, &lb, ia, ib);
    // A symmetric cell's lower half takes its mirror rows' labels (module doc, "Symmetric cells").
    let mirror = MirrorRows::of(cell, &grid_a, &grid_b);
    let reflected = |ia: usize| mirror.as_ref().is_some_and(|m| m.a[ia].is_some());
    let labeller = RowLabeller::new(&b0);
    let unknown = UnknownCells::new(&la, &lb);
    let refine_row = |ia, row: &mut [Label]| unknown.refine_row(&la, &lb, ia, row);
    let mut labels =
        label_rows_except(&labeller, &a0, collides, rows, progress, reflected, refine_row);
    if let Some(m) = &mirror {
        m.fill(&mut labels, rows, |ia| {
            let mut row = vec![Label::Collision; b0.len()];
            labeller.row(&a0, ia, &collides, &mut row);
            unknown.refine_row(&la, &lb, ia, &mut row);
            row
        });
    }
    drop((xa, xb, labeller, unknown));
    let (ga, gb) = (grid_a.clone(), grid_b.clone());
    if subdivide && defer_sub {
        let mut source = SubCellSource { a: la, b: lb };
        return Ok(then(certified(labels, None, 0.0, ga, gb), Some(&mut source)));
    }
    let start = std::time::Instant::now();
    let stored = stored_half(cell, &grid_a);
    let sub = subdivide
        .then(|| sub_cells(&la, &lb, &labels, rows, |ia| stored.as_ref().is_none_or(|s| s[ia])));
    let sub_secs = start.elapsed().as_secs_f64();
    Ok(then(certified(labels, sub, sub_secs, ga, gb), None))
}

/// One robot's level-1 boxes: at each sample's reference point `refs[s]`, swept by its
/// whole-cell displacement sets (`Unreachable` where the whole cell is, `empty[s]`).
fn whole_cell_boxes(
    robot: &RobotSpec,
    refs: &[Vec3],
    sweeps: &[[Sweep; MAX_BOXES]],
    empty: &[bool],
) -> SampleBoxes {
    let inflate = |s: usize| if empty[s] { Inflation::Unreachable } else { inflation(sweeps[s]) };
    SampleBoxes::new(&robot.model, &robot.placement, refs, inflate)
}

/// One robot's level-2 boxes: entry `8 s + i` for octant `i` of sample `s` ([`octants`]).
fn octant_boxes(robot: &RobotSpec, grid: &SampleGrid) -> SampleBoxes {
    let (refs, inflate) = octants(&robot.model, grid);
    SampleBoxes::new(&robot.model, &robot.placement, &refs, |s| inflate[s])
}

#[cfg(test)]
mod tests {
    use super::refine::*;
    use super::sweeps::octant_centre;
    use super::*;
    use crate::cell::reference::reference_cell;
    use crate::cspace::label::{all_box_pairs, Slot};
    use crate::cspace::{label_space, Label};
    use crate::geometry::Obb;

    /// Certified labels only add collisions to the exact centre labels, are "unreachable" only
    /// where the centre is, and refinement only removes collisions that level 1 could not
    /// prove free.
    #[test]
    fn certified_labels_contain_exact_collisions_and_refinement_only_frees() {
        let ws = Workspace::THESIS;
        for name in ["T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let exact = label_space(&cell, 16, &ws, 0.0, Progress::Silent).unwrap();
            let whole_cells =
                CertifyConfig { refinement: Refinement::WholeCells, progress: Progress::Silent };
            let coarse = label_space_certified_with(&cell, 16, &ws, &whole_cells).unwrap();
            let fine = label_space_certified(&cell, 16, &ws, Progress::Silent).unwrap();
            let (mut freed, mut added) = (0, 0);
            for ((e, c), f) in
                exact.labels.iter().zip(coarse.space.labels.iter()).zip(fine.space.labels.iter())
            {
                assert!(f != Label::Unreachable || e == Label::Unreachable);
                assert_eq!(c == Label::Unreachable, f == Label::Unreachable);
                assert!(e != Label::Collision || f == Label::Collision);
                assert!(c != Label::Free || f == Label::Free);
                freed += (c == Label::Collision && f == Label::Free) as usize;
                added += (e == Label::Free && f == Label::Collision) as usize;
            }
            assert!(freed > 0 && added > 0, "{name}: {freed} freed, {added} added");
        }
    }

    /// Both robots' boxes at both levels, as [`label_space_subdivided`] builds them: `(a0, a1,
    /// b0, b1)`.
    fn level_boxes(cell: &Cell, k: u32) -> (SampleBoxes, SampleBoxes, SampleBoxes, SampleBoxes) {
        let (grid_a, grid_b) = two_robot_grids(cell, k, &Workspace::THESIS).unwrap();
        let whole = |r: &RobotSpec, g: &SampleGrid| {
            whole_cell_boxes(
                r,
                &references(&r.model, g),
                &cell_sweeps(&r.model, g),
                &unreachable_cells(&r.model, g),
            )
        };
        let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
        (
            whole(ra, &grid_a),
            octant_boxes(ra, &grid_a),
            whole(rb, &grid_b),
            octant_boxes(rb, &grid_b),
        )
    }

    /// The labels of A's lower half taken from the mirror rows ([`MirrorRows`]) are those the
    /// rows' own tests give: on the symmetric T1 and T2 at k = 16, every label of a certified
    /// labelling equals the one found by levels 1 and 2 on its own row, with no row reflected
    /// (every reflected row is checked: a third of the rows or more).
    #[test]
    fn mirror_rows_give_the_labels_of_their_own_tests() {
        for name in ["T1", "T2"] {
            let cell = reference_cell(name).unwrap();
            let c = label_space_certified(&cell, 16, &Workspace::THESIS, Progress::Silent).unwrap();
            let (ga, gb) = (&c.space.grid_a, &c.space.grid_b);
            let mirror = MirrorRows::of(&cell, ga, gb).expect("T1 and T2 are symmetric");
            let reflected = mirror.a.iter().filter(|m| m.is_some()).count();
            assert!(3 * reflected >= ga.cells.len(), "{name}: {reflected} rows reflected");
            let (a0, a1, b0, b1) = level_boxes(&cell, 16);
            let (la, lb) = (Levels::new(&a0, &a1), Levels::new(&b0, &b1));
            let collides = |ia, ib| !octants_prove_free(&la, &lb, ia, ib);
            let mut own = label_pairs(&a0, &b0, collides, Rows::ALL, Progress::Silent);
            let unknown = UnknownCells::new(&la, &lb);
            own.rows_mut(|ia, row| unknown.refine_row(&la, &lb, ia, row));
            let differ = own.iter().zip(c.space.labels.iter()).filter(|(o, l)| o != l).count();
            assert_eq!(differ, 0, "{name}: {differ} labels differ");
        }
    }

    /// Reference cell `name` at k = 16 with both robots' sample grids and their whole-cell and
    /// octant boxes ([`level_boxes`]): where the sub-cell tests start.
    #[allow(clippy::type_complexity)]
    fn cell_at_16(
        name: &str,
    ) -> (Cell, (SampleGrid, SampleGrid), (SampleBoxes, SampleBoxes, SampleBoxes, SampleBoxes))
    {
        let cell = reference_cell(name).unwrap();
        let grids = two_robot_grids(&cell, 16, &Workspace::THESIS).unwrap();
        let boxes = level_boxes(&cell, 16);
        (cell, grids, boxes)
    }

    /// Robot `r`'s levels over `whole` and `octs` with its sub-octants, and with its whole
    /// cells' meeting references when `held` (as [`label_space_subdivided`] builds them).
    fn levels_with_subs<'a>(
        (whole, octs): (&'a SampleBoxes, &'a SampleBoxes),
        r: &'a RobotSpec,
        g: &'a SampleGrid,
        held: bool,
    ) -> Levels<'a> {
        let mut levels = match held {
            true => {
                Levels::with_references(whole, octs, reference_octants(g, &references(&r.model, g)))
            }
            false => Levels::new(whole, octs),
        };
        levels.subs = Some(SubOctants::new(r, g));
        levels
    }

    /// Without level 3, the sub-cells are exactly those of the plain octant tests
    /// ([`octant_pairs`]), pair by pair, on every collision pair at k = 16; a subdivided
    /// labelling has the same pairs and care masks, and level 3 only frees sub-cells.
    #[test]
    fn sub_cells_are_those_of_the_plain_octant_tests() {
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let c =
                label_space_subdivided(&cell, 16, &Workspace::THESIS, Progress::Silent).unwrap();
            let (a0, a1, b0, b1) = level_boxes(&cell, 16);
            let nb = b0.len();
            let mut want = SubCells::default();
            // A symmetric cell's sub-cells are those of A's stored half (module doc).
            let stored = stored_half(&cell, &c.space.grid_a);
            assert_eq!(stored.is_some(), name != "T3");
            let kept = |p: usize| stored.as_ref().is_none_or(|s| s[p / nb]);
            for (p, _) in
                c.space.labels.iter().enumerate().filter(|&(p, l)| l == Label::Collision && kept(p))
            {
                let (care, collision) = octant_pairs(&a0, &a1, &b0, &b1, p / nb, p % nb, false);
                want.pairs.push(p as u64);
                want.care.push(care);
                want.collision.push(collision);
            }
            assert!(!want.pairs.is_empty());
            let (a, b) = (Levels::new(&a0, &a1), Levels::new(&b0, &b1));
            assert!(
                sub_cells(&a, &b, &c.space.labels, Rows::ALL, |ia| kept(ia * nb)) == want,
                "{name}: the fast sub-cells differ from the plain ones"
            );
            let got = c.sub.as_ref().unwrap();
            assert_eq!(
                (&got.pairs, &got.care),
                (&want.pairs, &want.care),
                "{name}: pairs and care masks"
            );
            let (mut before, mut after) = (0, 0);
            for (g, w) in got.collision.iter().zip(&want.collision) {
                assert_eq!(g & !w, 0, "{name}: level 3 made a sub-cell a collision");
                (before, after) = (before + w.count_ones(), after + g.count_ones());
            }
            assert!(after < before, "{name}: level 3 freed nothing ({before} sub-cells)");
            // The labels' level 2 (first octant pair not proved free) answers as the plain one.
            let unreachable = |s: &SampleBoxes, e: usize| s.slot[e] == Slot::Unreachable;
            for ia in (0..a0.len()).filter(|&ia| !unreachable(&a0, ia)) {
                for ib in (0..nb).filter(|&ib| !unreachable(&b0, ib)) {
                    let plain = octant_pairs(&a0, &a1, &b0, &b1, ia, ib, true).1 == 0;
                    assert_eq!(
                        octants_prove_free(&a, &b, ia, ib),
                        plain,
                        "{name} pair ({ia}, {ib})"
                    );
                }
            }
        }
    }

    /// Boxes that meet at two octants' reference TCPs ([`meet_at_references`]) are never
    /// proved disjoint by the swept tests of the octants or of the whole cells that hold
    /// them: the premise of deciding a sub-cell by them. On T1, T2 and T3 at k = 16, every
    /// box pair of a spread of pairs of octants.
    #[test]
    fn boxes_meeting_at_the_references_are_never_proved_apart() {
        use crate::cspace::label::boxes_may_touch;
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let (a0, a1, b0, b1) = level_boxes(&cell, 16);
            let (na, nb) = (a0.per_entry, b0.per_entry);
            let boxes = |s: &SampleBoxes, e: usize| s.slot[e] == Slot::Boxes;
            let (mut met, mut tried) = (0, 0);
            for ia in (0..a0.len()).step_by(5).filter(|&ia| boxes(&a0, ia)) {
                for ib in (ia % 7..b0.len()).step_by(7).filter(|&ib| boxes(&b0, ib)) {
                    if !entries_collide(&a0, ia, &b0, ib) {
                        continue;
                    }
                    for (i, j) in (0..8).flat_map(|i| (0..8).map(move |j| (i, j))) {
                        let (sa, sb) = (8 * ia + i, 8 * ib + j);
                        if !boxes(&a1, sa) || !boxes(&b1, sb) {
                            continue;
                        }
                        for p in (0..na).flat_map(|x| (0..nb).map(move |y| 8 * x + y)) {
                            tried += 1;
                            if !meet_at_references(&a1, sa, &b1, sb, p) {
                                continue;
                            }
                            met += 1;
                            let (x, y) = (p / 8, p % 8);
                            assert!(
                                boxes_may_touch(&a1, sa * na + x, &b1, sb * nb + y),
                                "{name} octants {sa} {sb}"
                            );
                            let (i, j) = (sa * na + x, ib * nb + y);
                            assert!(
                                boxes_may_touch(&a1, i, &b0, j),
                                "{name} octant {sa}, cell {ib}"
                            );
                            let (i, j) = (ia * na + x, sb * nb + y);
                            assert!(
                                boxes_may_touch(&a0, i, &b1, j),
                                "{name} cell {ia}, octant {sb}"
                            );
                            assert!(
                                boxes_may_touch(&a0, ia * na + x, &b0, ib * nb + y),
                                "{name} cells {ia} {ib}"
                            );
                        }
                    }
                }
            }
            assert!(met > 100, "{name}: {met} of {tried} box pairs meet at the references");
        }
    }

    /// The octant pairs held by the whole cells' meeting references ([`held_by_references`])
    /// change no sub-cell: on T1, T2 and T3 at k = 16, every collision pair's sub-cells,
    /// levels 2 and 3, are those found without that exit, which decides many pairs.
    #[test]
    fn reference_exits_change_no_sub_cell() {
        let ws = Workspace::THESIS;
        for name in ["T1", "T2", "T3"] {
            let (cell, (grid_a, grid_b), (a0, a1, b0, b1)) = cell_at_16(name);
            let labels =
                label_space_certified(&cell, 16, &ws, Progress::Silent).unwrap().space.labels;
            let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
            let levels = |fast: bool| {
                (
                    levels_with_subs((&a0, &a1), ra, &grid_a, fast),
                    levels_with_subs((&b0, &b1), rb, &grid_b, fast),
                )
            };
            let ((fa, fb), (pa, pb)) = (levels(true), levels(false));
            let nb = b0.len();
            let collisions = labels.iter().enumerate().filter(|&(_, l)| l == Label::Collision);
            let decided = collisions
                .filter(|&(p, _)| held_by_references(&fa, &fb, p / nb, p % nb) != 0)
                .count();
            let fast = sub_cells(&fa, &fb, &labels, Rows::ALL, |_| true);
            let plain = sub_cells(&pa, &pb, &labels, Rows::ALL, |_| true);
            assert!(fast == plain, "{name}: the references' exit changed sub-cells");
            assert!(
                decided > 1000,
                "{name}: {decided} of {} pairs decided by the references",
                fast.pairs.len()
            );
        }
    }

    /// [`Known`] answers as asking the test about the whole mask every time, and asks it about
    /// each box pair once: random masks over random answers.
    #[test]
    fn known_answers_as_testing_every_time() {
        let mut rng = crate::test_rng::TestRng(0x5eed);
        for _ in 0..500 {
            let truth = rng.next_u64();
            let (mut known, mut asked) = (Known::default(), 0u64);
            for _ in 0..20 {
                let mask = rng.next_u64() & rng.next_u64();
                let got = known.open(mask, |m| {
                    assert_eq!(m & asked, 0, "a box pair asked twice");
                    asked |= m;
                    truth & m
                });
                assert_eq!(got, truth & mask);
            }
        }
    }

    /// The sub-cells of [`sub_cell_masks`] with level 3 and every exit (the whole cells' and
    /// the octants' references, the cores, level 3's hinted exit and its columns tested only
    /// where a row leaves a box pair open) are those of the plain statement: level 2 as
    /// [`octant_pairs`], then level 3 as [`sub_octants_prove_free_plainly`] on the box pairs
    /// the three tests of the octant pair leave open. A third of the collision pairs of T1, T2
    /// and T3 at k = 16.
    #[test]
    fn sub_cells_with_level_3_answer_as_their_plain_statement() {
        use crate::cspace::label::collision_mask;
        let ws = Workspace::THESIS;
        for name in ["T1", "T2", "T3"] {
            let (cell, (grid_a, grid_b), (a0, a1, b0, b1)) = cell_at_16(name);
            let labels =
                label_space_certified(&cell, 16, &ws, Progress::Silent).unwrap().space.labels;
            let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
            let a = levels_with_subs((&a0, &a1), ra, &grid_a, true);
            let b = levels_with_subs((&b0, &b1), rb, &grid_b, true);
            let nb = b0.len();
            let all = all_box_pairs(a0.per_entry, b0.per_entry);
            let boxes = |s: &SampleBoxes, e: usize| s.slot[e] == Slot::Boxes;
            let (mut pairs, mut freed) = (0, 0);
            for (p, _) in
                labels.iter().enumerate().filter(|&(_, l)| l == Label::Collision).step_by(3)
            {
                let (ia, ib) = (p / nb, p % nb);
                let (care, level_2) = octant_pairs(&a0, &a1, &b0, &b1, ia, ib, false);
                let (whole_a, whole_b) = (boxes(&a0, ia), boxes(&b0, ib));
                let open0 =
                    if whole_a && whole_b { collision_mask(&a0, ia, &b0, ib, all) } else { all };
                let mut want = level_2;
                for (i, j) in (0..8).flat_map(|i| (0..8).map(move |j| (i, j))) {
                    let (sa, sb, bit) = (8 * ia + i, 8 * ib + j, 1u64 << sub_cell_index(i, j));
                    if level_2 & bit == 0 || !boxes(&a1, sa) || !boxes(&b1, sb) {
                        continue;
                    }
                    let row = if whole_b { collision_mask(&a1, sa, &b0, ib, open0) } else { open0 };
                    let column =
                        if whole_a { collision_mask(&a0, ia, &b1, sb, open0) } else { open0 };
                    let open = collision_mask(&a1, sa, &b1, sb, row & column);
                    if sub_octants_prove_free_plainly(&a, &b, sa, sb, open) {
                        want &= !bit;
                        freed += 1;
                    }
                }
                assert_eq!(
                    sub_cell_masks(&a, &b, ia, ib, false),
                    (care, want),
                    "{name} pair ({ia}, {ib})"
                );
                pairs += 1;
            }
            assert!(freed > 1000, "{name}: {freed} octant pairs freed by level 3 in {pairs} pairs");
        }
    }

    /// Level 3 ([`sub_octants_prove_free`], with its hint, its reference test and its columns
    /// tested only where a row leaves a box pair open) answers as its plain statement
    /// ([`sub_octants_prove_free_plainly`]) on every octant pair that level 2 leaves open, of
    /// a spread of collision pairs of T1, T2 and T3 at k = 16.
    #[test]
    fn level_3_answers_as_its_plain_statement() {
        use crate::cspace::label::collision_mask;
        for name in ["T1", "T2", "T3"] {
            let (cell, (grid_a, grid_b), (a0, a1, b0, b1)) = cell_at_16(name);
            let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
            let a = levels_with_subs((&a0, &a1), ra, &grid_a, false);
            let b = levels_with_subs((&b0, &b1), rb, &grid_b, false);
            let (na, nb) = (a0.per_entry, b0.per_entry);
            let all = all_box_pairs(na, nb);
            let boxes = |s: &SampleBoxes, e: usize| s.slot[e] == Slot::Boxes;
            let (mut hint, mut tried, mut freed) = (0, 0, 0);
            for ia in (0..a0.len()).step_by(3).filter(|&ia| boxes(&a0, ia)) {
                for ib in (ia % 5..b0.len()).step_by(5).filter(|&ib| boxes(&b0, ib)) {
                    let open0 = collision_mask(&a0, ia, &b0, ib, all);
                    if open0 == 0 {
                        continue;
                    }
                    for (sa, sb) in
                        (0..8).flat_map(|i| (0..8).map(move |j| (8 * ia + i, 8 * ib + j)))
                    {
                        if !boxes(&a1, sa) || !boxes(&b1, sb) {
                            continue;
                        }
                        let open = collision_mask(&a1, sa, &b0, ib, open0)
                            & collision_mask(&a0, ia, &b1, sb, open0)
                            & collision_mask(&a1, sa, &b1, sb, open0);
                        if open == 0 {
                            continue;
                        }
                        let first = open.trailing_zeros() as usize;
                        let fast =
                            sub_octants_prove_free(&a, &b, sa, sb, first, || open, &mut hint);
                        assert_eq!(
                            fast,
                            sub_octants_prove_free_plainly(&a, &b, sa, sb, open),
                            "{name} {sa} {sb}"
                        );
                        (tried, freed) = (tried + 1, freed + fast as usize);
                    }
                }
            }
            assert!(freed > 100 && tried > freed, "{name}: {freed} of {tried} octant pairs freed");
        }
    }

    /// At k = 32, where cores exist, the fast masks ([`sub_cell_masks`]) equal the plain ones on
    /// a spread of pairs whose boxes may meet, among them pairs where each certificate of a
    /// certain intersection (whole cells, A's octant with B's cell, A's cell with B's octant)
    /// decides.
    #[test]
    fn fast_sub_cell_masks_match_the_plain_ones_where_cores_meet() {
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let (a0, a1, b0, b1) = level_boxes(&cell, 32);
            let (a, b) = (Levels::new(&a0, &a1), Levels::new(&b0, &b1));
            let (na, nb) = (a0.per_entry, b0.per_entry);
            let all = all_box_pairs(na, nb);
            let (mut tried, mut whole, mut row, mut column) = (0, 0, 0, 0);
            for ia in (0..a0.len()).step_by(7) {
                for ib in (ia % 11..b0.len()).step_by(11) {
                    let boxes = a0.slot[ia] == Slot::Boxes && b0.slot[ib] == Slot::Boxes;
                    if !boxes || !entries_collide(&a0, ia, &b0, ib) {
                        continue;
                    }
                    tried += 1;
                    let got = sub_cell_masks(&a, &b, ia, ib, false);
                    assert_eq!(
                        got,
                        octant_pairs(&a0, &a1, &b0, &b1, ia, ib, false),
                        "{name} pair ({ia}, {ib})"
                    );
                    whole +=
                        cores_meet(&a.whole_cores, ia, na, &b.whole_cores, ib, nb, all) as usize;
                    let octant_meets =
                        |c: &[Option<Obb>], s: usize, d: &[Option<Obb>], e: usize, f: usize| {
                            (0..8).any(|i| {
                                if f == 0 {
                                    cores_meet(c, 8 * s + i, na, d, e, nb, all)
                                } else {
                                    cores_meet(c, s, na, d, 8 * e + i, nb, all)
                                }
                            })
                        };
                    row += octant_meets(&a.oct_cores, ia, &b.whole_cores, ib, 0) as usize;
                    column += octant_meets(&a.whole_cores, ia, &b.oct_cores, ib, 1) as usize;
                }
            }
            assert!(
                whole > 0 && row > whole && column > whole,
                "{name}: {tried} pairs, cores meet {whole} {row} {column}"
            );
        }
    }

    /// Level 3 is sound: in every sub-cell that it frees (a collision at level 2, on T1, T2
    /// and T3 at k = 16), 16 random configurations, each TCP uniform in its octant, are free
    /// for the exact model; and so are their mirror images (`y -> -y` of both TCPs in their
    /// MCS) on the symmetric T1 and T2, whose sub-cells are found for the stored half alone
    /// (module doc, "Symmetric cells").
    #[test]
    fn sub_cells_freed_by_level_3_hold_no_collision() {
        use crate::cell::{ExactChecker, SatMethod};
        use rand::{rngs::StdRng, RngExt, SeedableRng};
        let ws = Workspace::THESIS;
        let mut rng = StdRng::seed_from_u64(3);
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let c = label_space_subdivided(&cell, 16, &ws, Progress::Silent).unwrap();
            let (a0, a1, b0, b1) = level_boxes(&cell, 16);
            let stored = stored_half(&cell, &c.space.grid_a);
            let plain = sub_cells(
                &Levels::new(&a0, &a1),
                &Levels::new(&b0, &b1),
                &c.space.labels,
                Rows::ALL,
                |ia| stored.as_ref().is_none_or(|s| s[ia]),
            );
            assert_eq!(plain.pairs, c.sub.as_ref().unwrap().pairs);
            let got = c.sub.as_ref().unwrap();
            let (ga, gb, nb) = (&c.space.grid_a, &c.space.grid_b, c.space.grid_b.cells.len());
            let mut exact = ExactChecker::new(Cell { method: SatMethod::Sat, ..cell.clone() });
            let octant = |g: &SampleGrid, s: usize, o: usize| {
                octant_centre(&g.sample_center(s), o, 0.25 * g.r)
            };
            let (mut freed, mut checked, mut mirrored) = (0, 0, 0);
            for (e, &pair) in got.pairs.iter().enumerate() {
                let (ia, ib) = (pair as usize / nb, pair as usize % nb);
                for (i, j) in (0..8).flat_map(|i| (0..8).map(move |j| (i, j))) {
                    let bit = 1u64 << sub_cell_index(i, j);
                    if plain.collision[e] & bit == 0 || got.collision[e] & bit != 0 {
                        continue;
                    }
                    freed += 1;
                    let (ca, cb) = (octant(ga, ia, i), octant(gb, ib, j));
                    for _ in 0..16 {
                        let mut point = |c: &Vec3, g: &SampleGrid| {
                            c + Vec3::from_fn(|_, _| (rng.random::<Real>() - 0.5) * 0.5 * g.r)
                        };
                        let tcps = [point(&ca, ga), point(&cb, gb)];
                        let v = exact.check(&tcps).unwrap();
                        if v.unreachable_mask == 0 {
                            checked += 1;
                            assert!(
                                !v.collides(),
                                "{name}: sub-cell ({i}, {j}) of pair ({ia}, {ib}) collides at {tcps:?}"
                            );
                        }
                        if stored.is_some() {
                            let mirror = tcps.map(|p| Vec3::new(p.x, -p.y, p.z));
                            let v = exact.check(&mirror).unwrap();
                            mirrored += usize::from(v.unreachable_mask == 0);
                            assert!(
                                v.unreachable_mask != 0 || !v.collides(),
                                "{name}: the mirror of sub-cell ({i}, {j}) of pair ({ia}, {ib}) collides at {mirror:?}"
                            );
                        }
                    }
                }
            }
            assert!(
                freed > 1000 && checked > 8 * freed,
                "{name}: {freed} freed sub-cells, {checked} configurations"
            );
            assert!(
                stored.is_none() || mirrored > 8 * freed,
                "{name}: {mirrored} mirror configurations"
            );
        }
    }
}
