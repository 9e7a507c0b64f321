//! A counting global allocator: how many allocations the extension made, in all and while a
//! call's work ran with the GIL released (the library's own part of a call), so that the
//! tests can show that the `out=` forms allocate nothing.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// The system allocator, counting.
pub struct Counting;

static TOTAL: AtomicU64 = AtomicU64::new(0);
static IN_WORK: AtomicU64 = AtomicU64::new(0);

thread_local! {
    /// Whether this thread runs a call's work now (const-initialised: reading it allocates
    /// nothing and it has no destructor).
    static WORKING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    TOTAL.fetch_add(1, Ordering::Relaxed);
    if WORKING.try_with(Cell::get).unwrap_or(false) {
        IN_WORK.fetch_add(1, Ordering::Relaxed);
    }
}

// SAFETY: every method forwards to `System` with the caller's arguments unchanged, so it
// keeps `System`'s guarantees; the counting touches only atomics and a const thread-local.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract, passed on as it is.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: as in `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: `ptr` came from this allocator (so from `System`) with `layout`.
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from this allocator (so from `System`) with `layout`.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Runs `work` counted as a call's work on this thread.
pub fn work<R>(work: impl FnOnce() -> R) -> R {
    WORKING.with(|w| w.set(true));
    let out = work();
    WORKING.with(|w| w.set(false));
    out
}

/// Allocations so far: in all, and during calls' work.
pub fn counts() -> (u64, u64) {
    (TOTAL.load(Ordering::Relaxed), IN_WORK.load(Ordering::Relaxed))
}
