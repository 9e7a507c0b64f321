//! A handle's tick statistics through the C ABI (`dc_tick_stats`, `src/ffi/stats.rs`): each
//! kind of call counted on its own, the largest time at least the last and the mean between
//! the least and the largest (times measured here around the same calls bound them), the
//! speed limits' proof tests as work with the ticks that spent their cap, the reset, the
//! statuses of bad arguments, and no allocation.

mod ffi_common;
mod protective_common;

use delta_collide::ffi::*;
use ffi_common::two_robot_cell;
use protective_common::allocations;
use std::time::Instant;

fn stats(h: *mut DcCollider) -> DcTickStats {
    let mut out = DcTickStats {
        struct_size: std::mem::size_of::<DcTickStats>() as u32,
        ..Default::default()
    };
    // SAFETY: live handle, writable out with its size set.
    assert_eq!(unsafe { dc_tick_stats(h, &mut out) }, DC_STATUS_OK);
    out
}

/// A protective query of T1 with robot 1's TCP at `x` (robot 0 stands).
fn protective(h: *mut DcCollider, x: f64) -> DcStatus {
    let tcps = [DcVec3 { x: -150.0, y: 0.0, z: -450.0 }, DcVec3 { x, y: 0.0, z: -450.0 }];
    let mut verdict = DC_VERDICT_STOP;
    let mut report = std::mem::MaybeUninit::<DcProtectiveReport>::zeroed();
    // SAFETY: live handle, two readable TCPs, writable outputs.
    unsafe { dc_protective_query(h, tcps.as_ptr(), 2, &mut verdict, report.as_mut_ptr()) }
}

#[test]
fn each_kind_of_call_is_counted_timed_and_reset() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT_CACHE);
    let stops = [dc_stop_config_default(); 2];
    // SAFETY: live handle, two readable configs.
    assert_eq!(unsafe { dc_set_stop_model(h, 1.0, 10.0, stops.as_ptr(), 2) }, DC_STATUS_OK);
    assert_eq!(stats(h), DcTickStats { struct_size: stats(h).struct_size, ..Default::default() });

    // 200 protective queries, robot 1 moving 1 mm a tick toward robot 0; 50 exact queries.
    let (mut least, mut most) = (u64::MAX, 0u64);
    for k in 0..200 {
        let t0 = Instant::now();
        assert_eq!(protective(h, 150.0 - f64::from(k) * 0.5), DC_STATUS_OK);
        let ns = t0.elapsed().as_nanos() as u64;
        (least, most) = (least.min(ns), most.max(ns));
    }
    let tcps = [DcVec3 { x: -150.0, y: 0.0, z: -450.0 }, DcVec3 { x: 150.0, y: 0.0, z: -450.0 }];
    for _ in 0..50 {
        let (s, _, _) = ffi_common::query(h, &tcps);
        assert_eq!(s, DC_STATUS_OK);
    }
    let before = allocations();
    let s = stats(h);
    assert_eq!(allocations(), before, "dc_tick_stats allocated");
    println!("{s:?}");
    assert_eq!((s.protective.calls, s.query.calls, s.coordinate.calls), (200, 50, 0));
    let p = s.protective;
    assert!(p.largest_ns >= p.last_ns && p.largest_ns >= p.mean_ns && p.mean_ns > 0, "{p:?}");
    // Inside the library, each call within the time measured around it here.
    assert!(p.largest_ns <= most, "largest {} ns, measured around {most} ns", p.largest_ns);
    assert!(p.mean_ns <= most && least > 0, "{p:?}");
    // The speed limits search with proof tests, capped per tick (n + 2 by default).
    assert!(p.largest_work > 0 && p.largest_work >= p.last_work, "{p:?}");
    assert_eq!(s.query.largest_work, 0, "dc_query reports no work");

    // A cap of one test per tick: every tick with a history spends it.
    // SAFETY: live handle.
    unsafe {
        assert_eq!(dc_tick_stats_reset(h), DC_STATUS_OK);
        assert_eq!(dc_set_limit_tests(h, 1), DC_STATUS_OK);
    }
    for k in 0..20 {
        assert_eq!(protective(h, 50.0 - f64::from(k) * 0.5), DC_STATUS_OK);
    }
    let p = stats(h).protective;
    assert_eq!(p.calls, 20, "{p:?}");
    assert!(p.largest_work <= 2 && p.budget_spent >= 18, "one test a tick, spent: {p:?}");
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

/// A protective query with paths of T1: robot 1 at `x` comes toward robot 0 along x, its
/// stop path the next 60 mm of that line; robot 0 stands, its path its one point.
fn protective_with_paths(h: *mut DcCollider, x: f64) -> DcStatus {
    let tcps = [DcVec3 { x: -150.0, y: 0.0, z: -450.0 }, DcVec3 { x, y: 0.0, z: -450.0 }];
    let ahead: Vec<DcVec3> =
        (0..16).map(|k| DcVec3 { x: x - 4.0 * f64::from(k), y: 0.0, z: -450.0 }).collect();
    let paths = [
        DcStopPath { points: &tcps[0], n_points: 1, tolerance_mm: 0.5 },
        DcStopPath { points: ahead.as_ptr(), n_points: ahead.len(), tolerance_mm: 0.5 },
    ];
    let mut verdict = DC_VERDICT_STOP;
    let mut report = std::mem::MaybeUninit::<DcProtectiveReport>::zeroed();
    // SAFETY: live handle, two readable TCPs and paths, writable outputs.
    unsafe {
        dc_protective_query_with_paths(
            h,
            tcps.as_ptr(),
            2,
            paths.as_ptr(),
            2,
            &mut verdict,
            report.as_mut_ptr(),
        )
    }
}

/// `dc_set_path_work`: the work of a query with paths is its limit tests plus its units along
/// the paths, within the caps; a small cap is spent and counted, and the setting outlives
/// `dc_set_stop_model`.
#[test]
fn the_work_along_the_paths_is_capped_and_counted() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT_CACHE);
    let stops = [dc_stop_config_default(); 2];
    // SAFETY: live handle or NULL; two readable configs.
    unsafe {
        assert_eq!(dc_set_path_work(std::ptr::null_mut(), 5), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_set_path_work(h, 5), DC_STATUS_OK);
        assert_eq!(dc_set_stop_model(h, 1.0, 10.0, stops.as_ptr(), 2), DC_STATUS_OK);
        assert_eq!(dc_set_limit_tests(h, 3), DC_STATUS_OK);
    }
    for k in 0..40 {
        assert_eq!(protective_with_paths(h, 120.0 - f64::from(k) * 1.0), DC_STATUS_OK);
    }
    let p = stats(h).protective;
    assert!(p.largest_work <= 3 + 5, "at most 3 tests and 5 units: {p:?}");
    assert!(p.budget_spent >= 30, "a cap of 5 units is spent: {p:?}");
    // No cap: more work than 5 units on the same ticks, and none of it cut short.
    // SAFETY: live handle.
    unsafe {
        dc_protective_reset(h);
        assert_eq!(dc_tick_stats_reset(h), DC_STATUS_OK);
        assert_eq!(dc_set_limit_tests(h, u32::MAX), DC_STATUS_OK);
        assert_eq!(dc_set_path_work(h, u32::MAX), DC_STATUS_OK);
    }
    for k in 0..40 {
        assert_eq!(protective_with_paths(h, 120.0 - f64::from(k) * 1.0), DC_STATUS_OK);
    }
    let p = stats(h).protective;
    assert!(p.largest_work > 8 && p.budget_spent == 0, "{p:?}");
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

#[test]
fn bad_arguments_have_their_status_and_write_nothing() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT);
    let mut out = DcTickStats { struct_size: 8, ..Default::default() };
    // SAFETY: live handle or NULL; `out` writable.
    unsafe {
        assert_eq!(dc_tick_stats(h, &mut out), DC_STATUS_INVALID_ARGUMENT);
        // A NULL handle is NULL whatever the size (found by the c_abi fuzz target).
        assert_eq!(dc_tick_stats(std::ptr::null_mut(), &mut out), DC_STATUS_NULL_POINTER);
        assert_eq!(out, DcTickStats { struct_size: 8, ..Default::default() }, "written");
        out.struct_size = std::mem::size_of::<DcTickStats>() as u32;
        assert_eq!(dc_tick_stats(std::ptr::null_mut(), &mut out), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_tick_stats(h, std::ptr::null_mut()), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_tick_stats_reset(std::ptr::null_mut()), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_tick_stats(h, &mut out), DC_STATUS_OK);
        dc_destroy(h);
    }
}
