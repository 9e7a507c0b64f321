//! `eval`'s report of table mode with confirmation (a COLLISION lookup answered by the exact
//! check) against exact mode, on the cell's scenarios: confirmed ticks, and per-tick times of
//! both paths measured in the same run, tick by tick, on the same TCPs.

use crate::percentile;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::math::Vec3;
use delta_collide::table::{Confirmation, TableAnswer, TableChecker};
use std::hint::black_box;
use std::time::Instant;

/// Times each scenario tick is answered by each path (more rounds: steadier tails).
pub(crate) const ROUNDS: u32 = 50;

/// Median, p99.9 and max of `ns`, sorted here.
fn spread(ns: &mut [u64]) -> String {
    ns.sort_unstable();
    format!(
        "median {} p99.9 {} max {}",
        percentile(ns, 0.5),
        percentile(ns, 0.999),
        ns[ns.len() - 1]
    )
}

/// The exact verdict in the table's terms.
fn exact_answer(exact: &mut ExactChecker, tcps: &[Vec3]) -> Result<TableAnswer, String> {
    let v = exact.check(tcps).map_err(|e| e.to_string())?;
    Ok(match (v.unreachable_mask, v.collides()) {
        (0, true) => TableAnswer::Collision,
        (0, false) => TableAnswer::Free,
        (m, _) => TableAnswer::Unreachable(m),
    })
}

/// Prints one line per scenario of `cell`: ticks confirmed in one pass, and the per-tick
/// times (ns, clock read included) of `table` with [`Confirmation::Exact`] and of exact mode
/// (the cell's SAT method), each tick answered [`ROUNDS`] times by both, alternating which
/// goes first.
///
/// # Errors
/// A scenario file error, a query error, or a tick on which the two paths answer differently.
pub(crate) fn report(cell: &Cell, table: &TableChecker, scenarios: &str) -> Result<(), String> {
    let mut tcps = vec![Vec3::zeros(); 2];
    for scenario in
        parse_scenarios(scenarios)?.iter().filter(|s| s.cell.eq_ignore_ascii_case(&cell.name))
    {
        let mut confirmed = table.clone();
        confirmed.set_confirmation(Confirmation::Exact);
        let mut exact = ExactChecker::new(cell.clone());
        let (mut table_ns, mut exact_ns) = (Vec::new(), Vec::new());
        let mut ticks_confirmed = 0;
        for round in 0..ROUNDS {
            let before = confirmed.confirmations();
            for tick in 0..RUN_TICKS {
                scenario.tcps_at(tick, &mut tcps);
                let mut timed_table = || {
                    let start = Instant::now();
                    let answer = confirmed.check(black_box(&tcps)).map_err(|e| e.to_string());
                    (start.elapsed().as_nanos() as u64, answer)
                };
                let mut timed_exact = || {
                    let start = Instant::now();
                    let answer = exact_answer(&mut exact, black_box(&tcps));
                    (start.elapsed().as_nanos() as u64, answer)
                };
                let ((nt, a), (ne, e)) = if tick % 2 == 0 {
                    let t = timed_table();
                    (t, timed_exact())
                } else {
                    let e = timed_exact();
                    (timed_table(), e)
                };
                let (a, e) = (a?, e?);
                if a != e {
                    return Err(format!(
                        "{} {} tick {tick}: table mode with confirmation says {a:?}, exact mode {e:?}",
                        scenario.cell, scenario.case
                    ));
                }
                table_ns.push(nt);
                exact_ns.push(ne);
            }
            if round == 0 {
                ticks_confirmed = confirmed.confirmations() - before;
            }
        }
        println!(
            "{} {} with confirmation: {ticks_confirmed} of {RUN_TICKS} ticks confirmed, same verdict as exact mode on \
             every tick; per tick over {ROUNDS} rounds (ns): table+confirm {}, exact {}",
            scenario.cell,
            scenario.case,
            spread(&mut table_ns),
            spread(&mut exact_ns)
        );
    }
    Ok(())
}
