//! Coordination (SPEC §9): each robot's speed override from the robots' programmes ahead, so
//! that a line keeps moving without the protective verdict having to stop it. The protective
//! verdict (`cell::protective`) stays the last layer with its proof unchanged: nothing here is
//! a proof, an override that the robots do not follow costs at most a STOP.
//!
//! # The rule and why it never deadlocks
//! 1. **Diagram.** For each robot pair that can meet, the coordination diagram of their
//!    programmes over the horizon (`diagram.rs`): a cell `(a, b)` is in conflict when the
//!    boxes at sample `a` of one and sample `b` of the other may come within `clearance_mm`.
//! 2. **Shadow.** Robot `i` *yielding* to `j` may advance only to samples whose whole column
//!    over `j`'s horizon is free: wherever `j` goes next, and at whatever speed (it may slow or
//!    stop without notice, as in Gregoire et al., arXiv 1306.0785), `i` standing there is
//!    apart from it. Its *hold point* is the first sample with a conflicting column; it must be
//!    able to stand before it: its stopping distance now (the stopping model's, one more tick
//!    for the override's own latency) plus `hold_margin_mm` within the arc length to the
//!    sample before. The column of a sample shrinks as `j` advances, so a sample once allowed
//!    stays allowed.
//! 3. **Right of way.** Per pair in conflict exactly one robot yields. A robot that cannot
//!    stand before its hold point any more (it stands in the other's shadow, or is too fast to
//!    stop short of it) cannot yield: the other does. A robot standing still, or moving along
//!    its path away from the other (no conflict ahead of it but where it is), is therefore
//!    never held. Otherwise the robot that reaches its hold point first at its programmed
//!    speed has the right of way, and keeps it until the other would reach its own hold point
//!    `hysteresis_ticks` sooner (so a decision is not undone every tick); ties go to the lower
//!    index. The decision stands while the pair's windows hold a conflict.
//! 4. **No cycle.** In a line the decisions are made consistent with one ranking of the robots
//!    (`right_of_way.rs`: a topological order of the forced decisions, the others by
//!    urgency), so the robot ranked first yields to no one. With its programme unfinished it
//!    moves: some robot progresses at every tick, and no set of robots waits for each other.
//!    A robot yields only to robots that move or will move, except to one whose programme ends
//!    in its way, which no rule can resolve.
//! 5. **Override.** A robot that yields gets the largest factor whose speed still lets it
//!    stand before its hold point (bisection of the stopping distance); every factor is ramped
//!    within shares of the stopping model's `max_accel_mm_s2` (SPEC §9).
//! 6. **Stalls.** Steps 2-4 decide within the horizon. A programme revealed later can come
//!    back through where a robot waits while that robot's way is blocked by the other: each
//!    waits for the other (measured by `delta-collide simulate`). When every robot with
//!    somewhere to go has stood held for [`STALL_TICKS`], one is released in turn for
//!    [`RELEASE_TICKS`]; the protective verdict decides whether it may move.
//!
//! # Programmed order
//! When the programmes' ticks are one clock of the line ([`RightOfWay::Programmed`]: a
//! planner timed the robots together), steps 2-4 are replaced by one rule, the order in
//! which the programme passes each conflict (the action dependency graph of Hoenig et al.,
//! "Persistent and robust execution of MAPF schedules in warehouses", RA-L 2019, over the
//! diagram's samples). Sample `s` of robot `i`, programmed at tick `t_s`, is *forbidden*
//! while another robot `j` has not left a sample `u` in conflict with it that `j` is
//! programmed to pass at least `L` sooner (`t_u + L <= t_s`, `L` =
//! [`CoordinationConfig::order_slack_ticks`], at least the two strides together), or one
//! where `j` can be until it stands; so is every sample so late that such `u` may lie beyond
//! `j`'s horizon. Robot `i`'s hold point is its first forbidden sample ahead, and step 5 sets
//! its override from it, in progress too: it comes no nearer than [`HOLD_SLACK_TICKS`] to
//! the tick `t_s - stride_i` of the sample before. A robot is never held for a sample the
//! other is programmed to pass later (unless the other can be there before it stands), so
//! robots that keep to a timing that keeps them apart are not held, and:
//!
//! *No deadlock.* A robot has left sample `u` once its progress is within that slack of the
//! next sample. Say every unfinished robot stands at its hold, and `i` waits for `j` at `u`
//! for its sample `s`: `j` has not left `u`, so its progress `p_j < t_u + stride_j - slack
//! <= t_s - L + stride_j - slack <= t_s - stride_i - slack`, where `i` stands. Along every
//! chain of waits the progress falls, so no chain closes: the robot furthest behind is held
//! by no time rule (its [`RobotCoordination::rank`] is 0). The argument needs every robot
//! where the order lets it be: programmes ending in each other's way, a start, a STOP or an
//! override not followed can leave robots where each is in the other's way, and then step 6
//! releases them in turn; whether a released robot can move is the protective verdict's to
//! say (on dense cells it may not: docs/record/2026-12-02-programmed-order.md). Nor can the
//! order help programmes that meet as timed (both robots at one place point at once): it
//! keeps the robots near that timing, and the protective verdict stops them there.
//!
//! Nothing here allocates after [`Coordinator::new`]; each loop is bounded by
//! [`MAX_SAMPLES`] samples per robot and the cell's robot pairs.

pub mod diagram;
pub mod right_of_way;
pub mod speed;

use crate::cell::{Cell, ExactChecker};
use crate::math::{float, Real, Vec3};
use alloc::vec;
use alloc::vec::Vec;
pub use diagram::MAX_SAMPLES;
use diagram::{window, Diagram, Track};

/// One robot's programme ahead, as its controller has it (SPEC §9): set-points at the nominal
/// timing from `first_tick`, one every `stride_ticks` programme ticks, and how far along it
/// the robot is.
#[derive(Clone, Copy, Debug)]
pub struct Programme<'a> {
    /// The programme tick of `points[0]`, a multiple of `stride_ticks`.
    pub first_tick: u64,
    /// Programme ticks between two points (at least 1).
    pub stride_ticks: u32,
    /// The set-points (the robot's MCS, mm); the robot stands at the last one when its
    /// programme ends there. Only the first [`MAX_SAMPLES`] from the robot's progress count.
    pub points: &'a [Vec3],
    /// The robot's progress now, in programme ticks, from `first_tick` to the last point's.
    pub progress: Real,
    /// The override the robot followed over the last tick (0 when it stands).
    pub override_now: Real,
}

/// A call's inputs: one programme per robot.
#[derive(Clone, Copy, Debug)]
pub struct CoordinationRequest<'a> {
    /// Robot `j`'s programme ahead.
    pub programmes: &'a [Programme<'a>],
}

/// The coordination's settings (units in the names).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoordinationConfig {
    /// Two samples conflict when their boxes may come closer than this (mm): the room the
    /// protective verdict needs beyond contact to prove a stop of the moving robot apart.
    pub clearance_mm: Real,
    /// Room kept between a yielding robot's stop and its hold point (mm), in the arrival order
    /// (the programmed order stops short of its hold point in progress instead).
    pub hold_margin_mm: Real,
    /// How much sooner the other robot must reach its hold point to take the right of way
    /// (programme ticks).
    pub hysteresis_ticks: Real,
    /// Share of `max_accel_mm_s2` an override may add to the programme's speed per second.
    pub speed_up_share: Real,
    /// Share of `max_accel_mm_s2` an override may take from it per second.
    pub slow_down_share: Real,
    /// How the right of way of a conflict is decided.
    pub right_of_way: RightOfWay,
    /// Under [`RightOfWay::Programmed`], how much sooner (programme ticks) the other robot
    /// must be programmed at a conflicting sample to have the right of way there; at least
    /// the two robots' strides together (module doc, "Programmed order").
    pub order_slack_ticks: Real,
}

/// How the right of way of a conflict is decided (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RightOfWay {
    /// The robot that reaches its hold point first, for programmes each on a clock of its
    /// own (steps 2-4).
    Arrival,
    /// The robot programmed to be there first, for programmes whose ticks are one clock of
    /// the line (a planner that timed the robots together): step 3 of "Programmed order".
    Programmed,
}

impl Default for CoordinationConfig {
    fn default() -> Self {
        CoordinationConfig {
            clearance_mm: 40.0,
            hold_margin_mm: 2.0,
            hysteresis_ticks: 40.0,
            speed_up_share: 0.25,
            slow_down_share: 0.6,
            right_of_way: RightOfWay::Arrival,
            order_slack_ticks: 8.0,
        }
    }
}

/// Why a request cannot be coordinated (every robot's override is then 0).
#[derive(Clone, Debug, PartialEq)]
pub enum CoordinationError {
    /// Not one programme per robot.
    WrongRobotCount {
        /// Robots of the cell.
        expected: usize,
        /// Programmes given.
        found: usize,
    },
    /// Robot `robot`'s programme breaks its contract: `what` says how.
    InvalidProgramme {
        /// The robot.
        robot: usize,
        /// What is wrong.
        what: &'static str,
    },
}

impl core::fmt::Display for CoordinationError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CoordinationError::WrongRobotCount { expected, found } => {
                write!(f, "expected {expected} programmes (one per robot), found {found}")
            }
            CoordinationError::InvalidProgramme { robot, what } => {
                write!(f, "invalid programme of robot {robot}: {what}")
            }
        }
    }
}

/// What the coordination answers for one robot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotCoordination {
    /// The override to apply over the next tick, in [0, 1].
    pub override_factor: Real,
    /// The robot it yields to and whose conflict sets its hold point, if any.
    pub held_by: Option<usize>,
    /// Arc length from the TCP now to the hold point (mm); infinite when not held.
    pub hold_mm: Real,
    /// Its place in this tick's ranking (0: yields in no conflict; it may still stand short
    /// of where another robot can be until that one stands).
    pub rank: usize,
}

/// The result of one call.
#[derive(Clone, Debug, PartialEq)]
pub struct CoordinationReport {
    /// One entry per robot.
    pub robots: Vec<RobotCoordination>,
    /// Diagram cells tested by this call (the per-tick work).
    pub cells_tested: u64,
}

/// One robot's horizon this tick: where its samples start, how many, how far each is.
#[derive(Clone, Copy, Debug)]
struct Horizon {
    /// Absolute number of the sample at or just behind the progress.
    first: u64,
    /// Samples from `first` on (at most [`MAX_SAMPLES`]).
    count: usize,
    /// Arc length from the TCP now to each sample (mm; 0 for the one behind).
    arc_mm: [Real; MAX_SAMPLES],
    /// The largest programmed speed over the next samples (mm/s).
    speed_ahead_mm_s: Real,
    /// The speed now, the override followed times the programmed speed (mm/s).
    speed_now_mm_s: Real,
    /// Programme ticks between two samples.
    stride: Real,
    /// Programme ticks from the sample `first` to the progress.
    behind: Real,
    /// Samples from `first` on that the robot can reach before it stands, stopped now.
    reach: usize,
}

/// The largest programmed speed (mm/s) from the progress to sample `last` of horizon `h`,
/// over at most [`speed::SPEED_AHEAD_SAMPLES`] samples.
fn speed_until(h: &Horizon, last: usize, tick_s: Real) -> Real {
    let end = last.min(h.count - 1).min(speed::SPEED_AHEAD_SAMPLES);
    (0..end)
        .map(|k| {
            let ticks = if k == 0 { h.stride - h.behind } else { h.stride };
            (h.arc_mm[k + 1] - h.arc_mm[k]) / (ticks.max(HOLD_SLACK_TICKS) * tick_s)
        })
        .fold(0.0, Real::max)
}

/// What one robot pair's diagram gives this tick: each robot's hold point if it yields.
#[derive(Clone, Copy, Debug, Default)]
struct PairHolds {
    /// Whether the windows hold a conflict at all.
    conflict: bool,
    /// For robot `a`, then `b`: (arc length to its hold point, programme ticks to reach it).
    hold: [(Real, Real); 2],
    /// For robot `a`, then `b`: arc length to its first sample in conflict with where the
    /// other robot can be until it stands (its samples within its stopping distance).
    block: [Real; 2],
    /// For robot `a`, then `b`: arc length to where it may rest short of its block.
    harbour: [Real; 2],
}

/// The coordination of one cell: its model (the cell, the pairs, the settings) and its state
/// (the samples in the horizon, the diagrams, the decisions).
#[derive(Debug)]
pub struct Coordinator {
    exact: ExactChecker,
    config: CoordinationConfig,
    pairs: Vec<(usize, usize)>,
    tracks: Vec<Track>,
    diagrams: Vec<Diagram>,
    horizons: Vec<Horizon>,
    holds: Vec<PairHolds>,
    /// Per pair, the robot with the right of way while its conflict lasts.
    winners: Vec<Option<usize>>,
    /// Per robot, under the programmed order, the tick of the sample before its hold point.
    hold_ticks: Vec<Real>,
    ranking: right_of_way::Ranking,
    stall: Stall,
    report: CoordinationReport,
}

/// Ticks during which every robot with somewhere to go is held before one is released.
pub const STALL_TICKS: u32 = 100;

/// Ticks one released robot may move regardless of its holds.
pub const RELEASE_TICKS: u32 = 300;

/// Programme ticks a robot held under the programmed order stays short of the sample before
/// its hold point (a few micrometres at full speed).
const HOLD_SLACK_TICKS: Real = 1e-3;

/// An override (or a target) below this holds a robot.
const HELD: Real = 1e-6;

/// The breaking of a stall (module doc, step 6): how long every robot with somewhere to go
/// has been held, the robot released and for how many more ticks, whose turn is next.
#[derive(Clone, Copy, Debug, Default)]
struct Stall {
    ticks: u32,
    released: Option<(usize, u32)>,
    turn: usize,
}

impl Coordinator {
    /// The coordination of `cell` (its pairs that can meet) with `config`.
    pub fn new(cell: Cell, config: CoordinationConfig) -> Self {
        let n = cell.robots.len();
        let pairs = cell.pairs_that_can_meet();
        let horizon = Horizon {
            first: 0,
            count: 0,
            arc_mm: [0.0; MAX_SAMPLES],
            speed_ahead_mm_s: 0.0,
            speed_now_mm_s: 0.0,
            stride: 1.0,
            behind: 0.0,
            reach: 1,
        };
        let idle = RobotCoordination {
            override_factor: 0.0,
            held_by: None,
            hold_mm: Real::INFINITY,
            rank: 0,
        };
        Coordinator {
            exact: ExactChecker::new(cell),
            config,
            tracks: (0..n).map(|_| Track::default()).collect(),
            diagrams: vec![Diagram::default(); pairs.len()],
            horizons: vec![horizon; n],
            holds: vec![PairHolds::default(); pairs.len()],
            winners: vec![None; pairs.len()],
            hold_ticks: vec![Real::INFINITY; n],
            ranking: right_of_way::Ranking::new(n, pairs.len()),
            stall: Stall::default(),
            report: CoordinationReport { robots: vec![idle; n], cells_tested: 0 },
            pairs,
        }
    }

    /// The cell coordinated.
    pub fn cell(&self) -> &Cell {
        self.exact.cell()
    }

    /// The settings.
    pub fn config(&self) -> &CoordinationConfig {
        &self.config
    }

    /// The robot pairs coordinated (those that can meet).
    pub fn pairs(&self) -> &[(usize, usize)] {
        &self.pairs
    }

    /// The last report.
    pub fn report(&self) -> &CoordinationReport {
        &self.report
    }

    /// Forgets every decision and sample (a restart of the line); allocates nothing.
    pub fn reset(&mut self) {
        self.tracks.iter_mut().for_each(Track::clear);
        self.diagrams.iter_mut().for_each(|d| *d = Diagram::default());
        self.winners.iter_mut().for_each(|w| *w = None);
        self.ranking.reset();
        self.stall = Stall::default();
    }

    /// Each robot's override for the next tick (module doc): the chain `horizons`, `place`,
    /// `pair_holds`, `decide`, `overrides`.
    ///
    /// # Errors
    /// A wrong count of programmes, or one that breaks its contract ([`Programme`]): every
    /// override in the report is then 0 and the decisions are forgotten.
    pub fn coordinate(
        &mut self,
        request: &CoordinationRequest,
    ) -> Result<&CoordinationReport, CoordinationError> {
        let checked = self.horizons(request).and_then(|()| self.place(request));
        if let Err(e) = checked {
            self.winners.iter_mut().for_each(|w| *w = None);
            for r in &mut self.report.robots {
                *r = RobotCoordination {
                    override_factor: 0.0,
                    held_by: None,
                    hold_mm: 0.0,
                    rank: 0,
                };
            }
            return Err(e);
        }
        let before: u64 = self.diagrams.iter().map(|d| d.tests).sum();
        match self.config.right_of_way {
            RightOfWay::Arrival => {
                self.pair_holds();
                self.decide();
                self.holds_of_winners();
            }
            RightOfWay::Programmed => self.programmed_holds(request),
        }
        self.overrides(request);
        self.report.cells_tested = self.diagrams.iter().map(|d| d.tests).sum::<u64>() - before;
        Ok(&self.report)
    }

    /// Step 1: checks each programme and measures its horizon.
    fn horizons(&mut self, request: &CoordinationRequest) -> Result<(), CoordinationError> {
        let n = self.tracks.len();
        if request.programmes.len() != n {
            return Err(CoordinationError::WrongRobotCount {
                expected: n,
                found: request.programmes.len(),
            });
        }
        let tick_s = self.cell().tick_ms * 1e-3;
        for (j, p) in request.programmes.iter().enumerate() {
            let bad =
                |what: &'static str| Err(CoordinationError::InvalidProgramme { robot: j, what });
            if p.stride_ticks == 0 {
                return bad("stride_ticks is 0");
            }
            if p.first_tick % u64::from(p.stride_ticks) != 0 {
                return bad("first_tick is not a multiple of stride_ticks");
            }
            if p.points.is_empty() {
                return bad("no points");
            }
            if !p.points.iter().all(|q| q.iter().all(|v| v.is_finite())) {
                return bad("a point is not finite");
            }
            let stride = Real::from(p.stride_ticks);
            let last = p.first_tick as Real + stride * (p.points.len() - 1) as Real;
            if !(p.progress >= p.first_tick as Real && p.progress <= last) {
                return bad("progress is not within the points' ticks");
            }
            if !(p.override_now >= 0.0 && p.override_now <= 1.0) {
                return bad("override_now is not within [0, 1]");
            }
            let step = float::floor((p.progress - p.first_tick as Real) / stride) as usize;
            let k0 = step.min(p.points.len() - 1);
            let frac = (p.progress - p.first_tick as Real) / stride - k0 as Real;
            let count = (p.points.len() - k0).min(MAX_SAMPLES);
            let h = &mut self.horizons[j];
            h.first = p.first_tick / u64::from(p.stride_ticks) + k0 as u64;
            h.count = count;
            h.stride = stride;
            h.behind = frac * stride;
            let pts = &p.points[k0..k0 + count];
            let now = match pts.get(1) {
                Some(next) => pts[0] + (next - pts[0]) * frac,
                None => pts[0],
            };
            h.arc_mm[0] = 0.0;
            let mut arc = 0.0;
            let mut from = now;
            for (k, p) in pts.iter().enumerate().skip(1) {
                arc += (p - from).norm();
                from = *p;
                h.arc_mm[k] = arc;
            }
            let speed_of = |k: usize| (pts[k + 1] - pts[k]).norm() / (stride * tick_s);
            let now_speed = if count > 1 { speed_of(0) } else { 0.0 };
            h.speed_now_mm_s = p.override_now * now_speed;
            h.speed_ahead_mm_s = (0..count.saturating_sub(1).min(speed::SPEED_AHEAD_SAMPLES))
                .map(speed_of)
                .fold(0.0, Real::max);
            let stop = speed::stopping_mm(self.exact.cell(), j, h.speed_now_mm_s);
            // The sample past the stop too: the robot may stand between it and the one before.
            h.reach = (1..count).find(|&k| h.arc_mm[k] > stop).map_or(count, |k| k + 1);
        }
        Ok(())
    }

    /// Step 2: puts every robot's samples in its ring (only new or changed ones are placed).
    fn place(&mut self, request: &CoordinationRequest) -> Result<(), CoordinationError> {
        let growth = 0.5 * self.config.clearance_mm;
        for (j, p) in request.programmes.iter().enumerate() {
            let h = self.horizons[j];
            let k0 = (h.first - p.first_tick / u64::from(p.stride_ticks)) as usize;
            for k in 0..h.count {
                self.tracks[j].place(&self.exact, j, h.first + k as u64, &p.points[k0 + k], growth);
            }
        }
        for (d, &(a, b)) in self.diagrams.iter_mut().zip(&self.pairs) {
            d.forget(self.tracks[a].replaced, self.tracks[b].replaced);
        }
        self.tracks.iter_mut().for_each(|t| t.replaced = 0);
        Ok(())
    }

    /// Step 3: per pair, whether its windows conflict, each robot's hold point if it yields
    /// (its first sample whose column over the other's horizon conflicts) and its first
    /// sample in conflict with where the other can be until it stands.
    fn pair_holds(&mut self) {
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (ha, hb) = (&self.horizons[a], &self.horizons[b]);
            let (wa, wb) = (window(ha.first, ha.count), window(hb.first, hb.count));
            let (ra, rb) = (window(ha.first, ha.reach), window(hb.first, hb.reach));
            let (ta, tb) = (&self.tracks[a], &self.tracks[b]);
            let d = &mut self.diagrams[k];
            let slot =
                |t: &Track, h: &Horizon, s: usize| t.slot_of(h.first + s as u64).unwrap_or(0);
            let first_a = (0..ha.count).find(|&s| d.row_conflicts(ta, tb, slot(ta, ha, s), wb));
            let first_b = (0..hb.count).find(|&s| d.col_conflicts(ta, tb, slot(tb, hb, s), wa));
            let (block_a, block_b) = if first_a.is_some() {
                (
                    (0..ha.count).find(|&s| d.row_conflicts(ta, tb, slot(ta, ha, s), rb)),
                    (0..hb.count).find(|&s| d.col_conflicts(ta, tb, slot(tb, hb, s), ra)),
                )
            } else {
                (None, None)
            };
            let room = |h: &Horizon, first: Option<usize>| {
                first.map_or(Real::INFINITY, |s| h.arc_mm[s.saturating_sub(1)])
            };
            let hold = |h: &Horizon, first: Option<usize>| match first {
                Some(s) => (room(h, first), s as Real * h.stride - h.behind),
                None => (Real::INFINITY, Real::INFINITY),
            };
            // Where a robot that must stop short of the other may come to rest: the last sample
            // before its block outside the other's shadow (not on the other's way ahead), so
            // that waiting there never keeps the other from passing; its block when none is.
            let harbour_a = block_a.map_or(Real::INFINITY, |end| {
                (0..end)
                    .rev()
                    .find(|&s| !d.row_conflicts(ta, tb, slot(ta, ha, s), wb))
                    .map_or(room(ha, block_a), |s| ha.arc_mm[s])
            });
            let harbour_b = block_b.map_or(Real::INFINITY, |end| {
                (0..end)
                    .rev()
                    .find(|&s| !d.col_conflicts(ta, tb, slot(tb, hb, s), wa))
                    .map_or(room(hb, block_b), |s| hb.arc_mm[s])
            });
            self.holds[k] = PairHolds {
                conflict: first_a.is_some() || first_b.is_some(),
                hold: [hold(ha, first_a), hold(hb, first_b)],
                block: [room(ha, block_a), room(hb, block_b)],
                harbour: [harbour_a, harbour_b],
            };
        }
    }

    /// Step 4: the right of way of every pair in conflict, consistent with one ranking.
    fn decide(&mut self) {
        let cell = self.exact.cell();
        self.ranking.clear();
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let holds = &self.holds[k];
            if !holds.conflict {
                self.winners[k] = None;
                continue;
            }
            let can_yield = |j: usize, side: usize| {
                let stop = speed::stopping_mm(cell, j, self.horizons[j].speed_now_mm_s);
                stop + self.config.hold_margin_mm <= holds.hold[side].0
            };
            let forced = match (can_yield(a, 0), can_yield(b, 1)) {
                (false, true) => Some(a),
                (true, false) => Some(b),
                (true, true) => None,
                // Neither can stand short of the other's shadow: the one with more room
                // before where the other can be until it stands goes (the other stops).
                (false, false) => Some(if holds.block[1] > holds.block[0] { b } else { a }),
            };
            let ticks = [holds.hold[0].1, holds.hold[1].1];
            self.ranking.set_pair(k, forced, self.winners[k], ticks);
        }
        self.ranking.rank(&self.pairs, self.config.hysteresis_ticks);
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            if self.holds[k].conflict {
                self.winners[k] = Some(self.ranking.winner(a, b));
            }
        }
    }

    /// Step 4 of the arrival order: each robot's nearest hold point among the pairs it
    /// yields in (and, for a robot with the right of way, where the yielder can be).
    fn holds_of_winners(&mut self) {
        for (j, r) in self.report.robots.iter_mut().enumerate() {
            *r = RobotCoordination {
                override_factor: 1.0,
                held_by: None,
                hold_mm: Real::INFINITY,
                rank: self.ranking.rank_of(j),
            };
        }
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let Some(w) = self.winners[k] else { continue };
            let (y, w_side, y_side) = if w == a { (b, 0, 1) } else { (a, 1, 0) };
            // The yielder stands short of the winner's shadow; the winner short of where the
            // yielder can be until it stands.
            let (hold, harbour) = (self.holds[k].hold[y_side].0, self.holds[k].harbour[w_side]);
            for (j, room) in [(y, hold), (w, harbour)] {
                let r = &mut self.report.robots[j];
                if room < r.hold_mm {
                    r.hold_mm = room;
                    r.held_by = Some(if j == y { w } else { y });
                }
            }
        }
    }

    /// Step 3 of the programmed order (module doc): each robot's hold point, its first
    /// forbidden sample ahead over every pair; its rank, how many robots are behind it in
    /// progress (ties to the lower index).
    fn programmed_holds(&mut self, request: &CoordinationRequest) {
        let progress = |j: usize| request.programmes[j].progress;
        self.hold_ticks.iter_mut().for_each(|t| *t = Real::INFINITY);
        for (j, r) in self.report.robots.iter_mut().enumerate() {
            let behind = (0..request.programmes.len())
                .filter(|&i| progress(i) < progress(j) || (progress(i) == progress(j) && i < j))
                .count();
            *r = RobotCoordination {
                override_factor: 1.0,
                held_by: None,
                hold_mm: Real::INFINITY,
                rank: behind,
            };
        }
        for k in 0..self.pairs.len() {
            let (a, b) = self.pairs[k];
            for (me, other) in [(a, b), (b, a)] {
                let Some(s) = self.first_forbidden(k, me == a) else { continue };
                let h = &self.horizons[me];
                let tick = (h.first + s as u64 - 1) as Real * h.stride;
                if tick < self.hold_ticks[me] {
                    self.hold_ticks[me] = tick;
                    let r = &mut self.report.robots[me];
                    r.hold_mm = h.arc_mm[s - 1];
                    r.held_by = Some(other);
                }
            }
        }
    }

    /// Robot `me`'s first forbidden sample ahead (from 1 on) in pair `k`, `me` being the
    /// pair's first robot when `row` (module doc, "Programmed order").
    fn first_forbidden(&mut self, k: usize, row: bool) -> Option<usize> {
        let (a, b) = self.pairs[k];
        let (me, other) = if row { (a, b) } else { (b, a) };
        let (hm, ho) = (&self.horizons[me], &self.horizons[other]);
        let slack = self.config.order_slack_ticks.max(hm.stride + ho.stride);
        let (ta, tb) = (&self.tracks[a], &self.tracks[b]);
        let d = &mut self.diagrams[k];
        let mine = if row { ta } else { tb };
        let truncated = ho.count == MAX_SAMPLES;
        // A robot within the hold's slack of its next sample has left the one behind (it
        // stands there at its hold: module doc, "No deadlock").
        let left_first = ho.count > 1 && ho.behind >= ho.stride - HOLD_SLACK_TICKS;
        let from = ho.first + u64::from(left_first);
        (1..hm.count).find(|&s| {
            let tick = (hm.first + s as u64) as Real * hm.stride;
            // The other's samples programmed at least `slack` sooner that it has not left:
            // `from ..= last`.
            let last = float::floor((tick - slack) / ho.stride);
            let sooner = if last < from as Real {
                0
            } else {
                let m = (last - from as Real) as u64 + 1;
                if truncated && m > (ho.first + ho.count as u64 - from) {
                    return true;
                }
                m.min(ho.first + ho.count as u64 - from) as usize
            };
            let slot = mine.slot_of(hm.first + s as u64).unwrap_or(0);
            let w = window(from, sooner) | window(ho.first, ho.reach);
            if row {
                d.row_conflicts(ta, tb, slot, w)
            } else {
                d.col_conflicts(ta, tb, slot, w)
            }
        })
    }

    /// Step 5: each robot's override from its hold point.
    fn overrides(&mut self, request: &CoordinationRequest) {
        let cell = self.exact.cell();
        let tick_s = cell.tick_ms * 1e-3;
        let n = self.report.robots.len();
        let mut targets = [0.0; crate::cell::MAX_ROBOTS];
        for (j, r) in self.report.robots.iter_mut().enumerate() {
            let h = &self.horizons[j];
            // The override whose speed stops within `room` at the largest programmed speed
            // `ahead` the override must hold.
            let by_speed = |room: Real, ahead: Real| {
                let v = speed::allowed_speed(cell, j, room);
                if ahead > 0.0 {
                    (v / ahead).min(1.0)
                } else if v > 0.0 {
                    1.0
                } else {
                    0.0
                }
            };
            let target = match (r.held_by, self.config.right_of_way) {
                (None, _) => 1.0,
                (Some(_), RightOfWay::Arrival) => {
                    by_speed(r.hold_mm - self.config.hold_margin_mm, h.speed_ahead_mm_s)
                }
                // Short of the sample before the hold point in progress too, so that a robot
                // standing at its hold never covers the hold point; the speed that matters is
                // the programme's up to there (through a programmed wait, any factor).
                (Some(_), RightOfWay::Programmed) => {
                    let hold = self.hold_ticks[j];
                    let left = hold - HOLD_SLACK_TICKS - request.programmes[j].progress;
                    let last = ((hold / h.stride) as u64).saturating_sub(h.first) as usize;
                    let ahead = speed_until(h, last, tick_s);
                    let speed = if ahead > 0.0 { by_speed(r.hold_mm, ahead) } else { 1.0 };
                    speed.min(left.max(0.0))
                }
            };
            targets[j] = target;
        }
        self.break_stall(request, &mut targets[..n]);
        let cell = self.exact.cell();
        for (j, r) in self.report.robots.iter_mut().enumerate() {
            let h = &self.horizons[j];
            let stop = &cell.stops[j];
            r.override_factor = speed::ramped(
                request.programmes[j].override_now,
                targets[j],
                h.speed_ahead_mm_s,
                stop.max_accel_mm_s2 * tick_s,
                (self.config.speed_up_share, self.config.slow_down_share),
            );
        }
    }

    /// Step 6: when every robot with somewhere to go (a sample ahead) has stood
    /// held for [`STALL_TICKS`], releases one of them, in turn, for [`RELEASE_TICKS`]: its
    /// target is 1 whatever holds it. The protective verdict stays the proof of its motion.
    fn break_stall(&mut self, request: &CoordinationRequest, targets: &mut [Real]) {
        // Somewhere to go: a sample ahead (a programmed wait is progress too).
        let wants = |j: usize| self.horizons[j].count > 1;
        let n = targets.len();
        if let Some((r, left)) = self.stall.released {
            if left == 0 || !wants(r) {
                self.stall.released = None;
            } else {
                self.stall.released = Some((r, left - 1));
                targets[r] = 1.0;
                self.report.robots[r].held_by = None;
                return;
            }
        }
        let held = |j: usize| targets[j] < HELD && request.programmes[j].override_now < HELD;
        let stalled = (0..n).any(wants) && (0..n).filter(|&j| wants(j)).all(held);
        self.stall.ticks = if stalled { self.stall.ticks.saturating_add(1) } else { 0 };
        if self.stall.ticks >= STALL_TICKS {
            // The next robot in turn that has somewhere to go (one exists: the stall says so).
            let r = (0..n).map(|k| (self.stall.turn + k) % n).find(|&j| wants(j)).unwrap_or(0);
            self.stall = Stall { ticks: 0, released: Some((r, RELEASE_TICKS)), turn: r + 1 };
            targets[r] = 1.0;
            self.report.robots[r].held_by = None;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;
    use crate::geometry::clearance::boxes_clearance;
    use crate::robot::RobotBoxes;

    /// Robot `j`'s MCS point of the WCS point `p`.
    fn mcs(cell: &Cell, j: usize, p: Vec3) -> Vec3 {
        let pl = &cell.robots[j].placement;
        pl.rotation().transpose() * (p - pl.t)
    }

    /// One point per tick: from `far` to `place` over ticks `go .. go + 100`, held 60 ticks,
    /// back over 100, then at `far` until tick 600 (linear legs: the test needs positions,
    /// not a smooth profile).
    fn visit(far: Vec3, place: Vec3, go: usize) -> Vec<Vec3> {
        (0..=600)
            .map(|t| {
                let f = match t {
                    t if t < go => 0.0,
                    t if t < go + 100 => (t - go) as Real / 100.0,
                    t if t < go + 160 => 1.0,
                    t if t < go + 260 => 1.0 - (t - go - 160) as Real / 100.0,
                    _ => 0.0,
                };
                far + (place - far) * f
            })
            .collect()
    }

    /// Brute force with the exact clearance (not the diagram's grown boxes): the first tick of
    /// `mine` (robot `me`) within `clearance_mm` of any point of `other`'s (robot `you`)
    /// programmed at least `slack` ticks sooner.
    fn first_meeting(
        cell: &Cell,
        (me, mine): (usize, &[Vec3]),
        (you, other): (usize, &[Vec3]),
        clearance_mm: Real,
        slack: usize,
    ) -> Option<usize> {
        let exact = ExactChecker::new(cell.clone());
        let (mut a, mut b) = (RobotBoxes::empty(), RobotBoxes::empty());
        (0..mine.len()).find(|&t| {
            exact.boxes_in_wcs(me, &mine[t], &mut a).unwrap();
            (0..=t.saturating_sub(slack)).any(|u| {
                exact.boxes_in_wcs(you, &other[u], &mut b).unwrap();
                boxes_clearance(a.as_slice(), b.as_slice()).distance < clearance_mm
            })
        })
    }

    #[test]
    fn the_robot_programmed_later_yields_and_the_earlier_goes() {
        let cell = reference_cell("T1").unwrap();
        // Place points 80 mm apart between the bases (450 mm apart), pick points on the far
        // sides: executed at once, the two visits collide.
        let at = |j: usize, x: [Real; 2]| mcs(&cell, j, Vec3::new(x[j], 0.0, -480.0));
        let (place, far) = (|j| at(j, [185.0, 265.0]), |j| at(j, [-120.0, 570.0]));
        // The clearance of T1's benchmark programmes: at 40 mm a robot at the midpoint comes
        // within the clearance of the other's links standing at its far side.
        let config = CoordinationConfig {
            clearance_mm: 10.0,
            right_of_way: RightOfWay::Programmed,
            ..CoordinationConfig::default()
        };
        let exact = ExactChecker::new(cell.clone());
        let (mut a, mut b) = (RobotBoxes::empty(), RobotBoxes::empty());
        exact.boxes_in_wcs(0, &place(0), &mut a).unwrap();
        exact.boxes_in_wcs(1, &place(1), &mut b).unwrap();
        assert!(boxes_clearance(a.as_slice(), b.as_slice()).distance < 0.0, "no conflict");
        for first in [0, 1] {
            // Robot `first` visits the shared place point at tick 0, the other at tick 300.
            let progs: Vec<Vec<Vec3>> =
                (0..2).map(|j| visit(far(j), place(j), if j == first { 0 } else { 300 })).collect();
            let later = 1 - first;
            let mut coordinator = Coordinator::new(cell.clone(), config);
            let stride = 4;
            let horizon: Vec<Vec<Vec3>> = progs
                .iter()
                .map(|p| p.iter().step_by(stride).take(MAX_SAMPLES).copied().collect())
                .collect();
            let programmes: Vec<Programme> = horizon
                .iter()
                .map(|points| Programme {
                    first_tick: 0,
                    stride_ticks: stride as u32,
                    points,
                    progress: 0.0,
                    override_now: 0.0,
                })
                .collect();
            let report = coordinator.coordinate(&CoordinationRequest { programmes: &programmes });
            let r = report.unwrap().robots.clone();
            assert_eq!(r[first].held_by, None, "robot {first} is programmed there first: {r:?}");
            assert_eq!(r[later].held_by, Some(first), "robot {later} must yield: {r:?}");
            // It holds before the first point where it would come within the clearance of
            // where the other is programmed sooner (the diagram's boxes hold the exact ones,
            // so its hold point comes no later than the brute force's).
            let meet = first_meeting(
                &cell,
                (later, &progs[later]),
                (first, &progs[first]),
                config.clearance_mm,
                config.order_slack_ticks as usize,
            )
            .expect("the programmes meet");
            let arc: Real = progs[later][..meet].windows(2).map(|w| (w[1] - w[0]).norm()).sum();
            assert!(r[later].hold_mm <= arc, "hold {} mm, meeting at {arc} mm", r[later].hold_mm);
            assert_eq!((r[0].rank, r[1].rank), (0, 1), "ties go to the lower index");
        }
    }
}
