//! The signed clearance of a cell at the exact checker's last configuration (SPEC §8), as
//! `check --clearance` prints it and `replay --plot` draws it: the library's
//! [`clearance_now`], `None` when a TCP was unreachable (its boxes are not built).

use delta_collide::cell::protective::clearance_now;
use delta_collide::cell::ExactChecker;

/// The cell's signed clearance (mm) as of `exact`'s last check; `None` when a TCP was
/// unreachable, `+inf` when no pair can meet.
pub fn signed_clearance(exact: &ExactChecker) -> Option<f64> {
    exact.verdict().all_reachable().then(|| clearance_now(exact).0)
}
