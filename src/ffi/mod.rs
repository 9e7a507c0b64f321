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
//! - Two modes behind one handle: exact (`dc_init`, `dc_init_from_cell_file`) and table
//!   (`dc_init_with_table`, `dc_init_from_files`; a table, or a bundle of one table per pair
//!   that can meet); `dc_query` is the same.
//! - Table mode confirms a COLLISION lookup by the exact check unless
//!   `dc_set_table_confirmation` (or the cell file's `table_confirm`) says otherwise, so it
//!   answers as exact mode; `dc_table_confirmations` counts those ticks. With a clearance
//!   table the protective verdict is FREE by one lookup where the table's bound proves it
//!   (`dc_table_protective_lookups`), else the exact protective check.
//! - A handle is used by one task at a time; distinct handles are independent. A call that
//!   finds its handle in use by another call returns `DC_STATUS_BUSY` and does nothing
//!   ([`live`]: the handle's state is reached only under its busy flag).
#![allow(unsafe_code)]

mod collider;
mod convert;
pub mod types;

pub use convert::table_error_status;
pub use types::*;

use crate::cell::protective::TickTime;
use collider::{Collider, InitError};
use std::cell::{RefCell, UnsafeCell};
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// An initialised collision checker for one cell, in exact or table mode (opaque to C).
pub struct DcCollider {
    /// Reached only through [`live`], while `busy` is held.
    inner: UnsafeCell<Collider>,
    /// Set when a panic was caught inside a call: the handle's state is not trusted.
    poisoned: AtomicBool,
    /// Set while a call uses `inner`: a second call meanwhile (another task) is refused.
    busy: AtomicBool,
}

/// Runs `f` on the collider of a live handle: `DC_STATUS_NULL_POINTER` for NULL,
/// `DC_STATUS_BUSY` while another call uses the handle (nothing is done),
/// `DC_STATUS_PANIC` for a poisoned handle or a panic in `f` (which poisons it).
///
/// # Safety
/// `handle` must be NULL or a live handle from `dc_init*`.
unsafe fn live<R>(handle: *const DcCollider, f: impl FnOnce(&mut Collider) -> R) -> Result<R, DcStatus> {
    // SAFETY: the caller guarantees NULL or live; only shared references to the handle are
    // made, and its collider is reached through the cell below while `busy` is ours.
    let Some(h) = (unsafe { handle.as_ref() }) else { return Err(DC_STATUS_NULL_POINTER) };
    if h.busy.swap(true, Ordering::Acquire) {
        return Err(DC_STATUS_BUSY);
    }
    let result = if h.poisoned.load(Ordering::Relaxed) {
        Err(DC_STATUS_PANIC)
    } else {
        // SAFETY: `busy` was clear and is now set by this call: no other reference to the
        // collider exists until it is cleared below.
        let inner = unsafe { &mut *h.inner.get() };
        catch_unwind(AssertUnwindSafe(|| f(inner))).map_err(|_| {
            h.poisoned.store(true, Ordering::Relaxed);
            DC_STATUS_PANIC
        })
    };
    h.busy.store(false, Ordering::Release);
    result
}

/// The status of a call whose body returns its own status.
fn flatten(result: Result<DcStatus, DcStatus>) -> DcStatus {
    result.unwrap_or_else(|status| status)
}

thread_local! {
    /// The message of this thread's last failed `dc_init*` (empty after a success).
    static LAST_INIT_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Runs `f`, turning a panic into `DC_STATUS_PANIC`.
fn boundary(f: impl FnOnce() -> DcStatus) -> DcStatus {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(DC_STATUS_PANIC)
}

/// The common part of every `dc_init*`: sets `*out_handle` to NULL, runs `make`, stores the
/// new handle or records the error message for `dc_last_init_error`, returns the status.
///
/// # Safety
/// `out_handle` must be NULL or writable.
unsafe fn init_handle(
    out_handle: *mut *mut DcCollider,
    make: impl FnOnce() -> Result<Collider, InitError>,
) -> DcStatus {
    boundary(|| {
        let result = if out_handle.is_null() {
            Err(InitError::new(
                DC_STATUS_NULL_POINTER,
                "out_handle is NULL: pass the address of a DcCollider * variable",
            ))
        } else {
            // SAFETY: checked non-null above; the caller guarantees it is writable.
            unsafe { *out_handle = std::ptr::null_mut() };
            catch_unwind(AssertUnwindSafe(make)).unwrap_or_else(|_| {
                Err(InitError::new(DC_STATUS_PANIC, "internal error (a panic) caught during init; please report it"))
            })
        };
        let (status, message) = match result {
            Ok(inner) => {
                // SAFETY: `result` is Ok only when `out_handle` was checked non-null above.
                let handle = DcCollider {
                    inner: UnsafeCell::new(inner),
                    poisoned: AtomicBool::new(false),
                    busy: AtomicBool::new(false),
                };
                unsafe { *out_handle = Box::into_raw(Box::new(handle)) };
                (DC_STATUS_OK, String::new())
            }
            Err(e) => (e.status, e.message),
        };
        let _ = LAST_INIT_ERROR.try_with(|m| *m.borrow_mut() = message);
        status
    })
}

/// The validated cell of a C configuration.
///
/// # Safety
/// `config` must be NULL or point to a valid `DcCellConfig` whose `robots` points to
/// `n_robots` valid `DcRobotConfig`.
unsafe fn cell_from_config(config: *const DcCellConfig) -> Result<crate::cell::Cell, InitError> {
    // SAFETY: the caller guarantees `config` is NULL or valid.
    let Some(config) = (unsafe { config.as_ref() }) else {
        return Err(InitError::new(DC_STATUS_NULL_POINTER, "config is NULL: pass a DcCellConfig"));
    };
    if config.robots.is_null() {
        return Err(InitError::new(DC_STATUS_NULL_POINTER, "config->robots is NULL: point it at n_robots robots"));
    }
    if config.n_robots == 0 || config.n_robots > crate::cell::MAX_ROBOTS {
        let message =
            format!("config->n_robots = {}: a cell has 1 to {} robots", config.n_robots, crate::cell::MAX_ROBOTS);
        return Err(InitError::new(DC_STATUS_INVALID_CONFIG, message));
    }
    // SAFETY: non-null, and the caller guarantees `n_robots` valid elements.
    let robots = unsafe { std::slice::from_raw_parts(config.robots, config.n_robots) };
    convert::cell_from_c(robots, config.method)
}

/// A path argument as a `Path`; `what` names the argument in the error.
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string that outlives `'a`.
unsafe fn path_arg<'a>(path: *const c_char, what: &str) -> Result<&'a Path, InitError> {
    if path.is_null() {
        return Err(InitError::new(DC_STATUS_NULL_POINTER, format!("{what} is NULL: pass a NUL-terminated path")));
    }
    // SAFETY: non-null, and the caller guarantees NUL termination.
    let Ok(text) = unsafe { CStr::from_ptr(path) }.to_str() else {
        return Err(InitError::new(DC_STATUS_INVALID_ARGUMENT, format!("{what} is not UTF-8: rename the file")));
    };
    Ok(Path::new(text))
}

/// The thesis robot (f 100, rf 150, re 400, e 40, limits [-pi/2, 2 pi/3], H 70, D 17.5,
/// margin 0, lower links only) placed at the WCS origin: a starting point for a config.
#[no_mangle]
pub extern "C" fn dc_robot_config_thesis() -> DcRobotConfig {
    convert::thesis_robot_config()
}

/// Creates an exact-mode checker for the cell described by `config` (POU start-up): every
/// query tests every box pair that can meet (`dc_mode` gives `DC_MODE_EXACT`).
///
/// On success `*out_handle` holds a handle to pass to `dc_query` and finally to
/// `dc_destroy`; on any failure `*out_handle` is set to NULL (when `out_handle` is not
/// NULL) and `dc_last_init_error` tells why. Statuses: `DC_STATUS_NULL_POINTER` (config, its
/// robots array or out_handle is NULL), `DC_STATUS_INVALID_CONFIG` (no robots or more than
/// 32, a length <= 0, a negative margin or box extent, motor limits not a proper range,
/// NaN/inf, unknown method).
///
/// # Safety
/// `config` must be NULL or point to a valid `DcCellConfig` whose `robots` points to
/// `n_robots` valid `DcRobotConfig`; `out_handle` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_init(config: *const DcCellConfig, out_handle: *mut *mut DcCollider) -> DcStatus {
    let make = || {
        // SAFETY: the caller guarantees `config` is NULL or valid.
        let cell = unsafe { cell_from_config(config) }?;
        Ok(Collider::exact(cell))
    };
    // SAFETY: the caller guarantees `out_handle` is NULL or writable.
    unsafe { init_handle(out_handle, make) }
}

/// Creates an exact-mode checker from a TOML cell file (see `cells/t1.toml`); the file is
/// read once, here, never during a tick.
///
/// `*out_handle` as for `dc_init`. Statuses: `DC_STATUS_NULL_POINTER`,
/// `DC_STATUS_INVALID_ARGUMENT` (path not UTF-8), `DC_STATUS_IO` (cannot read),
/// `DC_STATUS_PARSE` (not TOML, unknown key, wrong type), `DC_STATUS_INVALID_CONFIG`.
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string; `out_handle` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_init_from_cell_file(path: *const c_char, out_handle: *mut *mut DcCollider) -> DcStatus {
    let make = || {
        // SAFETY: the caller guarantees `path` is NULL or NUL-terminated.
        let path = unsafe { path_arg(path, "path") }?;
        crate::cell::Cell::from_file(path)
            .map(Collider::exact)
            .map_err(|e| InitError::new(convert::cell_error_status(&e), e.to_string()))
    };
    // SAFETY: the caller guarantees `out_handle` is NULL or writable.
    unsafe { init_handle(out_handle, make) }
}

/// Creates a table-mode checker (POU start-up) for the cell `config` from the bytes of a table
/// file built offline for that cell (`delta-collide build --cell ...`): each query is then one
/// table lookup per pair of robots that can meet (`dc_mode` gives `DC_MODE_TABLE`). A
/// two-robot cell takes a table; a cell of more robots takes a bundle (the file `build` writes
/// for it), in which each pair finds the table of its relative placement. The table never answers
/// FREE where the exact model collides; where its lookup says COLLISION the exact check
/// confirms it (`DC_CONFIRMATION_EXACT`, the default), so the verdicts are exact mode's;
/// `dc_set_table_confirmation` with `DC_CONFIRMATION_NONE` answers the table's label instead
/// (it may say COLLISION where the exact model is free).
///
/// The buffer is validated once, here (magic, endianness, version, lengths, checksum, every
/// index, and that it was built for this cell), and copied: the caller may free it as soon
/// as this returns. `*out_handle` as for `dc_init`; `dc_last_init_error` names the field at
/// fault. Statuses: those of `dc_init`, and `DC_STATUS_NULL_POINTER` (table is NULL),
/// `DC_STATUS_TABLE_NOT_TWO_ROBOTS`, `DC_STATUS_TABLE_TRUNCATED` (also for table_len 0),
/// `DC_STATUS_TABLE_BAD_MAGIC`, `DC_STATUS_TABLE_UNSUPPORTED_VERSION`,
/// `DC_STATUS_TABLE_WRONG_ENDIANNESS`, `DC_STATUS_TABLE_CORRUPT`, `DC_STATUS_TABLE_WRONG_CELL`,
/// and for a bundle `DC_STATUS_TABLE_MISSING_PAIR` and `DC_STATUS_TABLE_WRONG_PAIR`.
///
/// # Safety
/// `config` as for `dc_init`; `table` must be NULL or point to `table_len` readable bytes;
/// `out_handle` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_init_with_table(
    config: *const DcCellConfig,
    table: *const u8,
    table_len: usize,
    out_handle: *mut *mut DcCollider,
) -> DcStatus {
    let make = || {
        // SAFETY: the caller guarantees `config` is NULL or valid.
        let cell = unsafe { cell_from_config(config) }?;
        if table.is_null() {
            return Err(InitError::new(DC_STATUS_NULL_POINTER, "table is NULL: pass the table file's bytes"));
        }
        // SAFETY: non-null, and the caller guarantees `table_len` readable bytes.
        let bytes = unsafe { std::slice::from_raw_parts(table, table_len) };
        Collider::table(cell, bytes, crate::table::Confirmation::Exact)
    };
    // SAFETY: the caller guarantees `out_handle` is NULL or writable.
    unsafe { init_handle(out_handle, make) }
}

/// Creates a table-mode checker from a TOML cell file and a table file, both read once,
/// here: `dc_init_from_cell_file` followed by `dc_init_with_table` on the file's bytes. The
/// cell file's `table_confirm = "exact"` (the default) or `"none"` sets the confirmation.
///
/// `*out_handle` as for `dc_init`. Statuses: those of `dc_init_from_cell_file` (for either
/// path; `DC_STATUS_IO` when a file cannot be read) and those of `dc_init_with_table`.
///
/// # Safety
/// `cell_path` and `table_path` must be NULL or NUL-terminated strings; `out_handle` must be
/// NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_init_from_files(
    cell_path: *const c_char,
    table_path: *const c_char,
    out_handle: *mut *mut DcCollider,
) -> DcStatus {
    let make = || {
        // SAFETY: the caller guarantees both paths are NULL or NUL-terminated.
        let (cell_path, table_path) =
            unsafe { (path_arg(cell_path, "cell_path")?, path_arg(table_path, "table_path")?) };
        Collider::from_files(cell_path, table_path)
    };
    // SAFETY: the caller guarantees `out_handle` is NULL or writable.
    unsafe { init_handle(out_handle, make) }
}

/// Copies the message of the calling thread's last failed `dc_init*` into `buf`
/// (NUL-terminated, cut to `capacity - 1` bytes) and returns the message's full length
/// without the NUL: it names the field at fault and the fix, e.g. "table is truncated:
/// section 0 (codes) needs 3139976 bytes, the buffer has 4096; copy the whole table file
/// again". Returns 0 (and writes "" when it can) after a successful init or before any.
/// `buf` may be NULL or `capacity` 0 to ask for the length only. Not for the tick loop.
///
/// # Safety
/// `buf` must be NULL or hold `capacity` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn dc_last_init_error(buf: *mut c_char, capacity: usize) -> usize {
    let copy = || {
        LAST_INIT_ERROR.with(|m| {
            let m = m.borrow();
            if !buf.is_null() && capacity > 0 {
                let n = m.len().min(capacity - 1);
                // SAFETY: non-null; the caller guarantees `capacity > n` writable bytes, and
                // a thread-local String never overlaps the caller's buffer.
                unsafe {
                    std::ptr::copy_nonoverlapping(m.as_ptr().cast::<c_char>(), buf, n);
                    *buf.add(n) = 0;
                }
            }
            m.len()
        })
    };
    catch_unwind(AssertUnwindSafe(copy)).unwrap_or(0)
}

/// The per-tick query: do the robots collide with robot j's TCP at `tcps_mcs[j]` (its MCS)?
/// Works the same in exact and table mode.
///
/// Writes `*out_verdict` (and `*out_report` when not NULL) on every call:
/// `DC_VERDICT_FREE` or `DC_VERDICT_COLLISION` with `DC_STATUS_OK`, else `DC_VERDICT_STOP`.
/// Statuses: `DC_STATUS_NULL_POINTER` (handle, tcps_mcs or out_verdict NULL),
/// `DC_STATUS_WRONG_ROBOT_COUNT`, `DC_STATUS_NON_FINITE` (a NaN/inf coordinate; the
/// report's `unreachable_mask` names the robot), `DC_STATUS_UNREACHABLE` (a TCP outside
/// the robot's reach or motor limits; mask as before), `DC_STATUS_PANIC` (destroy the
/// handle). In table mode a COLLISION report names robots 0 and 1 and no boxes
/// (`DC_BOX_NONE`). Never allocates, locks or does I/O.
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
        if out_verdict.is_null() || tcps_mcs.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees `n_tcps` readable elements.
        let tcps = unsafe { std::slice::from_raw_parts(tcps_mcs, n_tcps) };
        // SAFETY: the caller guarantees `handle` is NULL or live.
        flatten(unsafe { live(handle, |c| c.query(tcps, &mut report)) })
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

/// The default stopping model (SPEC section 8: reaction 4 ms, decel 40000 mm/s^2, max accel
/// 130000 mm/s^2, max speed 4600 mm/s) with `struct_size` set: start from it and change
/// the fields that differ.
#[no_mangle]
pub extern "C" fn dc_stop_config_default() -> DcStopConfig {
    convert::stop_config_default()
}

/// Sets the protective verdict's controller tick (ms), WARN threshold (mm) and one stopping
/// model per robot (`n_stops` = the cell's robots), and forgets the previous TCPs. Until it
/// is called a handle uses the cell file's `tick_ms` and `stop` keys, or for `dc_init` the
/// defaults (tick 1 ms, `dc_stop_config_default()`), and `warn_mm` = 10. Setup only: it
/// allocates; call it before the tick loop. On failure the handle keeps its previous models
/// and `dc_last_init_error` names the field at fault.
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle or stops NULL), `DC_STATUS_WRONG_ROBOT_COUNT`,
/// `DC_STATUS_INVALID_ARGUMENT` (a `struct_size` that is not this header's
/// `sizeof(DcStopConfig)`), `DC_STATUS_INVALID_CONFIG` (a value NaN, infinite or not > 0,
/// `decel_mm_s2` above `max_accel_mm_s2`, `warn_mm` negative), `DC_STATUS_PANIC`.
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread; `stops` must be NULL
/// or point to `n_stops` readable `DcStopConfig`.
#[no_mangle]
pub unsafe extern "C" fn dc_set_stop_model(
    handle: *mut DcCollider,
    tick_ms: f64,
    warn_mm: f64,
    stops: *const DcStopConfig,
    n_stops: usize,
) -> DcStatus {
    boundary(|| {
        if stops.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees `n_stops` readable elements.
        let stops = unsafe { std::slice::from_raw_parts(stops, n_stops) };
        let set = |c: &mut Collider| {
            if n_stops != c.robot_count() {
                return DC_STATUS_WRONG_ROBOT_COUNT;
            }
            let (status, message) = match c.set_stopping(tick_ms, warn_mm, stops) {
                Ok(()) => (DC_STATUS_OK, String::new()),
                Err(e) => (e.status, e.message),
            };
            let _ = LAST_INIT_ERROR.try_with(|m| *m.borrow_mut() = message);
            status
        };
        // SAFETY: the caller guarantees `handle` is NULL or live.
        flatten(unsafe { live(handle, set) })
    })
}

/// Forgets the previous TCPs of the protective verdict and the last call's cycle (e.g. after
/// the robots were moved by hand): the next protective query assumes every robot at full
/// speed. NULL is a no-op; a panic inside poisons the handle.
///
/// # Safety
/// `handle` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn dc_protective_reset(handle: *mut DcCollider) {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    let _ = unsafe { live(handle, Collider::reset_protective) };
}

/// The protective query (SPEC section 8) without a time: can every robot still stop, from
/// now on, without any box touching a box of another robot? Robot j's TCP is `tcps_mcs[j]`
/// (its MCS); its speed is estimated from the TCP of the previous call, assumed exactly one
/// tick of `dc_set_stop_model` earlier. Correct only when called exactly once per cycle, at
/// the cycle's nominal time: called twice in one cycle it reads a moving robot as standing.
/// `dc_protective_query_timed` takes the cycle and fails closed on every timing fault: use
/// it in the tick loop. Works in exact and table mode (it reads the exact boxes). In table mode with a clearance table, a tick whose certified clearance bound
/// exceeds both robots' motion bounds over their stops plus `warn_mm` is FREE by the lookup,
/// without the box-pair proof (`dc_table_protective_lookups`); every other tick takes the
/// exact protective check, as in exact mode. The report is filled alike in both modes.
///
/// Writes `*out_verdict` (and `*out_report` when not NULL) on every call:
/// `DC_VERDICT_FREE` (proved: every stop the models allow keeps the boxes apart),
/// `DC_VERDICT_WARN` (proved, with less than `warn_mm` to spare) or `DC_VERDICT_STOP` (not
/// proved, or any status other than OK). The first call, and the first after any error or
/// `dc_protective_reset`, has no previous TCP and assumes full speed. Statuses:
/// `DC_STATUS_NULL_POINTER` (handle, tcps_mcs or out_verdict NULL),
/// `DC_STATUS_WRONG_ROBOT_COUNT`, `DC_STATUS_NON_FINITE`, `DC_STATUS_UNREACHABLE`,
/// `DC_STATUS_IMPLAUSIBLE_MOTION` (the report's `unreachable_mask` names the robot),
/// `DC_STATUS_PANIC` (destroy the handle). Never allocates, locks or does I/O; it takes a
/// few hundred microseconds (the speed limits are most of it).
///
/// # Safety
/// `handle` must be NULL or a live handle from `dc_init*` not used by another thread;
/// `tcps_mcs` must be NULL or point to `n_tcps` readable `DcVec3`; the out pointers must be
/// NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_protective_query(
    handle: *mut DcCollider,
    tcps_mcs: *const DcVec3,
    n_tcps: usize,
    out_verdict: *mut DcVerdict,
    out_report: *mut DcProtectiveReport,
) -> DcStatus {
    // SAFETY: the caller's guarantees on `handle`, `tcps_mcs` and the outputs are passed on.
    unsafe {
        protective_entry(handle, tcps_mcs, n_tcps, out_verdict, out_report, |c, tcps, report| {
            c.protective_query(TickTime::Nominal, tcps, None, report)
        })
    }
}

/// `dc_protective_query` (untimed: exactly once per cycle, at its nominal time; the timed
/// call takes the paths in its request) for a controller that knows the path each robot's
/// stop will follow (a path-maintaining stop: its next set-points), which brings STOPs down
/// toward the ticks where a stop really cannot avoid contact. `paths[j]` is robot `j`'s `DcStopPath`
/// (`n_points` 0: not known; that robot is then bounded as by `dc_protective_query`). The
/// verdict is the better of the proof without paths and the proof along them; the speed
/// limits are those without paths. Statuses: those of `dc_protective_query`, and
/// `DC_STATUS_NULL_POINTER` (paths NULL, or a path's points NULL with `n_points` > 0),
/// `DC_STATUS_WRONG_ROBOT_COUNT` (`n_paths` differs from the robot count),
/// `DC_STATUS_INVALID_ARGUMENT` (a path with more than `DC_MAX_PATH_POINTS` points, a
/// non-finite point or tolerance, a negative tolerance, or the TCP now farther than the
/// tolerance from its path; `unreachable_mask` names the robot). On every status but OK the
/// verdict is STOP, and the next call assumes full speed. Never allocates, locks or does I/O.
///
/// # Safety
/// As `dc_protective_query`; `paths` must be NULL or point to `n_paths` readable
/// `DcStopPath`, each with `points` NULL or pointing to `n_points` readable `DcVec3`.
#[no_mangle]
pub unsafe extern "C" fn dc_protective_query_with_paths(
    handle: *mut DcCollider,
    tcps_mcs: *const DcVec3,
    n_tcps: usize,
    paths: *const DcStopPath,
    n_paths: usize,
    out_verdict: *mut DcVerdict,
    out_report: *mut DcProtectiveReport,
) -> DcStatus {
    // SAFETY: the caller's guarantees on `handle`, `tcps_mcs` and the outputs are passed on.
    unsafe {
        protective_entry(handle, tcps_mcs, n_tcps, out_verdict, out_report, |c, tcps, report| {
            // SAFETY: non-null, and the caller guarantees `n_paths` readable paths.
            with_path_views(c, paths, n_paths, report, |c, views, report| {
                c.protective_query(TickTime::Nominal, tcps, Some(views), report)
            })
        })
    }
}

/// A `DcProtectiveRequest` with `struct_size` set, `DC_CLOCK_CYCLE`, time 0, no TCPs and no
/// paths: set `time`, `tcps_mcs` and `n_tcps` (and the paths, if known) before each call.
#[no_mangle]
pub extern "C" fn dc_protective_request_default() -> DcProtectiveRequest {
    DcProtectiveRequest {
        struct_size: std::mem::size_of::<DcProtectiveRequest>(),
        clock: DC_CLOCK_CYCLE,
        time: 0,
        tcps_mcs: std::ptr::null(),
        n_tcps: 0,
        paths: std::ptr::null(),
        n_paths: 0,
    }
}

/// The protective query with the time its TCPs hold, the call for the tick loop:
/// `dc_protective_query` (or, with paths, `dc_protective_query_with_paths`) whose speeds are
/// bounded over the real interval since the last call, from `request->time`:
/// - `DC_CLOCK_CYCLE`: the controller's cycle counter, one more per `tick_ms`, the TCPs that
///   cycle's; `DC_CLOCK_NANOS`: a monotonic timestamp (ns) of the TCPs' measurement.
/// - The same cycle (or timestamp) as the last call with the same TCPs (a function block
///   called twice, a retried call) writes the last call's verdict, report and status again,
///   unchanged. Every other timing fault is STOP with its own status, and the next call
///   assumes full speed: the same cycle with other TCPs `DC_STATUS_TIME_REPEATED`, an
///   earlier one `DC_STATUS_TIME_BACKWARDS`, more than `DC_MAX_INTERVAL_TICKS` ticks later
///   `DC_STATUS_TIME_JUMP`, a timestamp less than half a tick later `DC_STATUS_TIME_EARLY`,
///   a change of `clock` `DC_STATUS_CLOCK_CHANGED`. A skipped cycle (up to
///   `DC_MAX_INTERVAL_TICKS`) is bounded over its real interval.
/// - The first timed call, and the first after an untimed call, an error or
///   `dc_protective_reset`, assumes full speed.
/// A FREE or WARN covers a STOP issued at the next cycle: a controller that misses one must
/// stop the robots itself.
///
/// Statuses: those of `dc_protective_query_with_paths`, the timing statuses above,
/// `DC_STATUS_NULL_POINTER` (request NULL, or paths NULL with `n_paths` > 0),
/// `DC_STATUS_INVALID_ARGUMENT` (a `struct_size` that is not this header's
/// `sizeof(DcProtectiveRequest)`, an unknown `clock`), `DC_STATUS_WRONG_ROBOT_COUNT` (`n_paths` neither 0 nor the robot
/// count), `DC_STATUS_BUSY` (the handle is in another call). `*out_verdict` and
/// `*out_report` are written on every call. Never allocates, locks or does I/O.
///
/// # Safety
/// `handle` must be NULL or a live handle from `dc_init*`; `request` must be NULL or point
/// to a readable `DcProtectiveRequest` whose `tcps_mcs` is NULL or points to `n_tcps`
/// readable `DcVec3` and whose `paths` is as for `dc_protective_query_with_paths`; the out
/// pointers must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_protective_query_timed(
    handle: *mut DcCollider,
    request: *const DcProtectiveRequest,
    out_verdict: *mut DcVerdict,
    out_report: *mut DcProtectiveReport,
) -> DcStatus {
    // SAFETY: the caller guarantees `request` is NULL or readable.
    let request = match unsafe { request.as_ref() } {
        Some(r) => *r,
        None => DcProtectiveRequest { tcps_mcs: std::ptr::null(), ..dc_protective_request_default() },
    };
    let time = match (request.struct_size == std::mem::size_of::<DcProtectiveRequest>(), request.clock) {
        (true, DC_CLOCK_CYCLE) => Ok(TickTime::Cycle(request.time)),
        (true, DC_CLOCK_NANOS) => Ok(TickTime::Nanos(request.time)),
        _ => Err(DC_STATUS_INVALID_ARGUMENT),
    };
    let (tcps, n_tcps, paths, n_paths) = (request.tcps_mcs, request.n_tcps, request.paths, request.n_paths);
    // SAFETY: the caller's guarantees on `handle`, the request's TCPs and the outputs are
    // passed on; a NULL request reads as NULL TCPs.
    unsafe {
        protective_entry(handle, tcps, n_tcps, out_verdict, out_report, |c, tcps, report| {
            let time = match time {
                Ok(time) => time,
                Err(status) => return status,
            };
            if n_paths == 0 {
                return c.protective_query(time, tcps, None, report);
            }
            // SAFETY: the caller guarantees `n_paths` readable paths when `paths` is not NULL.
            with_path_views(c, paths, n_paths, report, |c, views, report| {
                c.protective_query(time, tcps, Some(views), report)
            })
        })
    }
}

/// Runs `query` with the robots' stop paths `paths[0..n_paths]` read as slices (after the
/// checks of `dc_protective_query_with_paths`: a path with NULL points and `n_points` > 0,
/// or more than `DC_MAX_PATH_POINTS` points, names its robot in the report and forgets the
/// previous TCPs).
///
/// # Safety
/// `paths` must be NULL or point to `n_paths` readable `DcStopPath`, each with `points` NULL
/// or pointing to `n_points` readable `DcVec3`, alive for the call.
unsafe fn with_path_views(
    c: &mut Collider,
    paths: *const DcStopPath,
    n_paths: usize,
    report: &mut DcProtectiveReport,
    query: impl FnOnce(&mut Collider, &[(&[DcVec3], f64)], &mut DcProtectiveReport) -> DcStatus,
) -> DcStatus {
    if paths.is_null() {
        return DC_STATUS_NULL_POINTER;
    }
    if n_paths != c.robot_count() {
        return DC_STATUS_WRONG_ROBOT_COUNT;
    }
    // SAFETY: non-null, and the caller guarantees `n_paths` readable elements.
    let paths = unsafe { std::slice::from_raw_parts(paths, n_paths) };
    let mut views: [(&[DcVec3], f64); crate::cell::MAX_ROBOTS] = [(&[], 0.0); crate::cell::MAX_ROBOTS];
    for (j, (view, path)) in views.iter_mut().zip(paths).enumerate() {
        if path.n_points == 0 {
            continue;
        }
        if path.points.is_null() || path.n_points > DC_MAX_PATH_POINTS {
            report.unreachable_mask = 1 << j;
            c.reset_protective();
            return if path.points.is_null() { DC_STATUS_NULL_POINTER } else { DC_STATUS_INVALID_ARGUMENT };
        }
        // SAFETY: non-null, and the caller guarantees `n_points` readable elements.
        *view = (unsafe { std::slice::from_raw_parts(path.points, path.n_points) }, path.tolerance_mm);
    }
    query(c, &views[..n_paths], report)
}

/// The common part of the protective entry points: checks the handle and the pointers, runs
/// `query` on the handle's collider with the TCPs (a panic poisons the handle), and writes
/// the outputs on every call, the verdict STOP on every status but OK.
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread; `tcps_mcs` NULL or
/// `n_tcps` readable elements; the outputs NULL or writable.
unsafe fn protective_entry(
    handle: *mut DcCollider,
    tcps_mcs: *const DcVec3,
    n_tcps: usize,
    out_verdict: *mut DcVerdict,
    out_report: *mut DcProtectiveReport,
    query: impl FnOnce(&mut Collider, &[DcVec3], &mut DcProtectiveReport) -> DcStatus,
) -> DcStatus {
    let mut report = DcProtectiveReport::STOP;
    let status = boundary(|| {
        if out_verdict.is_null() || tcps_mcs.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees `n_tcps` readable elements.
        let tcps = unsafe { std::slice::from_raw_parts(tcps_mcs, n_tcps) };
        // SAFETY: the caller guarantees `handle` is NULL or live.
        flatten(unsafe { live(handle, |c| query(c, tcps, &mut report)) })
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

/// Copies the per-pair results of the last query into `out[0..]` and their number into
/// `*out_len`. Exact mode: the pairs whose reach can overlap (`dc_pair_count`), with the
/// colliding boxes. Table mode: one pair (robots 0 and 1), `collides` as the last verdict,
/// boxes `DC_BOX_NONE` unless the exact check answered; with a bundle, as exact mode's pairs,
/// each pair's own answer. After a query that did not return `DC_STATUS_OK` the results are
/// not a decision (table mode: `collides` 0). Statuses: `DC_STATUS_NULL_POINTER`,
/// `DC_STATUS_INVALID_ARGUMENT` (`capacity` smaller than `dc_pair_count`; `*out_len` then
/// holds the count needed).
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
        if out.is_null() || out_len.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        let copy = |c: &mut Collider| {
            let n = c.pair_count();
            // SAFETY: non-null; the caller guarantees it is writable.
            unsafe { *out_len = n };
            if capacity < n {
                return DC_STATUS_INVALID_ARGUMENT;
            }
            // SAFETY: non-null, and the caller guarantees `capacity >= n` writable elements.
            let out = unsafe { std::slice::from_raw_parts_mut(out, n) };
            c.pair_results(out);
            DC_STATUS_OK
        };
        // SAFETY: the caller guarantees `handle` is NULL or live.
        flatten(unsafe { live(handle, copy) })
    })
}

/// How the handle answers: `DC_MODE_EXACT` or `DC_MODE_TABLE`; `DC_MODE_NONE` for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_mode(handle: *const DcCollider) -> DcMode {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { live(handle, |c| c.mode()) }.unwrap_or(DC_MODE_NONE)
}

/// Table mode: how many queries so far were answered by the exact model because a TCP lay
/// reachable but outside the table's sampled grid (the answer is then exact, never a
/// guess). 0 in exact mode and for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_table_fallbacks(handle: *const DcCollider) -> u64 {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { live(handle, |c| c.table_fallbacks()) }.unwrap_or(0)
}

/// Table mode with a clearance table (`delta-collide build --variant clearance`): the
/// certified lower bound on the robots' clearance (mm, SPEC section 8) over the table's grid
/// cell of `tcps_mcs` (robot j's TCP in its own MCS): every configuration of that cell keeps
/// the robots' boxes at least this far apart. One lookup; never allocates.
///
/// Writes `*out_mm` on every call: the bound with `DC_STATUS_OK`, or `-INFINITY` when
/// nothing is proved (the cell may collide, a TCP lies outside the table's grid, an
/// exact-mode handle or a boolean table) and on any error. Statuses as `dc_query`:
/// `DC_STATUS_NULL_POINTER` (handle, tcps_mcs or out_mm NULL), `DC_STATUS_WRONG_ROBOT_COUNT`,
/// `DC_STATUS_NON_FINITE`, `DC_STATUS_UNREACHABLE`, `DC_STATUS_PANIC`.
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread; `tcps_mcs` must be
/// NULL or point to `n_tcps` readable `DcVec3`; `out_mm` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn dc_table_clearance_bound(
    handle: *mut DcCollider,
    tcps_mcs: *const DcVec3,
    n_tcps: usize,
    out_mm: *mut f64,
) -> DcStatus {
    let mut bound = f64::NEG_INFINITY;
    let status = boundary(|| {
        if out_mm.is_null() || tcps_mcs.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null, and the caller guarantees `n_tcps` readable elements.
        let tcps = unsafe { std::slice::from_raw_parts(tcps_mcs, n_tcps) };
        // SAFETY: the caller guarantees `handle` is NULL or live.
        let (status, mm) = unsafe { live(handle, |c| c.clearance_bound(tcps)) }.unwrap_or_else(|s| (s, f64::NEG_INFINITY));
        bound = mm;
        status
    });
    if !out_mm.is_null() {
        // SAFETY: non-null; the caller guarantees it is writable.
        unsafe { *out_mm = if status == DC_STATUS_OK { bound } else { f64::NEG_INFINITY } };
    }
    status
}

/// Table mode: chooses what a query does when the table's lookup says COLLISION, from the
/// next query on: `DC_CONFIRMATION_EXACT` (the default) runs the exact check and answers its
/// verdict, so the handle answers as exact mode; `DC_CONFIRMATION_NONE` answers the table's
/// label. Setup only, like `dc_set_stop_model`; the per-tick query still never allocates.
/// On an exact-mode handle it changes nothing (exact mode always answers exactly).
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle NULL), `DC_STATUS_INVALID_ARGUMENT` (a value
/// that is neither; the handle keeps its setting and `dc_last_init_error` says so),
/// `DC_STATUS_PANIC` (a poisoned handle).
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread.
#[no_mangle]
pub unsafe extern "C" fn dc_set_table_confirmation(handle: *mut DcCollider, confirmation: DcConfirmation) -> DcStatus {
    // SAFETY: the caller guarantees `handle` is NULL or live and unshared.
    unsafe {
        set_on_handle(handle, |c| match convert::confirmation_from_c(confirmation) {
            Some(value) => {
                c.set_table_confirmation(value);
                Ok(())
            }
            None => Err(format!("confirmation = {confirmation}: use DC_CONFIRMATION_EXACT or DC_CONFIRMATION_NONE")),
        })
    }
}

/// The body of a setup setter: NULL and poisoned handles are statuses; `set` applies the
/// value or says why it is refused (`DC_STATUS_INVALID_ARGUMENT`, the handle unchanged);
/// `dc_last_init_error` holds that message, or is cleared.
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread.
unsafe fn set_on_handle(handle: *mut DcCollider, set: impl FnOnce(&mut Collider) -> Result<(), String>) -> DcStatus {
    let apply = |c: &mut Collider| {
        let (status, message) = match set(c) {
            Ok(()) => (DC_STATUS_OK, String::new()),
            Err(message) => (DC_STATUS_INVALID_ARGUMENT, message),
        };
        let _ = LAST_INIT_ERROR.try_with(|m| *m.borrow_mut() = message);
        status
    };
    // SAFETY: the caller guarantees `handle` is NULL or live.
    boundary(|| flatten(unsafe { live(handle, apply) }))
}

/// Whether `dc_protective_query` (and `..._with_paths`) finds each robot's speed limit (`on`
/// 1, the default) or leaves `speed_limit_mm_s` NaN (`on` 0): the verdict is the same
/// either way, and without the limits a tick takes a fraction of the time (the limits search
/// several speeds per robot; README, "Stopping before contact"). Setup only, like
/// `dc_set_stop_model`, and kept by it.
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle NULL), `DC_STATUS_INVALID_ARGUMENT` (`on`
/// neither 0 nor 1; the handle keeps its setting and `dc_last_init_error` says so),
/// `DC_STATUS_PANIC` (a poisoned handle).
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread.
#[no_mangle]
pub unsafe extern "C" fn dc_set_speed_limits(handle: *mut DcCollider, on: u32) -> DcStatus {
    // SAFETY: the caller guarantees `handle` is NULL or live and unshared.
    unsafe {
        set_on_handle(handle, |c| match on {
            0 | 1 => {
                c.set_speed_limits(on == 1);
                Ok(())
            }
            _ => Err(format!("on = {on}: use 1 (speed limits) or 0 (verdict only)")),
        })
    }
}

/// Caps the speeds that the speed-limit searches of `dc_protective_query` test per tick, all
/// robots together: each test costs about one robot's stop sweeps and their proof, so this
/// bounds the time a tick's limits take. The default is the robot count plus one; 0 reports
/// each robot's measured speed when the verdict is not STOP (else 0); `UINT32_MAX` lets
/// every search run to its end. Out of tests, a robot's limit is the largest speed its search
/// proved: a proved speed, perhaps below what the full search would find; the next tick goes
/// on from there. The verdict is the same whatever the cap. Setup only, like
/// `dc_set_stop_model`, and kept by it.
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle NULL), `DC_STATUS_PANIC` (a poisoned handle).
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread.
#[no_mangle]
pub unsafe extern "C" fn dc_set_limit_tests(handle: *mut DcCollider, tests: u32) -> DcStatus {
    // SAFETY: the caller guarantees `handle` is NULL or live and unshared.
    unsafe {
        set_on_handle(handle, |c| {
            c.set_limit_tests(tests);
            Ok(())
        })
    }
}

/// Table mode: how many queries so far the table's lookup said COLLISION and the exact check
/// confirmed or refuted it (`DC_CONFIRMATION_EXACT`); ticks answered by the exact fallback
/// are counted by `dc_table_fallbacks` instead. 0 in exact mode and for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_table_confirmations(handle: *const DcCollider) -> u64 {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { live(handle, |c| c.table_confirmations()) }.unwrap_or(0)
}

/// Table mode with a clearance table (`build --variant clearance`): how many protective
/// queries so far (`dc_protective_query`, `dc_protective_query_with_paths`) were answered
/// FREE by the table's certified clearance bound alone, which exceeded both robots' motion
/// bounds over their stops plus `warn_mm` (docs/PROTECTIVE.md); every other protective query
/// took the exact protective proof. 0 in exact mode, with a boolean table and for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_table_protective_lookups(handle: *const DcCollider) -> u64 {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { live(handle, |c| c.table_protective_lookups()) }.unwrap_or(0)
}

/// Number of robots of the handle's cell; 0 for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_robot_count(handle: *const DcCollider) -> usize {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { live(handle, |c| c.robot_count()) }.unwrap_or(0)
}

/// Number of robot pairs `dc_pair_results` reports: exact mode, the pairs that can meet
/// (kept after pruning at init); table mode, 1 (a bundle: the pairs that can meet, one lookup
/// each); 0 for NULL.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_pair_count(handle: *const DcCollider) -> usize {
    // SAFETY: the caller guarantees `handle` is NULL or live.
    unsafe { live(handle, |c| c.pair_count()) }.unwrap_or(0)
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
        DC_STATUS_TABLE_TRUNCATED => c"the table is truncated: copy the whole table file again",
        DC_STATUS_TABLE_BAD_MAGIC => {
            c"not a delta-collide table (bad magic): check that the right file or buffer is given"
        }
        DC_STATUS_TABLE_UNSUPPORTED_VERSION => {
            c"the table's format version is not supported: rebuild it with `delta-collide build`"
        }
        DC_STATUS_TABLE_WRONG_ENDIANNESS => {
            c"the table is big-endian, this library reads little-endian tables: rebuild it with `delta-collide build`"
        }
        DC_STATUS_TABLE_CORRUPT => c"the table is corrupt (checksum or a field): rebuild it or copy it again",
        DC_STATUS_TABLE_WRONG_CELL => {
            c"the table was built for another cell: rebuild it with `delta-collide build --cell ...` for this cell"
        }
        DC_STATUS_TABLE_NOT_TWO_ROBOTS => c"a table serves a cell of two or more robots: use dc_init (exact mode) for this cell",
        DC_STATUS_IMPLAUSIBLE_MOTION => {
            c"a TCP moved further or changed its velocity more in one tick than its stopping model allows"
        }
        DC_STATUS_TABLE_MISSING_PAIR => {
            c"the table bundle holds no table for a pair that can meet: rebuild it with `delta-collide build --cell ...`"
        }
        DC_STATUS_TABLE_WRONG_PAIR => {
            c"the table bundle's table for a pair was built for another spacing: rebuild it with `delta-collide build --cell ...`"
        }
        DC_STATUS_TIME_REPEATED => c"the same cycle as the last protective call, with other TCPs",
        DC_STATUS_TIME_BACKWARDS => c"a cycle or timestamp before the last protective call's",
        DC_STATUS_TIME_JUMP => c"more than DC_MAX_INTERVAL_TICKS ticks since the last protective call",
        DC_STATUS_TIME_EARLY => c"a timestamp less than half a tick after the last protective call's",
        DC_STATUS_CLOCK_CHANGED => c"a cycle counter after a timestamp, or a timestamp after a cycle counter",
        DC_STATUS_BUSY => c"the handle is in use by another call: give each task its own handle",
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
