//! The C ABI's contract, exercised from Rust through the exported functions themselves:
//! fail-closed outputs, every bad input's status, and no allocation in `dc_query`, in exact
//! and in table mode (tables of T1 and T2 built here at k = 16).

use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::Workspace;
use delta_collide::ffi::*;
use delta_collide::table::{build_table, to_bytes, Labelling, Variant};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::CStr;
use std::sync::OnceLock;

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

fn two_robot_cell(dx: f64, method: u32) -> *mut DcCollider {
    let a = dc_robot_config_thesis();
    let mut b = dc_robot_config_thesis();
    b.translation = DcVec3 { x: dx, y: 0.0, z: 0.0 };
    let robots = [a, b];
    let config = DcCellConfig { robots: robots.as_ptr(), n_robots: 2, method };
    let mut h = std::ptr::null_mut();
    // SAFETY: valid config and out pointer.
    assert_eq!(unsafe { dc_init(&config, &mut h) }, DC_STATUS_OK);
    assert!(!h.is_null());
    h
}

/// The bytes of a certified 6-D table of reference cell `name` at k = 16, built once per process.
fn table_bytes(name: &str) -> &'static [u8] {
    static TABLES: [OnceLock<Vec<u8>>; 2] = [OnceLock::new(), OnceLock::new()];
    let slot = ["T1", "T2"].iter().position(|n| *n == name).expect("tables of T1 and T2 only");
    TABLES[slot].get_or_init(|| {
        let cell = reference_cell(name).unwrap();
        let (header, table, _) = build_table(&cell, 16, &Workspace::THESIS, Variant::D6, Labelling::Certified, false)
            .unwrap_or_else(|e| panic!("building the {name} table: {e}"));
        to_bytes(&table, &header)
    })
}

/// `dc_init_with_table` on a copy of `bytes` that is freed before returning (the handle
/// must not keep the caller's buffer); returns the status and the handle (NULL on failure).
fn init_table(config: *const DcCellConfig, bytes: &[u8]) -> (DcStatus, *mut DcCollider) {
    let copy = bytes.to_vec();
    let mut h: *mut DcCollider = 8 as *mut DcCollider; // garbage that must be overwritten
                                                       // SAFETY: the config is NULL or valid, the buffer holds `copy.len()` bytes.
    let s = unsafe { dc_init_with_table(config, copy.as_ptr(), copy.len(), &mut h) };
    drop(copy);
    assert_eq!(s == DC_STATUS_OK, !h.is_null(), "handle set exactly on success (status {s})");
    (s, h)
}

/// A table-mode handle for T1 (thesis robots 450 mm apart) from its table bytes.
fn t1_table_handle() -> *mut DcCollider {
    let robots =
        [dc_robot_config_thesis(), DcRobotConfig { translation: v(450.0, 0.0, 0.0), ..dc_robot_config_thesis() }];
    let config = DcCellConfig { robots: robots.as_ptr(), n_robots: 2, method: DC_METHOD_SAT };
    let (s, h) = init_table(&config, table_bytes("T1"));
    assert_eq!(s, DC_STATUS_OK, "{}", last_init_error());
    h
}

/// This thread's `dc_last_init_error` message.
fn last_init_error() -> String {
    let mut buf = [0u8; 512];
    // SAFETY: the buffer holds 512 writable bytes.
    let n = unsafe { dc_last_init_error(buf.as_mut_ptr().cast(), buf.len()) };
    assert!(n < buf.len(), "message of {n} bytes does not fit 512");
    String::from_utf8(buf[..n].to_vec()).unwrap()
}

fn zero_report() -> DcQueryReport {
    DcQueryReport {
        verdict: 0,
        colliding_pairs: 0,
        unreachable_mask: 0,
        first_robot_a: 0,
        first_robot_b: 0,
        first_box_a: 0,
        first_box_b: 0,
    }
}

fn v(x: f64, y: f64, z: f64) -> DcVec3 {
    DcVec3 { x, y, z }
}

/// Queries `h`, with the verdict pre-set to FREE to prove it is always written.
fn query(h: *mut DcCollider, tcps: &[DcVec3]) -> (DcStatus, DcVerdict, DcQueryReport) {
    let mut verdict = DC_VERDICT_FREE;
    let mut report = DcQueryReport {
        verdict: DC_VERDICT_FREE,
        colliding_pairs: 7,
        unreachable_mask: 7,
        first_robot_a: 7,
        first_robot_b: 7,
        first_box_a: 7,
        first_box_b: 7,
    };
    // SAFETY: h is NULL or live; slices and outputs are valid.
    let s = unsafe { dc_query(h, tcps.as_ptr(), tcps.len(), &mut verdict, &mut report) };
    assert_eq!(report.verdict, verdict, "report and out_verdict agree");
    if s != DC_STATUS_OK {
        assert_eq!(verdict, DC_VERDICT_STOP, "fail closed on status {s}");
    }
    (s, verdict, report)
}

#[test]
fn query_does_not_allocate_over_a_million_ticks() {
    for method in [DC_METHOD_SAT, DC_METHOD_SAT_CACHE] {
        let h = two_robot_cell(450.0, method);
        let mut verdict = DC_VERDICT_STOP;
        let mut report = zero_report();
        let ring: Vec<[DcVec3; 2]> = (0..128)
            .map(|i| {
                let s = i as f64 / 127.0;
                [v(-150.0 + 330.0 * s, 30.0, -450.0), v(150.0 - 330.0 * s, -20.0, -430.0)]
            })
            .collect();
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
        let after = allocations();
        assert_eq!(after - before, 0, "dc_query allocated");
        assert!(free > 0 && hit > 0, "the ring covers both verdicts ({free} free, {hit} collisions)");
        // SAFETY: live handle, destroyed once.
        unsafe { dc_destroy(h) };
    }
}

#[test]
fn table_mode_query_does_not_allocate_over_a_million_ticks() {
    let h = t1_table_handle();
    let mut verdict = DC_VERDICT_STOP;
    let mut report = zero_report();
    // Toward each other through the shared space; every 16th tick robot A is above the
    // sampled workspace (z = -340, reachable): the exact fallback must not allocate either.
    let ring: Vec<[DcVec3; 2]> = (0..128)
        .map(|i| {
            let s = i as f64 / 127.0;
            let z = if i % 16 == 0 { -340.0 } else { -450.0 };
            [v(-150.0 + 330.0 * s, 30.0, z), v(150.0 - 330.0 * s, -20.0, -430.0)]
        })
        .collect();
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
    let after = allocations();
    assert_eq!(after - before, 0, "dc_query allocated in table mode");
    assert!(free > 0 && hit > 0, "the ring covers both verdicts ({free} free, {hit} collisions)");
    // SAFETY: live handle.
    let fallbacks = unsafe { dc_table_fallbacks(h) };
    assert_eq!(fallbacks, 1_000_000 / 16, "one exact fallback per out-of-grid tick");
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
    let mut verdict = DC_VERDICT_FREE;
    // SAFETY: NULL tcps and NULL out_verdict are the inputs under test.
    unsafe {
        assert_eq!(dc_query(h, std::ptr::null(), 2, &mut verdict, std::ptr::null_mut()), DC_STATUS_NULL_POINTER);
        assert_eq!(verdict, DC_VERDICT_STOP);
        assert_eq!(
            dc_query(h, [home, home].as_ptr(), 2, std::ptr::null_mut(), std::ptr::null_mut()),
            DC_STATUS_NULL_POINTER
        );
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
                                                           // SAFETY: valid pointers; the config content is what is under test.
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
    let dir = std::env::temp_dir().join(format!("dc-ffi-{}", std::process::id()));
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
        assert_eq!(dc_init_from_cell_file(c"\xff\xfe.toml".as_ptr(), &mut h), DC_STATUS_INVALID_ARGUMENT);
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
        DcPairResult { robot_a: 0, robot_b: 1, collides: 1, box_a: r.first_box_a, box_b: r.first_box_b }
    );
    let (s, verdict, r) = query(h, &[v(-150.0, 0.0, -450.0), v(150.0, 0.0, -450.0)]);
    assert_eq!((s, verdict, r.first_box_a), (DC_STATUS_OK, DC_VERDICT_FREE, DC_BOX_NONE));
    // SAFETY: live handle.
    unsafe { dc_destroy(h) };
}

#[test]
fn status_strings_cover_every_code_and_kinematics_round_trip() {
    for s in 0..=17u32 {
        // SAFETY: dc_status_str returns a static NUL-terminated string.
        let text = unsafe { CStr::from_ptr(dc_status_str(s)) }.to_str().unwrap();
        assert!(!text.is_empty());
        assert_eq!(text == "unknown status", s == 17, "code {s}");
    }
    // SAFETY: static NUL-terminated string.
    assert_eq!(unsafe { CStr::from_ptr(dc_version()) }.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
    let g = dc_robot_config_thesis().geometry;
    let mut theta = [0.0; 3];
    let mut back = v(0.0, 0.0, 0.0);
    // SAFETY: valid geometry and buffers.
    unsafe {
        assert_eq!(dc_delta3_inverse_kinematics(&g, v(30.0, -20.0, -460.0), theta.as_mut_ptr()), DC_STATUS_OK);
        assert_eq!(dc_delta3_forward_kinematics(&g, theta.as_ptr(), &mut back), DC_STATUS_OK);
        assert_eq!(dc_delta3_inverse_kinematics(&g, v(0.0, 0.0, -900.0), theta.as_mut_ptr()), DC_STATUS_UNREACHABLE);
        assert_eq!(
            dc_delta3_inverse_kinematics(&g, v(0.0, f64::NAN, -400.0), theta.as_mut_ptr()),
            DC_STATUS_NON_FINITE
        );
        assert_eq!(
            dc_delta3_inverse_kinematics(std::ptr::null(), v(0.0, 0.0, -400.0), theta.as_mut_ptr()),
            DC_STATUS_NULL_POINTER
        );
    }
    assert!((back.x - 30.0).abs() < 1e-9 && (back.y + 20.0).abs() < 1e-9 && (back.z + 460.0).abs() < 1e-9);
}

/// T1 as a C config (thesis robots 450 mm apart) kept alive with its robots array.
struct Config {
    robots: Vec<DcRobotConfig>,
}

impl Config {
    fn cell(dx: f64, n: usize) -> Config {
        let robots = (0..n)
            .map(|i| DcRobotConfig { translation: v(dx * i as f64, 0.0, 0.0), ..dc_robot_config_thesis() })
            .collect();
        Config { robots }
    }

    fn c(&self) -> DcCellConfig {
        DcCellConfig { robots: self.robots.as_ptr(), n_robots: self.robots.len(), method: DC_METHOD_SAT }
    }
}

#[test]
fn table_init_gives_each_table_error_its_own_status_and_no_handle() {
    let t1 = table_bytes("T1");
    let t1_config = Config::cell(450.0, 2);
    let config = t1_config.c();
    let with = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = t1.to_vec();
        f(&mut b);
        b
    };
    let mut cases: Vec<(String, Vec<u8>, DcStatus, &str)> = vec![
        ("T2's table for T1".into(), table_bytes("T2").to_vec(), DC_STATUS_TABLE_WRONG_CELL, "built for cell"),
        ("bad magic".into(), with(&|b| b[0] = b'X'), DC_STATUS_TABLE_BAD_MAGIC, "magic"),
        (
            "byte-swapped endianness marker".into(),
            with(&|b| b[8..12].reverse()),
            DC_STATUS_TABLE_WRONG_ENDIANNESS,
            "big-endian",
        ),
        ("version 99".into(), with(&|b| b[12] = 99), DC_STATUS_TABLE_UNSUPPORTED_VERSION, "version 99"),
        ("one trailing byte".into(), with(&|b| b.push(0)), DC_STATUS_TABLE_CORRUPT, "trailing"),
        (
            "flipped bit in the checksum".into(),
            with(&|b| *b.last_mut().unwrap() ^= 0x10),
            DC_STATUS_TABLE_CORRUPT,
            "checksum",
        ),
    ];
    for at in [200, t1.len() / 2, t1.len() - 9] {
        cases.push((format!("bit flipped at {at}"), with(&|b| b[at] ^= 1), DC_STATUS_TABLE_CORRUPT, "corrupt"));
    }
    for len in [0, 1, 7, 8, 100, 183, 184, 191, t1.len() / 2, t1.len() - 8, t1.len() - 1] {
        cases.push((format!("truncated to {len} bytes"), t1[..len].to_vec(), DC_STATUS_TABLE_TRUNCATED, "truncated"));
    }
    for (what, bytes, want, says) in &cases {
        let (s, h) = init_table(&config, bytes);
        assert_eq!(s, *want, "{what}");
        assert!(h.is_null(), "{what}: no handle on failure");
        let message = last_init_error();
        assert!(message.contains(says), "{what}: message {message:?} does not say {says:?}");
        assert!(
            ["rebuild", "copy", "check"].iter().any(|fix| message.contains(fix)),
            "{what}: message {message:?} names no fix"
        );
        // A failed init leaves a NULL handle, which queries as NULL_POINTER and STOP.
        let (s, verdict, _) = query(h, &[v(0.0, 0.0, -450.0); 2]);
        assert_eq!((s, verdict), (DC_STATUS_NULL_POINTER, DC_VERDICT_STOP), "{what}");
    }
    // Tables serve two-robot cells only; a bad config is reported before the table is read.
    for (n, want) in
        [(1, DC_STATUS_TABLE_NOT_TWO_ROBOTS), (3, DC_STATUS_TABLE_NOT_TWO_ROBOTS), (0, DC_STATUS_INVALID_CONFIG)]
    {
        let (s, h) = init_table(&Config::cell(450.0, n).c(), t1);
        assert_eq!((s, h.is_null()), (want, true), "{n} robots");
    }
    assert!(last_init_error().contains("n_robots = 0"), "{}", last_init_error());
    let mut h = std::ptr::null_mut();
    // SAFETY: NULL config, NULL table and NULL out_handle are the inputs under test.
    unsafe {
        assert_eq!(dc_init_with_table(std::ptr::null(), t1.as_ptr(), t1.len(), &mut h), DC_STATUS_NULL_POINTER);
        assert_eq!(dc_init_with_table(&config, std::ptr::null(), 0, &mut h), DC_STATUS_NULL_POINTER);
        assert!(last_init_error().contains("table is NULL"));
        assert_eq!(dc_init_with_table(&config, t1.as_ptr(), t1.len(), std::ptr::null_mut()), DC_STATUS_NULL_POINTER);
        assert!(last_init_error().contains("out_handle"));
        // Asking for the length only, and a buffer too small: cut, NUL-terminated.
        let n = dc_last_init_error(std::ptr::null_mut(), 0);
        let mut small = [0x55u8; 8];
        assert_eq!(dc_last_init_error(small.as_mut_ptr().cast(), small.len()), n);
        assert_eq!(&small[..], b"out_han\0");
    }
    let h = t1_table_handle();
    assert_eq!(last_init_error(), "", "a successful init clears the message");
    // SAFETY: live handle, destroyed once.
    unsafe { dc_destroy(h) };
}

#[test]
fn table_mode_reports_fail_closed_and_pair_results() {
    let h = t1_table_handle();
    let exact = two_robot_cell(450.0, DC_METHOD_SAT);
    // SAFETY: live handles and NULL.
    unsafe {
        assert_eq!(
            (dc_mode(h), dc_mode(exact), dc_mode(std::ptr::null())),
            (DC_MODE_TABLE, DC_MODE_EXACT, DC_MODE_NONE)
        );
        assert_eq!((dc_robot_count(h), dc_pair_count(h), dc_table_fallbacks(exact)), (2, 1, 0));
    }
    let pair = |h| {
        let mut out = [DcPairResult { robot_a: 9, robot_b: 9, collides: 9, box_a: 9, box_b: 9 }; 2];
        let mut len = 0;
        // SAFETY: live handle, valid buffers.
        assert_eq!(unsafe { dc_pair_results(h, out.as_mut_ptr(), 2, &mut len) }, DC_STATUS_OK);
        assert_eq!(len, 1);
        out[0]
    };
    let none = |collides| DcPairResult { robot_a: 0, robot_b: 1, collides, box_a: DC_BOX_NONE, box_b: DC_BOX_NONE };
    let (s, verdict, r) = query(h, &[v(180.0, 0.0, -450.0), v(-180.0, 0.0, -450.0)]);
    assert_eq!(
        (s, verdict, r.colliding_pairs, r.first_robot_a, r.first_robot_b),
        (DC_STATUS_OK, DC_VERDICT_COLLISION, 1, 0, 1)
    );
    assert_eq!((r.first_box_a, r.first_box_b, r.unreachable_mask), (DC_BOX_NONE, DC_BOX_NONE, 0));
    assert_eq!(pair(h), none(1));
    let (s, verdict, r) = query(h, &[v(-150.0, 0.0, -450.0), v(150.0, 0.0, -450.0)]);
    assert_eq!((s, verdict, r.colliding_pairs, r.first_robot_a), (DC_STATUS_OK, DC_VERDICT_FREE, 0, DC_BOX_NONE));
    assert_eq!(pair(h), none(0));
    let home = v(0.0, 0.0, -450.0);
    assert_eq!(query(h, &[v(180.0, 0.0, -450.0), v(-180.0, 0.0, -450.0)]).1, DC_VERDICT_COLLISION);
    for (tcps, want, mask) in [
        (vec![home, v(f64::NAN, 0.0, -450.0)], DC_STATUS_NON_FINITE, 0b10),
        (vec![v(0.0, f64::NEG_INFINITY, -450.0), home], DC_STATUS_NON_FINITE, 0b01),
        (vec![v(0.0, 0.0, -900.0), home], DC_STATUS_UNREACHABLE, 0b01),
        (vec![v(0.0, 0.0, 100.0), v(400.0, 0.0, -450.0)], DC_STATUS_UNREACHABLE, 0b11),
        (vec![home], DC_STATUS_WRONG_ROBOT_COUNT, 0),
        (vec![home; 3], DC_STATUS_WRONG_ROBOT_COUNT, 0),
    ] {
        let (s, _, r) = query(h, &tcps);
        assert_eq!((s, r.unreachable_mask), (want, mask), "{tcps:?}");
        assert_eq!(pair(h), none(0), "after a failed query the pair is not reported colliding");
    }
    let mut verdict = DC_VERDICT_FREE;
    // SAFETY: NULL tcps and NULL out_verdict are the inputs under test.
    unsafe {
        assert_eq!(dc_query(h, std::ptr::null(), 2, &mut verdict, std::ptr::null_mut()), DC_STATUS_NULL_POINTER);
        assert_eq!(verdict, DC_VERDICT_STOP);
        assert_eq!(
            dc_query(h, [home, home].as_ptr(), 2, std::ptr::null_mut(), std::ptr::null_mut()),
            DC_STATUS_NULL_POINTER
        );
        dc_destroy(h);
        dc_destroy(exact);
    }
}

#[test]
fn table_mode_never_answers_free_where_the_exact_model_collides() {
    let h = t1_table_handle();
    let exact = two_robot_cell(450.0, DC_METHOD_SAT);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = |lo: f64, hi: f64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut both, mut table_only, mut free, mut unreachable) = (0, 0, 0, 0);
    for i in 0..100_000 {
        // Robot A's TCP reaching toward B and B's toward A, often overlapping.
        let tcps = [
            v(uniform(-100.0, 260.0), uniform(-200.0, 200.0), uniform(-540.0, -360.0)),
            v(uniform(-260.0, 100.0), uniform(-200.0, 200.0), uniform(-540.0, -360.0)),
        ];
        let (st, vt, _) = query(h, &tcps);
        let (se, ve, _) = query(exact, &tcps);
        assert_eq!(st, se, "case {i}: {tcps:?}: both modes agree on reachability");
        match (se, ve, vt) {
            (DC_STATUS_UNREACHABLE, ..) => unreachable += 1,
            (_, DC_VERDICT_COLLISION, DC_VERDICT_COLLISION) => both += 1,
            (_, DC_VERDICT_COLLISION, _) => panic!("case {i}: the table says FREE, the exact model collides: {tcps:?}"),
            (_, _, DC_VERDICT_COLLISION) => table_only += 1,
            _ => free += 1,
        }
    }
    println!("100,000 configurations: {both} collide, {table_only} only the table stops, {free} free, {unreachable} unreachable");
    assert!(both > 1000 && free > 1000 && unreachable > 0, "the sample covers every outcome");
    // SAFETY: live handles.
    unsafe {
        dc_destroy(h);
        dc_destroy(exact);
    }
}

#[test]
fn table_files_init_the_same_checker_as_buffers() {
    let dir = std::env::temp_dir().join(format!("dc-ffi-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let table_path = dir.join("t1_k16.dct");
    std::fs::write(&table_path, table_bytes("T1")).unwrap();
    std::fs::write(dir.join("t1_cut.dct"), &table_bytes("T1")[..1000]).unwrap();
    std::fs::write(dir.join("bad.toml"), "[[robot]]\nmodel = { margn = 1 }\n").unwrap();
    let c = |p: std::path::PathBuf| format!("{}\0", p.display());
    let t1_cell = concat!(env!("CARGO_MANIFEST_DIR"), "/cells/t1.toml\0").to_string();
    let t2_cell = concat!(env!("CARGO_MANIFEST_DIR"), "/cells/t2.toml\0").to_string();
    let cases = [
        (t1_cell.clone(), c(table_path.clone()), DC_STATUS_OK),
        (t2_cell, c(table_path.clone()), DC_STATUS_TABLE_WRONG_CELL),
        (t1_cell.clone(), c(dir.join("t1_cut.dct")), DC_STATUS_TABLE_TRUNCATED),
        (t1_cell.clone(), c(dir.join("missing.dct")), DC_STATUS_IO),
        (c(dir.join("missing.toml")), c(table_path.clone()), DC_STATUS_IO),
        (c(dir.join("bad.toml")), c(table_path.clone()), DC_STATUS_PARSE),
    ];
    let from_buffer = t1_table_handle();
    for (cell, table, want) in &cases {
        let mut h = 8 as *mut DcCollider;
        // SAFETY: NUL-terminated paths, valid out pointer.
        let s = unsafe { dc_init_from_files(cell.as_ptr().cast(), table.as_ptr().cast(), &mut h) };
        assert_eq!((s, h.is_null()), (*want, *want != DC_STATUS_OK), "{cell} {table}: {}", last_init_error());
        if *want == DC_STATUS_IO {
            assert!(last_init_error().contains("missing"), "the message names the file: {}", last_init_error());
        }
        if s == DC_STATUS_OK {
            // SAFETY: live handle.
            assert_eq!(unsafe { dc_mode(h) }, DC_MODE_TABLE);
            for k in 0..400 {
                let s = k as f64 / 400.0;
                let tcps = [v(-150.0 + 350.0 * s, 0.0, -450.0), v(150.0 - 350.0 * s, 10.0, -450.0)];
                assert_eq!(query(h, &tcps).1, query(from_buffer, &tcps).1, "step {k}");
            }
        }
        // SAFETY: live or NULL handle.
        unsafe { dc_destroy(h) };
    }
    let mut h = std::ptr::null_mut();
    // SAFETY: NULL and non-UTF-8 paths are the inputs under test.
    unsafe {
        assert_eq!(dc_init_from_files(std::ptr::null(), cases[0].1.as_ptr().cast(), &mut h), DC_STATUS_NULL_POINTER);
        assert!(last_init_error().contains("cell_path"));
        assert_eq!(dc_init_from_files(t1_cell.as_ptr().cast(), std::ptr::null(), &mut h), DC_STATUS_NULL_POINTER);
        assert!(last_init_error().contains("table_path"));
        let not_utf8 = c"/tmp/\xff\xfe.dct";
        assert_eq!(dc_init_from_files(t1_cell.as_ptr().cast(), not_utf8.as_ptr(), &mut h), DC_STATUS_INVALID_ARGUMENT);
        assert_eq!(
            dc_init_from_files(t1_cell.as_ptr().cast(), cases[0].1.as_ptr().cast(), std::ptr::null_mut()),
            DC_STATUS_NULL_POINTER
        );
        assert!(h.is_null());
        dc_destroy(from_buffer);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
