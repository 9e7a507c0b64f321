//! The protective verdict in table mode (SPEC §8, clearance tables SPEC §6) next to the same
//! verdict in exact mode and the plain per-tick query, on T1's practical run: the 6,000 ticks
//! replayed in order (speeds from the tick history, as in operation), speed limits off (the
//! verdict alone), with the default and the stiff stopping model of the protective tests.
//!
//! Functions per group: `table mode` (`check_with_table` on a certified clearance table of
//! T1, default levels, k = 16, built here), `exact mode` (`check`), and the peers
//! `dc_query exact` (`ExactChecker::check`, what `dc_query` runs in exact mode) and
//! `dc_query table` (`TableChecker::check` with confirmation, `dc_query` in table mode).
//! Every verdict is computed before timing and asserted inside the loop.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use delta_collide::cell::protective::{Protective, ProtectiveChecker, ProtectiveRequest};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::Vec3;
use delta_collide::robot::StopModel;
use delta_collide::table::{
    build_table, to_bytes, Confirmation, Labelling, Ladder, TableAnswer, TableChecker, Variant,
};
use std::hint::black_box;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");

/// Resolution of the clearance table (its labelling takes seconds at 16, a minute at 32).
const K: u32 = 16;

fn run_ticks() -> Vec<[Vec3; 2]> {
    let s = parse_scenarios(SCENARIOS)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == "practical")
        .unwrap();
    (0..RUN_TICKS)
        .map(|tick| {
            let mut now = [Vec3::zeros(); 2];
            s.tcps_at(tick, &mut now);
            now
        })
        .collect()
}

fn table_protective(c: &mut Criterion) {
    let t1 = reference_cell("T1").unwrap();
    let (header, table, _) = build_table(
        &t1,
        K,
        &Workspace::THESIS,
        Variant::Clearance(Ladder::default_ladder()),
        Labelling::Certified,
        Progress::Silent,
    )
    .unwrap();
    let bytes = to_bytes(&table, &header);
    let ticks = run_ticks();
    let stiff = StopModel {
        reaction_ms: 2.0,
        decel_mm_s2: 120_000.0,
        max_accel_mm_s2: 130_000.0,
        max_speed_mm_s: 4_600.0,
    };
    for (name, cell) in
        [("default", t1.clone()), ("stiff", t1.clone().with_stopping(1.0, vec![stiff; 2]).unwrap())]
    {
        group(c, name, &cell, &bytes, &ticks);
    }
}

fn group(c: &mut Criterion, model: &str, cell: &Cell, bytes: &[u8], ticks: &[[Vec3; 2]]) {
    let lookup = TableChecker::new(cell.clone(), bytes).unwrap();
    let bound = |_: usize, _: usize, t: &[Vec3]| lookup.clearance_bound(t);
    let mut group = c.benchmark_group(format!("table_protective_T1_practical_{model}"));
    let mut table_mode =
        ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
    let reports: Vec<(Protective, bool)> = ticks
        .iter()
        .map(|t| {
            let r = table_mode.check(ProtectiveRequest::new(t).with_table(&bound)).unwrap();
            (r.verdict, r.table_lookup)
        })
        .collect();
    let mut exact_mode =
        ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
    let verdicts: Vec<Protective> =
        ticks.iter().map(|t| exact_mode.check(t).unwrap().verdict).collect();
    let count =
        |v: Protective, of: &mut dyn Iterator<Item = Protective>| of.filter(|x| *x == v).count();
    let lookups = reports.iter().filter(|r| r.1).count();
    println!(
        "{model}: table mode STOP {} WARN {}, {lookups} of {} ticks by the lookup alone; exact mode STOP {} WARN {}",
        count(Protective::Stop, &mut reports.iter().map(|r| r.0)),
        count(Protective::Warn, &mut reports.iter().map(|r| r.0)),
        ticks.len(),
        count(Protective::Stop, &mut verdicts.iter().copied()),
        count(Protective::Warn, &mut verdicts.iter().copied()),
    );
    let mut i = 0;
    group.bench_function(BenchmarkId::new("protective", "table mode"), |b| {
        b.iter(|| {
            let k = i % ticks.len();
            if k == 0 {
                table_mode.reset();
            }
            i += 1;
            // The verdict as in the first pass; whether the lookup or a proof kept from the
            // previous pass gives it may differ (kept proofs outlive `reset`).
            assert_eq!(
                table_mode
                    .check(ProtectiveRequest::new(black_box(&ticks[k])).with_table(&bound))
                    .unwrap()
                    .verdict,
                reports[k].0
            );
        })
    });
    let mut i = 0;
    group.bench_function(BenchmarkId::new("protective", "exact mode"), |b| {
        b.iter(|| {
            let k = i % ticks.len();
            if k == 0 {
                exact_mode.reset();
            }
            i += 1;
            assert_eq!(exact_mode.check(black_box(&ticks[k])).unwrap().verdict, verdicts[k]);
        })
    });
    let mut exact = ExactChecker::new(cell.clone());
    let hits: Vec<bool> = ticks.iter().map(|t| exact.check(t).unwrap().collides()).collect();
    let mut i = 0;
    group.bench_function(BenchmarkId::new("dc_query", "exact"), |b| {
        b.iter(|| {
            let k = i % ticks.len();
            i += 1;
            assert_eq!(exact.check(black_box(&ticks[k])).unwrap().collides(), hits[k]);
        })
    });
    let mut table =
        TableChecker::with_confirmation(cell.clone(), bytes, Confirmation::Exact).unwrap();
    let mut i = 0;
    group.bench_function(BenchmarkId::new("dc_query", "table"), |b| {
        b.iter(|| {
            let k = i % ticks.len();
            i += 1;
            let want = if hits[k] { TableAnswer::Collision } else { TableAnswer::Free };
            assert_eq!(table.check(black_box(&ticks[k])).unwrap(), want);
        })
    });
    group.finish();
}

criterion_group!(benches, table_protective);
criterion_main!(benches);
