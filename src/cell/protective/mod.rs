//! The protective verdict (SPEC §8): can both robots still stop, from this tick on, without
//! any box of one touching any box of the other? FREE only when that is proved.
//!
//! # The bound
//! 1. **Speed now.** The controller gives TCPs, not speeds. With `v_fd = (p - p_prev) / dt`
//!    the average velocity since the previous call, `dt` the real interval between the two
//!    calls' times ([`TickTime`]; `protective/clock.rs`: `T = tick_ms` for an untimed call,
//!    a timing fault is STOP), the true speed now differs from `|v_fd|` by at most `a_max dt`
//!    (`|v(t) - v(s)| <= a_max |t - s|` for `s` in the interval), so
//!    `v <= v_b := min(|v_fd| + a_max dt, v_max)`. Without a previous TCP (first tick, after
//!    any error) `v_b = v_max`. A step longer than `v_max dt`, or a change of `v_fd` between
//!    two intervals `dt_1`, `dt_2` larger than `a_max (dt_1 + dt_2) / 2` (two consecutive
//!    averages differ by at most that), is impossible under the model:
//!    [`ProtectiveStatus::ImplausibleMotion`], STOP.
//! 2. **Latency of the verdict itself.** A FREE at tick `k` must cover a STOP issued at tick
//!    `k + 1`: the robot then moves one more tick before its reaction starts. The reaction
//!    time used is therefore `T_r = reaction_ms + tick_ms`.
//! 3. **Where the TCP can be.** Along its path the TCP travels at most
//!    `min(v_b T_r + a_max T_r^2 / 2, v_max T_r)` while reacting, then, braking from
//!    `v_r = min(v_b + a_max T_r, v_max)` at `>= decel`, at most `v_r^2 / (2 decel)`: in all
//!    `S` ([`StopModel::stopping_distance`]). The path is unknown, so every TCP of the whole
//!    stop lies in the ball of radius `S` around the TCP now, hence in the cube of half-side
//!    `S` around it (and in the robot's reachable space). With a measured velocity `v_fd`
//!    the direction is known during the reaction: the TCP is within `a_max dt t + a_max t^2/2`
//!    of `p + v_fd t`, so the whole stop lies in the capsule around `p .. p + v_fd T_r` of
//!    radius `S - |v_fd| T_r`, and in the ball around its middle of radius
//!    `S - |v_fd| T_r / 2` ([`capsule_ball`]); that ball is used, with the boxes built at its
//!    centre, when the centre is reachable.
//! 4. **Where the boxes can be.** [`box_sweep_forms_into`] bounds, per box, the displacement
//!    of every box point for every reachable TCP of that cube, measured from its centre
//!    (interval inverse kinematics: elbows may swing far more than the TCP moves, SPEC §8);
//!    the displacement set is a [`Sweep`] (MCS, rotated to the WCS with the robot's
//!    placement). It gives two sound forms of one bound ([`SweepForms`]): `[0]` with the
//!    TCP's displacement in the cube of half-side `S`, `[1]` in the ball of radius `S` that
//!    holds the TCP (the ball takes the cube's place inside each lower link's hull, and the
//!    link's turn is bounded with `|D| <= S`, not the cube's half-diagonal). A box pair is
//!    proved apart when, on one axis, the smaller support of either form of each box
//!    separates them ([`swept_boxes_apart_either`]: the cube is tighter where the separating
//!    axis is a world axis, the ball elsewhere).
//!    The motor angles over the cube come in **tiers**, each a sound enclosure of the angle
//!    of every reachable TCP of the cube (the only input of the bound that needs inverse
//!    kinematics): tier 1 reads them from the robot's [`MotorTable`] (certified interval
//!    inverse kinematics per 16 mm cell, computed in [`ProtectiveChecker::new`]; its module
//!    doc proves the cover), 8 reads per arm; tier 2, only where tier 1 leaves the tick
//!    unproved (STOP or WARN), intersects that with the direct enclosure over the cube in
//!    [`PRECISE_SPLITS`]`^3` sub-boxes (two sound enclosures: so is their intersection, and
//!    a narrower angle range gives a smaller sweep on every axis, so tier 2 proves whatever
//!    the direct enclosure alone proved before the table existed). Each tier's angles are
//!    then intersected with
//!    [`ball_theta_range`](crate::robot::motion_bound::ball_theta_range), an enclosure over
//!    the ball itself in the arm's polar coordinates (the TCP never leaves the ball; the cube
//!    only writes it as a box), and a lower link's turn is split between a ball and a
//!    segment along its own axis (`robot::motion_bound`, steps 10 and 11).
//! 5. **Apart.** Box `i` of robot `a` over the stop lies in `box_i(now)` with each point moved
//!    within `sweep_i` as the graded reading of [`crate::geometry::sweep`] allows: a point of
//!    a lower link at `l` along it moves within `|l| Z + |1 - l| A` (`robot::motion_bound`, step
//!    4), so the end nearer the platform joint carries the TCP's set and hardly any of the
//!    elbow's arc, the end at the elbow the reverse; likewise for `b`.
//!    [`swept_boxes_apart_either`] proves the two swept sets disjoint, with a positive gap, on
//!    one of the 15 axes of the box pair, on the direction between the robot pair's closest
//!    points this tick, or on the box pair's *graded axis*: the direction between the closest
//!    points of the two boxes swept by the graded balls of step 6, which every sweep holds
//!    ([`graded_closest`], found from the boxes and radii alone, and only for pairs the
//!    others leave unproved). Any axis is sound; the 15 decide whether two boxes meet, not
//!    whether two swept sets do, and the graded axis looks where the sweeps come nearest (on
//!    the reference runs it proves most of the pairs that the 16 others leave unproved:
//!    `cargo test --release --lib graded_points -- --nocapture`). All box pairs of all pairs
//!    that can meet proved: FREE. Proved again with `warn_mm` added to one sweep's ball (and
//!    to the graded ball its axis is sought with): else WARN. Any unproved pair, unreachable
//!    TCP, unbounded sweep or status other than OK: STOP.
//! 6. **Certain STOP, before any sweep.** In every sweep of a box, a point at fraction `f` of
//!    the way from the box's face at `-half_0 u_0` to the one at `+half_0 u_0` moves within a
//!    set that holds the ball of radius `((1 - f) e_1 + f e_2) S'` (`S'` the radius of step 3's
//!    ball; `e_k` the weight of the TCP's set `Z` at end `k`, [`tcp_weights`]: `mu` at a lower
//!    link's elbow, `1 + mu` at its platform joint, 1 for platform and tool boxes, 0 for upper
//!    links): form 0's `Z` is the cube of half-side `S >= S'`, form 1's the ball of radius `S`,
//!    and the arc, ball and segment terms hold 0. So on every axis, toward either box, each
//!    form's graded support is at least that of the [`Sweep::graded_ball`] of radii
//!    `e_k S'`. When the boxes swept by those graded balls (radii shrunk by a relative 1e-9,
//!    far above rounding) are not separated on the axes of step 5 ([`balls_swept_apart_with`]
//!    on the 16, then on the graded axis, which the graded balls define alone, so that this
//!    step and the proof try the very same axis), no tier can: STOP at
//!    once, without inverse kinematics beyond the reference boxes'. The graded axis's two
//!    points, one of each box, lying closer than their two radii show the swept boxes share a
//!    point ([`GradedClosest::meet`]), so that no axis at all separates them. An elbow's end
//!    holds only `mu S'` of the TCP's ball, so this step settles the pairs that meet near
//!    platform joints, platforms and tools; near the elbows step 7 does. Steps 6 and 7 live in
//!    `protective/certain_stop.rs`.
//! 7. **Certain STOP, before tier 2.** Every tier's enclosure of an arm's angle over the ball
//!    holds the angle `th(p)` of every reachable TCP `p` of the ball, whichever points are
//!    picked: here its centre `p0` and the two points `p0 +- S w / |w|` of the ball
//!    (`w = E_i - G_i`, the lower link of the box's arm at `p0`: the gradient of `th_i` is
//!    parallel to `w`, so these are where the angle is largest and smallest to first order),
//!    those that are reachable. Step 4's sweep of a box depends on the enclosure only through
//!    its arm's `dth = max(th.hi - th(p0), th(p0) - th.lo)`, and grows with it on every axis,
//!    at both ends (the elbow's chord `2 rf sin(dth / 2)`, the arc's `sin dth` and `1 - cos dth`, all
//!    increasing on `[0, pi]`; the TCP terms do not depend on it). So the sweeps built from
//!    the hull of those angles alone ([`ProtectiveChecker::least_sweeps`]: each angle taken
//!    `ANGLE_SLACK` toward `th(p0)`, far above the rounding of the inverse kinematics, and
//!    each ball shrunk by `LEAST_SLACK`, far above the rounding of the supports, which stay
//!    `>= 0`: every ball holds `BOUND_SLACK`) have, on every axis and in both forms, a support
//!    at most that of the sweeps of any tier. When they do not prove the limiting box pair of
//!    tier 1 apart on the axes of step 5 (with `warn_mm` for a WARN; the graded axis depends
//!    on the reference boxes and radii, not on the tier), no refinement of tier 2 proves it:
//!    the pairs before it stay proved (a narrower angle range, a smaller sweep), it stays the
//!    first unproved one, and the verdict and limiting pair are final without tier 2's direct
//!    enclosures. This test only ends a search for a proof; it never proves anything.
//! 8. **Certain STOP, first.** Any box pair that steps 6 or 7 show no tier can prove apart
//!    makes the tick STOP, whatever the other pairs give: the verdict does not depend on the
//!    order in which pairs are tried, only the limiting pair reported (then that pair: one
//!    the proof cannot separate). So both tests are tried first on the closest box pair now,
//!    the likeliest to fail (step 7 only after a STOP tick, when another STOP is likely),
//!    before any reference is set and any sweep of a tier, and step 6 again on that pair
//!    before each speed tested for a limit. (Step 6 over every box pair, tried after the
//!    references before the graded axes existed, settled no tick of the reference runs once
//!    they did: `prot_tick` printed the same answers without it.)
//! 9. **Certain STOP, kept.** Two reachable TCPs, one in each robot's stop ball, whose boxes
//!    overlap, make every tick whose balls still hold them STOP (`protective/contact.rs`:
//!    every sweep holds the boxes of every TCP of its ball). After a STOP the checker seeks
//!    such a contact; a tick that it settles needs neither references nor sweeps.
//!
//! The **speed limit** of a robot is the largest measured speed `|v_fd|` in `[0, v_max]` at
//! which every pair involving it is still proved, the other robots as they are: bisection to
//! `v_max / 2^LIMIT_STEPS` ([`LIMIT_STEPS`]) that keeps the last speed proved. Ticks of
//! [`ProtectiveChecker::check`] start from the last tick's limit and step away from it by
//! doubling steps to a bracket before bisecting: the same kind of answer (a grid speed proved,
//! the next one up not) in a few tests where limits change little between ticks. 0 when not
//! even standing still is proved; `v_max` when full speed is. The tests of a tick are capped,
//! all robots together ([`ProtectiveChecker::with_limit_tests`],
//! [`DEFAULT_EXTRA_LIMIT_TESTS`]): at the cap the largest speed proved so far is the limit (a
//! proved speed, lower than the search's end, which the next ticks approach from it, with the
//! step reached), 0 when no test proved one. Never below that, the tick's measured speed when
//! its verdict is not STOP: the verdict proved every pair with the ball of that speed and
//! direction, the ball a test at that speed builds. By default the bisection uses
//! tier 1 alone (a few us per robot): that limit is proved, and never above the limit of
//! both tiers ([`ProtectiveChecker::with_precise_limits`] for that one: both tiers, the
//! second only above the first's limit and below the speed where step 6 already fails).
//!
//! **Kept proofs** (`protective/kept.rs`): a FREE proof made for stop balls that hold this
//! tick's balls covers this tick too, so FREE ticks that follow FREE ticks mostly reuse one
//! instead of computing sweeps ([`ProtectiveReport::kept_proof`]).
//!
//! **Table mode** (`protective/lookup.rs`): with certified clearance tables, in a tick not
//! settled by a kept proof or a certain STOP, a pair whose table bound exceeds both robots'
//! motion bounds (the largest displacement of any box point under step 4's sweeps) plus
//! `warn_mm` is proved by the lookup, without its box-pair proof; the tick is FREE by the
//! lookups when every pair is ([`ProtectiveRequest::with_table`],
//! [`ProtectiveReport::table_lookup`], [`ProtectiveReport::table_pairs`]); the other pairs
//! take the proof above, unchanged.
//!
//! Nothing here allocates after [`ProtectiveChecker::new`].
//!
//! [`box_sweep_forms_into`]: crate::robot::motion_bound::box_sweep_forms_into
//! [`tcp_weights`]: crate::robot::motion_bound::tcp_weights
//! [`balls_swept_apart_with`]: crate::geometry::sweep::balls_swept_apart_with
//! [`swept_boxes_apart_either`]: crate::geometry::sweep::swept_boxes_apart_either
//! [`graded_closest`]: crate::geometry::graded_closest
//! [`GradedClosest::meet`]: crate::geometry::graded_closest::GradedClosest::meet

use crate::cell::{Cell, CellError, ExactChecker, QueryError};
use crate::geometry::clearance::{boxes_clearance, CoherentClearance, PairClearance};
use crate::geometry::sweep::FaceTerms;
use crate::geometry::{Obb, Sweep};
use crate::math::{Real, Vec3};
use crate::robot::motor_table::MotorTable;
use crate::robot::{BoxKind, StopModel};
use alloc::sync::Arc;

mod certain_stop;
mod clock;
mod contact;
mod kept;
mod lookup;
mod path;
mod request;
mod slices;
mod speed_limit;
mod stop_sweeps;
mod work;
pub use clock::{TickTime, TimingFault, MAX_INTERVAL_TICKS, MIN_INTERVAL_TICKS};
pub use kept::{KEPT_MARGIN_MM, KEPT_WIDEN};
pub use lookup::{ClearanceBound, LOOKUP_SLACK_MM};
pub use path::{path_through_samples, StopPath, MAX_PATH_POINTS};
pub use request::ProtectiveRequest;
use stop_sweeps::{first_unproved_between, stop_sweeps_wcs_into, SweptBall};
pub use stop_sweeps::{stop_sweeps_wcs, SweepForms};
pub use work::DEFAULT_PATH_WORK;

/// Sub-boxes per axis when enclosing the motor angles over the stopping cube (`STOP_SPLITS^3` per
/// arm). The cubes here are tens to hundreds of mm, where finer splits shrink the sweeps by
/// about 1 % for 7 times the time (2: about 11 us per robot, 4: 74 us); a tick evaluates up
/// to `2 + LIMIT_STEPS + 1` sweep sets per robot.
pub const STOP_SPLITS: u32 = 2;

/// The WARN threshold of the C ABI until `dc_set_stop_model` sets one (mm): the 10 mm by which
/// the practical scenarios clear the robots (SPEC §5).
pub const DEFAULT_WARN_MM: Real = 10.0;

/// Sub-boxes per axis of the second tier: where the table alone does not prove FREE, the
/// motor angles are enclosed again directly over the stopping cube with `PRECISE_SPLITS^3`
/// sub-boxes and intersected with the table's enclosure (module doc, step 4).
pub const PRECISE_SPLITS: u32 = 2;

/// Bisection steps of a speed limit (after the checks at 0 and at `v_max`).
pub const LIMIT_STEPS: u32 = 8;

/// How many speeds the searches of the robots' speed limits test per tick in all, beyond one
/// per robot, by default ([`ProtectiveChecker::with_limit_tests`]); one test costs about as
/// much as one robot's sweeps and their swept-box proof.
pub const DEFAULT_EXTRA_LIMIT_TESTS: u32 = 1;

/// Relative and absolute slack of the plausibility checks: rounding of the caller's own
/// trajectory arithmetic must not read as an impossible motion.
const PLAUSIBLE_SLACK: Real = 1e-9;

/// The protective verdict of one tick, ordered from the best (`Free`) to the worst (`Stop`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
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
    /// Robot `.0`'s stop path is unusable: no point, a non-finite point or tolerance, a
    /// negative tolerance, or the TCP now farther than the tolerance from it ([`StopPath`]).
    InvalidPath(usize),
    /// The call's time gives no interval to bound the speeds with (`protective/clock.rs`).
    Timing(TimingFault),
}

/// Box `box_a` of robot `a` and box `box_b` of robot `b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoxPair {
    /// First robot (`a < b`).
    pub a: usize,
    /// Second robot.
    pub b: usize,
    /// Box of `a` ([`RobotModel::boxes`](crate::robot::RobotModel::boxes) order).
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
#[derive(Debug, PartialEq)]
pub struct ProtectiveReport {
    /// FREE, WARN or STOP.
    pub verdict: Protective,
    /// OK, or why there is no proof.
    pub status: ProtectiveStatus,
    /// The signed clearance of the cell now (mm, SPEC §8: the gap when apart, minus the
    /// penetration depth when boxes intersect, 0 when they touch; `INFINITY` when no pair can
    /// meet, NaN when not computed). The exact clearance in table mode too: every tick with
    /// status OK computes it before any proof, the table's lookup included.
    pub clearance_mm: Real,
    /// The box pair of the smallest clearance now.
    pub closest: Option<BoxPair>,
    /// A box pair not proved apart (STOP) or not with `warn_mm` to spare (WARN): the closest
    /// pair now when that one is certain to stay unproved (module doc, step 8), else the first
    /// such pair in the order of the robots and boxes.
    pub limiting: Option<BoxPair>,
    /// One entry per robot.
    pub robots: alloc::vec::Vec<RobotProtection>,
    /// Whether the verdict is FREE by a proof kept from an earlier tick or made for balls
    /// wider than this tick's (`protective/kept.rs`) rather than by this tick's own proof.
    pub kept_proof: bool,
    /// Whether the verdict is FREE by the clearance table's bound alone, without a swept-box
    /// proof (`protective/lookup.rs`; only with [`ProtectiveRequest::with_table`]).
    pub table_lookup: bool,
    /// Whether some pair is proved only with its stop cut into time slices (`slices.rs`;
    /// only with stop paths).
    pub time_sliced: bool,
    /// How many pairs that can meet the table's bound proved apart this tick, which the
    /// swept-box proof then skipped (all of them when `table_lookup`).
    pub table_pairs: u32,
    /// Proof tests the speed limits' searches made this tick (the per-tick work they take;
    /// [`ProtectiveChecker::with_limit_tests`] caps it).
    pub limit_tests: u32,
    /// Whether the searches used the whole cap this tick: some limit is then the largest speed
    /// proved so far, its search going on next tick.
    pub limit_budget_spent: bool,
    /// Units of work the proof along the stop paths spent this tick (`protective/work.rs`;
    /// [`ProtectiveChecker::with_path_work`] caps it); 0 without paths.
    pub path_work: u32,
    /// Whether the proof along the paths left a step untaken for want of units this tick:
    /// the verdict is then at best the one without paths, or a speed limit the highest speed
    /// proved so far.
    pub path_work_spent: bool,
}

impl Clone for ProtectiveReport {
    fn clone(&self) -> Self {
        let mut out = ProtectiveReport { robots: alloc::vec::Vec::new(), ..self.head() };
        out.robots.clone_from(&self.robots);
        out
    }

    /// Field by field, the robots' entries into the capacity already there: a tick that keeps
    /// its report for a repeated cycle allocates nothing.
    fn clone_from(&mut self, source: &Self) {
        let robots = core::mem::take(&mut self.robots);
        *self = ProtectiveReport { robots, ..source.head() };
        self.robots.clone_from(&source.robots);
    }
}

impl ProtectiveReport {
    /// A copy of this report without the robots' entries (no allocation).
    fn head(&self) -> ProtectiveReport {
        let (verdict, status, clearance_mm, closest, limiting) =
            (self.verdict, self.status, self.clearance_mm, self.closest, self.limiting);
        let (kept_proof, table_lookup, table_pairs, time_sliced) =
            (self.kept_proof, self.table_lookup, self.table_pairs, self.time_sliced);
        let (limit_tests, limit_budget_spent) = (self.limit_tests, self.limit_budget_spent);
        let (path_work, path_work_spent) = (self.path_work, self.path_work_spent);
        let robots = alloc::vec::Vec::new();
        ProtectiveReport {
            verdict,
            status,
            clearance_mm,
            closest,
            limiting,
            robots,
            kept_proof,
            table_lookup,
            time_sliced,
            table_pairs,
            limit_tests,
            limit_budget_spent,
            path_work,
            path_work_spent,
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct History {
    tcp: Option<Vec3>,
    /// The last finite-difference velocity (mm/s) and the interval it was measured over (s).
    velocity: Option<(Vec3, Real)>,
    /// The last speed limit (mm/s): where this tick's search starts; and the step of its
    /// first test above that limit (mm/s; module doc).
    limit: Option<(Real, Real)>,
    /// The last speed limit along the paths (mm/s; `path.rs`): where that search starts.
    path_limit: Option<Real>,
}

const NO_HISTORY: History = History { tcp: None, velocity: None, limit: None, path_limit: None };

/// What the checker keeps of one robot: what the previous calls left (its history, where
/// its limit search goes on) and this tick's stop (the measured velocity, the stop ball, the
/// reference swept over it).
#[derive(Clone, Copy, Debug)]
struct RobotState {
    history: History,
    /// The measured velocity of this tick (MCS, mm/s; zero when unknown).
    velocity: Vec3,
    /// `S` and the ball of [`ProtectiveChecker::stop_ball`] at this tick's measured speed:
    /// computed once per tick, read again when the tick needs its references.
    stop_ball: (Real, (Vec3, Real)),
    /// The step of the next tick's first test above the speed limit.
    limit_step: Real,
    /// The boxes at the centre of the ball that holds the TCP over the stop, and their sweeps
    /// over it (module doc, steps 3-6).
    reference: SweptBall,
    /// The tier the reference's sweeps were computed with (`None`: not for this reference).
    tier: Option<(u32, u8)>,
}

/// What the checker keeps of one pair of robots that can meet.
#[derive(Clone, Debug)]
struct PairState {
    /// Its clearance at the last tick: where this tick's computation starts (same answer, a
    /// fraction of the time).
    clearance: CoherentClearance,
    /// The direction between its closest points this tick: an axis the proofs of the tick
    /// try besides the 15 of each box pair (module doc, step 5).
    axis: Vec3,
    /// Whether the clearance table's bound proved it apart over this tick's stop balls
    /// (`protective/lookup.rs`).
    table_proved: bool,
}

/// What does not change from tick to tick: the robots' motor-angle tables and the settings.
#[derive(Clone, Debug)]
struct Model {
    /// Per robot, the motor-angle table of its kinematics (shared by equal robots; `None`:
    /// the interval inverse kinematics alone).
    tables: alloc::vec::Vec<Option<Arc<MotorTable>>>,
    warn_mm: Real,
    /// Whether each tick also finds the speed limits (most of its time).
    speed_limits: bool,
    /// Sub-boxes per axis of the second tier's direct enclosure (0: no second tier).
    precise_splits: u32,
    /// Whether the speed limits use the second tier too (else the table's alone).
    precise_limits: bool,
    /// Speeds tested per tick at most, all robots together, by the searches of the table
    /// tier's limits.
    limit_tests: u32,
    /// Units of work the proof along the paths may spend per tick (`protective/work.rs`).
    path_work: u32,
    /// Whether the certain STOPs are tried on the closest pair before any reference is set
    /// (module doc, step 8; off only in the test that checks it changes no verdict).
    certain_stops_first: bool,
    /// Face terms of no box (fills the unused entries of a box list).
    no_faces: FaceTerms,
}

/// What the sequence of calls left (`protective/clock.rs`): the last call's time, TCPs and
/// report, this tick's interval, whose limit search goes first, and whether the last tick
/// set its references.
#[derive(Clone, Debug)]
struct Calls {
    /// The interval the speeds of this tick are bounded over (s).
    interval_s: Real,
    /// The time of the last call (`None`: none since the checker was made or reset).
    time: Option<TickTime>,
    /// The TCPs of the last call: a call of the same cycle with the same TCPs gets its report
    /// again.
    last_tcps: alloc::vec::Vec<Vec3>,
    /// The last call's report, put aside here when `check_at_speeds` wrote over it (then
    /// `set_aside`): a tick copies nothing when nothing came between.
    cycle_report: ProtectiveReport,
    set_aside: bool,
    /// Which robot's speed-limit search comes first this tick (and may use the most tests).
    limit_turn: usize,
    /// Whether the last tick ended before setting the references of its stop balls (a kept
    /// proof or a certain STOP without speed limits): every robot's reference is then an
    /// earlier tick's.
    references_stale: bool,
}

/// The protective check of one cell: the exact checker of the cell, what does not change,
/// and what each robot, each pair that can meet and the sequence of calls leave from tick to
/// tick (each in its own type).
#[derive(Clone, Debug)]
pub struct ProtectiveChecker {
    exact: ExactChecker,
    model: Model,
    robots: alloc::vec::Vec<RobotState>,
    pairs: alloc::vec::Vec<PairState>,
    /// FREE proofs kept from earlier ticks (`protective/kept.rs`).
    kept: kept::Kept,
    /// Two TCPs in earlier stop balls whose boxes overlap, which make every tick whose stop
    /// balls still hold them STOP (`protective/contact.rs`).
    contact: contact::KeptContact,
    /// Each robot's piece of its whole stop along its path this tick (`path.rs`).
    whole_pieces: alloc::vec::Vec<Option<path::Piece>>,
    /// Each robot's halving tree of its whole piece this tick (`path.rs`): the halves that
    /// the verdict and every test of the speed limits along the paths build once.
    whole_halves: alloc::vec::Vec<[path::Halves; path::TREE_NODES]>,
    /// The work the proof along the paths spends this tick (`protective/work.rs`).
    work: work::PathWork,
    calls: Calls,
    report: ProtectiveReport,
}

impl ProtectiveChecker {
    /// A checker for `cell` (its `tick_ms` and stopping models) that warns with less than
    /// `warn_mm` to spare.
    ///
    /// # Errors
    /// [`CellError::Invalid`] when `warn_mm` is NaN, infinite or negative.
    pub fn new(cell: Cell, warn_mm: Real) -> Result<Self, CellError> {
        Self::build(cell, warn_mm, true)
    }

    /// A checker like [`ProtectiveChecker::new`] that builds no motor-angle table: the same
    /// verdicts from the interval inverse kinematics alone, several times slower per tick, but
    /// nothing to build (about 0.3 s and 21.6 MB per robot kinematics) at construction. For a
    /// handle that may never be asked for a protective verdict.
    ///
    /// # Errors
    /// As [`ProtectiveChecker::new`].
    pub fn without_motor_tables(cell: Cell, warn_mm: Real) -> Result<Self, CellError> {
        Self::build(cell, warn_mm, false)
    }

    fn build(cell: Cell, warn_mm: Real, motor_tables: bool) -> Result<Self, CellError> {
        if !(warn_mm.is_finite() && warn_mm >= 0.0) {
            return Err(CellError::Invalid(alloc::format!(
                "warn_mm = {warn_mm} must be finite and >= 0"
            )));
        }
        let n = cell.robots.len();
        let mut tables: alloc::vec::Vec<Option<Arc<MotorTable>>> =
            alloc::vec::Vec::with_capacity(n);
        for robot in &cell.robots {
            let table = if motor_tables {
                let shared =
                    tables.iter().flatten().find(|t| *t.delta() == robot.model.delta).cloned();
                Some(shared.unwrap_or_else(|| Arc::new(MotorTable::new(&robot.model.delta))))
            } else {
                None
            };
            tables.push(table);
        }
        let unit = Obb::new(Vec3::zeros(), crate::math::Mat3::identity(), Vec3::repeat(1.0));
        let no_faces = FaceTerms::new(&unit, &Sweep::ZERO);
        let tick_s = cell.tick_ms * 1e-3;
        let exact = ExactChecker::new(cell);
        let n_pairs = exact.verdict().pairs.len();
        let kept = kept::Kept::new(n, n_pairs);
        let report = ProtectiveReport {
            verdict: Protective::Stop,
            status: ProtectiveStatus::Ok,
            clearance_mm: Real::NAN,
            closest: None,
            limiting: None,
            robots: alloc::vec![RobotProtection::UNKNOWN; n],
            kept_proof: false,
            table_lookup: false,
            time_sliced: false,
            table_pairs: 0,
            limit_tests: 0,
            limit_budget_spent: false,
            path_work: 0,
            path_work_spent: false,
        };
        let robot = RobotState {
            history: NO_HISTORY,
            velocity: Vec3::zeros(),
            stop_ball: (0.0, (Vec3::zeros(), 0.0)),
            limit_step: 0.0,
            reference: SweptBall::empty(no_faces),
            tier: None,
        };
        let pair = PairState {
            clearance: CoherentClearance::new(),
            axis: Vec3::zeros(),
            table_proved: false,
        };
        let model = Model {
            tables,
            warn_mm,
            speed_limits: true,
            precise_splits: PRECISE_SPLITS,
            precise_limits: false,
            limit_tests: n as u32 + DEFAULT_EXTRA_LIMIT_TESTS,
            path_work: DEFAULT_PATH_WORK,
            certain_stops_first: true,
            no_faces,
        };
        let calls = Calls {
            interval_s: tick_s,
            time: None,
            last_tcps: alloc::vec![Vec3::zeros(); n],
            cycle_report: report.clone(),
            set_aside: false,
            limit_turn: 0,
            references_stale: true,
        };
        Ok(ProtectiveChecker {
            exact,
            model,
            robots: alloc::vec![robot; n],
            pairs: alloc::vec![pair; n_pairs],
            kept,
            contact: contact::KeptContact::default(),
            whole_pieces: alloc::vec![None; n],
            whole_halves: (0..n).map(|_| core::array::from_fn(|_| path::Halves::new())).collect(),
            work: work::PathWork::default(),
            calls,
            report,
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
        ProtectiveChecker { model: Model { speed_limits: on, ..self.model }, ..self }
    }

    /// Turns the speed limits of the ticks to come on or off
    /// ([`ProtectiveChecker::with_speed_limits`]).
    pub fn set_speed_limits(&mut self, on: bool) {
        self.model.speed_limits = on;
    }

    /// Whether each tick finds the speed limits.
    pub fn speed_limits(&self) -> bool {
        self.model.speed_limits
    }

    /// This checker with a second tier of `splits^3` direct sub-boxes ([`PRECISE_SPLITS`] by
    /// default; 0: the table alone, faster, more STOPs).
    pub fn with_precise_splits(self, splits: u32) -> Self {
        ProtectiveChecker { model: Model { precise_splits: splits, ..self.model }, ..self }
    }

    /// This checker finding the speed limits with both tiers (`true`: the largest speed at
    /// which the verdict itself proves FREE, to [`LIMIT_STEPS`] bisection steps; about 100 us
    /// per robot) or with the table's tier alone (`false`, the default: a few us per robot,
    /// never above the precise limit, so FREE holds at it too).
    pub fn with_precise_limits(self, on: bool) -> Self {
        ProtectiveChecker { model: Model { precise_limits: on, ..self.model }, ..self }
    }

    /// This checker testing at most `tests` speeds per tick, all robots together, in the
    /// searches of the speed limits of the table's tier (by default one per robot plus
    /// [`DEFAULT_EXTRA_LIMIT_TESTS`]; `u32::MAX`: every search runs to its end). One test
    /// costs about one robot's sweeps and their proof, so this bounds the time of a tick's
    /// limits. The robots search in turn, the first one changing every tick; each may use
    /// what is left but one test per robot after it. When a search runs out of tests the
    /// limit reported is the largest speed it proved: still a proved speed, possibly lower
    /// than the search would have found; the next tick's search starts from it, with the
    /// step it had reached, so a limit that moved by more than one tick's tests reach is
    /// found over a few ticks. A robot left no test reports this tick's measured speed when
    /// the verdict is not STOP, else 0 (module doc). Not capped: the precise limits
    /// ([`ProtectiveChecker::with_precise_limits`]), and the searches of
    /// [`ProtectiveChecker::check_at_speeds`], which has no last limit to start from.
    pub fn with_limit_tests(self, tests: u32) -> Self {
        ProtectiveChecker { model: Model { limit_tests: tests, ..self.model }, ..self }
    }

    /// Sets the cap on speeds tested per tick from the next tick on
    /// ([`ProtectiveChecker::with_limit_tests`]).
    pub fn set_limit_tests(&mut self, tests: u32) {
        self.model.limit_tests = tests;
    }

    /// The cap on speeds tested per tick ([`ProtectiveChecker::with_limit_tests`]).
    pub fn limit_tests(&self) -> u32 {
        self.model.limit_tests
    }

    /// This checker spending at most `units` of work per tick on the proof along the stop
    /// paths ([`DEFAULT_PATH_WORK`] by default; 0: the verdict and limits without paths;
    /// `u32::MAX`: no cap). The part of a tick whose work grows with the inputs (`path.rs`:
    /// halvings, time slices, the limits' tests along the paths) then stays within a count
    /// the caller sets; a step without the units it needs is not taken and what it would
    /// have proved stays unproved (`protective/work.rs`): the verdict is at best the one
    /// without paths, a limit the highest speed proved. The rest of a tick is bounded by its
    /// tiers and by [`ProtectiveChecker::with_limit_tests`].
    pub fn with_path_work(self, units: u32) -> Self {
        ProtectiveChecker { model: Model { path_work: units, ..self.model }, ..self }
    }

    /// Sets the cap on the work along the paths from the next tick on
    /// ([`ProtectiveChecker::with_path_work`]).
    pub fn set_path_work(&mut self, units: u32) {
        self.model.path_work = units;
    }

    /// The cap on the work along the paths per tick ([`ProtectiveChecker::with_path_work`]).
    pub fn path_work(&self) -> u32 {
        self.model.path_work
    }

    /// The WARN threshold (mm).
    pub fn warn_mm(&self) -> Real {
        self.model.warn_mm
    }

    /// The exact checker underneath: its boxes and unreachable robots are those of the last
    /// check; its pairs are left undecided (the report's clearance says whether boxes
    /// intersect: the verdict needs the boxes, not the separating axis test).
    pub fn exact(&self) -> &ExactChecker {
        &self.exact
    }

    /// The report of the last check.
    pub fn report(&self) -> &ProtectiveReport {
        &self.report
    }

    /// Forgets every previous TCP and the last call's time: the next tick assumes full speed
    /// (module doc, step 1).
    pub fn reset(&mut self) {
        self.forget_motion();
        self.calls.time = None;
        // What only speeds a tick up goes too (kept proofs, the clearances' warm starts):
        // a checker reset answers bit for bit as a new one would.
        self.kept.clear();
        for pair in &mut self.pairs {
            (pair.clearance, pair.axis, pair.table_proved) =
                (CoherentClearance::new(), Vec3::zeros(), false);
        }
        (self.calls.limit_turn, self.calls.references_stale) = (0, true);
    }

    /// Forgets every previous TCP, and the contact found from them.
    fn forget_motion(&mut self) {
        self.robots.iter_mut().for_each(|r| r.history = NO_HISTORY);
        self.contact = contact::KeptContact::default();
    }

    /// One tick: robot `j`'s TCP now is `request.tcps_mcs[j]` (its MCS); its speed comes from
    /// its TCP at the previous call and the interval between the two calls' times
    /// (`protective/clock.rs`); with paths, the verdict is also proved along them
    /// (`protective/path.rs`: the better of the verdicts without and along them, the speed
    /// limits those without); with a table, a tick its bound proves FREE is answered from it
    /// (`protective/lookup.rs`; a bound that proves nothing changes nothing). A slice of TCPs is an untimed
    /// request ([`TickTime::Nominal`]: one tick after the last call, whenever it comes).
    ///
    /// A call of the same cycle (or timestamp) as the last one with the same TCPs gets the
    /// last report unchanged; every other timing fault is STOP with
    /// [`ProtectiveStatus::Timing`], and the next call assumes full speed.
    ///
    /// # Errors
    /// [`QueryError::WrongRobotCount`] when the TCPs, or the paths when given, are not one per
    /// robot (the history and the last call's time are then left as they were).
    pub fn check<'r>(
        &mut self,
        request: impl Into<ProtectiveRequest<'r>>,
    ) -> Result<&ProtectiveReport, QueryError> {
        let request = request.into();
        let n = self.cell().robots.len();
        for len in
            [request.tcps_mcs.len(), if request.paths.is_empty() { n } else { request.paths.len() }]
        {
            if len != n {
                return Err(QueryError::WrongRobotCount { expected: n, found: len });
            }
        }
        let tick_s = self.cell().tick_ms * 1e-3;
        let tcps = request.tcps_mcs;
        match clock::interval(self.calls.time, request.time, tick_s) {
            clock::Interval::Same if same_bits(&self.calls.last_tcps, tcps) => {
                if core::mem::take(&mut self.calls.set_aside) {
                    self.report.clone_from(&self.calls.cycle_report);
                }
                return Ok(&self.report);
            }
            clock::Interval::Same => self.timing_fault(TimingFault::Repeated),
            clock::Interval::Fault(fault) => self.timing_fault(fault),
            clock::Interval::Unknown => {
                self.forget_motion();
                self.calls.interval_s = tick_s;
                self.tick(&request);
            }
            clock::Interval::Seconds(dt) => {
                self.calls.interval_s = dt;
                self.tick(&request);
            }
        }
        self.calls.time = Some(request.time);
        self.calls.last_tcps.copy_from_slice(tcps);
        self.calls.set_aside = false;
        Ok(&self.report)
    }

    /// A call whose time gives no interval: STOP, every previous TCP forgotten.
    fn timing_fault(&mut self, fault: TimingFault) {
        self.forget_motion();
        self.report.robots.fill(RobotProtection::UNKNOWN);
        self.clear_report(ProtectiveStatus::Timing(fault));
    }

    /// The tick of a request whose interval is `self.calls.interval_s` (counts checked).
    fn tick(&mut self, request: &ProtectiveRequest) {
        if request.paths.is_empty() {
            self.check_bounded(request.tcps_mcs, request.table);
        } else {
            self.paths_bounded(request.tcps_mcs, request.paths, request.table);
        }
    }

    /// The verdict without paths, the speeds bounded over `self.calls.interval_s` (module doc, step
    /// 1; counts checked by the caller).
    fn check_bounded(&mut self, tcps_mcs: &[Vec3], bound: Option<ClearanceBound>) {
        let dt = self.calls.interval_s;
        let mut status = ProtectiveStatus::Ok;
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            let stop = self.exact.cell().stops[j];
            let slot = &mut self.report.robots[j];
            *slot = RobotProtection::UNKNOWN;
            self.robots[j].velocity = Vec3::zeros();
            if !tcp.iter().all(|v| v.is_finite()) {
                status = worse(status, ProtectiveStatus::NonFinite(j));
                continue;
            }
            let Some(prev) = self.robots[j].history.tcp else { continue };
            let velocity = (tcp - prev) / dt;
            let plausible =
                |x: Real, limit: Real| x <= limit * (1.0 + PLAUSIBLE_SLACK) + PLAUSIBLE_SLACK;
            // Two averages over consecutive intervals differ by at most `a_max` times the
            // distance between the intervals' middles.
            let accel_ok = self.robots[j].history.velocity.is_none_or(|(v, before)| {
                plausible((velocity - v).norm(), stop.max_accel_mm_s2 * (before + dt) / 2.0)
            });
            if !plausible(velocity.norm(), stop.max_speed_mm_s) || !accel_ok {
                status = worse(status, ProtectiveStatus::ImplausibleMotion(j));
            }
            slot.speed_mm_s = velocity.norm();
            self.robots[j].velocity = velocity;
            self.robots[j].history.velocity = Some((velocity, dt));
        }
        self.evaluate(tcps_mcs, status, true, bound);
        // Only a tick without error (unreachable included) becomes the next one's history.
        if self.report.status == ProtectiveStatus::Ok {
            for ((robot, tcp), r) in self.robots.iter_mut().zip(tcps_mcs).zip(&self.report.robots) {
                robot.history.tcp = Some(*tcp);
                let limit = Some(r.speed_limit_mm_s).filter(|v| v.is_finite());
                robot.history.limit = limit.map(|v| (v, robot.limit_step));
            }
        } else {
            self.forget_motion();
        }
    }

    /// The verdict with paths (counts checked by the caller): the better of the one without
    /// paths and the one along them.
    fn paths_bounded(
        &mut self,
        tcps_mcs: &[Vec3],
        paths: &[Option<StopPath>],
        bound: Option<ClearanceBound>,
    ) {
        self.check_bounded(tcps_mcs, bound);
        if self.report.status != ProtectiveStatus::Ok {
            return;
        }
        let invalid = paths
            .iter()
            .zip(tcps_mcs)
            .position(|(p, tcp)| p.as_ref().is_some_and(|p| !path::path_is_valid(p, tcp)));
        if let Some(j) = invalid {
            let report = &mut self.report;
            (report.verdict, report.status, report.limiting) =
                (Protective::Stop, ProtectiveStatus::InvalidPath(j), None);
            report.robots.iter_mut().for_each(|r| r.speed_limit_mm_s = 0.0);
            self.forget_motion();
            return;
        }
        let along = paths.iter().any(Option::is_some);
        if along && (self.report.verdict != Protective::Free || self.model.speed_limits) {
            // The proof along the paths reads this tick's references (a robot without a path
            // keeps its stop ball's), which a tick settled early has not set.
            if self.calls.references_stale {
                self.set_references(tcps_mcs);
            }
            self.work.start(self.model.path_work);
            self.along_paths(tcps_mcs, paths);
            (self.report.path_work, self.report.path_work_spent) =
                (self.work.used(), self.work.ran_out());
        }
    }

    /// The proof along the paths and its speed limits, within the tick's work (`path.rs`,
    /// `work.rs`).
    fn along_paths(&mut self, tcps_mcs: &[Vec3], paths: &[Option<StopPath>]) {
        if self.set_whole_pieces(tcps_mcs, paths) {
            if self.report.verdict != Protective::Free {
                let (verdict, limiting, sliced) = self.prove_with_paths(tcps_mcs, paths);
                if verdict < self.report.verdict {
                    (self.report.verdict, self.report.limiting) = (verdict, limiting);
                    self.report.time_sliced = sliced;
                }
            }
            if self.model.speed_limits {
                self.path_limits(tcps_mcs, paths);
            }
        }
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
        // The last call's report, which a repeat of its cycle answers, is put aside first.
        if !core::mem::replace(&mut self.calls.set_aside, true) {
            self.calls.cycle_report.clone_from(&self.report);
        }
        // A given speed is the speed now: bounded as a measured one over one tick.
        self.calls.interval_s = self.cell().tick_ms * 1e-3;
        let mut status = ProtectiveStatus::Ok;
        for (j, (tcp, &v)) in tcps_mcs.iter().zip(speeds_mm_s).enumerate() {
            self.report.robots[j] = RobotProtection { speed_mm_s: v, ..RobotProtection::UNKNOWN };
            self.robots[j].velocity = Vec3::zeros();
            if !tcp.iter().all(|x| x.is_finite()) || v.is_nan() || v < 0.0 {
                status = worse(status, ProtectiveStatus::NonFinite(j));
            }
        }
        self.evaluate(tcps_mcs, status, false, None);
        Ok(&self.report)
    }

    /// Fills the report from the TCPs and the measured speeds already in `report.robots`;
    /// with `from_history`, each speed limit's search starts at the last tick's limit; with
    /// `table`, a tick the table's bound proves FREE is answered from it.
    ///
    /// A flat chain of steps, the cheaper first, each settling the verdict or passing on: a
    /// kept proof and a certain STOP need no reference (and end the tick when no speed limit
    /// is asked for); a proof kept for wider balls needs sweeps only where those widen; the
    /// table's bounds read this tick's sweeps of the table's tier, which the proof in tiers
    /// then reuses.
    fn evaluate(
        &mut self,
        tcps_mcs: &[Vec3],
        status: ProtectiveStatus,
        from_history: bool,
        table: Option<ClearanceBound>,
    ) {
        let last = self.report.verdict;
        self.clear_report(status);
        if status != ProtectiveStatus::Ok {
            return;
        }
        let Some(points) = self.measure(tcps_mcs) else { return };
        let early = self.kept_proof().or_else(|| self.certain_stop(tcps_mcs, last));
        if early.is_some() && !self.model.speed_limits {
            self.settle(early.unwrap_or(Settled::KeptProof), points);
            self.report.robots.iter_mut().for_each(|r| r.speed_limit_mm_s = Real::NAN);
            self.calls.references_stale = true;
            return;
        }
        self.set_references(tcps_mcs);
        let settled = early
            .or_else(|| self.wider_kept_proof(last))
            .or_else(|| table.and_then(|bound| self.table_lookup(bound)))
            .unwrap_or_else(|| self.prove_in_tiers());
        self.settle(settled, points);
        self.speed_limits_of(tcps_mcs, from_history);
    }

    /// The report of a tick not yet decided: STOP with `status`, nothing measured.
    fn clear_report(&mut self, status: ProtectiveStatus) {
        let report = &mut self.report;
        (report.verdict, report.status, report.clearance_mm) =
            (Protective::Stop, status, Real::NAN);
        (report.closest, report.limiting, report.kept_proof, report.table_lookup) =
            (None, None, false, false);
        (report.table_pairs, report.limit_tests, report.limit_budget_spent) = (0, 0, false);
        (report.time_sliced, report.path_work, report.path_work_spent) = (false, 0, false);
        self.pairs.iter_mut().for_each(|p| p.table_proved = false);
    }

    /// The boxes now, each robot's stop ball and motion bound (module doc, steps 1-3) and the
    /// clearance with its closest pair; the closest pair's points (WCS). `None` when a TCP is
    /// unreachable (the status says which) or the boxes cannot be placed.
    fn measure(&mut self, tcps_mcs: &[Vec3]) -> Option<[Vec3; 2]> {
        let exact = self.exact.place_boxes(tcps_mcs).ok()?;
        if let Some((j, _)) = exact.first_unreachable {
            self.report.status = ProtectiveStatus::Unreachable(j);
            return None;
        }
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            let v = self.report.robots[j].speed_mm_s;
            let (s, ball) = self.stop_ball(j, tcp, v);
            self.robots[j].stop_ball = (s, ball);
            self.kept.set_inside(j, &[ball, (*tcp, s)]);
            let bound = self.speed_bound(j, v);
            let r = &mut self.report.robots[j];
            (r.speed_bound_mm_s, r.protective_mm) = (bound, s);
        }
        let pairs = &mut self.pairs;
        let (clearance, closest, points) = clearance_over_pairs(&self.exact, |k, a, b| {
            let c = pairs[k].clearance.boxes_clearance(a, b);
            pairs[k].axis = c.point_b - c.point_a;
            c
        });
        (self.report.clearance_mm, self.report.closest) = (clearance, closest);
        Some(points)
    }

    /// FREE by the proofs kept from earlier ticks (`protective/kept.rs`), with no sweeps.
    fn kept_proof(&self) -> Option<Settled> {
        self.kept_free(None).then_some(Settled::KeptProof)
    }

    /// STOP without a proof: by a contact kept from an earlier STOP tick (no inverse
    /// kinematics at all), else by steps 6 and 7 on the closest pair, which need two reference
    /// boxes, not every robot's (module doc, step 8).
    fn certain_stop(&mut self, tcps_mcs: &[Vec3], last: Protective) -> Option<Settled> {
        if !self.model.certain_stops_first {
            return None;
        }
        if let Some(pair) = self.contact_holds(tcps_mcs) {
            return Some(Settled::Contact(pair));
        }
        let was_stop = last == Protective::Stop;
        let closest = self.report.closest?;
        self.reference_pair_stops(tcps_mcs, closest, was_stop)
            .then_some(Settled::CertainStop(closest))
    }

    /// FREE by balls wider than the stop balls, kept after a FREE tick (`protective/kept.rs`).
    fn wider_kept_proof(&mut self, last: Protective) -> Option<Settled> {
        (last == Protective::Free && self.keep_and_prove()).then_some(Settled::KeptProof)
    }

    /// FREE by the clearance table's bounds alone (`protective/lookup.rs`); the pairs it
    /// proves are left out of the proof that follows when it does not prove them all.
    fn table_lookup(&mut self, bound: ClearanceBound) -> Option<Settled> {
        self.lookup_pairs(bound).then_some(Settled::TableLookup)
    }

    /// The proof (module doc, step 5) with the table's tier, then tier 2 arm by arm: a box's
    /// sweep depends on its own arm's angles only, so the arms of the limiting pair are
    /// refined until it is proved or both are refined (then the full tier 2 fails on it too:
    /// the same verdict and limiting pair, as a pair proved with fewer arms refined stays
    /// proved with more). A limiting pair that the sweeps of the angles sampled in the cube
    /// cannot prove apart, no tier can (step 7): the verdict stands. Tried on tier 1's
    /// limiting pair only: a pair that tier 2 proved is followed by another mostly when tier 2
    /// proves that one too.
    fn prove_in_tiers(&mut self) -> Settled {
        let (mut verdict, mut limiting) = self.prove();
        if verdict == Protective::Free {
            self.keep_references();
        }
        let splits = self.model.precise_splits;
        let mut first = true;
        while let (Some(p), true) = (limiting, splits > 0) {
            let extra = if verdict == Protective::Warn { self.model.warn_mm } else { 0.0 };
            if core::mem::take(&mut first) && self.beyond_every_tier(p, extra) {
                break;
            }
            let (arms_a, arms_b) = (self.arm_bit(p.a, p.box_a), self.arm_bit(p.b, p.box_b));
            let refined = |me: &Self, j: usize| match me.model.tables[j] {
                None => 0b111,
                Some(_) => me.robots[j].tier.filter(|t| t.0 == splits).map_or(0, |t| t.1),
            };
            let (ra, rb) = (refined(self, p.a), refined(self, p.b));
            if ra & arms_a == arms_a && rb & arms_b == arms_b {
                break;
            }
            self.sweeps_at(p.a, splits, ra | arms_a);
            let rb = refined(self, p.b);
            self.sweeps_at(p.b, splits, rb | arms_b);
            (verdict, limiting) = self.prove();
        }
        Settled::Proved(verdict, limiting)
    }

    /// Writes the settled verdict into the report; a STOP not settled by a kept contact seeks
    /// one for the ticks that follow (from the closest pair and its points `points`).
    fn settle(&mut self, settled: Settled, points: [Vec3; 2]) {
        let report = &mut self.report;
        match settled {
            Settled::KeptProof => (report.verdict, report.kept_proof) = (Protective::Free, true),
            Settled::TableLookup => {
                (report.verdict, report.table_lookup) = (Protective::Free, true);
                // The lookup proved FREE for every TCP of every stop ball: kept like a proof.
                self.keep_references();
            }
            Settled::Contact(pair) | Settled::CertainStop(pair) => {
                (report.verdict, report.limiting) = (Protective::Stop, Some(pair))
            }
            Settled::Proved(verdict, limiting) => {
                (report.verdict, report.limiting) = (verdict, limiting)
            }
        }
        let seek = self.model.certain_stops_first && !matches!(settled, Settled::Contact(_));
        if let (true, Protective::Stop, Some(p)) = (seek, self.report.verdict, self.report.closest)
        {
            self.seek_contact(p, points);
        }
    }

    /// The verdict and its limiting pair for the sweeps as they are (module doc, step 5).
    /// A robot without sweeps for this tick's reference gets those of the table's tier first,
    /// pair by pair: a line's STOP is often found before most robots need any.
    fn prove(&mut self) -> (Protective, Option<BoxPair>) {
        let passes = [(0.0, Protective::Stop), (self.model.warn_mm, Protective::Warn)];
        for (extra, verdict) in
            passes.into_iter().filter(|&(extra, v)| v == Protective::Stop || extra > 0.0)
        {
            for k in 0..self.exact.verdict().pairs.len() {
                let p = self.exact.verdict().pairs[k];
                if self.pairs[k].table_proved {
                    continue;
                }
                for j in [p.a, p.b] {
                    if self.robots[j].tier.is_none() {
                        self.sweeps_at(j, 0, 0);
                    }
                }
                let (ra, rb) = (&self.robots[p.a].reference, &self.robots[p.b].reference);
                if let Some((box_a, box_b)) =
                    first_unproved_between(ra, rb, extra, &self.pairs[k].axis)
                {
                    return (verdict, Some(BoxPair { a: p.a, b: p.b, box_a, box_b }));
                }
            }
        }
        (Protective::Free, None)
    }

    /// `v_b` of robot `j` for measured speed `v` (module doc, step 1).
    fn speed_bound(&self, j: usize, v: Real) -> Real {
        let stop = &self.cell().stops[j];
        let bound = v + stop.max_accel_mm_s2 * self.calls.interval_s;
        if bound.is_finite() {
            bound.min(stop.max_speed_mm_s)
        } else {
            stop.max_speed_mm_s
        }
    }

    /// `S` of robot `j` for TCP `tcp_mcs` at measured speed `v`, and the ball (centre MCS,
    /// radius) that holds its TCP over the stop (module doc, step 3), its centre not
    /// necessarily reachable.
    fn stop_ball(&self, j: usize, tcp_mcs: &Vec3, v: Real) -> (Real, (Vec3, Real)) {
        let cell = self.exact.cell();
        let stop = cell.stops[j];
        let reaction_s = (stop.reaction_ms + cell.tick_ms) * 1e-3;
        let s = stop.stopping_distance(self.speed_bound(j, v), reaction_s);
        (
            s,
            capsule_ball(
                &stop,
                self.calls.interval_s,
                reaction_s,
                tcp_mcs,
                &self.robots[j].velocity,
                v,
                s,
            ),
        )
    }

    /// Every robot's reference for this tick's stop ball ([`ProtectiveChecker::reference_at`]),
    /// from the stop balls [`ProtectiveChecker::evaluate`] computed for `tcps_mcs`.
    fn set_references(&mut self, tcps_mcs: &[Vec3]) {
        for (j, tcp) in tcps_mcs.iter().enumerate() {
            self.reference_at(j, tcp, self.robots[j].stop_ball);
        }
        self.calls.references_stale = false;
    }

    /// Sets robot `j`'s reference boxes, the centre and radius of the ball that holds its TCP
    /// over the stop (module doc, step 3) for TCP `tcp_mcs` at measured speed `v`, and marks its
    /// sweeps as not computed; returns `S`.
    fn stop_reference(&mut self, j: usize, tcp_mcs: &Vec3, v: Real) -> Real {
        let ball = self.stop_ball(j, tcp_mcs, v);
        self.reference_at(j, tcp_mcs, ball)
    }

    /// [`ProtectiveChecker::stop_reference`] from `S` and the ball already computed by
    /// [`ProtectiveChecker::stop_ball`] for this robot, TCP and speed.
    fn reference_at(
        &mut self,
        j: usize,
        tcp_mcs: &Vec3,
        (s, (centre, radius)): (Real, (Vec3, Real)),
    ) -> Real {
        let robot = &mut self.robots[j];
        let (centre, radius) = match self.exact.boxes_in_wcs(j, &centre, &mut robot.reference.boxes)
        {
            Ok(()) if centre != *tcp_mcs => (centre, radius),
            _ => {
                robot.reference.boxes = *self.exact.boxes(j);
                (*tcp_mcs, s)
            }
        };
        (robot.reference.centre, robot.reference.radius, robot.tier) = (centre, radius, None);
        robot.reference.graded =
            certain_stop::graded_radii(&self.exact.cell().robots[j].model, radius);
        s
    }

    /// The arm whose motor angle box `k` of robot `j` moves with, as a bit (0 for platform
    /// and tool boxes, which move with the TCP alone).
    fn arm_bit(&self, j: usize, k: usize) -> u8 {
        match self.exact.cell().robots[j].model.box_kind(k) {
            BoxKind::LowerLink(arm) | BoxKind::UpperLink(arm) => 1 << arm,
            BoxKind::Platform | BoxKind::Tool => 0,
        }
    }

    /// Computes robot `j`'s sweeps (and their face terms) about its reference ball, with the
    /// motor angles of `tier` (0: the table alone; else also `tier^3` direct sub-boxes for the
    /// arms in the bit mask `arms`).
    fn sweeps_at(&mut self, j: usize, tier: u32, arms: u8) {
        // Without a table, tier 1 is already the direct enclosure: a second tier repeats it.
        let (tier, arms) =
            if tier == 0 || self.model.tables[j].is_none() { (0, 0) } else { (tier, arms) };
        if self.robots[j].tier == Some((tier, arms)) {
            return;
        }
        let model = &self.exact.cell().robots[j].model;
        let rot = self.exact.rotation(j);
        let table = self.model.tables[j].as_deref();
        let r = &mut self.robots[j].reference;
        stop_sweeps_wcs_into(&mut r.sweeps, model, rot, &r.centre, r.radius, table, tier, arms);
        r.set_faces();
        self.robots[j].tier = Some((tier, arms));
    }
}

/// How a step of the tick settled its verdict ([`ProtectiveChecker::evaluate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Settled {
    /// FREE by a proof kept from earlier ticks, or kept for wider balls.
    KeptProof,
    /// STOP: a contact kept from an earlier tick still holds (module doc, step 9).
    Contact(BoxPair),
    /// STOP: steps 6 or 7 show that no tier proves the closest pair apart.
    CertainStop(BoxPair),
    /// FREE by the clearance table's bounds.
    TableLookup,
    /// The proof's verdict and limiting pair.
    Proved(Protective, Option<BoxPair>),
}

/// A ball holding every TCP of the stop when the measured velocity `velocity` is known
/// (module doc, step 3, direction-aware): while reacting the TCP is within
/// `a_max dt t + a_max t^2 / 2` of `p + v_fd t` (`v_fd` scaled to speed `v`), then travels at
/// most `L_b` more; all of it lies in the capsule around the segment from `p` to
/// `p + v_fd T_r` of radius `R = a_max dt T_r + a_max T_r^2 / 2 + L_b`, and so in the ball
/// around the segment's middle of radius `R + v T_r / 2`. Returns that ball when it is
/// smaller than the ball of radius `s` around `p`, else `(p, s)`.
fn capsule_ball(
    stop: &StopModel,
    interval_s: Real,
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
    let delta = a * interval_s;
    let v_r = (v + delta + a * t).min(vmax);
    let r = delta * t + 0.5 * a * t * t + v_r * v_r / (2.0 * stop.decel_mm_s2);
    let radius = r + 0.5 * v * t;
    if radius < s {
        (p + velocity * (v / norm * 0.5 * t), radius)
    } else {
        (*p, s)
    }
}

/// The status that wins when several robots fail: non-finite, then implausible, then an
/// invalid path, then unreachable; the lowest robot index first within one kind.
fn worse(a: ProtectiveStatus, b: ProtectiveStatus) -> ProtectiveStatus {
    let rank = |s: &ProtectiveStatus| match s {
        ProtectiveStatus::Ok => 0,
        ProtectiveStatus::Unreachable(_) => 1,
        ProtectiveStatus::InvalidPath(_) => 2,
        ProtectiveStatus::ImplausibleMotion(_) => 3,
        ProtectiveStatus::NonFinite(_) => 4,
        ProtectiveStatus::Timing(_) => 5,
    };
    if rank(&b) > rank(&a) {
        b
    } else {
        a
    }
}

/// Whether `a` and `b` hold the same numbers, bit for bit (NaN equal to itself).
fn same_bits(a: &[Vec3], b: &[Vec3]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.iter().zip(y.iter()).all(|(p, q)| p.to_bits() == q.to_bits()))
}

/// The signed clearance of the cell as of the exact checker's last check (SPEC §8: the gap
/// when apart, minus the penetration depth when intersecting, 0 when touching) and its
/// closest box pair (mm).
pub fn clearance_now(exact: &ExactChecker) -> (Real, Option<BoxPair>) {
    let (clearance, closest, _) = clearance_over_pairs(exact, |_, a, b| boxes_clearance(a, b));
    (clearance, closest)
}

/// [`clearance_now`] with each robot pair's clearance from `pair_clearance(pair index, boxes
/// of a, boxes of b)`, and the closest pair's closest points (WCS).
fn clearance_over_pairs(
    exact: &ExactChecker,
    mut pair_clearance: impl FnMut(usize, &[Obb], &[Obb]) -> PairClearance,
) -> (Real, Option<BoxPair>, [Vec3; 2]) {
    let mut best = (Real::INFINITY, None, [Vec3::zeros(); 2]);
    for (k, p) in exact.verdict().pairs.iter().enumerate() {
        let c = pair_clearance(k, exact.boxes(p.a).as_slice(), exact.boxes(p.b).as_slice());
        // A NaN distance (a non-finite box) wins, so it shows in the report.
        if c.distance.is_nan() || c.distance < best.0 {
            let pair = BoxPair { a: p.a, b: p.b, box_a: c.box_a, box_b: c.box_b };
            best = (c.distance, Some(pair), [c.point_a, c.point_b]);
            if c.distance.is_nan() {
                break;
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

    /// Step 8 changes no verdict: every tick of the default model's practical and collision
    /// runs of T1, T2 and T3 gets the same verdict with the certain STOPs tried first and without,
    /// and it settles more than 50 STOPs of each run.
    #[test]
    fn certain_stops_first_change_no_verdict() {
        let text = include_str!("../../../c_harness/scenarios.txt");
        for s in crate::cell::trajectory::parse_scenarios(text).unwrap().iter() {
            let cell = reference_cell(&s.cell)
                .unwrap()
                .with_stopping(1.0, vec![StopModel::DEFAULT; 2])
                .unwrap();
            let mut first =
                ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
            let mut plain = first.clone();
            plain.model.certain_stops_first = false;
            let (mut tcps, mut early, mut stops) = ([Vec3::zeros(); 2], 0, 0);
            for tick in 0..crate::cell::trajectory::RUN_TICKS {
                s.tcps_at(tick, &mut tcps);
                let v = first.check(&tcps).unwrap().verdict;
                early += usize::from(v == Protective::Stop && first.calls.references_stale);
                stops += usize::from(v == Protective::Stop);
                assert_eq!(
                    plain.check(&tcps).unwrap().verdict,
                    v,
                    "{} {} tick {tick}",
                    s.cell,
                    s.case
                );
            }
            let (cell, case) = (&s.cell, &s.case);
            assert!(early > 50, "{cell} {case}: {early} of {stops} STOPs settled by step 8");
        }
    }

    /// Robot A at 1 m/s along x, B still: calls at cycles 0, 1 and 3 (cycle 2 skipped)
    /// measure A at 1 m/s over the two ticks of the gap, with the bound `a_max dt` of that
    /// interval; the same TCPs called without time read 2 m/s after 1 m/s, a change the
    /// model forbids within one tick.
    #[test]
    fn a_skipped_cycle_is_measured_over_its_real_interval() {
        let (b, v) = (Vec3::new(150.0, 0.0, -450.0), Vec3::new(1000.0, 0.0, 0.0));
        let a = |cycle: u64| Vec3::new(-250.0, 0.0, -450.0) + v * (cycle as Real * 1e-3);
        let mut timed = checker("T1");
        let mut untimed = checker("T1");
        for cycle in [0, 1, 3] {
            let tcps = [a(cycle), b];
            let r = timed.check(ProtectiveRequest::new(&tcps).at(TickTime::Cycle(cycle))).unwrap();
            assert_eq!(r.status, ProtectiveStatus::Ok, "cycle {cycle}");
            untimed.check(&tcps).unwrap();
        }
        let r = timed.report();
        let a_max = timed.cell().stops[0].max_accel_mm_s2;
        assert!((r.robots[0].speed_mm_s - 1000.0).abs() < 1e-6, "{r:?}");
        assert!((r.robots[0].speed_bound_mm_s - (1000.0 + a_max * 2e-3)).abs() < 1e-6, "{r:?}");
        assert_eq!(untimed.report().status, ProtectiveStatus::ImplausibleMotion(0));
    }

    /// Every state kept between calls that a speed or a kept STOP depends on is forgotten by
    /// an error, a timing fault and `reset`: the next call has no previous TCP (full speed)
    /// and no contact; `reset` also forgets the cycle, so a call of the same cycle with the
    /// same TCPs is computed again instead of answered from the last report.
    #[test]
    fn errors_timing_faults_and_reset_forget_the_motion_and_the_contact() {
        let text = include_str!("../../../c_harness/scenarios.txt");
        let s = crate::cell::trajectory::parse_scenarios(text).unwrap();
        let s = s.iter().find(|s| s.cell == "T2" && s.case == "collision").unwrap();
        let mut c = checker("T2");
        let mut tcps = [Vec3::zeros(); 2];
        fn at(cycle: u64, tcps: &[Vec3; 2]) -> ProtectiveRequest<'_> {
            ProtectiveRequest::new(tcps).at(TickTime::Cycle(cycle))
        }
        let mut cycle = 0;
        // Drive the collision run until a contact is kept (a STOP tick that found one).
        while !c.contact.is_kept() {
            cycle += 1;
            s.tcps_at(cycle as u32, &mut tcps);
            c.check(at(cycle, &tcps)).unwrap();
            assert!(cycle < 6000, "no contact on T2's collision run");
        }
        let speeds_unknown =
            |c: &ProtectiveChecker| c.report().robots.iter().all(|r| r.speed_mm_s.is_infinite());
        // Each fault relative to the last call's cycle: the same one with other TCPs, one
        // before it, and past the largest interval.
        type Fault = (fn(u64) -> u64, TimingFault);
        let faults: [Fault; 3] = [
            (|c| c, TimingFault::Repeated),
            (|c| c - 1, TimingFault::Backwards),
            (|c| c + MAX_INTERVAL_TICKS + 1, TimingFault::Jump),
        ];
        for (time, fault) in faults {
            let time = time(cycle);
            let mut sent = tcps;
            if fault == TimingFault::Repeated {
                sent[0].z -= 0.5;
            }
            let r = c.check(at(time, &sent)).unwrap();
            assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::Timing(fault)));
            assert!(
                !c.contact.is_kept() && c.robots.iter().all(|r| r.history.tcp.is_none()),
                "{fault:?}"
            );
            // Back in step: the next call's speeds are unknown, its own contact search aside.
            cycle = time + 1;
            s.tcps_at(cycle as u32, &mut tcps);
            c.check(at(cycle, &tcps)).unwrap();
            assert!(speeds_unknown(&c), "after {fault:?}");
            // A kept contact needs a STOP tick with history: run on until the next is kept.
            while !c.contact.is_kept() {
                cycle += 1;
                s.tcps_at(cycle as u32, &mut tcps);
                c.check(at(cycle, &tcps)).unwrap();
            }
        }
        let mut bad = tcps;
        bad[1].x = Real::NAN;
        assert_eq!(c.check(at(cycle + 1, &bad)).unwrap().status, ProtectiveStatus::NonFinite(1));
        assert!(!c.contact.is_kept());
        s.tcps_at(cycle as u32 + 2, &mut tcps);
        c.check(at(cycle + 2, &tcps)).unwrap();
        assert!(speeds_unknown(&c));
        s.tcps_at(cycle as u32 + 3, &mut tcps);
        c.check(at(cycle + 3, &tcps)).unwrap();
        assert!(!speeds_unknown(&c));
        c.reset();
        assert!(!c.contact.is_kept() && c.calls.time.is_none());
        c.check(at(cycle + 3, &tcps)).unwrap();
        assert!(speeds_unknown(&c), "after reset the same cycle is computed again");
    }

    #[test]
    fn far_apart_and_still_is_free_and_close_at_speed_is_stop() {
        let mut c = checker("T1");
        let (a, b) = (Vec3::new(-150.0, 0.0, -450.0), Vec3::new(150.0, 0.0, -450.0));
        // First tick: full speed assumed.
        let r = c.check(&[a, b]).unwrap().clone();
        assert_eq!(r.status, ProtectiveStatus::Ok);
        assert_eq!(r.robots[0].speed_bound_mm_s, 4_600.0);
        // Standing still: the bound is the reaction only. The search without a cap finds both
        // limits at once; the capped one (a few tests per tick) reaches them a few ticks later.
        let mut uncapped = c.clone().with_limit_tests(u32::MAX);
        let r = uncapped.check(&[a, b]).unwrap();
        assert!(r.robots.iter().all(|x| x.speed_limit_mm_s > 0.0), "{r:?}");
        let r = c.check(&[a, b]).unwrap().clone();
        assert_eq!(r.verdict, Protective::Free, "{r:?}");
        assert!(r.clearance_mm > 100.0);
        for _ in 0..3 {
            c.check(&[a, b]).unwrap();
        }
        assert!(c.report().robots.iter().all(|x| x.speed_limit_mm_s > 0.0), "{:?}", c.report());
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
        assert_eq!(
            (r.verdict, r.status),
            (Protective::Stop, ProtectiveStatus::ImplausibleMotion(0))
        );
        let r = c.check(&[a, Vec3::new(0.0, 0.0, 100.0)]).unwrap();
        assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::Unreachable(1)));
        let r = c.check(&[a, Vec3::new(Real::NAN, 0.0, -450.0)]).unwrap();
        assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::NonFinite(1)));
    }
}
