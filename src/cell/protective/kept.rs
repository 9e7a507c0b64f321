//! FREE proofs kept from tick to tick: a robot moves a few millimetres per tick while its stop
//! ball is tens to hundreds of millimetres across, so a proof made for a larger ball keeps
//! covering the stops of the ticks that follow.
//!
//! # Why a kept proof still proves
//! The sweeps of a ball `B(c0, R0)` bound the boxes of every reachable TCP of that ball
//! (module doc of `protective`, step 4), and the swept-box test proves two such sets apart
//! with `warn_mm` to spare. When this tick's stop ball `B(c, R)` lies inside `B(c0, R0)`,
//! that is `|c - c0| + R <= R0`, every TCP of this tick's stop is a TCP of the kept ball, so
//! its boxes lie in the kept swept sets: when every robot's stop ball lies in its kept ball
//! and every pair that can meet was proved for those kept balls, the tick is FREE. Either
//! ball of step 3 may be tested (the capsule's ball or the ball of radius `S` around the TCP):
//! each holds every TCP of the stop.
//!
//! # When a ball is kept
//! - When the full proof proves FREE with the table's tier alone, every robot keeps the ball
//!   and sweeps of that proof (nothing more to compute; they cover later stops that lie
//!   inside, as when the robot stands or slows down). So does a FREE from a clearance
//!   table's lookup (`protective/lookup.rs`): it proves FREE for every pair of TCPs of both
//!   balls, the same claim.
//! - On the tick after a FREE tick, a robot whose stop ball has left its kept ball gets a
//!   wider one: its stop ball widened by [`KEPT_WIDEN`] and [`KEPT_MARGIN_MM`] and moved
//!   ahead along the measured velocity by half the widening, with its own boxes and the
//!   table's tier of sweeps, so that the ticks that follow at speed stay inside. Each pair is
//!   proved once per pair of kept balls (a generation number per ball). Where the wider balls
//!   are not proved apart (robots close for their speed), the tick takes the full proof, and
//!   wider balls are not tried again for [`KEPT_BACKOFF`] ticks.
//!
//! Keeping turns no verdict of the full proof into a worse one: it only adds a way to FREE.

use super::certain_stop::graded_radii;
use super::stop_sweeps::SweptBall;
use super::{first_unproved_between, stop_sweeps_wcs, ProtectiveChecker};
use crate::math::{Real, Vec3};
use crate::robot::MAX_BOXES;

/// A kept ball's radius is the stop ball's times `1 + KEPT_WIDEN`, plus [`KEPT_MARGIN_MM`].
pub const KEPT_WIDEN: Real = 0.1;

/// The part of a kept ball's widening that does not scale with the stop ball (mm): about
/// two ticks at the fastest reference speed.
pub const KEPT_MARGIN_MM: Real = 3.0;

/// Ticks without trying wider balls after they failed to prove a pair: one. A failed try
/// costs about one proof; waiting longer leaves ticks that a wider ball would have settled
/// to the full proof (on the default model's T1 practical run, 16 ticks of waiting left
/// 40 % of the FREE ticks over 1 us, one tick 29 %: `prot_tick default verdict`).
pub const KEPT_BACKOFF: u32 = 1;

/// A robot's kept ball: the ball, its boxes and their sweeps, and which ball it is.
#[derive(Clone, Copy, Debug)]
pub(super) struct KeptBall {
    ball: SweptBall,
    /// Tells this ball from the robot's earlier ones.
    generation: u64,
}

/// What is kept: per robot its ball and whether this tick's stop lies in it, per pair that
/// can meet the generations it was proved for and whether it was proved FREE.
#[derive(Clone, Debug, Default)]
pub(super) struct Kept {
    balls: alloc::vec::Vec<Option<KeptBall>>,
    inside: alloc::vec::Vec<bool>,
    pairs: alloc::vec::Vec<Option<(u64, u64, bool)>>,
    next_generation: u64,
    /// Ticks left before wider balls are tried again.
    backoff: u32,
}

impl Kept {
    /// Nothing kept yet, for `robots` robots and `pairs` pairs that can meet.
    pub(super) fn new(robots: usize, pairs: usize) -> Self {
        Kept {
            balls: alloc::vec![None; robots],
            inside: alloc::vec![false; robots],
            pairs: alloc::vec![None; pairs],
            next_generation: 0,
            backoff: 0,
        }
    }

    /// Forgets everything kept, as [`Kept::new`] (no allocation).
    pub(super) fn clear(&mut self) {
        self.balls.fill(None);
        self.inside.fill(false);
        self.pairs.fill(None);
        (self.next_generation, self.backoff) = (0, 0);
    }

    /// Records whether robot `j`'s stop, held by each of `balls` (centre MCS, radius), lies
    /// in its kept ball; returns that.
    pub(super) fn set_inside(&mut self, j: usize, balls: &[(Vec3, Real)]) -> bool {
        let inside = self.balls[j].as_ref().is_some_and(|k| {
            balls
                .iter()
                .any(|(c, r)| r.is_finite() && (c - k.ball.centre).norm() + r <= k.ball.radius)
        });
        self.inside[j] = inside;
        inside
    }

    /// Whether robot `j`'s stop lay in its kept ball at the last [`Kept::set_inside`].
    pub(super) fn inside(&self, j: usize) -> bool {
        self.inside[j]
    }

    /// Sets back what [`Kept::inside`] returned for robot `j`.
    pub(super) fn restore_inside(&mut self, j: usize, inside: bool) {
        self.inside[j] = inside;
    }

    /// Whether every robot of pair `k` = `(a, b)` is inside its kept ball and the pair was
    /// proved FREE for those balls.
    fn pair_free(&self, k: usize, a: usize, b: usize) -> bool {
        match (&self.balls[a], &self.balls[b], self.pairs[k]) {
            (Some(ka), Some(kb), Some((ga, gb, free))) => {
                free && self.inside[a]
                    && self.inside[b]
                    && (ga, gb) == (ka.generation, kb.generation)
            }
            _ => false,
        }
    }
}

impl ProtectiveChecker {
    /// Whether the kept proofs cover every pair that can meet (of the pairs involving `only`,
    /// or of all), as of the last [`Kept::set_inside`] of each robot.
    pub(super) fn kept_free(&self, only: Option<usize>) -> bool {
        let pairs = &self.exact.verdict().pairs;
        pairs
            .iter()
            .enumerate()
            .filter(|(_, p)| only.is_none_or(|j| p.a == j || p.b == j))
            .all(|(k, p)| self.kept.pair_free(k, p.a, p.b))
    }

    /// After the references of this tick are set (`centres`, `reach`, `ref_boxes`): gives
    /// every robot outside its kept ball a wider one, proves the pairs not yet proved for
    /// their balls, and returns whether all pairs now are (module doc). `false` at once
    /// while backing off.
    pub(super) fn keep_and_prove(&mut self) -> bool {
        if self.kept.backoff > 0 {
            self.kept.backoff -= 1;
            return false;
        }
        for j in 0..self.kept.balls.len() {
            if !self.kept.inside[j] {
                self.keep_wider(j);
            }
        }
        let extra = self.model.warn_mm;
        let pairs = &self.exact.verdict().pairs;
        for (k, p) in pairs.iter().enumerate() {
            let (Some(ka), Some(kb)) = (&self.kept.balls[p.a], &self.kept.balls[p.b]) else {
                continue;
            };
            if self.kept.pairs[k]
                .is_some_and(|(ga, gb, _)| (ga, gb) == (ka.generation, kb.generation))
            {
                continue;
            }
            let free =
                first_unproved_between(&ka.ball, &kb.ball, extra, &self.pairs[k].axis).is_none();
            self.kept.pairs[k] = Some((ka.generation, kb.generation, free));
        }
        let free = self.kept_free(None);
        if !free {
            self.kept.backoff = KEPT_BACKOFF;
        }
        free
    }

    /// After the full proof (or a clearance table's lookup) proved every pair FREE with the
    /// sweeps of the table's tier about each robot's reference: keeps those balls (of every robot
    /// that has sweeps: every robot of a pair that can meet) and marks every pair proved for them.
    pub(super) fn keep_references(&mut self) {
        for j in 0..self.kept.balls.len() {
            if self.robots[j].tier == Some((0, 0)) {
                self.keep(j, self.robots[j].reference);
            }
        }
        let balls = &self.kept.balls;
        let pairs = &self.exact.verdict().pairs;
        for (slot, p) in self.kept.pairs.iter_mut().zip(pairs) {
            *slot = balls[p.a]
                .as_ref()
                .zip(balls[p.b].as_ref())
                .map(|(a, b)| (a.generation, b.generation, true));
        }
    }

    /// A wider kept ball for robot `j` (module doc): its stop ball widened, and moved ahead
    /// along the measured velocity by half the widening (so it still holds this tick's ball,
    /// and the balls of the ticks that follow at that velocity for twice as long as a ball
    /// around this tick's centre would), with its own boxes; around the reference centre when
    /// the robot stands or the centre ahead is unreachable.
    fn keep_wider(&mut self, j: usize) {
        let robot = &self.exact.cell().robots[j];
        let reference = &self.robots[j].reference;
        let radius = reference.radius * (1.0 + KEPT_WIDEN) + KEPT_MARGIN_MM;
        let rot = self.exact.rotation(j);
        let mut ball = SweptBall { radius, ..*reference };
        let ahead = self.robots[j].velocity.try_normalize(0.0);
        let ahead = ahead.map(|u| reference.centre + u * (0.5 * (radius - reference.radius)));
        match ahead {
            Some(c) if self.exact.boxes_in_wcs(j, &c, &mut ball.boxes).is_ok() => ball.centre = c,
            _ => ball.boxes = reference.boxes,
        }
        ball.sweeps = stop_sweeps_wcs(
            &robot.model,
            rot,
            &ball.centre,
            radius,
            self.model.tables[j].as_deref(),
        );
        ball.faces = [[self.model.no_faces; MAX_BOXES]; 2];
        ball.set_faces();
        ball.graded = graded_radii(&robot.model, radius);
        self.keep(j, ball);
    }

    /// Keeps `ball` for robot `j` under a new generation.
    fn keep(&mut self, j: usize, ball: SweptBall) {
        let generation = self.kept.next_generation;
        self.kept.next_generation += 1;
        self.kept.balls[j] = Some(KeptBall { ball, generation });
        self.kept.inside[j] = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::protective::ProtectiveChecker;
    use crate::cell::reference::reference_cell;
    use crate::cell::trajectory::{parse_scenarios, RUN_TICKS};
    use crate::cell::ExactChecker;
    use crate::robot::StopModel;

    /// Every kept ball holds its boxes at its own centre (the exact query's boxes there, its
    /// own inverse kinematics and placement), and the stop ball of the tick that kept it; and
    /// balls moved ahead of the reference are kept on the practical runs.
    #[test]
    fn kept_balls_hold_their_own_boxes_and_the_stop() {
        let text = include_str!("../../../c_harness/scenarios.txt");
        for s in parse_scenarios(text).unwrap().iter().filter(|s| s.case == "practical") {
            let cell = reference_cell(&s.cell)
                .unwrap()
                .with_stopping(1.0, alloc::vec![StopModel::DEFAULT; 2])
                .unwrap();
            let mut c =
                ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
            let mut exact = ExactChecker::new(cell);
            let (mut tcps, mut moved, mut last) = ([Vec3::zeros(); 2], 0, [None; 2]);
            for tick in 0..RUN_TICKS {
                s.tcps_at(tick, &mut tcps);
                c.check(&tcps).unwrap();
                for j in 0..2 {
                    let Some(k) = &c.kept.balls[j] else { continue };
                    if last[j] == Some(k.generation) {
                        continue;
                    }
                    last[j] = Some(k.generation);
                    let mut at = tcps;
                    at[j] = k.ball.centre;
                    exact.place_boxes(&at).unwrap();
                    for (x, y) in k.ball.boxes.as_slice().iter().zip(exact.boxes(j).as_slice()) {
                        let close =
                            (x.center - y.center).norm() < 1e-9 && (x.axes - y.axes).norm() < 1e-12;
                        assert!(
                            close && x.half == y.half,
                            "{} tick {tick} robot {j}: {x:?} {y:?}",
                            s.cell
                        );
                    }
                    let (_, (centre, radius)) = c.robots[j].stop_ball;
                    let inside =
                        (centre - k.ball.centre).norm() + radius <= k.ball.radius * (1.0 + 1e-12);
                    let (sc, ss) = (tcps[j], c.robots[j].stop_ball.0);
                    assert!(
                        inside || (sc - k.ball.centre).norm() + ss <= k.ball.radius * (1.0 + 1e-12),
                        "{} tick {tick}",
                        s.cell
                    );
                    moved += usize::from(k.ball.centre != c.robots[j].reference.centre);
                }
            }
            assert!(moved > 50, "{}: {moved} balls kept ahead", s.cell);
        }
    }
}
