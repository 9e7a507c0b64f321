//! A yielding robot's speed (coordination, step 5 of the module doc): the largest speed whose
//! stop stands within the room to the hold point, and the ramp of an override within shares of
//! the stopping model's acceleration (SPEC §9).

use crate::cell::Cell;
use crate::math::Real;

/// Samples ahead whose programmed speed the override is measured against: the programme may
/// speed up over the next ticks, and the override must hold its speed then too.
pub const SPEED_AHEAD_SAMPLES: usize = 8;

/// Bisection steps of [`allowed_speed`]: `v_max / 2^32`, far below any servo's resolution.
const SPEED_STEPS: u32 = 32;

/// The room robot `j` needs ahead along its path to stand from a stop issued now at speed
/// `v_mm_s`: the stopping model's distance with the protective verdict's reaction
/// (`reaction_ms` plus its tick of latency) and one more tick, in which the override of this
/// call is applied, less that distance from standstill. A standing robot that the override
/// holds does not move; the stopping model's motion from standstill (an acceleration during
/// the reaction) is within the diagram's clearance, and the protective verdict covers it.
pub fn stopping_mm(cell: &Cell, j: usize, v_mm_s: Real) -> Real {
    let stop = &cell.stops[j];
    let reaction_s = (stop.reaction_ms + 2.0 * cell.tick_ms) * 1e-3;
    stop.stopping_distance(v_mm_s, reaction_s) - stop.stopping_distance(0.0, reaction_s)
}

/// The largest speed of robot `j` whose stop ([`stopping_mm`]) stays within `room_mm`; 0
/// when the room is negative. The distance grows with the speed, so
/// bisection finds it.
pub fn allowed_speed(cell: &Cell, j: usize, room_mm: Real) -> Real {
    let v_max = cell.stops[j].max_speed_mm_s;
    if room_mm.is_nan() || stopping_mm(cell, j, 0.0) > room_mm {
        return 0.0;
    }
    if stopping_mm(cell, j, v_max) <= room_mm {
        return v_max;
    }
    let (mut lo, mut hi) = (0.0, v_max);
    for _ in 0..SPEED_STEPS {
        let mid = 0.5 * (lo + hi);
        if stopping_mm(cell, j, mid) <= room_mm {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The override toward `target` from `now`, changed by at most a share of `accel_per_tick`
/// (mm/s gained or lost in one tick at the model's acceleration) at the programmed speed
/// `speed_mm_s`: `(up, down)` shares. A robot whose programme stands may take any factor.
pub fn ramped(
    now: Real,
    target: Real,
    speed_mm_s: Real,
    accel_per_tick: Real,
    (up, down): (Real, Real),
) -> Real {
    let target = target.clamp(0.0, 1.0);
    if speed_mm_s.is_nan() || speed_mm_s <= 0.0 {
        return target;
    }
    let step = accel_per_tick / speed_mm_s;
    target.clamp((now - down * step).max(0.0), (now + up * step).min(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::reference::reference_cell;

    #[test]
    fn the_allowed_speed_stops_within_the_room_and_no_faster_speed_does() {
        let cell = reference_cell("T1").unwrap();
        for room in [0.0, 3.0, 10.0, 50.0, 150.0, 400.0, 1e4] {
            let v = allowed_speed(&cell, 0, room);
            let v_max = cell.stops[0].max_speed_mm_s;
            if v > 0.0 {
                assert!(stopping_mm(&cell, 0, v) <= room, "room {room}: v {v}");
            }
            if v < v_max {
                assert!(stopping_mm(&cell, 0, v + 1e-3) > room, "room {room}: v {v} not largest");
            }
        }
    }

    #[test]
    fn ramps_hold_the_share_of_the_acceleration() {
        // 1 m/s^2 per tick share 0.5 at 2 m/s programmed: 0.25 of the factor per tick at most.
        assert_eq!(ramped(1.0, 0.0, 2000.0, 1000.0, (0.5, 0.5)), 0.75);
        assert_eq!(ramped(0.0, 1.0, 2000.0, 1000.0, (0.5, 0.5)), 0.25);
        assert_eq!(ramped(0.5, 0.6, 2000.0, 1000.0, (0.5, 0.5)), 0.6);
        assert_eq!(ramped(0.5, 0.0, 0.0, 1000.0, (0.5, 0.5)), 0.0);
    }
}
