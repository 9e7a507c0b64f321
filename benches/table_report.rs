//! The tables side by side on the reference cells: for each
//! cell, one certified labelling, then every variant built from it (and the thesis-style
//! table from the thesis's `r / sqrt 2` labelling), each evaluated on the same random
//! reachable configurations against the exact model (TP, TN, FP, FN) and timed per query,
//! in three regimes: hot, streamed and with the table flushed from the caches before every
//! query.
//!
//! Run: `cargo bench --bench table_report -- [--cells T1,T2,T3] [--k 32] [--random 1000000]
//! [--cold 100000] [--cold-shared 1000000] [--variants shared,...] [--timer instant|tsc]
//! [--slowest 0] [--passes 3] [--hot-block 256]` (`--help` lists them). `--cold-shared`:
//! flushed queries of the shared table without sub-cells; `--cold`: of every other table.
//! `--variants`: which tables (default all). Only the labellings a chosen table needs are
//! made: the plain certified one for the first six, and with it the 6-D table whenever a
//! shared table is asked for, for the agreement check; so the subdivided table and the
//! baselines of its sub-cell labels alone skip the plain labels and that check.
//! `--timer tsc`: `rdtsc` between `lfence`s, converted to ns with a rate calibrated against
//! `Instant` in the same run.
//! `--slowest N`: for each shared table and for the hot and streamed regimes, the N slowest
//! queries with the memory reads of their descent (dependent steps, cache lines, pages),
//! re-timed one by one, and the regime's times grouped by steps and lines. Without `--bench`
//! (as `cargo test` runs it) it does a small smoke run (T2, k = 16) that still checks FN = 0
//! and the shared table's agreement with the 6-D table.
//!
//! A query here is the table lookup alone (`Table::query` on a precomputed 6-D cell). All
//! queries are timed in three passes (`--passes`) and each keeps its fastest pass, so that the
//! maximum is the slowest query and not an interrupt. Three regimes: *hot*, the passes run
//! back to back over blocks of 256 queries, so that every line a query reads is in the
//! caches (the blocks of the slowest queries then run again, `timing::CONFIRM_ROUNDS`);
//! *streamed*, the passes run over all queries, whose own input (12 bytes a query) evicts the
//! table's rarely read lines between passes, a mix of hot and cold reads; and *flushed*,
//! every line of the table evicted (`clflush`) before each query. Timing costs two clock
//! reads, shown as the "timer" rows (the floor of every figure, measured in the same run for
//! both clocks, the same way: when their maximum is high, the machine was too busy for the
//! maximum of any row to mean more). The shared table's separate-arrays layout (its peer) is
//! timed in the same run, the two taking turns.
//! Configurations whose TCP lies outside the sampled grid (none on the reference cells) would
//! go to the exact check, as `TableChecker` does, and are counted apart.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::cspace::symmetry::reflection_y;
use delta_collide::cspace::{
    label_space_certified, label_space_subdivided, label_space_thesis, CertifiedSpace,
    LabelledSpace, Progress, SampleGrid, SubdividedLabels, Symmetry, Workspace,
};
use delta_collide::math::Vec3;
use delta_collide::table::*;
#[path = "support/rng.rs"]
mod rng;
#[path = "support/shared_peer.rs"]
mod shared_peer;
#[path = "support/timing.rs"]
mod timing;

use rng::BenchRng;
use shared_peer::SeparateArrays;
use std::collections::HashSet;
use std::time::Instant;
use timing::{
    fastest_of_passes, fastest_of_passes_in_turns, flush, hottest_of_passes, percentiles, Clock,
};

/// The tables of the report, by the key `--variants` takes, in report order (see
/// [`entries`]; the plain kinds by their [`TableKind`] names, the two `-bound` keys are
/// notes, [`Run::slice_bounds`]).
const VARIANTS: [&str; 14] = [
    "6d",
    "5d",
    "4d-yy",
    "4d-zz",
    "4d-yy-lossy",
    "shared",
    "shared-sub",
    "4d-yy-sub",
    "4d-zz-sub",
    "4d-yy-sub-bound",
    "4d-zz-sub-bound",
    "6d-sub",
    "5d-sub",
    "thesis",
];

const USAGE: &str = "cargo bench --bench table_report -- [options]
  --cells T1,T2,T3      reference cells (default all three)
  --k 32                cells per axis
  --random 1000000      random reachable configurations per cell
  --cold 100000         flushed queries per table (not the shared one)
  --cold-shared 1000000 flushed queries of the shared table without sub-cells
  --cold-own 1000000    flushed queries of each shared table with only their own lines
                        evicted (a note under the table)
  --variants LIST       comma list of 6d,5d,4d-yy,4d-zz,4d-yy-lossy,shared,shared-sub,4d-yy-sub,
                        4d-zz-sub,4d-yy-sub-bound,4d-zz-sub-bound,6d-sub,5d-sub,thesis (default
                        all; 4d-yy-sub, 4d-zz-sub: the 4D t=0 tables of the sub-cell labels at
                        2k; 4d-yy-sub-bound, 4d-zz-sub-bound: a lower bound on their bytes, a
                        note; 6d-sub, 5d-sub: from those labels made dense, up to k = 32)
  --timer instant|tsc   clock of the query timings (default instant; tsc: rdtsc between lfences)
  --slowest N           the N slowest hot and streamed queries of each shared table, analysed
                        (default 0)
  --passes 3            passes over the queries; each query keeps its fastest
  --hot-block 256       queries per block of the hot regime";

struct Options {
    cells: Vec<String>,
    k: u32,
    random: usize,
    cold: usize,
    cold_shared: usize,
    cold_own: usize,
    variants: Vec<String>,
    tsc: bool,
    slowest: usize,
    smoke: bool,
}

fn options() -> Options {
    let args: Vec<String> = std::env::args().collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{USAGE}");
        std::process::exit(0);
    }
    let value =
        |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let num =
        |name: &str, default: usize| value(name).map_or(default, |v| v.parse().expect("a number"));
    let all = || VARIANTS.iter().map(|v| v.to_string()).collect();
    if !args.iter().any(|a| a == "--bench") {
        return Options {
            cells: vec!["T2".into()],
            k: 16,
            random: 2000,
            cold: 200,
            cold_shared: 200,
            cold_own: 2000,
            variants: all(),
            tsc: false,
            slowest: 3,
            smoke: true,
        };
    }
    let list =
        |name: &str| value(name).map(|v| v.split(',').map(str::to_string).collect::<Vec<_>>());
    let variants = list("--variants").unwrap_or_else(all);
    if let Some(v) = variants.iter().find(|v| !VARIANTS.contains(&v.as_str())) {
        panic!("--variants: unknown table {v:?}; use {}", VARIANTS.join(","));
    }
    timing::PASSES.store(num("--passes", 3).max(1), std::sync::atomic::Ordering::Relaxed);
    timing::HOT_BLOCK.store(num("--hot-block", 256).max(1), std::sync::atomic::Ordering::Relaxed);
    let tsc = match value("--timer").as_deref() {
        None | Some("instant") => false,
        Some("tsc") => true,
        Some(t) => panic!("--timer: {t:?} is neither instant nor tsc"),
    };
    Options {
        cells: list("--cells").unwrap_or_else(|| vec!["T1".into(), "T2".into(), "T3".into()]),
        k: num("--k", 32) as u32,
        random: num("--random", 1_000_000),
        cold: num("--cold", 100_000),
        cold_shared: num("--cold-shared", 1_000_000),
        cold_own: num("--cold-own", 1_000_000),
        variants,
        tsc,
        slowest: num("--slowest", 0),
        smoke: false,
    }
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
    let mut rng = BenchRng(1);
    let mut out = Vec::with_capacity(n);
    let mut tcps = [Vec3::zeros(); 2];
    while out.len() < n {
        for t in &mut tcps {
            let (x, y, d) = (rng.uniform(), rng.uniform(), rng.uniform());
            *t = Vec3::new(
                rmax * (2.0 * x - 1.0),
                rmax * (2.0 * y - 1.0),
                -(ws.zu + (dmax - ws.zu) * d),
            );
        }
        if !tcps.iter().all(|t| ws.contains(t)) {
            continue;
        }
        let v = exact.check(&tcps).expect("two TCPs");
        if v.unreachable_mask != 0 {
            continue;
        }
        let cell = match (
            grid_cell(&space.grid_a, &sa, &tcps[0]),
            grid_cell(&space.grid_b, &sb, &tcps[1]),
        ) {
            (Some(a), Some(b)) => Some([a[0], a[1], a[2], b[0], b[1], b[2]]),
            _ => None,
        };
        out.push(Config { fine: cell, collides: v.collides() });
    }
    out
}

fn query_ns(
    clock: Clock,
    table: &Table,
    cell: [u16; 6],
    regions: Option<&[(usize, usize)]>,
) -> u64 {
    if let Some(r) = regions {
        flush(r);
    }
    clock.time(cell, |c| table.query(c))
}

/// Untimed queries that re-warm a layout at the start of its turn (more than its lines and
/// pages: a T3 table at k = 32 has about 6,000 lines and 93 pages).
const WARM_UP: usize = 1 << 16;

/// Per query, its fastest time (ns) in each regime: hot (its block's passes back to back,
/// [`hottest_of_passes`]), streamed (passes over all queries, whose input stream evicts
/// rarely read lines) and flushed (the first `cold` queries, the table flushed before each).
#[derive(Default)]
struct Times {
    hot: Vec<u64>,
    streamed: Vec<u64>,
    flushed: Vec<u64>,
}

/// As [`time_queries`] for a shared table and its separate-arrays peer, taking turns: the
/// table's times, then the peer's.
fn time_with_peer(
    clock: Clock,
    table: &Table,
    peer: &SeparateArrays,
    cells: &[[u16; 6]],
    cold: usize,
) -> [Times; 2] {
    let (hot, hot_peer) = hottest_of_passes(
        cells,
        |c| query_ns(clock, table, c, None),
        Some(&mut |c| clock.time(c, |c| peer.query(c))),
    );
    let (streamed, streamed_peer) = fastest_of_passes_in_turns(
        cells,
        WARM_UP,
        |c| query_ns(clock, table, c, None),
        |c| clock.time(c, |c| peer.query(c)),
    );
    let (regions, peer_regions) = (table.memory_regions(), peer.memory_regions());
    let cold_cells = &cells[..cold.min(cells.len())];
    let (flushed, flushed_peer) = if cfg!(target_arch = "x86_64") {
        fastest_of_passes_in_turns(
            cold_cells,
            0,
            |c| query_ns(clock, table, c, Some(&regions)),
            |c| {
                flush(&peer_regions);
                clock.time(c, |c| peer.query(c))
            },
        )
    } else {
        (vec![], vec![])
    };
    [
        Times { hot, streamed, flushed },
        Times { hot: hot_peer, streamed: streamed_peer, flushed: flushed_peer },
    ]
}

/// The report's three timing cells: hot, streamed, flushed (of `cold` queries).
fn timing_cells(t: &Times, cold: usize) -> [String; 3] {
    let cell = |ns: &[u64]| match percentiles(ns) {
        (_, _, 0) => "n/a".into(),
        (m, p, x) => format!("{m} / {p} / {x} ({:.1}x)", x as f64 / m.max(1) as f64),
    };
    [cell(&t.hot), cell(&t.streamed), format!("{} ({cold})", cell(&t.flushed))]
}

/// Per query, its fastest time (ns) in each regime ([`Times`]).
fn time_queries(clock: Clock, table: &Table, cells: &[[u16; 6]], cold: usize) -> Times {
    let (hot, _) = hottest_of_passes(cells, |c| query_ns(clock, table, c, None), None);
    let streamed = fastest_of_passes(cells, |c| query_ns(clock, table, c, None));
    let regions = table.memory_regions();
    let cold_cells = &cells[..cold.min(cells.len())];
    let flushed = if cfg!(target_arch = "x86_64") {
        fastest_of_passes(cold_cells, |c| query_ns(clock, table, c, Some(&regions)))
    } else {
        vec![]
    };
    Times { hot, streamed, flushed }
}

/// Per query of a shared table, its fastest time with only the lines it reads evicted before
/// it (`SharedQuadtree6d::query_reads`): the flushed regime at a few `clflush`es a query
/// instead of the whole table's, so that a million queries of a 90 MB table take seconds.
/// The lines are listed before the flush; the query then reads every one of them from memory.
fn own_lines_flushed(clock: Clock, table: &Table, cells: &[[u16; 6]]) -> Vec<u64> {
    let Table::Shared(shared) = table else { return vec![] };
    if !cfg!(target_arch = "x86_64") {
        return vec![];
    }
    fastest_of_passes(cells, |c| {
        let lines: Vec<(usize, usize)> =
            shared.query_reads(c).1.iter().map(|&(a, n, _)| (a, n)).collect();
        query_ns(clock, table, c, Some(&lines))
    })
}

/// The reads of one shared-table query: dependent steps, reads, cache lines, 4 KiB pages.
fn read_counts(reads: &[(usize, usize, u32)]) -> (u32, usize, usize, usize) {
    let steps = reads.iter().map(|r| r.2 + 1).max().unwrap_or(0);
    let mut lines: Vec<usize> =
        reads.iter().flat_map(|&(a, n, _)| [a / 64, (a + n - 1) / 64]).collect();
    let mut pages: Vec<usize> = reads.iter().map(|&(a, _, _)| a / 4096).collect();
    for v in [&mut lines, &mut pages] {
        v.sort_unstable();
        v.dedup();
    }
    (steps, reads.len(), lines.len(), pages.len())
}

/// Min and median of `n` timings of `f`.
fn min_median(n: usize, mut f: impl FnMut() -> u64) -> (u64, u64) {
    let mut t: Vec<u64> = (0..n).map(|_| f()).collect();
    t.sort_unstable();
    (t[0], t[n / 2])
}

/// The slowest queries of a shared table in one regime (`times`), their reads and their
/// times alone; then that regime's times of all queries grouped by dependent steps and by
/// cache lines.
fn slowest_report(
    clock: Clock,
    table: &Table,
    cells: &[[u16; 6]],
    times: &[u64],
    regime: &str,
    n: usize,
) -> Vec<String> {
    let Table::Shared(shared) = table else { return vec![] };
    let regions = table.memory_regions();
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_unstable_by_key(|&i| std::cmp::Reverse(times[i]));
    let p = shared.parts();
    let refs: Vec<usize> = p
        .depth_start
        .windows(2)
        .map(|w| {
            p.masks[w[0] as usize..w[1] as usize].iter().map(|m| m[0].count_ones() as usize).sum()
        })
        .collect();
    let mut out = vec![
        format!(
            "nodes per depth (then leaves): {:?}; child refs out of each depth: {refs:?}",
            shared.nodes_per_depth()
        ),
        format!("{} slowest {regime} queries ({}):", n.min(cells.len()), table.name()),
    ];
    for &i in order.iter().take(n) {
        let (steps, reads, lines, pages) = read_counts(&shared.query_reads(cells[i]).1);
        let (hot, hot_med) = min_median(101, || query_ns(clock, table, cells[i], None));
        let (cold, cold_med) = min_median(11, || query_ns(clock, table, cells[i], Some(&regions)));
        out.push(format!(
            "  #{i} {:?} {regime} {} ns: {steps} steps, {reads} reads, {lines} lines, {pages} pages; alone hot min/median {hot} / {hot_med} ns, flushed {cold} / {cold_med} ns",
            cells[i], times[i]
        ));
    }
    let mut by: [std::collections::BTreeMap<usize, Vec<u64>>; 2] = Default::default();
    for (c, &t) in cells.iter().zip(times) {
        let (steps, _, lines, _) = read_counts(&shared.query_reads(*c).1);
        by[0].entry(steps as usize).or_default().push(t);
        by[1].entry(lines).or_default().push(t);
    }
    for (what, groups) in ["dependent steps", "cache lines"].iter().zip(&by) {
        out.push(format!("{regime} ns by {what}: value: queries, median / p99.9 / max"));
        for (v, ts) in groups {
            let (m, p, x) = percentiles(ts);
            out.push(format!("  {v}: {}, {m} / {p} / {x}", ts.len()));
        }
    }
    out
}

/// What a table holds, in the thesis's terms (Tables 3.3-3.5).
fn contents(table: &Table) -> String {
    match table {
        Table::D6(q) => format!("{} codes", q.codes().len()),
        Table::D5(q) => format!("{} codes", q.parts().0.len()),
        Table::D4(q) => format!("{} codes / {} slices", q.parts().0.len(), q.slice_count()),
        Table::Shared(q) => {
            let per_depth = q.nodes_per_depth();
            let depths: Vec<String> = per_depth.iter().map(|n| n.to_string()).collect();
            let bits: Vec<String> = q.slot_bits().iter().map(|b| b.to_string()).collect();
            format!(
                "{} nodes ({}; slot bits {})",
                per_depth.iter().sum::<usize>(),
                depths.join("/"),
                bits.join("/")
            )
        }
        Table::Clearance(q) => {
            format!("{} levels, level tree at k / {}", q.ladder().len(), 1u32 << q.shift())
        }
    }
}

/// The labellings one cell's tables are built from, each with the seconds it took (only
/// those a chosen table needs are made: the largest runs need the memory).
struct Labellings<'s> {
    /// The plain certified labels.
    certified: Option<(LabelledSpace, f64)>,
    /// The certified labels with sub-cells ([`subdivided`]).
    subdivided: Option<&'s (CertifiedSpace, f64)>,
    /// Its sub-cell labels at `2 k`, read pair by pair (their dense form takes 64 times the
    /// bytes of the labels at `k`).
    fine: Option<(SubdividedLabels<'s>, f64)>,
    /// The same labels as one array, for the 6-D and 5-D builders.
    dense: Option<(LabelledSpace, f64)>,
    /// The thesis's `r / sqrt 2` labels.
    thesis: Option<(LabelledSpace, f64)>,
}

/// Runs `f` and the seconds it took.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    (f(), start.elapsed().as_secs_f64())
}

/// The keys of the tables built from the sub-cell labels at `2 k`.
const OF_SUB_CELL_LABELS: [&str; 6] =
    ["4d-yy-sub", "4d-zz-sub", "4d-yy-sub-bound", "4d-zz-sub-bound", "6d-sub", "5d-sub"];

/// The subdivided certified labelling of `cell`, when a table `wants` asks for needs it.
fn subdivided(
    cell: &Cell,
    k: u32,
    ws: &Workspace,
    wants: &dyn Fn(&str) -> bool,
) -> Option<(CertifiedSpace, f64)> {
    (wants("shared-sub") || OF_SUB_CELL_LABELS.iter().any(|key| wants(key))).then(|| {
        timed(|| label_space_subdivided(cell, k, ws, Progress::Silent).expect("labelling"))
    })
}

impl<'s> Labellings<'s> {
    /// The other labellings of `cell` the tables `wants` asks for need.
    fn make(
        cell: &Cell,
        k: u32,
        ws: &Workspace,
        wants: &dyn Fn(&str) -> bool,
        subdivided: Option<&'s (CertifiedSpace, f64)>,
    ) -> Labellings<'s> {
        let needs = |keys: &[&str]| keys.iter().any(|key| wants(key));
        // The 6-D table of the plain labels is also the reference the shared tables are
        // checked against.
        let plain = needs(&["6d", "5d", "4d-yy", "4d-zz", "4d-yy-lossy", "shared"]);
        let certified = plain.then(|| {
            timed(|| label_space_certified(cell, k, ws, Progress::Silent).expect("labelling").space)
        });
        let fine = subdivided.filter(|_| needs(&OF_SUB_CELL_LABELS)).map(|(s, secs)| {
            let (f, more) = timed(|| SubdividedLabels::new(cell, ws, s).expect("2k grids"));
            (f, secs + more)
        });
        let dense = fine.as_ref().filter(|_| needs(&["6d-sub", "5d-sub"])).map(|(f, secs)| {
            let (d, more) = timed(|| f.to_dense());
            (d, secs + more)
        });
        let thesis = wants("thesis").then(|| {
            timed(|| label_space_thesis(cell, k, ws, Progress::Silent).expect("labelling"))
        });
        Labellings { certified, subdivided, fine, dense, thesis }
    }

    /// The grids every labelling shares (the first made).
    fn grids(&self) -> &LabelledSpace {
        (self.certified.as_ref().map(|c| &c.0))
            .or(self.subdivided.map(|s| &s.0.space))
            .or(self.thesis.as_ref().map(|t| &t.0))
            .expect("a table to report")
    }
}

type Build<'a> = Box<dyn Fn(&LabelledSpace) -> Result<Table, TableError> + 'a>;

/// One table of the report.
struct Entry<'a> {
    /// Its key in `--variants`.
    key: &'static str,
    /// Its name in the report's rows.
    label: String,
    /// The labels it is built from and the seconds they took.
    space: &'a LabelledSpace,
    label_secs: f64,
    /// Whether it answers for certified labels: a false negative fails the report.
    certified: bool,
    /// Whether it is a plain table of the sub-cell labels at `2 k`: it must answer as the
    /// shared table of sub-cells.
    of_sub_cell_labels: bool,
    build: Build<'a>,
}

impl<'a> Entry<'a> {
    fn new(
        key: &'static str,
        label: impl Into<String>,
        labels: &'a (LabelledSpace, f64),
        build: Build<'a>,
    ) -> Self {
        let label = label.into();
        Entry {
            key,
            label,
            space: &labels.0,
            label_secs: labels.1,
            certified: true,
            of_sub_cell_labels: false,
            build,
        }
    }
}

/// Every table the labellings made allow, in report order.
fn entries<'a>(l: &'a Labellings<'a>, symmetric: bool, t_lossy: u32) -> Vec<Entry<'a>> {
    let mut out = vec![];
    if let Some(c) = &l.certified {
        let d4 = |axes, t| -> Build<'a> {
            Box::new(move |s| {
                LinearQuadtree4d::build(s, Symmetry::from_flag(symmetric), axes, t).map(Table::D4)
            })
        };
        out.push(Entry::new(
            TableKind::D6.name(),
            "6D",
            c,
            Box::new(move |s| {
                LinearQuadtree6d::build(s, Symmetry::from_flag(symmetric)).map(Table::D6)
            }),
        ));
        out.push(Entry::new(
            TableKind::D5.name(),
            "5D",
            c,
            Box::new(move |s| {
                LinearQuadtree5d::build(s, Symmetry::from_flag(symmetric)).map(Table::D5)
            }),
        ));
        out.push(Entry::new(TableKind::D4yy.name(), "4D/yy t=0", c, d4(SliceAxes::YY, 0)));
        out.push(Entry::new(TableKind::D4zz.name(), "4D/zz t=0", c, d4(SliceAxes::ZZ, 0)));
        out.push(Entry::new(
            "4d-yy-lossy",
            format!("4D/yy t={t_lossy}"),
            c,
            d4(SliceAxes::YY, t_lossy),
        ));
        let shared: Build = Box::new(move |s| {
            SharedQuadtree6d::build(s, Symmetry::from_flag(symmetric)).map(Table::Shared)
        });
        out.push(Entry::new(TableKind::Shared.name(), "6D-shared", c, shared));
    }
    if let Some((sub, secs)) = l.subdivided {
        let sub_cells = sub.sub.as_ref().expect("sub-cells");
        let build: Build = Box::new(move |s| {
            SharedQuadtree6d::build_subdivided(s, sub_cells, Symmetry::from_flag(symmetric))
                .map(Table::Shared)
        });
        out.push(Entry {
            key: TableKind::SharedSub.name(),
            label: "6D-shared/sub".into(),
            space: &sub.space,
            label_secs: *secs,
            certified: true,
            of_sub_cell_labels: false,
            build,
        });
    }
    if let (Some((sub, _)), Some((fine, secs))) = (l.subdivided, &l.fine) {
        for (key, axes, name) in
            [("4d-yy-sub", SliceAxes::YY, "yy"), ("4d-zz-sub", SliceAxes::ZZ, "zz")]
        {
            let build: Build = Box::new(move |_| {
                LinearQuadtree4d::build_subdivided(fine, Symmetry::from_flag(symmetric), axes, 0)
                    .map(Table::D4)
            });
            let label = format!("4D/{name} t=0 of the sub-cell labels (2k)");
            out.push(Entry {
                key,
                label,
                space: &sub.space,
                label_secs: *secs,
                certified: true,
                of_sub_cell_labels: true,
                build,
            });
        }
    }
    if let Some(dense) = &l.dense {
        let d6: Build = Box::new(move |s| {
            LinearQuadtree6d::build(s, Symmetry::from_flag(symmetric)).map(Table::D6)
        });
        let d5: Build = Box::new(move |s| {
            LinearQuadtree5d::build(s, Symmetry::from_flag(symmetric)).map(Table::D5)
        });
        out.push(Entry {
            of_sub_cell_labels: true,
            ..Entry::new("6d-sub", "6D of the sub-cell labels (2k)", dense, d6)
        });
        out.push(Entry {
            of_sub_cell_labels: true,
            ..Entry::new("5d-sub", "5D of the sub-cell labels (2k)", dense, d5)
        });
    }
    if let Some(thesis) = &l.thesis {
        let d6: Build = Box::new(move |s| {
            LinearQuadtree6d::build(s, Symmetry::from_flag(symmetric)).map(Table::D6)
        });
        out.push(Entry {
            certified: false,
            ..Entry::new("thesis", "thesis-style 6D (r/sqrt 2)", thesis, d6)
        });
    }
    out
}

/// What every table of one cell is evaluated on.
struct Run<'a> {
    name: &'a str,
    opt: &'a Options,
    clock: Clock,
    configs: Vec<Config>,
    /// The sampled configurations' cells at `2^fine_levels` per axis.
    fine: Vec<[u16; 6]>,
    fine_levels: u32,
}

impl Run<'_> {
    /// The report row of `table` (`entry`): accuracy against the exact model, times in the
    /// three regimes (with the separate-arrays peer of a shared table), and notes.
    fn report(&self, entry: &Entry, table: &Table, build_secs: f64, notes: &mut Vec<String>) {
        let (name, opt, label) = (self.name, self.opt, &entry.label);
        let (mut tp, mut tn, mut fp, mut fn_) = (0u64, 0u64, 0u64, 0u64);
        for c in &self.configs {
            let Some(f) = c.fine else { continue };
            match (table.query(query_cell(table, f, self.fine_levels)), c.collides) {
                (true, true) => tp += 1,
                (false, false) => tn += 1,
                (true, false) => fp += 1,
                (false, true) => fn_ += 1,
            }
        }
        let is_shared = matches!(table, Table::Shared(_)) && table.sub_levels() == 0;
        let cold = if is_shared { opt.cold_shared } else { opt.cold };
        let cells: Vec<[u16; 6]> =
            self.fine.iter().map(|&f| query_cell(table, f, self.fine_levels)).collect();
        let cold = cold.min(cells.len());
        let peer = match table {
            Table::Shared(t) => Some(SeparateArrays::new(t)),
            _ => None,
        };
        let [times, peer_times] = match &peer {
            Some(peer) => {
                // The separate-arrays peer answers as the table on every configuration.
                for &c in &cells {
                    assert_eq!(
                        peer.query(c),
                        table.query(c),
                        "{name} {label}: separate-arrays peer at {c:?}"
                    );
                }
                time_with_peer(self.clock, table, peer, &cells, cold)
            }
            None => [time_queries(self.clock, table, &cells, cold), Times::default()],
        };
        let [h, s, f] = timing_cells(&times, cold);
        let accuracy = 100.0 * (tp + tn) as f64 / (tp + tn + fp + fn_).max(1) as f64;
        println!(
            "| {name} | {} | {label} | {} | {} | {build_secs:.2} | {h} | {s} | {f} | {tp} | {tn} | {fp} | {fn_} | {accuracy:.2} % |",
            opt.k,
            contents(table),
            table.memory_bytes(),
        );
        if let Some(peer) = &peer {
            let [h, s, f] = timing_cells(&peer_times, cold);
            println!(
                "| {name} | {} | {label}, separate arrays (same run, taking turns) | | {} | | {h} | {s} | {f} | | | | | |",
                opt.k,
                peer.memory_bytes(),
            );
        }
        if entry.certified {
            assert_eq!(fn_, 0, "{name} {label}: a false negative on a certified table");
        }
        let own = own_lines_flushed(self.clock, table, &cells[..opt.cold_own.min(cells.len())]);
        if !own.is_empty() {
            let n = own.len().min(cold);
            let [_, _, all] =
                timing_cells(&Times { flushed: own.clone(), ..Times::default() }, own.len());
            let [_, _, first] =
                timing_cells(&Times { flushed: own[..n].to_vec(), ..Times::default() }, n);
            notes.push(format!(
                "{label}: flushed with only its own lines evicted: {all}; its first {n} queries: {first} \
                 (the whole table evicted: {f})"
            ));
        }
        if opt.slowest > 0 {
            notes.extend(slowest_report(self.clock, table, &cells, &times.hot, "hot", opt.slowest));
            notes.extend(slowest_report(
                self.clock,
                table,
                &cells,
                &times.streamed,
                "streamed",
                opt.slowest,
            ));
        }
    }

    /// Asserts that `table` answers as `reference` on every configuration drawn; with
    /// `may_free`, it may instead free a configuration `reference` calls collision.
    fn check_against(&self, label: &str, table: &Table, reference: &Table, may_free: bool) {
        for &f in &self.fine {
            let want = reference.query(query_cell(reference, f, self.fine_levels));
            let got = table.query(query_cell(table, f, self.fine_levels));
            assert!(got == want || (may_free && want), "{} {label}: {f:?}", self.name);
        }
    }

    /// The notes on the lower bounds of the 4-D tables of the sub-cell labels, for when
    /// building them would take hours ([`SliceBound`]).
    fn slice_bounds(
        &self,
        fine: &SubdividedLabels,
        symmetric: bool,
        sub_table: Option<&Table>,
        wants: &dyn Fn(&str) -> bool,
    ) -> Vec<String> {
        let bounds =
            [("4d-yy-sub-bound", SliceAxes::YY, "yy"), ("4d-zz-sub-bound", SliceAxes::ZZ, "zz")];
        let mut notes = vec![];
        for (_, axes, axes_name) in bounds.into_iter().filter(|b| wants(b.0)) {
            let start = Instant::now();
            let mut bound = SliceBound::new(fine.grid_a.levels, symmetric, axes);
            subdivided_slices(fine, symmetric, axes, |_, s, care| bound.add(s, care))
                .expect("slices");
            let ((groups, (r0, c0, side)), bytes) =
                (bound.groups_at_least(), bound.bytes_at_least());
            let ratio = sub_table.map_or(String::new(), |t| {
                let b = t.memory_bytes();
                format!(
                    "; `6D-shared/sub` ({b} bytes) is {:.1} % of that",
                    100.0 * b as f64 / bytes as f64
                )
            });
            notes.push(format!(
                "4D/{axes_name} t=0 of the sub-cell labels (2k), bounded in {:.0} s: {} codes, at least {groups} \
                 slices (patterns in the {side} x {side} window at row {r0}, column {c0}), at least {bytes} bytes{ratio}",
                start.elapsed().as_secs_f64(),
                bound.codes,
            ));
        }
        notes
    }
}

fn main() {
    let opt = options();
    let wants = |key: &str| opt.variants.iter().any(|v| v == key);
    let ws = Workspace::THESIS;
    let tsc = Clock::tsc();
    let clock = if opt.tsc { tsc.expect("--timer tsc needs x86-64") } else { Clock::Instant };
    println!("(query timings: {})", clock.name());
    println!(
        "| cell | k | table | location codes / slices / nodes | bytes in memory | build s | hot median / p99.9 / max ns (max/median) | streamed median / p99.9 / max ns | flushed median / p99.9 / max ns (queries) | TP | TN | FP | FN | accuracy |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for name in &opt.cells {
        let cell = reference_cell(name).expect("a reference cell");
        let symmetric = reflection_y(&cell);
        let subdivided = subdivided(&cell, opt.k, &ws, &wants);
        let labellings = Labellings::make(&cell, opt.k, &ws, &wants, subdivided.as_ref());
        let configs = configurations(&cell, labellings.grids(), opt.random, &ws);
        let fine: Vec<[u16; 6]> = configs.iter().filter_map(|c| c.fine).collect();
        let outside = configs.len() - fine.len();
        let run =
            Run { name, opt: &opt, clock, configs, fine, fine_levels: opt.k.trailing_zeros() + 1 };
        for c in [Some(Clock::Instant), tsc].into_iter().flatten() {
            let (hot, _) = hottest_of_passes(&run.fine, |f| c.time(f, |f| f), None);
            let streamed = fastest_of_passes(&run.fine, |f| c.time(f, |f| f));
            let [h, s, _] = timing_cells(&Times { hot, streamed, flushed: vec![] }, 0);
            println!(
                "| {name} | {} | timer: {} (two reads) | | | | {h} | {s} | | | | | | |",
                opt.k,
                c.name()
            );
        }
        let shared_wanted = wants("shared") || wants("shared-sub");
        let (mut d6, mut sub_table): (Option<Table>, Option<Table>) = (None, None);
        let mut notes = vec![];
        let t_lossy = if opt.k >= 64 { 545 } else { 150 };
        for entry in entries(&labellings, symmetric, t_lossy) {
            // The 6-D table is the shared tables' reference: built (not reported) when only they
            // are asked for.
            let report = wants(entry.key);
            if !(report || entry.key == "6d" && shared_wanted) {
                continue;
            }
            let (table, secs) = timed(|| (entry.build)(entry.space).expect("build"));
            if report {
                run.report(&entry, &table, entry.label_secs + secs, &mut notes);
            }
            // The plain table of the sub-cell labels answers as the subdivided table does.
            if let (Some(subdivided), true) = (&sub_table, entry.of_sub_cell_labels) {
                run.check_against(&entry.label, &table, subdivided, false);
            }
            if table.sub_levels() == 1 {
                sub_table = Some(table.clone());
            }
            match (&d6, &table) {
                (None, Table::D6(_)) => d6 = Some(table),
                // The shared table answers as the 6-D table on every configuration drawn;
                // with sub-cells it only frees configurations the 6-D table calls collision.
                (Some(reference), Table::Shared(_)) => {
                    run.check_against(&entry.label, &table, reference, table.sub_levels() == 1)
                }
                _ => {}
            }
        }
        if outside > 0 {
            println!(
                "| {name} | {} | ({outside} configurations outside the sampled grid: exact check) | | | | | | | | | |",
                opt.k
            );
        }
        if let Some((fine, _)) = &labellings.fine {
            notes.extend(run.slice_bounds(fine, symmetric, sub_table.as_ref(), &wants));
        }
        for n in notes {
            println!("{name}: {n}");
        }
    }
    if opt.smoke {
        println!("(smoke run; pass --bench for the full report)");
    }
}
