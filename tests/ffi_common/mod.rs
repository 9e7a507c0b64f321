//! Helpers shared by the C ABI contract tests (`ffi_contract.rs`, `ffi_table_contract.rs`):
//! handles of the reference cells in exact and table mode, and a query that checks the
//! fail-closed outputs on every call.
#![allow(dead_code)] // each test file uses a subset

use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::ffi::*;
use delta_collide::table::{build_table, to_bytes, Labelling, Variant};
use std::sync::OnceLock;

/// An exact-mode handle of two thesis robots `dx` mm apart along x.
pub fn two_robot_cell(dx: f64, method: u32) -> *mut DcCollider {
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
pub fn table_bytes(name: &str) -> &'static [u8] {
    static TABLES: [OnceLock<Vec<u8>>; 2] = [OnceLock::new(), OnceLock::new()];
    let slot = ["T1", "T2"].iter().position(|n| *n == name).expect("tables of T1 and T2 only");
    TABLES[slot].get_or_init(|| {
        let cell = reference_cell(name).unwrap();
        let (header, table, _) = build_table(
            &cell,
            16,
            &Workspace::THESIS,
            Variant::D6,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap_or_else(|e| panic!("building the {name} table: {e}"));
        to_bytes(&table, &header)
    })
}

/// The bytes of the bundle of `cells/line4.toml` (four thesis robots 450 mm apart: three
/// shared 6-D tables at k = 16, certified), built once per process.
pub fn line4_bundle_bytes() -> &'static [u8] {
    static BUNDLE: OnceLock<Vec<u8>> = OnceLock::new();
    BUNDLE.get_or_init(|| {
        let cell = delta_collide::cell::parse_cell(include_str!("../../cells/line4.toml")).unwrap();
        delta_collide::table::bundle::build_bundle(
            &cell,
            16,
            &Workspace::THESIS,
            Variant::Shared,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap_or_else(|e| panic!("building the line4 bundle: {e}"))
        .bytes
    })
}

/// `dc_init_with_table` on a copy of `bytes` that is freed before returning (the handle
/// must not keep the caller's buffer); returns the status and the handle (NULL on failure).
pub fn init_table(config: *const DcCellConfig, bytes: &[u8]) -> (DcStatus, *mut DcCollider) {
    let copy = bytes.to_vec();
    let mut h: *mut DcCollider = 8 as *mut DcCollider; // garbage that must be overwritten
                                                       // SAFETY: the config is NULL or valid, the
                                                       // buffer holds `copy.len()` bytes.
    let s = unsafe { dc_init_with_table(config, copy.as_ptr(), copy.len(), &mut h) };
    drop(copy);
    assert_eq!(s == DC_STATUS_OK, !h.is_null(), "handle set exactly on success (status {s})");
    (s, h)
}

/// A table-mode handle for T1 (thesis robots 450 mm apart) from its table bytes.
pub fn t1_table_handle() -> *mut DcCollider {
    let robots = [
        dc_robot_config_thesis(),
        DcRobotConfig { translation: v(450.0, 0.0, 0.0), ..dc_robot_config_thesis() },
    ];
    let config = DcCellConfig { robots: robots.as_ptr(), n_robots: 2, method: DC_METHOD_SAT };
    let (s, h) = init_table(&config, table_bytes("T1"));
    assert_eq!(s, DC_STATUS_OK, "{}", last_init_error());
    h
}

/// This thread's `dc_last_init_error` message.
pub fn last_init_error() -> String {
    let mut buf = [0u8; 512];
    // SAFETY: the buffer holds 512 writable bytes.
    let n = unsafe { dc_last_init_error(buf.as_mut_ptr().cast(), buf.len()) };
    assert!(n < buf.len(), "message of {n} bytes does not fit 512");
    String::from_utf8(buf[..n].to_vec()).unwrap()
}

/// A report with every field 0 (to be overwritten by `dc_query`).
pub fn zero_report() -> DcQueryReport {
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

/// A `DcVec3` (mm).
pub fn v(x: f64, y: f64, z: f64) -> DcVec3 {
    DcVec3 { x, y, z }
}

/// Queries `h`, with the verdict pre-set to FREE to prove it is always written.
pub fn query(h: *mut DcCollider, tcps: &[DcVec3]) -> (DcStatus, DcVerdict, DcQueryReport) {
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

/// `dc_query` on live `h` with NULL `tcps` answers NULL_POINTER with the verdict STOP, and
/// with NULL `out_verdict` answers NULL_POINTER.
pub fn assert_null_outputs_rejected(h: *mut DcCollider, home: DcVec3) {
    let mut verdict = DC_VERDICT_FREE;
    // SAFETY: h is live; NULL tcps and NULL out_verdict are the inputs under test.
    unsafe {
        assert_eq!(
            dc_query(h, std::ptr::null(), 2, &mut verdict, std::ptr::null_mut()),
            DC_STATUS_NULL_POINTER
        );
        assert_eq!(verdict, DC_VERDICT_STOP);
        assert_eq!(
            dc_query(h, [home, home].as_ptr(), 2, std::ptr::null_mut(), std::ptr::null_mut()),
            DC_STATUS_NULL_POINTER
        );
    }
}

/// A C config of `n` thesis robots `dx` mm apart along x, owning its robots array (keep it
/// alive while the `DcCellConfig` from [`Config::c`] is used).
pub struct Config {
    pub robots: Vec<DcRobotConfig>,
}

impl Config {
    pub fn cell(dx: f64, n: usize) -> Config {
        let robots = (0..n)
            .map(|i| DcRobotConfig {
                translation: v(dx * i as f64, 0.0, 0.0),
                ..dc_robot_config_thesis()
            })
            .collect();
        Config { robots }
    }

    pub fn c(&self) -> DcCellConfig {
        DcCellConfig {
            robots: self.robots.as_ptr(),
            n_robots: self.robots.len(),
            method: DC_METHOD_SAT,
        }
    }
}
