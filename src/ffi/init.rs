//! Making and freeing a handle (the POU's start-up and shut-down): from a C configuration, a
//! cell file, a table or bundle in memory, or files; the last init error of each thread.

use super::collider::Collider;
use super::convert;
use super::convert::InitError;
use super::handle::{boundary, DcCollider};
use super::types::*;
use std::cell::RefCell;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

thread_local! {
    /// The message of this thread's last failed `dc_init*` (empty after a success).
    pub(super) static LAST_INIT_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
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
                Err(InitError::new(
                    DC_STATUS_PANIC,
                    "internal error (a panic) caught during init; please report it",
                ))
            })
        };
        let (status, message) = match result {
            Ok(inner) => {
                let handle = DcCollider::new(inner);
                // SAFETY: `result` is Ok only when `out_handle` was checked non-null above.
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
        return Err(InitError::new(
            DC_STATUS_NULL_POINTER,
            "config->robots is NULL: point it at n_robots robots",
        ));
    }
    if config.n_robots == 0 || config.n_robots > crate::cell::MAX_ROBOTS {
        let message = format!(
            "config->n_robots = {}: a cell has 1 to {} robots",
            config.n_robots,
            crate::cell::MAX_ROBOTS
        );
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
        return Err(InitError::new(
            DC_STATUS_NULL_POINTER,
            format!("{what} is NULL: pass a NUL-terminated path"),
        ));
    }
    // SAFETY: non-null, and the caller guarantees NUL termination.
    let Ok(text) = unsafe { CStr::from_ptr(path) }.to_str() else {
        return Err(InitError::new(
            DC_STATUS_INVALID_ARGUMENT,
            format!("{what} is not UTF-8: rename the file"),
        ));
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
pub unsafe extern "C" fn dc_init(
    config: *const DcCellConfig,
    out_handle: *mut *mut DcCollider,
) -> DcStatus {
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
pub unsafe extern "C" fn dc_init_from_cell_file(
    path: *const c_char,
    out_handle: *mut *mut DcCollider,
) -> DcStatus {
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
            return Err(InitError::new(
                DC_STATUS_NULL_POINTER,
                "table is NULL: pass the table file's bytes",
            ));
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
