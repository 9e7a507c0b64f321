//! Each robot's speed limit (the module doc of `protective` defines it): the largest
//! measured speed at which every pair involving it is still proved, the other robots as they
//! are, searched by bisection on a grid of `v_max / 2^LIMIT_STEPS` within a budget of tests
//! per tick.

use super::stop_sweeps::first_unproved;
use super::{Protective, ProtectiveChecker, LIMIT_STEPS};
use crate::math::{Real, Vec3};

impl ProtectiveChecker {
    /// Each robot's speed limit when they are asked for (else NaN), with this tick's stop
    /// references of every robot already set (the limits search about them).
    pub(super) fn speed_limits_of(&mut self, tcps_mcs: &[Vec3], from_history: bool) {
        if !self.model.speed_limits {
            self.report.robots.iter_mut().for_each(|r| r.speed_limit_mm_s = Real::NAN);
            return;
        }
        // This tick's verdict, when not STOP, proved every pair at each robot's measured speed
        // (with its measured direction, the ball the search's tests build at that speed too).
        let proved_now = self.report.verdict != Protective::Stop;
        let n = tcps_mcs.len();
        // Without a history (`check_at_speeds`) no search has a last limit to start from, so
        // none would get far with a few tests: those searches are not capped.
        let cap = if from_history { self.model.limit_tests } else { u32::MAX };
        let (first, mut left) = (self.calls.limit_turn % n.max(1), cap);
        self.calls.limit_turn = self.calls.limit_turn.wrapping_add(1);
        for i in 0..n {
            let j = (first + i) % n;
            let tcp = &tcps_mcs[j];
            let start = self.robots[j].history.limit.filter(|_| from_history);
            let v = self.report.robots[j].speed_mm_s;
            let floor =
                if proved_now && v <= self.cell().stops[j].max_speed_mm_s { v } else { 0.0 };
            // What is left, but one test for each robot after this one (while there are any).
            let after = (n - 1 - i) as u32;
            let budget = if left > after { left - after } else { left.min(1) };
            let (limit, used, step) = self.speed_limit(j, tcp, start, floor, budget);
            left -= used;
            (self.report.robots[j].speed_limit_mm_s, self.robots[j].limit_step) = (limit, step);
        }
    }

    /// Robot `j`'s speed limit (module doc), the other robots' sweeps as they are: the search
    /// from `start` (the last tick's limit and the step of the first test above it), never
    /// below `floor`, a speed this tick's verdict proved for `j` (0 when none), with at most
    /// `budget` tests of the table's tier. Returns the limit, the tests used, and the step of
    /// the next tick's first test above the limit.
    fn speed_limit(
        &mut self,
        j: usize,
        tcp_mcs: &Vec3,
        start: Option<(Real, Real)>,
        floor: Real,
        budget: u32,
    ) -> (Real, u32, Real) {
        // Robot `j`'s state, whose reference each test replaces: restored after the search.
        let saved = self.robots[j];
        let inside = self.kept.inside(j);
        // `tier` None: only the certain-STOP test (no sweeps), which every tier needs to pass.
        let proved = |me: &mut Self, v: Real, tier: Option<u32>| {
            let s = me.stop_reference(j, tcp_mcs, v);
            if me.kept.set_inside(
                j,
                &[(me.robots[j].reference.centre, me.robots[j].reference.radius), (*tcp_mcs, s)],
            ) && me.kept_free(Some(j))
            {
                return true;
            }
            if me.report.closest.is_some_and(|h| (h.a == j || h.b == j) && me.ball_swept_meet(h)) {
                return false;
            }
            let Some(tier) = tier else { return true };
            // The robots that can meet `j` as they are, with the motor angles of the same tier;
            // with tier 1, another robot keeps the sweeps it has for this tick's reference,
            // tier 1 or the verdict's second tier on some arms: each encloses every box of its
            // stop (module doc, step 4), the second tier within the first, so a test proved
            // with them is a proof, and tier 2 on every arm proves it too (the precise limit
            // stays the higher); only a robot without sweeps gets tier 1's.
            for k in 0..me.exact.verdict().pairs.len() {
                let p = me.exact.verdict().pairs[k];
                if p.a == j || p.b == j {
                    for i in [p.a, p.b] {
                        if i == j || tier > 0 || me.robots[i].tier.is_none() {
                            me.sweeps_at(i, tier, 0b111);
                        }
                    }
                }
            }
            let (robots, pairs) = (&me.robots, &me.pairs);
            let (ball, axis) = (|i: usize| &robots[i].reference, |k: usize| &pairs[k].axis);
            first_unproved(&me.exact.verdict().pairs, ball, axis, Some(j), 0.0).is_none()
        };
        let vmax = self.cell().stops[j].max_speed_mm_s;
        let resolution = vmax / (1u32 << LIMIT_STEPS) as Real;
        // The speed on the grid of `resolution` nearest the middle of `lo` and `hi` (grid
        // speeds, at least two steps apart), strictly between them: every search tests grid
        // speeds only, so that searches of the same proof end at the same bracket (`v_max` is
        // `2^LIMIT_STEPS` steps exactly; so is every grid speed a whole number of steps).
        let middle =
            |lo: Real, hi: Real| lo + (0.5 * (hi - lo) / resolution).floor().max(1.0) * resolution;
        // From `lo` (proved) and `hi` (not), halves until they are `resolution` apart.
        let bisect = |me: &mut Self, (mut lo, mut hi): (Real, Real), tier: Option<u32>| {
            while hi - lo > resolution {
                let mid = middle(lo, hi);
                if proved(me, mid, tier) {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            (lo, hi)
        };
        // The bracket of one test alone below `top` (not proved there, unless `top = vmax`).
        let limit_of = |me: &mut Self, tier: Option<u32>, top: Real| {
            if top == vmax && proved(me, vmax, tier) {
                (vmax, vmax)
            } else if !proved(me, 0.0, tier) {
                (0.0, 0.0)
            } else {
                bisect(me, (0.0, top), tier)
            }
        };
        // The same bracket found from `h`, the last tick's limit: steps of doubling length up
        // (while proved) or down (while not) to a bracket, then the bisection. Limits change
        // little from tick to tick, so this takes a few tests instead of `LIMIT_STEPS + 2`.
        let limit_near = |me: &mut Self, h: Real| {
            let h = ((h / resolution).round() * resolution).clamp(0.0, vmax);
            let up = proved(me, h, Some(0));
            let (mut from, mut step) = (h, resolution);
            loop {
                let to = if up { (from + step).min(vmax) } else { (from - step).max(0.0) };
                if to == from {
                    return (from, from);
                }
                if proved(me, to, Some(0)) != up {
                    return bisect(me, if up { (from, to) } else { (to, from) }, Some(0));
                }
                (from, step) = (to, 2.0 * step);
            }
        };
        // `limit_of` or `limit_near` with tier 1 alone, at most `budget` tests: the largest speed
        // a test proved (0 when none did, or when every speed above `floor` that the search
        // would still test is at most `floor`: `floor` is the answer then), the tests used, and
        // where the next tick's first step up starts: where this one's steps or bisection
        // stopped for want of tests (`resolution` when the search ended).
        let mut used = 0;
        let mut capped = |me: &mut Self| -> (Real, Real) {
            let mut test = |me: &mut Self, v: Real| {
                let left = used < budget;
                used += u32::from(left);
                left.then(|| proved(me, v, Some(0)))
            };
            // `lo` proved, `hi` not (`None`: no such speed tested yet).
            let (mut lo, mut hi) = (None, None);
            let mut step = resolution;
            match start {
                Some((h, carried)) => {
                    let h = ((h / resolution).round() * resolution).clamp(0.0, vmax);
                    match test(me, h) {
                        None => return (0.0, resolution),
                        Some(true) => (lo, step) = (Some(h), carried.max(resolution)),
                        Some(false) => hi = Some(h),
                    }
                }
                None => {
                    match test(me, vmax) {
                        None => return (0.0, resolution),
                        Some(true) => return (vmax, resolution),
                        Some(false) => hi = Some(vmax),
                    }
                    match test(me, 0.0) {
                        Some(true) => lo = Some(0.0),
                        _ => return (0.0, resolution),
                    }
                }
            }
            loop {
                let (to, up) = match (lo, hi) {
                    (Some(l), None) if l >= vmax => return (vmax, resolution),
                    (Some(l), None) => ((l + step).min(vmax), true),
                    (None, Some(h)) if h <= floor || h <= 0.0 => return (0.0, resolution),
                    (None, Some(h)) => ((h - step).max(0.0), false),
                    _ => break,
                };
                match test(me, to) {
                    // Out of tests while going up: the next tick goes on with the next step.
                    None => return (lo.unwrap_or(0.0), if up { step } else { resolution }),
                    Some(true) => lo = Some(to),
                    Some(false) => hi = Some(to),
                }
                // A bracket found going down from `hi` ends the steps; going up, so does `hi`.
                if !up && lo.is_some() {
                    break;
                }
                step *= 2.0;
            }
            let (Some(mut lo), Some(mut hi)) = (lo, hi) else {
                return (lo.unwrap_or(0.0), resolution);
            };
            while hi - lo > resolution && hi > floor {
                let mid = middle(lo, hi);
                match test(me, mid) {
                    // Out of tests: the next tick tries the middle of the bracket first.
                    None => return (lo, mid - lo),
                    Some(true) => lo = mid,
                    Some(false) => hi = mid,
                }
            }
            (lo, resolution)
        };
        let tier = if self.model.precise_limits { self.model.precise_splits } else { 0 };
        // Tier 1 alone on the grid `v_max k / 2^LIMIT_STEPS`: the default limit (capped), and
        // the floor of the precise one (not capped).
        let mut next_step = resolution;
        let (lo, hi) = match start {
            _ if tier == 0 => {
                let (lo, step) = capped(self);
                next_step = step;
                (lo, vmax)
            }
            Some((h, _)) => limit_near(self, h),
            None => limit_of(self, Some(0), vmax),
        };
        let limit = if tier == 0 || lo == vmax {
            lo
        } else {
            // Above `top` no tier proves anything: the certain-STOP test fails there.
            let top = limit_of(self, None, vmax).1;
            if top == 0.0 {
                0.0
            } else if hi == 0.0 {
                // The table proves not even standing still: the second tier alone.
                limit_of(self, Some(tier), top).0
            } else if hi >= top || !proved(self, hi, Some(tier)) {
                lo
            } else if top == vmax && proved(self, vmax, Some(tier)) {
                vmax
            } else {
                bisect(self, (hi, top), Some(tier)).0
            }
        };
        self.robots[j] = saved;
        self.kept.restore_inside(j, inside);
        // The step is kept only when the limit is the one the steps were taken from.
        let next_step = if limit >= floor { next_step } else { resolution };
        (limit.max(floor), used, next_step)
    }
}
