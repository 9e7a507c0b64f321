//! The signed clearance of a cell at the exact checker's last configuration (SPEC §8): the
//! smallest signed clearance ([`boxes_clearance`]) over the robot pairs that can meet, so
//! positive is the gap and negative minus the penetration depth. `check --clearance` and
//! `replay --plot` print and draw it.

use delta_collide::cell::ExactChecker;
use delta_collide::geometry::boxes_clearance;

/// The cell's signed clearance (mm) as of `exact`'s last check; `None` when a TCP was
/// unreachable (its boxes are not built), `+inf` when no pair can meet.
pub fn signed_clearance(exact: &ExactChecker) -> Option<f64> {
    let v = exact.verdict();
    if !v.all_reachable() {
        return None;
    }
    let pair = |a: usize, b: usize| boxes_clearance(exact.boxes(a).as_slice(), exact.boxes(b).as_slice()).distance;
    // A NaN (a non-finite box) wins, so it shows instead of a finite minimum.
    Some(v.pairs.iter().map(|p| pair(p.a, p.b)).fold(f64::INFINITY, |m, d| if d.is_nan() || d < m { d } else { m }))
}
