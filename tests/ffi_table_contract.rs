//! The C ABI's table mode, exercised from Rust through the exported
//! functions: every table error's own status and message with no handle, fail-closed
//! reports and pair results, no FREE where the exact model collides, files like buffers.
//! Tables of T1 and T2 are built here at k = 16.

mod ffi_common;

use delta_collide::ffi::*;
use ffi_common::*;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

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
        (
            "T2's table for T1".into(),
            table_bytes("T2").to_vec(),
            DC_STATUS_TABLE_WRONG_CELL,
            "built for cell",
        ),
        ("bad magic".into(), with(&|b| b[0] = b'X'), DC_STATUS_TABLE_BAD_MAGIC, "magic"),
        (
            "byte-swapped endianness marker".into(),
            with(&|b| b[8..12].reverse()),
            DC_STATUS_TABLE_WRONG_ENDIANNESS,
            "big-endian",
        ),
        (
            "version 99".into(),
            with(&|b| b[12] = 99),
            DC_STATUS_TABLE_UNSUPPORTED_VERSION,
            "version 99",
        ),
        ("one trailing byte".into(), with(&|b| b.push(0)), DC_STATUS_TABLE_CORRUPT, "trailing"),
        (
            "flipped bit in the checksum".into(),
            with(&|b| *b.last_mut().unwrap() ^= 0x10),
            DC_STATUS_TABLE_CORRUPT,
            "checksum",
        ),
    ];
    for at in [200, t1.len() / 2, t1.len() - 9] {
        cases.push((
            format!("bit flipped at {at}"),
            with(&|b| b[at] ^= 1),
            DC_STATUS_TABLE_CORRUPT,
            "corrupt",
        ));
    }
    for len in [0, 1, 7, 8, 100, 183, 184, 191, t1.len() / 2, t1.len() - 8, t1.len() - 1] {
        cases.push((
            format!("truncated to {len} bytes"),
            t1[..len].to_vec(),
            DC_STATUS_TABLE_TRUNCATED,
            "truncated",
        ));
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
    // A table needs two robots; three 450 mm apart need the pair 900 mm apart too, which
    // T1's table is not; a bad config is reported before the table is read.
    for (n, want) in [
        (1, DC_STATUS_TABLE_NOT_TWO_ROBOTS),
        (3, DC_STATUS_TABLE_MISSING_PAIR),
        (0, DC_STATUS_INVALID_CONFIG),
    ] {
        let (s, h) = init_table(&Config::cell(450.0, n).c(), t1);
        assert_eq!((s, h.is_null()), (want, true), "{n} robots");
    }
    assert!(last_init_error().contains("n_robots = 0"), "{}", last_init_error());
    let mut h = std::ptr::null_mut();
    // SAFETY: NULL config, NULL table and NULL out_handle are the inputs under test.
    unsafe {
        assert_eq!(
            dc_init_with_table(std::ptr::null(), t1.as_ptr(), t1.len(), &mut h),
            DC_STATUS_NULL_POINTER
        );
        assert_eq!(
            dc_init_with_table(&config, std::ptr::null(), 0, &mut h),
            DC_STATUS_NULL_POINTER
        );
        assert!(last_init_error().contains("table is NULL"));
        assert_eq!(
            dc_init_with_table(&config, t1.as_ptr(), t1.len(), std::ptr::null_mut()),
            DC_STATUS_NULL_POINTER
        );
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
    let none = |collides| DcPairResult {
        robot_a: 0,
        robot_b: 1,
        collides,
        box_a: DC_BOX_NONE,
        box_b: DC_BOX_NONE,
    };
    let crossed = [v(180.0, 0.0, -450.0), v(-180.0, 0.0, -450.0)];
    let (s, verdict, r) = query(h, &crossed);
    assert_eq!(
        (s, verdict, r.colliding_pairs, r.first_robot_a, r.first_robot_b),
        (DC_STATUS_OK, DC_VERDICT_COLLISION, 1, 0, 1)
    );
    // Confirmed by the exact check (the handle's default): its boxes, as exact mode names them.
    let (_, exact_verdict, e) = query(exact, &crossed);
    assert_eq!(exact_verdict, DC_VERDICT_COLLISION);
    assert_ne!(e.first_box_a, DC_BOX_NONE);
    assert_eq!(
        (r.first_box_a, r.first_box_b, r.unreachable_mask),
        (e.first_box_a, e.first_box_b, 0)
    );
    assert_eq!(pair(h), DcPairResult { box_a: e.first_box_a, box_b: e.first_box_b, ..none(1) });
    // Without confirmation the lookup alone answers: the cell, not the boxes.
    // SAFETY: live handle.
    assert_eq!(unsafe { dc_set_table_confirmation(h, DC_CONFIRMATION_NONE) }, DC_STATUS_OK);
    let (_, verdict, r) = query(h, &crossed);
    assert_eq!(
        (verdict, r.first_box_a, r.first_box_b),
        (DC_VERDICT_COLLISION, DC_BOX_NONE, DC_BOX_NONE)
    );
    assert_eq!(pair(h), none(1));
    // SAFETY: live handle.
    assert_eq!(unsafe { dc_set_table_confirmation(h, DC_CONFIRMATION_EXACT) }, DC_STATUS_OK);
    let (s, verdict, r) = query(h, &[v(-150.0, 0.0, -450.0), v(150.0, 0.0, -450.0)]);
    assert_eq!(
        (s, verdict, r.colliding_pairs, r.first_robot_a),
        (DC_STATUS_OK, DC_VERDICT_FREE, 0, DC_BOX_NONE)
    );
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
    assert_null_outputs_rejected(h, home);
    // SAFETY: both handles are live (or NULL) and not used again.
    unsafe {
        dc_destroy(h);
        dc_destroy(exact);
    }
}

#[test]
fn table_mode_never_answers_free_where_the_exact_model_collides_and_confirmed_answers_as_exact_mode(
) {
    let raw = t1_table_handle();
    // SAFETY: live handle.
    assert_eq!(unsafe { dc_set_table_confirmation(raw, DC_CONFIRMATION_NONE) }, DC_STATUS_OK);
    let confirmed = t1_table_handle(); // DC_CONFIRMATION_EXACT: the default of a new handle
    let exact = two_robot_cell(450.0, DC_METHOD_SAT);
    let mut rng = StdRng::seed_from_u64(0x2545_f491_4f6c_dd1d);
    let mut uniform = |lo: f64, hi: f64| rng.random_range(lo..hi);
    let (mut both, mut table_only, mut free, mut unreachable, mut lookup_hits) = (0, 0, 0, 0, 0u64);
    for i in 0..100_000 {
        // Robot A's TCP reaching toward B and B's toward A, often overlapping.
        let tcps = [
            v(uniform(-100.0, 260.0), uniform(-200.0, 200.0), uniform(-540.0, -360.0)),
            v(uniform(-260.0, 100.0), uniform(-200.0, 200.0), uniform(-540.0, -360.0)),
        ];
        // SAFETY: live handle.
        let fallbacks_before = unsafe { dc_table_fallbacks(raw) };
        let (st, vt, _) = query(raw, &tcps);
        // SAFETY: live handle.
        let fell_back = unsafe { dc_table_fallbacks(raw) } != fallbacks_before;
        let (se, ve, _) = query(exact, &tcps);
        let (sc, vc, _) = query(confirmed, &tcps);
        assert_eq!(st, se, "case {i}: {tcps:?}: both modes agree on reachability");
        assert_eq!(
            (sc, vc),
            (se, ve),
            "case {i}: {tcps:?}: the confirmed table answers as exact mode"
        );
        lookup_hits += u64::from(vt == DC_VERDICT_COLLISION && !fell_back);
        match (se, ve, vt) {
            (DC_STATUS_UNREACHABLE, ..) => unreachable += 1,
            (_, DC_VERDICT_COLLISION, DC_VERDICT_COLLISION) => both += 1,
            (_, DC_VERDICT_COLLISION, _) => {
                panic!("case {i}: the table says FREE, the exact model collides: {tcps:?}")
            }
            (_, _, DC_VERDICT_COLLISION) => table_only += 1,
            _ => free += 1,
        }
    }
    println!("100,000 configurations: {both} collide, {table_only} only the table stops, {free} free, {unreachable} unreachable");
    assert!(both > 1000 && free > 1000 && unreachable > 0, "the sample covers every outcome");
    assert!(
        table_only > 100,
        "the unconfirmed table stops where the robots are apart ({table_only})"
    );
    // SAFETY: live handles.
    unsafe {
        assert_eq!(
            dc_table_confirmations(confirmed),
            lookup_hits,
            "one confirmation per COLLISION lookup"
        );
        assert_eq!(dc_table_confirmations(raw), 0);
        dc_destroy(raw);
        dc_destroy(confirmed);
        dc_destroy(exact);
    }
}

#[test]
fn table_confirmation_is_chosen_per_handle_checked_and_read_from_the_cell_file() {
    let colliding = [v(180.0, 0.0, -450.0), v(-180.0, 0.0, -450.0)];
    let h = t1_table_handle();
    let exact = two_robot_cell(450.0, DC_METHOD_SAT);
    // SAFETY: live handles, NULL, and values that are no DcConfirmation are the inputs under test.
    unsafe {
        assert_eq!(query(h, &colliding).1, DC_VERDICT_COLLISION);
        assert_eq!(dc_table_confirmations(h), 1, "new handles confirm");
        assert_eq!(
            dc_set_table_confirmation(std::ptr::null_mut(), DC_CONFIRMATION_NONE),
            DC_STATUS_NULL_POINTER
        );
        for bad in [2, 7, u32::MAX] {
            assert_eq!(dc_set_table_confirmation(h, bad), DC_STATUS_INVALID_ARGUMENT, "{bad}");
            assert!(
                last_init_error().contains(&format!("confirmation = {bad}")),
                "{}",
                last_init_error()
            );
        }
        assert_eq!(query(h, &colliding).1, DC_VERDICT_COLLISION);
        assert_eq!(dc_table_confirmations(h), 2, "a refused value keeps the setting");
        assert_eq!(dc_set_table_confirmation(h, DC_CONFIRMATION_NONE), DC_STATUS_OK);
        assert_eq!(last_init_error(), "");
        assert_eq!(query(h, &colliding).1, DC_VERDICT_COLLISION);
        assert_eq!(dc_table_confirmations(h), 2, "not confirmed once switched off");
        assert_eq!(
            dc_set_table_confirmation(exact, DC_CONFIRMATION_NONE),
            DC_STATUS_OK,
            "exact mode: no effect"
        );
        assert_eq!(query(exact, &colliding).1, DC_VERDICT_COLLISION);
        assert_eq!(
            (dc_table_confirmations(exact), dc_table_confirmations(std::ptr::null())),
            (0, 0)
        );
        dc_destroy(h);
        dc_destroy(exact);
    }
    // The cell file's table_confirm, read by dc_init_from_files.
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("dc-ffi-confirm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let table_path = dir.join("t1_k16.dct");
    std::fs::write(&table_path, table_bytes("T1")).unwrap();
    let t1 =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/cells/t1.toml")).unwrap();
    let table = format!("{}\0", table_path.display());
    for (key, want_status, want_confirmations) in [
        ("", DC_STATUS_OK, 1),
        ("table_confirm = \"exact\"\n", DC_STATUS_OK, 1),
        ("table_confirm = \"none\"\n", DC_STATUS_OK, 0),
        ("table_confirm = \"sometimes\"\n", DC_STATUS_PARSE, 0),
    ] {
        let cell_path = dir.join("cell.toml");
        std::fs::write(&cell_path, format!("{key}{t1}")).unwrap();
        let cell = format!("{}\0", cell_path.display());
        let mut h = std::ptr::null_mut();
        // SAFETY: NUL-terminated paths, valid out pointer; the handle is live or NULL.
        unsafe {
            let s = dc_init_from_files(cell.as_ptr().cast(), table.as_ptr().cast(), &mut h);
            assert_eq!(s, want_status, "{key:?}: {}", last_init_error());
            if s == DC_STATUS_OK {
                assert_eq!(query(h, &colliding).1, DC_VERDICT_COLLISION, "{key:?}");
                assert_eq!(dc_table_confirmations(h), want_confirmations, "{key:?}");
            } else {
                assert!(last_init_error().contains("sometimes"), "{}", last_init_error());
            }
            dc_destroy(h);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn table_files_init_the_same_checker_as_buffers() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("dc-ffi-table-{}", std::process::id()));
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
        assert_eq!(
            (s, h.is_null()),
            (*want, *want != DC_STATUS_OK),
            "{cell} {table}: {}",
            last_init_error()
        );
        if *want == DC_STATUS_IO {
            assert!(
                last_init_error().contains("missing"),
                "the message names the file: {}",
                last_init_error()
            );
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
        assert_eq!(
            dc_init_from_files(std::ptr::null(), cases[0].1.as_ptr().cast(), &mut h),
            DC_STATUS_NULL_POINTER
        );
        assert!(last_init_error().contains("cell_path"));
        assert_eq!(
            dc_init_from_files(t1_cell.as_ptr().cast(), std::ptr::null(), &mut h),
            DC_STATUS_NULL_POINTER
        );
        assert!(last_init_error().contains("table_path"));
        let not_utf8 = c"/tmp/\xff\xfe.dct";
        assert_eq!(
            dc_init_from_files(t1_cell.as_ptr().cast(), not_utf8.as_ptr(), &mut h),
            DC_STATUS_INVALID_ARGUMENT
        );
        assert_eq!(
            dc_init_from_files(
                t1_cell.as_ptr().cast(),
                cases[0].1.as_ptr().cast(),
                std::ptr::null_mut()
            ),
            DC_STATUS_NULL_POINTER
        );
        assert!(h.is_null());
        dc_destroy(from_buffer);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `dc_table_clearance_bound` on a T1 clearance table at k = 16: the handle's bound is the
/// Rust `TableChecker`'s, never above the exact clearance, `-inf` exactly where the table
/// says the cell may collide; errors and other handles give `-inf` with their status.
#[test]
fn clearance_bound_through_the_c_abi_matches_the_table_and_stays_under_the_exact_clearance() {
    use delta_collide::cell::protective::clearance_now;
    use delta_collide::cell::reference::reference_cell;
    use delta_collide::cell::ExactChecker;
    use delta_collide::cspace::{Progress, Workspace};
    use delta_collide::math::Vec3;
    use delta_collide::table::{build_table, to_bytes, Labelling, Ladder, TableChecker, Variant};
    let cell = reference_cell("T1").unwrap();
    let variant = Variant::Clearance(Ladder::default_ladder());
    let (header, table, _) =
        build_table(&cell, 16, &Workspace::THESIS, variant, Labelling::Certified, Progress::Silent)
            .unwrap();
    let bytes = to_bytes(&table, &header);
    let checker = TableChecker::new(cell.clone(), &bytes).unwrap();
    let config = Config::cell(450.0, 2);
    let (s, h) = init_table(&config.c(), &bytes);
    assert_eq!(s, DC_STATUS_OK, "{}", last_init_error());
    let bound = |h: *mut DcCollider, tcps: &[DcVec3]| {
        let mut mm = 12345.0;
        // SAFETY: `h` is live or NULL, `tcps` readable, `mm` writable.
        let s = unsafe { dc_table_clearance_bound(h, tcps.as_ptr(), tcps.len(), &mut mm) };
        (s, mm)
    };
    let mut exact = ExactChecker::new(cell.clone());
    let mut rng = StdRng::seed_from_u64(18);
    let (mut levelled, mut none) = (0, 0);
    for _ in 0..50_000 {
        let p = |rng: &mut StdRng| {
            v(
                rng.random_range(-230.0..230.0),
                rng.random_range(-230.0..230.0),
                rng.random_range(-530.0..-365.0),
            )
        };
        let tcps = [p(&mut rng), p(&mut rng)];
        let rust: Vec<Vec3> = tcps.iter().map(|t| Vec3::new(t.x, t.y, t.z)).collect();
        let (s, mm) = bound(h, &tcps);
        let verdict = exact.check(&rust).unwrap();
        if !verdict.all_reachable() {
            assert_eq!((s, mm), (DC_STATUS_UNREACHABLE, f64::NEG_INFINITY));
            continue;
        }
        assert_eq!(s, DC_STATUS_OK);
        assert_eq!(mm, checker.clearance_bound(&rust).unwrap_or(f64::NEG_INFINITY));
        if mm == f64::NEG_INFINITY {
            none += 1;
        } else {
            assert!(mm <= clearance_now(&exact).0, "{rust:?}: bound {mm} above the clearance");
            levelled += 1;
        }
    }
    assert!(levelled > 1000 && none > 100, "{levelled} with a level, {none} without");
    let home = [v(150.0, 0.0, -450.0), v(-150.0, 0.0, -450.0)];
    assert_eq!(bound(h, &home[..1]), (DC_STATUS_WRONG_ROBOT_COUNT, f64::NEG_INFINITY));
    assert_eq!(
        bound(h, &[v(f64::NAN, 0.0, -450.0), home[1]]),
        (DC_STATUS_NON_FINITE, f64::NEG_INFINITY)
    );
    assert_eq!(bound(std::ptr::null_mut(), &home), (DC_STATUS_NULL_POINTER, f64::NEG_INFINITY));
    // SAFETY: a live handle, readable TCPs; a NULL output is refused, not written.
    assert_eq!(
        unsafe { dc_table_clearance_bound(h, home.as_ptr(), 2, std::ptr::null_mut()) },
        DC_STATUS_NULL_POINTER
    );
    // An exact-mode handle and a boolean table prove no bound.
    let exact_handle = two_robot_cell(450.0, DC_METHOD_SAT);
    assert_eq!(bound(exact_handle, &home), (DC_STATUS_OK, f64::NEG_INFINITY));
    let (s, boolean) = init_table(&config.c(), table_bytes("T1"));
    assert_eq!(s, DC_STATUS_OK);
    assert_eq!(bound(boolean, &home), (DC_STATUS_OK, f64::NEG_INFINITY));
    // SAFETY: live handles, destroyed once.
    unsafe {
        dc_destroy(h);
        dc_destroy(exact_handle);
        dc_destroy(boolean);
    }
}

/// Pair results of a handle's last query.
fn pair_results(h: *mut DcCollider) -> Vec<DcPairResult> {
    let mut out = [DcPairResult { robot_a: 9, robot_b: 9, collides: 9, box_a: 9, box_b: 9 }; 8];
    let mut len = 0;
    // SAFETY: live handle, valid buffers.
    assert_eq!(unsafe { dc_pair_results(h, out.as_mut_ptr(), out.len(), &mut len) }, DC_STATUS_OK);
    out[..len].to_vec()
}

#[test]
fn a_line_in_table_mode_answers_per_pair_as_exact_mode_from_its_bundle() {
    let line = Config::cell(450.0, 4);
    let (s, h) = init_table(&line.c(), line4_bundle_bytes());
    assert_eq!(s, DC_STATUS_OK, "{}", last_init_error());
    let mut exact = std::ptr::null_mut();
    // SAFETY: valid config and out pointer; live handles.
    unsafe {
        assert_eq!(dc_init(&line.c(), &mut exact), DC_STATUS_OK);
        assert_eq!(
            (dc_mode(h), dc_robot_count(h), dc_pair_count(h)),
            (DC_MODE_TABLE, 4, dc_pair_count(exact))
        );
        assert_eq!(dc_pair_count(h), 6);
    }
    let mut rng = StdRng::seed_from_u64(0x5eed_11fe);
    let mut uniform = |lo: f64, hi: f64| rng.random_range(lo..hi);
    let (mut collisions, mut unreachable) = (0, 0);
    for i in 0..50_000 {
        let tcps: Vec<DcVec3> = (0..4)
            .map(|_| v(uniform(-240.0, 240.0), uniform(-200.0, 200.0), uniform(-545.0, -355.0)))
            .collect();
        let (st, vt, rt) = query(h, &tcps);
        let (se, ve, re) = query(exact, &tcps);
        assert_eq!(
            (st, vt, rt.colliding_pairs, rt.unreachable_mask),
            (se, ve, re.colliding_pairs, re.unreachable_mask),
            "case {i}: {tcps:?}"
        );
        assert_eq!(
            (rt.first_robot_a, rt.first_robot_b),
            (re.first_robot_a, re.first_robot_b),
            "case {i}"
        );
        // Each pair as the exact model answers it; the boxes of a confirmed collision too.
        let (pt, pe) = (pair_results(h), pair_results(exact));
        assert_eq!(pt, pe, "case {i}: {tcps:?}");
        collisions += usize::from(ve == DC_VERDICT_COLLISION);
        unreachable += usize::from(se == DC_STATUS_UNREACHABLE);
    }
    assert!(
        collisions > 1000 && unreachable > 1000,
        "{collisions} collisions, {unreachable} unreachable"
    );
    // SAFETY: live handles.
    unsafe {
        assert!(dc_table_confirmations(h) > 0, "COLLISION lookups were confirmed");
        dc_destroy(h);
        dc_destroy(exact);
    }
}

#[test]
fn a_bundle_for_another_spacing_or_missing_a_pair_is_its_own_init_error() {
    let cases = [
        (Config::cell(460.0, 4), DC_STATUS_TABLE_WRONG_PAIR, "placement.translation.x is 450"),
        // Five robots 450 mm apart need no other spacing: the bundle of four serves them.
        (Config::cell(450.0, 5), DC_STATUS_OK, ""),
        (Config::cell(340.0, 3), DC_STATUS_TABLE_WRONG_PAIR, "robot 1: placement.translation.x"),
    ];
    for (config, want, says) in cases {
        let (s, h) = init_table(&config.c(), line4_bundle_bytes());
        let message = last_init_error();
        assert_eq!(s, want, "{} robots: {message}", config.robots.len());
        assert!(
            message.contains(says)
                && (want == DC_STATUS_OK || message.contains("rebuild the bundle")),
            "{message}"
        );
        // SAFETY: the handle is NULL or live, destroyed once.
        unsafe { dc_destroy(h) };
    }
    // A line whose outer robots stand 1340 mm apart (not 1350) and its neighbours 450 and 440:
    // the pair R1-R3 at 890 mm has no table in the bundle and no directory entry of its own
    // spacing; the bundle names the first pair it cannot serve.
    let mut config = Config::cell(450.0, 3);
    config.robots[2].translation.x = 890.0;
    let (s, _) = init_table(&config.c(), line4_bundle_bytes());
    assert_eq!(s, DC_STATUS_TABLE_WRONG_PAIR, "{}", last_init_error());
    // T1's table alone for three robots: the neighbours find it, the pair 900 mm apart not.
    let (s, _) = init_table(&Config::cell(450.0, 3).c(), table_bytes("T1"));
    assert_eq!(s, DC_STATUS_TABLE_MISSING_PAIR);
    let message = last_init_error();
    assert!(message.contains("robots 0 and 2") && message.contains("(900, 0, 0)"), "{message}");
}
