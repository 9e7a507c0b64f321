//! Steps 6 and 7 of the protective verdict (module doc of `protective`): the STOPs that are
//! certain before any sweep of a tier is computed. Step 6 sweeps each reference box by the
//! graded ball of its stop's radius alone, which every sweep of the box holds; step 7 by the
//! sweeps of the motor angles sampled in the ball, which every tier's
//! sweeps hold. A box pair that those are not proved apart by is not proved apart by any
//! tier: STOP without the full proof.

use super::stop_sweeps::{graded_points, pair_apart_in_some_form, GradedRadii};
use super::{BoxPair, ProtectiveChecker};
use crate::geometry::sweep::{balls_swept_apart_with, Axes, FaceTerms};
use crate::geometry::{Obb, Sweep};
use crate::math::interval::Interval;
use crate::math::{Real, Vec3};
use crate::robot::delta3::{ArmSolution, MotorCosSin};
use crate::robot::motion_bound::{box_sweep_forms, tcp_weights};
use crate::robot::{BoxKind, RobotModel};

/// How far (rad) each sampled motor angle of [`ProtectiveChecker::least_sweeps`] is taken
/// toward the centre's: far above the rounding of the inverse kinematics, even near the edge of
/// the workspace, where the angle's error is about the square root of the machine epsilon.
const ANGLE_SLACK: Real = 1e-6;

/// How much (mm) the balls of [`ProtectiveChecker::least_sweeps`] are shrunk: far above the
/// rounding of a support (about `1e-13 |n|`), far below the `BOUND_SLACK` every ball holds.
const LEAST_SLACK: Real = 1e-9;

impl ProtectiveChecker {
    /// The sweep of robot `j`'s box `k` about the reference ball `(centre, s)` (centre MCS;
    /// both forms, WCS) from the motor angles of the centre and of the two points of the
    /// ball along the gradient of its arm's angle alone, each angle `ANGLE_SLACK` toward the
    /// centre's and each ball `LEAST_SLACK` smaller: on every axis no larger than the sweeps
    /// of any tier (module doc, step 7). `None` when the centre is unreachable or a point's angle
    /// lies more than a right angle from the centre's (a range across the branch cut at `+-pi`,
    /// which no motor limit of a Delta robot allows): nothing learned. `at_centre`: the centre's
    /// inverse kinematics, when the caller has it.
    fn least_sweeps(
        &self,
        j: usize,
        k: usize,
        centre: Vec3,
        s: Real,
        at_centre: Option<MotorCosSin>,
    ) -> Option<[Sweep; 2]> {
        let robot = &self.exact.cell().robots[j];
        let d = &robot.model.delta;
        let at_centre = match at_centre {
            Some(sol) => sol,
            None => d.inverse_kinematics_cos_sin(&centre).ok()?,
        };
        // Box `k`'s sweep depends on its own arm's range alone; the others' are not read.
        let mut th = [Interval::point(0.0); 3];
        let mut sol = ArmSolution { theta: [0.0; 3], cos: at_centre.cos, sin: at_centre.sin };
        if let BoxKind::LowerLink(arm) | BoxKind::UpperLink(arm) = robot.model.box_kind(k) {
            let i = arm as usize;
            let theta0 = at_centre.theta(i);
            sol.theta[i] = theta0;
            // `w = E_i - G_i`: the platform joint `p + e u_i` less the elbow
            // `(f + rf cos th) u_i - rf sin th z`.
            let u = crate::robot::delta3::radial(i);
            let w = centre
                + u * (d.e - d.f - d.rf * at_centre.cos[i])
                + Vec3::z() * (d.rf * at_centre.sin[i]);
            let toward = w * (s / w.norm());
            let (mut lo, mut hi) = (theta0, theta0);
            for point in [centre + toward, centre - toward] {
                let Ok(at) = d.inverse_kinematics_cos_sin(&point) else { continue };
                let theta = at.theta(i);
                // A NaN is not close either: nothing learned.
                let close = (theta - theta0).abs() <= core::f64::consts::FRAC_PI_2;
                if !close {
                    return None;
                }
                (lo, hi) = (lo.min(theta + ANGLE_SLACK), hi.max(theta - ANGLE_SLACK));
            }
            th[i] = Interval::new(lo, hi);
        }
        let rot = self.exact.rotation(j);
        let forms = box_sweep_forms(&robot.model, &centre, s, &centre, &sol, &th, k);
        Some(
            forms.map(|form| Sweep {
                ball: (form.ball - LEAST_SLACK).max(0.0),
                ..form.rotated(rot)
            }),
        )
    }

    /// Whether box pair `p` is certain not to be proved apart (with `extra` mm added to the
    /// first robot's sweeps) by the sweeps of any tier (module doc, step 7); `false` when that
    /// is not known.
    pub(super) fn beyond_every_tier(&self, p: BoxPair, extra: Real) -> bool {
        let reference = |j: usize, k: usize| {
            (
                self.robots[j].reference.boxes.as_slice()[k],
                self.robots[j].reference.centre,
                self.robots[j].reference.radius,
                None,
            )
        };
        self.beyond_every_tier_at(p, [reference(p.a, p.box_a), reference(p.b, p.box_b)], extra)
    }

    /// [`ProtectiveChecker::beyond_every_tier`] with the pair's two reference boxes (WCS),
    /// each robot's reference ball (centre MCS, radius) and, when at hand, its centre's inverse
    /// kinematics given.
    fn beyond_every_tier_at(
        &self,
        p: BoxPair,
        [(box_a, ca, sa, ika), (box_b, cb, sb, ikb)]: [(Obb, Vec3, Real, Option<MotorCosSin>); 2],
        extra: Real,
    ) -> bool {
        let (Some(la), Some(lb)) = (
            self.least_sweeps(p.a, p.box_a, ca, sa, ika),
            self.least_sweeps(p.b, p.box_b, cb, sb, ikb),
        ) else {
            return false;
        };
        let (ra, rb) =
            (self.graded_ball_radii(p.a, p.box_a, sa), self.graded_ball_radii(p.b, p.box_b, sb));
        let (a, b) = ((&box_a, [&la[0], &la[1]], ra), (&box_b, [&lb[0], &lb[1]], rb));
        !pair_apart_in_some_form(a, b, extra, &self.pair_axis(p))
    }

    /// The axis the proofs of this tick try for box pair `p`'s robot pair besides the 15 of
    /// each box pair (`pair_axes`); none for a pair that cannot meet.
    fn pair_axis(&self, p: BoxPair) -> Vec3 {
        let pairs = &self.exact.verdict().pairs;
        pairs
            .iter()
            .position(|q| (q.a, q.b) == (p.a, p.b))
            .map_or(Vec3::zeros(), |k| self.pairs[k].axis)
    }

    /// The certain STOPs of steps 6 and 7 on box pair `p` before the references are set
    /// (step 8): its two reference boxes built as [`ProtectiveChecker::reference_at`] builds
    /// them (the same operations, so the same answers), from this tick's stop balls; step 7
    /// only when `also_least`.
    pub(super) fn reference_pair_stops(
        &self,
        tcps_mcs: &[Vec3],
        p: BoxPair,
        also_least: bool,
    ) -> bool {
        let refs = self.reference_pair(tcps_mcs, p);
        let (ra, rb) = (
            self.graded_ball_radii(p.a, p.box_a, refs[0].2),
            self.graded_ball_radii(p.b, p.box_b, refs[1].2),
        );
        !balls_apart((&refs[0].0, ra), (&refs[1].0, rb), &self.pair_axis(p))
            || (also_least && self.beyond_every_tier_at(p, refs, 0.0))
    }

    /// Box pair `p`'s reference boxes (WCS) as [`ProtectiveChecker::reference_at`] builds them
    /// (the same operations, so the same values) from this tick's stop balls, each with its
    /// reference centre (MCS), radius and, at a ball's centre, the inverse kinematics there.
    fn reference_pair(
        &self,
        tcps_mcs: &[Vec3],
        p: BoxPair,
    ) -> [(Obb, Vec3, Real, Option<MotorCosSin>); 2] {
        let reference = |j: usize, k: usize| {
            let robot = &self.exact.cell().robots[j];
            let (tcp, (s, (centre, radius))) = (&tcps_mcs[j], self.robots[j].stop_ball);
            match robot.model.delta.inverse_kinematics_cos_sin(&centre) {
                Ok(sol) if centre != *tcp => {
                    let b = robot.model.box_from_cos_sin(&centre, &sol, k);
                    (
                        b.transformed(self.exact.rotation(j), &robot.placement.t),
                        centre,
                        radius,
                        Some(sol),
                    )
                }
                _ => (self.exact.boxes(j).as_slice()[k], *tcp, s, None),
            }
        };
        [reference(p.a, p.box_a), reference(p.b, p.box_b)]
    }

    /// [`least_radii`] of robot `j`'s box `k` for reference radius `reach`.
    fn graded_ball_radii(&self, j: usize, k: usize, reach: Real) -> [Real; 2] {
        least_radii(&self.exact.cell().robots[j].model, k, reach)
    }

    /// Whether box pair `p`'s reference boxes swept by their stop balls alone are not proved
    /// apart: step 6 for one pair, as the speed limits' search asks it before each test's sweeps.
    pub(super) fn ball_swept_meet(&self, p: BoxPair) -> bool {
        let (box_a, box_b) = (
            &self.robots[p.a].reference.boxes.as_slice()[p.box_a],
            &self.robots[p.b].reference.boxes.as_slice()[p.box_b],
        );
        let (ra, rb) = (
            self.robots[p.a].reference.graded[p.box_a],
            self.robots[p.b].reference.graded[p.box_b],
        );
        !balls_apart((box_a, ra), (box_b, rb), &self.pair_axis(p))
    }
}

/// The radii of box `k`'s sweep of step 6, a [`Sweep::graded_ball`]: the stop's radius `reach`
/// (shrunk by a relative 1e-9) times the weight of the TCP's set at each end of the box's
/// sweeps ([`tcp_weights`]).
fn least_radii(model: &RobotModel, k: usize, reach: Real) -> [Real; 2] {
    tcp_weights(model, k).map(|e| e * reach * (1.0 - 1e-9))
}

/// [`least_radii`] of every box of a robot of `model` for reference radius `reach`.
pub(super) fn graded_radii(model: &RobotModel, reach: Real) -> GradedRadii {
    core::array::from_fn(|k| {
        if k < model.box_count() {
            least_radii(model, k, reach)
        } else {
            [0.0; 2]
        }
    })
}

/// Whether box `a` swept by the graded ball of radii `ra` and box `b` by that of `rb` are
/// proved apart on the axes the proof tries (module doc, step 5): the 15, `axis` (the robot
/// pair's) and the pair's graded axis ([`graded_points`]). `false` also when the two swept sets
/// are found to share a point there, which no axis separates.
fn balls_apart((a, ra): (&Obb, [Real; 2]), (b, rb): (&Obb, [Real; 2]), axis: &Vec3) -> bool {
    let (fa, fb) = (FaceTerms::ball(a, ra), FaceTerms::ball(b, rb));
    if balls_swept_apart_with(a, ra, &fa, b, rb, &fb, Axes::FifteenAnd(axis)) {
        return true;
    }
    // When the graded balls meet, no axis separates the sweeps that hold them.
    let closest = graded_points((a, ra), (b, rb), 0.0);
    !closest.meet() && balls_swept_apart_with(a, ra, &fa, b, rb, &fb, Axes::Only(&closest.axis()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;
    use crate::robot::StopModel;

    /// Step 6's points answer as its separating axis tests on every closest pair of the
    /// default model's runs (graded balls found meeting: no axis separates, neither the 16 nor
    /// the pair's graded axis), and the graded axis separates most of the pairs that the 16
    /// leave unproved: `cargo test --release --lib graded_points -- --nocapture` prints how
    /// many of each.
    #[test]
    fn graded_points_answer_as_the_axes() {
        let text = include_str!("../../../c_harness/scenarios.txt");
        let (mut settled, mut separated) = (0, 0);
        for s in crate::cell::trajectory::parse_scenarios(text).unwrap().iter() {
            let cell = reference_cell(&s.cell)
                .unwrap()
                .with_stopping(1.0, vec![StopModel::DEFAULT; 2])
                .unwrap();
            let mut c = ProtectiveChecker::new(cell, 10.0).unwrap().with_speed_limits(false);
            let (mut tcps, mut unproved, mut found, mut along) = ([Vec3::zeros(); 2], 0, 0, 0);
            for tick in 0..crate::cell::trajectory::RUN_TICKS {
                s.tcps_at(tick, &mut tcps);
                c.check(&tcps).unwrap();
                let Some(p) = c.report.closest else { continue };
                let [(a, _, reach_a, _), (b, _, reach_b, _)] = c.reference_pair(&tcps, p);
                let (ra, rb) = (
                    c.graded_ball_radii(p.a, p.box_a, reach_a),
                    c.graded_ball_radii(p.b, p.box_b, reach_b),
                );
                let (fa, fb, axis) =
                    (FaceTerms::ball(&a, ra), FaceTerms::ball(&b, rb), c.pair_axis(p));
                let points = graded_points((&a, ra), (&b, rb), 0.0);
                let apart =
                    balls_swept_apart_with(&a, ra, &fa, &b, rb, &fb, Axes::FifteenAnd(&axis));
                let graded =
                    balls_swept_apart_with(&a, ra, &fa, &b, rb, &fb, Axes::Only(&points.axis()));
                assert!(!(points.meet() && (apart || graded)), "{} {} tick {tick}", s.cell, s.case);
                assert_eq!(balls_apart((&a, ra), (&b, rb), &axis), apart || graded);
                unproved += usize::from(!apart);
                found += usize::from(points.meet());
                along += usize::from(!apart && graded);
            }
            let (cell, case) = (&s.cell, &s.case);
            println!(
                "{cell} {case}: of the {unproved} closest pairs the 16 axes leave unproved, \
                 {found} are settled by the points, {along} separated by the graded axis"
            );
            (settled, separated) = (settled + found, separated + along);
        }
        assert!(settled > 20 && separated > 1000, "{settled} {separated}");
    }
}
