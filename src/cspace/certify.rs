//! Certified labelling: free labels that are proofs for whole 6-D grid cells (SPEC §6,
//! thesis 3.2.7; issues 3 and 4).
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
//!    whole sub-cell. These sweeps are not made mirror-symmetric: the tables merge each
//!    sub-cell with its mirror's, collision winning.
//!
//! The sub-cells are found faster than by 64 runs of level 2 (`sub_cell_masks`, same
//! answers): an octant pair is a collision without its tests when a box pair certainly
//! intersects for every configuration of a (sub)cell pair holding it (the boxes' *cores*
//! overlap, [`crate::geometry::sweep`], "Certain intersection"); whole cells decide all 64
//! at once, an octant with the other robot's whole cell decides a row or column of 8.
//!
//! A sample is labelled [`Label::Unreachable`](crate::cspace::Label) ("don't care") only
//! when no TCP of its whole cell is reachable ([`cube_unreachable`]); a cell whose centre is
//! unreachable but which holds reachable TCPs is measured from a reachable reference point,
//! or, without one, has no displacement bound and is a collision.
//!
//! Sweeps are made mirror-symmetric (every size the larger of an entry's and its mirror's,
//! arms 1 and 2 swapped), so that a symmetric cell gets symmetric labels (thesis 3.2.8).

use crate::cell::{Cell, RobotSpec};
use crate::cspace::guarantee::{box_sweeps, cube_box_sweeps, cube_unreachable, reference_point, SPLITS};
use crate::cspace::label::{
    aabbs_apart, all_box_pairs, boxes_may_touch, collision_mask, entries_apart, entries_collide, label_pairs,
    two_robot_grids, Inflation, SampleBoxes, Slot,
};
use crate::cspace::sampler::{SampleGrid, Workspace};
use crate::cspace::symmetry::mirror_cell;
use crate::cspace::{Label, LabelledSpace};
use crate::geometry::sweep::{boxes_overlap_deeply, core};
use crate::geometry::witness::MAX_BOXES;
use crate::geometry::{Obb, Sweep};
use crate::math::{max_or_nan, min_or_nan, Real, Vec3};
use crate::robot::{BoxKind, RobotModel};
use rayon::prelude::*;
use std::sync::OnceLock;

/// Rows of A whose sub-cells are found together ([`sub_cells`]; a cache blocking, any value
/// gives the same answers).
const SUB_CELL_ROWS: usize = 16;

/// Sub-boxes per axis when enclosing the motor angles over an octant (an octant is half as
/// wide as a cell, so this gives the same sub-box size as [`SPLITS`] on a cell).
pub const OCTANT_SPLITS: u32 = SPLITS / 2;

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
}

/// Sub-cell labels of the pairs labelled collision: each such 6-D cell cut into its 64
/// sub-cells (A's octant `i` x B's octant `j`), each proved free or not with the octants'
/// own bounds and, failing that, the sub-octants' (levels 2 and 3 of the module doc;
/// adaptive resolution where the labels change).
///
/// Bit `c` of a mask is the sub-cell with child index `c = ax << 5 | ay << 4 | az << 3 |
/// bx << 2 | by << 1 | bz` (octant bits x, y, z of A then B; the order of
/// [`crate::table::code`]). A sub-cell outside `care` holds no reachable TCP of A or of B
/// ("don't care"); one in `collision` could not be proved free.
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

/// The child index of A's octant `i` and B's octant `j` (octant bits x, y, z = 0, 1, 2).
pub fn sub_cell_index(i: usize, j: usize) -> u32 {
    let b = |o: usize, bit: usize| (o >> bit & 1) as u32;
    b(i, 0) << 5 | b(i, 1) << 4 | b(i, 2) << 3 | b(j, 0) << 2 | b(j, 1) << 1 | b(j, 2)
}

/// Certified labels of every sample pair of the two-robot `cell` at `k` cells per axis, with
/// octant refinement (see the module doc).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_certified(cell: &Cell, k: u32, ws: &Workspace, progress: bool) -> Result<CertifiedSpace, String> {
    label_space_certified_with(cell, k, ws, true, progress)
}

/// As [`label_space_certified`], and every pair labelled collision is subdivided into its 64
/// sub-cells, each certified with the octants' bounds or the sub-octants' (levels 2 and 3,
/// [`CertifiedSpace::sub`]).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_subdivided(cell: &Cell, k: u32, ws: &Workspace, progress: bool) -> Result<CertifiedSpace, String> {
    label_space_certified_inner(cell, k, ws, true, true, progress)
}

/// As [`label_space_certified`]; `refine = false` stops at level 1 (whole-cell bounds only).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_certified_with(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    refine: bool,
    progress: bool,
) -> Result<CertifiedSpace, String> {
    label_space_certified_inner(cell, k, ws, refine, false, progress)
}

fn label_space_certified_inner(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    refine: bool,
    subdivide: bool,
    progress: bool,
) -> Result<CertifiedSpace, String> {
    let (grid_a, grid_b) = two_robot_grids(cell, k, ws)?;
    let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
    let (sweeps_a, sweeps_b) = (cell_sweeps(&ra.model, &grid_a), cell_sweeps(&rb.model, &grid_b));
    let (empty_a, empty_b) = (unreachable_cells(&ra.model, &grid_a), unreachable_cells(&rb.model, &grid_b));
    let (refs_a, refs_b) = (references(&ra.model, &grid_a), references(&rb.model, &grid_b));
    let a0 = whole_cell_boxes(ra, &refs_a, &sweeps_a, &empty_a);
    let b0 = whole_cell_boxes(rb, &refs_b, &sweeps_b, &empty_b);
    let labels = if refine {
        let (a1, b1) = (octant_boxes(ra, &grid_a), octant_boxes(rb, &grid_b));
        // The physical boxes at the reference points: a pair that collides there is a
        // collision without refinement.
        let none = |_| Inflation::Swept([Sweep::ZERO; MAX_BOXES]);
        let (xa, xb) = (
            SampleBoxes::new(&ra.model, &ra.placement, &refs_a, none),
            SampleBoxes::new(&rb.model, &rb.placement, &refs_b, none),
        );
        let (mut la, mut lb) = (Levels::new(&a0, &a1), Levels::new(&b0, &b1));
        if subdivide {
            (la.subs, lb.subs) = (Some(SubOctants::new(ra, &grid_a)), Some(SubOctants::new(rb, &grid_b)));
        }
        let collides = |ia, ib| entries_collide(&xa, ia, &xb, ib) || !octants_prove_free(&la, &lb, ia, ib);
        let mut labels = label_pairs(&a0, &b0, collides, progress);
        refine_unknown_cells(&la, &lb, &mut labels);
        let sub = subdivide.then(|| {
            let start = std::time::Instant::now();
            let sub = sub_cells(&la, &lb, &labels);
            if progress {
                eprintln!("sub-cells of {} collision pairs: {:.2} s", sub.pairs.len(), start.elapsed().as_secs_f64());
            }
            sub
        });
        (labels, sub)
    } else {
        (label_pairs(&a0, &b0, |_, _| true, progress), None)
    };
    let (labels, sub) = labels;
    let radii = |ss: &[[Sweep; MAX_BOXES]]| ss.iter().map(|s| s.map(|w| w.radius())).collect::<Vec<_>>();
    let (bounds_a, bounds_b) = (radii(&sweeps_a), radii(&sweeps_b));
    let used = |bs: &[[Real; MAX_BOXES]]| bs.iter().flatten().copied().filter(|v| v.is_finite()).fold(0.0, Real::max);
    let margin = used(&bounds_a).max(used(&bounds_b));
    let space = LabelledSpace { grid_a, grid_b, labels, margin };
    Ok(CertifiedSpace { space, bounds_a, bounds_b, refined: refine, sub })
}

/// One robot's level-1 boxes: at each sample's reference point `refs[s]`, swept by its
/// whole-cell displacement sets (`Unreachable` where the whole cell is, `empty[s]`).
fn whole_cell_boxes(robot: &RobotSpec, refs: &[Vec3], sweeps: &[[Sweep; MAX_BOXES]], empty: &[bool]) -> SampleBoxes {
    let inflate = |s: usize| if empty[s] { Inflation::Unreachable } else { inflation(sweeps[s]) };
    SampleBoxes::new(&robot.model, &robot.placement, refs, inflate)
}

/// One robot's level-2 boxes: entry `8 s + i` for octant `i` of sample `s` ([`octants`]).
fn octant_boxes(robot: &RobotSpec, grid: &SampleGrid) -> SampleBoxes {
    let (refs, inflate) = octants(&robot.model, grid);
    SampleBoxes::new(&robot.model, &robot.placement, &refs, |s| inflate[s])
}

/// One robot's boxes at both levels with their cores ([`core`]: what every configuration of
/// the (sub)cell covers; `None` for a box without one or an entry without boxes).
struct Levels<'a> {
    whole: &'a SampleBoxes,
    octs: &'a SampleBoxes,
    whole_cores: Vec<Option<Obb>>,
    oct_cores: Vec<Option<Obb>>,
    /// Level 3, for the sub-cells only.
    subs: Option<SubOctants<'a>>,
}

impl<'a> Levels<'a> {
    fn new(whole: &'a SampleBoxes, octs: &'a SampleBoxes) -> Self {
        Levels { whole, octs, whole_cores: cores(whole), oct_cores: cores(octs), subs: None }
    }
}

/// Level 3 (sub-cells only, module doc): each octant cut into its 8 sub-octants (half-side
/// `r/8`), their boxes and sweeps made when an octant first needs them.
struct SubOctants<'a> {
    robot: &'a RobotSpec,
    grid: &'a SampleGrid,
    /// Per octant entry `8 s + i`: its sub-octants, entry `u` offset by `+/- r/8` along x,
    /// y, z for bits 0, 1, 2 of `u`.
    boxes: Vec<OnceLock<SampleBoxes>>,
}

impl<'a> SubOctants<'a> {
    fn new(robot: &'a RobotSpec, grid: &'a SampleGrid) -> Self {
        SubOctants { robot, grid, boxes: (0..8 * grid.cells.len()).map(|_| OnceLock::new()).collect() }
    }

    /// The sub-octants of octant entry `e`.
    fn of(&self, e: usize) -> &SampleBoxes {
        self.boxes[e].get_or_init(|| {
            let (model, r) = (&self.robot.model, self.grid.r);
            let octant = octant_centre(&self.grid.sample_center(e / 8), e % 8, 0.25 * r);
            let h = 0.125 * r;
            let cs: Vec<Vec3> = (0..8).map(|u| octant_centre(&octant, u, h)).collect();
            let refs: Vec<Vec3> = cs.iter().map(|c| reference_point(&model.delta, c, h).unwrap_or(*c)).collect();
            let inflate = |u: usize| octant_sweeps(model, &cs[u], h, &refs[u]).map_or(Inflation::Vacuous, inflation);
            SampleBoxes::new(model, &self.robot.placement, &refs, inflate)
        })
    }
}

/// Whether level 3 proves octant pair (A's entry `sa`, B's entry `sb`) free: for each pair
/// of their sub-octants, each box pair of `open` (those the octant pair's tests left open) is
/// proved disjoint by (A sub-octant, B sub-octant), (A sub-octant, B octant) or (A octant,
/// B sub-octant). Never when a box pair's octant cores meet (a certain collision). The
/// sub-octant pair `hint` (`8 u + v`) is tried first; it is set to the one that fails.
fn sub_octants_prove_free(
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
    // The pair that failed last first, on box pair `first`, finest test first: a collision
    // usually fails there.
    let (u0, v0) = (*hint / 8, *hint % 8);
    let stays = |open: u64| {
        let left = fine(u0, v0, open);
        left != 0 && collision_mask(x, u0, b1, sb, left) & collision_mask(a1, sa, y, v0, left) != 0
    };
    let hinted = x.slot[u0] == Slot::Boxes && y.slot[v0] == Slot::Boxes;
    if hinted && stays(1 << first) {
        return false;
    }
    let open = open();
    if cores_meet(&a.oct_cores, sa, na, &b.oct_cores, sb, nb, open) || hinted && stays(open & !(1 << first)) {
        return false;
    }
    // Then each sub-octant against the other octant, and the finest test for what is left.
    let mut columns = [None; 8];
    for u in (0..8).filter(|&u| x.slot[u] == Slot::Boxes) {
        let row = collision_mask(x, u, b1, sb, open);
        if row == 0 {
            continue;
        }
        for v in (0..8).filter(|&v| y.slot[v] == Slot::Boxes) {
            let column = *columns[v].get_or_insert_with(|| collision_mask(a1, sa, y, v, open));
            if fine(u, v, row & column) != 0 {
                *hint = 8 * u + v;
                return false;
            }
        }
    }
    true
}

/// Per box of `boxes`: its core under its sweep, when its entry has boxes and the core exists.
fn cores(boxes: &SampleBoxes) -> Vec<Option<Obb>> {
    let n = boxes.per_entry;
    (0..boxes.boxes.len())
        .into_par_iter()
        .map(|i| if boxes.slot[i / n] == Slot::Boxes { core(&boxes.boxes[i].obb, &boxes.boxes[i].sweep) } else { None })
        .collect()
}

/// Whether some box pair among `mask` (as [`collision_mask`]) of A's entry `ia` and B's entry
/// `ib` certainly intersects: their cores overlap deeply ([`boxes_overlap_deeply`]), so the
/// boxes meet for every configuration of the two (sub)cells.
fn cores_meet(a: &[Option<Obb>], ia: usize, na: usize, b: &[Option<Obb>], ib: usize, nb: usize, mask: u64) -> bool {
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

/// The sub-cell labels of every pair labelled collision (see [`SubCells`]).
///
/// Rows of A are taken [`SUB_CELL_ROWS`] at a time, column by column, so that B's boxes of a
/// column are used by every row of the block while they are in the cache.
fn sub_cells(a: &Levels, b: &Levels, labels: &[Label]) -> SubCells {
    let nb = b.whole.len();
    if nb == 0 {
        return SubCells::default();
    }
    let rows: Vec<Vec<(u64, u64, u64)>> = labels
        .par_chunks(nb * SUB_CELL_ROWS)
        .enumerate()
        .map(|(block, rows)| {
            let mut out = vec![];
            for ib in 0..nb {
                for (r, row) in rows.chunks(nb).enumerate() {
                    if row[ib] == Label::Collision {
                        let ia = block * SUB_CELL_ROWS + r;
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
    let mut out =
        SubCells { pairs: Vec::with_capacity(n), care: Vec::with_capacity(n), collision: Vec::with_capacity(n) };
    for (pair, care, collision) in rows.into_iter().flatten() {
        out.pairs.push(pair);
        out.care.push(care);
        out.collision.push(collision);
    }
    out
}

/// The labels a subdivided labelling ([`label_space_subdivided`]) stands for, on the grid of
/// `2k` cells per axis (the octants of the `k` grid), found pair by pair: a sub-cell takes
/// its pair's label, or, for a pair with sub-cells, its own ("don't care" outside `care`). A
/// sample of the `2k` grid whose parent cell is not sampled at `k` is "don't care": queries
/// there never reach the table. A plain table built from these labels answers as the
/// subdivided one does on every sub-cell (the baseline for its size); at `k = 64` the dense
/// labels ([`SubdividedLabels::to_dense`]) would not fit in memory, so the 4-D builder reads them
/// here ([`crate::table::LinearQuadtree4d::build_subdivided`]).
pub struct SubdividedLabels<'a> {
    coarse: &'a LabelledSpace,
    sub: &'a SubCells,
    /// A's samples at `2k`.
    pub grid_a: SampleGrid,
    /// B's samples at `2k`.
    pub grid_b: SampleGrid,
    /// Per sample at `2k`: its parent sample at `k` and its octant (bits x, y, z = 0, 1, 2).
    parent_a: Vec<Option<(u32, u8)>>,
    parent_b: Vec<Option<(u32, u8)>>,
    /// `sub.pairs[row_start[ia]..row_start[ia + 1]]` are the pairs of A's sample `ia` at `k`.
    row_start: Vec<usize>,
}

impl<'a> SubdividedLabels<'a> {
    /// The `2k` grids of `cell` and the parents of their samples in `certified`'s grids.
    ///
    /// # Errors
    /// When `certified` has no sub-cells, or as [`crate::cspace::label_space`].
    pub fn new(cell: &Cell, ws: &Workspace, certified: &'a CertifiedSpace) -> Result<SubdividedLabels<'a>, String> {
        let sub = certified.sub.as_ref().ok_or("the labelling has no sub-cells")?;
        let coarse = &certified.space;
        let (grid_a, grid_b) = two_robot_grids(cell, 2 * coarse.grid_a.k, ws)?;
        let parents = |fine: &SampleGrid, coarse: &SampleGrid| -> Vec<Option<(u32, u8)>> {
            let of = |c: &[u16; 3]| {
                let p = coarse.index_of([c[0] / 2, c[1] / 2, c[2] / 2])?;
                Some((p as u32, (c[0] & 1) as u8 | ((c[1] & 1) as u8) << 1 | ((c[2] & 1) as u8) << 2))
            };
            fine.cells.iter().map(of).collect()
        };
        let (parent_a, parent_b) = (parents(&grid_a, &coarse.grid_a), parents(&grid_b, &coarse.grid_b));
        let nb0 = coarse.grid_b.cells.len() as u64;
        let row_start =
            (0..=coarse.grid_a.cells.len() as u64).map(|ia| sub.pairs.partition_point(|&p| p < ia * nb0)).collect();
        Ok(SubdividedLabels { coarse, sub, grid_a, grid_b, parent_a, parent_b, row_start })
    }

    /// These labels as one array (`8^2` times the bytes of the labels at `k`).
    pub fn to_dense(&self) -> LabelledSpace {
        let nb = self.grid_b.cells.len();
        let ibs: Vec<u32> = (0..nb as u32).collect();
        let mut labels = vec![Label::Unreachable; self.grid_a.cells.len() * nb];
        if nb > 0 {
            labels.par_chunks_mut(nb).enumerate().for_each(|(ia, row)| self.row(Some(ia), &ibs, row));
        }
        let (grid_a, grid_b) = (self.grid_a.clone(), self.grid_b.clone());
        LabelledSpace { grid_a, grid_b, labels, margin: self.coarse.margin }
    }

    /// The labels at `k` the sub-cells refine.
    pub fn coarse(&self) -> &LabelledSpace {
        self.coarse
    }

    /// The labels of A's sample `ia` with each of B's samples `ibs` (`u32::MAX`, or `ia =
    /// None`: no sample, "don't care"), into `out`.
    pub fn row(&self, ia: Option<usize>, ibs: &[u32], out: &mut [Label]) {
        let Some((pa, i)) = ia.and_then(|ia| self.parent_a[ia]) else {
            out.fill(Label::Unreachable);
            return;
        };
        let (pa, nb0) = (pa as usize, self.coarse.grid_b.cells.len());
        let labels = &self.coarse.labels[pa * nb0..(pa + 1) * nb0];
        let (first, last) = (self.row_start[pa], self.row_start[pa + 1]);
        let row = &self.sub.pairs[first..last];
        for (l, &ib) in out.iter_mut().zip(ibs) {
            let Some(&Some((pb, j))) = self.parent_b.get(ib as usize) else {
                *l = Label::Unreachable;
                continue;
            };
            *l = match labels[pb as usize] {
                Label::Collision => match row.binary_search(&((pa * nb0) as u64 + u64::from(pb))) {
                    Ok(e) => {
                        let bit = 1u64 << sub_cell_index(usize::from(i), usize::from(j));
                        if self.sub.care[first + e] & bit == 0 {
                            Label::Unreachable
                        } else if self.sub.collision[first + e] & bit != 0 {
                            Label::Collision
                        } else {
                            Label::Free
                        }
                    }
                    Err(_) => Label::Collision,
                },
                label => label,
            };
        }
    }
}

/// The sub-cells of `(ia, ib)` that hold reachable TCPs of both robots: neither octant is
/// [`Slot::Vacuous`].
fn care_mask(a1: &SampleBoxes, ia: usize, b1: &SampleBoxes, ib: usize) -> u64 {
    // `sub_cell_index(i, j) = 8 sub_cell_index(i, 0) + sub_cell_index(0, j)`: B's occupied
    // octants as one byte, shifted to each occupied octant of A's byte.
    let column =
        (0..8).filter(|&j| b1.slot[8 * ib + j] != Slot::Vacuous).fold(0u64, |m, j| m | 1 << sub_cell_index(0, j));
    (0..8).filter(|&i| a1.slot[8 * ia + i] != Slot::Vacuous).fold(0, |m, i| m | column << sub_cell_index(i, 0))
}

/// `(care, collision)` over the 64 octant pairs of `(ia, ib)`, as [`octant_pairs`] gives
/// them, faster (every change only skips tests whose answers are implied, or reorders tests
/// whose answers are combined by "and"/"or"):
/// - an octant pair is a collision as soon as a box pair certainly intersects for every
///   configuration of a (sub)cell pair that holds it ([`cores_meet`]): of the whole cells
///   (then every octant pair is), of A's octant and B's cell (its row), of A's cell and B's
///   octant (its column). Such an octant pair is never proved free by [`octant_pairs`]: its
///   octants are [`Slot::Boxes`] only with reachable reference TCPs, a configuration of the
///   pair that collides, and its tests are sound; other octants it calls collisions anyway.
/// - a box pair of an octant pair is proved disjoint when one of the tests (A octant, B
///   cell), (A cell, B octant), (A octant, B octant) proves it (after the whole cells left it
///   open); an octant pair is free when all its box pairs are. The octant-cell tests are
///   shared by the 8 pairs of a row or column and run only when first needed; the box pairs
///   are tried from the one that last stopped an octant pair, and an octant pair stops at
///   its first box pair that no test proves.
///
/// With `first_only`, stops at the first octant pair not proved free.
fn sub_cell_masks(a: &Levels, b: &Levels, ia: usize, ib: usize, first_only: bool) -> (u64, u64) {
    let (a0, a1, b0, b1) = (a.whole, a.octs, b.whole, b.octs);
    let (na, nb) = (a0.per_entry, b0.per_entry);
    let care = care_mask(a1, ia, b1, ib);
    let (whole_a, whole_b) = (a0.slot[ia] == Slot::Boxes, b0.slot[ib] == Slot::Boxes);
    let all = all_box_pairs(na, nb);
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
            let decided = !boxes(a1, sa) || !boxes(b1, sb) || row_meet || column_meet;
            // Whether box pair `p` stays open: no test of the octant pair proves it.
            let mut open = |p: usize| {
                rows.open(i, p, || !whole_b || touch(a1, sa, b0, ib, p))
                    && columns.open(j, p, || !whole_a || touch(a0, ia, b1, sb, p))
                    && touch(a1, sa, b1, sb, p)
            };
            let stopper = if decided {
                None
            } else if entries_apart(a1, sa, b1, sb) {
                Some(None)
            } else {
                Some(hint_first(open0, hint).find(|&p| open(p)))
            };
            match stopper {
                Some(None) => continue,
                Some(Some(p)) => {
                    hint = p;
                    if !first_only {
                        let left = || hint_first(open0, p).filter(|&q| open(q)).fold(0u64, |m, q| m | 1 << q);
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
struct Memo {
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
fn hint_first(mask: u64, hint: usize) -> impl Iterator<Item = usize> {
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
fn octant_pairs(
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
        let open_a = if a_slot == Slot::Boxes && whole_b { collision_mask(a1, sa, b0, ib, open0) } else { open0 };
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
                open == 0 || entries_apart(a1, sa, b1, sb) || collision_mask(a1, sa, b1, sb, open) == 0
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

/// Level 2 for a pair whose whole-cell test failed or could not run (a sample without a
/// whole-cell bound, [`Slot::Unknown`]: its centre is unreachable but its cell is not):
/// every octant pair proved free ([`sub_cell_masks`], stopping at the first that is not).
fn octants_prove_free(a: &Levels, b: &Levels, ia: usize, ib: usize) -> bool {
    sub_cell_masks(a, b, ia, ib, true).1 == 0
}

/// Level 2 for the pairs that [`label_pairs`] made collisions because a sample has no
/// whole-cell bound ([`Slot::Unknown`]): each is retried octant by octant.
fn refine_unknown_cells(a: &Levels, b: &Levels, labels: &mut [Label]) {
    let (a0, a1, b0, b1) = (a.whole, a.octs, b.whole, b.octs);
    let unknown_b: Vec<usize> = (0..b0.len()).filter(|&ib| b0.slot[ib] == Slot::Unknown).collect();
    let (cover_a, cover_b) = (octant_covers(a1), octant_covers(b1));
    let nb = b0.len();
    if nb == 0 {
        return;
    }
    labels.par_chunks_mut(nb).enumerate().for_each(|(ia, row)| {
        let mut retry = |ib: usize| {
            if row[ib] == Label::Collision
                && b0.slot[ib] != Slot::Unreachable
                && (cover_apart(&cover_a[ia], &cover_b[ib]) || octants_prove_free(a, b, ia, ib))
            {
                row[ib] = Label::Free;
            }
        };
        match a0.slot[ia] {
            Slot::Unknown => (0..nb).for_each(&mut retry),
            Slot::Boxes => unknown_b.iter().for_each(|&ib| retry(ib)),
            Slot::Unreachable | Slot::Vacuous => {}
        }
    });
}

/// Per sample: the AABB of its 8 octants' boxes (empty when every octant is vacuous), or
/// `None` when an octant has no bound (nothing can be proved from it).
fn octant_covers(octs: &SampleBoxes) -> Vec<Option<([Real; 3], [Real; 3])>> {
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
fn cover_apart(a: &Option<([Real; 3], [Real; 3])>, b: &Option<([Real; 3], [Real; 3])>) -> bool {
    match (a, b) {
        (Some((alo, ahi)), Some((blo, bhi))) => aabbs_apart(alo, ahi, blo, bhi),
        _ => false,
    }
}

/// Per sample: whether its whole cell is proved unreachable ([`cube_unreachable`]; only
/// samples whose centre is unreachable are tried). Mirror-symmetric: a sample counts only
/// when its mirror is proved too.
fn unreachable_cells(model: &RobotModel, grid: &SampleGrid) -> Vec<bool> {
    let raw: Vec<bool> = (0..grid.cells.len())
        .into_par_iter()
        .map(|s| !grid.reachable[s] && cube_unreachable(&model.delta, &grid.sample_center(s), 0.5 * grid.r))
        .collect();
    (0..raw.len()).map(|s| raw[s] && grid.index_of(mirror_cell(grid, grid.cells[s])).is_none_or(|m| raw[m])).collect()
}

/// Box index of the mirror image under `y -> -y` (arms 1 and 2 swap).
fn mirror_box(model: &RobotModel, j: usize) -> usize {
    match model.box_kind(j) {
        BoxKind::LowerLink(1) | BoxKind::UpperLink(1) => j + 1,
        BoxKind::LowerLink(2) | BoxKind::UpperLink(2) => j - 1,
        _ => j,
    }
}

/// A displacement set holding both `a` and its mirror entry's `b` (given in the mirror's box
/// order): every size the larger of the two. The directions are `a`'s; the mirror's are
/// their mirror images (the cube's axes map to themselves up to sign, and the elbow arcs of
/// arms 1 and 2 swap with equal motor angles, up to rounding: the table merges each label
/// with its mirror's anyway, [`crate::table`]), so each term of `b` lies in the same term of
/// the result.
fn mirror_max(model: &RobotModel, a: &[Sweep; MAX_BOXES], b: &[Sweep; MAX_BOXES]) -> [Sweep; MAX_BOXES] {
    std::array::from_fn(|j| if j < model.box_count() { larger(&a[j], &b[mirror_box(model, j)]) } else { a[j] })
}

fn larger(a: &Sweep, b: &Sweep) -> Sweep {
    // The cubes are axis-aligned in the MCS: half-edge `i` is `(amax) e_i`.
    let cube = std::array::from_fn(|i| {
        let mut w = Vec3::zeros();
        w[i] = a.cube[i].amax().max(b.cube[i].amax());
        w
    });
    let arc = std::array::from_fn(|i| {
        let (la, lb) = (a.arc[i].norm(), b.arc[i].norm());
        if la > 0.0 && lb > la {
            a.arc[i] * (lb / la)
        } else {
            a.arc[i]
        }
    });
    let ends = std::array::from_fn(|k| (a.ends[k].0.max(b.ends[k].0), a.ends[k].1.max(b.ends[k].1)));
    Sweep { cube, arc, ends, ball: a.ball.max(b.ball) }
}

/// The mirror image of `s` under `y -> -y` (the MCS cube maps to itself).
fn mirrored(s: &Sweep) -> Sweep {
    let flip = |v: Vec3| Vec3::new(v.x, -v.y, v.z);
    Sweep { cube: s.cube.map(flip), arc: s.arc.map(flip), ..*s }
}

/// How to build an entry's boxes from its displacement sets: unknown when one is unbounded.
fn inflation(s: [Sweep; MAX_BOXES]) -> Inflation {
    if s.iter().any(|w| !w.radius().is_finite()) {
        Inflation::Unknown
    } else {
        Inflation::Swept(s)
    }
}

/// The centre of octant `o` of a cube of centre `c` and half-side `2 d`: offset by `+/- d`
/// along x, y, z for bits 0, 1, 2 of `o`.
fn octant_centre(c: &Vec3, o: usize, d: Real) -> Vec3 {
    c + Vec3::from_fn(|a, _| if o >> a & 1 == 1 { d } else { -d })
}

/// The box sweeps over the cube of centre `c` and half-side `h` (about `reference`, with
/// [`OCTANT_SPLITS`]), or `None` when the cube is proved to hold no reachable TCP or has no
/// bound: the octants and sub-octants of levels 2 and 3.
fn octant_sweeps(model: &RobotModel, c: &Vec3, h: Real, reference: &Vec3) -> Option<[Sweep; MAX_BOXES]> {
    let vacuous = !model.delta.is_reachable(c) && cube_unreachable(&model.delta, c, h);
    if vacuous {
        return None;
    }
    cube_box_sweeps(model, c, h, reference, OCTANT_SPLITS)
}

/// Every sample's reference point ([`reference_point`]; its centre when none).
fn references(model: &RobotModel, grid: &SampleGrid) -> Vec<Vec3> {
    let h = 0.5 * grid.r;
    (0..grid.cells.len())
        .into_par_iter()
        .map(|s| {
            let c = grid.sample_center(s);
            reference_point(&model.delta, &c, h).unwrap_or(c)
        })
        .collect()
}

/// Whole-cell displacement sets of every sample, made mirror-symmetric.
fn cell_sweeps(model: &RobotModel, grid: &SampleGrid) -> Vec<[Sweep; MAX_BOXES]> {
    let raw: Vec<_> = (0..grid.cells.len()).into_par_iter().map(|s| box_sweeps(model, grid, s)).collect();
    (0..raw.len())
        .map(|s| match grid.index_of(mirror_cell(grid, grid.cells[s])) {
            Some(m) => mirror_max(model, &raw[s], &raw[m]),
            None => raw[s],
        })
        .collect()
}

/// Reference points and enlargements of the 8 octants of every sample (entry `8 s + i`,
/// octant `i` offset by `+/- r/4` along x, y, z for bits 0, 1, 2 of `i`), made
/// mirror-symmetric.
fn octants(model: &RobotModel, grid: &SampleGrid) -> (Vec<Vec3>, Vec<Inflation>) {
    let q = 0.25 * grid.r;
    let n = grid.cells.len() * 8;
    let cs: Vec<Vec3> = (0..n).map(|e| octant_centre(&grid.sample_center(e / 8), e % 8, q)).collect();
    let refs: Vec<Vec3> = cs.par_iter().map(|c| reference_point(&model.delta, c, q).unwrap_or(*c)).collect();
    let raw: Vec<Option<[Sweep; MAX_BOXES]>> =
        (0..n).into_par_iter().map(|e| octant_sweeps(model, &cs[e], q, &refs[e])).collect();
    let inflation = (0..n)
        .map(|e| {
            let mirror = grid.index_of(mirror_cell(grid, grid.cells[e / 8])).map(|m| 8 * m + ((e % 8) ^ 2));
            let b = match (raw[e], mirror.and_then(|m| raw[m])) {
                (None, None) => return Inflation::Vacuous,
                (Some(a), Some(b)) => mirror_max(model, &a, &b),
                (Some(a), None) => a,
                (None, Some(b)) => std::array::from_fn(|j| {
                    if j < model.box_count() {
                        mirrored(&b[mirror_box(model, j)])
                    } else {
                        Sweep::ZERO
                    }
                }),
            };
            inflation(b)
        })
        .collect();
    (refs, inflation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;
    use crate::cspace::{label_space, Label};

    /// Certified labels only add collisions to the exact centre labels, are "unreachable" only
    /// where the centre is, and refinement only removes collisions that level 1 could not
    /// prove free.
    #[test]
    fn certified_labels_contain_exact_collisions_and_refinement_only_frees() {
        let ws = Workspace::THESIS;
        for name in ["T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let exact = label_space(&cell, 16, &ws, 0.0, false).unwrap();
            let coarse = label_space_certified_with(&cell, 16, &ws, false, false).unwrap();
            let fine = label_space_certified(&cell, 16, &ws, false).unwrap();
            let (mut freed, mut added) = (0, 0);
            for ((e, c), f) in exact.labels.iter().zip(&coarse.space.labels).zip(&fine.space.labels) {
                assert!(*f != Label::Unreachable || *e == Label::Unreachable);
                assert_eq!(*c == Label::Unreachable, *f == Label::Unreachable);
                assert!(*e != Label::Collision || *f == Label::Collision);
                assert!(*c != Label::Free || *f == Label::Free);
                freed += (*c == Label::Collision && *f == Label::Free) as usize;
                added += (*e == Label::Free && *f == Label::Collision) as usize;
            }
            assert!(freed > 0 && added > 0, "{name}: {freed} freed, {added} added");
        }
    }

    /// Both robots' boxes at both levels, as [`label_space_subdivided`] builds them: `(a0, a1,
    /// b0, b1)`.
    fn level_boxes(cell: &Cell, k: u32) -> (SampleBoxes, SampleBoxes, SampleBoxes, SampleBoxes) {
        let (grid_a, grid_b) = two_robot_grids(cell, k, &Workspace::THESIS).unwrap();
        let whole = |r: &RobotSpec, g: &SampleGrid| {
            whole_cell_boxes(r, &references(&r.model, g), &cell_sweeps(&r.model, g), &unreachable_cells(&r.model, g))
        };
        let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
        (whole(ra, &grid_a), octant_boxes(ra, &grid_a), whole(rb, &grid_b), octant_boxes(rb, &grid_b))
    }

    /// Without level 3, the sub-cells are exactly those of the plain octant tests
    /// ([`octant_pairs`]), pair by pair, on every collision pair at k = 16; a subdivided
    /// labelling has the same pairs and care masks, and level 3 only frees sub-cells.
    #[test]
    fn sub_cells_are_those_of_the_plain_octant_tests() {
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let c = label_space_subdivided(&cell, 16, &Workspace::THESIS, false).unwrap();
            let (a0, a1, b0, b1) = level_boxes(&cell, 16);
            let nb = b0.len();
            let mut want = SubCells::default();
            for (p, _) in c.space.labels.iter().enumerate().filter(|(_, &l)| l == Label::Collision) {
                let (care, collision) = octant_pairs(&a0, &a1, &b0, &b1, p / nb, p % nb, false);
                want.pairs.push(p as u64);
                want.care.push(care);
                want.collision.push(collision);
            }
            assert!(!want.pairs.is_empty());
            let (a, b) = (Levels::new(&a0, &a1), Levels::new(&b0, &b1));
            assert!(
                sub_cells(&a, &b, &c.space.labels) == want,
                "{name}: the fast sub-cells differ from the plain ones"
            );
            let got = c.sub.as_ref().unwrap();
            assert_eq!((&got.pairs, &got.care), (&want.pairs, &want.care), "{name}: pairs and care masks");
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
                    assert_eq!(octants_prove_free(&a, &b, ia, ib), plain, "{name} pair ({ia}, {ib})");
                }
            }
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
                    assert_eq!(got, octant_pairs(&a0, &a1, &b0, &b1, ia, ib, false), "{name} pair ({ia}, {ib})");
                    whole += cores_meet(&a.whole_cores, ia, na, &b.whole_cores, ib, nb, all) as usize;
                    let octant_meets = |c: &[Option<Obb>], s: usize, d: &[Option<Obb>], e: usize, f: usize| {
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
    /// for the exact model.
    #[test]
    fn sub_cells_freed_by_level_3_hold_no_collision() {
        use crate::cell::{ExactChecker, SatMethod};
        use rand::{rngs::StdRng, RngExt, SeedableRng};
        let ws = Workspace::THESIS;
        let mut rng = StdRng::seed_from_u64(3);
        for name in ["T1", "T2", "T3"] {
            let cell = reference_cell(name).unwrap();
            let c = label_space_subdivided(&cell, 16, &ws, false).unwrap();
            let (a0, a1, b0, b1) = level_boxes(&cell, 16);
            let plain = sub_cells(&Levels::new(&a0, &a1), &Levels::new(&b0, &b1), &c.space.labels);
            let got = c.sub.as_ref().unwrap();
            let (ga, gb, nb) = (&c.space.grid_a, &c.space.grid_b, c.space.grid_b.cells.len());
            let mut exact = ExactChecker::new(Cell { method: SatMethod::Sat, ..cell.clone() });
            let octant = |g: &SampleGrid, s: usize, o: usize| octant_centre(&g.sample_center(s), o, 0.25 * g.r);
            let (mut freed, mut checked) = (0, 0);
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
                    }
                }
            }
            assert!(freed > 1000 && checked > 8 * freed, "{name}: {freed} freed sub-cells, {checked} configurations");
        }
    }

    /// The `2k` labels of a subdivided labelling: every sub-cell of a collision pair as its
    /// mask says (looked up the plain way), everything else as its parent pair.
    #[test]
    fn subdivided_labels_spell_out_the_sub_cells() {
        let ws = Workspace::THESIS;
        let cell = reference_cell("T2").unwrap();
        let c = label_space_subdivided(&cell, 16, &ws, false).unwrap();
        let fine = SubdividedLabels::new(&cell, &ws, &c).unwrap().to_dense();
        let sub = c.sub.as_ref().unwrap();
        let (coarse, nb0) = (&c.space, c.space.grid_b.cells.len());
        let (mut seen, mut freed) = (0, 0);
        for (ja, ca) in fine.grid_a.cells.iter().enumerate() {
            for (jb, cb) in fine.grid_b.cells.iter().enumerate() {
                let up = |g: &SampleGrid, x: &[u16; 3]| g.index_of([x[0] / 2, x[1] / 2, x[2] / 2]);
                let octant =
                    |x: &[u16; 3]| usize::from(x[0] & 1) | usize::from(x[1] & 1) << 1 | usize::from(x[2] & 1) << 2;
                let want = match (up(&coarse.grid_a, ca), up(&coarse.grid_b, cb)) {
                    (Some(ia), Some(ib)) => match sub.get((ia * nb0 + ib) as u64) {
                        Some((care, collision)) => {
                            seen += 1;
                            let bit = 1u64 << sub_cell_index(octant(ca), octant(cb));
                            match (care & bit != 0, collision & bit != 0) {
                                (false, _) => Label::Unreachable,
                                (true, true) => Label::Collision,
                                (true, false) => {
                                    freed += 1;
                                    Label::Free
                                }
                            }
                        }
                        None => coarse.label(ia, ib),
                    },
                    _ => Label::Unreachable,
                };
                assert_eq!(fine.label(ja, jb), want, "fine pair ({ja}, {jb})");
            }
        }
        assert!(seen > 0 && freed > 0, "{seen} sub-cells, {freed} freed");
    }
}
