//! The protective verdict (SPEC §8) against brute force, independent of its construction:
//! whenever it says FREE, many stopping motions that the model allows are simulated at
//! 0.1 ms steps with the exact checker and none may bring two boxes into contact. Also the
//! fail-closed rules (first tick, implausible jumps, unreachable TCPs), the WARN threshold's
//! monotonicity, the speed limit, no allocation per tick, and the counts on the scenarios.

use delta_collide::cell::protective::{
    Protective, ProtectiveChecker, ProtectiveReport, ProtectiveRequest, ProtectiveStatus,
};
use delta_collide::cell::trajectory::{parse_scenarios, Scenario, RUN_TICKS};
use delta_collide::cell::ExactChecker;
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::StopModel;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

mod protective_common;
use protective_common::{
    allocations, assert_stops_never_touch, cell, programmed_paths, tcp_near_reach_boundary,
    tcp_toward_other, unit, STIFF,
};

/// Random states near each other; for each FREE one, random stops are simulated.
/// `precise`: the second tier's splits (0: the motor-angle table alone); `edge`: TCPs near the
/// reach boundary.
fn brute_force(
    name: &str,
    stop: StopModel,
    states: usize,
    seed: u64,
    precise: u32,
    edge: bool,
) -> (usize, usize) {
    let cell = cell(name, stop);
    let mut checker =
        ProtectiveChecker::new(cell.clone(), 5.0).unwrap().with_precise_splits(precise);
    let mut rng = StdRng::seed_from_u64(seed);
    let (mut free, mut steps) = (0, 0);
    let tick = cell.tick_ms * 1e-3;
    let sample = if edge { tcp_near_reach_boundary } else { tcp_toward_other };
    for _ in 0..states {
        let tcps = [sample(&cell, 0, &mut rng), sample(&cell, 1, &mut rng)];
        // Speeds mostly low (else nothing near is FREE), directions random.
        let v_fd: [Vec3; 2] = std::array::from_fn(|_| {
            unit(&mut rng) * stop.max_speed_mm_s * rng.random::<Real>().powi(3)
        });
        let prev = [tcps[0] - v_fd[0] * tick, tcps[1] - v_fd[1] * tick];
        checker.reset();
        checker.check(&prev).unwrap();
        let r = checker.check(&tcps).unwrap().clone();
        if r.status != ProtectiveStatus::Ok || r.verdict == Protective::Stop {
            continue;
        }
        free += 1;
        // The true velocity now: within a_max * tick of the finite difference, under v_max.
        let vel = v_fd.map(|v| {
            let w = v + unit(&mut rng) * stop.max_accel_mm_s2 * tick * rng.random::<Real>();
            if w.norm() > stop.max_speed_mm_s {
                w * (stop.max_speed_mm_s / w.norm())
            } else {
                w
            }
        });
        steps += assert_stops_never_touch(&cell, &tcps, &vel, 8, &mut rng);
    }
    (free, steps)
}

#[test]
fn free_verdicts_survive_simulated_stops() {
    let mut total = 0;
    for (i, name) in ["T1", "T2", "T3"].iter().enumerate() {
        for (k, stop) in [STIFF, StopModel::DEFAULT].into_iter().enumerate() {
            let (free, steps) =
                brute_force(name, stop, 150, 100 + 10 * i as u64 + k as u64, 2, false);
            println!("{name} model {k}: {free} FREE/WARN states of 150, {steps} exact checks of simulated stops");
            total += free;
        }
    }
    assert!(total >= 60, "too few FREE states to test: {total}");
}

/// The first tier alone (motor angles from the table, no direct enclosure), near the reach
/// boundary (elbows swinging fastest) and in the open: FREE still survives every simulated stop.
#[test]
fn free_verdicts_of_the_table_tier_survive_simulated_stops_near_the_reach_boundary() {
    let (mut total, mut edge_total) = (0, 0);
    for (i, name) in ["T1", "T2", "T3"].iter().enumerate() {
        for (k, stop) in [STIFF, StopModel::DEFAULT].into_iter().enumerate() {
            for edge in [false, true] {
                let seed = 500 + 10 * i as u64 + k as u64 + 100 * edge as u64;
                let (free, steps) = brute_force(name, stop, 150, seed, 0, edge);
                println!(
                    "{name} model {k} edge {edge}: {free} FREE/WARN of 150, {steps} exact checks"
                );
                total += free;
                edge_total += free * edge as usize;
            }
        }
    }
    assert!(
        total >= 60 && edge_total >= 20,
        "too few FREE states to test: {total}, {edge_total} near the edge"
    );
}

/// FREE by a proof kept from an earlier tick (or made for wider balls) survives simulated
/// stops: the runs of the C harness (practical and collision, T1-T3, both models) replayed
/// tick by tick; at every third kept-proof FREE tick, random stops from the true velocity (the
/// finite difference moved within `a_max T`).
#[test]
fn free_verdicts_of_kept_proofs_survive_simulated_stops() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let mut rng = StdRng::seed_from_u64(7);
    let (mut kept_total, mut tested) = (0, 0);
    for s in parse_scenarios(&text).unwrap() {
        for (k, stop) in [STIFF, StopModel::DEFAULT].into_iter().enumerate() {
            let cell = cell(&s.cell, stop);
            let tick = cell.tick_ms * 1e-3;
            let mut checker =
                ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
            let (mut tcps, mut prev) = ([Vec3::zeros(); 2], [Vec3::zeros(); 2]);
            let mut kept = 0;
            for t in 0..RUN_TICKS {
                s.tcps_at(t, &mut tcps);
                let r = checker.check(&tcps).unwrap();
                if r.kept_proof {
                    assert_eq!(r.verdict, Protective::Free);
                    kept += 1;
                    if kept % 3 == 0 {
                        let vel = std::array::from_fn(|j| {
                            let w = (tcps[j] - prev[j]) / tick
                                + unit(&mut rng)
                                    * stop.max_accel_mm_s2
                                    * tick
                                    * rng.random::<Real>();
                            w * (stop.max_speed_mm_s / w.norm()).min(1.0)
                        });
                        assert_stops_never_touch(&cell, &tcps, &vel, 4, &mut rng);
                        tested += 1;
                    }
                }
                prev = tcps;
            }
            println!("{} {} model {k}: {kept} ticks FREE by a kept proof", s.cell, s.case);
            kept_total += kept;
        }
    }
    println!("{tested} kept-proof ticks checked with 4 simulated stops each");
    assert!(kept_total >= 10_000, "too few kept proofs to test: {kept_total}");
}

fn verdict_rank(v: Protective) -> u8 {
    match v {
        Protective::Free => 0,
        Protective::Warn => 1,
        Protective::Stop => 2,
    }
}

#[test]
fn first_tick_assumes_full_speed_and_close_robots_are_never_free() {
    let mut rng = StdRng::seed_from_u64(7);
    for name in ["T1", "T2", "T3"] {
        let cell = cell(name, StopModel::DEFAULT);
        let mut c = ProtectiveChecker::new(cell.clone(), 0.0).unwrap();
        for _ in 0..100 {
            let tcps = [tcp_toward_other(&cell, 0, &mut rng), tcp_toward_other(&cell, 1, &mut rng)];
            c.reset();
            let first = c.check(&tcps).unwrap().clone();
            assert!(first
                .robots
                .iter()
                .all(|r| r.speed_bound_mm_s == 4_600.0 && r.speed_mm_s.is_infinite()));
            let full = c.check_at_speeds(&tcps, &[Real::INFINITY; 2]).unwrap().clone();
            assert_eq!(first.verdict, full.verdict);
            if first.clearance_mm < 100.0 {
                assert_eq!(first.verdict, Protective::Stop, "{name} {tcps:?}");
            }
        }
    }
}

#[test]
fn implausible_jumps_unreachable_and_non_finite_tcps_stop() {
    let cell = cell("T1", STIFF);
    let mut c = ProtectiveChecker::new(cell, 5.0).unwrap();
    let (a, b) = (Vec3::new(-150.0, 0.0, -450.0), Vec3::new(150.0, 0.0, -450.0));
    c.check(&[a, b]).unwrap();
    assert_eq!(c.check(&[a, b]).unwrap().verdict, Protective::Free);
    // 4.6 m/s is 4.6 mm per tick: 5 mm is too far.
    let r = c.check(&[a + Vec3::new(0.0, 5.0, 0.0), b]).unwrap();
    assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::ImplausibleMotion(0)));
    // After an error there is no previous TCP: full speed assumed.
    let r = c.check(&[a, b]).unwrap();
    assert_eq!(r.robots[0].speed_bound_mm_s, 4_600.0);
    c.check(&[a, b]).unwrap();
    // Within the speed limit but a velocity change of 2 m/s in one tick: over 130 m/s^2.
    let r = c.check(&[a, b + Vec3::new(2.0, 0.0, 0.0)]).unwrap();
    assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::ImplausibleMotion(1)));
    c.reset();
    let r = c.check(&[a, Vec3::new(0.0, 0.0, -700.0)]).unwrap();
    assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::Unreachable(1)));
    // An unreachable TCP is no history either.
    let r = c.check(&[a, b]).unwrap();
    assert_eq!((r.status, r.robots[1].speed_bound_mm_s), (ProtectiveStatus::Ok, 4_600.0));
    let r = c.check(&[Vec3::new(0.0, Real::INFINITY, -450.0), b]).unwrap();
    assert_eq!((r.verdict, r.status), (Protective::Stop, ProtectiveStatus::NonFinite(0)));
    assert!(c.check(&[a]).is_err());
}

#[test]
fn a_larger_warn_threshold_never_warns_less() {
    let mut rng = StdRng::seed_from_u64(11);
    for name in ["T1", "T2", "T3"] {
        let cell = cell(name, STIFF);
        let mut checkers: Vec<ProtectiveChecker> = [0.0, 2.0, 10.0, 40.0]
            .iter()
            .map(|&w| ProtectiveChecker::new(cell.clone(), w).unwrap())
            .collect();
        let mut counts = [0usize; 4];
        for _ in 0..150 {
            let tcps = [tcp_toward_other(&cell, 0, &mut rng), tcp_toward_other(&cell, 1, &mut rng)];
            let speeds = [rng.random_range(0.0..1_500.0), rng.random_range(0.0..1_500.0)];
            let ranks: Vec<u8> = checkers
                .iter_mut()
                .map(|c| verdict_rank(c.check_at_speeds(&tcps, &speeds).unwrap().verdict))
                .collect();
            assert!(
                ranks.windows(2).all(|w| w[0] <= w[1]),
                "{name} {tcps:?} {speeds:?}: {ranks:?}"
            );
            for (k, r) in ranks.iter().enumerate() {
                counts[k] += (*r > 0) as usize;
            }
        }
        println!("{name}: WARN+STOP of 150 for warn 0, 2, 10, 40 mm: {counts:?}");
    }
}

#[test]
fn at_the_speed_limit_the_verdict_holds_and_ten_percent_above_it_does_not() {
    let mut rng = StdRng::seed_from_u64(13);
    let mut checked = 0;
    for name in ["T1", "T2", "T3"] {
        for stop in [STIFF, StopModel::DEFAULT] {
            let cell = cell(name, stop);
            let mut c =
                ProtectiveChecker::new(cell.clone(), 0.0).unwrap().with_precise_limits(true);
            let mut cheap = ProtectiveChecker::new(cell.clone(), 0.0).unwrap();
            let resolution = stop.max_speed_mm_s / 256.0;
            for _ in 0..40 {
                let tcps =
                    [tcp_toward_other(&cell, 0, &mut rng), tcp_toward_other(&cell, 1, &mut rng)];
                let speeds = [rng.random_range(0.0..800.0), rng.random_range(0.0..800.0)];
                let r: ProtectiveReport = c.check_at_speeds(&tcps, &speeds).unwrap().clone();
                let fast = cheap.check_at_speeds(&tcps, &speeds).unwrap().clone();
                assert_eq!(fast.verdict, r.verdict);
                for j in 0..2 {
                    // The table tier's limit: never above the precise one, and FREE at it.
                    let low = fast.robots[j].speed_limit_mm_s;
                    assert!(
                        low <= r.robots[j].speed_limit_mm_s,
                        "{name} {tcps:?} {speeds:?}: {low} > {r:?}"
                    );
                    if low > 0.0 {
                        let mut at = speeds;
                        at[j] = low;
                        assert_ne!(
                            cheap.check_at_speeds(&tcps, &at).unwrap().verdict,
                            Protective::Stop
                        );
                    }
                    let limit = r.robots[j].speed_limit_mm_s;
                    let mut at = speeds;
                    at[j] = limit;
                    if limit > 0.0 {
                        assert_ne!(
                            c.check_at_speeds(&tcps, &at).unwrap().verdict,
                            Protective::Stop,
                            "{name} {tcps:?} {at:?}"
                        );
                        checked += 1;
                    }
                    if limit < stop.max_speed_mm_s {
                        at[j] = (1.1 * limit).max(limit + resolution);
                        assert_eq!(
                            c.check_at_speeds(&tcps, &at).unwrap().verdict,
                            Protective::Stop,
                            "{name} {tcps:?} {at:?}"
                        );
                    }
                }
            }
        }
    }
    assert!(checked > 40, "{checked}");
}

#[test]
fn the_speed_limit_through_the_tick_history_gives_a_proof() {
    let cell = cell("T1", STIFF);
    let mut c = ProtectiveChecker::new(cell, 0.0).unwrap();
    let (a, b) = (Vec3::new(60.0, 0.0, -450.0), Vec3::new(-80.0, 0.0, -450.0));
    let r = c.check_at_speeds(&[a, b], &[0.0, 0.0]).unwrap().clone();
    let limit = r.robots[0].speed_limit_mm_s;
    assert!(limit > 0.0 && limit < 4_600.0, "{r:?}");
    // Robot A moving toward B at its limit, measured from the previous TCP.
    let step = Vec3::x() * (limit * 1e-3 * (1.0 - 1e-9));
    c.reset();
    c.check(&[a - step * 2.0, b]).unwrap();
    c.check(&[a - step, b]).unwrap();
    let r = c.check(&[a, b]).unwrap();
    assert_eq!(r.status, ProtectiveStatus::Ok);
    assert_ne!(r.verdict, Protective::Stop, "{r:?}");
}

#[test]
fn a_tick_never_allocates() {
    let cell = cell("T2", STIFF);
    let mut c = ProtectiveChecker::new(cell.clone(), 5.0).unwrap();
    let mut rng = StdRng::seed_from_u64(17);
    let states: Vec<[Vec3; 2]> = (0..64)
        .map(|_| [tcp_toward_other(&cell, 0, &mut rng), tcp_toward_other(&cell, 1, &mut rng)])
        .collect();
    let before = allocations();
    for k in 0..2_000 {
        let s = &states[k % states.len()];
        c.check(s).unwrap();
        c.check_at_speeds(s, &[100.0, 300.0]).unwrap();
    }
    assert_eq!(allocations(), before);
    // Without the speed limits: the same verdicts, NaN limits.
    let mut fast = ProtectiveChecker::new(cell, 5.0).unwrap().with_speed_limits(false);
    for s in &states {
        let full = c.check_at_speeds(s, &[100.0, 300.0]).unwrap().clone();
        let r = fast.check_at_speeds(s, &[100.0, 300.0]).unwrap();
        assert_eq!(r.verdict, full.verdict);
        assert!(r.robots.iter().all(|x| x.speed_limit_mm_s.is_nan()));
    }
}

/// Per scenario of `c_harness/scenarios.txt`: ticks with WARN and STOP, the first of each,
/// the smallest clearance, and that the first STOP comes before the first contact.
fn scenario_counts(stop: StopModel, label: &str) {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    for s in parse_scenarios(&text).unwrap() {
        let cell = cell(&s.cell, stop);
        let mut c = ProtectiveChecker::new(cell.clone(), 10.0).unwrap();
        let mut verdict_only =
            ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
        let mut precise =
            ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_precise_limits(true);
        let (mut limit_ratio, mut limited) = (0.0, 0);
        let mut exact = ExactChecker::new(cell);
        let mut tcps = vec![Vec3::zeros(); s.robots.len()];
        let (mut t_full, mut t_verdict, mut t_exact) = (
            Vec::with_capacity(RUN_TICKS as usize),
            Vec::with_capacity(RUN_TICKS as usize),
            Vec::with_capacity(RUN_TICKS as usize),
        );
        let (mut warn, mut stops, mut implausible) = (0, 0, 0);
        let (mut first_warn, mut first_stop, mut first_contact) = (None, None, None);
        let mut min_clear = Real::INFINITY;
        let started = std::time::Instant::now();
        for tick in 0..RUN_TICKS {
            s.tcps_at(tick, &mut tcps);
            let t0 = std::time::Instant::now();
            let v = verdict_only.check(&tcps).unwrap().verdict;
            let t1 = std::time::Instant::now();
            let hit = exact.check(&tcps).unwrap().collides();
            let t2 = std::time::Instant::now();
            let r = c.check(&tcps).unwrap();
            t_full.push(t2.elapsed().as_secs_f64() * 1e6);
            let p = precise.check(&tcps).unwrap();
            assert_eq!(p.verdict, r.verdict);
            for (fast, slow) in r.robots.iter().zip(&p.robots) {
                assert!(
                    fast.speed_limit_mm_s <= slow.speed_limit_mm_s,
                    "tick {tick}: {fast:?} {slow:?}"
                );
                if slow.speed_limit_mm_s > 0.0 {
                    (limit_ratio, limited) =
                        (limit_ratio + fast.speed_limit_mm_s / slow.speed_limit_mm_s, limited + 1);
                }
            }
            t_verdict.push((t1 - t0).as_secs_f64() * 1e6);
            t_exact.push((t2 - t1).as_secs_f64() * 1e6);
            assert_eq!(
                v, r.verdict,
                "tick {tick}: the verdict does not depend on the speed limits"
            );
            min_clear = min_clear.min(r.clearance_mm);
            implausible += matches!(r.status, ProtectiveStatus::ImplausibleMotion(_)) as u32;
            match r.verdict {
                Protective::Warn => {
                    warn += 1;
                    first_warn.get_or_insert(tick);
                }
                Protective::Stop => {
                    stops += 1;
                    first_stop.get_or_insert(tick);
                }
                Protective::Free => {}
            }
            if first_contact.is_none() && hit {
                first_contact = Some(tick);
            }
        }
        let us = started.elapsed().as_secs_f64() * 1e6 / RUN_TICKS as f64;
        let median = |t: &mut Vec<f64>| {
            t.sort_by(f64::total_cmp);
            (t[t.len() / 2], t[t.len() * 99 / 100])
        };
        let ((full, full99), (verdict, verdict99), (plain, _)) =
            (median(&mut t_full), median(&mut t_verdict), median(&mut t_exact));
        println!(
            "{label} {} {}: STOP {stops} WARN {warn} ticks of {RUN_TICKS}, first WARN {first_warn:?} first STOP \
             {first_stop:?} first contact {first_contact:?}, min clearance {min_clear:.1} mm, implausible {implausible}, \
             {us:.0} us/tick in all; median (p99) us per tick: with limits {full:.1} ({full99:.1}), verdict {verdict:.2} \
             ({verdict99:.1}), exact {plain:.2}; table-tier speed limit / precise: {:.3} on average",
            s.cell, s.case, limit_ratio / limited.max(1) as f64
        );
        assert_eq!(implausible, 0, "the scenarios respect the stopping model's limits");
        if let Some(contact) = first_contact {
            assert!(first_stop.is_some_and(|t| t < contact), "STOP must come before contact");
        }
    }
}

#[test]
fn scenario_counts_with_the_default_and_a_stiff_model() {
    scenario_counts(StopModel::DEFAULT, "default");
    scenario_counts(STIFF, "stiff");
}

/// A C handle on T1's robots with the default stopping models.
fn t1_handle_with_default_stops() -> *mut delta_collide::ffi::DcCollider {
    use delta_collide::ffi::*;
    let mut robots = [dc_robot_config_thesis(); 2];
    robots[1].translation = DcVec3 { x: 450.0, y: 0.0, z: 0.0 };
    let config = DcCellConfig { robots: robots.as_ptr(), n_robots: 2, method: DC_METHOD_SAT_CACHE };
    let mut h = std::ptr::null_mut();
    // SAFETY: valid config and out pointer.
    assert_eq!(unsafe { dc_init(&config, &mut h) }, DC_STATUS_OK);
    let stops = [dc_stop_config_default(); 2];
    // SAFETY: live handle, two readable configs.
    assert_eq!(unsafe { dc_set_stop_model(h, 1.0, 10.0, stops.as_ptr(), 2) }, DC_STATUS_OK);
    h
}

/// `dc_protective_query` through the C ABI: no allocation per call, FREE for robots standing
/// apart, and the report's per-robot fields filled.
#[test]
fn the_c_entry_point_never_allocates_and_fills_the_report() {
    use delta_collide::ffi::*;
    let h = t1_handle_with_default_stops();
    let tcps = [DcVec3 { x: -150.0, y: 0.0, z: -450.0 }, DcVec3 { x: 150.0, y: 0.0, z: -450.0 }];
    let mut verdict = DC_VERDICT_STOP;
    let mut report = std::mem::MaybeUninit::<DcProtectiveReport>::zeroed();
    let before = allocations();
    for _ in 0..1_000 {
        // SAFETY: live handle, two readable TCPs, writable outputs.
        let s =
            unsafe { dc_protective_query(h, tcps.as_ptr(), 2, &mut verdict, report.as_mut_ptr()) };
        assert_eq!(s, DC_STATUS_OK);
    }
    assert_eq!(allocations(), before);
    // SAFETY: written by every call above.
    let report = unsafe { report.assume_init() };
    assert_eq!((verdict, report.verdict, report.n_robots), (DC_VERDICT_FREE, DC_VERDICT_FREE, 2));
    assert!(
        report.clearance_mm > 100.0
            && report.protective_mm[0] > 0.0
            && report.speed_limit_mm_s[1] > 0.0
    );
    assert_eq!(
        (report.closest_robot_a, report.closest_robot_b, report.limiting_robot_a),
        (0, 1, DC_BOX_NONE)
    );
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

/// `dc_set_speed_limits`: with the limits off the verdicts of T1's practical run through the C
/// ABI are those with the limits on, the limits read NaN, nothing allocates, the setting
/// survives `dc_set_stop_model`, and a bad value or NULL handle is a status.
#[test]
fn speed_limits_off_give_the_same_verdicts_and_nan_limits() {
    use delta_collide::ffi::*;
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let s = parse_scenarios(&text)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == "practical")
        .unwrap();
    let (on, off) = (t1_handle_with_default_stops(), t1_handle_with_default_stops());
    // SAFETY: live handles (and NULL, rejected).
    unsafe {
        assert_eq!(dc_set_speed_limits(off, 2), DC_STATUS_INVALID_ARGUMENT);
        assert_eq!(dc_set_speed_limits(std::ptr::null_mut(), 0), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_set_speed_limits(off, 0), DC_STATUS_OK);
        let stops = [dc_stop_config_default(); 2];
        assert_eq!(dc_set_stop_model(off, 1.0, 10.0, stops.as_ptr(), 2), DC_STATUS_OK);
    }
    let mut tcps = [Vec3::zeros(); 2];
    // SAFETY: the report holds numbers only, for which all-zero bytes are valid values.
    let zeroed = || unsafe { std::mem::MaybeUninit::<DcProtectiveReport>::zeroed().assume_init() };
    let (mut report_on, mut report_off) = (zeroed(), zeroed());
    let (mut verdict_on, mut verdict_off, mut free) = (DC_VERDICT_STOP, DC_VERDICT_STOP, 0);
    let mut allocated = 0;
    for tick in 0..RUN_TICKS {
        s.tcps_at(tick, &mut tcps);
        let c = tcps.map(|t| DcVec3 { x: t.x, y: t.y, z: t.z });
        // SAFETY: live handles, two readable TCPs, writable outputs.
        unsafe {
            assert_eq!(
                dc_protective_query(on, c.as_ptr(), 2, &mut verdict_on, &mut report_on),
                DC_STATUS_OK
            );
            let before = allocations();
            assert_eq!(
                dc_protective_query(off, c.as_ptr(), 2, &mut verdict_off, &mut report_off),
                DC_STATUS_OK
            );
            allocated += allocations() - before;
        }
        assert_eq!(verdict_off, verdict_on, "tick {tick}");
        assert!(report_off.speed_limit_mm_s[..2].iter().all(|v| v.is_nan()), "tick {tick}");
        assert!(report_on.speed_limit_mm_s[..2].iter().all(|v| v.is_finite()), "tick {tick}");
        free += (verdict_on == DC_VERDICT_FREE) as u32;
    }
    assert_eq!(allocated, 0);
    assert!(free > 1_000, "{free} FREE ticks");
    // SAFETY: live handles, destroyed once.
    unsafe {
        dc_destroy(on);
        dc_destroy(off);
    }
}

/// Reports of `checker` over ticks `ticks` of scenario `s`, with the programmed path ahead as
/// the stop paths on even ticks.
fn run_reports(
    checker: &mut ProtectiveChecker,
    s: &Scenario,
    ticks: std::ops::Range<u32>,
) -> Vec<ProtectiveReport> {
    let mut tcps = vec![Vec3::zeros(); s.robots.len()];
    let mut points = vec![[Vec3::zeros(); 32]; s.robots.len()];
    let mut out = Vec::new();
    for tick in ticks {
        s.tcps_at(tick, &mut tcps);
        let paths = programmed_paths(s, tick, &mut points);
        let request = ProtectiveRequest::new(&tcps);
        let request = if tick % 2 == 0 { request.with_paths(&paths) } else { request };
        out.push(checker.check(request).unwrap().clone());
    }
    out
}

/// A checker reset answers a run bit for bit as a new one does (no warm start or kept proof
/// of the run before it survives), with paths too, and the reset allocates nothing.
#[test]
fn a_reset_checker_answers_as_a_new_one() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    for s in parse_scenarios(&text).unwrap().iter().filter(|s| s.case == "practical") {
        let fresh = ProtectiveChecker::new(cell(&s.cell, StopModel::DEFAULT), 10.0).unwrap();
        let mut used = fresh.clone();
        run_reports(&mut used, s, 1_000..1_700);
        let before = allocations();
        used.reset();
        assert_eq!(allocations(), before, "{}: the reset allocated", s.cell);
        let again = run_reports(&mut used, s, 0..1_500);
        let new = run_reports(&mut fresh.clone(), s, 0..1_500);
        for (tick, (a, b)) in again.iter().zip(&new).enumerate() {
            assert_eq!(a.clearance_mm.to_bits(), b.clearance_mm.to_bits(), "{} {tick}", s.cell);
            assert_eq!(a, b, "{} tick {tick}", s.cell);
        }
    }
}

/// `dc_set_limit_tests`: the verdicts of T1's practical run are the same with no limit tests,
/// the default budget and the full search; with none each limit is the tick's floor, at most
/// the default budget's and below it on many ticks; the full search's limits are the highest on
/// average; nothing allocates; the cap survives `dc_set_stop_model`; a NULL handle is a status.
#[test]
fn the_c_abi_caps_the_limit_tests_without_changing_the_verdicts() {
    use delta_collide::ffi::*;
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let s = parse_scenarios(&text)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == "practical")
        .unwrap();
    let handles = [
        t1_handle_with_default_stops(),
        t1_handle_with_default_stops(),
        t1_handle_with_default_stops(),
    ];
    // SAFETY: live handles (and NULL, rejected).
    unsafe {
        assert_eq!(dc_set_limit_tests(std::ptr::null_mut(), 0), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_set_limit_tests(handles[0], 0), DC_STATUS_OK);
        assert_eq!(dc_set_limit_tests(handles[2], u32::MAX), DC_STATUS_OK);
        let stops = [dc_stop_config_default(); 2];
        assert_eq!(dc_set_stop_model(handles[0], 1.0, 10.0, stops.as_ptr(), 2), DC_STATUS_OK);
    }
    let mut tcps = [Vec3::zeros(); 2];
    // SAFETY: the report holds numbers only, for which all-zero bytes are valid values.
    let zeroed = || unsafe { std::mem::MaybeUninit::<DcProtectiveReport>::zeroed().assume_init() };
    let mut reports = [zeroed(), zeroed(), zeroed()];
    let mut verdicts = [DC_VERDICT_STOP; 3];
    let (mut lower, mut sums, mut allocated) = (0, [0.0; 3], 0);
    for tick in 0..RUN_TICKS {
        s.tcps_at(tick, &mut tcps);
        let c = tcps.map(|t| DcVec3 { x: t.x, y: t.y, z: t.z });
        for ((h, v), r) in handles.iter().zip(&mut verdicts).zip(&mut reports) {
            let before = allocations();
            // SAFETY: live handles, two readable TCPs, writable outputs.
            assert_eq!(unsafe { dc_protective_query(*h, c.as_ptr(), 2, v, r) }, DC_STATUS_OK);
            allocated += allocations() - before;
        }
        assert!(verdicts.iter().all(|v| *v == verdicts[0]), "tick {tick}: {verdicts:?}");
        for j in 0..2 {
            let [none, default, full] = reports.map(|r| r.speed_limit_mm_s[j]);
            assert!(none <= default * (1.0 + 1e-12), "tick {tick}, robot {j}: {none} > {default}");
            lower += usize::from(none < default * 0.99);
            for (sum, v) in sums.iter_mut().zip([none, default, full]) {
                *sum += v;
            }
        }
    }
    assert_eq!(allocated, 0);
    assert!(
        lower > 1_000,
        "the default budget finds higher limits than the floor on {lower} robot ticks"
    );
    assert!(sums[0] < sums[1] && sums[1] <= sums[2], "mean limits: none, default, full {sums:?}");
    // SAFETY: live handles, destroyed once.
    handles.iter().for_each(|&h| unsafe { dc_destroy(h) });
}

/// `dc_protective_query_with_paths` through the C ABI: no allocation per call while the
/// robots move toward each other along their paths, and a status naming the robot for every
/// kind of bad path.
#[test]
fn the_c_entry_point_with_paths_never_allocates_and_names_a_bad_path() {
    use delta_collide::ffi::*;
    let h = t1_handle_with_default_stops();
    let at = |k: f64| {
        [
            DcVec3 { x: -100.0 + 0.5 * k, y: 20.0, z: -450.0 },
            DcVec3 { x: 100.0 - 0.5 * k, y: -20.0, z: -450.0 },
        ]
    };
    // Each robot's path: straight on toward the other for 60 mm, then back up.
    let path_of = |p: DcVec3, dx: f64| {
        [p, DcVec3 { x: p.x + dx, ..p }, DcVec3 { x: p.x + dx, z: p.z + 80.0, ..p }]
    };
    let (mut verdict, mut report) =
        (DC_VERDICT_STOP, std::mem::MaybeUninit::<DcProtectiveReport>::zeroed());
    let query = |h,
                 tcps: &[DcVec3; 2],
                 paths: &[DcStopPath],
                 verdict: &mut DcVerdict,
                 report: *mut DcProtectiveReport| {
        // SAFETY: live handle, readable TCPs and paths (whose points outlive the call), writable
        // outputs.
        unsafe {
            dc_protective_query_with_paths(
                h,
                tcps.as_ptr(),
                2,
                paths.as_ptr(),
                paths.len(),
                verdict,
                report,
            )
        }
    };
    let (mut seen, before) = ([0u32; 3], allocations());
    for k in 0..160 {
        let tcps = at(k as f64);
        let (pa, pb) = (path_of(tcps[0], 60.0), path_of(tcps[1], -60.0));
        let paths = [
            DcStopPath { points: pa.as_ptr(), n_points: 3, tolerance_mm: 0.5 },
            DcStopPath { points: pb.as_ptr(), n_points: 3, tolerance_mm: 0.5 },
        ];
        assert_eq!(
            query(h, &tcps, &paths, &mut verdict, report.as_mut_ptr()),
            DC_STATUS_OK,
            "call {k}"
        );
        seen[verdict as usize] += 1;
    }
    assert_eq!(allocations(), before, "verdicts seen (free, warn, stop): {seen:?}");
    let tcps = at(160.0);
    let on = path_of(tcps[0], 60.0);
    let good = DcStopPath { points: on.as_ptr(), n_points: 3, tolerance_mm: 0.5 };
    let none = DcStopPath { points: std::ptr::null(), n_points: 0, tolerance_mm: 0.0 };
    let off = [DcVec3 { y: 60.0, ..tcps[0] }, DcVec3 { x: 0.0, y: 60.0, z: -450.0 }];
    let many = [tcps[1]; DC_MAX_PATH_POINTS + 1];
    let cases = [
        (
            [none, DcStopPath { points: std::ptr::null(), n_points: 2, tolerance_mm: 1.0 }],
            DC_STATUS_NULL_POINTER,
            2,
        ),
        (
            [DcStopPath { points: off.as_ptr(), n_points: 2, tolerance_mm: 1.0 }, none],
            DC_STATUS_INVALID_ARGUMENT,
            1,
        ),
        ([DcStopPath { tolerance_mm: f64::NAN, ..good }, none], DC_STATUS_INVALID_ARGUMENT, 1),
        ([DcStopPath { tolerance_mm: -1.0, ..good }, none], DC_STATUS_INVALID_ARGUMENT, 1),
        (
            [good, DcStopPath { points: many.as_ptr(), n_points: many.len(), tolerance_mm: 1.0 }],
            DC_STATUS_INVALID_ARGUMENT,
            2,
        ),
    ];
    for (i, (paths, status, mask)) in cases.iter().enumerate() {
        verdict = DC_VERDICT_FREE;
        assert_eq!(query(h, &tcps, paths, &mut verdict, report.as_mut_ptr()), *status, "case {i}");
        // SAFETY: written by the call.
        let r = unsafe { report.assume_init_ref() };
        assert_eq!(
            (verdict, r.verdict, r.unreachable_mask),
            (DC_VERDICT_STOP, DC_VERDICT_STOP, *mask),
            "case {i}"
        );
    }
    // One path per robot, and the paths array itself.
    assert_eq!(
        query(h, &tcps, &[good], &mut verdict, report.as_mut_ptr()),
        DC_STATUS_WRONG_ROBOT_COUNT
    );
    // SAFETY: live handle, readable TCPs; a NULL paths pointer is the case under test.
    let s = unsafe {
        dc_protective_query_with_paths(
            h,
            tcps.as_ptr(),
            2,
            std::ptr::null(),
            2,
            &mut verdict,
            report.as_mut_ptr(),
        )
    };
    assert_eq!((s, verdict), (DC_STATUS_NULL_POINTER, DC_VERDICT_STOP));
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

/// The speed limits of a capped search (the default: a few tests per tick, all robots
/// together) are proved speeds: over the runs of the C harness (T1-T3, practical and
/// collision, both models), every fifth tick, each robot's reported limit is checked again by
/// a separate checker that sees the robot arrive at its TCP at exactly that speed in its
/// measured direction (the other robot as it moved): that verdict, a full proof of its own,
/// must not be STOP. Also: a limit is never below the measured speed of a tick whose verdict
/// is not STOP (that verdict proved it), and with no tests at all the limit is that speed (or
/// 0 at a STOP). Prints how far below the uncapped search's limits the capped ones are.
#[test]
fn capped_speed_limits_are_proved_when_checked_again_by_another_checker() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let (mut rechecked, mut lower, mut compared) = (0, 0, 0);
    for s in parse_scenarios(&text).unwrap() {
        for (k, stop) in [STIFF, StopModel::DEFAULT].into_iter().enumerate() {
            let cell = cell(&s.cell, stop);
            let tick = cell.tick_ms * 1e-3;
            let mut capped = ProtectiveChecker::new(cell.clone(), 10.0).unwrap();
            let mut full = capped.clone().with_limit_tests(u32::MAX);
            let mut none = capped.clone().with_limit_tests(0);
            let mut oracle = capped.clone().with_speed_limits(false);
            let (mut tcps, mut prev) = ([Vec3::zeros(); 2], [Vec3::zeros(); 2]);
            let (mut ratio, mut ratios) = (0.0, 0);
            for t in 0..RUN_TICKS {
                s.tcps_at(t, &mut tcps);
                let r = capped.check(&tcps).unwrap().clone();
                let f = full.check(&tcps).unwrap().clone();
                let z = none.check(&tcps).unwrap().clone();
                assert_eq!((f.verdict, z.verdict), (r.verdict, r.verdict), "tick {t}");
                for j in 0..2 {
                    let (limit, v) = (r.robots[j].speed_limit_mm_s, r.robots[j].speed_mm_s);
                    assert!((0.0..=stop.max_speed_mm_s).contains(&limit), "tick {t}: {r:?}");
                    let floor = if r.verdict != Protective::Stop && v <= stop.max_speed_mm_s {
                        v
                    } else {
                        0.0
                    };
                    assert!(
                        limit >= floor,
                        "tick {t} robot {j}: limit {limit} below the proved {floor}"
                    );
                    assert_eq!(
                        z.robots[j].speed_limit_mm_s, floor,
                        "tick {t} robot {j}: no tests, {z:?}"
                    );
                    let uncapped = f.robots[j].speed_limit_mm_s;
                    if uncapped > 0.0 {
                        (ratio, ratios) = (ratio + limit / uncapped, ratios + 1);
                        lower += usize::from(limit < uncapped);
                        compared += 1;
                    }
                    // The check again: robot j arrives at `limit` along its measured direction.
                    let dir = tcps[j] - prev[j];
                    if t % 5 != 0 || t == 0 || limit == 0.0 || dir.norm() == 0.0 {
                        continue;
                    }
                    let mut before = prev;
                    before[j] = tcps[j] - dir * (limit * tick / dir.norm());
                    oracle.reset();
                    oracle.check(&before).unwrap();
                    let again = oracle.check(&tcps).unwrap();
                    assert_eq!(again.status, ProtectiveStatus::Ok, "tick {t} robot {j}");
                    assert!((again.robots[j].speed_mm_s - limit).abs() <= 1e-6 * limit.max(1.0));
                    assert_ne!(
                        again.verdict,
                        Protective::Stop,
                        "{} {} model {k} tick {t} robot {j}: limit {limit} not proved: {again:?}",
                        s.cell,
                        s.case
                    );
                    rechecked += 1;
                }
                prev = tcps;
            }
            println!(
                "{} {} model {k}: capped limit / uncapped limit {:.3} on average",
                s.cell,
                s.case,
                ratio / ratios.max(1) as f64
            );
        }
    }
    println!("{rechecked} limits checked again; capped below uncapped at {lower} of {compared} robot ticks");
    assert!(rechecked > 2_000, "too few limits checked again: {rechecked}");
}
