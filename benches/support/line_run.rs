//! The line that `benches/line.rs` and `examples/line_tick.rs` replay: `n` thesis robots 450 mm
//! apart along x (as T1 and `cells/line4.toml`), robot `j` running T1 practical's trajectory of
//! robot A (even `j`) or B (odd `j`), so every other neighbour pair works as T1's pair does.

use delta_collide::cell::placement::Placement;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{parse_scenarios, RUN_TICKS};
use delta_collide::cell::{Cell, RobotSpec};
use delta_collide::math::Vec3;

const SCENARIOS: &str = include_str!("../../c_harness/scenarios.txt");

/// A line of `n` thesis robots, 450 mm apart along x.
pub fn line(n: usize) -> Cell {
    let t1 = reference_cell("T1").unwrap();
    let robots = (0..n)
        .map(|j| RobotSpec {
            name: format!("R{}", j + 1),
            placement: Placement { alpha: 0.0, t: Vec3::new(450.0 * j as f64, 0.0, 0.0) },
            ..t1.robots[0].clone()
        })
        .collect();
    Cell::new(format!("line{n}"), robots, t1.method).unwrap()
}

/// The ticks of the run for `n` robots, each robot's TCP in its own MCS.
pub fn ticks(n: usize) -> Vec<Vec<Vec3>> {
    let s = parse_scenarios(SCENARIOS)
        .unwrap()
        .into_iter()
        .find(|s| s.cell == "T1" && s.case == "practical")
        .unwrap();
    (0..RUN_TICKS)
        .map(|tick| {
            let mut pair = [Vec3::zeros(); 2];
            s.tcps_at(tick, &mut pair);
            (0..n).map(|j| pair[j % 2]).collect()
        })
        .collect()
}
