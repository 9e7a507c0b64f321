//! `replay`: a recorded trajectory, one row per controller tick, through the protective
//! verdict (SPEC §8), one output line per tick; with `--plot`, a picture of the run
//! ([`crate::replay_plot`]).

use crate::args::ReplayArgs;
use crate::clearance::signed_clearance;
use crate::replay_plot::{draw_replay, ReplayTrace};
use crate::{open_input, write_output, Failure};
use delta_collide::cell::protective::{Protective, ProtectiveChecker, ProtectiveStatus};
use std::io::{BufRead, Write};

pub fn replay(args: &ReplayArgs) -> Result<(), Failure> {
    let mut checker = ProtectiveChecker::new(args.cell.clone(), args.warn_mm).map_err(|e| e.to_string())?;
    let mut input = open_input(args.input.as_deref())?;
    let names = checker.cell().robots.iter().map(|r| r.name.clone()).collect();
    let mut trace = args.plot.as_ref().map(|_| ReplayTrace::new(names));
    write_output(args.output.as_deref(), |out| replay_rows(&mut input, out, &mut checker, trace.as_mut()))?;
    if let (Some(path), Some(trace)) = (&args.plot, &trace) {
        let source = args.input.as_ref().map_or("stdin".to_string(), |p| p.display().to_string());
        let title = format!(
            "cell {}, replay of {source}: clearance, protective distances and verdict per tick (WARN below {} mm)",
            checker.cell().name,
            args.warn_mm
        );
        draw_replay(path, (args.width, args.height), &title, trace)?;
        // The verdicts may be on stdout: the note on the picture goes to stderr.
        eprintln!("{}: {} x {} pixels, {} ticks", path.display(), args.width, args.height, trace.len());
    }
    Ok(())
}

/// Replays every row of `input` (one tick each) and writes one line per tick on `out`;
/// records each tick into `trace` when given.
///
/// # Errors
/// A row that is not `3 n` numbers (naming its line; the first line may be a header), or a
/// read or write error.
fn replay_rows(
    input: &mut dyn BufRead,
    out: &mut dyn Write,
    checker: &mut ProtectiveChecker,
    mut trace: Option<&mut ReplayTrace>,
) -> Result<(), String> {
    let names: Vec<String> = checker.cell().robots.iter().map(|r| r.name.clone()).collect();
    let n = names.len();
    let write_err = |e: std::io::Error| format!("writing the verdicts: {e}");
    let columns = |prefix: &str| names.iter().map(|r| format!(",{prefix}_{r}")).collect::<String>();
    writeln!(out, "tick,verdict,status,clearance_mm{}{}", columns("protective_mm"), columns("speed_limit_mm_s"))
        .map_err(write_err)?;
    let mut tick = 0u64;
    crate::rows::for_each_row(input, n, |line_no, tcps| {
        checker.check(tcps).map_err(|e| format!("line {line_no}: {e}"))?;
        let r = checker.report();
        if let Some(t) = trace.as_deref_mut() {
            // The exact check under the verdict ran only when the status is OK.
            let ok = r.status == ProtectiveStatus::Ok;
            t.push(r, ok.then(|| signed_clearance(checker.exact())).flatten());
        }
        let verdict = match r.verdict {
            Protective::Free => "FREE",
            Protective::Warn => "WARN",
            Protective::Stop => "STOP",
        };
        let status = match r.status {
            ProtectiveStatus::Ok => "ok".to_string(),
            ProtectiveStatus::NonFinite(j) => format!("non-finite {}", names[j]),
            ProtectiveStatus::ImplausibleMotion(j) => format!("implausible {}", names[j]),
            ProtectiveStatus::Unreachable(j) => format!("unreachable {}", names[j]),
            ProtectiveStatus::InvalidPath(j) => format!("invalid path {}", names[j]),
        };
        let mut row = format!("{tick},{verdict},{status},{:.3}", r.clearance_mm);
        r.robots.iter().for_each(|x| row += &format!(",{:.3}", x.protective_mm));
        r.robots.iter().for_each(|x| row += &format!(",{:.1}", x.speed_limit_mm_s));
        writeln!(out, "{row}").map_err(write_err)?;
        tick += 1;
        Ok(())
    })
}
