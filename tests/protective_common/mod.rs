//! What the protective tests share: the stiff stopping model, the reference cells with one
//! model for every robot, and random directions and TCPs near the other robot.

use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::Cell;
use delta_collide::math::Vec3;
use delta_collide::robot::StopModel;
use rand::rngs::StdRng;
use rand::RngExt;

/// A stiffer robot than the default (short reaction, hard braking): FREE then happens with
/// the robots close, where a wrong bound would show.
pub const STIFF: StopModel =
    StopModel { reaction_ms: 2.0, decel_mm_s2: 120_000.0, max_accel_mm_s2: 130_000.0, max_speed_mm_s: 4_600.0 };

pub fn cell(name: &str, stop: StopModel) -> Cell {
    let c = reference_cell(name).unwrap();
    let n = c.robots.len();
    c.with_stopping(1.0, vec![stop; n]).unwrap()
}

pub fn unit(rng: &mut StdRng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

/// A reachable TCP of robot `j` (MCS) out toward the other robot, at a random depth.
pub fn tcp_toward_other(cell: &Cell, j: usize, rng: &mut StdRng) -> Vec3 {
    let other = cell.robots[1 - j].placement.t - cell.robots[j].placement.t;
    let alpha = cell.robots[j].placement.alpha;
    let (s, c) = alpha.sin_cos();
    // The direction to the other base in robot j's MCS: Rz(-alpha) applied.
    let d = Vec3::new(c * other.x + s * other.y, -s * other.x + c * other.y, 0.0).normalize();
    let side = Vec3::new(-d.y, d.x, 0.0);
    loop {
        let p = d * rng.random_range(-60.0..230.0)
            + side * rng.random_range(-140.0..140.0)
            + Vec3::z() * rng.random_range(-530.0..-370.0);
        if cell.robots[j].model.delta.is_reachable(&p) {
            return p;
        }
    }
}
