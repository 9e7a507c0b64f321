//! The delta-collide command line: runs the thesis's scenarios, checks CSV files of
//! configurations, and (with tables) builds, inspects and evaluates precomputed tables.
//!
//! ```text
//! delta-collide demo  [--cell T1|T2|T3|all|FILE.toml]
//! delta-collide check --cell T1|FILE.toml [--input FILE.csv] [--output FILE.csv]
//! ```

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, Scenario, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::math::Vec3;
use std::io::{BufRead, BufWriter, Write};
use std::time::Instant;

/// The scenario file shared with the C harness.
const SCENARIOS: &str = include_str!("../../c_harness/scenarios.txt");

const USAGE: &str = "usage:
  delta-collide demo  [--cell T1|T2|T3|all|FILE.toml]
      runs the practical and collision scenarios (c_harness/scenarios.txt) with SAT and
      SAT-cache; prints the first collision tick and per-tick query times
  delta-collide check --cell T1|T2|T3|FILE.toml [--input FILE.csv] [--output FILE.csv]
      reads rows x,y,z,x2,y2,z2 (one TCP per robot, each in its own MCS; stdin by default),
      writes one line `reachable,collide` per row (stdout by default); collide is NA when a
      TCP is unreachable";

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("demo") => demo(&args[1..]),
        Some("check") => check(&args[1..]),
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
    println!("delta-collide {} demo: exact check (SAT on the box model), {RUN_TICKS} ticks of 1 ms per run", env!("CARGO_PKG_VERSION"));
    println!("per-tick query time = 2 IK + box models + pair tests, measured with Instant (includes ~20 ns timer overhead)");
    println!("{:<4} {:<10} {:<9} {:>15} {:>15} {:>10} {:>10} {:>10}", "cell", "case", "method", "first collision", "collision ticks", "median ns", "p99 ns", "max ns");
    for cell in &cells {
        let cases: Vec<&Scenario> = scenarios.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name)).collect();
        if cases.is_empty() {
            return Err(format!("no scenario for cell {} in c_harness/scenarios.txt", cell.name));
        }
        for scenario in cases {
            if scenario.robots.len() != cell.robots.len() {
                return Err(format!("scenario {} {} has {} robots, the cell {}", scenario.cell, scenario.case, scenario.robots.len(), cell.robots.len()));
            }
            for (name, method) in [("SAT", SatMethod::Sat), ("SAT-cache", SatMethod::SatCache)] {
                let r = run(&with_method(cell, method), scenario)?;
                let first = r.first_collision.map_or("none".to_string(), |t| format!("tick {t}"));
                println!(
                    "{:<4} {:<10} {:<9} {:>15} {:>15} {:>10} {:>10} {:>10}",
                    cell.name, scenario.case, name, first, r.collision_ticks,
                    percentile(&r.ns, 0.5), percentile(&r.ns, 0.99), r.ns[r.ns.len() - 1]
                );
            }
        }
    }
    Ok(())
}

fn check(args: &[String]) -> Result<(), String> {
    known_options(args, &["--cell", "--input", "--output"])?;
    let cell = load_cell(option(args, "--cell")?.ok_or("check needs --cell")?)?;
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
        let parsed: Result<(), ()> = line.split(',').try_for_each(|f| f.trim().parse::<f64>().map(|v| values.push(v)).map_err(|_| ()));
        if parsed.is_err() && line_no == 0 {
            continue; // a header row
        }
        if parsed.is_err() || values.len() != 3 * n {
            return Err(format!("line {}: expected {} numbers (x,y,z per robot), got `{line}`", line_no + 1, 3 * n));
        }
        for (j, t) in tcps.iter_mut().enumerate() {
            *t = Vec3::new(values[3 * j], values[3 * j + 1], values[3 * j + 2]);
        }
        let v = checker.check(&tcps).map_err(|e| e.to_string())?;
        let row = if !v.all_reachable() { "0,NA\n" } else if v.collides() { "1,1\n" } else { "1,0\n" };
        out.write_all(row.as_bytes()).map_err(write_err)?;
    }
    out.flush().map_err(write_err)
}
