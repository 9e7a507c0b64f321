//! A handle's tick statistics (`dc_tick_stats`): per kind of call, how many, the time of the
//! last and of the largest and their mean, the work of the last and of the largest, and how
//! many ran out of their work budget, as a controller's task monitor counts its overruns
//! (Omron's `_MaxExecTime` and `_ExceedCount`). Kept behind the handle by the calls
//! themselves (`collider.rs`, `coordination.rs`): two reads of the monotonic clock a call.

use super::handle::{boundary, flatten, live, DcCollider};
use super::types::*;
use std::mem::size_of;
use std::time::Duration;

/// One kind of call's figures so far.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CallStats {
    calls: u64,
    last_ns: u64,
    largest_ns: u64,
    total_ns: u64,
    last_work: u64,
    largest_work: u64,
    budget_spent: u64,
}

impl CallStats {
    /// Counts one call that took `took` and did `work` units of work, its budget `spent`.
    pub(crate) fn record(&mut self, took: Duration, work: u64, spent: bool) {
        let ns = u64::try_from(took.as_nanos()).unwrap_or(u64::MAX);
        self.calls = self.calls.saturating_add(1);
        self.last_ns = ns;
        self.largest_ns = self.largest_ns.max(ns);
        self.total_ns = self.total_ns.saturating_add(ns);
        self.last_work = work;
        self.largest_work = self.largest_work.max(work);
        self.budget_spent += u64::from(spent);
    }

    /// The C form: the mean from the total.
    fn to_c(self) -> DcCallStats {
        DcCallStats {
            calls: self.calls,
            last_ns: self.last_ns,
            largest_ns: self.largest_ns,
            mean_ns: self.total_ns.checked_div(self.calls).unwrap_or(0),
            last_work: self.last_work,
            largest_work: self.largest_work,
            budget_spent: self.budget_spent,
        }
    }
}

/// Every kind of call's figures (`DcTickStats`).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TickStats {
    pub(crate) query: CallStats,
    pub(crate) protective: CallStats,
    pub(crate) coordinate: CallStats,
}

/// Writes the handle's tick statistics to `*out`, whose `struct_size` the caller sets to
/// `sizeof(DcTickStats)` first (a later, larger version is filled as far as this one knows;
/// `struct_size` is then this version's). Counted since the handle was made or since
/// `dc_tick_stats_reset`: `query` for `dc_query`, `protective` for every protective query,
/// `coordinate` for `dc_coordinate`; a call that finds the handle busy is not counted. Times
/// are inside the library, from the monotonic clock. A protective call's work is its speed
/// limits' proof tests (`dc_set_limit_tests` caps them per tick) plus the units of its proof
/// along the stop paths (`dc_set_path_work` caps them), each about one stop's sweeps or one
/// swept-box proof; `budget_spent` counts the calls that used either whole cap (their limits
/// then the largest speeds proved so far, their verdict at best the one without paths). The
/// coordination's work is its diagram cells; `dc_query` reports no work (its box tests are fixed by the cell). Cheap
/// enough for every tick: it copies about 200 bytes and allocates nothing.
///
/// Statuses: `DC_STATUS_NULL_POINTER` (handle or out NULL), `DC_STATUS_INVALID_ARGUMENT`
/// (`out->struct_size` smaller than this header's `sizeof(DcTickStats)`; nothing written),
/// `DC_STATUS_BUSY`, `DC_STATUS_PANIC` (a poisoned handle).
///
/// # Safety
/// `handle` must be NULL or live; `out` must be NULL or point to a writable `DcTickStats`
/// whose `struct_size` is readable.
#[no_mangle]
pub unsafe extern "C" fn dc_tick_stats(handle: *mut DcCollider, out: *mut DcTickStats) -> DcStatus {
    boundary(|| {
        if handle.is_null() || out.is_null() {
            return DC_STATUS_NULL_POINTER;
        }
        // SAFETY: non-null; the caller guarantees `struct_size` readable.
        let size = unsafe { std::ptr::addr_of!((*out).struct_size).read() } as usize;
        if size < size_of::<DcTickStats>() {
            return DC_STATUS_INVALID_ARGUMENT;
        }
        // SAFETY: the caller guarantees `handle` is NULL or live.
        let stats = unsafe { live(handle, |c| c.stats) };
        flatten(stats.map(|s| {
            let c_form = DcTickStats {
                struct_size: size_of::<DcTickStats>() as u32,
                query: s.query.to_c(),
                protective: s.protective.to_c(),
                coordinate: s.coordinate.to_c(),
            };
            // SAFETY: non-null, and `struct_size` says it holds this version's struct.
            unsafe { out.write(c_form) };
            DC_STATUS_OK
        }))
    })
}

/// Zeroes the handle's tick statistics (`dc_tick_stats`), e.g. after start-up, so that the
/// largest times are those of the line running. Allocates nothing. Statuses:
/// `DC_STATUS_NULL_POINTER`, `DC_STATUS_BUSY`, `DC_STATUS_PANIC`.
///
/// # Safety
/// `handle` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn dc_tick_stats_reset(handle: *mut DcCollider) -> DcStatus {
    boundary(|| {
        // SAFETY: the caller guarantees `handle` is NULL or live.
        let reset = unsafe { live(handle, |c| c.stats = TickStats::default()) };
        reset.map_or_else(|e| e, |()| DC_STATUS_OK)
    })
}
