//! The adversary of the protective tests: for one tick's TCPs and finite-difference
//! velocities, a search over the stops the stopping model allows for the one that brings the
//! two robots closest (exact boxes and signed clearance). `tests/protective_adversary.rs`
//! says what a stop is made of and why.

use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::geometry::boxes_clearance;
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::{RobotBoxes, StopModel};
use rand::rngs::StdRng;
use rand::RngExt;

/// Numbers per robot: velocity offset (3), push (3), braking direction (3), moment (1).
pub const PER_ROBOT: usize = 10;

/// Steps of the reaction's simulation (trapezoidal: exact for a constant push below the cap).
const REACTION_STEPS: usize = 64;

/// One robot's state at a tick and its stopping model: the true velocity now is within
/// `a_max interval_s` of `v_fd` (the average over the last `interval_s`), and a STOP comes at
/// most one tick (`tick_s`) later.
pub struct Robot {
    pub tcp: Vec3,
    pub v_fd: Vec3,
    pub stop: StopModel,
    pub tick_s: Real,
    pub interval_s: Real,
}

/// `v` shortened to length `max` when longer.
fn capped(v: Vec3, max: Real) -> Vec3 {
    let n = v.norm();
    if n > max {
        v * (max / n)
    } else {
        v
    }
}

impl Robot {
    /// The TCP (MCS) of the stop that `x` describes (`tests/protective_adversary.rs`, module doc).
    pub fn point(&self, x: &[Real]) -> Vec3 {
        let s = &self.stop;
        let v0 = capped(
            self.v_fd
                + capped(Vec3::new(x[0], x[1], x[2]), 1.0) * (s.max_accel_mm_s2 * self.interval_s),
            s.max_speed_mm_s,
        );
        let push = capped(Vec3::new(x[3], x[4], x[5]), 1.0) * s.max_accel_mm_s2;
        let reaction_s = (s.reaction_ms + self.tick_s * 1e3) * 1e-3;
        // Moment in [0, 2]: below 1 a share of the reaction, above it a share of the braking path.
        let moment = x[9].clamp(0.0, 2.0);
        let steps = if moment < 1.0 {
            (moment * REACTION_STEPS as Real).ceil() as usize
        } else {
            REACTION_STEPS
        };
        let dt = reaction_s / REACTION_STEPS as Real;
        let (mut p, mut v) = (self.tcp, v0);
        for _ in 0..steps {
            let next = capped(v + push * dt, s.max_speed_mm_s);
            p += (v + next) * (0.5 * dt);
            v = next;
        }
        if moment <= 1.0 {
            return p;
        }
        let w = Vec3::new(x[6], x[7], x[8]).try_normalize(1e-12).unwrap_or(Vec3::z());
        let braking = v.norm_squared() / (2.0 * s.decel_mm_s2);
        p + w * ((moment - 1.0) * braking)
    }
}

/// The robots' signed clearance (mm) for the stops `x` (robot 0's numbers, then robot 1's),
/// `+inf` where a TCP is unreachable.
pub struct Objective<'a> {
    pub exact: ExactChecker,
    pub robots: &'a [Robot; 2],
    pub boxes: [RobotBoxes; 2],
}

impl Objective<'_> {
    pub fn tcps(&self, x: &[Real]) -> [Vec3; 2] {
        [self.robots[0].point(&x[..PER_ROBOT]), self.robots[1].point(&x[PER_ROBOT..])]
    }

    pub fn clearance(&mut self, x: &[Real]) -> Real {
        let tcps = self.tcps(x);
        clearance_at(&self.exact, &mut self.boxes, &tcps)
    }
}

/// A (1+1) evolution strategy with the one-fifth success rule: the least value of `f` found
/// from `start` in `evaluations` steps, and where.
pub fn descend(
    mut f: impl FnMut(&[Real]) -> Real,
    start: Vec<Real>,
    evaluations: usize,
    rng: &mut StdRng,
) -> (Real, Vec<Real>) {
    let (mut best, mut x) = (f(&start), start);
    let mut sigma = 0.3;
    for _ in 0..evaluations {
        let y: Vec<Real> = x.iter().map(|xi| xi + sigma * gauss(rng)).collect();
        let fy = f(&y);
        if fy <= best {
            (best, x) = (fy, y);
            sigma *= 1.5;
        } else {
            sigma *= 0.9;
        }
        sigma = sigma.clamp(1e-4, 1.0);
    }
    (best, x)
}

/// A standard normal draw (Box-Muller).
fn gauss(rng: &mut StdRng) -> Real {
    let (u, v): (Real, Real) = (rng.random_range(1e-12..1.0), rng.random_range(0.0..1.0));
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// Both robots' numbers drawn at random, each uniform in its range.
pub fn random_stop(rng: &mut StdRng) -> Vec<Real> {
    (0..2 * PER_ROBOT)
        .map(|i| {
            if i % PER_ROBOT == 9 {
                rng.random_range(0.0..2.0)
            } else {
                rng.random_range(-1.0..1.0)
            }
        })
        .collect()
}

/// The robots' exact signed clearance at `tcps` (MCS), `+inf` where a TCP is unreachable.
pub fn clearance_at(exact: &ExactChecker, boxes: &mut [RobotBoxes; 2], tcps: &[Vec3; 2]) -> Real {
    for (j, b) in boxes.iter_mut().enumerate() {
        if exact.boxes_in_wcs(j, &tcps[j], b).is_err() {
            return Real::INFINITY;
        }
    }
    boxes_clearance(boxes[0].as_slice(), boxes[1].as_slice()).distance
}

/// The least clearance the adversary finds for the robots' stops from this tick, and the
/// TCPs there.
pub fn worst_stop(
    cell: &Cell,
    robots: &[Robot; 2],
    evaluations: usize,
    rng: &mut StdRng,
) -> (Real, [Vec3; 2]) {
    let mut f = Objective {
        exact: ExactChecker::new(cell.clone()),
        robots,
        boxes: [RobotBoxes::empty(), RobotBoxes::empty()],
    };
    let mut starts: Vec<Vec<Real>> = Vec::new();
    // Each robot at full push and braking toward the other, looked at when it stands still.
    starts.push(
        (0..2)
            .flat_map(|j| {
                let d = super::toward_other(cell, j);
                [d.x, d.y, d.z, d.x, d.y, d.z, d.x, d.y, d.z, 2.0]
            })
            .collect(),
    );
    starts.extend((0..3).map(|_| random_stop(rng)));
    let mut worst = (Real::INFINITY, Vec::new());
    for s in starts {
        let found = descend(|x| f.clearance(x), s, evaluations, rng);
        if found.0 < worst.0 {
            worst = found;
        }
    }
    let tcps = if worst.1.is_empty() { [robots[0].tcp, robots[1].tcp] } else { f.tcps(&worst.1) };
    (worst.0, tcps)
}
