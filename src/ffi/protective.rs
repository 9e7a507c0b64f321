//! The protective queries (SPEC section 8): timed, untimed, with stop paths; the reset of
//! their history.

use super::collider::Collider;
use super::handle::{live, tick_entry, DcCollider};
use super::types::*;
use crate::cell::protective::TickTime;

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
/// it in the tick loop. Works in exact and table mode (it reads the exact boxes). In table mode
/// with a clearance table, a tick whose certified clearance bound exceeds both robots' motion
/// bounds over their stops plus `warn_mm` is FREE by the lookup, without the box-pair proof
/// (`dc_table_protective_lookups`); every other tick takes the exact protective check, as in exact
/// mode. The report is filled alike in both modes.
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
/// toward the ticks where a stop really cannot avoid contact. `paths[j]` is robot `j`'s
/// `DcStopPath` (`n_points` 0: not known; that robot is then bounded as by `dc_protective_query`).
/// The verdict is the better of the proof without paths and the proof along them; the speed
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
///
/// A FREE or WARN covers a STOP issued at the next cycle: a controller that misses one must
/// stop the robots itself.
///
/// Statuses: those of `dc_protective_query_with_paths`, the timing statuses above,
/// `DC_STATUS_NULL_POINTER` (request NULL, or paths NULL with `n_paths` > 0),
/// `DC_STATUS_INVALID_ARGUMENT` (a `struct_size` that is not this header's
/// `sizeof(DcProtectiveRequest)`, an unknown `clock`), `DC_STATUS_WRONG_ROBOT_COUNT` (`n_paths`
/// neither 0 nor the robot count), `DC_STATUS_BUSY` (the handle is in another call). `*out_verdict`
/// and `*out_report` are written on every call. Never allocates, locks or does I/O.
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
        None => {
            DcProtectiveRequest { tcps_mcs: std::ptr::null(), ..dc_protective_request_default() }
        }
    };
    let (tcps, n_tcps) = (request.tcps_mcs, request.n_tcps);
    // SAFETY: the caller's guarantees on `handle`, the request's TCPs and paths and the
    // outputs are passed on; a NULL request reads as NULL TCPs.
    unsafe {
        protective_entry(handle, tcps, n_tcps, out_verdict, out_report, |c, tcps, report| {
            timed_query(c, &request, tcps, report)
        })
    }
}

/// The timed query of `request` on a collider, its TCPs read as `tcps`.
///
/// # Safety
/// The request's `paths` must be NULL or point to `n_paths` readable `DcStopPath`, as for
/// `dc_protective_query_with_paths`.
unsafe fn timed_query(
    c: &mut Collider,
    request: &DcProtectiveRequest,
    tcps: &[DcVec3],
    report: &mut DcProtectiveReport,
) -> DcStatus {
    let (paths, n_paths) = (request.paths, request.n_paths);
    match (request_time(request), n_paths) {
        (Err(status), _) => status,
        (Ok(time), 0) => c.protective_query(time, tcps, None, report),
        // SAFETY: the caller guarantees `n_paths` readable paths when not NULL.
        (Ok(time), _) => unsafe {
            with_path_views(c, paths, n_paths, report, |c, views, report| {
                c.protective_query(time, tcps, Some(views), report)
            })
        },
    }
}

/// The time of a request, or `DC_STATUS_INVALID_ARGUMENT` for another `struct_size` than
/// this header's or an unknown clock.
fn request_time(request: &DcProtectiveRequest) -> Result<TickTime, DcStatus> {
    match (request.struct_size == std::mem::size_of::<DcProtectiveRequest>(), request.clock) {
        (true, DC_CLOCK_CYCLE) => Ok(TickTime::Cycle(request.time)),
        (true, DC_CLOCK_NANOS) => Ok(TickTime::Nanos(request.time)),
        _ => Err(DC_STATUS_INVALID_ARGUMENT),
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
    let mut views: [(&[DcVec3], f64); crate::cell::MAX_ROBOTS] =
        [(&[], 0.0); crate::cell::MAX_ROBOTS];
    for (j, (view, path)) in views.iter_mut().zip(paths).enumerate() {
        if path.n_points == 0 {
            continue;
        }
        if path.points.is_null() || path.n_points > DC_MAX_PATH_POINTS {
            report.unreachable_mask = 1 << j;
            c.reset_protective();
            return if path.points.is_null() {
                DC_STATUS_NULL_POINTER
            } else {
                DC_STATUS_INVALID_ARGUMENT
            };
        }
        // SAFETY: non-null, and the caller guarantees `n_points` readable elements.
        *view =
            (unsafe { std::slice::from_raw_parts(path.points, path.n_points) }, path.tolerance_mm);
    }
    query(c, &views[..n_paths], report)
}

/// The common part of the protective entry points: [`tick_entry`] with a protective report.
///
/// # Safety
/// As [`tick_entry`].
unsafe fn protective_entry(
    handle: *mut DcCollider,
    tcps_mcs: *const DcVec3,
    n_tcps: usize,
    out_verdict: *mut DcVerdict,
    out_report: *mut DcProtectiveReport,
    query: impl FnOnce(&mut Collider, &[DcVec3], &mut DcProtectiveReport) -> DcStatus,
) -> DcStatus {
    let stop = DcProtectiveReport::STOP;
    // SAFETY: the caller's guarantees are passed on.
    unsafe { tick_entry(handle, (tcps_mcs, n_tcps), (out_verdict, out_report), stop, query) }
}
