//! The full exact query of two robots from two TCPs (two IKs, six boxes, the AABB pre-test,
//! up to nine box tests), on the thesis's practical and collision trajectories (thesis
//! Figures 3.2 and 3.3), with SAT and with SAT-cache, and through the C ABI's `dc_query`.
//!
//! Inputs: the first 128 ticks of each run sampled every 47 ticks (a ring covering the whole
//! trajectory); every iteration asserts the verdict computed before timing.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::ffi::*;
use delta_collide::math::Vec3;
use std::hint::black_box;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");

/// 128 two-robot configurations along `case` on T1, with their verdicts.
fn ring(case: &str) -> Vec<([Vec3; 2], bool)> {
    let scenario = parse_scenarios(SCENARIOS)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == case)
        .unwrap();
    let mut checker = ExactChecker::new(reference_cell("T1").unwrap());
    (0..128)
        .map(|i| {
            // The collision run's last part collides: weight the ring toward it there.
            let tick =
                if case == "collision" { 3000 + (i * 23) % 3000 } else { (i * 47) % RUN_TICKS };
            let mut tcps = [Vec3::zeros(); 2];
            scenario.tcps_at(tick, &mut tcps);
            let hit = checker.check(&tcps).unwrap().collides();
            (tcps, hit)
        })
        .collect()
}

fn exact_query(c: &mut Criterion) {
    let mut group = c.benchmark_group("exact_query_T1");
    for case in ["practical", "collision"] {
        let inputs = ring(case);
        for (name, method) in [("SAT", SatMethod::Sat), ("SAT-cache", SatMethod::SatCache)] {
            let cell = Cell { method, ..reference_cell("T1").unwrap() };
            let mut checker = ExactChecker::new(cell);
            let mut i = 0;
            group.bench_function(BenchmarkId::new(name, case), |b| {
                b.iter(|| {
                    let (tcps, hit) = &inputs[i % inputs.len()];
                    i += 1;
                    let v = checker.check(black_box(tcps)).unwrap();
                    assert_eq!(v.collides(), *hit);
                })
            });
        }
        // The same query through the C ABI (handle, pointer checks, panic boundary).
        let mut robots = [dc_robot_config_thesis(); 2];
        robots[1].translation = DcVec3 { x: 450.0, y: 0.0, z: 0.0 };
        let config =
            DcCellConfig { robots: robots.as_ptr(), n_robots: 2, method: DC_METHOD_SAT_CACHE };
        let mut h = std::ptr::null_mut();
        // SAFETY: valid config and out pointer.
        assert_eq!(unsafe { dc_init(&config, &mut h) }, DC_STATUS_OK);
        let c_inputs: Vec<([DcVec3; 2], DcVerdict)> = inputs
            .iter()
            .map(|(t, hit)| {
                let v = |p: &Vec3| DcVec3 { x: p.x, y: p.y, z: p.z };
                ([v(&t[0]), v(&t[1])], if *hit { DC_VERDICT_COLLISION } else { DC_VERDICT_FREE })
            })
            .collect();
        let mut i = 0;
        group.bench_function(BenchmarkId::new("dc_query", case), |b| {
            b.iter(|| {
                let (tcps, want) = &c_inputs[i % c_inputs.len()];
                i += 1;
                let mut verdict = DC_VERDICT_STOP;
                // SAFETY: live handle, two readable TCPs, writable verdict.
                let s = unsafe {
                    dc_query(h, black_box(tcps.as_ptr()), 2, &mut verdict, std::ptr::null_mut())
                };
                assert_eq!((s, verdict), (DC_STATUS_OK, *want));
            })
        });
        // SAFETY: live handle, destroyed once.
        unsafe { dc_destroy(h) };
    }
    group.finish();
}

criterion_group!(benches, exact_query);
criterion_main!(benches);
