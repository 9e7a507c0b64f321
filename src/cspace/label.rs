//! Labelling every two-robot sample with the exact box test, in parallel (thesis 3.2.3,
//! 3.2.7; SPEC §6; issue 3 items 2 and 4).
//!
//! The product structure is used twice: each robot's boxes are built once per sample (IK,
//! boxes, placement, inflation, axis-aligned bounds), never once per pair; and for one sample
//! of A, the samples of B whose robot AABB cannot reach A's along x are skipped wholesale (B's
//! samples are sorted by their AABB's lower x, so the candidates form one slice found by
//! binary search). The candidates then go through the AABB test in y and z, a per-box AABB
//! test and finally the separating axis test.
//!
//! Three labellings share the kernel [`label_pairs`]:
//! - [`label_space`]: every box enlarged by one global `margin` (the thesis's blown-up model
//!   with `margin = r / sqrt(2)`, or the exact labelling of the centres with 0);
//! - [`label_space_certified`]: every box enlarged by its own per-sample displacement bound
//!   ([`crate::cspace::guarantee`]), so that a free label holds for the whole 6-D cell.
//!
//! # Numerics
//! Every pre-test errs toward overlap (slack [`AABB_SLACK`]); only the separating axis test
//! (itself conservative) can turn a candidate free.

use crate::cell::{Cell, Placement};
use crate::cspace::guarantee::{box_displacement_bounds, thesis_margin};
use crate::cspace::sampler::{SampleGrid, Workspace};
use crate::cspace::{Label, LabelledSpace};
use crate::geometry::sat::separating_axis;
use crate::geometry::witness::MAX_BOXES;
use crate::geometry::Obb;
use crate::math::Real;
use crate::cspace::symmetry::mirror_cell;
use crate::robot::{BoxKind, ModelOptions, RobotModel};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

/// Slack (mm) of every axis-aligned pre-test: boxes closer than this go on to the exact test.
pub const AABB_SLACK: Real = 1e-6;

/// One robot's boxes at every sample centre, in the WCS, with their axis-aligned bounds.
#[derive(Clone, Debug)]
pub struct SampleBoxes {
    /// Boxes per sample.
    pub per_sample: usize,
    /// Box `j` of sample `s` at `s * per_sample + j` (meaningless when unreachable).
    pub boxes: Vec<Obb>,
    /// Per box: AABB lower and upper corners.
    pub box_lo: Vec<[Real; 3]>,
    /// Per box: AABB upper corner.
    pub box_hi: Vec<[Real; 3]>,
    /// Per sample: the AABB of all its boxes, lower corner.
    pub lo: Vec<[Real; 3]>,
    /// Per sample: upper corner.
    pub hi: Vec<[Real; 3]>,
    /// Whether the sample's centre is reachable.
    pub reachable: Vec<bool>,
}

impl SampleBoxes {
    /// The boxes of `model` placed by `placement` at every centre of `grid`, box `j` of sample
    /// `s` enlarged by `inflate(s)[j]` on every half-extent (on top of the model's margin).
    pub fn new<F>(model: &RobotModel, placement: &Placement, grid: &SampleGrid, inflate: F) -> SampleBoxes
    where
        F: Fn(usize) -> [Real; MAX_BOXES] + Sync,
    {
        let nb = model.box_count();
        let n = grid.cells.len();
        let per: Vec<Option<Vec<Obb>>> = (0..n)
            .into_par_iter()
            .map(|s| {
                let boxes = model.boxes(&grid.sample_center(s)).ok()?;
                let extra = inflate(s);
                Some(boxes.as_slice().iter().zip(extra).map(|(b, m)| placement.obb_to_wcs(&b.inflated(m))).collect())
            })
            .collect();
        let empty = Obb::new(Default::default(), crate::math::Mat3::identity(), Default::default());
        let mut out = SampleBoxes {
            per_sample: nb,
            boxes: Vec::with_capacity(n * nb),
            box_lo: Vec::with_capacity(n * nb),
            box_hi: Vec::with_capacity(n * nb),
            lo: Vec::with_capacity(n),
            hi: Vec::with_capacity(n),
            reachable: Vec::with_capacity(n),
        };
        for p in per {
            let reachable = p.as_ref().is_some_and(|b| b.iter().all(|o| o.half.iter().all(|h| h.is_finite())));
            let (mut lo, mut hi) = ([Real::INFINITY; 3], [Real::NEG_INFINITY; 3]);
            for j in 0..nb {
                let b = if reachable { p.as_ref().unwrap()[j] } else { empty };
                let h = b.aabb_half();
                let (bl, bh) = (b.center - h, b.center + h);
                for a in 0..3 {
                    lo[a] = lo[a].min(bl[a]);
                    hi[a] = hi[a].max(bh[a]);
                }
                out.boxes.push(b);
                out.box_lo.push([bl.x, bl.y, bl.z]);
                out.box_hi.push([bh.x, bh.y, bh.z]);
            }
            out.lo.push(lo);
            out.hi.push(hi);
            out.reachable.push(reachable);
        }
        out
    }

    /// Sample count.
    pub fn len(&self) -> usize {
        self.reachable.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.reachable.is_empty()
    }
}

/// Whether the closed boxes `[alo, ahi]` and `[blo, bhi]` are apart by more than the slack.
#[inline]
fn aabbs_apart(alo: &[Real; 3], ahi: &[Real; 3], blo: &[Real; 3], bhi: &[Real; 3]) -> bool {
    (0..3).any(|k| blo[k] > ahi[k] + AABB_SLACK || alo[k] > bhi[k] + AABB_SLACK)
}

/// Whether some box of A's sample `ia` intersects some box of B's sample `ib`.
#[inline]
fn samples_collide(a: &SampleBoxes, ia: usize, b: &SampleBoxes, ib: usize) -> bool {
    let (na, nb) = (a.per_sample, b.per_sample);
    for i in ia * na..(ia + 1) * na {
        for j in ib * nb..(ib + 1) * nb {
            if !aabbs_apart(&a.box_lo[i], &a.box_hi[i], &b.box_lo[j], &b.box_hi[j])
                && separating_axis(&a.boxes[i], &b.boxes[j]).is_none()
            {
                return true;
            }
        }
    }
    false
}

/// The label of every pair `(ia, ib)` at `ia * b.len() + ib`: `Unreachable` when either
/// centre is unreachable, else `Collision` when some pair of boxes intersects, else `Free`.
/// Rows are labelled in parallel; `progress` draws a bar on stderr.
pub fn label_pairs(a: &SampleBoxes, b: &SampleBoxes, progress: bool) -> Vec<Label> {
    let (na, nb) = (a.len(), b.len());
    let base: Vec<Label> = b.reachable.iter().map(|&r| if r { Label::Free } else { Label::Unreachable }).collect();
    // Reachable samples of B sorted by the lower x of their AABB.
    let mut order: Vec<u32> = (0..nb as u32).filter(|&i| b.reachable[i as usize]).collect();
    order.sort_by(|&i, &j| b.lo[i as usize][0].total_cmp(&b.lo[j as usize][0]));
    let keys: Vec<Real> = order.iter().map(|&i| b.lo[i as usize][0]).collect();
    let widest = order.iter().map(|&i| b.hi[i as usize][0] - b.lo[i as usize][0]).fold(0.0, Real::max);
    let bar = if progress { ProgressBar::new(na as u64) } else { ProgressBar::hidden() };
    if let Ok(style) = ProgressStyle::with_template("labelling {bar:40} {pos}/{len} rows of A, {elapsed} (eta {eta})") {
        bar.set_style(style);
    }
    let mut labels = vec![Label::Unreachable; na * nb];
    if nb > 0 {
        labels.par_chunks_mut(nb).enumerate().for_each(|(ia, row)| {
            if a.reachable[ia] {
                row.copy_from_slice(&base);
                let (alo, ahi) = (&a.lo[ia], &a.hi[ia]);
                let first = keys.partition_point(|&x| x < alo[0] - widest - AABB_SLACK);
                let last = keys.partition_point(|&x| x <= ahi[0] + AABB_SLACK);
                for &ib in &order[first..last.max(first)] {
                    let ib = ib as usize;
                    if !aabbs_apart(alo, ahi, &b.lo[ib], &b.hi[ib]) && samples_collide(a, ia, b, ib) {
                        row[ib] = Label::Collision;
                    }
                }
            }
            bar.inc(1);
        });
    }
    bar.finish_and_clear();
    labels
}

/// Robot `i` of a two-robot cell with `margin` added to its model's margin.
fn robot_with_margin(cell: &Cell, i: usize, margin: Real) -> (RobotModel, Placement) {
    let r = &cell.robots[i];
    let options = ModelOptions { margin: r.model.options.margin + margin, ..r.model.options };
    (RobotModel { options, ..r.model }, r.placement)
}

fn two_robot_grids(cell: &Cell, k: u32, ws: &Workspace) -> Result<(SampleGrid, SampleGrid), String> {
    if cell.robots.len() != 2 {
        return Err(format!(
            "cell '{}' has {} robots; tables are built for two-robot cells (split the cell into pairs)",
            cell.name,
            cell.robots.len()
        ));
    }
    Ok((SampleGrid::new(ws, k, &cell.robots[0].model.delta)?, SampleGrid::new(ws, k, &cell.robots[1].model.delta)?))
}

/// Labels every sample pair of the two-robot `cell` (robots 0 and 1) at `k` cells per axis,
/// with `margin` added to every half-extent of both robots (on top of their own margins).
///
/// # Errors
/// When the cell does not have exactly two robots, `margin` is not finite and >= 0, or the
/// grid cannot be built ([`SampleGrid::new`]).
pub fn label_space(cell: &Cell, k: u32, ws: &Workspace, margin: Real, progress: bool) -> Result<LabelledSpace, String> {
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(format!("labelling margin = {margin} must be finite and >= 0 (mm)"));
    }
    let (grid_a, grid_b) = two_robot_grids(cell, k, ws)?;
    let (ma, pa) = robot_with_margin(cell, 0, margin);
    let (mb, pb) = robot_with_margin(cell, 1, margin);
    let a = SampleBoxes::new(&ma, &pa, &grid_a, |_| [0.0; MAX_BOXES]);
    let b = SampleBoxes::new(&mb, &pb, &grid_b, |_| [0.0; MAX_BOXES]);
    let labels = label_pairs(&a, &b, progress);
    Ok(LabelledSpace { grid_a, grid_b, labels, margin })
}

/// The thesis's labelling (3.2.7): every half-extent enlarged by `r / sqrt(2)`. Not a proof
/// (see [`crate::cspace::guarantee`]); kept for comparison.
///
/// # Errors
/// As [`label_space`].
pub fn label_space_thesis(cell: &Cell, k: u32, ws: &Workspace, progress: bool) -> Result<LabelledSpace, String> {
    let (g, _) = two_robot_grids(cell, k, ws)?;
    label_space(cell, k, ws, thesis_margin(g.r), progress)
}

/// A labelling whose free labels are proofs for whole 6-D cells, with the bounds it used.
#[derive(Clone, Debug, PartialEq)]
pub struct CertifiedSpace {
    /// The labels; `space.margin` is the largest per-box enlargement used (each box got its
    /// own, never more than this).
    pub space: LabelledSpace,
    /// Per sample of A, per box: the displacement bound its box was enlarged by.
    pub bounds_a: Vec<[Real; MAX_BOXES]>,
    /// Per sample of B, per box.
    pub bounds_b: Vec<[Real; MAX_BOXES]>,
}

impl CertifiedSpace {
    /// The largest displacement bound of A's sample `ia` (`reach_a[ia]`, mm).
    pub fn reach_a(&self, ia: usize) -> Real {
        self.bounds_a[ia].iter().copied().fold(0.0, Real::max)
    }

    /// The largest displacement bound of B's sample `ib`.
    pub fn reach_b(&self, ib: usize) -> Real {
        self.bounds_b[ib].iter().copied().fold(0.0, Real::max)
    }
}

/// Labels every sample pair of the two-robot `cell` so that a free label holds for every
/// configuration of the 6-D grid cell (SPEC §6): each box at the cell centre is enlarged by
/// its own displacement bound ([`box_displacement_bounds`]) and the pair is free only when no
/// enlarged boxes meet. Pairs whose bound is unknown are labelled collision.
///
/// # Errors
/// As [`label_space`].
pub fn label_space_certified(cell: &Cell, k: u32, ws: &Workspace, progress: bool) -> Result<CertifiedSpace, String> {
    let (grid_a, grid_b) = two_robot_grids(cell, k, ws)?;
    let bounds = |i: usize, grid: &SampleGrid| -> Vec<[Real; MAX_BOXES]> {
        let model = cell.robots[i].model;
        let raw: Vec<_> = (0..grid.cells.len()).into_par_iter().map(|s| box_displacement_bounds(&model, grid, s)).collect();
        mirror_max(&model, grid, &raw)
    };
    let (bounds_a, bounds_b) = (bounds(0, &grid_a), bounds(1, &grid_b));
    let a = SampleBoxes::new(&cell.robots[0].model, &cell.robots[0].placement, &grid_a, |s| finite(bounds_a[s]));
    let b = SampleBoxes::new(&cell.robots[1].model, &cell.robots[1].placement, &grid_b, |s| finite(bounds_b[s]));
    let mut labels = label_pairs(&a, &b, progress);
    // A reachable centre with an unknown bound: nothing is proved, every pair collides.
    let unknown = |bs: &[Real; MAX_BOXES]| bs.iter().any(|v| v.is_infinite());
    let nb = grid_b.cells.len();
    let any_unknown = |bs: &[[Real; MAX_BOXES]], grid: &SampleGrid| bs.iter().zip(&grid.reachable).any(|(b, &r)| r && unknown(b));
    if any_unknown(&bounds_a, &grid_a) || any_unknown(&bounds_b, &grid_b) {
        for (ia, row) in labels.chunks_mut(nb.max(1)).enumerate() {
            for (ib, l) in row.iter_mut().enumerate() {
                if *l == Label::Free && (unknown(&bounds_a[ia]) || unknown(&bounds_b[ib])) {
                    *l = Label::Collision;
                }
            }
        }
    }
    let used = |bs: &[[Real; MAX_BOXES]]| bs.iter().flatten().copied().filter(|v| v.is_finite()).fold(0.0, Real::max);
    let margin = used(&bounds_a).max(used(&bounds_b));
    Ok(CertifiedSpace { space: LabelledSpace { grid_a, grid_b, labels, margin }, bounds_a, bounds_b })
}

/// Per sample, the larger of its own bounds and its mirror sample's (arms 1 and 2 swapped):
/// still upper bounds, and exactly mirror-symmetric, so that the labels of a symmetric cell
/// are exactly symmetric (thesis 3.2.8) despite rounding in the enclosures.
fn mirror_max(model: &RobotModel, grid: &SampleGrid, raw: &[[Real; MAX_BOXES]]) -> Vec<[Real; MAX_BOXES]> {
    let swap = |j: usize| match model.box_kind(j) {
        BoxKind::LowerLink(1) | BoxKind::UpperLink(1) => j + 1,
        BoxKind::LowerLink(2) | BoxKind::UpperLink(2) => j - 1,
        _ => j,
    };
    (0..raw.len())
        .map(|s| match grid.index_of(mirror_cell(grid, grid.cells[s])) {
            Some(m) => std::array::from_fn(|j| if j < model.box_count() { raw[s][j].max(raw[m][swap(j)]) } else { raw[s][j] }),
            None => raw[s],
        })
        .collect()
}

/// Infinite bounds (unreachable centres) replaced by 0 so the box can still be built; such
/// samples are unreachable or relabelled by the caller.
fn finite(mut b: [Real; MAX_BOXES]) -> [Real; MAX_BOXES] {
    b.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = 0.0);
    b
}
