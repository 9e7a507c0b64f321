//! The tables side by side on the reference cells (issue 3 item 8, issue 4 item 4): for each
//! cell, one certified labelling, then every variant built from it (and the thesis-style
//! table from the thesis's `r / sqrt 2` labelling), each evaluated on the same random
//! reachable configurations against the exact model (TP, TN, FP, FN) and timed per query,
//! warm and with the table flushed from the caches before every query.
//!
//! Run: `cargo bench --bench table_report -- [--cells T1,T2,T3] [--k 32] [--random 1000000]
//! [--cold 100000] [--cold-shared 1000000]` (`--cold-shared`: flushed queries of the
//! shared table without sub-cells; `--cold`: of every other table). Without `--bench` (as `cargo test` runs it) it
//! does a small smoke run (T2, k = 16) that still checks FN = 0 and the shared table's
//! agreement with the 6-D table.
//!
//! A query here is the table lookup alone (`Table::query` on a precomputed 6-D cell). All
//! queries are timed in three passes (flushed before each query for the flushed figures) and
//! each keeps its fastest pass, so that the maximum is the slowest query and not an
//! interrupt; timing costs two clock reads, shown as the "timer" row (the floor of every
//! figure).
//! Configurations whose TCP lies outside the sampled grid (none on the reference cells) would
//! go to the exact check, as `TableChecker` does, and are counted apart.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::cspace::symmetry::reflection_y;
use delta_collide::cspace::{
    label_space_certified, label_space_subdivided, label_space_thesis, subdivided_labels, LabelledSpace, SampleGrid,
    Workspace,
};
use delta_collide::math::Vec3;
use delta_collide::table::*;
use std::collections::HashSet;
use std::hint::black_box;
use std::time::Instant;

struct Options {
    cells: Vec<String>,
    k: u32,
    random: usize,
    cold: usize,
    cold_shared: usize,
    sub: bool,
    smoke: bool,
}

fn options() -> Options {
    let args: Vec<String> = std::env::args().collect();
    let value = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let num = |name: &str, default: usize| value(name).map_or(default, |v| v.parse().expect("a number"));
    if !args.iter().any(|a| a == "--bench") {
        return Options {
            cells: vec!["T2".into()],
            k: 16,
            random: 2000,
            cold: 200,
            cold_shared: 200,
            sub: true,
            smoke: true,
        };
    }
    let cells = value("--cells").unwrap_or("T1,T2,T3".into()).split(',').map(str::to_string).collect();
    Options {
        cells,
        k: num("--k", 32) as u32,
        random: num("--random", 1_000_000),
        cold: num("--cold", 100_000),
        cold_shared: num("--cold-shared", 1_000_000),
        sub: !args.iter().any(|a| a == "--no-sub"),
        smoke: false,
    }
}

/// xorshift64*: uniform in [0, 1).
fn uniform(seed: &mut u64) -> f64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    (seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
}

/// A random configuration's table cell (or `None` outside the sampled grid) and whether the
/// exact model finds a collision.
struct Config {
    /// At `2 k` per axis (sub-cell resolution); the grid cell is `fine >> 1`.
    fine: Option<[u16; 6]>,
    collides: bool,
}

/// The sub-cell (`2 k` per axis) of `p`, when its grid cell is sampled (as `TableChecker`).
fn grid_cell(g: &SampleGrid, sampled: &HashSet<[u16; 3]>, p: &Vec3) -> Option<[u16; 3]> {
    let mut c = [0u16; 3];
    for a in 0..3 {
        let u = ((p[a] - g.origin[a]) / (0.5 * g.r)).floor();
        if !(u >= 0.0 && u < f64::from(2 * g.k)) {
            return None;
        }
        c[a] = u as u16;
    }
    sampled.contains(&c.map(|v| v >> 1)).then_some(c)
}

/// The indices `table` is queried with: sub-cells for a subdivided table, else grid cells.
/// The cell `table` is queried with for the `fine` cell (at `2^fine_levels` per axis).
fn query_cell(table: &Table, fine: [u16; 6], fine_levels: u32) -> [u16; 6] {
    let shift = fine_levels - (table.levels() + table.sub_levels());
    fine.map(|v| v >> shift)
}

/// `n` random reachable configurations of both TCPs in the workspace (as `eval` draws them).
fn configurations(cell: &Cell, space: &LabelledSpace, n: usize, ws: &Workspace) -> Vec<Config> {
    let mut exact = ExactChecker::new(Cell { method: SatMethod::Sat, ..cell.clone() });
    let sampled = |g: &SampleGrid| g.cells.iter().copied().collect::<HashSet<_>>();
    let (sa, sb) = (sampled(&space.grid_a), sampled(&space.grid_b));
    let (rmax, dmax) = (ws.rcy, ws.max_depth());
    let mut seed = 1u64;
    let mut out = Vec::with_capacity(n);
    let mut tcps = [Vec3::zeros(); 2];
    while out.len() < n {
        for t in &mut tcps {
            let (x, y, d) = (uniform(&mut seed), uniform(&mut seed), uniform(&mut seed));
            *t = Vec3::new(rmax * (2.0 * x - 1.0), rmax * (2.0 * y - 1.0), -(ws.zu + (dmax - ws.zu) * d));
        }
        if !tcps.iter().all(|t| ws.contains(t)) {
            continue;
        }
        let v = exact.check(&tcps).expect("two TCPs");
        if v.unreachable_mask != 0 {
            continue;
        }
        let cell = match (grid_cell(&space.grid_a, &sa, &tcps[0]), grid_cell(&space.grid_b, &sb, &tcps[1])) {
            (Some(a), Some(b)) => Some([a[0], a[1], a[2], b[0], b[1], b[2]]),
            _ => None,
        };
        out.push(Config { fine: cell, collides: v.collides() });
    }
    out
}

/// Evicts every cache line of `regions` (x86-64 `clflush`), then waits for it.
#[cfg(target_arch = "x86_64")]
fn flush(regions: &[(usize, usize)]) {
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
fn flush(_regions: &[(usize, usize)]) {}

/// Median, p99.9 and maximum of `ns` (sorted in place).
fn percentiles(ns: &mut [u64]) -> (u64, u64, u64) {
    if ns.is_empty() {
        return (0, 0, 0);
    }
    ns.sort_unstable();
    let at = |q: f64| ns[((ns.len() - 1) as f64 * q).round() as usize];
    (at(0.5), at(0.999), ns[ns.len() - 1])
}

/// Passes over the queries; each query keeps its fastest pass: the query's own cost without
/// the interrupts and preemptions of a shared machine (single readings reach milliseconds,
/// and an interrupt rarely hits the same query in every pass).
const REPEATS: usize = 3;

fn query_ns(table: &Table, cell: [u16; 6], regions: Option<&[(usize, usize)]>) -> u64 {
    if let Some(r) = regions {
        flush(r);
    }
    let start = Instant::now();
    black_box(table.query(black_box(cell)));
    start.elapsed().as_nanos() as u64
}

/// Per query, the fastest of [`REPEATS`] passes over all of `cells`.
fn fastest_of_passes(cells: &[[u16; 6]], mut time: impl FnMut([u16; 6]) -> u64) -> Vec<u64> {
    let mut best = vec![u64::MAX; cells.len()];
    for _ in 0..REPEATS {
        for (b, &c) in best.iter_mut().zip(cells) {
            *b = (*b).min(time(c));
        }
    }
    best
}

/// (warm, flushed) median, p99.9 and maximum over the queries.
fn time_queries(table: &Table, cells: &[[u16; 6]], cold: usize) -> ((u64, u64, u64), (u64, u64, u64)) {
    let mut warm = fastest_of_passes(cells, |c| query_ns(table, c, None));
    let regions = table.memory_regions();
    let cold_cells = &cells[..cold.min(cells.len())];
    let mut flushed = if cfg!(target_arch = "x86_64") {
        fastest_of_passes(cold_cells, |c| query_ns(table, c, Some(&regions)))
    } else {
        vec![]
    };
    (percentiles(&mut warm), percentiles(&mut flushed))
}

/// What a table holds, in the thesis's terms (Tables 3.3-3.5).
fn contents(table: &Table) -> String {
    match table {
        Table::D6(q) => format!("{} codes", q.codes().len()),
        Table::D5(q) => format!("{} codes", q.parts().0.len()),
        Table::D4(q) => format!("{} codes / {} slices", q.parts().0.len(), q.slice_count()),
        Table::Shared(q) => format!("{} nodes", q.nodes_per_depth().iter().sum::<usize>()),
    }
}

fn main() {
    let opt = options();
    let ws = Workspace::THESIS;
    println!(
        "| cell | k | table | location codes / slices / nodes | bytes in memory | build s | warm median / p99.9 / max ns | flushed median / p99.9 / max ns (queries) | TP | TN | FP | FN | accuracy |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for name in &opt.cells {
        let cell = reference_cell(name).expect("a reference cell");
        let symmetric = reflection_y(&cell);
        let start = Instant::now();
        let certified = label_space_certified(&cell, opt.k, &ws, false).expect("labelling").space;
        let label_secs = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let subdivided = opt.sub.then(|| label_space_subdivided(&cell, opt.k, &ws, false).expect("labelling"));
        let sub_secs = start.elapsed().as_secs_f64();
        let expanded = subdivided.as_ref().map(|s| subdivided_labels(&cell, &ws, s).expect("2k labels"));
        let start = Instant::now();
        let thesis = label_space_thesis(&cell, opt.k, &ws, false).expect("labelling");
        let thesis_secs = start.elapsed().as_secs_f64();
        let configs = configurations(&cell, &certified, opt.random, &ws);
        let fine: Vec<[u16; 6]> = configs.iter().filter_map(|c| c.fine).collect();
        let outside = configs.len() - fine.len();
        let t_lossy = if opt.k >= 64 { 545 } else { 150 };
        type Build = Box<dyn Fn(&LabelledSpace) -> Result<Table, TableError>>;
        let mut variants: Vec<(String, &LabelledSpace, f64, Build)> = vec![
            (
                "6D".into(),
                &certified,
                label_secs,
                Box::new(move |s| LinearQuadtree6d::build(s, symmetric).map(Table::D6)),
            ),
            (
                "5D".into(),
                &certified,
                label_secs,
                Box::new(move |s| LinearQuadtree5d::build(s, symmetric).map(Table::D5)),
            ),
            (
                "4D/yy t=0".into(),
                &certified,
                label_secs,
                Box::new(move |s| LinearQuadtree4d::build(s, symmetric, SliceAxes::YY, 0).map(Table::D4)),
            ),
            (
                "4D/zz t=0".into(),
                &certified,
                label_secs,
                Box::new(move |s| LinearQuadtree4d::build(s, symmetric, SliceAxes::ZZ, 0).map(Table::D4)),
            ),
            (
                format!("4D/yy t={t_lossy}"),
                &certified,
                label_secs,
                Box::new(move |s| LinearQuadtree4d::build(s, symmetric, SliceAxes::YY, t_lossy).map(Table::D4)),
            ),
            (
                "6D-shared (new)".into(),
                &certified,
                label_secs,
                Box::new(move |s| SharedQuadtree6d::build(s, symmetric).map(Table::Shared)),
            ),
            (
                "thesis-style 6D (r/sqrt 2)".into(),
                &thesis,
                thesis_secs,
                Box::new(move |s| LinearQuadtree6d::build(s, symmetric).map(Table::D6)),
            ),
        ];
        if let (Some(subdivided), Some(expanded)) = (&subdivided, &expanded) {
            let sub_cells = subdivided.sub.clone().expect("sub-cells");
            variants.push((
                "6D-shared/sub (new)".into(),
                &subdivided.space,
                sub_secs,
                Box::new(move |s| SharedQuadtree6d::build_subdivided(s, &sub_cells, symmetric).map(Table::Shared)),
            ));
            variants.push((
                "4D/yy t=0 of the sub-cell labels (2k)".into(),
                expanded,
                sub_secs,
                Box::new(move |s| LinearQuadtree4d::build(s, symmetric, SliceAxes::YY, 0).map(Table::D4)),
            ));
        }
        let fine_levels = opt.k.trailing_zeros() + 1;
        let mut timer = fastest_of_passes(&fine, |c| {
            let start = Instant::now();
            black_box(c);
            start.elapsed().as_nanos() as u64
        });
        let (m, p, x) = percentiles(&mut timer);
        println!("| {name} | {} | timer (two clock reads) | | | | {m} / {p} / {x} | | | | | | |", opt.k);
        let (mut d6, mut sub_table): (Option<Table>, Option<Table>) = (None, None);
        for (label, space, secs, build) in &variants {
            let start = Instant::now();
            let table = build(space).expect("build");
            let build_secs = secs + start.elapsed().as_secs_f64();
            let (mut tp, mut tn, mut fp, mut fn_) = (0u64, 0u64, 0u64, 0u64);
            for c in &configs {
                let Some(f) = c.fine else { continue };
                match (table.query(query_cell(&table, f, fine_levels)), c.collides) {
                    (true, true) => tp += 1,
                    (false, false) => tn += 1,
                    (true, false) => fp += 1,
                    (false, true) => fn_ += 1,
                }
            }
            let is_shared = matches!(table, Table::Shared(_)) && table.sub_levels() == 0;
            let cold = if is_shared { opt.cold_shared } else { opt.cold };
            let cells: Vec<[u16; 6]> = fine.iter().map(|&f| query_cell(&table, f, fine_levels)).collect();
            let (w, f) = time_queries(&table, &cells, cold);
            let flushed = if f.2 == 0 {
                "n/a".into()
            } else {
                format!("{} / {} / {} ({})", f.0, f.1, f.2, cold.min(cells.len()))
            };
            let accuracy = 100.0 * (tp + tn) as f64 / (tp + tn + fp + fn_).max(1) as f64;
            println!(
                "| {name} | {} | {label} | {} | {} | {build_secs:.2} | {} / {} / {} | {flushed} | {tp} | {tn} | {fp} | {fn_} | {accuracy:.2} % |",
                opt.k,
                contents(&table),
                table.memory_bytes(),
                w.0,
                w.1,
                w.2
            );
            if !label.starts_with("thesis") {
                assert_eq!(fn_, 0, "{name} {label}: a false negative on a certified table");
            }
            // The plain table of the sub-cell labels answers as the subdivided table does.
            if let (Some(subdivided), true) = (&sub_table, label.contains("sub-cell labels")) {
                for &f in &fine {
                    let want = subdivided.query(query_cell(subdivided, f, fine_levels));
                    assert_eq!(table.query(query_cell(&table, f, fine_levels)), want, "{name} {label}: {f:?}");
                }
            }
            if table.sub_levels() == 1 {
                sub_table = Some(table.clone());
            }
            match (&d6, &table) {
                (None, Table::D6(_)) => d6 = Some(table),
                (Some(reference), Table::Shared(_)) => {
                    // The shared table answers as the 6-D table on every configuration drawn;
                    // with sub-cells it only frees configurations the 6-D table calls collision.
                    for &f in &fine {
                        let (want, got) = (
                            reference.query(query_cell(reference, f, fine_levels)),
                            table.query(query_cell(&table, f, fine_levels)),
                        );
                        assert!(got == want || (table.sub_levels() == 1 && want), "{name} {label}: {f:?}");
                    }
                }
                _ => {}
            }
        }
        if outside > 0 {
            println!(
                "| {name} | {} | ({outside} configurations outside the sampled grid: exact check) | | | | | | | | |",
                opt.k
            );
        }
    }
    if opt.smoke {
        println!("(smoke run; pass --bench for the full report)");
    }
}
