//! A stop along a path cut into time slices (SPEC §8, "Where the controller knows more"; step
//! 4 of `path.rs`): where along its path a robot can be at each moment of its stop, so that
//! the proof pairs the robots' positions at the same time instead of every position of one
//! stop with every position of the other.
//!
//! # The bounds
//! Let `sigma(t)` be the arc position along the path `Q` of the point the TCP follows at time
//! `t` after this tick (`|TCP(t) - Q(sigma(t))| <= tol`). A path-maintaining stop brakes along
//! its path: `sigma` never decreases (the promise of a [`StopPath`]).
//! 1. **Fastest.** The TCP travels at most `D(t)` by time `t`: from the speed bound `v_b` it
//!    accelerates at `a_max` (up to `v_max`) over the reaction `T_r`, then brakes at the
//!    least deceleration until it stands at `T_stop = T_r + v_r / decel` ([`reach_by`]).
//!    So `|TCP(t) - p| <= D(t)`, and `Q(sigma(t))` lies within `D(t) + tol` of `p`: `sigma(t)`
//!    is in the cover of that ball (`path::arc_cover`).
//! 2. **Slowest.** With a measured velocity `v_fd` over the last interval `dt`, the velocity
//!    at time `t` differs from it by at most `a_max (dt + t)` (braking is an acceleration
//!    too, at most `a_max`), so `TCP(t)` is within `r(t) = a_max (dt t + t^2 / 2)` of
//!    `p + v_fd t` ([`slowest_ball`]), and `sigma(t)` is at least the first arc position of
//!    `Q` within `r(t) + tol` of that point. Without a measured velocity there is no such
//!    bound (0).
//! 3. **Slices.** Cut `[0, T_end]` into [`SLICES`] equal slices, `T_end` the latest `T_stop`
//!    of the robots paired (after it every robot of the pair stands where it stood at
//!    `T_end`). As `sigma` never decreases, over slice `[t_k, t_k+1]` it lies in
//!    `[max_{t <= t_k} lo(t), hi(t_k+1)]`, the lower bound of step 2 taken at the slice
//!    starts and at the moment it is largest (`t* = |v_fd| / a_max - dt`), the upper bound of
//!    step 1 and, where smaller, the last position within step 2's ball at `t_k+1`.
//! 4. **Apart.** At every moment both robots are in the same slice: when, for every slice,
//!    the pieces of the two robots' ranges are proved apart, so is every pair of positions
//!    the robots can take at the same time.
//!
//! A range that comes out empty (no point of the path where step 2 puts the TCP, or a lower
//! bound above the upper one) means that the promise and the measured motion disagree: no
//! slices, and the verdict is the one without them. Nothing here allocates.

use super::path::{arc_cover, arc_range, StopPath};
use crate::math::{Real, Vec3};
use crate::robot::StopModel;

/// Time slices of a stop (step 3): more slices pair positions more tightly and cost one
/// proof of two pieces each.
pub const SLICES: usize = 4;

/// How one robot can move over its stop, from what this tick measured.
#[derive(Clone, Copy, Debug)]
pub struct StopMotion {
    /// The TCP now (MCS, mm).
    pub tcp: Vec3,
    /// The measured velocity `v_fd` (MCS, mm/s), `None` when unknown.
    pub velocity: Option<Vec3>,
    /// The speed bound now, `v_b` (mm/s).
    pub speed_bound_mm_s: Real,
    /// The interval `v_fd` was measured over (s).
    pub interval_s: Real,
    /// The reaction time the verdict uses, the verdict's own latency included (s).
    pub reaction_s: Real,
    /// The robot's stopping model.
    pub stop: StopModel,
}

/// The speed at the end of the reaction, `v_r = min(v_b + a_max T_r, v_max)` (mm/s).
fn reacted_speed(m: &StopMotion) -> Real {
    (m.speed_bound_mm_s + m.stop.max_accel_mm_s2 * m.reaction_s).min(m.stop.max_speed_mm_s)
}

/// The latest time the robot can still move, `T_stop = T_r + v_r / decel` (s; step 1).
pub fn stands_by(m: &StopMotion) -> Real {
    m.reaction_s + reacted_speed(m) / m.stop.decel_mm_s2
}

/// `D(t)`: the farthest the TCP travels by time `t` (mm; step 1).
pub fn reach_by(m: &StopMotion, t: Real) -> Real {
    let (a, vmax, v0) = (m.stop.max_accel_mm_s2, m.stop.max_speed_mm_s, m.speed_bound_mm_s);
    let v0 = v0.clamp(0.0, vmax);
    // Accelerating at `a_max` up to `v_max`, over `tau <= T_r`.
    let accelerating = |tau: Real| {
        let to_max = (vmax - v0) / a;
        if tau <= to_max {
            v0 * tau + 0.5 * a * tau * tau
        } else {
            v0 * to_max + 0.5 * a * to_max * to_max + vmax * (tau - to_max)
        }
    };
    if t <= m.reaction_s {
        return accelerating(t.max(0.0));
    }
    let v_r = reacted_speed(m);
    let tau = (t - m.reaction_s).min(v_r / m.stop.decel_mm_s2);
    accelerating(m.reaction_s) + v_r * tau - 0.5 * m.stop.decel_mm_s2 * tau * tau
}

/// The ball that holds the TCP at time `t` by step 2: centre `p + v_fd t`, radius
/// `a_max (dt t + t^2 / 2)`; `None` without a measured velocity.
pub fn slowest_ball(m: &StopMotion, t: Real) -> Option<(Vec3, Real)> {
    let v = m.velocity?;
    let a = m.stop.max_accel_mm_s2;
    Some((m.tcp + v * t, a * (m.interval_s * t + 0.5 * t * t)))
}

/// Each slice's arc range of `sigma` over `[0, end]` (module doc, step 3), `end` at least
/// [`stands_by`]; `false` when a range is empty (the promise and the motion disagree).
pub fn slice_arcs(
    m: &StopMotion,
    path: &StopPath,
    end: Real,
    out: &mut [(Real, Real); SLICES],
) -> bool {
    let (points, tol) = (path.points, path.tolerance_mm);
    // Rounding must not cut a position off: the balls are widened a little.
    let widen = |r: Real| (r + tol) * (1.0 + 1e-9) + 1e-9;
    let lowest = |t: Real| match slowest_ball(m, t) {
        Some((c, r)) => arc_range(points, &c, widen(r)).map(|(s0, _)| s0),
        None => Some(0.0),
    };
    let highest = |t: Real| {
        let fastest = arc_cover(points, &m.tcp, widen(reach_by(m, t)), tol).map(|(_, s1)| s1);
        let slowest = slowest_ball(m, t).and_then(|(c, r)| arc_range(points, &c, widen(r)));
        match (fastest, slowest) {
            (Some(f), Some((_, s))) => Some(f.min(s)),
            (f, _) => f,
        }
    };
    let peak =
        m.velocity.map_or(Real::INFINITY, |v| v.norm() / m.stop.max_accel_mm_s2 - m.interval_s);
    let mut lo: Real = 0.0;
    let mut peak_taken = false;
    for (k, slot) in out.iter_mut().enumerate() {
        let t0 = end * k as Real / SLICES as Real;
        let t1 = end * (k + 1) as Real / SLICES as Real;
        let Some(at_start) = lowest(t0) else { return false };
        lo = lo.max(at_start);
        if !peak_taken && peak <= t0 {
            let Some(at_peak) = lowest(peak.max(0.0)) else { return false };
            (lo, peak_taken) = (lo.max(at_peak), true);
        }
        match highest(t1) {
            Some(hi) if lo <= hi => *slot = (lo, hi),
            _ => return false,
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn motion(v: Real) -> StopMotion {
        StopMotion {
            tcp: Vec3::new(0.0, 0.0, -400.0),
            velocity: Some(Vec3::new(v, 0.0, 0.0)),
            speed_bound_mm_s: v + 130_000.0 * 1e-3,
            interval_s: 1e-3,
            reaction_s: 5e-3,
            stop: StopModel::DEFAULT,
        }
    }

    #[test]
    fn the_fastest_reach_ends_at_the_stopping_distance() {
        for v in [0.0, 500.0, 2_000.0, 4_000.0, 4_600.0] {
            let m = motion(v);
            let s = m.stop.stopping_distance(m.speed_bound_mm_s, m.reaction_s);
            let end = reach_by(&m, stands_by(&m));
            assert!(end <= s * (1.0 + 1e-12) && end >= 0.999 * s, "{v}: {end} against {s}");
            assert_eq!(reach_by(&m, 10.0 * stands_by(&m)), end);
            // Non-decreasing in time, and never faster than `v_max`.
            let mut last = 0.0;
            for i in 0..=1000 {
                let t = stands_by(&m) * i as Real / 1000.0;
                let d = reach_by(&m, t);
                assert!(d >= last && d <= m.stop.max_speed_mm_s * t + 1e-9, "{v} {t}: {d}");
                last = d;
            }
        }
    }

    #[test]
    fn slices_of_a_straight_stop_bracket_every_braking_the_model_allows() {
        // A straight path along the velocity; brute force over braking profiles: constant
        // deceleration from `decel` to `a_max`, after any reaction within the limits.
        let m = motion(4_000.0);
        let pts = [m.tcp, m.tcp + Vec3::new(600.0, 0.0, 0.0)];
        let path = StopPath { points: &pts, tolerance_mm: 0.0 };
        let end = stands_by(&m);
        let mut arcs = [(0.0, 0.0); SLICES];
        assert!(slice_arcs(&m, &path, end, &mut arcs));
        let (a, dec) = (m.stop.max_accel_mm_s2, m.stop.decel_mm_s2);
        for react_accel in [-a, -0.5 * a, 0.0, 0.5 * a, a] {
            for brake in [dec, 0.5 * (dec + a), a] {
                // The speed now within `a dt` of the measured one.
                for v0 in [4_000.0 - a * 1e-3, 4_000.0, 4_000.0 + a * 1e-3] {
                    let (mut s, mut v, mut t) = (0.0, v0, 0.0);
                    let dt = 1e-5;
                    while t < end {
                        let acc = if t < m.reaction_s { react_accel } else { -brake };
                        v = (v + acc * dt).clamp(0.0, m.stop.max_speed_mm_s);
                        s += v * dt;
                        t += dt;
                        let k = ((t / end * SLICES as Real) as usize).min(SLICES - 1);
                        let (lo, hi) = arcs[k];
                        assert!(
                            s >= lo - 0.05 && s <= hi + 0.05,
                            "t {t}: {s} outside {lo}..{hi} ({react_accel} {brake} {v0})"
                        );
                    }
                }
            }
        }
        // The slices are tighter than the whole stop: late ones start well past the TCP.
        assert!(arcs[SLICES - 1].0 > 40.0, "{arcs:?}");
        assert!(arcs[0].1 < 0.5 * arcs[SLICES - 1].1, "{arcs:?}");
    }

    #[test]
    fn a_path_against_the_measured_motion_gives_no_slices() {
        let m = motion(3_000.0);
        let back = [m.tcp, m.tcp - Vec3::new(600.0, 0.0, 0.0)];
        let path = StopPath { points: &back, tolerance_mm: 0.5 };
        let mut arcs = [(0.0, 0.0); SLICES];
        assert!(!slice_arcs(&m, &path, stands_by(&m), &mut arcs));
        // Without a measured velocity the lower bounds are 0 and the ranges not empty.
        let unknown = StopMotion { velocity: None, ..m };
        assert!(slice_arcs(&unknown, &path, stands_by(&unknown), &mut arcs));
        assert!(arcs.iter().all(|&(lo, _)| lo == 0.0));
    }
}
