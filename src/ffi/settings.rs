//! Setup calls that change how a handle answers: the stopping models, table mode's
//! confirmation, the speed limits and their cap.

use super::collider::Collider;
use super::convert;
use super::handle::{boundary, flatten, live, DcCollider};
use super::init::LAST_INIT_ERROR;
use super::types::*;

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
pub unsafe extern "C" fn dc_set_table_confirmation(
    handle: *mut DcCollider,
    confirmation: DcConfirmation,
) -> DcStatus {
    // SAFETY: the caller guarantees `handle` is NULL or live and unshared.
    unsafe {
        set_on_handle(handle, |c| match convert::confirmation_from_c(confirmation) {
            Some(value) => {
                c.set_table_confirmation(value);
                Ok(())
            }
            None => Err(format!(
                "confirmation = {confirmation}: use DC_CONFIRMATION_EXACT or DC_CONFIRMATION_NONE"
            )),
        })
    }
}

/// The body of a setup setter: NULL and poisoned handles are statuses; `set` applies the
/// value or says why it is refused (`DC_STATUS_INVALID_ARGUMENT`, the handle unchanged);
/// `dc_last_init_error` holds that message, or is cleared.
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread.
pub(super) unsafe fn set_on_handle(
    handle: *mut DcCollider,
    set: impl FnOnce(&mut Collider) -> Result<(), String>,
) -> DcStatus {
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

/// Caps the units of work that `dc_protective_query_with_paths` spends per tick on the proof
/// along the stop paths: its halvings of the paths into pieces, its time slices and its
/// speed limits' tests along the paths, each unit one piece's stop sweeps or one proof of two
/// pieces apart (about 21,000 x86-64 instructions; docs/record/2026-12-02-worst-cases.md).
/// The default is `DC_DEFAULT_PATH_WORK`, which keeps the worst call found by search within
/// a 1 ms tick on the machine of the records; 0 answers as `dc_protective_query` does; `UINT32_MAX`
/// sets no cap. A step that finds too few units left is not taken and what it would have
/// proved stays unproved: the verdict is then at best the one without paths, a speed limit
/// the highest speed proved so far (`dc_tick_stats` counts such calls in `budget_spent`). So
/// the cap bounds the work that grows with the inputs, and running out answers the safe way.
/// Setup only, like `dc_set_stop_model`, and kept by it.
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle NULL), `DC_STATUS_PANIC` (a poisoned handle).
///
/// # Safety
/// `handle` must be NULL or a live handle not used by another thread.
#[no_mangle]
pub unsafe extern "C" fn dc_set_path_work(handle: *mut DcCollider, units: u32) -> DcStatus {
    // SAFETY: the caller guarantees `handle` is NULL or live and unshared.
    unsafe {
        set_on_handle(handle, |c| {
            c.set_path_work(units);
            Ok(())
        })
    }
}
