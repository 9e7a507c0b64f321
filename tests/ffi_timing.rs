//! The timed protective query through the C ABI from two threads at once
//! (`dc_protective_query_timed`, `src/ffi/mod.rs`): a handle in use by one call refuses a
//! second one with `DC_STATUS_BUSY` and STOP, and does nothing else. Two threads hammer one
//! handle with their own cycle counters over the same motion, so besides BUSY their calls
//! interleave into timing faults (a cycle sent again, an older one, a gap); every status must
//! be one of those or OK, every one but OK must read STOP, and afterwards the handle answers a
//! fresh sequence of calls as a new handle does (a call that was refused left no damage and no
//! poison behind).

use delta_collide::ffi::*;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Barrier;

/// Calls per thread at least, of which [`MIN_ANSWERED`] not refused (a refused call returns at
/// once, so a thread can spend thousands while the other computes one); then each goes on
/// until BUSY was seen, up to [`MAX_CALLS`].
const MIN_CALLS: u64 = 2_000;
const MIN_ANSWERED: u64 = 300;
/// Calls per thread at most: with two cores and calls of tens of microseconds BUSY comes within
/// the first few hundred; a machine that runs the threads one after the other may never show it.
const MAX_CALLS: u64 = 1_000_000;

/// The statuses the threads may see: OK, BUSY, and the timing faults of interleaved cycles.
const ALLOWED: [DcStatus; 7] = [
    DC_STATUS_OK,
    DC_STATUS_BUSY,
    DC_STATUS_TIME_REPEATED,
    DC_STATUS_TIME_BACKWARDS,
    DC_STATUS_TIME_JUMP,
    DC_STATUS_TIME_EARLY,
    DC_STATUS_CLOCK_CHANGED,
];

/// The handle shared by the threads: the timed query may be called on it from any thread (its
/// busy flag refuses a concurrent call); nothing else is.
#[derive(Clone, Copy)]
struct Shared(*mut DcCollider);
// SAFETY: the threads only call `dc_protective_query_timed`, whose contract allows concurrent
// calls on one live handle; the handle outlives the threads (joined before it is destroyed).
unsafe impl Send for Shared {}
// SAFETY: as above.
unsafe impl Sync for Shared {}

/// T1's robots, 450 mm apart, with the default stopping model.
fn t1_handle() -> *mut DcCollider {
    let a = dc_robot_config_thesis();
    let b = DcRobotConfig {
        translation: DcVec3 { x: 450.0, y: 0.0, z: 0.0 },
        ..dc_robot_config_thesis()
    };
    let robots = [a, b];
    let config = DcCellConfig { robots: robots.as_ptr(), n_robots: 2, method: DC_METHOD_SAT_CACHE };
    let mut h = std::ptr::null_mut();
    // SAFETY: valid config and out pointer.
    assert_eq!(unsafe { dc_init(&config, &mut h) }, DC_STATUS_OK);
    assert!(!h.is_null());
    h
}

/// Both TCPs at `cycle` (1 ms each): circles of 20 mm at 0.5 rad/s, never near each other (a
/// slow motion, so that any two cycles the threads interleave are a plausible displacement).
fn tcps(cycle: u64) -> [DcVec3; 2] {
    let phase = cycle as f64 * 5e-4;
    let (s, c) = phase.sin_cos();
    [
        DcVec3 { x: -120.0 + 20.0 * c, y: 20.0 * s, z: -450.0 },
        DcVec3 { x: 120.0 - 20.0 * c, y: 20.0 * s, z: -450.0 },
    ]
}

/// One timed call at `cycle` with the TCPs of `at`; the outputs start as FREE so that a call
/// which forgot to write them would show.
fn timed(h: *mut DcCollider, cycle: u64, at: u64) -> (DcStatus, DcVerdict, DcProtectiveReport) {
    let points = tcps(at);
    let request = DcProtectiveRequest {
        time: cycle,
        tcps_mcs: points.as_ptr(),
        n_tcps: 2,
        ..dc_protective_request_default()
    };
    let mut verdict = DC_VERDICT_FREE;
    // SAFETY: all-zero is a valid report (numbers and integers only).
    let mut report: DcProtectiveReport = unsafe { std::mem::zeroed() };
    report.verdict = DC_VERDICT_FREE;
    // SAFETY: a live handle, a readable request whose TCPs live for the call, writable outputs.
    let status = unsafe { dc_protective_query_timed(h, &request, &mut verdict, &mut report) };
    (status, verdict, report)
}

/// What one thread saw.
#[derive(Debug, Default)]
struct Seen {
    calls: u64,
    by_status: [u64; 32],
    not_allowed: Vec<DcStatus>,
    open: u64,
    /// OK answers whose report is not a whole one: the verdict, two robots, finite distances.
    torn: u64,
}

#[test]
fn two_threads_on_one_handle_get_busy_and_stop_and_leave_it_working() {
    let h = t1_handle();
    let shared = Shared(h);
    let busy_seen = AtomicBool::new(false);
    let highest = AtomicU64::new(0);
    let start = Barrier::new(2);
    let seen: Vec<Seen> = std::thread::scope(|scope| {
        let threads: Vec<_> = (0..2u64)
            .map(|t| {
                let (busy_seen, highest, start) = (&busy_seen, &highest, &start);
                scope.spawn(move || {
                    let h = shared;
                    let mut seen = Seen::default();
                    start.wait();
                    // Thread 1 runs 3 cycles behind thread 0: their calls interleave into
                    // repeats, older cycles and gaps.
                    let mut cycle = 1_000 + 3 * (1 - t);
                    let more = |s: &Seen| {
                        let answered = s.calls - s.by_status[DC_STATUS_BUSY as usize];
                        s.calls < MIN_CALLS
                            || answered < MIN_ANSWERED
                            || !busy_seen.load(Ordering::Relaxed)
                    };
                    while more(&seen) && seen.calls < MAX_CALLS {
                        let (status, verdict, report) = timed(h.0, cycle, cycle);
                        seen.calls += 1;
                        seen.by_status[(status as usize).min(31)] += 1;
                        if !ALLOWED.contains(&status) {
                            seen.not_allowed.push(status);
                        }
                        if status != DC_STATUS_OK
                            && (verdict != DC_VERDICT_STOP || report.verdict != DC_VERDICT_STOP)
                        {
                            seen.open += 1;
                        }
                        let whole = report.verdict == verdict
                            && [DC_VERDICT_FREE, DC_VERDICT_WARN, DC_VERDICT_STOP]
                                .contains(&verdict)
                            && report.n_robots == 2
                            && report.clearance_mm.is_finite()
                            && report.protective_mm[..2].iter().all(|s| s.is_finite() && *s > 0.0);
                        if status == DC_STATUS_OK && !whole {
                            seen.torn += 1;
                        }
                        if status == DC_STATUS_BUSY {
                            busy_seen.store(true, Ordering::Relaxed);
                            // A task refused retries in its next cycle, not in a tight loop.
                            std::thread::yield_now();
                        }
                        highest.fetch_max(cycle, Ordering::Relaxed);
                        cycle += 1;
                    }
                    seen
                })
            })
            .collect();
        threads.into_iter().map(|t| t.join().expect("a thread panicked")).collect()
    });
    for (t, s) in seen.iter().enumerate() {
        println!(
            "thread {t}: {} calls, OK {}, BUSY {}, REPEATED {}, BACKWARDS {}, JUMP {}, EARLY {}, CLOCK_CHANGED {}",
            s.calls,
            s.by_status[DC_STATUS_OK as usize],
            s.by_status[DC_STATUS_BUSY as usize],
            s.by_status[DC_STATUS_TIME_REPEATED as usize],
            s.by_status[DC_STATUS_TIME_BACKWARDS as usize],
            s.by_status[DC_STATUS_TIME_JUMP as usize],
            s.by_status[DC_STATUS_TIME_EARLY as usize],
            s.by_status[DC_STATUS_CLOCK_CHANGED as usize],
        );
        assert!(s.not_allowed.is_empty(), "thread {t}: statuses {:?}", s.not_allowed);
        assert_eq!(s.open, 0, "thread {t}: calls that failed without STOP");
        assert_eq!(s.torn, 0, "thread {t}: OK answers with a report not whole");
        let answered = s.calls - s.by_status[DC_STATUS_BUSY as usize];
        assert!(answered >= MIN_ANSWERED, "thread {t}: {answered} calls answered of {}", s.calls);
    }
    let busy: u64 = seen.iter().map(|s| s.by_status[DC_STATUS_BUSY as usize]).sum();
    let ok: u64 = seen.iter().map(|s| s.by_status[DC_STATUS_OK as usize]).sum();
    assert!(ok > 0, "no call was answered OK: {seen:?}");
    // Two threads on two cores overlap within a few hundred calls; on one core they may take
    // turns for good, and then there is nothing to refuse.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    assert!(
        busy > 0 || cores < 2,
        "no BUSY in {} calls on {cores} cores",
        seen[0].calls + seen[1].calls
    );

    // The handle afterwards: a cycle well after every one the threads sent is a gap (JUMP), and
    // from the next cycle on it answers as a new handle given the same calls after its first.
    let fresh = t1_handle();
    let next = highest.load(Ordering::Relaxed) + 100;
    let (status, verdict, _) = timed(h, next, next);
    assert_eq!(
        (status, verdict),
        (DC_STATUS_TIME_JUMP, DC_VERDICT_STOP),
        "the first call after the threads"
    );
    for k in 1..=200 {
        let (s, v, r) = timed(h, next + k, k);
        let (s_new, v_new, r_new) = timed(fresh, 5_000 + k, k);
        assert_eq!((s, v), (s_new, v_new), "cycle {k} after the threads");
        assert_eq!(s, DC_STATUS_OK, "cycle {k} after the threads");
        // The first answered call has no previous TCP on either handle: full speed alike.
        assert_eq!(r.protective_mm[..2], r_new.protective_mm[..2], "cycle {k} after the threads");
    }
    // The same cycle again with the same TCPs: the last answer, on the handle the threads used.
    let last = timed(h, next + 200, 200);
    let again = timed(h, next + 200, 200);
    assert_eq!((last.0, last.1), (again.0, again.1));
    assert_eq!(
        format!("{:?}", last.2),
        format!("{:?}", again.2),
        "a repeat answers the same report"
    );
    // SAFETY: live handles, destroyed once; the threads are joined.
    unsafe {
        dc_destroy(h);
        dc_destroy(fresh);
    }
}
