//! The work budget of the proof along the stop paths (`path.rs`): the part of a tick whose
//! cost grows with the inputs (pieces halved per pair, time slices, tests of the speed limits
//! along the paths), counted in *units* and capped per tick by the caller
//! ([`ProtectiveChecker::with_path_work`](super::ProtectiveChecker::with_path_work)).
//!
//! One unit is one piece of a stop built (its sweeps over the piece's ball: inverse
//! kinematics through the motor table and one sweep per box) or one pair of pieces tested
//! (the swept-box proof of their box pairs); on the worst inputs found by search a unit
//! costs about 21,000 x86-64 instructions (docs/record/2026-12-02-worst-cases.md). A step that would need more units than are left is not
//! taken, and what it would have proved stays unproved: the verdict is then the one without
//! the paths (a proof too, never better than a completed proof along them) and a speed limit
//! the highest speed proved so far. So the budget bounds the tick's work whatever the inputs,
//! and the answer when it runs out is the safe one.
//!
//! The count lives in `Cell`s because the prover reads the checker through `&self` while it
//! halves pieces; nothing here allocates.

use core::cell::Cell;

/// Units a tick may spend on the proof along the paths by default: few enough that the
/// worst call found by search stays within one 1 ms tick on the machine of the records
/// (about 61,000 + 21,000 units instructions at about 12,000 a microsecond:
/// docs/record/2026-12-02-worst-cases.md), enough that the closed-loop benchmark keeps what
/// it keeps uncapped (docs/record/2026-12-02-work-budget.md).
pub const DEFAULT_PATH_WORK: u32 = 500;

/// One tick's count: the units left and whether a step found too few.
#[derive(Clone, Debug, Default)]
pub(super) struct PathWork {
    left: Cell<u32>,
    used: Cell<u32>,
    ran_out: Cell<bool>,
}

impl PathWork {
    /// A new tick with `budget` units.
    pub(super) fn start(&self, budget: u32) {
        self.left.set(budget);
        self.used.set(0);
        self.ran_out.set(false);
    }

    /// Takes `units` when that many are left (then `true`); else takes none and remembers
    /// that the budget ran out.
    pub(super) fn spend(&self, units: u32) -> bool {
        let left = self.left.get();
        if left < units {
            self.ran_out.set(true);
            return false;
        }
        self.left.set(left - units);
        self.used.set(self.used.get() + units);
        true
    }

    /// Units spent this tick.
    pub(super) fn used(&self) -> u32 {
        self.used.get()
    }

    /// Whether some step this tick was not taken for want of units.
    pub(super) fn ran_out(&self) -> bool {
        self.ran_out.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_larger_than_what_is_left_takes_nothing() {
        let w = PathWork::default();
        w.start(3);
        assert!(w.spend(2));
        assert!(!w.spend(2));
        assert!((w.used(), w.ran_out()) == (2, true));
        assert!(w.spend(1));
        assert!(!w.spend(1));
        assert_eq!(w.used(), 3);
        w.start(1);
        assert!((w.used(), w.ran_out()) == (0, false));
    }
}
