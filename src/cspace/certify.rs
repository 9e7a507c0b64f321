//! Certified labelling: free labels that are proofs for whole 6-D grid cells (SPEC §6,
//! thesis 3.2.7; issue 3 item 4).
//!
//! A pair of samples `(ia, ib)` is free when it is proved free at one of two levels:
//! 1. the boxes at both cell centres, each enlarged by its own displacement bound over the
//!    whole cell ([`box_displacement_bounds`]), are disjoint; or, failing that,
//! 2. (refinement) each robot's cell is cut into its 8 octants, each with its own centre
//!    boxes and bounds over the octant ([`cube_box_bounds`], about half as large), and for
//!    every pair (octant i of A, octant j of B) each box pair is proved disjoint by one of
//!    the tests (A cell, B cell), (A octant i, B cell) or (A octant i, B octant j) (a box
//!    pair proved disjoint by a coarser test is disjoint for every configuration it covers). Octants that hold no reachable TCP are skipped. Pairs
//!    whose physical boxes collide at the centres skip this level.
//!
//! Either way every configuration of the 6-D cell is covered by a disjoint pair of enlarged
//! box sets, each of which contains the physical boxes for every TCP of its (sub)cell (see
//! [`crate::cspace::guarantee`]). Anything not proved is a collision.
//!
//! Bounds are made exactly mirror-symmetric (the larger of an entry's bound and its mirror's,
//! arms 1 and 2 swapped), so that a symmetric cell gets exactly symmetric labels (thesis 3.2.8).

use crate::cell::Cell;
use crate::cspace::guarantee::{box_displacement_bounds, cube_box_bounds, SPLITS};
use crate::cspace::label::{all_box_pairs, centres, collision_mask, entries_collide, label_pairs, two_robot_grids, Inflation, SampleBoxes, Slot};
use crate::cspace::sampler::{SampleGrid, Workspace};
use crate::cspace::symmetry::mirror_cell;
use crate::cspace::LabelledSpace;
use crate::geometry::witness::MAX_BOXES;
use crate::math::{Real, Vec3};
use crate::robot::{BoxKind, RobotModel};
use rayon::prelude::*;

/// Sub-boxes per axis when enclosing the motor angles over an octant (an octant is half as
/// wide as a cell, so this gives the same sub-box size as [`SPLITS`] on a cell).
pub const OCTANT_SPLITS: u32 = SPLITS / 2;

/// A labelling whose free labels are proofs for whole 6-D cells, with the bounds it used.
#[derive(Clone, Debug, PartialEq)]
pub struct CertifiedSpace {
    /// The labels; `space.margin` is the largest whole-cell enlargement used (each box got
    /// its own, never more than this).
    pub space: LabelledSpace,
    /// Per sample of A, per box: the whole-cell displacement bound its box was enlarged by.
    pub bounds_a: Vec<[Real; MAX_BOXES]>,
    /// Per sample of B, per box.
    pub bounds_b: Vec<[Real; MAX_BOXES]>,
    /// Whether level 2 (octant refinement) was used.
    pub refined: bool,
}

impl CertifiedSpace {
    /// The largest whole-cell displacement bound of A's sample `ia` (`reach_a[ia]`, mm).
    pub fn reach_a(&self, ia: usize) -> Real {
        self.bounds_a[ia].iter().copied().fold(0.0, Real::max)
    }

    /// The largest whole-cell displacement bound of B's sample `ib`.
    pub fn reach_b(&self, ib: usize) -> Real {
        self.bounds_b[ib].iter().copied().fold(0.0, Real::max)
    }
}

/// Certified labels of every sample pair of the two-robot `cell` at `k` cells per axis, with
/// octant refinement (see the module doc).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_certified(cell: &Cell, k: u32, ws: &Workspace, progress: bool) -> Result<CertifiedSpace, String> {
    label_space_certified_with(cell, k, ws, true, progress)
}

/// As [`label_space_certified`]; `refine = false` stops at level 1 (whole-cell bounds only).
///
/// # Errors
/// As [`crate::cspace::label_space`].
pub fn label_space_certified_with(cell: &Cell, k: u32, ws: &Workspace, refine: bool, progress: bool) -> Result<CertifiedSpace, String> {
    let (grid_a, grid_b) = two_robot_grids(cell, k, ws)?;
    let (ra, rb) = (&cell.robots[0], &cell.robots[1]);
    let (bounds_a, bounds_b) = (cell_bounds(&ra.model, &grid_a), cell_bounds(&rb.model, &grid_b));
    let level1 = |b: &[[Real; MAX_BOXES]], s: usize| {
        if b[s].iter().any(|v| v.is_infinite()) {
            Inflation::Unknown
        } else {
            Inflation::By(b[s])
        }
    };
    let a0 = SampleBoxes::new(&ra.model, &ra.placement, &centres(&grid_a), |s| level1(&bounds_a, s));
    let b0 = SampleBoxes::new(&rb.model, &rb.placement, &centres(&grid_b), |s| level1(&bounds_b, s));
    let labels = if refine {
        let (ca, ea) = octants(&ra.model, &grid_a);
        let (cb, eb) = octants(&rb.model, &grid_b);
        let a1 = SampleBoxes::new(&ra.model, &ra.placement, &ca, |s| ea[s]);
        let b1 = SampleBoxes::new(&rb.model, &rb.placement, &cb, |s| eb[s]);
        // The physical boxes at the centres: a pair that collides there is a collision
        // without refinement.
        let none = |_| Inflation::By([0.0; MAX_BOXES]);
        let (xa, xb) = (SampleBoxes::new(&ra.model, &ra.placement, &centres(&grid_a), none), SampleBoxes::new(&rb.model, &rb.placement, &centres(&grid_b), none));
        let collides = |ia, ib| entries_collide(&xa, ia, &xb, ib) || !octants_prove_free(&a0, &a1, &b0, &b1, ia, ib);
        label_pairs(&a0, &b0, collides, progress)
    } else {
        label_pairs(&a0, &b0, |_, _| true, progress)
    };
    let used = |bs: &[[Real; MAX_BOXES]]| bs.iter().flatten().copied().filter(|v| v.is_finite()).fold(0.0, Real::max);
    let margin = used(&bounds_a).max(used(&bounds_b));
    Ok(CertifiedSpace { space: LabelledSpace { grid_a, grid_b, labels, margin }, bounds_a, bounds_b, refined: refine })
}

/// Level 2 for a pair whose whole-cell test failed. Only the box pairs that level 1 left
/// open need a proof (the others are disjoint for every configuration of the 6-D cell);
/// each octant of A narrows them against B's whole cell, and what stays open must be proved
/// disjoint against every octant of B.
fn octants_prove_free(a0: &SampleBoxes, a1: &SampleBoxes, b0: &SampleBoxes, b1: &SampleBoxes, ia: usize, ib: usize) -> bool {
    let open = collision_mask(a0, ia, b0, ib, all_box_pairs(a0.per_entry, b0.per_entry));
    for sa in ia * 8..ia * 8 + 8 {
        match a1.slot[sa] {
            Slot::Vacuous => continue,
            Slot::Boxes => {}
            Slot::Unreachable | Slot::Unknown => return false,
        }
        let open = collision_mask(a1, sa, b0, ib, open);
        if open == 0 {
            continue;
        }
        for sb in ib * 8..ib * 8 + 8 {
            match b1.slot[sb] {
                Slot::Vacuous => continue,
                Slot::Boxes => {}
                Slot::Unreachable | Slot::Unknown => return false,
            }
            if collision_mask(a1, sa, b1, sb, open) != 0 {
                return false;
            }
        }
    }
    true
}

/// Box index of the mirror image under `y -> -y` (arms 1 and 2 swap).
fn mirror_box(model: &RobotModel, j: usize) -> usize {
    match model.box_kind(j) {
        BoxKind::LowerLink(1) | BoxKind::UpperLink(1) => j + 1,
        BoxKind::LowerLink(2) | BoxKind::UpperLink(2) => j - 1,
        _ => j,
    }
}

/// The larger of two bounds of mirror entries, `b` given in the mirror's box order.
fn mirror_max(model: &RobotModel, a: &[Real; MAX_BOXES], b: &[Real; MAX_BOXES]) -> [Real; MAX_BOXES] {
    std::array::from_fn(|j| if j < model.box_count() { a[j].max(b[mirror_box(model, j)]) } else { a[j] })
}

/// Whole-cell bounds of every sample, made mirror-symmetric.
fn cell_bounds(model: &RobotModel, grid: &SampleGrid) -> Vec<[Real; MAX_BOXES]> {
    let raw: Vec<_> = (0..grid.cells.len()).into_par_iter().map(|s| box_displacement_bounds(model, grid, s)).collect();
    (0..raw.len())
        .map(|s| match grid.index_of(mirror_cell(grid, grid.cells[s])) {
            Some(m) => mirror_max(model, &raw[s], &raw[m]),
            None => raw[s],
        })
        .collect()
}

/// Centres and enlargements of the 8 octants of every sample (entry `8 s + i`, octant `i`
/// offset by `+/- r/4` along x, y, z for bits 0, 1, 2 of `i`), made mirror-symmetric.
fn octants(model: &RobotModel, grid: &SampleGrid) -> (Vec<Vec3>, Vec<Inflation>) {
    let q = 0.25 * grid.r;
    let centre = |e: usize| {
        let (s, i) = (e / 8, e % 8);
        let sign = |bit: usize| if i >> bit & 1 == 1 { q } else { -q };
        grid.sample_center(s) + Vec3::new(sign(0), sign(1), sign(2))
    };
    let n = grid.cells.len() * 8;
    let cs: Vec<Vec3> = (0..n).map(centre).collect();
    let raw: Vec<Option<[Real; MAX_BOXES]>> = cs.par_iter().map(|c| cube_box_bounds(model, c, q, OCTANT_SPLITS)).collect();
    let inflation = (0..n)
        .map(|e| {
            let mirror = grid.index_of(mirror_cell(grid, grid.cells[e / 8])).map(|m| 8 * m + (e % 8 ^ 2));
            let b = match (raw[e], mirror.and_then(|m| raw[m])) {
                (None, None) => return Inflation::Vacuous,
                (Some(a), Some(b)) => mirror_max(model, &a, &b),
                (Some(a), None) => a,
                (None, Some(b)) => std::array::from_fn(|j| if j < model.box_count() { b[mirror_box(model, j)] } else { 0.0 }),
            };
            if b.iter().any(|v| v.is_infinite()) {
                Inflation::Unknown
            } else {
                Inflation::By(b)
            }
        })
        .collect();
    (cs, inflation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;
    use crate::cspace::{label_space, Label};

    /// Certified labels only add collisions to the exact centre labels, and refinement only
    /// removes collisions that level 1 could not prove free.
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
                assert_eq!(*e == Label::Unreachable, *f == Label::Unreachable);
                assert!(*e != Label::Collision || *f == Label::Collision);
                assert!(*c != Label::Free || *f == Label::Free);
                freed += (*c == Label::Collision && *f == Label::Free) as usize;
                added += (*e == Label::Free && *f == Label::Collision) as usize;
            }
            assert!(freed > 0 && added > 0, "{name}: {freed} freed, {added} added");
        }
    }
}
