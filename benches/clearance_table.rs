//! Clearance tables next to the boolean shared table of the same labels, per reference cell:
//! bytes, and per lookup (the table alone, on precomputed grid cells of random reachable
//! configurations) median / p99.9 / max, hot and with both tables flushed from the caches
//! before every query, the two tables timed in the same run. The clearance lookup answers
//! the certified bound (mm); the boolean lookup answers free or collision. Both answers are
//! checked inside the timed loop against each other: a level exactly where the boolean table
//! says free.
//!
//! Run: `cargo bench --bench clearance_table -- --dir DIR [--cells T1,T2,T3] [--k 32]
//! [--random 1000000] [--cold 100000]`, with the tables built beforehand by the CLI as
//! `DIR/{cell}_k{k}_shared.dct` and `DIR/{cell}_k{k}_clearance.dct` (the record gives the
//! commands). Without `--bench` (as `cargo test` runs it) a smoke run builds T1's tables at
//! k = 16 in memory.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cspace::{Progress, SampleGrid, Workspace};
use delta_collide::math::Vec3;
use delta_collide::table::*;
#[path = "support/rng.rs"]
mod rng;
#[path = "support/timing.rs"]
#[allow(dead_code)] // shared with table_report, which uses all of it
mod timing;

use rng::BenchRng;
use std::hint::black_box;
use timing::{flush, hottest_of_passes, percentiles, Clock};

/// Grid cells of `n` random reachable configurations of `cell` whose TCPs lie in sampled
/// grid cells at `k` (drawn as the CLI's `eval` draws them).
fn random_cells(cell: &delta_collide::cell::Cell, k: u32, n: usize) -> Vec<[u16; 6]> {
    let ws = Workspace::THESIS;
    let grids: Vec<SampleGrid> =
        (0..2).map(|j| SampleGrid::new(&ws, k, &cell.robots[j].model.delta).unwrap()).collect();
    let mut rng = BenchRng(1);
    let (rmax, dmax) = (ws.rcy, ws.zu + ws.hcy + ws.hco);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let mut c = [0u16; 6];
        let mut ok = true;
        for (j, g) in grids.iter().enumerate() {
            let t = Vec3::new(
                rmax * (2.0 * rng.uniform() - 1.0),
                rmax * (2.0 * rng.uniform() - 1.0),
                -(ws.zu + (dmax - ws.zu) * rng.uniform()),
            );
            let reachable = ws.contains(&t) && cell.robots[j].model.delta.is_reachable(&t);
            match g.cell_of(&t).filter(|&gc| reachable && g.index_of(gc).is_some()) {
                Some(gc) => c[3 * j..3 * j + 3].copy_from_slice(&gc),
                None => ok = false,
            }
        }
        if ok {
            out.push(c);
        }
    }
    out
}

/// One lookup of each table, checked against the other (closures, not boxed: the benchmark
/// times them).
#[allow(clippy::type_complexity)]
fn lookups<'a>(
    shared: &'a Table,
    clearance: &'a ClearanceTable,
) -> (impl Fn([u16; 6]) -> bool + 'a, impl Fn([u16; 6]) -> Option<f64> + 'a) {
    (move |c| shared.query(c), move |c| clearance.bound_mm(c))
}

fn row(what: &str, ns: &[u64]) -> String {
    let (median, p999, max) = percentiles(ns);
    format!(
        "{what:<34} median {median:>5} ns  p99.9 {p999:>6} ns  max {max:>8} ns  ({} queries)",
        ns.len()
    )
}

/// Times and compares both tables of one cell on `cells`; `cold` of them flushed.
fn report(name: &str, shared: &Table, clearance_table: &Table, cells: &[[u16; 6]], cold: usize) {
    let clearance = clearance_table.as_clearance().expect("a clearance table");
    let (boolean, bound) = lookups(shared, clearance);
    for &c in cells {
        assert_eq!(
            boolean(c),
            bound(c).is_none(),
            "{name} {c:?}: the level and the boolean table disagree"
        );
    }
    let clock = Clock::tsc().unwrap_or(Clock::Instant);
    println!(
        "{name}: shared {} bytes, clearance {} bytes ({:.2}x; level tree at k / {}, {}), levels {:?} mm; clock {}",
        shared.memory_bytes(),
        clearance_table.memory_bytes(),
        clearance_table.memory_bytes() as f64 / shared.memory_bytes() as f64,
        1u32 << clearance.shift(),
        if clearance.has_level_grid() { "descent + level grid" } else { "two descents" },
        clearance.ladder().mm(),
        clock.name()
    );
    let timer = |c: [u16; 6]| clock.time(c, |c| c);
    let time_shared = |c: [u16; 6]| clock.time(c, |c| black_box(boolean(c)));
    let time_bound = |c: [u16; 6]| clock.time(c, |c| black_box(bound(c)));
    let (t_timer, _) = hottest_of_passes(cells, timer, None);
    let mut b = time_bound;
    let (t_shared, t_bound) = hottest_of_passes(cells, time_shared, Some(&mut b));
    println!("  {}", row("hot: timer alone", &t_timer));
    println!("  {}", row("hot: shared (boolean)", &t_shared));
    println!("  {}", row("hot: clearance bound", &t_bound));
    let (mut f_shared, mut f_bound) = (Vec::with_capacity(cold), Vec::with_capacity(cold));
    let (rs, rc) = (shared.memory_regions(), clearance_table.memory_regions());
    for &c in cells.iter().take(cold) {
        flush(&rs);
        flush(&rc);
        f_shared.push(clock.time(c, |c| black_box(boolean(c))));
        flush(&rs);
        flush(&rc);
        f_bound.push(clock.time(c, |c| black_box(bound(c))));
    }
    println!("  {}", row("flushed: shared (boolean)", &f_shared));
    println!("  {}", row("flushed: clearance bound", &f_bound));
}

fn arg(args: &[String], name: &str) -> Option<String> {
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !args.iter().any(|a| a == "--bench") {
        // Smoke run (cargo test): T1 at k = 16 built in memory.
        let cell = reference_cell("T1").unwrap();
        let variants = [Variant::Shared, Variant::Clearance(Ladder::default_ladder())];
        let (_, tables, _) = build_tables(
            &cell,
            16,
            &Workspace::THESIS,
            &variants,
            Labelling::Certified,
            Progress::Silent,
        )
        .unwrap();
        report(
            "T1 k = 16 (smoke run)",
            &tables[0],
            &tables[1],
            &random_cells(&cell, 16, 20_000),
            2_000,
        );
        return;
    }
    let dir = arg(&args, "--dir").expect("--dir DIR: the tables built by the CLI (module doc)");
    let k: u32 = arg(&args, "--k").map_or(32, |v| v.parse().unwrap());
    let n: usize = arg(&args, "--random").map_or(1_000_000, |v| v.parse().unwrap());
    let cold: usize = arg(&args, "--cold").map_or(100_000, |v| v.parse().unwrap());
    let cells = arg(&args, "--cells").unwrap_or_else(|| "T1,T2,T3".into());
    for name in cells.split(',') {
        let cell = reference_cell(name).unwrap();
        let load = |kind: &str| {
            let path =
                std::path::Path::new(&dir).join(format!("{}_k{k}_{kind}.dct", name.to_lowercase()));
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let (header, table) = format::from_bytes(&bytes).unwrap();
            header.check_cell_parameters(&cell).unwrap();
            table
        };
        let (shared, clearance) = (load("shared"), load("clearance"));
        report(&format!("{name} k = {k}"), &shared, &clearance, &random_cells(&cell, k, n), cold);
    }
}
