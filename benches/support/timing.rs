//! Timing for `table_report`: the clocks (with their floor measured in the same run), cache
//! flushing, and passes that keep each query's fastest time.

use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::time::Instant;

/// Evicts every cache line of `regions` (x86-64 `clflush`), then waits for it.
#[cfg(target_arch = "x86_64")]
pub fn flush(regions: &[(usize, usize)]) {
    use std::arch::x86_64::{_mm_clflush, _mm_mfence};
    for &(addr, len) in regions {
        let mut line = addr & !63;
        while line < addr + len {
            // SAFETY: `line` is the start of a cache line that holds bytes of a live array of
            // the table (`memory_regions`), which outlives this call; clflush reads no data
            // and changes no value, it only writes the line back and evicts it.
            unsafe { _mm_clflush(line as *const u8) };
            line += 64;
        }
    }
    // SAFETY: sse2 is part of the x86-64 baseline; a fence has no other precondition.
    unsafe { _mm_mfence() };
}

#[cfg(not(target_arch = "x86_64"))]
pub fn flush(_regions: &[(usize, usize)]) {}

/// The time stamp counter between two `lfence`s: no earlier instruction is still running
/// when it is read, and no later one has started.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn tsc() -> u64 {
    use std::arch::x86_64::{_mm_lfence, _rdtsc};
    // SAFETY: rdtsc and lfence (sse2) are part of the x86-64 baseline; they read a counter
    // and order instructions, touching no memory.
    unsafe {
        _mm_lfence();
        let t = _rdtsc();
        _mm_lfence();
        t
    }
}

#[cfg(not(target_arch = "x86_64"))]
pub fn tsc() -> u64 {
    0
}

/// The clock of the query timings.
#[derive(Clone, Copy, Debug)]
pub enum Clock {
    /// `Instant::now` (on Linux the vDSO `clock_gettime`).
    Instant,
    /// [`tsc`] at `ns_per_tick`, calibrated against `Instant`.
    Tsc { ns_per_tick: f64 },
}

impl Clock {
    /// The time stamp counter, calibrated over 200 ms against `Instant` (x86-64 only; the
    /// invariant TSC of current CPUs runs at a constant rate).
    pub fn tsc() -> Option<Clock> {
        if !cfg!(target_arch = "x86_64") {
            return None;
        }
        let (i0, t0) = (Instant::now(), tsc());
        while i0.elapsed().as_millis() < 200 {}
        let (ns, t1) = (i0.elapsed().as_nanos(), tsc());
        Some(Clock::Tsc { ns_per_tick: ns as f64 / t1.wrapping_sub(t0) as f64 })
    }

    /// Nanoseconds `f(input)` takes, with the cost of reading the clock twice (the timer
    /// row). `input` is in a register before the clock starts: a load of it that misses
    /// (the first query of each page of a streamed input array) is not timed.
    #[inline(always)]
    pub fn time<T, R>(self, input: T, f: impl FnOnce(T) -> R) -> u64 {
        let input = black_box(input);
        match self {
            Clock::Instant => {
                let start = Instant::now();
                black_box(f(input));
                start.elapsed().as_nanos() as u64
            }
            Clock::Tsc { ns_per_tick } => {
                let t0 = tsc();
                black_box(f(input));
                let t1 = tsc();
                (t1.wrapping_sub(t0) as f64 * ns_per_tick).round() as u64
            }
        }
    }

    pub fn name(self) -> String {
        match self {
            Clock::Instant => "Instant".into(),
            Clock::Tsc { ns_per_tick } => format!("rdtsc+lfence, {:.3} GHz", 1.0 / ns_per_tick),
        }
    }
}

/// Median, p99.9 and maximum of `ns`.
pub fn percentiles(ns: &[u64]) -> (u64, u64, u64) {
    if ns.is_empty() {
        return (0, 0, 0);
    }
    let mut ns = ns.to_vec();
    ns.sort_unstable();
    let at = |q: f64| ns[((ns.len() - 1) as f64 * q).round() as usize];
    (at(0.5), at(0.999), ns[ns.len() - 1])
}

/// Passes over the queries (3 unless `--passes` says otherwise); each query keeps its fastest
/// pass: the query's own cost without the interrupts and preemptions of a shared machine
/// (single readings reach milliseconds, and an interrupt rarely hits the same query in every
/// pass; on a loaded machine more passes filter more, see the timer rows).
pub static PASSES: AtomicUsize = AtomicUsize::new(3);

/// Per query, the fastest of [`PASSES`] passes over all of `cells`.
pub fn fastest_of_passes(cells: &[[u16; 6]], mut time: impl FnMut([u16; 6]) -> u64) -> Vec<u64> {
    let mut best = vec![u64::MAX; cells.len()];
    for _ in 0..PASSES.load(Relaxed) {
        for (b, &c) in best.iter_mut().zip(cells) {
            *b = (*b).min(time(c));
        }
    }
    best
}

/// Queries per block of the hot regime (256 unless `--hot-block` says otherwise), so that
/// between a query's untimed and timed run the block's lines stay in the 2 MiB L2 and its
/// pages in the 3,072-entry L2 TLB of the EPYC that measures here: a `6D-shared/sub` descent
/// reads up to 11 lines on 6 pages at k = 32 (T3, `--slowest`), one level more at k = 64.
/// Blocks of 256 fit both with room to spare; those of 4,096 (before) fit neither in the
/// worst case.
pub static HOT_BLOCK: AtomicUsize = AtomicUsize::new(256);

/// After the passes of the hot regime, the blocks holding the [`CONFIRM_SLOWEST`] slowest
/// queries (of either layout) are run again, untimed then timed as in a pass, this many
/// times: a query slow only because a disturbance hit it in every pass gets further
/// chances, one slow in its own right (its block evicting its lines) stays slow, since its
/// block runs as before.
pub const CONFIRM_ROUNDS: usize = 8;
pub const CONFIRM_SLOWEST: usize = 16;

/// The blocks (of `n` queries) that hold the `k` slowest of `best`, in order.
fn slowest_blocks(best: &[u64], n: usize, k: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..best.len()).collect();
    let k = k.min(order.len());
    if k == 0 {
        return vec![];
    }
    order.select_nth_unstable_by_key(k - 1, |&i| std::cmp::Reverse(best[i]));
    let mut blocks: Vec<usize> = order[..k].iter().map(|&i| i / n).collect();
    blocks.sort_unstable();
    blocks.dedup();
    blocks
}

/// Per query, the fastest of [`PASSES`] passes, each over every block of [`HOT_BLOCK`]
/// queries: the block is run once untimed, then timed (of `a`, then of `b`), so that every
/// line a query reads was read by the same query a block before (hot caches). Unlike
/// [`fastest_of_passes`] over a long stream, whose own input evicts rarely read lines of the
/// table between passes. A query's timed runs are a whole pass apart, so that a burst of a
/// co-runner thrashing the shared caches does not hit all of them, and every other pass runs
/// backwards, so that a periodic disturbance does not either. Then the blocks of the slowest
/// queries are confirmed ([`CONFIRM_ROUNDS`]).
pub fn hottest_of_passes(
    cells: &[[u16; 6]],
    mut a: impl FnMut([u16; 6]) -> u64,
    mut b: Option<&mut dyn FnMut([u16; 6]) -> u64>,
) -> (Vec<u64>, Vec<u64>) {
    fn block(
        best: &mut [u64],
        cells: &[[u16; 6]],
        backwards: bool,
        time: &mut dyn FnMut([u16; 6]) -> u64,
    ) {
        cells.iter().for_each(|&c| _ = black_box(time(c)));
        let pairs = best.iter_mut().zip(cells);
        if backwards {
            pairs.rev().for_each(|(t, &c)| *t = (*t).min(time(c)));
        } else {
            pairs.for_each(|(t, &c)| *t = (*t).min(time(c)));
        }
    }
    let n = HOT_BLOCK.load(Relaxed).max(1);
    let with_b = b.is_some();
    let (mut best_a, mut best_b) = (vec![u64::MAX; cells.len()], vec![u64::MAX; cells.len()]);
    let mut run = |blocks: &mut dyn Iterator<Item = usize>,
                   best_a: &mut [u64],
                   best_b: &mut [u64],
                   backwards| {
        for i in blocks {
            let range = i * n..((i + 1) * n).min(cells.len());
            block(&mut best_a[range.clone()], &cells[range.clone()], backwards, &mut a);
            if let Some(b) = b.as_mut() {
                block(&mut best_b[range.clone()], &cells[range], backwards, b);
            }
        }
    };
    for pass in 0..PASSES.load(Relaxed) {
        run(&mut (0..cells.len().div_ceil(n)), &mut best_a, &mut best_b, pass % 2 == 1);
    }
    for round in 0..CONFIRM_ROUNDS {
        let mut blocks = slowest_blocks(&best_a, n, CONFIRM_SLOWEST);
        if with_b {
            blocks.extend(slowest_blocks(&best_b, n, CONFIRM_SLOWEST));
            blocks.sort_unstable();
            blocks.dedup();
        }
        run(&mut blocks.into_iter(), &mut best_a, &mut best_b, round % 2 == 1);
    }
    if !with_b {
        best_b.clear();
    }
    (best_a, best_b)
}

/// Queries per turn when two layouts take turns within a pass.
pub const TURN: usize = 1 << 20;

/// Per query, the fastest of [`PASSES`] passes of `a` and of `b`, which take turns every
/// [`TURN`] queries, so that both see the same machine (the load of a shared machine changes
/// by the second). With `warm_up`, each turn first repeats, untimed, the `warm_up` queries
/// before it: the other layout's turn evicted this one from the caches and the TLB, which
/// would otherwise make the first queries of every turn the slowest of the run.
pub fn fastest_of_passes_in_turns(
    cells: &[[u16; 6]],
    warm_up: usize,
    mut a: impl FnMut([u16; 6]) -> u64,
    mut b: impl FnMut([u16; 6]) -> u64,
) -> (Vec<u64>, Vec<u64>) {
    let (mut best_a, mut best_b) = (vec![u64::MAX; cells.len()], vec![u64::MAX; cells.len()]);
    for pass in 0..PASSES.load(Relaxed) {
        for (turn, (ba, bb)) in best_a.chunks_mut(TURN).zip(best_b.chunks_mut(TURN)).enumerate() {
            let start = turn * TURN;
            // Before the first turn of a later pass: the end of the pass before.
            let before = match (start, pass) {
                (0, 0) => &cells[..0],
                (0, _) => &cells[cells.len().saturating_sub(warm_up)..],
                _ => &cells[start.saturating_sub(warm_up)..start],
            };
            let cs = &cells[start..start + ba.len()];
            before.iter().for_each(|&c| _ = black_box(a(c)));
            for (t, &c) in ba.iter_mut().zip(cs) {
                *t = (*t).min(a(c));
            }
            before.iter().for_each(|&c| _ = black_box(b(c)));
            for (t, &c) in bb.iter_mut().zip(cs) {
                *t = (*t).min(b(c));
            }
        }
    }
    (best_a, best_b)
}
