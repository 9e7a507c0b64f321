//! What the protective tests share: the stiff stopping model, the reference cells with one
//! model for every robot, random directions and TCPs near the other robot, and the brute-force
//! oracle (random stops within the model, checked with the exact model every 0.1 ms), the
//! adversary (`adversary.rs`: the stop that comes closest, searched), and an allocator that
//! counts.
#![allow(dead_code)] // each test file uses a subset

pub mod adversary;

use delta_collide::cell::protective::StopPath;
use delta_collide::cell::reference::reference_cell;
use delta_collide::cell::trajectory::{path_ahead, Scenario};
use delta_collide::cell::{Cell, ExactChecker};
use delta_collide::math::{Real, Vec3};
use delta_collide::robot::StopModel;
use rand::rngs::StdRng;
use rand::RngExt;
use std::alloc::{GlobalAlloc, Layout, System};

/// Counts allocations per thread (tests run in parallel threads of one process): every test
/// binary that includes this module counts with it.
struct Counting;
thread_local! {
    static ALLOCATIONS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Allocations made so far by this thread.
pub fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

// SAFETY: forwards to the system allocator unchanged; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A stiffer robot than the default (short reaction, hard braking): FREE then happens with
/// the robots close, where a wrong bound would show.
pub const STIFF: StopModel = StopModel {
    reaction_ms: 2.0,
    decel_mm_s2: 120_000.0,
    max_accel_mm_s2: 130_000.0,
    max_speed_mm_s: 4_600.0,
};

pub fn cell(name: &str, stop: StopModel) -> Cell {
    let c = reference_cell(name).unwrap();
    let n = c.robots.len();
    c.with_stopping(1.0, vec![stop; n]).unwrap()
}

pub fn unit(rng: &mut StdRng) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

/// The direction from robot `j`'s base to the other robot's, in `j`'s MCS (horizontal, unit):
/// where the other robot's TCP roughly lies.
pub fn toward_other(cell: &Cell, j: usize) -> Vec3 {
    let other = cell.robots[1 - j].placement.t - cell.robots[j].placement.t;
    let (s, c) = cell.robots[j].placement.alpha.sin_cos();
    Vec3::new(c * other.x + s * other.y, -s * other.x + c * other.y, 0.0).normalize()
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

/// One robot's stopping motion, sampled every `DT`: reaction with random accelerations,
/// then braking along a straight or curved path.
pub struct Motion {
    p: Vec3,
    v: Vec3,
    accel: Vec3,
    braking: bool,
    /// Braking: deceleration along the path and turn rate of the path (rad/s about `axis`).
    decel: Real,
    turn: Real,
    axis: Vec3,
    done: bool,
}

pub const DT: Real = 1e-4;

impl Motion {
    fn step(
        &mut self,
        t: Real,
        reaction_s: Real,
        model: &StopModel,
        rng: &mut StdRng,
        kind: usize,
        toward: &Vec3,
    ) {
        if self.done {
            return;
        }
        if t < reaction_s {
            // New random acceleration every 0.5 ms (kind 0: always the hardest push toward the
            // other robot).
            if kind == 0 {
                self.accel = toward * model.max_accel_mm_s2;
            } else if (t / 5e-4).fract() < DT / 5e-4 + 1e-12 {
                self.accel =
                    unit(rng) * model.max_accel_mm_s2 * rng.random_range(0.0..1.0f64).sqrt();
            }
            self.v += self.accel * DT;
            let speed = self.v.norm();
            if speed > model.max_speed_mm_s {
                self.v *= model.max_speed_mm_s / speed;
            }
            self.p += self.v * DT;
            return;
        }
        if !self.braking {
            self.braking = true;
            let speed = self.v.norm();
            // The path's direction at the start of braking: kind 0 toward the other robot,
            // 1 straight on, 2 a random direction, 3 random and curving.
            let dir = match kind {
                0 => *toward,
                1 if speed > 0.0 => self.v / speed,
                _ => unit(rng),
            };
            self.v = dir * speed;
            self.decel = if kind == 0 {
                model.decel_mm_s2
            } else {
                model.decel_mm_s2 * rng.random_range(1.0..1.5)
            };
            self.turn = if kind == 3 { rng.random_range(-40.0..40.0) } else { 0.0 };
            self.axis = unit(rng);
        }
        let speed = self.v.norm();
        let new_speed = (speed - self.decel * DT).max(0.0);
        if new_speed == 0.0 || speed == 0.0 {
            self.done = true;
            return;
        }
        let mut dir = self.v / speed;
        if self.turn != 0.0 {
            let rot = nalgebra::Rotation3::from_axis_angle(
                &nalgebra::Unit::new_normalize(self.axis),
                self.turn * DT,
            );
            dir = rot * dir;
        }
        self.v = dir * new_speed;
        self.p += dir * (0.5 * (speed + new_speed) * DT);
    }
}

/// Simulates `motions` random stops of both robots from TCPs `tcps` with true velocities
/// `vel`; panics at the first contact.
pub fn assert_stops_never_touch(
    cell: &Cell,
    tcps: &[Vec3; 2],
    vel: &[Vec3; 2],
    motions: usize,
    rng: &mut StdRng,
) -> usize {
    let mut exact = ExactChecker::new(cell.clone());
    let mut steps = 0;
    for m in 0..motions {
        let kind = m % 4;
        let toward = |j: usize| toward_other(cell, j);
        let mut robots: Vec<Motion> = (0..2)
            .map(|j| Motion {
                p: tcps[j],
                v: vel[j],
                accel: Vec3::zeros(),
                braking: false,
                decel: 0.0,
                turn: 0.0,
                axis: Vec3::z(),
                done: false,
            })
            .collect();
        let mut t = 0.0;
        while !robots.iter().all(|r| r.done) {
            for (j, r) in robots.iter_mut().enumerate() {
                let stop = cell.stops[j];
                r.step(t, (stop.reaction_ms + cell.tick_ms) * 1e-3, &stop, rng, kind, &toward(j));
            }
            t += DT;
            let v = exact.check(&[robots[0].p, robots[1].p]).unwrap();
            if !v.all_reachable() {
                break; // the robot cannot go there: this motion is not physical
            }
            steps += 1;
            assert!(
                !v.collides(),
                "contact at t = {t:.4} s in motion {m} from {tcps:?} with {vel:?}"
            );
            assert!(t < 1.0, "a stop lasted a second");
        }
    }
    steps
}

/// A reachable TCP of robot `j` within 0 to 8 mm of its reach boundary (pushed out from
/// [`tcp_toward_other`] along its radial direction), where elbows swing fastest.
pub fn tcp_near_reach_boundary(cell: &Cell, j: usize, rng: &mut StdRng) -> Vec3 {
    pushed_to_reach_boundary(cell, j, rng, tcp_toward_other)
}

/// A reachable TCP of robot `j` within 0 to 8 mm of its reach boundary: a TCP from `start`
/// pushed out along its radial direction.
pub fn pushed_to_reach_boundary(
    cell: &Cell,
    j: usize,
    rng: &mut StdRng,
    start: impl Fn(&Cell, usize, &mut StdRng) -> Vec3,
) -> Vec3 {
    let delta = &cell.robots[j].model.delta;
    loop {
        let p = start(cell, j, rng);
        let out = Vec3::new(p.x, p.y, 0.0).try_normalize(1e-9).unwrap_or(Vec3::x());
        let mut step = 0.0;
        while delta.is_reachable(&(p + out * (step + 1.0))) && step < 400.0 {
            step += 1.0;
        }
        let q = p + out * (step - rng.random_range(0.0..8.0f64)).max(0.0);
        if delta.is_reachable(&q) {
            return q;
        }
    }
}

/// Each robot's programmed path ahead at `tick` of scenario `s` (400 mm, 0.1 mm tolerance) as
/// its stop path, its points written into `points` (one buffer per robot).
pub fn programmed_paths<'a>(
    s: &Scenario,
    tick: u32,
    points: &'a mut [[Vec3; 32]],
) -> Vec<Option<StopPath<'a>>> {
    points
        .iter_mut()
        .enumerate()
        .map(|(j, buf)| {
            let len = path_ahead(&s.robots[j], tick, 400.0, buf);
            Some(StopPath { points: &buf[..len], tolerance_mm: 0.1 })
        })
        .collect()
}
