//! The protective verdict (SPEC §8): can both robots still stop, from this tick on, without
//! any box of one touching any box of the other? FREE only when that is proved.
//!
//! # The bound
//! 1. **Speed now.** The controller gives TCPs, not speeds. With `v_fd = |p - p_prev| / T`
//!    (`T = tick_ms`) the average velocity over the last tick, the true speed now differs from
//!    `|v_fd|` by at most `a_max T` (`|v(t) - v(s)| <= a_max |t - s|` for `s` in the tick), so
//!    `v <= v_b := min(|v_fd| + a_max T, v_max)`. Without a previous TCP (first tick, after
//!    any error) `v_b = v_max`. A step longer than `v_max T`, or a change of `v_fd` between
//!    two ticks larger than `a_max T` (two consecutive averages differ by at most that), is
//!    impossible under the model: [`ProtectiveStatus::ImplausibleMotion`], STOP.
//! 2. **Latency of the verdict itself.** A FREE at tick `k` must cover a STOP issued at tick
//!    `k + 1`: the robot then moves one more tick before its reaction starts. The reaction
//!    time used is therefore `T_r = reaction_ms + tick_ms`.
//! 3. **Where the TCP can be.** Along its path the TCP travels at most
//!    `min(v_b T_r + a_max T_r^2 / 2, v_max T_r)` while reacting, then, braking from
//!    `v_r = min(v_b + a_max T_r, v_max)` at `>= decel`, at most `v_r^2 / (2 decel)`: in all
//!    `S` ([`StopModel::stopping_distance`]). The path is unknown, so every TCP of the whole
//!    stop lies in the ball of radius `S` around the TCP now, hence in the cube of half-side
//!    `S` around it (and in the robot's reachable space). With a measured velocity `v_fd`
//!    the direction is known during the reaction: the TCP is within `a_max T t + a_max t^2/2`
//!    of `p + v_fd t`, so the whole stop lies in the capsule around `p .. p + v_fd T_r` of
//!    radius `S - |v_fd| T_r`, and in the ball around its middle of radius
//!    `S - |v_fd| T_r / 2` ([`capsule_ball`]); that ball is used, with the boxes built at its
//!    centre, when the centre is reachable.
//! 4. **Where the boxes can be.** [`cube_box_sweeps`] bounds, per box, the displacement of
//!    every box point for every reachable TCP of that cube, measured from its centre (interval
//!    inverse kinematics: elbows may swing far more than the TCP moves, SPEC §8); the
//!    displacement set is a [`Sweep`] (MCS, rotated to the WCS with the robot's placement).
//!    Its TCP term (the cube of half-side `S`, weighted `e_k`) may equally be replaced by the
//!    ball of radius `S` that holds the TCP (weight `max e_k`): two sound forms of one bound
//!    ([`SweepForms`]); a box pair is proved apart when any combination of forms proves it
//!    (the cube is tighter where the separating axis is a world axis, the ball elsewhere).
//! 5. **Apart.** Box `i` of robot `a` over the stop lies in `box_i(now) + sweep_i`, and
//!    likewise for `b`; [`swept_boxes_apart`] proves the two sums disjoint on one of the 15
//!    axes (with a positive gap). All box pairs of all pairs that can meet proved: FREE.
//!    Proved again with `warn_mm` added to one sweep's ball: else WARN. Any unproved pair,
//!    unreachable TCP, unbounded sweep or status other than OK: STOP.
//!
//! The **speed limit** of a robot is the largest measured speed `|v_fd|` in `[0, v_max]` at
//! which every pair involving it is still proved, the other robots as they are: bisection
//! (at most [`LIMIT_STEPS`] + 2 evaluations) that keeps the last speed proved. 0 when not
//! even standing still is proved; `v_max` when full speed is.
//!
//! Nothing here allocates after [`ProtectiveChecker::new`].

use crate::cell::exact::PairVerdict;
use crate::cell::{Cell, CellError, ExactChecker, QueryError};
use crate::cspace::guarantee::cube_box_sweeps;
use crate::geometry::distance::obb_distance;
use crate::robot::MAX_BOXES;
use crate::geometry::{swept_boxes_apart, Obb, Sweep};
use crate::math::{Real, Vec3};
use crate::robot::{RobotBoxes, RobotModel, StopModel};

/// Sub-boxes per axis when enclosing the motor angles over the stopping cube (`SPLITS^3` per
/// arm). The cubes here are tens to hundreds of mm, where finer splits shrink the sweeps by
/// about 1 % for 7 times the time (2: about 11 us per robot, 4: 74 us); a tick evaluates up
/// to `2 + LIMIT_STEPS + 1` sweep sets per robot.
pub const SPLITS: u32 = 2;

/// The WARN threshold of the C ABI until `dc_set_stop_model` sets one (mm): the 10 mm by which
/// the practical scenarios clear the robots (SPEC §5).
pub const DEFAULT_WARN_MM: Real = 10.0;

/// Bisection steps of a speed limit (after the checks at 0 and at `v_max`).
pub const LIMIT_STEPS: u32 = 8;

/// Relative and absolute slack of the plausibility checks: rounding of the caller's own
/// trajectory arithmetic must not read as an impossible motion.
const PLAUSIBLE_SLACK: Real = 1e-9;

/// The protective verdict of one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Protective {
    /// Proved: a stop started now ends with every box apart.
    Free,
    /// Proved, but with less than `warn_mm` to spare.
    Warn,
    /// Not proved (or a status other than OK): stop now.
    Stop,
}

/// Why a tick has no proof to offer at all (the verdict is then STOP).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProtectiveStatus {
    /// The inputs were usable.
    Ok,
    /// Robot `.0`'s TCP (or given speed) is NaN or infinite.
    NonFinite(usize),
    /// Robot `.0`'s TCP moved further, or changed its velocity more, in one tick than its
    /// stopping model allows.
    ImplausibleMotion(usize),
    /// Robot `.0`'s TCP is outside its reach or motor limits.
    Unreachable(usize),
}

/// Box `box_a` of robot `a` and box `box_b` of robot `b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoxPair {
    /// First robot (`a < b`).
    pub a: usize,
    /// Second robot.
    pub b: usize,
    /// Box of `a` ([`RobotModel::boxes`] order).
    pub box_a: usize,
    /// Box of `b`.
    pub box_b: usize,
}

/// What the verdict assumed and found for one robot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotProtection {
    /// The measured speed `|v_fd|` (mm/s); `INFINITY` when there was no previous TCP.
    pub speed_mm_s: Real,
    /// The speed bound used, `v_b` (mm/s).
    pub speed_bound_mm_s: Real,
    /// `S`: how far the TCP may travel until it stands still (mm).
    pub protective_mm: Real,
    /// The largest measured speed at which FREE would still hold (mm/s; module doc); NaN when
    /// not computed ([`ProtectiveChecker::with_speed_limits`]).
    pub speed_limit_mm_s: Real,
}

impl RobotProtection {
    const UNKNOWN: RobotProtection = RobotProtection {
        speed_mm_s: Real::INFINITY,
        speed_bound_mm_s: 0.0,
        protective_mm: 0.0,
        speed_limit_mm_s: 0.0,
    };
}

/// The result of one protective check.
#[derive(Clone, Debug, PartialEq)]
pub struct ProtectiveReport {
    /// FREE, WARN or STOP.
    pub verdict: Protective,
    /// OK, or why there is no proof.
    pub status: ProtectiveStatus,
    /// The clearance of the cell now (mm, SPEC §8; 0 when boxes touch or intersect,
    /// `INFINITY` when no pair can meet, NaN when not computed).
    pub clearance_mm: Real,
    /// The box pair of the smallest clearance now.
    pub closest: Option<BoxPair>,
    /// The first box pair not proved apart (STOP) or not with `warn_mm` to spare (WARN).
    pub limiting: Option<BoxPair>,
    /// One entry per robot.
    pub robots: alloc::vec::Vec<RobotProtection>,
}

#[derive(Clone, Copy, Debug)]
struct History {
    tcp: Option<Vec3>,
    /// The last finite-difference velocity (mm/s).
    velocity: Option<Vec3>,
}

const NO_HISTORY: History = History { tcp: None, velocity: None };

/// The protective check of one cell; keeps each robot's previous TCP between ticks.
#[derive(Clone, Debug)]
pub struct ProtectiveChecker {
    exact: ExactChecker,
    warn_mm: Real,
    history: alloc::vec::Vec<History>,
    /// Per robot, the WCS displacement sets of its boxes over the stop.
    sweeps: alloc::vec::Vec<SweepForms>,
    /// Per robot, the measured velocity of this tick (MCS, mm/s; zero when unknown).
    velocity: alloc::vec::Vec<Vec3>,
    /// Per robot, its boxes (WCS) at the reference TCP its sweeps are measured from.
    ref_boxes: alloc::vec::Vec<RobotBoxes>,
    /// Whether each tick also finds the speed limits (most of its time).
    speed_limits: bool,
    report: ProtectiveReport,
}

impl ProtectiveChecker {
    /// A checker for `cell` (its `tick_ms` and stopping models) that warns with less than
    /// `warn_mm` to spare.
    ///
    /// # Errors
    /// [`CellError::Invalid`] when `warn_mm` is NaN, infinite or negative.
    pub fn new(cell: Cell, warn_mm: Real) -> Result<Self, CellError> {
        if !(warn_mm.is_finite() && warn_mm >= 0.0) {
            return Err(CellError::Invalid(alloc::format!("warn_mm = {warn_mm} must be finite and >= 0")));
        }
        let n = cell.robots.len();
        Ok(ProtectiveChecker {
            exact: ExactChecker::new(cell),
            warn_mm,
            history: alloc::vec![NO_HISTORY; n],
            sweeps: alloc::vec![[[Sweep::ZERO; MAX_BOXES]; 2]; n],
            velocity: alloc::vec![Vec3::zeros(); n],
            ref_boxes: alloc::vec![RobotBoxes::empty(); n],
            speed_limits: true,
            report: ProtectiveReport {
                verdict: Protective::Stop,
                status: ProtectiveStatus::Ok,
                clearance_mm: Real::NAN,
                closest: None,
                limiting: None,
                robots: alloc::vec![RobotProtection::UNKNOWN; n],
            },
        })
    }

    /// The cell being checked.
    pub fn cell(&self) -> &Cell {
        self.exact.cell()
    }

    /// This checker finding the speed limits on every tick (the default), or not: the verdict
    /// alone takes under a third of the time (`benches/protective.rs`), and the limits then
    /// read NaN.
    pub fn with_speed_limits(self, on: bool) -> Self {
        ProtectiveChecker { speed_limits: on, ..self }
    }

    /// The WARN threshold (mm).
    pub fn warn_mm(&self) -> Real {
        self.warn_mm
    }

    /// The exact checker underneath (its boxes are those of the last check).
    pub fn exact(&self) -> &ExactChecker {
        &self.exact
    }

    /// The report of the last check.
    pub fn report(&self) -> &ProtectiveReport {
        &self.report
    }

    /// Forgets every previous TCP: the next tick assumes full speed (module doc, step 1).
    pub fn reset(&mut self) {
        self.history.fill(NO_HISTORY);
    }

    /// One tick: `tcps_mcs[j]` is robot `j`'s TCP now, in its own MCS; the speeds come from
    /// the TCPs of the previous call (module doc).
    ///
    /// # Errors
    /// [`QueryError::WrongRobotCount`] (the history is then left as it was).
    pub fn check(&mut self, tcps_mcs: &[Vec3]) -> Result<&ProtectiveReport, QueryError> {
        let n = self.cell().robots.len();
        if tcps_mcs.len() != n {
            return Err(QueryError::WrongRobotCount { expected: n, found: tcps_mcs.len() });
        }
        let tick_s = self.cell().tick_ms * 1e-3;
        let mut status = ProtectiveStatus::Ok;
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            let stop = self.exact.cell().stops[j];
            let slot = &mut self.report.robots[j];
            *slot = RobotProtection::UNKNOWN;
            self.velocity[j] = Vec3::zeros();
            if !tcp.iter().all(|v| v.is_finite()) {
                status = worse(status, ProtectiveStatus::NonFinite(j));
                continue;
            }
            let Some(prev) = self.history[j].tcp else { continue };
            let velocity = (tcp - prev) / tick_s;
            let plausible = |x: Real, limit: Real| x <= limit * (1.0 + PLAUSIBLE_SLACK) + PLAUSIBLE_SLACK;
            let accel_ok = self.history[j]
                .velocity
                .is_none_or(|v| plausible((velocity - v).norm(), stop.max_accel_mm_s2 * tick_s));
            if !plausible(velocity.norm(), stop.max_speed_mm_s) || !accel_ok {
                status = worse(status, ProtectiveStatus::ImplausibleMotion(j));
            }
            slot.speed_mm_s = velocity.norm();
            self.velocity[j] = velocity;
            self.history[j].velocity = Some(velocity);
        }
        self.evaluate(tcps_mcs, status);
        // Only a tick without error (unreachable included) becomes the next one's history.
        if self.report.status == ProtectiveStatus::Ok {
            for (h, tcp) in self.history.iter_mut().zip(tcps_mcs) {
                h.tcp = Some(*tcp);
            }
        } else {
            self.reset();
        }
        Ok(&self.report)
    }

    /// The verdict for TCPs `tcps_mcs` moving at measured speeds `speeds_mm_s` (`INFINITY`:
    /// unknown, full speed), without reading or changing the history: for a controller that
    /// knows its speeds, and to check a reported speed limit.
    ///
    /// # Errors
    /// [`QueryError::WrongRobotCount`] when either slice's length differs from the robot count.
    pub fn check_at_speeds(
        &mut self,
        tcps_mcs: &[Vec3],
        speeds_mm_s: &[Real],
    ) -> Result<&ProtectiveReport, QueryError> {
        let n = self.cell().robots.len();
        for len in [tcps_mcs.len(), speeds_mm_s.len()] {
            if len != n {
                return Err(QueryError::WrongRobotCount { expected: n, found: len });
            }
        }
        let mut status = ProtectiveStatus::Ok;
        for (j, (tcp, &v)) in tcps_mcs.iter().zip(speeds_mm_s).enumerate() {
            self.report.robots[j] = RobotProtection { speed_mm_s: v, ..RobotProtection::UNKNOWN };
            self.velocity[j] = Vec3::zeros();
            if !tcp.iter().all(|x| x.is_finite()) || v.is_nan() || v < 0.0 {
                status = worse(status, ProtectiveStatus::NonFinite(j));
            }
        }
        self.evaluate(tcps_mcs, status);
        Ok(&self.report)
    }

    /// Fills the report from the TCPs and the measured speeds already in `report.robots`.
    fn evaluate(&mut self, tcps_mcs: &[Vec3], status: ProtectiveStatus) {
        let report = &mut self.report;
        (report.verdict, report.status, report.clearance_mm) = (Protective::Stop, status, Real::NAN);
        (report.closest, report.limiting) = (None, None);
        if status != ProtectiveStatus::Ok {
            return;
        }
        let Ok(exact) = self.exact.check(tcps_mcs) else { return };
        if let Some((j, _)) = exact.first_unreachable {
            self.report.status = ProtectiveStatus::Unreachable(j);
            return;
        }
        let (clearance, closest) = clearance_now(&self.exact);
        (self.report.clearance_mm, self.report.closest) = (clearance, closest);
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            let v = self.report.robots[j].speed_mm_s;
            let s = self.stop_sweeps(j, tcp, v);
            let bound = self.speed_bound(j, v);
            let r = &mut self.report.robots[j];
            (r.speed_bound_mm_s, r.protective_mm) = (bound, s);
        }
        let pairs = &self.exact.verdict().pairs;
        let boxes = |j: usize| self.ref_boxes[j].as_slice();
        self.report.limiting = first_unproved(pairs, &boxes, &self.sweeps, None, 0.0);
        self.report.verdict = if self.report.limiting.is_some() {
            Protective::Stop
        } else if self.warn_mm > 0.0 {
            self.report.limiting = first_unproved(pairs, &boxes, &self.sweeps, None, self.warn_mm);
            if self.report.limiting.is_some() {
                Protective::Warn
            } else {
                Protective::Free
            }
        } else {
            Protective::Free
        };
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            self.report.robots[j].speed_limit_mm_s =
                if self.speed_limits { self.speed_limit(j, tcp) } else { Real::NAN };
        }
    }

    /// `v_b` of robot `j` for measured speed `v` (module doc, step 1).
    fn speed_bound(&self, j: usize, v: Real) -> Real {
        let stop = &self.cell().stops[j];
        let bound = v + stop.max_accel_mm_s2 * self.cell().tick_ms * 1e-3;
        if bound.is_finite() {
            bound.min(stop.max_speed_mm_s)
        } else {
            stop.max_speed_mm_s
        }
    }

    /// Sets robot `j`'s reference boxes and sweeps for TCP `tcp_mcs` at measured speed `v`
    /// (along the measured velocity's direction, when known); returns `S`.
    fn stop_sweeps(&mut self, j: usize, tcp_mcs: &Vec3, v: Real) -> Real {
        let cell = self.exact.cell();
        let stop = cell.stops[j];
        let reaction_s = (stop.reaction_ms + cell.tick_ms) * 1e-3;
        let s = stop.stopping_distance(self.speed_bound(j, v), reaction_s);
        let (centre, radius) = capsule_ball(&stop, cell.tick_ms * 1e-3, reaction_s, tcp_mcs, &self.velocity[j], v, s);
        let robot = &cell.robots[j];
        let (rot, t) = (robot.placement.rotation(), robot.placement.t);
        let (centre, radius) = match robot.model.boxes_into(&centre, &mut self.ref_boxes[j]) {
            Ok(()) if centre != *tcp_mcs => (centre, radius),
            _ => {
                self.ref_boxes[j] = *self.exact.boxes(j);
                (*tcp_mcs, s)
            }
        };
        if centre != *tcp_mcs {
            let boxes = &mut self.ref_boxes[j];
            for b in &mut boxes.boxes[..boxes.len] {
                *b = b.transformed(&rot, &t);
            }
        }
        self.sweeps[j] = stop_sweeps_wcs(&robot.model, &rot, &centre, radius);
        s
    }

    /// Robot `j`'s speed limit (module doc), the other robots' sweeps as they are.
    fn speed_limit(&mut self, j: usize, tcp_mcs: &Vec3) -> Real {
        let saved = (self.sweeps[j], self.ref_boxes[j]);
        let proved = |me: &mut Self, v: Real| {
            me.stop_sweeps(j, tcp_mcs, v);
            let boxes = |i: usize| me.ref_boxes[i].as_slice();
            first_unproved(&me.exact.verdict().pairs, &boxes, &me.sweeps, Some(j), 0.0).is_none()
        };
        let vmax = self.cell().stops[j].max_speed_mm_s;
        let limit = if proved(self, vmax) {
            vmax
        } else if !proved(self, 0.0) {
            0.0
        } else {
            let (mut lo, mut hi) = (0.0, vmax);
            for _ in 0..LIMIT_STEPS {
                let mid = 0.5 * (lo + hi);
                if proved(self, mid) {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            lo
        };
        (self.sweeps[j], self.ref_boxes[j]) = saved;
        limit
    }
}

/// A ball holding every TCP of the stop when the measured velocity `velocity` is known
/// (module doc, step 3, direction-aware): while reacting the TCP is within
/// `a_max T t + a_max t^2 / 2` of `p + v_fd t` (`v_fd` scaled to speed `v`), then travels at
/// most `L_b` more; all of it lies in the capsule around the segment from `p` to
/// `p + v_fd T_r` of radius `R = a_max T T_r + a_max T_r^2 / 2 + L_b`, and so in the ball
/// around the segment's middle of radius `R + v T_r / 2`. Returns that ball when it is
/// smaller than the ball of radius `s` around `p`, else `(p, s)`.
fn capsule_ball(
    stop: &StopModel,
    tick_s: Real,
    reaction_s: Real,
    p: &Vec3,
    velocity: &Vec3,
    v: Real,
    s: Real,
) -> (Vec3, Real) {
    let norm = velocity.norm();
    if !(norm > 0.0 && v.is_finite()) {
        return (*p, s);
    }
    let (a, vmax, t) = (stop.max_accel_mm_s2, stop.max_speed_mm_s, reaction_s);
    let delta = a * tick_s;
    let v_r = (v + delta + a * t).min(vmax);
    let r = delta * t + 0.5 * a * t * t + v_r * v_r / (2.0 * stop.decel_mm_s2);
    let radius = r + 0.5 * v * t;
    if radius < s {
        (p + velocity * (v / norm * 0.5 * t), radius)
    } else {
        (*p, s)
    }
}

/// The status that wins when several robots fail: non-finite, then implausible, then
/// unreachable; the lowest robot index first within one kind.
fn worse(a: ProtectiveStatus, b: ProtectiveStatus) -> ProtectiveStatus {
    let rank = |s: &ProtectiveStatus| match s {
        ProtectiveStatus::Ok => 0,
        ProtectiveStatus::Unreachable(_) => 1,
        ProtectiveStatus::ImplausibleMotion(_) => 2,
        ProtectiveStatus::NonFinite(_) => 3,
    };
    if rank(&b) > rank(&a) {
        b
    } else {
        a
    }
}

/// The WCS displacement sets of the boxes of a robot at `tcp_mcs` when its TCP may go
/// anywhere within `s` of it (module doc, steps 3-4); infinite balls when unbounded.
pub fn stop_sweeps_wcs(model: &RobotModel, rot_wcs: &crate::math::Mat3, tcp_mcs: &Vec3, s: Real) -> SweepForms {
    match cube_box_sweeps(model, tcp_mcs, s, tcp_mcs, SPLITS) {
        Some(sweeps) => {
            // The TCP's own displacement lies in the ball of radius `s` (widened as the cube
            // is in `cube_box_sweeps`), so its cube term may be traded for that ball.
            let reach = s * (1.0 + 1e-12) + 1e-12;
            let ball_form = |w: &Sweep| {
                let [(e1, d1), (e2, d2)] = w.ends;
                Sweep {
                    cube: [Vec3::zeros(); 3],
                    ends: [(0.0, d1), (0.0, d2)],
                    ball: w.ball + e1.max(e2) * reach,
                    ..*w
                }
            };
            [sweeps.map(|w| w.rotated(rot_wcs)), sweeps.map(|w| ball_form(&w).rotated(rot_wcs))]
        }
        None => [[Sweep { ball: Real::INFINITY, ..Sweep::ZERO }; MAX_BOXES]; 2],
    }
}

/// Two forms of the same bound on each box's displacements (module doc, step 4): `[0]` with
/// the TCP's motion as a cube, `[1]` as a ball; either alone is sound.
pub type SweepForms = [[Sweep; MAX_BOXES]; 2];

/// The first box pair (of the pairs involving `only`, or of all pairs) not proved apart
/// with `extra` mm added to the first robot's sweep.
fn first_unproved<'a>(
    pairs: &[PairVerdict],
    boxes: &impl Fn(usize) -> &'a [Obb],
    sweeps: &[SweepForms],
    only: Option<usize>,
    extra: Real,
) -> Option<BoxPair> {
    const FORMS: [(usize, usize); 4] = [(0, 0), (1, 1), (0, 1), (1, 0)];
    for p in pairs.iter().filter(|p| only.is_none_or(|j| p.a == j || p.b == j)) {
        for (i, box_a) in boxes(p.a).iter().enumerate() {
            for (k, box_b) in boxes(p.b).iter().enumerate() {
                let apart = |&(fa, fb): &(usize, usize)| {
                    let sa = &sweeps[p.a][fa][i];
                    let sa = Sweep { ball: sa.ball + extra, ..*sa };
                    swept_boxes_apart(box_a, &sa, box_b, &sweeps[p.b][fb][k])
                };
                if !FORMS.iter().any(apart) {
                    return Some(BoxPair { a: p.a, b: p.b, box_a: i, box_b: k });
                }
            }
        }
    }
    None
}

/// The clearance of the cell as of the exact checker's last check and its closest box pair:
/// the one place that computes it (mm; 0 when boxes touch or intersect).
pub fn clearance_now(exact: &ExactChecker) -> (Real, Option<BoxPair>) {
    let mut best = (Real::INFINITY, None);
    for p in &exact.verdict().pairs {
        for (i, box_a) in exact.boxes(p.a).as_slice().iter().enumerate() {
            for (k, box_b) in exact.boxes(p.b).as_slice().iter().enumerate() {
                let d = obb_distance(box_a, box_b);
                // A NaN distance (a non-finite box) wins, so it shows in the report.
                if d.is_nan() || d < best.0 {
                    best = (d, Some(BoxPair { a: p.a, b: p.b, box_a: i, box_b: k }));
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;

    fn checker(name: &str) -> ProtectiveChecker {
        ProtectiveChecker::new(reference_cell(name).unwrap(), 10.0).unwrap()
    }

    #[test]
    fn far_apart_and_still_is_free_and_close_at_speed_is_stop() {
        let mut c = checker("T1");
        let (a, b) = (Vec3::new(-150.0, 0.0, -450.0), Vec3::new(150.0, 0.0, -450.0));
        // First tick: full speed assumed.
        let r = c.check(&[a, b]).unwrap().clone();
        assert_eq!(r.status, ProtectiveStatus::Ok);
        assert_eq!(r.robots[0].speed_bound_mm_s, 4_600.0);
        // Standing still: the bound is the reaction only.
        let r = c.check(&[a, b]).unwrap().clone();
        assert_eq!(r.verdict, Protective::Free, "{r:?}");
        assert!(r.clearance_mm > 100.0);
        assert!(r.robots.iter().all(|x| x.speed_limit_mm_s > 0.0));
        let close = [Vec3::new(60.0, 30.0, -420.0), Vec3::new(-60.0, -30.0, -430.0)];
        let r = c.check_at_speeds(&close, &[4_000.0, 4_000.0]).unwrap();
        assert_eq!(r.verdict, Protective::Stop);
    }

    #[test]
    fn jumps_and_unreachable_tcps_are_statuses_with_stop() {
        let mut c = checker("T1");
        let (a, b) = (Vec3::new(-150.0, 0.0, -450.0), Vec3::new(150.0, 0.0, -450.0));
        c.check(&[a, b]).unwrap();
        let r = c.check(&[a + Vec3::new(10.0, 0.0, 0.0), b]).unwrap();
        assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::ImplausibleMotion(0)));
        let r = c.check(&[a, Vec3::new(0.0, 0.0, 100.0)]).unwrap();
        assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::Unreachable(1)));
        let r = c.check(&[a, Vec3::new(Real::NAN, 0.0, -450.0)]).unwrap();
        assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::NonFinite(1)));
    }
}
