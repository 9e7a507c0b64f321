//! An adversary against the protective verdict (SPEC §8). Random stopping motions
//! (`tests/protective.rs`) rarely hit the worst one; here, for every FREE or WARN tick, a
//! search over the stops the model allows looks for the one that brings the two robots
//! closest, and none may bring two boxes into contact.
//!
//! A stop of one robot is given by ten numbers, each mapped into the model's limits:
//! - the true velocity now: the finite difference `v_fd` plus up to `a_max T` in any
//!   direction, at most `v_max` (the model's bound on how far they differ);
//! - a constant push during the reaction (`T_r` = reaction time plus one tick, the verdict's
//!   own latency), up to `a_max` in any direction, the speed held under `v_max` (the
//!   velocity projected back onto that ball, which never changes it faster than the push);
//! - where the stop is looked at: a moment of the reaction, or a point of the braking path,
//!   which may run in any direction from where the reaction ends and is at most
//!   `v_r^2 / (2 decel)` long (`v_r` the speed then).
//!
//! The search minimises the exact signed clearance of the two robots over both robots'
//! numbers (twenty in all) with a (1+1) evolution strategy from several starts, one of them
//! each robot pushing and braking toward the other. Every point the model allows for each
//! robot is checked against every point of the other's, whatever the moments: what a FREE
//! proof covers (every TCP of each stop ball against every TCP of the other's), and more than
//! a stop at one common moment needs. Unreachable TCPs are not physical: left out.
//!
//! That the search has teeth is asserted too: among the STOP ticks, whose robots the proof
//! could not keep apart, it finds stops that bring boxes into contact.

use delta_collide::cell::protective::{Protective, ProtectiveChecker, ProtectiveStatus};
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::{RobotBoxes, StopModel};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

mod protective_common;
use protective_common::adversary::{random_stop, worst_stop, Objective, Robot};
use protective_common::{cell, tcp_near_reach_boundary, tcp_toward_other, unit, STIFF};

/// The least clearance over as many stops drawn at random (each number uniform in its range)
/// as [`worst_stop`] evaluates: what the search adds over random stops.
fn random_stops(cell: &Cell, robots: &[Robot; 2], evaluations: usize, rng: &mut StdRng) -> Real {
    let mut f = Objective {
        exact: ExactChecker::new(cell.clone()),
        robots,
        boxes: [RobotBoxes::empty(), RobotBoxes::empty()],
    };
    (0..4 * (evaluations + 1))
        .map(|_| f.clearance(&random_stop(rng)))
        .fold(Real::INFINITY, Real::min)
}

/// A tick of `cell` from `tcps` and the finite differences `v_fd`: the verdict (after a first
/// tick at `tcps - v_fd T`, so that the checker knows the speeds) and the robots.
fn tick_of(
    checker: &mut ProtectiveChecker,
    cell: &Cell,
    tcps: [Vec3; 2],
    v_fd: [Vec3; 2],
) -> Option<(Protective, [Robot; 2])> {
    let tick_s = cell.tick_ms * 1e-3;
    checker.reset();
    checker.check(&[tcps[0] - v_fd[0] * tick_s, tcps[1] - v_fd[1] * tick_s]).unwrap();
    let r = checker.check(&tcps).unwrap();
    (r.status == ProtectiveStatus::Ok).then(|| {
        (
            r.verdict,
            std::array::from_fn(|j| Robot {
                tcp: tcps[j],
                v_fd: v_fd[j],
                stop: cell.stops[j],
                tick_s,
                interval_s: tick_s,
            }),
        )
    })
}

/// What the adversary found over some ticks.
#[derive(Default)]
struct Tally {
    /// FREE or WARN ticks searched, and the least clearance reached over them (mm).
    proved: usize,
    least: Real,
    /// The least clearance of as many random stops over the same ticks (mm), when asked.
    random: Real,
    /// STOP ticks searched, those where it found contact, and the least clearance it reached
    /// in each of the others (mm): how far from contact those STOPs were.
    stops: usize,
    touched: usize,
    spared: Vec<Real>,
}

impl Tally {
    fn new() -> Self {
        Tally { least: Real::INFINITY, random: Real::INFINITY, ..Default::default() }
    }

    /// Searches the stops of one tick; panics when a FREE or WARN tick's stop touches.
    fn search(
        &mut self,
        cell: &Cell,
        verdict: Protective,
        robots: &[Robot; 2],
        evaluations: usize,
        rng: &mut StdRng,
    ) {
        let (least, tcps) = worst_stop(cell, robots, evaluations, rng);
        if verdict == Protective::Stop {
            self.stops += 1;
            self.touched += usize::from(least <= 0.0);
            if least > 0.0 {
                self.spared.push(least);
            }
            return;
        }
        let contact = ExactChecker::new(cell.clone()).check(&tcps).unwrap().collides();
        assert!(
            least > 0.0 && !contact,
            "{verdict:?} tick, yet a stop the model allows reaches clearance {least} mm at TCPs {tcps:?} \
             (from {:?} {:?}, v_fd {:?} {:?})",
            robots[0].tcp,
            robots[1].tcp,
            robots[0].v_fd,
            robots[1].v_fd
        );
        self.proved += 1;
        self.least = self.least.min(least);
    }

    /// The least, median and largest of [`Tally::spared`] (NaN when empty).
    fn spared_range(&mut self) -> (Real, Real, Real) {
        self.spared.sort_by(Real::total_cmp);
        let at = |i: usize| self.spared.get(i).copied().unwrap_or(Real::NAN);
        (at(0), at(self.spared.len() / 2), at(self.spared.len().wrapping_sub(1)))
    }

    /// As [`Tally::search`], with random stops beside it on FREE and WARN ticks.
    fn search_and_draw(
        &mut self,
        cell: &Cell,
        verdict: Protective,
        robots: &[Robot; 2],
        evaluations: usize,
        rng: &mut StdRng,
    ) {
        self.search(cell, verdict, robots, evaluations, rng);
        if verdict != Protective::Stop {
            self.random = self.random.min(random_stops(cell, robots, evaluations, rng));
        }
    }
}

/// Evaluations per start of the search on random ticks: 400, or `ADVERSARY_EVALUATIONS`.
fn evaluations() -> usize {
    std::env::var("ADVERSARY_EVALUATIONS")
        .map_or(400, |v| v.parse().expect("ADVERSARY_EVALUATIONS: a count"))
}

/// Random ticks with the robots reaching toward each other (and near their reach boundary,
/// where elbows swing fastest), speeds mostly low, directions random.
#[test]
fn no_stop_the_model_allows_touches_after_a_free_verdict() {
    let mut all = Tally::new();
    for (i, name) in ["T1", "T2", "T3"].iter().enumerate() {
        for (k, stop) in [STIFF, StopModel::DEFAULT].into_iter().enumerate() {
            let cell = cell(name, stop);
            let mut checker =
                ProtectiveChecker::new(cell.clone(), 5.0).unwrap().with_speed_limits(false);
            let mut rng = StdRng::seed_from_u64(900 + 10 * i as u64 + k as u64);
            // The search draws from its own stream: the ticks do not depend on its budget.
            let mut search = StdRng::seed_from_u64(1900 + 10 * i as u64 + k as u64);
            let mut tally = Tally::new();
            for state in 0..120 {
                let sample =
                    if state % 2 == 0 { tcp_toward_other } else { tcp_near_reach_boundary };
                let tcps = [sample(&cell, 0, &mut rng), sample(&cell, 1, &mut rng)];
                let v_fd = std::array::from_fn(|_| {
                    unit(&mut rng) * stop.max_speed_mm_s * rng.random::<Real>().powi(3)
                });
                let Some((verdict, robots)) = tick_of(&mut checker, &cell, tcps, v_fd) else {
                    continue;
                };
                // Every FREE and WARN tick; one STOP tick in four (to show the search's teeth).
                if verdict != Protective::Stop || state % 4 == 0 {
                    tally.search_and_draw(&cell, verdict, &robots, evaluations(), &mut search);
                }
            }
            println!(
                "{name} model {k}: {} FREE/WARN ticks, least clearance reached {:.3} mm (random stops {:.3} mm); \
                 {} of {} STOP ticks brought into contact",
                tally.proved, tally.least, tally.random, tally.touched, tally.stops
            );
            all.proved += tally.proved;
            all.least = all.least.min(tally.least);
            all.random = all.random.min(tally.random);
            all.stops += tally.stops;
            all.touched += tally.touched;
        }
    }
    println!(
        "in all: {} FREE/WARN ticks searched, least clearance {:.3} mm (random stops {:.3} mm)",
        all.proved, all.least, all.random
    );
    assert!(all.proved >= 60, "too few FREE ticks to search: {}", all.proved);
    assert!(
        all.least < all.random,
        "the search gets no closer than random stops: {} {}",
        all.least,
        all.random
    );
    assert!(
        all.touched * 4 >= all.stops,
        "the search finds contact in too few STOP ticks: {} of {}",
        all.touched,
        all.stops
    );
}

/// The ticks of the C harness's runs (practical and collision, T1-T3, both models), where
/// most FREE ticks reuse a proof kept from an earlier tick: every 25th FREE or WARN tick, and
/// every 25th STOP tick, to count those where some allowed stop reaches contact (the others
/// are STOPs that a tighter proof might spare: the search found no contact, which proves
/// nothing but bounds what a tighter proof could gain).
#[test]
fn no_stop_the_model_allows_touches_along_the_scenarios() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let mut rng = StdRng::seed_from_u64(31);
    let mut all = Tally::new();
    for s in parse_scenarios(&text).unwrap() {
        for (k, stop) in [STIFF, StopModel::DEFAULT].into_iter().enumerate() {
            let cell = cell(&s.cell, stop);
            let tick_s = cell.tick_ms * 1e-3;
            let mut checker =
                ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
            let (mut tcps, mut prev) = ([Vec3::zeros(); 2], [Vec3::zeros(); 2]);
            let mut tally = Tally::new();
            let mut seen = [0; 2];
            for t in 0..RUN_TICKS {
                s.tcps_at(t, &mut tcps);
                let verdict = checker.check(&tcps).unwrap().verdict;
                let count = &mut seen[usize::from(verdict == Protective::Stop)];
                *count += 1;
                if t > 0 && *count % 25 == 0 {
                    let v_fd = |j: usize| (tcps[j] - prev[j]) / tick_s;
                    let robots: [Robot; 2] = std::array::from_fn(|j| Robot {
                        tcp: tcps[j],
                        v_fd: v_fd(j),
                        stop,
                        tick_s,
                        interval_s: tick_s,
                    });
                    tally.search(&cell, verdict, &robots, 300, &mut rng);
                }
                prev = tcps;
            }
            let spared = tally.spared_range();
            println!(
                "{} {} model {k}: {} FREE/WARN ticks searched, least clearance {:.3} mm; \
                 {} of {} STOP ticks reach contact, the others' least clearance {:.1} / {:.1} / {:.1} mm \
                 (min / median / max)",
                s.cell, s.case, tally.proved, tally.least, tally.touched, tally.stops, spared.0, spared.1, spared.2
            );
            all.proved += tally.proved;
            all.least = all.least.min(tally.least);
        }
    }
    println!(
        "{} FREE/WARN ticks of the runs searched, least clearance reached {:.3} mm",
        all.proved, all.least
    );
    assert!(all.proved >= 200, "too few FREE ticks to search: {}", all.proved);
}
