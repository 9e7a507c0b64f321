//! `replay`: a recorded trajectory, one row per controller tick, through the protective
//! verdict (SPEC §8), one output line per tick.

use crate::args::ReplayArgs;
use crate::{open_input, write_output, Failure};
use delta_collide::cell::protective::{Protective, ProtectiveChecker, ProtectiveStatus};
use std::io::{BufRead, Write};

pub fn replay(args: &ReplayArgs) -> Result<(), Failure> {
    let mut checker = ProtectiveChecker::new(args.cell.clone(), args.warn_mm).map_err(|e| e.to_string())?;
    let mut input = open_input(args.input.as_deref())?;
    write_output(args.output.as_deref(), |out| replay_rows(&mut input, out, &mut checker))?;
    Ok(())
}

/// Replays every row of `input` (one tick each) and writes one line per tick on `out`.
///
/// # Errors
/// A row that is not `3 n` numbers (naming its line; the first line may be a header), or a
/// read or write error.
fn replay_rows(input: &mut dyn BufRead, out: &mut dyn Write, checker: &mut ProtectiveChecker) -> Result<(), String> {
    let names: Vec<String> = checker.cell().robots.iter().map(|r| r.name.clone()).collect();
    let n = names.len();
    let write_err = |e: std::io::Error| format!("writing the verdicts: {e}");
    let columns = |prefix: &str| names.iter().map(|r| format!(",{prefix}_{r}")).collect::<String>();
    writeln!(out, "tick,verdict,status,clearance_mm{}{}", columns("protective_mm"), columns("speed_limit_mm_s"))
        .map_err(write_err)?;
    let mut tick = 0u64;
    crate::rows::for_each_row(input, n, |line_no, tcps| {
        let r = checker.check(tcps).map_err(|e| format!("line {line_no}: {e}"))?;
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
        };
        let mut row = format!("{tick},{verdict},{status},{:.3}", r.clearance_mm);
        r.robots.iter().for_each(|x| row += &format!(",{:.3}", x.protective_mm));
        r.robots.iter().for_each(|x| row += &format!(",{:.1}", x.speed_limit_mm_s));
        writeln!(out, "{row}").map_err(write_err)?;
        tick += 1;
        Ok(())
    })
}
