//! The per-tick collision query and what it reports: per pair results, the mode, the table
//! mode's counters and clearance bound, the robot and pair counts.

use super::collider::Collider;
use super::handle::{boundary, flatten, live, tick_entry, DcCollider};
use super::types::*;

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
    let stop = DcQueryReport::STOP;
    // SAFETY: the caller's guarantees on the handle, the TCPs and the outputs are passed on.
    unsafe {
        tick_entry(handle, (tcps_mcs, n_tcps), (out_verdict, out_report), stop, |c, tcps, r| {
            c.query(tcps, r)
        })
    }
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
        let (status, mm) = unsafe { live(handle, |c| c.clearance_bound(tcps)) }
            .unwrap_or_else(|s| (s, f64::NEG_INFINITY));
        bound = mm;
        status
    });
    if !out_mm.is_null() {
        // SAFETY: non-null; the caller guarantees it is writable.
        unsafe { *out_mm = if status == DC_STATUS_OK { bound } else { f64::NEG_INFINITY } };
    }
    status
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
