//! Lines of 2, 4, 8 and 16 thesis robots along one conveyor, bases 450 mm apart (as T1 and
//! `cells/line4.toml`): the exact query and the protective verdict (alone, and with speed
//! limits) per tick, against the number of pairs that can meet. Robot `j` runs T1 practical's
//! trajectory of robot A (even `j`) or B (odd `j`), so every other neighbour pair works as
//! T1's pair does; the 6,000 ticks are replayed in order (`check`, speeds from the history)
//! and every answer is asserted against one computed before timing. The exact query of the
//! two-robot line is the peer of every other figure. Table mode (one lookup per pair, COLLISION
//! confirmed by the exact check) runs on the bundle of `cells/line4.toml`'s spacing, which
//! serves every line here: k = 32 `shared` when benchmarking, k = 16 in `cargo test`'s quick
//! pass (the build then takes a second, not half a minute). With the stiff stopping model, the
//! protective verdict in exact mode against table mode on the bundle of clearance tables
//! (k = 16) of the same spacing.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use delta_collide::cell::placement::Placement;
use delta_collide::cell::protective::{Protective, ProtectiveChecker};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker, RobotSpec};
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::bundle::build_bundle;
use delta_collide::robot::StopModel;
use delta_collide::table::{BundleChecker, Confirmation, Labelling, Ladder, TableAnswer, Variant};
use std::hint::black_box;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");

/// A line of `n` thesis robots, 450 mm apart along x.
fn line(n: usize) -> Cell {
    let t1 = reference_cell("T1").unwrap();
    let robots = (0..n)
        .map(|j| RobotSpec {
            name: format!("R{}", j + 1),
            placement: Placement { alpha: 0.0, t: Vec3::new(450.0 * j as f64, 0.0, 0.0) },
            ..t1.robots[0].clone()
        })
        .collect();
    Cell::new(format!("line{n}"), robots, t1.method).unwrap()
}

/// The ticks of the run for `n` robots.
fn ticks(n: usize) -> Vec<Vec<Vec3>> {
    let s = parse_scenarios(SCENARIOS).unwrap().into_iter().find(|s| s.cell == "T1" && s.case == "practical").unwrap();
    (0..RUN_TICKS)
        .map(|tick| {
            let mut pair = [Vec3::zeros(); 2];
            s.tcps_at(tick, &mut pair);
            (0..n).map(|j| pair[j % 2]).collect()
        })
        .collect()
}

/// The stiff stopping model of the protective tests (2 ms reaction, 120 m/s^2 braking): stops
/// short enough for a clearance table's levels to prove far pairs.
const STIFF: StopModel =
    StopModel { reaction_ms: 2.0, decel_mm_s2: 120_000.0, max_accel_mm_s2: 130_000.0, max_speed_mm_s: 4_600.0 };

/// The bundle of clearance tables (k = 16, default levels) of a line 450 mm apart.
fn clearance_bundle() -> Vec<u8> {
    let variant = Variant::Clearance(Ladder::default_ladder());
    build_bundle(&line(4), 16, &Workspace::THESIS, variant, Labelling::Certified, Progress::Silent)
        .expect("the line's clearance bundle builds")
        .bytes
}

/// The bundle of a line 450 mm apart (three tables: 450, 900 and 1350 mm), its k, and bytes.
fn bundle() -> (u32, Vec<u8>) {
    let k = if std::env::args().any(|a| a == "--bench") { 32 } else { 16 };
    let built = build_bundle(&line(4), k, &Workspace::THESIS, Variant::Shared, Labelling::Certified, Progress::Silent)
        .expect("the line's bundle builds");
    println!("bundle of line4, k = {k}: {} tables, {} bytes", built.tables.len(), built.bytes.len());
    (k, built.bytes)
}

fn lines(c: &mut Criterion) {
    let (k, bundle) = bundle();
    let clearance = clearance_bundle();
    let mut group = c.benchmark_group("line_T1_practical_replay");
    for n in [2, 4, 8, 16] {
        let cell = line(n);
        let pairs = cell.pairs_that_can_meet().len();
        let run = ticks(n);
        let mut exact = ExactChecker::new(cell.clone());
        let hits: Vec<bool> = run.iter().map(|t| exact.check(t).unwrap().collides()).collect();
        let label = format!("{n} robots, {pairs} pairs");
        let mut i = 0;
        group.bench_function(BenchmarkId::new("exact", &label), |b| {
            b.iter(|| {
                let k = i % run.len();
                i += 1;
                assert_eq!(exact.check(black_box(&run[k])).unwrap().collides(), hits[k]);
            })
        });
        let mut table = BundleChecker::new(cell.clone(), &bundle, Confirmation::Exact).unwrap();
        let mut i = 0;
        group.bench_function(BenchmarkId::new(format!("table k{k}, exact confirmation"), &label), |b| {
            b.iter(|| {
                let k = i % run.len();
                i += 1;
                assert_eq!(table.check(black_box(&run[k])).unwrap() == TableAnswer::Collision, hits[k]);
            })
        });
        for (name, limits) in [("protective verdict", false), ("protective with speed limits", true)] {
            let mut checker = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(limits);
            let verdicts: Vec<Protective> = run.iter().map(|t| checker.check(t).unwrap().verdict).collect();
            let mut i = 0;
            group.bench_function(BenchmarkId::new(name, &label), |b| {
                b.iter(|| {
                    let k = i % run.len();
                    if k == 0 {
                        checker.reset();
                    }
                    i += 1;
                    assert_eq!(checker.check(black_box(&run[k])).unwrap().verdict, verdicts[k]);
                })
            });
        }
    }
    group.finish();
    // The stiff model, exact mode against table mode on the clearance bundle (far pairs proved
    // by their table's bound skip the box-pair proof), same ticks.
    let mut group = c.benchmark_group("line_T1_practical_replay_stiff");
    for n in [2, 4, 8, 16] {
        let cell = line(n).with_stopping(1.0, vec![STIFF; n]).unwrap();
        let label = format!("{n} robots, {} pairs", cell.pairs_that_can_meet().len());
        let run = ticks(n);
        let table = BundleChecker::new(cell.clone(), &clearance, Confirmation::Exact).unwrap();
        let bound = |a: usize, b: usize, t: &[Vec3]| table.clearance_bound(a, b, t);
        let mut exact = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let mut lookup = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let verdicts: Vec<Protective> = run.iter().map(|t| exact.check(t).unwrap().verdict).collect();
        let pairs: u64 = run.iter().map(|t| u64::from(lookup.check_with_table(t, &bound).unwrap().table_pairs)).sum();
        println!("{label}, stiff: {pairs} pairs proved by a lookup over {} ticks", run.len());
        for (name, table_mode) in [("protective", false), ("protective, table mode", true)] {
            let checker = if table_mode { &mut lookup } else { &mut exact };
            let mut i = 0;
            group.bench_function(BenchmarkId::new(name, &label), |b| {
                b.iter(|| {
                    let k = i % run.len();
                    if k == 0 {
                        checker.reset();
                    }
                    i += 1;
                    let r = match table_mode {
                        true => checker.check_with_table(black_box(&run[k]), &bound).unwrap(),
                        false => checker.check(black_box(&run[k])).unwrap(),
                    };
                    // Table mode proves some pairs another way: never a worse verdict.
                    assert!(r.verdict <= verdicts[k]);
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, lines);
criterion_main!(benches);
