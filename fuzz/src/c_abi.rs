//! Target `c_abi`: a sequence of up to [`MAX_OPS`] calls of the exported `extern "C"`
//! functions with arbitrary arguments, within each function's `# Safety` contract (pointers
//! are NULL or valid; lengths are true).
//!
//! # Encoding
//! Each call is an opcode byte (`byte % OPS`, see [`Op`]) followed by its arguments, read
//! with [`Input`]; bytes past the end read as zeros. Up to [`MAX_HANDLES`] handles are live;
//! a handle argument is a byte picking one of them or NULL. [`seeds`] writes example inputs.
//!
//! # Properties
//! - No call returns `DC_STATUS_PANIC` (a panic caught at the boundary is a bug).
//! - Fail closed: `*out_verdict` and `out_report.verdict` are written on every call, read
//!   FREE only with `DC_STATUS_OK`, STOP on every error, and agree with each other.
//! - Statuses name the cause: NULL pointers, a wrong TCP count, NaN (the mask names exactly
//!   the non-finite TCPs), unreachable TCPs (the mask names exactly the TCPs that
//!   `dc_delta3_inverse_kinematics` rejects), in exact and table mode alike.
//! - `dc_init*` give exactly the status the Rust API implies (`Cell::new`,
//!   `TableChecker::new`), leave `*out_handle` NULL on failure, and `dc_last_init_error`
//!   holds a message exactly when they failed; pair results agree with the report.
//! - Kinematics: outputs are finite; for the thesis robot FK(IK(p)) = p.
//! - The timed protective query (`dc_protective_query_timed`): never BUSY from one thread; a
//!   wrong `struct_size` or an unknown clock is `DC_STATUS_INVALID_ARGUMENT`; against the last
//!   timed call on the same handle (when no other call used the handle since), the timing
//!   rules' status: a change of clock `DC_STATUS_CLOCK_CHANGED`, an earlier time
//!   `DC_STATUS_TIME_BACKWARDS`, the same time with other TCPs `DC_STATUS_TIME_REPEATED`, a
//!   cycle more than `DC_MAX_INTERVAL_TICKS` later `DC_STATUS_TIME_JUMP`; the same clock, time
//!   and TCPs (bit for bit) again answer that call's status, verdict and report unchanged.
//! - The coordination (`dc_coordinate`): a status it documents, naming the cause in the
//!   order it checks (NULL handle, request or `out_overrides`; a short `struct_size`; NULL
//!   programmes; the robot count; a programme's point count, then its NULL points; then each
//!   programme's ticks, non-finite numbers, progress or `override_now` out of range). Fail
//!   closed: on every error each override written is 0.0 and each robot stands, held by no
//!   one, wherever the request holds `n_robots`; with `DC_STATUS_OK` every override is in
//!   [0, 1]; nothing is written past `n_robots`. `dc_set_coordination_clearance` takes
//!   exactly the finite clearances above 0, `dc_set_coordination_right_of_way` exactly its
//!   two rules.

mod coordinate;
mod init;

use super::input::{Encoder, Input};
use delta_collide::ffi::*;
use delta_collide::table::TableKind;
use std::cell::RefCell;
use std::ffi::CStr;

/// Calls per input at most.
pub const MAX_OPS: usize = 64;
/// Live handles at most; a further init destroys the oldest.
pub const MAX_HANDLES: usize = 4;
/// Number of opcodes.
const OPS: u8 = 15;

/// The opcodes.
#[derive(Clone, Copy, Debug)]
#[repr(u8)]
pub enum Op {
    /// `dc_init`: n (byte % 41), method (byte), NULL flags (byte: config, robots), edits
    /// (byte % 16) of (robot byte, field byte, value) on thesis robots 450 mm apart, NULL out
    /// flag (byte); then the capacity (byte) for `dc_last_init_error`, as after every init.
    Init = 0,
    /// `dc_query`: handle, count (byte: < 192 the robot count, else byte % 40), points, NULL
    /// flags (byte: tcps, out_verdict, out_report); then `dc_table_clearance_bound` of the
    /// same TCPs.
    Query = 1,
    /// `dc_pair_results`: handle, capacity (byte * 2), NULL flags (byte: out, out_len).
    PairResults = 2,
    /// `dc_robot_count`, `dc_pair_count`, `dc_mode`, `dc_table_fallbacks`,
    /// `dc_table_confirmations`, then `dc_set_table_confirmation`, `dc_set_speed_limits`,
    /// `dc_set_limit_tests` and `dc_set_path_work`: handle.
    Counts = 3,
    /// `dc_delta3_inverse_kinematics`: edits (byte % 4) of the thesis geometry, point, NULL
    /// flags (byte: geometry, out_theta).
    Inverse = 4,
    /// `dc_delta3_forward_kinematics`: edits, three numbers, NULL flags (geometry, theta, out).
    Forward = 5,
    /// `dc_status_str` of a `u32`, and `dc_version`.
    StatusStr = 6,
    /// `dc_destroy`: handle (NULL allowed).
    Destroy = 7,
    /// `dc_init_from_cell_file`: path kind (byte % 6: NULL, not UTF-8, missing, a directory,
    /// empty, `cells/t1.toml`), NULL out flag (byte).
    InitFromFile = 8,
    /// `dc_init_with_table`: a config as for `Init` with n = byte % 4, then the table: source
    /// (byte % 7: six T1 seed tables, one per variant, or u16 % 512 bytes of the input), up to 7 edits
    /// (byte % 8 of u16 offset, value), reseal flag (fingerprint of the config's cell,
    /// checksum), NULL table and NULL out flags.
    InitWithTable = 9,
    /// `dc_init_from_files`: cell and table path kinds (as `InitFromFile`; the real table is
    /// a T1 seed), NULL out flag.
    InitFromFiles = 10,
    /// `dc_protective_query` or, with a flag, `dc_protective_query_with_paths`: handle, count
    /// and points as for `Query`; with paths, per robot a point count (byte % 40; above
    /// `DC_MAX_PATH_POINTS` is refused), its points and a tolerance, and a NULL flag for the
    /// paths array; NULL flags (tcps, out_verdict, out_report); then
    /// `dc_table_protective_lookups`. `dc_set_stop_model` is not called: its motor-angle
    /// table takes about 0.3 s to build (so the default model's stops, too long for any
    /// clearance level, never let a lookup answer).
    Protective = 11,
    /// `dc_protective_query_timed`: handle; a flag to send the TCPs of the handle's last timed
    /// call again (when it has one), else count and points as for `Query`; paths as for
    /// `Protective`; `struct_size` (byte % 8: 0-3 right, then 0, 8 short, 8 long, `usize::MAX`);
    /// clock (byte: below 200 its parity, `DC_CLOCK_CYCLE` or `DC_CLOCK_NANOS`; then the byte
    /// itself, 255 `u32::MAX`); time (byte % 4, the last three only after a timed call on the
    /// handle: a `u64`; that call's time; that time plus a byte % 8 cycles, or plus a `u16` *
    /// 128 ns on `DC_CLOCK_NANOS`; that time minus 1 + byte % 8); NULL flags (byte: request,
    /// tcps, out_verdict, out_report).
    ProtectiveTimed = 12,
    /// `dc_coordinate`: handle; a flag to send the handle's last answered programmes again
    /// one tick on (each progress advanced by its override, which is the next
    /// `override_now`), else a count (byte: < 192 the robot count, else byte % 40) and per
    /// robot a programme (`coordinate::Programme::read`: stride, first tick, point count,
    /// points, progress, override_now); `struct_size` (byte % 8: 0-2 right, then 0, 4, 8, a
    /// byte short, 16 long); NULL flags (byte: request, programmes, out_overrides, out_robots,
    /// the first programme's points, the last one's).
    Coordinate = 13,
    /// `dc_coordination_reset` or `dc_set_coordination_clearance`: handle, what (byte % 3:
    /// reset, a clearance `f64`, a clearance of byte mm); then `dc_coordination_horizon` and
    /// `dc_coordination_request_default`.
    CoordinationSettings = 14,
}

/// A live handle, the robots it was made from, its timed protective calls and its last
/// answered coordination (which the next one may follow on from).
struct Live {
    handle: *mut DcCollider,
    robots: Vec<DcRobotConfig>,
    timed: RefCell<Timed>,
    coordinated: RefCell<Option<coordinate::Coordinated>>,
}

impl Live {
    fn new(handle: *mut DcCollider, robots: Vec<DcRobotConfig>) -> Live {
        Live { handle, robots, timed: RefCell::default(), coordinated: RefCell::default() }
    }
}

/// The timed protective calls on one handle.
#[derive(Default)]
struct Timed {
    /// The clock and time of the last timed call that reached the checker: the next ones are
    /// aimed near it.
    time: Option<(DcClock, u64)>,
    /// That call, while it is the handle's last call: the timing rules compare with it.
    last: Option<LastTimed>,
}

/// A timed call that reached the checker, and its answer.
#[derive(Clone)]
struct LastTimed {
    clock: DcClock,
    time: u64,
    tcps: Vec<DcVec3>,
    status: DcStatus,
    verdict: DcVerdict,
    /// `None` when the call's `out_report` was NULL.
    report: Option<DcProtectiveReport>,
}

/// The target: never panics on any input.
pub fn c_abi(data: &[u8]) {
    let mut input = Input::new(data);
    let mut live: Vec<Live> = Vec::new();
    for _ in 0..MAX_OPS {
        if input.is_empty() {
            break;
        }
        match input.byte() % OPS {
            0 => init::init(&mut input, &mut live),
            1 => query(&mut input, &live),
            2 => pair_results(&mut input, &live),
            3 => counts(&mut input, &live),
            4 => inverse(&mut input),
            5 => forward(&mut input),
            6 => status_str(&mut input),
            7 => destroy(&mut input, &mut live),
            8 => init::init_from_file(&mut input, &mut live),
            9 => init::init_with_table(&mut input, &mut live),
            10 => init::init_from_files(&mut input, &mut live),
            11 => protective(&mut input, &live),
            12 => protective_timed(&mut input, &live),
            13 => coordinate::coordinate(&mut input, &live),
            _ => coordinate::settings(&mut input, &live),
        }
    }
    for l in live {
        // SAFETY: live handle from dc_init*, destroyed once.
        unsafe { dc_destroy(l.handle) };
    }
}

/// A non-NULL pointer no handle can have: `dc_init*` must overwrite it.
fn sentinel() -> *mut DcCollider {
    std::ptr::NonNull::dangling().as_ptr()
}

/// A handle argument; the handle's last call is then no longer a timed one.
fn pick<'a>(input: &mut Input, live: &'a [Live]) -> Option<&'a Live> {
    let l = pick_keeping(input, live);
    if let Some(l) = l {
        l.timed.borrow_mut().last = None;
    }
    l
}

/// A handle argument, keeping what its last timed call was.
fn pick_keeping<'a>(input: &mut Input, live: &'a [Live]) -> Option<&'a Live> {
    live.get(usize::from(input.byte()) % (live.len() + 1))
}

fn handle_of(l: Option<&Live>) -> *mut DcCollider {
    l.map_or(std::ptr::null_mut(), |l| l.handle)
}

fn keep(live: &mut Vec<Live>, l: Live) {
    if live.len() == MAX_HANDLES {
        // SAFETY: live handle, destroyed once (removed from the list).
        unsafe { dc_destroy(live.remove(0).handle) };
    }
    live.push(l);
}

fn null_if<T>(null: bool, p: *mut T) -> *mut T {
    if null {
        std::ptr::null_mut()
    } else {
        p
    }
}

fn query(input: &mut Input, live: &[Live]) {
    let l = pick(input, live);
    let n = l.map_or(0, |l| l.robots.len());
    let count = match input.byte() {
        b @ 192.. => usize::from(b % 40),
        _ => n,
    };
    let tcps: Vec<DcVec3> = (0..count)
        .map(|_| {
            let [x, y, z] = input.point();
            DcVec3 { x, y, z }
        })
        .collect();
    let nulls = input.byte();
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
    let tcps_ptr = if nulls & 1 != 0 { std::ptr::null() } else { tcps.as_ptr() };
    // SAFETY: the handle is NULL or live; `tcps` holds `count` points; outputs are NULL or
    // writable.
    let status = unsafe {
        dc_query(
            handle_of(l),
            tcps_ptr,
            count,
            null_if(nulls & 2 != 0, &mut verdict),
            null_if(nulls & 4 != 0, &mut report),
        )
    };
    assert_ne!(status, DC_STATUS_PANIC, "dc_query panicked");
    clearance_bound(
        l,
        tcps_ptr,
        count,
        (status == DC_STATUS_OK && nulls & 2 == 0).then_some(verdict),
    );
    if nulls & 2 == 0 {
        assert!(verdict <= DC_VERDICT_COLLISION, "verdict {verdict}");
        assert_eq!(
            status == DC_STATUS_OK,
            verdict != DC_VERDICT_STOP,
            "status {status} with verdict {verdict}"
        );
    }
    if nulls & 4 == 0 {
        assert!(
            nulls & 2 != 0 || report.verdict == verdict,
            "report {report:?}, verdict {verdict}"
        );
        assert_eq!(
            status == DC_STATUS_OK,
            report.verdict != DC_VERDICT_STOP,
            "status {status}, report {report:?}"
        );
    }
    let Some(l) = l.filter(|_| nulls & 3 == 0) else {
        return assert_eq!(status, DC_STATUS_NULL_POINTER);
    };
    if count != n {
        return assert_eq!(status, DC_STATUS_WRONG_ROBOT_COUNT);
    }
    let not_finite = |p: &DcVec3| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite());
    let mask_of =
        |bad: &dyn Fn(usize) -> bool| (0..n).fold(0u32, |m, j| m | u32::from(bad(j)) << j);
    let non_finite = mask_of(&|j| not_finite(&tcps[j]));
    let unreachable = mask_of(&|j| !reachable(&l.robots[j].geometry, tcps[j]));
    let expected = match (non_finite, unreachable) {
        (0, 0) => DC_STATUS_OK,
        (0, _) => DC_STATUS_UNREACHABLE,
        _ => DC_STATUS_NON_FINITE,
    };
    assert_eq!(status, expected, "TCPs {tcps:?}");
    if nulls & 4 != 0 {
        return;
    }
    match status {
        DC_STATUS_NON_FINITE => assert_eq!(report.unreachable_mask, non_finite),
        DC_STATUS_UNREACHABLE => assert_eq!(report.unreachable_mask, unreachable),
        _ => check_ok_report(l, &report),
    }
}

/// `dc_table_clearance_bound` on the TCPs of a `dc_query` (no input read): never a panic,
/// `-inf` unless OK and always in exact mode, and a bound only where that query answered FREE
/// (`verdict`: the query's, when it was OK and written).
fn clearance_bound(
    l: Option<&Live>,
    tcps: *const DcVec3,
    count: usize,
    verdict: Option<DcVerdict>,
) {
    let mut mm = f64::NAN;
    // SAFETY: the handle is NULL or live; `tcps` is NULL or holds `count` points; `mm` is
    // writable.
    let status = unsafe { dc_table_clearance_bound(handle_of(l), tcps, count, &mut mm) };
    assert_ne!(status, DC_STATUS_PANIC, "dc_table_clearance_bound panicked");
    assert!(
        !mm.is_nan() && (status == DC_STATUS_OK || mm == f64::NEG_INFINITY),
        "status {status}, {mm} mm"
    );
    // SAFETY: NULL or live.
    if unsafe { dc_mode(handle_of(l)) } != DC_MODE_TABLE {
        assert_eq!(mm, f64::NEG_INFINITY);
    }
    if let (true, Some(v)) = (mm > f64::NEG_INFINITY, verdict) {
        assert_eq!(v, DC_VERDICT_FREE, "a clearance bound of {mm} mm where the query says {v}");
    }
}

fn protective(input: &mut Input, live: &[Live]) {
    let l = pick(input, live);
    let n = l.map_or(0, |l| l.robots.len());
    let count = match input.byte() {
        b @ 192.. => usize::from(b % 40),
        _ => n,
    };
    let point = |input: &mut Input| {
        let [x, y, z] = input.point();
        DcVec3 { x, y, z }
    };
    let tcps: Vec<DcVec3> = (0..count).map(|_| point(input)).collect();
    let with_paths = input.flag();
    let points: Vec<Vec<DcVec3>> = if with_paths {
        (0..count).map(|_| (0..input.byte() % 40).map(|_| point(input)).collect()).collect()
    } else {
        Vec::new()
    };
    let paths: Vec<DcStopPath> = points
        .iter()
        .map(|p| DcStopPath { points: p.as_ptr(), n_points: p.len(), tolerance_mm: input.f64() })
        .collect();
    let null_paths = with_paths && input.flag();
    let nulls = input.byte();
    let mut verdict = DC_VERDICT_COLLISION;
    // SAFETY: all-zero is a valid `DcProtectiveReport` (numbers and integers only).
    let mut report: DcProtectiveReport = unsafe { std::mem::zeroed() };
    report.verdict = 7;
    let tcps_ptr = if nulls & 1 != 0 { std::ptr::null() } else { tcps.as_ptr() };
    let (out_verdict, out_report) =
        (null_if(nulls & 2 != 0, &mut verdict), null_if(nulls & 4 != 0, &mut report));
    // SAFETY: NULL or live.
    let lookups_before = unsafe { dc_table_protective_lookups(handle_of(l)) };
    // SAFETY: the handle is NULL or live; `tcps` holds `count` points, `paths` one path per
    // TCP whose points it holds; outputs are NULL or writable.
    let status = unsafe {
        if with_paths {
            let paths_ptr = if null_paths { std::ptr::null() } else { paths.as_ptr() };
            dc_protective_query_with_paths(
                handle_of(l),
                tcps_ptr,
                count,
                paths_ptr,
                count,
                out_verdict,
                out_report,
            )
        } else {
            dc_protective_query(handle_of(l), tcps_ptr, count, out_verdict, out_report)
        }
    };
    assert_ne!(status, DC_STATUS_PANIC, "the protective query panicked");
    // A query answered by the clearance table alone is one more lookup, and only a FREE one.
    // SAFETY: NULL or live.
    let (lookups, mode) =
        unsafe { (dc_table_protective_lookups(handle_of(l)), dc_mode(handle_of(l))) };
    let looked_up = lookups.checked_sub(lookups_before).expect("the lookup count never falls");
    assert!(
        looked_up <= 1 && (mode == DC_MODE_TABLE || lookups == 0),
        "{looked_up} lookups in one query, mode {mode}"
    );
    assert!(
        looked_up == 0 || status == DC_STATUS_OK,
        "a lookup answered a query with status {status}"
    );
    assert!(
        looked_up == 0 || nulls & 2 != 0 || verdict == DC_VERDICT_FREE,
        "a lookup answered verdict {verdict}"
    );
    if nulls & 2 == 0 {
        assert!(
            [DC_VERDICT_FREE, DC_VERDICT_WARN, DC_VERDICT_STOP].contains(&verdict),
            "verdict {verdict}"
        );
        assert!(
            status == DC_STATUS_OK || verdict == DC_VERDICT_STOP,
            "status {status} with verdict {verdict}"
        );
    }
    if nulls & 4 == 0 {
        assert!(
            nulls & 2 != 0 || report.verdict == verdict,
            "report {}, verdict {verdict}",
            report.verdict
        );
        assert!(
            status == DC_STATUS_OK || report.verdict == DC_VERDICT_STOP,
            "status {status}, report verdict {}",
            report.verdict
        );
    }
    if l.is_none() || nulls & 3 != 0 || null_paths {
        return assert_eq!(status, DC_STATUS_NULL_POINTER);
    }
    if count != n {
        return assert_eq!(status, DC_STATUS_WRONG_ROBOT_COUNT);
    }
    // A path too long for the call is refused before the TCPs are read.
    if paths.iter().any(|p| p.n_points > DC_MAX_PATH_POINTS) {
        return assert_eq!(
            status, DC_STATUS_INVALID_ARGUMENT,
            "a path of more than {DC_MAX_PATH_POINTS} points"
        );
    }
    let tcp_finite = tcps.iter().all(|p| p.x.is_finite() && p.y.is_finite() && p.z.is_finite());
    assert!(
        tcp_finite || status == DC_STATUS_NON_FINITE,
        "non-finite TCPs {tcps:?}: status {status}"
    );
}

/// `Op::ProtectiveTimed` (encoding in [`Op`], properties in the module doc).
fn protective_timed(input: &mut Input, live: &[Live]) {
    let l = pick_keeping(input, live);
    let n = l.map_or(0, |l| l.robots.len());
    let (aim, last) = l.map_or((None, None), |l| {
        let t = l.timed.borrow();
        (t.time, t.last.clone())
    });
    let point = |input: &mut Input| {
        let [x, y, z] = input.point();
        DcVec3 { x, y, z }
    };
    let tcps: Vec<DcVec3> = match (input.flag(), &last) {
        (true, Some(last)) => last.tcps.clone(),
        _ => {
            let count = match input.byte() {
                b @ 192.. => usize::from(b % 40),
                _ => n,
            };
            (0..count).map(|_| point(input)).collect()
        }
    };
    let count = tcps.len();
    let with_paths = input.flag();
    let points: Vec<Vec<DcVec3>> = if with_paths {
        (0..count).map(|_| (0..input.byte() % 40).map(|_| point(input)).collect()).collect()
    } else {
        Vec::new()
    };
    let paths: Vec<DcStopPath> = points
        .iter()
        .map(|p| DcStopPath { points: p.as_ptr(), n_points: p.len(), tolerance_mm: input.f64() })
        .collect();
    let null_paths = with_paths && input.flag();
    let size = std::mem::size_of::<DcProtectiveRequest>();
    let struct_size = match input.byte() % 8 {
        0..=3 => size,
        4 => 0,
        5 => size - 8,
        6 => size + 8,
        _ => usize::MAX,
    };
    let clock = match input.byte() {
        b @ 0..=199 => DcClock::from(b % 2),
        255 => DcClock::MAX,
        b => DcClock::from(b),
    };
    let time = match (input.byte() % 4, aim) {
        (1, Some((_, t))) => t,
        (2, Some((DC_CLOCK_NANOS, t))) => {
            t.wrapping_add(u64::from(u16::from_le_bytes(input.bytes())) * 128)
        }
        (2, Some((_, t))) => t.wrapping_add(u64::from(input.byte() % 8)),
        (3, Some((_, t))) => t.wrapping_sub(1 + u64::from(input.byte() % 8)),
        _ => input.u64(),
    };
    let nulls = input.byte();
    let request = DcProtectiveRequest {
        struct_size,
        clock,
        time,
        tcps_mcs: if nulls & 2 != 0 { std::ptr::null() } else { tcps.as_ptr() },
        n_tcps: count,
        paths: if null_paths { std::ptr::null() } else { paths.as_ptr() },
        n_paths: if with_paths { count } else { 0 },
    };
    let request_ptr: *const DcProtectiveRequest =
        if nulls & 1 != 0 { std::ptr::null() } else { &request };
    let mut verdict = DC_VERDICT_COLLISION;
    // SAFETY: all-zero is a valid `DcProtectiveReport` (numbers and integers only).
    let mut report: DcProtectiveReport = unsafe { std::mem::zeroed() };
    report.verdict = 7;
    let (out_verdict, out_report) =
        (null_if(nulls & 4 != 0, &mut verdict), null_if(nulls & 8 != 0, &mut report));
    // SAFETY: the handle is NULL or live; the request is NULL or readable, its TCPs hold
    // `count` points and its paths one path per TCP whose points they hold (or NULL);
    // outputs are NULL or writable.
    let status =
        unsafe { dc_protective_query_timed(handle_of(l), request_ptr, out_verdict, out_report) };
    assert_ne!(status, DC_STATUS_PANIC, "the timed protective query panicked");
    assert_ne!(status, DC_STATUS_BUSY, "a handle busy with no other thread");
    if nulls & 4 == 0 {
        assert!(
            [DC_VERDICT_FREE, DC_VERDICT_WARN, DC_VERDICT_STOP].contains(&verdict),
            "verdict {verdict}"
        );
        assert!(
            status == DC_STATUS_OK || verdict == DC_VERDICT_STOP,
            "status {status} with verdict {verdict}"
        );
    }
    if nulls & 8 == 0 {
        assert!(
            nulls & 4 != 0 || report.verdict == verdict,
            "report {}, verdict {verdict}",
            report.verdict
        );
        assert!(
            status == DC_STATUS_OK || report.verdict == DC_VERDICT_STOP,
            "status {status}, report {report:?}"
        );
    }
    // Which checks refuse the call before the checker sees it: from here on the call is the
    // handle's last, so the rules compare with it only if it reaches the checker.
    let Some(l) = l else { return assert_eq!(status, DC_STATUS_NULL_POINTER) };
    let mut timed = l.timed.borrow_mut();
    timed.last = None;
    if nulls & 7 != 0 {
        return assert_eq!(status, DC_STATUS_NULL_POINTER, "a NULL request, TCPs or verdict");
    }
    if struct_size != size || clock > DC_CLOCK_NANOS {
        return assert_eq!(
            status, DC_STATUS_INVALID_ARGUMENT,
            "struct_size {struct_size} (not {size}), clock {clock}"
        );
    }
    // No paths (`n_paths` 0) are not read at all, NULL or not.
    if null_paths && count > 0 {
        return assert_eq!(status, DC_STATUS_NULL_POINTER, "NULL paths");
    }
    if count != n {
        return assert_eq!(status, DC_STATUS_WRONG_ROBOT_COUNT);
    }
    if paths.iter().any(|p| p.n_points > DC_MAX_PATH_POINTS) {
        return assert_eq!(
            status, DC_STATUS_INVALID_ARGUMENT,
            "a path of more than {DC_MAX_PATH_POINTS} points"
        );
    }
    let timing = [
        DC_STATUS_TIME_REPEATED,
        DC_STATUS_TIME_BACKWARDS,
        DC_STATUS_TIME_JUMP,
        DC_STATUS_TIME_EARLY,
        DC_STATUS_CLOCK_CHANGED,
    ];
    let allowed = [
        DC_STATUS_OK,
        DC_STATUS_NON_FINITE,
        DC_STATUS_UNREACHABLE,
        DC_STATUS_IMPLAUSIBLE_MOTION,
        DC_STATUS_INVALID_ARGUMENT,
    ];
    assert!(allowed.contains(&status) || timing.contains(&status), "status {status}");
    let tcp_finite = tcps.iter().all(|p| p.x.is_finite() && p.y.is_finite() && p.z.is_finite());
    assert!(
        tcp_finite || status == DC_STATUS_NON_FINITE || timing.contains(&status),
        "TCPs {tcps:?}: status {status}"
    );
    let answer = if nulls & 8 == 0 { Some(report) } else { None };
    if let Some(last) = last {
        let same_tcps = tcps.iter().zip(&last.tcps).all(|(a, b)| bits(a) == bits(b));
        let expected = if clock != last.clock {
            Some(DC_STATUS_CLOCK_CHANGED)
        } else if time < last.time {
            Some(DC_STATUS_TIME_BACKWARDS)
        } else if time == last.time && !same_tcps {
            Some(DC_STATUS_TIME_REPEATED)
        } else if time == last.time {
            Some(last.status)
        } else if clock == DC_CLOCK_CYCLE && time - last.time > DC_MAX_INTERVAL_TICKS {
            Some(DC_STATUS_TIME_JUMP)
        } else {
            None
        };
        if let Some(expected) = expected {
            assert_eq!(
                status, expected,
                "clock {clock} time {time} after clock {} time {}",
                last.clock, last.time
            );
        }
        if time == last.time && clock == last.clock && same_tcps {
            assert_eq!(verdict, last.verdict, "a repeated call's verdict");
            if let (Some(now), Some(then)) = (answer, last.report) {
                assert_eq!(format!("{now:?}"), format!("{then:?}"), "a repeated call's report");
            }
        }
    }
    timed.time = Some((clock, time));
    timed.last = Some(LastTimed { clock, time, tcps, status, verdict, report: answer });
}

/// The bits of a point: equal exactly when the library's repeat test finds them equal.
fn bits(p: &DcVec3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// Whether `dc_delta3_inverse_kinematics` accepts `tcp` for `geometry`.
fn reachable(geometry: &DcDelta3, tcp: DcVec3) -> bool {
    let mut theta = [0.0; 3];
    // SAFETY: valid geometry and 3 writable doubles.
    unsafe { dc_delta3_inverse_kinematics(geometry, tcp, theta.as_mut_ptr()) == DC_STATUS_OK }
}

/// An OK report agrees with `dc_pair_results`.
fn check_ok_report(l: &Live, report: &DcQueryReport) {
    let n = l.robots.len() as u32;
    assert_eq!(report.unreachable_mask, 0);
    assert_eq!(report.verdict == DC_VERDICT_COLLISION, report.colliding_pairs > 0, "{report:?}");
    // SAFETY: live handle.
    let (pairs, status) = results(l.handle, unsafe { dc_pair_count(l.handle) });
    assert_eq!(status, DC_STATUS_OK);
    let colliding: Vec<&DcPairResult> = pairs.iter().filter(|p| p.collides == 1).collect();
    assert_eq!(colliding.len(), report.colliding_pairs as usize, "{report:?} vs {pairs:?}");
    if let Some(first) = colliding.first() {
        let (a, b) = (report.first_robot_a, report.first_robot_b);
        assert!(
            (a, b) == (first.robot_a, first.robot_b) && a < b && b < n,
            "{report:?} vs {first:?}"
        );
        assert!(
            (report.first_box_a, report.first_box_b) == (first.box_a, first.box_b),
            "{report:?} vs {first:?}"
        );
    }
}

/// Calls `dc_pair_results` with room for `capacity` results.
fn results(h: *mut DcCollider, capacity: usize) -> (Vec<DcPairResult>, DcStatus) {
    let blank = DcPairResult { robot_a: 7, robot_b: 7, collides: 7, box_a: 7, box_b: 7 };
    let mut out = vec![blank; capacity];
    let mut len = usize::MAX;
    // SAFETY: `h` is NULL or live; `out` holds `capacity` elements; `len` is writable.
    let status = unsafe { dc_pair_results(h, out.as_mut_ptr(), capacity, &mut len) };
    assert_ne!(status, DC_STATUS_PANIC, "dc_pair_results panicked");
    if status == DC_STATUS_OK {
        out.truncate(len);
    }
    (out, status)
}

fn pair_results(input: &mut Input, live: &[Live]) {
    let l = pick(input, live);
    let capacity = usize::from(input.byte()) * 2;
    let nulls = input.byte();
    let h = handle_of(l);
    if nulls & 3 != 0 {
        let mut out = vec![
            DcPairResult { robot_a: 0, robot_b: 0, collides: 0, box_a: 0, box_b: 0 };
            capacity
        ];
        let mut len = usize::MAX;
        // SAFETY: `h` is NULL or live; `out` NULL or `capacity` elements; `len` NULL or writable.
        let status = unsafe {
            dc_pair_results(
                h,
                null_if(nulls & 1 != 0, out.as_mut_ptr()),
                capacity,
                null_if(nulls & 2 != 0, &mut len),
            )
        };
        return assert_eq!(status, DC_STATUS_NULL_POINTER);
    }
    let (pairs, status) = results(h, capacity);
    let Some(l) = l else { return assert_eq!(status, DC_STATUS_NULL_POINTER) };
    // SAFETY: live handle.
    let count = unsafe { dc_pair_count(l.handle) };
    if capacity < count {
        return assert_eq!(status, DC_STATUS_INVALID_ARGUMENT);
    }
    assert!(
        status == DC_STATUS_OK && pairs.len() == count,
        "status {status}, {} pairs of {count}",
        pairs.len()
    );
    let n = l.robots.len() as u32;
    for p in pairs {
        assert!(p.robot_a < p.robot_b && p.robot_b < n && p.collides <= 1, "{p:?}");
        // SAFETY: live handle.
        let exact = unsafe { dc_mode(l.handle) } == DC_MODE_EXACT;
        let no_boxes = p.box_a == DC_BOX_NONE && p.box_b == DC_BOX_NONE;
        // Table mode names boxes only when the exact check answered the collision.
        assert_eq!(p.box_a == DC_BOX_NONE, p.box_b == DC_BOX_NONE, "{p:?}");
        assert!(
            if exact { (p.collides == 0) == no_boxes } else { p.collides == 1 || no_boxes },
            "{p:?}"
        );
    }
}

fn counts(input: &mut Input, live: &[Live]) {
    let l = pick(input, live);
    // SAFETY: NULL or live.
    let (robots, pairs, mode, fallbacks) = unsafe {
        let h = handle_of(l);
        (dc_robot_count(h), dc_pair_count(h), dc_mode(h), dc_table_fallbacks(h))
    };
    let n = l.map_or(0, |l| l.robots.len());
    assert!(
        robots == n && pairs <= n * n.saturating_sub(1) / 2,
        "{robots} robots, {pairs} pairs, n = {n}"
    );
    let expected_mode =
        if l.is_none() { DC_MODE_NONE } else { mode.clamp(DC_MODE_EXACT, DC_MODE_TABLE) };
    assert_eq!(mode, expected_mode, "dc_mode");
    assert!(mode == DC_MODE_TABLE || fallbacks == 0, "{fallbacks} table fallbacks in mode {mode}");
    // Then switches the table confirmation by the counts seen so far (no input read), with a
    // value that is no DcConfirmation one time in three.
    // SAFETY: NULL or live.
    let confirmations = unsafe { dc_table_confirmations(handle_of(l)) };
    assert!(
        mode == DC_MODE_TABLE || confirmations == 0,
        "{confirmations} confirmations in mode {mode}"
    );
    let value = ((fallbacks + confirmations) % 3) as DcConfirmation;
    // SAFETY: NULL or live.
    let status = unsafe { dc_set_table_confirmation(handle_of(l), value) };
    let expected = match (l, value) {
        (None, _) => DC_STATUS_NULL_POINTER,
        (_, DC_CONFIRMATION_EXACT | DC_CONFIRMATION_NONE) => DC_STATUS_OK,
        _ => DC_STATUS_INVALID_ARGUMENT,
    };
    assert_eq!(status, expected, "dc_set_table_confirmation({value})");
    // And the speed limits by the same counts, with a value that is neither 0 nor 1 one time
    // in three.
    let on = ((fallbacks + confirmations + robots as u64) % 3) as u32;
    // SAFETY: NULL or live.
    let status = unsafe { dc_set_speed_limits(handle_of(l), on) };
    let expected = match (l, on) {
        (None, _) => DC_STATUS_NULL_POINTER,
        (_, 0 | 1) => DC_STATUS_OK,
        _ => DC_STATUS_INVALID_ARGUMENT,
    };
    assert_eq!(status, expected, "dc_set_speed_limits({on})");
    // And the cap on limit tests: none, one, a few, or the full search.
    let tests = [0, 1, 3, u32::MAX][((confirmations + robots as u64) % 4) as usize];
    // SAFETY: NULL or live.
    let status = unsafe { dc_set_limit_tests(handle_of(l), tests) };
    let expected = if l.is_none() { DC_STATUS_NULL_POINTER } else { DC_STATUS_OK };
    assert_eq!(status, expected, "dc_set_limit_tests({tests})");
    // And the cap on the work along the stop paths, likewise.
    let units = [0, 1, 40, u32::MAX][((fallbacks + robots as u64) % 4) as usize];
    // SAFETY: NULL or live.
    let status = unsafe { dc_set_path_work(handle_of(l), units) };
    assert_eq!(status, expected, "dc_set_path_work({units})");
}

/// The thesis geometry with up to three edits; also says whether it is unedited.
fn geometry(input: &mut Input) -> (DcDelta3, bool) {
    let mut r = dc_robot_config_thesis();
    let edits = input.byte() % 4;
    for _ in 0..edits {
        let field = input.byte() % 6;
        init::edit(&mut r, field, input);
    }
    (r.geometry, edits == 0)
}

fn inverse(input: &mut Input) {
    let (g, thesis) = geometry(input);
    let [x, y, z] = input.point();
    let nulls = input.byte();
    let mut theta = [f64::NAN; 3];
    let g_ptr: *const DcDelta3 = if nulls & 1 != 0 { std::ptr::null() } else { &g };
    // SAFETY: geometry NULL or valid; `theta` NULL or 3 writable doubles.
    let status = unsafe {
        dc_delta3_inverse_kinematics(
            g_ptr,
            DcVec3 { x, y, z },
            null_if(nulls & 2 != 0, theta.as_mut_ptr()),
        )
    };
    assert_ne!(status, DC_STATUS_PANIC, "dc_delta3_inverse_kinematics panicked");
    if nulls & 3 != 0 {
        return assert_eq!(status, DC_STATUS_NULL_POINTER);
    }
    if status != DC_STATUS_OK {
        return;
    }
    assert!(theta.iter().all(|t| t.is_finite()), "IK of {:?} gave {theta:?}", (x, y, z));
    if thesis {
        let mut back = DcVec3 { x: f64::NAN, y: 0.0, z: 0.0 };
        // SAFETY: valid geometry, 3 readable doubles, writable output.
        let status = unsafe { dc_delta3_forward_kinematics(&g, theta.as_ptr(), &mut back) };
        assert_eq!(status, DC_STATUS_OK);
        let err = (back.x - x).hypot(back.y - y).hypot(back.z - z);
        assert!(err < 1e-6, "FK(IK({:?})) = {back:?}, {err} mm off", (x, y, z));
    }
}

fn forward(input: &mut Input) {
    let (g, _) = geometry(input);
    let theta = [input.f64(), input.f64(), input.f64()];
    let nulls = input.byte();
    let mut tcp = DcVec3 { x: f64::NAN, y: f64::NAN, z: f64::NAN };
    let g_ptr: *const DcDelta3 = if nulls & 1 != 0 { std::ptr::null() } else { &g };
    let t_ptr = if nulls & 2 != 0 { std::ptr::null() } else { theta.as_ptr() };
    // SAFETY: each pointer NULL or valid for its use.
    let status =
        unsafe { dc_delta3_forward_kinematics(g_ptr, t_ptr, null_if(nulls & 4 != 0, &mut tcp)) };
    assert_ne!(status, DC_STATUS_PANIC, "dc_delta3_forward_kinematics panicked");
    if nulls & 7 != 0 {
        return assert_eq!(status, DC_STATUS_NULL_POINTER);
    }
    if status == DC_STATUS_OK {
        assert!(
            tcp.x.is_finite() && tcp.y.is_finite() && tcp.z.is_finite(),
            "FK({theta:?}) = {tcp:?} with {g:?}"
        );
    }
}

fn status_str(input: &mut Input) {
    let status = if input.flag() { u32::from(input.byte()) } else { input.u32() };
    // SAFETY: `dc_status_str` returns a static NUL-terminated string.
    let text = unsafe { CStr::from_ptr(dc_status_str(status)) };
    assert!(!text.to_bytes().is_empty() && text.to_str().is_ok(), "status {status}: {text:?}");
    if status <= DC_STATUS_PROGRESS_OUT_OF_RANGE {
        assert_ne!(text.to_bytes(), b"unknown status", "status {status} has no description");
    }
    // SAFETY: `dc_version` returns a static NUL-terminated string.
    assert!(!unsafe { CStr::from_ptr(dc_version()) }.to_bytes().is_empty());
}

fn destroy(input: &mut Input, live: &mut Vec<Live>) {
    let i = usize::from(input.byte()) % (live.len() + 1);
    let h = if i < live.len() { live.remove(i).handle } else { std::ptr::null_mut() };
    // SAFETY: NULL or a live handle, now removed from the list.
    unsafe { dc_destroy(h) };
}

/// Seed inputs, one per situation, written with the encoding above.
pub fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let home = [0.0, 0.0, -450.0];
    // Init: n, method, NULL flags, edit count, edits, NULL out flag, init error capacity.
    let init = |e: &mut Encoder, n: u8, method: u8, nulls: u8| {
        e.byte(Op::Init as u8).byte(n).byte(method).byte(nulls).byte(0).byte(0).byte(64);
    };
    let query2 = |e: &mut Encoder, a: [f64; 3], b: [f64; 3]| {
        e.byte(Op::Query as u8).byte(0).byte(0).point(a).point(b).byte(0);
    };
    let mut out = Vec::new();
    let mut e = Encoder::default();
    init(&mut e, 2, 1, 0);
    query2(&mut e, home, home);
    query2(&mut e, [225.0, 0.0, -450.0], [-225.0, 0.0, -450.0]);
    query2(&mut e, [f64::NAN, 0.0, -450.0], home);
    query2(&mut e, [0.0, 0.0, 10.0], home);
    e.byte(Op::PairResults as u8).byte(0).byte(1).byte(0);
    e.byte(Op::Counts as u8).byte(0).byte(Op::Destroy as u8).byte(0);
    out.push(("two_robots_query_then_destroy", e.bytes));
    let mut e = Encoder::default();
    init(&mut e, 32, 0, 0);
    e.byte(Op::Query as u8).byte(0).byte(0);
    (0..32).for_each(|_| {
        e.point(home);
    });
    e.byte(0).byte(Op::PairResults as u8).byte(0).byte(255).byte(0);
    out.push(("thirty_two_robots", e.bytes));
    let mut e = Encoder::default();
    e.byte(Op::Init as u8).byte(2).byte(0).byte(0).byte(3);
    e.byte(1).byte(8).f64(5.0); // robot 1: margin 5
    e.byte(1).byte(25).byte(1); // robot 1: upper links on
    e.byte(0).byte(9).f64(f64::NAN); // robot 0: upper half-height NaN (unused: upper links off)
    e.byte(0).byte(255);
    query2(&mut e, [200.0, 0.0, -400.0], [-200.0, 0.0, -400.0]);
    out.push(("edited_config", e.bytes));
    let mut e = Encoder::default();
    init(&mut e, 2, 1, 0);
    // Protective: handle 0, two TCPs, no paths, no NULLs; twice (speeds from the first).
    for _ in 0..2 {
        e.byte(Op::Protective as u8)
            .byte(0)
            .byte(0)
            .point([-150.0, 0.0, -450.0])
            .point([150.0, 0.0, -450.0]);
        e.byte(0).byte(0);
    }
    // With paths: robot 0 along x for 50 mm (tolerance 1), robot 1 none.
    e.byte(Op::Protective as u8)
        .byte(0)
        .byte(0)
        .point([-150.0, 0.0, -450.0])
        .point([150.0, 0.0, -450.0])
        .byte(1);
    e.byte(2).point([-150.0, 0.0, -450.0]).point([-100.0, 0.0, -450.0]).byte(0);
    e.f64(1.0).f64(0.0).byte(0).byte(0);
    out.push(("protective", e.bytes));
    // The timed protective query on handle 0: TCPs (None: the last call's again), no paths,
    // then struct_size, clock and time bytes, and the NULL flags.
    let timed = |e: &mut Encoder,
                 tcps: Option<[[f64; 3]; 2]>,
                 size: u8,
                 clock: u8,
                 time: &[u8],
                 nulls: u8| {
        e.byte(Op::ProtectiveTimed as u8).byte(0);
        match tcps {
            None => e.byte(1),
            Some([a, b]) => e.byte(0).byte(0).point(a).point(b),
        };
        e.byte(0).byte(size).byte(clock);
        e.bytes.extend_from_slice(time);
        e.byte(nulls);
    };
    // The time bytes: a u64; the last call's time; cycles or 128 ns steps on; cycles back - 1.
    let time = |tag: u8, rest: &[u8]| [&[tag][..], rest].concat();
    let raw = |t: u64| time(0, &t.to_le_bytes());
    let last = || time(1, &[]);
    let ahead = |k: u8| time(2, &[k]);
    let ahead_ns = |steps: u16| time(2, &steps.to_le_bytes());
    let back = |k: u8| time(3, &[k]);
    let (a, b) = ([-150.0, 0.0, -450.0], [150.0, 0.0, -450.0]);
    let (a2, b2) = ([-149.5, 0.0, -450.0], [149.5, 0.0, -450.0]);
    let mut e = Encoder::default();
    init(&mut e, 2, 1, 0);
    timed(&mut e, Some([a, b]), 0, 0, &raw(1000), 0);
    // The same cycle and TCPs (the last answer again), the next cycle, the same one with
    // other TCPs (REPEATED), 7 cycles on (JUMP), 2 back (BACKWARDS), timestamps (CLOCK_CHANGED),
    // 1.000064 ms on, 12.8 us on (EARLY) and that again with no report.
    timed(&mut e, None, 0, 0, &last(), 0);
    timed(&mut e, Some([a2, b2]), 0, 0, &ahead(1), 0);
    timed(&mut e, Some([a, b]), 0, 0, &last(), 0);
    timed(&mut e, None, 0, 0, &ahead(7), 0);
    timed(&mut e, None, 0, 0, &back(1), 0);
    timed(&mut e, None, 0, 1, &raw(5_000_000_000), 0);
    timed(&mut e, None, 0, 1, &ahead_ns(7813), 0);
    timed(&mut e, None, 0, 1, &ahead_ns(100), 0);
    timed(&mut e, None, 0, 1, &last(), 8);
    // Refused: struct_size 8 short, clock 200, a NULL request.
    timed(&mut e, None, 5, 0, &raw(1010), 0);
    timed(&mut e, Some([a, b]), 0, 200, &raw(1010), 0);
    timed(&mut e, Some([a, b]), 0, 0, &raw(7), 1);
    // With paths: robot 0 along x for 50 mm (tolerance 1), robot 1 none; 1.000064 ms on.
    e.byte(Op::ProtectiveTimed as u8).byte(0).byte(0).byte(0).point(a).point(b).byte(1);
    e.byte(2).point(a).point([-100.0, 0.0, -450.0]).byte(0);
    e.f64(1.0).f64(0.0).byte(0).byte(0).byte(1);
    e.bytes.extend_from_slice(&ahead_ns(7813));
    e.byte(0);
    out.push(("protective_timed", e.bytes));
    let mut e = Encoder::default();
    e.byte(Op::Init as u8)
        .byte(2)
        .byte(0)
        .byte(0)
        .byte(1)
        .byte(0)
        .byte(0)
        .f64(-100.0)
        .byte(0)
        .byte(8);
    init(&mut e, 0, 0, 0);
    init(&mut e, 33, 0, 0);
    e.byte(Op::Init as u8).byte(2).byte(3).u32(7).byte(0).byte(0).byte(0).byte(0);
    init(&mut e, 2, 0, 3);
    e.byte(Op::Init as u8).byte(2).byte(0).byte(0).byte(0).byte(1).byte(1);
    query2(&mut e, home, home);
    out.push(("refused_inits", e.bytes));
    let mut e = Encoder::default();
    e.byte(Op::Inverse as u8).byte(0).point([30.0, -40.0, -420.0]).byte(0);
    e.byte(Op::Inverse as u8).byte(1).byte(2).f64(1e300).point(home).byte(0);
    e.byte(Op::Forward as u8).byte(0).f64(0.3).f64(0.2).f64(0.1).byte(0);
    e.byte(Op::Forward as u8).byte(0).f64(f64::INFINITY).f64(0.0).f64(0.0).byte(4);
    out.push(("kinematics", e.bytes));
    let mut e = Encoder::default();
    for s in 0..=DC_STATUS_PROGRESS_OUT_OF_RANGE as u8 {
        e.byte(Op::StatusStr as u8).byte(1).byte(s);
    }
    e.byte(Op::StatusStr as u8).byte(0).u32(u32::MAX);
    out.push(("status_strings", e.bytes));
    let mut e = Encoder::default();
    for kind in 0..6 {
        e.byte(Op::InitFromFile as u8).byte(kind).byte(0).byte(40);
    }
    query2(&mut e, home, home);
    for (cell, table) in [(5, 5), (5, 2), (2, 5), (0, 5), (5, 1)] {
        e.byte(Op::InitFromFiles as u8).byte(cell).byte(table).byte(0).byte(40);
    }
    e.byte(Op::Counts as u8).byte(0);
    out.push(("init_from_files", e.bytes));
    // InitWithTable: config (n, method, NULL flags, edit count), source, edit count, reseal,
    // NULL table, NULL out, init error capacity.
    let tables = [
        ("table_6d", TableKind::D6),
        ("table_5d", TableKind::D5),
        ("table_4d", TableKind::D4yy),
        ("table_shared", TableKind::Shared),
        ("table_shared_sub", TableKind::SharedSub),
        ("table_clearance", TableKind::Clearance),
    ];
    for (name, kind) in tables {
        let source = init::table_source(kind).expect("a seed table of every kind listed");
        let mut e = Encoder::default();
        e.byte(Op::InitWithTable as u8).byte(2).byte(1).byte(0).byte(0);
        e.byte(source).byte(0).byte(0).byte(0).byte(0).byte(100);
        query2(&mut e, home, home);
        query2(&mut e, [120.0, 0.0, -420.0], [-120.0, 0.0, -420.0]);
        query2(&mut e, [0.0, 0.0, -900.0], home);
        e.byte(Op::PairResults as u8).byte(0).byte(1).byte(0).byte(Op::Counts as u8).byte(0);
        // The protective verdict in table mode, twice (speeds from the first).
        for _ in 0..2 {
            e.byte(Op::Protective as u8)
                .byte(0)
                .byte(0)
                .point([-150.0, 0.0, -450.0])
                .point([150.0, 0.0, -450.0]);
            e.byte(0).byte(0);
        }
        out.push((name, e.bytes));
    }
    let mut e = Encoder::default();
    e.byte(Op::InitWithTable as u8)
        .byte(3)
        .byte(1)
        .byte(0)
        .byte(0)
        .byte(0)
        .byte(0)
        .byte(0)
        .byte(0)
        .byte(0)
        .byte(9);
    // Robot 1 with a margin of 1 mm, the table resealed with that cell's fingerprint: loads.
    e.byte(Op::InitWithTable as u8).byte(2).byte(1).byte(0).byte(1).byte(1).byte(8).f64(1.0);
    e.byte(0).byte(0).byte(1).byte(0).byte(0).byte(200);
    // One byte of the table changed (offset 48, r), not resealed: the checksum fails.
    e.byte(Op::InitWithTable as u8)
        .byte(2)
        .byte(1)
        .byte(0)
        .byte(0)
        .byte(0)
        .byte(1)
        .u16(48)
        .byte(0x10);
    e.byte(0).byte(0).byte(0).byte(200);
    // A table of 16 bytes from the input: truncated.
    e.byte(Op::InitWithTable as u8).byte(2).byte(1).byte(0).byte(0).byte(5).u16(16);
    e.bytes.extend_from_slice(b"DCTABLE\0\x04\x03\x02\x01\x01\0\0\0");
    e.byte(0).byte(0).byte(0).byte(0).byte(200);
    out.push(("refused_tables", e.bytes));
    // Coordinate: handle 0, not the last programmes again, the robot count; per programme its
    // stride, first tick, point count and progress and override_now bytes (`Programme::read`);
    // then struct_size and NULL flags.
    let programme = |e: &mut Encoder,
                     (stride, first): (&[u8], &[u8]),
                     n: u8,
                     points: &[[f64; 3]],
                     (progress, override_now): (&[u8], &[u8])| {
        e.bytes.extend_from_slice(stride);
        e.bytes.extend_from_slice(first);
        e.byte(n);
        points.iter().for_each(|&p| {
            e.point(p);
        });
        e.bytes.extend_from_slice(progress);
        e.bytes.extend_from_slice(override_now);
    };
    // Each robot from its far side (x = -150 in its MCS, toward the other) to the midpoint of
    // the bases and back, 40 points 4 ticks apart (156 ticks): they meet in the middle.
    let towards = |toward: f64| -> Vec<[f64; 3]> {
        (0..40)
            .map(|k| {
                let s = 1.0 - (f64::from(k) / 19.5 - 1.0).abs();
                [toward * (-150.0 + 375.0 * s), 0.0, -450.0]
            })
            .collect()
    };
    let (a, b) = (towards(1.0), towards(-1.0));
    let stride4: (&[u8], &[u8]) = (&[2, 3], &[0]);
    let standing: (&[u8], &[u8]) = (&[4], &[3]);
    let call = |e: &mut Encoder, handle: u8, count: u8, size: u8, nulls: u8, programmes: &[u8]| {
        e.byte(Op::Coordinate as u8).byte(handle).byte(0).byte(count);
        e.bytes.extend_from_slice(programmes);
        e.byte(size).byte(nulls);
    };
    let again = |e: &mut Encoder, size: u8, nulls: u8| {
        e.byte(Op::Coordinate as u8).byte(0).byte(1).byte(size).byte(nulls);
    };
    let bytes_of = |f: &dyn Fn(&mut Encoder)| {
        let mut e = Encoder::default();
        f(&mut e);
        e.bytes
    };
    let line = bytes_of(&|e| {
        programme(e, stride4, 40, &a, standing);
        programme(e, stride4, 40, &b, standing);
    });
    // Within MAX_OPS calls: both standing at their first points, then 50 ticks following the
    // overrides (robot 1 yields), some with no out_robots.
    let mut e = Encoder::default();
    init(&mut e, 2, 1, 0);
    call(&mut e, 0, 0, 0, 0, &line);
    for k in 0..50 {
        again(&mut e, 0, if k % 7 == 3 { 8 } else { 0 });
    }
    // Refused, the outputs written 0.0 or left alone: struct_size 8 (n_robots readable) and 0,
    // a NULL request, programmes and out_overrides; the first and the last points NULL; a NULL
    // handle; one programme for two robots.
    for (size, nulls) in [(5, 0), (3, 0), (0, 1), (0, 2), (0, 4), (0, 16), (0, 32 | 8)] {
        again(&mut e, size, nulls);
    }
    call(&mut e, 1, 0, 0, 0, &line);
    call(&mut e, 0, 201, 0, 0, &line[..line.len() / 2]);
    out.push(("coordination_line", e.bytes));
    // Robot 1's programme broken, robot 0's as before: no points, one above the maximum, the
    // maximum (48 points then standing: answered), stride 0, a first tick that is no multiple of
    // the stride, a last tick past u64::MAX, a NaN point, f64::MAX, an infinite progress, a
    // progress before the first point and after the last, override_now 1.5.
    let first_a = bytes_of(&|e| programme(e, stride4, 40, &a, standing));
    let b48 = [b.as_slice(), &b[..8]].concat();
    let mut broken: Vec<Vec<u8>> = vec![
        bytes_of(&|e| programme(e, stride4, 0, &[], standing)),
        bytes_of(&|e| programme(e, stride4, 255, &b48, standing)),
        bytes_of(&|e| programme(e, stride4, 254, &b48, standing)),
        bytes_of(&|e| programme(e, (&[0], &[0]), 40, &b, standing)),
        bytes_of(&|e| programme(e, (&[2, 3], &[2, 6, 0, 0, 0, 0, 0, 0, 0]), 40, &b, standing)),
        bytes_of(&|e| programme(e, (&[2, 3], &[3]), 2, &b[..2], standing)),
    ];
    let mut nan = b.clone();
    nan[7][2] = f64::NAN;
    let mut huge = b.clone();
    huge[0] = [f64::MAX, -f64::MAX, -450.0];
    huge[1] = [-f64::MAX, f64::MAX, -450.0];
    broken.push(bytes_of(&|e| programme(e, stride4, 40, &nan, standing)));
    broken.push(bytes_of(&|e| programme(e, stride4, 40, &huge, standing)));
    broken.push(bytes_of(&|e| programme(e, stride4, 40, &b, (&[0, 0, 5], &[3]))));
    broken.push(bytes_of(&|e| programme(e, stride4, 40, &b, (&[6, 0], &[3]))));
    broken.push(bytes_of(&|e| programme(e, stride4, 40, &b, (&[7, 0], &[3]))));
    let too_fast = bytes_of(&|e| {
        e.byte(0).f64(1.5);
    });
    broken.push(bytes_of(&|e| programme(e, stride4, 40, &b, (&[4], &too_fast))));
    let mut e = Encoder::default();
    init(&mut e, 2, 1, 0);
    for robot_1 in &broken {
        call(&mut e, 0, 0, 0, 0, &[first_a.as_slice(), robot_1].concat());
    }
    // The settings: a reset, clearances of 0 and NaN (refused), of 100 mm and then of 40 again,
    // each followed by the line from the start.
    for what in [&[0][..], &[2, 0], &[1, 0, 4], &[2, 100], &[2, 40]] {
        e.byte(Op::CoordinationSettings as u8).byte(0);
        e.bytes.extend_from_slice(what);
        call(&mut e, 0, 0, 0, 0, &line);
        for _ in 0..5 {
            again(&mut e, 0, 0);
        }
    }
    e.byte(Op::CoordinationSettings as u8).byte(1).byte(1).byte(0).byte(13);
    out.push(("coordination_programmes", e.bytes));
    out
}
