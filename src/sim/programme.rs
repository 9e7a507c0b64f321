//! Seeded dense pick-and-place programmes for any cell (the closed-loop benchmark's input):
//! each robot picks on its far side (across the conveyor when it has neighbours on both
//! sides) and places toward a neighbour, into the region their reaches share, with arch moves
//! of one minimum-jerk leg each. An offline interlock times them as a line's planner would:
//! robot by robot, a move starts only when, executed as programmed, it keeps `gap_mm` between
//! its boxes and those of every robot planned before it; else the robot waits at its pick
//! point. A programme is one set-point per programme tick (1 ms), ending at a park point.

use super::rng::Rng;
use crate::cell::exact::{aabb_of, pair_state, PairState, RobotInWcs};
use crate::cell::trajectory::minimum_jerk;
use crate::cell::{Cell, ExactChecker};
use crate::math::{Real, Vec3};
use crate::robot::RobotBoxes;
use alloc::vec;

/// How the programmes are drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProgrammeConfig {
    /// Programme ticks of cycling before the robots park.
    pub ticks: u32,
    /// Clearance the offline interlock keeps between robots executing their programmes (mm).
    pub gap_mm: Real,
    /// Range of a move's peak speed (mm/s), before the acceleration bound stretches it.
    pub peak_speed_mm_s: (Real, Real),
    /// Share of each robot's `max_accel_mm_s2` a programme uses at most (the rest is the
    /// override's, SPEC §9).
    pub accel_share: Real,
    /// Range of the dwell at a pick or place point (ticks).
    pub dwell_ticks: (u32, u32),
    /// Range of how far toward the neighbour the place points lie (mm from the base axis).
    pub place_reach_mm: (Real, Real),
}

impl Default for ProgrammeConfig {
    fn default() -> Self {
        ProgrammeConfig {
            ticks: 6000,
            gap_mm: 10.0,
            peak_speed_mm_s: (3400.0, 4600.0),
            accel_share: 0.5,
            dwell_ticks: (20, 60),
            place_reach_mm: (150.0, 230.0),
        }
    }
}

/// Each robot's programme: its TCP (its MCS) at every programme tick.
pub type Programmes = alloc::vec::Vec<alloc::vec::Vec<Vec3>>;

/// The horizontal unit direction from robot `j`'s base to robot `k`'s, in `j`'s MCS.
fn toward(cell: &Cell, j: usize, k: usize) -> Vec3 {
    let d = cell.robots[k].placement.t - cell.robots[j].placement.t;
    let r = cell.robots[j].placement.rotation();
    let local = r.transpose() * Vec3::new(d.x, d.y, 0.0);
    let n = local.xy().norm();
    if n > 0.0 {
        Vec3::new(local.x / n, local.y / n, 0.0)
    } else {
        Vec3::new(1.0, 0.0, 0.0)
    }
}

/// A reachable TCP of robot `j` at `radius` along `dir`, `side` across, `z` deep, pulled
/// toward the axis until reachable (a bounded loop: the axis at that depth is reachable).
fn reachable(cell: &Cell, j: usize, dir: Vec3, radius: Real, side: Real, z: Real) -> Vec3 {
    let across = Vec3::new(-dir.y, dir.x, 0.0);
    let delta = &cell.robots[j].model.delta;
    for step in 0..=20 {
        let k = 1.0 - 0.05 * Real::from(step);
        let p = (dir * radius + across * side) * k + Vec3::new(0.0, 0.0, z);
        if delta.is_reachable(&p) {
            return p;
        }
    }
    Vec3::new(0.0, 0.0, z)
}

/// One arch move from `a` to `b` over `height_mm`, sampled at every tick: `a` at tick 0, `b`
/// at the last. Its duration gives the peak speed `v_peak` unless that needs more than
/// `a_max` (then it is stretched).
fn arch(a: Vec3, b: Vec3, height_mm: Real, v_peak: Real, a_max: Real, tick_s: Real) -> Vec<Vec3> {
    let at = |s: Real| a + (b - a) * s + Vec3::new(0.0, 0.0, height_mm * 4.0 * s * (1.0 - s));
    let length = (b - a).norm() + 2.0 * height_mm;
    // Minimum jerk: peak speed 1.875 L / T, peak acceleration 5.77 L / T^2.
    let mut duration = (1.875 * length / v_peak).max((5.78 * length / a_max).sqrt());
    for _ in 0..20 {
        let n = (duration / tick_s).ceil().max(2.0) as usize;
        let pts: Vec<Vec3> = (0..=n).map(|k| at(minimum_jerk(k as Real / n as Real))).collect();
        let worst = pts
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).norm() / (tick_s * tick_s))
            .fold(0.0, Real::max);
        if worst <= a_max {
            return pts;
        }
        duration *= 1.1;
    }
    vec![a, b]
}

/// Whether robot `j` at `tcp` keeps `gap` (boxes grown by half of it) from every robot
/// before it at their positions of tick `t` in `planned`.
fn keeps_gap(
    exact: &ExactChecker,
    planned: &[Vec<Vec3>],
    j: usize,
    tcp: &Vec3,
    t: usize,
    gap: Real,
    scratch: &mut [RobotBoxes; 2],
) -> bool {
    let grown = |boxes: &mut RobotBoxes| {
        for b in &mut boxes.boxes[..boxes.len] {
            *b = b.inflated(0.5 * gap);
        }
    };
    if exact.boxes_in_wcs(j, tcp, &mut scratch[0]).is_err() {
        return false;
    }
    grown(&mut scratch[0]);
    let aabb_j = aabb_of(&scratch[0]);
    for (k, prog) in planned.iter().enumerate().take(j) {
        let at = prog[t.min(prog.len() - 1)];
        if exact.boxes_in_wcs(k, &at, &mut scratch[1]).is_err() {
            return false;
        }
        grown(&mut scratch[1]);
        let aabb_k = aabb_of(&scratch[1]);
        let a = RobotInWcs { boxes: scratch[0].as_slice(), aabb: &aabb_j };
        let b = RobotInWcs { boxes: scratch[1].as_slice(), aabb: &aabb_k };
        if !matches!(pair_state(&a, &b, None), PairState::Free) {
            return false;
        }
    }
    true
}

/// The programmes of every robot of `cell` (module doc), drawn from `rng`.
pub fn programmes(cell: &Cell, config: &ProgrammeConfig, rng: &mut Rng) -> Programmes {
    let n = cell.robots.len();
    let exact = ExactChecker::new(cell.clone());
    let tick_s = cell.tick_ms * 1e-3;
    let pairs = cell.pairs_that_can_meet();
    let mut planned: Programmes = Vec::with_capacity(n);
    let mut scratch = [RobotBoxes::empty(); 2];
    for j in 0..n {
        let neighbours: Vec<usize> = pairs
            .iter()
            .filter_map(|&(a, b)| {
                if a == j {
                    Some(b)
                } else if b == j {
                    Some(a)
                } else {
                    None
                }
            })
            .collect();
        let sum = neighbours.iter().fold(Vec3::zeros(), |s, &k| s + toward(cell, j, k));
        let far = if sum.norm() > 0.5 { -sum / sum.norm() } else { Vec3::new(0.0, 1.0, 0.0) };
        let a_max = config.accel_share * cell.stops[j].max_accel_mm_s2;
        let park = reachable(cell, j, far, 100.0, 0.0, -460.0);
        let mut prog = vec![park; 1 + rng.below(200) as usize];
        let mut at = park;
        let leg = |from: Vec3, to: Vec3, rng: &mut Rng| {
            let v = rng.range(config.peak_speed_mm_s.0, config.peak_speed_mm_s.1);
            let mut pts = arch(from, to, rng.range(25.0, 50.0), v, a_max, tick_s);
            let (lo, hi) = config.dwell_ticks;
            let dwell = rng.range(Real::from(lo), Real::from(hi)) as usize;
            pts.extend(core::iter::repeat_n(to, dwell));
            pts
        };
        while prog.len() < config.ticks as usize {
            let (r, side) = (rng.range(90.0, 140.0), rng.range(-60.0, 60.0));
            let pick = reachable(cell, j, far, r, side, -480.0);
            let target = match neighbours.len() {
                0 => far,
                m => toward(cell, j, neighbours[rng.below(m as u64) as usize]),
            };
            let (lo, hi) = config.place_reach_mm;
            let (r, side, z) =
                (rng.range(lo, hi), rng.range(-40.0, 40.0), rng.range(-490.0, -450.0));
            let place = reachable(cell, j, target, r, side, z);
            // To the pick point, then the cycle's block: to the place point, dwell, back to
            // the next pick point. The offline interlock lets the block start (after up to a
            // second of waiting at the pick point, in 10 ms steps) only when it keeps the gap
            // from every robot planned before, executed as programmed.
            let to_pick = leg(at, pick, rng);
            prog.extend_from_slice(&to_pick[1..]);
            let mut block = leg(pick, place, rng);
            let back = leg(place, pick, rng);
            block.extend_from_slice(&back[1..]);
            for _ in 0..100 {
                let start = prog.len();
                let clear = block.iter().enumerate().step_by(2).all(|(t, p)| {
                    keeps_gap(&exact, &planned, j, p, start + t, config.gap_mm, &mut scratch)
                });
                if clear {
                    break;
                }
                prog.extend(core::iter::repeat_n(pick, 10));
            }
            prog.extend_from_slice(&block[1..]);
            at = pick;
        }
        let v = config.peak_speed_mm_s.0;
        let home = arch(at, park, 30.0, v, a_max, tick_s);
        prog.extend_from_slice(&home[1..]);
        planned.push(prog);
    }
    planned
}
