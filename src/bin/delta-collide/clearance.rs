//! The signed clearance of a cell at the exact checker's last configuration (SPEC §8), as
//! `check --clearance` prints it and `replay --plot` draws it: the library's
//! [`clearance_now`], `None` when a TCP was unreachable (its boxes are not built); and per
//! robot pair, as `replay --pairs` prints it.

use delta_collide::cell::protective::clearance_now;
use delta_collide::cell::ExactChecker;
use delta_collide::geometry::boxes_clearance;

/// The cell's signed clearance (mm) as of `exact`'s last check; `None` when a TCP was
/// unreachable, `+inf` when no pair can meet.
pub fn signed_clearance(exact: &ExactChecker) -> Option<f64> {
    exact.verdict().all_reachable().then(|| clearance_now(exact).0)
}

/// Per robot pair that can meet (in `exact.verdict().pairs` order), its signed clearance (mm)
/// as of `exact`'s last check; `None` when a TCP was unreachable.
pub fn pair_clearances(exact: &ExactChecker) -> Option<Vec<f64>> {
    let pairs = &exact.verdict().pairs;
    let each = |p: &delta_collide::cell::exact::PairVerdict| {
        boxes_clearance(exact.boxes(p.a).as_slice(), exact.boxes(p.b).as_slice()).distance
    };
    exact.verdict().all_reachable().then(|| pairs.iter().map(each).collect())
}
