//! The delta-collide command line: runs the thesis's scenarios, checks CSV files of
//! configurations, and (with tables) builds, inspects and evaluates precomputed tables.
//!
//! ```text
//! delta-collide demo  [--cell T1|T2|T3|all|FILE.toml]
//! delta-collide check --cell T1|FILE.toml [--table FILE.dct] [--input FILE.csv] [--output FILE.csv]
//! delta-collide build --cell T1|FILE.toml --output FILE.dct [--k 32] [--variant 6d|5d|4d-yy|4d-zz|shared|shared-sub] [--t 0] [--labelling certified|thesis]
//! delta-collide inspect FILE.dct
//! delta-collide eval  --cell T1|FILE.toml --table FILE.dct [--random N] [--seed S] [--plot FILE.png]
//! delta-collide render --cell T1|FILE.toml --tcp x,y,z --tcp x,y,z [--output FILE.png]
//! delta-collide quilt --cell T1|FILE.toml --table FILE.dct [--axes yy|zz|xx] [--fix i,j] [--a ix,iy,iz] [--output FILE.png]
//! ```
//!
//! The pictures (`render`, `quilt`, `eval --plot`) are PNG files drawn in-process (modules
//! [`render`], [`quilt`], [`plot`]; shared parts in [`picture`]).

mod picture;
mod plot;
mod quilt;
mod render;

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, Scenario, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::cspace::Workspace;
use delta_collide::math::Vec3;
use delta_collide::table::{
    build_table, from_bytes, to_bytes, Labelling, SliceAxes, Table, TableAnswer, TableChecker, Variant,
};
use std::io::{BufRead, BufWriter, Write};
use std::time::Instant;

/// The scenario file shared with the C harness.
const SCENARIOS: &str = include_str!("../../../c_harness/scenarios.txt");

const USAGE: &str = "usage:
  delta-collide demo  [--cell T1|T2|T3|all|FILE.toml]
      runs the practical and collision scenarios (c_harness/scenarios.txt) with SAT and
      SAT-cache; prints the first collision tick and per-tick query times
  delta-collide check --cell T1|T2|T3|FILE.toml [--table FILE.dct] [--input FILE.csv] [--output FILE.csv]
      reads rows x,y,z,x2,y2,z2 (one TCP per robot, each in its own MCS; stdin by default),
      writes one line `reachable,collide` per row (stdout by default); collide is NA when a
      TCP is unreachable; with --table the answers come from the table
  delta-collide build --cell T1|FILE.toml --output FILE.dct [--k 32] [--variant 6d|5d|4d-yy|4d-zz|shared|shared-sub]
                      [--t 0] [--labelling certified|thesis]
      samples, labels (certified per-cell bounds by default) and builds a table file
  delta-collide inspect FILE.dct
      prints what a table file holds
  delta-collide eval --cell T1|FILE.toml --table FILE.dct [--random N] [--seed S] [--plot FILE.png]
                     [--width W] [--height H]
      compares the table with the exact physical model (margin 0) on the cell's scenarios and
      on N random reachable configurations: TP, TN, FP, FN, accuracy, query times; --plot
      draws, per scenario and tick, the distance between the robots' boxes and the labels
      reported by the table and by the exact model
  delta-collide render --cell T1|FILE.toml --tcp x,y,z --tcp x,y,z [--output render.png]
                       [--width 1400] [--height 700]
      draws the cell at one configuration (one --tcp per robot, each in its own MCS) in top
      and side view: every box of the model, the colliding ones in red
  delta-collide quilt --cell T1|FILE.toml --table FILE.dct [--axes yy|zz|xx] [--fix i,j]
                      [--output quilt.png] [--width 1200] [--height 1200]
  delta-collide quilt --cell T1|FILE.toml --table FILE.dct --a ix,iy,iz [--output quilt.png]
      draws the table's 2-D slices as in the thesis's Figures 3.16-3.17: --axes yy puts
      yy'-slices in a quilt over (z, z'), zz puts zz'-slices in a quilt over (y, y'), xx puts
      xx'-slices over (z, z'); --fix gives the grid indices of the remaining pair (default: half
      the workspace radius toward the other robot). With --a, A's grid cell is fixed and each
      panel is an x'y'-slice of B's grid at one depth z'. Black: collision, white: free, orange:
      a cell proved unreachable (don't care), grey: outside the sampled grid";

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("demo") => demo(&args[1..]),
        Some("check") => check(&args[1..]),
        Some("build") => build(&args[1..]),
        Some("inspect") => inspect(&args[1..]),
        Some("eval") => eval(&args[1..]),
        Some("render") => render::render(&args[1..]),
        Some("quilt") => quilt::quilt(&args[1..]),
        Some("-h" | "--help" | "help") => {
            println!("{USAGE}");
            Ok(())
        }
        _ => Err(format!("unknown or missing command\n{USAGE}")),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}

/// The value of `--name` in `args`, if given.
fn option<'a>(args: &'a [String], name: &str) -> Result<Option<&'a str>, String> {
    match args.iter().position(|a| a == name) {
        Some(i) => args.get(i + 1).map(|v| Some(v.as_str())).ok_or(format!("{name} needs a value")),
        None => Ok(None),
    }
}

/// Refuses options the command does not know (a typo never passes silently).
fn known_options(args: &[String], known: &[&str]) -> Result<(), String> {
    let mut i = 0;
    while i < args.len() {
        if !known.contains(&args[i].as_str()) {
            return Err(format!("unknown argument `{}`\n{USAGE}", args[i]));
        }
        i += 2;
    }
    Ok(())
}

/// A reference cell by name, or a cell file.
fn load_cell(spec: &str) -> Result<Cell, String> {
    reference_cell(spec).map_or_else(|| Cell::from_file(std::path::Path::new(spec)).map_err(|e| e.to_string()), Ok)
}

fn with_method(cell: &Cell, method: SatMethod) -> Cell {
    Cell { method, ..cell.clone() }
}

/// Per-tick timings of one run: nanoseconds, sorted.
struct RunResult {
    first_collision: Option<u32>,
    collision_ticks: u32,
    ns: Vec<u64>,
}

fn run(cell: &Cell, scenario: &Scenario) -> Result<RunResult, String> {
    let mut checker = ExactChecker::new(cell.clone());
    let mut tcps = vec![Vec3::zeros(); cell.robots.len()];
    let mut r = RunResult { first_collision: None, collision_ticks: 0, ns: Vec::with_capacity(RUN_TICKS as usize) };
    for tick in 0..RUN_TICKS {
        scenario.tcps_at(tick, &mut tcps);
        let start = Instant::now();
        let v = checker.check(&tcps).map_err(|e| e.to_string())?;
        let (reachable, collides) = (v.all_reachable(), v.collides());
        r.ns.push(start.elapsed().as_nanos() as u64);
        if !reachable {
            return Err(format!("{} {}: a TCP is unreachable at tick {tick}", scenario.cell, scenario.case));
        }
        if collides {
            r.collision_ticks += 1;
            r.first_collision.get_or_insert(tick);
        }
    }
    r.ns.sort_unstable();
    Ok(r)
}

fn percentile(sorted: &[u64], p: f64) -> u64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn demo(args: &[String]) -> Result<(), String> {
    known_options(args, &["--cell"])?;
    let which = option(args, "--cell")?.unwrap_or("T1");
    let scenarios = parse_scenarios(SCENARIOS)?;
    let cells: Vec<Cell> = if which.eq_ignore_ascii_case("all") {
        ["T1", "T2", "T3"].iter().filter_map(|n| reference_cell(n)).collect()
    } else {
        vec![load_cell(which)?]
    };
    println!(
        "delta-collide {} demo: exact check (SAT on the box model), {RUN_TICKS} ticks of 1 ms per run",
        env!("CARGO_PKG_VERSION")
    );
    println!(
        "per-tick query time = 2 IK + box models + pair tests, measured with Instant (includes ~20 ns timer overhead)"
    );
    println!(
        "{:<4} {:<10} {:<9} {:>15} {:>15} {:>10} {:>10} {:>10}",
        "cell", "case", "method", "first collision", "collision ticks", "median ns", "p99 ns", "max ns"
    );
    for cell in &cells {
        let cases: Vec<&Scenario> = scenarios.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name)).collect();
        if cases.is_empty() {
            return Err(format!("no scenario for cell {} in c_harness/scenarios.txt", cell.name));
        }
        for scenario in cases {
            if scenario.robots.len() != cell.robots.len() {
                return Err(format!(
                    "scenario {} {} has {} robots, the cell {}",
                    scenario.cell,
                    scenario.case,
                    scenario.robots.len(),
                    cell.robots.len()
                ));
            }
            for (name, method) in [("SAT", SatMethod::Sat), ("SAT-cache", SatMethod::SatCache)] {
                let r = run(&with_method(cell, method), scenario)?;
                let first = r.first_collision.map_or("none".to_string(), |t| format!("tick {t}"));
                println!(
                    "{:<4} {:<10} {:<9} {:>15} {:>15} {:>10} {:>10} {:>10}",
                    cell.name,
                    scenario.case,
                    name,
                    first,
                    r.collision_ticks,
                    percentile(&r.ns, 0.5),
                    percentile(&r.ns, 0.99),
                    r.ns[r.ns.len() - 1]
                );
            }
        }
    }
    Ok(())
}

fn check(args: &[String]) -> Result<(), String> {
    known_options(args, &["--cell", "--table", "--input", "--output"])?;
    let cell = load_cell(option(args, "--cell")?.ok_or("check needs --cell")?)?;
    let mut table = option(args, "--table")?.map(|p| load_table(&cell, p)).transpose()?;
    let n = cell.robots.len();
    let input: Box<dyn BufRead> = match option(args, "--input")? {
        Some(p) => Box::new(std::io::BufReader::new(std::fs::File::open(p).map_err(|e| format!("{p}: {e}"))?)),
        None => Box::new(std::io::stdin().lock()),
    };
    let output: Box<dyn Write> = match option(args, "--output")? {
        Some(p) => Box::new(std::fs::File::create(p).map_err(|e| format!("{p}: {e}"))?),
        None => Box::new(std::io::stdout().lock()),
    };
    let mut out = BufWriter::with_capacity(1 << 16, output);
    let mut checker = ExactChecker::new(cell);
    let mut tcps = vec![Vec3::zeros(); n];
    let mut values = Vec::with_capacity(3 * n);
    let write_err = |e: std::io::Error| e.to_string();
    writeln!(out, "reachable,collide").map_err(write_err)?;
    for (line_no, line) in input.lines().enumerate() {
        let line = line.map_err(|e| e.to_string())?;
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        values.clear();
        let parsed: Result<(), ()> =
            line.split(',').try_for_each(|f| f.trim().parse::<f64>().map(|v| values.push(v)).map_err(|_| ()));
        if parsed.is_err() && line_no == 0 {
            continue; // a header row
        }
        if parsed.is_err() || values.len() != 3 * n {
            return Err(format!("line {}: expected {} numbers (x,y,z per robot), got `{line}`", line_no + 1, 3 * n));
        }
        for (j, t) in tcps.iter_mut().enumerate() {
            *t = Vec3::new(values[3 * j], values[3 * j + 1], values[3 * j + 2]);
        }
        let answer = match table.as_mut() {
            Some(t) => t.check(&tcps),
            None => checker.check(&tcps).map(exact_answer),
        };
        let row = match answer.map_err(|e| e.to_string())? {
            TableAnswer::Unreachable(_) => "0,NA\n",
            TableAnswer::Collision => "1,1\n",
            TableAnswer::Free => "1,0\n",
        };
        out.write_all(row.as_bytes()).map_err(write_err)?;
    }
    out.flush().map_err(write_err)
}

/// The exact verdict in the table's terms.
fn exact_answer(v: &delta_collide::cell::CellVerdict) -> TableAnswer {
    match (v.unreachable_mask, v.collides()) {
        (0, true) => TableAnswer::Collision,
        (0, false) => TableAnswer::Free,
        (m, _) => TableAnswer::Unreachable(m),
    }
}

fn load_table(cell: &Cell, path: &str) -> Result<TableChecker, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    TableChecker::new(cell.clone(), &bytes).map_err(|e| format!("{path}: {e}"))
}

fn parse_num<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> Result<T, String> {
    option(args, name)?.map_or(Ok(default), |v| v.parse().map_err(|_| format!("{name} {v}: not a number")))
}

fn build(args: &[String]) -> Result<(), String> {
    known_options(args, &["--cell", "--output", "--k", "--variant", "--t", "--labelling"])?;
    let cell = load_cell(option(args, "--cell")?.ok_or("build needs --cell")?)?;
    let output = option(args, "--output")?.ok_or("build needs --output FILE.dct")?;
    let k: u32 = parse_num(args, "--k", 32)?;
    let t: u32 = parse_num(args, "--t", 0)?;
    let variant = match option(args, "--variant")?.unwrap_or("6d") {
        "6d" => Variant::D6,
        "5d" => Variant::D5,
        "4d-yy" => Variant::D4 { axes: SliceAxes::YY, t },
        "4d-zz" => Variant::D4 { axes: SliceAxes::ZZ, t },
        "shared" => Variant::Shared,
        "shared-sub" => Variant::SharedSubdivided,
        v => return Err(format!("--variant {v}: use 6d, 5d, 4d-yy, 4d-zz, shared or shared-sub")),
    };
    let labelling = match option(args, "--labelling")?.unwrap_or("certified") {
        "certified" => Labelling::Certified,
        "thesis" => Labelling::ThesisMargin,
        v => return Err(format!("--labelling {v}: use certified or thesis")),
    };
    let (header, table, r) = build_table(&cell, k, &Workspace::THESIS, variant, labelling, true)?;
    let bytes = to_bytes(&table, &header);
    std::fs::write(output, &bytes).map_err(|e| format!("{output}: {e}"))?;
    println!("cell {} k {k}: {} x {} samples, {} pairs", cell.name, r.samples.0, r.samples.1, r.pairs);
    let unreachable = match labelling {
        Labelling::Certified => "cell proved unreachable (don't care)",
        Labelling::ThesisMargin => "unreachable centre (stored as collision)",
    };
    println!(
        "labels ({labelling:?}): {} collision, {} {unreachable}, symmetric: {}",
        r.collisions, r.unreachable, r.symmetric
    );
    println!("labelling {:.2} s, building {:.2} s", r.label_secs, r.build_secs);
    println!(
        "{output}: {} ({} bytes in memory, {} bytes on disk)",
        describe(&table),
        table.memory_bytes(),
        bytes.len()
    );
    Ok(())
}

/// Variant, sizes and thesis-formula bytes of a table.
fn describe(table: &Table) -> String {
    match table {
        Table::D6(q) => {
            format!("{}: {} location codes, thesis formula {} bytes", table.name(), q.codes().len(), q.thesis_bytes())
        }
        Table::D5(q) => format!("{}: thesis formula {} bytes", table.name(), q.thesis_bytes()),
        Table::D4(q) => format!("{}: {} slices", table.name(), q.slice_count()),
        Table::Shared(q) => format!("{}: nodes per depth then leaves {:?}", table.name(), q.nodes_per_depth()),
    }
}

fn inspect(args: &[String]) -> Result<(), String> {
    let path = args.first().ok_or("inspect needs a table file")?;
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    let (h, table) = from_bytes(&bytes).map_err(|e| format!("{path}: {e}"))?;
    println!("{path}: {} bytes", bytes.len());
    println!("table: {}", describe(&table));
    println!("k {} (levels {}), r {} mm, symmetric {}", 1u32 << table.levels(), table.levels(), h.r, table.symmetric());
    println!("cell fingerprint {:#018x}, margin {} mm ({:?})", h.cell_fingerprint, h.margin, h.certification);
    println!("grid origins A {:?} B {:?}; workspace {:?}", h.origin_a, h.origin_b, h.workspace);
    println!("memory {} bytes", table.memory_bytes());
    Ok(())
}

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

fn eval(args: &[String]) -> Result<(), String> {
    known_options(args, &["--cell", "--table", "--random", "--seed", "--plot", "--width", "--height"])?;
    let cell = load_cell(option(args, "--cell")?.ok_or("eval needs --cell")?)?;
    let table_path = option(args, "--table")?.ok_or("eval needs --table FILE.dct")?;
    let mut table = load_table(&cell, table_path)?;
    let n: u64 = parse_num(args, "--random", 1_000_000)?;
    let mut seed: u64 = parse_num(args, "--seed", 1)?;
    let plot = option(args, "--plot")?;
    let plot_size = picture::size_option(args, (1400, 900), (500, 400))?;
    let table_name = format!("{} k = {}", table.table().name(), 1u32 << table.table().levels());
    let mut exact = ExactChecker::new(Cell { method: SatMethod::Sat, ..cell.clone() });
    let mut ns = Vec::new();
    // The table's answer and the exact verdict; counted in `c` unless a TCP is unreachable.
    let mut compare = |tcps: &[Vec3], c: &mut Confusion, ns: &mut Vec<u64>| -> Result<TableAnswer, String> {
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
    for scenario in parse_scenarios(SCENARIOS)?.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name)) {
        let mut c = Confusion::default();
        let mut trace = plot.map(|_| plot::Trace::new(&cell, format!("{} {}", scenario.cell, scenario.case)));
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
        let title = format!("cell {}, table {table_path} ({table_name}): box distance and labels per tick", cell.name);
        plot::draw_plot(path, plot_size, &title, &traces)?;
        println!("{path}: {} x {} pixels, {} scenarios", plot_size.0, plot_size.1, traces.len());
    }
    // Random reachable configurations, uniform in the workspace box (xorshift64*, seeded).
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    };
    let ws = Workspace::THESIS;
    let (rmax, dmax) = (ws.rcy, ws.zu + ws.hcy + ws.hco);
    let mut c = Confusion::default();
    let mut kept = 0;
    while kept < n {
        for t in tcps.iter_mut() {
            *t =
                Vec3::new(rmax * (2.0 * next() - 1.0), rmax * (2.0 * next() - 1.0), -(ws.zu + (dmax - ws.zu) * next()));
        }
        if tcps.iter().all(|t| ws.contains(t))
            && !matches!(compare(&tcps, &mut c, &mut ns)?, TableAnswer::Unreachable(_))
        {
            kept += 1;
        }
    }
    println!("{}", c.line(&format!("{n} random configurations")));
    ns.sort_unstable();
    println!(
        "table query incl. IK reachability: median {} ns, p99.9 {} ns, max {} ns over {} queries; {} exact fallbacks",
        percentile(&ns, 0.5),
        percentile(&ns, 0.999),
        ns[ns.len() - 1],
        ns.len(),
        table.fallbacks()
    );
    Ok(())
}
