//! The closed-loop benchmark in its short form (`delta_collide::sim`; the full one is
//! `delta-collide simulate`): the coordination on seeded programmes of a reference cell and of
//! a cell nothing is tuned on, and on adversarial programmes written here (both robots
//! heading for the same place point, a robot stopped on the other's path, three robots in a
//! row). Contact is checked by the exact model every tick and every 0.2 ms of every simulated
//! stop; none may occur in any run. Liveness (no deadlock, every programme finished) is
//! asserted where the coordination reaches it today: the seeded runs of T1 and the
//! adversarial programmes under the arrival order, no deadlock under the programmed order on
//! R60 and D380, and 75 % of the throughput kept under it on T1-T3 and H80; elsewhere it is
//! printed, not asserted: there a STOP at standstill can hold the robots for good
//! (docs/record/2026-12-02-path-limits.md).

use delta_collide::cell::protective::Protective;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::minimum_jerk;
use delta_collide::cell::{parse_cell, Cell};
use delta_collide::coord::{CoordinationConfig, RightOfWay};
use delta_collide::math::{Real, Vec3};
use delta_collide::sim::run::{run, run_traced, Trace};
use delta_collide::sim::{
    programmes, Mode, ProgrammeConfig, Programmes, Rng, RunMetrics, SimConfig,
};

fn config(mode: Mode) -> SimConfig {
    SimConfig { mode, ..SimConfig::default() }
}

fn assert_safe(what: &str, m: &RunMetrics) {
    assert_eq!(m.contact_ticks + m.contact_stop_samples, 0, "{what}: contact: {m:?}");
}

/// Liveness too under the arrival order (the adversaries below meet as timed, where the
/// programmed order cannot keep them moving: [`coordinations`]).
fn assert_safe_and_live_under_arrival(rule: &str, what: &str, m: &RunMetrics) {
    if rule == "arrival order" {
        assert_safe_and_live(what, m);
    } else {
        assert_safe(what, m);
    }
}

fn assert_safe_and_live(what: &str, m: &RunMetrics) {
    assert_safe(what, m);
    assert!(!m.deadlock, "{what}: deadlock: {m:?}");
    assert!(m.finished, "{what}: unfinished: {m:?}");
}

#[test]
fn runs_never_touch_anywhere_and_finish_on_t1() {
    let cells =
        [reference_cell("T1").unwrap(), parse_cell(include_str!("../cells/r60.toml")).unwrap()];
    let programme = ProgrammeConfig { ticks: 1500, ..ProgrammeConfig::default() };
    for cell in &cells {
        for seed in [11, 12] {
            let progs = programmes(cell, &programme, &mut Rng::new(seed));
            for mode in [Mode::Coordinate, Mode::Interlock, Mode::Limits] {
                let m = run(cell, &progs, &config(mode));
                println!("{} seed {seed} {}: {m:?}", cell.name, mode.name());
                let what = format!("{} seed {seed} {}", cell.name, mode.name());
                if cell.name == "T1" {
                    assert_safe_and_live(&what, &m);
                } else {
                    assert_safe(&what, &m);
                }
            }
        }
    }
}

/// Robot `j`'s MCS point of the WCS point `p`.
fn mcs(cell: &Cell, j: usize, p: Vec3) -> Vec3 {
    let pl = &cell.robots[j].placement;
    pl.rotation().transpose() * (p - pl.t)
}

/// Panics unless robot `j` of `cell` reaches every point of `prog` (an unreachable set-point
/// would make the coordination hold the robot before it, and the adversary toothless).
fn reachable(cell: &Cell, j: usize, prog: &[Vec3]) {
    let exact = delta_collide::cell::ExactChecker::new(cell.clone());
    let mut boxes = delta_collide::robot::RobotBoxes::empty();
    for (t, p) in prog.iter().enumerate() {
        assert!(exact.boxes_in_wcs(j, p, &mut boxes).is_ok(), "robot {j} cannot reach {p:?} ({t})");
    }
}

/// Both rules of coordination: the arrival and the programmed order (at the programmes'
/// clearance). The programmes below meet as timed, where the programmed order keeps the
/// robots near their timing and the protective verdict stops them (module doc of `coord`):
/// for it only safety is asserted.
fn coordinations() -> [(&'static str, SimConfig); 2] {
    let programmed = CoordinationConfig {
        clearance_mm: 10.0,
        right_of_way: RightOfWay::Programmed,
        ..CoordinationConfig::default()
    };
    [
        ("arrival order", config(Mode::Coordinate)),
        ("programmed order", SimConfig { coordination: programmed, ..config(Mode::Coordinate) }),
    ]
}

/// A programme through `waypoints` (MCS), each reached in `leg` ticks with a minimum-jerk
/// profile and held `hold` ticks.
fn through(waypoints: &[Vec3], leg: usize, hold: usize) -> Vec<Vec3> {
    let mut out = vec![waypoints[0]];
    for w in waypoints.windows(2) {
        for k in 1..=leg {
            out.push(w[0] + (w[1] - w[0]) * minimum_jerk(k as Real / leg as Real));
        }
        out.extend(std::iter::repeat_n(w[1], hold));
    }
    out
}

#[test]
fn both_robots_heading_for_the_same_place_point_never_touch() {
    let cell = reference_cell("T1").unwrap();
    // Each robot picks on its far side and places at the WCS point midway between the bases,
    // at the same programmed ticks: executed as programmed, they collide every cycle.
    let place = Vec3::new(225.0, 0.0, -440.0);
    let progs: Programmes = (0..2)
        .map(|j| {
            let far = mcs(&cell, j, Vec3::new(if j == 0 { -120.0 } else { 570.0 }, 0.0, -480.0));
            let p = mcs(&cell, j, place);
            through(&[far, p, far, p, far, p, far], 180, 40)
        })
        .collect();
    (0..2).for_each(|j| reachable(&cell, j, &progs[j]));
    let interlock = ("interlock", config(Mode::Interlock));
    for (name, sim) in coordinations().into_iter().chain([interlock]) {
        let m = run(&cell, &progs, &sim);
        println!("same place point, {name}: {m:?}");
        let what = format!("same place point, {name}");
        assert_safe_and_live_under_arrival(name, &what, &m);
    }
    // Without coordination the programmes themselves meet: the oracle has teeth.
    let m = run(&cell, &progs, &config(Mode::Free));
    assert!(m.stop_events > 0, "the free run should need the protective STOP: {m:?}");
}

#[test]
fn a_robot_stopped_on_the_others_path_is_never_touched() {
    let cell = reference_cell("T1").unwrap();
    let mid = Vec3::new(225.0, 0.0, -440.0);
    // Robot 1 stands at the midpoint for 1.5 s, then leaves; robot 0 goes there and back.
    let home = mcs(&cell, 0, Vec3::new(-120.0, 0.0, -480.0));
    let a = through(&[home, mcs(&cell, 0, Vec3::new(240.0, 0.0, -440.0)), home], 250, 100);
    let b = {
        let at = mcs(&cell, 1, mid);
        let mut p = vec![at; 1500];
        p.extend(through(&[at, mcs(&cell, 1, Vec3::new(570.0, 0.0, -480.0))], 200, 10));
        p
    };
    let progs = vec![a, b];
    (0..2).for_each(|j| reachable(&cell, j, &progs[j]));
    for (name, sim) in coordinations() {
        let m = run(&cell, &progs, &sim);
        println!("stopped on the path, {name}: {m:?}");
        let what = format!("stopped on the path, {name}");
        assert_safe_and_live_under_arrival(name, &what, &m);
        assert!(m.ticks > 1500, "robot 0 cannot have been there before robot 1 left: {m:?}");
    }
}

#[test]
fn three_robots_in_a_row_never_touch() {
    let line = parse_cell(include_str!("../cells/line4.toml")).unwrap();
    let cell = Cell { robots: line.robots[..3].to_vec(), stops: line.stops[..3].to_vec(), ..line };
    // Each robot places at the midpoint toward its right neighbour and the last toward its
    // left one, all at once: every pair meets, the middle robot with both.
    let mids = [225.0, 675.0, 675.0];
    let homes = [-120.0, 450.0, 1020.0];
    let progs: Programmes = (0..3)
        .map(|j| {
            let home = mcs(&cell, j, Vec3::new(homes[j], if j == 1 { 150.0 } else { 0.0 }, -480.0));
            let p = mcs(&cell, j, Vec3::new(mids[j], 0.0, -440.0));
            through(&[home, p, home, p, home], 200, 30)
        })
        .collect();
    (0..3).for_each(|j| reachable(&cell, j, &progs[j]));
    for (name, sim) in coordinations() {
        let m = run(&cell, &progs, &sim);
        println!("three in a row, {name}: {m:?}");
        let what = format!("three in a row, {name}");
        assert_safe_and_live_under_arrival(name, &what, &m);
    }
}

/// Coordination under the programmed order at the programmes' own clearance, stop paths on.
fn programmed_order() -> SimConfig {
    SimConfig {
        coordination: CoordinationConfig {
            clearance_mm: 10.0,
            right_of_way: RightOfWay::Programmed,
            ..CoordinationConfig::default()
        },
        ..config(Mode::Coordinate)
    }
}

#[test]
fn the_programmed_order_keeps_moving_where_the_arrival_order_deadlocks() {
    // Cells of our own where the arrival order deadlocks with stop paths; the programmed
    // order at the programmes' own clearance keeps them moving (SPEC §9's measure), though
    // slowly: most of these runs do not finish within 4x (printed; the record has figures).
    let cells = [
        parse_cell(include_str!("../cells/r60.toml")).unwrap(),
        parse_cell(include_str!("../cells/d380.toml")).unwrap(),
    ];
    let programme = ProgrammeConfig { ticks: 1500, ..ProgrammeConfig::default() };
    let sim = programmed_order();
    for cell in &cells {
        for seed in [11, 12] {
            let progs = programmes(cell, &programme, &mut Rng::new(seed));
            let m = run(cell, &progs, &sim);
            println!("{} seed {seed} programmed order: {m:?}", cell.name);
            let what = format!("{} seed {seed} programmed order", cell.name);
            assert_safe(&what, &m);
            assert!(!m.deadlock, "{what}: deadlock: {m:?}");
        }
    }
}

#[test]
fn the_programmed_order_keeps_most_of_the_throughput_on_two_robot_cells() {
    // Seeds no rule was tuned on; SPEC §9's target is 95 % (the record has the full runs:
    // 83-96 % on these cells). Here each run must finish without deadlock and keep 75 %.
    let cells = [
        reference_cell("T1").unwrap(),
        reference_cell("T2").unwrap(),
        reference_cell("T3").unwrap(),
        parse_cell(include_str!("../cells/h80.toml")).unwrap(),
    ];
    let programme = ProgrammeConfig { ticks: 1500, ..ProgrammeConfig::default() };
    let sim = programmed_order();
    for cell in &cells {
        for seed in [51, 52] {
            let progs = programmes(cell, &programme, &mut Rng::new(seed));
            let m = run(cell, &progs, &sim);
            let what = format!("{} seed {seed} programmed order", cell.name);
            println!("{what}: {:.1} %, {} STOP events", 100.0 * m.throughput, m.stop_events);
            assert_safe_and_live(&what, &m);
            assert!(m.throughput >= 0.75, "{what}: {:.1} % kept", 100.0 * m.throughput);
        }
    }
}

#[test]
fn a_trace_holds_one_record_per_tick_that_agrees_with_the_metrics() {
    let cell = reference_cell("T1").unwrap();
    let programme = ProgrammeConfig { ticks: 600, ..ProgrammeConfig::default() };
    let progs = programmes(&cell, &programme, &mut Rng::new(3));
    let mut trace = Trace::default();
    let m = run_traced(&cell, &progs, &programmed_order(), Some(&mut trace));
    assert_safe("T1 seed 3 traced", &m);
    // One record per verdict, ticks increasing (a STOP skips the ticks of its stop).
    assert_eq!(trace.ticks.len(), m.verdicts.iter().sum::<usize>());
    assert!(trace.ticks.windows(2).all(|w| w[0].tick < w[1].tick));
    let count = |v: Protective| trace.ticks.iter().filter(|t| t.verdict == v).count();
    let verdicts = [Protective::Free, Protective::Warn, Protective::Stop];
    assert_eq!(verdicts.map(count), m.verdicts);
    for (j, _) in cell.robots.iter().enumerate() {
        // Progress never goes back; overrides are factors; a robot is held by another one.
        assert!(trace.ticks.windows(2).all(|w| w[1].progress[j] >= w[0].progress[j]));
        for t in &trace.ticks {
            assert!((0.0..=1.0).contains(&t.coordination[j]), "{t:?}");
            assert!((0.0..=1.0).contains(&t.override_now[j]), "{t:?}");
            assert!(t.held_by[j].is_none_or(|h| h != j && h < cell.robots.len()), "{t:?}");
        }
    }
    assert!(trace.ticks.iter().any(|t| t.held_by.iter().any(Option::is_some)), "no hold at all");
}
