//! The handle behind every stateful export and the guard every export goes through: a
//! `DcCollider` is reached only under its busy flag ([`live`]), a panic never crosses the
//! boundary ([`boundary`]) and poisons the handle it happened on.

use super::collider::Collider;
use super::types::*;
use std::cell::UnsafeCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
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

impl DcCollider {
    /// A handle for `inner`, not busy, not poisoned.
    pub(super) fn new(inner: Collider) -> DcCollider {
        DcCollider {
            inner: UnsafeCell::new(inner),
            poisoned: AtomicBool::new(false),
            busy: AtomicBool::new(false),
        }
    }
}

/// Runs `f` on the collider of a live handle: `DC_STATUS_NULL_POINTER` for NULL,
/// `DC_STATUS_BUSY` while another call uses the handle (nothing is done),
/// `DC_STATUS_PANIC` for a poisoned handle or a panic in `f` (which poisons it).
///
/// # Safety
/// `handle` must be NULL or a live handle from `dc_init*`.
pub(super) unsafe fn live<R>(
    handle: *const DcCollider,
    f: impl FnOnce(&mut Collider) -> R,
) -> Result<R, DcStatus> {
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
pub(super) fn flatten(result: Result<DcStatus, DcStatus>) -> DcStatus {
    result.unwrap_or_else(|status| status)
}

/// Runs `f`, turning a panic into `DC_STATUS_PANIC`.
pub(super) fn boundary(f: impl FnOnce() -> DcStatus) -> DcStatus {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(DC_STATUS_PANIC)
}

/// A C report with a verdict, written out on every call.
pub(super) trait Verdicted: Copy {
    /// Sets the report's verdict.
    fn set_verdict(&mut self, verdict: DcVerdict);
    /// The report's verdict.
    fn verdict(&self) -> DcVerdict;
}

impl Verdicted for DcQueryReport {
    fn set_verdict(&mut self, verdict: DcVerdict) {
        self.verdict = verdict;
    }
    fn verdict(&self) -> DcVerdict {
        self.verdict
    }
}

impl Verdicted for DcProtectiveReport {
    fn set_verdict(&mut self, verdict: DcVerdict) {
        self.verdict = verdict;
    }
    fn verdict(&self) -> DcVerdict {
        self.verdict
    }
}

/// Writes `report` and its verdict to the outputs that are not NULL, the verdict STOP unless
/// `status` is OK (fail closed); returns `status`.
///
/// # Safety
/// `out_verdict` and `out_report` must be NULL or writable.
pub(super) unsafe fn write_out<R: Verdicted>(
    status: DcStatus,
    mut report: R,
    out_verdict: *mut DcVerdict,
    out_report: *mut R,
) -> DcStatus {
    if status != DC_STATUS_OK {
        report.set_verdict(DC_VERDICT_STOP);
    }
    if !out_verdict.is_null() {
        // SAFETY: non-null; the caller guarantees it is writable.
        unsafe { *out_verdict = report.verdict() };
    }
    if !out_report.is_null() {
        // SAFETY: non-null; the caller guarantees it is writable.
        unsafe { *out_report = report };
    }
    status
}

/// The `len` elements at `ptr`, or `DC_STATUS_NULL_POINTER` when it is NULL.
///
/// # Safety
/// `ptr` must be NULL or point to `len` readable elements that outlive `'a`.
pub(super) unsafe fn read_slice<'a, T>(ptr: *const T, len: usize) -> Result<&'a [T], DcStatus> {
    if ptr.is_null() {
        return Err(DC_STATUS_NULL_POINTER);
    }
    // SAFETY: non-null, and the caller guarantees `len` readable elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// The body of a per-tick export: checks the pointers, runs `query` on the handle's collider
/// with the TCPs (through [`live`]: a panic poisons the handle), and writes `report` (which
/// starts as `stop`) and its verdict on every call, STOP on every status but OK.
///
/// # Safety
/// `handle` must be NULL or live; `tcps_mcs` NULL or `n_tcps` readable elements; the outputs
/// NULL or writable.
pub(super) unsafe fn tick_entry<R: Verdicted>(
    handle: *const DcCollider,
    (tcps_mcs, n_tcps): (*const DcVec3, usize),
    (out_verdict, out_report): (*mut DcVerdict, *mut R),
    stop: R,
    query: impl FnOnce(&mut Collider, &[DcVec3], &mut R) -> DcStatus,
) -> DcStatus {
    let mut report = stop;
    let status = boundary(|| {
        if out_verdict.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: the caller guarantees `n_tcps` readable elements when not NULL.
        let tcps = match unsafe { read_slice(tcps_mcs, n_tcps) } {
            Ok(tcps) => tcps,
            Err(status) => return status,
        };
        // SAFETY: the caller guarantees `handle` is NULL or live.
        flatten(unsafe { live(handle, |c| query(c, tcps, &mut report)) })
    });
    // SAFETY: the caller guarantees the out pointers are NULL or writable.
    unsafe { write_out(status, report, out_verdict, out_report) }
}
