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
//! peer. The verdict of every tick is computed before timing and asserted.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use delta_collide::cell::protective::{Protective, ProtectiveChecker};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::ExactChecker;
use delta_collide::math::{Real, Vec3};
use std::hint::black_box;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");

type Case = ([Vec3; 2], [Real; 2], Protective, bool);

/// 128 configurations along T1 practical with speeds, protective verdicts and collisions.
fn ring(protective: &mut ProtectiveChecker, exact: &mut ExactChecker) -> Vec<Case> {
    let s = parse_scenarios(SCENARIOS).unwrap().into_iter().find(|s| s.cell == "T1" && s.case == "practical").unwrap();
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
            assert_eq!(protective.check_at_speeds(black_box(tcps), speeds).unwrap().verdict, *verdict);
        })
    });
    let mut verdict_only =
        ProtectiveChecker::new(reference_cell("T1").unwrap(), 10.0).unwrap().with_speed_limits(false);
    let mut i = 0;
    group.bench_function(BenchmarkId::new("protective", "verdict only"), |b| {
        b.iter(|| {
            let (tcps, speeds, verdict, _) = &inputs[i % inputs.len()];
            i += 1;
            assert_eq!(verdict_only.check_at_speeds(black_box(tcps), speeds).unwrap().verdict, *verdict);
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

/// The run's TCPs, tick by tick.
fn run_ticks() -> Vec<[Vec3; 2]> {
    let s = parse_scenarios(SCENARIOS).unwrap().into_iter().find(|s| s.cell == "T1" && s.case == "practical").unwrap();
    (0..RUN_TICKS)
        .map(|tick| {
            let mut now = [Vec3::zeros(); 2];
            s.tcps_at(tick, &mut now);
            now
        })
        .collect()
}

fn protective_replay(c: &mut Criterion) {
    let ticks = run_ticks();
    let cell = reference_cell("T1").unwrap();
    let mut exact = ExactChecker::new(cell.clone());
    let hits: Vec<bool> = ticks.iter().map(|t| exact.check(t).unwrap().collides()).collect();
    let mut group = c.benchmark_group("protective_T1_practical_replay");
    for (name, limits) in [("with speed limits", true), ("verdict only", false)] {
        let mut checker = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(limits);
        let verdicts: Vec<Protective> = ticks.iter().map(|t| checker.check(t).unwrap().verdict).collect();
        let mut i = 0;
        group.bench_function(BenchmarkId::new("protective", name), |b| {
            b.iter(|| {
                let k = i % ticks.len();
                if k == 0 {
                    checker.reset();
                }
                i += 1;
                assert_eq!(checker.check(black_box(&ticks[k])).unwrap().verdict, verdicts[k]);
            })
        });
    }
    let mut i = 0;
    group.bench_function(BenchmarkId::new("exact", "SAT-cache"), |b| {
        b.iter(|| {
            let k = i % ticks.len();
            i += 1;
            assert_eq!(exact.check(black_box(&ticks[k])).unwrap().collides(), hits[k]);
        })
    });
    group.finish();
}

criterion_group!(benches, protective_query, protective_replay);
criterion_main!(benches);
