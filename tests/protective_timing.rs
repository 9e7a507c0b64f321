//! A timing adversary against the protective verdict (SPEC §8; `cell/protective/clock.rs`).
//! The controller's calls repeat a cycle (with the same TCPs and with others), skip cycles,
//! go backwards, come with jittered or early timestamps, switch clocks and interleave with
//! untimed calls and with `check_at_speeds`, on the reference runs of T1-T3 and on seeded
//! pick-and-place runs of three cells of our own (`cells/r60.toml`, `h80.toml`, `d380.toml`),
//! none of which the verdict was tuned on. Asserted:
//! - every injected timing fault answers STOP with its own status, and the next call has no
//!   previous TCP (full speed);
//! - a repeated cycle with the same TCPs answers the first call's report unchanged;
//! - every other call's measured speed is the displacement over the real interval;
//! - no FREE or WARN where a stop of the true motion touches: the programme followed for the
//!   reaction and one tick, then braking straight at the model's deceleration, both robots on
//!   one clock, checked with the exact model every 0.2 ms; and on a sample of the closest
//!   FREE/WARN calls, no contact for the worst stop that the adversary of
//!   `protective_common::adversary` finds within the model.
//!
//! The oracle has teeth: the untimed call made twice per cycle (what the timed call replaces)
//! answers FREE or WARN where that stop of the true motion touches.

use delta_collide::cell::protective::{
    Protective, ProtectiveChecker, ProtectiveReport, ProtectiveRequest, ProtectiveStatus, TickTime,
    TimingFault,
};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, Waypoint, RUN_TICKS};
use delta_collide::cell::{parse_cell, Cell, ExactChecker};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::{RobotBoxes, StopModel};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

mod protective_common;
use protective_common::adversary::{clearance_at, worst_stop, Robot};
use protective_common::{allocations, toward_other};

/// The stopping model of the dense runs that found the hazard: 3 ms reaction, 40 m/s^2
/// braking, 150 m/s^2 and 5 m/s at most.
const MODEL: StopModel = StopModel {
    reaction_ms: 3.0,
    decel_mm_s2: 40_000.0,
    max_accel_mm_s2: 150_000.0,
    max_speed_mm_s: 5_000.0,
};

/// Tick (ms) of every run.
const TICK_MS: Real = 1.0;

/// Step of the simulated stops (s).
const STOP_STEP_S: Real = 0.2e-3;

/// One run: a cell and each robot's programme.
struct Run {
    name: String,
    cell: Cell,
    robots: Vec<Vec<Waypoint>>,
}

/// Robot's TCP at time `t` (ticks, not necessarily whole) along `w`: the minimum-jerk motion
/// between waypoints that `c_harness/scenarios.txt` defines, written here from that text.
fn position(w: &[Waypoint], t: Real) -> Vec3 {
    let Some(i) = w.iter().rposition(|p| Real::from(p.tick) <= t) else { return w[0].tcp };
    let Some(b) = w.get(i + 1) else { return w[i].tcp };
    let a = &w[i];
    let tau = ((t - Real::from(a.tick)) / Real::from(b.tick - a.tick)).clamp(0.0, 1.0);
    let s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    a.tcp + (b.tcp - a.tcp) * s
}

/// The velocity (mm/s) at time `t` (ticks), by a central difference over 1 us.
fn velocity(w: &[Waypoint], t: Real) -> Vec3 {
    let h = 1e-3;
    (position(w, t + h) - position(w, t - h)) / (2.0 * h * TICK_MS * 1e-3)
}

fn with_model(cell: Cell) -> Cell {
    cell.with_stopping(TICK_MS, vec![MODEL; 2]).unwrap()
}

/// The practical and collision runs of T1, T2 and T3.
fn reference_runs() -> Vec<Run> {
    let text = include_str!("../c_harness/scenarios.txt");
    let runs = parse_scenarios(text).unwrap().into_iter();
    runs.map(|s| Run {
        name: format!("{} {}", s.cell, s.case),
        cell: with_model(reference_cell(&s.cell).unwrap()),
        robots: s.robots,
    })
    .collect()
}

/// A reachable TCP of robot `j` at `radius` toward (or, negative, away from) the other
/// robot, `side` across, `z` deep: pulled toward the axis until reachable.
fn reachable(cell: &Cell, j: usize, radius: Real, side: Real, z: Real) -> Vec3 {
    let d = toward_other(cell, j);
    let across = Vec3::new(-d.y, d.x, 0.0);
    let mut k = 1.0;
    loop {
        let p = (d * radius + across * side) * k + Vec3::new(0.0, 0.0, z);
        if cell.robots[j].model.delta.is_reachable(&p) {
            return p;
        }
        k -= 0.05;
    }
}

/// Seeded pick-and-place programmes on `cell`: each robot picks on its far side and places
/// toward the other over an arch (a hop between), cycles of 300-420 ms. Practical: the
/// robots place in turn, half a cycle apart, 150-190 mm out; collision: from the fourth cycle
/// on they place at the same time, halfway to the other base, where their links meet.
fn programme(cell: &Cell, collide: bool, rng: &mut StdRng) -> Vec<Vec<Waypoint>> {
    let spacing = (cell.robots[1].placement.t - cell.robots[0].placement.t).xy().norm();
    let mut robots = vec![Vec::new(), Vec::new()];
    for (j, w) in robots.iter_mut().enumerate() {
        let mut tick = if collide || j == 0 { 200 } else { 380 };
        w.push(Waypoint { tick: 0, tcp: reachable(cell, j, -100.0, 0.0, -460.0) });
        let mut cycle = 0;
        while tick < RUN_TICKS - 400 {
            let radius =
                if collide && cycle >= 3 { spacing / 2.0 } else { rng.random_range(150.0..190.0) };
            let pick = reachable(
                cell,
                j,
                rng.random_range(-140.0..-90.0),
                rng.random_range(-60.0..60.0),
                -480.0,
            );
            let place = reachable(
                cell,
                j,
                radius,
                rng.random_range(-40.0..40.0),
                rng.random_range(-490.0..-450.0),
            );
            let hop = (pick + place) / 2.0 + Vec3::new(0.0, 0.0, 50.0);
            let leg = rng.random_range(95..125);
            for p in [hop, place, hop, pick] {
                tick += leg;
                w.push(Waypoint { tick, tcp: p });
            }
            cycle += 1;
        }
    }
    if collide {
        // Both robots' legs drawn alike but not equal: bring robot 1 onto robot 0's ticks.
        let ticks: Vec<u32> = robots[0].iter().map(|w| w.tick).collect();
        robots[1].truncate(ticks.len());
        robots[1].iter_mut().zip(&ticks).for_each(|(w, &t)| w.tick = t);
    }
    robots
}

/// The runs of the cells of our own, from `seed`.
fn own_runs(seed: u64) -> Vec<Run> {
    let mut rng = StdRng::seed_from_u64(seed);
    let files = [
        ("R60", include_str!("../cells/r60.toml")),
        ("H80", include_str!("../cells/h80.toml")),
        ("D380", include_str!("../cells/d380.toml")),
    ];
    let mut runs = Vec::new();
    for (name, text) in files {
        let cell = with_model(parse_cell(text).unwrap());
        for (case, collide) in [("practical", false), ("collision", true)] {
            let robots = programme(&cell, collide, &mut rng);
            runs.push(Run { name: format!("{name} {case}"), cell: cell.clone(), robots });
        }
    }
    runs
}

/// The least signed clearance (mm) over a stop issued at time `t` (ticks) and taking effect
/// one tick later: each robot follows its programme for the reaction and that tick, then
/// brakes on a straight line along its velocity then at the model's deceleration until it
/// stands; both on one clock, every [`STOP_STEP_S`].
fn true_stop_clearance(run: &Run, exact: &ExactChecker, t: Real) -> Real {
    let stop = MODEL;
    let latency_s = (stop.reaction_ms + TICK_MS) * 1e-3;
    let braking: Vec<(Vec3, Vec3, Real)> = run
        .robots
        .iter()
        .map(|w| {
            let t_brake = t + latency_s * 1e3 / TICK_MS;
            let v = velocity(w, t_brake);
            (position(w, t_brake), v, v.norm() / stop.decel_mm_s2)
        })
        .collect();
    let end_s = latency_s + braking.iter().map(|b| b.2).fold(0.0, Real::max);
    let mut boxes = [RobotBoxes::empty(), RobotBoxes::empty()];
    let mut least = Real::INFINITY;
    let steps = (end_s / STOP_STEP_S).ceil() as usize;
    for k in 0..=steps {
        let tau = (k as Real * STOP_STEP_S).min(end_s);
        let tcps: [Vec3; 2] = std::array::from_fn(|j| {
            if tau <= latency_s {
                return position(&run.robots[j], t + tau * 1e3 / TICK_MS);
            }
            let (p, v, stop_s) = braking[j];
            let s = (tau - latency_s).min(stop_s);
            let speed = v.norm();
            if speed == 0.0 {
                return p;
            }
            p + v / speed * (speed * s - 0.5 * stop.decel_mm_s2 * s * s)
        });
        least = least.min(clearance_at(exact, &mut boxes, &tcps));
    }
    least
}

/// How a controller calls, each a way of getting time wrong.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Schedule {
    /// Once per cycle, the cycle counter (the baseline).
    EveryCycle,
    /// Twice per cycle with the same TCPs (a function block called in two places).
    Repeat,
    /// Now and then a second call of the cycle with other TCPs (two tasks on one handle).
    RepeatOther,
    /// Skips of 1-3 cycles, now and then of 5-9 (a stalled task).
    Skips,
    /// Now and then an older cycle sent again (calls reordered).
    Backwards,
    /// Timestamps jittered by up to 30 % of a tick, the TCPs taken at the true time.
    Jitter,
    /// Jittered timestamps, now and then an extra call 0.3 ticks after the last.
    Early,
    /// Cycle counter, now and then an untimed call, a `check_at_speeds` or a timestamp between.
    Mixed,
}

const SCHEDULES: [Schedule; 8] = [
    Schedule::EveryCycle,
    Schedule::Repeat,
    Schedule::RepeatOther,
    Schedule::Skips,
    Schedule::Backwards,
    Schedule::Jitter,
    Schedule::Early,
    Schedule::Mixed,
];

/// What one run under one schedule gave.
#[derive(Default, Debug)]
struct Tally {
    calls: usize,
    free_warn: usize,
    stops: usize,
    faults: usize,
    repeats: usize,
    /// FREE/WARN calls whose true stop was simulated, and the least clearance it reached.
    simulated: usize,
    least_true: Real,
    /// FREE/WARN calls searched by the adversary, and the least clearance it reached.
    searched: usize,
    least_worst: Real,
    /// FREE/WARN calls whose true stop touched (must stay 0 for timed calls).
    touched: usize,
}

/// The checker's call and what the test knows of it.
struct Driver<'a> {
    run: &'a Run,
    checker: ProtectiveChecker,
    exact: ExactChecker,
    tally: Tally,
    /// The last call the checker kept as history: its time (s) and TCPs.
    history: Option<(Real, [Vec3; 2])>,
    /// The last call: time, TCPs, report.
    last: Option<(TickTime, [Vec3; 2], ProtectiveReport)>,
    evaluations: usize,
    search_budget: usize,
    rng: StdRng,
}

impl<'a> Driver<'a> {
    fn new(run: &'a Run, seed: u64, evaluations: usize) -> Self {
        Driver {
            run,
            checker: ProtectiveChecker::new(run.cell.clone(), 10.0).unwrap(),
            exact: ExactChecker::new(run.cell.clone()),
            tally: Tally {
                least_true: Real::INFINITY,
                least_worst: Real::INFINITY,
                ..Default::default()
            },
            history: None,
            last: None,
            evaluations,
            search_budget: 6,
            rng: StdRng::seed_from_u64(seed),
        }
    }

    fn tcps(&self, t: Real) -> [Vec3; 2] {
        std::array::from_fn(|j| position(&self.run.robots[j], t))
    }

    /// One call at true time `t` (ticks) with `time` and `tcps`; `fault` is the fault the
    /// schedule injected (if any). Checks the answer; returns the report.
    fn call(
        &mut self,
        time: TickTime,
        t: Real,
        tcps: [Vec3; 2],
        fault: Option<TimingFault>,
    ) -> ProtectiveReport {
        let name = &self.run.name;
        let r = self.checker.check(ProtectiveRequest::new(&tcps).at(time)).unwrap().clone();
        self.tally.calls += 1;
        let repeat = self.last.as_ref().is_some_and(|(lt, lp, _)| *lt == time && *lp == tcps);
        if repeat && time != TickTime::Nominal {
            let first = &self.last.as_ref().unwrap().2;
            // Compared as printed: a NaN clearance (a STOP without a proof) equals itself there.
            let (got, want) = (format!("{r:?}"), format!("{first:?}"));
            assert_eq!(
                got, want,
                "{name}: a repeated cycle must answer the first call's report, at {time:?}"
            );
            self.tally.repeats += 1;
            return r;
        }
        let previous = self.history;
        if let Some(f) = fault {
            let (verdict, status) = (r.verdict, r.status);
            assert_eq!(
                (verdict, status),
                (Protective::Stop, ProtectiveStatus::Timing(f)),
                "{name} at {time:?}"
            );
            self.tally.faults += 1;
            self.history = None;
        } else {
            self.check_speeds(&r, t, &tcps, time, previous);
            self.history = (r.status == ProtectiveStatus::Ok).then_some((t * TICK_MS * 1e-3, tcps));
            if r.status == ProtectiveStatus::Ok && r.verdict != Protective::Stop {
                self.check_stop(&r, t, &tcps, previous);
            }
        }
        match r.verdict {
            Protective::Stop => self.tally.stops += 1,
            _ => self.tally.free_warn += 1,
        }
        self.last = Some((time, tcps, r.clone()));
        r
    }

    /// The measured speeds are the displacement over the real interval since the last call
    /// kept as history, or unknown (no previous TCP: full speed) when there is none or the
    /// clock gave nothing to measure from (a timed call after an untimed one or of the other
    /// clock).
    fn check_speeds(
        &self,
        r: &ProtectiveReport,
        t: Real,
        tcps: &[Vec3; 2],
        time: TickTime,
        previous: Option<(Real, [Vec3; 2])>,
    ) {
        if r.status != ProtectiveStatus::Ok {
            return;
        }
        let last = self.last.as_ref().map(|l| l.0);
        let measurable = matches!(
            (last, time),
            (_, TickTime::Nominal)
                | (Some(TickTime::Cycle(_)), TickTime::Cycle(_))
                | (Some(TickTime::Nanos(_)), TickTime::Nanos(_))
        );
        for j in 0..2 {
            let got = r.robots[j].speed_mm_s;
            match previous.filter(|_| measurable) {
                Some((t0, p0)) => {
                    let want = (tcps[j] - p0[j]).norm() / (t * TICK_MS * 1e-3 - t0);
                    let name = &self.run.name;
                    assert!(
                        (got - want).abs() <= 1e-6 * want.max(1.0),
                        "{name}: speed {got} != {want} at {time:?}"
                    );
                }
                None => assert_eq!(
                    got,
                    Real::INFINITY,
                    "{}: no previous TCP, at {time:?}",
                    self.run.name
                ),
            }
        }
    }

    /// A FREE or WARN call: its true stop, and on a sample the worst stop the model allows
    /// from what the checker measured, never touch.
    fn check_stop(
        &mut self,
        r: &ProtectiveReport,
        t: Real,
        tcps: &[Vec3; 2],
        previous: Option<(Real, [Vec3; 2])>,
    ) {
        // Every call near the other robot; one in ten farther out (the oracle's budget).
        if r.clearance_mm > 120.0 && self.rng.random_range(0..10) != 0 {
            return;
        }
        let name = &self.run.name;
        let least = true_stop_clearance(self.run, &self.exact, t);
        self.tally.simulated += 1;
        self.tally.least_true = self.tally.least_true.min(least);
        self.tally.touched += usize::from(least <= 0.0);
        assert!(
            least > 0.0,
            "{name}: {:?} at t = {t} ticks, yet its true stop reaches {least} mm",
            r.verdict
        );
        if r.clearance_mm > 60.0 || self.search_budget == 0 || self.rng.random_range(0..4) != 0 {
            return;
        }
        self.search_budget -= 1;
        let (now_s, tick_s) = (t * TICK_MS * 1e-3, TICK_MS * 1e-3);
        // What the checker assumed: the measured velocity over the real interval, or (no
        // previous TCP) any speed, of which the true velocity is one.
        let robots: [Robot; 2] = std::array::from_fn(|j| {
            let (v_fd, interval_s) = match previous.filter(|_| r.robots[j].speed_mm_s.is_finite()) {
                Some((t0, p0)) => ((tcps[j] - p0[j]) / (now_s - t0), now_s - t0),
                None => (velocity(&self.run.robots[j], t), tick_s),
            };
            Robot { tcp: tcps[j], v_fd, stop: MODEL, tick_s, interval_s }
        });
        let (worst, at) = worst_stop(&self.run.cell, &robots, self.evaluations, &mut self.rng);
        self.tally.searched += 1;
        self.tally.least_worst = self.tally.least_worst.min(worst);
        assert!(
            worst > 0.0,
            "{name}: {:?} at t = {t}, yet a stop the model allows reaches {worst} mm at {at:?}",
            r.verdict
        );
    }
}

/// Nanoseconds of time `t` (ticks), from an origin far from 0.
fn nanos(t: Real) -> TickTime {
    TickTime::Nanos((1e12 + t * TICK_MS * 1e6).round() as u64)
}

/// One run under one schedule (module doc); panics on any broken promise.
fn drive(run: &Run, schedule: Schedule, seed: u64, evaluations: usize) -> Tally {
    use Schedule::*;
    use TickTime::Cycle;
    let mut d = Driver::new(run, seed, evaluations);
    let mut rng = StdRng::seed_from_u64(seed ^ 0x5eed);
    let (mut c, mut fault) = (0u64, None);
    // The true time (ticks) of the last timestamped call.
    let mut t_last: Real = -1.0;
    while c < u64::from(RUN_TICKS) {
        let t = c as Real;
        let p = d.tcps(t);
        match schedule {
            EveryCycle => drop(d.call(Cycle(c), t, p, fault.take())),
            Repeat => {
                d.call(Cycle(c), t, p, fault.take());
                d.call(Cycle(c), t, p, None);
            }
            RepeatOther => {
                d.call(Cycle(c), t, p, fault.take());
                if rng.random_range(0..30) == 0 {
                    let other = d.tcps(t + 1.0).map(|q| q + Vec3::new(0.0, 0.0, 1e-3));
                    d.call(Cycle(c), t, other, Some(TimingFault::Repeated));
                }
            }
            Skips => {
                d.call(Cycle(c), t, p, fault.take());
                let gap = match rng.random_range(0..100) {
                    0 => rng.random_range(5..10),
                    1..10 => rng.random_range(2..5),
                    _ => 1,
                };
                fault = (gap > 4).then_some(TimingFault::Jump);
                c += gap - 1;
            }
            Backwards => {
                d.call(Cycle(c), t, p, fault.take());
                if c >= 3 && rng.random_range(0..100) == 0 {
                    d.call(Cycle(c - 3), t - 3.0, d.tcps(t - 3.0), Some(TimingFault::Backwards));
                }
            }
            Jitter | Early => {
                // Whole nanoseconds, so that the test's intervals are the checker's.
                let t_true =
                    ((t + rng.random_range(-0.2..0.2)).max(t_last + 0.6) * 1e6).round() / 1e6;
                d.call(nanos(t_true), t_true, d.tcps(t_true), fault.take());
                t_last = t_true;
                if schedule == Early && rng.random_range(0..100) == 0 {
                    let t_early = t_true + 0.3;
                    d.call(nanos(t_early), t_early, d.tcps(t_early), Some(TimingFault::Early));
                    t_last = t_early;
                }
            }
            Mixed => match rng.random_range(0..200) {
                // An untimed call is never a timing fault, and the next timed call starts over.
                0 | 1 => drop((d.call(TickTime::Nominal, t, p, None), fault.take())),
                2 | 3 => {
                    let speeds = [MODEL.max_speed_mm_s; 2];
                    d.checker.check_at_speeds(&p, &speeds).unwrap();
                    d.call(Cycle(c), t, p, fault.take());
                    // A repeat after it still answers the cycle's report.
                    d.call(Cycle(c), t, p, None);
                }
                4 => {
                    // A timestamp after the cycle counter (after an untimed call: a new start).
                    let after_cycle = matches!(d.last, Some((Cycle(_), _, _)));
                    d.call(nanos(t), t, p, after_cycle.then_some(TimingFault::ClockChanged));
                    fault = Some(TimingFault::ClockChanged);
                }
                _ => drop(d.call(Cycle(c), t, p, fault.take())),
            },
        }
        c += 1;
    }
    d.tally
}

fn evaluations() -> usize {
    std::env::var("ADVERSARY_EVALUATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(150)
}

/// Every schedule on every run of `runs`; prints one line per run and schedule.
fn every_schedule(runs: &[Run]) {
    let evaluations = evaluations();
    for (i, run) in runs.iter().enumerate() {
        for (k, &schedule) in SCHEDULES.iter().enumerate() {
            let t = drive(run, schedule, 1000 * i as u64 + k as u64, evaluations);
            println!(
                "{:<16} {:<12} calls {:>5}  free/warn {:>5}  stop {:>5}  faults {:>3}  repeats {:>5}  \
                 true stops {:>4} (least {:>7.2} mm)  searched {:>2} (least {:>7.2} mm)",
                run.name,
                format!("{schedule:?}"),
                t.calls,
                t.free_warn,
                t.stops,
                t.faults,
                t.repeats,
                t.simulated,
                t.least_true,
                t.searched,
                t.least_worst
            );
            assert_eq!(t.touched, 0);
        }
    }
}

#[test]
fn timing_faults_fail_closed_on_the_reference_runs() {
    every_schedule(&reference_runs());
}

#[test]
fn timing_faults_fail_closed_on_runs_of_cells_of_our_own() {
    every_schedule(&own_runs(46));
}

/// The hazard the timed call removes: the untimed call made a second time in a cycle reads a
/// displacement of 0 as a robot that stands, and answers FREE or WARN where a stop of the
/// true motion touches (on the collision runs, where the robots close in at full speed).
#[test]
fn the_untimed_call_twice_per_cycle_answers_free_where_a_stop_touches() {
    let mut runs: Vec<Run> =
        reference_runs().into_iter().filter(|r| r.name.ends_with("collision")).collect();
    runs.extend(own_runs(46).into_iter().filter(|r| r.name.ends_with("collision")));
    let mut touched_total = 0;
    for run in &runs {
        let mut checker =
            ProtectiveChecker::new(run.cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let exact = ExactChecker::new(run.cell.clone());
        let (mut better, mut touched) = (0, 0);
        for c in 0..RUN_TICKS {
            let p: [Vec3; 2] = std::array::from_fn(|j| position(&run.robots[j], Real::from(c)));
            let first = checker.check(&p).unwrap().verdict;
            let second = checker.check(&p).unwrap().clone();
            if second.status == ProtectiveStatus::Ok && second.verdict < first {
                better += 1;
                if second.clearance_mm < 150.0
                    && true_stop_clearance(run, &exact, Real::from(c)) <= 0.0
                {
                    touched += 1;
                }
            }
        }
        println!("{:<16} untimed second call better than the first on {better:>4} ticks, {touched:>3} of them touch", run.name);
        touched_total += touched;
    }
    assert!(touched_total > 0, "the oracle found no FREE/WARN of the untimed repeat that touches");
}

/// At the nominal timing the timed call is the untimed one: once per cycle, with each cycle's
/// call made twice, it answers every tick of every run, the line of four included, as the
/// untimed call made once per cycle (the same reports), and allocates nothing; a fault on
/// the line is STOP there too.
#[test]
fn timed_calls_at_the_nominal_timing_answer_as_the_untimed_calls() {
    let mut runs: Vec<Run> = reference_runs();
    let line = include_str!("../c_harness/line_scenarios.txt");
    let line_cell = parse_cell(include_str!("../cells/line4.toml")).unwrap();
    for s in parse_scenarios(line).unwrap() {
        let cell = line_cell.clone().with_stopping(TICK_MS, vec![MODEL; 4]).unwrap();
        runs.push(Run { name: format!("{} {}", s.cell, s.case), cell, robots: s.robots });
    }
    for run in &runs {
        let mut timed = ProtectiveChecker::new(run.cell.clone(), 10.0).unwrap();
        let mut untimed = timed.clone();
        let n = run.robots.len();
        for c in 0..RUN_TICKS {
            let p: Vec<Vec3> = (0..n).map(|j| position(&run.robots[j], Real::from(c))).collect();
            let want = format!("{:?}", untimed.check(&p).unwrap());
            let request = ProtectiveRequest::new(&p).at(TickTime::Cycle(u64::from(c)));
            let before = allocations();
            timed.check(request).unwrap();
            let first = allocations() - before;
            assert_eq!(format!("{:?}", timed.report()), want, "{} tick {c}", run.name);
            let before = allocations();
            timed.check(request).unwrap();
            assert_eq!((first, allocations() - before), (0, 0), "{}: tick {c} allocated", run.name);
            assert_eq!(format!("{:?}", timed.report()), want, "{} tick {c}, again", run.name);
        }
        let p: Vec<Vec3> =
            (0..n).map(|j| position(&run.robots[j], Real::from(RUN_TICKS))).collect();
        let r = timed.check(ProtectiveRequest::new(&p).at(TickTime::Cycle(3))).unwrap();
        assert_eq!(
            (r.verdict, r.status),
            (Protective::Stop, ProtectiveStatus::Timing(TimingFault::Backwards))
        );
    }
}
