//! One closed-loop run (SPEC §9): every tick the controller reads each robot's TCP from its
//! progress along its programme, asks the library (coordination, then the protective
//! verdict), and applies the answer: the override, or a STOP. A STOP is simulated as the
//! stopping model allows it: for the reaction and one tick each robot goes on along its
//! programme at its override, then brakes along the path at `decel_mm_s2`. A robot standing
//! and held this tick (by the coordination, else by the override) passes a one-point stop
//! path (docs/PROTECTIVE.md). Every tick and every
//! [`STOP_STEP_S`] of every stop is checked for contact by the exact check (`cell::exact`),
//! which shares no code with the protective proof or the coordination.

use super::interlock::Interlock;
use super::programme::Programmes;
use super::{Mode, RunMetrics, SimConfig, Timings};
use crate::cell::protective::{
    path_through_samples, Protective, ProtectiveChecker, ProtectiveRequest, StopPath, TickTime,
};
use crate::cell::{Cell, ExactChecker};
use crate::coord::speed::ramped;
use crate::coord::{Coordinator, Programme, MAX_SAMPLES};
use crate::math::{Real, Vec3};
use std::time::Instant;

/// Step of the simulated stops (s).
pub const STOP_STEP_S: Real = 0.2e-3;

/// Points of a stop path at most (the C ABI's `DC_MAX_PATH_POINTS`).
const PATH_POINTS: usize = 32;

/// Ticks over which a deadlock is measured (SPEC §9: 3 s at 1 ms).
const DEADLOCK_TICKS: usize = 3000;

/// The TCP at progress `s` (programme ticks) of `prog`: linear between set-points.
pub fn tcp_at(prog: &[Vec3], s: Real) -> Vec3 {
    let last = prog.len() - 1;
    let k = (s.floor().max(0.0) as usize).min(last);
    match prog.get(k + 1) {
        Some(next) => prog[k] + (next - prog[k]) * (s - k as Real),
        None => prog[last],
    }
}

/// The programmed speed (mm per programme tick) at progress `s`.
fn rate_at(prog: &[Vec3], s: Real) -> Real {
    let k = (s.floor().max(0.0) as usize).min(prog.len() - 1);
    prog.get(k + 1).map_or(0.0, |n| (n - prog[k]).norm())
}

/// The largest programmed speed (mm per tick) over the next `ticks` from `s`.
fn rate_ahead(prog: &[Vec3], s: Real, ticks: usize) -> Real {
    let k = (s.floor().max(0.0) as usize).min(prog.len() - 1);
    let end = (k + ticks + 1).min(prog.len());
    prog[k..end].windows(2).map(|w| (w[1] - w[0]).norm()).fold(0.0, Real::max)
}

/// The controller's right of way over the speed limits: when every robot stands with a limit
/// of 0 (each waits for the others), one robot at a time is released in turn and the others
/// are held, so that they promise to stay where they are (a one-point stop path) and its
/// limit is proved against them standing. A release lasts [`RELEASE_TICKS`]; when all wait
/// again after it, the next robot has its turn.
#[derive(Clone, Copy, Debug, Default)]
struct Release {
    robot: Option<usize>,
    since: u64,
    turn: usize,
}

/// An override below this is a robot waiting (the limits of standing robots are their
/// measured speeds, rounding's specks).
const WAITING: Real = 1e-6;

/// Ticks of one release (module doc of [`Release`]).
const RELEASE_TICKS: u64 = 300;

impl Release {
    fn apply(&mut self, robots: &[Robot], targets: &mut [Real], cycle: u64) {
        let n = robots.len();
        let all_wait =
            robots.iter().all(|r| r.override_now < WAITING) && targets.iter().all(|&t| t < WAITING);
        if let Some(r) = self.robot {
            if cycle - self.since >= RELEASE_TICKS {
                self.robot = None;
            } else {
                for (j, t) in targets.iter_mut().enumerate() {
                    if j != r {
                        *t = 0.0;
                    }
                }
                return;
            }
        }
        if all_wait {
            let r = self.turn % n;
            self.turn += 1;
            (self.robot, self.since) = (Some(r), cycle);
        }
    }
}

/// The override that holds a robot's speed at 0.9 of its speed limit (SPEC §8), at the
/// programmed speed ahead `ahead_mm_s`; 0 for a limit that is NaN or negative.
fn cap_of(limit_mm_s: Real, ahead_mm_s: Real) -> Real {
    let cap = 0.9 * limit_mm_s;
    if cap.is_nan() || cap < 0.0 {
        0.0
    } else if ahead_mm_s > 0.0 {
        (cap / ahead_mm_s).min(1.0)
    } else {
        1.0
    }
}

/// What the loop keeps per robot.
#[derive(Clone, Copy, Debug)]
struct Robot {
    progress: Real,
    override_now: Real,
}

/// What a run did, tick by tick, for its pictures and its trace file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    /// Per tick, each robot's progress (programme ticks).
    pub progress: Vec<Vec<Real>>,
    /// Per STOP event, each robot's progress when it was issued.
    pub stops: Vec<Vec<Real>>,
    /// Per tick, what the controller asked and was answered.
    pub ticks: Vec<TickRecord>,
}

/// One tick of a run as the controller saw it (before the tick's motion).
#[derive(Clone, Debug, PartialEq)]
pub struct TickRecord {
    /// The loop's tick (a STOP's simulated ticks are skipped).
    pub tick: usize,
    /// Per robot, its progress (programme ticks).
    pub progress: Vec<Real>,
    /// Per robot, the override it followed over the last tick.
    pub override_now: Vec<Real>,
    /// Per robot, the coordination's override (1 outside coordinate mode).
    pub coordination: Vec<Real>,
    /// Per robot, the robot whose conflict holds it, if any.
    pub held_by: Vec<Option<usize>>,
    /// The protective verdict.
    pub verdict: Protective,
    /// Per robot, the protective verdict's speed limit (mm/s).
    pub limit_mm_s: Vec<Real>,
    /// The exact signed clearance of the cell (mm).
    pub clearance_mm: Real,
}

/// Runs `programmes` on `cell` in closed loop (module doc).
pub fn run(cell: &Cell, programmes: &Programmes, config: &SimConfig) -> RunMetrics {
    run_traced(cell, programmes, config, None)
}

/// [`run`], recording each tick's progress into `trace` when one is given.
pub fn run_traced(
    cell: &Cell,
    programmes: &Programmes,
    config: &SimConfig,
    mut trace: Option<&mut Trace>,
) -> RunMetrics {
    let n = cell.robots.len();
    let tick_s = cell.tick_ms * 1e-3;
    let mut exact = ExactChecker::new(cell.clone());
    let with_limits = matches!(config.mode, Mode::Limits | Mode::Coordinate);
    let mut protective = ProtectiveChecker::new(cell.clone(), config.warn_mm)
        .expect("a cell that parsed builds a protective checker")
        .with_speed_limits(with_limits)
        .with_path_work(config.path_work);
    let mut coordinator = Coordinator::new(cell.clone(), config.coordination);
    let mut interlock = (config.mode == Mode::Interlock)
        .then(|| Interlock::new(cell, programmes, config.coordination.clearance_mm, 2.0));
    let mut robots = vec![Robot { progress: 0.0, override_now: 0.0 }; n];
    let programmed = programmes.iter().map(|p| p.len() - 1).max().unwrap_or(0);
    let max_ticks = (config.max_ticks_factor * programmed as Real) as usize;
    let mut metrics = RunMetrics { programmed_ticks: programmed, ..RunMetrics::default() };
    let (mut ours, mut coord_ns, mut exact_ns) = (Vec::new(), Vec::new(), Vec::new());
    let mut tcps = vec![Vec3::zeros(); n];
    let mut last_tcps: Vec<Vec3> = programmes.iter().map(|p| p[0]).collect();
    let mut travel = vec![0.0; DEADLOCK_TICKS];
    let mut travel_sum = 0.0;
    let mut paths_buf = vec![[Vec3::zeros(); PATH_POINTS]; n];
    let mut targets = vec![1.0; n];
    let mut wanted = vec![1.0; n];
    let mut held_by: Vec<Option<usize>> = vec![None; n];
    let mut next = vec![0.0; n];
    let mut limits: Vec<Real> = vec![0.0; n];
    let mut last_verdict = Protective::Stop;
    let mut release = Release::default();
    let mut points = vec![[Vec3::zeros(); MAX_SAMPLES]; n];
    let mut cycle: u64 = 0;
    let mut tick = 0usize;
    loop {
        let finished = |r: &Robot, p: &Vec<Vec3>| r.progress >= (p.len() - 1) as Real;
        if robots.iter().zip(programmes).all(|(r, p)| finished(r, p)) {
            metrics.finished = true;
            break;
        }
        if tick >= max_ticks {
            break;
        }
        for j in 0..n {
            tcps[j] = tcp_at(&programmes[j], robots[j].progress);
        }
        // Deadlock: under 1 mm of travel of all robots together over the last 3 s.
        let moved: Real = tcps.iter().zip(&last_tcps).map(|(a, b)| (a - b).norm()).sum();
        travel_sum += moved - travel[tick % DEADLOCK_TICKS];
        travel[tick % DEADLOCK_TICKS] = moved;
        last_tcps.copy_from_slice(&tcps);
        if tick >= DEADLOCK_TICKS && travel_sum < 1.0 {
            metrics.deadlock = true;
            break;
        }
        let t0 = Instant::now();
        let collides = exact.check(&tcps).map(|v| v.collides()).unwrap_or(true);
        exact_ns.push(t0.elapsed().as_nanos() as u64);
        metrics.contact_ticks += usize::from(collides);

        // The controller's call of the coordination (its programmes ahead).
        let mut coordination = 0;
        if config.mode == Mode::Coordinate {
            let stride = config.stride_ticks as usize;
            let mut list = [None; crate::cell::MAX_ROBOTS];
            for j in 0..n {
                let p = &programmes[j];
                let first = (robots[j].progress.floor() as usize / stride) * stride;
                let count = ((p.len() - 1 - first) / stride + 1).min(MAX_SAMPLES);
                for k in 0..count {
                    points[j][k] = p[first + k * stride];
                }
                list[j] = Some((first, count));
            }
            let programmes_ahead: Vec<Programme> = (0..n)
                .map(|j| {
                    let (first, count) = list[j].unwrap();
                    Programme {
                        first_tick: first as u64,
                        stride_ticks: config.stride_ticks,
                        points: &points[j][..count],
                        progress: robots[j].progress.min((first + (count - 1) * stride) as Real),
                        override_now: robots[j].override_now,
                    }
                })
                .collect();
            let request = crate::coord::CoordinationRequest { programmes: &programmes_ahead };
            let t0 = Instant::now();
            let answer = coordinator.coordinate(&request);
            coordination = t0.elapsed().as_nanos() as u64;
            match answer {
                Ok(report) => {
                    for (t, r) in targets.iter_mut().zip(&report.robots) {
                        *t = r.override_factor;
                    }
                    for (h, r) in held_by.iter_mut().zip(&report.robots) {
                        *h = r.held_by;
                    }
                    metrics.cells_tested_max = metrics.cells_tested_max.max(report.cells_tested);
                }
                Err(_) => targets.iter_mut().for_each(|t| *t = 0.0),
            }
        }
        coord_ns.push(coordination);
        // What the coordination asks before the controller's cap: a robot it lets move shows
        // the protective verdict its path, so that its speed limit is the one along the path.
        wanted.copy_from_slice(&targets);

        // The controller's override targets (the speed limits of the last verdict).
        for j in 0..n {
            let ahead = rate_ahead(&programmes[j], robots[j].progress, 8) / tick_s;
            let target = match config.mode {
                Mode::Free => 1.0,
                Mode::Coordinate => targets[j].min(cap_of(limits[j], ahead)),
                Mode::Limits if last_verdict == Protective::Stop => 0.0,
                Mode::Limits => cap_of(limits[j], ahead),
                Mode::Interlock => targets[j],
            };
            targets[j] = target;
        }
        // The coordination has its own right of way; the speed limits alone need this one.
        if config.mode == Mode::Limits {
            release.apply(&robots, &mut targets, cycle);
        }
        if let Some(lock) = interlock.as_mut() {
            let progress: Vec<Real> = robots.iter().map(|r| r.progress).collect();
            let now: Vec<Real> = (0..n)
                .map(|j| {
                    robots[j].override_now * rate_at(&programmes[j], robots[j].progress) / tick_s
                })
                .collect();
            let ahead: Vec<Real> = (0..n)
                .map(|j| rate_ahead(&programmes[j], robots[j].progress, 8) / tick_s)
                .collect();
            lock.targets(cell, programmes, &progress, &now, &ahead, &mut targets);
        }
        for j in 0..n {
            let p = &programmes[j];
            let ahead = rate_ahead(p, robots[j].progress, 8) / tick_s;
            let a_tick = cell.stops[j].max_accel_mm_s2 * tick_s;
            let shares = match config.mode {
                Mode::Limits => (0.5, 0.5),
                Mode::Coordinate => {
                    (config.coordination.speed_up_share, config.coordination.slow_down_share)
                }
                _ => (0.2, 0.45),
            };
            next[j] = ramped(robots[j].override_now, targets[j], ahead, a_tick, shares);
        }

        // The protective verdict, with each robot's programme ahead as its stop path; a robot
        // that stands and is held this tick promises to stay where it is.
        let mut stops: Vec<Option<StopPath>> = Vec::new();
        let mut found = [None; crate::cell::MAX_ROBOTS];
        if config.paths {
            for j in 0..n {
                let p = &programmes[j];
                let k = robots[j].progress.floor() as usize;
                let mut dense = [Vec3::zeros(); 400];
                dense[0] = tcps[j];
                let mut m = 1;
                let stays = if config.mode == Mode::Coordinate { wanted[j] } else { next[j] };
                let held = stays < WAITING && robots[j].override_now < WAITING;
                for q in p.iter().skip(k + 1).take(if held { 0 } else { dense.len() - 1 }) {
                    dense[m] = *q;
                    m += 1;
                }
                let mut got = None;
                for tol in [0.5, 1.0, 2.0, 4.0] {
                    if let Some(c) = path_through_samples(
                        &dense[..m],
                        config.path_length_mm,
                        tol,
                        &mut paths_buf[j],
                    ) {
                        got = Some((c, tol));
                        break;
                    }
                }
                found[j] = got;
            }
            for (j, got) in found.iter().enumerate().take(n) {
                stops.push(
                    got.map(|(c, tol)| StopPath { points: &paths_buf[j][..c], tolerance_mm: tol }),
                );
            }
        }
        let request = ProtectiveRequest::new(&tcps).at(TickTime::Cycle(cycle));
        let request = if config.paths { request.with_paths(&stops) } else { request };
        let t0 = Instant::now();
        let answer = protective.check(request);
        let protective_ns = t0.elapsed().as_nanos() as u64;
        let verdict = match answer {
            Ok(r) => {
                for (l, x) in limits.iter_mut().zip(&r.robots) {
                    *l = x.speed_limit_mm_s;
                }
                metrics.path_work_max = metrics.path_work_max.max(r.path_work);
                metrics.path_work_spent += usize::from(r.path_work_spent);
                r.verdict
            }
            Err(_) => {
                limits.iter_mut().for_each(|l| *l = 0.0);
                Protective::Stop
            }
        };
        last_verdict = verdict;
        if let Some(t) = trace.as_deref_mut() {
            t.ticks.push(TickRecord {
                tick,
                progress: robots.iter().map(|r| r.progress).collect(),
                override_now: robots.iter().map(|r| r.override_now).collect(),
                coordination: if config.mode == Mode::Coordinate {
                    wanted.clone()
                } else {
                    vec![1.0; n]
                },
                held_by: held_by.clone(),
                verdict,
                limit_mm_s: limits.clone(),
                clearance_mm: protective.report().clearance_mm,
            });
        }
        ours.push(coordination + protective_ns);
        metrics.verdicts[verdict as usize] += 1;
        drop(stops);

        let moving = (0..n)
            .any(|j| robots[j].override_now * rate_at(&programmes[j], robots[j].progress) > 0.0);
        if verdict == Protective::Stop && moving {
            metrics.stop_events += 1;
            if let Some(t) = trace.as_deref_mut() {
                t.stops.push(robots.iter().map(|r| r.progress).collect());
            }
            let (ticks, contacts) = simulate_stop(cell, &mut exact, programmes, &mut robots);
            metrics.contact_stop_samples += contacts;
            tick += ticks;
            cycle += ticks as u64;
            protective.reset();
            coordinator.reset();
            for j in 0..n {
                last_tcps[j] = tcp_at(&programmes[j], robots[j].progress);
            }
            continue;
        }

        for j in 0..n {
            let p = &programmes[j];
            let o = if verdict == Protective::Stop { 0.0 } else { next[j] };
            let end = (p.len() - 1) as Real;
            robots[j].progress = (robots[j].progress + o).min(end);
            robots[j].override_now = if robots[j].progress >= end { 0.0 } else { o };
        }
        if let Some(t) = trace.as_deref_mut() {
            t.progress.push(robots.iter().map(|r| r.progress).collect());
        }
        tick += 1;
        cycle += 1;
    }
    metrics.ticks = tick;
    metrics.throughput =
        if metrics.finished && tick > 0 { programmed as Real / tick as Real } else { 0.0 };
    metrics.ours_ns = Timings::of(&mut ours);
    metrics.coordination_ns = Timings::of(&mut coord_ns);
    metrics.exact_ns = Timings::of(&mut exact_ns);
    metrics
}

/// A stop of every robot issued now (module doc): each goes on along its programme at its
/// override for the reaction and one tick, then brakes along its path from the speed it has
/// then at its `decel_mm_s2`, never ahead of its programme at that override (a braking robot
/// is not faster than its programme). Returns the ticks it took and the samples in contact.
fn simulate_stop(
    cell: &Cell,
    exact: &mut ExactChecker,
    programmes: &Programmes,
    robots: &mut [Robot],
) -> (usize, usize) {
    let tick_s = cell.tick_ms * 1e-3;
    let n = robots.len();
    let mut speed = vec![Real::INFINITY; n];
    let (mut t, mut contacts) = (0.0, 0usize);
    let mut tcps = vec![Vec3::zeros(); n];
    // Bounded: the slowest robot stands after v_max / decel plus its reaction.
    let longest = (0..n)
        .map(|j| {
            let s = &cell.stops[j];
            s.reaction_ms * 1e-3 + tick_s + s.max_speed_mm_s / s.decel_mm_s2
        })
        .fold(0.0, Real::max);
    let step_ticks = STOP_STEP_S / tick_s;
    while t <= longest + STOP_STEP_S {
        for j in 0..n {
            let p = &programmes[j];
            let end = (p.len() - 1) as Real;
            let o = robots[j].override_now;
            let rate = rate_at(p, robots[j].progress) / tick_s;
            let along = if t < cell.stops[j].reaction_ms * 1e-3 + tick_s {
                o * step_ticks
            } else {
                if speed[j].is_infinite() {
                    speed[j] = o * rate;
                }
                speed[j] = (speed[j] - cell.stops[j].decel_mm_s2 * STOP_STEP_S).max(0.0);
                let by_speed =
                    if rate > 0.0 { speed[j] * STOP_STEP_S / (rate * tick_s) } else { 0.0 };
                by_speed.min(o * step_ticks)
            };
            robots[j].progress = (robots[j].progress + along).min(end);
            tcps[j] = tcp_at(p, robots[j].progress);
        }
        contacts += usize::from(exact.check(&tcps).map(|v| v.collides()).unwrap_or(true));
        t += STOP_STEP_S;
        if speed.iter().all(|&v| v == 0.0) {
            break;
        }
    }
    for r in robots.iter_mut() {
        r.override_now = 0.0;
    }
    ((t / tick_s).ceil() as usize, contacts)
}
