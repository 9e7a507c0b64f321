//! The C ABI: the only `extern "C"` functions, `#[no_mangle]` symbols and `unsafe` of the
//! crate (thesis appendix A: the POU's init / per-tick query / destroy).
//!
//! # Conventions
//! - Argument order: handle, inputs, outputs. Lengths in mm, angles in rad; each TCP in its
//!   own robot's MCS.
//! - Every exported function catches panics (`DC_STATUS_PANIC`); none crosses into C.
//! - Every pointer is checked; NaN and infinity are rejected.
//! - `*out_verdict` and `*out_report`, when not NULL, are written on every call, and read
//!   `DC_VERDICT_FREE` only together with `DC_STATUS_OK` (fail closed).
//! - `dc_init*` allocate; `dc_query` never allocates, locks or does I/O.
//! - A handle is used by one thread at a time; distinct handles are independent.
#![allow(unsafe_code)]

mod convert;
pub mod types;

pub use types::*;

use crate::cell::exact::PairState;
use crate::cell::{Cell, ExactChecker};
use crate::math::Vec3;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// An initialised collision checker for one cell (opaque to C).
pub struct DcCollider {
    checker: ExactChecker,
    /// The TCPs of the current query, converted; sized once at init.
    tcps: Vec<Vec3>,
    /// Set when a panic was caught inside a query: the handle's state is not trusted.
    poisoned: bool,
}

/// Runs `f`, turning a panic into `DC_STATUS_PANIC`.
fn boundary(f: impl FnOnce() -> DcStatus) -> DcStatus {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(DC_STATUS_PANIC)
}

fn new_handle(cell: Cell) -> *mut DcCollider {
    let n = cell.robots.len();
    Box::into_raw(Box::new(DcCollider {
        checker: ExactChecker::new(cell),
        tcps: vec![Vec3::zeros(); n],
        poisoned: false,
    }))
}

/// The thesis robot (f 100, rf 150, re 400, e 40, limits [-pi/2, 2 pi/3], H 70, D 17.5,
/// margin 0, lower links only) placed at the WCS origin: a starting point for a config.
#[no_mangle]
pub extern "C" fn dc_robot_config_thesis() -> DcRobotConfig {
    convert::thesis_robot_config()
}

/// Creates a checker for the cell described by `config` (POU start-up).
///
/// On success `*out_handle` holds a handle to pass to `dc_query` and finally to
/// `dc_destroy`; on any failure `*out_handle` is set to NULL (when `out_handle` is not
/// NULL). Statuses: `DC_STATUS_NULL_POINTER` (config, its robots array or out_handle is
/// NULL), `DC_STATUS_INVALID_CONFIG` (no robots or more than 32, a length <= 0, a negative
/// margin or box extent, motor limits not a proper range, NaN/inf, unknown method).
///
/// # Safety
/// `config` must be NULL or point to a valid `DcCellConfig` whose `robots` points to
/// `n_robots` valid `DcRobotConfig`; `out_handle` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_init(config: *const DcCellConfig, out_handle: *mut *mut DcCollider) -> DcStatus {
    boundary(|| {
        if out_handle.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: checked non-null above; the caller guarantees it is writable.
        unsafe { *out_handle = std::ptr::null_mut() };
        // SAFETY: the caller guarantees `config` is NULL or valid.
        let Some(config) = (unsafe { config.as_ref() }) else { return DC_STATUS_NULL_POINTER };
        if config.robots.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        if config.n_robots == 0 || config.n_robots > crate::cell::MAX_ROBOTS {
            return DC_STATUS_INVALID_CONFIG;
        }
        // SAFETY: non-null, and the caller guarantees `n_robots` valid elements.
        let robots = unsafe { std::slice::from_raw_parts(config.robots, config.n_robots) };
        match convert::cell_from_c(robots, config.method) {
            Ok(cell) => {
                // SAFETY: checked non-null above.
                unsafe { *out_handle = new_handle(cell) };
                DC_STATUS_OK
            }
            Err(status) => status,
        }
    })
}

/// Creates a checker from a TOML cell file (see `cells/t1.toml`); the file is read once,
/// here, never during a tick.
///
/// `*out_handle` as for `dc_init`. Statuses: `DC_STATUS_NULL_POINTER`,
/// `DC_STATUS_INVALID_ARGUMENT` (path not UTF-8), `DC_STATUS_IO` (cannot read),
/// `DC_STATUS_PARSE` (not TOML, unknown key, wrong type), `DC_STATUS_INVALID_CONFIG`.
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string; `out_handle` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_init_from_cell_file(path: *const c_char, out_handle: *mut *mut DcCollider) -> DcStatus {
    boundary(|| {
        if out_handle.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: checked non-null above; the caller guarantees it is writable.
        unsafe { *out_handle = std::ptr::null_mut() };
        if path.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees NUL termination.
        let Ok(path) = unsafe { CStr::from_ptr(path) }.to_str() else { return DC_STATUS_INVALID_ARGUMENT };
        match Cell::from_file(std::path::Path::new(path)) {
            Ok(cell) => {
                // SAFETY: checked non-null above.
                unsafe { *out_handle = new_handle(cell) };
                DC_STATUS_OK
            }
            Err(e) => convert::cell_error_status(&e),
        }
    })
}

/// The per-tick query: do the robots collide with robot j's TCP at `tcps_mcs[j]` (its MCS)?
///
/// Writes `*out_verdict` (and `*out_report` when not NULL) on every call:
/// `DC_VERDICT_FREE` or `DC_VERDICT_COLLISION` with `DC_STATUS_OK`, else `DC_VERDICT_STOP`.
/// Statuses: `DC_STATUS_NULL_POINTER` (handle, tcps_mcs or out_verdict NULL),
/// `DC_STATUS_WRONG_ROBOT_COUNT`, `DC_STATUS_NON_FINITE` (a NaN/inf coordinate; the
/// report's `unreachable_mask` names the robot), `DC_STATUS_UNREACHABLE` (a TCP outside
/// the robot's reach or motor limits; mask as before), `DC_STATUS_PANIC` (destroy the
/// handle). Never allocates, locks or does I/O.
///
/// # Safety
/// `handle` must be NULL or a live handle from `dc_init*` not used by another thread;
/// `tcps_mcs` must be NULL or point to `n_tcps` readable `DcVec3`; the out pointers must be
/// NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_query(
    handle: *mut DcCollider,
    tcps_mcs: *const DcVec3,
    n_tcps: usize,
    out_verdict: *mut DcVerdict,
    out_report: *mut DcQueryReport,
) -> DcStatus {
    let mut report = DcQueryReport::STOP;
    let status = boundary(|| {
        // SAFETY: the caller guarantees `handle` is NULL or live and unshared.
        let Some(h) = (unsafe { handle.as_mut() }) else { return DC_STATUS_NULL_POINTER };
        if out_verdict.is_null() || tcps_mcs.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        if h.poisoned {
            return DC_STATUS_PANIC;
        }
        // SAFETY: non-null, and the caller guarantees `n_tcps` readable elements.
        let tcps = unsafe { std::slice::from_raw_parts(tcps_mcs, n_tcps) };
        let status = catch_unwind(AssertUnwindSafe(|| query(h, tcps, &mut report)));
        status.unwrap_or_else(|_| {
            h.poisoned = true;
            DC_STATUS_PANIC
        })
    });
    if status != DC_STATUS_OK {
        report.verdict = DC_VERDICT_STOP;
    }
    if !out_verdict.is_null() {
        // SAFETY: non-null; the caller guarantees it is writable.
        unsafe { *out_verdict = report.verdict };
    }
    if !out_report.is_null() {
        // SAFETY: non-null; the caller guarantees it is writable.
        unsafe { *out_report = report };
    }
    status
}

/// The safe body of `dc_query`: fills `report`, returns the status.
fn query(h: &mut DcCollider, tcps: &[DcVec3], report: &mut DcQueryReport) -> DcStatus {
    if tcps.len() != h.tcps.len() {
        return DC_STATUS_WRONG_ROBOT_COUNT;
    }
    let mut non_finite = 0u32;
    for (j, (dst, src)) in h.tcps.iter_mut().zip(tcps).enumerate() {
        non_finite |= (!src.is_finite() as u32) << j;
        *dst = src.to_vec3();
    }
    if non_finite != 0 {
        report.unreachable_mask = non_finite;
        return DC_STATUS_NON_FINITE;
    }
    let Ok(v) = h.checker.check(&h.tcps) else { return DC_STATUS_WRONG_ROBOT_COUNT };
    report.unreachable_mask = v.unreachable_mask;
    report.colliding_pairs = v.colliding_pairs() as u32;
    if let Some(p) = v.first_collision() {
        if let PairState::Collides(ba, bb) = p.state {
            (report.first_robot_a, report.first_robot_b) = (p.a as u32, p.b as u32);
            (report.first_box_a, report.first_box_b) = (ba as u32, bb as u32);
        }
    }
    if !v.all_reachable() {
        return DC_STATUS_UNREACHABLE;
    }
    report.verdict = if v.collides() { DC_VERDICT_COLLISION } else { DC_VERDICT_FREE };
    DC_STATUS_OK
}

/// Copies the per-pair results of the last query into `out[0..]` and their number into
/// `*out_len`. Only pairs whose reach can overlap are listed (`dc_pair_count`).
/// Statuses: `DC_STATUS_NULL_POINTER`, `DC_STATUS_INVALID_ARGUMENT` (`capacity` smaller
/// than `dc_pair_count`; `*out_len` then holds the count needed).
///
/// # Safety
/// `handle` must be NULL or live; `out` must be NULL or hold `capacity` writable elements;
/// `out_len` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_pair_results(
    handle: *const DcCollider,
    out: *mut DcPairResult,
    capacity: usize,
    out_len: *mut usize,
) -> DcStatus {
    boundary(|| {
        // SAFETY: the caller guarantees `handle` is NULL or live.
        let Some(h) = (unsafe { handle.as_ref() }) else { return DC_STATUS_NULL_POINTER };
        if out.is_null() || out_len.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        let pairs = &h.checker.verdict().pairs;
        // SAFETY: non-null; the caller guarantees it is writable.
        unsafe { *out_len = pairs.len() };
        if capacity < pairs.len() {
            return DC_STATUS_INVALID_ARGUMENT;
        }
        // SAFETY: non-null, and the caller guarantees `capacity >= pairs.len()` elements.
        let out = unsafe { std::slice::from_raw_parts_mut(out, pairs.len()) };
        for (o, p) in out.iter_mut().zip(pairs) {
            let (collides, box_a, box_b) = match p.state {
                PairState::Collides(a, b) => (1, a as u32, b as u32),
                _ => (0, DC_BOX_NONE, DC_BOX_NONE),
            };
            *o = DcPairResult { robot_a: p.a as u32, robot_b: p.b as u32, collides, box_a, box_b };
        }
        DC_STATUS_OK
    })
}

/// Number of robots of the handle's cell; 0 for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_robot_count(handle: *const DcCollider) -> usize {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { handle.as_ref() }.map_or(0, |h| h.tcps.len())
}

/// Number of robot pairs that can meet (kept after pruning at init); 0 for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_pair_count(handle: *const DcCollider) -> usize {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { handle.as_ref() }.map_or(0, |h| h.checker.verdict().pairs.len())
}

/// Frees a handle (POU shut-down). NULL is a no-op. The handle must not be used afterwards.
///
/// # Safety
/// `handle` must be NULL or a live handle from `dc_init*`, destroyed only once.
#[no_mangle]
pub unsafe extern "C" fn dc_destroy(handle: *mut DcCollider) {
    if !handle.is_null() {
        // SAFETY: the caller guarantees a live handle from Box::into_raw, destroyed once.
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(handle) })));
    }
}

/// A static, NUL-terminated English description of `status`; never NULL.
#[no_mangle]
pub extern "C" fn dc_status_str(status: DcStatus) -> *const c_char {
    let s: &'static CStr = match status {
        DC_STATUS_OK => c"ok",
        DC_STATUS_NULL_POINTER => c"a required pointer argument is NULL",
        DC_STATUS_NON_FINITE => c"an input number is NaN or infinite",
        DC_STATUS_UNREACHABLE => c"a TCP is outside its robot's reach or motor limits",
        DC_STATUS_INVALID_CONFIG => c"a configuration value is out of range",
        DC_STATUS_WRONG_ROBOT_COUNT => c"the number of TCPs differs from the number of robots",
        DC_STATUS_IO => c"a file could not be read",
        DC_STATUS_PARSE => c"the cell file is not valid TOML or does not follow the schema",
        DC_STATUS_PANIC => c"internal error caught at the library boundary; destroy the handle",
        DC_STATUS_INVALID_ARGUMENT => c"an argument is malformed (path not UTF-8, capacity too small)",
        _ => c"unknown status",
    };
    s.as_ptr()
}

/// The library version, a static NUL-terminated string such as "0.1.0".
#[no_mangle]
pub extern "C" fn dc_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// Elbow-out inverse kinematics (SPEC section 2) of `tcp_mcs`, for a controller or a test harness
/// to cross-check its own kinematics. Writes `out_theta[0..3]` (rad) on success.
/// Statuses: `DC_STATUS_NULL_POINTER`, `DC_STATUS_NON_FINITE`, `DC_STATUS_INVALID_CONFIG`
/// (bad geometry), `DC_STATUS_UNREACHABLE`.
///
/// # Safety
/// `geometry` must be NULL or valid; `out_theta` must be NULL or hold 3 writable doubles.
#[no_mangle]
pub unsafe extern "C" fn dc_delta3_inverse_kinematics(
    geometry: *const DcDelta3,
    tcp_mcs: DcVec3,
    out_theta: *mut f64,
) -> DcStatus {
    boundary(|| {
        // SAFETY: the caller guarantees `geometry` is NULL or valid.
        let Some(g) = (unsafe { geometry.as_ref() }) else { return DC_STATUS_NULL_POINTER };
        if out_theta.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        if !tcp_mcs.is_finite() {
            return DC_STATUS_NON_FINITE;
        }
        let d = match convert::delta3_from_c(g) {
            Ok(d) => d,
            Err(s) => return s,
        };
        match d.inverse_kinematics(&tcp_mcs.to_vec3()) {
            Ok(sol) => {
                // SAFETY: non-null, and the caller guarantees 3 writable doubles.
                unsafe { std::ptr::copy_nonoverlapping(sol.theta.as_ptr(), out_theta, 3) };
                DC_STATUS_OK
            }
            Err(_) => DC_STATUS_UNREACHABLE,
        }
    })
}

/// Forward kinematics (SPEC section 2): the TCP for motor angles `theta[0..3]` (rad), written to
/// `*out_tcp`. Statuses: `DC_STATUS_NULL_POINTER`, `DC_STATUS_NON_FINITE`,
/// `DC_STATUS_INVALID_CONFIG`, `DC_STATUS_UNREACHABLE` (the three spheres do not meet).
///
/// # Safety
/// `geometry` must be NULL or valid; `theta` NULL or 3 readable doubles; `out_tcp` NULL or
/// writable.
#[no_mangle]
pub unsafe extern "C" fn dc_delta3_forward_kinematics(
    geometry: *const DcDelta3,
    theta: *const f64,
    out_tcp: *mut DcVec3,
) -> DcStatus {
    boundary(|| {
        // SAFETY: the caller guarantees `geometry` is NULL or valid.
        let Some(g) = (unsafe { geometry.as_ref() }) else { return DC_STATUS_NULL_POINTER };
        if theta.is_null() || out_tcp.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees 3 readable doubles.
        let theta: [f64; 3] = unsafe { std::ptr::read_unaligned(theta.cast()) };
        if !theta.iter().all(|t| t.is_finite()) {
            return DC_STATUS_NON_FINITE;
        }
        let d = match convert::delta3_from_c(g) {
            Ok(d) => d,
            Err(s) => return s,
        };
        match d.forward_kinematics(&theta) {
            Some(p) => {
                // SAFETY: non-null; the caller guarantees it is writable.
                unsafe { *out_tcp = DcVec3::from_vec3(&p) };
                DC_STATUS_OK
            }
            None => DC_STATUS_UNREACHABLE,
        }
    })
}
