//! The safety guarantee of a table (thesis 3.2.7, SPEC §6): per sample, how far any point of
//! any box of a robot can move while its TCP stays inside the sample's grid cell. The bound
//! itself is one robot's motion bound over a cube of TCPs ([`crate::robot::motion_bound`],
//! which derives it); here it is taken over each grid cell, from the cell's reference point.
//!
//! For every TCP `p` of the cell, box(p) lies in box(p0) moved within the sweep of each box,
//! so if the swept boxes of A and B are proved apart, no configuration of the 6-D cell
//! collides: a free label is a proof.

use crate::cspace::sampler::SampleGrid;
use crate::geometry::Sweep;
use crate::math::Real;
use crate::robot::motion_bound::{cube_box_sweeps, reference_point, unbounded_sweeps};
use crate::robot::{RobotModel, MAX_BOXES};

/// Sub-boxes per axis when enclosing the motor angles over a grid cell (`CELL_SPLITS^3` per
/// arm).
pub const CELL_SPLITS: u32 = 4;

/// Per box of `model`, the set of displacements of its points when the TCP moves from sample
/// `sample`'s reference point to any reachable point of its closed cell, in the MCS
/// ([`cube_box_sweeps`]). An infinite ball for every box when nothing can be bounded.
pub fn box_sweeps(model: &RobotModel, grid: &SampleGrid, sample: usize) -> [Sweep; MAX_BOXES] {
    let (c, h) = (grid.sample_center(sample), 0.5 * grid.r);
    reference_point(&model.delta, &c, h)
        .and_then(|p0| cube_box_sweeps(model, &c, h, &p0, CELL_SPLITS))
        .unwrap_or_else(|| unbounded_sweeps(model))
}

/// The thesis's global blow-up margin for spacing `r`: `r / sqrt(2)` (thesis 3.2.7; not a
/// proof, kept for comparison).
pub(crate) fn thesis_margin(r: Real) -> Real {
    r * core::f64::consts::FRAC_1_SQRT_2
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cspace::Workspace;
    use crate::robot::Delta3;

    /// A cell whose TCPs are all unreachable has unbounded sweeps; a cell with a reachable
    /// centre is bounded from it, and each box's bound exceeds the TCP's own reach over the
    /// cell (half its diagonal).
    #[test]
    fn cells_are_bounded_from_their_reference_or_not_at_all() {
        let model = RobotModel::THESIS;
        let grid = SampleGrid::new(&Workspace::THESIS, 16, &Delta3::THESIS).unwrap();
        let (mut bounded, mut unbounded) = (0, 0);
        for s in 0..grid.cells.len() {
            let sweeps = box_sweeps(&model, &grid, s);
            let radii: Vec<Real> = sweeps[..model.box_count()].iter().map(|w| w.radius()).collect();
            let c = grid.sample_center(s);
            match reference_point(&model.delta, &c, 0.5 * grid.r) {
                None => {
                    assert!(radii.iter().all(|r| r.is_infinite()), "sample {s}");
                    unbounded += 1;
                }
                Some(_) if grid.reachable[s] => {
                    let half_diagonal = 0.5 * grid.r * 3f64.sqrt();
                    assert!(
                        radii.iter().all(|&r| r.is_finite() && r >= half_diagonal),
                        "sample {s}: {radii:?}"
                    );
                    bounded += 1;
                }
                Some(_) => {}
            }
        }
        assert!(bounded > 100 && unbounded > 0, "{bounded} bounded, {unbounded} unbounded");
    }
}
