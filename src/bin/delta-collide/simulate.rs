//! `simulate`: the closed-loop benchmark (`delta_collide::sim`) on one cell, one table row per
//! run and mode, and a summary per mode.

use crate::args::SimulateArgs;
use delta_collide::cell::protective::Protective;
use delta_collide::coord::{CoordinationConfig, RightOfWay};
use delta_collide::sim::cells::conflict_cells;
use delta_collide::sim::run::{run_traced, Trace};
use delta_collide::sim::{programmes, Mode, ProgrammeConfig, Rng, SimConfig};
use std::io::Write;

/// Runs the benchmark and prints its figures.
pub fn simulate(a: &SimulateArgs) -> Result<(), String> {
    let modes: Vec<Mode> = match a.mode.as_str() {
        "all" => Mode::ALL.to_vec(),
        name => vec![Mode::ALL.into_iter().find(|m| m.name() == name).ok_or(format!(
            "--mode {name}: expected coordinate, limits, interlock, free or all"
        ))?],
    };
    let programme =
        ProgrammeConfig { ticks: a.ticks, gap_mm: a.gap_mm, ..ProgrammeConfig::default() };
    let right_of_way = match a.right_of_way.as_str() {
        "arrival" => RightOfWay::Arrival,
        _ => RightOfWay::Programmed,
    };
    let coordination = CoordinationConfig {
        clearance_mm: a.clearance_mm,
        right_of_way,
        ..CoordinationConfig::default()
    };
    println!(
        "cell {}: {} robots, {} runs from seed {}, stop paths {}",
        a.cell.name,
        a.cell.robots.len(),
        a.runs,
        a.seed,
        if a.paths { "on" } else { "off" }
    );
    println!(
        "{:<11} {:>4} {:>10} {:>6} {:>5} {:>8} {:>8} {:>14} {:>24} {:>18} {:>12}",
        "mode",
        "run",
        "throughput",
        "stops",
        "dead",
        "contact",
        "finished",
        "FREE/WARN/STOP",
        "ours med/p99/max us",
        "exact med/p99/max",
        "work max/out"
    );
    let last = modes.len() - 1;
    for (m, mode) in modes.into_iter().enumerate() {
        let config = SimConfig {
            mode,
            paths: a.paths,
            coordination,
            path_work: a.path_work,
            ..SimConfig::default()
        };
        let mut kept = Vec::new();
        for r in 0..a.runs {
            let seed = a.seed + u64::from(r);
            let progs = programmes(&a.cell, &programme, &mut Rng::new(seed));
            let first = r == 0 && m == last;
            let plot = a.plot.as_ref().filter(|_| first);
            let csv = a.trace.as_ref().filter(|_| first);
            let mut trace = Trace::default();
            let traced = (plot.is_some() || csv.is_some()).then_some(&mut trace);
            let m = run_traced(&a.cell, &progs, &config, traced);
            if let Some(path) = csv {
                let text = trace_csv(&trace, a.cell.robots.len());
                crate::files::write_file(path, |out| {
                    out.write_all(text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
                })?;
            }
            if let (Some(path), Some(&pair)) = (plot, a.cell.pairs_that_can_meet().first()) {
                let cells = conflict_cells(&a.cell, &progs, pair, 8, a.clearance_mm);
                let names = (&*a.cell.robots[pair.0].name, &*a.cell.robots[pair.1].name);
                let title = format!(
                    "{}, seed {seed}, {}{}: coordination diagram of {} and {}",
                    a.cell.name,
                    mode.name(),
                    if a.paths { " with stop paths" } else { "" },
                    names.0,
                    names.1
                );
                crate::diagram_plot::draw_diagram(path, &title, names, pair, &cells, &trace)?;
            }
            let us = |t: &delta_collide::sim::Timings| {
                format!(
                    "{:.1}/{:.1}/{:.1}",
                    t.median as f64 / 1e3,
                    t.p99 as f64 / 1e3,
                    t.max as f64 / 1e3
                )
            };
            println!(
                "{:<11} {:>4} {:>9.1}% {:>6} {:>5} {:>8} {:>8} {:>14} {:>24} {:>18} {:>12}",
                mode.name(),
                seed,
                100.0 * m.throughput,
                m.stop_events,
                u8::from(m.deadlock),
                m.contact_ticks + m.contact_stop_samples,
                m.finished,
                format!("{}/{}/{}", m.verdicts[0], m.verdicts[1], m.verdicts[2]),
                us(&m.ours_ns),
                us(&m.exact_ns),
                format!("{}/{}", m.path_work_max, m.path_work_spent),
            );
            kept.push(m);
        }
        let worst = kept.iter().map(|m| m.throughput).fold(f64::INFINITY, f64::min);
        println!(
            "{:<11} all  least {:.1}%, {} STOP events, {} deadlocks, {} contacts",
            mode.name(),
            100.0 * worst,
            kept.iter().map(|m| m.stop_events).sum::<usize>(),
            kept.iter().filter(|m| m.deadlock).count(),
            kept.iter().map(|m| m.contact_ticks + m.contact_stop_samples).sum::<usize>(),
        );
    }
    Ok(())
}

/// The trace file (`--trace`): a header, then one row per tick of the loop.
fn trace_csv(trace: &Trace, n: usize) -> String {
    let mut out = String::from("tick");
    for key in ["progress", "override", "coordination", "held_by", "limit_mm_s"] {
        for j in 0..n {
            out.push_str(&format!(",{key}_{j}"));
        }
    }
    out.push_str(",verdict,clearance_mm\n");
    for t in &trace.ticks {
        out.push_str(&t.tick.to_string());
        for column in [&t.progress, &t.override_now, &t.coordination] {
            column.iter().for_each(|x| out.push_str(&format!(",{x:.4}")));
        }
        for h in &t.held_by {
            out.push_str(&h.map_or(",".to_string(), |j| format!(",{j}")));
        }
        t.limit_mm_s.iter().for_each(|x| out.push_str(&format!(",{x:.1}")));
        let verdict = match t.verdict {
            Protective::Free => "FREE",
            Protective::Warn => "WARN",
            Protective::Stop => "STOP",
        };
        out.push_str(&format!(",{verdict},{:.3}\n", t.clearance_mm));
    }
    out
}
