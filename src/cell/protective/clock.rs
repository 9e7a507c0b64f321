//! When a protective call's TCPs hold, and what the interval since the last call means
//! (module doc of `protective`, step 1: the speed bound needs the real interval).
//!
//! The verdict infers each robot's speed from its displacement since the last call. That
//! displacement means a speed only over a known interval: two calls in one cycle see a
//! displacement of 0 and, read as one tick apart, would bound a robot at full speed by
//! `a_max T`. So the time is an input ([`TickTime`]), and [`interval`] turns two times into
//! an interval the speed bound may use, or into a [`TimingFault`] (STOP):
//! - the **same cycle** (or timestamp) again is the last call repeated: with the same TCPs it
//!   gets that call's report unchanged, never a recomputed one; with other TCPs it is
//!   [`TimingFault::Repeated`];
//! - a time **before** the last one is [`TimingFault::Backwards`];
//! - more than [`MAX_INTERVAL_TICKS`] ticks after it is [`TimingFault::Jump`];
//! - a timestamp less than [`MIN_INTERVAL_TICKS`] of a tick after it is
//!   [`TimingFault::Early`] (a stale measurement with a fresh timestamp reads as a robot that
//!   stands; a cycle counter cannot be early);
//! - a cycle counter after timestamps, or the reverse, is [`TimingFault::ClockChanged`];
//! - otherwise the speed is bounded over the real interval `dt`: a skipped cycle gives
//!   `dt = 2 T` and the bound of step 1 over `2 T`, never less safe than a call every cycle.
//!
//! After a fault the checker forgets every previous TCP (the next call assumes full speed)
//! and measures the next interval from the faulty call's time.

use crate::math::Real;

/// Most ticks between two timed calls whose interval still bounds the speeds; a longer gap is
/// [`TimingFault::Jump`]. Four ticks: a skipped cycle or two is a real controller's jitter,
/// more is a stalled task, and over `4 T` the bound `a_max dt` of step 1 comes near `v_max`
/// anyway (130 m/s^2 over 4 ms is 0.52 m/s).
pub const MAX_INTERVAL_TICKS: u64 = 4;

/// Least interval between two timestamps, in ticks; a shorter one is [`TimingFault::Early`].
pub const MIN_INTERVAL_TICKS: Real = 0.5;

/// When the TCPs of one protective call hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TickTime {
    /// One `tick_ms` after the last call, whenever this call comes: correct only for a
    /// controller that calls exactly once per cycle, at the cycle's nominal time.
    Nominal,
    /// The controller's cycle counter, one more per `tick_ms`; the TCPs are that cycle's
    /// (its set-points, or positions measured at the cycle's nominal time).
    Cycle(u64),
    /// A monotonic timestamp (ns) of the moment the TCPs were measured.
    Nanos(u64),
}

/// A timing fault: the call's time gives no interval to bound the speeds with (STOP).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingFault {
    /// The same cycle or timestamp as the last call, with other TCPs.
    Repeated,
    /// A cycle or timestamp before the last call's.
    Backwards,
    /// More than [`MAX_INTERVAL_TICKS`] ticks after the last call.
    Jump,
    /// A timestamp less than [`MIN_INTERVAL_TICKS`] of a tick after the last one.
    Early,
    /// A cycle counter after a timestamp, or a timestamp after a cycle counter.
    ClockChanged,
}

/// What the time of a call means against the last call's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Interval {
    /// No earlier time to measure from (the first timed call, or one after an untimed call):
    /// every previous TCP is forgotten, full speed assumed.
    Unknown,
    /// The same cycle or timestamp as the last call: its report again, if the TCPs are equal.
    Same,
    /// The interval (s) to bound the speeds over.
    Seconds(Real),
    /// No interval: STOP.
    Fault(TimingFault),
}

/// The interval from the last call's time `last` (`None`: none yet) to `now`, for a tick of
/// `tick_s` seconds (module doc).
pub(super) fn interval(last: Option<TickTime>, now: TickTime, tick_s: Real) -> Interval {
    let max_s = MAX_INTERVAL_TICKS as Real * tick_s;
    match (last, now) {
        (_, TickTime::Nominal) => Interval::Seconds(tick_s),
        (None | Some(TickTime::Nominal), _) => Interval::Unknown,
        (Some(TickTime::Cycle(before)), TickTime::Cycle(c)) => match c.checked_sub(before) {
            None => Interval::Fault(TimingFault::Backwards),
            Some(0) => Interval::Same,
            Some(n) if n > MAX_INTERVAL_TICKS => Interval::Fault(TimingFault::Jump),
            Some(n) => Interval::Seconds(n as Real * tick_s),
        },
        (Some(TickTime::Nanos(before)), TickTime::Nanos(t)) => match t.checked_sub(before) {
            None => Interval::Fault(TimingFault::Backwards),
            Some(0) => Interval::Same,
            Some(ns) => {
                let dt = ns as Real * 1e-9;
                // Relative slack: a timestamp of exactly half a tick or four ticks is in range.
                if dt < MIN_INTERVAL_TICKS * tick_s * (1.0 - 1e-12) {
                    Interval::Fault(TimingFault::Early)
                } else if dt > max_s * (1.0 + 1e-12) {
                    Interval::Fault(TimingFault::Jump)
                } else {
                    Interval::Seconds(dt)
                }
            }
        },
        (Some(_), _) => Interval::Fault(TimingFault::ClockChanged),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use TickTime::{Cycle, Nanos, Nominal};

    const T: Real = 1e-3;

    #[test]
    fn cycles_give_whole_ticks_and_faults_at_each_edge() {
        let at = |before, now| interval(Some(Cycle(before)), Cycle(now), T);
        assert_eq!(at(7, 8), Interval::Seconds(T));
        assert_eq!(at(7, 9), Interval::Seconds(2.0 * T));
        assert_eq!(
            at(7, 7 + MAX_INTERVAL_TICKS),
            Interval::Seconds(MAX_INTERVAL_TICKS as Real * T)
        );
        assert_eq!(at(7, 8 + MAX_INTERVAL_TICKS), Interval::Fault(TimingFault::Jump));
        assert_eq!(at(7, 7), Interval::Same);
        assert_eq!(at(7, 6), Interval::Fault(TimingFault::Backwards));
        assert_eq!(at(0, u64::MAX), Interval::Fault(TimingFault::Jump));
        assert_eq!(at(u64::MAX, 0), Interval::Fault(TimingFault::Backwards));
    }

    #[test]
    fn timestamps_give_the_real_interval_between_half_a_tick_and_the_jump() {
        let at = |before, now| interval(Some(Nanos(before)), Nanos(now), T);
        assert_eq!(at(1_000_000, 2_000_000), Interval::Seconds(1e-3));
        assert_eq!(at(1_000_000, 1_500_000), Interval::Seconds(0.5e-3));
        assert_eq!(at(1_000_000, 1_499_999), Interval::Fault(TimingFault::Early));
        assert_eq!(at(1_000_000, 1_000_001), Interval::Fault(TimingFault::Early));
        assert_eq!(at(1_000_000, 5_000_000), Interval::Seconds(4e-3));
        assert_eq!(at(1_000_000, 5_000_001), Interval::Fault(TimingFault::Jump));
        assert_eq!(at(1_000_000, 1_000_000), Interval::Same);
        assert_eq!(at(1_000_000, 999_999), Interval::Fault(TimingFault::Backwards));
    }

    #[test]
    fn nominal_calls_are_one_tick_and_clocks_do_not_mix() {
        assert_eq!(interval(Some(Cycle(3)), Nominal, T), Interval::Seconds(T));
        assert_eq!(interval(None, Nominal, T), Interval::Seconds(T));
        assert_eq!(interval(None, Cycle(3), T), Interval::Unknown);
        assert_eq!(interval(Some(Nominal), Nanos(3), T), Interval::Unknown);
        assert_eq!(
            interval(Some(Cycle(3)), Nanos(3), T),
            Interval::Fault(TimingFault::ClockChanged)
        );
        assert_eq!(
            interval(Some(Nanos(3)), Cycle(4), T),
            Interval::Fault(TimingFault::ClockChanged)
        );
    }
}
