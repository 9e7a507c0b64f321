//! The protective verdict from a certified clearance table (SPEC §8; clearance tables, SPEC
//! §6): where the table's bound alone proves FREE, a tick costs two table lookups and one
//! motion bound per robot instead of the swept-box proof of every box pair.
//!
//! # Why a lookup proves FREE
//! Let robot `j`'s stop ball be `B(c_j, R_j)` (module doc of `protective`, step 3: the
//! capsule's ball when its centre is reachable, else the ball of radius `S` around the TCP
//! now): every TCP of the whole stop lies in it. Its sweeps (step 4, the table's tier of
//! motor angles, either form) bound the displacement of every box point, for every
//! reachable TCP of that ball, from the same point of the boxes at `c_j`; so no box point of
//! robot `j` moves further than `d_j`, the largest [`crate::geometry::Sweep::radius`] of its boxes, from
//! where it is at `c_j`, until `j` stands still. A clearance table certifies `L`: every
//! configuration of the table cell of `(c_A, c_B)` (both TCPs, each in its own MCS) has
//! clearance at least `L`, in particular `(c_A, c_B)` itself. Any point `x` of a box of A
//! and `y` of a box of B during the stop come from points `x0`, `y0` of those boxes at
//! `(c_A, c_B)` with `|x - x0| <= d_A` and `|y - y0| <= d_B`, so
//! `|x - y| >= |x0 - y0| - d_A - d_B >= L - d_A - d_B`. Hence `L > d_A + d_B + warn_mm`
//! proves FREE with `warn_mm` to spare. The reference points `c_A`, `c_B` need not be
//! where the robots are at the same time: the bound holds for the pair of configurations.
//!
//! Only FREE is answered this way. Where the bound does not prove FREE the tick takes the
//! full proof, unchanged, so table mode never answers worse than exact mode, and better
//! only where the lookup's proof holds. A WARN from the lookup (`L > d_A + d_B` alone) is
//! not answered: the full proof may still prove FREE there.
//!
//! # The clearance reported
//! The TCPs now lie in the stop balls, so the clearance now is at least `L - d_A - d_B`
//! (> `warn_mm`); the table's bound at the TCPs now, when it has a level there, is another
//! certified lower bound. The report holds the larger: never above the exact clearance.
//!
//! # Numerics
//! The proof asks `L` to exceed `d_A + d_B + warn_mm` by [`LOOKUP_SLACK_MM`], far above the
//! rounding of the radii; sweeps that are not finite (a ball centre or cube out of reach of
//! every bound) prove nothing.

use super::ProtectiveChecker;
use crate::math::{Real, Vec3};

/// A certified lower bound on the clearance (SPEC §8, mm) of a two-robot cell at the given
/// TCPs (each in its own robot's MCS), `None` when nothing is proved; for example
/// [`crate::table::TableChecker::clearance_bound`] of a clearance table.
pub type ClearanceBound<'a> = &'a dyn Fn(&[Vec3]) -> Option<Real>;

/// How far (mm) the table's bound must exceed both motion bounds and `warn_mm` before a
/// lookup proves FREE: far above the rounding of the radii (about 1e-13 of a metre).
pub const LOOKUP_SLACK_MM: Real = 1e-6;

impl ProtectiveChecker {
    /// Sets robot `j`'s stop reference for TCP `tcp_mcs` at measured speed `v` (its stop
    /// ball's centre, the TCP when that is not reachable) with the table's tier of sweeps,
    /// which the full proof reuses, and returns `d_j`: the farthest any of its box points
    /// moves from its place at the reference over the stop (module doc); `INFINITY` when no
    /// bound is found.
    fn motion_bound(&mut self, j: usize, tcp_mcs: &Vec3, v: Real) -> Real {
        self.stop_reference(j, tcp_mcs, v);
        self.sweeps_at(j, 0, 0);
        let [cube, ball] = &self.sweeps[j];
        // Either form holds every displacement: the smaller radius bounds it.
        let d = cube.iter().zip(ball).map(|(c, b)| c.radius().min(b.radius())).fold(0.0, Real::max);
        if d.is_nan() {
            Real::INFINITY
        } else {
            d
        }
    }

    /// Whether `bound` proves FREE with `warn_mm` to spare for the two robots at `tcps_mcs`
    /// (speeds in the report), and if so a certified lower bound on the clearance now (module
    /// doc). `None` for any other number of robots, or when the bound does not prove it. Sets
    /// every robot's stop reference and table-tier sweeps either way.
    pub(super) fn lookup_free(&mut self, tcps_mcs: &[Vec3], bound: ClearanceBound) -> Option<Real> {
        let mut motion = 0.0;
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            motion += self.motion_bound(j, tcp, self.report.robots[j].speed_mm_s);
        }
        if tcps_mcs.len() != 2 {
            return None;
        }
        let at_centres = bound(&[self.centres[0], self.centres[1]])?;
        if !(motion.is_finite() && at_centres > motion + self.warn_mm + LOOKUP_SLACK_MM) {
            return None;
        }
        let now = bound(tcps_mcs).unwrap_or(Real::NEG_INFINITY);
        Some(now.max(at_centres - motion))
    }
}
