//! Lines of 2, 4, 8 and 16 thesis robots along one conveyor, bases 450 mm apart (as T1 and
//! `cells/line4.toml`): the exact query and the protective verdict (alone, and with speed
//! limits) per tick, against the number of pairs that can meet, on the run of
//! `support/line_run.rs`: its 6,000 ticks are replayed in order (`check`, speeds from the
//! history) and every answer is asserted against one computed before timing. The exact query of the
//! two-robot line is the peer of every other figure. Table mode (one lookup per pair, COLLISION
//! confirmed by the exact check) runs on the bundle of `cells/line4.toml`'s spacing, which
//! serves every line here: k = 32 `shared` when benchmarking, k = 16 in `cargo test`'s quick
//! pass (the build then takes a second, not half a minute). With the stiff stopping model, the
//! protective verdict in exact mode against table mode on the bundle of clearance tables
//! (k = 16) of the same spacing.

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, BenchmarkId, Criterion};
use delta_collide::cell::protective::{Protective, ProtectiveChecker, ProtectiveRequest};
use delta_collide::cell::ExactChecker;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::robot::StopModel;
use delta_collide::table::bundle::build_bundle;
use delta_collide::table::{BundleChecker, Confirmation, Labelling, Ladder, TableAnswer, Variant};
use std::hint::black_box;

#[path = "support/line_run.rs"]
mod line_run;
use line_run::{line, ticks};

/// The stiff stopping model of the protective tests (2 ms reaction, 120 m/s^2 braking): stops
/// short enough for a clearance table's levels to prove far pairs.
const STIFF: StopModel = StopModel {
    reaction_ms: 2.0,
    decel_mm_s2: 120_000.0,
    max_accel_mm_s2: 130_000.0,
    max_speed_mm_s: 4_600.0,
};

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
    let built = build_bundle(
        &line(4),
        k,
        &Workspace::THESIS,
        Variant::Shared,
        Labelling::Certified,
        Progress::Silent,
    )
    .expect("the line's bundle builds");
    println!(
        "bundle of line4, k = {k}: {} tables, {} bytes",
        built.tables.len(),
        built.bytes.len()
    );
    (k, built.bytes)
}

/// Times `tick(k)` on ticks `k = 0, 1, ..., len - 1, 0, ...` in order, as a controller sends them.
fn replay(
    group: &mut BenchmarkGroup<WallTime>,
    id: BenchmarkId,
    len: usize,
    mut tick: impl FnMut(usize),
) {
    let mut i = 0;
    group.bench_function(id, |b| {
        b.iter(|| {
            tick(i % len);
            i += 1;
        })
    });
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
        replay(&mut group, BenchmarkId::new("exact", &label), run.len(), |k| {
            assert_eq!(exact.check(black_box(&run[k])).unwrap().collides(), hits[k]);
        });
        let mut table = BundleChecker::new(cell.clone(), &bundle, Confirmation::Exact).unwrap();
        let id = BenchmarkId::new(format!("table k{k}, exact confirmation"), &label);
        replay(&mut group, id, run.len(), |k| {
            assert_eq!(table.check(black_box(&run[k])).unwrap() == TableAnswer::Collision, hits[k]);
        });
        for (name, limits) in
            [("protective verdict", false), ("protective with speed limits", true)]
        {
            let mut checker =
                ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(limits);
            let verdicts: Vec<Protective> =
                run.iter().map(|t| checker.check(t).unwrap().verdict).collect();
            replay(&mut group, BenchmarkId::new(name, &label), run.len(), |k| {
                if k == 0 {
                    checker.reset();
                }
                assert_eq!(checker.check(black_box(&run[k])).unwrap().verdict, verdicts[k]);
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
        let mut exact =
            ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let mut lookup =
            ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let verdicts: Vec<Protective> =
            run.iter().map(|t| exact.check(t).unwrap().verdict).collect();
        let pairs: u64 = run
            .iter()
            .map(|t| {
                u64::from(
                    lookup.check(ProtectiveRequest::new(t).with_table(&bound)).unwrap().table_pairs,
                )
            })
            .sum();
        println!("{label}, stiff: {pairs} pairs proved by a lookup over {} ticks", run.len());
        for (name, table_mode) in [("protective", false), ("protective, table mode", true)] {
            let checker = if table_mode { &mut lookup } else { &mut exact };
            replay(&mut group, BenchmarkId::new(name, &label), run.len(), |k| {
                if k == 0 {
                    checker.reset();
                }
                let r = match table_mode {
                    true => checker
                        .check(ProtectiveRequest::new(black_box(&run[k])).with_table(&bound))
                        .unwrap(),
                    false => checker.check(black_box(&run[k])).unwrap(),
                };
                // Table mode proves some pairs another way: never a worse verdict.
                assert!(r.verdict <= verdicts[k]);
            });
        }
    }
    group.finish();
}

criterion_group!(benches, lines);
criterion_main!(benches);
