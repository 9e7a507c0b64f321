//! Per-tick medians of the protective verdict and the exact query over the practical and
//! collision runs, for profiling: `prot_tick [stiff|default] [verdict|limits] [repeats]
//! [T1practical|...]` (the last argument keeps one run). With `COMPONENTS` set in the environment
//! it times only the parts of a tick that reuses a kept proof: the boxes, the clearance, the
//! closest box pair alone. `LIMIT_TESTS=n` caps the speeds tested per robot and tick by the
//! speed-limit search (`ProtectiveChecker::with_limit_tests`; `4294967295`: not capped).

use delta_collide::cell::protective::{Protective, ProtectiveChecker};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::ExactChecker;
use delta_collide::math::Vec3;
use delta_collide::robot::StopModel;
use std::time::Instant;

const SCENARIOS: &str = include_str!("../c_harness/scenarios.txt");

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let stiff = args.get(1).is_none_or(|a| a == "stiff");
    let limits = args.get(2).is_some_and(|a| a == "limits");
    let repeats: usize = args.get(3).map_or(1, |a| a.parse().unwrap());
    let only = args.get(4).cloned();
    let stop = if stiff {
        StopModel {
            reaction_ms: 2.0,
            decel_mm_s2: 120_000.0,
            max_accel_mm_s2: 130_000.0,
            max_speed_mm_s: 4_600.0,
        }
    } else {
        StopModel::DEFAULT
    };
    for s in parse_scenarios(SCENARIOS).unwrap() {
        if only.as_ref().is_some_and(|o| *o != format!("{}{}", s.cell, s.case)) {
            continue;
        }
        let base = reference_cell(&s.cell).unwrap();
        let n = base.robots.len();
        let cell = base.with_stopping(1.0, vec![stop; n]).unwrap();
        let mut c = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(limits);
        if let Ok(tests) = std::env::var("LIMIT_TESTS") {
            c = c.with_limit_tests(tests.parse().unwrap());
        }
        let mut exact = ExactChecker::new(cell);
        let mut tcps = vec![Vec3::zeros(); n];
        let (mut tp, mut te) = (Vec::new(), Vec::new());
        // The protective times again, by the tick's verdict (FREE, WARN, STOP).
        let mut by_verdict: [Vec<f64>; 3] = Default::default();
        // Ticks settled by a FREE proof kept from an earlier tick (`ProtectiveReport::kept_proof`).
        let (mut stops, mut warns, mut kept) = (0, 0, 0);
        // The reported speed limits of the first pass (mm/s): their sum and count, for the mean.
        let (mut limit_sum, mut limit_count) = (0.0, 0u32);
        // The first pass's verdicts and limiting pairs, tick by tick, hashed (FNV-1a): equal
        // hashes say two builds gave the same answers; the verdicts alone, likewise (the
        // limiting pair is any pair not proved, and may change with the order of the tests);
        // and the first WARN and STOP ticks.
        let (mut answers, mut verdicts): (u64, u64) =
            (0xcbf2_9ce4_8422_2325, 0xcbf2_9ce4_8422_2325);
        let (mut first_warn, mut first_stop) = (None, None);
        for rep in 0..repeats * usize::from(std::env::var("COMPONENTS").is_err()) {
            c.reset();
            for tick in 0..RUN_TICKS {
                s.tcps_at(tick, &mut tcps);
                let t0 = Instant::now();
                let v = c.check(&tcps).unwrap().verdict;
                let t1 = Instant::now();
                if rep == 0 && limits {
                    for r in &c.report().robots {
                        limit_sum += r.speed_limit_mm_s;
                        limit_count += 1;
                    }
                }
                std::hint::black_box(exact.check(&tcps).unwrap().collides());
                let t2 = Instant::now();
                tp.push((t1 - t0).as_secs_f64() * 1e6);
                by_verdict[v as usize].push((t1 - t0).as_secs_f64() * 1e6);
                te.push((t2 - t1).as_secs_f64() * 1e6);
                if rep == 0 {
                    let r = c.report();
                    let limiting = r
                        .limiting
                        .map_or(0, |p| 1 + p.a * 1000 + p.b * 100 + p.box_a * 10 + p.box_b);
                    for x in [v as u64, limiting as u64] {
                        answers = (answers ^ x).wrapping_mul(0x0100_0000_01b3);
                    }
                    verdicts = (verdicts ^ v as u64).wrapping_mul(0x0100_0000_01b3);
                    first_warn = first_warn.or((v == Protective::Warn).then_some(tick));
                    first_stop = first_stop.or((v == Protective::Stop).then_some(tick));
                    stops += (v == Protective::Stop) as u32;
                    kept += u32::from(r.kept_proof);
                    warns += (v == Protective::Warn) as u32;
                }
            }
        }
        // Components on the same ticks: boxes alone, then the clearance over them.
        let (mut tb, mut tc) = (Vec::new(), Vec::new());
        let mut memory = delta_collide::geometry::clearance::CoherentClearance::new();
        let mut singles = vec![delta_collide::geometry::clearance::CoherentClearance::new(); 9];
        let mut ts = Vec::new();
        let component_repeats = if std::env::var("COMPONENTS").is_ok() { 200 } else { 1 };
        for tick in (0..RUN_TICKS).cycle().take(RUN_TICKS as usize * component_repeats) {
            s.tcps_at(tick, &mut tcps);
            let t0 = Instant::now();
            std::hint::black_box(exact.place_boxes(&tcps).unwrap());
            let t1 = Instant::now();
            let c = memory.boxes_clearance(exact.boxes(0).as_slice(), exact.boxes(1).as_slice());
            let t2 = Instant::now();
            let (ba, bb) = (
                &exact.boxes(0).as_slice()[c.box_a..c.box_a + 1],
                &exact.boxes(1).as_slice()[c.box_b..c.box_b + 1],
            );
            let t3 = Instant::now();
            std::hint::black_box(singles[c.box_a * 3 + c.box_b].boxes_clearance(ba, bb));
            let t4 = Instant::now();
            ts.push((t4 - t3).as_secs_f64() * 1e6);
            tb.push((t1 - t0).as_secs_f64() * 1e6);
            tc.push((t2 - t1).as_secs_f64() * 1e6);
        }
        let q = |t: &mut Vec<f64>| {
            t.sort_by(f64::total_cmp);
            (t[t.len() / 2], t[t.len() * 99 / 100], t.iter().sum::<f64>() / t.len() as f64)
        };
        let ((bm, _, _), (cm, _, _)) = (q(&mut tb), q(&mut tc));
        let (sm, _, _) = q(&mut ts);
        println!(
            "  place_boxes median {bm:.3} us, coherent clearance median {cm:.3} us, closest pair alone {sm:.3} us"
        );
        if tp.is_empty() {
            continue;
        }
        // Each tick's least time over the repeats (every repeat takes the same path through
        // the same tick; a busy host only adds time), then the median over the ticks: steadier
        // than the median of all times on a shared machine.
        let least = |t: &[f64]| {
            let mut m: Vec<f64> = (0..RUN_TICKS as usize)
                .map(|i| {
                    t.iter()
                        .skip(i)
                        .step_by(RUN_TICKS as usize)
                        .copied()
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            let median = q(&mut m).0;
            (median, m[m.len() - 1])
        };
        let ((pl, worst), (el, _)) = (least(&tp), least(&te));
        let ((pm, p99, pmean), (em, _, _)) = (q(&mut tp), q(&mut te));
        for (name, t) in
            ["FREE", "WARN", "STOP"].iter().zip(&mut by_verdict).filter(|(_, t)| !t.is_empty())
        {
            let (m, p, _) = q(t);
            let under = t.iter().filter(|&&x| x < 1.0).count();
            println!(
                "  {name} ticks: {} ({under} under 1 us), median {m:.3} us, p99 {p:.1} us",
                t.len() / repeats.max(1)
            );
        }
        let mean_limit = match limit_count {
            0 => String::new(),
            n => format!(", mean speed limit {:.1} mm/s", limit_sum / n as f64),
        };
        println!(
            "{} {}: STOP {stops} WARN {warns} kept-proof FREE {kept}; \
             protective median {pm:.3} p99 {p99:.1} mean {pmean:.2}, \
             exact median {em:.3} us{mean_limit}; \
             least of repeats: protective {pl:.3} exact {el:.3} us ({ratio:.2}x), worst tick {worst:.1} us; \
             first WARN {first_warn:?} STOP {first_stop:?}, \
             answers {answers:016x}, verdicts {verdicts:016x}",
            s.cell,
            s.case,
            ratio = pl / el
        );
    }
}
