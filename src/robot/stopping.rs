//! The stopping model of one robot (SPEC §8): what its TCP may do from the tick a stop is
//! issued until it stands still, and the distance that can take.
//!
//! From the stop, for `reaction_ms` the TCP may move in any way within `max_speed_mm_s` and
//! `max_accel_mm_s2` (detection, bus and drive latency: the drive still follows the last
//! set-points); then it brakes along its path, its speed falling by at least `decel_mm_s2`
//! per second. Nothing is known of the path's direction.
//!
//! # Defaults and why
//! - `reaction_ms = 4`: a few 1 ms ticks of detection, fieldbus and drive latency.
//! - `decel_mm_s2 = 40 000` (40 m/s^2): a conservative path-maintaining stop of a Delta3
//!   (SPEC §8: "braking from 4.5 m/s at 40 m/s^2").
//! - `max_accel_mm_s2 = 130 000` (130 m/s^2): the peak acceleration of a fast pick-and-place
//!   cycle (SPEC §5).
//! - `max_speed_mm_s = 4 600` (4.6 m/s): the peak TCP speed of such a cycle (SPEC §5).
//! - cell `tick_ms = 1`: the controller's cycle (thesis: 1 ms).

use crate::math::Real;
use alloc::{format, string::String};

/// How one robot stops (SPEC §8); mm, s and ms as the field names say.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StopModel {
    /// Time from the stop being issued until braking starts (ms); the TCP may do anything
    /// within the speed and acceleration limits meanwhile.
    pub reaction_ms: Real,
    /// The least deceleration while braking along the path (mm/s^2).
    pub decel_mm_s2: Real,
    /// The largest acceleration of the TCP at any time (mm/s^2).
    pub max_accel_mm_s2: Real,
    /// The largest speed of the TCP at any time (mm/s).
    pub max_speed_mm_s: Real,
}

/// The default controller cycle (ms).
pub const DEFAULT_TICK_MS: Real = 1.0;

impl Default for StopModel {
    fn default() -> Self {
        StopModel::DEFAULT
    }
}

impl StopModel {
    /// The defaults of the module doc.
    pub const DEFAULT: StopModel = StopModel {
        reaction_ms: 4.0,
        decel_mm_s2: 40_000.0,
        max_accel_mm_s2: 130_000.0,
        max_speed_mm_s: 4_600.0,
    };

    /// Checks every field; the error names the field (`what` prefixes it, e.g. "robot 1 (B):
    /// stop").
    ///
    /// # Errors
    /// A message when a field is NaN, infinite or not > 0, or when `decel_mm_s2` exceeds
    /// `max_accel_mm_s2` (braking is an acceleration too).
    pub fn validate(&self, what: &str) -> Result<(), String> {
        for (name, v) in [
            ("reaction_ms", self.reaction_ms),
            ("decel_mm_s2", self.decel_mm_s2),
            ("max_accel_mm_s2", self.max_accel_mm_s2),
            ("max_speed_mm_s", self.max_speed_mm_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{what}.{name} = {v} must be finite and > 0"));
            }
        }
        if self.decel_mm_s2 > self.max_accel_mm_s2 {
            return Err(format!(
                "{what}.decel_mm_s2 = {} exceeds {what}.max_accel_mm_s2 = {}: braking is an acceleration too; \
                 lower decel_mm_s2 or raise max_accel_mm_s2",
                self.decel_mm_s2, self.max_accel_mm_s2
            ));
        }
        Ok(())
    }

    /// The distance (mm) the TCP can travel along its path from a stop issued now, when its
    /// speed now is at most `v_mm_s`, reacting for `reaction_s` seconds:
    /// `min(v T + a T^2 / 2, v_max T) + v_r^2 / (2 decel)` with `v_r = min(v + a T, v_max)`.
    pub fn stopping_distance(&self, v_mm_s: Real, reaction_s: Real) -> Real {
        let (a, vmax, t) = (self.max_accel_mm_s2, self.max_speed_mm_s, reaction_s);
        let v = v_mm_s.clamp(0.0, vmax);
        let during_reaction = (v * t + 0.5 * a * t * t).min(vmax * t);
        let v_r = (v + a * t).min(vmax);
        during_reaction + v_r * v_r / (2.0 * self.decel_mm_s2)
    }
}

/// Checks a cell's tick (ms).
///
/// # Errors
/// A message naming `tick_ms` when it is NaN, infinite or not > 0.
pub fn validate_tick_ms(tick_ms: Real) -> Result<(), String> {
    if tick_ms.is_finite() && tick_ms > 0.0 {
        Ok(())
    } else {
        Err(format!("tick_ms = {tick_ms} must be finite and > 0"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_the_distance_matches_the_spec_figure() {
        StopModel::DEFAULT.validate("stop").unwrap();
        // SPEC §8: braking from 4.5 m/s at 40 m/s^2 ends within about 250 mm.
        let s = StopModel::DEFAULT.stopping_distance(4_500.0, 0.0);
        assert!((s - 253.125).abs() < 1e-9, "{s}");
        assert_eq!(StopModel::DEFAULT.stopping_distance(0.0, 0.0), 0.0);
        // The speed cap binds during the reaction.
        let s = StopModel::DEFAULT.stopping_distance(4_600.0, 0.004);
        assert!((s - (4_600.0 * 0.004 + 4_600.0f64.powi(2) / 80_000.0)).abs() < 1e-9);
    }

    #[test]
    fn bad_fields_are_named() {
        let bad = |m: StopModel| m.validate("robot 0 (A): stop").unwrap_err();
        assert!(bad(StopModel { reaction_ms: 0.0, ..StopModel::DEFAULT }).contains("reaction_ms"));
        assert!(
            bad(StopModel { decel_mm_s2: Real::NAN, ..StopModel::DEFAULT }).contains("decel_mm_s2")
        );
        assert!(bad(StopModel { max_speed_mm_s: -1.0, ..StopModel::DEFAULT })
            .contains("max_speed_mm_s"));
        let e = bad(StopModel { decel_mm_s2: 200_000.0, ..StopModel::DEFAULT });
        assert!(e.contains("decel_mm_s2") && e.contains("max_accel_mm_s2"), "{e}");
        assert!(validate_tick_ms(0.0).unwrap_err().contains("tick_ms"));
    }
}
