//! `eval`: a table, or a bundle of a line's tables, against the exact physical model
//! (margin 0): true and false positives and negatives on the cell's scenarios and on random
//! reachable configurations, query times, and table mode with the exact confirmation against
//! exact mode in the same run.

use crate::args::EvalArgs;
use crate::{confirm, levels_line, plot, spread, Failure, LINE_SCENARIOS, SCENARIOS};
use delta_collide::cell::exact::{CellVerdict, PairState};
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::cspace::Workspace;
use delta_collide::math::Vec3;
use delta_collide::table::{is_bundle, BundleChecker, Confirmation, TableAnswer, TableChecker};
use std::time::Instant;

/// True/false positives and negatives of the table against the exact model.
#[derive(Default)]
struct Confusion {
    tp: u64,
    tn: u64,
    fp: u64,
    false_neg: u64,
}

impl Confusion {
    fn add(&mut self, table_hit: bool, exact_hit: bool) {
        match (table_hit, exact_hit) {
            (true, true) => self.tp += 1,
            (false, false) => self.tn += 1,
            (true, false) => self.fp += 1,
            (false, true) => self.false_neg += 1,
        }
    }

    fn line(&self, what: &str) -> String {
        let n = (self.tp + self.tn + self.fp + self.false_neg).max(1);
        let acc = 100.0 * (self.tp + self.tn) as f64 / n as f64;
        format!(
            "{what:<28} TP {:>9} TN {:>9} FP {:>9} FN {:>3} accuracy {acc:6.2} %",
            self.tp, self.tn, self.fp, self.false_neg
        )
    }
}

/// `eval`: a two-robot table as the command's help says; a bundle, or any cell of more than
/// two robots, by [`eval_line`].
pub(crate) fn eval(args: &EvalArgs) -> Result<(), Failure> {
    let cell = &args.cell;
    let bytes = std::fs::read(&args.table).map_err(|e| format!("{}: {e}", args.table.display()))?;
    if cell.robots.len() > 2 || is_bundle(&bytes) {
        return eval_line(args, &bytes);
    }
    let mut table = TableChecker::new(cell.clone(), &bytes)
        .map_err(|e| format!("{}: {e}", args.table.display()))?;
    let (n, seed) = (args.random, args.seed);
    let plot = args.plot.as_deref();
    let plot_size = (args.width, args.height);
    let table_name = format!("{} k = {}", table.table().name(), 1u32 << table.table().levels());
    let mut exact = ExactChecker::new(Cell { method: SatMethod::Sat, ..cell.clone() });
    let is_clearance = table.table().as_clearance().is_some();
    let mut ns = Vec::new();
    // The table's answer and the exact verdict; counted in `c` unless a TCP is unreachable.
    let mut compare =
        |tcps: &[Vec3], c: &mut Confusion, ns: &mut Vec<u64>| -> Result<TableAnswer, String> {
            let start = Instant::now();
            let answer = table.check(tcps).map_err(|e| e.to_string())?;
            ns.push(start.elapsed().as_nanos() as u64);
            let v = exact.check(tcps).map_err(|e| e.to_string())?;
            if !matches!(answer, TableAnswer::Unreachable(_)) {
                c.add(answer == TableAnswer::Collision, v.collides());
            }
            Ok(answer)
        };
    let mut tcps = vec![Vec3::zeros(); 2];
    let mut traces = Vec::new();
    for scenario in
        parse_scenarios(SCENARIOS)?.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name))
    {
        let mut c = Confusion::default();
        let mut trace =
            plot.map(|_| plot::Trace::new(cell, format!("{} {}", scenario.cell, scenario.case)));
        for tick in 0..RUN_TICKS {
            scenario.tcps_at(tick, &mut tcps);
            let answer = compare(&tcps, &mut c, &mut ns)?;
            if let Some(t) = trace.as_mut() {
                t.push(&tcps, answer)?;
            }
        }
        println!("{}", c.line(&format!("{} {}", scenario.cell, scenario.case)));
        traces.extend(trace);
    }
    if let Some(path) = plot {
        let title = format!(
            "cell {}, table {} ({table_name}): box distance and labels per tick",
            cell.name,
            args.table.display()
        );
        plot::draw_plot(path, plot_size, &title, &traces)?;
        println!(
            "{}: {} x {} pixels, {} scenarios",
            path.display(),
            plot_size.0,
            plot_size.1,
            traces.len()
        );
    }
    // Random reachable configurations, uniform in the workspace box (xorshift64*, seeded).
    let (mut random, ws) = (RandomTcps(seed), Workspace::THESIS);
    let mut c = Confusion::default();
    let mut kept = 0;
    // A clearance table's bound is timed on the same configurations afterwards.
    let mut kept_tcps = Vec::new();
    while kept < n {
        random.fill(&mut tcps);
        if tcps.iter().all(|t| ws.contains(t))
            && !matches!(compare(&tcps, &mut c, &mut ns)?, TableAnswer::Unreachable(_))
        {
            kept += 1;
            if is_clearance {
                kept_tcps.push([tcps[0], tcps[1]]);
            }
        }
    }
    println!("{}", c.line(&format!("{n} random configurations")));
    ns.sort_unstable();
    println!(
        "table query incl. IK reachability: {}; {} exact fallbacks",
        spread(&ns),
        table.fallbacks()
    );
    if let Some(q) = table.table().as_clearance() {
        let (mut ns, mut per_level) =
            (Vec::with_capacity(kept_tcps.len()), vec![0u64; q.ladder().len() + 1]);
        for tcps in &kept_tcps {
            let start = Instant::now();
            let bound = table.clearance_bound(std::hint::black_box(tcps));
            ns.push(start.elapsed().as_nanos() as u64);
            per_level[bound
                .map_or(0, |b| 1 + q.ladder().mm().iter().position(|&l| l == b).unwrap_or(0))] += 1;
        }
        ns.sort_unstable();
        println!("clearance bound incl. IK reachability: {}", spread(&ns));
        println!("{}", levels_line("random configurations", q, &per_level));
    }
    confirm::report(cell, &table, SCENARIOS)?;
    Ok(())
}

/// Uniform TCPs in the thesis workspace's bounding box, each in its robot's own MCS
/// (xorshift64*, seeded; the caller keeps those inside the workspace).
struct RandomTcps(u64);

impl RandomTcps {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn fill(&mut self, tcps: &mut [Vec3]) {
        let ws = Workspace::THESIS;
        let (rmax, dmax) = (ws.rcy, ws.zu + ws.hcy + ws.hco);
        for t in tcps.iter_mut() {
            *t = Vec3::new(
                rmax * (2.0 * self.unit() - 1.0),
                rmax * (2.0 * self.unit() - 1.0),
                -(ws.zu + (dmax - ws.zu) * self.unit()),
            );
        }
    }
}

/// A line's confusion counts: the whole tick (COLLISION when any pair's answer is) and each
/// pair that can meet.
struct LineConfusion {
    whole: Confusion,
    pairs: Vec<Confusion>,
}

impl LineConfusion {
    fn new(pairs: usize) -> LineConfusion {
        LineConfusion {
            whole: Confusion::default(),
            pairs: (0..pairs).map(|_| Confusion::default()).collect(),
        }
    }

    /// Counts the labels of `table` against the exact verdict `v` of the same TCPs, unless a
    /// TCP is unreachable.
    fn add(&mut self, table: &BundleChecker, v: &CellVerdict) {
        if v.unreachable_mask != 0 {
            return;
        }
        for (c, (p, e)) in self.pairs.iter_mut().zip(table.pairs().iter().zip(&v.pairs)) {
            c.add(p.answer == TableAnswer::Collision, matches!(e.state, PairState::Collides(..)));
        }
        self.whole
            .add(table.pairs().iter().any(|p| p.answer == TableAnswer::Collision), v.collides());
    }

    fn print(&self, what: &str, names: Option<&[String]>) {
        println!("{}", self.whole.line(what));
        for (c, name) in self.pairs.iter().zip(names.unwrap_or_default()) {
            println!("{}", c.line(&format!("  pair {name}")));
        }
    }
}

/// `eval` of a bundle (or a table) on a cell of any number of robots: the labels of every pair
/// that can meet against the exact model of the whole cell (robots at their placements), on
/// the line scenarios of the cell and on random reachable configurations; with `--pairs`, one
/// line per pair. Table mode with the exact confirmation must answer every tick as exact mode
/// (an error otherwise); the three paths are timed tick by tick in the same run.
fn eval_line(args: &EvalArgs, bytes: &[u8]) -> Result<(), Failure> {
    let cell = &args.cell;
    let at = |e: delta_collide::table::TableError| format!("{}: {e}", args.table.display());
    let mut labels = BundleChecker::new(cell.clone(), bytes, Confirmation::None).map_err(at)?;
    let mut confirmed = BundleChecker::new(cell.clone(), bytes, Confirmation::Exact).map_err(at)?;
    let mut exact = ExactChecker::new(Cell { method: SatMethod::Sat, ..cell.clone() });
    let names: Vec<String> = labels
        .pairs()
        .iter()
        .map(|p| format!("{}-{}", cell.robots[p.a].name, cell.robots[p.b].name))
        .collect();
    let names = args.pairs.then_some(names.as_slice());
    let pair_count = labels.pairs().len();
    println!("{pair_count} pairs that can meet, {} tables", labels.table_count());
    let mut ns: [Vec<u64>; 3] = Default::default();
    let mut compare = |tcps: &[Vec3], c: &mut LineConfusion| -> Result<bool, String> {
        let start = Instant::now();
        let label = labels.check(tcps).map_err(|e| e.to_string())?;
        ns[0].push(start.elapsed().as_nanos() as u64);
        let start = Instant::now();
        let answer = confirmed.check(tcps).map_err(|e| e.to_string())?;
        ns[1].push(start.elapsed().as_nanos() as u64);
        let start = Instant::now();
        let v = exact.check(tcps).map_err(|e| e.to_string())?;
        ns[2].push(start.elapsed().as_nanos() as u64);
        let want = match (v.unreachable_mask, v.collides()) {
            (0, true) => TableAnswer::Collision,
            (0, false) => TableAnswer::Free,
            (m, _) => TableAnswer::Unreachable(m),
        };
        if answer != want {
            return Err(format!(
                "table mode with the exact confirmation answered {answer:?}, exact mode {want:?}, at {tcps:?}"
            ));
        }
        c.add(&labels, v);
        Ok(!matches!(label, TableAnswer::Unreachable(_)))
    };
    let mut tcps = vec![Vec3::zeros(); cell.robots.len()];
    let text = [SCENARIOS, LINE_SCENARIOS].concat();
    for scenario in
        parse_scenarios(&text)?.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name))
    {
        let mut c = LineConfusion::new(pair_count);
        for tick in 0..RUN_TICKS {
            scenario.tcps_at(tick, &mut tcps);
            compare(&tcps, &mut c)?;
        }
        c.print(&format!("{} {}", scenario.cell, scenario.case), names);
    }
    let (mut random, mut kept) = (RandomTcps(args.seed), 0);
    let mut c = LineConfusion::new(pair_count);
    while kept < args.random {
        random.fill(&mut tcps);
        if tcps.iter().all(|t| Workspace::THESIS.contains(t)) && compare(&tcps, &mut c)? {
            kept += 1;
        }
    }
    c.print(&format!("{} random configurations", args.random), names);
    for (what, ns) in
        ["table labels", "table mode, exact confirmation", "exact mode"].iter().zip(&mut ns)
    {
        ns.sort_unstable();
        println!("{what:<32} per tick: {}", spread(ns));
    }
    println!("{} ticks confirmed by the exact check", confirmed.confirmations());
    Ok(())
}
