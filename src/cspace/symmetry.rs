//! Reflection symmetry of a cell (thesis 3.2.8, Lemma 3.2.1): when the reflection
//! `y -> -y` of the WCS maps every robot onto itself, the configurations
//! `(x, y, z, x', y', z')` and `(x, -y, z, x', -y', z')` (MCS coordinates) collide together,
//! and a table may store half of them. Detected from the cell, never assumed.
//!
//! # Conventions
//! Robot `j` is placed by `p_wcs = Rz(alpha) p_mcs + t`. In its MCS a Delta3 is symmetric
//! under `S: y -> -y`: the arm azimuths `0, 2pi/3, 4pi/3` map to `0, 4pi/3, 2pi/3` (arms 1
//! and 2 swap; a lower link box is built from the line of `t_i`, so its reflection is the
//! box of the mirrored arm). The WCS reflection then acts on the MCS as `S` itself iff
//! `S (Rz(alpha) q + t) = Rz(alpha) S q + t` for all `q`, i.e. `t.y = 0` and
//! `Rz(2 alpha) = I` (`alpha` = 0 or pi). Extra boxes (platform, tool) are world-aligned in
//! the MCS and must satisfy `offset.y = 0`. Upper link boxes are symmetric like lower links.
//!
//! # Numerics
//! `t.y` must be exactly 0; `alpha` may differ from 0 or pi by at most [`ALPHA_TOLERANCE`]
//! (pi is not representable).

use crate::cell::Cell;
use crate::cspace::sampler::{CellIndex, SampleGrid};
use crate::math::{float, Real};
use alloc::vec::Vec;
use core::f64::consts::PI;

/// How far `alpha` may be from 0 or pi (rad) and still count as symmetric.
pub const ALPHA_TOLERANCE: Real = 1e-12;

/// Whether the reflection `y -> -y` of the WCS maps every robot of `cell` onto itself, so
/// that the MCS configuration `(x, y, z, ...)` and its mirror `(x, -y, z, ...)` always agree.
pub fn reflection_y(cell: &Cell) -> bool {
    cell.robots.iter().all(|r| {
        let p = &r.placement;
        let a = float::rem_euclid(p.alpha, 2.0 * PI);
        let alpha_ok =
            a.min(2.0 * PI - a) <= ALPHA_TOLERANCE || (a - PI).max(PI - a) <= ALPHA_TOLERANCE;
        let extras_ok = [r.model.options.platform, r.model.options.tool]
            .iter()
            .flatten()
            .all(|b| b.offset.y == 0.0);
        p.t.y == 0.0 && alpha_ok && extras_ok
    })
}

/// Whether a table stores every configuration or one of each mirror pair under `y -> -y`
/// (what the table builders take; a table file records it as a flag).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// Every configuration is stored; right for any cell.
    Whole,
    /// Only A's upper half `iy >= k/2` is stored, a query in the other half reads its
    /// mirror; right only for a cell with [`reflection_y`].
    MirrorY,
}

impl Symmetry {
    /// [`Symmetry::MirrorY`] when `cell` has the reflection ([`reflection_y`]), else
    /// [`Symmetry::Whole`].
    pub fn of(cell: &Cell) -> Symmetry {
        Symmetry::from_flag(reflection_y(cell))
    }

    /// [`Symmetry::MirrorY`] for `true` (a table file's symmetry flag), else [`Symmetry::Whole`].
    pub const fn from_flag(mirrored: bool) -> Symmetry {
        if mirrored {
            Symmetry::MirrorY
        } else {
            Symmetry::Whole
        }
    }

    /// Whether only half is stored.
    pub const fn is_mirrored(self) -> bool {
        matches!(self, Symmetry::MirrorY)
    }
}

/// The mirror `(ix, k - 1 - iy, iz)` of a grid cell under `y -> -y`.
pub fn mirror_cell(grid: &SampleGrid, cell: CellIndex) -> CellIndex {
    [cell[0], (grid.k - 1) as u16 - cell[1], cell[2]]
}

/// Per sample of `grid`: the index of its mirror sample ([`mirror_cell`]), when sampled.
pub fn mirror_samples(grid: &SampleGrid) -> Vec<Option<usize>> {
    grid.cells.iter().map(|&c| grid.index_of(mirror_cell(grid, c))).collect()
}

/// Whether a grid cell lies in the half that a table of a mirror-symmetric cell stores
/// (`iy >= k/2`: TCP `y >= 0`, the grid's y origin being `-k r / 2`).
pub fn in_stored_half(grid: &SampleGrid, cell: CellIndex) -> bool {
    u32::from(cell[1]) >= grid.k / 2
}

/// Whether the sampled cells of `grid` are closed under `y -> -y` (every mirror is sampled).
pub fn grid_is_y_symmetric(grid: &SampleGrid) -> bool {
    grid.cells.iter().all(|&c| grid.index_of(mirror_cell(grid, c)).is_some())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;
    use crate::cell::Placement;
    use crate::math::Vec3;

    #[test]
    fn reference_cells_t1_t2_are_symmetric_and_t3_is_not() {
        assert!(reflection_y(&reference_cell("T1").unwrap()));
        assert!(reflection_y(&reference_cell("T2").unwrap()));
        assert!(!reflection_y(&reference_cell("T3").unwrap()));
    }

    #[test]
    fn placements_that_break_the_mirror_are_detected() {
        let base = reference_cell("T1").unwrap();
        let with = |p: Placement| {
            let mut c = base.clone();
            c.robots[1].placement = p;
            reflection_y(&c)
        };
        assert!(with(Placement { alpha: PI, t: Vec3::new(450.0, 0.0, 0.0) }));
        assert!(with(Placement { alpha: -PI, t: Vec3::new(450.0, 0.0, 30.0) }));
        assert!(
            !with(Placement { alpha: PI / 3.0, t: Vec3::new(450.0, 0.0, 0.0) }),
            "arms map, MCS mirror does not"
        );
        assert!(!with(Placement { alpha: 0.0, t: Vec3::new(450.0, 1e-9, 0.0) }));
        assert!(!with(Placement { alpha: 1e-6, t: Vec3::new(450.0, 0.0, 0.0) }));
        let mut tool = base.clone();
        tool.robots[0].model.options.tool = Some(crate::robot::ToolBox {
            offset: Vec3::new(0.0, 5.0, -30.0),
            half: Vec3::repeat(10.0),
        });
        assert!(!reflection_y(&tool));
    }

    /// Labels of mirrored sample pairs that differ (both grids must be y-symmetric).
    fn mirror_mismatches(space: &crate::cspace::LabelledSpace) -> usize {
        let (ga, gb) = (&space.grid_a, &space.grid_b);
        assert!(grid_is_y_symmetric(ga) && grid_is_y_symmetric(gb));
        let mb: Vec<usize> =
            gb.cells.iter().map(|&c| gb.index_of(mirror_cell(gb, c)).unwrap()).collect();
        let mut bad = 0;
        for (ia, &c) in ga.cells.iter().enumerate() {
            let ma = ga.index_of(mirror_cell(ga, c)).unwrap();
            bad += (0..gb.cells.len())
                .filter(|&ib| space.label(ia, ib) != space.label(ma, mb[ib]))
                .count();
        }
        bad
    }

    #[test]
    fn labels_of_symmetric_cells_agree_with_their_mirrors() {
        use crate::cspace::{label_space, label_space_certified, Progress, Workspace};
        let ws = Workspace::THESIS;
        for name in ["T1", "T2"] {
            let cell = reference_cell(name).unwrap();
            assert!(reflection_y(&cell));
            let exact = label_space(&cell, 16, &ws, 0.0, Progress::Silent).unwrap();
            assert_eq!(mirror_mismatches(&exact), 0, "{name} exact");
            let certified = label_space_certified(&cell, 16, &ws, Progress::Silent).unwrap();
            assert_eq!(mirror_mismatches(&certified.space), 0, "{name} certified");
        }
        // T3 is not symmetric, and its labels show it.
        let t3 = reference_cell("T3").unwrap();
        assert!(!reflection_y(&t3));
        assert!(mirror_mismatches(&label_space(&t3, 16, &ws, 0.0, Progress::Silent).unwrap()) > 0);
    }
}
