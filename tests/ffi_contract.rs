//! The C ABI's contract, exercised from Rust through the exported functions themselves:
//! fail-closed outputs, every bad input's status, and no allocation in `dc_query`, in exact
//! and in table mode (a T1 table built here at k = 16). Table-mode init errors and answers:
//! `ffi_table_contract.rs`.

mod ffi_common;

use delta_collide::ffi::*;
use ffi_common::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::CStr;

/// Counts allocations per thread (tests run in parallel threads of one process).
struct Counting;
thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count_allocation() {
    // `try_with`: the thread-local may already be gone while a thread shuts down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

// SAFETY: forwards to the system allocator unchanged; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// 1,000,000 `dc_query` calls on `h` cycling through `ring`, each asserted OK: (free
/// verdicts, collision verdicts, allocations made by the calls).
fn query_million_ticks(h: *mut DcCollider, ring: &[[DcVec3; 2]]) -> (u32, u32, usize) {
    let mut verdict = DC_VERDICT_STOP;
    let mut report = zero_report();
    let (mut free, mut hit) = (0, 0);
    let before = allocations();
    for i in 0..1_000_000 {
        let tcps = &ring[i % ring.len()];
        // SAFETY: live handle, valid slices and outputs.
        let s = unsafe { dc_query(h, tcps.as_ptr(), 2, &mut verdict, &mut report) };
        assert_eq!(s, DC_STATUS_OK);
        if verdict == DC_VERDICT_FREE {
            free += 1
        } else {
            hit += 1
        }
    }
    (free, hit, allocations() - before)
}

#[test]
fn query_does_not_allocate_over_a_million_ticks() {
    for method in [DC_METHOD_SAT, DC_METHOD_SAT_CACHE] {
        let h = two_robot_cell(450.0, method);
        let ring: Vec<[DcVec3; 2]> = (0..128)
            .map(|i| {
                let s = i as f64 / 127.0;
                [v(-150.0 + 330.0 * s, 30.0, -450.0), v(150.0 - 330.0 * s, -20.0, -430.0)]
            })
            .collect();
        let (free, hit, allocated) = query_million_ticks(h, &ring);
        assert_eq!(allocated, 0, "dc_query allocated");
        assert!(
            free > 0 && hit > 0,
            "the ring covers both verdicts ({free} free, {hit} collisions)"
        );
        // SAFETY: live handle, destroyed once.
        unsafe { dc_destroy(h) };
    }
}

#[test]
fn table_mode_query_does_not_allocate_over_a_million_ticks() {
    // Toward each other through the shared space; every 16th tick robot A is above the
    // sampled workspace (z = -340, reachable): the exact fallback must not allocate either.
    let ring: Vec<[DcVec3; 2]> = (0..128)
        .map(|i| {
            let s = i as f64 / 127.0;
            let z = if i % 16 == 0 { -340.0 } else { -450.0 };
            [v(-150.0 + 330.0 * s, 30.0, z), v(150.0 - 330.0 * s, -20.0, -430.0)]
        })
        .collect();
    // With and without the exact check confirming a COLLISION lookup.
    for confirmation in [DC_CONFIRMATION_EXACT, DC_CONFIRMATION_NONE] {
        let h = t1_table_handle();
        // SAFETY: live handle.
        assert_eq!(unsafe { dc_set_table_confirmation(h, confirmation) }, DC_STATUS_OK);
        let (free, hit, allocated) = query_million_ticks(h, &ring);
        assert_eq!(allocated, 0, "dc_query allocated in table mode (confirmation {confirmation})");
        assert!(
            free > 0 && hit > 0,
            "the ring covers both verdicts ({free} free, {hit} collisions)"
        );
        // SAFETY: live handle.
        let (fallbacks, confirmations) =
            unsafe { (dc_table_fallbacks(h), dc_table_confirmations(h)) };
        assert_eq!(fallbacks, 1_000_000 / 16, "one exact fallback per out-of-grid tick");
        if confirmation == DC_CONFIRMATION_EXACT {
            // A COLLISION verdict comes from a confirmed lookup or from a fallback.
            assert!(
                confirmations + fallbacks >= u64::from(hit),
                "{confirmations} confirmed, {hit} collisions"
            );
            assert!(
                confirmations > 0 && confirmations < 1_000_000 - fallbacks,
                "{confirmations} confirmed"
            );
        } else {
            assert_eq!(confirmations, 0, "nothing is confirmed with DC_CONFIRMATION_NONE");
        }
        // SAFETY: live handle, destroyed once.
        unsafe { dc_destroy(h) };
    }
}

#[test]
fn line_table_mode_query_does_not_allocate_over_a_million_ticks() {
    let line: Vec<DcRobotConfig> = (0..4)
        .map(|j| DcRobotConfig {
            translation: v(450.0 * j as f64, 0.0, 0.0),
            ..dc_robot_config_thesis()
        })
        .collect();
    let config = DcCellConfig { robots: line.as_ptr(), n_robots: 4, method: DC_METHOD_SAT };
    let (s, h) = init_table(&config, line4_bundle_bytes());
    assert_eq!(s, DC_STATUS_OK, "{}", last_init_error());
    // Neighbours reach toward each other; every 16th tick R2 is above the sampled workspace
    // (z = -340, reachable), so its pairs fall back to the exact check.
    let ring: Vec<[DcVec3; 4]> = (0..128)
        .map(|i| {
            let s = i as f64 / 127.0;
            let z = if i % 16 == 0 { -340.0 } else { -450.0 };
            [
                v(-150.0 + 330.0 * s, 30.0, -450.0),
                v(150.0 - 330.0 * s, -20.0, z),
                v(0.0, 0.0, -450.0),
                v(-150.0 + 330.0 * s, 0.0, -430.0),
            ]
        })
        .collect();
    let mut verdict = DC_VERDICT_STOP;
    let mut report = zero_report();
    let (mut free, mut hit) = (0, 0);
    let before = allocations();
    for i in 0..1_000_000 {
        let tcps = &ring[i % ring.len()];
        // SAFETY: live handle, valid slices and outputs.
        assert_eq!(
            unsafe { dc_query(h, tcps.as_ptr(), 4, &mut verdict, &mut report) },
            DC_STATUS_OK
        );
        if verdict == DC_VERDICT_FREE {
            free += 1
        } else {
            hit += 1
        }
    }
    assert_eq!(allocations() - before, 0, "dc_query allocated on a bundle");
    assert!(free > 0 && hit > 0, "the ring covers both verdicts ({free} free, {hit} collisions)");
    // SAFETY: live handle.
    let (fallbacks, confirmations) = unsafe { (dc_table_fallbacks(h), dc_table_confirmations(h)) };
    assert!(
        fallbacks > 0 && confirmations > 0,
        "{fallbacks} fallbacks, {confirmations} confirmations"
    );
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

#[test]
fn every_bad_input_gets_its_status_and_stop() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT_CACHE);
    let home = v(0.0, 0.0, -450.0);
    assert_eq!(query(h, &[home, home]).0, DC_STATUS_OK);
    assert_eq!(query(std::ptr::null_mut(), &[home, home]).0, DC_STATUS_NULL_POINTER);
    assert_eq!(query(h, &[home]).0, DC_STATUS_WRONG_ROBOT_COUNT);
    let (s, _, r) = query(h, &[home, v(f64::NAN, 0.0, -450.0)]);
    assert_eq!((s, r.unreachable_mask), (DC_STATUS_NON_FINITE, 0b10));
    assert_eq!(query(h, &[v(0.0, f64::INFINITY, -450.0), home]).0, DC_STATUS_NON_FINITE);
    let (s, _, r) = query(h, &[v(0.0, 0.0, -900.0), home]);
    assert_eq!((s, r.unreachable_mask), (DC_STATUS_UNREACHABLE, 0b01));
    assert_eq!(query(h, &[home, v(0.0, 0.0, 100.0)]).0, DC_STATUS_UNREACHABLE);
    assert_null_outputs_rejected(h, home);
    // SAFETY: both handles are live (or NULL) and not used again.
    unsafe {
        dc_destroy(h);
        dc_destroy(std::ptr::null_mut());
    }
}

#[test]
fn init_rejects_bad_configs_and_clears_the_handle() {
    let good = dc_robot_config_thesis();
    let mut bad_len = good;
    bad_len.geometry.re = -400.0;
    let mut bad_margin = good;
    bad_margin.margin = -1.0;
    let mut nan_place = good;
    nan_place.alpha = f64::NAN;
    let mut bad_limits = good;
    bad_limits.geometry.theta_min = 3.0;
    for (robots, method, want) in [
        (vec![good, bad_len], DC_METHOD_SAT, DC_STATUS_INVALID_CONFIG),
        (vec![good, bad_margin], DC_METHOD_SAT, DC_STATUS_INVALID_CONFIG),
        (vec![nan_place], DC_METHOD_SAT, DC_STATUS_INVALID_CONFIG),
        (vec![bad_limits], DC_METHOD_SAT, DC_STATUS_INVALID_CONFIG),
        (vec![good, good], 7, DC_STATUS_INVALID_CONFIG),
        (vec![], DC_METHOD_SAT, DC_STATUS_INVALID_CONFIG),
        (vec![good; 33], DC_METHOD_SAT, DC_STATUS_INVALID_CONFIG),
    ] {
        let config = DcCellConfig { robots: robots.as_ptr(), n_robots: robots.len(), method };
        let mut h: *mut DcCollider = 8 as *mut DcCollider; // garbage that must be overwritten
                                                           // SAFETY: valid pointers; the config
                                                           // content is what is under test.
        assert_eq!(unsafe { dc_init(&config, &mut h) }, want);
        assert!(h.is_null());
    }
    let mut h: *mut DcCollider = 8 as *mut DcCollider;
    // SAFETY: NULL config is the input under test.
    assert_eq!(unsafe { dc_init(std::ptr::null(), &mut h) }, DC_STATUS_NULL_POINTER);
    assert!(h.is_null());
    let config = DcCellConfig { robots: std::ptr::null(), n_robots: 2, method: DC_METHOD_SAT };
    // SAFETY: NULL robots and NULL out_handle are the inputs under test.
    unsafe {
        assert_eq!(dc_init(&config, &mut h), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_init(&config, std::ptr::null_mut()), DC_STATUS_NULL_POINTER);
    }
}

#[test]
fn cell_files_init_the_same_checker_as_configs() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("dc-ffi-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[[robot]]\nmodel = { margn = 1 }\n").unwrap();
    let cases = [
        (concat!(env!("CARGO_MANIFEST_DIR"), "/cells/t1.toml\0").to_string(), DC_STATUS_OK),
        (format!("{}\0", dir.join("missing.toml").display()), DC_STATUS_IO),
        (format!("{}\0", bad.display()), DC_STATUS_PARSE),
    ];
    let from_config = two_robot_cell(450.0, DC_METHOD_SAT_CACHE);
    for (path, want) in cases {
        let mut h = std::ptr::null_mut();
        // SAFETY: NUL-terminated path, valid out pointer.
        assert_eq!(unsafe { dc_init_from_cell_file(path.as_ptr().cast(), &mut h) }, want, "{path}");
        if want == DC_STATUS_OK {
            for k in 0..200 {
                let s = k as f64 / 200.0;
                let tcps = [v(-150.0 + 350.0 * s, 0.0, -450.0), v(150.0 - 350.0 * s, 10.0, -450.0)];
                assert_eq!(query(h, &tcps).1, query(from_config, &tcps).1, "step {k}");
            }
            // SAFETY: live handle.
            unsafe { assert_eq!((dc_robot_count(h), dc_pair_count(h)), (2, 1)) };
        }
        // SAFETY: live or NULL handle.
        unsafe { dc_destroy(h) };
    }
    // SAFETY: NULL path and a non-UTF-8 path are the inputs under test.
    unsafe {
        let mut h = std::ptr::null_mut();
        assert_eq!(dc_init_from_cell_file(std::ptr::null(), &mut h), DC_STATUS_NULL_POINTER);
        assert_eq!(
            dc_init_from_cell_file(c"\xff\xfe.toml".as_ptr(), &mut h),
            DC_STATUS_INVALID_ARGUMENT
        );
        dc_destroy(from_config);
    }
}

#[test]
fn reports_name_the_colliding_boxes_and_pair_results_match() {
    let h = two_robot_cell(450.0, DC_METHOD_SAT);
    let (s, verdict, r) = query(h, &[v(180.0, 0.0, -450.0), v(-180.0, 0.0, -450.0)]);
    assert_eq!((s, verdict), (DC_STATUS_OK, DC_VERDICT_COLLISION));
    assert_eq!((r.first_robot_a, r.first_robot_b, r.colliding_pairs), (0, 1, 1));
    assert!(r.first_box_a < 3 && r.first_box_b < 3);
    let mut out = [DcPairResult { robot_a: 9, robot_b: 9, collides: 9, box_a: 9, box_b: 9 }; 1];
    let mut len = 0;
    // SAFETY: live handle, valid buffers.
    unsafe {
        assert_eq!(dc_pair_results(h, out.as_mut_ptr(), 1, &mut len), DC_STATUS_OK);
        assert_eq!(dc_pair_results(h, out.as_mut_ptr(), 0, &mut len), DC_STATUS_INVALID_ARGUMENT);
        assert_eq!(len, 1);
    }
    assert_eq!(
        out[0],
        DcPairResult {
            robot_a: 0,
            robot_b: 1,
            collides: 1,
            box_a: r.first_box_a,
            box_b: r.first_box_b
        }
    );
    let (s, verdict, r) = query(h, &[v(-150.0, 0.0, -450.0), v(150.0, 0.0, -450.0)]);
    assert_eq!((s, verdict, r.first_box_a), (DC_STATUS_OK, DC_VERDICT_FREE, DC_BOX_NONE));
    // SAFETY: live handle.
    unsafe { dc_destroy(h) };
}

#[test]
fn status_strings_cover_every_code_and_kinematics_round_trip() {
    for s in 0..=28u32 {
        // SAFETY: dc_status_str returns a static NUL-terminated string.
        let text = unsafe { CStr::from_ptr(dc_status_str(s)) }.to_str().unwrap();
        assert!(!text.is_empty());
        assert_eq!(text == "unknown status", s == 28, "code {s}");
    }
    // SAFETY: static NUL-terminated string.
    assert_eq!(
        unsafe { CStr::from_ptr(dc_version()) }.to_str().unwrap(),
        env!("CARGO_PKG_VERSION")
    );
    let g = dc_robot_config_thesis().geometry;
    let mut theta = [0.0; 3];
    let mut back = v(0.0, 0.0, 0.0);
    // SAFETY: valid geometry and buffers.
    unsafe {
        assert_eq!(
            dc_delta3_inverse_kinematics(&g, v(30.0, -20.0, -460.0), theta.as_mut_ptr()),
            DC_STATUS_OK
        );
        assert_eq!(dc_delta3_forward_kinematics(&g, theta.as_ptr(), &mut back), DC_STATUS_OK);
        assert_eq!(
            dc_delta3_inverse_kinematics(&g, v(0.0, 0.0, -900.0), theta.as_mut_ptr()),
            DC_STATUS_UNREACHABLE
        );
        assert_eq!(
            dc_delta3_inverse_kinematics(&g, v(0.0, f64::NAN, -400.0), theta.as_mut_ptr()),
            DC_STATUS_NON_FINITE
        );
        assert_eq!(
            dc_delta3_inverse_kinematics(std::ptr::null(), v(0.0, 0.0, -400.0), theta.as_mut_ptr()),
            DC_STATUS_NULL_POINTER
        );
    }
    assert!(
        (back.x - 30.0).abs() < 1e-9
            && (back.y + 20.0).abs() < 1e-9
            && (back.z + 460.0).abs() < 1e-9
    );
}
