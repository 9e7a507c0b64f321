//! Certain STOPs kept from tick to tick by a *contact*: two reachable TCPs, one in each
//! robot's stop ball, at which a box of one robot overlaps a box of the other.
//!
//! # Why a contact settles a tick
//! Every tier's sweeps of a robot's stop ball bound the boxes of every reachable TCP of that
//! ball (module doc of `protective`, step 4), in either form. So when a reachable TCP `q_a`
//! of robot `a`'s ball and one `q_b` of robot `b`'s give boxes `i` of `a` and `k` of `b`
//! whose interiors meet (they overlap by more than `MEET_DEPTH` on each of their 15 axes:
//! [`boxes_overlap_deeply`]), the swept sets of that box pair share those points, no axis
//! separates them with a positive gap, and no tier proves the pair apart: the tick is STOP,
//! the verdict the full proof gives (step 8: the verdict does not depend on which unproved
//! pair is found). This only ends a search for a proof; it never proves anything.
//!
//! `q_a` and `q_b` stay reachable (the inverse kinematics is deterministic) and their boxes
//! stay where they are, so the contact holds at every later tick whose stop balls still hold
//! `q_a` and `q_b`. Both balls of step 3 are tested (the capsule's ball and the ball of radius
//! `S` around the TCP): the proof measures its sweeps from one of them.
//!
//! # Finding one
//! A robot stops within tens of millimetres but moves a few per tick, so a contact found deep
//! inside the balls settles the STOP ticks that follow with two distance tests. It is sought
//! after a STOP tick without one, along the line between the closest points now: each TCP is
//! moved from its ball's centre toward the other robot by [`REACH_FRACTIONS`] of its radius,
//! the nearest first, and the pair closest now is tested at each.

use super::{BoxPair, ProtectiveChecker};
use crate::geometry::sweep::boxes_overlap_deeply;
use crate::math::{Real, Vec3};

/// Fractions of each stop ball's radius tried when seeking a contact, nearest the centre
/// first: a contact nearer the centre stays inside the balls of more later ticks.
const REACH_FRACTIONS: [Real; 4] = [0.25, 0.5, 0.75, 0.95];

/// How far inside each stop ball a contact's TCP must lie (mm): far above the rounding of
/// a ball's centre and radius (about `1e-13` of a few hundred mm).
const INSIDE_SLACK_MM: Real = 1e-6;

/// STOP ticks without seeking after a search found nothing: robots close for their stop
/// balls but not close enough to touch stay so for many ticks, and a search costs about
/// three exact queries.
const SEEK_BACKOFF: u32 = 16;

/// Two reachable TCPs (each in its robot's MCS) at which box pair `pair` overlaps.
#[derive(Clone, Copy, Debug)]
struct Contact {
    pair: BoxPair,
    tcps: [Vec3; 2],
}

/// The contact kept, if any, and the STOP ticks left before the next search.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct KeptContact {
    contact: Option<Contact>,
    backoff: u32,
}

#[cfg(test)]
impl KeptContact {
    /// Whether a contact is kept.
    pub(super) fn is_kept(&self) -> bool {
        self.contact.is_some()
    }
}

impl ProtectiveChecker {
    /// The box pair of the kept contact when its TCPs lie in this tick's stop balls of both
    /// robots (`tcps_mcs`: this tick's TCPs, whose balls `stop_balls` holds).
    pub(super) fn contact_holds(&self, tcps_mcs: &[Vec3]) -> Option<BoxPair> {
        let w = self.contact.contact?;
        let inside = |j: usize, q: &Vec3| {
            let (s, (centre, radius)) = self.robots[j].stop_ball;
            (q - centre).norm() <= radius - INSIDE_SLACK_MM
                && (q - tcps_mcs[j]).norm() <= s - INSIDE_SLACK_MM
        };
        (inside(w.pair.a, &w.tcps[0]) && inside(w.pair.b, &w.tcps[1])).then_some(w.pair)
    }

    /// Seeks a contact for this tick's stop balls (module doc, "Finding one") on box pair
    /// `closest`, whose closest points now (WCS) are `points`; keeps it when found, else
    /// forgets the last one.
    pub(super) fn seek_contact(&mut self, closest: BoxPair, points: [Vec3; 2]) {
        self.contact.contact = None;
        if self.contact.backoff > 0 {
            self.contact.backoff -= 1;
            return;
        }
        self.contact.backoff = SEEK_BACKOFF;
        let gap = points[1] - points[0];
        let robots = &self.exact.cell().robots;
        let (ra, rb) = (&robots[closest.a], &robots[closest.b]);
        let (box_a, box_b) = (
            &self.exact.boxes(closest.a).as_slice()[closest.box_a],
            &self.exact.boxes(closest.b).as_slice()[closest.box_b],
        );
        // Toward the other robot: along the closest points when apart, else between centres.
        let toward = if gap.norm() > 1e-9 { gap } else { box_b.center - box_a.center };
        let Some(u) = toward.try_normalize(0.0) else { return };
        let (rot_a, rot_b) = (self.exact.rotation(closest.a), self.exact.rotation(closest.b));
        let (ua, ub) = (rot_a.transpose() * u, -(rot_b.transpose() * u));
        let ((_, (ca, sa)), (_, (cb, sb))) =
            (self.robots[closest.a].stop_ball, self.robots[closest.b].stop_ball);
        for f in REACH_FRACTIONS {
            let (qa, qb) = (ca + ua * (f * sa), cb + ub * (f * sb));
            let (Ok(ika), Ok(ikb)) = (
                ra.model.delta.inverse_kinematics_cos_sin(&qa),
                rb.model.delta.inverse_kinematics_cos_sin(&qb),
            ) else {
                continue;
            };
            let a = ra
                .model
                .box_from_cos_sin(&qa, &ika, closest.box_a)
                .transformed(rot_a, &ra.placement.t);
            let b = rb
                .model
                .box_from_cos_sin(&qb, &ikb, closest.box_b)
                .transformed(rot_b, &rb.placement.t);
            if boxes_overlap_deeply(&a, &b) {
                self.contact = KeptContact {
                    contact: Some(Contact { pair: closest, tcps: [qa, qb] }),
                    backoff: 0,
                };
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::protective::Protective;
    use crate::cell::reference::reference_cell;
    use crate::cell::trajectory::{parse_scenarios, RUN_TICKS};
    use crate::cell::ExactChecker;
    use crate::robot::StopModel;

    /// Every contact behind a STOP is a real collision within the stop: the exact query (its
    /// own inverse kinematics and boxes, every box pair) finds the robots colliding at the
    /// contact's TCPs, each within the stopping distance `S` of its robot's TCP now. And the
    /// collision runs, where the robots do meet, have contacts on many STOP ticks.
    #[test]
    fn contacts_are_collisions_within_the_stop() {
        let text = include_str!("../../../c_harness/scenarios.txt");
        for s in parse_scenarios(text).unwrap() {
            let cell = reference_cell(&s.cell)
                .unwrap()
                .with_stopping(1.0, alloc::vec![StopModel::DEFAULT; 2])
                .unwrap();
            let mut c =
                ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
            let mut exact = ExactChecker::new(cell);
            let (mut tcps, mut contacted, mut stops) = ([Vec3::zeros(); 2], 0, 0);
            for tick in 0..RUN_TICKS {
                s.tcps_at(tick, &mut tcps);
                let r = c.check(&tcps).unwrap().clone();
                stops += usize::from(r.verdict == Protective::Stop);
                let Some(w) = c.contact.contact.filter(|_| r.verdict == Protective::Stop) else {
                    continue;
                };
                contacted += 1;
                for (j, q) in [(w.pair.a, w.tcps[0]), (w.pair.b, w.tcps[1])] {
                    assert!(
                        (q - tcps[j]).norm() <= r.robots[j].protective_mm,
                        "{} {} tick {tick}",
                        s.cell,
                        s.case
                    );
                }
                assert!(
                    exact.check(&w.tcps).unwrap().collides(),
                    "{} {} tick {tick}: {w:?}",
                    s.cell,
                    s.case
                );
            }
            std::eprintln!(
                "{} {}: {contacted} of {stops} STOP ticks with a contact",
                s.cell,
                s.case
            );
            if s.case == "collision" {
                assert!(3 * contacted > stops, "{} {}: {contacted} of {stops}", s.cell, s.case);
            }
        }
    }
}
