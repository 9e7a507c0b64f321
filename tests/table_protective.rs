//! The protective verdict in table mode (SPEC §8; clearance tables, SPEC §6) against brute
//! force: every tick answered FREE by the clearance table's lookup alone
//! (`ProtectiveReport::table_lookup`) is followed by random stops within the stopping model,
//! checked with the exact model every 0.1 ms (the oracle of `tests/protective.rs`), and by the
//! stop that comes closest, searched (the adversary of `tests/protective_adversary.rs`), and
//! none may bring two boxes into contact: random states in the open, next to the reach boundary
//! and with TCPs on the table's grid-cell faces (where the level changes), and the reference
//! runs. The reported clearance of a lookup tick never exceeds the exact one; a boolean table
//! changes no verdict; a tick allocates nothing. The clearance tables are certified, at
//! k = 16 (a few seconds per cell, built once per test process and shared by the tests; at
//! k = 32 the clearance labelling takes a minute per cell).

use delta_collide::cell::parse_cell;
use delta_collide::cell::protective::{
    ClearanceBound, Protective, ProtectiveChecker, ProtectiveRequest, ProtectiveStatus,
};
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, Scenario, RUN_TICKS};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::cspace::{Progress, Workspace};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::StopModel;
use delta_collide::table::bundle::build_bundle;
use delta_collide::table::{
    build_table, pair_cell, to_bytes, BundleChecker, Confirmation, Labelling, Ladder, TableChecker,
    Variant,
};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::sync::OnceLock;

mod protective_common;
use protective_common::adversary::{worst_stop, Robot};
use protective_common::{
    allocations, assert_stops_never_touch, cell, tcp_toward_other, unit, STIFF,
};

/// Resolution of the tables built here (SPEC §4: r = 33.125 mm).
const K: u32 = 16;

/// The bytes of the certified clearance table (default ladder of levels) and of the boolean
/// shared 6-D table of reference cell `name` at [`K`], built once (the stopping models are
/// no part of a table: one serves every model).
fn table_bytes(name: &str) -> &'static [Vec<u8>; 2] {
    static BYTES: [OnceLock<[Vec<u8>; 2]>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    let c = ["T1", "T2", "T3"].iter().position(|n| *n == name).unwrap();
    BYTES[c].get_or_init(|| {
        let cell = reference_cell(name).unwrap();
        let build = |variant| {
            let (header, table, _) = build_table(
                &cell,
                K,
                &Workspace::THESIS,
                variant,
                Labelling::Certified,
                Progress::Silent,
            )
            .unwrap();
            to_bytes(&table, &header)
        };
        [build(Variant::Clearance(Ladder::default_ladder())), build(Variant::Shared)]
    })
}

/// The clearance table (or the boolean one) of `cell`, a reference cell with any stopping
/// models, loaded.
fn table(cell: &Cell, clearance: bool) -> TableChecker {
    TableChecker::new(cell.clone(), &table_bytes(&cell.name)[usize::from(!clearance)]).unwrap()
}

/// A reachable TCP of robot `j` (MCS): half of them out toward the other robot, half
/// anywhere in the working depth.
fn tcp_anywhere(cell: &Cell, j: usize, rng: &mut StdRng) -> Vec3 {
    if rng.random::<bool>() {
        return tcp_toward_other(cell, j, rng);
    }
    loop {
        let p = Vec3::new(
            rng.random_range(-320.0..320.0),
            rng.random_range(-320.0..320.0),
            rng.random_range(-560.0..-350.0),
        );
        if cell.robots[j].model.delta.is_reachable(&p) {
            return p;
        }
    }
}

/// A reachable TCP of robot `j` within 0 to 8 mm of its reach boundary, pushed out radially
/// from [`tcp_anywhere`] (elbows swing fastest there).
fn tcp_at_reach_boundary(cell: &Cell, j: usize, rng: &mut StdRng) -> Vec3 {
    protective_common::pushed_to_reach_boundary(cell, j, rng, tcp_anywhere)
}

/// Where the random states are drawn.
#[derive(Clone, Copy, Debug)]
enum Place {
    /// Out toward the other robot or anywhere.
    Open,
    /// Within 8 mm of the reach boundary, where elbows swing fastest.
    ReachBoundary,
    /// As `Open`, every coordinate moved onto a face of its table grid cell (within 1e-7 mm
    /// either side), where the stored level changes.
    CellFaces,
}

/// Robot `j`'s TCP at `place`.
fn sample(cell: &Cell, table: &TableChecker, j: usize, place: Place, rng: &mut StdRng) -> Vec3 {
    match place {
        Place::Open => tcp_anywhere(cell, j, rng),
        Place::ReachBoundary => tcp_at_reach_boundary(cell, j, rng),
        Place::CellFaces => loop {
            let h = table.header();
            let origin = if j == 0 { h.origin_a } else { h.origin_b };
            let mut p = tcp_anywhere(cell, j, rng);
            for a in 0..3 {
                let u = ((p[a] - origin[a]) / h.r).round();
                p[a] = origin[a] + u * h.r + rng.random_range(-1e-7..1e-7);
            }
            if cell.robots[j].model.delta.is_reachable(&p) {
                return p;
            }
        },
    }
}

/// Random states of `cell` at `place` (speeds mostly low, directions random), each checked
/// in table mode after one tick that gives its speeds; from every state answered by the
/// lookup alone, 8 random stops are simulated. Returns (lookup states, exact checks).
fn brute_force(
    cell: &Cell,
    table: &TableChecker,
    warn_mm: Real,
    place: Place,
    states: usize,
    seed: u64,
) -> (usize, usize) {
    let bound = |_: usize, _: usize, t: &[Vec3]| table.clearance_bound(t);
    let mut checker =
        ProtectiveChecker::new(cell.clone(), warn_mm).unwrap().with_speed_limits(false);
    let mut exact = ExactChecker::new(cell.clone());
    let mut rng = StdRng::seed_from_u64(seed);
    let stop = cell.stops[0];
    let tick = cell.tick_ms * 1e-3;
    let (mut lookups, mut steps) = (0, 0);
    for _ in 0..states {
        let tcps =
            [sample(cell, table, 0, place, &mut rng), sample(cell, table, 1, place, &mut rng)];
        let v_fd: [Vec3; 2] = std::array::from_fn(|_| {
            unit(&mut rng) * stop.max_speed_mm_s * rng.random::<Real>().powi(3)
        });
        let prev = [tcps[0] - v_fd[0] * tick, tcps[1] - v_fd[1] * tick];
        checker.reset();
        checker.check(ProtectiveRequest::new(&prev).with_table(&bound)).unwrap();
        let r = checker.check(ProtectiveRequest::new(&tcps).with_table(&bound)).unwrap().clone();
        if !r.table_lookup {
            continue;
        }
        assert_eq!((r.verdict, r.status), (Protective::Free, ProtectiveStatus::Ok), "{tcps:?}");
        let truth = protective_common_clearance(&mut exact, &tcps);
        // The report's clearance starts from the last tick's features (`CoherentClearance`):
        // the exact value to rounding, not bit for bit the one computed from scratch.
        assert!(
            r.clearance_mm <= truth + 1e-9 && r.clearance_mm > warn_mm,
            "{} vs exact {truth}: {tcps:?}",
            r.clearance_mm
        );
        lookups += 1;
        let vel = v_fd.map(|v| {
            let w = v + unit(&mut rng) * stop.max_accel_mm_s2 * tick * rng.random::<Real>();
            w * (stop.max_speed_mm_s / w.norm()).min(1.0)
        });
        steps += assert_stops_never_touch(cell, &tcps, &vel, 8, &mut rng);
        // The stop that comes closest, searched (`tests/protective_adversary.rs`).
        let robots = std::array::from_fn(|j| Robot {
            tcp: tcps[j],
            v_fd: v_fd[j],
            stop,
            tick_s: tick,
            interval_s: tick,
        });
        let (least, at) = worst_stop(cell, &robots, 100, &mut rng);
        assert!(
            least > 0.0,
            "a stop after a lookup FREE reaches clearance {least} mm at {at:?} from {tcps:?}"
        );
    }
    (lookups, steps)
}

/// The exact signed clearance of `cell` at `tcps` (SPEC §8).
fn protective_common_clearance(exact: &mut ExactChecker, tcps: &[Vec3; 2]) -> Real {
    exact.check(tcps).unwrap();
    delta_collide::cell::protective::clearance_now(exact).0
}

#[test]
fn lookup_free_verdicts_survive_simulated_stops() {
    let mut total = [0usize; 3];
    for (i, name) in ["T1", "T2", "T3"].iter().enumerate() {
        for (k, stop) in [STIFF, StopModel::DEFAULT].into_iter().enumerate() {
            let cell = cell(name, stop);
            let table = table(&cell, true);
            // The reach boundary yields fewest lookups (elbows move far): more states there.
            for (p, (place, states)) in
                [(Place::Open, 1_000), (Place::ReachBoundary, 10_000), (Place::CellFaces, 1_000)]
                    .into_iter()
                    .enumerate()
            {
                // warn_mm 0: the lookup proves FREE with the least to spare.
                let seed = 900 + 10 * i as u64 + k as u64 + 100 * p as u64;
                let (lookups, steps) = brute_force(&cell, &table, 0.0, place, states, seed);
                println!(
                    "{name} model {k} {place:?}: {lookups} of {states} states FREE by the lookup, {steps} exact checks"
                );
                total[p] += lookups;
            }
        }
    }
    println!("FREE by the lookup (open, reach boundary, cell faces): {total:?}");
    assert!(
        total[0] >= 50 && total[1] >= 5 && total[2] >= 50,
        "too few lookup states to test: {total:?}"
    );
}

/// One run in exact and table mode side by side: verdict counts of each, ticks FREE by the
/// lookups alone, pairs proved by a lookup, and ticks tested with simulated stops.
#[derive(Default)]
struct SideBySide {
    counts: [[u32; 3]; 2],
    lookups: u64,
    pairs: u64,
    tested: u64,
}

impl SideBySide {
    fn line(&self) -> String {
        let c = &self.counts;
        format!(
            "exact mode STOP {} WARN {}; table mode STOP {} WARN {}, {} ticks ({:.1} %) by the lookups alone, {} pairs proved by a lookup",
            c[0][2],
            c[0][1],
            c[1][2],
            c[1][1],
            self.lookups,
            100.0 * self.lookups as f64 / RUN_TICKS as f64,
            self.pairs
        )
    }
}

/// `scenario` on `cell` (every robot with stopping model `stop`) in exact and table mode side
/// by side. Every FREE tick a lookup took part in (`table_pairs`: the pairs the table's
/// bound proved; the proof took the others) reports a clearance at most the exact one (which
/// the exact-mode checker reports on the same tick); at every fifth one, and at every fifth
/// tick FREE by a proof kept since (a lookup keeps its balls as a proof does), random stops
/// from the true velocities (the finite difference moved within `a_max T`) and the stop that
/// comes closest (searched) never touch, each
/// pair that can meet checked as its pair cell (the two robots where they stand relative to
/// each other: a two-robot cell's own pair, a line's as its bundle reduces it, whose soundness
/// `tests/bundles.rs` checks against the whole line).
fn side_by_side(
    cell: &Cell,
    bound: ClearanceBound,
    s: &Scenario,
    stop: StopModel,
    rng: &mut StdRng,
) -> SideBySide {
    let n = cell.robots.len();
    let tick = cell.tick_ms * 1e-3;
    let mut exact = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
    let mut lookup = ProtectiveChecker::new(cell.clone(), 10.0).unwrap().with_speed_limits(false);
    let (mut tcps, mut prev) = (vec![Vec3::zeros(); n], vec![Vec3::zeros(); n]);
    let mut out = SideBySide::default();
    // Whether every tick since the last lookup was FREE (a kept proof may be its).
    let (mut since_lookup, mut candidates) = (false, 0u64);
    for t in 0..RUN_TICKS {
        s.tcps_at(t, &mut tcps);
        let e = exact.check(&tcps).unwrap().clone();
        let r = lookup.check(ProtectiveRequest::new(&tcps).with_table(bound)).unwrap();
        out.counts[0][e.verdict as usize] += 1;
        out.counts[1][r.verdict as usize] += 1;
        out.pairs += u64::from(r.table_pairs);
        let looked_up = r.table_pairs > 0 && r.verdict == Protective::Free;
        since_lookup = (since_lookup || looked_up) && r.verdict == Protective::Free;
        if looked_up || (since_lookup && r.kept_proof) {
            assert_eq!((r.verdict, r.status), (Protective::Free, ProtectiveStatus::Ok));
            let (case, got, want) = (&s.case, r.clearance_mm, e.clearance_mm);
            assert!(got <= want, "{} {case} tick {t}: {got} > {want}", cell.name);
            out.lookups += u64::from(r.table_lookup);
            candidates += 1;
            if candidates % 5 == 0 {
                let vel: Vec<Vec3> = (0..n)
                    .map(|j| {
                        let w = (tcps[j] - prev[j]) / tick
                            + unit(rng) * stop.max_accel_mm_s2 * tick * rng.random::<Real>();
                        w * (stop.max_speed_mm_s / w.norm()).min(1.0)
                    })
                    .collect();
                for (a, b) in cell.pairs_that_can_meet() {
                    let pair = pair_cell(cell, a, b);
                    assert_stops_never_touch(&pair, &[tcps[a], tcps[b]], &[vel[a], vel[b]], 4, rng);
                    let robot = |j: usize| Robot {
                        tcp: tcps[j],
                        v_fd: (tcps[j] - prev[j]) / tick,
                        stop,
                        tick_s: tick,
                        interval_s: tick,
                    };
                    let (least, at) = worst_stop(&pair, &[robot(a), robot(b)], 100, rng);
                    let (name, case) = (&cell.name, &s.case);
                    assert!(
                        least > 0.0,
                        "{name} {case} tick {t}: a stop reaches clearance {least} mm at {at:?}"
                    );
                }
                out.tested += 1;
            }
        }
        prev.clone_from(&tcps);
    }
    out
}

/// Per reference run (T1-T3, practical and collision) and model: [`side_by_side`]. Returns
/// the ticks FREE by the lookup alone and the ticks tested with simulated stops.
fn runs(stop: StopModel, label: &str) -> (u64, u64) {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let scenarios = parse_scenarios(&text).unwrap();
    let mut rng = StdRng::seed_from_u64(11);
    let (mut lookups, mut tested) = (0, 0);
    for name in ["T1", "T2", "T3"] {
        let cell = cell(name, stop);
        let table = table(&cell, true);
        let bound = |_: usize, _: usize, t: &[Vec3]| table.clearance_bound(t);
        for s in scenarios.iter().filter(|s| s.cell == name) {
            let run = side_by_side(&cell, &bound, s, stop, &mut rng);
            println!("{label} {name} {:<9}: {}", s.case, run.line());
            assert!(
                run.counts[1][2] <= run.counts[0][2],
                "table mode stops more often than exact mode"
            );
            (lookups, tested) = (lookups + run.lookups, tested + run.tested);
        }
    }
    (lookups, tested)
}

/// Table mode never stops a reference run more often than exact mode. Its lookups come after
/// the proofs kept for wider balls, which settle almost every tick of these smooth runs, so
/// the lookups rarely answer here: `lookup_free_verdicts_survive_simulated_stops` and the
/// line's test are where they are tested hardest.
#[test]
fn lookup_ticks_of_the_reference_runs_are_sound() {
    let (stiff, tested_stiff) = runs(STIFF, "stiff");
    let (default, tested_default) = runs(StopModel::DEFAULT, "default");
    println!("lookup ticks: stiff {stiff} ({tested_stiff} with simulated stops), default {default} ({tested_default})");
}

/// A boolean table proves no clearance: table mode then gives every verdict of exact mode,
/// with no lookup tick.
#[test]
fn a_boolean_table_changes_nothing() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/c_harness/scenarios.txt"))
            .unwrap();
    let s = parse_scenarios(&text)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == "practical")
        .unwrap();
    let cell = cell("T1", STIFF);
    let table = table(&cell, false);
    let bound = |_: usize, _: usize, t: &[Vec3]| table.clearance_bound(t);
    let mut exact = ProtectiveChecker::new(cell.clone(), 10.0).unwrap();
    let mut lookup = ProtectiveChecker::new(cell.clone(), 10.0).unwrap();
    let mut tcps = [Vec3::zeros(); 2];
    for t in 0..1_500 {
        s.tcps_at(t, &mut tcps);
        let e = exact.check(&tcps).unwrap().clone();
        assert_eq!(
            lookup.check(ProtectiveRequest::new(&tcps).with_table(&bound)).unwrap(),
            &e,
            "tick {t}"
        );
    }
}

/// Table-mode ticks allocate nothing: random states of T3 with TCPs on grid-cell faces, each
/// a tick that gives the speeds and the tick checked (where lookups answer: see
/// `lookup_free_verdicts_survive_simulated_stops`).
#[test]
fn a_table_mode_tick_never_allocates() {
    let cell = cell("T3", STIFF);
    let table = table(&cell, true);
    let bound = |_: usize, _: usize, t: &[Vec3]| table.clearance_bound(t);
    let mut rng = StdRng::seed_from_u64(5);
    let tick = cell.tick_ms * 1e-3;
    let states: Vec<[[Vec3; 2]; 2]> = (0..2_000)
        .map(|_| {
            let tcps = [0, 1].map(|j| sample(&cell, &table, j, Place::CellFaces, &mut rng));
            let v = [0, 1].map(|_| {
                unit(&mut rng) * STIFF.max_speed_mm_s * rng.random::<Real>().powi(3) * tick
            });
            [[tcps[0] - v[0], tcps[1] - v[1]], tcps]
        })
        .collect();
    let mut c = ProtectiveChecker::new(cell, 10.0).unwrap().with_speed_limits(false);
    let before = allocations();
    let mut lookups = 0;
    for [prev, tcps] in &states {
        c.reset();
        c.check(ProtectiveRequest::new(prev).with_table(&bound)).unwrap();
        lookups += c.check(ProtectiveRequest::new(tcps).with_table(&bound)).unwrap().table_pairs;
    }
    assert_eq!(allocations(), before);
    assert!(lookups > 10, "{lookups} pairs proved by a lookup: the lookup path was not exercised");
}

#[test]
fn the_c_counter_reads_zero_for_null() {
    // SAFETY: NULL is a documented argument (the counter reads 0).
    assert_eq!(unsafe { delta_collide::ffi::dc_table_protective_lookups(std::ptr::null()) }, 0);
}

/// The line of four (`cells/line4.toml`, stiff models) in table mode from the bundle of its
/// clearance tables (one per spacing), beside exact mode, on both line cases
/// ([`side_by_side`]). A neighbour pair is always close, so the lookups prove pairs, not
/// whole ticks; table mode never stops more often than exact mode.
#[test]
fn a_line_in_table_mode_stops_in_time() {
    let line = parse_cell(include_str!("../cells/line4.toml"))
        .unwrap()
        .with_stopping(1.0, vec![STIFF; 4])
        .unwrap();
    let ladder = Variant::Clearance(Ladder::default_ladder());
    let built =
        build_bundle(&line, K, &Workspace::THESIS, ladder, Labelling::Certified, Progress::Silent)
            .unwrap();
    let bundle = BundleChecker::new(line.clone(), &built.bytes, Confirmation::Exact).unwrap();
    assert!(bundle.has_clearance());
    let bound = |a: usize, b: usize, t: &[Vec3]| bundle.clearance_bound(a, b, t);
    let mut rng = StdRng::seed_from_u64(23);
    let (mut pairs, mut tested) = (0, 0);
    for s in &parse_scenarios(include_str!("../c_harness/line_scenarios.txt")).unwrap() {
        let run = side_by_side(&line, &bound, s, STIFF, &mut rng);
        println!("line4 {:<9}: {}", s.case, run.line());
        assert!(
            run.counts[1][2] <= run.counts[0][2],
            "table mode stops more often than exact mode"
        );
        (pairs, tested) = (pairs + run.pairs, tested + run.tested);
    }
    println!("{tested} ticks tested with simulated stops");
    assert!(pairs >= 100, "the line's runs have few pairs proved by a lookup: {pairs}");
}
