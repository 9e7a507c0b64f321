//! The coordination diagram of two whole programmes, offline: which pairs of their samples
//! (one every `stride` programme ticks) bring the robots within a clearance of each other,
//! tested with each robot's boxes grown by half of it (a grown box holds every point within
//! its growth). The zone interlock finds its zones from it; `simulate --plot` draws it.

use super::programme::Programmes;
use crate::cell::exact::{aabb_of, pair_state, PairState, RobotInWcs};
use crate::cell::{Cell, ExactChecker};
use crate::math::{Real, Vec3};
use crate::robot::RobotBoxes;

/// The conflict cells of robots `a` and `b`: `cells[i * cols + k]` for sample `i` of `a`
/// and sample `k` of `b`.
#[derive(Clone, Debug, PartialEq)]
pub struct ConflictCells {
    /// Programme ticks between two samples.
    pub stride: usize,
    /// Samples of `a` (rows) and of `b` (columns).
    pub rows: usize,
    /// Samples of `b`.
    pub cols: usize,
    /// Whether each cell is in conflict (an unreachable set-point conflicts with all).
    pub cells: Vec<bool>,
}

/// Robot `j`'s boxes at `tcp`, grown by `growth`, with their AABB (None when unreachable).
fn grown(
    exact: &ExactChecker,
    j: usize,
    tcp: &Vec3,
    growth: Real,
) -> Option<(RobotBoxes, (Vec3, Vec3))> {
    let mut boxes = RobotBoxes::empty();
    exact.boxes_in_wcs(j, tcp, &mut boxes).ok()?;
    for b in &mut boxes.boxes[..boxes.len] {
        *b = b.inflated(growth);
    }
    let aabb = aabb_of(&boxes);
    Some((boxes, aabb))
}

/// The conflict cells of robots `a` and `b` of `cell` over their whole `programmes`.
pub fn conflict_cells(
    cell: &Cell,
    programmes: &Programmes,
    (a, b): (usize, usize),
    stride: usize,
    clearance_mm: Real,
) -> ConflictCells {
    let exact = ExactChecker::new(cell.clone());
    let samples = |j: usize| -> Vec<_> {
        programmes[j]
            .iter()
            .step_by(stride)
            .map(|t| grown(&exact, j, t, 0.5 * clearance_mm))
            .collect()
    };
    let (sa, sb) = (samples(a), samples(b));
    let mut cells = Vec::with_capacity(sa.len() * sb.len());
    for x in &sa {
        for y in &sb {
            cells.push(match (x, y) {
                (Some(x), Some(y)) => {
                    let ra = RobotInWcs { boxes: x.0.as_slice(), aabb: &x.1 };
                    let rb = RobotInWcs { boxes: y.0.as_slice(), aabb: &y.1 };
                    !matches!(pair_state(&ra, &rb, None), PairState::Free)
                }
                _ => true,
            });
        }
    }
    ConflictCells { stride, rows: sa.len(), cols: sb.len(), cells }
}
