//! `demo`: the practical and collision scenarios of each chosen cell, first with the exact
//! check (SAT and SAT-cache: first collision, collision ticks, per-tick query times), then
//! with the protective verdict (SPEC §8) along the same runs: first WARN and STOP, their
//! counts, and whether a stop issued at the first STOP stays clear ([`crate::stop`]).

use crate::args::DemoArgs;
use crate::stop::simulate_stop;
use crate::{percentile, Failure, LINE_SCENARIOS, SCENARIOS};
use delta_collide::cell::protective::{Protective, ProtectiveChecker};
use delta_collide::cell::trajectory::{parse_scenarios, Scenario, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker, SatMethod};
use delta_collide::math::Vec3;
use std::time::Instant;

/// The WARN threshold of the demo's protective runs (mm): the C ABI's default.
const WARN_MM: f64 = delta_collide::cell::protective::DEFAULT_WARN_MM;

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
    let mut r = RunResult {
        first_collision: None,
        collision_ticks: 0,
        ns: Vec::with_capacity(RUN_TICKS as usize),
    };
    for tick in 0..RUN_TICKS {
        scenario.tcps_at(tick, &mut tcps);
        let start = Instant::now();
        let v = checker.check(&tcps).map_err(|e| e.to_string())?;
        let (reachable, collides) = (v.all_reachable(), v.collides());
        r.ns.push(start.elapsed().as_nanos() as u64);
        if !reachable {
            return Err(format!(
                "{} {}: a TCP is unreachable at tick {tick}",
                scenario.cell, scenario.case
            ));
        }
        if collides {
            r.collision_ticks += 1;
            r.first_collision.get_or_insert(tick);
        }
    }
    r.ns.sort_unstable();
    Ok(r)
}

pub fn demo(args: &DemoArgs) -> Result<(), Failure> {
    let mut scenarios = parse_scenarios(SCENARIOS)?;
    scenarios.extend(parse_scenarios(LINE_SCENARIOS)?);
    let cells = &args.cell.0;
    println!(
        "delta-collide {} demo: exact check (SAT on the box model), {RUN_TICKS} ticks of 1 ms per run",
        env!("CARGO_PKG_VERSION")
    );
    println!(
        "per-tick query time = IK and boxes of every robot + pair tests, measured with Instant (includes ~20 ns timer overhead)"
    );
    println!(
        "{:<4} {:<10} {:<9} {:>15} {:>15} {:>10} {:>10} {:>10}",
        "cell",
        "case",
        "method",
        "first collision",
        "collision ticks",
        "median ns",
        "p99 ns",
        "max ns"
    );
    for cell in cells {
        let cases: Vec<&Scenario> =
            scenarios.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name)).collect();
        if cases.is_empty() {
            return Err(format!(
                "no scenario for cell {} in c_harness/scenarios.txt or line_scenarios.txt",
                cell.name
            )
            .into());
        }
        for scenario in cases {
            if scenario.robots.len() != cell.robots.len() {
                return Err(Failure::Failed(format!(
                    "scenario {} {} has {} robots, the cell {}",
                    scenario.cell,
                    scenario.case,
                    scenario.robots.len(),
                    cell.robots.len()
                )));
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
    protective_table(cells, &scenarios)
}

/// The protective verdict along one scenario, without stopping (so its counts compare with
/// the exact run's), and the stop simulated from its first STOP.
struct ProtectiveRun {
    first_warn: Option<u32>,
    first_stop: Option<u32>,
    warn_ticks: u32,
    stop_ticks: u32,
    /// Each tick's time (ns), sorted once the run ends.
    ns: Vec<u64>,
}

fn protective_run(cell: &Cell, scenario: &Scenario) -> Result<ProtectiveRun, String> {
    // The speed limits are not shown here; without them a tick takes under a third of the time.
    let mut checker = ProtectiveChecker::new(cell.clone(), WARN_MM)
        .map_err(|e| e.to_string())?
        .with_speed_limits(false);
    let mut tcps = vec![Vec3::zeros(); cell.robots.len()];
    // Start-up, as in the C harness: the robots stand at their first waypoint, which gives the
    // first tick a measured speed instead of the full speed assumed without history.
    scenario.tcps_at(0, &mut tcps);
    checker.check(&tcps).map_err(|e| e.to_string())?;
    let mut r = ProtectiveRun {
        first_warn: None,
        first_stop: None,
        warn_ticks: 0,
        stop_ticks: 0,
        ns: Vec::new(),
    };
    for tick in 0..RUN_TICKS {
        scenario.tcps_at(tick, &mut tcps);
        let start = Instant::now();
        let verdict = checker.check(&tcps).map_err(|e| e.to_string())?.verdict;
        r.ns.push(start.elapsed().as_nanos() as u64);
        match verdict {
            Protective::Free => {}
            Protective::Warn => {
                r.warn_ticks += 1;
                r.first_warn.get_or_insert(tick);
            }
            Protective::Stop => {
                r.stop_ticks += 1;
                r.first_stop.get_or_insert(tick);
            }
        }
    }
    r.ns.sort_unstable();
    Ok(r)
}

fn protective_table(cells: &[Cell], scenarios: &[Scenario]) -> Result<(), Failure> {
    println!();
    println!(
        "protective verdict (SPEC section 8) along the same runs: the cell's stopping models, WARN below {WARN_MM} mm \
         to spare; at the first STOP a stop is simulated (each robot keeps its motion for its reaction time, then \
         brakes along its path) and checked with the exact model every 0.1 ms"
    );
    println!(
        "{:<4} {:<10} {:>10} {:>10} {:>10} {:>10} {:>14} {:>8} {:>11} {:>10}",
        "cell",
        "case",
        "first WARN",
        "first STOP",
        "WARN ticks",
        "STOP ticks",
        "simulated stop",
        "stop ms",
        "closest mm",
        "median us"
    );
    let tick = |t: Option<u32>| t.map_or("none".to_string(), |t| t.to_string());
    for cell in cells {
        for scenario in scenarios.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name)) {
            let r = protective_run(cell, scenario)?;
            let (outcome, stop_ms, closest) = match r.first_stop {
                Some(t) => {
                    let s = simulate_stop(cell, scenario, t)?;
                    let outcome = if s.contacts == 0 {
                        "clear".to_string()
                    } else {
                        format!("TOUCHES({})", s.contacts)
                    };
                    (outcome, format!("{:.1}", s.stop_ms), format!("{:.1}", s.closest_mm))
                }
                None => ("none".to_string(), "-".to_string(), "-".to_string()),
            };
            println!(
                "{:<4} {:<10} {:>10} {:>10} {:>10} {:>10} {:>14} {:>8} {:>11} {:>10}",
                cell.name,
                scenario.case,
                tick(r.first_warn),
                tick(r.first_stop),
                r.warn_ticks,
                r.stop_ticks,
                outcome,
                stop_ms,
                closest,
                format!("{:.2}", percentile(&r.ns, 0.5) as f64 * 1e-3)
            );
        }
    }
    Ok(())
}
