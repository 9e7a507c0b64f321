//! The protective verdict from a certified clearance table (SPEC §8; clearance tables, SPEC
//! §6): where the table's bound alone proves FREE, a tick costs one table lookup per pair
//! that can meet and one motion bound per robot instead of the swept-box proof of every box
//! pair. A line's pairs each take their table's bound (a bundle's): the pairs it proves are
//! skipped by the proof of the others, and the tick needs no proof when it proves them all. It
//! is tried after the cheaper answers (a kept proof, a certain STOP, a proof kept for wider
//! balls) and before the proof, which reuses the sweeps it computed.
//!
//! # Why a lookup proves FREE
//! Let robot `j`'s stop ball be `B(c_j, R_j)` (its stop reference, module doc of
//! `protective`, step 3: the capsule's ball when the boxes at its centre exist, else the ball
//! of radius `S` around the TCP now): every TCP of the whole stop lies in it. Its sweeps (step 4,
//! the table's tier of motor angles, either form) bound the displacement of every box point, for
//! every reachable TCP of that ball, from the same point of the boxes at `c_j`; so no box point of
//! robot `j` moves further than `d_j`, the largest [`crate::geometry::Sweep::radius`] of its boxes,
//! from where it is at `c_j`, until `j` stands still. A clearance table certifies `L`: every
//! configuration of the table cell of `(c_A, c_B)` (both TCPs, each in its own MCS) has
//! clearance at least `L`, in particular `(c_A, c_B)` itself. Any point `x` of a box of A
//! and `y` of a box of B during the stop come from points `x0`, `y0` of those boxes at
//! `(c_A, c_B)` with `|x - x0| <= d_A` and `|y - y0| <= d_B`, so
//! `|x - y| >= |x0 - y0| - d_A - d_B >= L - d_A - d_B`. Hence `L > d_A + d_B + warn_mm`
//! proves FREE with `warn_mm` to spare. The reference points `c_A`, `c_B` need not be
//! where the robots are at the same time: the bound holds for the pair of configurations.
//!
//! Only FREE is answered this way, pair by pair. Where the bound does not prove a pair, the
//! pair takes the full proof, unchanged, so table mode never answers worse than exact mode,
//! and better only where the lookup's proof holds. A WARN from the lookup (`L > d_A + d_B` alone)
//! is not answered: the full proof may still prove FREE there.
//!
//! # The clearance reported
//! Unchanged: every tick with status OK computes the exact clearance before any proof.
//!
//! # Numerics
//! The proof asks `L` to exceed `d_A + d_B + warn_mm` by [`LOOKUP_SLACK_MM`], far above the
//! rounding of the radii; sweeps that are not finite (a ball centre or cube out of reach of
//! every bound) prove nothing.

use super::ProtectiveChecker;
use crate::math::{Real, Vec3};

/// A certified lower bound on the clearance (SPEC §8, mm) between robots `a` and `b` of the
/// cell (the first two arguments, `a < b`) with their TCPs at `[tcp_a, tcp_b]` (each in its
/// own robot's MCS), `None` when nothing is proved; for example
/// [`crate::table::TableChecker::clearance_bound`] of a clearance table for two robots, or
/// [`crate::table::BundleChecker::clearance_bound`] of a bundle of clearance tables for a line.
pub type ClearanceBound<'a> = &'a dyn Fn(usize, usize, &[Vec3]) -> Option<Real>;

/// How far (mm) the table's bound must exceed both motion bounds and `warn_mm` before a
/// lookup proves FREE: far above the rounding of the radii (about 1e-13 of a metre).
pub const LOOKUP_SLACK_MM: Real = 1e-6;

impl ProtectiveChecker {
    /// Robot `j`'s `d_j` about its stop reference (set for this tick): the farthest any of
    /// its box points moves from its place at the reference over the stop, from the table's
    /// tier of sweeps, which the full proof then reuses (module doc); `INFINITY` when no bound
    /// is found.
    fn motion_bound(&mut self, j: usize) -> Real {
        self.sweeps_at(j, 0, 0);
        let [cube, ball] = &self.robots[j].reference.sweeps;
        // Either form holds every displacement: the smaller radius bounds it.
        let d = cube.iter().zip(ball).map(|(c, b)| c.radius().min(b.radius())).fold(0.0, Real::max);
        if d.is_nan() {
            Real::INFINITY
        } else {
            d
        }
    }

    /// Marks each pair that can meet whose robots `bound` proves apart with `warn_mm` to spare
    /// about this tick's stop references (module doc), counts them in the report, and says
    /// whether that is every pair: the tick is then FREE. The swept-box proof skips the pairs
    /// marked (a line's far pairs, while its neighbours come close).
    pub(super) fn lookup_pairs(&mut self, bound: ClearanceBound) -> bool {
        let mut proved = 0;
        for k in 0..self.exact.verdict().pairs.len() {
            let (a, b) = (self.exact.verdict().pairs[k].a, self.exact.verdict().pairs[k].b);
            self.pairs[k].table_proved = self.pair_proved(bound, a, b);
            proved += u32::from(self.pairs[k].table_proved);
        }
        self.report.table_pairs = proved;
        proved as usize == self.pairs.len()
    }

    /// Whether `bound` proves robots `a` and `b` apart with `warn_mm` to spare (module doc).
    fn pair_proved(&mut self, bound: ClearanceBound, a: usize, b: usize) -> bool {
        let Some(at_centres) =
            bound(a, b, &[self.robots[a].reference.centre, self.robots[b].reference.centre])
        else {
            return false;
        };
        // A lower link's sweep at its platform joint's end, and a platform's or tool's sweep,
        // hold the ball of the stop's radius (module doc of `protective`, step 6), so
        // `d_j >= R_j`: where the bound cannot exceed
        // that, the sweeps are not computed (the proof may still need them).
        let least =
            self.robots[a].reference.radius + self.robots[b].reference.radius + self.model.warn_mm;
        if at_centres.partial_cmp(&least) != Some(core::cmp::Ordering::Greater) {
            return false;
        }
        let motion = self.motion_bound(a) + self.motion_bound(b);
        motion.is_finite() && at_centres > motion + self.model.warn_mm + LOOKUP_SLACK_MM
    }
}
