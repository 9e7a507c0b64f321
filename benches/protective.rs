//! The protective verdict (SPEC §8) next to the plain exact query it builds on, on T1's
//! practical trajectory: one `check_at_speeds` (sweeps of both robots, the swept-box proofs
//! and both speed limits; and the verdict alone) against one `ExactChecker::check` of the
//! same TCPs.
//!
//! Inputs: 128 ticks of the run sampled every 47 ticks, with the speeds of the trajectory
//! there; every iteration asserts the verdict computed before timing.
//!
//! The realistic mix (`protective_T1_practical_replay`): the 6,000 ticks of the run replayed in
//! order through `check` (speeds from the tick history, as in operation), so the share of ticks
//! that reach the slower tiers is the scenario's own; the exact query on the same ticks is the
//! peer. The verdict of every tick is computed before timing and asserted. "verdict with
//! paths" is the same replay through `check_with_paths`, each robot's stop path its programmed
//! path ahead (up to 400 mm, 0.1 mm tolerance), as a controller with a path-maintaining stop
//! would give it. `protective_T1_practical_replay_stiff` replays the same run for robots with
//! the stiff stopping model of the protective tests (2 ms reaction, 120 m/s^2 braking), where
//! most ticks are FREE and most FREE ticks reuse a kept proof.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use delta_collide::cell::protective::{Protective, ProtectiveChecker, ProtectiveRequest, StopPath};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, path_ahead, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::StopModel;
use std::hint::black_box;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");

type Case = ([Vec3; 2], [Real; 2], Protective, bool);

/// 128 configurations along T1 practical with speeds, protective verdicts and collisions.
fn ring(protective: &mut ProtectiveChecker, exact: &mut ExactChecker) -> Vec<Case> {
    let s = parse_scenarios(SCENARIOS)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == "practical")
        .unwrap();
    (0..128)
        .map(|i| {
            let tick = 1 + (i * 47) % (RUN_TICKS - 1);
            let (mut now, mut before) = ([Vec3::zeros(); 2], [Vec3::zeros(); 2]);
            s.tcps_at(tick, &mut now);
            s.tcps_at(tick - 1, &mut before);
            let speeds = [(now[0] - before[0]).norm() * 1e3, (now[1] - before[1]).norm() * 1e3];
            let verdict = protective.check_at_speeds(&now, &speeds).unwrap().verdict;
            (now, speeds, verdict, exact.check(&now).unwrap().collides())
        })
        .collect()
}

fn protective_query(c: &mut Criterion) {
    let cell = reference_cell("T1").unwrap();
    let mut protective = ProtectiveChecker::new(cell.clone(), 10.0).unwrap();
    let mut exact = ExactChecker::new(cell);
    let inputs = ring(&mut protective, &mut exact);
    let mut group = c.benchmark_group("protective_T1_practical");
    let mut i = 0;
    group.bench_function(BenchmarkId::new("protective", "with speed limits"), |b| {
        b.iter(|| {
            let (tcps, speeds, verdict, _) = &inputs[i % inputs.len()];
            i += 1;
            assert_eq!(
                protective.check_at_speeds(black_box(tcps), speeds).unwrap().verdict,
                *verdict
            );
        })
    });
    let mut verdict_only = ProtectiveChecker::new(reference_cell("T1").unwrap(), 10.0)
        .unwrap()
        .with_speed_limits(false);
    let mut i = 0;
    group.bench_function(BenchmarkId::new("protective", "verdict only"), |b| {
        b.iter(|| {
            let (tcps, speeds, verdict, _) = &inputs[i % inputs.len()];
            i += 1;
            assert_eq!(
                verdict_only.check_at_speeds(black_box(tcps), speeds).unwrap().verdict,
                *verdict
            );
        })
    });
    let mut i = 0;
    group.bench_function(BenchmarkId::new("exact", "SAT-cache"), |b| {
        b.iter(|| {
            let (tcps, _, _, hit) = &inputs[i % inputs.len()];
            i += 1;
            assert_eq!(exact.check(black_box(tcps)).unwrap().collides(), *hit);
        })
    });
    group.finish();
}

/// One robot's stop path: its points and how many are used.
type PathAhead = ([Vec3; 32], usize);

/// The run's TCPs, tick by tick, with each robot's programmed path ahead.
fn run_ticks() -> Vec<([Vec3; 2], [PathAhead; 2])> {
    let s = parse_scenarios(SCENARIOS)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == "practical")
        .unwrap();
    (0..RUN_TICKS)
        .map(|tick| {
            let mut now = [Vec3::zeros(); 2];
            s.tcps_at(tick, &mut now);
            let paths = std::array::from_fn(|j| {
                let mut points = [Vec3::zeros(); 32];
                let n = path_ahead(&s.robots[j], tick, 400.0, &mut points);
                (points, n)
            });
            (now, paths)
        })
        .collect()
}

fn stop_paths(paths: &[PathAhead; 2]) -> [Option<StopPath<'_>>; 2] {
    paths.each_ref().map(|(p, n)| Some(StopPath { points: &p[..*n], tolerance_mm: 0.1 }))
}

fn protective_replay(c: &mut Criterion) {
    replay(c, "protective_T1_practical_replay", reference_cell("T1").unwrap());
    let stiff = StopModel {
        reaction_ms: 2.0,
        decel_mm_s2: 120_000.0,
        max_accel_mm_s2: 130_000.0,
        max_speed_mm_s: 4_600.0,
    };
    replay(
        c,
        "protective_T1_practical_replay_stiff",
        reference_cell("T1").unwrap().with_stopping(1.0, vec![stiff; 2]).unwrap(),
    );
}

fn replay(c: &mut Criterion, name: &str, cell: Cell) {
    let ticks = run_ticks();
    let mut exact = ExactChecker::new(cell.clone());
    let hits: Vec<bool> = ticks.iter().map(|t| exact.check(&t.0).unwrap().collides()).collect();
    let mut group = c.benchmark_group(name);
    for (name, limits) in [("with speed limits", true), ("verdict only", false)] {
        let mut checker =
            ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(limits);
        let verdicts: Vec<Protective> =
            ticks.iter().map(|t| checker.check(&t.0).unwrap().verdict).collect();
        let mut i = 0;
        group.bench_function(BenchmarkId::new("protective", name), |b| {
            b.iter(|| {
                let k = i % ticks.len();
                if k == 0 {
                    checker.reset();
                }
                i += 1;
                assert_eq!(checker.check(black_box(&ticks[k].0)).unwrap().verdict, verdicts[k]);
            })
        });
    }
    let mut checker = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
    let verdicts: Vec<Protective> = ticks
        .iter()
        .map(|(t, p)| {
            checker.check(ProtectiveRequest::new(t).with_paths(&stop_paths(p))).unwrap().verdict
        })
        .collect();
    let mut i = 0;
    group.bench_function(BenchmarkId::new("protective", "verdict with paths"), |b| {
        b.iter(|| {
            let k = i % ticks.len();
            if k == 0 {
                checker.reset();
            }
            i += 1;
            let (tcps, paths) = &ticks[k];
            assert_eq!(
                checker
                    .check(ProtectiveRequest::new(black_box(tcps)).with_paths(&stop_paths(paths)))
                    .unwrap()
                    .verdict,
                verdicts[k]
            );
        })
    });
    let mut i = 0;
    group.bench_function(BenchmarkId::new("exact", "SAT-cache"), |b| {
        b.iter(|| {
            let k = i % ticks.len();
            i += 1;
            assert_eq!(exact.check(black_box(&ticks[k].0)).unwrap().collides(), hits[k]);
        })
    });
    group.finish();
}

criterion_group!(benches, protective_query, protective_replay);
criterion_main!(benches);
