//! Table mode with confirmation (a COLLISION lookup answered by the exact check) next to its
//! peers, exact mode and the table's labels alone, on T1's practical and collision runs, with
//! T1's certified k = 16 `6d` table kept in `tests/data/golden/` (coarse, so that the collision
//! run's ring holds false alarms to confirm).
//!
//! Run: `cargo bench --bench table_confirm -- --warm-up-time 1 --measurement-time 2`.
//! Inputs: 128 ticks of each run (the collision run's from its colliding second half); every
//! iteration asserts the answer computed before timing. Per-tick percentiles and confirmed
//! ticks on T1-T3: `delta-collide eval` (docs/record/2026-11-24-table-confirmation.md).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::ExactChecker;
use delta_collide::math::Vec3;
use delta_collide::table::{Confirmation, TableAnswer, TableChecker};
use std::hint::black_box;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");
const TABLE: &[u8] = include_bytes!("../tests/data/golden/t1_k16_6d.dct");

/// 128 configurations along `case` on T1: (TCPs, exact answer, the table's label).
fn ring(case: &str) -> Vec<([Vec3; 2], TableAnswer, TableAnswer)> {
    let scenario = parse_scenarios(SCENARIOS)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == case)
        .unwrap();
    let cell = reference_cell("T1").unwrap();
    let mut exact = ExactChecker::new(cell.clone());
    let mut labels = TableChecker::with_confirmation(cell, TABLE, Confirmation::None).unwrap();
    (0..128)
        .map(|i| {
            let tick =
                if case == "collision" { 3000 + (i * 23) % 3000 } else { (i * 47) % RUN_TICKS };
            let mut tcps = [Vec3::zeros(); 2];
            scenario.tcps_at(tick, &mut tcps);
            let hit = exact.check(&tcps).unwrap().collides();
            let truth = if hit { TableAnswer::Collision } else { TableAnswer::Free };
            (tcps, truth, labels.check(&tcps).unwrap())
        })
        .collect()
}

fn table_confirm(c: &mut Criterion) {
    let mut group = c.benchmark_group("table_confirm_T1_k16");
    for case in ["practical", "collision"] {
        let inputs = ring(case);
        let alarms = inputs.iter().filter(|(_, truth, label)| label != truth).count();
        let lookups =
            inputs.iter().filter(|(_, _, label)| *label == TableAnswer::Collision).count();
        eprintln!(
            "T1 {case}: {lookups} of {} ring ticks confirmed, {alarms} of them false alarms",
            inputs.len()
        );
        let mut exact = ExactChecker::new(reference_cell("T1").unwrap());
        let mut i = 0;
        group.bench_function(BenchmarkId::new("exact", case), |b| {
            b.iter(|| {
                let (tcps, truth, _) = &inputs[i % inputs.len()];
                i += 1;
                let hit = exact.check(black_box(tcps)).unwrap().collides();
                assert_eq!(hit, *truth == TableAnswer::Collision);
            })
        });
        for (name, confirmation) in
            [("table+confirm", Confirmation::Exact), ("table labels", Confirmation::None)]
        {
            let cell = reference_cell("T1").unwrap();
            let mut table = TableChecker::with_confirmation(cell, TABLE, confirmation).unwrap();
            let mut i = 0;
            group.bench_function(BenchmarkId::new(name, case), |b| {
                b.iter(|| {
                    let (tcps, truth, label) = &inputs[i % inputs.len()];
                    i += 1;
                    let want = if confirmation == Confirmation::Exact { truth } else { label };
                    assert_eq!(table.check(black_box(tcps)).unwrap(), *want);
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, table_confirm);
criterion_main!(benches);
