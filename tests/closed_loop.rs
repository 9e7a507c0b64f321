//! The closed-loop benchmark in its short form (`delta_collide::sim`; the full one is
//! `delta-collide simulate`): the coordination on seeded programmes of a reference cell and of
//! a cell nothing is tuned on, and on adversarial programmes written here (both robots
//! heading for the same place point, a robot stopped on the other's path, three robots in a
//! row). Contact is checked by the exact model every tick and every 0.2 ms of every simulated
//! stop; none may occur in any run. Liveness (no deadlock, every programme finished) is
//! asserted where the coordination reaches it today, the seeded runs of T1; on the cell of
//! our own and the adversarial programmes it is printed, not asserted: there a STOP at
//! standstill can hold the robots for good (docs/record/2026-12-02-closed-loop-benchmark.md).

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::minimum_jerk;
use delta_collide::cell::{parse_cell, Cell};
use delta_collide::math::{Real, Vec3};
use delta_collide::sim::run::run;
use delta_collide::sim::{
    programmes, Mode, ProgrammeConfig, Programmes, Rng, RunMetrics, SimConfig,
};

fn config(mode: Mode) -> SimConfig {
    SimConfig { mode, ..SimConfig::default() }
}

fn assert_safe(what: &str, m: &RunMetrics) {
    assert_eq!(m.contact_ticks + m.contact_stop_samples, 0, "{what}: contact: {m:?}");
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
    let place = Vec3::new(225.0, 0.0, -470.0);
    let progs: Programmes = (0..2)
        .map(|j| {
            let far = mcs(&cell, j, Vec3::new(if j == 0 { -120.0 } else { 570.0 }, 0.0, -480.0));
            let p = mcs(&cell, j, place);
            through(&[far, p, far, p, far, p, far], 180, 40)
        })
        .collect();
    for mode in [Mode::Coordinate, Mode::Interlock] {
        let m = run(&cell, &progs, &config(mode));
        println!("same place point, {}: {m:?}", mode.name());
        assert_safe(&format!("same place point, {}", mode.name()), &m);
    }
    // Without coordination the programmes themselves meet: the oracle has teeth.
    let m = run(&cell, &progs, &config(Mode::Free));
    assert!(m.stop_events > 0 || m.deadlock, "the free run should need the protective STOP: {m:?}");
}

#[test]
fn a_robot_stopped_on_the_others_path_is_never_touched() {
    let cell = reference_cell("T1").unwrap();
    let mid = Vec3::new(225.0, 0.0, -470.0);
    // Robot 1 stands at the midpoint for 1.5 s, then leaves; robot 0 goes there and back.
    let home = mcs(&cell, 0, Vec3::new(-120.0, 0.0, -480.0));
    let a = through(&[home, mcs(&cell, 0, Vec3::new(240.0, 0.0, -470.0)), home], 250, 100);
    let b = {
        let at = mcs(&cell, 1, mid);
        let mut p = vec![at; 1500];
        p.extend(through(&[at, mcs(&cell, 1, Vec3::new(570.0, 0.0, -480.0))], 200, 10));
        p
    };
    let m = run(&cell, &vec![a, b], &config(Mode::Coordinate));
    println!("stopped on the path: {m:?}");
    assert_safe("stopped on the path", &m);
    assert!(m.ticks > 1500, "robot 0 cannot have been there before robot 1 left: {m:?}");
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
            let p = mcs(&cell, j, Vec3::new(mids[j], 0.0, -470.0));
            through(&[home, p, home, p, home], 200, 30)
        })
        .collect();
    let m = run(&cell, &progs, &config(Mode::Coordinate));
    println!("three in a row: {m:?}");
    assert_safe("three in a row", &m);
}
