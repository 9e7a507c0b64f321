//! `replay`: a recorded trajectory, one row per controller tick, through the protective
//! verdict (SPEC §8), one output line per tick; with `--plot`, a picture of the run
//! ([`crate::replay_plot`]).

use crate::args::ReplayArgs;
use crate::clearance::{pair_clearances, signed_clearance};
use crate::replay_plot::{draw_replay, ReplayTrace};
use crate::rows::real;
use crate::{load_table_or_bundle, open_input, write_output, Failure, Loaded};
use delta_collide::cell::protective::{
    path_through_samples, Protective, ProtectiveChecker, ProtectiveRequest, ProtectiveStatus,
    StopPath, TickTime,
};
use delta_collide::math::Vec3;
use delta_collide::table::Confirmation;
use std::io::{BufRead, Write};

pub fn replay(args: &ReplayArgs) -> Result<(), Failure> {
    let mut checker =
        ProtectiveChecker::new(args.cell.clone(), args.warn_mm).map_err(|e| e.to_string())?;
    let table = args
        .table
        .as_ref()
        .map(|p| load_table_or_bundle(&args.cell, p, Confirmation::Exact))
        .transpose()?;
    let mut input = open_input(args.input.as_deref())?;
    let names = checker.cell().robots.iter().map(|r| r.name.clone()).collect();
    let mut trace = args.plot.as_ref().map(|_| ReplayTrace::new(names));
    let paths = args
        .stop_path_mm
        .map(|length_mm| PathsAhead { length_mm, tolerance_mm: args.path_tolerance_mm });
    let mut lookups = Lookups::default();
    write_output(args.output.as_deref(), |out| {
        let columns =
            Columns { table: table.as_ref(), paths, pairs: args.pairs, decimals: args.decimals };
        lookups = replay_rows(&mut input, out, &mut checker, columns, trace.as_mut())?;
        Ok(())
    })?;
    if let (Some(path), Some(t)) = (&args.table, &table) {
        let Lookups { ticks: n, pairs, of: ticks } = lookups;
        let share = if ticks > 0 { 100.0 * n as f64 / ticks as f64 } else { 0.0 };
        let kind = if t.has_clearance() { "" } else { " (a boolean table proves no clearance)" };
        // The verdicts may be on stdout: the summary goes to stderr.
        eprintln!(
            "table mode ({}): {n} of {ticks} ticks ({share:.1} %) answered FREE by the lookup alone, \
             {pairs} pairs proved apart by a lookup{kind}",
            path.display()
        );
    }
    if let (Some(path), Some(trace)) = (&args.plot, &trace) {
        let source = args.input.as_ref().map_or("stdin".to_string(), |p| p.display().to_string());
        let title = format!(
            "cell {}, replay of {source}: clearance, protective distances and verdict per tick (WARN below {} mm)",
            checker.cell().name,
            args.warn_mm
        );
        draw_replay(path, (args.width, args.height), &title, trace)?;
        // The verdicts may be on stdout: the note on the picture goes to stderr.
        eprintln!(
            "{}: {} x {} pixels, {} ticks",
            path.display(),
            args.width,
            args.height,
            trace.len()
        );
    }
    Ok(())
}

/// How a replay runs and what it adds to the verdicts: table mode, stop paths from the rows
/// ahead, per-pair clearances.
struct Columns<'a> {
    table: Option<&'a Loaded>,
    paths: Option<PathsAhead>,
    pairs: bool,
    decimals: Option<u8>,
}

/// What the table's lookups answered over a replay: whole ticks, pairs, of all ticks.
#[derive(Default)]
struct Lookups {
    ticks: usize,
    pairs: usize,
    of: usize,
}

/// Each robot's stop path taken from the recorded rows ahead (`replay --stop-path-mm`).
#[derive(Clone, Copy)]
struct PathsAhead {
    length_mm: f64,
    tolerance_mm: f64,
}

/// Most points of a stop path, as a controller passes them.
const PATH_POINTS: usize = delta_collide::cell::protective::MAX_PATH_POINTS;

/// Replays every row of `input` (one tick each) and writes one line per tick on `out`, with
/// stop paths from the rows ahead, table mode and per-pair clearances as `columns` says;
/// records each tick into `trace`. Returns what the table's lookups answered.
///
/// # Errors
/// A row that is not `3 n` numbers (naming its line; the first line may be a header), or a
/// read or write error.
fn replay_rows(
    input: &mut dyn BufRead,
    out: &mut dyn Write,
    checker: &mut ProtectiveChecker,
    Columns { table, paths, pairs, decimals }: Columns<'_>,
    mut trace: Option<&mut ReplayTrace>,
) -> Result<Lookups, String> {
    let bound =
        |a: usize, b: usize, tcps: &[Vec3]| table.and_then(|t| t.clearance_bound(a, b, tcps));
    let mut lookups = Lookups::default();
    let names: Vec<String> = checker.cell().robots.iter().map(|r| r.name.clone()).collect();
    let n = names.len();
    let write_err = |e: std::io::Error| format!("writing the verdicts: {e}");
    let columns = |prefix: &str| names.iter().map(|r| format!(",{prefix}_{r}")).collect::<String>();
    let pair_columns: String = match pairs {
        true => {
            let pairs = &checker.exact().verdict().pairs;
            pairs.iter().map(|p| format!(",clearance_mm_{}_{}", names[p.a], names[p.b])).collect()
        }
        false => String::new(),
    };
    let (protective, limits) = (columns("protective_mm"), columns("speed_limit_mm_s"));
    writeln!(out, "tick,verdict,clearance_mm,status{protective}{limits}{pair_columns}")
        .map_err(write_err)?;
    let (mut rows, mut ticks): (Vec<Vec<Vec3>>, Vec<String>) = (Vec::new(), Vec::new());
    // Each row's cycle: its tick when it is a whole number, else its row number.
    let mut cycles: Vec<u64> = Vec::new();
    crate::rows::for_each_row(input, n, |_, tick, tcps| {
        cycles.push(tick.and_then(|t| t.trim().parse().ok()).unwrap_or(rows.len() as u64));
        ticks.push(tick.map_or_else(|| rows.len().to_string(), str::to_string));
        rows.push(tcps.to_vec());
        Ok(())
    })?;
    // Per robot, its TCPs tick by tick: the samples ahead of a tick are a slice of these.
    let runs: Vec<Vec<Vec3>> = if paths.is_some() {
        (0..n).map(|j| rows.iter().map(|r| r[j]).collect()).collect()
    } else {
        Vec::new()
    };
    let mut points = vec![[Vec3::zeros(); PATH_POINTS]; n];
    for (tick, tcps) in rows.iter().enumerate() {
        // Robot j's samples ahead: its TCP in this row and the rows that follow.
        let lens: Vec<Option<usize>> = match paths {
            Some(p) => (0..n)
                .map(|j| {
                    path_through_samples(
                        &runs[j][tick..],
                        p.length_mm,
                        p.tolerance_mm,
                        &mut points[j],
                    )
                })
                .collect(),
            None => Vec::new(),
        };
        let tolerance_mm = paths.map_or(0.0, |p| p.tolerance_mm);
        let stop_paths: Vec<Option<StopPath>> = lens
            .iter()
            .zip(&points)
            .map(|(len, pts)| len.map(|len| StopPath { points: &pts[..len], tolerance_mm }))
            .collect();
        let mut request =
            ProtectiveRequest::new(tcps).at(TickTime::Cycle(cycles[tick])).with_paths(&stop_paths);
        if table.is_some() {
            request = request.with_table(&bound);
        }
        checker.check(request).map_err(|e| format!("row {tick}: {e}"))?;
        let r = checker.report();
        lookups.ticks += usize::from(r.table_lookup);
        lookups.pairs += r.table_pairs as usize;
        if let Some(t) = trace.as_deref_mut() {
            // The exact check under the verdict ran only when the status is OK.
            let ok = r.status == ProtectiveStatus::Ok;
            t.push(r, ok.then(|| signed_clearance(checker.exact())).flatten());
        }
        let verdict = match r.verdict {
            Protective::Free => "free",
            Protective::Warn => "warn",
            Protective::Stop => "stop",
        };
        let status = match r.status {
            ProtectiveStatus::Ok => "ok".to_string(),
            ProtectiveStatus::NonFinite(j) => format!("non-finite {}", names[j]),
            ProtectiveStatus::ImplausibleMotion(j) => format!("implausible {}", names[j]),
            ProtectiveStatus::Unreachable(j) => format!("unreachable {}", names[j]),
            ProtectiveStatus::InvalidPath(j) => format!("invalid path {}", names[j]),
            ProtectiveStatus::Timing(fault) => format!("timing {fault:?}").to_lowercase(),
        };
        let num = |v: f64| real(v, decimals);
        let mut row = format!("{},{verdict},{},{status}", ticks[tick], num(r.clearance_mm));
        r.robots.iter().for_each(|x| row += &format!(",{}", num(x.protective_mm)));
        r.robots.iter().for_each(|x| row += &format!(",{}", num(x.speed_limit_mm_s)));
        if pairs {
            let ok = r.status == ProtectiveStatus::Ok;
            match ok.then(|| pair_clearances(checker.exact())).flatten() {
                Some(c) => c.iter().for_each(|d| row += &format!(",{}", num(*d))),
                None => (0..checker.exact().verdict().pairs.len()).for_each(|_| row += ",NA"),
            }
        }
        writeln!(out, "{row}").map_err(write_err)?;
    }
    lookups.of = rows.len();
    Ok(lookups)
}
