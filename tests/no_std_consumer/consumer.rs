//! A firmware's use of delta-collide without an operating system (README "Without an
//! operating system"): `#![no_std]`, its own panic handler and allocator, tables read from
//! bytes it carries, [`TableChecker`](delta_collide::table::TableChecker) per tick.
//!
//! `tests/portability.rs` compiles it with `rustc` as a static library against the
//! `--no-default-features` build of delta-collide: for the host, linked into `driver.c` and
//! run; for `thumbv7em-none-eabihf`, linked with `rust-lld` (not run). The tables are
//! embedded at compile time from the directory in `DC_NOSTD_TABLES`.
#![no_std]

extern crate alloc;

#[path = "workload.rs"]
mod workload;

use core::alloc::{GlobalAlloc, Layout};
use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicUsize, Ordering};
use workload::Summary;

/// The tables of T1 (k = 16), in the order of `dc_nostd_run`'s `table` argument.
static TABLES: [&[u8]; 6] = [
    include_bytes!(concat!(env!("DC_NOSTD_TABLES"), "/t1_6d.dct")),
    include_bytes!(concat!(env!("DC_NOSTD_TABLES"), "/t1_5d.dct")),
    include_bytes!(concat!(env!("DC_NOSTD_TABLES"), "/t1_4d_yy.dct")),
    include_bytes!(concat!(env!("DC_NOSTD_TABLES"), "/t1_4d_zz.dct")),
    include_bytes!(concat!(env!("DC_NOSTD_TABLES"), "/t1_shared.dct")),
    include_bytes!(concat!(env!("DC_NOSTD_TABLES"), "/t1_shared_sub.dct")),
];

/// Loads table `table` and answers `n` configurations of `seed` (see `workload.rs`); a
/// table index out of range gives status 100.
#[no_mangle]
pub extern "C" fn dc_nostd_run(table: u32, seed: u64, n: u32) -> Summary {
    match TABLES.get(table as usize) {
        Some(bytes) => workload::run(bytes, seed, n, || ALLOCATOR.count.load(Ordering::Relaxed) as u64),
        None => Summary { status: 100, ..Summary::default() },
    }
}

const HEAP_BYTES: usize = 8 << 20;

/// A bump allocator over a static array that counts allocations; it never frees (enough
/// for one load per run, as a firmware that allocates only at start-up).
struct Bump {
    heap: UnsafeCell<[u8; HEAP_BYTES]>,
    used: AtomicUsize,
    count: AtomicUsize,
}

// SAFETY: the heap is handed out in disjoint pieces, claimed by compare-and-swap on `used`.
unsafe impl Sync for Bump {}

// SAFETY: every returned block lies inside `heap`, is aligned as asked and is never handed
// out again; null when the heap is exhausted.
unsafe impl GlobalAlloc for Bump {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        self.count.fetch_add(1, Ordering::Relaxed);
        let base = self.heap.get() as *mut u8;
        let mut used = self.used.load(Ordering::Relaxed);
        loop {
            let start = (base as usize + used).next_multiple_of(layout.align()) - base as usize;
            let Some(end) = start.checked_add(layout.size()).filter(|&e| e <= HEAP_BYTES) else {
                return core::ptr::null_mut();
            };
            match self.used.compare_exchange_weak(used, end, Ordering::Relaxed, Ordering::Relaxed) {
                Ok(_) => return base.wrapping_add(start),
                Err(now) => used = now,
            }
        }
    }

    unsafe fn dealloc(&self, _ptr: *mut u8, _layout: Layout) {}
}

#[global_allocator]
static ALLOCATOR: Bump =
    Bump { heap: UnsafeCell::new([0; HEAP_BYTES]), used: AtomicUsize::new(0), count: AtomicUsize::new(0) };

/// The host's precompiled `core` and `alloc` are built for unwinding and name this symbol in
/// their unwind tables; with `panic = "abort"` nothing unwinds, so it is never called. A
/// bare-metal target's libraries do not name it.
#[cfg(not(target_os = "none"))]
#[no_mangle]
pub extern "C" fn rust_eh_personality() {}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    #[cfg(not(target_os = "none"))]
    {
        extern "C" {
            fn abort() -> !;
        }
        // SAFETY: C's abort takes no arguments and does not return; the host driver links libc.
        unsafe { abort() }
    }
    #[cfg(target_os = "none")]
    loop {
        core::hint::spin_loop();
    }
}
